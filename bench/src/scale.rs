//! Scale: a deterministic tiled scene of transformed copies of the benchmark meshes, from 10k
//! to 1M+ triangles, to see how build time and Mrays/s grow beyond the caches.
//!
//! The recipe is `shared/bench/make_tiled.py`'s (10×10 cells on a `⌈√n⌉`-wide grid, each
//! instance scaled to a horizontal radius of 4.5, rotated about y by the rational
//! parametrisation `cos = (1−t²)/(1+t²)`, `sin = 2t/(1+t²)`, stood on y = 0, a ground plane
//! 0.1 below, 2 triangles per cell, the same 3/4 camera), with two differences: the random
//! numbers come from SplitMix64 rather than numpy's PCG64 (so the instance mix differs from
//! the `city` file), and the last instance is cut so the instances hold exactly the target
//! count. Rays: primary from that camera, incoherent from SplitMix64 in the scene box.

use crate::error::Error;
use crate::ours::{count_work, mrays};
use crate::results::ScaleRow;
use crate::workload::{incoherent_rays, primary_rays, side_for};
use host::obj::Mesh;
use host::scene::PinholeCamera;
use host::trace::{
    build_and_visit, median, prepare_rays, trace_closest, AccelConfig, Mode, NodeArena,
    PreparedRays,
};
use raykernel::bvh::BuildOptions;
use raykernel::{Accel, AccelKind, AccelVisitor, Scalar, TraversalStats, I16F16};
use raykernel_testkit::Rng;
use std::path::Path;

const CELL: f64 = 10.0;
const FOOTPRINT: f64 = 0.45;
const GROUND_DROP: f64 = 0.01;

/// A generated tiled scene.
pub struct Tiled {
    /// The triangles (positions not merged).
    pub mesh: Mesh,
    /// Instances placed (the last one possibly cut).
    pub instances: usize,
    /// The 3/4 view camera over the grid.
    pub camera: PinholeCamera,
}

/// How one source mesh is placed: its referenced box centre and scale.
struct Source<'m> {
    mesh: &'m Mesh,
    cx: f64,
    cz: f64,
    lo_y: f64,
    scale: f64,
}

impl<'m> Source<'m> {
    fn new(mesh: &'m Mesh) -> Option<Self> {
        let (lo, hi) = crate::workload::referenced_bounds(mesh);
        let (cx, cz) = ((lo[0] + hi[0]) * 0.5, (lo[2] + hi[2]) * 0.5);
        let mut radius: f64 = 0.0;
        for t in &mesh.triangles {
            for &i in t {
                let p = mesh.positions[i as usize];
                let (x, z) = (f64::from(p[0]) - cx, f64::from(p[2]) - cz);
                radius = radius.max((x * x + z * z).sqrt());
            }
        }
        (radius > 0.0 && !mesh.triangles.is_empty()).then(|| Self {
            mesh,
            cx,
            cz,
            lo_y: lo[1],
            scale: FOOTPRINT * CELL / radius,
        })
    }
}

