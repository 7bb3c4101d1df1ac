//! Interleaved rounds: the headline contenders (the 4-wide and the 8-wide BVH collapsed from
//! the SAH BVH, `f32`, leaf order, the 8-wide by both of its walks) and the peers they are
//! compared with trace one ray set in alternation, round after round: ours per ray (each ray
//! constructed from its record in the timed loop), Embree HIGH and Embree HIGH in its robust
//! mode (`rtcIntersect1` on the raw records, flagged coherent on primary rays, with the
//! `embree` feature), ours on pre-built rays, tinybvh's BVH2 on pre-built rays (with the
//! `tinybvh` feature); then again. Each structure is built once; only tracing is timed. The
//! per-round ratios pair like with like: ours per ray ÷ Embree (both pay their ray setup),
//! ours pre-built ÷ tinybvh (neither does).
//!
//! Why: on a shared VM a slow spell (another tenant's memory traffic) can last seconds to
//! minutes, long enough to cover one contender's consecutive runs and not the other's. In
//! alternation both see every spell, so the per-round ratio compares like with like. Each
//! contender's fastest round is reported too: such noise only ever adds time, so the minimum
//! time is the estimate least disturbed by it (Chen and Revels 2016, "Robust benchmarking in
//! noisy environments").

use crate::error::Error;
use crate::ours::{count_work, mrays};
use crate::workload::{BenchScene, RayKind, RaySet};
use host::rayfile::{HitRecord, RayRecord};
use host::trace::{
    build_and_visit, median, prepare_rays, trace_closest, trace_closest_per_ray, AccelConfig,
    NodeArena, PreparedRays,
};
use raykernel::bvh::BuildOptions;
use raykernel::{Accel, AccelKind, AccelVisitor, Coherent, TraversalStats, Triangle};
use serde::Serialize;

/// The structures of the rounds, in this order: the wide BVHs from the SAH build.
pub const STRUCTURES: [AccelKind; 2] = [
    AccelKind::Bvh4(BuildOptions::DEFAULT),
    AccelKind::Bvh8(BuildOptions::DEFAULT),
];

/// Ours in the rounds, in this order: each of [`STRUCTURES`] by its name, then the 8-wide BVH
/// queried through [`Coherent`] (its walk for coherent rays), as the report names them.
pub const CONTENDERS: [&str; 3] = [STRUCTURES[0].name(), STRUCTURES[1].name(), "bvh8 coherent"];

/// One of ours in the rounds: Mrays/s in each round.
#[derive(Clone, Debug, Serialize)]
pub struct OursRounds {
    /// The contender's name (one of [`CONTENDERS`]).
    pub structure: &'static str,
    /// Each ray constructed in the loop (closest hit).
    pub per_ray_mrays: Vec<f64>,
    /// On pre-built rays.
    pub prebuilt_mrays: Vec<f64>,
}

/// One ray set's rounds: Mrays/s of each contender in each round, in round order (a
/// contender this build lacks has no figures).
#[derive(Clone, Debug, Serialize)]
pub struct RoundsRow {
    /// Scene.
    pub scene: String,
    /// Ray set.
    pub rays: RayKind,
    /// Rays traced per round.
    pub ray_count: usize,
    /// Ours, one entry per contender of [`CONTENDERS`].
    pub ours: Vec<OursRounds>,
    /// Embree 3 HIGH, `rtcIntersect1` on the raw records (flagged coherent on primary rays).
    pub embree_mrays: Vec<f64>,
    /// Embree 3 HIGH in its robust mode (`RTC_SCENE_FLAG_ROBUST`), traced as `embree_mrays`.
    pub embree_robust_mrays: Vec<f64>,
    /// tinybvh's BVH2 on pre-built rays.
    pub tinybvh_mrays: Vec<f64>,
    /// tinybvh's 8-wide CPU BVH, each build of it (none without the `tinybvh` feature).
    pub tinybvh8: Vec<PrebuiltPeer>,
}

/// A peer traced in the rounds on pre-built rays, with how often it agrees with ours.
#[derive(Clone, Debug, Serialize)]
pub struct PrebuiltPeer {
    /// The report's name.
    pub name: &'static str,
    /// Mrays/s in each round.
    pub mrays: Vec<f64>,
    /// Percentage of rays whose hit triangle (or miss) is the one ours reports.
    pub same_prim_pct: f64,
}

