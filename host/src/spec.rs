//! [`SceneSpec`]: a scene the host owns (built-in, loaded from a scene file, or made from an
//! OBJ), lending the kernel's plain-data view [`SceneData`], and turning the kernel's typed
//! [`SceneError`]s back into messages that name the file and the field the user wrote.

use crate::error::Error;
use crate::obj::{coordinate_range, point_error_text, ObjError, ObjErrorKind};
use crate::scenefile::Transform;
use raykernel::render::scenes::{ObjectData, SceneData, ShapeRange, SphereData};
use raykernel::render::{Camera, Item, Light, Material, Problem, Rgb, SceneError, Settings};
use raykernel::{BuildError, F32_COORD_LIMIT, FIXED_COORD_LIMIT};
use std::path::PathBuf;

/// Where an object's geometry came from (for error messages).
#[derive(Clone, Debug, PartialEq)]
pub enum ObjectSource {
    /// Written in the scene (inline triangles or spheres, or a built-in scene).
    Inline,
    /// Read from an OBJ file: the line of each corner of each triangle, in triangle order.
    Mesh {
        /// The OBJ file.
        path: PathBuf,
        /// `vertex_lines[t][c]`: the line defining corner `c` of the object's triangle `t`.
        vertex_lines: Vec<[usize; 3]>,
        /// The placement applied to the file's vertices, if any.
        transform: Option<Transform>,
    },
}

/// Where a whole scene came from: decides how errors are worded.
#[derive(Clone, Debug, PartialEq)]
pub enum SceneOrigin {
    /// A built-in scene of the kernel.
    BuiltIn,
    /// A scene file (errors name its JSON fields).
    File(PathBuf),
    /// An OBJ file rendered with the host's default materials, lights and camera.
    Obj(PathBuf),
}

/// A scene as owned `f32` data: the same shape as the kernel's [`SceneData`], plus the names and
/// sources error messages need. Object `i`, material `i` and light `i` are entry `i` of the
/// scene file's lists.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneSpec {
    /// Short name (reports, file names).
    pub name: String,
    /// Where it came from.
    pub origin: SceneOrigin,
    /// Every triangle; objects' ranges index into it.
    pub triangles: Vec<[[f32; 3]; 3]>,
    /// Vertex normals: empty (flat shading) or one entry per triangle, zero for a flat one.
    pub vertex_normals: Vec<[[f32; 3]; 3]>,
    /// Every sphere.
    pub spheres: Vec<SphereData>,
    /// Objects.
    pub objects: Vec<ObjectData>,
    /// Where each object came from.
    pub object_sources: Vec<ObjectSource>,
    /// Materials.
    pub materials: Vec<Material>,
    /// The name of each material.
    pub material_names: Vec<String>,
    /// Lights.
    pub lights: Vec<Light>,
    /// Camera.
    pub camera: Camera,
    /// Background radiance.
    pub background: Rgb,
    /// Settings to render with.
    pub settings: Settings,
}

