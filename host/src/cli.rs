//! The command line: argument types (clap derive) and the commands behind them.
//!
//! Each command returns the JSON object `main` prints as the last line of stdout.

use crate::check::{check_scene, describe_differences, CaseReport};
use crate::classify::{classify, Classification};
use crate::compare::{compare_hits, Comparison, DEFAULT_REL};
use crate::error::Error;
use crate::obj::load_obj;
use crate::rayfile::{read_hits, read_rays, write_hits};
use crate::render::{
    accel_choice, accel_name, mode_name, plan, render, write_pfm, write_png, RenderError,
    RenderOptions,
};
use crate::scene::{resolve_scene, DEFAULT_SCENE};
use crate::scenefile::{write_scene_file, FilterName, SamplerName};
use crate::spec::{SceneOrigin, SceneSpec};
use crate::trace::{trace, AccelKind, Builder, Mode, TraceConfig};
use clap::builder::RangedU64ValueParser;
use clap::{Args, Parser, Subcommand};
use raykernel::bvh::{BuildOptions, BuilderKind, DEFAULT_LEAF_SIZE, MAX_LEAF_SIZE};
use raykernel::render::{scenes, Settings};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// Command-line host for raykernel.
#[derive(Debug, Parser)]
#[command(name = "host", version, about)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Trace a ray file against an OBJ scene and write the closest hits.
    Trace(TraceArgs),
    /// Compare two hit files ray by ray (same rule as shared/bench/compare_hits.py); with
    /// --scene and --rays, also check each differing ray passes within quantization error of an
    /// edge of a reported triangle.
    CompareHits(CompareArgs),
    /// Benchmark speed and accuracy on the shared scenes, with peers in the same run; writes
    /// BENCHMARKS.md, data.csv, data.json and plots/ into --out.
    Bench(BenchArgs),
    /// Render a scene with the distribution ray tracer: a built-in scene (default `cornell`),
    /// a scene file (.json, see docs/SCENE_FORMAT.md) or an OBJ mesh; PNG out, optionally
    /// linear PFM; parallel over tiles.
    Render(RenderArgs),
    /// Render scenes every way (kernel single-threaded, host tiles at several thread counts
    /// and tile sizes, every accelerator) and check all are byte-identical.
    Check(CheckArgs),
}

/// Settings a command line may override (scene or file settings otherwise).
#[derive(Clone, Debug, Default, Args)]
pub struct SettingsArgs {
    /// Image width in pixels [default: the scene file's, else 512].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=16384))]
    pub width: Option<u32>,
    /// Image height in pixels [default: the scene file's, else 512 (built-ins keep their
    /// aspect ratio)].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=16384))]
    pub height: Option<u32>,
    /// Samples per pixel [default: the scene file's, else 64].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    pub spp: Option<u32>,
    /// Most reflection bounces [default: the scene's].
    #[arg(long, value_parser = clap::value_parser!(u32).range(0..=64))]
    pub max_depth: Option<u32>,
    /// Sample placement [default: the scene's].
    #[arg(long, value_enum)]
    pub sampler: Option<SamplerName>,
    /// Pixel filter [default: the scene's].
    #[arg(long, value_enum)]
    pub filter: Option<FilterName>,
    /// Seed of every random value [default: the scene's].
    #[arg(long)]
    pub seed: Option<u32>,
}

impl SettingsArgs {
    /// `base` with every given flag applied.
    #[must_use]
    pub fn apply(&self, base: Settings) -> Settings {
        Settings {
            width: self.width.unwrap_or(base.width),
            height: self.height.unwrap_or(base.height),
            spp: self.spp.unwrap_or(base.spp),
            max_depth: self.max_depth.unwrap_or(base.max_depth),
            sampler: self.sampler.map_or(base.sampler, Into::into),
            filter: self.filter.map_or(base.filter, Into::into),
            seed: self.seed.unwrap_or(base.seed),
        }
    }
}

