//! Next-event estimation: one sample and shadow ray per light at a shading point, weighted by
//! the point's lobe, and the light-sampling densities multiple importance sampling compares
//! with the BSDF's.

use super::emitters;
use super::geometry::Geometry;
use super::lights::LightGeom;
use super::sampling::{power_heuristic, to_world, uniform_cone, SampleStream};
use super::scene::Light;
use super::surface::{dir_in_mode, Facing, SurfacePoint};
use super::vector;
use super::{RenderFeatures, RenderStats, Renderer};
use crate::accel::{AccelFamily, NoStats};
use crate::geom::spawn::shadow_t_max;
use crate::geom::Ray;
use crate::scalar::{sqrtf, Scalar};
use core::f32::consts::{FRAC_1_PI, PI};
use glam::Vec3;

/// How a shading point's BSDF weighs light arriving from direction `wi`, without its
/// reflectance (the caller multiplies by it).
#[derive(Clone, Copy, Debug)]
pub(super) enum Lobe {
    /// Lambertian: the weight is `cos θ` (the caller multiplies by `albedo / π`); BSDF
    /// sampling is cosine-weighted, density `cos θ / π`.
    Diffuse,
    /// The normalised Phong lobe around the unit mirror direction: the weight is the lobe's
    /// density `(n+1)/(2π)·cos^n α` (the BSDF times `cos θ`, over the reflectance), which is
    /// also BSDF sampling's density. Shaded by the path integrator alone.
    #[cfg_attr(not(feature = "path-tracing"), allow(dead_code))]
    Glossy {
        /// Unit mirror direction.
        mirror: Vec3,
        /// Lobe exponent.
        exponent: f32,
    },
}

impl Lobe {
    /// The weight of light from `to / len` (any length `len > 0`) at `cos = nf·wi > 0`, and
    /// BSDF sampling's density of that direction.
    #[inline]
    pub(super) fn weigh(self, to: Vec3, len: f32, cos: f32) -> (f32, f32) {
        match self {
            Self::Diffuse => (cos, cos * FRAC_1_PI),
            Self::Glossy { mirror, exponent } => {
                let d = phong_density(mirror.dot(to / len), exponent);
                (d, d)
            }
        }
    }
}

/// The normalised Phong lobe's density `(n+1)/(2π)·cos^n α` at `cos α = c` (0 for `c <= 0`).
pub(super) fn phong_density(c: f32, exponent: f32) -> f32 {
    if c > 0.0 {
        (exponent + 1.0) * (0.5 * FRAC_1_PI) * libm::powf(c, exponent)
    } else {
        0.0
    }
}

