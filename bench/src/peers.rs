//! Peers measured in the same run, on the same triangles and rays: with the `embree` feature,
//! Embree 3 at HIGH and MEDIUM build quality, and at HIGH in its robust mode
//! ([`crate::embree`]); `obvhs` 0.4 (BVH2 and CWBVH, its own two-sided Möller–Trumbore test),
//! `bvh` 0.13 (svenstaro; its triangle test culls back faces, so it traces with this
//! benchmark's two-sided Möller–Trumbore from [`crate::mt`], as the workload's triangles are
//! two-sided) and, with the `tinybvh` feature, tinybvh 1.6.8's scalar BVH2 (C++, through
//! `tinybvh-rs`).
//!
//! Each peer is used as its documentation shows, single-threaded (no rayon features; Embree's
//! device on one thread): build from the triangle list, then one query per ray. Times and
//! figures follow our rows: build wall time of the library call, medians over the runs.
//! Embree's call takes the raw ray record; the other peers' rays are converted to their ray
//! type before timing, and that conversion (`setup_ms`) is added to their per-ray figure.

#[cfg(feature = "embree")]
use crate::embree::Settings;
use crate::mt::moller_trumbore;
use crate::ours::{mrays, RunOptions};
use crate::results::TraceRow;
use crate::workload::{BenchScene, RaySet};
use glam_peer::Vec3A;
use host::rayfile::{HitRecord, RayRecord};
use host::trace::{median, millis};
use std::cell::Cell;
use std::hint::black_box;
use std::time::{Duration, Instant};

/// The peers, in report order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Peer {
    /// `obvhs` BVH2: PLOC build (`medium_build` preset) with reinsertion and leaf collapse.
    ObvhsBvh2,
    /// `obvhs` CWBVH: the same PLOC BVH2 compressed to 8-wide nodes (Ylitie et al. 2017).
    ObvhsCwbvh,
    /// `bvh` (svenstaro): binned SAH BVH2.
    SvenstaroBvh,
    /// tinybvh's BVH2 (`BVH::Build`, binned SAH) and its scalar `BVH::Intersect`.
    TinybvhBvh2,
    /// Embree 3, `RTC_BUILD_QUALITY_HIGH` (SAH with spatial splits), `rtcIntersect1`.
    EmbreeHigh,
    /// Embree 3, `RTC_BUILD_QUALITY_MEDIUM` (SAH), `rtcIntersect1`.
    EmbreeMedium,
    /// Embree 3, `RTC_BUILD_QUALITY_HIGH` with `RTC_SCENE_FLAG_ROBUST` (which builds without
    /// spatial splits), `rtcIntersect1`.
    EmbreeHighRobust,
}

impl Peer {
    /// Every peer this build can run (Embree with the `embree` feature only, tinybvh with the
    /// `tinybvh` feature only).
    pub const ALL: &'static [Peer] = &[
        #[cfg(feature = "embree")]
        Self::EmbreeHigh,
        #[cfg(feature = "embree")]
        Self::EmbreeMedium,
        #[cfg(feature = "embree")]
        Self::EmbreeHighRobust,
        #[cfg(feature = "tinybvh")]
        Self::TinybvhBvh2,
        Self::ObvhsBvh2,
        Self::ObvhsCwbvh,
        Self::SvenstaroBvh,
    ];

    /// Name in the report.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::ObvhsBvh2 => "obvhs 0.4 BVH2",
            Self::ObvhsCwbvh => "obvhs 0.4 CWBVH",
            Self::SvenstaroBvh => "bvh 0.13",
            Self::TinybvhBvh2 => "tinybvh 1.6 BVH2",
            Self::EmbreeHigh => "Embree 3 HIGH",
            Self::EmbreeMedium => "Embree 3 MEDIUM",
            Self::EmbreeHighRobust => "Embree 3 HIGH robust",
        }
    }

    /// True for Embree (any of its settings).
    #[must_use]
    pub fn is_embree(self) -> bool {
        matches!(
            self,
            Self::EmbreeHigh | Self::EmbreeMedium | Self::EmbreeHighRobust
        )
    }

    fn builder(self) -> &'static str {
        match self {
            Self::ObvhsBvh2 | Self::ObvhsCwbvh => "PLOC medium",
            Self::SvenstaroBvh | Self::TinybvhBvh2 => "binned SAH",
            Self::EmbreeHigh => "SAH + spatial splits",
            Self::EmbreeMedium => "SAH",
            Self::EmbreeHighRobust => "SAH (robust mode)",
        }
    }

    fn test(self) -> &'static str {
        match self {
            Self::ObvhsBvh2 | Self::ObvhsCwbvh => "Möller–Trumbore (obvhs)",
            Self::SvenstaroBvh => "Möller–Trumbore (bench)",
            Self::TinybvhBvh2 => "Möller–Trumbore (tinybvh)",
            Self::EmbreeHigh | Self::EmbreeMedium => "Embree's",
            Self::EmbreeHighRobust => "Embree's robust",
        }
    }
}

