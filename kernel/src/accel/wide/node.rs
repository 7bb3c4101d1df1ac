use crate::geom::Aabb;
use crate::scalar::lanes::F4;
use crate::scalar::Scalar;

/// `count` of an unused child slot.
pub(crate) const EMPTY_SLOT: u32 = u32::MAX;

/// One of a [`WideNode`]'s child slots, as [`WideNode::slot`] reads it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ChildSlot {
    /// Node index (inner child) or first primitive-id slot (leaf).
    pub child: u32,
    /// 0 for an inner child, the primitive count for a leaf, `u32::MAX` unused.
    pub count: u32,
}

/// One wide BVH node of `W` child slots (`W` = 4 or 8): the boxes of its children in
/// structure-of-arrays form, so one vector instruction tests an axis of four (or eight) at
/// once. `32·W` bytes in both modes (128 for [`Node4`], 256 for [`Node8`]), aligned to 128:
/// whole pairs of cache lines, which x86's adjacent-line prefetcher fetches together.
///
/// Layout: `lo[axis][slot]`, `hi[axis][slot]` (`24·W` bytes for `f32` and `I16F16`), then
/// `child[slot]` and `count[slot]`.
///
/// Invariants, per slot `i`:
/// - `count[i] == 0`: an inner child, the node `child[i]`, always at a higher index than this
///   node;
/// - `1 <= count[i] <=` [`crate::bvh::MAX_LEAF_SIZE`]: a leaf covering
///   `prim_ids[child[i]..child[i] + count[i]]`;
/// - `count[i] == u32::MAX`: an unused slot. Unused slots come after the used ones. Their
///   boxes are inverted (`lo = +inf`, `hi = -inf` in `f32`; largest and smallest value in fixed
///   point), but
///   traversal does **not** rely on the box test rejecting them: the slab test's `min`/`max`
///   turns an inverted box into an unbounded slab, and under IEEE infinities no box at all is
///   missed by every ray, so unused slots are masked out by their `count`.
///
/// Every node has at least two used slots, except a root whose only child is a leaf (a tree
/// over one leaf). Boxes are the BVH2's node boxes, bit for bit (already padded by
/// `Numerics::pad_bounds`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(128))]
pub struct WideNode<S: Scalar, const W: usize> {
    pub(crate) lo: [[S; W]; 3],
    pub(crate) hi: [[S; W]; 3],
    pub(crate) child: [u32; W],
    pub(crate) count: [u32; W],
}

/// A node of the 4-wide BVH, [`crate::Bvh4`].
pub type Node4<S> = WideNode<S, 4>;
/// A node of the 8-wide BVH, [`crate::Bvh8`].
pub type Node8<S> = WideNode<S, 8>;

const _: () = assert!(core::mem::size_of::<Node4<f32>>() == 128);
const _: () = assert!(core::mem::size_of::<Node4<crate::I16F16>>() == 128);
const _: () = assert!(core::mem::size_of::<Node8<f32>>() == 256);
const _: () = assert!(core::mem::size_of::<Node8<crate::I16F16>>() == 256);

impl<S: Scalar, const W: usize> WideNode<S, W> {
    /// A placeholder to fill arenas with, e.g. `[Node4::EMPTY; nodes4_needed(N)]`. Only the
    /// widths there are walks for, 4 and 8, compile:
    ///
    /// ```compile_fail
    /// let _ = raykernel::WideNode::<f32, 2>::EMPTY;
    /// ```
    pub const EMPTY: Self = Self {
        lo: {
            assert!(W == 4 || W == 8, "wide BVH nodes have 4 or 8 slots");
            [[S::ZERO; W]; 3]
        },
        hi: [[S::ZERO; W]; 3],
        child: [0; W],
        count: [EMPTY_SLOT; W],
    };

    /// Bit `i` set if slot `i` is used: the sign bits of `count` (a used slot's count is at
    /// most [`crate::bvh::MAX_LEAF_SIZE`], [`EMPTY_SLOT`] has its top bit set), inverted; one
    /// vector move-mask per four slots where `F4` has SSE.
    #[inline(always)]
    pub(crate) fn used_mask(&self) -> u32 {
        let mut signs = 0u32;
        for (quad, counts) in self.count.chunks_exact(4).enumerate() {
            let lanes = [0, 1, 2, 3].map(|i| counts.get(i).map_or(0.0, |&c| f32::from_bits(c)));
            signs |= F4::new(lanes).sign_mask() << (4 * quad);
        }
        !signs & ((1 << W) - 1)
    }

    /// Sets slot `i` (`0..W`; others are ignored).
    pub(crate) fn set(&mut self, i: usize, b: &Aabb<S>, child: u32, count: u32) {
        for axis in 0..3 {
            if let (Some(lo), Some(hi)) = (self.lo[axis].get_mut(i), self.hi[axis].get_mut(i)) {
                *lo = b.lo[axis];
                *hi = b.hi[axis];
            }
        }
        if let (Some(c), Some(n)) = (self.child.get_mut(i), self.count.get_mut(i)) {
            *c = child;
            *n = count;
        }
    }

    /// Marks slot `i` unused, with an inverted box.
    pub(crate) fn clear(&mut self, i: usize) {
        let low = S::from_f32_saturating(f32::NEG_INFINITY);
        let inverted = Aabb::new([S::FAR; 3], [low; 3]);
        self.set(i, &inverted, 0, EMPTY_SLOT);
    }

    /// Slots in use (leading slots; at most `W`).
    #[must_use]
    pub fn child_count(&self) -> usize {
        self.count.iter().take_while(|&&c| c != EMPTY_SLOT).count()
    }
    /// Box of slot `i`, if `i < W`.
    #[must_use]
    pub fn bounds(&self, i: usize) -> Option<Aabb<S>> {
        let i = (i < W).then_some(i)?;
        let lo = [self.lo[0].get(i), self.lo[1].get(i), self.lo[2].get(i)];
        let hi = [self.hi[0].get(i), self.hi[1].get(i), self.hi[2].get(i)];
        let g = |x: Option<&S>| x.copied().unwrap_or(S::ZERO);
        Some(Aabb::new(lo.map(g), hi.map(g)))
    }
    /// Slot `i`, if `i < W`.
    #[must_use]
    pub fn slot(&self, i: usize) -> Option<ChildSlot> {
        Some(ChildSlot {
            child: *self.child.get(i)?,
            count: *self.count.get(i)?,
        })
    }
}
