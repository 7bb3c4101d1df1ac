//! Scene files: a versioned JSON format for scenes written by hand or by other tools (documented
//! in `docs/SCENE_FORMAT.md`), loaded into a [`SceneSpec`], and the dump of any kernel
//! [`SceneData`] (every built-in scene) into the same format.
//!
//! Every struct denies unknown fields, so a misspelt key is an error, not a silent default.
//! A file is at most [`MAX_SCENE_FILE_BYTES`] of UTF-8 (a leading byte-order mark is
//! skipped), and its lists are bounded by [`crate::limits`] before any mesh is read.
//! Errors name the file, the field as a path (`objects[2].spheres[0].radius`, from
//! `serde_path_to_error`) and what was expected; values the kernel rejects are reported the
//! same way ([`SceneSpec::explain`]).

use crate::error::{shorten_long_words, Error};
use crate::input::read_text_limited;
use crate::limits::{
    check_count, OverLimit, MAX_MATERIALS, MAX_OBJECTS, MAX_SCENE_FILE_BYTES, MAX_SPHERES,
    MAX_TRIANGLES,
};
use crate::obj::load_obj;
use crate::spec::{eye_to_look_at, ObjectSource, SceneOrigin, SceneSpec};
use raykernel::render::scenes::{ObjectData, SceneData, ShapeRange, SphereData};
use raykernel::render::MAX_LIGHTS;
use raykernel::render::{Camera, Filter, Integrator, Light, Material, SamplerKind, Settings};
use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::collections::HashMap;
use std::path::{Component, Path, PathBuf};

/// The `format` key every scene file starts with.
pub const FORMAT: &str = "raykernel-scene";
/// The version this reader reads and the dump writes.
pub const VERSION: u32 = 1;
/// Longest word (key, value, token) an error message quotes from a file whole.
const QUOTE_CHARS: usize = 80;

/// Settings for fields a scene file leaves out (and for OBJ scenes).
pub const DEFAULT_SETTINGS: Settings = Settings {
    width: 512,
    height: 512,
    spp: 64,
    max_depth: 4,
    integrator: Integrator::Direct,
    sampler: SamplerKind::Sobol,
    filter: Filter::Box,
    seed: 0,
};

/// Path length (segments) of the path integrator when a file or flag names it without one:
/// four bounces.
pub const DEFAULT_MAX_PATH_LENGTH: u32 = 5;

/// A whole scene file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// Always `raykernel-scene`.
    pub format: String,
    /// Always 1 (this reader's [`VERSION`]).
    pub version: u32,
    /// Short name (defaults to the file's stem).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// The camera.
    pub camera: CameraEntry,
    /// Radiance of rays that leave the scene (default black).
    #[serde(default)]
    pub background: [f32; 3],
    /// Render settings (each optional).
    #[serde(default)]
    pub settings: SettingsEntry,
    /// Named materials.
    pub materials: Vec<MaterialEntry>,
    /// Objects.
    pub objects: Vec<ObjectEntry>,
    /// Lights (default none).
    #[serde(default)]
    pub lights: Vec<LightEntry>,
}

/// `camera`: a thin lens (pinhole when `aperture_radius` is 0).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraEntry {
    /// Lens centre.
    pub eye: [f32; 3],
    /// A point on the optical axis.
    pub look_at: [f32; 3],
    /// Up hint (default +y).
    #[serde(default = "up_y")]
    pub up: [f32; 3],
    /// Full vertical field of view, degrees.
    pub vfov_deg: f32,
    /// Lens radius, world units (default 0: pinhole).
    #[serde(default)]
    pub aperture_radius: f32,
    /// Distance to the plane in focus (default: from `eye` to `look_at`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub focus_distance: Option<f32>,
}

fn up_y() -> [f32; 3] {
    [0.0, 1.0, 0.0]
}

/// `settings`: every field optional ([`DEFAULT_SETTINGS`]).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SettingsEntry {
    /// Image width, pixels.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub width: Option<u32>,
    /// Image height, pixels.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub height: Option<u32>,
    /// Samples per pixel.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spp: Option<u32>,
    /// Most mirror and glossy bounces (direct integrator).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_depth: Option<u32>,
    /// Light transport.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub integrator: Option<IntegratorName>,
    /// Most segments of a path, camera ray included (path integrator).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_path_length: Option<u32>,
    /// Sample placement.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sampler: Option<SamplerName>,
    /// Pixel filter.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub filter: Option<FilterName>,
    /// Gaussian filter: standard deviation, pixels.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub filter_sigma: Option<f32>,
    /// Gaussian filter: truncation radius, pixels.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub filter_radius: Option<f32>,
    /// Seed of every random value.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seed: Option<u32>,
}

/// `settings.integrator`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum IntegratorName {
    /// Distribution ray tracing: direct light at the first diffuse surface.
    Direct,
    /// Path tracing with light sampling and MIS.
    Path,
}