/// Figures of one peer run (medians over the runs).
struct PeerMeasured {
    build_ms: f64,
    setup_ms: f64,
    closest_ms: f64,
    any_ms: f64,
    hits: Vec<HitRecord>,
    any_hits: usize,
    /// Primitive tests over all rays, where the peer lets us count them.
    prims_tested: Option<u64>,
    bytes: usize,
    /// The query takes raw records (Embree): its times include ray setup, and there is no
    /// pre-built figure.
    raw_records: bool,
}

/// Runs one peer on one ray set (`None`: a peer this build cannot run).
#[must_use]
pub fn run(peer: Peer, scene: &BenchScene, set: &RaySet, opts: RunOptions) -> Option<TraceRow> {
    let tris: Vec<[[f32; 3]; 3]> = (0..scene.mesh.triangle_count())
        .map(|i| scene.mesh.triangle_f32(i))
        .collect();
    let records: Vec<&RayRecord> = set.records.iter().collect();
    let runs = opts.runs.max(1);
    let m = match peer {
        Peer::ObvhsBvh2 | Peer::ObvhsCwbvh => obvhs_run(peer, &tris, &records, runs),
        Peer::SvenstaroBvh => svenstaro_run(&tris, &records, runs),
        #[cfg(feature = "tinybvh")]
        Peer::TinybvhBvh2 => tinybvh::run(&tris, &records, runs)?,
        #[cfg(not(feature = "tinybvh"))]
        Peer::TinybvhBvh2 => return None,
        #[cfg(feature = "embree")]
        Peer::EmbreeHigh => embree_peer::run(Settings::HIGH, &scene.mesh, set, opts)?,
        #[cfg(feature = "embree")]
        Peer::EmbreeMedium => embree_peer::run(Settings::MEDIUM, &scene.mesh, set, opts)?,
        #[cfg(feature = "embree")]
        Peer::EmbreeHighRobust => embree_peer::run(Settings::HIGH_ROBUST, &scene.mesh, set, opts)?,
        #[cfg(not(feature = "embree"))]
        Peer::EmbreeHigh | Peer::EmbreeMedium | Peer::EmbreeHighRobust => return None,
    };
    let n = m.hits.len();
    Some(TraceRow {
        scene: scene.name.clone(),
        rays: set.kind,
        ray_count: n,
        triangles: tris.len(),
        ours: false,
        contender: peer.name().into(),
        builder: peer.builder().into(),
        test: peer.test().into(),
        mode: "f32".into(),
        build_ms: m.build_ms,
        setup_ms: m.setup_ms,
        setup_ns_per_ray: if n > 0 {
            m.setup_ms * 1e6 / n as f64
        } else {
            0.0
        },
        // What a caller pays per ray: the conversion to the peer's ray type, then the query.
        closest_mrays: mrays(n, m.setup_ms + m.closest_ms),
        closest_mrays_prebuilt: (!m.raw_records).then(|| mrays(n, m.closest_ms)),
        any_mrays: if m.any_ms > 0.0 {
            mrays(n, m.setup_ms + m.any_ms)
        } else {
            0.0
        },
        any_mrays_prebuilt: (!m.raw_records).then(|| mrays(n, m.any_ms)),
        nodes_per_ray: None,
        prims_per_ray: m
            .prims_tested
            .map(|k| if n > 0 { k as f64 / n as f64 } else { 0.0 }),
        bytes_per_tri: if tris.is_empty() {
            0.0
        } else {
            m.bytes as f64 / tris.len() as f64
        },
        depth: None,
        hits: m.hits.iter().filter(|h| h.is_hit()).count(),
        any_hits: m.any_hits,
        vs_ours: None,
        hitmiss_split: None,
        accuracy: None,
        hit_records: m.hits,
    })
}

