//! BVH2 → wide collapse. Which BVH2 nodes become wide nodes, and which subtrees become leaves,
//! is chosen to minimise the surface area heuristic by dynamic programming over the BVH2
//! (Ylitie, Karras and Laine 2017, "Efficient incoherent ray traversal on GPUs through
//! compressed wide BVHs", section 4.1): a cost table in caller scratch, filled bottom-up, then
//! read top-down while the wide nodes are laid out breadth-first, with the output arena as the
//! work queue. Should that tree not fit the arena (whose bound, [`super::wide_nodes_needed`],
//! is proved for the greedy collapse), the greedy collapse is laid out instead: each node
//! opens its largest inner child until it is full.

use super::node::WideNode;
use super::wide_nodes_needed;
use crate::accel::bvh::{half_area, Node};
use crate::accel::{Arena, BuildError};
use crate::scalar::Scalar;

/// SAH cost of visiting a wide node, relative to one primitive test (the binary builder's).
const NODE_COST: f32 = 1.0;

/// A child of a wide node: the BVH2 node it stands for, and the primitive range
/// `(first, count)` if it is a leaf (a BVH2 leaf, or a whole BVH2 subtree made one leaf).
#[derive(Clone, Copy)]
struct Root {
    source: u32,
    leaf: Option<(u32, u32)>,
}

/// Collapses the BVH2 `src` (root first, as [`crate::Bvh::nodes`]) over `prim_count`
/// primitives into `out`, with `W - 1` words of `scratch` per slot of `src`. Returns the wide
/// nodes used and the depth of the deepest one.
pub(super) fn collapse<S: Scalar, const W: usize>(
    src: &[Node<S>],
    out: &mut [WideNode<S, W>],
    scratch: &mut [u32],
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
    let words = (W - 1).saturating_mul(src.len());
    let Some(scratch) = scratch.get_mut(..words) else {
        return Err(BuildError::ArenaTooSmall {
            arena: Arena::Scratch,
            needed: words,
            available: scratch.len(),
        });
    };
    let Some(root) = src.first() else {
        return Ok((0, 0));
    };
    if root.is_leaf() {
        // A tree over one leaf: a root with one leaf child.
        let mut n = WideNode::EMPTY;
        n.set(0, &root.bounds(), root.first(), root.count());
        for i in 1..W {
            n.clear(i);
        }
        let first = out.first_mut().ok_or(too_small)?;
        *first = n;
        return Ok((1, 0));
    }
    optimal_or_greedy(src, out, &Costs::<W>::plan(src, scratch)).ok_or(too_small)
}

/// The tree `costs` describe if it fits `out`, otherwise the greedy one (`None` if neither
/// does, which a BVH2 from [`crate::Bvh::build`] and an arena of the bound never meet).
fn optimal_or_greedy<S: Scalar, const W: usize>(
    src: &[Node<S>],
    out: &mut [WideNode<S, W>],
    costs: &Costs<W>,
) -> Option<(usize, u32)> {
    layout(src, out, |s| costs.roots(src, s)).or_else(|| layout(src, out, |s| greedy_roots(src, s)))
}

/// Lays the wide tree out breadth-first from the BVH2 root (an inner node), `roots` giving
/// each wide node's children. `None` if `out` runs out.
fn layout<S: Scalar, const W: usize>(
    src: &[Node<S>],
    out: &mut [WideNode<S, W>],
    roots: impl Fn(usize) -> ([Root; W], usize),
) -> Option<(usize, u32)> {
    *out.first_mut()? = pending(0, 0);
    let (mut used, mut next, mut deepest) = (1usize, 0usize, 0u32);
    while next < used {
        let queued = out.get(next)?;
        let (source, depth) = (queued.child[0], queued.count[0]);
        deepest = deepest.max(depth);
        let mut node = WideNode::EMPTY;
        let (kids, k) = roots(source as usize);
        for (slot, kid) in kids.iter().enumerate() {
            // Every BVH2 index here is in range for a tree `Bvh::build` made; a missing
            // node would only leave its slot unused.
            match (src.get(kid.source as usize).filter(|_| slot < k), kid.leaf) {
                (Some(c), Some((first, count))) => node.set(slot, &c.bounds(), first, count),
                (Some(c), None) => {
                    *out.get_mut(used)? = pending(kid.source, depth + 1);
                    node.set(slot, &c.bounds(), used as u32, 0);
                    used += 1;
                }
                (None, _) => node.clear(slot),
            }
        }
        *out.get_mut(next)? = node;
        next += 1;
    }
    Some((used, deepest))
}

