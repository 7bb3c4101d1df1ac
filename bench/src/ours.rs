//! Our kernel's contenders: every accelerator of [`AccelKind::ALL`] (brute force excepted),
//! every builder it takes, in `f32` (watertight, and Möller–Trumbore as a contrast on SAH) and
//! fixed point. The build and the trace go through [`host::trace`]'s shared functions.

use crate::error::Error;
use crate::mt::MtTriangle;
use crate::results::TraceRow;
use crate::workload::{BenchScene, RaySet};
use host::rayfile::HitRecord;
use host::rayfile::RayRecord;
use host::trace::{
    build_and_visit, median, millis, occluded_per_ray, prepare_rays, trace_closest,
    trace_closest_per_ray, AccelConfig, BuildFigures, Mode, NodeArena, PreparedRays,
};
use raykernel::bvh::{BuildOptions, BuilderKind};
use raykernel::{
    Accel, AccelKind, AccelVisitor, Coherent, Primitive, Ray, Scalar, TraversalStats, Triangle,
    I16F16,
};
use std::hint::black_box;
use std::path::Path;
use std::time::Instant;

/// The `test` label of the Möller–Trumbore contrast rows.
pub const MT_TEST: &str = "Möller–Trumbore";

/// Repetitions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RunOptions {
    /// Full runs (build + trace); figures are medians.
    pub runs: usize,
}

/// One configuration of ours.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OurConfig {
    /// Accelerator and builder.
    pub accel: AccelConfig,
    /// Number mode.
    pub mode: Mode,
    /// Möller–Trumbore instead of the watertight test (`f32` only).
    pub mt: bool,
    /// Queried through [`Coherent`]: the walk for coherent rays (the 8-wide BVH's).
    pub coherent: bool,
}

impl OurConfig {
    /// The contender's name: `raykernel` and the structure, `coherent` for the walk for
    /// coherent rays.
    #[must_use]
    pub fn contender(&self) -> String {
        let walk = if self.coherent { " coherent" } else { "" };
        format!("raykernel {}{walk}", self.accel.accel.name())
    }
}

/// Every configuration measured: for each non-brute-force accelerator and each builder it
/// takes, `f32` and fixed point; plus `f32` Möller–Trumbore on the default BVH builder, and
/// the 8-wide BVH from the default builder queried by its walk for coherent rays, both modes.
#[must_use]
pub fn configs() -> Vec<OurConfig> {
    let mut out = Vec::new();
    for accel in AccelKind::ALL {
        if accel.is_brute_force() {
            continue;
        }
        let builders: Vec<BuilderKind> = if accel.build_options().is_some() {
            BuilderKind::ALL.to_vec()
        } else {
            vec![BuilderKind::default()]
        };
        for builder in builders {
            // Primitives in leaf order wherever the structure takes it (the BVHs): one
            // indirection fewer per primitive test, and no memory more (an in-place permutation).
            let accel = AccelConfig {
                accel: accel.with_build_options(BuildOptions {
                    builder,
                    ..BuildOptions::default()
                }),
                leaf_order: accel.permutes_into_leaf_order(),
            };
            let has_coherent_walk = accel.accel == AccelKind::Bvh8(BuildOptions::default());
            for coherent in [false, true] {
                if coherent && !has_coherent_walk {
                    continue;
                }
                for mode in Mode::ALL {
                    out.push(OurConfig {
                        accel,
                        mode,
                        mt: false,
                        coherent,
                    });
                }
            }
            if accel.accel == AccelKind::Bvh(BuildOptions::default()) {
                out.push(OurConfig {
                    accel,
                    mode: Mode::F32,
                    mt: true,
                    coherent: false,
                });
            }
        }
    }
    out
}

/// Scenes above this many triangles (the city) run the headline configurations only: the
/// 4-wide and 8-wide BVHs from the SAH build in both modes (the 8-wide by both walks). The
/// full matrix there would take most of a run's time for structures that lose on every
/// smaller scene already.
pub const LARGE_SCENE_TRIANGLES: usize = 500_000;

/// The configurations measured on a scene of `triangles`: every one of [`configs`], or the
/// headline ones on a scene above [`LARGE_SCENE_TRIANGLES`].
#[must_use]
pub fn configs_for(triangles: usize) -> Vec<OurConfig> {
    let all = configs();
    if triangles <= LARGE_SCENE_TRIANGLES {
        return all;
    }
    all.into_iter()
        .filter(|c| {
            matches!(
                c.accel.accel,
                AccelKind::Bvh4(b) | AccelKind::Bvh8(b) if b.builder == BuilderKind::default()
            ) && !c.mt
        })
        .collect()
}