/// Embree through [`crate::embree`], with the `embree` feature.
#[cfg(feature = "embree")]
mod embree_peer {
    use super::{empty_measured, PeerMeasured};
    use crate::embree::{flat_records, Device, Geometry, Scene, Settings};
    use crate::ours::RunOptions;
    use crate::workload::RaySet;
    use host::obj::Mesh;
    use host::trace::median;

    /// `runs` builds with `settings`, each followed by a closest-hit pass over the set's records
    /// (flagged coherent for primary rays, see [`Scene::closest`]); any hit once after the
    /// last. `None` if Embree cannot make a device or refuses the scene.
    pub(super) fn run(
        settings: Settings,
        mesh: &Mesh,
        set: &RaySet,
        opts: RunOptions,
    ) -> Option<PeerMeasured> {
        let device = Device::new()?;
        let geometry = Geometry::of(mesh);
        let flat = flat_records(&set.records);
        let (mut builds, mut closest) = (Vec::new(), Vec::new());
        let mut m = empty_measured();
        for run in 0..opts.runs.max(1) {
            let (scene, built) = Scene::build(&device, &geometry, settings)?;
            builds.push(built.build_ms);
            let (hits, ms) = scene.closest(&flat, set.kind);
            closest.push(ms);
            m.hits = hits;
            m.bytes = built.bytes;
            if run + 1 == opts.runs.max(1) {
                let (occluded, ms) = scene.occluded(&flat, set.kind);
                m.any_hits = occluded;
                m.any_ms = ms;
            }
        }
        m.build_ms = median(&builds);
        m.closest_ms = median(&closest);
        m.raw_records = true;
        Some(m)
    }
}

/// Builds tinybvh's BVH2 once, then runs `rounds` rounds of `ours()` followed by one timed
/// closest-hit pass of tinybvh over `records`; returns tinybvh's Mrays/s per round. `None`
/// without the `tinybvh` feature, or if tinybvh refuses the scene (then `ours` never ran).
#[must_use]
pub fn alternate_with_tinybvh(
    tris: &[[[f32; 3]; 3]],
    records: &[&host::rayfile::RayRecord],
    rounds: usize,
    ours: &mut dyn FnMut(),
) -> Option<Vec<f64>> {
    #[cfg(feature = "tinybvh")]
    return tinybvh::alternate(tris, records, rounds, ours);
    #[cfg(not(feature = "tinybvh"))]
    {
        let _ = (tris, records, rounds, ours);
        None
    }
}

/// The two obvhs structures share this query surface.
trait ObvhsQueries {
    fn closest<F: FnMut(&obvhs::ray::Ray, usize) -> f32>(
        &self,
        ray: obvhs::ray::Ray,
        hit: &mut obvhs::ray::RayHit,
        f: F,
    ) -> bool;
    fn miss<F: FnMut(&obvhs::ray::Ray, usize) -> f32>(&self, ray: obvhs::ray::Ray, f: F) -> bool;
    fn ids(&self) -> &[u32];
    fn bytes(&self) -> usize;
}

