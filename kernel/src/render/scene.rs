//! Scene data the caller owns: objects (triangle meshes or spheres, each with a material and an
//! optional linear motion), materials, lights, camera, and render settings.
//!
//! Radiometry: every colour is linear RGB. Reflectances are in `[0, 1]`. Emitted radiance
//! (emissive materials, area lights, the background) is in radiance units (W·sr⁻¹·m⁻² per
//! channel); point lights give radiant intensity (W·sr⁻¹). A pixel's linear value is the mean
//! radiance through it; [`crate::render::encode_srgb8`] maps `[0, 1]` to 8-bit sRGB (values above
//! 1 clip).

use super::sampling::SamplerKind;
use crate::geom::{Sphere, Triangle};
use crate::scalar::Scalar;
use core::fmt;

/// Linear RGB.
pub type Rgb = [f32; 3];

/// How a surface scatters or emits light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Material {
    /// Lambertian. The direct integrator lights it by the lights alone (no interreflection, as
    /// in Cook et al.); the path integrator also by every other surface.
    Diffuse {
        /// Reflectance per channel, in `[0, 1]`.
        albedo: Rgb,
    },
    /// Perfect specular reflection.
    Mirror {
        /// Reflectance per channel, in `[0, 1]`.
        reflectance: Rgb,
    },
    /// Glossy reflection: a normalised Phong lobe `(n+1)/(2π)·cos^n α` around the mirror
    /// direction, sampled exactly (each reflection ray carries weight `reflectance`; samples
    /// below the surface are absorbed).
    Glossy {
        /// Reflectance per channel, in `[0, 1]`.
        reflectance: Rgb,
        /// Lobe exponent `n >= 1`: larger is sharper.
        exponent: f32,
    },
    /// Emits `radiance` (from both sides unless the object is [`Object::one_sided`]) and
    /// reflects nothing. An area light: seen by camera and reflection rays, sampled by
    /// next-event estimation in both integrators (the direct one lights diffuse surfaces by
    /// it), casting shadows like any surface. A surface that both emits and reflects is any
    /// other material with [`Object::emission`].
    Emissive {
        /// Emitted radiance per channel, `>= 0`.
        radiance: Rgb,
    },
}

impl Material {
    /// True for mirror and glossy materials (the ones that spawn reflection rays).
    #[must_use]
    pub const fn reflects(&self) -> bool {
        matches!(self, Self::Mirror { .. } | Self::Glossy { .. })
    }
}

/// The geometry of an object.
#[derive(Clone, Copy, Debug)]
pub enum Shape<'a, S: Scalar> {
    /// A triangle mesh.
    Triangles(&'a [Triangle<S>]),
    /// A set of spheres.
    Spheres(&'a [Sphere<S>]),
}

impl<S: Scalar> Shape<'_, S> {
    /// Number of primitives.
    #[must_use]
    pub const fn len(&self) -> usize {
        match self {
            Self::Triangles(t) => t.len(),
            Self::Spheres(s) => s.len(),
        }
    }
    /// True if the shape has no primitives.
    #[must_use]
    pub const fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// A mesh or a set of spheres with one material, static or moving.
#[derive(Clone, Copy, Debug)]
pub struct Object<'a, S: Scalar> {
    /// Geometry, at shutter open.
    pub shape: Shape<'a, S>,
    /// Index into [`Scene::materials`].
    pub material: u32,
    /// Displacement from shutter open to shutter close (linear motion); zero for a static
    /// object. At shutter time `s ∈ [0, 1)` the object sits at its position plus `s·motion`.
    pub motion: [f32; 3],
    /// Radiance every surface of the object emits, per channel `>= 0`, on top of what its
    /// material reflects; from both sides unless [`Object::one_sided`]. An area light, as an
    /// emissive material is ([`Material::Emissive`]). Zero for most objects.
    pub emission: Rgb,
    /// One-sided: the object reflects and emits only on the front of its surfaces, the side
    /// the geometric normal points to (a triangle's `(v1 − v0) × (v2 − v0)`: its vertices run
    /// counter-clockwise seen from the front; a sphere's outside). Seen from behind it is
    /// black, and it blocks light from both sides. `false` (two-sided, the default): both
    /// sides reflect and emit alike.
    pub one_sided: bool,
    /// Smooth shading: for each triangle of a [`Shape::Triangles`] shape, the normals at its
    /// three vertices (any length; interpolated by the hit's barycentrics and normalised), or
    /// empty for flat shading. A triangle whose normals are all zero is shaded flat. The
    /// geometric normal still decides offsets, sidedness and which directions leave the surface.
    pub vertex_normals: &'a [[[f32; 3]; 3]],
}

