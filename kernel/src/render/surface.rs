//! Points on surfaces and how rays leave them: the spawn rule per primitive kind, checked in
//! the object's frame when it moves.

use super::motion::shifted;
use crate::geom::spawn::{self, sub, MAX_NUDGES};
use crate::geom::{Sphere, Triangle};
use crate::scalar::Scalar;
use glam::Vec3;

/// Spheres leave their surface this many times the triangle rule's offset (the sphere test
/// solves a quadratic: its roots near the surface carry more rounding than a plane's).
pub const SPHERE_SPAWN_FACTOR: f64 = 8.0;

/// The primitive a surface point lies on (in its object's frame at shutter open).
#[derive(Clone, Copy, Debug)]
pub(crate) enum Prim<'a, S: Scalar> {
    Triangle(&'a Triangle<S>, S, S),
    Sphere(&'a Sphere<S>),
}

/// A point on a surface, and how to leave it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SurfacePoint<'a, S: Scalar> {
    /// World position (`f64`).
    pub(crate) position: [f64; 3],
    /// Unit geometric normal (triangles: `(v1−v0)×(v2−v0)`; spheres: outward).
    pub(crate) normal: [f32; 3],
    /// Unit shading normal, on the geometric normal's side: interpolated from
    /// [`super::Object::vertex_normals`], else the geometric normal itself.
    pub(crate) shading: [f32; 3],
    pub(super) prim: Prim<'a, S>,
    /// The object's displacement at the ray's time (zero when static).
    pub(super) shift: [f64; 3],
}

/// The normals at a surface point, both turned to face the ray that arrived there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Facing {
    /// Geometric normal: which directions leave the surface on the arriving ray's side.
    pub(crate) geometric: Vec3,
    /// Shading normal: cosines, reflection and BSDF sampling.
    pub(crate) shading: Vec3,
}

impl Facing {
    /// True if a ray along `dir` leaves the surface on the arriving side, as far as shading
    /// needs to check: with flat shading every direction shading accepts does (its cosine test
    /// is the same one); with smooth shading the geometric side is tested too.
    #[inline(always)]
    pub(crate) fn leaves(&self, dir: Vec3) -> bool {
        self.shading == self.geometric || self.geometric.dot(dir) > 0.0
    }
}

impl<S: Scalar> SurfacePoint<'_, S> {
    /// The normals facing a ray arriving along `dir`.
    #[inline(always)]
    pub(crate) fn facing(&self, dir: Vec3) -> Facing {
        let n = Vec3::from_array(self.normal);
        let s = Vec3::from_array(self.shading);
        if n.dot(dir) > 0.0 {
            Facing {
                geometric: -n,
                shading: -s,
            }
        } else {
            Facing {
                geometric: n,
                shading: s,
            }
        }
    }
}

impl<S: Scalar> SurfacePoint<'_, S> {
    /// An origin for a ray leaving the surface towards `toward` (any length), off the surface
    /// on `toward`'s side by the spawn rule of [`crate::spawn`], checked in the object's frame
    /// after the motion shift (so the object's own test sees it on the right side).
    pub(crate) fn spawn_origin(&self, toward: [f32; 3]) -> [S; 3] {
        let dir_s = dir_in_mode::<S>(toward);
        match self.prim {
            Prim::Triangle(tri, u, v) => {
                let local = spawn::offset_origin(tri, u, v, dir_s);
                if self.shift == [0.0; 3] {
                    return local;
                }
                let want = S::side(&tri.v, &local);
                let mut world = shifted(local, self.shift, 1.0);
                if want == 0 {
                    return world;
                }
                let n = self.normal;
                let axis = dominant(n);
                let up = (n[axis] > 0.0) == (want > 0);
                for _ in 0..MAX_NUDGES {
                    if S::side(&tri.v, &shifted(world, self.shift, -1.0)) == want {
                        break;
                    }
                    world[axis] = S::step(world[axis], up);
                }
                world
            }
            Prim::Sphere(sp) => {
                let n = self.normal.map(f64::from);
                let t = toward.map(f64::from);
                // `<` alone, as in `spawn::offset_origin` (both vectors are finite).
                let inward = n[0] * t[0] + n[1] * t[1] + n[2] * t[2] < 0.0;
                let outside = !inward;
                let c = sp.center.map(S::to_f64);
                let r = sp.radius.to_f64();
                let m = c.iter().fold(r, |m, x| libm::fmax(m, libm::fabs(*x) + r));
                let delta = SPHERE_SPAWN_FACTOR * S::spawn_offset(m);
                let s = if outside { 1.0 } else { -1.0 };
                let local: [f64; 3] = core::array::from_fn(|k| c[k] + (r + s * delta) * n[k]);
                let mut world = shifted(S::point_from_f64(local), self.shift, 1.0);
                let axis = dominant(self.normal);
                let up = (n[axis] > 0.0) == outside;
                for _ in 0..MAX_NUDGES {
                    let q = shifted(world, self.shift, -1.0).map(S::to_f64);
                    let dq = sub(&q, &c);
                    let dist2 = dq[0] * dq[0] + dq[1] * dq[1] + dq[2] * dq[2];
                    if (dist2 > r * r) == outside && dist2 != r * r {
                        break;
                    }
                    world[axis] = S::step(world[axis], up);
                }
                world
            }
        }
    }
}

/// A direction in the mode, scaled by 1024 so fixed point keeps its precision (ray
/// constructors normalise; the scale is a power of two, exact in `f32`).
pub(crate) fn dir_in_mode<S: Scalar>(d: [f32; 3]) -> S::Vec3 {
    S::array_to_vec(d.map(|x| S::from_f32_saturating(x * 1024.0)))
}

/// The axis (0, 1 or 2) of `n`'s largest magnitude, first on ties.
///
/// Always inlined, and clamped: callers index three-element arrays with it, and the bound
/// must be visible to the optimiser in every build (out of line, a C library's build kept a
/// bounds check, a panic path, at each use).
#[inline(always)]
fn dominant(n: [f32; 3]) -> usize {
    let a = n.map(libm::fabsf);
    let axis = if a[0] >= a[1] && a[0] >= a[2] {
        0
    } else if a[1] >= a[2] {
        1
    } else {
        2
    };
    axis.min(2)
}
