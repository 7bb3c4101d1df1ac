//! A distribution ray tracer (Cook, Porter, Carpenter 1984) on the kernel's queries: many rays
//! per pixel, each sampling a point on the pixel, the lens, the lights, the reflection lobe and
//! the shutter interval. `no_std`, no allocation, both number modes.
//!
//! - The caller owns the scene ([`Scene`]: objects, materials, lights, camera) and the memory
//!   ([`AccelMemory`](crate::AccelMemory) for the accelerators, sized by [`memory_needed`]; the framebuffer).
//! - [`Renderer::new`] checks the scene (typed [`SceneError`]s), builds one accelerator per
//!   object and derives the [`RenderPlan`]: the features the scene and settings need. Features
//!   the plan leaves out cost a branch, not work.
//! - [`Renderer::render_tile`] renders any rectangle of pixels. Every random value is a pure
//!   function of (pixel, sample, dimension, seed), so tiles can be rendered in any order, on
//!   any thread or core, and the image is the same bits.
//!
//! Geometry (rays, boxes, primitive tests, spawn offsets) runs in the mode `S`; shading runs in
//! `f32` in both modes (correctly rounded IEEE operations and `libm`, hence the same bits on
//! every platform). The time dimension, the lens, the pixel jitter and light samples use
//! separate dimension pairs of the sample stream ([`sampling`]).

mod camera;
mod emitters;
mod features;
mod geometry;
mod integrator;
mod lighting;
mod lights;
mod memory;
mod motion;
mod objects;
#[cfg(feature = "path-tracing")]
mod path;
pub mod sampling;
mod scene;
pub mod scenes;
mod srgb;
mod surface;
mod vector;

pub use features::{AllFeatures, RenderFeatures};
pub use lights::MAX_LIGHTS;
pub use memory::{memory_needed, RenderMemory, RenderMemoryNeeded};
pub use objects::ObjectSlot;
pub use sampling::SamplerKind;
pub use scene::{
    Camera, Filter, Integrator, Item, Light, Material, Object, Problem, Rgb, Scene, SceneError,
    Settings, Shape,
};
pub use srgb::encode_srgb8;
pub use surface::SPHERE_SPAWN_FACTOR;

use crate::accel::{AccelFamily, AnyFamily};
use crate::geom::Ray;
use crate::scalar::Scalar;
use camera::CameraFrame;
use core::fmt;
use core::marker::PhantomData;
use geometry::Geometry;
use glam::Vec3;
use sampling::Sampler;

/// What a render will do, derived once from the scene and settings. Features marked `false`
/// are skipped entirely (no samples drawn, no rays cast).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderPlan {
    /// Samples per pixel.
    pub spp: u32,
    /// One sample per pixel: it goes through the pixel centre (no jitter, no filter).
    pub pixel_centre: bool,
    /// Sample placement (irrelevant when `pixel_centre` and nothing else samples).
    pub sampler: SamplerKind,
    /// Pixel filter (when not `pixel_centre`).
    pub filter: Filter,
    /// Depth of field: the aperture is open, so camera rays sample the lens.
    pub lens: bool,
    /// Motion blur: some object moves, so rays carry a shutter time.
    pub motion: bool,
    /// Point lights (one shadow ray each per diffuse hit).
    pub point_lights: u32,
    /// Area lights (one sample and shadow ray each per diffuse hit: soft shadows).
    pub area_lights: u32,
    /// Light transport: [`Integrator::Direct`], or [`Integrator::Path`] with its length.
    pub integrator: Integrator,
    /// Some object emits ([`Object::emission`]): hits add its radiance.
    pub emitting_objects: bool,
    /// Some object emits (its [`Object::emission`] or an emissive material): next-event
    /// estimation samples its surfaces as area lights.
    pub emissive_geometry: bool,
    /// Some object is [`Object::one_sided`]: hits on a surface's back are checked (black, the
    /// path ends).
    pub one_sided: bool,
    /// Some object's material takes light (diffuse, mirror or glossy: anything but
    /// [`Material::Emissive`]), so lights and reflections can change what a camera ray sees.
    pub lit_surfaces: bool,
    /// Some radiance is found only by rays that hit it, not by sampling the lights: a
    /// background that is not black, an emissive material or an emitting object. Without it
    /// the path integrator ends a path at its last vertex once the lights are sampled.
    pub unsampled_emission: bool,
    /// Direct integrator: some object is mirror or glossy, so reflection rays are traced.
    pub reflections: bool,
    /// Direct integrator: some object is glossy, so reflection rays sample a lobe.
    pub glossy: bool,
    /// Direct integrator: most reflection bounces (0 without reflecting materials, and under
    /// the path integrator).
    pub max_depth: u32,
}

