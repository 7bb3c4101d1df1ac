//! The path integrator's loop: from the camera, each vertex samples every light (next-event
//! estimation) and its BSDF, the two combined by multiple importance sampling, until the
//! path reaches its length, leaves the scene, hits an emitter or Russian roulette ends it.
//! Iterative, no recursion, a fixed amount of state.
//!
//! Path length counts segments ([`Integrator`]). At vertex `k` (reached by segment `k`) both
//! strategies add segment `k + 1`. On the path's last vertex (`k + 1` is the last segment) the
//! BSDF-sampled ray cannot be continued, so the lights are estimated by their samples alone
//! (weight 1) and that ray collects only what light sampling cannot reach: the background and
//! emitting surfaces. With length 2 on a scene without mirror or glossy surfaces, the light
//! estimate is then the direct integrator's, bit for bit.
//!
//! Random values per vertex, in stream order: one pair per area light, one pair for the BSDF
//! direction, and once the path has [`Integrator::ROULETTE_AFTER`] segments one pair (its first
//! value used) for Russian roulette whenever the throughput's largest channel is below 1 (the
//! survival probability).

use super::emitters;
use super::geometry::Surface;
use super::integrator::{
    behind_one_sided, camera_sample, emitted, light_seen, material_of, reflect,
};
use super::lighting::{light_pdf, light_sum, phong_density, Lobe};
use super::sampling::{cosine_hemisphere, phong_lobe, to_world, SampleStream};
use super::scene::{Integrator, Material};
use super::surface::dir_in_mode;
use super::vector;
use super::{RenderFeatures, RenderStats, Renderer};
use crate::accel::{AccelFamily, NoStats};
use crate::geom::Ray;
use crate::scalar::Scalar;
use core::f32::consts::FRAC_1_PI;
use glam::Vec3;

/// How a light surface hit by the path's latest segment is weighted, from the vertex the
/// segment left.
#[derive(Clone, Copy, Debug)]
enum Previous {
    /// The camera or a mirror: only this strategy reaches the light (weight 1).
    Specular,
    /// A vertex whose lights were sampled with MIS: the power heuristic of the BSDF's density
    /// `pdf` against the light's from `position`.
    Sampled { position: Vec3, pdf: f32 },
    /// The path's last vertex, at `position`: its lights were sampled with weight 1 (weight 0
    /// here, unless light sampling cannot reach the surface hit).
    LightsDone { position: Vec3 },
}