impl<'a, S: Scalar> Object<'a, S> {
    /// A static object.
    #[must_use]
    pub const fn new(shape: Shape<'a, S>, material: u32) -> Self {
        Self {
            shape,
            material,
            motion: [0.0; 3],
            emission: [0.0; 3],
            one_sided: false,
            vertex_normals: &[],
        }
    }
    /// True if the object moves during the shutter interval.
    #[must_use]
    pub fn moves(&self) -> bool {
        self.motion != [0.0; 3]
    }
}

/// A light source: sampled explicitly at diffuse surfaces (shadow rays).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// A point light (hard shadows); invisible to camera and reflection rays.
    Point {
        /// Position.
        position: [f32; 3],
        /// Radiant intensity per channel (W·sr⁻¹), `>= 0`.
        intensity: Rgb,
    },
    /// A parallelogram `corner + a·edge_u + b·edge_v`, `a, b ∈ [0, 1]`, emitting `radiance` from
    /// the side `edge_u × edge_v` points to. Visible to camera and reflection rays from that
    /// side; it casts no shadow itself.
    Rect {
        /// One corner.
        corner: [f32; 3],
        /// First edge.
        edge_u: [f32; 3],
        /// Second edge.
        edge_v: [f32; 3],
        /// Emitted radiance per channel, `>= 0`.
        radiance: Rgb,
    },
    /// A sphere emitting `radiance` outwards: soft shadows by sampling its visible cone.
    /// Visible to camera and reflection rays; casts no shadow itself.
    Sphere {
        /// Centre.
        center: [f32; 3],
        /// Radius, `> 0`.
        radius: f32,
        /// Emitted radiance per channel, `>= 0`.
        radiance: Rgb,
    },
}

impl Light {
    /// True for rectangle and sphere lights.
    #[must_use]
    pub const fn is_area(&self) -> bool {
        !matches!(self, Self::Point { .. })
    }
}

/// A thin-lens camera; `aperture_radius == 0` is a pinhole.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye (lens centre).
    pub eye: [f32; 3],
    /// A point on the optical axis.
    pub look_at: [f32; 3],
    /// Up hint (not parallel to the view direction).
    pub up: [f32; 3],
    /// Full vertical field of view, degrees, in `(0, 180)`.
    pub vfov_deg: f32,
    /// Lens radius (world units), `>= 0`.
    pub aperture_radius: f32,
    /// Distance from the eye to the plane in focus, `> 0` (ignored for a pinhole).
    pub focus_distance: f32,
}

/// Pixel reconstruction filter, applied by importance sampling (every sample has weight 1).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Filter {
    /// Uniform over the pixel.
    #[default]
    Box,
    /// Triangle filter of radius one pixel.
    Tent,
    /// Gaussian of standard deviation `sigma` pixels about the pixel centre, per axis,
    /// truncated at `radius` pixels (a square support: the product of two truncated 1D
    /// Gaussians).
    Gaussian {
        /// Standard deviation, pixels (finite, `> 0`).
        sigma: f32,
        /// Truncation radius, pixels (finite, `> 0`, at most [`Filter::MAX_RADIUS`]).
        radius: f32,
    },
}