impl RenderPlan {
    /// True when camera rays are all a render casts: the direct integrator, one sample at each
    /// pixel centre, a pinhole, nothing moving, and nothing a light could reach: either no
    /// surface is lit (every object emits through its material), or there are no lights, no
    /// emissive geometry and nothing reflecting. The renderer then runs a first-hit loop
    /// without sample streams or a bounce loop (the same bits).
    #[must_use]
    pub const fn camera_rays_only(&self) -> bool {
        let unlit = !self.lit_surfaces
            || (!self.emissive_geometry
                && !self.reflections
                && self.point_lights == 0
                && self.area_lights == 0);
        matches!(self.integrator, Integrator::Direct)
            && self.pixel_centre
            && !self.lens
            && !self.motion
            && unlit
    }

    fn derive<S: Scalar>(scene: &Scene<'_, S>, settings: &Settings) -> Self {
        let used = |f: fn(&Material) -> bool| {
            scene
                .objects
                .iter()
                .any(|o| scene.materials.get(o.material as usize).is_some_and(f))
        };
        let direct = matches!(settings.integrator, Integrator::Direct);
        let emitting_objects = scene.objects.iter().any(|o| o.emission != [0.0; 3]);
        let reflections = direct && used(Material::reflects) && settings.max_depth > 0;
        let count = |area: bool| scene.lights.iter().filter(|l| l.is_area() == area).count() as u32;
        Self {
            spp: settings.spp,
            pixel_centre: settings.spp == 1,
            sampler: settings.sampler,
            filter: settings.filter,
            lens: scene.camera.aperture_radius > 0.0,
            motion: scene
                .objects
                .iter()
                .any(|o| o.moves() && !o.shape.is_empty()),
            point_lights: count(false),
            area_lights: count(true),
            integrator: settings.integrator,
            emitting_objects,
            emissive_geometry: scene.objects.iter().any(|o| {
                !o.shape.is_empty() && geometry::emitted_by(o, scene.materials) != [0.0; 3]
            }),
            one_sided: scene.objects.iter().any(|o| o.one_sided),
            lit_surfaces: scene.objects.iter().any(|o| {
                !o.shape.is_empty()
                    && scene
                        .materials
                        .get(o.material as usize)
                        .is_some_and(|m| !matches!(m, Material::Emissive { .. }))
            }),
            unsampled_emission: emitting_objects
                || scene.background != [0.0; 3]
                || used(|m| matches!(m, Material::Emissive { .. })),
            reflections,
            glossy: reflections && used(|m| matches!(m, Material::Glossy { .. })),
            max_depth: if reflections { settings.max_depth } else { 0 },
        }
    }
}

impl fmt::Display for RenderPlan {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let on = |b: bool| if b { "on" } else { "off" };
        if self.pixel_centre {
            write!(f, "anti-aliasing off (1 spp at pixel centres)")?;
        } else {
            write!(
                f,
                "anti-aliasing on ({} spp, {}, {} filter)",
                self.spp,
                self.sampler.name(),
                self.filter.name()
            )?;
        }
        write!(
            f,
            "; depth of field {}; motion blur {}; lights: {} point, {} area (soft shadows {})",
            on(self.lens),
            on(self.motion),
            self.point_lights,
            self.area_lights,
            on(self.area_lights > 0),
        )?;
        if self.emitting_objects {
            write!(f, "; emitting objects")?;
        }
        if self.emissive_geometry {
            write!(f, "; emissive geometry sampled as lights")?;
        }
        if self.one_sided {
            write!(f, "; one-sided surfaces")?;
        }
        match self.integrator {
            Integrator::Direct => write!(
                f,
                "; reflections {} (glossy {}, max depth {})",
                on(self.reflections),
                on(self.glossy),
                self.max_depth
            )?,
            Integrator::Path { max_length } => write!(
                f,
                "; path tracing (max length {max_length} segments, Russian roulette after {}, \
                 light and BSDF sampling with MIS)",
                Integrator::ROULETTE_AFTER
            )?,
        }
        if self.camera_rays_only() {
            write!(f, "; camera rays only (first-hit loop)")?;
        }
        Ok(())
    }
}

