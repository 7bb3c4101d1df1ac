//! Build an accelerator over a mesh and trace rays through it: the in-memory core of
//! `host trace` and of the benchmark (`raykernel-bench`), written once over the kernel's [`Scalar`] and dispatched on
//! [`Mode`].
//!
//! The pieces are public so the benchmark reuses them rather than copying the loop:
//! [`build_and_visit`] builds whichever kernel [`AccelKind`] is asked for (timed, through
//! [`AnyAccel`]) and hands the structure itself to an [`AccelVisitor`];
//! [`trace_closest_per_ray`] times queries that set one ray from each record in turn,
//! [`prepare_rays`] and [`trace_closest`] the two halves of a trace of pre-built rays.
//!
//! [`AccelKind::Bvh4`] and [`AccelKind::Bvh8`] build the BVH (timed) and collapse it into the
//! wide tree (timed too); the BVH's node arena is build scratch, so their figures count only
//! the wide nodes and the primitive ids the queries read.

use crate::error::Error;
use crate::obj::Mesh;
use crate::pages;
use crate::rayfile::{every, HitRecord, RayRecord};
use raykernel::bvh::BuilderKind;
use raykernel::{
    Accel, AccelKind, AccelMemory, AccelVisitor, AnyAccel, Coherent, KdNode, Node, Node4, Node8,
    Primitive, Ray, Scalar, Triangle, I16F16,
};
use std::path::Path;
use std::time::Instant;

/// Parses `--accel` into the kernel's [`AccelKind`] (default options) by its names, which
/// the help lists.
#[must_use]
pub fn accel_parser() -> impl clap::builder::TypedValueParser<Value = AccelKind> {
    use clap::builder::TypedValueParser;
    clap::builder::PossibleValuesParser::new(AccelKind::ALL.map(|k| k.name()))
        .map(|name: String| AccelKind::from_name(&name).unwrap_or_default())
}

/// The kernel's number mode.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Mode {
    /// 32-bit IEEE floating point.
    F32,
    /// Fixed point: Q16.16 coordinates within ±8192 (the kernel's `I16F16`).
    Fixed,
}

impl Mode {
    /// Both modes.
    pub const ALL: [Mode; 2] = [Self::F32, Self::Fixed];

    /// Name as on the command line (the kernel's `Scalar::NAME`).
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::F32 => <f32 as Scalar>::NAME,
            Self::Fixed => <I16F16 as Scalar>::NAME,
        }
    }
}

/// BVH builder, as chosen on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Builder {
    /// Binned SAH.
    Sah,
    /// Median split.
    Median,
    /// Midpoint split.
    Midpoint,
}

impl From<Builder> for BuilderKind {
    fn from(b: Builder) -> Self {
        match b {
            Builder::Sah => BuilderKind::Sah,
            Builder::Median => BuilderKind::Median,
            Builder::Midpoint => BuilderKind::Midpoint,
        }
    }
}

/// What to build and which rays to trace.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TraceConfig {
    /// Accelerator and its options.
    pub accel: AccelKind,
    /// Number mode.
    pub mode: Mode,
    /// Trace rays `0, stride, 2·stride, ...` only. Must be at least 1.
    pub stride: usize,
    /// Full runs (build + trace) to time; the figures are their medians. Must be at least 1.
    pub runs: usize,
    /// Build with [`Bvh::build_in_leaf_order`] (primitives permuted into leaf order; hits
    /// still report original ids). Ignored by [`AccelKind::Linear`].
    pub leaf_order: bool,
    /// Query through [`raykernel::Coherent`]: the walk for coherent rays (camera rays in
    /// scanline order), where the structure has one. Same hits.
    pub coherent: bool,
}

impl TraceConfig {
    /// The build part of the configuration.
    #[must_use]
    pub fn accel_config(&self) -> AccelConfig {
        AccelConfig {
            accel: self.accel,
            leaf_order: self.leaf_order,
        }
    }
}

/// What to build: accelerator with its options, leaf order.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AccelConfig {
    /// Accelerator and its options.
    pub accel: AccelKind,
    /// Permute the primitives into leaf order (only the structures that
    /// [`AccelKind::permutes_into_leaf_order`]).
    pub leaf_order: bool,
}

/// Figures of one build.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BuildFigures {
    /// Wall time of the build, including the leaf-order permutation (0 for brute force).
    pub build_ms: f64,
    /// Nodes in use (0 for brute force).
    pub nodes: usize,
    /// Bytes of nodes and primitive ids in use (0 for brute force).
    pub accel_bytes: usize,
    /// Depth of the deepest leaf (0 for brute force).
    pub depth: u32,
}

