//! Stack-based traversal of the 8-wide tree, nearest child first (any hit: the first hit child
//! in slot order, below). One routine serves closest hit and any hit. The eight boxes of a node
//! are tested in two 4-lane halves (`Numerics::slab8`), or in the 256-bit lanes of one AVX2
//! vector (`Numerics::slab8_avx2`) where the CPU has it: the same bits either way.

#[cfg(target_arch = "x86_64")]
use super::order::{slot_of, sorted8_avx2};
use super::traverse::{first_in_slot_order, pop_in_reach, Entry, Walk};
use super::Bvh8;
use crate::accel::bvh::{test_leaf, MAX_DEPTH};
use crate::accel::Counters;
use crate::geom::{Primitive, Ray};
use crate::scalar::Scalar;

/// Traversal stack capacity.
///
/// Bound: as for the 4-wide tree (`traverse.rs`), wide nodes sit at depths
/// `0..=MAX_DEPTH - 1`, and visiting one pushes its hit children but the nearest: at most 7.
/// So the stack holds at most `7·d` entries on entering a node at depth `d`, and at most
/// `7·d + 7 <= 7·MAX_DEPTH` after it has pushed.
const STACK: usize = 7 * MAX_DEPTH;

impl<S: Scalar, P: Primitive<S>> Walk<S> for Bvh8<'_, S, P> {
    /// Runs the copy of [`Bvh8::walk8`] that [`crate::cpu`] selects.
    #[inline(always)]
    fn traverse<const ANY: bool, const COHERENT: bool, C: Counters>(
        &self,
        ray: &Ray<S>,
        stats: &mut C,
    ) -> (S, u32, usize) {
        #[cfg(all(target_arch = "x86_64", not(target_feature = "avx2")))]
        if crate::cpu::avx2() {
            #[allow(unsafe_code)]
            // SAFETY: `cpu::avx2` is true only on a CPU with every feature `walk8_avx2` enables.
            return unsafe { self.walk8_avx2::<ANY, COHERENT, C>(ray, stats) };
        }
        self.walk8_baseline::<ANY, COHERENT, C>(ray, stats)
    }
}

/// `(child, count)` of slot `$slot` of `$node`, reached by a branch per slot (a jump over the
/// slot number), not by an index computed from it: the branch predictor can then fetch the next
/// node before the slot number is known, where an index would wait for it. (A macro, not a
/// closure: closures compile to the index.)
macro_rules! by_branch {
    ($node:expr, $slot:expr) => {
        match $slot {
            0 => ($node.child[0], $node.count[0]),
            1 => ($node.child[1], $node.count[1]),
            2 => ($node.child[2], $node.count[2]),
            3 => ($node.child[3], $node.count[3]),
            4 => ($node.child[4], $node.count[4]),
            5 => ($node.child[5], $node.count[5]),
            6 => ($node.child[6], $node.count[6]),
            _ => ($node.child[7], $node.count[7]),
        }
    };
}

