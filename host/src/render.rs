//! The host's render path: the kernel's renderer ([`raykernel::render`]) over
//! tiles in parallel (rayon, a local thread pool), and the image files (PNG, PFM).
//!
//! Every pixel is a pure function of the scene, the settings and its position, so tiles can run
//! in any order on any thread: the image is the same bytes for any thread count and tile size
//! as the kernel's single-threaded [`Renderer::render_srgb8`] (`host check` proves it).

use crate::error::Error;
use crate::trace::{Mode, NodeArena};
use indicatif::{ProgressBar, ProgressStyle};
use raykernel::render::scenes::SceneData;
use raykernel::render::{
    encode_srgb8, memory_needed, Object, ObjectSlot, RenderMemory, RenderPlan, RenderStats,
    Renderer, Rgb, SceneError, Settings, Shape, Tile,
};
use raykernel::{AccelKind, AnyFamily, Scalar, Sphere, Triangle, I16F16};
use rayon::prelude::*;
use std::io::Write;
use std::path::Path;
use std::time::Instant;

/// How to render (the scene and its settings come separately).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderOptions {
    /// Number mode of the geometry.
    pub mode: Mode,
    /// Accelerator of every object.
    pub accel: AccelKind,
    /// Worker threads (at least 1).
    pub threads: usize,
    /// Tile width and height in pixels (at least 1 each).
    pub tile: (u32, u32),
    /// Show a progress bar on stderr (only drawn when stderr is a terminal).
    pub progress: bool,
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            mode: Mode::F32,
            accel: AccelKind::default(),
            threads: 1,
            tile: (16, 16),
            progress: false,
        }
    }
}

/// A rendered image in linear RGB (mean radiance per pixel), rows top to bottom.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width * height` pixels.
    pub linear: Vec<Rgb>,
}

impl Frame {
    /// The 8-bit sRGB image (the kernel's [`encode_srgb8`] per channel: the same bytes as the
    /// kernel's `render_srgb8`).
    #[must_use]
    pub fn srgb8(&self) -> Image {
        Image {
            width: self.width,
            height: self.height,
            rgb: self
                .linear
                .iter()
                .flat_map(|p| p.map(encode_srgb8))
                .collect(),
        }
    }
}

/// An 8-bit sRGB image: `width * height` RGB pixels, rows top to bottom.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `3 * width * height` bytes.
    pub rgb: Vec<u8>,
}

/// A finished render.
#[derive(Clone, Debug)]
pub struct Rendered {
    /// The picture.
    pub frame: Frame,
    /// What the kernel did.
    pub plan: RenderPlan,
    /// Rays cast.
    pub stats: RenderStats,
    /// Wall time of converting the scene and building the accelerators.
    pub build_ms: f64,
    /// Wall time of rendering every tile.
    pub render_ms: f64,
}

/// Builds the kernel's renderer for `data` in mode `S` (converted primitives, objects and BVH
/// memory owned here) and hands it to `f`; returns `f`'s result and the build time in ms.
///
/// # Errors
/// The kernel's [`SceneError`] (map it with [`crate::spec::SceneSpec::explain`]).
pub fn with_renderer<S: Scalar, R>(
    data: &SceneData<'_>,
    settings: Settings,
    accel: AccelKind,
    f: impl for<'r> FnOnce(&Renderer<'r, S>) -> R,
) -> Result<(R, f64), SceneError> {
    let start = Instant::now();
    let mut triangles = vec![
        Triangle {
            v: [[S::ZERO; 3]; 3]
        };
        data.triangles.len()
    ];
    data.triangles_into(&mut triangles)?;
    let mut spheres = vec![
        Sphere {
            center: [S::ZERO; 3],
            radius: S::ZERO,
        };
        data.spheres.len()
    ];
    data.spheres_into(&mut spheres)?;
    let mut objects = vec![Object::new(Shape::Triangles(&[]), 0); data.objects.len()];
    let scene = data.scene(&triangles, &spheres, &mut objects)?;
    let need = memory_needed::<S, AnyFamily>(scene.objects, &accel);
    let mut slots = vec![ObjectSlot::EMPTY; need.objects];
    // 64-byte aligned BVH nodes, a sibling pair per cache line, as the kernel's layout intends.
    let mut arena = NodeArena::<S>::sized(need.accel);
    let memory = RenderMemory {
        objects: &mut slots,
        accel: arena.memory(),
    };
    let renderer = Renderer::new(&scene, settings, accel, memory)?;
    let build_ms = start.elapsed().as_secs_f64() * 1e3;
    Ok((f(&renderer), build_ms))
}

/// The plan the kernel derives for `data` with `settings` in `mode` (nothing is rendered).
///
/// # Errors
/// As [`with_renderer`].
pub fn plan(
    data: &SceneData<'_>,
    settings: Settings,
    mode: Mode,
) -> Result<RenderPlan, SceneError> {
    fn go<S: Scalar>(d: &SceneData<'_>, s: Settings) -> Result<RenderPlan, SceneError> {
        with_renderer::<S, _>(d, s, AccelKind::Linear, |r| *r.plan()).map(|(p, _)| p)
    }
    match mode {
        Mode::F32 => go::<f32>(data, settings),
        Mode::Fixed => go::<I16F16>(data, settings),
    }
}

