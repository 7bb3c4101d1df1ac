//! Writing the results: `BENCHMARKS.md` (Markdown report), `data.csv` and `data.json`'s
//! `figures` (one figure per row, [`crate::figures`]), the rest of `data.json` (everything,
//! structured) and `plots/*.png`.

use crate::error::Error;
use crate::fireflies::{self, FireflyRow};
use crate::gi::{time_to_reach, GiResults, GiRow};
use crate::images::ImageRow;
use crate::machine::Machine;
use crate::objects::ObjectsRow;
use crate::overhead::OverheadRow;
use crate::plot::{grouped_bars, loglog, Series};
use crate::refit::RefitRow;
use crate::results::{ScaleRow, TraceRow};
use crate::rounds::{Pairing, PrebuiltPeer, RoundsRow};
use crate::workload::RayKind;
use serde::Serialize;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Everything one benchmark run measured.
#[derive(Clone, Debug, Serialize)]
pub struct BenchResults {
    /// Machine line data.
    pub machine: Machine,
    /// The command as typed (program name normalised).
    pub command: String,
    /// `--quick` run.
    pub quick: bool,
    /// Ray stride.
    pub stride: usize,
    /// Runs (medians).
    pub runs: usize,
    /// Where the rays came from.
    pub ray_source: String,
    /// Every trace row: ours and the peers, per scene and ray set.
    pub rows: Vec<TraceRow>,
    /// Interleaved rounds of the headline contender and tinybvh, per ray set.
    pub rounds: Vec<RoundsRow>,
    /// Per scene and ray set: rays and hits of the `f64` reference.
    pub reference: Vec<ReferenceRow>,
    /// The tiled-scene sweep.
    pub scale: Vec<ScaleRow>,
    /// Refit against rebuild, per scene and mode.
    pub refit: Vec<RefitRow>,
    /// The image-convergence renders.
    pub images: Vec<ImageRow>,
    /// The path tracer against Mitsuba 3 (`None`: not run).
    pub gi: Option<GiResults>,
    /// Per-pixel error percentiles of the default scene, direct against path integrator.
    pub fireflies: Vec<FireflyRow>,
    /// The renderer against hand-written casters.
    pub overhead: Vec<OverheadRow>,
    /// Many one-sphere objects against one object holding them.
    pub objects: Vec<ObjectsRow>,
    /// Fitted log-log slopes of the plots.
    pub slopes: Vec<SlopeRow>,
    /// Wall time of the whole run, seconds.
    pub elapsed_s: f64,
}

/// The `f64` reference's figures for one ray set.
#[derive(Clone, Debug, Serialize)]
pub struct ReferenceRow {
    /// Scene.
    pub scene: String,
    /// Ray set.
    pub rays: RayKind,
    /// Rays traced.
    pub ray_count: usize,
    /// Rays the reference hits.
    pub hits: usize,
}

/// One fitted slope.
#[derive(Clone, Debug, Serialize)]
pub struct SlopeRow {
    /// Plot file name.
    pub plot: String,
    /// Series.
    pub series: String,
    /// Slope of ln y against ln x.
    pub slope: f64,
}

/// Files written.
#[derive(Clone, Debug)]
pub struct Written {
    /// The Markdown report.
    pub report: PathBuf,
    /// The CSV.
    pub csv: PathBuf,
    /// The JSON.
    pub json: PathBuf,
    /// The plots.
    pub plots: Vec<PathBuf>,
    /// Rows of `data.json`'s `figures` (and lines of `data.csv` after its header).
    pub figures: usize,
}

/// `data.json`: the long figures first, then every structured result.
#[derive(Serialize)]
struct DataJson<'a> {
    figures: &'a [crate::figures::Figure],
    #[serde(flatten)]
    results: &'a BenchResults,
}

fn io_error(path: &Path, e: &std::io::Error) -> Error {
    Error::Bench(format!("cannot write {}: {e}", path.display()))
}

/// Draws the plots (recording their slopes in `results`), then writes the report, CSV and
/// JSON into `out`.
///
/// # Errors
/// [`Error::Bench`] if a file cannot be written.
pub fn write_all(results: &mut BenchResults, out: &Path) -> Result<Written, Error> {
    let plots_dir = out.join("plots");
    std::fs::create_dir_all(&plots_dir).map_err(|e| io_error(&plots_dir, &e))?;
    let plots = draw_plots(results, &plots_dir)?;
    let report = out.join("BENCHMARKS.md");
    std::fs::write(&report, markdown(results)).map_err(|e| io_error(&report, &e))?;
    let figures = crate::figures::figures(results);
    let csv = out.join("data.csv");
    std::fs::write(&csv, crate::figures::csv_text(&figures)).map_err(|e| io_error(&csv, &e))?;
    let json = out.join("data.json");
    let data = DataJson {
        figures: &figures,
        results,
    };
    let text = serde_json::to_string_pretty(&data)
        .map_err(|e| Error::Bench(format!("cannot encode the results: {e}")))?;
    std::fs::write(&json, text + "\n").map_err(|e| io_error(&json, &e))?;
    Ok(Written {
        report,
        csv,
        json,
        plots,
        figures: figures.len(),
    })
}

fn scenes(rows: &[TraceRow]) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for r in rows {
        if !out.contains(&r.scene) {
            out.push(r.scene.clone());
        }
    }
    out
}

fn labels(rows: &[TraceRow], pick: impl Fn(&TraceRow) -> bool) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for r in rows.iter().filter(|r| pick(r)) {
        let l = r.label();
        if !out.contains(&l) {
            out.push(l);
        }
    }
    out
}

/// The headline contenders of the speed plot: ours on the default builder, and the peers.
fn headline(r: &TraceRow) -> bool {
    !r.ours || r.builder == raykernel::bvh::BuilderKind::default().name()
}