/// Figures of a trace: times are the medians over the runs.
///
/// Two timings of the same closest-hit queries: `per_ray_ms` sets one kernel ray from each
/// record inside the timed loop (what a caller pays per ray), `trace_ms` traces rays
/// constructed beforehand (`setup_ms`, timed apart) and so counts traversal alone.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TraceStats {
    /// Triangles in the scene.
    pub triangles: usize,
    /// Median wall time of the build, including the leaf-order permutation (0 for linear).
    pub build_ms: f64,
    /// Median wall time of constructing every traced ray and tracing it, one record at a
    /// time, storing the hits.
    pub per_ray_ms: f64,
    /// Median wall time of turning every traced record into a kernel ray (normalisation,
    /// reciprocals, shear constants) ahead of tracing.
    pub setup_ms: f64,
    /// Median wall time of tracing and storing every pre-built ray (setup excluded).
    pub trace_ms: f64,
    /// Build time of each run, in run order.
    pub build_ms_runs: Vec<f64>,
    /// Per-ray time (construction included) of each run, in run order.
    pub per_ray_ms_runs: Vec<f64>,
    /// Pre-built trace time of each run, in run order.
    pub trace_ms_runs: Vec<f64>,
    /// Rays traced (after the stride).
    pub rays: usize,
    /// Rays that hit something.
    pub hits: usize,
    /// Rays the kernel rejected (written as misses).
    pub bad_rays: usize,
    /// BVH nodes in use (0 for linear).
    pub nodes: usize,
    /// Bytes of nodes and primitive ids in use (0 for linear).
    pub accel_bytes: usize,
    /// Depth of the deepest leaf (0 for linear).
    pub depth: u32,
}

/// Hits (one per traced ray, in ray order) and figures.
#[derive(Clone, Debug, PartialEq)]
pub struct TraceOutput {
    /// Closest hits.
    pub hits: Vec<HitRecord>,
    /// Figures.
    pub stats: TraceStats,
}

/// Builds the accelerator `config` asks for over `mesh` and traces every `stride`-th ray,
/// `config.runs` times (build + trace each time, single-threaded), as WORKLOAD.md's protocol
/// asks. Times are the medians over the runs; the hits are those of the last run, which must
/// equal those of every other run. `scene` only labels errors.
///
/// # Errors
/// [`Error::Obj`] for a vertex the mode cannot represent, [`Error::Build`] if the kernel
/// refuses to build, [`Error::RunsDiffer`] if two runs give different hits.
///
/// # Panics
/// If `config.stride` or `config.runs` is 0.
pub fn trace(
    mesh: &Mesh,
    scene: &Path,
    rays: &[RayRecord],
    config: &TraceConfig,
) -> Result<TraceOutput, Error> {
    match config.mode {
        Mode::F32 => trace_in::<f32>(mesh, scene, rays, config),
        Mode::Fixed => trace_in::<I16F16>(mesh, scene, rays, config),
    }
}

fn trace_in<S: Scalar>(
    mesh: &Mesh,
    scene: &Path,
    rays: &[RayRecord],
    config: &TraceConfig,
) -> Result<TraceOutput, Error> {
    assert!(config.stride > 0, "stride must be at least 1");
    assert!(config.runs > 0, "runs must be at least 1");
    let tris = mesh.kernel_triangles::<S>(scene)?;
    let mut arena = NodeArena::<S>::for_accel(config.accel, &tris);
    // The traced records, gathered once (see `every`).
    let rays = every(rays, config.stride);
    let mut first: Option<Vec<HitRecord>> = None;
    let mut last = None;
    let (mut build_ms_runs, mut trace_ms_runs) = (Vec::new(), Vec::new());
    let (mut setup_ms_runs, mut per_ray_ms_runs) = (Vec::new(), Vec::new());
    for run in 0..config.runs {
        let (hits, stats) = run_once(&tris, &mut arena, scene, &rays, config)?;
        if let Some(first) = &first {
            if let Some(ray) = first_difference(first, &hits) {
                return Err(Error::RunsDiffer {
                    scene: scene.to_path_buf(),
                    run: run + 1,
                    ray: ray * config.stride,
                });
            }
        } else {
            first = Some(hits.clone());
        }
        build_ms_runs.push(stats.build_ms);
        trace_ms_runs.push(stats.trace_ms);
        setup_ms_runs.push(stats.setup_ms);
        per_ray_ms_runs.push(stats.per_ray_ms);
        last = Some((hits, stats));
    }
    let (hits, stats) = last.unwrap_or_default();
    let stats = TraceStats {
        triangles: tris.len(),
        build_ms: median(&build_ms_runs),
        per_ray_ms: median(&per_ray_ms_runs),
        setup_ms: median(&setup_ms_runs),
        trace_ms: median(&trace_ms_runs),
        build_ms_runs,
        per_ray_ms_runs,
        trace_ms_runs,
        ..stats
    };
    Ok(TraceOutput { hits, stats })
}

