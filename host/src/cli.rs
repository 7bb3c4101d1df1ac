//! The command line: argument types (clap derive) and the commands behind them.
//!
//! Each command returns the JSON object `main` prints as the last line of stdout; lines for
//! people go through a [`Console`] as the work happens.

use crate::bake::{run_bake, run_trace_baked, BakeArgs, TraceBakedArgs};
use crate::check::{check_scene_with, describe_differences, renders_per_case, CaseReport};
use crate::classify::{classify, Classification};
use crate::compare::{compare_hits, Comparison, DEFAULT_REL};
use crate::console::Console;
use crate::error::Error;
use crate::limits::{
    check_memory, check_settings, render_bytes, MAX_DEPTH, MAX_PATH_LENGTH, MAX_SIDE, MAX_SPP,
};
use crate::obj::{load_obj, point_error_text};
use crate::output::{Format, Reserved};
use crate::rayfile::{read_hits, read_rays, write_hits, RayRecord};
use crate::render::{encode_pfm, encode_png, mode_name, plan, render, RenderError, RenderOptions};
use crate::scene::{resolve_scene, DEFAULT_SCENE};
use crate::scenefile::{
    filter_over, integrator_over, scene_file_text, spec_to_scene_file, FilterName, IntegratorName,
    SamplerName, DEFAULT_MAX_PATH_LENGTH,
};
use crate::spec::{eye_to_look_at, SceneOrigin, SceneSpec};
use crate::trace::{accel_parser, trace, Builder, Mode, TraceConfig};
use clap::builder::RangedU64ValueParser;
use clap::{Args, CommandFactory, Parser, Subcommand};
use raykernel::bvh::{BuildOptions, BuilderKind, DEFAULT_LEAF_SIZE, MAX_LEAF_SIZE};
use raykernel::render::{scenes, Camera, Integrator, RenderPlan, SamplerKind, Settings};
use raykernel::AccelKind;
use raykernel::{Ray, RayError, Scalar, I16F16};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// The program's name, as installed and as shown in help and completions.
pub const PROGRAM: &str = "raykernel";

/// Command-line host for raykernel.
#[derive(Debug, Parser)]
#[command(name = PROGRAM, version, about)]
pub struct Cli {
    /// Print only the JSON report (and warnings and errors): no summaries, no progress.
    #[arg(long, short, global = true)]
    pub quiet: bool,
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
    /// Render a scene (distribution ray tracer, or path tracer with `--integrator path`): a
    /// built-in scene (default `cornell`), a scene file (.json, see docs/SCENE_FORMAT.md) or an
    /// OBJ mesh; PNG out, optionally linear PFM; parallel over tiles.
    Render(RenderArgs),
    /// Render scenes every way (kernel single-threaded, host tiles at several thread counts
    /// and tile sizes, every accelerator) and check all are byte-identical.
    Check(CheckArgs),
    /// Print a shell completion script, e.g. `raykernel completions bash >
    /// ~/.local/share/bash-completion/completions/raykernel`.
    Completions(CompletionsArgs),
    /// Build a BVH or 4-wide BVH over an OBJ mesh and write it with its triangles as a baked
    /// file (docs/BAKED_FORMAT.md), to be loaded in place on a device.
    Bake(BakeArgs),
    /// Load a baked file as a device does (all checks, no build) and trace a ray file.
    TraceBaked(TraceBakedArgs),
}

/// `raykernel completions SHELL`.
#[derive(Clone, Debug, Args)]
pub struct CompletionsArgs {
    /// The shell.
    #[arg(value_enum)]
    pub shell: clap_complete::Shell,
}