impl Filter {
    /// Largest Gaussian truncation radius, pixels.
    pub const MAX_RADIUS: f32 = 16.0;

    /// Lower-case name as used on command lines.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::Box => "box",
            Self::Tent => "tent",
            Self::Gaussian { .. } => "gaussian",
        }
    }
}

/// The light transport a render computes.
///
/// Path length counts segments, camera ray included (the convention of Mitsuba's `max_depth`;
/// pbrt's `maxdepth` counts bounces, one fewer): length 1 sees emitters, 2 adds direct light,
/// each more adds one bounce of indirect light. [`Settings::max_depth`] is the direct
/// integrator's limit on mirror and glossy bounces only; the path integrator ignores it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Integrator {
    /// Distribution ray tracing: camera rays, mirror and glossy reflections up to
    /// [`Settings::max_depth`], and at the first diffuse surface the lights' direct light.
    #[default]
    Direct,
    /// Path tracing: diffuse, glossy and mirror bounces; at every non-mirror vertex each light
    /// is sampled (next-event estimation) and the BSDF is sampled, the two combined by multiple
    /// importance sampling (power heuristic); Russian roulette once a path has
    /// [`Integrator::ROULETTE_AFTER`] segments.
    ///
    /// Linked only with the kernel's `path-tracing` feature; without it the variant still
    /// exists (scene files and settings keep one shape) and [`crate::render::Renderer::new`]
    /// rejects it with a [`SceneError`] on [`Item::Settings`], field `integrator`,
    /// [`Problem::NotLinked`].
    Path {
        /// Most segments of a path (`>= 1`).
        max_length: u32,
    },
}

impl Integrator {
    /// Segments a path has before Russian roulette may end it.
    pub const ROULETTE_AFTER: u32 = 3;

    /// Lower-case name as used on command lines and in scene files.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::Direct => "direct",
            Self::Path { .. } => "path",
        }
    }
}

/// Image and sampling settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// Image width, pixels (`>= 1`).
    pub width: u32,
    /// Image height, pixels (`>= 1`).
    pub height: u32,
    /// Samples per pixel (`>= 1`); 1 samples the pixel centre.
    pub spp: u32,
    /// Most mirror and glossy bounces after the camera ray ([`Integrator::Direct`] only).
    pub max_depth: u32,
    /// Light transport.
    pub integrator: Integrator,
    /// Sample placement.
    pub sampler: SamplerKind,
    /// Pixel filter.
    pub filter: Filter,
    /// Seed of every random value: renders with equal seeds are equal bit for bit.
    pub seed: u32,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            width: 64,
            height: 64,
            spp: 16,
            max_depth: 4,
            integrator: Integrator::Direct,
            sampler: SamplerKind::Stratified,
            filter: Filter::Box,
            seed: 0,
        }
    }
}

/// Everything a render needs, borrowed from the caller.
#[derive(Clone, Copy, Debug)]
pub struct Scene<'a, S: Scalar> {
    /// Geometry.
    pub objects: &'a [Object<'a, S>],
    /// Materials, referenced by index from objects.
    pub materials: &'a [Material],
    /// Lights.
    pub lights: &'a [Light],
    /// Camera.
    pub camera: Camera,
    /// Radiance of rays that leave the scene.
    pub background: Rgb,
}

/// Which part of the scene or settings a [`SceneError`] is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Item {
    /// `Scene::objects[index]`.
    Object,
    /// `Scene::materials[index]`.
    Material,
    /// `Scene::lights[index]`.
    Light,
    /// The camera (index 0).
    Camera,
    /// The render settings (index 0).
    Settings,
    /// A render tile (index 0).
    Tile,
}

