use super::{Aabb, Barycentrics, Ray, TriangleHit};
use crate::scalar::PointError;
use crate::scalar::Scalar;
use core::fmt;

/// An unusable vertex (or field) of a primitive: its index within the primitive (0..3 for
/// triangles; 0 = centre, 1 = radius for spheres) and what is wrong with it.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct VertexError {
    /// Index of the vertex (or field) within the primitive.
    pub vertex: usize,
    /// What is wrong with it.
    pub error: PointError,
}

impl VertexError {
    /// Vertex (or field) `vertex` is unusable for the reason `error`.
    #[must_use]
    pub const fn new(vertex: usize, error: PointError) -> Self {
        Self { vertex, error }
    }
}

impl fmt::Display for VertexError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "vertex {}: {}", self.vertex, self.error)
    }
}

impl core::error::Error for VertexError {}

/// Something an accelerator can hold: it has bounds and a pure intersection test. Plain data
/// (`Copy`), so built structures over it are `Copy` too.
///
/// `hit_t` must be a pure function of the ray and the primitive, so that every accelerator
/// computes the same bits for it.
pub trait Primitive<S: Scalar>: Copy + core::fmt::Debug {
    /// A box holding the primitive.
    fn bounds(&self) -> Aabb<S>;
    /// Checks the primitive's data.
    ///
    /// # Errors
    /// The first unusable vertex (or field).
    fn check(&self) -> Result<(), VertexError>;
    /// Distance of a hit within `[t_min, t_max]`, if any.
    fn hit_t(&self, ray: &S::RayData, t_min: S, t_max: S) -> Option<S>;
    /// Barycentrics of a hit reported by `hit_t` (zero for primitives without them).
    fn hit_uv(&self, ray: &S::RayData) -> Barycentrics<S>;
}

/// A two-sided triangle. Degenerate ones (zero area) are accepted and never hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle<S: Scalar> {
    /// The three vertices.
    pub v: [[S; 3]; 3],
}

impl<S: Scalar> Triangle<S> {
    /// From three vertices.
    pub fn new(a: S::Vec3, b: S::Vec3, c: S::Vec3) -> Self {
        Self {
            v: [S::vec_to_array(a), S::vec_to_array(b), S::vec_to_array(c)],
        }
    }

    /// From `f32` vertices, converting each coordinate.
    ///
    /// # Errors
    /// The first unusable vertex.
    pub fn from_f32(v: [[f32; 3]; 3]) -> Result<Self, VertexError> {
        let mut out = [[S::ZERO; 3]; 3];
        for (i, p) in v.iter().enumerate() {
            for k in 0..3 {
                out[i][k] = S::coord_from_f32(p[k]).map_err(|e| VertexError::new(i, e))?;
            }
        }
        Ok(Self { v: out })
    }

    /// Closest-hit test for this triangle alone: distance and barycentrics.
    pub fn intersect(&self, ray: &Ray<S>) -> Option<TriangleHit<S>> {
        let t = self.hit_t(ray.data(), ray.t_min(), ray.t_max())?;
        let Barycentrics { u, v } = self.hit_uv(ray.data());
        Some(TriangleHit { t, u, v })
    }
}

impl<S: Scalar> Primitive<S> for Triangle<S> {
    #[inline(always)]
    fn bounds(&self) -> Aabb<S> {
        let [a, b, c] = &self.v;
        let mut r = Aabb::new(*a, *a);
        for i in 0..3 {
            r.lo[i] = r.lo[i].min_of(b[i]).min_of(c[i]);
            r.hi[i] = r.hi[i].max_of(b[i]).max_of(c[i]);
        }
        r
    }
    fn check(&self) -> Result<(), VertexError> {
        for (i, p) in self.v.iter().enumerate() {
            S::check_point(*p).map_err(|e| VertexError::new(i, e))?;
        }
        Ok(())
    }
    #[inline(always)]
    fn hit_t(&self, ray: &S::RayData, t_min: S, t_max: S) -> Option<S> {
        S::triangle_t(ray, &self.v, t_min, t_max)
    }
    fn hit_uv(&self, ray: &S::RayData) -> Barycentrics<S> {
        let (u, v) = S::triangle_uv(ray, &self.v);
        Barycentrics { u, v }
    }
}

/// A sphere: the lecture's second shape. Hit from outside or inside (nearest root in range).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere<S: Scalar> {
    /// Centre.
    pub center: [S; 3],
    /// Radius, not negative.
    pub radius: S,
}

impl<S: Scalar> Sphere<S> {
    /// From centre and radius.
    pub fn new(center: S::Vec3, radius: S) -> Self {
        Self {
            center: S::vec_to_array(center),
            radius,
        }
    }
}

impl<S: Scalar> Primitive<S> for Sphere<S> {
    fn bounds(&self) -> Aabb<S> {
        let (lo, hi) = S::sphere_bounds(&self.center, self.radius);
        Aabb::new(lo, hi)
    }
    fn check(&self) -> Result<(), VertexError> {
        S::check_point(self.center).map_err(|e| VertexError::new(0, e))?;
        S::check_radius(self.radius).map_err(|e| VertexError::new(1, e))?;
        let b = self.bounds();
        S::check_point(b.lo)
            .and(S::check_point(b.hi))
            .map_err(|e| VertexError::new(1, e))
    }
    #[inline(always)]
    fn hit_t(&self, ray: &S::RayData, t_min: S, t_max: S) -> Option<S> {
        S::sphere_t(ray, &self.center, self.radius, t_min, t_max)
    }
    fn hit_uv(&self, _ray: &S::RayData) -> Barycentrics<S> {
        Barycentrics::ZERO
    }
}
