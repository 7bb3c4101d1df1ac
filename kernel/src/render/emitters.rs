//! Emissive geometry as area lights: every primitive of an object that emits
//! ([`super::Object::emission`] or an emissive material) is sampled by next-event estimation,
//! as the analytic area lights are, and a BSDF-sampled ray that hits one is weighted against
//! that sampling by multiple importance sampling.
//!
//! The sampling density: one sample per shading point over all `N` emissive primitives, each
//! chosen with probability `1/N` (no table: the objects' running counts find the primitive);
//! on a triangle of area `A` a uniform point (area density `1/(N·A)`, turned into solid angle
//! by `d²/cos θ_l`); on a sphere a uniform direction in the cone it subtends (density
//! `1/(N·Ω)`), nothing from inside it. A two-sided triangle emits from both faces
//! (`cos θ_l = |n·ω|`), a one-sided one ([`super::Object::one_sided`]) from its front only;
//! a sphere emits outwards.
//!
//! Random values per sample, in stream order: one pair (its first value chooses the
//! primitive), then one pair for the point or direction on it.

use super::lighting::Lobe;
use super::motion::displacement;
use super::objects::ObjectGeom;
use super::sampling::{power_heuristic, to_world, uniform_cone, SampleStream};
use super::scene::Shape;
use super::vector;
use super::{RenderFeatures, Renderer};
use crate::accel::AccelFamily;
use crate::geom::Triangle;
use crate::scalar::{sqrtf, Scalar};
use core::f32::consts::PI;
use glam::Vec3;

/// Points closer to an emissive sphere's centre than its radius times `√ON_SPHERE` count as
/// inside it (nothing sampled): a shading point on the sphere itself may land just outside by
/// rounding, where the cone it sees is a half-space whose nearest point is the point itself.
const ON_SPHERE: f32 = 1.0 + 1.0 / 1024.0;

/// A sampled point on an emitter: the shadow ray's target and the unoccluded contribution.
pub(super) struct EmitterSample {
    pub(super) target: [f32; 3],
    pub(super) contribution: Vec3,
}

/// The object holding emissive primitive `k` (`k < Geometry::emitter_count`) and `k`'s index
/// within it.
fn emitter<'g, 'a, S: Scalar, F: AccelFamily<S>, K: RenderFeatures>(
    r: &'g Renderer<'a, S, F, K>,
    k: u32,
) -> Option<(&'g ObjectGeom<'a, S, F>, u32)> {
    // The last object whose running count is at most `k` is the emitter holding it (objects
    // that do not emit add nothing to the count, so an emitter after them shares their count
    // and comes later).
    let objects = r.geometry.slots();
    let i = objects.partition_point(|s| s.0.is_some_and(|o| o.emitter_base <= k));
    let o = objects.get(i.checked_sub(1)?)?.0.as_ref()?;
    Some((o, k - o.emitter_base))
}

/// Triangle `tri`'s corners in world space at the displacement `d`, in `f32`.
fn corners<S: Scalar>(tri: &Triangle<S>, d: [f64; 3]) -> [Vec3; 3] {
    tri.v.map(|p| {
        let q: [f64; 3] = core::array::from_fn(|k| S::to_f64(p[k]) + d[k]);
        Vec3::new(q[0] as f32, q[1] as f32, q[2] as f32)
    })
}