/// Renders `data` with `settings`: parallel tiles on a local pool of `options.threads`.
///
/// # Errors
/// The kernel's [`SceneError`] for the scene or settings, or [`Error::Usage`] if the thread
/// pool cannot be started (wrapped so the caller maps scene errors itself).
pub fn render(
    data: &SceneData<'_>,
    settings: Settings,
    options: &RenderOptions,
) -> Result<Rendered, RenderError> {
    match options.mode {
        Mode::F32 => render_in::<f32>(data, settings, options),
        Mode::Fixed => render_in::<I16F16>(data, settings, options),
    }
}

/// Why [`render`] failed.
#[derive(Debug)]
pub enum RenderError {
    /// The kernel rejected the scene or settings.
    Scene(SceneError),
    /// The thread pool could not be started.
    Pool(String),
}

impl From<SceneError> for RenderError {
    fn from(e: SceneError) -> Self {
        Self::Scene(e)
    }
}

fn render_in<S: Scalar + Send + Sync>(
    data: &SceneData<'_>,
    settings: Settings,
    options: &RenderOptions,
) -> Result<Rendered, RenderError> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(options.threads.max(1))
        .build()
        .map_err(|e| RenderError::Pool(e.to_string()))?;
    let (result, build_ms) = with_renderer::<S, _>(data, settings, options.accel, |r| {
        let start = Instant::now();
        let tiles = tiles(settings.width, settings.height, options.tile);
        let bar = progress_bar(options.progress, &settings, tiles.len());
        let rendered: Vec<Result<(Vec<Rgb>, RenderStats), SceneError>> = pool.install(|| {
            tiles
                .par_iter()
                .map(|t| {
                    let mut buf = vec![[0.0; 3]; t.width as usize * t.height as usize];
                    let stats = r.render_tile(*t, &mut buf)?;
                    bar.inc(1);
                    Ok((buf, stats))
                })
                .collect()
        });
        bar.finish_and_clear();
        let (w, h) = (settings.width as usize, settings.height as usize);
        let mut linear = vec![[0.0; 3]; w * h];
        let mut stats = RenderStats::default();
        for (t, result) in tiles.iter().zip(rendered) {
            let (buf, s) = result?;
            stats = stats.add(s);
            for (row, src) in buf.chunks_exact(t.width as usize).enumerate() {
                let at = (t.y as usize + row) * w + t.x as usize;
                linear[at..at + src.len()].copy_from_slice(src);
            }
        }
        Ok::<_, SceneError>(Rendered {
            frame: Frame {
                width: settings.width,
                height: settings.height,
                linear,
            },
            plan: *r.plan(),
            stats,
            build_ms: 0.0,
            render_ms: start.elapsed().as_secs_f64() * 1e3,
        })
    })?;
    let mut rendered = result?;
    rendered.build_ms = build_ms;
    Ok(rendered)
}

/// The tiles covering a `width`×`height` image, row by row; edge tiles are cut to fit.
#[must_use]
pub fn tiles(width: u32, height: u32, (tw, th): (u32, u32)) -> Vec<Tile> {
    let (tw, th) = (tw.max(1), th.max(1));
    let mut out = Vec::new();
    for y in (0..height).step_by(th as usize) {
        for x in (0..width).step_by(tw as usize) {
            out.push(Tile {
                x,
                y,
                width: tw.min(width - x),
                height: th.min(height - y),
            });
        }
    }
    out
}

/// Samples above which a render counts as long enough for a progress bar.
const LONG_RENDER_SAMPLES: u64 = 4 << 20;

fn progress_bar(wanted: bool, s: &Settings, tiles: usize) -> ProgressBar {
    use std::io::IsTerminal;
    let samples = u64::from(s.width) * u64::from(s.height) * u64::from(s.spp);
    if !wanted || samples < LONG_RENDER_SAMPLES || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let style = ProgressStyle::with_template(
        "{spinner} rendering [{bar:30}] {pos}/{len} tiles, {elapsed} (eta {eta})",
    )
    .map_or_else(
        |_| ProgressStyle::default_bar(),
        |s| s.progress_chars("=> "),
    );
    ProgressBar::new(tiles as u64).with_style(style)
}