/// Median, fastest round, and per-round ratios of two series of figures.
#[derive(Clone, Debug, PartialEq)]
pub struct Pairing {
    /// Median of ours.
    pub ours_median: f64,
    /// Ours' fastest round.
    pub ours_best: f64,
    /// Median of the peer.
    pub peer_median: f64,
    /// The peer's fastest round.
    pub peer_best: f64,
    /// Ours ÷ peer within each round.
    pub ratios: Vec<f64>,
}

impl Pairing {
    /// `None` without the peer's figures.
    #[must_use]
    pub fn of(ours: &[f64], peer: &[f64]) -> Option<Self> {
        if peer.is_empty() {
            return None;
        }
        Some(Self {
            ours_median: median(ours),
            ours_best: best(ours),
            peer_median: median(peer),
            peer_best: best(peer),
            ratios: ours
                .iter()
                .zip(peer)
                .filter(|(_, &p)| p > 0.0)
                .map(|(o, p)| o / p)
                .collect(),
        })
    }

    /// Median per-round ratio.
    #[must_use]
    pub fn median_ratio(&self) -> f64 {
        median(&self.ratios)
    }

    /// Smallest and largest per-round ratio.
    #[must_use]
    pub fn ratio_range(&self) -> (f64, f64) {
        let lo = self.ratios.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = self.ratios.iter().copied().fold(0.0, f64::max);
        (lo, hi)
    }
}

impl RoundsRow {
    /// Ours fastest per ray (by median), the headline structure of this ray set.
    #[must_use]
    pub fn fastest(&self) -> Option<&OursRounds> {
        self.ours.iter().reduce(|a, b| {
            if median(&b.per_ray_mrays) > median(&a.per_ray_mrays) {
                b
            } else {
                a
            }
        })
    }

    /// `ours` per ray against Embree HIGH (`None` without Embree).
    #[must_use]
    pub fn vs_embree(&self, ours: &OursRounds) -> Option<Pairing> {
        Pairing::of(&ours.per_ray_mrays, &self.embree_mrays)
    }

    /// `ours` per ray against Embree HIGH in its robust mode (`None` without Embree).
    #[must_use]
    pub fn vs_embree_robust(&self, ours: &OursRounds) -> Option<Pairing> {
        Pairing::of(&ours.per_ray_mrays, &self.embree_robust_mrays)
    }

    /// `ours` pre-built against tinybvh (`None` without tinybvh).
    #[must_use]
    pub fn vs_tinybvh(&self, ours: &OursRounds) -> Option<Pairing> {
        Pairing::of(&ours.prebuilt_mrays, &self.tinybvh_mrays)
    }

    /// `ours` against `peer`, both on pre-built rays.
    #[must_use]
    pub fn vs_prebuilt_peer(&self, ours: &OursRounds, peer: &PrebuiltPeer) -> Option<Pairing> {
        Pairing::of(&ours.prebuilt_mrays, &peer.mrays)
    }

    /// `peer` (pre-built) against Embree HIGH per ray (`None` without Embree): how near the
    /// issue's reference for a wide SIMD BVH comes to Embree.
    #[must_use]
    pub fn vs_embree_of(&self, peer: &PrebuiltPeer) -> Option<Pairing> {
        Pairing::of(&peer.mrays, &self.embree_mrays)
    }
}

/// The largest figure (0 for none).
fn best(xs: &[f64]) -> f64 {
    xs.iter().copied().fold(0.0, f64::max)
}

/// A structure of [`STRUCTURES`] as built for the rounds: primitives in leaf order.
fn config(accel: AccelKind) -> AccelConfig {
    AccelConfig {
        accel,
        leaf_order: accel.permutes_into_leaf_order(),
    }
}

/// Runs `rounds` rounds on one ray set, with the peers this build has when `with_peers`.
///
/// # Errors
/// A build the kernel refuses.
pub fn run(
    scene: &BenchScene,
    set: &RaySet,
    rounds: usize,
    with_peers: bool,
) -> Result<RoundsRow, Error> {
    let tris = scene.mesh.kernel_triangles::<f32>(&scene.path)?;
    let prepared = prepare_rays::<f32>(&set.records);
    let [first, second] = STRUCTURES.map(config);
    let mut arena = NodeArena::<f32>::for_accel(first.accel, &tris);
    let mut second_arena = NodeArena::<f32>::for_accel(second.accel, &tris);
    let rounds_of = Alternate {
        scene,
        set,
        prepared: &prepared,
        rounds: rounds.max(1),
        with_peers,
    };
    let builds_second = BuildSecond {
        tris: &tris,
        arena: &mut second_arena,
        scene,
        config: second,
        rounds_of,
    };
    let (_, figures) = build_and_visit(&tris, &mut arena, &scene.path, &first, builds_second)?;
    let figures = figures?;
    let ours = CONTENDERS
        .iter()
        .zip(figures.per_ray)
        .zip(figures.prebuilt)
        .map(|((&structure, per_ray_mrays), prebuilt_mrays)| OursRounds {
            structure,
            per_ray_mrays,
            prebuilt_mrays,
        })
        .collect();
    Ok(RoundsRow {
        scene: scene.name.clone(),
        rays: set.kind,
        ray_count: prepared.rays.len(),
        ours,
        embree_mrays: figures.embree,
        embree_robust_mrays: figures.embree_robust,
        tinybvh_mrays: figures.tinybvh,
        tinybvh8: figures.tinybvh8,
    })
}