/// Both obvhs layouts answer the same calls under the same names.
macro_rules! obvhs_queries {
    ($($layout:ty),*) => {$(
        impl ObvhsQueries for $layout {
            fn closest<F: FnMut(&obvhs::ray::Ray, usize) -> f32>(
                &self,
                ray: obvhs::ray::Ray,
                hit: &mut obvhs::ray::RayHit,
                f: F,
            ) -> bool {
                self.ray_traverse(ray, hit, f)
            }
            fn miss<F: FnMut(&obvhs::ray::Ray, usize) -> f32>(
                &self,
                ray: obvhs::ray::Ray,
                f: F,
            ) -> bool {
                self.ray_traverse_miss(ray, f)
            }
            fn ids(&self) -> &[u32] {
                &self.primitive_indices
            }
            fn bytes(&self) -> usize {
                std::mem::size_of_val(&self.nodes[..])
                    + std::mem::size_of_val(&self.primitive_indices[..])
            }
        }
    )*};
}

obvhs_queries!(obvhs::bvh2::Bvh2, obvhs::cwbvh::CwBvh);

fn obvhs_run(
    peer: Peer,
    tris: &[[[f32; 3]; 3]],
    records: &[&host::rayfile::RayRecord],
    runs: usize,
) -> PeerMeasured {
    let v = |p: [f32; 3]| Vec3A::new(p[0], p[1], p[2]);
    let otris: Vec<obvhs::triangle::Triangle> = tris
        .iter()
        .map(|t| obvhs::triangle::Triangle {
            v0: v(t[0]),
            v1: v(t[1]),
            v2: v(t[2]),
        })
        .collect();
    let start = Instant::now();
    let rays: Vec<obvhs::ray::Ray> = records
        .iter()
        .map(|r| obvhs::ray::Ray::new(v(r.origin), v(r.dir), r.t_min, r.t_max))
        .collect();
    let setup_ms = millis(start);
    let params = obvhs::BvhBuildParams::medium_build();
    let mut builds = Vec::new();
    let mut out = None;
    for _ in 0..runs {
        let mut core = Duration::default();
        let start = Instant::now();
        match peer {
            Peer::ObvhsCwbvh => {
                let bvh = obvhs::cwbvh::builder::build_cwbvh_from_tris(&otris, params, &mut core);
                builds.push(millis(start));
                out = Some(obvhs_queries(&bvh, &otris, &rays, runs));
            }
            _ => {
                let bvh = obvhs::bvh2::builder::build_bvh2_from_tris(&otris, params, &mut core);
                builds.push(millis(start));
                out = Some(obvhs_queries(&bvh, &otris, &rays, runs));
            }
        }
    }
    let (mut m, closest) = out.unwrap_or_else(|| (empty_measured(), Vec::new()));
    m.build_ms = median(&builds);
    m.setup_ms = setup_ms;
    m.closest_ms = median(&closest);
    m
}

fn empty_measured() -> PeerMeasured {
    PeerMeasured {
        build_ms: 0.0,
        setup_ms: 0.0,
        closest_ms: 0.0,
        any_ms: 0.0,
        hits: Vec::new(),
        any_hits: 0,
        prims_tested: None,
        bytes: 0,
        raw_records: false,
    }
}

