use crate::scalar::Scalar;

/// A closest hit: distance, primitive id and barycentrics.
///
/// For triangles `(u, v)` are the weights of the second and third vertex
/// (hit = `(1-u-v)·v0 + u·v1 + v·v2`); for spheres both are zero.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit<S: Scalar> {
    /// Distance along the unit direction.
    pub t: S,
    /// Index of the primitive in the slice the accelerator was built over.
    pub prim: u32,
    /// Weight of the second vertex.
    pub u: S,
    /// Weight of the third vertex.
    pub v: S,
}

/// Barycentrics of a point on a triangle: the weights `u` of the second and `v` of the third
/// vertex (point = `(1-u-v)·v0 + u·v1 + v·v2`). Both zero for primitives without them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Barycentrics<S: Scalar> {
    /// Weight of the second vertex.
    pub u: S,
    /// Weight of the third vertex.
    pub v: S,
}

impl<S: Scalar> Barycentrics<S> {
    /// Both weights zero: what primitives without barycentrics report.
    pub const ZERO: Self = Self {
        u: S::ZERO,
        v: S::ZERO,
    };
}

/// A hit on one triangle tested alone ([`crate::Triangle::intersect`]): distance and
/// barycentrics, as in [`Hit`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit<S: Scalar> {
    /// Distance along the unit direction.
    pub t: S,
    /// Weight of the second vertex.
    pub u: S,
    /// Weight of the third vertex.
    pub v: S,
}

/// The closest-hit order: nearer first, and at equal distance the lower primitive id.
/// Every accelerator uses it, so all return the same hit.
#[inline(always)]
#[must_use]
pub fn closer<S: Scalar>(t: S, prim: u32, best_t: S, best_prim: u32) -> bool {
    t < best_t || (t == best_t && prim < best_prim)
}