/// Visits the first built structure: builds the second and visits both ([`Both`]).
struct BuildSecond<'p, 'a> {
    tris: &'p [Triangle<f32>],
    arena: &'a mut NodeArena<f32>,
    scene: &'p BenchScene,
    config: AccelConfig,
    rounds_of: Alternate<'p>,
}

impl AccelVisitor<f32> for BuildSecond<'_, '_> {
    type Output = Result<Figures, Error>;

    fn visit<A: Accel<f32>>(self, first: &A) -> Self::Output {
        let both = Both {
            first,
            rounds_of: self.rounds_of,
        };
        build_and_visit(self.tris, self.arena, &self.scene.path, &self.config, both)
            .map(|(_, figures)| figures)
            .map_err(Error::from)
    }
}

/// Visits the second built structure, with the first at hand: the rounds themselves.
struct Both<'p, 'f, A> {
    first: &'f A,
    rounds_of: Alternate<'p>,
}

impl<A: Accel<f32>> AccelVisitor<f32> for Both<'_, '_, A> {
    type Output = Figures;

    fn visit<B: Accel<f32>>(self, second: &B) -> Figures {
        self.rounds_of.run(self.first, second)
    }
}

/// The rounds over the two built structures.
struct Alternate<'p> {
    scene: &'p BenchScene,
    set: &'p RaySet,
    prepared: &'p PreparedRays<f32>,
    rounds: usize,
    with_peers: bool,
}

/// Each contender's figures, round by round; ours per contender of [`CONTENDERS`].
#[derive(Default)]
struct Figures {
    per_ray: [Vec<f64>; 3],
    prebuilt: [Vec<f64>; 3],
    embree: Vec<f64>,
    embree_robust: Vec<f64>,
    tinybvh: Vec<f64>,
    tinybvh8: Vec<PrebuiltPeer>,
}

impl Alternate<'_> {
    fn run<A: Accel<f32>, B: Accel<f32>>(self, first: &A, second: &B) -> Figures {
        let n = self.prepared.rays.len();
        let mut figures = Figures::default();
        let inputs = EmbreeInputs::new(self.scene, self.set.kind, self.with_peers);
        let embree = inputs.build(false);
        let embree_robust = inputs.build(true);
        let flat = if embree.is_some() {
            EmbreeInputs::flatten(&self.set.records)
        } else {
            Vec::new()
        };
        let coherent = Coherent(second);
        // The triangles as tinybvh's peers take them (none without peers).
        let tris: Vec<[[f32; 3]; 3]> = if self.with_peers {
            (0..self.scene.mesh.triangle_count())
                .map(|i| self.scene.mesh.triangle_f32(i))
                .collect()
        } else {
            Vec::new()
        };
        let mut tinybvh8 = TinyBvh8Peers::new(self.with_peers, &tris, &self.set.records, || {
            trace_closest_per_ray(second, &self.set.records).0
        });
        let mut round = |figures: &mut Figures| {
            let [per_ray_a, per_ray_b, per_ray_c] = &mut figures.per_ray;
            per_ray_a.push(mrays(n, trace_closest_per_ray(first, &self.set.records).1));
            per_ray_b.push(mrays(n, trace_closest_per_ray(second, &self.set.records).1));
            per_ray_c.push(mrays(
                n,
                trace_closest_per_ray(&coherent, &self.set.records).1,
            ));
            if let Some(e) = &embree {
                figures.embree.push(e.trace(&flat));
            }
            if let Some(e) = &embree_robust {
                figures.embree_robust.push(e.trace(&flat));
            }
            let [prebuilt_a, prebuilt_b, prebuilt_c] = &mut figures.prebuilt;
            prebuilt_a.push(mrays(n, trace_closest(first, self.prepared).1));
            prebuilt_b.push(mrays(n, trace_closest(second, self.prepared).1));
            prebuilt_c.push(mrays(n, trace_closest(&coherent, self.prepared).1));
            tinybvh8.round();
        };
        let tinybvh = self.with_peers.then(|| {
            let records: Vec<&RayRecord> = self.set.records.iter().collect();
            crate::peers::alternate_with_tinybvh(&tris, &records, self.rounds, &mut || {
                round(&mut figures);
            })
        });
        match tinybvh.flatten() {
            Some(t) => figures.tinybvh = t,
            // No tinybvh in this build (or it refused the scene): the rounds without it.
            None => {
                for _ in 0..self.rounds {
                    round(&mut figures);
                }
            }
        }
        figures.tinybvh8 = tinybvh8.into_rows();
        figures
    }
}

