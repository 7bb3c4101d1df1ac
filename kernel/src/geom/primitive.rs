use super::{Aabb, Ray};
use crate::scalar::PointError;
use crate::scalar::Scalar;

/// Something an accelerator can hold: it has bounds and a pure intersection test.
///
/// `hit_t` must be a pure function of the ray and the primitive, so that every accelerator
/// computes the same bits for it.
pub trait Primitive<S: Scalar> {
    /// A box holding the primitive.
    fn bounds(&self) -> Aabb<S>;
    /// Checks the primitive's data. On error, the index of the bad vertex (or field).
    fn check(&self) -> Result<(), (usize, PointError)>;
    /// Distance of a hit within `[t_min, t_max]`, if any.
    fn hit_t(&self, ray: &S::RayData, t_min: S, t_max: S) -> Option<S>;
    /// Barycentrics of a hit reported by `hit_t` (zero for primitives without them).
    fn hit_uv(&self, ray: &S::RayData) -> (S, S);
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
    /// The index of the first bad vertex and what is wrong with it.
    pub fn from_f32(v: [[f32; 3]; 3]) -> Result<Self, (usize, PointError)> {
        let mut out = [[S::ZERO; 3]; 3];
        for (i, p) in v.iter().enumerate() {
            for k in 0..3 {
                out[i][k] = S::coord_from_f32(p[k]).map_err(|e| (i, e))?;
            }
        }
        Ok(Self { v: out })
    }

    /// Closest-hit test for this triangle alone: distance and barycentrics.
    pub fn intersect(&self, ray: &Ray<S>) -> Option<(S, S, S)> {
        let t = self.hit_t(ray.data(), ray.t_min(), ray.t_max())?;
        let (u, v) = self.hit_uv(ray.data());
        Some((t, u, v))
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
    fn check(&self) -> Result<(), (usize, PointError)> {
        for (i, p) in self.v.iter().enumerate() {
            S::check_point(*p).map_err(|e| (i, e))?;
        }
        Ok(())
    }
    #[inline(always)]
    fn hit_t(&self, ray: &S::RayData, t_min: S, t_max: S) -> Option<S> {
        S::triangle_t(ray, &self.v, t_min, t_max)
    }
    fn hit_uv(&self, ray: &S::RayData) -> (S, S) {
        S::triangle_uv(ray, &self.v)
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
    fn check(&self) -> Result<(), (usize, PointError)> {
        S::check_point(self.center).map_err(|e| (0, e))?;
        S::check_radius(self.radius).map_err(|e| (1, e))?;
        let b = self.bounds();
        S::check_point(b.lo)
            .and(S::check_point(b.hi))
            .map_err(|e| (1, e))
    }
    #[inline(always)]
    fn hit_t(&self, ray: &S::RayData, t_min: S, t_max: S) -> Option<S> {
        S::sphere_t(ray, &self.center, self.radius, t_min, t_max)
    }
    fn hit_uv(&self, _ray: &S::RayData) -> (S, S) {
        (S::ZERO, S::ZERO)
    }
}