/// `host render [SCENE] --out FILE.png [options]`.
#[derive(Clone, Debug, Args)]
pub struct RenderArgs {
    /// A built-in scene (cornell, spheres, motion), a scene file (.json) or an OBJ mesh (.obj,
    /// camera from NAME.camera beside it or framed) [default: cornell].
    pub scene: Option<String>,
    /// The PNG to write (8-bit sRGB).
    #[arg(long, required_unless_present_any = ["explain", "dump_scene"])]
    pub out: Option<PathBuf>,
    /// Also write the linear image (mean radiance per pixel, unclipped) as a PFM file.
    #[arg(long, value_name = "FILE.pfm")]
    pub linear: Option<PathBuf>,
    /// Also write the linear image as an OpenEXR file (32-bit float RGB, the PFM's values).
    #[arg(long, value_name = "FILE.exr")]
    pub exr: Option<PathBuf>,
    /// Write the scene, with the settings this command would render it with, as a scene file.
    #[arg(long, value_name = "FILE.json")]
    pub dump_scene: Option<PathBuf>,
    /// Print the render plan (what the kernel will do) and exit without rendering.
    #[arg(long)]
    pub explain: bool,
    /// Settings.
    #[command(flatten)]
    pub settings: SettingsArgs,
    /// Number mode of the kernel's geometry.
    #[arg(long, value_enum, default_value_t = Mode::F32)]
    pub mode: Mode,
    /// Worker threads [default: the available parallelism].
    #[arg(long, value_parser = RangedU64ValueParser::<usize>::new().range(1..=1024))]
    pub threads: Option<usize>,
    /// Accelerator of every object.
    #[arg(long, value_enum, default_value_t = AccelKind::Bvh)]
    pub accel: AccelKind,
    /// BVH builder.
    #[arg(long, value_enum, default_value_t = Builder::Sah)]
    pub builder: Builder,
    /// Largest BVH leaf (1..=64).
    #[arg(long, default_value_t = DEFAULT_LEAF_SIZE,
          value_parser = clap::value_parser!(u32).range(1..=i64::from(MAX_LEAF_SIZE)))]
    pub leaf: u32,
    /// Skip the BVH's reinsertion pass (keep the tree exactly as the builder split it).
    #[arg(long)]
    pub no_reinsertion: bool,
    /// Tile size in pixels (square tiles, rendered in parallel).
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub tile: u32,
}

/// `host check [SCENE...]`.
#[derive(Clone, Debug, Args)]
pub struct CheckArgs {
    /// Scenes as for `host render` [default: every built-in scene].
    pub scenes: Vec<String>,
    /// Only this mode [default: both].
    #[arg(long, value_enum)]
    pub mode: Option<Mode>,
    /// Settings [default: each scene's own].
    #[command(flatten)]
    pub settings: SettingsArgs,
}

/// The JSON report of `host render`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RenderReport {
    /// Scene name.
    pub scene: String,
    /// `built-in`, or the scene file or OBJ.
    pub source: String,
    /// PNG written, if any.
    pub out: Option<String>,
    /// PFM written, if any.
    pub linear: Option<String>,
    /// Scene file written, if any.
    pub dump_scene: Option<String>,
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Samples per pixel.
    pub spp: u32,
    /// `f32` or `fixed`.
    pub mode: &'static str,
    /// Accelerator: `linear` or `bvh BUILDER leaf N`.
    pub accel: String,
    /// Triangles.
    pub triangles: usize,
    /// Spheres.
    pub spheres: usize,
    /// The render plan (what the kernel does).
    pub plan: String,
    /// Figures of the render (absent with `--explain` or a dump only).
    #[serde(flatten)]
    pub figures: Option<RenderFigures>,
}

/// Times and ray counts of a render.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RenderFigures {
    /// Threads used.
    pub threads: usize,
    /// Tile size.
    pub tile: u32,
    /// Scene conversion and accelerator builds.
    pub build_ms: f64,
    /// Rendering every tile (all threads; no encoding or file writes).
    pub render_ms: f64,
    /// Camera rays.
    pub camera_rays: u64,
    /// Shadow rays.
    pub shadow_rays: u64,
    /// Reflection rays.
    pub reflection_rays: u64,
    /// Every ray.
    pub rays: u64,
    /// Million rays per second of render time.
    pub mrays_per_s: f64,
}