/// One run over the traced records `rays`: build (timed), trace constructing each ray in the
/// loop (timed), then prepare the rays (timed) and trace them again (timed).
fn run_once<S: Scalar>(
    tris: &[Triangle<S>],
    arena: &mut NodeArena<S>,
    scene: &Path,
    rays: &[RayRecord],
    config: &TraceConfig,
) -> Result<(Vec<HitRecord>, TraceStats), Error> {
    struct Closest<'r> {
        rays: &'r [RayRecord],
        coherent: bool,
    }
    impl<S: Scalar> AccelVisitor<S> for Closest<'_> {
        type Output = (Vec<HitRecord>, TraceStats);
        fn visit<A: Accel<S>>(self, accel: &A) -> Self::Output {
            if self.coherent {
                trace_rays(&Coherent(accel), self.rays)
            } else {
                trace_rays(accel, self.rays)
            }
        }
    }
    let visitor = Closest {
        rays,
        coherent: config.coherent,
    };
    let (built, (hits, stats)) =
        build_and_visit(tris, arena, scene, &config.accel_config(), visitor)?;
    let stats = TraceStats {
        build_ms: built.build_ms,
        nodes: built.nodes,
        accel_bytes: built.accel_bytes,
        depth: built.depth,
        ..stats
    };
    Ok((hits, stats))
}

/// Builds the accelerator `config` asks for over `prims` (timed, single-threaded) in `arena`
/// and hands it to `visitor`. `arena` must come from [`NodeArena::for_accel`] with the same
/// accelerator and primitive count. `scene` only labels errors.
///
/// # Errors
/// [`Error::Build`] if the kernel refuses to build.
pub fn build_and_visit<S: Scalar, P: Primitive<S> + Copy, V: AccelVisitor<S>>(
    prims: &[P],
    arena: &mut NodeArena<S>,
    scene: &Path,
    config: &AccelConfig,
    visitor: V,
) -> Result<(BuildFigures, V::Output), Error> {
    let build_error = |source| Error::Build {
        scene: scene.to_path_buf(),
        source,
    };
    // The leaf-order permutation works in place: give it a fresh copy (untimed, like parsing).
    let leaf_order = config.leaf_order && config.accel.permutes_into_leaf_order();
    let mut own = if leaf_order {
        pages::copied(prims)
    } else {
        Vec::new()
    };
    let mut memory = arena.memory();
    let start = Instant::now();
    let built = if leaf_order {
        AnyAccel::build_in_leaf_order(config.accel, &mut own, &mut memory)
    } else {
        AnyAccel::build(config.accel, prims, &mut memory)
    }
    .map_err(build_error)?;
    let build_ms = if config.accel.is_brute_force() {
        0.0
    } else {
        millis(start)
    };
    let figures = BuildFigures {
        build_ms,
        nodes: built.node_count(),
        accel_bytes: built.bytes_used(),
        depth: built.depth(),
    };
    Ok((figures, built.visit(visitor)))
}

/// Index of the first record that differs bit for bit (or the shorter length), if any.
fn first_difference(a: &[HitRecord], b: &[HitRecord]) -> Option<usize> {
    let same = |x: &HitRecord, y: &HitRecord| x.t.to_bits() == y.t.to_bits() && x.prim == y.prim;
    a.iter()
        .zip(b)
        .position(|(x, y)| !same(x, y))
        .or_else(|| (a.len() != b.len()).then(|| a.len().min(b.len())))
}

/// The median (mean of the middle two for an even count); 0 for none.
#[must_use]
pub fn median(xs: &[f64]) -> f64 {
    let mut v = xs.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    match n {
        0 => 0.0,
        _ if n % 2 == 1 => v[n / 2],
        _ => (v[n / 2 - 1] + v[n / 2]) / 2.0,
    }
}

/// The memory an accelerator is built into, allocated once outside the timed builds. BVH
/// nodes start on a 64-byte boundary, so that each sibling pair (two 32-byte nodes at an even
/// slot) is one cache line, as the kernel's layout intends.
pub struct NodeArena<S: Scalar> {
    /// One spare slot: `Node` is 32-aligned, so skipping at most one reaches a 64-byte line.
    nodes: Vec<Node<S>>,
    /// 4-wide BVH nodes (`Node4` is 128-byte aligned, so the vector is too).
    nodes4: Vec<Node4<S>>,
    /// 8-wide BVH nodes (128-byte aligned too).
    nodes8: Vec<Node8<S>>,
    kd_nodes: Vec<KdNode<S>>,
    words: Vec<u32>,
}

