//! Scenes for `raykernel render` and `raykernel check`: what the SCENE argument names (a
//! built-in scene, a scene file, or an OBJ mesh), and the lights, material and camera an OBJ
//! gets: the camera from its `NAME.camera` file (format of `shared/bench/WORKLOAD.md`) or
//! framed by its box.

use crate::error::Error;
use crate::input::read_text_limited;
use crate::limits::MAX_CAMERA_FILE_BYTES;
use crate::obj::load_obj_with_materials;
use crate::scenefile::{load_scene_file, DEFAULT_SETTINGS};
use crate::spec::{eye_to_look_at, ObjectSource, SceneOrigin, SceneSpec};
use raykernel::render::scenes::{self, ObjectData, ShapeRange};
use raykernel::render::{Camera, Light, Material};
use std::path::Path;

/// The built-in scene rendered when no SCENE is given.
pub const DEFAULT_SCENE: &str = "cornell";

/// Loads what a SCENE argument names: a built-in scene (`cornell`, `spheres`, `motion`), a
/// scene file (`.json`), an OBJ mesh (`.obj`) or a glTF 2.0 scene (`.gltf`, `.glb`).
///
/// # Errors
/// An unknown name, or the loader's error for the file.
pub fn resolve_scene(arg: &str) -> Result<SceneSpec, Error> {
    if let Some(d) = scenes::by_name(arg) {
        return Ok(SceneSpec::from_data(&d));
    }
    let path = Path::new(arg);
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    match ext.as_deref() {
        Some("json") => load_scene_file(path),
        Some("obj") => obj_scene(path),
        Some("gltf" | "glb") => crate::gltf::gltf_scene(path),
        _ => {
            let names: Vec<&str> = scenes::ALL.iter().map(|s| s.name).collect();
            Err(Error::Usage(format!(
                "unknown scene `{arg}`: expected a built-in scene ({}), a scene file (.json), \
                 an OBJ mesh (.obj) or a glTF scene (.gltf, .glb)",
                names.join(", ")
            )))
        }
    }
}

/// A pinhole camera, as in WORKLOAD.md: `vfov` is the full vertical field of view.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PinholeCamera {
    /// Eye position.
    pub eye: [f64; 3],
    /// Point looked at.
    pub target: [f64; 3],
    /// Up hint.
    pub up: [f64; 3],
    /// Full vertical field of view, degrees.
    pub vfov_deg: f64,
}

impl PinholeCamera {
    /// Parses `eye x y z`, `target x y z`, `up x y z` and `vfov degrees` lines; `#` starts a
    /// comment; a leading byte-order mark is skipped. `path` labels errors.
    ///
    /// # Errors
    /// [`Error::Camera`] naming the line of a bad statement, or a missing or unusable value.
    pub fn parse(text: &str, path: &Path) -> Result<Self, Error> {
        let err = |line: Option<usize>, msg: String| Error::Camera {
            path: path.to_path_buf(),
            line,
            msg,
        };
        let (mut eye, mut target, mut up, mut vfov) = (None, None, None, None);
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        for (i, raw) in text.lines().enumerate() {
            let line = Some(i + 1);
            let body = raw.split('#').next().unwrap_or_default();
            let mut words = body.split_whitespace();
            let Some(key) = words.next() else { continue };
            let nums = words
                .map(|w| w.parse::<f64>().ok().filter(|x| x.is_finite()))
                .collect::<Option<Vec<f64>>>()
                .ok_or_else(|| err(line, format!("`{key}`: values must be finite numbers")))?;
            let three = |nums: &[f64]| match *nums {
                [x, y, z] => Ok([x, y, z]),
                _ => Err(err(
                    line,
                    format!("`{key}` needs 3 numbers, got {}", nums.len()),
                )),
            };
            match key {
                "eye" => eye = Some(three(&nums)?),
                "target" => target = Some(three(&nums)?),
                "up" => up = Some(three(&nums)?),
                "vfov" => match *nums {
                    [v] if v > 0.0 && v < 180.0 => vfov = Some(v),
                    _ => return Err(err(line, "`vfov` needs one angle in (0, 180)".into())),
                },
                _ => return Err(err(line, format!("unknown statement `{key}`"))),
            }
        }
        let missing = |what: &str| err(None, format!("no `{what}` line"));
        let camera = Self {
            eye: eye.ok_or_else(|| missing("eye"))?,
            target: target.ok_or_else(|| missing("target"))?,
            up: up.ok_or_else(|| missing("up"))?,
            vfov_deg: vfov.ok_or_else(|| missing("vfov"))?,
        };
        if !camera.is_usable() {
            return Err(err(
                None,
                "eye equals target, or up is parallel to the view direction".into(),
            ));
        }
        Ok(camera)
    }