impl RenderReport {
    /// Lines for people: the plan, then what was rendered and how fast, or what was written.
    #[must_use]
    pub fn summary(&self) -> String {
        let mut lines = vec![format!("plan: {}", self.plan)];
        if let Some(f) = &self.figures {
            let m = |n: u64| n as f64 / 1e6;
            lines.push(format!(
                "rendered {} at {}x{}, {} spp, {}, {}, {} thread{}: build {:.1} ms, render \
                 {:.2} s, {:.1} M rays ({:.1} M camera + {:.1} M shadow + {:.1} M reflection), \
                 {:.2} Mrays/s -> {}",
                self.scene,
                self.width,
                self.height,
                self.spp,
                self.mode,
                self.accel,
                f.threads,
                if f.threads == 1 { "" } else { "s" },
                f.build_ms,
                f.render_ms / 1e3,
                m(f.rays),
                m(f.camera_rays),
                m(f.shadow_rays),
                m(f.reflection_rays),
                f.mrays_per_s,
                self.out.as_deref().unwrap_or("-")
            ));
        }
        if let Some(d) = &self.dump_scene {
            lines.push(format!("wrote scene file {d}"));
        }
        lines.join("\n")
    }
}

/// The JSON report of `host check`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CheckReport {
    /// One entry per scene and mode.
    pub cases: Vec<CaseReport>,
    /// Renders compared with their reference.
    pub renders: usize,
    /// Renders that differ.
    pub differences: usize,
}

/// `host trace SCENE.obj RAYS --out HITS [options]`.
#[derive(Clone, Debug, Args)]
pub struct TraceArgs {
    /// The scene (Wavefront OBJ).
    pub scene: PathBuf,
    /// The rays: 32-byte records `ox oy oz dx dy dz tmin tmax`, little-endian f32.
    pub rays: PathBuf,
    /// Where to write the hits: 8-byte records `t: f32, prim: u32` per traced ray.
    #[arg(long)]
    pub out: PathBuf,
    /// Accelerator.
    #[arg(long, value_enum, default_value_t = AccelKind::Bvh)]
    pub accel: AccelKind,
    /// BVH builder.
    #[arg(long, value_enum, default_value_t = Builder::Sah)]
    pub builder: Builder,
    /// Number mode.
    #[arg(long, value_enum, default_value_t = Mode::F32)]
    pub mode: Mode,
    /// Largest BVH leaf (1..=64).
    #[arg(long, default_value_t = DEFAULT_LEAF_SIZE,
          value_parser = clap::value_parser!(u32).range(1..=i64::from(MAX_LEAF_SIZE)))]
    pub leaf: u32,
    /// Skip the BVH's reinsertion pass (keep the tree exactly as the builder split it).
    #[arg(long)]
    pub no_reinsertion: bool,
    /// Trace only rays 0, K, 2K, ... (hit files of equal stride are comparable).
    #[arg(long, value_name = "K", default_value_t = 1,
          value_parser = RangedU64ValueParser::<usize>::new().range(1..))]
    pub stride: usize,
    /// Full runs (build + trace) in one process; times reported are the medians.
    #[arg(long, value_name = "N", default_value_t = 1,
          value_parser = RangedU64ValueParser::<usize>::new().range(1..))]
    pub runs: usize,
    /// Build with the primitives permuted into leaf order (BVH only; hits keep original ids).
    #[arg(long)]
    pub leaf_order: bool,
}

