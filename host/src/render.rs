//! `host render`: a primary-ray renderer on the kernel. One ray through each pixel centre,
//! Lambert shading (two-sided geometric normal) under one directional light with a hard shadow
//! ray (`occluded`), a small ambient term, and a background gradient; 8-bit sRGB PNG out.
//!
//! Hits come from the kernel in the chosen number mode; the colour arithmetic is `f32` on the
//! host. Pixels are independent, so the image is the same bytes for any thread count.

use crate::error::Error;
use crate::rayfile::FileError;
use crate::scene::{bounds, cross, normalize, Scene};
use crate::trace::Mode;
use raykernel::bvh::{nodes_needed, BuildOptions};
use raykernel::{Accel, Bvh, Node, Ray, Scalar, Triangle, I16F16};
use std::path::Path;
use std::sync::Mutex;
use std::time::Instant;

/// What to render and how.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RenderConfig {
    /// Image width in pixels (at least 1).
    pub width: u32,
    /// Image height in pixels (at least 1).
    pub height: u32,
    /// Number mode of the kernel.
    pub mode: Mode,
    /// Worker threads (at least 1; more than the rows are not started).
    pub threads: usize,
    /// BVH builder and leaf size.
    pub build: BuildOptions,
}

/// Figures of a render.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RenderStats {
    /// Triangles in the scene.
    pub triangles: usize,
    /// Wall time of the BVH build (primitives put in leaf order).
    pub build_ms: f64,
    /// Wall time of shading every pixel (all threads).
    pub render_ms: f64,
    /// Primary rays (one per pixel).
    pub primary_rays: u64,
    /// Shadow rays (one per lit-facing hit).
    pub shadow_rays: u64,
    /// Primary rays that hit.
    pub hits: u64,
    /// Threads used.
    pub threads: usize,
}

impl RenderStats {
    /// Primary and shadow rays.
    #[must_use]
    pub fn rays(&self) -> u64 {
        self.primary_rays + self.shadow_rays
    }

    /// Million rays per second of render time.
    #[must_use]
    pub fn mrays_per_s(&self) -> f64 {
        if self.render_ms > 0.0 {
            self.rays() as f64 / (self.render_ms / 1e3) / 1e6
        } else {
            0.0
        }
    }
}

/// A rendered image: `width * height` RGB pixels, 8-bit sRGB, rows top to bottom.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `3 * width * height` bytes.
    pub rgb: Vec<u8>,
}

/// Renders `scene`.
///
/// # Errors
/// [`Error::Obj`] for a vertex the mode cannot represent, [`Error::Build`] if the kernel
/// refuses to build, [`Error::Usage`] if the camera cannot be used (e.g. its eye lies outside
/// the fixed-point range).
///
/// # Panics
/// If `config.threads`, `config.width` or `config.height` is 0.
pub fn render(scene: &Scene, config: &RenderConfig) -> Result<(Image, RenderStats), Error> {
    match config.mode {
        Mode::F32 => render_in::<f32>(scene, config),
        Mode::Fixed => render_in::<I16F16>(scene, config),
    }
}

