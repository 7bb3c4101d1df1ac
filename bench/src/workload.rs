//! The benchmark's inputs: scenes (OBJ + `.camera`) and their two ray sets, read from the
//! files `shared/bench/make_rays.py` writes, or generated here.

use crate::error::Error;
use host::obj::{load_obj, Mesh};
use host::rayfile::{read_rays, RayRecord};
use host::scene::PinholeCamera;
use raykernel_testkit::Rng;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The two ray sets of WORKLOAD.md.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum RayKind {
    /// Pinhole camera, one ray per pixel centre.
    Primary,
    /// Origin uniform in the scene box, direction uniform on the sphere.
    Incoherent,
}

impl RayKind {
    /// Both, in report order.
    pub const ALL: [RayKind; 2] = [Self::Primary, Self::Incoherent];

    /// `primary` or `incoherent`, as in the ray file names.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Primary => "primary",
            Self::Incoherent => "incoherent",
        }
    }
}

/// Where the ray sets come from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum RaySource {
    /// `DIR/NAME.{primary,incoherent}.rays`, as written by `make_rays.py --out DIR`.
    Files(PathBuf),
    /// Run `make_rays.py` (beside the scenes, in `../bench/`) into a temporary directory.
    MakeRays,
    /// Generate in Rust, `count` rays per set: primary rays by WORKLOAD.md's camera formula on a
    /// `⌊√count⌋²` grid, incoherent rays from SplitMix64 (`raykernel_testkit::Rng`; not numpy's
    /// PCG64, so not the files' rays). For tests and machines without python.
    Rust {
        /// Rays per set.
        count: usize,
    },
}

/// One ray set of one scene.
#[derive(Clone, Debug)]
pub struct RaySet {
    /// Which set.
    pub kind: RayKind,
    /// The records: the whole file as loaded, the traced ones after [`keep_every`].
    pub records: Vec<RayRecord>,
}

/// Keeps in every ray set of `scenes` the records a run at `stride` traces, next to each other
/// ([`host::rayfile::every`]), so that every timed loop, ours and the peers', reads its records
/// in order.
pub fn keep_every(scenes: &mut [BenchScene], stride: usize) {
    for set in scenes.iter_mut().flat_map(|s| &mut s.ray_sets) {
        set.records = host::rayfile::every(&set.records, stride);
    }
}

/// A scene and its ray sets.
#[derive(Clone, Debug)]
pub struct BenchScene {
    /// Scene name (`bunny`).
    pub name: String,
    /// The OBJ file.
    pub path: PathBuf,
    /// The triangles.
    pub mesh: Mesh,
    /// Primary then incoherent.
    pub ray_sets: Vec<RaySet>,
}

/// Loads `names` from `scenes_dir` (each needs `NAME.obj`, and `NAME.camera` unless the rays
/// come from files) with their ray sets.
///
/// # Errors
/// [`Error::Bench`] with what is missing and how to get it (a fresh clone has no `../shared`);
/// OBJ, camera and ray file errors as such.
pub fn load_scenes(
    scenes_dir: &Path,
    names: &[String],
    source: &RaySource,
) -> Result<Vec<BenchScene>, Error> {
    if !scenes_dir.is_dir() {
        return Err(Error::Bench(format!(
            "scene directory {} not found: the benchmark runs on the shared scenes \
             (../shared/scenes beside the repository), or pass --scenes DIR",
            scenes_dir.display()
        )));
    }
    let made;
    let rays_dir = match source {
        RaySource::Files(dir) => Some(dir.as_path()),
        RaySource::MakeRays => {
            made = TempDir::new("rays")?;
            run_make_rays(scenes_dir, names, &made.0)?;
            Some(made.0.as_path())
        }
        RaySource::Rust { .. } => None,
    };
    let mut scenes = Vec::new();
    for name in names {
        let path = scenes_dir.join(format!("{name}.obj"));
        if !path.is_file() {
            return Err(Error::Bench(format!("scene {} not found", path.display())));
        }
        let mesh = load_obj(&path)?;
        let mut ray_sets = Vec::new();
        for kind in RayKind::ALL {
            let records = match (rays_dir, source) {
                (Some(dir), _) => {
                    let file = dir.join(format!("{name}.{}.rays", kind.name()));
                    if !file.is_file() {
                        return Err(Error::Bench(format!(
                            "ray file {} not found: make it with `python3 \
                             ../shared/bench/make_rays.py --out {} {name}`",
                            file.display(),
                            dir.display()
                        )));
                    }
                    read_rays(&file)?
                }
                (None, RaySource::Rust { count }) => {
                    generate_rays(scenes_dir, name, &mesh, kind, *count)?
                }
                (None, _) => Vec::new(),
            };
            ray_sets.push(RaySet { kind, records });
        }
        scenes.push(BenchScene {
            name: name.clone(),
            path,
            mesh,
            ray_sets,
        });
    }
    Ok(scenes)
}