/// One sample of the scene's emissive geometry seen from `pf` with facing normal `nf`,
/// weighted by `lobe` and, with `mis`, by the power heuristic against BSDF sampling.
/// `None` when the sample contributes nothing (below the horizon, behind a one-sided
/// emitter, inside a sphere).
#[allow(clippy::too_many_arguments)]
pub(super) fn sample<S: Scalar, F: AccelFamily<S>, K: RenderFeatures>(
    r: &Renderer<'_, S, F, K>,
    pf: Vec3,
    nf: Vec3,
    lobe: Lobe,
    mis: bool,
    time: f32,
    stream: &mut SampleStream,
) -> Option<EmitterSample> {
    let n = r.geometry.emitter_count;
    let (s, _) = stream.next_2d();
    let (a, b) = stream.next_2d();
    let k = ((s * n as f32) as u32).min(n.checked_sub(1)?);
    let (o, local) = emitter(r, k)?;
    let d = o.motion.map_or([0.0; 3], |m| displacement::<S>(m, time));
    let le = Vec3::from_array(o.emitted);
    // The inverse of the choice's probability.
    let count = n as f32;
    match o.shape {
        Shape::Triangles(t) => {
            let [v0, v1, v2] = corners(t.get(local as usize)?, d);
            let (a, b) = if a + b > 1.0 {
                (1.0 - a, 1.0 - b)
            } else {
                (a, b)
            };
            let (e1, e2) = (v1 - v0, v2 - v0);
            let y = v0 + e1 * a + e2 * b;
            let cross = e1.cross(e2);
            let twice_area = vector::length(cross);
            let to = y - pf;
            let d2 = to.length_squared();
            let dist = sqrtf(d2);
            let cos = nf.dot(to) / dist;
            let front = -cross.dot(to) / (twice_area * dist);
            let cos_l = if o.one_sided {
                front
            } else {
                libm::fabsf(front)
            };
            if !(cos > 0.0 && cos_l > 0.0 && d2 > 0.0) {
                return None;
            }
            let (w, bsdf_pdf) = lobe.weigh(to, dist, cos);
            // Area over density: N·A.
            let inv_density = count * (0.5 * twice_area);
            let c = le * (w * cos_l * inv_density / d2);
            let c = if mis {
                c * power_heuristic(d2 / (cos_l * inv_density), bsdf_pdf)
            } else {
                c
            };
            Some(EmitterSample {
                target: y.to_array(),
                contribution: c,
            })
        }
        Shape::Spheres(spheres) if F::SPHERES => {
            let sp = spheres.get(local as usize)?;
            let c: [f64; 3] = core::array::from_fn(|k| S::to_f64(sp.center[k]) + d[k]);
            let center = Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32);
            let radius = S::to_f64(sp.radius) as f32;
            let to_c = center - pf;
            let dc2 = to_c.length_squared();
            let r2 = radius * radius;
            if dc2 <= r2 * ON_SPHERE || dc2.is_nan() {
                return None;
            }
            let dc = sqrtf(dc2);
            let cos_max = sqrtf(1.0 - r2 / dc2);
            let wi = to_world(uniform_cone(a, b, cos_max), to_c / dc);
            let cos = nf.dot(wi);
            if cos <= 0.0 || cos.is_nan() {
                return None;
            }
            // Nearest root of |p + t·wi − c| = r (the cone guarantees one, up to rounding).
            let b_half = wi.dot(to_c);
            let disc = b_half * b_half - (dc2 - r2);
            let t = b_half - sqrtf(if disc > 0.0 { disc } else { 0.0 });
            let inv_density = count * (2.0 * PI * (1.0 - cos_max));
            let (w, bsdf_pdf) = lobe.weigh(wi, 1.0, cos);
            let c = le * (w * inv_density);
            let c = if mis {
                c * power_heuristic(1.0 / inv_density, bsdf_pdf)
            } else {
                c
            };
            Some(EmitterSample {
                target: (pf + wi * t).to_array(),
                contribution: c,
            })
        }
        Shape::Spheres(_) => None,
    }
}

/// The solid-angle density with which [`sample`] picks direction `dir` (unit) from `from`
/// towards primitive `local` of object `object`, which a ray along `dir` hit at distance `t`
/// (0 where it cannot: not an emitter, inside a sphere, a degenerate triangle).
#[cfg_attr(not(feature = "path-tracing"), allow(dead_code))]
pub(super) fn density<S: Scalar, F: AccelFamily<S>, K: RenderFeatures>(
    r: &Renderer<'_, S, F, K>,
    object: usize,
    local: u32,
    t: f32,
    from: Vec3,
    dir: Vec3,
    time: f32,
) -> f32 {
    let Some(o) = r.geometry.object(object) else {
        return 0.0;
    };
    if o.emitted == [0.0; 3] {
        return 0.0;
    }
    let count = r.geometry.emitter_count as f32;
    let d = o.motion.map_or([0.0; 3], |m| displacement::<S>(m, time));
    match o.shape {
        Shape::Triangles(tris) => {
            let Some(tri) = tris.get(local as usize) else {
                return 0.0;
            };
            let [v0, v1, v2] = corners(tri, d);
            let cross = (v1 - v0).cross(v2 - v0);
            let twice_area = vector::length(cross);
            let cos_l = libm::fabsf(cross.dot(dir)) / twice_area;
            if cos_l <= 0.0 || cos_l.is_nan() {
                return 0.0;
            }
            t * t / (cos_l * count * (0.5 * twice_area))
        }
        Shape::Spheres(spheres) if F::SPHERES => {
            let Some(sp) = spheres.get(local as usize) else {
                return 0.0;
            };
            let c: [f64; 3] = core::array::from_fn(|k| S::to_f64(sp.center[k]) + d[k]);
            let center = Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32);
            let radius = S::to_f64(sp.radius) as f32;
            let dc2 = (center - from).length_squared();
            let r2 = radius * radius;
            if dc2 <= r2 * ON_SPHERE || dc2.is_nan() {
                return 0.0;
            }
            let cos_max = sqrtf(1.0 - r2 / dc2);
            1.0 / (count * (2.0 * PI * (1.0 - cos_max)))
        }
        Shape::Spheres(_) => 0.0,
    }
}