/// Closest hit `runs` times, any hit once, one counted closest pass.
fn obvhs_queries<B: ObvhsQueries>(
    bvh: &B,
    tris: &[obvhs::triangle::Triangle],
    rays: &[obvhs::ray::Ray],
    runs: usize,
) -> (PeerMeasured, Vec<f64>) {
    let ids = bvh.ids();
    let tri = |id: usize| ids.get(id).and_then(|&p| tris.get(p as usize));
    let test = |r: &obvhs::ray::Ray, id: usize| tri(id).map_or(f32::INFINITY, |t| t.intersect(r));
    let mut closest = Vec::new();
    let mut hits = vec![HitRecord::MISS; rays.len()];
    for _ in 0..runs {
        let start = Instant::now();
        for (slot, ray) in hits.iter_mut().zip(rays) {
            let mut hit = obvhs::ray::RayHit::none();
            if bvh.closest(*ray, &mut hit, test) {
                *slot = HitRecord {
                    t: hit.t,
                    prim: ids
                        .get(hit.primitive_id as usize)
                        .copied()
                        .unwrap_or(u32::MAX),
                };
            }
        }
        closest.push(millis(start));
    }
    // Any hit timed once, as for ours.
    let mut any = Vec::new();
    let any_hits;
    {
        let start = Instant::now();
        let mut n = 0usize;
        for ray in rays {
            n += usize::from(!bvh.miss(*ray, test));
        }
        any.push(millis(start));
        any_hits = black_box(n);
    }
    let tested = Cell::new(0u64);
    for ray in rays {
        let mut hit = obvhs::ray::RayHit::none();
        black_box(bvh.closest(*ray, &mut hit, |r, id| {
            tested.set(tested.get() + 1);
            test(r, id)
        }));
    }
    let m = PeerMeasured {
        any_ms: median(&any),
        hits,
        any_hits,
        prims_tested: Some(tested.get()),
        bytes: bvh.bytes(),
        ..empty_measured()
    };
    (m, closest)
}

/// A triangle as the `bvh` crate wants it: bounds, and the node index it writes back.
struct SvenTri {
    v: [[f32; 3]; 3],
    id: u32,
    node: usize,
}

impl bvh::aabb::Bounded<f32, 3> for SvenTri {
    fn aabb(&self) -> bvh::aabb::Aabb<f32, 3> {
        let [a, b, c] = self.v;
        let lo = nalgebra::Point3::new(
            a[0].min(b[0]).min(c[0]),
            a[1].min(b[1]).min(c[1]),
            a[2].min(b[2]).min(c[2]),
        );
        let hi = nalgebra::Point3::new(
            a[0].max(b[0]).max(c[0]),
            a[1].max(b[1]).max(c[1]),
            a[2].max(b[2]).max(c[2]),
        );
        bvh::aabb::Aabb::with_bounds(lo, hi)
    }
}

impl bvh::bounding_hierarchy::BHShape<f32, 3> for SvenTri {
    fn set_bh_node_index(&mut self, index: usize) {
        self.node = index;
    }
    fn bh_node_index(&self) -> usize {
        self.node
    }
}

/// One ray for the `bvh` crate, with the record's fields for the triangle test.
struct SvenRay {
    ray: bvh::ray::Ray<f32, 3>,
    o: [f32; 3],
    d: [f32; 3],
    t_min: f32,
    t_max: f32,
}

/// Closest hit through `nearest_traverse_iterator` (shapes in order of box entry), stopping
/// at the first box entered beyond the best hit; ties to the lower id, as ours.
fn sven_closest(
    bvh: &bvh::bvh::Bvh<f32, 3>,
    shapes: &[SvenTri],
    r: &SvenRay,
    count: &mut u64,
) -> HitRecord {
    use bvh::aabb::Bounded;
    let mut best = HitRecord::MISS;
    for s in bvh.nearest_traverse_iterator(&r.ray, shapes) {
        if best.is_hit() {
            match r.ray.intersection_slice_for_aabb(&s.aabb()) {
                Some((entry, _)) if entry > best.t => break,
                _ => {}
            }
        }
        *count += 1;
        let t_max = if best.is_hit() { best.t } else { r.t_max };
        if let Some((t, _, _)) = moller_trumbore(&s.v, r.o, r.d, r.t_min, t_max) {
            if !best.is_hit() || t < best.t || (t == best.t && s.id < best.prim) {
                best = HitRecord { t, prim: s.id };
            }
        }
    }
    best
}