/// A rectangle of pixels: columns `x..x + width`, rows `y..y + height`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tile {
    /// First column.
    pub x: u32,
    /// First row (0 is the top).
    pub y: u32,
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
}

impl Tile {
    /// Calls `f(x, y, slot)` for the tile's pixels in row-major order, each with the next of
    /// `slots`, stopping when they run out. Two plain loops: a flattened iterator costs a few
    /// branches per pixel.
    #[cfg_attr(not(target_os = "none"), inline(always))]
    fn for_each_pixel<T>(self, mut slots: impl Iterator<Item = T>, mut f: impl FnMut(u32, u32, T)) {
        for y in self.y..self.y.saturating_add(self.height) {
            for x in self.x..self.x.saturating_add(self.width) {
                let Some(slot) = slots.next() else {
                    return;
                };
                f(x, y, slot);
            }
        }
    }
}

/// Rays a render cast.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RenderStats {
    /// Camera rays (one per pixel sample).
    pub camera_rays: u64,
    /// Shadow rays (any-hit).
    pub shadow_rays: u64,
    /// Reflection rays.
    pub reflection_rays: u64,
}

impl RenderStats {
    /// Every ray.
    #[must_use]
    pub const fn rays(&self) -> u64 {
        self.camera_rays + self.shadow_rays + self.reflection_rays
    }
    /// Sum of two counts.
    #[must_use]
    pub const fn add(self, o: Self) -> Self {
        Self {
            camera_rays: self.camera_rays + o.camera_rays,
            shadow_rays: self.shadow_rays + o.shadow_rays,
            reflection_rays: self.reflection_rays + o.reflection_rays,
        }
    }
}

/// A checked scene with its accelerators built, ready to render tiles. Every object's
/// accelerator is of the family `F`: [`AnyFamily`] chooses at run time; naming one structure's
/// family links that structure alone. Every family gives the same image, bit for bit (the
/// accelerators return the same closest hit, ties to the lowest id). `K` names the parts of
/// the renderer linked beyond its core ([`RenderFeatures`]; [`AllFeatures`] by default).
#[derive(Clone, Debug)]
pub struct Renderer<'a, S: Scalar, F: AccelFamily<S> = AnyFamily, K: RenderFeatures = AllFeatures> {
    geometry: Geometry<'a, S, F>,
    materials: &'a [Material],
    lights: &'a [Light],
    background: Rgb,
    camera: CameraFrame,
    /// The pinhole's ray along the view direction (`None` if the eye is outside the mode's
    /// range): every pinhole camera ray starts where it does, so the first-hit loop turns it
    /// into each of them with [`Ray::redirected_f32`].
    eye_ray: Option<Ray<S>>,
    settings: Settings,
    sampler: Sampler,
    plan: RenderPlan,
    features: PhantomData<K>,
}

impl<'a, S: Scalar, F: AccelFamily<S>> Renderer<'a, S, F> {
    /// Checks the scene and settings, builds every object's accelerator with `accel` into
    /// `memory` (at least what [`memory_needed`] gives) and derives the plan. Links every part
    /// of the renderer ([`AllFeatures`]); [`Renderer::with_features`] links fewer.
    ///
    /// # Errors
    /// A [`SceneError`] naming the item, its index, the field and the problem: bad settings,
    /// camera, material values or indices, light values, too many objects or lights, buffers
    /// too small, or a primitive the accelerator rejects (non-finite, out of range).
    pub fn new(
        scene: &Scene<'a, S>,
        settings: Settings,
        accel: F::Options,
        memory: RenderMemory<'a, S, F>,
    ) -> Result<Self, SceneError> {
        Self::with_features(scene, settings, accel, memory)
    }
}

