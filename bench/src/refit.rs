//! Refit against rebuild: every vertex of a scene moves by a smooth displacement field, then
//! the existing trees get new boxes (`Bvh::refit`, `Bvh4::refit`) or are built again from
//! scratch. Both are timed, and the primary rays are traced through the refitted and the
//! rebuilt 4-wide tree: what keeping the old topology costs per ray, and a check that a
//! refitted tree gives the same hits as a rebuilt one.

use crate::error::Error;
use crate::ours::{mrays, RunOptions};
use crate::workload::{BenchScene, RayKind};
use host::trace::{median, millis, prepare_rays, trace_closest};
use raykernel::bvh::{nodes_needed, BuildOptions};
use raykernel::bvh4::{collapse_words_needed, nodes4_needed};
use raykernel::{Bvh, Bvh4, Node, Node4, Scalar, Triangle, I16F16};
use serde::Serialize;
use std::time::Instant;

/// One scene and mode.
#[derive(Clone, Debug, Serialize)]
pub struct RefitRow {
    /// Scene.
    pub scene: String,
    /// Triangles.
    pub triangles: usize,
    /// `f32` or `fixed`.
    pub mode: &'static str,
    /// The displacement's amplitude as a fraction of the scene box's diagonal.
    pub amplitude: f64,
    /// SAH BVH build plus the 4-wide collapse over the moved mesh, ms (median).
    pub rebuild_ms: f64,
    /// `Bvh::refit` of the binary tree, ms (median).
    pub refit_bvh_ms: f64,
    /// `Bvh4::refit` of the 4-wide tree, ms (median).
    pub refit_bvh4_ms: f64,
    /// Primary rays through the rebuilt 4-wide tree, Mrays/s (pre-built rays, median).
    pub rebuilt_mrays: f64,
    /// Primary rays through the refitted 4-wide tree, Mrays/s (pre-built rays, median).
    pub refitted_mrays: f64,
    /// Rays traced.
    pub rays: usize,
    /// Rays whose closest hit differs between the refitted and the rebuilt tree (0 expected).
    pub differing_hits: usize,
}

/// The displacements' amplitudes, fractions of the scene box's diagonal: a small motion (an
/// animation step) and a large one (a deformation far from the pose the tree was built for).
pub const AMPLITUDES: [f64; 2] = [0.01, 0.1];

/// Refit and rebuild on every scene, for each of [`AMPLITUDES`], in both modes (fixed only
/// where the moved scene fits).
///
/// # Errors
/// A scene the kernel refuses to build, or a refit refusing the moved mesh.
pub fn run(scenes: &[BenchScene], opts: RunOptions) -> Result<Vec<RefitRow>, Error> {
    let mut rows = Vec::new();
    for scene in scenes {
        eprintln!("bench: refit {}", scene.name);
        let rays = scene
            .ray_sets
            .iter()
            .find(|s| s.kind == RayKind::Primary)
            .map_or(&[][..], |s| &s.records[..]);
        let before32 = scene.mesh.kernel_triangles::<f32>(&scene.path)?;
        let before_fixed = scene.mesh.kernel_triangles::<I16F16>(&scene.path).ok();
        for amplitude in AMPLITUDES {
            let moved = moved_triangles(scene, amplitude);
            let after32 = to_kernel::<f32>(&moved).ok_or_else(|| bad_motion(scene))?;
            let motion = (amplitude, rays);
            rows.push(measure(scene, "f32", &before32, &after32, motion, opts)?);
            if let (Some(before), Some(after)) = (&before_fixed, to_kernel::<I16F16>(&moved)) {
                rows.push(measure(scene, "fixed", before, &after, motion, opts)?);
            }
        }
    }
    Ok(rows)
}

fn bad_motion(scene: &BenchScene) -> Error {
    Error::Bench(format!(
        "refit: the moved {} has a vertex f32 cannot hold",
        scene.name
    ))
}

/// Each vertex `p` moved by `a·(sin(k·p.y), sin(k·p.z), sin(k·p.x))`, `a` = `amplitude` times the
/// box diagonal and `k` four periods across it: neighbouring triangles move together, as in
/// an animated mesh, so the old grouping stays reasonable.
fn moved_triangles(scene: &BenchScene, amplitude: f64) -> Vec<[[f32; 3]; 3]> {
    let (lo, hi) = crate::workload::referenced_bounds(&scene.mesh);
    let diagonal = (0..3).map(|i| (hi[i] - lo[i]).powi(2)).sum::<f64>().sqrt();
    let a = amplitude * diagonal;
    let k = if diagonal > 0.0 {
        8.0 * std::f64::consts::PI / diagonal
    } else {
        0.0
    };
    (0..scene.mesh.triangle_count())
        .map(|i| {
            scene.mesh.triangle_f32(i).map(|p| {
                let [x, y, z] = p.map(f64::from);
                [
                    (x + a * (k * y).sin()) as f32,
                    (y + a * (k * z).sin()) as f32,
                    (z + a * (k * x).sin()) as f32,
                ]
            })
        })
        .collect()
}