fn draw_plots(results: &mut BenchResults, dir: &Path) -> Result<Vec<PathBuf>, Error> {
    let mut written = Vec::new();
    let scene_names = scenes(&results.rows);
    let mut slopes = Vec::new();
    for kind in RayKind::ALL {
        let rows: Vec<&TraceRow> = results.rows.iter().filter(|r| r.rays == kind).collect();
        if rows.is_empty() {
            continue;
        }
        // Speed: closest-hit Mrays/s per scene.
        let path = dir.join(format!("speed_{}.png", kind.name()));
        let series: Vec<(String, Vec<f64>)> =
            labels(&results.rows, |r| r.rays == kind && headline(r))
                .into_iter()
                .map(|label| {
                    let values = scene_names
                        .iter()
                        .map(|s| {
                            rows.iter()
                                .find(|r| &r.scene == s && r.label() == label)
                                .map_or(0.0, |r| r.closest_mrays)
                        })
                        .collect();
                    (label, values)
                })
                .collect();
        grouped_bars(
            &path,
            &format!("Closest hit, {} rays, single thread", kind.name()),
            "Mrays/s",
            &scene_names,
            &series,
        )
        .map_err(Error::Bench)?;
        written.push(path);
        // Error against speed, one series per family and builder, over the scenes.
        let path = dir.join(format!("error_vs_speed_{}.png", kind.name()));
        let mut groups: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
        for r in &rows {
            let Some(a) = r.accuracy else { continue };
            let name = if r.ours {
                format!("{} {}", r.family(), r.builder)
            } else {
                r.family()
            };
            let point = (r.closest_mrays, a.t_rel_mean);
            match groups.iter_mut().find(|g| g.0 == name) {
                Some(g) => g.1.push(point),
                None => groups.push((name, vec![point])),
            }
        }
        let series: Vec<Series> = groups
            .into_iter()
            .map(|(name, points)| Series { name, points })
            .collect();
        let fitted = loglog(
            &path,
            &format!(
                "Mean relative hit-distance error vs speed, {} rays",
                kind.name()
            ),
            "closest hit, Mrays/s",
            "mean |t - t*| / t*",
            &series,
        )
        .map_err(Error::Bench)?;
        for (s, slope) in series.iter().zip(fitted) {
            if let Some(slope) = slope {
                slopes.push(SlopeRow {
                    plot: file_name(&path),
                    series: s.name.clone(),
                    slope,
                });
            }
        }
        written.push(path);
    }
    if !results.scale.is_empty() {
        let modes: Vec<String> = {
            let mut m: Vec<String> = Vec::new();
            for r in &results.scale {
                if !m.contains(&r.mode) {
                    m.push(r.mode.clone());
                }
            }
            m
        };
        let per_mode = |f: &dyn Fn(&ScaleRow) -> f64, suffix: &str| -> Vec<Series> {
            modes
                .iter()
                .map(|m| Series {
                    name: format!("{m}{suffix}"),
                    points: results
                        .scale
                        .iter()
                        .filter(|r| &r.mode == m)
                        .map(|r| (r.triangles as f64, f(r)))
                        .collect(),
                })
                .collect()
        };
        let path = dir.join("scale_build.png");
        let series = per_mode(&|r| r.build_ms, " SAH build");
        let fitted = loglog(
            &path,
            "SAH build time vs triangles (tiled scene)",
            "triangles",
            "build ms",
            &series,
        )
        .map_err(Error::Bench)?;
        record(&mut slopes, &path, &series, fitted);
        written.push(path);
        let path = dir.join("scale_trace.png");
        let mut series = per_mode(&|r| r.primary_mrays, " primary");
        series.extend(per_mode(&|r| r.incoherent_mrays, " incoherent"));
        let fitted = loglog(
            &path,
            "Closest-hit Mrays/s vs triangles (tiled scene)",
            "triangles",
            "Mrays/s",
            &series,
        )
        .map_err(Error::Bench)?;
        record(&mut slopes, &path, &series, fitted);
        written.push(path);
    }
    if !results.images.is_empty() {
        let path = dir.join("images_error_vs_time.png");
        let series: Vec<Series> = raykernel::render::SamplerKind::ALL
            .iter()
            .map(|k| Series {
                name: k.name().to_string(),
                points: results
                    .images
                    .iter()
                    .filter(|r| r.sampler == k.name() && r.seconds > 0.0 && r.rmse > 0.0)
                    .map(|r| (r.seconds, r.rmse))
                    .collect(),
            })
            .collect();
        let fitted = loglog(
            &path,
            "Image RMSE vs render time (default scene, one thread)",
            "seconds",
            "RMSE (linear)",
            &series,
        )
        .map_err(Error::Bench)?;
        record(&mut slopes, &path, &series, fitted);
        written.push(path);
    }
    results.slopes = slopes;
    Ok(written)
}

fn record(slopes: &mut Vec<SlopeRow>, path: &Path, series: &[Series], fitted: Vec<Option<f64>>) {
    for (s, slope) in series.iter().zip(fitted) {
        if let Some(slope) = slope {
            slopes.push(SlopeRow {
                plot: file_name(path),
                series: s.name.clone(),
                slope,
            });
        }
    }
}

fn file_name(path: &Path) -> String {
    path.file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// The reference row of a ray set: ours, `f32`, watertight, default builder.
/// The headline structures: the wide BVHs collapsed from the SAH BVH, the 8-wide by both of
/// its walks (as named in [`TraceRow::contender`]).
const HEADLINE_STRUCTURES: [&str; 3] = [
    "raykernel bvh4",
    "raykernel bvh8",
    "raykernel bvh8 coherent",
];

/// A contender of ours without the `raykernel ` prefix: the structure's name.
fn structure(row: &TraceRow) -> &str {
    row.contender
        .strip_prefix("raykernel ")
        .unwrap_or(&row.contender)
}

/// Ours in the headline for `mode`: of the wide BVHs from the SAH build (`f32`: with the
/// watertight test), the one fastest per ray (construction counted) on this ray set.
fn fastest_wide<'r>(
    rows: &'r [TraceRow],
    scene: &str,
    kind: RayKind,
    mode: &str,
) -> Option<&'r TraceRow> {
    rows.iter()
        .filter(|r| {
            r.ours
                && r.scene == scene
                && r.rays == kind
                && r.mode == mode
                && r.test != crate::ours::MT_TEST
                && r.builder == raykernel::bvh::BuilderKind::default().name()
                && HEADLINE_STRUCTURES.contains(&r.contender.as_str())
        })
        .reduce(|a, b| {
            if b.closest_mrays > a.closest_mrays {
                b
            } else {
                a
            }
        })
}

/// Ours in `f32` in the headline ([`fastest_wide`]).
fn our_reference<'r>(rows: &'r [TraceRow], scene: &str, kind: RayKind) -> Option<&'r TraceRow> {
    fastest_wide(rows, scene, kind, "f32")
}

/// Ours in fixed point in the headline: the faster wide BVH in that mode (which can be the
/// other structure than in `f32`), compared with `reference`, the `f32` one.
fn fixed_reference<'r>(rows: &'r [TraceRow], reference: &TraceRow) -> Option<&'r TraceRow> {
    fastest_wide(rows, &reference.scene, reference.rays, "fixed")
}

fn ratio(a: f64, b: f64) -> String {
    if a > 0.0 && b > 0.0 {
        format!("{:.2}×", a / b)
    } else {
        "-".into()
    }
}

fn opt(x: Option<f64>, digits: usize) -> String {
    x.map_or_else(|| "n/a".into(), |v| format!("{v:.digits$}"))
}

/// The Markdown report.
#[must_use]
pub fn markdown(r: &BenchResults) -> String {
    let mut s = String::new();
    let m = &r.machine;
    let _ = writeln!(s, "# Benchmarks\n");
    let _ = writeln!(s, "{}\n", m.line());
    let _ = writeln!(s, "- command: `{}`", r.command);
    let _ = writeln!(
        s,
        "- date: {}{}; wall time of the run: {:.0} s",
        m.date,
        m.commit
            .as_ref()
            .map_or(String::new(), |c| format!(", commit `{c}`")),
        r.elapsed_s
    );
    let load = |l: Option<f64>| l.map_or_else(|| "unknown".into(), |v| format!("{v:.2}"));
    let others = m.others_cores;
    let _ = writeln!(
        s,
        "- other processes used {} of CPU during the run (busy time in /proc/stat minus this \
         process's); load average (1 min, counts tasks waiting on I/O too) at start / end: \
         {} / {}{}",
        others.map_or_else(|| "unknown".into(), |c| format!("{c:.2} cores")),
        load(m.load_start),
        load(m.load_end),
        // The timed work is single-threaded: it needs one core to itself.
        if others.is_some_and(|c| c > m.cores as f64 - 1.0 + 0.2) {
            " — they left less than one core free, so times are noisy; rerun on a quieter \
             machine for figures to quote"
        } else {
            " — at least one core stayed free for the single-threaded timed work"
        }
    );
    let _ = writeln!(
        s,
        "- workload: `shared/bench/WORKLOAD.md` scenes and ray sets ({}), {}, \
         {} run{} (build + trace) per figure, medians, after one untimed warm-up run of the \
         first configuration; single thread{}",
        r.ray_source,
        if r.stride == 1 {
            "all rays".to_string()
        } else {
            format!(
                "every {}th ray, the traced records gathered next to each other (untimed) \
                 before every timed loop, ours and the peers' alike: read in place, 32-byte \
                 records {} bytes apart cost a memory access per ray that reading a ray file \
                 in order does not",
                r.stride,
                32 * r.stride
            )
        },
        r.runs,
        if r.runs == 1 { "" } else { "s" },
        if r.quick {
            "; **--quick** (CI smoke test: figures not for quoting)"
        } else {
            ""
        }
    );
    if m.profile != "release" {
        let _ = writeln!(
            s,
            "- **debug build: these figures are not meaningful** (use `--release`)"
        );
    }
    let _ = writeln!(s);
    headline_section(&mut s, r);
    rounds_section(&mut s, r);
    ours_section(&mut s, r);
    accelerators_section(&mut s, r);
    peers_section(&mut s, r);
    accuracy_section(&mut s, r);
    s.push_str(&images_section(r));
    s.push_str(&gi_section(r.gi.as_ref()));
    refit_section(&mut s, r);
    overhead_section(&mut s, r);
    objects_section(&mut s, r);
    scale_section(&mut s, r);
    notes_section(&mut s);
    s
}