/// Settings a command line may override (scene or file settings otherwise).
#[derive(Clone, Debug, Default, Args)]
pub struct SettingsArgs {
    /// Image width in pixels; alone, the height follows at the scene's aspect ratio
    /// (width × height ≤ 67108864) [default: the scene file's, else 512].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=i64::from(MAX_SIDE)))]
    pub width: Option<u32>,
    /// Image height in pixels; alone, the width follows at the scene's aspect ratio
    /// [default: the scene file's, else 512; built-ins: their aspect ratio at width 512].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=i64::from(MAX_SIDE)))]
    pub height: Option<u32>,
    /// Samples per pixel [default: the scene file's, else 64].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=i64::from(MAX_SPP)))]
    pub spp: Option<u32>,
    /// Most reflection bounces [default: the scene's].
    #[arg(long, value_parser = clap::value_parser!(u32).range(0..=i64::from(MAX_DEPTH)))]
    pub max_depth: Option<u32>,
    /// Light transport: `direct` (distribution ray tracing) or `path` (path tracing with light
    /// sampling and MIS) [default: the scene's].
    #[arg(long, value_enum)]
    pub integrator: Option<IntegratorName>,
    /// Most segments of a path, camera ray included (2: direct light; each more adds a bounce),
    /// for the path integrator [default: the scene's, else 5].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=i64::from(MAX_PATH_LENGTH)))]
    pub max_path_length: Option<u32>,
    /// Sample placement [default: the scene's].
    #[arg(long, value_enum)]
    pub sampler: Option<SamplerName>,
    /// Pixel filter [default: the scene's].
    #[arg(long, value_enum)]
    pub filter: Option<FilterName>,
    /// Gaussian filter: standard deviation in pixels [default: the scene's, else 0.5].
    #[arg(long)]
    pub filter_sigma: Option<f32>,
    /// Gaussian filter: truncation radius in pixels [default: the scene's, else 1.5].
    #[arg(long)]
    pub filter_radius: Option<f32>,
    /// Seed of every random value [default: the scene's].
    #[arg(long)]
    pub seed: Option<u32>,
}

/// `side × numerator / denominator`, rounded to the nearest integer, at least 1: the other side
/// of an image of aspect `numerator : denominator`.
#[must_use]
pub fn keep_aspect(side: u32, numerator: u32, denominator: u32) -> u32 {
    let scaled = (u64::from(side) * u64::from(numerator) + u64::from(denominator) / 2)
        / u64::from(denominator.max(1));
    u32::try_from(scaled.max(1)).unwrap_or(u32::MAX)
}

impl SettingsArgs {
    /// `base` with every given flag applied; a width or height given alone keeps `base`'s
    /// aspect ratio.
    #[must_use]
    pub fn apply(&self, base: Settings) -> Settings {
        let (width, height) = match (self.width, self.height) {
            (Some(w), Some(h)) => (w, h),
            (Some(w), None) => (w, keep_aspect(w, base.height, base.width)),
            (None, Some(h)) => (keep_aspect(h, base.width, base.height), h),
            (None, None) => (base.width, base.height),
        };
        Settings {
            width,
            height,
            spp: self.spp.unwrap_or(base.spp),
            max_depth: self.max_depth.unwrap_or(base.max_depth),
            integrator: integrator_over(self.integrator, self.max_path_length, base.integrator),
            sampler: self.sampler.map_or(base.sampler, Into::into),
            filter: filter_over(
                self.filter,
                self.filter_sigma,
                self.filter_radius,
                base.filter,
            ),
            seed: self.seed.unwrap_or(base.seed),
        }
    }
}

/// A point or vector on the command line: `x,y,z`.
fn parse_xyz(text: &str) -> Result<[f32; 3], String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let [x, y, z] = parts[..] else {
        return Err(format!(
            "expected three numbers `x,y,z`, found {} part(s)",
            parts.len()
        ));
    };
    let number = |t: &str| match t.parse::<f32>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(format!("`{t}` is not a finite number")),
    };
    Ok([number(x)?, number(y)?, number(z)?])
}

