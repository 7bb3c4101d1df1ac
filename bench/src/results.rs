//! What the benchmark measures, as plain data: one [`TraceRow`] per contender per ray set,
//! one [`ScaleRow`] per size of the tiled scene. The report, the CSV and the JSON are all
//! written from these.

use crate::accuracy::Accuracy;
use crate::workload::RayKind;
use host::compare::Comparison;
use host::rayfile::HitRecord;
use serde::Serialize;

/// Figures of one contender (our kernel in one configuration, or a peer) on one ray set.
///
/// Times are medians over the runs. `closest_mrays` and `any_mrays` are the per-ray figures,
/// what a caller pays: ours and Embree prepare each ray from its record inside the timed
/// loop; the other peers take rays converted ahead, so theirs add that conversion
/// (`setup_ms`) to the trace time. `*_prebuilt` count tracing of rays built ahead only (ours
/// and the peers that take pre-built rays; `None` for Embree, whose call takes raw records).
#[derive(Clone, Debug, Serialize)]
pub struct TraceRow {
    /// Scene name.
    pub scene: String,
    /// Ray set.
    pub rays: RayKind,
    /// Rays traced (after the stride).
    pub ray_count: usize,
    /// Triangles in the scene.
    pub triangles: usize,
    /// True for this project's kernel, false for a peer.
    pub ours: bool,
    /// `raykernel bvh`, `obvhs BVH2`, `obvhs CWBVH`, `bvh`.
    pub contender: String,
    /// Builder (`sah`, `median`, `midpoint`, or the peer's).
    pub builder: String,
    /// Triangle test: `watertight`, `Möller–Trumbore`, `exact integer`.
    pub test: String,
    /// Number mode: `f32` or `fixed`.
    pub mode: String,
    /// Build wall time, ms.
    pub build_ms: f64,
    /// Ray setup wall time, ms (records to the contender's ray type, ahead of tracing).
    pub setup_ms: f64,
    /// `setup_ms` per traced ray, ns.
    pub setup_ns_per_ray: f64,
    /// Closest hit, million rays per second, ray construction included.
    pub closest_mrays: f64,
    /// Closest hit of pre-built rays, million rays per second.
    pub closest_mrays_prebuilt: Option<f64>,
    /// Any hit (occlusion), million rays per second, ray construction included.
    pub any_mrays: f64,
    /// Any hit of pre-built rays, million rays per second.
    pub any_mrays_prebuilt: Option<f64>,
    /// Nodes visited per ray, closest hit (`None` where the contender cannot count them).
    pub nodes_per_ray: Option<f64>,
    /// Primitive tests per ray, closest hit.
    pub prims_per_ray: Option<f64>,
    /// Bytes of the structure per triangle (what is counted: see the report's notes).
    pub bytes_per_tri: f64,
    /// Depth of the deepest leaf, where known.
    pub depth: Option<u32>,
    /// Rays with a closest hit.
    pub hits: usize,
    /// Rays occluded (any hit).
    pub any_hits: usize,
    /// Agreement of the closest hits with our reference row (`f32`, watertight, SAH).
    pub vs_ours: Option<Comparison>,
    /// Of the rays only one side hits: how many only ours hits, how many only this peer.
    pub hitmiss_split: Option<HitMissSplit>,
    /// Errors against the `f64` reference.
    pub accuracy: Option<Accuracy>,
    /// The closest hits, one per traced ray (kept for the comparisons, not written out).
    #[serde(skip)]
    pub hit_records: Vec<HitRecord>,
}

impl TraceRow {
    /// A short unique name within a ray set: `raykernel bvh sah f32`, `obvhs CWBVH`, ...
    #[must_use]
    pub fn label(&self) -> String {
        if self.ours {
            let test = if self.test == crate::ours::MT_TEST {
                " MT"
            } else {
                ""
            };
            format!("{} {} {}{test}", self.contender, self.builder, self.mode)
        } else {
            self.contender.clone()
        }
    }

    /// The family the error-vs-speed plot groups by: `f32 watertight`, `f32 MT`, `fixed`, or
    /// the peer.
    #[must_use]
    pub fn family(&self) -> String {
        if self.ours {
            if self.test == crate::ours::MT_TEST {
                "raykernel f32 MT".into()
            } else {
                format!("raykernel {}", self.mode)
            }
        } else {
            self.contender.clone()
        }
    }
}

/// The rays on which exactly one of two hit lists has a hit, by side.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct HitMissSplit {
    /// Our reference row hits, the peer misses.
    pub ours_only: usize,
    /// The peer hits, our reference row misses.
    pub peer_only: usize,
}

impl HitMissSplit {
    /// Counts both sides over two equally long hit lists.
    #[must_use]
    pub fn of(ours: &[HitRecord], peer: &[HitRecord]) -> Self {
        let mut split = Self::default();
        for (a, b) in ours.iter().zip(peer) {
            match (a.is_hit(), b.is_hit()) {
                (true, false) => split.ours_only += 1,
                (false, true) => split.peer_only += 1,
                _ => {}
            }
        }
        split
    }
}

/// One size of the tiled scene: build and trace figures of one of our configurations.
#[derive(Clone, Debug, Serialize)]
pub struct ScaleRow {
    /// Triangles (instances, truncated to the target, plus the ground).
    pub triangles: usize,
    /// Instances placed.
    pub instances: usize,
    /// `f32` or `fixed`.
    pub mode: String,
    /// Builder.
    pub builder: String,
    /// Build wall time, ms (median).
    pub build_ms: f64,
    /// Bytes of nodes and ids per triangle.
    pub bytes_per_tri: f64,
    /// Rays per set.
    pub ray_count: usize,
    /// Closest hit, primary rays, Mrays/s.
    pub primary_mrays: f64,
    /// Closest hit, incoherent rays, Mrays/s.
    pub incoherent_mrays: f64,
    /// Nodes visited per incoherent ray.
    pub incoherent_nodes_per_ray: f64,
}