fn svenstaro_run(
    tris: &[[[f32; 3]; 3]],
    records: &[&host::rayfile::RayRecord],
    runs: usize,
) -> PeerMeasured {
    let start = Instant::now();
    let rays: Vec<SvenRay> = records
        .iter()
        .map(|r| SvenRay {
            ray: bvh::ray::Ray::new(
                nalgebra::Point3::from(r.origin),
                nalgebra::Vector3::from(r.dir),
            ),
            o: r.origin,
            d: r.dir,
            t_min: r.t_min,
            t_max: r.t_max,
        })
        .collect();
    let setup_ms = millis(start);
    let mut builds = Vec::new();
    let mut closest = Vec::new();
    let mut hits = vec![HitRecord::MISS; rays.len()];
    let mut shapes = Vec::new();
    let mut tree = None;
    let mut tested = 0u64;
    for _ in 0..runs {
        shapes = tris
            .iter()
            .enumerate()
            .map(|(i, t)| SvenTri {
                v: *t,
                id: i as u32,
                node: 0,
            })
            .collect();
        let start = Instant::now();
        let bvh = bvh::bvh::Bvh::build(&mut shapes);
        builds.push(millis(start));
        let start = Instant::now();
        // Counting the tests is one increment per test, negligible beside the test itself.
        let mut count = 0u64;
        for (slot, r) in hits.iter_mut().zip(&rays) {
            *slot = sven_closest(&bvh, &shapes, r, &mut count);
        }
        closest.push(millis(start));
        tested = count;
        tree = Some(bvh);
    }
    let Some(bvh) = tree else {
        return empty_measured();
    };
    let mut any = Vec::new();
    let any_hits;
    {
        let start = Instant::now();
        let mut n = 0usize;
        for r in &rays {
            let hit = bvh
                .nearest_traverse_iterator(&r.ray, &shapes)
                .any(|s| moller_trumbore(&s.v, r.o, r.d, r.t_min, r.t_max).is_some());
            n += usize::from(hit);
        }
        any.push(millis(start));
        any_hits = black_box(n);
    }
    PeerMeasured {
        build_ms: median(&builds),
        setup_ms,
        closest_ms: median(&closest),
        any_ms: median(&any),
        hits,
        any_hits,
        prims_tested: Some(tested),
        bytes: std::mem::size_of_val(&bvh.nodes[..]),
        raw_records: false,
    }
}

/// tinybvh through `tinybvh-rs`, with the `tinybvh` feature.
#[cfg(feature = "tinybvh")]
mod tinybvh {
    use super::{empty_measured, PeerMeasured};
    use host::rayfile::{HitRecord, RayRecord};
    use host::trace::{median, millis};
    use std::time::Instant;
    use tinybvh_rs::{bvh::BVH, Intersection, Intersector, Ray, INFINITE};

    /// Builds `runs` times (`BVH::new`: tinybvh's default binned SAH build) and traces every
    /// ray after each build with `BVH::Intersect`, its scalar BVH2 traversal. The workload's
    /// rays start at `t_min = 0`, where tinybvh starts too; `t_max` is the ray's hit distance
    /// on entry (tinybvh's "no hit" is 1e30). `tinybvh-rs` has no occlusion query: any hit is
    /// not measured (0). Primitive tests are not counted either (tinybvh returns a cost, not
    /// a count).
    pub(super) fn run(
        tris: &[[[f32; 3]; 3]],
        records: &[&RayRecord],
        runs: usize,
    ) -> Option<PeerMeasured> {
        let verts = vertices(tris);
        let start = Instant::now();
        let rays = rays(records);
        let setup_ms = millis(start);
        let mut builds = Vec::new();
        let mut closest = Vec::new();
        let mut hits = vec![HitRecord::MISS; rays.len()];
        let mut bytes = 0;
        for _ in 0..runs {
            let start = Instant::now();
            let bvh = BVH::new(verts.as_slice().into()).ok()?;
            builds.push(millis(start));
            closest.push(trace(&bvh, &rays, &mut hits));
            bytes = std::mem::size_of_val(bvh.nodes()) + std::mem::size_of_val(bvh.indices());
        }
        Some(PeerMeasured {
            build_ms: median(&builds),
            setup_ms,
            closest_ms: median(&closest),
            hits,
            bytes,
            ..empty_measured()
        })
    }