impl<'a, S: Scalar, F: AccelFamily<S>, K: RenderFeatures> Renderer<'a, S, F, K> {
    /// As [`Renderer::new`], linking only the parts of the renderer `K` names.
    ///
    /// # Errors
    /// As [`Renderer::new`], and [`Problem::NotLinked`] for what the scene or settings need of
    /// the parts `K` leaves out.
    pub fn with_features(
        scene: &Scene<'a, S>,
        settings: Settings,
        accel: F::Options,
        memory: RenderMemory<'a, S, F>,
    ) -> Result<Self, SceneError> {
        check_settings(&settings)?;
        check_materials(scene)?;
        check_linked::<S, K>(scene, &settings)?;
        let camera = CameraFrame::new(&scene.camera, settings.width, settings.height)?;
        scene::check_rgb(scene.background, false)
            .map_err(|p| SceneError::new(Item::Settings, 0, "background", p))?;
        let geometry =
            Geometry::build::<K>(scene.objects, scene.materials, scene.lights, &accel, memory)?;
        Ok(Self {
            geometry,
            materials: scene.materials,
            lights: scene.lights,
            background: scene.background,
            eye_ray: camera.eye_ray(),
            camera,
            settings,
            sampler: Sampler::new(settings.sampler, settings.spp, settings.seed),
            plan: RenderPlan::derive(scene, &settings),
            features: PhantomData,
        })
    }

    /// True when the plan takes the first-hit loop and `K` links it.
    #[inline]
    fn first_hit_loop(&self) -> bool {
        K::FIRST_HIT_LOOP && self.plan.camera_rays_only()
    }

    /// The plan derived from the scene and settings.
    #[must_use]
    pub const fn plan(&self) -> &RenderPlan {
        &self.plan
    }

    /// The settings.
    #[must_use]
    pub const fn settings(&self) -> &Settings {
        &self.settings
    }

    /// Mean linear radiance of pixel `(x, y)` over its samples (no bounds check: pixels
    /// outside the image are rendered as if the image extended there).
    #[must_use]
    pub fn pixel(&self, x: u32, y: u32, stats: &mut RenderStats) -> Rgb {
        if self.first_hit_loop() {
            self.camera_ray_pixel(x, y, stats)
        } else {
            self.sampled_pixel(x, y, stats)
        }
    }

    /// [`Renderer::pixel`] under a plan of camera rays only.
    #[cfg_attr(not(target_os = "none"), inline(always))] // see `integrator::sample_radiance`
    fn camera_ray_pixel(&self, x: u32, y: u32, stats: &mut RenderStats) -> Rgb {
        // The mean of one sample, as `sampled_pixel` sums it.
        (Vec3::ZERO + integrator::camera_ray_radiance(self, x, y, stats)).to_array()
    }

    /// [`Renderer::pixel`] under any plan: every sample's path.
    #[cfg_attr(not(target_os = "none"), inline(always))] // see `integrator::sample_radiance`
    fn sampled_pixel(&self, x: u32, y: u32, stats: &mut RenderStats) -> Rgb {
        let index = y.wrapping_mul(self.settings.width).wrapping_add(x);
        let spp = self.settings.spp;
        let mut sum = Vec3::ZERO;
        match self.plan.integrator {
            Integrator::Direct => {
                for k in 0..spp {
                    let mut stream = self.sampler.stream(index, k);
                    sum += integrator::sample_radiance(self, x, y, &mut stream, stats);
                }
            }
            #[cfg(feature = "path-tracing")]
            Integrator::Path { max_length } => {
                for k in 0..spp {
                    let mut stream = self.sampler.stream(index, k);
                    sum += path::sample_radiance(self, x, y, max_length, &mut stream, stats);
                }
            }
            // Rejected by `Renderer::new` (`check_settings`).
            #[cfg(not(feature = "path-tracing"))]
            Integrator::Path { .. } => {}
        }
        // One sample: the mean is the sample (x / 1 is x, bit for bit).
        if spp == 1 {
            sum.to_array()
        } else {
            (sum / spp as f32).to_array()
        }
    }