    /// A camera that frames the box `[lo, hi]` for a `width`×`height` image: looking at its
    /// centre from the front (+z), a little right and above, with +y up.
    #[must_use]
    pub fn frame(lo: [f64; 3], hi: [f64; 3], width: u32, height: u32) -> Self {
        let centre: [f64; 3] = std::array::from_fn(|k| (lo[k] + hi[k]) / 2.0);
        let radius = (norm(sub(hi, lo)) / 2.0).max(1e-3);
        let vfov_deg: f64 = 40.0;
        let half_v = (vfov_deg / 2.0).to_radians();
        let aspect = f64::from(width.max(1)) / f64::from(height.max(1));
        let half_h = (half_v.tan() * aspect).atan();
        let dist = 1.05 * radius / half_v.min(half_h).sin();
        let dir = normalize([0.45, 0.35, 1.0]);
        Self {
            eye: std::array::from_fn(|k| centre[k] + dist * dir[k]),
            target: centre,
            up: [0.0, 1.0, 0.0],
            vfov_deg,
        }
    }

    /// False if the eye equals the target or the up hint is parallel to the view direction.
    #[must_use]
    pub fn is_usable(&self) -> bool {
        let fwd = sub(self.target, self.eye);
        norm(fwd) > 0.0 && norm(cross(fwd, self.up)) > 0.0
    }

    /// The camera frame for a `width`×`height` image (aspect = width / height); `None` if the
    /// camera is not [usable](Self::is_usable).
    #[must_use]
    pub fn view(&self, width: u32, height: u32) -> Option<View> {
        if !self.is_usable() {
            return None;
        }
        let fwd = normalize(sub(self.target, self.eye));
        let right = normalize(cross(fwd, self.up));
        Some(View {
            fwd,
            right,
            up: cross(right, fwd),
            eye: self.eye,
            h: (self.vfov_deg.to_radians() / 2.0).tan(),
            aspect: f64::from(width) / f64::from(height),
            width,
            height,
        })
    }

    /// The kernel's camera: a pinhole, focused on the target (for when an aperture is set).
    #[must_use]
    pub fn to_kernel(&self) -> Camera {
        let f = |p: [f64; 3]| p.map(|x| x as f32);
        let (eye, look_at) = (f(self.eye), f(self.target));
        Camera {
            eye,
            look_at,
            up: f(self.up),
            vfov_deg: self.vfov_deg as f32,
            aperture_radius: 0.0,
            focus_distance: eye_to_look_at(eye, look_at),
        }
    }
}

/// A camera's frame for one image size: WORKLOAD.md's primary rays through pixel centres
/// (the benchmark's ray sets; the renderer uses the kernel's own camera).
#[derive(Clone, Copy, Debug)]
pub struct View {
    fwd: [f64; 3],
    right: [f64; 3],
    up: [f64; 3],
    eye: [f64; 3],
    h: f64,
    aspect: f64,
    width: u32,
    height: u32,
}

impl View {
    /// Origin and unit direction (rounded to `f32`) of the ray through the centre of pixel
    /// (`px`, `py`), `py` = 0 at the top, with `u` scaled by the aspect ratio.
    #[must_use]
    pub fn ray(&self, px: u32, py: u32) -> ([f32; 3], [f32; 3]) {
        let u = ((f64::from(px) + 0.5) / f64::from(self.width) * 2.0 - 1.0) * self.h * self.aspect;
        let v = (1.0 - (f64::from(py) + 0.5) / f64::from(self.height) * 2.0) * self.h;
        let d: [f64; 3] = std::array::from_fn(|k| self.fwd[k] + u * self.right[k] + v * self.up[k]);
        let d = normalize(d);
        (self.eye.map(|x| x as f32), d.map(|x| x as f32))
    }
}