    /// See [`super::alternate_with_tinybvh`].
    pub(super) fn alternate(
        tris: &[[[f32; 3]; 3]],
        records: &[&RayRecord],
        rounds: usize,
        ours: &mut dyn FnMut(),
    ) -> Option<Vec<f64>> {
        let verts = vertices(tris);
        let rays = rays(records);
        let bvh = BVH::new(verts.as_slice().into()).ok()?;
        let mut hits = vec![HitRecord::MISS; rays.len()];
        let mut out = Vec::with_capacity(rounds);
        for _ in 0..rounds {
            ours();
            out.push(super::mrays(rays.len(), trace(&bvh, &rays, &mut hits)));
        }
        Some(out)
    }

    /// tinybvh reads vertices as four floats each, three per triangle.
    fn vertices(tris: &[[[f32; 3]; 3]]) -> Vec<[f32; 4]> {
        tris.iter()
            .flat_map(|t| t.map(|p| [p[0], p[1], p[2], 0.0]))
            .collect()
    }

    /// A ray as tinybvh's C++ `Ray` lays it out: 128 bytes, aligned to 64. The binding's
    /// `Ray` is the first 64 bytes; tinybvh 1.6.8's `Intersection` grew 64 bytes of user
    /// data that the binding (0.1.0-beta.3) does not declare, and its fields `t` and `prim`
    /// sit at the offsets of the binding's `hit.t` and `hit.prim` (48 and 60). Handing the C++
    /// side a pointer into this padded slot keeps every byte it may touch inside our object.
    #[repr(C, align(64))]
    #[derive(Clone, Copy)]
    struct CppRay {
        ray: Ray,
        user_data: [u8; 64],
    }
    const _: () = assert!(std::mem::size_of::<CppRay>() == 128);

    /// The records as tinybvh rays, built as tinybvh's `Ray(origin, direction, t)`
    /// constructor does (direction normalised, reciprocal by `tinybvh_safercp`), in Rust:
    /// the binding's `Ray::new` returns the 128-byte C++ `Ray` by value into a 64-byte
    /// Rust one, overwriting 64 bytes of the caller's stack (seen as a crash). `t_max` is the
    /// hit distance on entry.
    fn rays(records: &[&RayRecord]) -> Vec<CppRay> {
        let far = INFINITE;
        let safe_rcp = |x: f32| {
            if x.abs() > 1e-12 {
                1.0 / x
            } else if x >= 0.0 {
                far
            } else {
                -far
            }
        };
        records
            .iter()
            .map(|r| {
                let [x, y, z] = r.dir;
                let len = (x * x + y * y + z * z).sqrt();
                let rl = if len == 0.0 { 0.0 } else { 1.0 / len };
                let dir = [x * rl, y * rl, z * rl];
                let ray = Ray {
                    origin: r.origin,
                    dir,
                    r_d: dir.map(safe_rcp),
                    hit: Intersection {
                        t: r.t_max.min(far),
                        ..Intersection::default()
                    },
                    ..Ray::default()
                };
                CppRay {
                    ray,
                    user_data: [0; 64],
                }
            })
            .collect()
    }

    /// One closest-hit pass into `hits`; returns its wall time, ms.
    fn trace(bvh: &BVH<'_>, rays: &[CppRay], hits: &mut [HitRecord]) -> f64 {
        let start = Instant::now();
        for (slot, ray) in hits.iter_mut().zip(rays) {
            let mut r = *ray;
            bvh.intersect(&mut r.ray);
            *slot = if r.ray.hit.t < ray.ray.hit.t {
                HitRecord {
                    t: r.ray.hit.t,
                    prim: r.ray.hit.prim,
                }
            } else {
                HitRecord::MISS
            };
        }
        millis(start)
    }
}