impl<S: Scalar> NodeArena<S> {
    const LINE: usize = 64;

    /// The memory `accel` needs over `prims` (empty for brute force, and for a grid the
    /// counting pass rejects: its build reports the error).
    #[must_use]
    pub fn for_accel<P: Primitive<S>>(accel: AccelKind, prims: &[P]) -> Self {
        Self::sized(accel.memory_needed(prims).unwrap_or_default())
    }

    /// Buffers of the lengths `need` gives.
    #[must_use]
    pub fn sized(need: raykernel::MemoryNeeded) -> Self {
        Self {
            nodes: pages::filled(need.nodes + 1, Node::EMPTY),
            nodes4: pages::filled(need.nodes4, Node4::EMPTY),
            nodes8: pages::filled(need.nodes8, Node8::EMPTY),
            kd_nodes: pages::filled(need.kd_nodes, KdNode::EMPTY),
            words: pages::filled(need.words, 0),
        }
    }

    /// `slots` BVH nodes and nothing else.
    #[must_use]
    pub fn with_slots(slots: usize) -> Self {
        Self::sized(raykernel::MemoryNeeded {
            nodes: slots,
            ..raykernel::MemoryNeeded::NONE
        })
    }

    /// The BVH nodes alone, starting on a 64-byte boundary.
    pub fn slots(&mut self) -> &mut [Node<S>] {
        self.memory().nodes
    }

    /// The buffers as the kernel's caller memory, BVH nodes starting on a 64-byte boundary.
    pub fn memory(&mut self) -> AccelMemory<'_, S> {
        let misaligned = (self.nodes.as_ptr() as usize) % Self::LINE != 0;
        let skip = usize::from(misaligned);
        let len = self.nodes.len() - 1;
        AccelMemory {
            nodes: &mut self.nodes[skip..skip + len],
            nodes4: &mut self.nodes4,
            nodes8: &mut self.nodes8,
            kd_nodes: &mut self.kd_nodes,
            words: &mut self.words,
        }
    }
}

/// Traces every record both ways (constructed in the loop, then pre-built); fills in the ray,
/// hit and timing figures. Both ways give the same hits.
fn trace_rays<S: Scalar, A: Accel<S>>(
    accel: &A,
    rays: &[RayRecord],
) -> (Vec<HitRecord>, TraceStats) {
    let (per_ray_hits, per_ray_ms) = trace_closest_per_ray(accel, rays);
    let prepared = prepare_rays::<S>(rays);
    let (hits, trace_ms) = trace_closest(accel, &prepared);
    debug_assert!(
        first_difference(&hits, &per_ray_hits).is_none(),
        "per-ray and pre-built rays must give the same hits"
    );
    let stats = TraceStats {
        per_ray_ms,
        setup_ms: prepared.setup_ms,
        trace_ms,
        rays: hits.len(),
        hits: hits.iter().filter(|h| h.is_hit()).count(),
        bad_rays: prepared.bad.len(),
        ..TraceStats::default()
    };
    (hits, stats)
}

/// Closest hit of every record, read in order (a subset is gathered first: [`every`]): one
/// kernel ray, set from each record's raw origin, direction and interval
/// ([`Ray::set_from_f32`], in place) inside the timed loop, then traced: what a caller pays
/// per query. A record the kernel rejects is a miss. Returns the hits and the loop's wall
/// time, ms.
#[must_use]
pub fn trace_closest_per_ray<S: Scalar, A: Accel<S>>(
    accel: &A,
    rays: &[RayRecord],
) -> (Vec<HitRecord>, f64) {
    let mut hits = vec![HitRecord::MISS; rays.len()];
    let mut ray = placeholder::<S>();
    let start = Instant::now();
    for (slot, r) in hits.iter_mut().zip(rays) {
        if ray.set_from_f32(r.origin, r.dir, r.t_min, r.t_max).is_err() {
            continue;
        }
        if let Some(h) = accel.nearest(&ray) {
            *slot = HitRecord {
                t: h.t.to_f32(),
                prim: h.prim,
            };
        }
    }
    (hits, millis(start))
}