/// tinybvh's 8-wide BVH for the rounds, each build of it, with the `tinybvh` feature; without
/// it, none.
struct TinyBvh8Peers {
    #[cfg(feature = "tinybvh")]
    built: Vec<(crate::tinybvh8::TinyBvh8, PrebuiltPeer)>,
}

impl TinyBvh8Peers {
    /// Every build over `tris` (none without peers), its rays set from `records`, each traced
    /// once untimed against the hits `ours` gives (asked for only if something was built).
    fn new(
        with_peers: bool,
        tris: &[[[f32; 3]; 3]],
        records: &[RayRecord],
        ours: impl FnOnce() -> Vec<HitRecord>,
    ) -> Self {
        #[cfg(feature = "tinybvh")]
        {
            use crate::tinybvh8::{Build, TinyBvh8};
            let peers: Vec<TinyBvh8> = if with_peers {
                Build::ALL
                    .iter()
                    .filter_map(|&b| TinyBvh8::new(tris, records, b))
                    .collect()
            } else {
                Vec::new()
            };
            let ours = if peers.is_empty() { Vec::new() } else { ours() };
            let built = peers
                .into_iter()
                .map(|mut peer| {
                    peer.trace();
                    let hits = peer.hits();
                    let same = hits.iter().zip(&ours).filter(|(a, b)| a.prim == b.prim);
                    let row = PrebuiltPeer {
                        name: peer.build().name(),
                        mrays: Vec::new(),
                        same_prim_pct: 100.0 * same.count() as f64 / ours.len().max(1) as f64,
                    };
                    (peer, row)
                })
                .collect();
            Self { built }
        }
        #[cfg(not(feature = "tinybvh"))]
        {
            let _ = (with_peers, tris, records, ours);
            Self {}
        }
    }

    /// One timed pass of each: Mrays/s appended to its series.
    fn round(&mut self) {
        #[cfg(feature = "tinybvh")]
        for (peer, row) in &mut self.built {
            row.mrays.push(mrays(peer.rays(), peer.trace()));
        }
    }

    /// The series and agreement of each.
    fn into_rows(self) -> Vec<PrebuiltPeer> {
        #[cfg(feature = "tinybvh")]
        return self.built.into_iter().map(|(_, row)| row).collect();
        #[cfg(not(feature = "tinybvh"))]
        Vec::new()
    }
}

/// Embree HIGH for the rounds, with the `embree` feature: a device and the scene's geometry
/// ([`EmbreeInputs::new`]), and a scene built over them in Embree's default mode or its robust
/// mode ([`EmbreeInputs::build`]), which traces records flattened by
/// [`EmbreeInputs::flatten`]. Without the feature, nothing.
#[cfg(feature = "embree")]
struct EmbreeInputs {
    device: Option<crate::embree::Device>,
    geometry: crate::embree::Geometry,
    kind: RayKind,
}

#[cfg(feature = "embree")]
impl EmbreeInputs {
    fn new(scene: &BenchScene, kind: RayKind, wanted: bool) -> Self {
        use crate::embree::{Device, Geometry};
        Self {
            device: if wanted { Device::new() } else { None },
            geometry: Geometry::of(&scene.mesh),
            kind,
        }
    }

    /// The scene at HIGH quality, in the robust mode if `robust`.
    fn build(&self, robust: bool) -> Option<EmbreeTracer<'_>> {
        use crate::embree::{Scene, Settings};
        let device = self.device.as_ref()?;
        let settings = if robust {
            Settings::HIGH_ROBUST
        } else {
            Settings::HIGH
        };
        let (scene, _) = Scene::build(device, &self.geometry, settings)?;
        Some(EmbreeTracer {
            scene,
            kind: self.kind,
        })
    }

    /// `records` as [`EmbreeTracer::trace`] takes them.
    fn flatten(records: &[RayRecord]) -> Vec<f32> {
        crate::embree::flat_records(records)
    }
}