/// `Σ L·w·G / pdf` over every light at a shading point with normals `facing`, one sample
/// per area light, each tested by a shadow ray; `w` is the [`Lobe`]'s weight. With `mis`, area
/// lights' samples carry the power heuristic's weight against BSDF sampling (point lights,
/// which BSDF sampling cannot reach, weight 1); without it every sample weighs 1.
///
/// Always inlined on hosted targets (as the integrators' loops are): each call site then has
/// its lobe and `mis` as constants, so the direct integrator's diffuse-only sum carries no
/// branch for what it does not use. Bare-metal targets keep one copy, for flash.
#[allow(clippy::too_many_arguments)]
#[cfg_attr(not(target_os = "none"), inline(always))]
pub(super) fn light_sum<S: Scalar, F: AccelFamily<S>, K: RenderFeatures>(
    r: &Renderer<'_, S, F, K>,
    sp: &SurfacePoint<'_, S>,
    facing: Facing,
    lobe: Lobe,
    mis: bool,
    time: f32,
    stream: &mut SampleStream,
    stats: &mut RenderStats,
) -> Vec3 {
    let nf = facing.shading;
    let p = sp.position;
    let pf = Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32);
    let mut sum = Vec3::ZERO;
    for light in r.lights {
        // Each arm gives the target point, the unoccluded contribution, or nothing.
        let (target, contribution) = match *light {
            Light::Point {
                position,
                intensity,
            } if K::POINT_LIGHTS => {
                let to = Vec3::from_array(position) - pf;
                let d2 = to.length_squared();
                let dist = sqrtf(d2);
                let cos = nf.dot(to) / dist;
                if !(cos > 0.0 && d2 > 0.0) {
                    continue;
                }
                let (w, _) = lobe.weigh(to, dist, cos);
                (position, Vec3::from_array(intensity) * (w / d2))
            }
            Light::Rect {
                corner,
                edge_u,
                edge_v,
                radiance,
            } => {
                let (a, b) = stream.next_2d();
                let (eu, ev) = (Vec3::from_array(edge_u), Vec3::from_array(edge_v));
                let y = Vec3::from_array(corner) + eu * a + ev * b;
                let to = y - pf;
                let d2 = to.length_squared();
                let dist = sqrtf(d2);
                let cross = eu.cross(ev);
                let area = vector::length(cross);
                let cos = nf.dot(to) / dist;
                let cos_l = -cross.dot(to) / (area * dist);
                if !(cos > 0.0 && cos_l > 0.0 && d2 > 0.0) {
                    continue;
                }
                let (w, bsdf_pdf) = lobe.weigh(to, dist, cos);
                let c = Vec3::from_array(radiance) * (w * cos_l * area / d2);
                let c = if mis {
                    c * power_heuristic(d2 / (cos_l * area), bsdf_pdf)
                } else {
                    c
                };
                (y.to_array(), c)
            }
            Light::Sphere {
                center,
                radius,
                radiance,
            } if K::SPHERE_LIGHTS => {
                let (a, b) = stream.next_2d();
                let to_c = Vec3::from_array(center) - pf;
                let dc2 = to_c.length_squared();
                let r2 = radius * radius;
                if dc2 <= r2 || dc2.is_nan() {
                    continue;
                }
                let dc = sqrtf(dc2);
                let axis = to_c / dc;
                let cos_max = sqrtf(1.0 - r2 / dc2);
                let wi = to_world(uniform_cone(a, b, cos_max), axis);
                let cos = nf.dot(wi);
                if cos <= 0.0 || cos.is_nan() {
                    continue;
                }
                // Nearest root of |p + t·wi − c| = r (the cone guarantees one, up to rounding).
                let b_half = wi.dot(to_c);
                let disc = b_half * b_half - (dc2 - r2);
                let t = b_half - sqrtf(if disc > 0.0 { disc } else { 0.0 });
                let solid_angle = 2.0 * PI * (1.0 - cos_max);
                let (w, bsdf_pdf) = lobe.weigh(wi, 1.0, cos);
                let c = Vec3::from_array(radiance) * (w * solid_angle);
                let c = if mis {
                    c * power_heuristic(1.0 / solid_angle, bsdf_pdf)
                } else {
                    c
                };
                ((pf + wi * t).to_array(), c)
            }
            // Kinds `K` leaves out (`Renderer::new` refuses them).
            Light::Point { .. } | Light::Sphere { .. } => continue,
        };
        if contribution == Vec3::ZERO || !facing.leaves(Vec3::from_array(target) - pf) {
            continue;
        }
        stats.shadow_rays += 1;
        if visible(r, sp, target, time, false) {
            sum += contribution;
        }
    }
    if K::EMISSIVE_GEOMETRY && r.plan.emissive_geometry {
        sum += emitter_light(r, sp, facing, lobe, mis, time, stream, stats);
    }
    sum
}

/// The emissive geometry's share of [`light_sum`]: one sample ([`emitters::sample`]) and its
/// shadow ray. Kept out of line: scenes without emissive geometry carry only the branch to it
/// in their shading loop.
#[allow(clippy::too_many_arguments)]
#[inline(never)]
fn emitter_light<S: Scalar, F: AccelFamily<S>, K: RenderFeatures>(
    r: &Renderer<'_, S, F, K>,
    sp: &SurfacePoint<'_, S>,
    facing: Facing,
    lobe: Lobe,
    mis: bool,
    time: f32,
    stream: &mut SampleStream,
    stats: &mut RenderStats,
) -> Vec3 {
    let p = sp.position;
    let pf = Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32);
    let Some(s) = emitters::sample(r, pf, facing.shading, lobe, mis, time, stream) else {
        return Vec3::ZERO;
    };
    if s.contribution == Vec3::ZERO || !facing.leaves(Vec3::from_array(s.target) - pf) {
        return Vec3::ZERO;
    }
    stats.shadow_rays += 1;
    if visible(r, sp, s.target, time, true) {
        s.contribution
    } else {
        Vec3::ZERO
    }
}