/// The kernel's single-threaded whole-image path ([`Renderer::render_srgb8`]): the reference
/// for `host check`.
///
/// # Errors
/// The kernel's [`SceneError`].
pub fn render_reference(
    data: &SceneData<'_>,
    settings: Settings,
    mode: Mode,
    accel: AccelKind,
) -> Result<Image, SceneError> {
    fn go<S: Scalar>(d: &SceneData<'_>, s: Settings, a: AccelKind) -> Result<Image, SceneError> {
        let mut rgb = vec![0u8; 3 * s.width as usize * s.height as usize];
        with_renderer::<S, _>(d, s, a, |r| r.render_srgb8(&mut rgb))?.0?;
        Ok(Image {
            width: s.width,
            height: s.height,
            rgb,
        })
    }
    match mode {
        Mode::F32 => go::<f32>(data, settings, accel),
        Mode::Fixed => go::<I16F16>(data, settings, accel),
    }
}

/// The mode's name as in reports and file names: `f32` or `fixed`.
#[must_use]
pub fn mode_name(mode: Mode) -> &'static str {
    match mode {
        Mode::F32 => <f32 as Scalar>::NAME,
        Mode::Fixed => <I16F16 as Scalar>::NAME,
    }
}

/// The PNG bytes of `image` (8-bit RGB, marked sRGB).
///
/// # Errors
/// A message if the encoder refuses (it does not for a well-formed image).
pub fn encode_png(image: &Image) -> Result<Vec<u8>, String> {
    let mut out = Vec::new();
    let mut enc = png::Encoder::new(&mut out, image.width, image.height);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    let fail = |e: png::EncodingError| format!("cannot encode PNG: {e}");
    let mut writer = enc.write_header().map_err(fail)?;
    writer.write_image_data(&image.rgb).map_err(fail)?;
    writer.finish().map_err(fail)?;
    Ok(out)
}

/// Decodes an 8-bit RGB PNG.
///
/// # Errors
/// A message for bytes that are not such a PNG.
pub fn decode_png(bytes: &[u8]) -> Result<Image, String> {
    let mut reader = png::Decoder::new(std::io::Cursor::new(bytes))
        .read_info()
        .map_err(|e| format!("not a PNG: {e}"))?;
    let size = reader
        .output_buffer_size()
        .ok_or_else(|| "PNG too large".to_string())?;
    let mut buf = vec![0; size];
    let info = reader
        .next_frame(&mut buf)
        .map_err(|e| format!("bad PNG data: {e}"))?;
    if info.color_type != png::ColorType::Rgb || info.bit_depth != png::BitDepth::Eight {
        return Err(format!(
            "expected 8-bit RGB, found {:?} {:?}",
            info.color_type, info.bit_depth
        ));
    }
    buf.truncate(info.buffer_size());
    Ok(Image {
        width: info.width,
        height: info.height,
        rgb: buf,
    })
}

/// Writes `image` as a PNG file.
///
/// # Errors
/// [`Error::Output`] if it cannot be encoded or written.
pub fn write_png(path: &Path, image: &Image) -> Result<(), Error> {
    let fail = |msg: String| Error::Output {
        path: path.to_path_buf(),
        msg,
    };
    let bytes = encode_png(image).map_err(fail)?;
    std::fs::write(path, bytes).map_err(|e| fail(format!("cannot write: {e}")))
}

/// The PFM bytes of `frame`: `PF`, size, `-1.0` (little-endian), then 32-bit floats, rows
/// bottom to top, linear RGB as rendered (no clipping, no encoding).
#[must_use]
pub fn encode_pfm(frame: &Frame) -> Vec<u8> {
    let mut out = format!("PF\n{} {}\n-1.0\n", frame.width, frame.height).into_bytes();
    for row in frame.linear.chunks(frame.width.max(1) as usize).rev() {
        for x in row.iter().flatten() {
            out.extend_from_slice(&x.to_le_bytes());
        }
    }
    out
}

/// Writes `frame` as a PFM file.
///
/// # Errors
/// [`Error::Output`] if it cannot be written.
pub fn write_pfm(path: &Path, frame: &Frame) -> Result<(), Error> {
    std::fs::File::create(path)
        .and_then(|mut f| f.write_all(&encode_pfm(frame)))
        .map_err(|e| Error::Output {
            path: path.to_path_buf(),
            msg: format!("cannot write: {e}"),
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_cover_the_image_once() {
        for (w, h, t) in [(64, 48, (16, 16)), (10, 7, (3, 5)), (1, 1, (16, 16))] {
            let mut seen = vec![0u8; (w * h) as usize];
            for tile in tiles(w, h, t) {
                for y in tile.y..tile.y + tile.height {
                    for x in tile.x..tile.x + tile.width {
                        seen[(y * w + x) as usize] += 1;
                    }
                }
            }
            assert!(seen.iter().all(|&n| n == 1), "{w}x{h} tiles {t:?}");
        }
    }

    #[test]
    fn pfm_header_and_row_order() {
        let f = Frame {
            width: 1,
            height: 2,
            linear: vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]],
        };
        let b = encode_pfm(&f);
        let head = b"PF\n1 2\n-1.0\n";
        assert_eq!(&b[..head.len()], head);
        // Bottom row first.
        assert_eq!(&b[head.len()..head.len() + 4], &4.0f32.to_le_bytes());
    }
}