impl IntegratorName {
    /// The name of `integrator`.
    #[must_use]
    pub const fn of(integrator: Integrator) -> Self {
        match integrator {
            Integrator::Direct => Self::Direct,
            Integrator::Path { .. } => Self::Path,
        }
    }
}

/// The integrator `name` and `max_length` ask for over `base` (each `None` keeps `base`'s; a
/// path integrator named over a direct one gets [`DEFAULT_MAX_PATH_LENGTH`]; a length under
/// the direct integrator is kept for nothing).
#[must_use]
pub fn integrator_over(
    name: Option<IntegratorName>,
    max_length: Option<u32>,
    base: Integrator,
) -> Integrator {
    let base_length = match base {
        Integrator::Path { max_length } => max_length,
        Integrator::Direct => DEFAULT_MAX_PATH_LENGTH,
    };
    match name.unwrap_or(IntegratorName::of(base)) {
        IntegratorName::Direct => Integrator::Direct,
        IntegratorName::Path => Integrator::Path {
            max_length: max_length.unwrap_or(base_length),
        },
    }
}

/// `settings.sampler`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum SamplerName {
    /// Independent uniform values.
    Independent,
    /// Jittered grid.
    Stratified,
    /// Owen-scrambled Sobol.
    Sobol,
}

impl From<SamplerName> for SamplerKind {
    fn from(s: SamplerName) -> Self {
        match s {
            SamplerName::Independent => Self::Independent,
            SamplerName::Stratified => Self::Stratified,
            SamplerName::Sobol => Self::Sobol,
        }
    }
}

impl From<SamplerKind> for SamplerName {
    fn from(s: SamplerKind) -> Self {
        match s {
            SamplerKind::Independent => Self::Independent,
            SamplerKind::Stratified => Self::Stratified,
            SamplerKind::Sobol => Self::Sobol,
        }
    }
}

/// `settings.filter`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum FilterName {
    /// Uniform over the pixel.
    Box,
    /// Triangle of radius one pixel.
    Tent,
    /// Truncated Gaussian (`filter_sigma`, `filter_radius`).
    Gaussian,
}

impl From<Filter> for FilterName {
    fn from(f: Filter) -> Self {
        match f {
            Filter::Box => Self::Box,
            Filter::Tent => Self::Tent,
            Filter::Gaussian { .. } => Self::Gaussian,
        }
    }
}

/// The Gaussian filter's standard deviation when none is given, pixels.
pub const DEFAULT_FILTER_SIGMA: f32 = 0.5;
/// The Gaussian filter's truncation radius when none is given, pixels.
pub const DEFAULT_FILTER_RADIUS: f32 = 1.5;

/// The filter `name`, `sigma` and `radius` ask for over `base` (each `None` keeps `base`'s; a
/// Gaussian named over another filter gets [`DEFAULT_FILTER_SIGMA`] and
/// [`DEFAULT_FILTER_RADIUS`]; parameters under another filter are kept for nothing).
#[must_use]
pub fn filter_over(
    name: Option<FilterName>,
    sigma: Option<f32>,
    radius: Option<f32>,
    base: Filter,
) -> Filter {
    let (base_sigma, base_radius) = match base {
        Filter::Gaussian { sigma, radius } => (sigma, radius),
        _ => (DEFAULT_FILTER_SIGMA, DEFAULT_FILTER_RADIUS),
    };
    match name.unwrap_or(FilterName::from(base)) {
        FilterName::Box => Filter::Box,
        FilterName::Tent => Filter::Tent,
        FilterName::Gaussian => Filter::Gaussian {
            sigma: sigma.unwrap_or(base_sigma),
            radius: radius.unwrap_or(base_radius),
        },
    }
}

/// One entry of `materials`: a name and exactly one kind.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialEntry {
    /// The name objects refer to it by (unique).
    pub name: String,
    /// Lambertian.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub diffuse: Option<Diffuse>,
    /// Perfect mirror.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mirror: Option<Mirror>,
    /// Phong lobe around the mirror direction.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub glossy: Option<Glossy>,
    /// Emits radiance, reflects nothing.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub emissive: Option<Emissive>,
}

/// `diffuse`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Diffuse {
    /// Reflectance per channel, `[0, 1]`.
    pub albedo: [f32; 3],
}

/// `mirror`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Mirror {
    /// Reflectance per channel, `[0, 1]`.
    pub reflectance: [f32; 3],
}

/// `glossy`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Glossy {
    /// Reflectance per channel, `[0, 1]`.
    pub reflectance: [f32; 3],
    /// Phong exponent, `>= 1` (larger is sharper).
    pub exponent: f32,
}

/// `emissive`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Emissive {
    /// Emitted radiance per channel (W·sr⁻¹·m⁻²), `>= 0`.
    pub radiance: [f32; 3],
}