/// Runs `python3 SCENES/../bench/make_rays.py --scenes-dir SCENES --out OUT NAMES...`.
fn run_make_rays(scenes_dir: &Path, names: &[String], out: &Path) -> Result<(), Error> {
    let mut args = vec![
        "--scenes-dir".into(),
        scenes_dir.as_os_str().to_owned(),
        "--out".into(),
        out.as_os_str().to_owned(),
    ];
    args.extend(names.iter().map(Into::into));
    let script = script_beside(scenes_dir, "make_rays.py")?;
    run_python(&script, &args)
}

/// `SCENES/../bench/NAME`, the shared scripts beside the shared scenes.
fn script_beside(scenes_dir: &Path, name: &str) -> Result<PathBuf, Error> {
    let script = scenes_dir.join("..").join("bench").join(name);
    if script.is_file() {
        Ok(script)
    } else {
        Err(Error::Bench(format!(
            "{} not found: pass --rays DIR (ray files from make_rays.py) or --rust-rays, \
             and --no-city",
            script.display()
        )))
    }
}

/// Runs `python3 SCRIPT ARGS...`, its output shown only if it fails.
fn run_python(script: &Path, args: &[std::ffi::OsString]) -> Result<(), Error> {
    let output = Command::new("python3")
        .arg(script)
        .args(args)
        .output()
        .map_err(|e| Error::Bench(format!("cannot run python3 {}: {e}", script.display())))?;
    if !output.status.success() {
        return Err(Error::Bench(format!(
            "{} failed ({}); it needs python3 with numpy (`pip install numpy`): {}",
            script.display(),
            output.status,
            String::from_utf8_lossy(&output.stderr).trim()
        )));
    }
    Ok(())
}

/// The tiled city's name (`shared/bench/make_tiled.py`'s default scene).
pub const CITY: &str = "city";

/// The 1.2M-triangle tiled city of WORKLOAD.md, kept in `city_dir`: `city.obj` and
/// `city.camera` from `make_tiled.py` (run with its defaults over `scenes_dir` when absent),
/// and its two ray sets from `make_rays.py` into the same directory (when absent), or
/// generated in Rust as `source` says.
///
/// # Errors
/// A script that is missing or fails, an unreadable scene or ray file.
pub fn load_city(
    scenes_dir: &Path,
    city_dir: &Path,
    source: &RaySource,
) -> Result<BenchScene, Error> {
    std::fs::create_dir_all(city_dir)
        .map_err(|e| Error::Bench(format!("cannot create {}: {e}", city_dir.display())))?;
    let file = |ext: &str| city_dir.join(format!("{CITY}.{ext}"));
    if !file("obj").is_file() || !file("camera").is_file() {
        eprintln!("bench: making {} with make_tiled.py", file("obj").display());
        let script = script_beside(scenes_dir, "make_tiled.py")?;
        run_python(
            &script,
            &[
                "--scenes-dir".into(),
                scenes_dir.as_os_str().to_owned(),
                "--out".into(),
                city_dir.as_os_str().to_owned(),
            ],
        )?;
    }
    let rays = match source {
        RaySource::Rust { count } => RaySource::Rust { count: *count },
        RaySource::Files(_) | RaySource::MakeRays => {
            let missing = RayKind::ALL
                .iter()
                .any(|k| !file(&format!("{}.rays", k.name())).is_file());
            if missing {
                eprintln!("bench: making the city's rays with make_rays.py");
                // make_rays.py lives beside the shared scenes, not beside the city.
                let script = script_beside(scenes_dir, "make_rays.py")?;
                run_python(
                    &script,
                    &[
                        "--scenes-dir".into(),
                        city_dir.as_os_str().to_owned(),
                        "--out".into(),
                        city_dir.as_os_str().to_owned(),
                        CITY.into(),
                    ],
                )?;
            }
            RaySource::Files(city_dir.to_path_buf())
        }
    };
    let mut scenes = load_scenes(city_dir, &[CITY.to_string()], &rays)?;
    scenes
        .pop()
        .ok_or_else(|| Error::Bench("the city did not load".into()))
}