/// Camera settings a command line may override (the scene's camera otherwise).
#[derive(Clone, Debug, Default, Args)]
pub struct CameraArgs {
    /// Lens centre `x,y,z`.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_xyz, allow_hyphen_values = true)]
    pub eye: Option<[f32; 3]>,
    /// A point on the optical axis `x,y,z`.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_xyz, allow_hyphen_values = true)]
    pub look_at: Option<[f32; 3]>,
    /// Up hint `x,y,z`.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_xyz, allow_hyphen_values = true)]
    pub up: Option<[f32; 3]>,
    /// Full vertical field of view, degrees, strictly between 0 and 180.
    #[arg(long, value_name = "DEGREES")]
    pub vfov: Option<f32>,
    /// Lens radius in world units (0: pinhole).
    #[arg(long, value_name = "RADIUS")]
    pub aperture: Option<f32>,
    /// Distance to the plane in focus [default: the scene's; from eye to look-at when
    /// --eye or --look-at is given].
    #[arg(long, value_name = "DISTANCE")]
    pub focus: Option<f32>,
}

impl CameraArgs {
    /// `base` with every given flag applied. Lights stay where the scene put them.
    #[must_use]
    pub fn apply(&self, base: Camera) -> Camera {
        let eye = self.eye.unwrap_or(base.eye);
        let look_at = self.look_at.unwrap_or(base.look_at);
        let moved = self.eye.is_some() || self.look_at.is_some();
        Camera {
            eye,
            look_at,
            up: self.up.unwrap_or(base.up),
            vfov_deg: self.vfov.unwrap_or(base.vfov_deg),
            aperture_radius: self.aperture.unwrap_or(base.aperture_radius),
            focus_distance: self.focus.unwrap_or(if moved {
                eye_to_look_at(eye, look_at)
            } else {
                base.focus_distance
            }),
        }
    }
}

/// `raykernel render [SCENE] --out FILE.png [options]`.
#[derive(Clone, Debug, Args)]
pub struct RenderArgs {
    /// A built-in scene (cornell, spheres, motion), a scene file (.json) or an OBJ mesh (.obj,
    /// camera from NAME.camera beside it or framed) [default: cornell].
    pub scene: Option<String>,
    /// The PNG to write (8-bit sRGB; the name must end in `.png`). Checked before rendering.
    #[arg(long, value_name = "FILE.png", required_unless_present_any = ["explain", "dump_scene"])]
    pub out: Option<PathBuf>,
    /// Also write the linear image (mean radiance per pixel, unclipped) as a PFM file.
    #[arg(long, value_name = "FILE.pfm")]
    pub linear: Option<PathBuf>,
    /// Also write the linear image as an OpenEXR file (32-bit float RGB, the PFM's values).
    #[arg(long, value_name = "FILE.exr")]
    pub exr: Option<PathBuf>,
    /// Write the scene, with the settings and camera this command would render it with, as a
    /// scene file (meshes read from OBJ files are named, relative to it, not inlined).
    #[arg(long, value_name = "FILE.json")]
    pub dump_scene: Option<PathBuf>,
    /// Print the render plan (what the kernel will do) and exit without rendering.
    #[arg(long)]
    pub explain: bool,
    /// Settings.
    #[command(flatten)]
    pub settings: SettingsArgs,
    /// Camera.
    #[command(flatten)]
    pub camera: CameraArgs,
    /// Number mode of the kernel's geometry.
    #[arg(long, value_enum, default_value_t = Mode::F32)]
    pub mode: Mode,
    /// Worker threads [default: the available parallelism].
    #[arg(long, value_parser = RangedU64ValueParser::<usize>::new().range(1..=1024))]
    pub threads: Option<usize>,
    /// Accelerator of every object.
    #[arg(long, default_value = "bvh", value_parser = accel_parser())]
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

/// `raykernel check [SCENE...]`.
#[derive(Clone, Debug, Args)]
pub struct CheckArgs {
    /// Scenes as for `raykernel render` [default: every built-in scene].
    pub scenes: Vec<String>,
    /// Only this mode [default: both].
    #[arg(long, value_enum)]
    pub mode: Option<Mode>,
    /// Settings [default: each scene's own].
    #[command(flatten)]
    pub settings: SettingsArgs,
}

/// The JSON report of `raykernel render`.
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
    /// The line for people printed before rendering: `plan: ...`.
    #[must_use]
    pub fn plan_line(&self) -> String {
        format!("plan: {}", self.plan)
    }