/// One entry of `objects`: exactly one of `mesh`, `triangles`, `spheres`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectEntry {
    /// An OBJ file, relative to the scene file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mesh: Option<String>,
    /// Triangles written out: three `[x, y, z]` corners each.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub triangles: Option<Vec<[[f32; 3]; 3]>>,
    /// Smooth shading of `triangles`: the normals at each triangle's three corners, one entry
    /// per triangle (all zero for a triangle shaded flat). A `mesh` takes its normals from the
    /// OBJ file's `vn`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vertex_normals: Option<Vec<[[f32; 3]; 3]>>,
    /// Spheres.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spheres: Option<Vec<SphereEntry>>,
    /// Placement of a mesh or of triangles (not spheres).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub transform: Option<Transform>,
    /// The material's name.
    pub material: String,
    /// Displacement over the shutter interval (default none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motion: Option<[f32; 3]>,
    /// Radiance the object's surfaces emit on top of what the material reflects (default
    /// none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub emission: Option<[f32; 3]>,
    /// Reflects and emits on the front of its surfaces only (the side a triangle's
    /// counter-clockwise winding faces, a sphere's outside); black from behind (default
    /// `false`: two-sided).
    #[serde(default, skip_serializing_if = "is_false")]
    pub one_sided: bool,
}

#[allow(clippy::trivially_copy_pass_by_ref)] // serde's `skip_serializing_if` passes a reference
fn is_false(b: &bool) -> bool {
    !*b
}

/// A sphere.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SphereEntry {
    /// Centre.
    pub center: [f32; 3],
    /// Radius, `>= 0`.
    pub radius: f32,
}

/// `transform`: scale, then rotate about x, then y, then z, then translate.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Transform {
    /// Uniform (a number) or per-axis (`[sx, sy, sz]`) scale.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale: Option<Scale>,
    /// Rotations in degrees about the x, y and z axes (right-handed), applied in that order.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotate_deg: Option<[f64; 3]>,
    /// Translation.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub translate: Option<[f64; 3]>,
}

/// A scale factor: one number or one per axis.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged, expecting = "a number or an array of 3 numbers")]
pub enum Scale {
    /// The same on every axis.
    Uniform(f64),
    /// Per axis.
    PerAxis([f64; 3]),
}

impl Transform {
    /// The transformed point, computed in `f64` and rounded to `f32` once.
    #[must_use]
    pub fn apply(&self, p: [f32; 3]) -> [f32; 3] {
        let s = self.scale_factors();
        let mut q: [f64; 3] = std::array::from_fn(|k| f64::from(p[k]) * s[k]);
        self.rotate(&mut q);
        let t = self.translate.unwrap_or([0.0; 3]);
        std::array::from_fn(|k| (q[k] + t[k]) as f32)
    }

    /// A surface normal transformed as the surface is (by the inverse transpose: the scale's
    /// inverse, then the rotations), in `f64` and rounded to `f32` once; zero if a scale is
    /// zero. Its length is not kept (the kernel normalises).
    #[must_use]
    pub fn apply_normal(&self, n: [f32; 3]) -> [f32; 3] {
        let s = self.scale_factors();
        if s.contains(&0.0) {
            return [0.0; 3];
        }
        let mut q: [f64; 3] = std::array::from_fn(|k| f64::from(n[k]) / s[k]);
        self.rotate(&mut q);
        q.map(|x| x as f32)
    }

    /// The scale per axis (1 without one).
    fn scale_factors(&self) -> [f64; 3] {
        match self.scale {
            None => [1.0; 3],
            Some(Scale::Uniform(s)) => [s; 3],
            Some(Scale::PerAxis(s)) => s,
        }
    }

    /// Applies the rotations about x, then y, then z.
    fn rotate(&self, q: &mut [f64; 3]) {
        if let Some(r) = self.rotate_deg {
            for (axis, deg) in r.iter().enumerate() {
                let (sin, cos) = deg.to_radians().sin_cos();
                // The two coordinates the rotation about `axis` mixes, in right-handed order.
                let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
                let (x, y) = (q[a], q[b]);
                q[a] = cos * x - sin * y;
                q[b] = sin * x + cos * y;
            }
        }
    }
}

/// One entry of `lights`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase", deny_unknown_fields)]
pub enum LightEntry {
    /// A point light.
    Point {
        /// Position.
        position: [f32; 3],
        /// Radiant intensity per channel (W·sr⁻¹).
        intensity: [f32; 3],
    },
    /// A parallelogram emitting towards `edge_u × edge_v`.
    Rect {
        /// One corner.
        corner: [f32; 3],
        /// First edge.
        edge_u: [f32; 3],
        /// Second edge.
        edge_v: [f32; 3],
        /// Radiance (W·sr⁻¹·m⁻²).
        radiance: [f32; 3],
    },
    /// A sphere emitting outwards.
    Sphere {
        /// Centre.
        center: [f32; 3],
        /// Radius, `> 0`.
        radius: f32,
        /// Radiance (W·sr⁻¹·m⁻²).
        radiance: [f32; 3],
    },
}

