//! Stack-based traversal of the 4-wide tree, nearest child first (any hit: the first hit child
//! in slot order; see `traverse8.rs`). One routine serves closest hit and any hit. The query
//! API of every wide tree is here too; `traverse8.rs` walks the 8-wide one.

use super::{Bvh4, WideBvh};
use crate::accel::bvh::{test_leaf, LeafPrims, MAX_DEPTH};
use crate::accel::{Accel, Counters, Nearest};
use crate::geom::{Barycentrics, Primitive, Ray};
use crate::scalar::Scalar;

/// Traversal stack capacity.
///
/// Bound: a wide node at depth `d` (root 0) stems from a BVH2 inner node at depth `>= d`
/// (each wide level descends at least one BVH2 level), and BVH2 leaves are at most
/// [`MAX_DEPTH`] deep, so BVH2 inner nodes and hence wide nodes sit at depths
/// `0..=MAX_DEPTH - 1`. Visiting a node pushes its hit children but the nearest: at most 3.
/// While the walk is inside the subtree of a node's child, the stack holds at most 3 entries
/// per ancestor of that child (their children not yet visited), so at most `3·d` on entering
/// a node at depth `d`, and at most `3·d + 3 <= 3·MAX_DEPTH` after it has pushed.
const STACK: usize = 3 * MAX_DEPTH;

/// A child to visit: `(child, count)` as in a [`super::WideNode`]'s slots (count 0: the node
/// `child`; otherwise the leaf `prim_ids[child..child + count]`), and its entry distance.
pub(super) type Entry<S> = (u32, u32, S);

/// Compare-exchange: `e[i]` before `e[j]` unless `e[j]` is strictly nearer.
#[inline(always)]
fn cmpx<S: Scalar>(e: &mut [Entry<S>; 4], i: usize, j: usize) {
    let (a, b) = (e[i & 3], e[j & 3]);
    if b.2 < a.2 {
        e[i & 3] = b;
        e[j & 3] = a;
    }
}

/// Sorts the first `n` entries by entry distance (sorting networks for 2, 3 and 4).
#[inline(always)]
fn sort_nearest_first<S: Scalar>(e: &mut [Entry<S>; 4], n: usize) {
    match n {
        2 => cmpx(e, 0, 1),
        3 => {
            cmpx(e, 0, 1);
            cmpx(e, 1, 2);
            cmpx(e, 0, 1);
        }
        4 => {
            cmpx(e, 0, 1);
            cmpx(e, 2, 3);
            cmpx(e, 0, 2);
            cmpx(e, 1, 3);
            cmpx(e, 1, 2);
        }
        _ => {}
    }
}

/// A wide tree's walk, written per width.
pub(super) trait Walk<S: Scalar> {
    /// Walks the tree. With `ANY`, returns at the first hit in range; otherwise finds the
    /// closest under [`closer`]. `COHERENT`: the walk for coherent rays where the width has
    /// one ([`crate::Coherent`]). Returns (t, prim id, index into `prims`) of the hit;
    /// `prim id == u32::MAX` for none.
    fn traverse<const ANY: bool, const COHERENT: bool, C: Counters>(
        &self,
        ray: &Ray<S>,
        stats: &mut C,
    ) -> (S, u32, usize);
}

impl<S: Scalar, P: Primitive<S>> Walk<S> for Bvh4<'_, S, P> {
    /// Runs the copy of [`Bvh4::walk`] that [`crate::cpu`] selects. One walk serves both kinds
    /// of rays: it already reaches the nearer of two hit children by a jump over the pairs.
    #[inline(always)]
    fn traverse<const ANY: bool, const COHERENT: bool, C: Counters>(
        &self,
        ray: &Ray<S>,
        stats: &mut C,
    ) -> (S, u32, usize) {
        #[cfg(all(target_arch = "x86_64", not(target_feature = "avx2")))]
        if crate::cpu::avx2() {
            #[allow(unsafe_code)]
            // SAFETY: `cpu::avx2` is true only on a CPU with every feature `walk_avx2` enables.
            return unsafe { self.walk_avx2::<ANY, C>(ray, stats) };
        }
        self.walk_baseline::<ANY, C>(ray, stats)
    }
}

