//! The bounce loop: camera ray, closest hit, emission, direct light at diffuse surfaces,
//! reflection rays at mirror and glossy ones. Iterative; each step does only what the render
//! plan says the scene needs.

use super::geometry::{dir_in_mode, Surface, SurfacePoint};
use super::sampling::{phong_lobe, tent, to_world, uniform_cone, SampleStream};
use super::scene::{Filter, Light, Material};
use super::{RenderPlan, RenderStats, Renderer};
use crate::accel::NoStats;
use crate::geom::spawn::{shadow_t_max, SpawnScalar};
use crate::geom::Ray;
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
pub(crate) fn sample_radiance<S: SpawnScalar>(
    r: &Renderer<'_, S>,
    x: u32,
    y: u32,
    stream: &mut SampleStream,
    stats: &mut RenderStats,
) -> Vec3 {
    let plan: &RenderPlan = &r.plan;
    let (px, py) = if plan.pixel_centre {
        (0.5, 0.5)
    } else {
        let (a, b) = stream.next_2d();
        match plan.filter {
            Filter::Box => (a, b),
            Filter::Tent => (0.5 + tent(a), 0.5 + tent(b)),
        }
    };
    let lens = plan.lens.then(|| stream.next_2d());
    let time = if plan.motion { stream.next_2d().0 } else { 0.0 };
    let (o, d) = r.camera.ray(x as f32 + px, y as f32 + py, lens);
    stats.camera_rays += 1;
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
        // Emitters end the path: no surface point needed.
        let material = match material_of(r, object) {
            None => break,
            Some(Material::Emissive { radiance: e }) => {
                radiance += throughput * Vec3::from_array(*e);
                break;
            }
            Some(m) => m,
        };
        let Some(sp) = r.geometry.surface_point(ray, &hit, time) else {
            break;
        };
        let dir_unit = unit_at(dir, depth);
        let n = Vec3::from_array(sp.normal);
        // Two-sided surfaces: shade with the normal facing the incoming ray.
        let nf = if n.dot(dir_unit) > 0.0 { -n } else { n };
        match material {
            Material::Emissive { .. } => break, // ended the path above
            Material::Diffuse { albedo } => {
                let e = direct_light(r, &sp, nf, time, stream, stats);
                radiance += throughput * Vec3::from_array(*albedo) * (e * FRAC_1_PI);
                break;
            }
            Material::Mirror { reflectance } => {
                if depth >= plan.max_depth {
                    break;
                }
                throughput *= Vec3::from_array(*reflectance);
                dir = reflect(dir_unit, nf);
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
                if lobe.dot(nf) <= 0.0 {
                    break;
                }
                throughput *= Vec3::from_array(*reflectance);
                dir = lobe.normalize_or_zero();
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

/// Radiance of pixel `(x, y)` when the plan needs only what camera rays see
/// ([`RenderPlan::camera_rays_only`]): one ray through the pixel centre from the renderer's
/// eye ray, a static scene, no lights to sample and nothing reflecting.
/// Emitters, light surfaces seen directly and the background are then the whole picture;
/// other surfaces are black. The same bits as [`sample_radiance`] under that plan (the same
/// operations in the same order), without its sample stream, path state and bounce loop.
#[cfg_attr(not(target_os = "none"), inline(always))]
pub(crate) fn camera_ray_radiance<S: SpawnScalar>(
    r: &Renderer<'_, S>,
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
            Surface::Light { light } => light_seen(r, light, d.normalize_or_zero()),
            Surface::Object { object, .. } => match material_of(r, object) {
                Some(Material::Emissive { radiance }) => Vec3::from_array(*radiance),
                _ => return Vec3::ZERO,
            },
        },
    };
    // As `sample_radiance` adds it: zero radiance plus unit throughput times what is seen.
    Vec3::ZERO + Vec3::ONE * seen
}

/// Object `object`'s material (`None` only for an index the renderer's checks rule out).
#[inline]
fn material_of<'r, S: SpawnScalar>(r: &'r Renderer<'_, S>, object: usize) -> Option<&'r Material> {
    r.geometry
        .object(object)
        .and_then(|o| r.materials.get(o.material as usize))
}

/// The path's direction at bounce `depth` as a unit vector: the camera's (depth 0) is
/// normalised here; reflected ones already are what shading uses.
#[inline]
fn unit_at(dir: Vec3, depth: u32) -> Vec3 {
    if depth == 0 {
        dir.normalize_or_zero()
    } else {
        dir
    }
}

fn reflect(d: Vec3, n: Vec3) -> Vec3 {
    d - n * (2.0 * d.dot(n))
}

/// Radiance a camera or reflection ray sees on light `i`'s surface.
fn light_seen<S: SpawnScalar>(r: &Renderer<'_, S>, i: usize, dir: Vec3) -> Vec3 {
    match (r.lights.get(i), r.geometry.lights.get(i)) {
        (Some(Light::Rect { radiance, .. }), Some(super::geometry::LightGeom::Rect(_, n))) => {
            if dir.dot(Vec3::from_array(*n)) < 0.0 {
                Vec3::from_array(*radiance)
            } else {
                Vec3::ZERO
            }
        }
        (Some(Light::Sphere { radiance, .. }), _) => Vec3::from_array(*radiance),
        _ => Vec3::ZERO,
    }
}

/// Irradiance-like sum `Σ L·cos θ / pdf` over every light at a diffuse point (the caller
/// multiplies by `albedo / π`), one sample per area light, each tested by a shadow ray.
fn direct_light<S: SpawnScalar>(
    r: &Renderer<'_, S>,
    sp: &SurfacePoint<'_, S>,
    nf: Vec3,
    time: f32,
    stream: &mut SampleStream,
    stats: &mut RenderStats,
) -> Vec3 {
    let p = sp.position;
    let pf = Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32);
    let mut sum = Vec3::ZERO;
    for light in r.lights {
        // Each arm gives the target point, the unoccluded contribution, or nothing.
        let (target, contribution) = match *light {
            Light::Point {
                position,
                intensity,
            } => {
                let to = Vec3::from_array(position) - pf;
                let d2 = to.length_squared();
                let cos = nf.dot(to) / libm::sqrtf(d2);
                if !(cos > 0.0 && d2 > 0.0) {
                    continue;
                }
                (position, Vec3::from_array(intensity) * (cos / d2))
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
                let dist = libm::sqrtf(d2);
                let cross = eu.cross(ev);
                let area = cross.length();
                let cos = nf.dot(to) / dist;
                let cos_l = -cross.dot(to) / (area * dist);
                if !(cos > 0.0 && cos_l > 0.0 && d2 > 0.0) {
                    continue;
                }
                (
                    y.to_array(),
                    Vec3::from_array(radiance) * (cos * cos_l * area / d2),
                )
            }
            Light::Sphere {
                center,
                radius,
                radiance,
            } => {
                let (a, b) = stream.next_2d();
                let to_c = Vec3::from_array(center) - pf;
                let dc2 = to_c.length_squared();
                let r2 = radius * radius;
                if dc2 <= r2 || dc2.is_nan() {
                    continue;
                }
                let dc = libm::sqrtf(dc2);
                let axis = to_c / dc;
                let cos_max = libm::sqrtf(1.0 - r2 / dc2);
                let wi = to_world(uniform_cone(a, b, cos_max), axis);
                let cos = nf.dot(wi);
                if cos <= 0.0 || cos.is_nan() {
                    continue;
                }
                // Nearest root of |p + t·wi − c| = r (the cone guarantees one, up to rounding).
                let b_half = wi.dot(to_c);
                let disc = b_half * b_half - (dc2 - r2);
                let t = b_half - libm::sqrtf(if disc > 0.0 { disc } else { 0.0 });
                let solid_angle = 2.0 * core::f32::consts::PI * (1.0 - cos_max);
                (
                    (pf + wi * t).to_array(),
                    Vec3::from_array(radiance) * (cos * solid_angle),
                )
            }
        };
        if contribution == Vec3::ZERO {
            continue;
        }
        stats.shadow_rays += 1;
        if visible(r, sp, target, time) {
            sum += contribution;
        }
    }
    sum
}

/// True if nothing blocks the segment from the surface point to `target`.
fn visible<S: SpawnScalar>(
    r: &Renderer<'_, S>,
    sp: &SurfacePoint<'_, S>,
    target: [f32; 3],
    time: f32,
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
    let len = libm::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    let dir = Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32).normalize_or_zero();
    let Ok(ray) = Ray::<S>::new(S::array_to_vec(origin), dir_in_mode::<S>(dir.to_array())) else {
        // Origin and target coincide (or the origin left the range): count as lit.
        return true;
    };
    let Ok(ray) = ray.with_interval(S::ZERO, shadow_t_max::<S>(len)) else {
        return true;
    };
    !r.geometry.occluded(&ray, time, &mut NoStats)
}
