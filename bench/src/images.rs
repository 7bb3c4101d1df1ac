//! Image convergence: how fast each sampler's error falls with render time. The default built-in
//! scene (every effect on: area light, glossy and mirror, depth of field, motion blur) renders at
//! doubling sample counts, single-threaded and timed, with each sampler; the error is the RMSE
//! of the linear image against a reference rendered (untimed, every core) with many more Sobol
//! samples. Monte Carlo error falls as `time^-1/2`; stratified and Sobol samples can do better
//! where the integrand is smooth.

use crate::error::Error;
use host::render::{render, RenderError, RenderOptions, Rendered};
use host::trace::Mode;
use raykernel::render::scenes;
use raykernel::render::{SamplerKind, Settings};
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
    let go = |settings, threads| render_f32(&data, settings, threads);
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

/// Renders `data` in `f32` on `threads` threads, without progress output.
///
/// # Errors
/// A render the kernel refuses (named by the scene), or a thread pool that cannot start.
pub fn render_f32(
    data: &scenes::SceneData<'_>,
    settings: Settings,
    threads: usize,
) -> Result<Rendered, Error> {
    let options = RenderOptions {
        mode: Mode::F32,
        threads,
        progress: false,
        ..RenderOptions::default()
    };
    render(data, settings, &options).map_err(|e| match e {
        RenderError::Scene(e) => Error::Bench(format!("{}: {e}", data.name)),
        RenderError::Pool(msg) => Error::Bench(format!("cannot start threads: {msg}")),
    })
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
}