/// Only `format` and `version`: read first, so a file of another version gets that message
/// rather than one about fields this reader does not know.
#[derive(Deserialize)]
struct Header {
    format: Option<Value>,
    version: Option<Value>,
}

/// Reads and checks a scene file: JSON syntax and types, names, references, and every value
/// the kernel checks (in `f32`; the fixed-point range is checked when rendering in that mode).
///
/// # Errors
/// [`Error::Scene`] naming the file, the field and the problem; [`Error::File`] if the file
/// cannot be read. Meshes that cannot be read or parsed are reported at their `mesh` field.
pub fn load_scene_file(path: &Path) -> Result<SceneSpec, Error> {
    let text = read_text_limited(path, MAX_SCENE_FILE_BYTES).map_err(|e| Error::Scene {
        file: path.display().to_string(),
        field: String::new(),
        msg: format!("cannot read: {e}"),
    })?;
    parse_scene_file(&text, path)
}

/// Parses scene-file text; `path` names the file in errors and anchors relative mesh paths.
///
/// # Errors
/// As [`load_scene_file`].
pub fn parse_scene_file(text: &str, path: &Path) -> Result<SceneSpec, Error> {
    // Keys and values quoted from the file are cut to a readable length.
    let err = |field: &str, msg: String| Error::Scene {
        file: path.display().to_string(),
        field: shorten_long_words(field, QUOTE_CHARS),
        msg: shorten_long_words(&msg, QUOTE_CHARS),
    };
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    if let Some(found) = not_an_object(text) {
        return Err(err(
            "",
            format!("a scene file is one JSON object `{{ ... }}`, but this file holds {found}"),
        ));
    }
    let header: Header = serde_json::from_str(text).map_err(|e| err("", e.to_string()))?;
    match header.format {
        Some(Value::String(f)) if f == FORMAT => {}
        Some(other) => {
            return Err(err(
                "format",
                format!("expected \"{FORMAT}\", found {other}"),
            ))
        }
        None => {
            return Err(err(
                "format",
                format!("missing: a scene file starts with \"format\": \"{FORMAT}\""),
            ))
        }
    }
    match header.version {
        Some(Value::Number(n)) if n.as_u64() == Some(u64::from(VERSION)) => {}
        Some(other) => {
            return Err(err(
                "version",
                format!("this reader reads version {VERSION}, found {other}"),
            ))
        }
        None => return Err(err("version", format!("missing: expected {VERSION}"))),
    }
    let mut de = serde_json::Deserializer::from_str(text);
    let file: SceneFile = serde_path_to_error::deserialize(&mut de).map_err(|e| {
        let field = e.path().to_string();
        let field = if field == "." { String::new() } else { field };
        err(&field, without_type_names(&e.into_inner().to_string()))
    })?;
    check_lists(&file).map_err(|e| err(e.field, e.msg))?;
    let stem = path
        .file_stem()
        .map_or("scene".into(), |s| s.to_string_lossy().into_owned());
    let spec = resolve(file, path, &stem)?;
    check_in_kernel(&spec)?;
    Ok(spec)
}

/// What a text that is not a JSON object starts with (`an array`, `a string`, ...), or `None`
/// for an object (or an empty text, which the JSON reader reports).
fn not_an_object(text: &str) -> Option<&'static str> {
    let first = text.trim_start().chars().next()?;
    Some(match first {
        '{' => return None,
        '[' => "an array",
        '"' => "a string",
        '-' | '0'..='9' => "a number",
        't' | 'f' => "a boolean",
        'n' => "null",
        _ => "no JSON value",
    })
}

/// A reader's message without the Rust type names it may quote (`expected struct
/// CameraEntry` becomes `expected a JSON object`).
fn without_type_names(msg: &str) -> String {
    let mut out = msg.to_string();
    for (prefix, plain) in [
        ("expected struct ", "expected a JSON object"),
        ("expected enum ", "expected a JSON object with one key"),
    ] {
        while let Some(at) = out.find(prefix) {
            let rest = &out[at + prefix.len()..];
            let end = rest
                .find(|c: char| !(c.is_alphanumeric() || c == '_'))
                .unwrap_or(rest.len());
            out = format!("{}{plain}{}", &out[..at], &rest[end..]);
        }
    }
    out
}

/// Bounds on the file's lists ([`crate::limits`]), checked before any mesh is read.
fn check_lists(file: &SceneFile) -> Result<(), OverLimit> {
    check_count(
        "materials",
        "materials",
        file.materials.len(),
        MAX_MATERIALS,
    )?;
    check_count("objects", "objects", file.objects.len(), MAX_OBJECTS)?;
    check_count("lights", "lights", file.lights.len(), MAX_LIGHTS)?;
    let inline = |f: fn(&ObjectEntry) -> usize| file.objects.iter().map(f).sum::<usize>();
    let triangles = inline(|o| o.triangles.as_ref().map_or(0, Vec::len));
    check_count("objects", "inline triangles", triangles, MAX_TRIANGLES)?;
    let spheres = inline(|o| o.spheres.as_ref().map_or(0, Vec::len));
    check_count("objects", "spheres", spheres, MAX_SPHERES)
}