fn render_in<S: Scalar>(
    scene: &Scene,
    config: &RenderConfig,
) -> Result<(Image, RenderStats), Error> {
    assert!(config.threads > 0 && config.width > 0 && config.height > 0);
    let label = Path::new(&scene.name);
    let mut tris: Vec<Triangle<S>> = match &scene.obj {
        Some((path, mesh)) => mesh.kernel_triangles::<S>(path)?,
        None => scene
            .triangles
            .iter()
            .map(|&v| Triangle::from_f32(v))
            .collect::<Result<_, _>>()
            .map_err(|(corner, e)| {
                Error::Usage(format!("{label:?}: vertex {corner} unusable: {e}"))
            })?,
    };
    let shader = Shader::new(scene, config)?;
    // The eye must be a usable ray origin in this mode.
    let (eye, dir) = shader.view.ray(config.width / 2, config.height / 2);
    Ray::<S>::from_f32(eye, dir, 0.0, f32::INFINITY).map_err(|e| {
        Error::Usage(format!(
            "{}: camera eye {eye:?} unusable in {} mode: {e}",
            scene.name,
            S::NAME
        ))
    })?;

    let mut nodes = vec![Node::<S>::EMPTY; nodes_needed(tris.len())];
    let mut ids = vec![0u32; tris.len()];
    let start = Instant::now();
    let bvh = Bvh::build_in_leaf_order(&mut tris, &mut nodes, &mut ids, config.build).map_err(
        |source| Error::Build {
            scene: label.to_path_buf(),
            source,
        },
    )?;
    let build_ms = start.elapsed().as_secs_f64() * 1e3;

    let (w, h) = (config.width as usize, config.height as usize);
    let mut rgb = vec![0u8; 3 * w * h];
    let threads = config.threads.min(h);
    let start = Instant::now();
    let counts = {
        // Rows are handed out one at a time, so uneven rows balance across threads.
        let rows = Mutex::new(rgb.chunks_mut(3 * w).enumerate());
        let work = || {
            let mut counts = Counts::default();
            loop {
                let next = rows.lock().unwrap_or_else(|e| e.into_inner()).next();
                let Some((y, row)) = next else { break };
                for (x, px) in row.chunks_exact_mut(3).enumerate() {
                    let c = shader.pixel(&bvh, x as u32, y as u32, &mut counts);
                    px.copy_from_slice(&c.map(to_srgb8));
                }
            }
            counts
        };
        std::thread::scope(|s| {
            let handles: Vec<_> = (0..threads).map(|_| s.spawn(work)).collect();
            handles
                .into_iter()
                .map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
                .fold(Counts::default(), Counts::add)
        })
    };
    let render_ms = start.elapsed().as_secs_f64() * 1e3;
    let stats = RenderStats {
        triangles: tris.len(),
        build_ms,
        render_ms,
        primary_rays: counts.primary,
        shadow_rays: counts.shadow,
        hits: counts.hits,
        threads,
    };
    let image = Image {
        width: config.width,
        height: config.height,
        rgb,
    };
    Ok((image, stats))
}

#[derive(Clone, Copy, Default)]
struct Counts {
    primary: u64,
    shadow: u64,
    hits: u64,
}

impl Counts {
    fn add(self, o: Self) -> Self {
        Self {
            primary: self.primary + o.primary,
            shadow: self.shadow + o.shadow,
            hits: self.hits + o.hits,
        }
    }
}

/// Ambient light (fraction of the albedo every visible surface gets).
const AMBIENT: f32 = 0.12;
/// Extra ambient on surfaces facing up (a hint of sky light).
const SKY: f32 = 0.1;
/// Strength of the directional light.
const SUN: f32 = 0.9;

/// Everything per-pixel shading needs except the accelerator.
struct Shader<'s> {
    scene: &'s Scene,
    view: crate::scene::View,
    /// Unit vector towards the light.
    light: [f32; 3],
    /// The camera's up: background gradient and sky term.
    up: [f32; 3],
    /// How far shadow rays start off the surface.
    offset: f32,
}

