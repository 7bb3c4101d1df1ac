//! The interleaved rounds alone, for quick A/B work on the headline structures: per ray set,
//! ray construction on its own (ns per ray) and the rounds of `raykernel_bench::rounds` (ours,
//! the 4-wide and the 8-wide BVH, per ray, Embree HIGH in its default and its robust mode with
//! the `embree` feature, ours on pre-built rays, tinybvh with the `tinybvh` feature), with the
//! per-round ratios against both Embree modes. Seconds per scene instead of the full
//! benchmark's quarter hour; the full run stays the one that writes the report.
//! `--simd-ab` compares the traversal's two compiled copies instead (`raykernel::cpu`);
//! `--split` times the rays that miss and the rays that hit apart, ours against Embree HIGH, and
//! counts the boxes and triangles ours tests per ray in each part.
//!
//! ```text
//! python3 ../shared/bench/make_rays.py --out /tmp/rays bunny sponza kitchen
//! cargo run --release -p raykernel-bench --features embree --example rounds -- --rays /tmp/rays
//! ```

use clap::Parser;
use host::trace::{median, prepare_rays};
use raykernel::cpu::{set_traversal_simd, Simd};
use raykernel_bench::error::Error;
use raykernel_bench::rounds;
use raykernel_bench::workload::{keep_every, load_scenes, BenchScene, RaySet, RaySource};
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
    /// Instead of the rounds: each ray set split into the rays ours misses and the rays it hits,
    /// and per round the 8-wide BVH's default walk (per ray) and Embree HIGH on each part
    /// (needs the `embree` feature), with the boxes and triangles ours tests per ray in each
    /// part. Shows whether a gap lies in what every ray pays (setup, the top nodes) or in the
    /// descent to a hit and the triangle tests.
    #[arg(long)]
    split: bool,
}

/// Per round, the headline structures traced with the baseline copy of the traversal and then
/// with the AVX2 copy; prints the per-round ratios (per ray, and their median on pre-built
/// rays) of each. Leaves the copy the CPU supports selected.
fn simd_ab(scene: &BenchScene, set: &RaySet, rounds: usize) -> Result<(), Error> {
    let available = set_traversal_simd(Simd::Avx2);
    if available != Simd::Avx2 {
        println!(
            "{:8} {:10} skipped: no AVX2 copy on this CPU",
            scene.name,
            set.kind.name()
        );
        return Ok(());
    }
    let structures = rounds::CONTENDERS.len();
    let (mut per_ray, mut prebuilt) = (vec![Vec::new(); structures], vec![Vec::new(); structures]);
    for _ in 0..rounds.max(1) {
        let once = |simd| {
            set_traversal_simd(simd);
            rounds::run(scene, set, 1, false)
        };
        let (base, avx2) = (once(Simd::Baseline)?, once(Simd::Avx2)?);
        let ratio = |a: &[f64], b: &[f64]| a.first().zip(b.first()).map_or(0.0, |(a, b)| a / b);
        for (i, (b, a)) in base.ours.iter().zip(&avx2.ours).enumerate() {
            per_ray[i].push(ratio(&a.per_ray_mrays, &b.per_ray_mrays));
            prebuilt[i].push(ratio(&a.prebuilt_mrays, &b.prebuilt_mrays));
        }
    }
    for (i, name) in rounds::CONTENDERS.iter().enumerate() {
        let listed: Vec<String> = per_ray[i].iter().map(|r| format!("{r:.3}")).collect();
        println!(
            "{:8} {:10} {} avx2 ÷ baseline per ray {:.3} (rounds {}), pre-built {:.3}",
            scene.name,
            set.kind.name(),
            name,
            median(&per_ray[i]),
            listed.join(" "),
            median(&prebuilt[i])
        );
    }
    Ok(())
}

/// Median ns per ray of the report's ray setup ([`prepare_rays`]: `Ray::from_f32` on every
/// traced record, into a vector) over `rounds` timings.
fn construction_ns(set: &RaySet, rounds: usize) -> f64 {
    let timings: Vec<f64> = (0..rounds.max(1))
        .map(|_| {
            let prepared = prepare_rays::<f32>(&set.records);
            prepared.setup_ms * 1e6 / prepared.rays.len().max(1) as f64
        })
        .collect();
    median(&timings)
}