/// Runs every configuration of [`configs_for`] the scene on one ray set. The first row's hits
/// are the reference the peers' hits are compared with: `f32`, watertight, on the first
/// builder of the first accelerator (the 4-wide BVH collapsed from the SAH BVH; every
/// structure returns the same hits).
///
/// # Errors
/// A scene the mode cannot represent, or a build the kernel refuses.
pub fn run(scene: &BenchScene, set: &RaySet, opts: RunOptions) -> Result<Vec<TraceRow>, Error> {
    let tris32 = scene.mesh.kernel_triangles::<f32>(&scene.path)?;
    let mt: Vec<MtTriangle> = tris32.iter().copied().map(MtTriangle).collect();
    let prepared32 = prepare_rays::<f32>(&set.records);
    // Fixed point may not represent the scene (coordinates beyond ±8192): then no fixed rows.
    let tris_fixed: Option<Vec<Triangle<I16F16>>> =
        scene.mesh.kernel_triangles::<I16F16>(&scene.path).ok();
    let prepared_fixed = tris_fixed
        .as_ref()
        .map(|_| prepare_rays::<I16F16>(&set.records));
    let rays = Records {
        traced: &set.records,
        opts,
        scene: &scene.path,
    };
    let mut rows = Vec::new();
    for config in configs_for(scene.mesh.triangle_count()) {
        let measured = match (config.mode, config.mt, &tris_fixed, &prepared_fixed) {
            (Mode::F32, false, _, _) => measure(&tris32, &prepared32, &rays, &config)?,
            (Mode::F32, true, _, _) => measure(&mt, &prepared32, &rays, &config)?,
            (Mode::Fixed, _, Some(tris), Some(prepared)) => {
                measure(tris, prepared, &rays, &config)?
            }
            (Mode::Fixed, _, _, _) => continue,
        };
        let setup_ms = match config.mode {
            Mode::F32 => prepared32.setup_ms,
            Mode::Fixed => prepared_fixed.as_ref().map_or(0.0, |p| p.setup_ms),
        };
        let n = measured.hits.len();
        let per_ray = |x: u64| if n > 0 { x as f64 / n as f64 } else { 0.0 };
        rows.push(TraceRow {
            scene: scene.name.clone(),
            rays: set.kind,
            ray_count: n,
            triangles: tris32.len(),
            ours: true,
            contender: config.contender(),
            builder: config
                .accel
                .accel
                .build_options()
                .map_or_else(|| "-".into(), |o| o.builder.name().into()),
            test: if config.mt {
                MT_TEST.into()
            } else if config.mode == Mode::Fixed {
                "exact integer".into()
            } else {
                "watertight".into()
            },
            mode: config.mode.name().into(),
            build_ms: measured.build_ms,
            setup_ms,
            setup_ns_per_ray: if n > 0 {
                setup_ms * 1e6 / n as f64
            } else {
                0.0
            },
            closest_mrays: mrays(n, measured.per_ray_ms),
            closest_mrays_prebuilt: Some(mrays(n, measured.closest_ms)),
            any_mrays: mrays(n, measured.any_per_ray_ms),
            any_mrays_prebuilt: Some(mrays(n, measured.any_ms)),
            nodes_per_ray: Some(per_ray(measured.counted.nodes_visited)),
            prims_per_ray: Some(per_ray(measured.counted.prims_tested)),
            bytes_per_tri: if tris32.is_empty() {
                0.0
            } else {
                measured.figures.accel_bytes as f64 / tris32.len() as f64
            },
            depth: Some(measured.figures.depth),
            hits: measured.hits.iter().filter(|h| h.is_hit()).count(),
            any_hits: measured.any_hits,
            vs_ours: None,
            hitmiss_split: None,
            accuracy: None,
            hit_records: measured.hits,
        });
    }
    Ok(rows)
}

/// One untimed build and trace of the first configuration of [`configs`] (the reference), to
/// let the machine settle before the first measured figure.
///
/// # Errors
/// As [`run`].
pub fn warm_up(scene: &BenchScene, set: &RaySet) -> Result<(), Error> {
    let Some(config) = configs().into_iter().next() else {
        return Ok(());
    };
    let tris32 = scene.mesh.kernel_triangles::<f32>(&scene.path)?;
    let prepared = prepare_rays::<f32>(&set.records);
    let rays = Records {
        traced: &set.records,
        opts: RunOptions { runs: 1 },
        scene: &scene.path,
    };
    measure(&tris32, &prepared, &rays, &config).map(|_| ())
}

/// The work (boxes and primitives tested) of a closest-hit pass of `accel` over `rays`,
/// untimed.
#[must_use]
pub fn count_work<S: Scalar, A: Accel<S>>(accel: &A, rays: &[Ray<S>]) -> TraversalStats {
    let mut counted = TraversalStats::default();
    for ray in rays {
        black_box(accel.intersect_counted(ray, &mut counted));
    }
    counted
}

/// Million rays per second.
#[must_use]
pub fn mrays(rays: usize, ms: f64) -> f64 {
    if ms > 0.0 {
        rays as f64 / ms / 1e3
    } else {
        0.0
    }
}