impl<S: Scalar, P: Primitive<S>> Bvh4<'_, S, P> {
    /// [`Bvh4::walk`] as compiled for the target.
    #[inline(never)]
    fn walk_baseline<const ANY: bool, C: Counters>(
        &self,
        ray: &Ray<S>,
        stats: &mut C,
    ) -> (S, u32, usize) {
        self.walk::<ANY, C>(ray, stats)
    }

    /// [`Bvh4::walk`] compiled for AVX2 (see [`crate::cpu`]).
    ///
    /// # Safety
    /// The CPU must have every feature enabled here (`cpu::avx2` checks).
    #[cfg(all(target_arch = "x86_64", not(target_feature = "avx2")))]
    #[allow(unsafe_code)]
    #[target_feature(enable = "avx,avx2,bmi1,bmi2,lzcnt,popcnt")]
    unsafe fn walk_avx2<const ANY: bool, C: Counters>(
        &self,
        ray: &Ray<S>,
        stats: &mut C,
    ) -> (S, u32, usize) {
        self.walk::<ANY, C>(ray, stats)
    }

    /// The traversal itself, inlined into each compiled copy.
    #[inline(always)]
    fn walk<const ANY: bool, C: Counters>(&self, ray: &Ray<S>, stats: &mut C) -> (S, u32, usize) {
        let rd = ray.data();
        let t_min = ray.t_min();
        // (t, prim id, index into `prims`) of the best hit so far.
        let mut best = (ray.t_max(), u32::MAX, 0usize);
        if self.nodes.is_empty() {
            return best;
        }
        // Cannot overflow (see `STACK`); a failed push would only skip a child.
        let mut stack: heapless::Vec<Entry<S>, STACK> = heapless::Vec::new();
        // The root's own box is not stored: its children's boxes are tested instead.
        let (mut child, mut count) = (0u32, 0u32);
        'walk: loop {
            if count == 0 {
                if let Some(node) = self.nodes.get(child as usize) {
                    let used = node.used_mask();
                    for _ in 0..used.count_ones() {
                        stats.node();
                    }
                    let (hit, t) = S::slab4(rd, &node.lo, &node.hi, t_min, best.0);
                    let hit = hit & used;
                    let slot = |i: u32| {
                        let i = i as usize & 3;
                        (node.child[i], node.count[i], t[i])
                    };
                    // None hit: fall through to the pop below.
                    if hit != 0 {
                        let others = hit & (hit - 1);
                        if others == 0 {
                            // One child hit (the common case deep in the tree): go there.
                            // A branch per slot, not an index computed from the mask: the
                            // branch predictor can then fetch the next node before this box
                            // test has finished, where an index would wait for it.
                            (child, count) = match hit {
                                1 => (node.child[0], node.count[0]),
                                2 => (node.child[1], node.count[1]),
                                4 => (node.child[2], node.count[2]),
                                _ => (node.child[3], node.count[3]),
                            };
                            continue 'walk;
                        }
                        if ANY {
                            // Any hit: no ordering.
                            (child, count) = first_in_slot_order(&mut stack, hit, slot);
                            continue 'walk;
                        }
                        if others & (others - 1) == 0 {
                            // Two: visit the nearer (the first on a tie), push the other.
                            // Slots by branch again (see above).
                            let pair = |i: u32, j: u32| {
                                let (a, b) = (slot(i), slot(j));
                                if b.2 < a.2 {
                                    (b, a)
                                } else {
                                    (a, b)
                                }
                            };
                            let (near, far) = match hit {
                                0b0011 => pair(0, 1),
                                0b0101 => pair(0, 2),
                                0b1001 => pair(0, 3),
                                0b0110 => pair(1, 2),
                                0b1010 => pair(1, 3),
                                _ => pair(2, 3),
                            };
                            let _ = stack.push(far);
                            (child, count) = (near.0, near.1);
                            continue 'walk;
                        }
                        // Three or four: the hit children compacted, then nearest first.
                        let mut e: [Entry<S>; 4] = [(0, 0, t_min); 4];
                        let mut n = 0usize;
                        let mut rest = hit;
                        while rest != 0 {
                            e[n & 3] = slot(rest.trailing_zeros());
                            rest &= rest - 1;
                            n += 1;
                        }
                        sort_nearest_first(&mut e, n);
                        if let Some((&(c, k, _), rest)) = e.get(..n).and_then(<[_]>::split_first) {
                            for &far in rest.iter().rev() {
                                let _ = stack.push(far);
                            }
                            (child, count) = (c, k);
                            continue 'walk;
                        }
                    }
                }
            } else {
                let leaf = (child as usize, count as usize);
                if test_leaf(self.leaf(), leaf, rd, t_min, &mut best, stats, ANY) {
                    return best;
                }
            }
            match pop_in_reach(&mut stack, best.0) {
                Some(next) => (child, count) = next,
                None => break 'walk,
            }
        }
        best
    }
}

