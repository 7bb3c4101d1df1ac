//! raykernel's benchmark (`raykernel-bench`): speed and accuracy in one run, with peers, on
//! the shared scenes and the 1.2M-triangle tiled city.
//!
//! - [`cli`]: the command line,
//! - [`workload`]: scenes and the WORKLOAD.md ray sets (files from `make_rays.py`, or
//!   generated), the city from `make_tiled.py`,
//! - [`ours`]: the kernel's contenders (every accelerator, builder and mode, plus the
//!   benchmark-only Möller–Trumbore contrast of [`mt`]); the headline figure sets the
//!   ray from each record inside the timed loop, the pre-built figure beside it does not,
//! - [`peers`]: Embree 3 (HIGH and MEDIUM, `embree` feature, through [`embree`]), tinybvh
//!   (`tinybvh` feature), `obvhs` (BVH2, CWBVH) and `bvh`, measured in the same run,
//! - [`rounds`]: the headline contender, Embree and tinybvh traced in alternation, round by
//!   round (tinybvh's 8-wide BVH through `tinybvh8`, `tinybvh` feature),
//! - [`accuracy`]: the `f64` reference and each contender's hit-distance error,
//! - [`scale`]: the tiled scene from 10k to 1M+ triangles,
//! - [`refit`]: refitting the trees after the mesh moved, against rebuilding them,
//! - [`images`]: the renderer's image error against time, per sampler,
//! - [`fireflies`]: isolated bright pixels around the glossy highlight, per integrator,
//! - [`gi`]: the path tracer against Mitsuba 3 on a Cornell box, error against time,
//! - [`overhead`]: the renderer against hand-written casters (the render plan's cost),
//! - [`report`], [`figures`], [`plot`], [`stats`]: Markdown, CSV, JSON and PNG output,
//! - [`machine`]: the machine line,
//! - [`error`]: why a run stopped.
//!
//! Everything timed is single-threaded; only the untimed `f64` reference uses every core.
#![deny(unsafe_code)]

pub mod accuracy;
pub mod cli;
#[cfg(feature = "embree")]
pub mod embree;
pub mod error;
pub mod figures;
pub mod fireflies;
pub mod gi;
pub mod images;
pub mod machine;
pub mod mt;
pub mod objects;
pub mod ours;
pub mod overhead;
pub mod peers;
pub mod plot;
pub mod refit;
pub mod report;
pub mod results;
pub mod rounds;
pub mod scale;
pub mod stats;
#[cfg(feature = "tinybvh")]
pub mod tinybvh8;
pub mod workload;

use crate::error::Error;
use host::compare::{compare_hits, DEFAULT_REL};
use report::{BenchResults, ReferenceRow, Written};
use results::HitMissSplit;
use std::path::PathBuf;
use std::time::Instant;
use workload::RaySource;

/// The optional peers this build has (cargo features), for the report's command line.
pub const FEATURES: &[&str] = &[
    #[cfg(feature = "embree")]
    "embree",
    #[cfg(feature = "tinybvh")]
    "tinybvh",
];

/// What to run.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BenchConfig {
    /// Directory of `NAME.obj` and `NAME.camera`.
    pub scenes_dir: PathBuf,
    /// Scene names.
    pub scenes: Vec<String>,
    /// Where the tiled city is kept (made there when absent); `None`: no city.
    pub city_dir: Option<PathBuf>,
    /// Where the rays come from.
    pub rays: RaySource,
    /// Output directory: `BENCHMARKS.md`, `data.csv`, `data.json`, `plots/`.
    pub out: PathBuf,
    /// Trace every `stride`-th ray.
    pub stride: usize,
    /// Runs per figure (medians).
    pub runs: usize,
    /// Measure the peers too.
    pub peers: bool,
    /// Interleaved rounds per ray set (0: skipped); see [`rounds`].
    pub rounds: usize,
    /// The tiled-scene sweep (empty sizes: skipped).
    pub scale: scale::ScaleOptions,
    /// The image-convergence renders (`None`: skipped).
    pub images: Option<images::ImageOptions>,
    /// The path tracer against Mitsuba 3 (`None`: skipped).
    pub gi: Option<gi::GiOptions>,
    /// Spheres of the objects comparison (0: skipped); see [`objects`].
    pub objects: usize,
    /// `--quick` (noted in the report).
    pub quick: bool,
    /// The command line, for the report.
    pub command: String,
}