/// Checks `spec` the way the kernel will: the camera as in
/// [`SceneSpec::check_camera`], then an `f32` renderer built over it with brute force (no
/// memory needed), any error mapped back to the scene's fields.
///
/// # Errors
/// [`SceneSpec::explain`] of the kernel's error.
pub fn check_in_kernel(spec: &SceneSpec) -> Result<(), Error> {
    spec.check_camera("f32")?;
    crate::render::with_renderer::<f32, _>(
        &spec.data(),
        spec.settings,
        raykernel::AccelKind::Linear,
        |_| (),
    )
    .map(|_| ())
    .map_err(|e| spec.explain(&e, "f32"))
}

/// Turns parsed entries into owned scene data: names to indices, meshes read and placed.
fn resolve(file: SceneFile, path: &Path, stem: &str) -> Result<SceneSpec, Error> {
    let err = |field: String, msg: String| Error::Scene {
        file: path.display().to_string(),
        field,
        msg,
    };
    let mut materials = Vec::with_capacity(file.materials.len());
    let mut names: Vec<String> = Vec::with_capacity(file.materials.len());
    let mut index_of: HashMap<&str, usize> = HashMap::with_capacity(file.materials.len());
    for (i, m) in file.materials.iter().enumerate() {
        let here = format!("materials[{i}] ({:?})", m.name);
        if index_of.insert(&m.name, i).is_some() {
            return Err(err(
                here,
                "duplicate name: material names must be unique".into(),
            ));
        }
        let kinds = [
            m.diffuse.map(|d| Material::Diffuse { albedo: d.albedo }),
            m.mirror.map(|d| Material::Mirror {
                reflectance: d.reflectance,
            }),
            m.glossy.map(|d| Material::Glossy {
                reflectance: d.reflectance,
                exponent: d.exponent,
            }),
            m.emissive.map(|d| Material::Emissive {
                radiance: d.radiance,
            }),
        ];
        let mut given = kinds.iter().flatten();
        match (given.next(), given.next()) {
            (Some(k), None) => materials.push(*k),
            _ => {
                return Err(err(
                    here,
                    "expected exactly one of `diffuse`, `mirror`, `glossy`, `emissive`".into(),
                ))
            }
        }
        names.push(m.name.clone());
    }

    let base = path.parent().unwrap_or(Path::new("."));
    let mut spec = SceneSpec {
        name: file.name.clone().unwrap_or_else(|| stem.to_string()),
        origin: SceneOrigin::File(path.to_path_buf()),
        triangles: Vec::new(),
        vertex_normals: Vec::new(),
        spheres: Vec::new(),
        objects: Vec::with_capacity(file.objects.len()),
        object_sources: Vec::with_capacity(file.objects.len()),
        materials,
        material_names: names,
        lights: file.lights.iter().map(|l| light(*l)).collect(),
        camera: camera(&file.camera),
        background: file.background,
        settings: settings(&file.settings, DEFAULT_SETTINGS),
    };
    for (i, o) in file.objects.iter().enumerate() {
        let here = |field: &str| format!("objects[{i}]{field}");
        let Some(&material) = index_of.get(o.material.as_str()) else {
            let mut known = spec
                .material_names
                .iter()
                .take(10)
                .map(|n| format!("{n:?}"))
                .collect::<Vec<_>>()
                .join(", ");
            if spec.material_names.len() > 10 {
                known.push_str(&format!(", … {} in all", spec.material_names.len()));
            }
            return Err(err(
                here(".material"),
                format!("no material named {:?} (materials: {known})", o.material),
            ));
        };
        let transform = o.transform.unwrap_or_default();
        let first_tri = spec.triangles.len();
        let (shape, source) = match (&o.mesh, &o.triangles, &o.spheres) {
            (Some(mesh), None, None) => {
                let obj_path = base.join(mesh);
                let m = load_obj(&obj_path).map_err(|e| err(here(".mesh"), e.to_string()))?;
                check_count(
                    "objects",
                    "triangles",
                    spec.triangles.len() + m.triangle_count(),
                    MAX_TRIANGLES,
                )
                .map_err(|e| err(here(".mesh"), e.msg))?;
                let mut lines = Vec::with_capacity(m.triangle_count());
                for (t, corners) in m.triangles.iter().enumerate() {
                    spec.triangles
                        .push(m.triangle_f32(t).map(|p| transform.apply(p)));
                    lines.push(corners.map(|c| m.position_lines[c as usize]));
                }
                if m.has_normals() {
                    let normals = (0..m.triangle_count()).map(|t| m.vertex_normals(t));
                    add_normals(&mut spec, first_tri, normals, &transform);
                }
                let source = ObjectSource::Mesh {
                    path: obj_path,
                    vertex_lines: lines,
                    transform: o.transform,
                };
                (tri_range(first_tri, spec.triangles.len()), source)
            }
            (None, Some(tris), None) => {
                spec.triangles
                    .extend(tris.iter().map(|t| t.map(|p| transform.apply(p))));
                if let Some(normals) = &o.vertex_normals {
                    if normals.len() != tris.len() {
                        return Err(err(
                            here(".vertex_normals"),
                            format!(
                                "{} entries for {} triangles: give one `[n0, n1, n2]` per \
                                 triangle",
                                normals.len(),
                                tris.len()
                            ),
                        ));
                    }
                    add_normals(&mut spec, first_tri, normals.iter().copied(), &transform);
                }
                (
                    tri_range(first_tri, spec.triangles.len()),
                    ObjectSource::Inline,
                )
            }
            (None, None, Some(spheres)) => {
                if o.vertex_normals.is_some() {
                    return Err(err(
                        here(".vertex_normals"),
                        "applies to `triangles` objects only".into(),
                    ));
                }
                if o.transform.is_some() {
                    return Err(err(
                        here(".transform"),
                        "applies to `mesh` and `triangles` objects only (place spheres by \
                         their centres)"
                            .into(),
                    ));
                }
                let first = spec.spheres.len();
                spec.spheres.extend(spheres.iter().map(|s| SphereData {
                    center: s.center,
                    radius: s.radius,
                }));
                let shape = ShapeRange::Spheres {
                    first: index_u32(first),
                    count: index_u32(spheres.len()),
                };
                (shape, ObjectSource::Inline)
            }
            _ => {
                return Err(err(
                    here(""),
                    "expected exactly one of `mesh`, `triangles`, `spheres`".into(),
                ))
            }
        };
        spec.objects.push(ObjectData {
            shape,
            material: index_u32(material),
            motion: o.motion.unwrap_or([0.0; 3]),
            emission: o.emission.unwrap_or([0.0; 3]),
            one_sided: o.one_sided,
        });
        spec.object_sources.push(source);
    }
    if !spec.vertex_normals.is_empty() {
        spec.vertex_normals
            .resize(spec.triangles.len(), [[0.0; 3]; 3]);
    }
    Ok(spec)
}