fn headline_section(s: &mut String, r: &BenchResults) {
    let peers = labels(&r.rows, |x| !x.ours);
    let _ = writeln!(
        s,
        "## Headline: closest hit per ray, Mrays/s, ours and peers in the same run\n"
    );
    let _ = writeln!(
        s,
        "What a caller pays per query: raykernel sets one kernel ray from each record's raw `f32` \
         origin, direction and interval inside the timed loop (`Ray::set_from_f32`, in place, \
         as a caller fills Embree's ray structure), and Embree's \
         `rtcIntersect1` takes the raw record; the other peers take rays converted ahead, so \
         their conversion time is added to their trace time. `pre-built` is raykernel tracing \
         rays constructed ahead (traversal alone). Ours is raykernel `f32`, watertight, with \
         the fastest per ray on the ray set (`structure`) of the 4-wide and the 8-wide BVH, \
         both collapsed from the SAH BVH with the triangles permuted into leaf order \
         (`build_in_leaf_order`, in place), the 8-wide one queried by its default walk and by \
         its walk for coherent rays (`bvh8 coherent`: through `raykernel::Coherent`, the \
         caller's hint that successive rays are alike, as Embree's \
         `RTC_INTERSECT_CONTEXT_FLAG_COHERENT` is; Embree is given that flag on primary rays, \
         its default incoherent one otherwise); ratios are ours per ray ÷ peer: above \
         1 means ours is faster. `Embree 3 HIGH robust` is Embree in its robust mode (see \
         Method). `fixed ÷ f32` is fixed point per ray, ray construction \
         included, against `f32`: the faster wide BVH in fixed point (named beside its figure), \
         which need not be the one of `f32`.\n"
    );
    let mut head =
        "| scene | triangles | rays | structure | raykernel f32 | raykernel f32 pre-built | raykernel fixed | fixed ÷ f32 |"
            .to_string();
    let mut rule = "|---|---:|---|---|---:|---:|---:|---:|".to_string();
    for p in &peers {
        let _ = write!(head, " {p} | ratio |");
        rule.push_str("---:|---:|");
    }
    let _ = writeln!(s, "{head}\n{rule}");
    for scene in scenes(&r.rows) {
        for kind in RayKind::ALL {
            let Some(ours) = our_reference(&r.rows, &scene, kind) else {
                continue;
            };
            let fixed = fixed_reference(&r.rows, ours);
            let mut line = format!(
                "| {scene} | {} | {} | {} | {:.2} | {} | {} | {} |",
                ours.triangles,
                kind.name(),
                structure(ours),
                ours.closest_mrays,
                opt(ours.closest_mrays_prebuilt, 2),
                fixed.map_or("-".into(), |f| format!(
                    "{:.2} ({})",
                    f.closest_mrays,
                    structure(f)
                )),
                fixed.map_or("-".into(), |f| ratio(f.closest_mrays, ours.closest_mrays))
            );
            for p in &peers {
                match r
                    .rows
                    .iter()
                    .find(|x| x.scene == scene && x.rays == kind && &x.label() == p)
                {
                    Some(x) => {
                        let _ = write!(
                            line,
                            " {:.2} | {} |",
                            x.closest_mrays,
                            ratio(ours.closest_mrays, x.closest_mrays)
                        );
                    }
                    None => line.push_str(" - | - |"),
                }
            }
            let _ = writeln!(s, "{line}");
        }
    }
    let _ = writeln!(
        s,
        "\n![closest hit, primary rays](plots/speed_primary.png)\n\
         ![closest hit, incoherent rays](plots/speed_incoherent.png)\n"
    );
    any_hit_table(s, r);
    construction_table(s, r);
}

fn any_hit_table(s: &mut String, r: &BenchResults) {
    let embree: Vec<String> = labels(&r.rows, |x| !x.ours && x.contender.starts_with("Embree"));
    let _ = writeln!(
        s,
        "### Any hit per ray, Mrays/s\n\n\
         `occluded` (the first hit in the interval), ray construction counted as above; timed \
         once per figure.\n"
    );
    let mut head = "| scene | rays | raykernel f32 | raykernel f32 pre-built |".to_string();
    let mut rule = "|---|---|---:|---:|".to_string();
    for p in &embree {
        let _ = write!(head, " {p} | ratio |");
        rule.push_str("---:|---:|");
    }
    let _ = writeln!(s, "{head}\n{rule}");
    for scene in scenes(&r.rows) {
        for kind in RayKind::ALL {
            let Some(ours) = our_reference(&r.rows, &scene, kind) else {
                continue;
            };
            let mut line = format!(
                "| {scene} | {} | {:.2} | {} |",
                kind.name(),
                ours.any_mrays,
                opt(ours.any_mrays_prebuilt, 2)
            );
            for p in &embree {
                match r
                    .rows
                    .iter()
                    .find(|x| x.scene == scene && x.rays == kind && &x.label() == p)
                {
                    Some(x) => {
                        let _ = write!(
                            line,
                            " {:.2} | {} |",
                            x.any_mrays,
                            ratio(ours.any_mrays, x.any_mrays)
                        );
                    }
                    None => line.push_str(" - | - |"),
                }
            }
            let _ = writeln!(s, "{line}");
        }
    }
    let _ = writeln!(s);
}

fn construction_table(s: &mut String, r: &BenchResults) {
    let _ = writeln!(
        s,
        "### Ray construction, ns per ray\n\n\
         `Ray::from_f32` on every traced record ahead of tracing (normalisation, reciprocals, \
         shear constants, margins; fixed point also rounds to its formats), stored into a \
         vector filled beforehand (so its page faults are not counted), timed apart. In the per-ray \
         loop nothing is stored and part of the work overlaps traversal: the per-ray and \
         pre-built figures above differ by what the loop pays. Before and after the construction work \
         (`f32` set up in `f64` before), measured in alternation with the CLI built at both \
         commits: [CONSTRUCTION.md](CONSTRUCTION.md), from `bench/scripts/construction.py`.\n"
    );
    let _ = writeln!(s, "| scene | rays | f32 | fixed |\n|---|---|---:|---:|");
    for scene in scenes(&r.rows) {
        for kind in RayKind::ALL {
            let Some(ours) = our_reference(&r.rows, &scene, kind) else {
                continue;
            };
            let fixed = fixed_reference(&r.rows, ours);
            let _ = writeln!(
                s,
                "| {scene} | {} | {:.1} | {} |",
                kind.name(),
                ours.setup_ns_per_ray,
                fixed.map_or("-".into(), |f| format!("{:.1}", f.setup_ns_per_ray))
            );
        }
    }
    let _ = writeln!(s);
}