/// What is wrong with a value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Problem {
    /// NaN or infinite.
    NonFinite,
    /// Must not be negative.
    Negative,
    /// Must be at most 1.
    AboveOne,
    /// Must be greater than zero.
    NotPositive,
    /// Outside the accepted range `[min, max]`.
    OutOfRange {
        /// Lowest accepted value.
        min: f32,
        /// Highest accepted value.
        max: f32,
    },
    /// The edges span no area (zero or parallel).
    ZeroArea,
    /// A direction of zero length, or `up` parallel to the view direction.
    Degenerate,
    /// An index past the end of the list it refers to, which has `len` entries.
    Index {
        /// The list's length.
        len: usize,
    },
    /// More entries than the fixed capacity `max`.
    TooMany {
        /// The capacity.
        max: usize,
    },
    /// A caller buffer of `available` slots where `needed` are required.
    TooSmall {
        /// Slots required.
        needed: usize,
        /// Slots given.
        available: usize,
    },
    /// A primitive could not be built into the accelerator.
    Build(crate::accel::BuildError),
    /// A list whose length must be `expected` (for example one entry per triangle).
    Length {
        /// The length required.
        expected: usize,
    },
    /// A part of the renderer this build leaves out: a kind of primitive the accelerator
    /// family does not link ([`crate::AccelFamily::SPHERES`]), or [`Integrator::Path`] without
    /// the kernel's `path-tracing` feature.
    NotLinked,
}

/// Bad scene data, settings or render call: which item, which field, and what is wrong.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneError {
    /// The list or part the error is in.
    pub item: Item,
    /// Index within that list (0 for camera, settings, tile).
    pub index: usize,
    /// The field's name as in the Rust struct (also the scene file's key).
    pub field: &'static str,
    /// What is wrong.
    pub problem: Problem,
}

impl SceneError {
    pub(crate) const fn new(
        item: Item,
        index: usize,
        field: &'static str,
        problem: Problem,
    ) -> Self {
        Self {
            item,
            index,
            field,
            problem,
        }
    }
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NonFinite => write!(f, "must be a finite number"),
            Self::Negative => write!(f, "must not be negative"),
            Self::AboveOne => write!(f, "must be at most 1"),
            Self::NotPositive => write!(f, "must be greater than zero"),
            Self::OutOfRange { min, max } => write!(f, "must lie in [{min}, {max}]"),
            Self::ZeroArea => write!(f, "edges must span a non-zero area"),
            Self::Degenerate => {
                write!(f, "must be a non-zero direction not parallel to the view")
            }
            Self::Index { len } => write!(f, "index out of range (the list has {len} entries)"),
            Self::TooMany { max } => write!(f, "too many entries (at most {max})"),
            Self::TooSmall { needed, available } => {
                write!(f, "buffer too small: need {needed} slots, have {available}")
            }
            Self::Length { expected } => write!(f, "must have {expected} entries"),
            Self::Build(e) => write!(f, "{e}"),
            Self::NotLinked => write!(f, "this renderer is built without it"),
        }
    }
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let item = match self.item {
            Item::Object => "object",
            Item::Material => "material",
            Item::Light => "light",
            Item::Camera => "camera",
            Item::Settings => "settings",
            Item::Tile => "tile",
        };
        match self.item {
            Item::Camera | Item::Settings | Item::Tile => {
                write!(f, "{item} `{}`: {}", self.field, self.problem)
            }
            _ => write!(
                f,
                "{item} {} `{}`: {}",
                self.index, self.field, self.problem
            ),
        }
    }
}

impl core::error::Error for SceneError {}

/// Checks that every component is finite.
pub(crate) fn finite3(v: [f32; 3]) -> bool {
    v.iter().all(|x| x.is_finite())
}

/// Checks a colour: finite, non-negative, and at most 1 if `reflectance`.
pub(crate) fn check_rgb(c: Rgb, reflectance: bool) -> Result<(), Problem> {
    for x in c {
        if !x.is_finite() {
            return Err(Problem::NonFinite);
        }
        if x < 0.0 {
            return Err(Problem::Negative);
        }
        if reflectance && x > 1.0 {
            return Err(Problem::AboveOne);
        }
    }
    Ok(())
}