/// Runs the benchmark and writes the report, data and plots.
///
/// # Errors
/// Missing inputs ([`Error::Bench`] says what and how to get them), unreadable scenes or ray
/// files, a build the kernel refuses, or an unwritable output.
pub fn run(config: &BenchConfig) -> Result<(BenchResults, Written), Error> {
    let start = Instant::now();
    let mut machine = machine::Machine::probe();
    let stride = config.stride.max(1);
    let runs = config.runs.max(1);
    let opts = ours::RunOptions { runs };
    eprintln!("bench: {}", machine.line());
    let mut scenes = workload::load_scenes(&config.scenes_dir, &config.scenes, &config.rays)?;
    if let Some(dir) = &config.city_dir {
        eprintln!("bench: the tiled city ({})", dir.display());
        scenes.push(workload::load_city(&config.scenes_dir, dir, &config.rays)?);
    }
    workload::keep_every(&mut scenes, stride);
    let threads = machine.cores.max(1);
    // Warm-up, untimed: the reference configuration once on the first ray set. Without it the
    // first figure of a run came out 10–20% below the same configuration measured later in
    // the run (the machine settling: clocks, page faults of fresh allocations).
    if let Some((scene, set)) = scenes.iter().find_map(|s| Some((s, s.ray_sets.first()?))) {
        eprintln!(
            "bench: warm-up ({} {}, untimed)",
            scene.name,
            set.kind.name()
        );
        ours::warm_up(scene, set)?;
    }
    let mut rows = Vec::new();
    let mut references = Vec::new();
    let mut round_rows = Vec::new();
    for scene in &scenes {
        let tris: Vec<[[f32; 3]; 3]> = (0..scene.mesh.triangle_count())
            .map(|i| scene.mesh.triangle_f32(i))
            .collect();
        for set in &scene.ray_sets {
            eprintln!(
                "bench: {} {} ({} rays traced, stride {stride})",
                scene.name,
                set.kind.name(),
                set.records.len()
            );
            let mut set_rows = ours::run(scene, set, opts)?;
            if config.peers {
                for &peer in peers::Peer::ALL {
                    eprintln!("bench:   {}", peer.name());
                    set_rows.extend(peers::run(peer, scene, set, opts));
                }
            }
            if config.rounds > 0 {
                eprintln!("bench:   interleaved rounds ({})", config.rounds);
                round_rows.push(rounds::run(scene, set, config.rounds, config.peers)?);
            }
            let reference =
                accuracy::Reference::compute(&tris, &set.records, threads).map_err(|source| {
                    host::Error::Build {
                        scene: scene.path.clone(),
                        source,
                    }
                })?;
            references.push(ReferenceRow {
                scene: scene.name.clone(),
                rays: set.kind,
                ray_count: reference.len(),
                hits: reference.hit_count(),
            });
            let ours_hits = set_rows
                .first()
                .filter(|r| r.ours)
                .map(|r| r.hit_records.clone())
                .unwrap_or_default();
            for row in &mut set_rows {
                row.accuracy = Some(reference.accuracy(&row.hit_records));
                if !row.ours {
                    row.vs_ours = Some(compare_hits(&ours_hits, &row.hit_records, DEFAULT_REL));
                    row.hitmiss_split = Some(HitMissSplit::of(&ours_hits, &row.hit_records));
                }
                // The hits have served; a full run would otherwise keep ~100 MB per set.
                row.hit_records = Vec::new();
            }
            rows.extend(set_rows);
        }
    }
    let scale_rows = if config.scale.sizes.is_empty() {
        Vec::new()
    } else {
        let meshes: Vec<&host::obj::Mesh> = scenes.iter().map(|s| &s.mesh).collect();
        scale::run(&meshes, &config.scale)?
    };
    let refit_rows = refit::run(&scenes, opts)?;
    eprintln!("bench: render overhead");
    let overhead_rows = overhead::run(if config.quick { 3 } else { 31 });
    let objects_rows = if config.objects == 0 {
        Vec::new()
    } else {
        objects::run(config.objects, runs)
    };
    let image_rows = match &config.images {
        Some(opts) => images::run(opts)?,
        None => Vec::new(),
    };
    let firefly_rows = match &config.images {
        Some(opts) => fireflies::run(config.quick, opts.threads)?,
        None => Vec::new(),
    };
    let gi_results = config.gi.as_ref().map(gi::run).transpose()?;
    machine.finish();
    let mut results = BenchResults {
        machine,
        command: config.command.clone(),
        quick: config.quick,
        stride,
        runs,
        ray_source: match &config.rays {
            RaySource::Files(dir) => format!("ray files from make_rays.py in {}", dir.display()),
            RaySource::MakeRays => "ray files written by make_rays.py for this run".into(),
            RaySource::Rust { count } => format!(
                "{count} rays per set generated in Rust (primary: WORKLOAD.md's camera; \
                 incoherent: SplitMix64, not the files' PCG64 rays)"
            ),
        } + &match (&config.city_dir, &config.rays) {
            (None, _) => String::new(),
            (Some(_), RaySource::Rust { .. }) => {
                "; the city from make_tiled.py, its rays generated as the others".into()
            }
            (Some(dir), _) => format!(
                "; the city from make_tiled.py and its rays from make_rays.py in {}",
                dir.display()
            ),
        },
        rows,
        rounds: round_rows,
        reference: references,
        scale: scale_rows,
        refit: refit_rows,
        images: image_rows,
        gi: gi_results,
        fireflies: firefly_rows,
        overhead: overhead_rows,
        objects: objects_rows,
        slopes: Vec::new(),
        elapsed_s: 0.0,
    };
    std::fs::create_dir_all(&config.out)
        .map_err(|e| Error::Bench(format!("cannot create {}: {e}", config.out.display())))?;
    results.elapsed_s = start.elapsed().as_secs_f64();
    let written = report::write_all(&mut results, &config.out)?;
    Ok((results, written))
}