#[cfg(feature = "embree")]
struct EmbreeTracer<'a> {
    scene: crate::embree::Scene<'a>,
    kind: RayKind,
}

#[cfg(feature = "embree")]
impl EmbreeTracer<'_> {
    /// Mrays/s of one pass over `flat` ([`EmbreeInputs::flatten`]).
    fn trace(&self, flat: &[f32]) -> f64 {
        let (hits, ms) = self.scene.closest(flat, self.kind);
        mrays(hits.len(), ms)
    }
}

#[cfg(not(feature = "embree"))]
struct EmbreeInputs;

#[cfg(not(feature = "embree"))]
impl EmbreeInputs {
    fn new(_: &BenchScene, _: RayKind, _: bool) -> Self {
        Self
    }

    fn build(&self, _robust: bool) -> Option<EmbreeTracer> {
        None
    }

    fn flatten(_: &[RayRecord]) -> Vec<f32> {
        Vec::new()
    }
}

#[cfg(not(feature = "embree"))]
struct EmbreeTracer;

#[cfg(not(feature = "embree"))]
impl EmbreeTracer {
    fn trace(&self, _: &[f32]) -> f64 {
        0.0
    }
}

/// One part of a ray set in [`split`]: its rays, and ours per ray against Embree HIGH.
#[derive(Clone, Debug)]
pub struct SplitPart {
    /// `misses` or `hits` (of ours).
    pub name: &'static str,
    /// Rays in the part.
    pub rays: usize,
    /// Mrays/s of the 8-wide BVH per ray and of Embree HIGH, round by round.
    pub vs_embree: Pairing,
    /// The 8-wide BVH's work over the part's rays (boxes and primitives tested), counted in a
    /// pass of its own, untimed.
    pub counted: TraversalStats,
}

/// The ray set split into the rays the 8-wide BVH of [`STRUCTURES`] misses and those it hits,
/// each part traced `rounds` times in alternation by that BVH (per ray, its default walk) and
/// by Embree HIGH: whether a gap lies in what every ray pays (setup, the top nodes) or in the
/// descent to a hit and the triangle tests. `None` without Embree in this build.
///
/// # Errors
/// A build the kernel refuses.
pub fn split(
    scene: &BenchScene,
    set: &RaySet,
    rounds: usize,
) -> Result<Option<Vec<SplitPart>>, Error> {
    let tris = scene.mesh.kernel_triangles::<f32>(&scene.path)?;
    let [_, accel] = STRUCTURES;
    let mut arena = NodeArena::<f32>::for_accel(accel, &tris);
    let parts = Split {
        scene,
        set,
        rounds: rounds.max(1),
    };
    let (_, parts) = build_and_visit(&tris, &mut arena, &scene.path, &config(accel), parts)?;
    Ok(parts)
}

/// Visits the built 8-wide BVH: the rounds of [`split`].
struct Split<'p> {
    scene: &'p BenchScene,
    set: &'p RaySet,
    rounds: usize,
}

impl AccelVisitor<f32> for Split<'_> {
    type Output = Option<Vec<SplitPart>>;

    fn visit<A: Accel<f32>>(self, accel: &A) -> Self::Output {
        let inputs = EmbreeInputs::new(self.scene, self.set.kind, true);
        let embree = inputs.build(false)?;
        let (hits, _) = trace_closest_per_ray(accel, &self.set.records);
        let (missed, hit): (Vec<_>, Vec<_>) = self
            .set
            .records
            .iter()
            .zip(&hits)
            .partition(|(_, found)| found.prim == HitRecord::MISS.prim);
        let part = |name, pairs: Vec<(&RayRecord, &HitRecord)>| {
            let records: Vec<RayRecord> = pairs.into_iter().map(|(r, _)| *r).collect();
            let flat = EmbreeInputs::flatten(&records);
            let (mut ours, mut peer) = (Vec::new(), Vec::new());
            for _ in 0..self.rounds {
                ours.push(mrays(
                    records.len(),
                    trace_closest_per_ray(accel, &records).1,
                ));
                peer.push(embree.trace(&flat));
            }
            let counted = count_work(accel, &prepare_rays::<f32>(&records).rays);
            Pairing::of(&ours, &peer).map(|vs_embree| SplitPart {
                name,
                rays: records.len(),
                vs_embree,
                counted,
            })
        };
        [part("misses", missed), part("hits", hit)]
            .into_iter()
            .collect()
    }
}