/// Tiles instances of `meshes` until they hold exactly `target` triangles (the last instance
/// cut), plus the ground. Deterministic for a given `seed`.
#[must_use]
pub fn tiled_scene(meshes: &[&Mesh], target: usize, seed: u64) -> Option<Tiled> {
    let sources: Vec<Source<'_>> = meshes.iter().filter_map(|m| Source::new(m)).collect();
    if sources.is_empty() || target == 0 {
        return None;
    }
    // Plan: (source, rotation parameter, half-turn flip) per instance.
    let mut rng = Rng::new(seed);
    let mut plan = Vec::new();
    let mut total = 0usize;
    while total < target {
        let m = ((rng.unit_f64() * sources.len() as f64) as usize).min(sources.len() - 1);
        let t = 2.0 * rng.unit_f64() - 1.0;
        let flip = rng.unit_f64() < 0.5;
        plan.push((m, t, flip));
        total += sources[m].mesh.triangles.len();
    }
    let cells = plan.len();
    let mut cols = (cells as f64).sqrt() as usize;
    while cols * cols < cells {
        cols += 1;
    }
    let rows = cells.div_ceil(cols);
    let (half_x, half_z) = (cols as f64 * CELL * 0.5, rows as f64 * CELL * 0.5);
    let mut mesh = Mesh::default();
    let mut left = target;
    for (k, &(m, t, flip)) in plan.iter().enumerate() {
        let s = &sources[m];
        let (r, c) = (k / cols, k % cols);
        let (ox, oz) = (
            -half_x + (c as f64 + 0.5) * CELL,
            -half_z + (r as f64 + 0.5) * CELL,
        );
        let tt = t * t;
        let (mut cos, mut sin) = ((1.0 - tt) / (1.0 + tt), (2.0 * t) / (1.0 + tt));
        if flip {
            (cos, sin) = (-cos, -sin);
        }
        let base = mesh.positions.len() as u32;
        for p in &s.mesh.positions {
            let x = f64::from(p[0]) - s.cx;
            let y = f64::from(p[1]) - s.lo_y;
            let z = f64::from(p[2]) - s.cz;
            mesh.positions.push([
                (ox + s.scale * (cos * x + sin * z)) as f32,
                (s.scale * y) as f32,
                (oz + s.scale * (cos * z - sin * x)) as f32,
            ]);
        }
        let take = left.min(s.mesh.triangles.len());
        mesh.triangles
            .extend(s.mesh.triangles[..take].iter().map(|t| t.map(|i| i + base)));
        left -= take;
    }
    // Ground: (cols+1)×(rows+1) vertices, two triangles per cell.
    let gy = (-GROUND_DROP * CELL) as f32;
    let base = mesh.positions.len() as u32;
    for r in 0..=rows {
        for c in 0..=cols {
            mesh.positions.push([
                (-half_x + c as f64 * CELL) as f32,
                gy,
                (-half_z + r as f64 * CELL) as f32,
            ]);
        }
    }
    let w = cols as u32 + 1;
    for r in 0..rows as u32 {
        for c in 0..cols as u32 {
            let v00 = base + r * w + c;
            let (v10, v01) = (v00 + 1, v00 + w);
            let v11 = v01 + 1;
            mesh.triangles.push([v00, v01, v11]);
            mesh.triangles.push([v00, v11, v10]);
        }
    }
    mesh.position_lines = vec![0; mesh.positions.len()];
    mesh.triangle_lines = vec![0; mesh.triangles.len()];
    // make_tiled.py's camera: above the (−x, +z) corner, looking across the grid.
    let diag = (half_x * half_x + half_z * half_z).sqrt();
    let camera = PinholeCamera {
        eye: [-0.85 * half_x, 0.62 * diag, 0.85 * half_z],
        target: [-0.1 * half_x, 0.0, 0.1 * half_z],
        up: [0.0, 1.0, 0.0],
        vfov_deg: 45.0,
    };
    Some(Tiled {
        mesh,
        instances: cells,
        camera,
    })
}

/// Sizes and rays of the sweep.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ScaleOptions {
    /// Instance triangle counts.
    pub sizes: Vec<usize>,
    /// Rays per set (primary: the largest square image with at most this many pixels).
    pub rays: usize,
    /// Runs (build + trace of both sets); medians.
    pub runs: usize,
}

/// Builds and traces the tiled scene at every size, SAH BVH, both modes.
///
/// # Errors
/// A build the kernel refuses, or no usable source mesh.
pub fn run(meshes: &[&Mesh], opts: &ScaleOptions) -> Result<Vec<ScaleRow>, Error> {
    let mut rows = Vec::new();
    for &size in &opts.sizes {
        let Some(tiled) = tiled_scene(meshes, size, 20_261_123) else {
            return Err(Error::Bench("no usable mesh to tile".into()));
        };
        eprintln!(
            "bench: scale {} triangles ({} instances)",
            tiled.mesh.triangle_count(),
            tiled.instances
        );
        let primary = primary_rays(&tiled.camera, side_for(opts.rays));
        let (lo, hi) = crate::workload::referenced_bounds(&tiled.mesh);
        let incoherent = incoherent_rays(lo, hi, opts.rays, 1);
        let path = Path::new("tiled");
        for mode in Mode::ALL {
            let row = match mode {
                Mode::F32 => measure_size::<f32>(&tiled, &primary, &incoherent, path, opts)?,
                Mode::Fixed => measure_size::<I16F16>(&tiled, &primary, &incoherent, path, opts)?,
            };
            rows.push(row);
        }
    }
    Ok(rows)
}