/// The traced records of one ray set, how often to trace them, and the scene (for errors).
pub(crate) struct Records<'r> {
    pub(crate) traced: &'r [RayRecord],
    pub(crate) opts: RunOptions,
    pub(crate) scene: &'r Path,
}

/// Medians over the runs, and the last run's hits and counters.
pub(crate) struct Measured {
    pub(crate) build_ms: f64,
    /// Closest hit, each ray constructed from its record in the timed loop.
    pub(crate) per_ray_ms: f64,
    /// Closest hit of the pre-built rays.
    pub(crate) closest_ms: f64,
    /// Any hit, each ray constructed in the loop.
    pub(crate) any_per_ray_ms: f64,
    /// Any hit of the pre-built rays.
    pub(crate) any_ms: f64,
    pub(crate) hits: Vec<HitRecord>,
    pub(crate) any_hits: usize,
    pub(crate) counted: TraversalStats,
    pub(crate) figures: BuildFigures,
}

/// `runs` full runs of build + closest-hit trace (per ray, then pre-built); the last run also
/// times any hit once each way and counts nodes and primitives in one more closest-hit pass
/// (untimed). `config`'s number mode and triangle test are those of `S` and `P`.
pub(crate) fn measure<S: Scalar, P: Primitive<S> + Copy>(
    prims: &[P],
    prepared: &PreparedRays<S>,
    rays: &Records<'_>,
    config: &OurConfig,
) -> Result<Measured, Error> {
    let runs = rays.opts.runs.max(1);
    let mut arena = NodeArena::<S>::for_accel(config.accel.accel, prims);
    let (mut builds, mut closest, mut per_ray) = (Vec::new(), Vec::new(), Vec::new());
    let mut last = None;
    for run in 0..runs {
        // Any hit is timed once, on the last run (closest hit carries the protocol's medians).
        let extras = run + 1 == runs;
        let pass = Pass {
            prepared,
            records: rays.traced,
            extras,
            coherent: config.coherent,
        };
        let (figures, out) = build_and_visit(prims, &mut arena, rays.scene, &config.accel, pass)?;
        builds.push(figures.build_ms);
        closest.push(out.closest_ms);
        per_ray.push(out.per_ray_ms);
        last = Some((figures, out));
    }
    let Some((figures, out)) = last else {
        return Err(Error::Bench("no run".into()));
    };
    Ok(Measured {
        build_ms: median(&builds),
        per_ray_ms: median(&per_ray),
        closest_ms: median(&closest),
        any_per_ray_ms: out.any_per_ray_ms,
        any_ms: out.any_ms,
        hits: out.hits,
        any_hits: out.any_hits,
        counted: out.counted,
        figures,
    })
}

/// One pass over a built accelerator: closest hit per ray and pre-built (timed); with
/// `extras`, also any hit both ways (timed once) and a counted closest-hit pass. With
/// `coherent`, every query goes through [`Coherent`].
struct Pass<'p, S: Scalar> {
    prepared: &'p PreparedRays<S>,
    records: &'p [RayRecord],
    extras: bool,
    coherent: bool,
}

struct PassOut {
    hits: Vec<HitRecord>,
    per_ray_ms: f64,
    closest_ms: f64,
    any_per_ray_ms: f64,
    any_ms: f64,
    any_hits: usize,
    counted: TraversalStats,
}

impl<S: Scalar> AccelVisitor<S> for Pass<'_, S> {
    type Output = PassOut;

    fn visit<A: Accel<S>>(self, accel: &A) -> PassOut {
        if self.coherent {
            self.run(&Coherent(accel))
        } else {
            self.run(accel)
        }
    }
}

impl<S: Scalar> Pass<'_, S> {
    fn run<A: Accel<S>>(self, accel: &A) -> PassOut {
        let (_, per_ray_ms) = trace_closest_per_ray(accel, self.records);
        let (hits, closest_ms) = trace_closest(accel, self.prepared);
        let mut out = PassOut {
            hits,
            per_ray_ms,
            closest_ms,
            any_per_ray_ms: 0.0,
            any_ms: 0.0,
            any_hits: 0,
            counted: TraversalStats::default(),
        };
        if !self.extras {
            return out;
        }
        let (_, any_per_ray_ms) = occluded_per_ray(accel, self.records);
        out.any_per_ray_ms = any_per_ray_ms;
        let rays = &self.prepared.rays;
        let start = Instant::now();
        let mut occluded = 0usize;
        for ray in rays {
            occluded += usize::from(accel.occluded(ray));
        }
        out.any_ms = millis(start);
        out.any_hits = black_box(occluded);
        // Rejected records are placeholders (empty interval): remove any count they made.
        for &i in &self.prepared.bad {
            if rays.get(i).is_some_and(|r| accel.occluded(r)) {
                out.any_hits -= 1;
            }
        }
        out.counted = count_work(accel, rays);
        out
    }
}