/// The solid-angle density with which [`light_sum`] samples the unit direction `dir` from
/// `from` towards light `i`, whose surface a ray along `dir` hit (0 where it samples nothing:
/// point lights, a rectangle's back, the inside of a sphere light).
#[cfg_attr(not(feature = "path-tracing"), allow(dead_code))]
pub(super) fn light_pdf<S: Scalar, F: AccelFamily<S>>(
    lights: &[Light],
    geometry: &Geometry<'_, S, F>,
    i: usize,
    from: Vec3,
    dir: Vec3,
) -> f32 {
    match (lights.get(i), geometry.lights.get(i)) {
        (
            Some(Light::Rect {
                corner,
                edge_u,
                edge_v,
                ..
            }),
            Some(LightGeom::Rect(..)),
        ) => {
            let cross = Vec3::from_array(*edge_u).cross(Vec3::from_array(*edge_v));
            let area = vector::length(cross);
            let facing = -cross.dot(dir);
            if !(facing > 0.0 && area > 0.0) {
                return 0.0;
            }
            // Distance to the light's plane along `dir`.
            let t = cross.dot(from - Vec3::from_array(*corner)) / facing;
            let cos_l = facing / area;
            t * t / (cos_l * area)
        }
        (Some(Light::Sphere { center, radius, .. }), _) => {
            let dc2 = (Vec3::from_array(*center) - from).length_squared();
            let r2 = radius * radius;
            if dc2 <= r2 || dc2.is_nan() {
                return 0.0;
            }
            let cos_max = sqrtf(1.0 - r2 / dc2);
            1.0 / (2.0 * PI * (1.0 - cos_max))
        }
        _ => 0.0,
    }
}

/// Shadow rays towards a point on emissive geometry stop this fraction of the distance short
/// of it: the emitter itself blocks light, so the ray must end before its surface, and the
/// sampled point carries `f32` rounding (the shadow rule's own shortening,
/// [`crate::spawn::SHADOW_SHORTEN`], is for exact targets).
const EMITTER_SHORTEN: f64 = 1.0 / 1024.0;

/// True if nothing blocks the segment from the surface point to `target` (`on_surface`: a
/// point on emissive geometry, the segment shortened by [`EMITTER_SHORTEN`]). Inlined on
/// hosted targets as [`light_sum`] is (two integrators call it; left alone, the optimiser
/// keeps it out of line and the direct integrator pays the calls).
#[cfg_attr(not(target_os = "none"), inline(always))]
fn visible<S: Scalar, F: AccelFamily<S>, K: RenderFeatures>(
    r: &Renderer<'_, S, F, K>,
    sp: &SurfacePoint<'_, S>,
    target: [f32; 3],
    time: f32,
    on_surface: bool,
) -> bool {
    let p = sp.position;
    let toward = [
        (f64::from(target[0]) - p[0]) as f32,
        (f64::from(target[1]) - p[1]) as f32,
        (f64::from(target[2]) - p[2]) as f32,
    ];
    let origin = sp.spawn_origin(toward);
    let o = origin.map(S::to_f64);
    let d = [
        f64::from(target[0]) - o[0],
        f64::from(target[1]) - o[1],
        f64::from(target[2]) - o[2],
    ];
    let len = crate::scalar::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    let dir = vector::normalize_or_zero(Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32));
    let Ok(ray) = Ray::<S>::new(S::array_to_vec(origin), dir_in_mode::<S>(dir.to_array())) else {
        // Origin and target coincide (or the origin left the range): count as lit.
        return true;
    };
    let t_max = if on_surface {
        S::t_down(len * (1.0 - EMITTER_SHORTEN), 1)
    } else {
        shadow_t_max::<S>(len)
    };
    let Ok(ray) = ray.with_interval(S::ZERO, t_max) else {
        return true;
    };
    !r.geometry.occluded(&ray, time, &mut NoStats)
}