/// Appends the vertex normals of the triangles from `first` on, placed by `transform`; the
/// triangles before them without normals are shaded flat (zero normals).
fn add_normals(
    spec: &mut SceneSpec,
    first: usize,
    normals: impl Iterator<Item = [[f32; 3]; 3]>,
    transform: &Transform,
) {
    spec.vertex_normals.resize(first, [[0.0; 3]; 3]);
    spec.vertex_normals
        .extend(normals.map(|t| t.map(|n| transform.apply_normal(n))));
}

/// Indices into host vectors fit `u32` for any scene that fits in memory; saturate otherwise
/// (the kernel then reports the range as out of bounds).
fn index_u32(i: usize) -> u32 {
    u32::try_from(i).unwrap_or(u32::MAX)
}

fn tri_range(first: usize, end: usize) -> ShapeRange {
    ShapeRange::Triangles {
        first: index_u32(first),
        count: index_u32(end - first),
    }
}

fn camera(c: &CameraEntry) -> Camera {
    let focus = c
        .focus_distance
        .unwrap_or_else(|| eye_to_look_at(c.eye, c.look_at));
    Camera {
        eye: c.eye,
        look_at: c.look_at,
        up: c.up,
        vfov_deg: c.vfov_deg,
        aperture_radius: c.aperture_radius,
        focus_distance: focus,
    }
}

/// `entry`'s settings over `base`.
#[must_use]
pub fn settings(entry: &SettingsEntry, base: Settings) -> Settings {
    Settings {
        width: entry.width.unwrap_or(base.width),
        height: entry.height.unwrap_or(base.height),
        spp: entry.spp.unwrap_or(base.spp),
        max_depth: entry.max_depth.unwrap_or(base.max_depth),
        integrator: integrator_over(entry.integrator, entry.max_path_length, base.integrator),
        sampler: entry.sampler.map_or(base.sampler, Into::into),
        filter: filter_over(
            entry.filter,
            entry.filter_sigma,
            entry.filter_radius,
            base.filter,
        ),
        seed: entry.seed.unwrap_or(base.seed),
    }
}

fn light(l: LightEntry) -> Light {
    match l {
        LightEntry::Point {
            position,
            intensity,
        } => Light::Point {
            position,
            intensity,
        },
        LightEntry::Rect {
            corner,
            edge_u,
            edge_v,
            radiance,
        } => Light::Rect {
            corner,
            edge_u,
            edge_v,
            radiance,
        },
        LightEntry::Sphere {
            center,
            radius,
            radiance,
        } => Light::Sphere {
            center,
            radius,
            radiance,
        },
    }
}