/// Any hit's visit order: the hit children in slot order, not by distance (whether something
/// is hit does not depend on the order). Pushes every child in `hit` (not empty) but the first
/// and returns the first's `(child, count)`; `slot(i)` is slot `i`'s entry.
#[inline(always)]
pub(super) fn first_in_slot_order<S: Scalar, const N: usize>(
    stack: &mut heapless::Vec<Entry<S>, N>,
    hit: u32,
    slot: impl Fn(u32) -> Entry<S>,
) -> (u32, u32) {
    let mut rest = hit & hit.wrapping_sub(1);
    while rest != 0 {
        let _ = stack.push(slot(rest.trailing_zeros()));
        rest &= rest - 1;
    }
    let (child, count, _) = slot(hit.trailing_zeros());
    (child, count)
}

/// Pops entries until one is still in reach of the best hit so far (entered by
/// `widen(best_t)`): its `(child, count)`; `None` once the stack is empty.
#[inline(always)]
pub(super) fn pop_in_reach<S: Scalar, const N: usize>(
    stack: &mut heapless::Vec<Entry<S>, N>,
    best_t: S,
) -> Option<(u32, u32)> {
    while let Some((child, count, t_near)) = stack.pop() {
        if t_near <= S::widen(best_t) {
            return Some((child, count));
        }
    }
    None
}

impl<S: Scalar, P: Primitive<S>, const W: usize> WideBvh<'_, S, P, W> {
    /// What [`test_leaf`] reads (see `Bvh::leaf`).
    #[inline(always)]
    pub(super) fn leaf(&self) -> LeafPrims<'_, P> {
        (self.prim_ids, self.prims, self.leaf_order)
    }
}

impl<S: Scalar, P: Primitive<S>, const W: usize> Accel<S> for WideBvh<'_, S, P, W>
where
    Self: Walk<S>,
{
    #[inline]
    fn nearest_counted<C: Counters>(&self, ray: &Ray<S>, stats: &mut C) -> Option<Nearest<S>> {
        let (t, prim, slot) = self.traverse::<false, false, C>(ray, stats);
        Nearest::found(t, prim, slot)
    }

    fn barycentrics(&self, ray: &Ray<S>, found: &Nearest<S>) -> Barycentrics<S> {
        found.barycentrics_in(self.prims, ray)
    }

    #[inline]
    fn occluded_counted<C: Counters>(&self, ray: &Ray<S>, stats: &mut C) -> bool {
        self.traverse::<true, false, C>(ray, stats).1 != u32::MAX
    }

    #[inline]
    fn nearest_coherent_counted<C: Counters>(
        &self,
        ray: &Ray<S>,
        stats: &mut C,
    ) -> Option<Nearest<S>> {
        let (t, prim, slot) = self.traverse::<false, true, C>(ray, stats);
        Nearest::found(t, prim, slot)
    }

    #[inline]
    fn occluded_coherent_counted<C: Counters>(&self, ray: &Ray<S>, stats: &mut C) -> bool {
        self.traverse::<true, true, C>(ray, stats).1 != u32::MAX
    }
}