/// `host compare-hits REF OTHER [--rel R] [--scene OBJ --rays RAYS]`.
#[derive(Clone, Debug, Args)]
pub struct CompareArgs {
    /// The reference hit file.
    pub reference: PathBuf,
    /// The hit file to compare with it.
    pub other: PathBuf,
    /// Relative tolerance on t.
    #[arg(long, default_value_t = DEFAULT_REL)]
    pub rel: f64,
    /// The scene both hit files were traced against: classify the rays whose prim differs.
    #[arg(long, requires = "rays")]
    pub scene: Option<PathBuf>,
    /// The ray file both hit files were traced from (whole file, stride 1).
    #[arg(long, requires = "scene")]
    pub rays: Option<PathBuf>,
}

/// The JSON report of `host compare-hits`: the agreement figures, plus the classification of the
/// differing rays when `--scene` and `--rays` are given.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CompareReport {
    /// Agreement figures.
    #[serde(flatten)]
    pub comparison: Comparison,
    /// Classification of the rays whose prim ids differ.
    #[serde(flatten)]
    pub classification: Option<Classification>,
}

/// `host bench [--quick] [--rays DIR | --rust-rays] [--out DIR] [options]`.
#[derive(Clone, Debug, Args)]
pub struct BenchArgs {
    /// CI smoke test: every 64th ray, one run, scale sweep up to 100k triangles.
    #[arg(long)]
    pub quick: bool,
    /// Directory of the scenes (NAME.obj, NAME.camera).
    #[arg(long, value_name = "DIR", default_value = "../shared/scenes")]
    pub scenes: PathBuf,
    /// Scenes to run (repeatable).
    #[arg(long = "scene", value_name = "NAME", default_values_t = ["bunny".to_string(), "sponza".to_string(), "kitchen".to_string()])]
    pub scene_names: Vec<String>,
    /// Ray files from `make_rays.py --out DIR` [default: run make_rays.py into a temp dir].
    #[arg(long, value_name = "DIR", conflicts_with = "rust_rays")]
    pub rays: Option<PathBuf>,
    /// Generate the rays in Rust instead (primary by WORKLOAD.md's camera formula,
    /// incoherent from SplitMix64: not the files' rays).
    #[arg(long)]
    pub rust_rays: bool,
    /// Rays per set with --rust-rays.
    #[arg(long, value_name = "N", default_value_t = 1 << 20,
          value_parser = RangedU64ValueParser::<usize>::new().range(1..))]
    pub rays_per_set: usize,
    /// Output directory.
    #[arg(long, value_name = "DIR", default_value = "docs/bench")]
    pub out: PathBuf,
    /// Trace every K-th ray [default: 1, or 64 with --quick].
    #[arg(long, value_name = "K", value_parser = RangedU64ValueParser::<usize>::new().range(1..))]
    pub stride: Option<usize>,
    /// Runs per figure, medians [default: 3, or 1 with --quick].
    #[arg(long, value_name = "N", value_parser = RangedU64ValueParser::<usize>::new().range(1..))]
    pub runs: Option<usize>,
    /// Skip the peers.
    #[arg(long)]
    pub no_peers: bool,
    /// Interleaved rounds per ray set: the headline contender and tinybvh's BVH2 (with the
    /// `tinybvh` feature) traced in alternation; `0` skips them [default: 7, or 2 with --quick].
    #[arg(long, value_name = "N")]
    pub rounds: Option<usize>,
    /// Tiled-scene sizes in triangles, comma-separated; `0` skips the sweep
    /// [default: 10k..2M, or 10k..100k with --quick].
    #[arg(long, value_name = "N,N,...", value_delimiter = ',')]
    pub scale: Option<Vec<usize>>,
    /// Rays per set in the scale sweep [default: 262144, or 16384 with --quick].
    #[arg(long, value_name = "N", value_parser = RangedU64ValueParser::<usize>::new().range(1..))]
    pub scale_rays: Option<usize>,
    /// Skip the image-convergence renders (RMSE against time per sampler).
    #[arg(long)]
    pub no_images: bool,
    /// Largest sample count of the image renders (1, 2, 4, … up to it; the reference uses 16
    /// times as many) [default: 256, or 16 with --quick].
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub image_spp: Option<u32>,
}