    /// Lines for people after the work: what was rendered and how fast, what was written.
    #[must_use]
    pub fn summary(&self) -> String {
        let mut lines = Vec::new();
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

/// The JSON report of `raykernel check`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CheckReport {
    /// One entry per scene and mode.
    pub cases: Vec<CaseReport>,
    /// Renders compared with their reference.
    pub renders: usize,
    /// Renders that differ.
    pub differences: usize,
}

/// `raykernel trace SCENE.obj RAYS --out HITS [options]`.
#[derive(Clone, Debug, Args)]
pub struct TraceArgs {
    /// The scene (Wavefront OBJ).
    pub scene: PathBuf,
    /// The rays: 32-byte records `ox oy oz dx dy dz tmin tmax`, little-endian f32.
    pub rays: PathBuf,
    /// Where to write the hits: 8-byte records `t: f32, prim: u32` per traced ray.
    #[arg(long)]
    pub out: PathBuf,
    /// Accelerator (default: the 4-wide BVH; the 8-wide one is faster on incoherent rays).
    #[arg(long, default_value = "bvh4", value_parser = accel_parser())]
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
    /// The rays are coherent (successive rays close in origin and direction, as a camera's in
    /// scanline order): query with the 8-wide BVH's walk for such rays, faster on them and
    /// slower on incoherent ones. Same hits; the other accelerators have one walk.
    #[arg(long)]
    pub coherent: bool,
}

/// `raykernel compare-hits REF OTHER [--rel R] [--scene OBJ --rays RAYS]`.
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

/// The JSON report of `raykernel compare-hits`: the agreement figures, plus the classification
/// of the differing rays when `--scene` and `--rays` are given.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CompareReport {
    /// Agreement figures.
    #[serde(flatten)]
    pub comparison: Comparison,
    /// Classification of the rays whose prim ids differ.
    #[serde(flatten)]
    pub classification: Option<Classification>,
}

/// The JSON report of `raykernel trace`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TraceReport {
    /// Scene path.
    pub scene: String,
    /// Ray file path.
    pub rays_file: String,
    /// Hit file path.
    pub out: String,
    /// `bvh4`, `bvh8`, `bvh`, `linear`, `grid` or `kdtree`.
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
    /// Queried by the walk for coherent rays (`--coherent`).
    pub coherent: bool,
    /// Full runs (build + trace); the times are medians over them.
    pub runs: usize,
    /// Ray stride.
    pub stride: usize,
    /// Triangles in the scene.
    pub triangles: usize,
    /// Median wall time of the build, leaf-order permutation included (0 for linear).
    pub build_ms: f64,
    /// Median wall time of constructing each kernel ray from its record and tracing it, one
    /// record at a time (what a caller pays; no file I/O).
    pub per_ray_ms: f64,
    /// Median wall time of turning records into kernel rays, ahead of tracing.
    pub setup_ms: f64,
    /// Median wall time of tracing and storing every pre-built ray (no setup, no file I/O).
    pub trace_ms: f64,
    /// Build time of each run.
    pub build_ms_runs: Vec<f64>,
    /// Per-ray time (construction included) of each run.
    pub per_ray_ms_runs: Vec<f64>,
    /// Pre-built trace time of each run.
    pub trace_ms_runs: Vec<f64>,
    /// Rays traced.
    pub rays: usize,
    /// Rays in the file.
    pub rays_in_file: usize,
    /// Million rays per second, each ray constructed from its record and traced (`per_ray_ms`).
    pub mrays_per_s: f64,
    /// Million rays per second of tracing pre-built rays (`trace_ms`: construction excluded).
    pub mrays_per_s_prebuilt: f64,
    /// Cost of constructing one kernel ray from its record, ns (`setup_ms` per ray).
    pub setup_ns_per_ray: f64,
    /// Rays that hit.
    pub hits: usize,
    /// Rays the kernel rejected, written as misses.
    pub bad_rays: usize,
    /// The first rejected ray: its index in the ray file, `null` if none.
    pub first_bad_ray: Option<usize>,
    /// Why the kernel rejected it, `null` if none.
    pub first_bad_ray_error: Option<String>,
    /// BVH nodes (bvh4, bvh8: wide nodes; 0 for linear).
    pub nodes: usize,
    /// Bytes of BVH nodes and primitive ids per triangle (bvh4, bvh8: its wide nodes and the ids;
    /// the BVH it is collapsed from is build scratch, not counted; 0 for linear).
    pub bytes_per_tri: f64,
    /// BVH depth (bvh4, bvh8: depth of the deepest wide node; 0 for linear).
    pub depth: u32,
}

