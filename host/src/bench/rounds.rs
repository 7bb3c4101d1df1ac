//! Interleaved rounds: the headline contender (the 4-wide BVH collapsed from the SAH BVH,
//! `f32`) and, with the `tinybvh` feature, tinybvh's scalar BVH2 (the peer the kernel issue
//! names) trace one ray set in alternation: ours, tinybvh, ours, tinybvh, ... Each structure
//! is built once; only tracing is timed.
//!
//! Why: on a shared VM a slow spell (another tenant's memory traffic) can last seconds to
//! minutes, long enough to cover one contender's consecutive runs and not the other's. In
//! alternation both see every spell, so the per-round ratio compares like with like. Each
//! contender's fastest round is reported too: such noise only ever adds time, so the minimum
//! time is the estimate least disturbed by it (Chen and Revels 2016, "Robust benchmarking in
//! noisy environments").

use super::ours::{mrays, RunOptions};
use super::workload::{BenchScene, RayKind, RaySet};
use crate::error::Error;
use crate::trace::{
    build_and_visit, median, prepare_rays, trace_closest, AccelConfig, NodeArena, PreparedRays,
};
use raykernel::{Accel, AccelKind, AccelVisitor};
use serde::Serialize;

/// One ray set's rounds: Mrays/s of each round, in round order.
#[derive(Clone, Debug, Serialize)]
pub struct RoundsRow {
    /// Scene.
    pub scene: String,
    /// Ray set.
    pub rays: RayKind,
    /// Rays traced per round.
    pub ray_count: usize,
    /// Ours (4-wide BVH, SAH, `f32`, closest hit), one figure per round.
    pub ours_mrays: Vec<f64>,
    /// tinybvh's BVH2 in the same rounds (empty without the `tinybvh` feature).
    pub peer_mrays: Vec<f64>,
}

impl RoundsRow {
    /// Median of ours over the rounds.
    #[must_use]
    pub fn ours_median(&self) -> f64 {
        median(&self.ours_mrays)
    }
    /// Ours' fastest round.
    #[must_use]
    pub fn ours_best(&self) -> f64 {
        best(&self.ours_mrays)
    }
    /// Median of the peer over the rounds (`None` without the peer).
    #[must_use]
    pub fn peer_median(&self) -> Option<f64> {
        (!self.peer_mrays.is_empty()).then(|| median(&self.peer_mrays))
    }
    /// The peer's fastest round.
    #[must_use]
    pub fn peer_best(&self) -> Option<f64> {
        (!self.peer_mrays.is_empty()).then(|| best(&self.peer_mrays))
    }
    /// Ours ÷ peer within each round (empty without the peer).
    #[must_use]
    pub fn ratios(&self) -> Vec<f64> {
        self.ours_mrays
            .iter()
            .zip(&self.peer_mrays)
            .filter(|(_, &p)| p > 0.0)
            .map(|(o, p)| o / p)
            .collect()
    }
}

/// The largest figure (0 for none).
fn best(xs: &[f64]) -> f64 {
    xs.iter().copied().fold(0.0, f64::max)
}

/// The headline configuration: 4-wide BVH, default (SAH) build, no leaf order.
fn headline_config() -> AccelConfig {
    AccelConfig {
        accel: AccelKind::Bvh4(raykernel::bvh::BuildOptions::default()),
        leaf_order: false,
    }
}

/// Runs `rounds` rounds on one ray set (every `opts.stride`-th ray).
///
/// # Errors
/// A build the kernel refuses.
pub fn run(
    scene: &BenchScene,
    set: &RaySet,
    opts: RunOptions,
    rounds: usize,
    with_peer: bool,
) -> Result<RoundsRow, Error> {
    let tris = scene.mesh.kernel_triangles::<f32>(&scene.path)?;
    let prepared = prepare_rays::<f32>(&set.records, opts.stride);
    let config = headline_config();
    let mut arena = NodeArena::<f32>::for_accel(config.accel, &tris);
    let peer = with_peer.then(|| {
        let tris: Vec<[[f32; 3]; 3]> = (0..scene.mesh.triangle_count())
            .map(|i| scene.mesh.triangle_f32(i))
            .collect();
        let records: Vec<_> = set.records.iter().step_by(opts.stride.max(1)).collect();
        (tris, records)
    });
    let visitor = Alternate {
        prepared: &prepared,
        rounds: rounds.max(1),
        peer: peer.as_ref().map(|(t, r)| (t.as_slice(), r.as_slice())),
    };
    let (_, (ours_mrays, peer_mrays)) =
        build_and_visit(&tris, &mut arena, &scene.path, &config, visitor)?;
    Ok(RoundsRow {
        scene: scene.name.clone(),
        rays: set.kind,
        ray_count: prepared.rays.len(),
        ours_mrays,
        peer_mrays,
    })
}

/// The peer's input: triangles and the traced ray records.
type PeerInput<'a> = (&'a [[[f32; 3]; 3]], &'a [&'a crate::rayfile::RayRecord]);

/// Visits the built headline structure: the rounds themselves.
struct Alternate<'p> {
    prepared: &'p PreparedRays<f32>,
    rounds: usize,
    peer: Option<PeerInput<'p>>,
}

impl AccelVisitor<f32> for Alternate<'_> {
    type Output = (Vec<f64>, Vec<f64>);

    fn visit<A: Accel<f32>>(self, accel: &A) -> Self::Output {
        let n = self.prepared.rays.len();
        let trace_ours = || mrays(n, trace_closest(accel, self.prepared).1);
        let mut ours = Vec::with_capacity(self.rounds);
        let peer = self.peer.and_then(|(tris, records)| {
            super::peers::alternate_with_tinybvh(tris, records, self.rounds, &mut || {
                ours.push(trace_ours());
            })
        });
        match peer {
            Some(peer) => (ours, peer),
            // No peer in this build (or it refused the scene): ours alone.
            None => ((0..self.rounds).map(|_| trace_ours()).collect(), Vec::new()),
        }
    }
}