/// The JSON report of `host bench`: where the files went, and the run's size.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BenchReport {
    /// The Markdown report.
    pub report: String,
    /// The CSV.
    pub csv: String,
    /// The JSON.
    pub json: String,
    /// PNG plots.
    pub plots: Vec<String>,
    /// Trace rows (ours and peers).
    pub rows: usize,
    /// Scale rows.
    pub scale_rows: usize,
    /// Wall time, seconds.
    pub elapsed_s: f64,
}

/// The JSON report of `host trace`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TraceReport {
    /// Scene path.
    pub scene: String,
    /// Ray file path.
    pub rays_file: String,
    /// Hit file path.
    pub out: String,
    /// `bvh`, `linear`, `grid` or `kdtree`.
    pub accel: &'static str,
    /// `sah`, `median` or `midpoint`; `null` for linear.
    pub builder: Option<&'static str>,
    /// `f32` or `fixed`.
    pub mode: &'static str,
    /// Largest leaf.
    pub leaf: u32,
    /// The BVH's reinsertion pass was asked for (BVH only).
    pub reinsertion: bool,
    /// Primitives permuted into leaf order at build time.
    pub leaf_order: bool,
    /// Full runs (build + trace); the times are medians over them.
    pub runs: usize,
    /// Ray stride.
    pub stride: usize,
    /// Triangles in the scene.
    pub triangles: usize,
    /// Median wall time of the build, leaf-order permutation included (0 for linear).
    pub build_ms: f64,
    /// Median wall time of turning records into kernel rays, before tracing.
    pub setup_ms: f64,
    /// Median wall time of tracing and storing every traced ray (no setup, no file I/O).
    pub trace_ms: f64,
    /// Build time of each run.
    pub build_ms_runs: Vec<f64>,
    /// Trace time of each run.
    pub trace_ms_runs: Vec<f64>,
    /// Rays traced.
    pub rays: usize,
    /// Rays in the file.
    pub rays_in_file: usize,
    /// Million rays per second of the median trace time.
    pub mrays_per_s: f64,
    /// Million rays per second counting setup as well.
    pub mrays_per_s_with_setup: f64,
    /// Rays that hit.
    pub hits: usize,
    /// Rays the kernel rejected, written as misses.
    pub bad_rays: usize,
    /// BVH nodes (bvh4: 4-wide nodes; 0 for linear).
    pub nodes: usize,
    /// Bytes of BVH nodes and primitive ids per triangle (bvh4: its 4-wide nodes and the ids;
    /// the BVH it is collapsed from is build scratch, not counted; 0 for linear).
    pub bytes_per_tri: f64,
    /// BVH depth (bvh4: depth of the deepest 4-wide node; 0 for linear).
    pub depth: u32,
}

/// Runs a parsed command line; returns what to print: the command's one-line JSON report as
/// the last line (`render` puts a summary line for people before it).
///
/// # Errors
/// Whatever the command fails with.
pub fn run(cli: &Cli) -> Result<String, Error> {
    let (summary, json) = match &cli.command {
        Command::Trace(args) => (None, serde_json::to_string(&run_trace(args)?)),
        Command::CompareHits(args) => (None, serde_json::to_string(&run_compare(args)?)),
        Command::Bench(args) => (None, serde_json::to_string(&run_bench(args)?)),
        Command::Render(args) => {
            let report = run_render(args)?;
            (Some(report.summary()), serde_json::to_string(&report))
        }
        Command::Check(args) => {
            let report = run_check(args)?;
            let line = format!(
                "check passed: {} renders of {} scene/mode cases identical to the kernel's",
                report.renders,
                report.cases.len()
            );
            (Some(line), serde_json::to_string(&report))
        }
    };
    // Structs of numbers and strings always serialize; the fallback only avoids a panic path.
    let json = json.unwrap_or_else(|e| format!("{{\"error\":\"cannot encode report: {e}\"}}"));
    Ok(match summary {
        Some(line) => format!("{line}\n{json}"),
        None => json,
    })
}