/// A node still to be filled: `child[0]` is its BVH2 source (an inner node), `count[0]` its
/// depth. Nodes are filled in index order, and a node's children get indices above every
/// node allocated before them, so the queue is the arena itself.
fn pending<S: Scalar, const W: usize>(source: u32, depth: u32) -> WideNode<S, W> {
    let mut n = WideNode::EMPTY;
    n.child[0] = source;
    n.count[0] = depth;
    n
}

/// `src[i]` as a child of a wide node that becomes a node of its own (if inner) or a leaf.
fn as_is<S: Scalar>(src: &[Node<S>], i: u32) -> Root {
    let leaf = src
        .get(i as usize)
        .filter(|n| n.is_leaf())
        .map(|n| (n.first(), n.count()));
    Root { source: i, leaf }
}

/// The greedy collapse's children of the wide node made from the inner node `src[parent]`:
/// start from its two children and open the inner child with the largest surface area (the
/// first of equals) until there are `W` or no inner one is left. Opening replaces a child by
/// its two children in place, so children stay in the BVH2's depth-first (leaf-range) order.
fn greedy_roots<S: Scalar, const W: usize>(src: &[Node<S>], parent: usize) -> ([Root; W], usize) {
    let mut kids = [0u32; W];
    let Some(first) = src.get(parent).map(Node::first) else {
        return (kids.map(|i| as_is(src, i)), 0);
    };
    if let [a, b, ..] = kids.as_mut_slice() {
        (*a, *b) = (first, first.wrapping_add(1));
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
    (kids.map(|i| as_is(src, i)), k)
}

/// The cost table: for each BVH2 slot `x` and `j` in `1..W`, `cost(x, j)`, the least SAH cost
/// of representing the subtree of `x` as at most `j` subtrees side by side (children of one
/// wide node), `f32` bits in `W - 1` consecutive words. `cost(x, 1)` is that of `x` as one
/// child: a leaf (a BVH2 leaf; an inner node whose subtree holds at most `max_leaf`
/// primitives, if cheaper or equal) or a wide node whose children are the cheapest forest of
/// at most `W` subtrees under it. Costs are sums of half areas (of a node times
/// [`NODE_COST`], of a leaf times its primitive count) in a fixed order of `f32` operations,
/// so the same on every platform.
struct Costs<'s, const W: usize> {
    words: &'s [u32],
    /// The largest leaf of the BVH2: merged leaves are no larger.
    max_leaf: u32,
}

impl<'s, const W: usize> Costs<'s, W> {
    /// Fills the table bottom-up (children come after their parent in a BVH2 arena).
    fn plan<S: Scalar>(src: &[Node<S>], words: &'s mut [u32]) -> Self {
        let max_leaf = src.iter().map(Node::count).max().unwrap_or(0);
        for x in (0..src.len()).rev() {
            // Slot 1 is padding, never a child.
            let row = if x == 1 {
                [f32::INFINITY; W]
            } else {
                Costs::<W> {
                    words: &*words,
                    max_leaf,
                }
                .row_of(src, x)
            };
            let start = (W - 1) * x;
            if let Some(dst) = words.get_mut(start..start + (W - 1)) {
                for (d, c) in dst.iter_mut().zip(row) {
                    *d = c.to_bits();
                }
            }
        }
        Self { words, max_leaf }
    }

    /// `cost(x, j)` for `j` in `1..W`; infinite outside the table.
    fn get(&self, x: usize, j: usize) -> f32 {
        let word = (W - 1).saturating_mul(x).saturating_add(j.wrapping_sub(1));
        match self.words.get(word) {
            Some(&w) if (1..W).contains(&j) => f32::from_bits(w),
            _ => f32::INFINITY,
        }
    }