/// Runs a parsed command line: lines for people go to `console` as the work happens; returns
/// the command's one-line JSON report, which `main` prints as the last line of stdout.
///
/// # Errors
/// Whatever the command fails with.
pub fn run(cli: &Cli, console: &Console) -> Result<String, Error> {
    let json = match &cli.command {
        Command::Trace(args) => {
            let report = run_trace(args)?;
            if let Some(line) = report.rejected_rays_warning() {
                console.warn(&line);
            }
            serde_json::to_string(&report)
        }
        Command::CompareHits(args) => serde_json::to_string(&run_compare(args)?),
        Command::Bake(args) => serde_json::to_string(&run_bake(args)?),
        Command::TraceBaked(args) => serde_json::to_string(&run_trace_baked(args)?),
        Command::Render(args) => {
            let job = RenderJob::prepare(args)?;
            console.line(&job.report.plan_line());
            let report = job.run(console)?;
            let summary = report.summary();
            if !summary.is_empty() {
                console.line(&summary);
            }
            serde_json::to_string(&report)
        }
        Command::Check(args) => {
            let report = run_check_with(args, console)?;
            console.line(&format!(
                "check passed: {} renders of {} scene/mode cases identical to the kernel's",
                report.renders,
                report.cases.len()
            ));
            serde_json::to_string(&report)
        }
        Command::Completions(args) => {
            let mut script = Vec::new();
            clap_complete::generate(args.shell, &mut Cli::command(), PROGRAM, &mut script);
            return Ok(String::from_utf8_lossy(&script).trim_end().to_string());
        }
    };
    // Structs of numbers and strings always serialize; the fallback only avoids a panic path.
    Ok(json.unwrap_or_else(|e| format!("{{\"error\":\"cannot encode report: {e}\"}}")))
}

/// Samples per pixel of `raykernel render` for built-in scenes (their own settings are the
/// small ones of the snapshot tests).
pub const BUILT_IN_SPP: u32 = 64;
/// Width of `raykernel render` for built-in scenes; the height keeps the scene's aspect ratio.
pub const BUILT_IN_WIDTH: u32 = 512;