/// Samples per pixel of `host render` for built-in scenes (their own settings are the small
/// ones of the snapshot tests).
pub const BUILT_IN_SPP: u32 = 64;
/// Width of `host render` for built-in scenes; the height keeps the scene's aspect ratio.
pub const BUILT_IN_WIDTH: u32 = 512;

/// The settings `host render` uses for `spec` before command-line flags: a scene file's or an
/// OBJ's own; for a built-in, 512 pixels wide (its aspect kept) at 64 spp.
#[must_use]
pub fn render_base_settings(spec: &SceneSpec) -> Settings {
    let s = spec.settings;
    match spec.origin {
        SceneOrigin::BuiltIn => Settings {
            width: BUILT_IN_WIDTH,
            height: ((u64::from(BUILT_IN_WIDTH) * u64::from(s.height) + u64::from(s.width) / 2)
                / u64::from(s.width.max(1)))
            .clamp(1, 16384) as u32,
            spp: BUILT_IN_SPP,
            ..s
        },
        SceneOrigin::File(_) | SceneOrigin::Obj(_) => s,
    }
}

fn render_error(spec: &SceneSpec, mode: Mode) -> impl Fn(RenderError) -> Error + '_ {
    move |e| match e {
        RenderError::Scene(e) => spec.explain(&e, mode_name(mode)),
        RenderError::Pool(msg) => Error::Usage(format!("cannot start threads: {msg}")),
    }
}

/// `host render`: load the scene, then dump it, explain the plan, or render and write images.
///
/// # Errors
/// An unknown scene, a bad or unreadable scene file, OBJ or `.camera` file, a scene the
/// kernel rejects in the chosen mode, or an unwritable output.
pub fn run_render(args: &RenderArgs) -> Result<RenderReport, Error> {
    let mut spec = resolve_scene(args.scene.as_deref().unwrap_or(DEFAULT_SCENE))?;
    spec.settings = args.settings.apply(render_base_settings(&spec));
    let settings = spec.settings;
    let data = spec.data();
    let mode = args.mode;
    if args.accel == AccelKind::Bvh4 {
        return Err(Error::Usage(
            "--accel bvh4 is for `host trace` only: the renderer has no 4-wide BVH".into(),
        ));
    }
    let accel = accel_choice(
        args.accel,
        BuildOptions {
            builder: args.builder.into(),
            max_leaf_size: args.leaf,
            reinsertion: !args.no_reinsertion,
        },
    );
    let the_plan = plan(&data, settings, mode).map_err(|e| spec.explain(&e, mode_name(mode)))?;
    if let Some(path) = &args.dump_scene {
        write_scene_file(path, &data, &spec.material_names)?;
    }
    let mut report = RenderReport {
        scene: spec.name.clone(),
        source: match &spec.origin {
            SceneOrigin::BuiltIn => "built-in".into(),
            SceneOrigin::File(p) | SceneOrigin::Obj(p) => p.display().to_string(),
        },
        out: None,
        linear: None,
        dump_scene: args.dump_scene.as_ref().map(|p| p.display().to_string()),
        width: settings.width,
        height: settings.height,
        spp: settings.spp,
        mode: mode_name(mode),
        accel: accel_name(accel),
        triangles: spec.triangles.len(),
        spheres: spec.spheres.len(),
        plan: the_plan.to_string(),
        figures: None,
    };
    let Some(out) = args.out.as_ref().filter(|_| !args.explain) else {
        return Ok(report);
    };
    let threads = args.threads.unwrap_or_else(|| {
        std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get)
    });
    let options = RenderOptions {
        mode,
        accel,
        threads,
        tile: (args.tile, args.tile),
        progress: true,
    };
    let r = render(&data, settings, &options).map_err(render_error(&spec, mode))?;
    write_png(out, &r.frame.srgb8())?;
    if let Some(path) = &args.linear {
        write_pfm(path, &r.frame)?;
        report.linear = Some(path.display().to_string());
    }
    if let Some(path) = &args.exr {
        crate::exr::write_exr(path, &r.frame)?;
    }
    report.out = Some(out.display().to_string());
    let rays = r.stats.rays();
    report.figures = Some(RenderFigures {
        threads,
        tile: args.tile,
        build_ms: r.build_ms,
        render_ms: r.render_ms,
        camera_rays: r.stats.camera_rays,
        shadow_rays: r.stats.shadow_rays,
        reflection_rays: r.stats.reflection_rays,
        rays,
        mrays_per_s: if r.render_ms > 0.0 {
            rays as f64 / r.render_ms / 1e3
        } else {
            0.0
        },
    });
    Ok(report)
}