fn measure_size<S: Scalar>(
    tiled: &Tiled,
    primary: &[host::rayfile::RayRecord],
    incoherent: &[host::rayfile::RayRecord],
    path: &Path,
    opts: &ScaleOptions,
) -> Result<ScaleRow, Error> {
    let tris = tiled.mesh.kernel_triangles::<S>(path)?;
    let (p, q) = (prepare_rays::<S>(primary), prepare_rays::<S>(incoherent));
    let config = AccelConfig {
        accel: AccelKind::Bvh(BuildOptions::default()),
        leaf_order: false,
    };
    let mut arena = NodeArena::<S>::for_accel(config.accel, &tris);
    let (mut builds, mut ps, mut qs) = (Vec::new(), Vec::new(), Vec::new());
    let mut bytes = 0;
    let mut nodes = 0;
    for run in 0..opts.runs.max(1) {
        let visitor = TwoSets {
            a: &p,
            b: &q,
            count: run == 0,
        };
        let (fig, (pa, pb, counted)) = build_and_visit(&tris, &mut arena, path, &config, visitor)?;
        builds.push(fig.build_ms);
        ps.push(pa);
        qs.push(pb);
        bytes = fig.accel_bytes;
        if run == 0 {
            nodes = counted.nodes_visited;
        }
    }
    let n = tris.len().max(1);
    Ok(ScaleRow {
        triangles: tris.len(),
        instances: tiled.instances,
        mode: S::NAME.into(),
        builder: BuildOptions::default().builder.name().into(),
        build_ms: median(&builds),
        bytes_per_tri: bytes as f64 / n as f64,
        ray_count: q.rays.len(),
        primary_mrays: mrays(p.rays.len(), median(&ps)),
        incoherent_mrays: mrays(q.rays.len(), median(&qs)),
        incoherent_nodes_per_ray: nodes as f64 / q.rays.len().max(1) as f64,
    })
}

/// Closest hit over two prepared sets (timed each), and optionally a counted pass over `b`.
struct TwoSets<'p, S: Scalar> {
    a: &'p PreparedRays<S>,
    b: &'p PreparedRays<S>,
    count: bool,
}

impl<S: Scalar> AccelVisitor<S> for TwoSets<'_, S> {
    type Output = (f64, f64, TraversalStats);
    fn visit<A: Accel<S>>(self, accel: &A) -> Self::Output {
        let (_, ms_a) = trace_closest(accel, self.a);
        let (_, ms_b) = trace_closest(accel, self.b);
        let stats = if self.count {
            count_work(accel, &self.b.rays)
        } else {
            TraversalStats::default()
        };
        (ms_a, ms_b, stats)
    }
}

/// Default sweep sizes: full, and `--quick`.
#[must_use]
pub fn default_sizes(quick: bool) -> Vec<usize> {
    if quick {
        vec![10_000, 30_000, 100_000]
    } else {
        vec![10_000, 30_000, 100_000, 300_000, 1_000_000, 2_000_000]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> Mesh {
        Mesh {
            positions: vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [0.0, 1.0, 0.0],
            ],
            position_lines: vec![1, 2, 3, 4],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
            triangle_lines: vec![5, 6],
            ..Mesh::default()
        }
    }

    #[test]
    fn tiles_exactly_the_target_plus_ground_and_is_deterministic() {
        let m = square();
        let a = tiled_scene(&[&m], 7, 5).unwrap();
        // 4 instances (2 triangles each), the last cut to 1; a 2×2 grid: 8 ground triangles.
        assert_eq!(a.instances, 4);
        assert_eq!(a.mesh.triangle_count(), 7 + 8);
        let b = tiled_scene(&[&m], 7, 5).unwrap();
        assert_eq!(a.mesh, b.mesh);
        // Instances stand on y = 0, within their cells' footprint.
        for t in &a.mesh.triangles[..7] {
            for &i in t {
                let p = a.mesh.positions[i as usize];
                assert!(
                    p[1] >= 0.0 && p[0].abs() <= 10.0 && p[2].abs() <= 10.0,
                    "{p:?}"
                );
            }
        }
    }
}