fn rounds_section(s: &mut String, r: &BenchResults) {
    let Some(first) = r.rounds.first() else {
        return;
    };
    let with_embree = r.rounds.iter().any(|x| !x.embree_mrays.is_empty());
    let with_tinybvh = r.rounds.iter().any(|x| !x.tinybvh_mrays.is_empty());
    let missing: Vec<&str> = [
        (!with_embree).then_some("Embree (`--features embree`)"),
        (!with_tinybvh).then_some("tinybvh (`--features tinybvh`)"),
    ]
    .into_iter()
    .flatten()
    .collect();
    let _ = writeln!(
        s,
        "### Interleaved rounds\n\n\
         Each ray set traced {} times in alternation: raykernel `f32` (the 4-wide and the \
         8-wide BVH, SAH, leaf order; the 8-wide by both walks) per ray, Embree 3 HIGH and \
         Embree 3 HIGH robust (coherent flag on primary rays), raykernel on pre-built rays, \
         tinybvh 1.6's BVH2 and its 8-wide CPU BVH (`BVH8_CPU`, built by `Build` and, as \
         `HQ`, by `BuildHQ` with spatial splits) on pre-built rays; each structure built once. \
         A slow spell of the \
         machine then slows every contender of a round, so the per-round ratio is the robust \
         comparison: ours per ray ÷ Embree (both pay their ray setup), ours pre-built ÷ tinybvh \
         (neither does). `fastest` marks the structure faster per ray on the set (by median): \
         the headline. `best` is the fastest round: noise from other tenants only adds time, \
         so it is the figure least disturbed by them (Chen and Revels 2016). Embree's AVX \
         kernels return with the upper halves of the vector registers in use, which slows the \
         SSE code timed after them until something clears them: the harness clears them \
         (`vzeroupper`) after every Embree call, outside its timing.{}\n",
        first.ours.first().map_or(0, |o| o.per_ray_mrays.len()),
        if missing.is_empty() {
            String::new()
        } else {
            format!(" Not in this build: {}.", missing.join(", "))
        }
    );
    let _ = writeln!(
        s,
        "| scene | rays | pair | ours median | ours best | peer median | peer best | ours ÷ peer per round: median (min–max) |\n\
         |---|---|---|---:|---:|---:|---:|---:|"
    );
    for x in &r.rounds {
        let fastest = x.fastest().map(|o| o.structure);
        for ours in &x.ours {
            let mark = if fastest == Some(ours.structure) {
                " (fastest)"
            } else {
                ""
            };
            let mut pairs = vec![
                ("per ray ÷ Embree 3 HIGH".to_string(), x.vs_embree(ours)),
                (
                    "per ray ÷ Embree 3 HIGH robust".to_string(),
                    x.vs_embree_robust(ours),
                ),
                ("pre-built ÷ tinybvh BVH2".to_string(), x.vs_tinybvh(ours)),
            ];
            // tinybvh's 8-wide BVH against the headline only.
            if fastest == Some(ours.structure) {
                pairs.extend(x.tinybvh8.iter().map(|t| {
                    (
                        format!("pre-built ÷ {}", t.name),
                        x.vs_prebuilt_peer(ours, t),
                    )
                }));
            }
            let mut any = false;
            for (name, pairing) in pairs {
                let Some(p) = pairing else { continue };
                any = true;
                let _ = writeln!(
                    s,
                    "| {} | {} | {}{mark} {name} | {} |",
                    x.scene,
                    x.rays.name(),
                    ours.structure,
                    pairing_cells(&p),
                );
            }
            if !any {
                let _ = writeln!(
                    s,
                    "| {} | {} | {}{mark} alone | {:.2} | {:.2} | - | - | - |",
                    x.scene,
                    x.rays.name(),
                    ours.structure,
                    host::trace::median(&ours.per_ray_mrays),
                    ours.per_ray_mrays.iter().copied().fold(0.0, f64::max),
                );
            }
        }
    }
    let _ = writeln!(s);
    tinybvh8_table(s, r);
}

/// tinybvh's 8-wide BVH against Embree in the same rounds: the wide SIMD BVH the speed issue
/// names as proof that Embree's figures can be reached, measured on this machine.
fn tinybvh8_table(s: &mut String, r: &BenchResults) {
    let rows: Vec<(&RoundsRow, &PrebuiltPeer, Pairing)> = r
        .rounds
        .iter()
        .flat_map(|x| {
            x.tinybvh8
                .iter()
                .filter_map(move |t| Some((x, t, x.vs_embree_of(t)?)))
        })
        .collect();
    if rows.is_empty() {
        return;
    }
    let _ = writeln!(
        s,
        "tinybvh's 8-wide BVH against Embree in the same rounds. tinybvh traces rays built \
         beforehand and Embree takes raw records, so this ratio favours tinybvh by Embree's ray \
         setup. tinybvh tests boxes with fused multiply-subtract and four triangles at once by \
         Möller–Trumbore with an approximate reciprocal, neither of which the kernel's \
         promises allow. `same` is the share of rays whose hit triangle (or miss) is ours.\n\n\
         | scene | rays | peer | peer median | peer best | Embree median | Embree best | peer ÷ Embree per round: median (min–max) | same |\n\
         |---|---|---|---:|---:|---:|---:|---:|---:|"
    );
    for (x, t, p) in rows {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {:.3}% |",
            x.scene,
            x.rays.name(),
            t.name,
            pairing_cells(&p),
            t.same_prim_pct,
        );
    }
    let _ = writeln!(s);
}

/// A pairing's table cells: each side's median and best round, then the median per-round
/// ratio with its range.
fn pairing_cells(p: &Pairing) -> String {
    let (lo, hi) = p.ratio_range();
    format!(
        "{:.2} | {:.2} | {:.2} | {:.2} | {:.2}× ({lo:.2}–{hi:.2})",
        p.ours_median,
        p.ours_best,
        p.peer_median,
        p.peer_best,
        p.median_ratio()
    )
}