/// `host check`: every scene (default: every built-in) in each mode, every way of rendering,
/// byte for byte.
///
/// # Errors
/// A scene that cannot be loaded or rendered, or [`Error::Mismatch`] listing every render that
/// differs (the first differing pixel and both values).
pub fn run_check(args: &CheckArgs) -> Result<CheckReport, Error> {
    let names: Vec<String> = if args.scenes.is_empty() {
        scenes::ALL.iter().map(|s| s.name.to_string()).collect()
    } else {
        args.scenes.clone()
    };
    let modes = match args.mode {
        Some(m) => vec![m],
        None => vec![Mode::F32, Mode::Fixed],
    };
    let mut cases = Vec::new();
    for name in &names {
        let mut spec = resolve_scene(name)?;
        spec.settings = args.settings.apply(spec.settings);
        for &mode in &modes {
            cases.push(check_scene(&spec, mode)?);
        }
    }
    let lines = describe_differences(&cases);
    if !lines.is_empty() {
        return Err(Error::Mismatch(format!(
            "check failed: {}",
            lines.join("\ncheck failed: ")
        )));
    }
    Ok(CheckReport {
        renders: cases.iter().map(|c| c.compared).sum(),
        differences: 0,
        cases,
    })
}

/// `host trace`: load the scene and rays, trace, write the hits.
///
/// # Errors
/// Bad or unreadable inputs, an unwritable output, or a build the kernel refuses.
pub fn run_trace(args: &TraceArgs) -> Result<TraceReport, Error> {
    let bvh_family = matches!(args.accel, AccelKind::Bvh | AccelKind::Bvh4);
    if args.leaf_order && !bvh_family {
        return Err(Error::Usage(
            "--leaf-order needs --accel bvh or bvh4 (the other accelerators do not permute \
             primitives)"
                .into(),
        ));
    }
    let mesh = load_obj(&args.scene)?;
    let rays = read_rays(&args.rays)?;
    let config = TraceConfig {
        accel: args.accel,
        build: BuildOptions {
            builder: args.builder.into(),
            max_leaf_size: args.leaf,
            reinsertion: !args.no_reinsertion,
        },
        mode: args.mode,
        stride: args.stride,
        runs: args.runs,
        leaf_order: args.leaf_order,
    };
    let output = trace(&mesh, &args.scene, &rays, &config)?;
    write_hits(&args.out, &output.hits)?;
    let s = output.stats;
    let per_s = |ms: f64| {
        if ms > 0.0 {
            s.rays as f64 / ms / 1e3
        } else {
            0.0
        }
    };
    Ok(TraceReport {
        scene: args.scene.display().to_string(),
        rays_file: args.rays.display().to_string(),
        out: args.out.display().to_string(),
        accel: args.accel.name(),
        builder: bvh_family.then(|| BuilderKind::from(args.builder).name()),
        mode: args.mode.name(),
        leaf: args.leaf,
        reinsertion: bvh_family && !args.no_reinsertion,
        leaf_order: args.leaf_order,
        runs: args.runs,
        stride: args.stride,
        triangles: s.triangles,
        build_ms: s.build_ms,
        setup_ms: s.setup_ms,
        trace_ms: s.trace_ms,
        build_ms_runs: s.build_ms_runs,
        trace_ms_runs: s.trace_ms_runs,
        rays: s.rays,
        rays_in_file: rays.len(),
        mrays_per_s: per_s(s.trace_ms),
        mrays_per_s_with_setup: per_s(s.trace_ms + s.setup_ms),
        hits: s.hits,
        bad_rays: s.bad_rays,
        nodes: s.nodes,
        bytes_per_tri: if s.triangles > 0 {
            s.accel_bytes as f64 / s.triangles as f64
        } else {
            0.0
        },
        depth: s.depth,
    })
}