fn main() -> Result<(), Error> {
    let args = Args::parse();
    let source = RaySource::Files(args.rays.clone());
    let mut scenes = load_scenes(&args.scenes, &args.scene_names, &source)?;
    keep_every(&mut scenes, args.stride);
    if args.split {
        for scene in &scenes {
            for set in &scene.ray_sets {
                split(scene, set, args.rounds)?;
            }
        }
        return Ok(());
    }
    if args.simd_ab {
        for scene in &scenes {
            for set in &scene.ray_sets {
                simd_ab(scene, set, args.rounds)?;
            }
        }
        return Ok(());
    }
    println!(
        "scene    rays       structure          setup ns  ours  pre-built  Embree  ours/Embree per round: median (min-max)  robust  ours/robust"
    );
    for scene in &scenes {
        for set in &scene.ray_sets {
            let setup = construction_ns(set, args.rounds);
            let row = rounds::run(scene, set, args.rounds, true)?;
            let fastest = row.fastest().map(|o| o.structure);
            for ours in &row.ours {
                let per_ray = median(&ours.per_ray_mrays);
                let prebuilt = median(&ours.prebuilt_mrays);
                let versus =
                    row.vs_embree(ours)
                        .map_or("no Embree in this build".to_string(), |p| {
                            let (lo, hi) = p.ratio_range();
                            format!(
                                "{:5.2}  {:.3} ({lo:.3}-{hi:.3})",
                                p.peer_median,
                                p.median_ratio()
                            )
                        });
                let robust = row.vs_embree_robust(ours).map_or(String::new(), |p| {
                    let (lo, hi) = p.ratio_range();
                    format!(
                        "  {:5.2}  {:.3} ({lo:.3}-{hi:.3})",
                        p.peer_median,
                        p.median_ratio()
                    )
                });
                let mark = if fastest == Some(ours.structure) {
                    "*"
                } else {
                    " "
                };
                println!(
                    "{:8} {:10} {:13}{mark}    {setup:8.1}  {per_ray:4.2}  {prebuilt:9.2}  {versus}{robust}",
                    scene.name,
                    set.kind.name(),
                    ours.structure,
                );
            }
            for t in &row.tinybvh8 {
                if let Some(p) = row.vs_embree_of(t) {
                    let (lo, hi) = p.ratio_range();
                    println!(
                        "{:8} {:10} {:19} pre-built {:5.2}  Embree {:5.2}  ÷ Embree per round {:.3} ({lo:.3}-{hi:.3}); same hit triangle as ours {:.3}%",
                        scene.name,
                        set.kind.name(),
                        t.name,
                        p.ours_median,
                        p.peer_median,
                        p.median_ratio(),
                        t.same_prim_pct
                    );
                }
            }
        }
    }
    Ok(())
}

/// `--split`: per part of the ray set ([`rounds::split`]), the median ns per ray of ours and of
/// Embree HIGH, and the per-round ratios ours ÷ Embree (speed: above 1, ours faster).
fn split(scene: &BenchScene, set: &RaySet, rounds: usize) -> Result<(), Error> {
    let Some(parts) = rounds::split(scene, set, rounds)? else {
        return Err(Error::Bench(
            "--split compares with Embree: build with --features embree".to_string(),
        ));
    };
    let ns = |mrays: f64| if mrays > 0.0 { 1e3 / mrays } else { 0.0 };
    for part in parts {
        if part.rays == 0 {
            println!(
                "{:8} {:10} {:6}       0 rays",
                scene.name,
                set.kind.name(),
                part.name
            );
            continue;
        }
        let p = &part.vs_embree;
        let (lo, hi) = p.ratio_range();
        let per_ray = |n: u64| n as f64 / part.rays as f64;
        println!(
            "{:8} {:10} {:6} {:7} rays: ours {:6.1} ns, Embree HIGH {:6.1} ns, ours ÷ Embree per round {:.3} ({lo:.3}-{hi:.3}); ours per ray {:.1} boxes, {:.2} triangles",
            scene.name,
            set.kind.name(),
            part.name,
            part.rays,
            ns(p.ours_median),
            ns(p.peer_median),
            p.median_ratio(),
            per_ray(part.counted.nodes_visited),
            per_ray(part.counted.prims_tested)
        );
    }
    Ok(())
}
