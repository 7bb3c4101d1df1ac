//! Build an accelerator over a mesh and trace rays through it: the in-memory core of
//! `host trace`, written once over the kernel's [`Scalar`] and dispatched on [`Mode`].

use crate::error::Error;
use crate::obj::Mesh;
use crate::rayfile::{HitRecord, RayRecord};
use raykernel::bvh::{nodes_needed, BuildOptions, BuilderKind};
use raykernel::{Accel, Bvh, Linear, Node, Ray, Scalar, I16F16};
use std::path::Path;
use std::time::Instant;

/// Which accelerator answers the queries.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum AccelKind {
    /// The kernel's BVH.
    Bvh,
    /// Brute force over every triangle: the reference.
    Linear,
}

impl AccelKind {
    /// Name as on the command line.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Bvh => "bvh",
            Self::Linear => "linear",
        }
    }
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
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TraceConfig {
    /// Accelerator.
    pub accel: AccelKind,
    /// BVH builder and leaf size (ignored by [`AccelKind::Linear`]).
    pub build: BuildOptions,
    /// Number mode.
    pub mode: Mode,
    /// Trace rays `0, stride, 2·stride, ...` only. Must be at least 1.
    pub stride: usize,
}

/// Figures of one trace run.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TraceStats {
    /// Triangles in the scene.
    pub triangles: usize,
    /// Wall time of `Bvh::build` (0 for linear).
    pub build_ms: f64,
    /// Wall time of preparing, tracing and storing every traced ray.
    pub trace_ms: f64,
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

/// Builds the accelerator `config` asks for over `mesh` and traces every `stride`-th ray.
/// Single-threaded. `scene` only labels errors.
///
/// # Errors
/// [`Error::Obj`] for a vertex the mode cannot represent, [`Error::Build`] if the kernel
/// refuses to build.
///
/// # Panics
/// If `config.stride` is 0.
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
    let tris = mesh.kernel_triangles::<S>(scene)?;
    let n = tris.len();
    let (hits, mut stats) = match config.accel {
        AccelKind::Linear => trace_rays(&Linear::new(&tris), rays, config.stride),
        AccelKind::Bvh => {
            let mut arena = NodeArena::<S>::new(nodes_needed(n));
            let mut ids = vec![0u32; n];
            let start = Instant::now();
            let bvh =
                Bvh::build(&tris, arena.slots(), &mut ids, config.build).map_err(|source| {
                    Error::Build {
                        scene: scene.to_path_buf(),
                        source,
                    }
                })?;
            let build_ms = millis(start);
            let (hits, stats) = trace_rays(&bvh, rays, config.stride);
            let stats = TraceStats {
                build_ms,
                nodes: bvh.nodes().len(),
                accel_bytes: bvh.bytes_used(),
                depth: bvh.depth(),
                ..stats
            };
            (hits, stats)
        }
    };
    stats.triangles = n;
    Ok(TraceOutput { hits, stats })
}

/// A node arena whose first slot sits on a 64-byte boundary, so that each sibling pair (two
/// 32-byte nodes at an even slot) is one cache line, as the kernel's layout intends.
struct NodeArena<S: Scalar> {
    nodes: Vec<Node<S>>,
}

impl<S: Scalar> NodeArena<S> {
    const LINE: usize = 64;

    fn new(slots: usize) -> Self {
        // One spare slot: `Node` is 32-aligned, so skipping at most one reaches a 64-byte line.
        Self {
            nodes: vec![Node::EMPTY; slots + 1],
        }
    }

    /// The `slots` requested, starting on a 64-byte boundary.
    fn slots(&mut self) -> &mut [Node<S>] {
        let misaligned = self.nodes.as_ptr() as usize % Self::LINE != 0;
        let skip = usize::from(misaligned);
        let len = self.nodes.len() - 1;
        &mut self.nodes[skip..skip + len]
    }
}

/// Traces every `stride`-th ray; fills in the ray, hit and timing figures.
fn trace_rays<S: Scalar, A: Accel<S>>(
    accel: &A,
    rays: &[RayRecord],
    stride: usize,
) -> (Vec<HitRecord>, TraceStats) {
    assert!(stride > 0, "stride must be at least 1");
    let mut hits = Vec::with_capacity(rays.len().div_ceil(stride));
    let mut bad_rays = 0;
    let start = Instant::now();
    for r in rays.iter().step_by(stride) {
        let hit = match Ray::<S>::from_f32(r.origin, r.dir, r.t_min, r.t_max) {
            Ok(ray) => accel
                .intersect(&ray)
                .map_or(HitRecord::MISS, |h| HitRecord {
                    t: h.t.to_f32(),
                    prim: h.prim,
                }),
            Err(_) => {
                bad_rays += 1;
                HitRecord::MISS
            }
        };
        hits.push(hit);
    }
    let trace_ms = millis(start);
    let stats = TraceStats {
        trace_ms,
        rays: hits.len(),
        hits: hits.iter().filter(|h| h.is_hit()).count(),
        bad_rays,
        ..TraceStats::default()
    };
    (hits, stats)
}

fn millis(start: Instant) -> f64 {
    start.elapsed().as_secs_f64() * 1e3
}