/// The scene-file form of kernel scene data: geometry inline, materials named by
/// `material_names` (or `m0`, `m1`, ... where absent), every setting written out.
#[must_use]
pub fn to_scene_file(d: &SceneData<'_>, material_names: &[String]) -> SceneFile {
    let name = |i: usize| {
        material_names
            .get(i)
            .cloned()
            .unwrap_or_else(|| format!("m{i}"))
    };
    let materials = d
        .materials
        .iter()
        .enumerate()
        .map(|(i, m)| {
            let mut e = MaterialEntry {
                name: name(i),
                diffuse: None,
                mirror: None,
                glossy: None,
                emissive: None,
            };
            match *m {
                Material::Diffuse { albedo } => e.diffuse = Some(Diffuse { albedo }),
                Material::Mirror { reflectance } => e.mirror = Some(Mirror { reflectance }),
                Material::Glossy {
                    reflectance,
                    exponent,
                } => {
                    e.glossy = Some(Glossy {
                        reflectance,
                        exponent,
                    });
                }
                Material::Emissive { radiance } => e.emissive = Some(Emissive { radiance }),
            }
            e
        })
        .collect();
    let slice = |first: u32, count: u32, len: usize| {
        let a = (first as usize).min(len);
        a..(a + count as usize).min(len)
    };
    let objects = d
        .objects
        .iter()
        .map(|o| {
            let (triangles, vertex_normals, spheres) = match o.shape {
                ShapeRange::Triangles { first, count } => {
                    let normals = d
                        .vertex_normals
                        .get(slice(first, count, d.vertex_normals.len()))
                        .filter(|n| n.iter().flatten().any(|c| *c != [0.0; 3]))
                        .map(<[_]>::to_vec);
                    (
                        Some(d.triangles[slice(first, count, d.triangles.len())].to_vec()),
                        normals,
                        None,
                    )
                }
                ShapeRange::Spheres { first, count } => (
                    None,
                    None,
                    Some(
                        d.spheres[slice(first, count, d.spheres.len())]
                            .iter()
                            .map(|s| SphereEntry {
                                center: s.center,
                                radius: s.radius,
                            })
                            .collect(),
                    ),
                ),
            };
            ObjectEntry {
                mesh: None,
                triangles,
                vertex_normals,
                spheres,
                transform: None,
                material: name(o.material as usize),
                motion: (o.motion != [0.0; 3]).then_some(o.motion),
                emission: (o.emission != [0.0; 3]).then_some(o.emission),
                one_sided: o.one_sided,
            }
        })
        .collect();
    let lights = d
        .lights
        .iter()
        .map(|l| match *l {
            Light::Point {
                position,
                intensity,
            } => LightEntry::Point {
                position,
                intensity,
            },
            Light::Rect {
                corner,
                edge_u,
                edge_v,
                radiance,
            } => LightEntry::Rect {
                corner,
                edge_u,
                edge_v,
                radiance,
            },
            Light::Sphere {
                center,
                radius,
                radiance,
            } => LightEntry::Sphere {
                center,
                radius,
                radiance,
            },
        })
        .collect();
    let s = d.settings;
    let c = d.camera;
    SceneFile {
        format: FORMAT.into(),
        version: VERSION,
        name: Some(d.name.to_string()),
        camera: CameraEntry {
            eye: c.eye,
            look_at: c.look_at,
            up: c.up,
            vfov_deg: c.vfov_deg,
            aperture_radius: c.aperture_radius,
            focus_distance: Some(c.focus_distance),
        },
        background: d.background,
        settings: SettingsEntry {
            width: Some(s.width),
            height: Some(s.height),
            spp: Some(s.spp),
            max_depth: Some(s.max_depth),
            // Written for the path integrator only (files of direct scenes stay as they were).
            integrator: matches!(s.integrator, Integrator::Path { .. })
                .then_some(IntegratorName::Path),
            max_path_length: match s.integrator {
                Integrator::Path { max_length } => Some(max_length),
                Integrator::Direct => None,
            },
            sampler: Some(s.sampler.into()),
            filter: Some(s.filter.into()),
            filter_sigma: match s.filter {
                Filter::Gaussian { sigma, .. } => Some(sigma),
                _ => None,
            },
            filter_radius: match s.filter {
                Filter::Gaussian { radius, .. } => Some(radius),
                _ => None,
            },
            seed: Some(s.seed),
        },
        materials,
        objects,
        lights,
    }
}

/// The scene-file form of `spec`, to be written at `scene_file`: as [`to_scene_file`], except
/// that an object read from an OBJ file names that file (relative to `scene_file`'s directory)
/// and its transform instead of listing its triangles.
#[must_use]
pub fn spec_to_scene_file(spec: &SceneSpec, scene_file: &Path) -> SceneFile {
    let mut file = to_scene_file(&spec.data(), &spec.material_names);
    for (entry, source) in file.objects.iter_mut().zip(&spec.object_sources) {
        if let ObjectSource::Mesh {
            path, transform, ..
        } = source
        {
            entry.triangles = None;
            entry.vertex_normals = None;
            entry.mesh = Some(relative_path(path, scene_file));
            entry.transform = *transform;
        }
    }
    file
}