/// Any hit (occlusion) of every record, the kernel ray set from each record inside the timed
/// loop as in [`trace_closest_per_ray`]. Returns how many are occluded and the loop's wall
/// time, ms.
#[must_use]
pub fn occluded_per_ray<S: Scalar, A: Accel<S>>(accel: &A, rays: &[RayRecord]) -> (usize, f64) {
    let mut ray = placeholder::<S>();
    let start = Instant::now();
    let mut occluded = 0usize;
    for r in rays {
        if ray.set_from_f32(r.origin, r.dir, r.t_min, r.t_max).is_ok() {
            occluded += usize::from(accel.occluded(&ray));
        }
    }
    (std::hint::black_box(occluded), millis(start))
}

/// A ray valid in both modes: what a reused ray starts as, and what stands in for a record the
/// kernel rejects.
fn placeholder<S: Scalar>() -> Ray<S> {
    Ray::from_f32([0.0; 3], [0.0, 0.0, 1.0], 0.0, 0.0)
        .expect("the placeholder ray is valid in both modes")
}

/// Kernel rays made from ray-file records, one per traced record.
///
/// Invariant: `rays.len()` is the number of traced records; a record the kernel rejects holds
/// a placeholder ray (valid in both modes) and its index is in `bad`, in increasing order.
#[derive(Clone, Debug)]
pub struct PreparedRays<S: Scalar> {
    /// One kernel ray per traced record.
    pub rays: Vec<Ray<S>>,
    /// Indices (into `rays`) of the records the kernel rejected: traced as misses.
    pub bad: Vec<usize>,
    /// Wall time of the preparation (normalisation, reciprocals, shear constants).
    pub setup_ms: f64,
}

/// Turns every record into a kernel ray (timed), reading them in order as
/// [`trace_closest_per_ray`] does.
#[must_use]
pub fn prepare_rays<S: Scalar>(rays: &[RayRecord]) -> PreparedRays<S> {
    // Rejected records (bad rays) are traced as a placeholder and written as misses. The
    // placeholder is a valid ray in both modes, so `prepared` keeps one entry per record.
    // The vector is filled with it before the clock starts, and each ray is then written in
    // place: the fill takes the page faults of fresh memory (most of the time of storing
    // 100+ bytes per ray), which are not ray construction. (One exact-size allocation:
    // growing a 100+ MB vector by reallocation measurably slowed the trace that follows.)
    let mut prepared = vec![placeholder::<S>(); rays.len()];
    let mut bad = Vec::new();
    let start = Instant::now();
    for (i, (slot, r)) in prepared.iter_mut().zip(rays).enumerate() {
        match Ray::<S>::from_f32(r.origin, r.dir, r.t_min, r.t_max) {
            Ok(ray) => *slot = ray,
            Err(_) => bad.push(i),
        }
    }
    PreparedRays {
        rays: prepared,
        bad,
        setup_ms: millis(start),
    }
}

/// Closest hit of every prepared ray, stored as hit records (misses for rejected records),
/// and the wall time of tracing and storing them in milliseconds.
#[must_use]
pub fn trace_closest<S: Scalar, A: Accel<S>>(
    accel: &A,
    prepared: &PreparedRays<S>,
) -> (Vec<HitRecord>, f64) {
    let mut hits = vec![HitRecord::MISS; prepared.rays.len()];
    let start = Instant::now();
    for (slot, ray) in hits.iter_mut().zip(&prepared.rays) {
        // A hit record holds t and the primitive: no barycentrics needed.
        if let Some(h) = accel.nearest(ray) {
            *slot = HitRecord {
                t: h.t.to_f32(),
                prim: h.prim,
            };
        }
    }
    for &i in &prepared.bad {
        hits[i] = HitRecord::MISS;
    }
    (hits, millis(start))
}

/// Milliseconds since `start`.
#[must_use]
pub fn millis(start: Instant) -> f64 {
    start.elapsed().as_secs_f64() * 1e3
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_of_odd_even_and_empty_lists() {
        assert_eq!(median(&[]), 0.0);
        assert_eq!(median(&[4.0]), 4.0);
        assert_eq!(median(&[9.0, 1.0, 5.0]), 5.0);
        assert_eq!(median(&[9.0, 1.0, 5.0, 3.0]), 4.0);
    }

    #[test]
    fn first_difference_is_bitwise() {
        let h = |t: f32, prim| HitRecord { t, prim };
        let a = [h(1.0, 1), h(0.0, 2), HitRecord::MISS];
        assert_eq!(first_difference(&a, &a), None);
        assert_eq!(
            first_difference(&a, &[h(1.0, 1), h(-0.0, 2), HitRecord::MISS]),
            Some(1)
        );
        assert_eq!(first_difference(&a, &a[..2]), Some(2));
        assert_eq!(
            first_difference(&a, &[h(1.0, 1), h(0.0, 3), HitRecord::MISS]),
            Some(1)
        );
    }
}