/// Radiance of one pixel sample under the path integrator with paths of at most `max_length`
/// segments.
///
/// Never inlined: a path costs many rays, so the call is nothing to it, while inlined into the
/// pixel loop it would change how the optimiser treats the direct integrator's loop there.
#[inline(never)]
pub(crate) fn sample_radiance<S: Scalar, F: AccelFamily<S>, K: RenderFeatures>(
    r: &Renderer<'_, S, F, K>,
    x: u32,
    y: u32,
    max_length: u32,
    stream: &mut SampleStream,
    stats: &mut RenderStats,
) -> Vec3 {
    let plan = &r.plan;
    let (o, d, time) = camera_sample(r, x, y, stream, stats);
    let mut current = Ray::<S>::from_f32(o.to_array(), d.to_array(), 0.0, f32::INFINITY);
    let mut dir = vector::normalize_or_zero(d);
    let mut throughput = Vec3::ONE;
    let mut radiance = Vec3::ZERO;
    let mut previous = Previous::Specular;
    // Segments traced so far, the current ray's included.
    let mut segments = 1u32;
    while let Ok(ray) = &current {
        let Some(hit) = r.geometry.intersect(ray, time, &mut NoStats) else {
            radiance += throughput * Vec3::from_array(r.background);
            break;
        };
        let object = match hit.surface {
            Surface::Light { light } => {
                let weight = match previous {
                    Previous::Specular => 1.0,
                    Previous::Sampled { position, pdf } => {
                        let light_pdf = light_pdf(r.lights, &r.geometry, light, position, dir);
                        super::sampling::power_heuristic(pdf, light_pdf)
                    }
                    Previous::LightsDone { .. } => 0.0,
                };
                if weight > 0.0 {
                    radiance += throughput * light_seen(r, light, dir) * weight;
                }
                break;
            }
            Surface::Object { object, local } => (object, local),
        };
        let (object, local) = object;
        if K::ONE_SIDED && plan.one_sided && behind_one_sided(r, ray, &hit, time, object, dir) {
            break;
        }
        if K::EMISSIVE_GEOMETRY && plan.emissive_geometry {
            let le = emitted(r, object);
            if le != Vec3::ZERO {
                // As for the lights above: weighted against next-event estimation's density.
                let density = |from| {
                    let t = S::to_f64(hit.t) as f32;
                    emitters::density(r, object, local, t, from, dir, time)
                };
                let weight = match previous {
                    Previous::Specular => 1.0,
                    Previous::Sampled { position, pdf } => {
                        super::sampling::power_heuristic(pdf, density(position))
                    }
                    // Light sampling reached it unless its density is zero.
                    Previous::LightsDone { position } if density(position) > 0.0 => 0.0,
                    Previous::LightsDone { .. } => 1.0,
                };
                radiance += throughput * le * weight;
            }
        }
        let material = match material_of(r, object) {
            // Emitted radiance was added above.
            None | Some(Material::Emissive { .. }) => break,
            Some(m) => m,
        };
        if segments >= max_length {
            break;
        }
        let Some(sp) = r.geometry.surface_point::<K>(ray, &hit, time) else {
            break;
        };
        // Two-sided surfaces: shade with the normals facing the incoming ray.
        let facing = sp.facing(dir);
        let nf = facing.shading;
        // Multiple importance sampling unless the BSDF ray is the path's last segment.
        let mis = segments + 1 < max_length;
        let p = sp.position;
        let position = Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32);
        let next = match material {
            Material::Emissive { .. } => break, // ended the path above
            Material::Diffuse { albedo } => {
                let albedo = Vec3::from_array(*albedo);
                let e = light_sum(r, &sp, facing, Lobe::Diffuse, mis, time, stream, stats);
                radiance += throughput * albedo * (e * FRAC_1_PI);
                let (a, b) = stream.next_2d();
                let wi = to_world(cosine_hemisphere(a, b), nf);
                let cos = wi.dot(nf);
                if cos <= 0.0 || cos.is_nan() || !facing.leaves(wi) {
                    break;
                }
                throughput *= albedo;
                (wi, Some(cos * FRAC_1_PI))
            }
            Material::Glossy {
                reflectance,
                exponent,
            } => {
                let reflectance = Vec3::from_array(*reflectance);
                let mirror = reflect(dir, nf);
                let lobe = Lobe::Glossy {
                    mirror,
                    exponent: *exponent,
                };
                let e = light_sum(r, &sp, facing, lobe, mis, time, stream, stats);
                radiance += throughput * reflectance * e;
                let (a, b) = stream.next_2d();
                let wi = vector::normalize_or_zero(to_world(phong_lobe(a, b, *exponent), mirror));
                if wi.dot(nf) <= 0.0 || !facing.leaves(wi) {
                    break;
                }
                throughput *= reflectance;
                (wi, Some(phong_density(wi.dot(mirror), *exponent)))
            }
            Material::Mirror { reflectance } => {
                let wi = reflect(dir, nf);
                if !facing.leaves(wi) {
                    break;
                }
                throughput *= Vec3::from_array(*reflectance);
                (wi, None)
            }
        };
        // The BSDF direction and its density (`None`: a mirror's, a delta).
        let (wi, pdf) = next;
        previous = match pdf {
            None => Previous::Specular,
            Some(pdf) if mis => Previous::Sampled { position, pdf },
            // The last segment can add only radiance light sampling does not reach.
            Some(_) if !plan.unsampled_emission => break,
            Some(_) => Previous::LightsDone { position },
        };
        dir = wi;
        segments += 1;
        if segments > Integrator::ROULETTE_AFTER {
            // Survive with the probability of the largest channel of the throughput (at most
            // 1), and carry the weight of the paths that ended.
            let t = throughput;
            let m = if t.x > t.y { t.x } else { t.y };
            let m = if t.z > m { t.z } else { m };
            let survive = if m < 1.0 { m } else { 1.0 };
            if survive < 1.0 {
                let u = stream.next_2d().0;
                if u >= survive {
                    break;
                }
                throughput /= survive;
            }
        }
        // As in the direct integrator: a weight below f32's normal range is spent.
        if throughput.cmplt(Vec3::splat(f32::MIN_POSITIVE)).all() {
            break;
        }
        let origin = sp.spawn_origin(dir.to_array());
        stats.reflection_rays += 1;
        current = Ray::<S>::new(S::array_to_vec(origin), dir_in_mode::<S>(dir.to_array()));
    }
    radiance
}