fn to_kernel<S: Scalar>(tris: &[[[f32; 3]; 3]]) -> Option<Vec<Triangle<S>>> {
    tris.iter().map(|&t| Triangle::from_f32(t).ok()).collect()
}

fn measure<S: Scalar>(
    scene: &BenchScene,
    mode: &'static str,
    before: &[Triangle<S>],
    after: &[Triangle<S>],
    (amplitude, rays): (f64, &[host::rayfile::RayRecord]),
    opts: RunOptions,
) -> Result<RefitRow, Error> {
    let build_error = |source| host::Error::Build {
        scene: scene.path.clone(),
        source,
    };
    let refit_error =
        |e: raykernel::bvh::RefitError| Error::Bench(format!("refit {} {mode}: {e}", scene.name));
    let n = before.len();
    let options = BuildOptions::default();
    let prepared = prepare_rays::<S>(rays);

    // The rebuilt trees over the moved mesh, timed, and their hits.
    let mut rebuild_ms = Vec::new();
    let mut rebuilt_hits = Vec::new();
    let mut rebuilt_trace_ms = Vec::new();
    for _ in 0..opts.runs {
        let mut nodes = vec![Node::<S>::EMPTY; nodes_needed(n)];
        let mut ids = vec![0u32; n];
        let mut nodes4 = vec![Node4::<S>::EMPTY; nodes4_needed(n)];
        let mut scratch = vec![0u32; collapse_words_needed(n, 4)];
        let start = Instant::now();
        let bvh = Bvh::build(after, &mut nodes, &mut ids, options).map_err(build_error)?;
        let wide = Bvh4::collapse(&bvh, &mut nodes4, &mut scratch).map_err(build_error)?;
        rebuild_ms.push(millis(start));
        let (hits, ms) = trace_closest(&wide, &prepared);
        rebuilt_hits = hits;
        rebuilt_trace_ms.push(ms);
    }

    // The trees built over the mesh before it moved, then refitted to the moved one.
    let mut nodes = vec![Node::<S>::EMPTY; nodes_needed(n)];
    let mut ids = vec![0u32; n];
    let mut nodes4 = vec![Node4::<S>::EMPTY; nodes4_needed(n)];
    let mut scratch = vec![0u32; collapse_words_needed(n, 4)];
    let bvh = Bvh::build(before, &mut nodes, &mut ids, options).map_err(build_error)?;
    let (shape, shape4) = {
        let wide = Bvh4::collapse(&bvh, &mut nodes4, &mut scratch).map_err(build_error)?;
        (bvh.shape(), wide.shape())
    };
    let mut refit_bvh_ms = Vec::new();
    let mut refit_bvh4_ms = Vec::new();
    let mut refitted_hits = Vec::new();
    let mut refitted_trace_ms = Vec::new();
    for _ in 0..opts.runs {
        let start = Instant::now();
        Bvh::refit(after, &mut nodes, &ids, shape).map_err(refit_error)?;
        refit_bvh_ms.push(millis(start));
        let start = Instant::now();
        let wide = Bvh4::refit(after, &mut nodes4, &ids, shape4).map_err(refit_error)?;
        refit_bvh4_ms.push(millis(start));
        let (hits, ms) = trace_closest(&wide, &prepared);
        refitted_hits = hits;
        refitted_trace_ms.push(ms);
    }
    let traced = prepared.rays.len();
    let differing_hits = rebuilt_hits
        .iter()
        .zip(&refitted_hits)
        .filter(|(a, b)| a != b)
        .count();
    Ok(RefitRow {
        scene: scene.name.clone(),
        triangles: n,
        mode,
        amplitude,
        rebuild_ms: median(&rebuild_ms),
        refit_bvh_ms: median(&refit_bvh_ms),
        refit_bvh4_ms: median(&refit_bvh4_ms),
        rebuilt_mrays: mrays(traced, median(&rebuilt_trace_ms)),
        refitted_mrays: mrays(traced, median(&refitted_trace_ms)),
        rays: traced,
        differing_hits,
    })
}
