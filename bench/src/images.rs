//! Image convergence: how fast each sampler's error falls with render time. The default built-in
//! scene (every effect on: area light, glossy and mirror, depth of field, motion blur) renders at
//! doubling sample counts, single-threaded and timed, with each sampler; the error is the RMSE
//! of the linear image against a reference rendered (untimed, every core) with many more Sobol
//! samples. Monte Carlo error falls as `time^-1/2`; stratified and Sobol samples can do better
//! where the integrand is smooth.

use crate::error::Error;
use host::render::{render, RenderError, RenderOptions};
use host::trace::Mode;
use raykernel::glam::DVec3;
use raykernel::render::scenes;
use raykernel::render::{Integrator, SamplerKind, Settings};
use serde::Serialize;

/// What to render.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ImageOptions {
    /// Built-in scene name.
    pub scene: &'static str,
    /// Image width and height in pixels.
    pub size: (u32, u32),
    /// Sample counts measured.
    pub spps: Vec<u32>,
    /// Samples per pixel of the reference.
    pub reference_spp: u32,
    /// Threads for the (untimed) reference.
    pub threads: usize,
}

impl ImageOptions {
    /// 128×96 pixels (`--quick`: 32×24), 1, 2, 4, … up to `top` samples (default 256, or 16
    /// with `--quick`), reference 16 × `top`.
    #[must_use]
    pub fn new(quick: bool, top: Option<u32>, threads: usize) -> Self {
        let size = if quick { (32, 24) } else { (128, 96) };
        let top = top.unwrap_or(if quick { 16 } else { 256 }).max(1);
        Self {
            scene: "cornell",
            size,
            spps: (0..31)
                .map(|k| 1u32 << k)
                .take_while(|&s| s <= top)
                .collect(),
            reference_spp: top.saturating_mul(16),
            threads,
        }
    }
}

/// One measured render.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ImageRow {
    /// Scene.
    pub scene: String,
    /// Sampler name.
    pub sampler: String,
    /// Samples per pixel.
    pub spp: u32,
    /// Render wall time (one thread), seconds.
    pub seconds: f64,
    /// Root mean square error of the linear RGB values against the reference.
    pub rmse: f64,
    /// Samples per pixel of the reference.
    pub reference_spp: u32,
}

/// Renders the reference, then every sampler at every sample count.
///
/// # Errors
/// An unknown scene name or a render the kernel refuses.
pub fn run(opts: &ImageOptions) -> Result<Vec<ImageRow>, Error> {
    let data = scenes::by_name(opts.scene)
        .ok_or_else(|| Error::Bench(format!("no built-in scene `{}`", opts.scene)))?;
    let settings = |sampler, spp| Settings {
        width: opts.size.0,
        height: opts.size.1,
        spp,
        sampler,
        ..data.settings
    };
    let go = |settings: Settings, threads: usize| {
        let options = RenderOptions {
            mode: Mode::F32,
            threads,
            progress: false,
            ..RenderOptions::default()
        };
        render(&data, settings, &options).map_err(|e| match e {
            RenderError::Scene(e) => Error::Bench(format!("{}: {e}", opts.scene)),
            RenderError::Pool(msg) => Error::Bench(format!("cannot start threads: {msg}")),
        })
    };
    eprintln!(
        "bench: images: {} {}x{}, reference {} spp",
        opts.scene, opts.size.0, opts.size.1, opts.reference_spp
    );
    let reference = go(
        settings(SamplerKind::Sobol, opts.reference_spp),
        opts.threads,
    )?;
    let mut rows = Vec::new();
    for sampler in SamplerKind::ALL {
        for &spp in &opts.spps {
            let r = go(settings(sampler, spp), 1)?;
            rows.push(ImageRow {
                scene: opts.scene.into(),
                sampler: sampler.name().into(),
                spp,
                seconds: r.render_ms / 1e3,
                rmse: rmse(&reference.frame.linear, &r.frame.linear),
                reference_spp: opts.reference_spp,
            });
        }
    }
    Ok(rows)
}

/// Isolated bright errors (fireflies) of one integrator on the default scene: the distribution
/// of per-pixel errors at `spp` against a reference of 16 times as many samples.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FireflyRow {
    /// `direct` or `path`.
    pub integrator: String,
    /// `whole image`, or `glossy sphere` (the pixels whose centre sees it, its rim left out).
    pub region: String,
    /// Image width and height.
    pub size: (u32, u32),
    /// Samples per pixel of the measured image.
    pub spp: u32,
    /// Samples per pixel of its reference (same integrator).
    pub reference_spp: u32,
    /// Median, 99th, 99.9th percentile and largest per-pixel error (RMS over the channels of
    /// the linear difference).
    pub median: f64,
    /// 99th percentile.
    pub p99: f64,
    /// 99.9th percentile.
    pub p999: f64,
    /// Largest.
    pub max: f64,
}