fn ours_section(s: &mut String, r: &BenchResults) {
    let _ = writeln!(
        s,
        "## Traversal: every accelerator, builder and mode of the kernel\n"
    );
    let _ = writeln!(
        s,
        "BVH leaves of up to {} primitives (`bvh::DEFAULT_LEAF_SIZE`); `bvh4` is the 4-wide BVH \
         collapsed from the BVH of the same builder; both BVHs permute the triangles into leaf \
         order (in place, timed with the build). `any hit` is `occluded` (first hit in \
         range), timed once on the last run. `per ray` sets the ray from each record in \
         the timed loop; `pre-built` traces rays constructed ahead (`ray setup ns` each). Nodes \
         and primitives are counted per closest-hit \
         ray (for `bvh4`, every child box tested counts as a node). Bytes per triangle count \
         the nodes in use and the primitive ids (not the triangles). `MT` is the \
         benchmark-only Möller–Trumbore test on the same tree (a contrast, not part of the \
         kernel).\n",
        raykernel::bvh::DEFAULT_LEAF_SIZE
    );
    let _ = writeln!(
        s,
        "| scene | rays | accel | builder | mode | test | build ms | closest Mrays/s per ray | pre-built | any-hit Mrays/s per ray | pre-built | ray setup ns | nodes/ray | prims/ray | bytes/tri | depth |"
    );
    let _ = writeln!(
        s,
        "|---|---|---|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for x in r.rows.iter().filter(|x| x.ours) {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {:.1} | {:.2} | {} | {:.2} | {} | {:.1} | {} | {} | {:.1} | {} |",
            x.scene,
            x.rays.name(),
            x.contender.trim_start_matches("raykernel "),
            x.builder,
            x.mode,
            x.test,
            x.build_ms,
            x.closest_mrays,
            opt(x.closest_mrays_prebuilt, 2),
            x.any_mrays,
            opt(x.any_mrays_prebuilt, 2),
            x.setup_ns_per_ray,
            opt(x.nodes_per_ray, 1),
            opt(x.prims_per_ray, 1),
            x.bytes_per_tri,
            x.depth.map_or("-".into(), |d| d.to_string())
        );
    }
    let _ = writeln!(s);
}

/// One of our structures on one scene (`f32`, watertight): build, memory, both ray sets.
struct AccelFigures {
    name: String,
    build_ms: f64,
    bytes_per_tri: f64,
    primary: f64,
    incoherent: f64,
}

fn accel_figures(r: &BenchResults, scene: &str) -> Vec<AccelFigures> {
    let mut out: Vec<AccelFigures> = Vec::new();
    let rows = r
        .rows
        .iter()
        .filter(|x| x.ours && x.scene == scene && x.mode == "f32" && x.test == "watertight");
    for x in rows {
        let accel = x.contender.trim_start_matches("raykernel ");
        let name = if x.builder == "-" {
            accel.to_string()
        } else {
            format!("{accel} {}", x.builder)
        };
        let i = out.iter().position(|f| f.name == name).unwrap_or_else(|| {
            out.push(AccelFigures {
                name,
                build_ms: x.build_ms,
                bytes_per_tri: x.bytes_per_tri,
                primary: 0.0,
                incoherent: 0.0,
            });
            out.len() - 1
        });
        let f = &mut out[i];
        match x.rays {
            RayKind::Primary => f.primary = x.closest_mrays,
            RayKind::Incoherent => f.incoherent = x.closest_mrays,
        }
    }
    out
}

/// The name of the best figure by `key` (`lower` wins or higher wins).
fn winner(figs: &[AccelFigures], key: fn(&AccelFigures) -> f64, lower: bool) -> String {
    let better = |a: f64, b: f64| if lower { a < b } else { a > b };
    figs.iter()
        .filter(|f| key(f) > 0.0)
        .fold(None::<&AccelFigures>, |best, f| match best {
            Some(b) if !better(key(f), key(b)) => Some(b),
            _ => Some(f),
        })
        .map_or_else(|| "-".into(), |f| format!("{} ({:.2})", f.name, key(f)))
}

fn accelerators_section(s: &mut String, r: &BenchResults) {
    let _ = writeln!(
        s,
        "## Accelerators: BVH (each builder), uniform grid, kd-tree\n\n\
         `f32`, watertight test, single thread; build time includes sizing the memory (the \
         grid's counting pass); memory is the structure's nodes or cells plus its references \
         (not the triangles), per triangle. Same rays and same hits (every structure returns \
         the brute-force closest hit, bit for bit).\n"
    );
    let _ = writeln!(
        s,
        "| scene | structure | build ms | bytes/tri | primary Mrays/s | incoherent Mrays/s |\n\
         |---|---|---:|---:|---:|---:|"
    );
    let mut winners = Vec::new();
    for scene in scenes(&r.rows) {
        let figs = accel_figures(r, &scene);
        for f in &figs {
            let _ = writeln!(
                s,
                "| {scene} | {} | {:.1} | {:.1} | {:.2} | {:.2} |",
                f.name, f.build_ms, f.bytes_per_tri, f.primary, f.incoherent
            );
        }
        winners.push(format!(
            "- {scene}: primary {}; incoherent {}; build {} ms; memory {} B/tri",
            winner(&figs, |f| f.primary, false),
            winner(&figs, |f| f.incoherent, false),
            winner(&figs, |f| f.build_ms, true),
            winner(&figs, |f| f.bytes_per_tri, true),
        ));
    }
    let _ = writeln!(
        s,
        "\nWinners in this run (per-ray closest-hit figures; build time; memory):\n\n{}\n",
        winners.join("\n")
    );
}

fn peers_section(s: &mut String, r: &BenchResults) {
    let _ = writeln!(s, "## Peers: same triangles, same rays, same run\n");
    let _ = writeln!(
        s,
        "Throughput ratios are ours ÷ peer, build ratio is peer time ÷ our time (both: above \
         1 means ours is faster); ours is raykernel `f32`, 4-wide BVH from the SAH BVH, \
         watertight, per ray (construction counted, as in the headline). Agreement with our \
         hits follows `compare_hits.py` (same prim and |Δt| ≤ 1e-5·t); `ties` = t agrees but \
         the prim differs; `hit/miss` = one side hits, the other misses, split into `only ours` \
         and `only peer` (the accuracy section says which side the `f64` reference takes). \
         Bytes per triangle: see Method. Peers cannot count nodes visited.\n"
    );
    let _ = writeln!(
        s,
        "| scene | rays | peer | build ms | build ratio | closest Mrays/s | ratio | pre-built | any-hit Mrays/s | ratio | prims/ray | bytes/tri | agree % | ties | hit/miss | only ours | only peer | hits ours / peer |"
    );
    let _ = writeln!(
        s,
        "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for x in r.rows.iter().filter(|x| !x.ours) {
        let Some(ours) = our_reference(&r.rows, &x.scene, x.rays) else {
            continue;
        };
        let c = x.vs_ours;
        let split = x.hitmiss_split;
        let _ = writeln!(
            s,
            "| {} | {} | {} | {:.1} | {} | {:.2} | {} | {} | {:.2} | {} | {} | {:.1} | {} | {} | {} | {} | {} | {} / {} |",
            x.scene,
            x.rays.name(),
            x.contender,
            x.build_ms,
            ratio(x.build_ms, ours.build_ms),
            x.closest_mrays,
            ratio(ours.closest_mrays, x.closest_mrays),
            opt(x.closest_mrays_prebuilt, 2),
            x.any_mrays,
            ratio(ours.any_mrays, x.any_mrays),
            opt(x.prims_per_ray, 1),
            x.bytes_per_tri,
            c.map_or("-".into(), |c| format!("{:.3}", c.agree_pct)),
            c.map_or("-".into(), |c| c.prim_only.to_string()),
            c.map_or("-".into(), |c| c.hitmiss.to_string()),
            split.map_or("-".into(), |h| h.ours_only.to_string()),
            split.map_or("-".into(), |h| h.peer_only.to_string()),
            ours.hits,
            x.hits
        );
    }
    let _ = writeln!(s);
}

