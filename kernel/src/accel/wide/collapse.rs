//! BVH2 → wide collapse, breadth-first, with the output arena as the work queue.

use super::node::WideNode;
use super::wide_nodes_needed;
use crate::accel::bvh::{half_area, Node};
use crate::accel::{Arena, BuildError};
use crate::scalar::Scalar;

/// A node still to be filled: `child[0]` is its BVH2 source (an inner node), `count[0]` its
/// depth. Nodes are filled in index order, and a node's children get indices above every
/// node allocated before them, so the queue is the arena itself.
fn pending<S: Scalar, const W: usize>(source: u32, depth: u32) -> WideNode<S, W> {
    let mut n = WideNode::EMPTY;
    n.child[0] = source;
    n.count[0] = depth;
    n
}

/// The BVH2 nodes a wide node made from the inner node `parent` gets as children: start from
/// its two children and open the inner child with the largest surface area (the first of
/// equals) until there are four or no inner one is left. Opening replaces a child by its two
/// children in place, so children stay in the BVH2's depth-first (leaf-range) order.
/// Returns the children and their number (`2..=W`).
fn open<S: Scalar, const W: usize>(src: &[Node<S>], parent: &Node<S>) -> ([u32; W], usize) {
    let mut kids = [0; W];
    if let [a, b, ..] = kids.as_mut_slice() {
        (*a, *b) = (parent.first, parent.first.wrapping_add(1));
    }
    let mut k = 2usize;
    while k < W {
        let mut pick: Option<(usize, f32)> = None;
        for (j, &c) in kids.iter().enumerate().take(k) {
            if let Some(n) = src.get(c as usize) {
                if !n.is_leaf() {
                    let area = half_area(&n.lo, &n.hi);
                    if pick.is_none_or(|(_, best)| area > best) {
                        pick = Some((j, area));
                    }
                }
            }
        }
        let Some((j, _)) = pick else {
            break;
        };
        let Some(first) = kids
            .get(j)
            .and_then(|&c| src.get(c as usize))
            .map(Node::first)
        else {
            break;
        };
        // kids[j + 1..k] move one slot right; kids[j], kids[j + 1] become the two children.
        // (Indices are below W here: j < k <= W - 1; the `% W` only shows the compiler, as
        // `rotate_right` kept a panic path for an empty slice.)
        let mut m = k;
        while m > j + 1 {
            kids[m % W] = kids[(m - 1) % W];
            m -= 1;
        }
        kids[j % W] = first;
        kids[(j + 1) % W] = first.wrapping_add(1);
        k += 1;
    }
    (kids, k)
}

/// Collapses the BVH2 `src` (root first, as [`crate::Bvh::nodes`]) into `out`. Returns the
/// wide nodes used and the depth of the deepest one.
pub(super) fn collapse<S: Scalar, const W: usize>(
    src: &[Node<S>],
    out: &mut [WideNode<S, W>],
    prim_count: usize,
) -> Result<(usize, u32), BuildError> {
    let needed = wide_nodes_needed(prim_count, W).max(usize::from(!src.is_empty()));
    let too_small = BuildError::ArenaTooSmall {
        arena: Arena::Nodes,
        needed,
        available: out.len(),
    };
    if out.len() < needed {
        return Err(too_small);
    }
    let Some(root) = src.first() else {
        return Ok((0, 0));
    };
    let Some(first) = out.first_mut() else {
        return Err(too_small);
    };
    if root.is_leaf() {
        // A tree over one leaf: a root with one leaf child.
        let mut n = WideNode::EMPTY;
        n.set(0, &root.bounds(), root.first(), root.count());
        for i in 1..W {
            n.clear(i);
        }
        *first = n;
        return Ok((1, 0));
    }
    *first = pending(0, 0);
    let (mut used, mut next, mut deepest) = (1usize, 0usize, 0u32);
    while next < used {
        let Some(&queued) = out.get(next) else {
            break;
        };
        let (source, depth) = (queued.child[0], queued.count[0]);
        deepest = deepest.max(depth);
        let mut node = WideNode::EMPTY;
        // Every BVH2 index below is in range for a tree `Bvh::build` made; a missing node
        // would only leave its slot unused.
        let (kids, k) = match src.get(source as usize) {
            Some(parent) => open(src, parent),
            None => ([0; W], 0),
        };
        for (slot, &kid) in kids.iter().enumerate() {
            let child = src.get(kid as usize).filter(|_| slot < k);
            match child {
                Some(c) if c.is_leaf() => node.set(slot, &c.bounds(), c.first(), c.count()),
                Some(c) => {
                    let Some(q) = out.get_mut(used) else {
                        return Err(too_small);
                    };
                    *q = pending(kid, depth + 1);
                    node.set(slot, &c.bounds(), used as u32, 0);
                    used += 1;
                }
                None => node.clear(slot),
            }
        }
        if let Some(n) = out.get_mut(next) {
            *n = node;
        }
        next += 1;
    }
    Ok((used, deepest))
}
