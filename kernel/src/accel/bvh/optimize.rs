//! Post-build tree optimization by subtree reinsertion (after Bittner, Hapala and Havran,
//! "Fast insertion-based optimization of bounding volume hierarchies", 2013).
//!
//! A top-down SAH build decides each split without knowing the levels below, and scenes with
//! long, thin or overlapping triangles (architecture) end up with large, overlapping inner
//! boxes. Reinsertion takes a node out of the tree (its parent goes, its sibling moves up),
//! searches the whole tree for the place where putting it back adds the least inner-node
//! area, and moves it there if that lowers the tree's cost. Leaves never change, so the cost
//! to lower is the summed surface area of the inner nodes.
//!
//! Candidates are the nodes with the largest boxes (by quarter-octave size class), in rounds:
//! a probe round over the largest 0.25% (at least 64 nodes), then up to three over the largest
//! 10%, stopping as soon as a round lowers the cost by less than 0.2%. Trees a top-down build already got right (closed
//! meshes such as the bunny) stop after the probe.
//!
//! Everything happens in place in the caller's arena. Sibling pairs keep their layout: the
//! pair freed by a removal holds the reinserted node and its new sibling. Afterwards the tree
//! is laid out again exactly as the builder lays trees out (pairs depth first after their
//! parent, leaves tiling the id slice in order), so [`Bvh::validate`](super::Bvh::validate)'s
//! invariants hold. The bookkeeping (per pair: parent slot and subtree heights; then a copy of
//! the ids) lives in the arena slots after the tree: the pass needs `max(used, n) / 2` of them
//! and is skipped when the arena (of [`nodes_needed`](super::nodes_needed) slots) has fewer,
//! i.e. for trees with about one primitive per leaf. Moves that would put a leaf deeper than
//! [`MAX_DEPTH`] are never made. Iterative, allocation-free and deterministic: `f32` areas, a
//! fixed candidate order.

use super::{Node, FIRST_PAIR, MAX_DEPTH};
use crate::geom::Aabb;
use crate::scalar::Scalar;

/// Share of the nodes (largest boxes first, as `1 / n`) that each round tries to move. The
/// first round is a cheap probe: a tree it cannot improve gets no further rounds.
const ROUND_SHARES: [usize; 4] = [400, 10, 10, 10];
/// Fewest candidates a round considers (all nodes of small trees).
const MIN_CANDIDATES: usize = 64;
/// Rounds stop once one lowers the cost by less than this fraction.
const MIN_ROUND_GAIN: f32 = 0.002;
/// A move must lower the cost by more than this fraction of what it removes.
const MIN_GAIN: f32 = 1e-5;
/// Area buckets for candidate selection (see [`Tree::candidate_threshold`]).
const BUCKETS: usize = 64;
type Histogram = [u32; BUCKETS];
/// Marks the root pair's missing parent.
const NO_PARENT: u32 = u32::MAX;

/// Optimizes the tree in `nodes[..used]` (root at 0, pairs from [`FIRST_PAIR`], bounds not
/// padded yet, leaves tiling `ids` in depth-first order) with `nodes[used..]` as scratch, then
/// lays it out again as the builder does: pairs in depth-first order after their parent,
/// leaves tiling `ids` in that order. Returns the new depth of the deepest leaf, or `None` if
/// the tree is unchanged (nothing to gain, or too little scratch: see the module docs).
///
/// Not inlined: its stack (about 1 KB: the search stack, the size histogram) is used only when
/// the pass runs.
#[inline(never)]
pub(super) fn reinsert<S: Scalar>(
    nodes: &mut [Node<S>],
    used: usize,
    ids: &mut [u32],
) -> Option<u32> {
    if used < 8 || used % 2 != 0 {
        return None;
    }
    let pairs = used / 2;
    let (tree, rest) = nodes.split_at_mut_checked(used)?;
    let scratch = rest.get_mut(..pairs.max(ids.len().div_ceil(2)))?;
    let mut t = Tree {
        nodes: tree,
        pairs: scratch,
    };
    t.link();
    let mut histogram: Histogram = [0; BUCKETS];
    let mut moved = false;
    for share in ROUND_SHARES {
        let cost = t.cost();
        let threshold =
            t.candidate_threshold(&mut histogram, (used / share.max(1)).max(MIN_CANDIDATES));
        let mut gained = 0.0f32;
        for slot in FIRST_PAIR..used {
            let Some(node) = t.nodes.get(slot) else { break };
            if size_class(half_area(&node.bounds())) >= threshold {
                gained += t.try_move(slot);
            }
        }
        moved |= gained > 0.0;
        if gained < MIN_ROUND_GAIN * cost {
            break;
        }
    }
    if !moved {
        return None;
    }
    let depth = t.height(0);
    t.relayout_pairs();
    t.retile_leaves(ids);
    Some(depth)
}