    /// The row of `x` (`cost(x, 1..W)`), from its children's rows.
    fn row_of<S: Scalar>(&self, src: &[Node<S>], x: usize) -> [f32; W] {
        let mut row = [f32::INFINITY; W];
        let Some(n) = src.get(x) else {
            return row;
        };
        let area = half_area(&n.lo, &n.hi);
        if n.is_leaf() {
            return [area * n.count() as f32; W];
        }
        let as_node = area * NODE_COST + self.split(n, W).0;
        let as_leaf = self.leaf_cost(src, x);
        row[0] = if as_leaf <= as_node { as_leaf } else { as_node };
        for j in 2..W {
            let (fewer, split) = (row[(j - 2) % W], self.split(n, j).0);
            row[(j - 1) % W] = if split < fewer { split } else { fewer };
        }
        row
    }

    /// Cost of the inner node `src[x]`'s subtree as one leaf; infinite above `max_leaf`.
    fn leaf_cost<S: Scalar>(&self, src: &[Node<S>], x: usize) -> f32 {
        let (_, count) = range(src, x);
        match src.get(x) {
            Some(n) if count <= self.max_leaf => half_area(&n.lo, &n.hi) * count as f32,
            _ => f32::INFINITY,
        }
    }

    /// The cheapest way to share `j >= 2` subtrees between the inner node `n`'s children:
    /// (cost, subtrees of the left child), the fewest for the left on equal costs.
    fn split<S: Scalar>(&self, n: &Node<S>, j: usize) -> (f32, usize) {
        let (l, r) = (n.first() as usize, n.first() as usize + 1);
        let mut best = (f32::INFINITY, 1);
        for k in 1..j {
            let c = self.get(l, k) + self.get(r, j - k);
            if c < best.0 {
                best = (c, k);
            }
        }
        best
    }

    /// Children of the wide node made from the inner node `src[parent]`, in depth-first
    /// order: the forest behind its `cost(parent, 1)`, unfolded with a stack of (node,
    /// subtrees allowed) whose allowances sum to at most `W`.
    fn roots<S: Scalar>(&self, src: &[Node<S>], parent: usize) -> ([Root; W], usize) {
        let mut kids = [Root {
            source: 0,
            leaf: None,
        }; W];
        let mut k = 0usize;
        let mut todo: heapless::Vec<(usize, usize), W> = heapless::Vec::new();
        let _ = todo.push((parent, W));
        while let Some((x, j)) = todo.pop() {
            let Some(n) = src.get(x) else {
                continue;
            };
            let (first, second) = (n.first() as usize, n.first() as usize + 1);
            if x != parent && (j == 1 || n.is_leaf()) {
                if let Some(slot) = kids.get_mut(k) {
                    *slot = self.as_child(src, x);
                    k += 1;
                }
            } else {
                let (cost, left) = self.split(n, j);
                if x != parent && cost >= self.get(x, j - 1) {
                    // Fewer subtrees cost no more.
                    let _ = todo.push((x, j - 1));
                } else {
                    let _ = todo.push((second, j - left));
                    let _ = todo.push((first, left));
                }
            }
        }
        (kids, k)
    }

    /// `src[x]` as one child: a leaf if it is one or its subtree is cheaper as one.
    fn as_child<S: Scalar>(&self, src: &[Node<S>], x: usize) -> Root {
        let inner_as_leaf =
            src.get(x).is_some_and(|n| !n.is_leaf()) && self.leaf_cost(src, x) <= self.get(x, 1);
        if inner_as_leaf {
            return Root {
                source: x as u32,
                leaf: Some(range(src, x)),
            };
        }
        as_is(src, x as u32)
    }
}