impl<'s> Shader<'s> {
    fn new(scene: &'s Scene, config: &RenderConfig) -> Result<Self, Error> {
        let view = scene
            .camera
            .view(config.width, config.height)
            .ok_or_else(|| Error::Usage(format!("{}: unusable camera", scene.name)))?;
        let light = scene.light.unwrap_or_else(|| {
            // Above and behind the camera, a little to its left.
            let (u, f, r) = (view.up(), view.forward(), view.right());
            normalize(std::array::from_fn(|k| {
                1.6 * u[k] - 0.7 * f[k] - 0.5 * r[k]
            }))
        });
        // Off the surface by a small fraction of the scene, and by several fixed-point units.
        let (lo, hi) = bounds(&scene.triangles);
        let extent = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max);
        let offset = (extent * 2e-4).max(16.0 / 65536.0) as f32;
        Ok(Self {
            scene,
            view,
            light: light.map(|x| x as f32),
            up: view.up().map(|x| x as f32),
            offset,
        })
    }

    /// Linear RGB of pixel (`x`, `y`).
    fn pixel<S: Scalar, A: Accel<S>>(&self, accel: &A, x: u32, y: u32, n: &mut Counts) -> [f32; 3] {
        let (o, d) = self.view.ray(x, y);
        n.primary += 1;
        let hit = Ray::<S>::from_f32(o, d, 0.0, f32::INFINITY)
            .ok()
            .and_then(|ray| accel.intersect(&ray));
        let Some(hit) = hit else {
            return self.background(d);
        };
        n.hits += 1;
        let id = hit.prim as usize;
        let [a, b, c] = self.scene.triangles[id];
        let (u, v) = (hit.u.to_f32(), hit.v.to_f32());
        let w = 1.0 - u - v;
        let p: [f32; 3] = std::array::from_fn(|k| w * a[k] + u * b[k] + v * c[k]);
        // Geometric normal, turned towards the viewer (triangles are two-sided).
        let e1: [f32; 3] = std::array::from_fn(|k| b[k] - a[k]);
        let e2: [f32; 3] = std::array::from_fn(|k| c[k] - a[k]);
        let mut normal = unit(cross3(e1, e2)).unwrap_or(d.map(|x| -x));
        if dot(normal, d) > 0.0 {
            normal = normal.map(|x| -x);
        }
        let facing = dot(normal, self.light);
        let mut sun = 0.0;
        if facing > 0.0 {
            n.shadow += 1;
            let origin: [f32; 3] = std::array::from_fn(|k| p[k] + self.offset * normal[k]);
            let blocked = Ray::<S>::from_f32(origin, self.light, 0.0, f32::INFINITY)
                .is_ok_and(|ray| accel.occluded(&ray));
            if !blocked {
                sun = facing;
            }
        }
        let sky = 0.5 + 0.5 * dot(normal, self.up);
        let light = AMBIENT + SKY * sky + SUN * sun;
        self.scene.albedo[id].map(|a| a * light)
    }

    /// Sky gradient by the direction's height: pale at the horizon and below, blue above.
    fn background(&self, d: [f32; 3]) -> [f32; 3] {
        let s = dot(d, self.up).clamp(0.0, 1.0);
        let (horizon, zenith) = ([0.80, 0.84, 0.90], [0.22, 0.38, 0.70]);
        std::array::from_fn(|k| horizon[k] + (zenith[k] - horizon[k]) * s)
    }
}

fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross3(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    let c = cross(a.map(f64::from), b.map(f64::from));
    c.map(|x| x as f32)
}

fn unit(a: [f32; 3]) -> Option<[f32; 3]> {
    let l = dot(a, a).sqrt();
    (l > 0.0 && l.is_finite()).then(|| a.map(|x| x / l))
}

/// Linear `[0, 1]` to an 8-bit sRGB value (clamped; NaN is 0).
#[must_use]
pub fn to_srgb8(c: f32) -> u8 {
    let c = if c.is_nan() { 0.0 } else { c.clamp(0.0, 1.0) };
    let s = if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    // In [0, 255.5): the cast neither saturates nor wraps.
    (s * 255.0 + 0.5) as u8
}

/// The PNG bytes of `image` (8-bit RGB, marked sRGB).
///
/// # Errors
/// [`Error::Usage`] if the encoder refuses (it does not for a well-formed image).
pub fn encode_png(image: &Image) -> Result<Vec<u8>, Error> {
    let mut out = Vec::new();
    let mut enc = png::Encoder::new(&mut out, image.width, image.height);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    let fail = |e: png::EncodingError| Error::Usage(format!("cannot encode PNG: {e}"));
    let mut writer = enc.write_header().map_err(fail)?;
    writer.write_image_data(&image.rgb).map_err(fail)?;
    writer.finish().map_err(fail)?;
    Ok(out)
}

/// Writes `image` as a PNG file.
///
/// # Errors
/// As [`encode_png`], or [`FileError::Write`].
pub fn write_png(path: &Path, image: &Image) -> Result<(), Error> {
    let bytes = encode_png(image)?;
    std::fs::write(path, bytes).map_err(|source| {
        Error::File(FileError::Write {
            path: path.to_path_buf(),
            source,
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_endpoints_and_midtones() {
        assert_eq!(to_srgb8(0.0), 0);
        assert_eq!(to_srgb8(1.0), 255);
        assert_eq!(to_srgb8(2.0), 255);
        assert_eq!(to_srgb8(-1.0), 0);
        assert_eq!(to_srgb8(f32::NAN), 0);
        // Linear 0.5 is sRGB 0.7354 -> 187.5 + 0.5 -> 188; 0.2 is sRGB 0.4845 -> 124.
        assert_eq!(to_srgb8(0.5), 188);
        assert_eq!(to_srgb8(0.2), 124);
        assert_eq!(to_srgb8(0.003), 10); // linear segment: 12.92 * 0.003 * 255 = 9.88
        let mut last = 0;
        for i in 0..=1000 {
            let v = to_srgb8(i as f32 / 1000.0);
            assert!(v >= last);
            last = v;
        }
    }
}