/// `target` relative to the directory of `scene_file` when both resolve to canonical paths,
/// else `target` as given.
fn relative_path(target: &Path, scene_file: &Path) -> String {
    let dir = scene_file
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let (Ok(target_abs), Ok(dir_abs)) = (target.canonicalize(), dir.canonicalize()) else {
        return target.display().to_string();
    };
    let t: Vec<Component<'_>> = target_abs.components().collect();
    let d: Vec<Component<'_>> = dir_abs.components().collect();
    let common = t.iter().zip(&d).take_while(|(a, b)| a == b).count();
    let mut rel = PathBuf::new();
    for _ in common..d.len() {
        rel.push("..");
    }
    for c in &t[common..] {
        rel.push(c);
    }
    rel.display().to_string()
}

/// The scene file text of `d` (see [`to_scene_file`] and [`scene_file_text`]).
#[must_use]
pub fn dump(d: &SceneData<'_>, material_names: &[String]) -> String {
    scene_file_text(&to_scene_file(d, material_names))
}

/// `file` as text: pretty-printed, with number arrays (points, colours, triangles) kept on
/// one line, every `f32` written in its shortest round-trip form.
#[must_use]
pub fn scene_file_text(file: &SceneFile) -> String {
    // A struct of numbers, strings and options: serialization cannot fail.
    let value = serde_json::to_value(file).unwrap_or(Value::Null);
    let mut out = String::new();
    pretty(&value, 0, &mut out);
    out.push('\n');
    out
}

/// True for a number, or an array of numbers, or an array of arrays of numbers.
fn flat(v: &Value, depth: u32) -> bool {
    match v {
        Value::Number(_) => true,
        Value::Array(a) => depth < 2 && a.iter().all(|x| flat(x, depth + 1)),
        _ => false,
    }
}

fn pretty(v: &Value, indent: usize, out: &mut String) {
    let pad = |n: usize| "  ".repeat(n);
    match v {
        Value::Object(map) if !map.is_empty() => {
            out.push_str("{\n");
            for (i, (k, x)) in map.iter().enumerate() {
                out.push_str(&pad(indent + 1));
                out.push_str(&Value::String(k.clone()).to_string());
                out.push_str(": ");
                pretty(x, indent + 1, out);
                out.push_str(if i + 1 < map.len() { ",\n" } else { "\n" });
            }
            out.push_str(&pad(indent));
            out.push('}');
        }
        Value::Array(a) if !a.is_empty() && !flat(v, 0) => {
            out.push_str("[\n");
            for (i, x) in a.iter().enumerate() {
                out.push_str(&pad(indent + 1));
                pretty(x, indent + 1, out);
                out.push_str(if i + 1 < a.len() { ",\n" } else { "\n" });
            }
            out.push_str(&pad(indent));
            out.push(']');
        }
        Value::Array(a) => {
            out.push('[');
            for (i, x) in a.iter().enumerate() {
                if i > 0 {
                    out.push_str(", ");
                }
                pretty(x, indent, out);
            }
            out.push(']');
        }
        // Every float in a scene file is an f32 widened to f64 (exactly): print the f32's
        // shortest round-trip form.
        Value::Number(n) if n.is_f64() => {
            let x = n.as_f64().unwrap_or(0.0) as f32;
            out.push_str(&format!("{x:?}"));
        }
        other => out.push_str(&other.to_string()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transform_scales_rotates_then_translates() {
        let t = Transform {
            scale: Some(Scale::Uniform(2.0)),
            rotate_deg: Some([0.0, 90.0, 0.0]),
            translate: Some([1.0, 0.0, 0.0]),
        };
        // (1,0,0) -> (2,0,0) -> about y by 90°: x -> -z -> (0,0,-2) -> (1,0,-2).
        let p = t.apply([1.0, 0.0, 0.0]);
        assert!((p[0] - 1.0).abs() < 1e-6 && p[1] == 0.0 && (p[2] + 2.0).abs() < 1e-6);
        // About z by 90°: x -> y.
        let z = Transform {
            rotate_deg: Some([0.0, 0.0, 90.0]),
            ..Transform::default()
        };
        let q = z.apply([1.0, 0.0, 0.0]);
        assert!(q[0].abs() < 1e-6 && (q[1] - 1.0).abs() < 1e-6);
        assert_eq!(Transform::default().apply([0.1, 0.2, 0.3]), [0.1, 0.2, 0.3]);
    }

    #[test]
    fn dump_prints_short_floats_and_inline_arrays() {
        let d = raykernel::render::scenes::CORNELL;
        let text = dump(&d, &[]);
        assert!(text.contains("\"albedo\": [0.73, 0.73, 0.73]"), "{text}");
        assert!(text.contains("[[-1.0, 0.0, -1.0], [-1.0, 0.0, 1.0], [1.0, 0.0, 1.0]]"));
        assert!(text.contains("\"sampler\": \"stratified\""));
    }
}
