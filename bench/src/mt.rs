//! Möller–Trumbore, benchmark only: the fast, non-watertight contrast to the kernel's test.
//!
//! Möller, Trumbore, *Fast, Minimum Storage Ray/Triangle Intersection*, JGT 2(1) 1997:
//! two-sided, rejects only `det == 0` (an `|det| < ε` test drops small triangles, tinybvh#283),
//! comparisons written so NaN rejects. It is not watertight: a shared edge is evaluated from
//! different base vertices by its two triangles, so rays through it can miss both.

use raykernel::{Aabb, Barycentrics, Primitive, RayData, Scalar, Triangle, VertexError};

/// A kernel triangle whose hit test is Möller–Trumbore in `f32` instead of the watertight one.
/// Same bounds, so a BVH over these is the same tree as over the plain triangles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MtTriangle(pub Triangle<f32>);

impl Primitive<f32> for MtTriangle {
    #[inline(always)]
    fn bounds(&self) -> Aabb<f32> {
        self.0.bounds()
    }
    fn check(&self) -> Result<(), VertexError> {
        self.0.check()
    }
    #[inline(always)]
    fn hit_t(&self, ray: &RayData<f32>, t_min: f32, t_max: f32) -> Option<f32> {
        let o = <f32 as Scalar>::ray_origin(ray);
        let d = <f32 as Scalar>::ray_dir(ray);
        moller_trumbore(&self.0.v, o, d, t_min, t_max).map(|(t, _, _)| t)
    }
    fn hit_uv(&self, ray: &RayData<f32>) -> Barycentrics<f32> {
        let o = <f32 as Scalar>::ray_origin(ray);
        let d = <f32 as Scalar>::ray_dir(ray);
        moller_trumbore(&self.0.v, o, d, 0.0, f32::INFINITY)
            .map_or(Barycentrics::ZERO, |(_, u, v)| Barycentrics { u, v })
    }
}

fn sub(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn cross(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `(t, u, v)` of a hit with `t` in `[t_min, t_max]`, by Möller–Trumbore in `f32`.
#[inline(always)]
#[must_use]
pub fn moller_trumbore(
    v: &[[f32; 3]; 3],
    o: [f32; 3],
    d: [f32; 3],
    t_min: f32,
    t_max: f32,
) -> Option<(f32, f32, f32)> {
    // Edges from the first vertex.
    let e1 = sub(v[1], v[0]);
    let e2 = sub(v[2], v[0]);
    // Determinant: zero when the ray is parallel to the plane (or the triangle degenerate).
    let p = cross(d, e2);
    let det = dot(e1, p);
    if det == 0.0 {
        return None;
    }
    let inv = 1.0 / det;
    // Barycentrics, NaN-safe (a NaN fails every `>=`).
    let s = sub(o, v[0]);
    let u = dot(s, p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = cross(s, e1);
    let w = dot(d, q) * inv;
    if !(w >= 0.0 && u + w <= 1.0) {
        return None;
    }
    let t = dot(e2, q) * inv;
    (t >= t_min && t <= t_max).then_some((t, u, w))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hits_the_middle_and_misses_outside() {
        let v = [[-1.0, -1.0, 5.0], [1.0, -1.0, 5.0], [0.0, 1.0, 5.0]];
        let hit = moller_trumbore(&v, [0.0; 3], [0.0, 0.0, 1.0], 0.0, f32::INFINITY);
        assert_eq!(hit.map(|h| h.0), Some(5.0));
        // Two-sided: from behind too.
        let back = moller_trumbore(&v, [0.0, 0.0, 9.0], [0.0, 0.0, -1.0], 0.0, f32::INFINITY);
        assert_eq!(back.map(|h| h.0), Some(4.0));
        assert_eq!(
            moller_trumbore(&v, [5.0, 0.0, 0.0], [0.0, 0.0, 1.0], 0.0, f32::INFINITY),
            None
        );
        // Out of the interval.
        assert_eq!(
            moller_trumbore(&v, [0.0; 3], [0.0, 0.0, 1.0], 0.0, 4.0),
            None
        );
    }
}