/// Albedo of an OBJ scene's one material.
pub const OBJ_ALBEDO: [f32; 3] = [0.73, 0.73, 0.73];
/// Radiance of an OBJ scene's area light.
pub const OBJ_LIGHT_RADIANCE: [f32; 3] = [10.0, 10.0, 9.5];
/// Background radiance of an OBJ scene.
pub const OBJ_BACKGROUND: [f32; 3] = [0.03, 0.035, 0.045];

/// An OBJ mesh as a scene: one white diffuse material ([`OBJ_ALBEDO`]), or with `mtllib` and
/// `usemtl` one object per material ([`crate::mtl`]); the camera from `NAME.camera` beside it,
/// else framed by the mesh's box; lights as [`lit_mesh_scene`] places them.
///
/// # Errors
/// An unreadable or bad OBJ or MTL file, or a bad `.camera` file.
pub fn obj_scene(path: &Path) -> Result<SceneSpec, Error> {
    let (mesh, material_refs) = load_obj_with_materials(path)?;
    let triangles: Vec<[[f32; 3]; 3]> = (0..mesh.triangle_count())
        .map(|i| mesh.triangle_f32(i))
        .collect();
    let vertex_lines = mesh
        .triangles
        .iter()
        .map(|t| t.map(|c| mesh.position_lines[c as usize]))
        .collect();
    let camera_path = path.with_extension("camera");
    let camera = if camera_path.is_file() {
        let text =
            read_text_limited(&camera_path, MAX_CAMERA_FILE_BYTES).map_err(|e| Error::Camera {
                path: camera_path.clone(),
                line: None,
                msg: format!("cannot read: {e}"),
            })?;
        Some(PinholeCamera::parse(&text, &camera_path)?)
    } else {
        None
    };
    let source = ObjectSource::Mesh {
        path: path.to_path_buf(),
        vertex_lines,
        transform: None,
    };
    let mut spec = lit_mesh_scene(path, triangles, source, camera);
    if mesh.has_normals() {
        spec.vertex_normals = (0..mesh.triangle_count())
            .map(|i| mesh.vertex_normals(i))
            .collect();
    }
    if let Some(m) = crate::mtl::resolve(path, &material_refs, mesh.triangle_count())? {
        crate::mtl::split_by_material(&mut spec, &m);
    }
    Ok(spec)
}

/// A triangle mesh from `path` (an OBJ or glTF file) as one white diffuse object ([`OBJ_ALBEDO`])
/// in a lit scene: the given camera, else one framing the mesh's box (for the default
/// 512×512 image); a square area light facing down, half the box's diagonal wide and half a
/// diagonal above the box's top (radiance [`OBJ_LIGHT_RADIANCE`]); a dim point light at the eye
/// for fill (it gives `0.35` irradiance at the box centre); +y is up. Settings are
/// [`DEFAULT_SETTINGS`].
#[must_use]
pub fn lit_mesh_scene(
    path: &Path,
    triangles: Vec<[[f32; 3]; 3]>,
    source: ObjectSource,
    camera: Option<PinholeCamera>,
) -> SceneSpec {
    let (lo, hi) = bounds(&triangles);
    let camera = camera.unwrap_or_else(|| {
        PinholeCamera::frame(lo, hi, DEFAULT_SETTINGS.width, DEFAULT_SETTINGS.height)
    });
    let diag = norm(sub(hi, lo)).max(1e-3);
    let centre: [f64; 3] = std::array::from_fn(|k| (lo[k] + hi[k]) / 2.0);
    let side = 0.5 * diag;
    let corner = [
        centre[0] - side / 2.0,
        hi[1] + 0.5 * diag,
        centre[2] - side / 2.0,
    ];
    let to_eye = norm(sub(camera.eye, centre));
    let f = |p: [f64; 3]| p.map(|x| x as f32);
    let fill = (0.35 * to_eye * to_eye) as f32;
    let count = u32::try_from(triangles.len()).unwrap_or(u32::MAX);
    let name = path
        .file_stem()
        .map_or("mesh".into(), |s| s.to_string_lossy().into_owned());
    SceneSpec {
        name,
        origin: SceneOrigin::Obj(path.to_path_buf()),
        triangles,
        vertex_normals: Vec::new(),
        spheres: Vec::new(),
        objects: vec![ObjectData {
            shape: ShapeRange::Triangles { first: 0, count },
            material: 0,
            motion: [0.0; 3],
            emission: [0.0; 3],
            one_sided: false,
        }],
        object_sources: vec![source],
        materials: vec![Material::Diffuse { albedo: OBJ_ALBEDO }],
        material_names: vec!["white".into()],
        lights: vec![
            Light::Rect {
                corner: f(corner),
                // edge_u × edge_v points down (-y): the light faces the model.
                edge_u: [side as f32, 0.0, 0.0],
                edge_v: [0.0, 0.0, side as f32],
                radiance: OBJ_LIGHT_RADIANCE,
            },
            Light::Point {
                position: f(camera.eye),
                intensity: [fill; 3],
            },
        ],
        camera: camera.to_kernel(),
        background: OBJ_BACKGROUND,
        settings: DEFAULT_SETTINGS,
    }
}