/// The settings `raykernel render` uses for `spec` before command-line flags: a scene file's
/// or an OBJ's own; for a built-in, 512 pixels wide (its aspect kept) at 64 Sobol samples,
/// with the path integrator (paths of [`DEFAULT_MAX_PATH_LENGTH`] segments: indirect light).
#[must_use]
pub fn render_base_settings(spec: &SceneSpec) -> Settings {
    let s = spec.settings;
    match spec.origin {
        SceneOrigin::BuiltIn => Settings {
            width: BUILT_IN_WIDTH,
            height: keep_aspect(BUILT_IN_WIDTH, s.height, s.width),
            spp: BUILT_IN_SPP,
            integrator: Integrator::Path {
                max_length: DEFAULT_MAX_PATH_LENGTH,
            },
            sampler: SamplerKind::Sobol,
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

/// Checks what `spec` asks of a render in `mode` before any work and returns the plan: the
/// settings' bounds and the memory the render needs (with the linear image if `linear`),
/// then what the kernel checks (the plan), then the camera ([`SceneSpec::check_camera`]).
///
/// # Errors
/// [`Error::Scene`] naming the setting or field.
pub fn check_render_request(
    spec: &SceneSpec,
    mode: Mode,
    linear: bool,
) -> Result<RenderPlan, Error> {
    let at = |e: crate::limits::OverLimit| Error::Scene {
        file: spec.label(),
        field: e.field.into(),
        msg: e.msg,
    };
    check_settings(&spec.settings).map_err(at)?;
    let needed = render_bytes(
        &spec.settings,
        spec.triangles.len(),
        spec.spheres.len(),
        linear,
    );
    check_memory(needed).map_err(at)?;
    let the_plan =
        plan(&spec.data(), spec.settings, mode).map_err(|e| spec.explain(&e, mode_name(mode)))?;
    spec.check_camera(mode_name(mode))?;
    Ok(the_plan)
}

/// A render whose inputs are loaded and checked, outputs reserved and plan known: what
/// `raykernel render` does before the work ([`RenderJob::prepare`]) and the work itself
/// ([`RenderJob::run`]).
#[derive(Debug)]
pub struct RenderJob {
    spec: SceneSpec,
    mode: Mode,
    accel: AccelKind,
    threads: usize,
    tile: u32,
    out: Option<Reserved>,
    linear: Option<Reserved>,
    exr: Option<Reserved>,
    /// The report so far: everything but the render's figures.
    pub report: RenderReport,
}

impl RenderJob {
    /// Checks the arguments and reserves the output files first (so a bad `--out` fails at
    /// once), then loads the scene, applies the settings and camera flags, checks them and the
    /// memory needed, derives the plan and writes the scene file if asked.
    ///
    /// # Errors
    /// A bad output name or directory, an unknown scene, a bad or unreadable scene file, OBJ
    /// or `.camera` file, settings beyond [`crate::limits`], a scene the kernel rejects in the
    /// chosen mode.
    pub fn prepare(args: &RenderArgs) -> Result<Self, Error> {
        let rendering = !args.explain;
        let out = match &args.out {
            Some(p) if rendering => Some(Reserved::new(p, Format::Png, "--out")?),
            _ => None,
        };
        let linear = match &args.linear {
            Some(p) if rendering => Some(Reserved::new(p, Format::Pfm, "--linear")?),
            _ => None,
        };
        let exr = match &args.exr {
            Some(p) if rendering => Some(Reserved::new(p, Format::Exr, "--exr")?),
            _ => None,
        };
        let dump = match &args.dump_scene {
            Some(p) => Some(Reserved::new(p, Format::SceneFile, "--dump-scene")?),
            None => None,
        };
        let mut spec = resolve_scene(args.scene.as_deref().unwrap_or(DEFAULT_SCENE))?;
        spec.settings = args.settings.apply(render_base_settings(&spec));
        spec.camera = args.camera.apply(spec.camera);
        let mode = args.mode;
        let the_plan = check_render_request(&spec, mode, linear.is_some() || exr.is_some())?;
        let settings = spec.settings;
        let accel = args.accel.with_build_options(BuildOptions {
            builder: args.builder.into(),
            max_leaf_size: args.leaf,
            reinsertion: !args.no_reinsertion,
        });
        if let Some(file) = dump {
            let text = scene_file_text(&spec_to_scene_file(&spec, file.path()));
            file.write(text.as_bytes())?;
        }
        let report = RenderReport {
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
            accel: accel.to_string(),
            triangles: spec.triangles.len(),
            spheres: spec.spheres.len(),
            plan: the_plan.to_string(),
            figures: None,
        };
        let threads = args.threads.unwrap_or_else(|| {
            std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get)
        });
        Ok(Self {
            spec,
            mode,
            accel,
            threads,
            tile: args.tile,
            out,
            linear,
            exr,
            report,
        })
    }

    /// Renders and writes the images (nothing to do with `--explain` or a dump only); a
    /// progress bar on stderr for long renders unless `console` is quiet.
    ///
    /// # Errors
    /// A scene the kernel rejects while rendering, threads that cannot start, an output that
    /// cannot be written.
    pub fn run(self, console: &Console) -> Result<RenderReport, Error> {
        let Self {
            spec,
            mode,
            accel,
            threads,
            tile,
            out,
            linear,
            exr,
            mut report,
        } = self;
        let Some(out) = out else {
            return Ok(report);
        };
        let options = RenderOptions {
            mode,
            accel,
            threads,
            tile: (tile, tile),
            progress: !console.quiet,
        };
        let r = render(&spec.data(), spec.settings, &options).map_err(render_error(&spec, mode))?;
        let png = encode_png(&r.frame.srgb8()).map_err(|msg| Error::Output {
            path: out.path().to_path_buf(),
            msg,
        })?;
        report.out = Some(out.path().display().to_string());
        out.write(&png)?;
        if let Some(file) = linear {
            report.linear = Some(file.path().display().to_string());
            file.write(&encode_pfm(&r.frame))?;
        }
        if let Some(file) = exr {
            let bytes = crate::exr::encode_exr(&r.frame).map_err(|msg| Error::Output {
                path: file.path().to_path_buf(),
                msg,
            })?;
            file.write(&bytes)?;
        }
        let rays = r.stats.rays();
        report.figures = Some(RenderFigures {
            threads,
            tile,
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
}

/// `raykernel render`: load the scene, then dump it, explain the plan, or render and write
/// images (no lines for people: [`run`] prints those).
///
/// # Errors
/// As [`RenderJob::prepare`] and [`RenderJob::run`].
pub fn run_render(args: &RenderArgs) -> Result<RenderReport, Error> {
    RenderJob::prepare(args)?.run(&Console::QUIET)
}

/// `raykernel check` without lines for people (see [`run_check_with`]).
///
/// # Errors
/// As [`run_check_with`].
pub fn run_check(args: &CheckArgs) -> Result<CheckReport, Error> {
    run_check_with(args, &Console::QUIET)
}

/// `raykernel check`: every scene (default: every built-in) in each mode, every way of
/// rendering, byte for byte. Says up front how many renders it will compare, then shows
/// progress with an estimate of the time left on `console`.
///
/// # Errors
/// A scene that cannot be loaded or rendered, or asks for more than [`crate::limits`]
/// allows, or [`Error::Mismatch`] listing every render that differs (the first differing
/// pixel and both values).
pub fn run_check_with(args: &CheckArgs, console: &Console) -> Result<CheckReport, Error> {
    let names: Vec<String> = if args.scenes.is_empty() {
        scenes::ALL.iter().map(|s| s.name.to_string()).collect()
    } else {
        args.scenes.clone()
    };
    let modes = match args.mode {
        Some(m) => vec![m],
        None => vec![Mode::F32, Mode::Fixed],
    };
    let mut specs = Vec::with_capacity(names.len());
    for name in &names {
        let mut spec = resolve_scene(name)?;
        spec.settings = args.settings.apply(spec.settings);
        for &mode in &modes {
            check_render_request(&spec, mode, false)?;
        }
        specs.push(spec);
    }
    let per_case = renders_per_case();
    let total = specs.len() * modes.len() * per_case;
    let samples: u64 = specs
        .iter()
        .map(|s| {
            u64::from(s.settings.width) * u64::from(s.settings.height) * u64::from(s.settings.spp)
        })
        .sum();
    console.line(&format!(
        "check: {} scene(s) × {} mode(s), {per_case} renders each (the kernel's reference and \
         {} ways to match it): {total} renders, {:.1} M samples per mode",
        specs.len(),
        modes.len(),
        per_case - 1,
        samples as f64 / 1e6
    ));
    let mut progress = console.progress("check", "renders", total);
    let mut cases = Vec::new();
    for spec in &specs {
        for &mode in &modes {
            cases.push(check_scene_with(spec, mode, &mut || progress.step())?);
        }
    }
    progress.finish();
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

/// `raykernel trace`: load the scene and rays, trace, write the hits.
///
/// # Errors
/// Bad or unreadable inputs, an unwritable output, or a build the kernel refuses.
pub fn run_trace(args: &TraceArgs) -> Result<TraceReport, Error> {
    let bvh_family = args.accel.permutes_into_leaf_order();
    if args.leaf_order && !bvh_family {
        return Err(Error::Usage(
            "--leaf-order needs --accel bvh, bvh4 or bvh8 (the other accelerators do not permute \
             primitives)"
                .into(),
        ));
    }
    let mesh = load_obj(&args.scene)?;
    let rays = read_rays(&args.rays)?;
    let config = TraceConfig {
        accel: args.accel.with_build_options(BuildOptions {
            builder: args.builder.into(),
            max_leaf_size: args.leaf,
            reinsertion: !args.no_reinsertion,
        }),
        mode: args.mode,
        stride: args.stride,
        runs: args.runs,
        leaf_order: args.leaf_order,
        coherent: args.coherent,
    };
    let output = trace(&mesh, &args.scene, &rays, &config)?;
    write_hits(&args.out, &output.hits)?;
    let s = output.stats;
    let first_bad = if s.bad_rays > 0 {
        match args.mode {
            Mode::F32 => first_rejected::<f32>(&rays, args.stride),
            Mode::Fixed => first_rejected::<I16F16>(&rays, args.stride),
        }
    } else {
        None
    };
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
        coherent: args.coherent,
        runs: args.runs,
        stride: args.stride,
        triangles: s.triangles,
        build_ms: s.build_ms,
        per_ray_ms: s.per_ray_ms,
        setup_ms: s.setup_ms,
        trace_ms: s.trace_ms,
        build_ms_runs: s.build_ms_runs,
        per_ray_ms_runs: s.per_ray_ms_runs,
        trace_ms_runs: s.trace_ms_runs,
        rays: s.rays,
        rays_in_file: rays.len(),
        mrays_per_s: per_s(s.per_ray_ms),
        mrays_per_s_prebuilt: per_s(s.trace_ms),
        setup_ns_per_ray: if s.rays > 0 {
            s.setup_ms * 1e6 / s.rays as f64
        } else {
            0.0
        },
        hits: s.hits,
        bad_rays: s.bad_rays,
        first_bad_ray: first_bad.map(|(i, _)| i),
        first_bad_ray_error: first_bad.map(|(_, e)| ray_error_text(e, args.mode.name())),
        nodes: s.nodes,
        bytes_per_tri: if s.triangles > 0 {
            s.accel_bytes as f64 / s.triangles as f64
        } else {
            0.0
        },
        depth: s.depth,
    })
}

/// The first of every `stride`-th record that mode `S` cannot make a ray of: its index in the
/// file and why.
fn first_rejected<S: Scalar>(rays: &[RayRecord], stride: usize) -> Option<(usize, RayError)> {
    rays.iter()
        .enumerate()
        .step_by(stride.max(1))
        .find_map(|(i, r)| {
            Ray::<S>::from_f32(r.origin, r.dir, r.t_min, r.t_max)
                .err()
                .map(|e| (i, e))
        })
}

/// What the kernel's [`RayError`] means in `mode`.
fn ray_error_text(e: RayError, mode: &str) -> String {
    match e {
        RayError::Origin(p) => format!("ray origin: {}", point_error_text(p, mode)),
        other => other.to_string(),
    }
}

impl TraceReport {
    /// `3 of 50 rays rejected ... (first: ray 7, ...)`, when the kernel rejected any.
    #[must_use]
    pub fn rejected_rays_warning(&self) -> Option<String> {
        if self.bad_rays == 0 {
            return None;
        }
        let first = match (self.first_bad_ray, &self.first_bad_ray_error) {
            (Some(i), Some(e)) => format!("; the first is record {i} of {}: {e}", self.rays_file),
            _ => String::new(),
        };
        Some(format!(
            "{} of {} traced rays rejected in {} mode and written as misses{first}",
            self.bad_rays, self.rays, self.mode
        ))
    }
}

/// `raykernel compare-hits`: agreement of OTHER with REF.
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
