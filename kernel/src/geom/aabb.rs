use super::Ray;
use crate::scalar::Scalar;

/// An axis-aligned box, `lo <= hi` per axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb<S: Scalar> {
    /// Lower corner.
    pub lo: [S; 3],
    /// Upper corner.
    pub hi: [S; 3],
}

impl<S: Scalar> Aabb<S> {
    /// A box from its corners.
    pub const fn new(lo: [S; 3], hi: [S; 3]) -> Self {
        Self { lo, hi }
    }

    /// The smallest box holding both.
    #[must_use]
    pub fn union(&self, o: &Self) -> Self {
        let mut r = *self;
        for i in 0..3 {
            r.lo[i] = r.lo[i].min_of(o.lo[i]);
            r.hi[i] = r.hi[i].max_of(o.hi[i]);
        }
        r
    }

    /// True if `o` lies inside `self` (boundaries included).
    #[must_use]
    pub fn contains(&self, o: &Self) -> bool {
        corners_contain((&self.lo, &self.hi), (&o.lo, &o.hi))
    }

    /// Conservative slab test: the entry distance if the ray's interval meets the box.
    ///
    /// Boundaries are inclusive: a ray lying in a face, along an edge, or starting on the box
    /// hits it. The test is conservative (it may accept a box the ray passes within a relative
    /// margin of about 2e-6 of the coordinates, never the reverse), so the entry distance is a
    /// lower bound, not exact.
    #[must_use]
    pub fn slab(&self, ray: &Ray<S>) -> Option<S> {
        S::slab(ray.data(), &self.lo, &self.hi, ray.t_min(), ray.t_max())
    }
}

/// [`Aabb::contains`] on corners where they are stored (a node's, say), so no box is copied to
/// ask: true if the box `inner_lo..inner_hi` lies inside `lo..hi`, boundaries included.
/// Bare-metal targets keep one copy (flash: the tree checks call it from two places).
#[cfg_attr(target_os = "none", inline(never))]
pub(crate) fn corners_contain<S: Scalar>(
    (lo, hi): (&[S; 3], &[S; 3]),
    (inner_lo, inner_hi): (&[S; 3], &[S; 3]),
) -> bool {
    (0..3).all(|i| lo[i] <= inner_lo[i] && inner_hi[i] <= hi[i])
}