/// The distance from `eye` to `look_at` (computed in `f64`): a camera's focus distance when
/// none is given.
#[must_use]
pub fn eye_to_look_at(eye: [f32; 3], look_at: [f32; 3]) -> f32 {
    let d: [f64; 3] = std::array::from_fn(|k| f64::from(look_at[k]) - f64::from(eye[k]));
    (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() as f32
}

/// The largest coordinate magnitude of `mode` (`f32` or `fixed`).
fn coordinate_limit(mode: &str) -> f32 {
    if mode == "fixed" {
        FIXED_COORD_LIMIT
    } else {
        F32_COORD_LIMIT
    }
}

impl SceneSpec {
    /// An owned copy of kernel scene data (a built-in scene); materials are named `m0`, `m1`, ...
    #[must_use]
    pub fn from_data(d: &SceneData<'_>) -> Self {
        Self {
            name: d.name.to_string(),
            origin: SceneOrigin::BuiltIn,
            triangles: d.triangles.to_vec(),
            vertex_normals: d.vertex_normals.to_vec(),
            spheres: d.spheres.to_vec(),
            objects: d.objects.to_vec(),
            object_sources: vec![ObjectSource::Inline; d.objects.len()],
            materials: d.materials.to_vec(),
            material_names: (0..d.materials.len()).map(|i| format!("m{i}")).collect(),
            lights: d.lights.to_vec(),
            camera: d.camera,
            background: d.background,
            settings: d.settings,
        }
    }

    /// The kernel's view of this scene.
    #[must_use]
    pub fn data(&self) -> SceneData<'_> {
        SceneData {
            name: &self.name,
            triangles: &self.triangles,
            vertex_normals: &self.vertex_normals,
            spheres: &self.spheres,
            objects: &self.objects,
            materials: &self.materials,
            lights: &self.lights,
            camera: self.camera,
            background: self.background,
            settings: self.settings,
        }
    }

    /// How messages name this scene: the file, or `built-in scene NAME`.
    #[must_use]
    pub fn label(&self) -> String {
        match &self.origin {
            SceneOrigin::BuiltIn => format!("built-in scene `{}`", self.name),
            SceneOrigin::File(p) | SceneOrigin::Obj(p) => p.display().to_string(),
        }
    }

    /// Checks the camera for what the kernel accepts but cannot render as asked in `mode`: an
    /// eye (or lens) outside the mode's coordinate range, where no camera ray can start (the
    /// image would be background only), an eye equal to `look_at`, and a view direction too
    /// long for `f32`. Call it before rendering, after any change to the camera.
    ///
    /// # Errors
    /// [`Error::Scene`] at the camera field to change.
    pub fn check_camera(&self, mode: &'static str) -> Result<(), Error> {
        let c = &self.camera;
        let at = |field: &str, msg: String| Error::Scene {
            file: self.label(),
            field: format!("camera.{field}"),
            msg,
        };
        let finite = |p: [f32; 3]| p.iter().all(|x| x.is_finite());
        if !finite(c.eye) || !finite(c.look_at) || !c.aperture_radius.is_finite() {
            return Ok(()); // the kernel names the field
        }
        let limit = coordinate_limit(mode);
        let reach = c.eye.iter().map(|x| x.abs()).fold(0.0f32, f32::max);
        if reach > limit {
            return Err(at(
                "eye",
                format!(
                    "{:?} lies outside {}: no camera ray can start there",
                    c.eye,
                    coordinate_range(mode)
                ),
            ));
        }
        if c.aperture_radius > 0.0 && reach + c.aperture_radius > limit {
            return Err(at(
                "aperture_radius",
                format!(
                    "the lens around `eye` reaches outside {}: make the aperture smaller or \
                     move the eye inwards",
                    coordinate_range(mode)
                ),
            ));
        }
        if c.eye == c.look_at {
            return Err(at(
                "look_at",
                format!(
                    "equals `eye` ({:?}): the camera must look at a point other than its own \
                     position",
                    c.eye
                ),
            ));
        }
        let d: [f32; 3] = std::array::from_fn(|k| c.look_at[k] - c.eye[k]);
        if !(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).is_finite() {
            return Err(at(
                "look_at",
                "too far from `eye`: the view direction overflows f32 (move `look_at` closer \
                 along the same line)"
                    .into(),
            ));
        }
        Ok(())
    }

    /// What a kernel [`Problem`] at `item.field` means here, in words for this scene and
    /// `mode` (the kernel's own words name no mode and no scene-file concepts).
    fn problem_text(&self, e: &SceneError, mode: &'static str) -> String {
        let coordinate_limit = coordinate_limit(mode);
        match (e.item, e.field, e.problem) {
            (Item::Camera, "vfov_deg", Problem::OutOfRange { min, max }) => format!(
                "must lie strictly between {min} and {max} degrees (both excluded): the full \
                 vertical field of view"
            ),
            (Item::Camera, "look_at", Problem::Degenerate)
                if self.camera.eye == self.camera.look_at =>
            {
                "equals `eye`: the camera must look at a point other than its own position".into()
            }
            (Item::Camera, "look_at", Problem::Degenerate) => {
                "the direction from `eye` to `look_at` cannot be normalised (too short or too \
                 long for f32)"
                    .into()
            }
            (Item::Camera, "up", Problem::Degenerate) => {
                "must be non-zero and not parallel to the view direction (from `eye` to \
                 `look_at`)"
                    .into()
            }
            (Item::Light, "radius", Problem::OutOfRange { .. }) => format!(
                "the sphere (centre ± radius) reaches outside {}: every point of it must lie \
                 inside (move it inwards or make it smaller)",
                coordinate_range(mode)
            ),
            (_, _, Problem::OutOfRange { min, max })
                if max == coordinate_limit && min == -coordinate_limit =>
            {
                format!("lies outside {}", coordinate_range(mode))
            }
            (_, _, p) => p.to_string(),
        }
    }

    /// Turns a kernel error on this scene (rendered in `mode`) into a message naming the file,
    /// the field as written in the scene file, and the problem, e.g.
    /// `scene.json: materials[2] ("gold").reflectance: must be at most 1`.
    #[must_use]
    pub fn explain(&self, e: &SceneError, mode: &'static str) -> Error {
        let at = |field: String, msg: String| Error::Scene {
            file: self.label(),
            field,
            msg,
        };
        let problem = self.problem_text(e, mode);
        let i = e.index;
        match e.item {
            Item::Material => {
                let name = self
                    .material_names
                    .get(i)
                    .map_or(String::new(), |n| format!(" ({n:?})"));
                at(format!("materials[{i}]{name}.{}", e.field), problem)
            }
            Item::Light => {
                if e.field == "lights" {
                    at("lights".into(), problem)
                } else {
                    at(format!("lights[{i}].{}", e.field), problem)
                }
            }
            Item::Camera => at(format!("camera.{}", e.field), problem),
            Item::Settings if e.field == "background" => at("background".into(), problem),
            Item::Settings => at(format!("settings.{}", e.field), problem),
            Item::Tile => at(format!("tile.{}", e.field), problem),
            Item::Object => self.explain_object(e, mode),
        }
    }

    fn explain_object(&self, e: &SceneError, mode: &'static str) -> Error {
        let at = |field: String, msg: String| Error::Scene {
            file: self.label(),
            field,
            msg,
        };
        let i = e.index;
        if matches!(e.field, "objects" | "nodes" | "prim_ids") {
            return at(e.field.into(), self.problem_text(e, mode));
        }
        let Problem::Build(BuildError::BadPrimitive {
            prim,
            vertex,
            error,
        }) = e.problem
        else {
            return at(
                format!("objects[{i}].{}", e.field),
                self.problem_text(e, mode),
            );
        };
        // `triangles_into`/`spheres_into` report the global primitive index, the accelerator
        // build (field `shape`) the object's own.
        let (first, spheres) = match self.objects.get(i).map(|o| o.shape) {
            Some(ShapeRange::Triangles { first, .. }) => (first as usize, false),
            Some(ShapeRange::Spheres { first, .. }) => (first as usize, true),
            None => (0, false),
        };
        let local = if e.field == "shape" {
            prim
        } else {
            prim.saturating_sub(first)
        };
        if spheres {
            let (field, msg) = match (vertex, error) {
                (0, _) => ("center", point_error_text(error, mode)),
                (_, raykernel::PointError::OutOfRange { .. }) => (
                    "radius",
                    format!(
                        "the sphere (centre ± radius) reaches outside {}: every point of it \
                         must lie inside (move it inwards or make it smaller)",
                        coordinate_range(mode)
                    ),
                ),
                (_, _) => ("radius", point_error_text(error, mode)),
            };
            return at(format!("objects[{i}].spheres[{local}].{field}"), msg);
        }
        match self.object_sources.get(i) {
            Some(ObjectSource::Mesh {
                path, vertex_lines, ..
            }) => {
                let line = vertex_lines
                    .get(local)
                    .and_then(|l| l.get(vertex))
                    .copied()
                    .unwrap_or(0);
                let obj = ObjError::at(
                    path,
                    line,
                    ObjErrorKind::UnusableVertex {
                        triangle: local,
                        mode,
                        error,
                    },
                );
                if let SceneOrigin::File(_) = self.origin {
                    at(format!("objects[{i}].mesh"), obj.to_string())
                } else {
                    Error::Obj(obj)
                }
            }
            _ => at(
                format!("objects[{i}].triangles[{local}][{vertex}]"),
                point_error_text(error, mode),
            ),
        }
    }
}
