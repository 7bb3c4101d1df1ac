//! The direct integrator's bounce loop: camera ray, closest hit, emission, direct light at
//! diffuse surfaces, reflection rays at mirror and glossy ones. Iterative; each step does only
//! what the render plan says the scene needs. Also the camera-ray-only loop and the helpers
//! the path integrator ([`super::path`]) shares.

use super::geometry::{SceneHit, Surface};
use super::lighting::{light_sum, Lobe};
use super::sampling::{gaussian, phong_lobe, tent, to_world, SampleStream};
use super::scene::{Filter, Light, Material};
use super::surface::dir_in_mode;
use super::vector;
use super::{RenderFeatures, RenderPlan, RenderStats, Renderer};
use crate::accel::AccelFamily;
use crate::accel::NoStats;
use crate::geom::Ray;
use crate::scalar::Scalar;
use core::f32::consts::FRAC_1_PI;
use glam::Vec3;

/// Radiance of one pixel sample.
///
/// Always inlined into the pixel loop on hosted targets, as `Renderer::sampled_pixel` is: left
/// to the optimiser, a large binary (the host's, with link-time optimisation) kept both out of
/// line, and the calls and the values passed through memory cost a primary-only render about a
/// tenth. Bare-metal targets keep the optimiser's choice, for flash (see `ray_data` in
/// `scalar/float.rs`).
#[cfg_attr(not(target_os = "none"), inline(always))]
pub(crate) fn sample_radiance<S: Scalar, F: AccelFamily<S>, K: RenderFeatures>(
    r: &Renderer<'_, S, F, K>,
    x: u32,
    y: u32,
    stream: &mut SampleStream,
    stats: &mut RenderStats,
) -> Vec3 {
    let plan: &RenderPlan = &r.plan;
    let (o, d, time) = camera_sample(r, x, y, stream, stats);
    // The path's current ray, read in place (`&current`): copying a just-built ray out of its
    // `Result` stalls on store forwarding, a measurable share of a primary-only render.
    let mut current = Ray::<S>::from_f32(o.to_array(), d.to_array(), 0.0, f32::INFINITY);
    // The ray's direction as shading sees it: the camera's is normalised only when a path
    // needs it (a surface or light seen), so emitters and the background never pay for it.
    let mut dir = d;
    let mut throughput = Vec3::ONE;
    let mut radiance = Vec3::ZERO;
    let mut depth = 0u32;
    // An unusable camera or reflection ray ends the path and adds nothing.
    while let Ok(ray) = &current {
        let Some(hit) = r.geometry.intersect(ray, time, &mut NoStats) else {
            radiance += throughput * Vec3::from_array(r.background);
            break;
        };
        let object = match hit.surface {
            Surface::Light { light } => {
                radiance += throughput * light_seen(r, light, unit_at(dir, depth));
                break;
            }
            Surface::Object { object, .. } => object,
        };
        if K::ONE_SIDED
            && plan.one_sided
            && behind_one_sided(r, ray, &hit, time, object, unit_at(dir, depth))
        {
            break;
        }
        if K::EMISSIVE_GEOMETRY && plan.emitting_objects {
            radiance += throughput * emission_of(r, object);
        }
        // Emitters end the path: no surface point needed.
        let material = match material_of(r, object) {
            None => break,
            Some(Material::Emissive { radiance: e }) => {
                radiance += throughput * Vec3::from_array(*e);
                break;
            }
            Some(m) => m,
        };
        let Some(sp) = r.geometry.surface_point::<K>(ray, &hit, time) else {
            break;
        };
        let dir_unit = unit_at(dir, depth);
        // Two-sided surfaces: shade with the normals facing the incoming ray.
        let facing = sp.facing(dir_unit);
        let nf = facing.shading;
        match material {
            Material::Emissive { .. } => break, // ended the path above
            Material::Diffuse { albedo } => {
                let e = light_sum(r, &sp, facing, Lobe::Diffuse, false, time, stream, stats);
                radiance += throughput * Vec3::from_array(*albedo) * (e * FRAC_1_PI);
                break;
            }
            Material::Mirror { reflectance } => {
                if depth >= plan.max_depth {
                    break;
                }
                dir = reflect(dir_unit, nf);
                if !facing.leaves(dir) {
                    break;
                }
                throughput *= Vec3::from_array(*reflectance);
            }
            Material::Glossy {
                reflectance,
                exponent,
            } => {
                if depth >= plan.max_depth {
                    break;
                }
                let (a, b) = stream.next_2d();
                let lobe = to_world(phong_lobe(a, b, *exponent), reflect(dir_unit, nf));
                if lobe.dot(nf) <= 0.0 || !facing.leaves(lobe) {
                    break;
                }
                throughput *= Vec3::from_array(*reflectance);
                dir = vector::normalize_or_zero(lobe);
            }
        }
        depth += 1;
        // The path's weight is spent once every channel is below the normal range: a
        // subnormal weight times a reflectance below one can round back to itself (the
        // smallest subnormal times 0.9 is the smallest subnormal), so waiting for zero could
        // bounce until `max_depth`, however large, for contributions below f32's normal range.
        if throughput.cmplt(Vec3::splat(f32::MIN_POSITIVE)).all() {
            break;
        }
        let origin = sp.spawn_origin(dir.to_array());
        stats.reflection_rays += 1;
        current = Ray::<S>::new(S::array_to_vec(origin), dir_in_mode::<S>(dir.to_array()));
    }
    radiance
}