/// A directory under the system's temp dir, removed on drop.
pub(crate) struct TempDir(pub(crate) PathBuf);

impl TempDir {
    pub(crate) fn new(what: &str) -> Result<Self, Error> {
        let dir = std::env::temp_dir().join(format!(
            "raykernel-bench-{what}-{}-{}",
            std::process::id(),
            std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0, |d| d.as_nanos())
        ));
        std::fs::create_dir_all(&dir)
            .map_err(|e| Error::Bench(format!("cannot create {}: {e}", dir.display())))?;
        Ok(Self(dir))
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        // Best effort: a leftover temp dir is not worth failing the benchmark.
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Rays generated in Rust for one scene (see [`RaySource::Rust`]).
fn generate_rays(
    scenes_dir: &Path,
    name: &str,
    mesh: &Mesh,
    kind: RayKind,
    count: usize,
) -> Result<Vec<RayRecord>, Error> {
    match kind {
        RayKind::Primary => {
            let cam_path = scenes_dir.join(format!("{name}.camera"));
            let text = std::fs::read_to_string(&cam_path).map_err(|e| {
                Error::Bench(format!("camera {} unreadable: {e}", cam_path.display()))
            })?;
            let camera = PinholeCamera::parse(&text, &cam_path)?;
            Ok(primary_rays(&camera, side_for(count)))
        }
        RayKind::Incoherent => {
            let (lo, hi) = referenced_bounds(mesh);
            Ok(incoherent_rays(lo, hi, count, 1))
        }
    }
}

/// The side of the largest square image with at most `count` pixels (at least 1).
#[must_use]
pub fn side_for(count: usize) -> u32 {
    let side = (count as f64).sqrt().floor() as u32;
    side.max(1)
}

/// WORKLOAD.md's primary rays for a `side`×`side` image, row-major from the top-left pixel.
#[must_use]
pub fn primary_rays(camera: &PinholeCamera, side: u32) -> Vec<RayRecord> {
    let Some(view) = camera.view(side, side) else {
        return Vec::new();
    };
    let mut rays = Vec::with_capacity(side as usize * side as usize);
    for py in 0..side {
        for px in 0..side {
            let (o, d) = view.ray(px, py);
            rays.push(RayRecord::new(o, d));
        }
    }
    rays
}

/// `count` rays with origins uniform in `[lo, hi]` and directions uniform on the unit sphere
/// (normalised in `f64`, then rounded), from SplitMix64 seeded with `seed`.
#[must_use]
pub fn incoherent_rays(lo: [f64; 3], hi: [f64; 3], count: usize, seed: u64) -> Vec<RayRecord> {
    let mut rng = Rng::new(seed);
    (0..count)
        .map(|_| {
            let o: [f64; 3] = std::array::from_fn(|k| lo[k] + rng.unit_f64() * (hi[k] - lo[k]));
            let z = 1.0 - 2.0 * rng.unit_f64();
            let phi = 2.0 * std::f64::consts::PI * rng.unit_f64();
            let s = (1.0 - z * z).max(0.0).sqrt();
            let d = [s * phi.cos(), s * phi.sin(), z];
            let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            RayRecord::new(o.map(|x| x as f32), d.map(|x| (x / n) as f32))
        })
        .collect()
}

/// Box of the vertices the triangles reference (as make_rays.py computes it).
#[must_use]
pub fn referenced_bounds(mesh: &Mesh) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for t in &mesh.triangles {
        for &i in t {
            let p = mesh.positions[i as usize];
            for k in 0..3 {
                lo[k] = lo[k].min(f64::from(p[k]));
                hi[k] = hi[k].max(f64::from(p[k]));
            }
        }
    }
    if lo[0] > hi[0] {
        return ([0.0; 3], [0.0; 3]);
    }
    (lo, hi)
}
