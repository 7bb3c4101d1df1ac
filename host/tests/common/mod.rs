//! Helpers shared by the integration tests: a seeded RNG, scene and ray generators, temp dirs.
#![allow(dead_code)]

use host::RayRecord;
use raykernel_testkit::vec3::{cross, normalize, sub};
use std::path::{Path, PathBuf};

pub use raykernel_testkit::Rng;

/// A fresh, empty directory under the integration tests' temp dir.
pub fn temp_dir(name: &str) -> PathBuf {
    raykernel_testkit::empty_dir(Path::new(env!("CARGO_TARGET_TMPDIR")).join(name))
}

/// A closed triangle mesh: an icosahedron subdivided `levels` times, projected on a sphere.
pub struct Sphere {
    pub positions: Vec<[f64; 3]>,
    pub triangles: Vec<[usize; 3]>,
}

pub fn icosphere(center: [f64; 3], radius: f64, levels: u32) -> Sphere {
    let (unit, triangles) = raykernel_testkit::icosphere::unit_icosphere(levels);
    let triangles = triangles.iter().map(|t| t.map(|i| i as usize)).collect();
    let positions = unit
        .iter()
        .map(|v| std::array::from_fn(|k| center[k] + radius * v[k]))
        .collect();
    Sphere {
        positions,
        triangles,
    }
}

impl Sphere {
    /// Vertex positions rounded to f32, as the OBJ file holds them.
    pub fn positions_f32(&self) -> Vec<[f32; 3]> {
        self.positions.iter().map(|p| p.map(|x| x as f32)).collect()
    }

    /// OBJ text: `v` lines (f32 printed round-trip exact), then one `f` line per triangle.
    pub fn to_obj(&self) -> String {
        let mut s = String::from("# icosphere\n");
        for p in self.positions_f32() {
            s += &format!("v {} {} {}\n", p[0], p[1], p[2]);
        }
        for t in &self.triangles {
            s += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
        }
        s
    }
}

/// Pinhole camera as in `shared/bench/WORKLOAD.md` (`NAME.camera`).
pub struct Camera {
    pub eye: [f64; 3],
    pub target: [f64; 3],
    pub up: [f64; 3],
    pub vfov_deg: f64,
}

impl Camera {
    /// Parses `eye`, `target`, `up` and `vfov` lines (`#` starts a comment).
    pub fn parse(text: &str) -> Self {
        let mut cam = Camera {
            eye: [0.0; 3],
            target: [0.0; 3],
            up: [0.0; 3],
            vfov_deg: 0.0,
        };
        for line in text.lines() {
            let line = line.split('#').next().unwrap_or_default();
            let mut it = line.split_whitespace();
            let Some(key) = it.next() else { continue };
            let nums: Vec<f64> = it.map(|x| x.parse().unwrap()).collect();
            match key {
                "eye" => cam.eye = [nums[0], nums[1], nums[2]],
                "target" => cam.target = [nums[0], nums[1], nums[2]],
                "up" => cam.up = [nums[0], nums[1], nums[2]],
                "vfov" => cam.vfov_deg = nums[0],
                _ => panic!("unknown camera key {key}"),
            }
        }
        cam
    }

    /// The ray through the centre of pixel (`px`, `py`) of a `size`×`size` image.
    pub fn ray(&self, px: usize, py: usize, size: usize) -> RayRecord {
        let fwd = normalize(sub(self.target, self.eye));
        let right = normalize(cross(fwd, self.up));
        let cup = cross(right, fwd);
        let h = (self.vfov_deg.to_radians() * 0.5).tan();
        let u = ((px as f64 + 0.5) / size as f64 * 2.0 - 1.0) * h;
        let v = (1.0 - (py as f64 + 0.5) / size as f64 * 2.0) * h;
        let d = normalize([
            fwd[0] + u * right[0] + v * cup[0],
            fwd[1] + u * right[1] + v * cup[1],
            fwd[2] + u * right[2] + v * cup[2],
        ]);
        RayRecord::new(self.eye.map(|x| x as f32), d.map(|x| x as f32))
    }
}

/// Bounding box of points.
pub fn bbox(points: &[[f32; 3]]) -> ([f32; 3], [f32; 3]) {
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for p in points {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (lo, hi)
}

/// Rays with origins uniform in the box and uniform directions.
pub fn random_rays(rng: &mut Rng, lo: [f32; 3], hi: [f32; 3], n: usize) -> Vec<RayRecord> {
    (0..n)
        .map(|_| {
            let o = [0, 1, 2].map(|k| rng.range_f64(f64::from(lo[k]), f64::from(hi[k])) as f32);
            RayRecord::new(o, rng.direction())
        })
        .collect()
}
