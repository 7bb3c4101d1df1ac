use crate::geom::Aabb;
use crate::scalar::lanes::F4;
use crate::scalar::Scalar;

/// `count` of an unused child slot.
pub(crate) const EMPTY_SLOT: u32 = u32::MAX;

/// One of a [`Node4`]'s four child slots, as [`Node4::slot`] reads it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ChildSlot {
    /// Node index (inner child) or first primitive-id slot (leaf).
    pub child: u32,
    /// 0 for an inner child, the primitive count for a leaf, `u32::MAX` unused.
    pub count: u32,
}

/// One 4-wide BVH node: the boxes of up to four children in structure-of-arrays form, so one
/// vector instruction tests an axis of all four. 128 bytes in both modes, aligned to 128: two
/// cache lines that x86's adjacent-line prefetcher fetches together.
///
/// Layout: `lo[axis][slot]`, `hi[axis][slot]` (96 bytes for `f32` and `I16F16`), then
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
pub struct Node4<S: Scalar> {
    pub(crate) lo: [[S; 4]; 3],
    pub(crate) hi: [[S; 4]; 3],
    pub(crate) child: [u32; 4],
    pub(crate) count: [u32; 4],
}

const _: () = assert!(core::mem::size_of::<Node4<f32>>() == 128);
const _: () = assert!(core::mem::size_of::<Node4<crate::I16F16>>() == 128);

impl<S: Scalar> Node4<S> {
    /// A placeholder to fill arenas with, e.g. `[Node4::EMPTY; nodes4_needed(N)]`.
    pub const EMPTY: Self = Self {
        lo: [[S::ZERO; 4]; 3],
        hi: [[S::ZERO; 4]; 3],
        child: [0; 4],
        count: [EMPTY_SLOT; 4],
    };

    /// Bit `i` set if slot `i` is used: the sign bits of `count` (a used slot's count is at
    /// most [`crate::bvh::MAX_LEAF_SIZE`], [`EMPTY_SLOT`] has its top bit set), inverted; one
    /// vector move-mask where `F4` has SSE.
    #[inline(always)]
    pub(crate) fn used_mask(&self) -> u32 {
        !F4::new(self.count.map(f32::from_bits)).sign_mask() & 0b1111
    }

    /// Sets slot `i` (0..4; others are ignored).
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

    /// Slots in use (leading slots; at most 4).
    #[must_use]
    pub fn child_count(&self) -> usize {
        self.count.iter().take_while(|&&c| c != EMPTY_SLOT).count()
    }
    /// Box of slot `i`, if `i < 4`.
    #[must_use]
    pub fn bounds(&self, i: usize) -> Option<Aabb<S>> {
        let i = (i < 4).then_some(i)?;
        let lo = [self.lo[0].get(i), self.lo[1].get(i), self.lo[2].get(i)];
        let hi = [self.hi[0].get(i), self.hi[1].get(i), self.hi[2].get(i)];
        let g = |x: Option<&S>| x.copied().unwrap_or(S::ZERO);
        Some(Aabb::new(lo.map(g), hi.map(g)))
    }
    /// Slot `i`, if `i < 4`.
    #[must_use]
    pub fn slot(&self, i: usize) -> Option<ChildSlot> {
        Some(ChildSlot {
            child: *self.child.get(i)?,
            count: *self.count.get(i)?,
        })
    }
}