/// The default scene (`cornell`) at `spp` (256, or 16 with `--quick`) with the direct
/// integrator, whose glossy reflections of the small light are not light-sampled, and with
/// the path integrator, whose glossy vertices sample the light with MIS; each against its own
/// reference of 16× the samples (Sobol), untimed on every core.
///
/// # Errors
/// A render the kernel refuses.
pub fn fireflies(quick: bool, threads: usize) -> Result<Vec<FireflyRow>, Error> {
    let data = scenes::CORNELL;
    let (size, spp) = if quick {
        ((16, 16), 16)
    } else {
        ((64, 64), 256)
    };
    let mut rows = Vec::new();
    for (name, integrator) in [
        ("direct", Integrator::Direct),
        (
            "path",
            Integrator::Path {
                max_length: host::scenefile::DEFAULT_MAX_PATH_LENGTH,
            },
        ),
    ] {
        eprintln!("bench: fireflies: {name} {}x{}, {spp} spp", size.0, size.1);
        let go = |spp| {
            let settings = Settings {
                width: size.0,
                height: size.1,
                spp,
                integrator,
                sampler: SamplerKind::Sobol,
                ..data.settings
            };
            let options = RenderOptions {
                mode: Mode::F32,
                threads,
                progress: false,
                ..RenderOptions::default()
            };
            render(&data, settings, &options)
                .map(|r| r.frame.linear)
                .map_err(|e| Error::Bench(format!("fireflies: {e:?}")))
        };
        let reference = go(spp * 16)?;
        let image = go(spp)?;
        let errors: Vec<f64> = image
            .iter()
            .zip(&reference)
            .map(|(p, q)| {
                let sum: f64 = p.iter().zip(q).map(|(x, y)| f64::from(x - y).powi(2)).sum();
                (sum / 3.0).sqrt()
            })
            .collect();
        let sphere = glossy_sphere_pixels(&data, size);
        for (region, mut e) in [
            ("whole image", errors.clone()),
            ("glossy sphere", sphere.iter().map(|&i| errors[i]).collect()),
        ] {
            if e.is_empty() {
                continue;
            }
            e.sort_by(f64::total_cmp);
            let at = |q: f64| e[((e.len() - 1) as f64 * q).round() as usize];
            rows.push(FireflyRow {
                integrator: name.into(),
                region: region.into(),
                size,
                spp,
                reference_spp: spp * 16,
                median: at(0.5),
                p99: at(0.99),
                p999: at(0.999),
                max: at(1.0),
            });
        }
    }
    Ok(rows)
}

/// The pixels whose centre's pinhole ray meets the default scene's glossy sphere within 90%
/// of its radius (away from its rim, which the lens blurs into the background).
fn glossy_sphere_pixels(data: &scenes::SceneData<'_>, (w, h): (u32, u32)) -> Vec<usize> {
    use raykernel::render::Material;
    let Some(sphere) = data.objects.iter().find_map(|o| match o.shape {
        scenes::ShapeRange::Spheres { first, .. }
            if matches!(
                data.materials.get(o.material as usize),
                Some(Material::Glossy { .. })
            ) =>
        {
            data.spheres.get(first as usize)
        }
        _ => None,
    }) else {
        return Vec::new();
    };
    let c = data.camera;
    let v = |a: [f32; 3]| DVec3::from_array(a.map(f64::from));
    let eye = v(c.eye);
    let forward = (v(c.look_at) - eye).normalize();
    let right = forward.cross(v(c.up)).normalize();
    let up = right.cross(forward);
    let half = (f64::from(c.vfov_deg).to_radians() / 2.0).tan();
    let aspect = f64::from(w) / f64::from(h);
    let to = v(sphere.center) - eye;
    let r = 0.9 * f64::from(sphere.radius);
    (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            let sx = (2.0 * (f64::from(x) + 0.5) / f64::from(w) - 1.0) * half * aspect;
            let sy = (1.0 - 2.0 * (f64::from(y) + 0.5) / f64::from(h)) * half;
            let d = (forward + sx * right + sy * up).normalize();
            // Distance from the centre to the ray's line, for a sphere in front of the eye.
            let along = to.dot(d);
            along > 0.0 && to.length_squared() - along * along < r * r
        })
        .map(|(x, y)| (y * w + x) as usize)
        .collect()
}

/// Root mean square difference over every channel of two images of the same size.
#[must_use]
pub fn rmse(a: &[[f32; 3]], b: &[[f32; 3]]) -> f64 {
    let n = a.len().min(b.len()) * 3;
    if n == 0 {
        return 0.0;
    }
    let sum: f64 = a
        .iter()
        .zip(b)
        .flat_map(|(p, q)| p.iter().zip(q).map(|(x, y)| f64::from(x - y).powi(2)))
        .sum();
    (sum / n as f64).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rmse_of_known_images() {
        let a = [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]];
        let b = [[0.0, 0.0, 0.0], [1.0, 1.0, 3.0]];
        // One channel of six differs by 2: sqrt(4 / 6).
        assert!((rmse(&a, &b) - (4.0f64 / 6.0).sqrt()).abs() < 1e-12);
        assert_eq!(rmse(&a, &a), 0.0);
    }

    #[test]
    fn the_glossy_sphere_lies_right_of_centre_below_the_middle() {
        let px = glossy_sphere_pixels(&scenes::CORNELL, (64, 64));
        assert!(px.len() > 100, "{} pixels", px.len());
        // Its centre (0.45, 0.35, 0.3) is right of and below the view's centre.
        assert!(px.iter().all(|&i| i % 64 >= 32 && i / 64 >= 32));
    }
}