fn accuracy_section(s: &mut String, r: &BenchResults) {
    let _ = writeln!(s, "## Accuracy against an f64 reference\n");
    let _ = writeln!(
        s,
        "The reference runs the kernel's watertight algorithm in `f64` on the same `f32` \
         vertices and ray records (closest hit, ties to the lowest id). `max`/`mean rel Δt`: \
         |t − t*| / t*, with t* the `f64` distance to the plane of the triangle the contender \
         reported. `wrong prim`: both hit, different surfaces (|Δt| > 1e-5·t); `ties`: \
         different triangle at the same distance; `leaks`: the reference hits, the contender \
         misses; `false hits`: the reverse.\n"
    );
    for row in &r.reference {
        let _ = writeln!(
            s,
            "- {} {}: the reference hits {} of {} rays",
            row.scene,
            row.rays.name(),
            row.hits,
            row.ray_count
        );
    }
    let _ = writeln!(
        s,
        "\n| scene | rays | contender | max rel Δt | mean rel Δt | wrong prim | ties | leaks | false hits | closest Mrays/s |"
    );
    let _ = writeln!(s, "|---|---|---|---:|---:|---:|---:|---:|---:|---:|");
    for x in &r.rows {
        let Some(a) = x.accuracy else { continue };
        let _ = writeln!(
            s,
            "| {} | {} | {} | {:.2e} | {:.2e} | {} | {} | {} | {} | {:.2} |",
            x.scene,
            x.rays.name(),
            x.label(),
            a.t_rel_max,
            a.t_rel_mean,
            a.wrong_prim,
            a.ties,
            a.leaks,
            a.false_hits,
            x.closest_mrays
        );
    }
    let _ = writeln!(
        s,
        "\n![error vs speed, primary](plots/error_vs_speed_primary.png)\n\
         ![error vs speed, incoherent](plots/error_vs_speed_incoherent.png)\n"
    );
    let _ = writeln!(
        s,
        "Fitted slopes (least squares of ln error against ln Mrays/s over the scenes; with \
         three points per series they describe the spread, not a law):\n"
    );
    let _ = writeln!(s, "| plot | series | slope |\n|---|---|---:|");
    for sl in r.slopes.iter().filter(|x| x.plot.starts_with("error")) {
        let _ = writeln!(s, "| {} | {} | {:.2} |", sl.plot, sl.series, sl.slope);
    }
    let _ = writeln!(s);
}

fn refit_section(s: &mut String, r: &BenchResults) {
    if r.refit.is_empty() {
        return;
    }
    let _ = writeln!(
        s,
        "## Refit: new boxes for a moved mesh, against rebuilding\n\n\
         Every vertex moves by a smooth field (`bench/src/refit.rs`) whose amplitude, the \
         `motion` column, is a fraction of the scene box's diagonal: {:.0}% as in an animation \
         step, {:.0}% for a deformation far from the pose the tree was built for. Rebuild: the \
         SAH BVH and its 4-wide collapse over the moved mesh; refit: `Bvh::refit` and \
         `Bvh4::refit` of the trees built before the motion (same topology, new boxes). Then \
         the primary rays through each 4-wide tree (pre-built rays): the refitted tree's loss \
         per ray, and its hits, which must equal the rebuilt tree's. Medians of {} runs; \
         single thread.\n",
        crate::refit::AMPLITUDES[0] * 100.0,
        crate::refit::AMPLITUDES[1] * 100.0,
        r.runs
    );
    let _ = writeln!(
        s,
        "| scene | triangles | mode | motion | rebuild ms | refit BVH ms | refit BVH4 ms | rebuilt Mrays/s | refitted Mrays/s | rays | differing hits |\n\
         |---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for x in &r.refit {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {:.0}% | {:.1} | {:.2} | {:.2} | {:.2} | {:.2} | {} | {} |",
            x.scene,
            x.triangles,
            x.mode,
            x.amplitude * 100.0,
            x.rebuild_ms,
            x.refit_bvh_ms,
            x.refit_bvh4_ms,
            x.rebuilt_mrays,
            x.refitted_mrays,
            x.rays,
            x.differing_hits
        );
    }
    let _ = writeln!(s);
}

fn objects_section(s: &mut String, r: &BenchResults) {
    if r.objects.is_empty() {
        return;
    }
    let _ = writeln!(
        s,
        "## Objects: many one-sphere objects against one object holding them\n\n\
         The renderer builds an accelerator per object and a BVH over the objects' boxes \
         (`bench/src/objects.rs`). A grid of spheres on the ground, {size}×{size} pixels, 1 spp, \
         one point light, single thread: each sphere its own object, against one object holding \
         every sphere. Render times are medians of {} interleaved pairs; the ratio is the median \
         of each pair's many ÷ one. Both images must be equal, and equal to brute force (the \
         one object traced by `AccelKind::Linear`).\n",
        r.runs,
        size = crate::objects::SIZE
    );
    let _ = writeln!(
        s,
        "| spheres | mode | build ms (many) | build ms (one) | render ms (many) | render ms (one) | render ratio | differing bytes | differing bytes vs brute force |\n\
         |---:|---|---:|---:|---:|---:|---:|---:|---:|"
    );
    for x in &r.objects {
        let _ = writeln!(
            s,
            "| {} | {} | {:.1} | {:.1} | {:.1} | {:.1} | {:.2}× | {} | {} |",
            x.spheres,
            x.mode,
            x.many_build_ms,
            x.one_build_ms,
            x.many_render_ms,
            x.one_render_ms,
            x.render_ratio,
            x.differing_bytes,
            x.differing_bytes_brute_force
        );
    }
    let _ = writeln!(s);
}

fn overhead_section(s: &mut String, r: &BenchResults) {
    let _ = writeln!(
        s,
        "## Render plan overhead: the renderer against hand-written casters\n\n\
         Same BVH, single thread, 256×256, a 20,480-triangle icosphere on a floor; medians of \
         interleaved runs (the overhead: the median of each run's renderer ÷ bare ratio). \
         `primary`: a scene that uses no effect (1 spp, pinhole, static, no \
         lights, emissive objects) against a bare primary-ray caster (camera ray, closest hit, \
         colour, sRGB); `shadow`: a diffuse scene with one point light against a caster that \
         also casts the shadow ray and shades Lambert (`bench/src/overhead.rs`). \
         Differing bytes: the `primary` images must be identical; the `shadow` caster shades \
         in `f32` where the renderer uses `f64` surface points.\n"
    );
    let _ = writeln!(
        s,
        "| workload | mode | bare caster ms | renderer ms | overhead | differing bytes |\n\
         |---|---|---:|---:|---:|---:|"
    );
    for x in &r.overhead {
        let _ = writeln!(
            s,
            "| {} | {} | {:.2} | {:.2} | {:+.1}% | {} |",
            x.workload, x.mode, x.bare_ms, x.renderer_ms, x.overhead_pct, x.differing_bytes
        );
    }
    let _ = writeln!(s);
}

