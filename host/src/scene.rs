//! Scenes for `host render`: the built-in one (generated in code, no files), or an OBJ with the
//! camera from its `.camera` file (format of `shared/bench/WORKLOAD.md`) or framed by its box.

use crate::error::Error;
use crate::obj::{load_obj, Mesh};
use std::f64::consts::PI;
use std::path::{Path, PathBuf};

/// A pinhole camera, as in WORKLOAD.md: `vfov` is the full vertical field of view.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub eye: [f64; 3],
    /// Point looked at.
    pub target: [f64; 3],
    /// Up hint.
    pub up: [f64; 3],
    /// Full vertical field of view, degrees.
    pub vfov_deg: f64,
}

/// A camera's frame for one image size: rays through pixel centres.
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

impl Camera {
    /// Parses `eye x y z`, `target x y z`, `up x y z` and `vfov degrees` lines; `#` starts a
    /// comment. `path` labels errors.
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
        if camera.view(1, 1).is_none() {
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

    /// The camera frame for a `width`×`height` image (aspect = width / height); `None` if the
    /// eye equals the target or the up hint is parallel to the view direction.
    #[must_use]
    pub fn view(&self, width: u32, height: u32) -> Option<View> {
        let fwd = sub(self.target, self.eye);
        let right = cross(fwd, self.up);
        if norm(fwd) == 0.0 || norm(right) == 0.0 {
            return None;
        }
        let (fwd, right) = (normalize(fwd), normalize(right));
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
}

impl View {
    /// Origin and unit direction (rounded to `f32`) of the ray through the centre of pixel
    /// (`px`, `py`), `py` = 0 at the top: WORKLOAD.md's camera model, with `u` scaled by the
    /// aspect ratio.
    #[must_use]
    pub fn ray(&self, px: u32, py: u32) -> ([f32; 3], [f32; 3]) {
        let u = ((f64::from(px) + 0.5) / f64::from(self.width) * 2.0 - 1.0) * self.h * self.aspect;
        let v = (1.0 - (f64::from(py) + 0.5) / f64::from(self.height) * 2.0) * self.h;
        let d: [f64; 3] = std::array::from_fn(|k| self.fwd[k] + u * self.right[k] + v * self.up[k]);
        let d = normalize(d);
        (self.eye.map(|x| x as f32), d.map(|x| x as f32))
    }

    /// The camera's unit up vector (orthogonal to the view direction).
    #[must_use]
    pub fn up(&self) -> [f64; 3] {
        self.up
    }

    /// The camera's unit right vector.
    #[must_use]
    pub fn right(&self) -> [f64; 3] {
        self.right
    }

    /// The camera's unit view direction.
    #[must_use]
    pub fn forward(&self) -> [f64; 3] {
        self.fwd
    }
}

/// Where a scene's camera came from.
#[derive(Clone, Debug, PartialEq)]
pub enum CameraSource {
    /// The built-in scene's fixed camera.
    BuiltIn,
    /// A `.camera` file next to the OBJ.
    File(PathBuf),
    /// Framed from the mesh's bounding box.
    Framed,
}

/// Something to render: triangles with a colour each, a camera, a light.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Label for reports: `built-in` or the OBJ path.
    pub name: String,
    /// The OBJ the triangles came from (for `file:line` errors in fixed mode), if any.
    pub obj: Option<(PathBuf, Mesh)>,
    /// Triangles (ids are indices here).
    pub triangles: Vec<[[f32; 3]; 3]>,
    /// Linear RGB albedo of each triangle.
    pub albedo: Vec<[f32; 3]>,
    /// The camera.
    pub camera: Camera,
    /// Where the camera came from.
    pub camera_source: CameraSource,
    /// Unit vector towards the directional light; `None`: derived from the camera (above and
    /// behind it, a little to its left).
    pub light: Option<[f64; 3]>,
}

impl Scene {
    /// Loads an OBJ; the camera is `NAME.camera` beside it if that exists, else the framing of
    /// the mesh's box for a `width`×`height` image. Every triangle is light grey.
    ///
    /// # Errors
    /// An unreadable or bad OBJ, or a bad `.camera` file.
    pub fn load(path: &Path, width: u32, height: u32) -> Result<Self, Error> {
        let mesh = load_obj(path)?;
        let triangles: Vec<_> = (0..mesh.triangle_count())
            .map(|i| mesh.triangle_f32(i))
            .collect();
        let camera_path = path.with_extension("camera");
        let (camera, camera_source) = if camera_path.is_file() {
            let text = std::fs::read_to_string(&camera_path).map_err(|e| Error::Camera {
                path: camera_path.clone(),
                line: None,
                msg: format!("cannot read: {e}"),
            })?;
            (
                Camera::parse(&text, &camera_path)?,
                CameraSource::File(camera_path),
            )
        } else {
            let (lo, hi) = bounds(&triangles);
            (Camera::frame(lo, hi, width, height), CameraSource::Framed)
        };
        Ok(Self {
            name: path.display().to_string(),
            albedo: vec![[0.75, 0.75, 0.72]; triangles.len()],
            triangles,
            obj: Some((path.to_path_buf(), mesh)),
            camera,
            camera_source,
            light: None,
        })
    }