/// Visits the tree in `nodes` depth first, left child first (the builder's order), calling
/// `visit` with each node (which must not change links). Explicit stack: one pending sibling
/// per level.
fn walk_mut<S: Scalar>(nodes: &mut [Node<S>], mut visit: impl FnMut(&mut Node<S>)) {
    let mut stack = [0u32; MAX_DEPTH + 2];
    let mut sp = 1usize;
    while sp > 0 {
        sp -= 1;
        let Some(&x) = stack.get(sp) else { break };
        let Some(node) = nodes.get_mut(x as usize) else {
            continue;
        };
        visit(node);
        if node.count == 0 {
            for child in [node.first + 1, node.first] {
                if let Some(entry) = stack.get_mut(sp) {
                    *entry = child;
                    sp += 1;
                }
            }
        }
    }
}

/// A monotone size class of a non-negative `f32`: its exponent and top two mantissa bits,
/// four classes per factor of two.
fn size_class(x: f32) -> usize {
    (x.to_bits() >> 21) as usize
}

/// Half the surface area of a box, in `f32`.
fn half_area<S: Scalar>(b: &Aabb<S>) -> f32 {
    super::half_area(&b.lo, &b.hi)
}

/// The tree and its per-pair bookkeeping: for pair `q` (slots `2q`, `2q + 1`; pair 0 is the
/// root and the padding slot), `pairs[q].first` is the parent's slot and `pairs[q].count` the
/// heights of the two slots (low and high 16 bits; a leaf has height 0).
struct Tree<'a, S: Scalar> {
    nodes: &'a mut [Node<S>],
    pairs: &'a mut [Node<S>],
}