/// The primitive range `(first, count)` of the subtree of `src[x]`: from its leftmost leaf's
/// first to its rightmost leaf's last (a BVH2 subtree's leaves cover consecutive ranges).
fn range<S: Scalar>(src: &[Node<S>], x: usize) -> (u32, u32) {
    let (mut a, mut b) = (x, x);
    while let Some(n) = src.get(a).filter(|n| !n.is_leaf()) {
        a = n.first() as usize;
    }
    while let Some(n) = src.get(b).filter(|n| !n.is_leaf()) {
        b = n.first() as usize + 1;
    }
    let first = src.get(a).map_or(0, Node::first);
    let end = src.get(b).map_or(0, |n| n.first().wrapping_add(n.count()));
    (first, end.wrapping_sub(first))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::bvh::{nodes_needed, BuildOptions, BuilderKind, Bvh};
    use crate::geom::Triangle;

    /// Most triangles a test here builds over (its arrays are sized for it: no `std`).
    const MAX: usize = 300;
    const NODES: usize = nodes_needed(MAX);

    /// SAH cost of a laid-out wide tree under the table's model: the root's box and every
    /// inner child's box times [`NODE_COST`], every leaf child's box times its count.
    fn sah<const W: usize>(root: &Node<f32>, nodes: &[WideNode<f32, W>]) -> f64 {
        let mut cost = f64::from(half_area(&root.lo, &root.hi) * NODE_COST);
        for n in nodes {
            for i in 0..n.child_count() {
                let (b, slot) = (n.bounds(i).unwrap(), n.slot(i).unwrap());
                let area = f64::from(half_area(&b.lo, &b.hi));
                let weight = if slot.count == 0 {
                    NODE_COST
                } else {
                    slot.count as f32
                };
                cost += area * f64::from(weight);
            }
        }
        cost
    }

    /// `MAX` triangles scattered by a linear congruential sequence from `seed`, sizes
    /// varying by 100×.
    fn soup(seed: u32) -> [Triangle<f32>; MAX] {
        let mut state = 12345u32 ^ seed.wrapping_mul(2_654_435_761);
        let mut next = move || {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (state >> 8) as f32 / 16_777_216.0
        };
        core::array::from_fn(|_| {
            let c = [next() * 100.0, next() * 100.0, next() * 10.0];
            let s = 0.1 + next() * 10.0;
            let mut v = |k: f32| [c[0] + s * next() * k, c[1] + s * next(), c[2] + s * next()];
            Triangle::from_f32([v(1.0), v(-1.0), v(0.5)]).unwrap()
        })
    }

    /// Builds the binary SAH BVH over the first `n` triangles of `soup(seed)` and the
    /// `W`-wide cost table over it, and hands both to `f`.
    fn with_table<const W: usize>(
        n: usize,
        seed: u32,
        max_leaf_size: u32,
        f: impl FnOnce(&[Node<f32>], &Costs<W>),
    ) {
        let tris = soup(seed);
        let mut nodes = [Node::EMPTY; NODES];
        let mut ids = [0u32; MAX];
        let options = BuildOptions {
            max_leaf_size,
            ..BuildOptions::default()
        };
        let bvh = Bvh::build(&tris[..n], &mut nodes, &mut ids, options).unwrap();
        let mut words = [u32::MAX; 7 * NODES];
        let words = &mut words[..(W - 1) * bvh.nodes().len()];
        f(bvh.nodes(), &Costs::<W>::plan(bvh.nodes(), words));
    }

    fn optimal_against_greedy<const W: usize>(max_leaf_size: u32) {
        for n in [2usize, 7, 40, MAX] {
            with_table::<W>(n, 0, max_leaf_size, |src, costs| {
                let mut out = [WideNode::<f32, W>::EMPTY; MAX];
                let out = &mut out[..wide_nodes_needed(n, W)];
                let (used, _) = layout(src, out, |s| costs.roots(src, s)).unwrap();
                let optimal = sah(&src[0], &out[..used]);
                let (greedy_used, _) = layout(src, out, |s| greedy_roots(src, s)).unwrap();
                let greedy = sah(&src[0], &out[..greedy_used]);
                // The table's root cost is the laid-out tree's (up to the order of the
                // additions), and no greater than the greedy tree's, one of those it ranges
                // over.
                let table = f64::from(costs.get(0, 1));
                assert!(
                    (optimal - table).abs() <= 1e-5 * table,
                    "{W}-wide, n = {n}: {optimal} vs {table}"
                );
                assert!(
                    optimal <= greedy * (1.0 + 1e-6),
                    "{W}-wide, n = {n}: {optimal} > {greedy}"
                );
                if n == MAX {
                    assert!(
                        used < greedy_used,
                        "{W}-wide: {used} nodes, greedy {greedy_used}"
                    );
                }
            });
        }
    }

    #[test]
    fn the_optimal_collapse_costs_no_more_than_the_greedy_one() {
        for leaf in [1, 3] {
            optimal_against_greedy::<4>(leaf);
            optimal_against_greedy::<8>(leaf);
        }
    }

    #[test]
    fn an_optimal_tree_too_large_for_the_arena_gives_way_to_the_greedy_one() {
        // Seed 1, 17 triangles: the optimal 4-wide tree has one node more than the greedy one.
        with_table::<4>(17, 1, 1, |src, costs| {
            let mut out = [WideNode::<f32, 4>::EMPTY; 17];
            let (optimal, _) = layout(src, &mut out, |s| costs.roots(src, s)).unwrap();
            let (greedy, _) = layout(src, &mut out, |s| greedy_roots(src, s)).unwrap();
            let greedy_tree = out;
            assert_eq!((optimal, greedy), (8, 7));
            let fits = optimal_or_greedy(src, &mut out[..optimal], costs).unwrap();
            assert_eq!(fits.0, optimal);
            assert_ne!(out[..optimal], greedy_tree[..optimal]);
            let falls_back = optimal_or_greedy(src, &mut out[..optimal - 1], costs).unwrap();
            assert_eq!(falls_back.0, greedy);
            assert_eq!(out[..greedy], greedy_tree[..greedy]);
        });
    }

    /// The bound is reached: the greedy collapse of a perfect BVH2 of `2W` one-triangle leaves
    /// in a row is a full root over `W` nodes of two leaves each. (The optimal one does
    /// better: the root holds leaves and nodes of more than two.)
    fn greedy_reaches_the_bound<const W: usize>() {
        let row: [Triangle<f32>; 16] = core::array::from_fn(|i| {
            let x = i as f32 * 2.0;
            Triangle::from_f32([[x, 0.0, 5.0], [x + 1.0, 0.0, 5.0], [x, 1.0, 5.0]]).unwrap()
        });
        let mut nodes = [Node::EMPTY; nodes_needed(16)];
        let mut ids = [0u32; 16];
        let options = BuildOptions {
            builder: BuilderKind::Median,
            max_leaf_size: 1,
            reinsertion: false,
        };
        let bvh = Bvh::build(&row[..2 * W], &mut nodes, &mut ids, options).unwrap();
        let src = bvh.nodes();
        let mut words = [0u32; 7 * nodes_needed(16)];
        let costs = Costs::<W>::plan(src, &mut words[..(W - 1) * src.len()]);
        let mut out = [WideNode::<f32, W>::EMPTY; 16];
        let out = &mut out[..wide_nodes_needed(2 * W, W)];
        assert_eq!(out.len(), W + 1);
        let greedy = layout(src, out, |s| greedy_roots(src, s)).unwrap();
        assert_eq!(greedy, (W + 1, 1));
        assert!(out.iter().skip(1).all(|n| n.child_count() == 2));
        let optimal = layout(src, out, |s| costs.roots(src, s)).unwrap();
        assert!(optimal.0 < W + 1, "{W}-wide: {optimal:?}");
    }

    #[test]
    fn the_greedy_collapse_reaches_the_arena_bound() {
        greedy_reaches_the_bound::<4>();
        greedy_reaches_the_bound::<8>();
    }

    #[test]
    fn scratch_shorter_than_the_table_is_a_typed_error() {
        with_table::<8>(40, 0, 1, |src, _| {
            let needed = 7 * src.len();
            let mut out = [WideNode::<f32, 8>::EMPTY; MAX];
            let out = &mut out[..wide_nodes_needed(40, 8)];
            let mut scratch = [0u32; 7 * NODES];
            assert!(collapse(src, out, &mut scratch[..needed], 40).is_ok());
            assert_eq!(
                collapse(src, out, &mut scratch[..needed - 1], 40),
                Err(BuildError::ArenaTooSmall {
                    arena: Arena::Scratch,
                    needed,
                    available: needed - 1
                })
            );
        });
    }
}