    /// Each pixel of `tile` in row-major order with its slot of the output: `put` stores the
    /// colour. The per-pixel path is chosen once, from the plan.
    #[cfg_attr(not(target_os = "none"), inline(always))]
    fn fill<T>(
        &self,
        tile: Tile,
        slots: impl Iterator<Item = T>,
        stats: &mut RenderStats,
        mut put: impl FnMut(T, Rgb),
    ) {
        if self.first_hit_loop() {
            tile.for_each_pixel(slots, |x, y, slot| {
                put(slot, self.camera_ray_pixel(x, y, stats));
            });
        } else {
            tile.for_each_pixel(slots, |x, y, slot| {
                put(slot, self.sampled_pixel(x, y, stats));
            });
        }
    }

    /// Renders `tile` as linear RGB into `out` (row-major within the tile, `width·height`
    /// entries).
    ///
    /// # Errors
    /// [`Item::Tile`] errors for a tile outside the image or an `out` too small.
    pub fn render_tile(&self, tile: Tile, out: &mut [Rgb]) -> Result<RenderStats, SceneError> {
        let n = self.check_tile(tile, out.len(), 1)?;
        let mut stats = RenderStats::default();
        self.fill(tile, out.iter_mut().take(n), &mut stats, |px, c| *px = c);
        Ok(stats)
    }

    /// Renders `tile` as 8-bit sRGB into `out` (3 bytes per pixel, row-major within the tile).
    ///
    /// # Errors
    /// As [`Renderer::render_tile`].
    // Not inlined: one copy per mode in every binary, so its speed does not depend on how a
    // caller's code around it was compiled (inlined into callers it measured 10-15% apart).
    #[inline(never)]
    pub fn render_tile_srgb8(&self, tile: Tile, out: &mut [u8]) -> Result<RenderStats, SceneError> {
        let n = self.check_tile(tile, out.len(), 3)?;
        let mut stats = RenderStats::default();
        let slots = out.chunks_exact_mut(3).take(n);
        self.fill(tile, slots, &mut stats, |px, c| {
            for (b, v) in px.iter_mut().zip(c) {
                *b = encode_srgb8(v);
            }
        });
        Ok(stats)
    }

    /// The whole image as 8-bit sRGB, single-threaded: the reference the host's parallel
    /// renders must equal.
    ///
    /// # Errors
    /// As [`Renderer::render_tile`].
    pub fn render_srgb8(&self, out: &mut [u8]) -> Result<RenderStats, SceneError> {
        let tile = Tile {
            x: 0,
            y: 0,
            width: self.settings.width,
            height: self.settings.height,
        };
        self.render_tile_srgb8(tile, out)
    }

    /// Checks a tile against the image and a buffer of `len` entries of `per_pixel` units;
    /// returns the pixel count.
    fn check_tile(&self, t: Tile, len: usize, per_pixel: usize) -> Result<usize, SceneError> {
        let err = |field, p| SceneError::new(Item::Tile, 0, field, p);
        let s = &self.settings;
        let fits =
            |start: u32, size: u32, max: u32| start.checked_add(size).is_some_and(|e| e <= max);
        if !fits(t.x, t.width, s.width) {
            let p = Problem::OutOfRange {
                min: 0.0,
                max: s.width as f32,
            };
            return Err(err("width", p));
        }
        if !fits(t.y, t.height, s.height) {
            let p = Problem::OutOfRange {
                min: 0.0,
                max: s.height as f32,
            };
            return Err(err("height", p));
        }
        let n = t.width as usize * t.height as usize;
        let needed = n.saturating_mul(per_pixel);
        if len < needed {
            return Err(err(
                "out",
                Problem::TooSmall {
                    needed,
                    available: len,
                },
            ));
        }
        Ok(n)
    }
}