    /// The built-in scene: an open box (white floor and back wall, red left and green right
    /// wall) holding two rotated blocks, a subdivided icosphere and a torus, lit by a sun from
    /// the front right. About 7,100 triangles, all within ±2 (fixed point takes them easily).
    #[must_use]
    pub fn built_in() -> Self {
        let mut b = Builder::default();
        let white = [0.73, 0.71, 0.68];
        // Floor and back wall extend past the side walls a little, so no light leaks at seams.
        b.quad(
            [
                [-1.0, 0.0, 1.0],
                [1.0, 0.0, 1.0],
                [1.0, 0.0, -1.0],
                [-1.0, 0.0, -1.0],
            ],
            white,
        );
        b.quad(
            [
                [-1.0, 0.0, -1.0],
                [1.0, 0.0, -1.0],
                [1.0, 2.0, -1.0],
                [-1.0, 2.0, -1.0],
            ],
            white,
        );
        b.quad(
            [
                [-1.0, 0.0, 1.0],
                [-1.0, 0.0, -1.0],
                [-1.0, 2.0, -1.0],
                [-1.0, 2.0, 1.0],
            ],
            [0.63, 0.07, 0.05],
        );
        b.quad(
            [
                [1.0, 0.0, -1.0],
                [1.0, 0.0, 1.0],
                [1.0, 2.0, 1.0],
                [1.0, 2.0, -1.0],
            ],
            [0.12, 0.45, 0.09],
        );
        let grey = [0.75, 0.74, 0.72];
        b.block([0.4, 0.0, -0.4], [0.27, 1.2, 0.27], 0.4, grey);
        b.block([-0.45, 0.0, -0.5], [0.22, 0.4, 0.22], -0.3, grey);
        b.icosphere([-0.38, 0.3, 0.35], 0.3, 4, [0.85, 0.62, 0.18]);
        b.torus([0.4, 0.08, 0.45], 0.25, 0.08, 48, 20, [0.15, 0.3, 0.75]);
        Self {
            name: "built-in".into(),
            obj: None,
            triangles: b.triangles,
            albedo: b.albedo,
            camera: Camera {
                eye: [0.0, 1.1, 5.2],
                target: [0.0, 0.95, 0.0],
                up: [0.0, 1.0, 0.0],
                vfov_deg: 33.0,
            },
            camera_source: CameraSource::BuiltIn,
            light: Some(normalize([0.3, 1.0, 0.8])),
        }
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

/// Collects triangles and their colours.
#[derive(Default)]
struct Builder {
    triangles: Vec<[[f32; 3]; 3]>,
    albedo: Vec<[f32; 3]>,
}

impl Builder {
    fn tri(&mut self, v: [[f64; 3]; 3], albedo: [f32; 3]) {
        self.triangles.push(v.map(|p| p.map(|x| x as f32)));
        self.albedo.push(albedo);
    }

    /// A planar quad, corners in order around it.
    fn quad(&mut self, [a, b, c, d]: [[f64; 3]; 4], albedo: [f32; 3]) {
        self.tri([a, b, c], albedo);
        self.tri([a, c, d], albedo);
    }

    /// A box standing on y = `base[1]`, centred on (`base[0]`, `base[2]`), with half widths
    /// `half[0]`, `half[2]` and height `half[1]`, turned `angle` radians about y.
    fn block(&mut self, base: [f64; 3], half: [f64; 3], angle: f64, albedo: [f32; 3]) {
        let (s, c) = angle.sin_cos();
        let corner = |i: usize| {
            let x = if i & 1 == 0 { -half[0] } else { half[0] };
            let y = if i & 2 == 0 { 0.0 } else { half[1] };
            let z = if i & 4 == 0 { -half[2] } else { half[2] };
            [
                base[0] + c * x + s * z,
                base[1] + y,
                base[2] - s * x + c * z,
            ]
        };
        let p: [[f64; 3]; 8] = std::array::from_fn(corner);
        for [a, b, c, d] in [
            [0, 1, 3, 2], // z-
            [4, 6, 7, 5], // z+
            [0, 2, 6, 4], // x-
            [1, 5, 7, 3], // x+
            [2, 3, 7, 6], // top
            [0, 4, 5, 1], // bottom
        ] {
            self.quad([p[a], p[b], p[c], p[d]], albedo);
        }
    }

    /// An icosahedron subdivided `levels` times onto a sphere (20·4^levels triangles).
    fn icosphere(&mut self, centre: [f64; 3], radius: f64, levels: u32, albedo: [f32; 3]) {
        let (p, faces) = crate::mesh::unit_icosphere(levels);
        let at = |i: usize| std::array::from_fn(|k| centre[k] + radius * p[i][k]);
        for [a, b, c] in faces {
            self.tri([at(a), at(b), at(c)], albedo);
        }
    }

    /// A torus lying flat (axis y): `major` radius of the ring, `minor` of the tube.
    fn torus(
        &mut self,
        centre: [f64; 3],
        major: f64,
        minor: f64,
        ring: usize,
        tube: usize,
        albedo: [f32; 3],
    ) {
        let at = |i: usize, j: usize| {
            let (st, ct) = (2.0 * PI * (i % ring) as f64 / ring as f64).sin_cos();
            let (sp, cp) = (2.0 * PI * (j % tube) as f64 / tube as f64).sin_cos();
            let r = major + minor * cp;
            [
                centre[0] + r * ct,
                centre[1] + minor * sp,
                centre[2] + r * st,
            ]
        };
        for i in 0..ring {
            for j in 0..tube {
                self.quad(
                    [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)],
                    albedo,
                );
            }
        }
    }
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
        let c = Camera::parse(
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
            let e = Camera::parse(text, p).unwrap_err().to_string();
            assert!(e.contains(needle), "{text:?}: {e}");
        }
    }