impl<S: Scalar, P: Primitive<S>> Bvh8<'_, S, P> {
    /// [`Bvh8::walk8`] as compiled for the target (in 256-bit lanes if the target has AVX2).
    #[inline(never)]
    fn walk8_baseline<const ANY: bool, const COHERENT: bool, C: Counters>(
        &self,
        ray: &Ray<S>,
        stats: &mut C,
    ) -> (S, u32, usize) {
        const AVX: bool = cfg!(all(target_arch = "x86_64", target_feature = "avx2"));
        self.walk8::<ANY, COHERENT, C, AVX>(ray, stats)
    }

    /// [`Bvh8::walk8`] compiled for AVX2, its box tests in 256-bit lanes (see [`crate::cpu`]).
    ///
    /// # Safety
    /// The CPU must have every feature enabled here (`cpu::avx2` checks).
    #[cfg(all(target_arch = "x86_64", not(target_feature = "avx2")))]
    #[allow(unsafe_code)]
    #[target_feature(enable = "avx,avx2,bmi1,bmi2,lzcnt,popcnt")]
    unsafe fn walk8_avx2<const ANY: bool, const COHERENT: bool, C: Counters>(
        &self,
        ray: &Ray<S>,
        stats: &mut C,
    ) -> (S, u32, usize) {
        self.walk8::<ANY, COHERENT, C, true>(ray, stats)
    }

    /// The traversal itself, inlined into each compiled copy. `COHERENT`: the walk for
    /// coherent rays (see [`crate::Coherent`]). `AVX`: test the boxes with
    /// `Numerics::slab8_avx2`; set only in copies that run on a CPU with AVX2.
    #[inline(always)]
    fn walk8<const ANY: bool, const COHERENT: bool, C: Counters, const AVX: bool>(
        &self,
        ray: &Ray<S>,
        stats: &mut C,
    ) -> (S, u32, usize) {
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
                    #[cfg(target_arch = "x86_64")]
                    let (hit, t) = if AVX {
                        #[allow(unsafe_code)]
                        // SAFETY: `AVX` is set only in copies that run on a CPU with AVX2.
                        unsafe {
                            S::slab8_avx2(rd, &node.lo, &node.hi, t_min, best.0)
                        }
                    } else {
                        S::slab8(rd, &node.lo, &node.hi, t_min, best.0)
                    };
                    #[cfg(not(target_arch = "x86_64"))]
                    let (hit, t) = S::slab8(rd, &node.lo, &node.hi, t_min, best.0);
                    let hit = hit & used;
                    let slot = |i: u32| {
                        let i = i as usize % 8;
                        (node.child[i], node.count[i], t[i])
                    };
                    // None hit: fall through to the pop below.
                    if hit != 0 {
                        let others = hit & (hit - 1);
                        if others == 0 {
                            // One child hit (the common case deep in the tree): go there. A
                            // branch per slot, not an index computed from the mask: the branch
                            // predictor can then fetch the next node before this box test has
                            // finished, where an index would wait for it (as in `traverse.rs`).
                            (child, count) = match hit {
                                1 => (node.child[0], node.count[0]),
                                2 => (node.child[1], node.count[1]),
                                4 => (node.child[2], node.count[2]),
                                8 => (node.child[3], node.count[3]),
                                16 => (node.child[4], node.count[4]),
                                32 => (node.child[5], node.count[5]),
                                64 => (node.child[6], node.count[6]),
                                _ => (node.child[7], node.count[7]),
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
                            if COHERENT {
                                // A jump over the 28 pairs, both children loaded from known
                                // slots: predicted well when successive rays hit the same
                                // pairs, mispredicted on incoherent rays.
                                let pair = |i: usize, j: usize| {
                                    let (a, b) = (slot(i as u32), slot(j as u32));
                                    if b.2 < a.2 {
                                        (b, a)
                                    } else {
                                        (a, b)
                                    }
                                };
                                let (near, far) = match hit {
                                    0b00000011 => pair(0, 1),
                                    0b00000101 => pair(0, 2),
                                    0b00001001 => pair(0, 3),
                                    0b00010001 => pair(0, 4),
                                    0b00100001 => pair(0, 5),
                                    0b01000001 => pair(0, 6),
                                    0b10000001 => pair(0, 7),
                                    0b00000110 => pair(1, 2),
                                    0b00001010 => pair(1, 3),
                                    0b00010010 => pair(1, 4),
                                    0b00100010 => pair(1, 5),
                                    0b01000010 => pair(1, 6),
                                    0b10000010 => pair(1, 7),
                                    0b00001100 => pair(2, 3),
                                    0b00010100 => pair(2, 4),
                                    0b00100100 => pair(2, 5),
                                    0b01000100 => pair(2, 6),
                                    0b10000100 => pair(2, 7),
                                    0b00011000 => pair(3, 4),
                                    0b00101000 => pair(3, 5),
                                    0b01001000 => pair(3, 6),
                                    0b10001000 => pair(3, 7),
                                    0b00110000 => pair(4, 5),
                                    0b01010000 => pair(4, 6),
                                    0b10010000 => pair(4, 7),
                                    0b01100000 => pair(5, 6),
                                    0b10100000 => pair(5, 7),
                                    _ => pair(6, 7),
                                };
                                let _ = stack.push(far);
                                (child, count) = (near.0, near.1);
                                continue 'walk;
                            }
                            // The nearer reached by branch again (a jump over its slot), which
                            // incoherent rays mispredict less often than a jump over the pairs.
                            let (i, j) = (hit.trailing_zeros(), others.trailing_zeros());
                            let (near, far) = if t[j as usize % 8] < t[i as usize % 8] {
                                (j, i)
                            } else {
                                (i, j)
                            };
                            let _ = stack.push(slot(far));
                            (child, count) = by_branch!(node, near);
                            continue 'walk;
                        }
                        // Three or more: nearest-first order, then the farthest pushed first.
                        // By insertion (the first of equals first), except in the default
                        // walk's AVX2 copy, which sorts in lanes (`order.rs`: no branch on the
                        // distances; in the coherent walk it was slower).
                        if COHERENT {
                            // Slot numbers sorted, the farther children pushed by index and
                            // the nearest reached by branch, as for one and two hits. (Both
                            // sorts written out: one generic insertion for both, or slot
                            // numbers sorted in the default walk too, measured slower.)
                            let mut e: [(u32, S); 8] = [(0, t_min); 8];
                            let mut n = 0usize;
                            let mut rest = hit;
                            while rest != 0 {
                                let i = rest.trailing_zeros();
                                let x = (i, t[i as usize % 8]);
                                rest &= rest - 1;
                                let mut m = n;
                                while m > 0 && x.1 < e[(m - 1) % 8].1 {
                                    e[m % 8] = e[(m - 1) % 8];
                                    m -= 1;
                                }
                                e[m % 8] = x;
                                n += 1;
                            }
                            for &(far, _) in e.get(1..n).unwrap_or_default().iter().rev() {
                                let _ = stack.push(slot(far));
                            }
                            (child, count) = by_branch!(node, e[0].0);
                            continue 'walk;
                        }
                        #[cfg(target_arch = "x86_64")]
                        if AVX {
                            #[allow(unsafe_code)]
                            // SAFETY: `AVX` is set only in copies that run on a CPU with AVX2.
                            let keys = unsafe { sorted8_avx2(&t.map(S::order_bits), hit) };
                            let n = hit.count_ones() as usize;
                            for &far in keys.get(1..n).unwrap_or_default().iter().rev() {
                                let _ = stack.push(slot(slot_of(far)));
                            }
                            (child, count) = by_branch!(node, slot_of(keys[0]));
                            continue 'walk;
                        }
                        let mut e: [Entry<S>; 8] = [(0, 0, t_min); 8];
                        let mut n = 0usize;
                        let mut rest = hit;
                        while rest != 0 {
                            let x = slot(rest.trailing_zeros());
                            rest &= rest - 1;
                            let mut m = n;
                            while m > 0 && x.2 < e[(m - 1) % 8].2 {
                                e[m % 8] = e[(m - 1) % 8];
                                m -= 1;
                            }
                            e[m % 8] = x;
                            n += 1;
                        }
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
