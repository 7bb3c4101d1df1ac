//! The interleaved rounds alone, for quick A/B work on the headline structure: per ray set,
//! ray construction on its own (ns per ray) and the rounds of `raykernel_bench::rounds` (ours
//! per ray, Embree HIGH with the `embree` feature, ours on pre-built rays, tinybvh with the
//! `tinybvh` feature), with the per-round ratio against Embree. Seconds per scene instead of
//! the full benchmark's quarter hour; the full run stays the one that writes the report.
//! `--simd-ab` compares the traversal's two compiled copies instead (`raykernel::cpu`).
//!
//! ```text
//! python3 ../shared/bench/make_rays.py --out /tmp/rays bunny sponza kitchen
//! cargo run --release -p raykernel-bench --features embree --example rounds -- --rays /tmp/rays
//! ```

use clap::Parser;
use host::trace::{median, prepare_rays};
use raykernel::cpu::{set_traversal_simd, Simd};
use raykernel_bench::error::Error;
use raykernel_bench::ours::RunOptions;
use raykernel_bench::rounds;
use raykernel_bench::workload::{load_scenes, BenchScene, RaySet, RaySource};
use std::path::PathBuf;

/// Interleaved rounds of the headline structure against Embree, without the rest of the
/// benchmark.
#[derive(Parser)]
struct Args {
    /// Ray files from `make_rays.py --out DIR`.
    #[arg(long, value_name = "DIR")]
    rays: PathBuf,
    /// Directory of the scenes (NAME.obj).
    #[arg(long, value_name = "DIR", default_value = "../shared/scenes")]
    scenes: PathBuf,
    /// Scenes to run (repeatable).
    #[arg(long = "scene", value_name = "NAME", default_values_t = ["bunny".to_string(), "sponza".to_string(), "kitchen".to_string()])]
    scene_names: Vec<String>,
    /// Trace every K-th ray.
    #[arg(long, value_name = "K", default_value_t = 8)]
    stride: usize,
    /// Rounds per ray set.
    #[arg(long, value_name = "N", default_value_t = 7)]
    rounds: usize,
    /// Instead of the peers: per round, ours with the traversal's baseline copy, then with its
    /// AVX2 copy (`raykernel::cpu`); prints the per-round ratios AVX2 ÷ baseline.
    #[arg(long)]
    simd_ab: bool,
}

/// Per round, the headline structure traced with the baseline copy of the traversal and then
/// with the AVX2 copy; prints the per-round ratios (per ray, and their median on pre-built
/// rays). Leaves the copy the CPU supports selected.
fn simd_ab(scene: &BenchScene, set: &RaySet, opts: RunOptions, rounds: usize) -> Result<(), Error> {
    let available = set_traversal_simd(Simd::Avx2);
    if available != Simd::Avx2 {
        println!(
            "{:8} {:10} skipped: no AVX2 copy on this CPU",
            scene.name,
            set.kind.name()
        );
        return Ok(());
    }
    let (mut per_ray, mut prebuilt) = (Vec::new(), Vec::new());
    for _ in 0..rounds.max(1) {
        let once = |simd| {
            set_traversal_simd(simd);
            rounds::run(scene, set, opts, 1, false)
        };
        let (base, avx2) = (once(Simd::Baseline)?, once(Simd::Avx2)?);
        let ratio = |a: &[f64], b: &[f64]| a.first().zip(b.first()).map_or(0.0, |(a, b)| a / b);
        per_ray.push(ratio(&avx2.ours_mrays, &base.ours_mrays));
        prebuilt.push(ratio(&avx2.ours_prebuilt_mrays, &base.ours_prebuilt_mrays));
    }
    let listed: Vec<String> = per_ray.iter().map(|r| format!("{r:.3}")).collect();
    println!(
        "{:8} {:10} avx2 ÷ baseline per ray {:.3} (rounds {}), pre-built {:.3}",
        scene.name,
        set.kind.name(),
        median(&per_ray),
        listed.join(" "),
        median(&prebuilt)
    );
    Ok(())
}

/// Median ns per ray of the report's ray setup ([`prepare_rays`]: `Ray::from_f32` on every
/// `stride`-th record, into a vector) over `rounds` timings.
fn construction_ns(set: &RaySet, stride: usize, rounds: usize) -> f64 {
    let timings: Vec<f64> = (0..rounds.max(1))
        .map(|_| {
            let prepared = prepare_rays::<f32>(&set.records, stride);
            prepared.setup_ms * 1e6 / prepared.rays.len().max(1) as f64
        })
        .collect();
    median(&timings)
}

fn main() -> Result<(), Error> {
    let args = Args::parse();
    let stride = args.stride.max(1);
    let source = RaySource::Files(args.rays.clone());
    let scenes = load_scenes(&args.scenes, &args.scene_names, &source)?;
    if args.simd_ab {
        for scene in &scenes {
            for set in &scene.ray_sets {
                simd_ab(scene, set, RunOptions { stride, runs: 1 }, args.rounds)?;
            }
        }
        return Ok(());
    }
    println!("scene    rays        setup ns  ours  pre-built  Embree  ours/Embree per round: median (min-max)");
    for scene in &scenes {
        for set in &scene.ray_sets {
            let setup = construction_ns(set, stride, args.rounds);
            let opts = RunOptions { stride, runs: 1 };
            let row = rounds::run(scene, set, opts, args.rounds, true)?;
            let ours = median(&row.ours_mrays);
            let prebuilt = median(&row.ours_prebuilt_mrays);
            let versus = row
                .vs_embree()
                .map_or("no Embree in this build".to_string(), |p| {
                    let (lo, hi) = p.ratio_range();
                    format!(
                        "{:5.2}  {:.3} ({lo:.3}-{hi:.3})",
                        p.peer_median,
                        p.median_ratio()
                    )
                });
            println!(
                "{:8} {:10} {setup:9.1}  {ours:4.2}  {prebuilt:9.2}  {versus}",
                scene.name,
                set.kind.name()
            );
        }
    }
    Ok(())
}