/// The camera ray of one pixel sample, origin and direction (not normalised), and its time:
/// the pixel position, lens and time drawn from `stream` in that order, as far as the plan uses
/// them. Both integrators start their paths here.
#[inline(always)]
pub(crate) fn camera_sample<S: Scalar, F: AccelFamily<S>, K: RenderFeatures>(
    r: &Renderer<'_, S, F, K>,
    x: u32,
    y: u32,
    stream: &mut SampleStream,
    stats: &mut RenderStats,
) -> (Vec3, Vec3, f32) {
    let plan: &RenderPlan = &r.plan;
    let (px, py) = if plan.pixel_centre {
        (0.5, 0.5)
    } else {
        let (a, b) = stream.next_2d();
        match plan.filter {
            Filter::Tent if K::FILTERS => (0.5 + tent(a), 0.5 + tent(b)),
            Filter::Gaussian { sigma, radius } if K::FILTERS => (
                0.5 + gaussian(a, sigma, radius),
                0.5 + gaussian(b, sigma, radius),
            ),
            // The box filter; the others only where `K` links them (`Renderer::new` checks).
            _ => (a, b),
        }
    };
    let lens = plan.lens.then(|| stream.next_2d());
    let time = if plan.motion { stream.next_2d().0 } else { 0.0 };
    let (o, d) = r.camera.ray(x as f32 + px, y as f32 + py, lens);
    stats.camera_rays += 1;
    (o, d, time)
}

/// Radiance of pixel `(x, y)` when the plan needs only what camera rays see
/// ([`RenderPlan::camera_rays_only`]): one ray through the pixel centre from the renderer's
/// eye ray, a static scene, and nothing a light could reach. The background, light surfaces
/// and emitters seen directly are then the whole picture; other objects are black. The same
/// bits as [`sample_radiance`] under that plan (the same operations in the same order),
/// without its sample stream, path state and bounce loop.
#[cfg_attr(not(target_os = "none"), inline(always))]
pub(crate) fn camera_ray_radiance<S: Scalar, F: AccelFamily<S>, K: RenderFeatures>(
    r: &Renderer<'_, S, F, K>,
    x: u32,
    y: u32,
    stats: &mut RenderStats,
) -> Vec3 {
    let (_, d) = r.camera.ray(x as f32 + 0.5, y as f32 + 0.5, None);
    stats.camera_rays += 1;
    let Some(eye) = &r.eye_ray else {
        return Vec3::ZERO;
    };
    let Ok(ray) = &eye.redirected_f32(d.to_array()) else {
        return Vec3::ZERO;
    };
    let seen = match r.geometry.intersect(ray, 0.0, &mut NoStats) {
        None => Vec3::from_array(r.background),
        Some(hit) => match hit.surface {
            Surface::Light { light } => light_seen(r, light, vector::normalize_or_zero(d)),
            // Emitters add what they emit, as the general loop adds it; nothing is lit.
            Surface::Object { object, .. } => {
                let plan = &r.plan;
                if K::ONE_SIDED
                    && plan.one_sided
                    && behind_one_sided(r, ray, &hit, 0.0, object, vector::normalize_or_zero(d))
                {
                    return Vec3::ZERO;
                }
                let mut radiance = Vec3::ZERO;
                if K::EMISSIVE_GEOMETRY && plan.emitting_objects {
                    radiance += Vec3::ONE * emission_of(r, object);
                }
                if let Some(Material::Emissive { radiance: e }) = material_of(r, object) {
                    radiance += Vec3::ONE * Vec3::from_array(*e);
                }
                return radiance;
            }
        },
    };
    // As `sample_radiance` adds it: zero radiance plus unit throughput times what is seen.
    Vec3::ZERO + Vec3::ONE * seen
}