/// The report's `## Images` section: the renderer's RMSE against render time per sampler,
/// with the fitted slopes.
#[must_use]
pub fn images_section(r: &BenchResults) -> String {
    let mut s = String::from("## Images: renderer RMSE against time per sampler\n\n");
    let Some(first) = r.images.first() else {
        s.push_str("Not measured in this run.\n\n");
        return s;
    };
    let _ = writeln!(
        s,
        "The built-in `{}` scene (area light, mirror and glossy spheres, depth of field, motion \
         blur; `f32`) rendered single-threaded at doubling sample counts with each sampler. \
         RMSE of the linear RGB values against a {}-spp Sobol reference (rendered untimed on \
         every core; its own noise puts a floor under the lowest errors). Monte Carlo error \
         falls as time^-0.5; a steeper slope is a better sampler on this scene.\n",
        first.scene, first.reference_spp
    );
    let _ = writeln!(
        s,
        "| sampler | spp | render ms | RMSE |\n|---|---:|---:|---:|"
    );
    for x in &r.images {
        let _ = writeln!(
            s,
            "| {} | {} | {:.2} | {:.5} |",
            x.sampler,
            x.spp,
            x.seconds * 1e3,
            x.rmse
        );
    }
    let _ = writeln!(
        s,
        "\n![image RMSE vs time](plots/images_error_vs_time.png)\n\n\
         Fitted slopes (least squares of ln RMSE against ln seconds):\n"
    );
    let _ = writeln!(s, "| sampler | slope |\n|---|---:|");
    for sl in r.slopes.iter().filter(|x| x.plot.starts_with("images")) {
        let _ = writeln!(s, "| {} | {:.2} |", sl.series, sl.slope);
    }
    s.push('\n');
    fireflies_section(&mut s, &r.fireflies);
    s
}

fn fireflies_section(s: &mut String, rows: &[FireflyRow]) {
    let Some(first) = rows.first() else {
        return;
    };
    let _ = writeln!(
        s,
        "### Fireflies: per-pixel error of the default scene\n\n\
         `cornell` at {}×{}, {} renders of {} Sobol spp (seeds 1-{}) against a {}-spp \
         reference (seed 0) of the same integrator. The direct integrator reflects the small \
         area light in the glossy sphere by sampling the lobe alone; the path integrator also \
         samples the light at glossy vertices, weighted by MIS. Percentiles pool every pixel of \
         the region over the renders. Linear error: RMS over the channels of the difference. \
         Display error: the luminance's 8-bit sRGB value against the reference's, on [0, 1]. \
         An isolated firefly is a pixel at least {}× as bright as its reference, {} or more \
         brighter on display, and by more than {}× the median display error of its eight \
         neighbours; the count sums the renders. The glossy highlight is the sphere's pixels \
         within 5% of the width of one whose reference luminance exceeds 1.\n",
        first.size.0,
        first.size.1,
        first.renders,
        first.spp,
        first.renders,
        first.reference_spp,
        fireflies::BRIGHTER,
        fireflies::VISIBLE,
        fireflies::ISOLATED,
    );
    let _ = writeln!(
        s,
        "| integrator | region | pixels | linear median | 99th percentile | 99.9th percentile | \
         largest | display 99.9th percentile | isolated fireflies |\n\
         |---|---|---:|---:|---:|---:|---:|---:|---:|"
    );
    for x in rows {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {:.5} | {:.5} | {:.5} | {:.5} | {:.4} | {} |",
            x.integrator,
            x.region,
            x.pixels,
            x.median,
            x.p99,
            x.p999,
            x.max,
            x.display_p999,
            x.fireflies
        );
    }
    s.push('\n');
}

/// The report's global-illumination section: our path tracer and Mitsuba 3 on one Cornell box,
/// each image's error against both references, and the time each needs for a given error.
#[must_use]
pub fn gi_section(gi: Option<&GiResults>) -> String {
    let mut s = String::from("## Global illumination: the path tracer against Mitsuba 3\n\n");
    let Some(g) = gi else {
        s.push_str("Not measured in this run.\n\n");
        return s;
    };
    let _ = writeln!(
        s,
        "A Cornell box of diffuse walls and two blocks, lit through a square hole in the ceiling \
         by a rect light, rendered by our path integrator (`f32`, paths of {} segments: the \
         camera ray and 4 bounces) and by Mitsuba 3 (`scalar_rgb`, `path` integrator with \
         `max_depth` {}, two-sided diffuse BSDFs, box filter) from the same scene file \
         (`bench/scripts/mitsuba_render.py`), {}×{} pixels, single-threaded and timed at \
         doubling sample counts. References: {} spp each (untimed, every core; ours Sobol, \
         Mitsuba's independent).\n",
        crate::gi::PATH_LENGTH,
        crate::gi::PATH_LENGTH,
        g.size.0,
        g.size.1,
        g.reference_spp
    );
    match &g.mitsuba {
        Ok(version) => {
            let _ = writeln!(s, "Mitsuba {version}.\n");
        }
        Err(why) => {
            let _ = writeln!(
                s,
                "**Mitsuba did not run**: {why}. Only our renders are shown.\n"
            );
        }
    }
    if let (Some(d), Some(n)) = (g.reference_difference, g.reference_noise) {
        let _ = writeln!(
            s,
            "**Same image**: the two references differ by RMSE {d:.5}; two unbiased references \
             with their estimated noise would differ by about {n:.5} (ratio {:.2}).\n",
            d / n
        );
    }
    if g.channel_means.len() == 2 {
        let m = &g.channel_means;
        let _ = writeln!(
            s,
            "Mean radiance per channel (R, G, B): ours {:.5}, {:.5}, {:.5}; Mitsuba {:.5}, \
             {:.5}, {:.5}.\n",
            m[0][0], m[0][1], m[0][2], m[1][0], m[1][1], m[1][2]
        );
    }
    gi_speed(&mut s, g);
    let _ = writeln!(
        s,
        "| renderer | sampler | spp | render ms | RMSE vs own reference | RMSE vs the other's \
         |\n|---|---|---:|---:|---:|---:|"
    );
    for x in &g.rows {
        let other = gi_other(x).map_or("–".into(), |e| format!("{e:.5}"));
        let _ = writeln!(
            s,
            "| {} | {} | {} | {:.2} | {:.5} | {other} |",
            x.renderer,
            x.sampler,
            x.spp,
            x.seconds * 1e3,
            gi_own(x).unwrap_or(f64::NAN)
        );
    }
    s.push('\n');
    s
}

/// A row's error against its own renderer's reference.
fn gi_own(x: &GiRow) -> Option<f64> {
    if x.renderer == "mitsuba" {
        x.rmse_mitsuba
    } else {
        Some(x.rmse_ours)
    }
}

/// A row's error against the other renderer's reference.
fn gi_other(x: &GiRow) -> Option<f64> {
    if x.renderer == "mitsuba" {
        Some(x.rmse_ours)
    } else {
        x.rmse_mitsuba
    }
}

/// Time to the error Mitsuba's best sampler reaches at its largest sample count.
fn gi_speed(s: &mut String, g: &GiResults) {
    let curve = |renderer: &str, sampler: &str| -> Vec<(f64, f64)> {
        g.rows
            .iter()
            .filter(|x| x.renderer == renderer && x.sampler == sampler)
            .filter_map(|x| Some((x.seconds, gi_own(x)?)))
            .collect()
    };
    let mut samplers: Vec<(&str, &str)> = Vec::new();
    for x in &g.rows {
        if !samplers.contains(&(x.renderer.as_str(), x.sampler.as_str())) {
            samplers.push((x.renderer.as_str(), x.sampler.as_str()));
        }
    }
    let Some((target, their_time, their_sampler)) = samplers
        .iter()
        .filter(|(r, _)| *r == "mitsuba")
        .filter_map(|(r, k)| {
            let last = *curve(r, k).last()?;
            Some((last.1, last.0, *k))
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))
    else {
        return;
    };
    let _ = writeln!(
        s,
        "**Time to the same error**: Mitsuba's `{their_sampler}` sampler reaches RMSE \
         {target:.5} in {:.1} ms. Ours, interpolated on log axes between measured renders:\n",
        their_time * 1e3
    );
    let _ = writeln!(
        s,
        "| our sampler | ms to RMSE {target:.5} | ÷ Mitsuba |\n|---|---:|---:|"
    );
    for (r, k) in samplers.iter().filter(|(r, _)| *r == "raykernel") {
        match time_to_reach(&curve(r, k), target) {
            Some(t) => {
                let _ = writeln!(s, "| {k} | {:.1} | {:.2}× |", t * 1e3, t / their_time);
            }
            None => {
                let _ = writeln!(s, "| {k} | not reached | – |");
            }
        }
    }
    s.push('\n');
}