    #[test]
    fn centre_pixel_ray_looks_at_the_target() {
        let c = Camera {
            eye: [0.0, 0.0, 5.0],
            target: [0.0, 0.0, 0.0],
            up: [0.0, 1.0, 0.0],
            vfov_deg: 90.0,
        };
        // Odd size: the middle pixel's centre is the image centre.
        let v = c.view(5, 3).unwrap();
        let (o, d) = v.ray(2, 1);
        assert_eq!(o, [0.0, 0.0, 5.0]);
        assert_eq!(d, [0.0, 0.0, -1.0]);
        // Top-left pixel looks up and left; vfov 90: v = (1 - 1/3)·1.
        let (_, d) = v.ray(0, 0);
        assert!(d[0] < 0.0 && d[1] > 0.0, "{d:?}");
        let (_, d2) = v.ray(4, 2);
        assert_eq!((d2[0], d2[1]), (-d[0], -d[1]));
    }

    #[test]
    fn framing_keeps_the_box_in_view() {
        let (lo, hi) = ([-3.0, 0.0, -1.0], [5.0, 2.0, 1.0]);
        for (w, h) in [(640, 480), (200, 600)] {
            let c = Camera::frame(lo, hi, w, h);
            let v = c.view(w, h).unwrap();
            let half_v = (c.vfov_deg / 2.0).to_radians().tan();
            let half_h = half_v * f64::from(w) / f64::from(h);
            for i in 0..8 {
                let p = [
                    if i & 1 == 0 { lo[0] } else { hi[0] },
                    if i & 2 == 0 { lo[1] } else { hi[1] },
                    if i & 4 == 0 { lo[2] } else { hi[2] },
                ];
                let r = sub(p, c.eye);
                let z: f64 = (0..3).map(|k| r[k] * v.forward()[k]).sum();
                let x: f64 = (0..3).map(|k| r[k] * v.right()[k]).sum();
                let y: f64 = (0..3).map(|k| r[k] * v.up()[k]).sum();
                assert!(z > 0.0 && (x / z).abs() < half_h && (y / z).abs() < half_v);
            }
        }
    }

    #[test]
    fn built_in_scene_is_sane() {
        let s = Scene::built_in();
        assert_eq!(s.triangles.len(), s.albedo.len());
        assert!(s.triangles.len() > 3000, "{}", s.triangles.len());
        let (lo, hi) = bounds(&s.triangles);
        assert!(
            lo.iter().chain(&hi).all(|x| x.abs() <= 2.0),
            "{lo:?} {hi:?}"
        );
        assert!(s.camera.view(640, 480).is_some());
    }
}