/// `host bench`: run the benchmark, write the report, data and plots.
///
/// # Errors
/// Missing inputs (the message says how to get them), bad scene or ray files, a build the
/// kernel refuses, or an unwritable output directory.
pub fn run_bench(args: &BenchArgs) -> Result<BenchReport, Error> {
    use crate::bench::{scale::ScaleOptions, workload::RaySource, BenchConfig};
    let rays = match (&args.rays, args.rust_rays) {
        (Some(dir), _) => RaySource::Files(dir.clone()),
        (None, true) => RaySource::Rust {
            count: args.rays_per_set,
        },
        (None, false) => RaySource::MakeRays,
    };
    let sizes = match &args.scale {
        Some(sizes) => sizes.iter().copied().filter(|&n| n > 0).collect(),
        None => crate::bench::scale::default_sizes(args.quick),
    };
    let config = BenchConfig {
        scenes_dir: args.scenes.clone(),
        scenes: args.scene_names.clone(),
        rays,
        out: args.out.clone(),
        stride: args.stride.unwrap_or(if args.quick { 64 } else { 1 }),
        runs: args.runs.unwrap_or(if args.quick { 1 } else { 3 }),
        peers: !args.no_peers,
        rounds: args.rounds.unwrap_or(if args.quick { 2 } else { 7 }),
        scale: ScaleOptions {
            sizes,
            rays: args
                .scale_rays
                .unwrap_or(if args.quick { 1 << 14 } else { 1 << 18 }),
            runs: args.runs.unwrap_or(if args.quick { 1 } else { 3 }),
        },
        images: (!args.no_images).then(|| {
            let threads = std::thread::available_parallelism().map_or(1, usize::from);
            crate::bench::images::ImageOptions::new(args.quick, args.image_spp, threads)
        }),
        quick: args.quick,
        command: bench_command(),
    };
    let (results, written) = crate::bench::run(&config)?;
    let show = |p: &Path| p.display().to_string();
    Ok(BenchReport {
        report: show(&written.report),
        csv: show(&written.csv),
        json: show(&written.json),
        plots: written.plots.iter().map(|p| show(p)).collect(),
        rows: results.rows.len(),
        scale_rows: results.scale.len(),
        elapsed_s: results.elapsed_s,
    })
}

/// The command line as typed, with the program shown as `host`.
fn bench_command() -> String {
    let mut words: Vec<String> = std::env::args().skip(1).collect();
    words.insert(0, "host".into());
    words.join(" ")
}

/// `host compare-hits`: agreement of OTHER with REF.
///
/// # Errors
/// Unreadable or malformed hit files, or files of different lengths; with `--scene` and
/// `--rays`, also a bad scene or ray file, or hits that do not fit them.
pub fn run_compare(args: &CompareArgs) -> Result<CompareReport, Error> {
    let reference = read_hits(&args.reference)?;
    let other = read_hits(&args.other)?;
    if reference.len() != other.len() {
        let entry = |p: &Path, n| (p.to_path_buf(), n);
        return Err(Error::HitCountMismatch {
            reference: entry(&args.reference, reference.len()),
            other: entry(&args.other, other.len()),
        });
    }
    let comparison = compare_hits(&reference, &other, args.rel);
    let classification = match (&args.scene, &args.rays) {
        (Some(scene), Some(rays_path)) => {
            let mesh = load_obj(scene)?;
            let rays = read_rays(rays_path)?;
            let c =
                classify(&reference, &other, &rays, &mesh).map_err(|source| Error::Classify {
                    scene: scene.clone(),
                    rays: rays_path.clone(),
                    source,
                })?;
            Some(c)
        }
        _ => None,
    };
    Ok(CompareReport {
        comparison,
        classification,
    })
}