fn scale_section(s: &mut String, r: &BenchResults) {
    let _ = writeln!(s, "## Scale: tiled scene from 10k to 1M+ triangles\n");
    if r.scale.is_empty() {
        let _ = writeln!(s, "Not run.\n");
        return;
    }
    let _ = writeln!(
        s,
        "Copies of the benchmark meshes on a grid of 10×10 cells (make_tiled.py's recipe with \
         SplitMix64 instead of numpy's generator; the last instance cut to the exact count) \
         plus a ground plane; SAH BVH, leaves of up to {}; {} rays per set (primary from the \
         3/4 camera, incoherent in the scene box).\n",
        raykernel::bvh::DEFAULT_LEAF_SIZE,
        r.scale.first().map_or(0, |x| x.ray_count)
    );
    let _ = writeln!(
        s,
        "| triangles | instances | mode | build ms | bytes/tri | primary Mrays/s | incoherent Mrays/s | nodes/incoherent ray |"
    );
    let _ = writeln!(s, "|---:|---:|---|---:|---:|---:|---:|---:|");
    for x in &r.scale {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {:.1} | {:.1} | {:.2} | {:.2} | {:.1} |",
            x.triangles,
            x.instances,
            x.mode,
            x.build_ms,
            x.bytes_per_tri,
            x.primary_mrays,
            x.incoherent_mrays,
            x.incoherent_nodes_per_ray
        );
    }
    let _ = writeln!(s, "\nFitted log-log slopes against the triangle count:\n");
    let _ = writeln!(s, "| plot | series | slope |\n|---|---|---:|");
    for sl in r.slopes.iter().filter(|x| x.plot.starts_with("scale")) {
        let _ = writeln!(s, "| {} | {} | {:.2} |", sl.plot, sl.series, sl.slope);
    }
    let _ = writeln!(
        s,
        "\n![build time](plots/scale_build.png)\n![trace speed](plots/scale_trace.png)\n"
    );
}

/// The machine's transparent-huge-page mode (Linux: the bracketed word of
/// `/sys/kernel/mm/transparent_hugepage/enabled`), or what stands in for it.
fn huge_page_mode() -> String {
    std::fs::read_to_string("/sys/kernel/mm/transparent_hugepage/enabled")
        .ok()
        .and_then(|m| Some(m.split_once('[')?.1.split_once(']')?.0.to_owned()))
        .unwrap_or_else(|| "none (no transparent huge pages)".to_owned())
}

fn notes_section(s: &mut String) {
    let _ = writeln!(
        s,
        "## Method\n\n\
         - Memory: ours allocates its node arenas and the leaf-order copy of the triangles \
         before writing them and, on Linux, advises them for transparent huge pages \
         (`host::pages`), as Embree's allocator advises its BVH; this machine's mode: `{}`.\n\
         - Build: wall time of the call that turns the triangle array into the structure \
         that is traversed (ours: `Bvh::build` into a 64-byte aligned arena, then the 4-wide \
         collapse; Embree: `rtcNewScene`, one triangle geometry over shared vertex and index \
         buffers, `rtcCommitScene`, on a device made with `threads=1`; obvhs: \
         `build_bvh2_from_tris` / `build_cwbvh_from_tris` with `BvhBuildParams::medium_build()`; \
         bvh: `Bvh::build`; tinybvh: `BVH::Build`, its default binned SAH build, through \
         `tinybvh_rs::bvh::BVH::new`), parsing excluded.\n\
         - Trace: wall time of tracing every ray and storing `{{t, prim}}`. Per ray: ours \
         constructs `Ray::from_f32` from each record inside the loop; Embree gets one \
         `rtcIntersect1` call per record (origin, direction, tnear = tmin, tfar = tmax as \
         given) from a C loop in the benchmark's shim, its context flagged coherent on primary \
         rays; the other peers' conversion to their ray \
         type is timed apart (`setup`) and added. Pre-built: tracing rays converted ahead.\n\
         - Embree 3 HIGH robust: the HIGH build with `RTC_SCENE_FLAG_ROBUST` (\"robust \
         traversal\", without \"optimizations that reduce arithmetic accuracy\", in its \
         documentation's words), the Embree setting closest to what ours promises. It promises \
         less: neither watertightness nor the same hits across CPUs, and no certified \
         distance. Its build time and bytes per triangle here are MEDIUM's, not HIGH's: in \
         robust mode Embree builds without HIGH's spatial splits, whatever quality is asked \
         for.\n\
         - Peers' triangle tests: Embree its own (Möller–Trumbore over blocks of four \
         triangles, Plücker in robust mode), in the kernels its CPU detection selects (its \
         AVX-512 ones on a CPU that has AVX-512); obvhs its own two-sided Möller–Trumbore; \
         bvh's `intersects_triangle` culls back faces, so its rows use this benchmark's \
         two-sided Möller–Trumbore and its `nearest_traverse_iterator` (boxes in order of \
         entry, stopped past the best hit); tinybvh traces with its scalar `BVH::Intersect` and \
         its own Möller–Trumbore (one FFI call per ray; `tinybvh-rs` builds the C++ with \
         `-march=native`), has no occlusion query in `tinybvh-rs` (any hit not measured) and \
         does not count primitive tests (n/a). tinybvh's 8-wide BVH (rounds only) is \
         `BVH8_CPU`, built by `Build` or `BuildHQ` and traced by `BVH8_CPU::Intersect` over \
         rays from tinybvh's own `Ray` constructor, one foreign call per pass, through this \
         benchmark's C++ shim (`csrc/tinybvh8_shim.cpp`: `tinybvh-rs` offers that query only \
         to crates compiled for AVX2), which compiles tinybvh-rs's copy of `tiny_bvh.h` with \
         its flags.\n\
         - Bytes per triangle: ours, the nodes in use and the primitive ids; Embree, what its \
         device memory monitor reports the build left allocated (its nodes and triangle \
         copies, counted in the blocks it reserves); obvhs and tinybvh, nodes and primitive \
         indices; bvh, nodes only. The triangles themselves are not counted.\n\
         - The city (`make_tiled.py`, 1.2M triangles) runs the headline configurations of ours \
         only (the 4-wide and the 8-wide BVH from the SAH BVH, the 8-wide by both walks, both \
         modes), with every peer.\n\
         - `data.json`'s `figures` holds one row per scene, ray set, contender and figure; \
         `bench/scripts/ratios.py data.json` recomputes the headline and round ratios from \
         them.\n\
         - Criterion micro-benchmarks of the hot functions (slab test, triangle test, one \
         traversal): `cargo bench -p raykernel-bench --bench hot`.\n\
         - The interleaved rounds alone, with ray construction timed apart, for A/B work on the \
         headline structure (seconds per scene): `cargo run --release -p raykernel-bench \
         --features embree --example rounds -- --rays RAYS_DIR`; with `--split`, the rays ours \
         misses and those it hits timed apart against Embree HIGH, with the boxes and \
         triangles ours tests per ray in each.\n",
        huge_page_mode()
    );
}