impl<S: Scalar> Tree<'_, S> {
    fn node(&self, slot: usize) -> Node<S> {
        self.nodes.get(slot).copied().unwrap_or(Node::EMPTY)
    }

    fn parent(&self, slot: usize) -> Option<usize> {
        match self.pairs.get(slot / 2) {
            Some(p) if p.first != NO_PARENT => Some(p.first as usize),
            _ => None,
        }
    }

    fn set_parent(&mut self, pair_slot: usize, parent: usize) {
        if let Some(p) = self.pairs.get_mut(pair_slot / 2) {
            p.first = parent as u32;
        }
    }

    fn height(&self, slot: usize) -> u32 {
        let packed = self.pairs.get(slot / 2).map_or(0, |p| p.count);
        if slot % 2 == 0 {
            packed & 0xffff
        } else {
            packed >> 16
        }
    }

    fn set_height(&mut self, slot: usize, h: u32) {
        if let Some(p) = self.pairs.get_mut(slot / 2) {
            p.count = if slot % 2 == 0 {
                (p.count & !0xffff) | h
            } else {
                (p.count & 0xffff) | (h << 16)
            };
        }
    }

    /// Fills parents and heights. Children always sit after their parent, so a backward
    /// sweep sees both children before the parent.
    fn link(&mut self) {
        for p in self.pairs.iter_mut() {
            *p = Node::EMPTY;
        }
        self.set_parent(0, NO_PARENT as usize);
        for slot in (0..self.nodes.len()).rev() {
            let node = self.node(slot);
            if node.count == 0 && slot != 1 {
                let c = node.first as usize;
                self.set_parent(c, slot);
                let h = 1 + self.height(c).max(self.height(c + 1));
                self.set_height(slot, h);
            }
        }
    }

    /// The tree's cost: the summed area of its inner nodes.
    fn cost(&self) -> f32 {
        let inner = self
            .nodes
            .iter()
            .enumerate()
            .filter(|(slot, n)| n.count == 0 && *slot != 1);
        inner.map(|(_, n)| half_area(&n.bounds())).sum()
    }

    /// The smallest area bucket such that about `wanted` non-root nodes are at least as large.
    /// Buckets count size classes (quarter octaves) below the root's area (no node is
    /// larger); the last one holds everything smaller still.
    fn candidate_threshold(&self, histogram: &mut Histogram, wanted: usize) -> usize {
        *histogram = [0; BUCKETS];
        let top = size_class(half_area(&self.node(0).bounds()));
        for node in self.nodes.iter().skip(FIRST_PAIR) {
            let below = top.saturating_sub(size_class(half_area(&node.bounds())));
            if let Some(h) = histogram.get_mut(below.min(BUCKETS - 1)) {
                *h += 1;
            }
        }
        let mut total = 0usize;
        for (below, &count) in histogram.iter().enumerate() {
            total += count as usize;
            if total >= wanted {
                return top.saturating_sub(below);
            }
        }
        0
    }

    /// Recomputes boxes and heights from `slot` up to the root; returns the summed decrease
    /// of their areas.
    fn refit_from(&mut self, mut slot: Option<usize>) -> f32 {
        let mut shrink = 0.0f32;
        while let Some(s) = slot {
            let node = self.node(s);
            let c = node.first as usize;
            let (a, b) = (self.node(c), self.node(c + 1));
            let bounds = a.bounds().union(&b.bounds());
            shrink += half_area(&node.bounds()) - half_area(&bounds);
            if let Some(n) = self.nodes.get_mut(s) {
                n.lo = bounds.lo;
                n.hi = bounds.hi;
            }
            let h = 1 + self.height(c).max(self.height(c + 1));
            self.set_height(s, h);
            slot = self.parent(s);
        }
        shrink
    }

    /// Puts `moved` (height `h`) next to the node at `x`, using the free pair at `pair`:
    /// `x` becomes their parent. `moved_second` picks the moved node's slot in the pair.
    fn insert(&mut self, x: usize, moved: Node<S>, h: u32, pair: usize, moved_second: bool) {
        let target = self.node(x);
        let hx = self.height(x);
        let (ms, ts) = if moved_second {
            (pair + 1, pair)
        } else {
            (pair, pair + 1)
        };
        for (slot, node, height) in [(ts, target, hx), (ms, moved, h)] {
            if let Some(n) = self.nodes.get_mut(slot) {
                *n = node;
            }
            self.set_height(slot, height);
            if node.count == 0 {
                self.set_parent(node.first as usize, slot);
            }
        }
        self.set_parent(pair, x);
        let bounds = target.bounds().union(&moved.bounds());
        if let Some(n) = self.nodes.get_mut(x) {
            *n = Node {
                lo: bounds.lo,
                first: pair as u32,
                hi: bounds.hi,
                count: 0,
            };
        }
        self.set_height(x, 1 + hx.max(h));
        let up = self.parent(x);
        self.refit_from(up);
    }

    /// Takes the node at `slot` out, finds its cheapest place, and moves it there if that
    /// lowers the cost; otherwise puts it back exactly where it was. Returns the decrease.
    fn try_move(&mut self, slot: usize) -> f32 {
        let Some(p) = self.parent(slot) else {
            return 0.0;
        };
        let moved = self.node(slot);
        let h = self.height(slot);
        let sibling_slot = slot ^ 1;
        let sibling = self.node(sibling_slot);
        let hs = self.height(sibling_slot);
        let parent_area = half_area(&self.node(p).bounds());
        // The sibling takes the parent's place; the pair is free.
        if let Some(n) = self.nodes.get_mut(p) {
            *n = sibling;
        }
        self.set_height(p, hs);
        if sibling.count == 0 {
            self.set_parent(sibling.first as usize, p);
        }
        let up = self.parent(p);
        let gain = parent_area + self.refit_from(up);
        let pair = slot & !1;
        match self.best_place(&moved.bounds(), h) {
            Some((x, cost)) if cost < gain - MIN_GAIN * gain => {
                self.insert(x, moved, h, pair, true);
                gain - cost
            }
            _ => {
                self.insert(p, moved, h, pair, slot % 2 == 1);
                0.0
            }
        }
    }

    /// Moves the pairs into depth-first order (each pair placed when its parent is visited,
    /// as the builder allocates them) and rewrites child links. Consumes the bookkeeping:
    /// `pairs[q].first` becomes pair `q`'s new index, `count` marks it placed.
    fn relayout_pairs(&mut self) {
        let Tree { nodes, pairs } = self;
        for p in pairs.iter_mut() {
            *p = Node::EMPTY;
        }
        let mut next = 1u32;
        walk_mut(nodes, |node| {
            if node.count == 0 {
                if let Some(p) = pairs.get_mut(node.first as usize / 2) {
                    p.first = next;
                }
                next += 1;
            }
        });
        let new_pair = |pairs: &[Node<S>], q: usize| pairs.get(q).map_or(0, |p| p.first as usize);
        for (slot, node) in nodes.iter_mut().enumerate() {
            if node.count == 0 && slot != 1 {
                node.first = (2 * new_pair(pairs, node.first as usize / 2)) as u32;
            }
        }
        // Apply the permutation cycle by cycle. It is a bijection on pairs 1.. (every pair is
        // in use); the step bound only guards termination.
        let count = nodes.len() / 2;
        let pair = |nodes: &[Node<S>], q: usize| {
            let get = |slot| nodes.get(slot).copied().unwrap_or(Node::EMPTY);
            [get(2 * q), get(2 * q + 1)]
        };
        for start in 1..count {
            if pairs.get(start).is_none_or(|p| p.count != 0) {
                continue;
            }
            let mut carry = pair(nodes, start);
            let mut at = new_pair(pairs, start);
            for _ in 0..count {
                if let Some(p) = pairs.get_mut(at) {
                    p.count = 1;
                }
                let here = pair(nodes, at);
                if let Some([a, b]) = nodes.get_mut(2 * at..2 * at + 2) {
                    [*a, *b] = carry;
                }
                if at == start {
                    break;
                }
                carry = here;
                at = new_pair(pairs, at);
            }
        }
    }

    /// Gives the leaves consecutive ranges of `ids` in depth-first order (the builder's
    /// tiling), moving the ids with them. The scratch holds a copy of `ids`, two per slot.
    fn retile_leaves(&mut self, ids: &mut [u32]) {
        let copy = &mut *self.pairs;
        for (slot, two) in copy.iter_mut().zip(ids.chunks(2)) {
            slot.first = two.first().copied().unwrap_or(0);
            slot.count = two.get(1).copied().unwrap_or(0);
        }
        let old_id = |k: usize| {
            copy.get(k / 2)
                .map_or(0, |s| if k % 2 == 0 { s.first } else { s.count })
        };
        let mut next = 0usize;
        walk_mut(self.nodes, |node| {
            if node.count > 0 {
                let (first, count) = (node.first as usize, node.count as usize);
                for (k, slot) in (first..first + count).zip(next..) {
                    if let Some(id) = ids.get_mut(slot) {
                        *id = old_id(k);
                    }
                }
                node.first = next as u32;
                next += count;
            }
        });
    }

    /// Branch and bound over the tree: the slot where inserting a box `b` (of a subtree of
    /// height `h`) adds the least area, and that area. Depth-first with an explicit stack
    /// (each step pushes at most two entries and pops one, so `MAX_DEPTH + 2` suffice).
    fn best_place(&self, b: &Aabb<S>, h: u32) -> Option<(usize, f32)> {
        let own = half_area(b);
        let mut best: Option<(usize, f32)> = None;
        // (slot, induced cost): 8 bytes an entry, as the M0's stack is small; a place's depth
        // is counted along its parent links only when it would become the best.
        let mut stack = [(0u32, 0.0f32); MAX_DEPTH + 2];
        let mut sp = 1usize;
        while sp > 0 {
            sp -= 1;
            let Some(&(x, induced)) = stack.get(sp) else {
                break;
            };
            let bound = induced + own;
            if best.is_some_and(|(_, c)| bound >= c) {
                continue;
            }
            let x = x as usize;
            let node = self.node(x);
            let merged = half_area(&node.bounds().union(b));
            let cost = induced + merged;
            if best.is_none_or(|(_, c)| cost < c)
                && self.depth(x) + 1 + self.height(x).max(h) as usize <= MAX_DEPTH
            {
                best = Some((x, cost));
            }
            if node.count != 0 {
                continue;
            }
            let child_induced = cost - half_area(&node.bounds());
            if best.is_some_and(|(_, c)| child_induced + own >= c) {
                continue;
            }
            // The child whose box grows less is searched first (pushed last).
            let c = node.first as usize;
            let grow = |s: usize| {
                let n = self.node(s).bounds();
                half_area(&n.union(b)) - half_area(&n)
            };
            let order = if grow(c) <= grow(c + 1) {
                [c + 1, c]
            } else {
                [c, c + 1]
            };
            for child in order {
                if let Some(entry) = stack.get_mut(sp) {
                    *entry = (child as u32, child_induced);
                    sp += 1;
                }
            }
        }
        best
    }

    /// Depth of `slot` (the root is 0), counted along parent links; at most [`MAX_DEPTH`]
    /// steps are taken.
    fn depth(&self, slot: usize) -> usize {
        let mut at = slot;
        for d in 0..=MAX_DEPTH {
            match self.parent(at) {
                Some(p) => at = p,
                None => return d,
            }
        }
        MAX_DEPTH + 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::bvh::{build::build, BuildOptions, BuilderKind};
    use crate::geom::Triangle;

    /// A tree whose deepest leaf sits far down a chain (triangles at exponentially shrinking
    /// offsets, split at the midpoint). The cheapest place for that leaf's box is down there;
    /// with a subtree tall enough to pass [`MAX_DEPTH`] from that place, the search must choose
    /// one that keeps within the cap.
    #[test]
    fn best_place_keeps_within_the_depth_cap() {
        const N: usize = 300;
        let tris: [Triangle<f32>; N] = core::array::from_fn(|i| {
            let (axis, j) = (i % 3, (i / 3) as i32);
            let mut a = [0.0f32; 3];
            a[axis] = if j < 60 {
                libm::exp2f(20.0 - j as f32)
            } else {
                0.0
            };
            let (mut b, mut c) = (a, a);
            b[(axis + 1) % 3] = 1.0;
            c[(axis + 2) % 3] = 1.0;
            Triangle::from_f32([a, b, c]).unwrap_or_else(|_| unreachable!())
        });
        let mut nodes = [Node::<f32>::EMPTY; 2 * N];
        let mut ids = [0u32; N];
        let options = BuildOptions {
            builder: BuilderKind::Midpoint,
            max_leaf_size: 4,
            reinsertion: false,
        };
        let (used, depth) = build(&tris, &mut nodes, &mut ids, options).unwrap();
        assert!(depth >= 32, "chain too short: depth {depth}");
        let (tree, rest) = nodes.split_at_mut(used);
        let mut t = Tree {
            nodes: tree,
            pairs: &mut rest[..used / 2],
        };
        t.link();
        let deepest = (0..used)
            .filter(|&s| s != 1 && t.node(s).count > 0)
            .max_by_key(|&s| t.depth(s))
            .unwrap();
        assert_eq!(t.depth(deepest) as u32, depth);
        let tiny = t.node(deepest).bounds();
        // Unconstrained, some place near that leaf wins; a subtree of height `h` there would
        // put leaves at MAX_DEPTH + 1.
        let (free, _) = t.best_place(&tiny, 0).unwrap();
        let h = (MAX_DEPTH - t.depth(free)) as u32;
        let (x, _) = t.best_place(&tiny, h).unwrap();
        let dx = t.depth(x);
        assert!(
            dx + 1 + t.height(x).max(h) as usize <= MAX_DEPTH,
            "placed at depth {dx}, height {} with a subtree of height {h}",
            t.height(x)
        );
    }
}