/// The box of a triangle list (the unit box for none).
#[must_use]
pub fn bounds(triangles: &[[[f32; 3]; 3]]) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in triangles.iter().flatten() {
        for k in 0..3 {
            lo[k] = lo[k].min(f64::from(p[k]));
            hi[k] = hi[k].max(f64::from(p[k]));
        }
    }
    if lo[0] > hi[0] {
        return ([0.0; 3], [1.0; 3]);
    }
    (lo, hi)
}

pub(crate) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub(crate) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub(crate) fn norm(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

pub(crate) fn normalize(a: [f64; 3]) -> [f64; 3] {
    let l = norm(a);
    a.map(|x| x / l)
}
#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn camera_file_parses_and_reports_bad_lines() {
        let p = Path::new("x.camera");
        let c = PinholeCamera::parse(
            "# comment\neye 1 2 3\ntarget 0 0 0 # look at the origin\nup 0 1 0\nvfov 45\n",
            p,
        )
        .unwrap();
        assert_eq!(c.eye, [1.0, 2.0, 3.0]);
        assert_eq!(c.vfov_deg, 45.0);
        for (text, needle) in [
            ("eye 1 2\n", "x.camera:1: `eye` needs 3 numbers, got 2"),
            ("eye 1 2 zz\n", "x.camera:1: `eye`: values must be finite"),
            ("eye 0 0 1\nfov 3\n", "x.camera:2: unknown statement `fov`"),
            (
                "vfov 180\n",
                "x.camera:1: `vfov` needs one angle in (0, 180)",
            ),
            (
                "eye 0 0 1\ntarget 0 0 0\nvfov 40\n",
                "x.camera: no `up` line",
            ),
            (
                "eye 0 0 1\ntarget 0 0 0\nup 0 0 1\nvfov 40\n",
                "up is parallel to the view direction",
            ),
        ] {
            let e = PinholeCamera::parse(text, p).unwrap_err().to_string();
            assert!(e.contains(needle), "{text:?}: {e}");
        }
    }

    #[test]
    fn framing_keeps_the_box_in_view() {
        let (lo, hi) = ([-3.0, 0.0, -1.0], [5.0, 2.0, 1.0]);
        for (w, h) in [(640, 480), (200, 600)] {
            let c = PinholeCamera::frame(lo, hi, w, h);
            let fwd = normalize(sub(c.target, c.eye));
            let right = normalize(cross(fwd, c.up));
            let up = cross(right, fwd);
            let half_v = (c.vfov_deg / 2.0).to_radians().tan();
            let half_h = half_v * f64::from(w) / f64::from(h);
            for i in 0..8 {
                let p = [
                    if i & 1 == 0 { lo[0] } else { hi[0] },
                    if i & 2 == 0 { lo[1] } else { hi[1] },
                    if i & 4 == 0 { lo[2] } else { hi[2] },
                ];
                let r = sub(p, c.eye);
                let z: f64 = (0..3).map(|k| r[k] * fwd[k]).sum();
                let x: f64 = (0..3).map(|k| r[k] * right[k]).sum();
                let y: f64 = (0..3).map(|k| r[k] * up[k]).sum();
                assert!(z > 0.0 && (x / z).abs() < half_h && (y / z).abs() < half_v);
            }
        }
    }
}