fn check_settings(s: &Settings) -> Result<(), SceneError> {
    let err = |field, p| Err(SceneError::new(Item::Settings, 0, field, p));
    if s.width == 0 {
        return err("width", Problem::NotPositive);
    }
    if s.height == 0 {
        return err("height", Problem::NotPositive);
    }
    if s.spp == 0 {
        return err("spp", Problem::NotPositive);
    }
    if s.width.checked_mul(s.height).is_none() {
        let p = Problem::OutOfRange {
            min: 1.0,
            max: u32::MAX as f32,
        };
        return err("height", p);
    }
    if let Filter::Gaussian { sigma, radius } = s.filter {
        for (field, v, max) in [
            ("filter_sigma", sigma, f32::MAX),
            ("filter_radius", radius, Filter::MAX_RADIUS),
        ] {
            if !v.is_finite() {
                return err(field, Problem::NonFinite);
            }
            if v <= 0.0 {
                return err(field, Problem::NotPositive);
            }
            if v > max {
                return err(field, Problem::OutOfRange { min: 0.0, max });
            }
        }
    }
    if let Integrator::Path { max_length } = s.integrator {
        if !cfg!(feature = "path-tracing") {
            return err("integrator", Problem::NotLinked);
        }
        if max_length == 0 {
            return err("max_length", Problem::NotPositive);
        }
    }
    Ok(())
}

/// Refuses what the scene or settings need of the parts `K` leaves out.
fn check_linked<S: Scalar, K: RenderFeatures>(
    scene: &Scene<'_, S>,
    settings: &Settings,
) -> Result<(), SceneError> {
    if !K::FILTERS && !matches!(settings.filter, Filter::Box) {
        return Err(SceneError::new(
            Item::Settings,
            0,
            "filter",
            Problem::NotLinked,
        ));
    }
    for (i, l) in scene.lights.iter().enumerate() {
        let field = match l {
            Light::Point { .. } if !K::POINT_LIGHTS => "point",
            Light::Sphere { .. } if !K::SPHERE_LIGHTS => "sphere",
            _ => continue,
        };
        return Err(SceneError::new(Item::Light, i, field, Problem::NotLinked));
    }
    for (i, o) in scene.objects.iter().enumerate() {
        let field = if !K::ONE_SIDED && o.one_sided {
            "one_sided"
        } else if !K::SMOOTH_SHADING && !o.vertex_normals.is_empty() {
            "vertex_normals"
        } else if K::EMISSIVE_GEOMETRY || o.shape.is_empty() {
            continue;
        } else if o.emission != [0.0; 3] {
            "emission"
        } else if geometry::emitted_by(o, scene.materials) != [0.0; 3] {
            "material"
        } else {
            continue;
        };
        return Err(SceneError::new(Item::Object, i, field, Problem::NotLinked));
    }
    Ok(())
}

fn check_materials<S: Scalar>(scene: &Scene<'_, S>) -> Result<(), SceneError> {
    for (i, m) in scene.materials.iter().enumerate() {
        let err = |field, p| SceneError::new(Item::Material, i, field, p);
        match *m {
            Material::Diffuse { albedo } => {
                scene::check_rgb(albedo, true).map_err(|p| err("albedo", p))?;
            }
            Material::Mirror { reflectance } => {
                scene::check_rgb(reflectance, true).map_err(|p| err("reflectance", p))?;
            }
            Material::Glossy {
                reflectance,
                exponent,
            } => {
                scene::check_rgb(reflectance, true).map_err(|p| err("reflectance", p))?;
                if !exponent.is_finite() {
                    return Err(err("exponent", Problem::NonFinite));
                }
                if exponent < 1.0 {
                    let p = Problem::OutOfRange {
                        min: 1.0,
                        max: f32::MAX,
                    };
                    return Err(err("exponent", p));
                }
            }
            Material::Emissive { radiance } => {
                scene::check_rgb(radiance, false).map_err(|p| err("radiance", p))?;
            }
        }
    }
    for (i, o) in scene.objects.iter().enumerate() {
        if o.material as usize >= scene.materials.len() {
            let p = Problem::Index {
                len: scene.materials.len(),
            };
            return Err(SceneError::new(Item::Object, i, "material", p));
        }
    }
    Ok(())
}