/// Object `object`'s material (`None` only for an index the renderer's checks rule out).
#[inline]
pub(super) fn material_of<'r, S: Scalar, F: AccelFamily<S>, K: RenderFeatures>(
    r: &'r Renderer<'_, S, F, K>,
    object: usize,
) -> Option<&'r Material> {
    r.geometry
        .object(object)
        .and_then(|o| r.materials.get(o.material as usize))
}

/// True if hit `hit` of `ray` (unit direction `dir`) lies on the back of object `object` and
/// the object is one-sided ([`super::Object::one_sided`]): the back is black and ends the path.
/// The side is the one shading sees: the sign of `dir` against the surface point's normal.
#[inline]
pub(super) fn behind_one_sided<S: Scalar, F: AccelFamily<S>, K: RenderFeatures>(
    r: &Renderer<'_, S, F, K>,
    ray: &Ray<S>,
    hit: &SceneHit<S>,
    time: f32,
    object: usize,
    dir: Vec3,
) -> bool {
    r.geometry.object(object).is_some_and(|o| o.one_sided)
        && r.geometry
            .normal_at(ray, hit, time)
            .is_some_and(|n| Vec3::from_array(n).dot(dir) > 0.0)
}

/// Radiance object `object` emits ([`super::Object::emission`]; zero for an index the
/// renderer's checks rule out).
#[inline]
pub(super) fn emission_of<S: Scalar, F: AccelFamily<S>, K: RenderFeatures>(
    r: &Renderer<'_, S, F, K>,
    object: usize,
) -> Vec3 {
    r.geometry
        .object(object)
        .map_or(Vec3::ZERO, |o| Vec3::from_array(o.emission))
}

/// Radiance object `object` emits as emissive geometry: its emission plus an emissive
/// material's (zero for an index the renderer's checks rule out).
#[cfg_attr(not(feature = "path-tracing"), allow(dead_code))]
#[inline]
pub(super) fn emitted<S: Scalar, F: AccelFamily<S>, K: RenderFeatures>(
    r: &Renderer<'_, S, F, K>,
    object: usize,
) -> Vec3 {
    r.geometry
        .object(object)
        .map_or(Vec3::ZERO, |o| Vec3::from_array(o.emitted))
}

/// The path's direction at bounce `depth` as a unit vector: the camera's (depth 0) is
/// normalised here; reflected ones already are what shading uses.
#[inline]
fn unit_at(dir: Vec3, depth: u32) -> Vec3 {
    if depth == 0 {
        vector::normalize_or_zero(dir)
    } else {
        dir
    }
}

pub(super) fn reflect(d: Vec3, n: Vec3) -> Vec3 {
    d - n * (2.0 * d.dot(n))
}

/// Radiance a camera or reflection ray sees on light `i`'s surface.
pub(super) fn light_seen<S: Scalar, F: AccelFamily<S>, K: RenderFeatures>(
    r: &Renderer<'_, S, F, K>,
    i: usize,
    dir: Vec3,
) -> Vec3 {
    match (r.lights.get(i), r.geometry.lights.get(i)) {
        (Some(Light::Rect { radiance, .. }), Some(super::lights::LightGeom::Rect(_, n))) => {
            if dir.dot(Vec3::from_array(*n)) < 0.0 {
                Vec3::from_array(*radiance)
            } else {
                Vec3::ZERO
            }
        }
        (Some(Light::Sphere { radiance, .. }), _) if K::SPHERE_LIGHTS => {
            Vec3::from_array(*radiance)
        }
        _ => Vec3::ZERO,
    }
}
