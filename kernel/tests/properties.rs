//! Differential properties: on random scenes and rays, for both number modes, every builder
//! and leaf sizes 1, 2, 4 and 8:
//! - the tree passes `validate()` after every build (and respects the leaf size);
//! - the BVH's closest hit equals brute force (`Linear`) bit for bit: t, primitive, u and v;
//! - so do those of the 4-wide and the 8-wide BVH collapsed from each tree (validated, within
//!   `nodes4_needed` / `nodes8_needed`), queried directly and through `Coherent`;
//! - so do the uniform grid's (densities 0.25, 2 and 8, each built into arenas of exactly the
//!   counted size and validated) and the kd-tree's (automatic depth, depth 3 and the maximum,
//!   built into the documented budgets and validated);
//! - any-hit (`occluded`) is true exactly when there is a closest hit.
//!
//! Scenes are triangle soups with random, small, degenerate, duplicated (coincident, permuted)
//! triangles and shared-edge grids, coordinates within ±~100 (valid in both modes), scaled
//! exactly by powers of two towards both modes' range ends; and sphere sets. Rays start inside or outside, run along axes (±0 components), or are aimed exactly at
//! vertices, edge points and centroids. The proptest seed is fixed (override with
//! `PROPTEST_RNG_SEED`, case count with `PROPTEST_CASES`); failures print the seed, the shrunk
//! scene and the offending ray with its bits.

mod common;

use common::{
    all_options, dir_to, query, same_hit, with_accel, with_bvh, with_wide, RaySpec, TestScalar,
    WideTree, GRID_DENSITIES, KD_DEPTHS,
};
use proptest::prelude::*;
use proptest::test_runner::{Config as ProptestConfig, RngSeed};
use raykernel::bvh::BuildOptions;
use raykernel::bvh8::wide_nodes_needed;
use raykernel::{
    grid::GridOptions, kdtree::KdOptions, Accel, AccelKind, Bvh, Coherent, Linear, Primitive,
    Sphere, Triangle, WideBvh, I16F16,
};

const SEED: u64 = 0x5eed_7a11_0001;
/// Cases per property (each case: 2 modes × 3 builders × 4 leaf sizes × RAYS_PER_CASE rays).
const TRIANGLE_CASES: u32 = 1500;
const SPHERE_CASES: u32 = 500;
const RAYS_PER_CASE: usize = 32;

fn seed() -> u64 {
    std::env::var("PROPTEST_RNG_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(SEED)
}

fn config(cases: u32) -> ProptestConfig {
    let cases = std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(cases);
    ProptestConfig {
        rng_seed: RngSeed::Fixed(seed()),
        // The seed is fixed, so a failure reproduces without a regressions file.
        failure_persistence: None,
        max_shrink_iters: 2000,
        ..ProptestConfig::with_cases(cases)
    }
}

// ---------------------------------------------------------------------------------------------
// Scene and ray descriptions (shrinkable), resolved into f32 data shared by both modes.

const MAX_TRIS: usize = 200;

/// One coordinate: integers and quarters (exact in both modes, so planes and edges coincide
/// exactly), arbitrary values, and -0.
fn coord() -> impl Strategy<Value = f32> {
    prop_oneof![
        3 => (-100i32..=100).prop_map(|x| x as f32),
        2 => (-400i32..=400).prop_map(|x| x as f32 * 0.25),
        4 => -100.0f32..100.0,
        1 => Just(-0.0f32),
    ]
}

fn point() -> impl Strategy<Value = [f32; 3]> {
    [coord(), coord(), coord()]
}

fn small_offset() -> impl Strategy<Value = [f32; 3]> {
    [-3.0f32..3.0, -3.0f32..3.0, -3.0f32..3.0]
}

#[derive(Clone, Debug)]
enum TriSpec {
    /// Three independent points.
    Random([[f32; 3]; 3]),
    /// A small triangle around a point.
    Small([f32; 3], [[f32; 3]; 3]),
    /// Zero area: `kind` 0 = one point, 1 = two equal vertices, 2 = collinear (a, b, a+s(b-a)).
    Degenerate([f32; 3], [f32; 3], u8, f32),
    /// An exact copy of an earlier triangle (index modulo the count so far), its vertices
    /// rotated or reflected by `perm`.
    Duplicate(usize, u8),
    /// A grid of `nu × nv` quads, two triangles each, over shared vertices `o + i·u + j·v`
    /// (so shared edges are bit-identical).
    Grid {
        o: [f32; 3],
        u: [f32; 3],
        v: [f32; 3],
        nu: u8,
        nv: u8,
    },
}

fn tri_spec() -> impl Strategy<Value = TriSpec> {
    let axis_vec = (
        0usize..3,
        prop_oneof![Just(1.0f32), Just(2.0), Just(-1.5), Just(0.25)],
    )
        .prop_map(|(a, s)| {
            let mut v = [0.0; 3];
            v[a] = s;
            v
        });
    let step = prop_oneof![
        2 => [-7.0f32..7.0, -7.0f32..7.0, -7.0f32..7.0],
        1 => axis_vec,
    ];
    prop_oneof![
        5 => [point(), point(), point()].prop_map(TriSpec::Random),
        4 => (point(), [small_offset(), small_offset(), small_offset()])
            .prop_map(|(c, o)| TriSpec::Small(c, o)),
        2 => (point(), point(), 0u8..3, prop_oneof![Just(0.5f32), Just(0.25), -1.0f32..2.0])
            .prop_map(|(a, b, k, s)| TriSpec::Degenerate(a, b, k, s)),
        2 => (any::<usize>(), 0u8..6).prop_map(|(i, p)| TriSpec::Duplicate(i, p)),
        1 => (
            [-50i32..50, -50i32..50, -50i32..50],
            step.clone(),
            step,
            1u8..7,
            1u8..7,
        )
            .prop_map(|(o, u, v, nu, nv)| TriSpec::Grid {
                o: o.map(|x| x as f32),
                u,
                v,
                nu,
                nv,
            }),
    ]
}

fn add(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn scale(a: [f32; 3], s: f32) -> [f32; 3] {
    a.map(|x| x * s)
}
fn lerp(a: [f32; 3], b: [f32; 3], s: f32) -> [f32; 3] {
    [0, 1, 2].map(|i| a[i] + s * (b[i] - a[i]))
}

/// Expands the specs into at most [`MAX_TRIS`] (and at least one) triangles.
fn resolve_scene(specs: &[TriSpec]) -> Vec<[[f32; 3]; 3]> {
    let mut out: Vec<[[f32; 3]; 3]> = Vec::new();
    for spec in specs {
        match *spec {
            TriSpec::Random(v) => out.push(v),
            TriSpec::Small(c, o) => out.push(o.map(|d| add(c, d))),
            TriSpec::Degenerate(a, b, kind, s) => out.push(match kind {
                0 => [a, a, a],
                1 => [a, b, a],
                _ => [a, b, lerp(a, b, s)],
            }),
            TriSpec::Duplicate(i, perm) => {
                if let Some(&[a, b, c]) = out.get(i % out.len().max(1)) {
                    out.push(match perm {
                        0 => [a, b, c],
                        1 => [b, c, a],
                        2 => [c, a, b],
                        3 => [b, a, c],
                        4 => [a, c, b],
                        _ => [c, b, a],
                    });
                }
            }
            TriSpec::Grid { o, u, v, nu, nv } => {
                let at = |i: u8, j: u8| add(add(o, scale(u, i as f32)), scale(v, j as f32));
                for i in 0..nu {
                    for j in 0..nv {
                        let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                        if (i + j) % 2 == 0 {
                            out.extend([[a, b, c], [a, c, d]]);
                        } else {
                            out.extend([[a, b, d], [b, c, d]]);
                        }
                    }
                }
            }
        }
    }
    out.truncate(MAX_TRIS);
    if out.is_empty() {
        out.push([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    }
    out
}

#[derive(Clone, Debug)]
enum OriginSpec {
    /// Anywhere in ±150 (mostly outside the scene's bulk, sometimes inside).
    Far([f32; 3]),
    /// Inside the scene's bulk.
    Near([f32; 3]),
    /// Exactly at a vertex of a triangle (index modulo the count).
    AtVertex(usize, usize),
}

#[derive(Clone, Debug)]
enum DirSpec {
    Random([f32; 3]),
    /// Along an axis, with the other two components +0 or -0.
    Axis(usize, bool, [bool; 2]),
    /// Exactly at a vertex of a triangle.
    AtVertex(usize, usize),
    /// At a point on an edge: the midpoint (`None`) or at a fraction.
    AtEdge(usize, usize, Option<f32>),
    AtCentroid(usize),
}

#[derive(Clone, Debug)]
struct RayDesc {
    origin: OriginSpec,
    dir: DirSpec,
    /// Axis-aligned ray through a vertex or edge midpoint: (tri, which, axis, negative,
    /// distance); replaces origin/dir when set, exact in both modes for grid-valued points.
    axis_through: Option<(usize, usize, usize, bool, u8)>,
    /// `None` for [0, inf); otherwise (t_min, length).
    interval: Option<(f32, f32)>,
}

fn ray_desc() -> impl Strategy<Value = RayDesc> {
    let origin = prop_oneof![
        3 => [-150.0f32..150.0, -150.0f32..150.0, -150.0f32..150.0].prop_map(OriginSpec::Far),
        3 => [-30.0f32..30.0, -30.0f32..30.0, -30.0f32..30.0].prop_map(OriginSpec::Near),
        1 => (any::<usize>(), 0usize..3).prop_map(|(t, v)| OriginSpec::AtVertex(t, v)),
    ];
    let dir = prop_oneof![
        3 => [-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0].prop_map(DirSpec::Random),
        2 => (0usize..3, any::<bool>(), any::<[bool; 2]>())
            .prop_map(|(a, n, z)| DirSpec::Axis(a, n, z)),
        3 => (any::<usize>(), 0usize..3).prop_map(|(t, v)| DirSpec::AtVertex(t, v)),
        3 => (any::<usize>(), 0usize..3, prop::option::of(0.0f32..1.0))
            .prop_map(|(t, e, s)| DirSpec::AtEdge(t, e, s)),
        1 => any::<usize>().prop_map(DirSpec::AtCentroid),
    ];
    let axis_through = prop::option::weighted(
        0.25,
        (
            any::<usize>(),
            0usize..6,
            0usize..3,
            any::<bool>(),
            1u8..200,
        ),
    );
    let interval = prop::option::weighted(0.15, (0.0f32..100.0, 0.0f32..200.0));
    (origin, dir, axis_through, interval).prop_map(|(origin, dir, axis_through, interval)| {
        RayDesc {
            origin,
            dir,
            axis_through,
            interval,
        }
    })
}

/// The f32 ray a description stands for in this scene (positions in f32, shared by both modes).
fn resolve_ray(d: &RayDesc, tris: &[[[f32; 3]; 3]]) -> RaySpec {
    let n = tris.len();
    let vertex = |t: usize, v: usize| tris[t % n][v % 3];
    let spec = if let Some((t, which, axis, neg, dist)) = d.axis_through {
        // which 0..3: a vertex; 3..6: an edge midpoint.
        let target = if which < 3 {
            vertex(t, which)
        } else {
            lerp(vertex(t, which), vertex(t, which + 1), 0.5)
        };
        let mut dir = [0.0; 3];
        dir[axis] = if neg { -1.0 } else { 1.0 };
        let mut o = target;
        o[axis] -= dir[axis] * dist as f32;
        RaySpec::new(o, dir)
    } else {
        let o = match d.origin {
            OriginSpec::Far(p) | OriginSpec::Near(p) => p,
            OriginSpec::AtVertex(t, v) => vertex(t, v),
        };
        let dir = match d.dir {
            DirSpec::Random(v) => {
                if v == [0.0; 3] {
                    [0.0, 0.0, 1.0]
                } else {
                    v
                }
            }
            DirSpec::Axis(a, negative, zeros) => {
                let mut v = [0.0; 3];
                v[a] = if negative { -1.0 } else { 1.0 };
                v[(a + 1) % 3] = if zeros[0] { -0.0 } else { 0.0 };
                v[(a + 2) % 3] = if zeros[1] { -0.0 } else { 0.0 };
                v
            }
            DirSpec::AtVertex(t, v) => dir_to(o, vertex(t, v)),
            DirSpec::AtEdge(t, e, s) => {
                dir_to(o, lerp(vertex(t, e), vertex(t, e + 1), s.unwrap_or(0.5)))
            }
            DirSpec::AtCentroid(t) => {
                let [a, b, c] = tris[t % n];
                dir_to(o, [0, 1, 2].map(|i| (a[i] + b[i] + c[i]) / 3.0))
            }
        };
        RaySpec::new(o, dir)
    };
    match d.interval {
        None => spec,
        Some((t0, len)) => spec.interval(t0, t0 + len),
    }
}

// ---------------------------------------------------------------------------------------------
// The properties, written once over the number mode.

/// Builds with every builder and leaf size; each tree must validate, respect the leaf size,
/// and answer every ray exactly as `Linear` does.
fn check_differential<S: TestScalar, P: Primitive<S> + std::fmt::Debug>(
    prims: &[P],
    rays: &[RaySpec],
) -> Result<(), String> {
    let linear = Linear::new(prims);
    let mut want = Vec::with_capacity(rays.len());
    for r in rays {
        let hit = query(&linear, &r.ray::<S>())
            .map_err(|e| format!("{} Linear: {e}; seed {}, ray {r}", S::NAME, seed()))?;
        want.push(hit);
    }
    for options in all_options() {
        with_bvh::<S, P, _>(prims, options, |bvh| -> Result<(), String> {
            let ctx = |msg: String| format!("{} {options:?}: {msg}; seed {}", S::NAME, seed());
            let stats = bvh.validate().map_err(|e| ctx(format!("validate: {e}")))?;
            if stats.max_leaf_size > options.max_leaf_size {
                return Err(ctx(format!("leaf of {} prims", stats.max_leaf_size)));
            }
            for (r, want) in rays.iter().zip(&want) {
                let got = query(bvh, &r.ray::<S>()).map_err(|e| ctx(format!("{e}, ray {r}")))?;
                same_hit(&got, want).map_err(|e| {
                    let prim = |h: &Option<raykernel::Hit<S>>| h.map(|h| &prims[h.prim as usize]);
                    ctx(format!(
                        "BVH vs Linear: {e}, ray {r}; BVH's prim {:?}, Linear's prim {:?}",
                        prim(&got),
                        prim(want)
                    ))
                })?;
            }
            // The wide BVHs collapsed from this tree.
            check_wide::<4, S, P>(bvh, rays, &want, &ctx)?;
            check_wide::<8, S, P>(bvh, rays, &want, &ctx)
        })?;
    }
    // The uniform grid and the kd-tree: the same answers, bit for bit.
    let compare = |name: &str, accel: &dyn Fn(&RaySpec) -> QueryResult<S>| {
        for (r, want) in rays.iter().zip(&want) {
            let ctx = |msg: String| format!("{} {name}: {msg}; seed {}", S::NAME, seed());
            let got = accel(r).map_err(|e| ctx(format!("{e}, ray {r}")))?;
            same_hit(&got, want).map_err(|e| {
                let prim = |h: &Option<raykernel::Hit<S>>| h.map(|h| &prims[h.prim as usize]);
                ctx(format!(
                    "{name} vs Linear: {e}, ray {r}; its prim {:?}, Linear's prim {:?}",
                    prim(&got),
                    prim(want)
                ))
            })?;
        }
        Ok::<(), String>(())
    };
    let grids = GRID_DENSITIES.map(|density| AccelKind::Grid(GridOptions { density }));
    let kd_trees = KD_DEPTHS.map(|max_depth| AccelKind::KdTree(KdOptions { max_depth }));
    for kind in grids.into_iter().chain(kd_trees) {
        with_accel::<S, P, _>(kind, prims, |accel| {
            compare(&kind.to_string(), &|r| query(accel, &r.ray::<S>()))
        })?;
    }
    Ok(())
}

/// The `W`-wide BVH collapsed from `bvh` validates, fits the documented bound
/// ([`wide_nodes_needed`]), and answers every ray exactly as `Linear` did (`want`).
fn check_wide<const W: usize, S: TestScalar, P: Primitive<S>>(
    bvh: &Bvh<'_, S, P>,
    rays: &[RaySpec],
    want: &[Option<raykernel::Hit<S>>],
    ctx: &dyn Fn(String) -> String,
) -> Result<(), String>
where
    for<'a> WideBvh<'a, S, P, W>: WideTree<S>,
{
    with_wide::<W, S, P, _>(bvh, |wide| {
        let name = <WideBvh<'_, S, P, W> as WideTree<S>>::NAME;
        let stats = wide
            .check()
            .map_err(|e| ctx(format!("{name} validate: {e}")))?;
        if stats.node_count > wide_nodes_needed(bvh.prims().len(), W) {
            return Err(ctx(format!("{name} uses {} nodes", stats.node_count)));
        }
        for (r, want) in rays.iter().zip(want) {
            let got =
                query(wide, &r.ray::<S>()).map_err(|e| ctx(format!("{name} {e}, ray {r}")))?;
            same_hit(&got, want).map_err(|e| ctx(format!("{name} vs Linear: {e}, ray {r}")))?;
            // The walk for coherent rays answers alike.
            let got = query(&Coherent(wide), &r.ray::<S>())
                .map_err(|e| ctx(format!("{name} coherent {e}, ray {r}")))?;
            same_hit(&got, want)
                .map_err(|e| ctx(format!("{name} coherent vs Linear: {e}, ray {r}")))?;
        }
        Ok(())
    })
}

/// A closest hit, or why the query was inconsistent (see `common::query`).
type QueryResult<S> = Result<Option<raykernel::Hit<S>>, String>;

fn triangles<S: TestScalar>(tris: &[[[f32; 3]; 3]]) -> Vec<Triangle<S>> {
    tris.iter()
        .map(|&v| Triangle::from_f32(v).unwrap_or_else(|e| panic!("{} {v:?}: {e:?}", S::NAME)))
        .collect()
}

fn check_triangle_scene<S: TestScalar>(
    tris: &[[[f32; 3]; 3]],
    rays: &[RaySpec],
) -> Result<(), String> {
    check_differential::<S, _>(&triangles::<S>(tris), rays)
}

proptest! {
    #![proptest_config(config(TRIANGLE_CASES))]

    /// Triangle soups (degenerate and coincident triangles included): BVH == Linear bit for
    /// bit, occluded == hit, validate() after each build. The whole scene (and the rays'
    /// origins and intervals) is scaled by a power of two, exactly: 1 (vertices ±~100, origins
    /// ±~300), 2^4 (origins up to ±~5000, within the fixed-point limit), 2^-8 (near the
    /// fixed-point resolution); f32 also runs at 2^28 (±~8e10).
    #[test]
    fn bvh_equals_linear_on_triangle_soups(
        specs in prop::collection::vec(tri_spec(), 1..60),
        descs in prop::collection::vec(ray_desc(), RAYS_PER_CASE),
        scale_exp in prop_oneof![4 => Just(0i32), 1 => Just(4), 1 => Just(-8)],
        f32_exp in prop_oneof![3 => Just(None), 1 => Just(Some(28i32))],
    ) {
        let tris = resolve_scene(&specs);
        let rays: Vec<RaySpec> = descs.iter().map(|d| resolve_ray(d, &tris)).collect();
        let (scene, probes) = scaled(&tris, &rays, scale_exp);
        check_triangle_scene::<f32>(&scene, &probes).map_err(TestCaseError::fail)?;
        check_triangle_scene::<I16F16>(&scene, &probes).map_err(TestCaseError::fail)?;
        if let Some(e) = f32_exp {
            let (scene, probes) = scaled(&tris, &rays, e);
            check_triangle_scene::<f32>(&scene, &probes).map_err(TestCaseError::fail)?;
        }
    }
}

/// The scene and rays scaled by `2^exp` (exact in f32 for these magnitudes; directions keep
/// pointing exactly at their scaled targets).
fn scaled(
    tris: &[[[f32; 3]; 3]],
    rays: &[RaySpec],
    exp: i32,
) -> (Vec<[[f32; 3]; 3]>, Vec<RaySpec>) {
    let s = 2f32.powi(exp);
    let tris = tris.iter().map(|t| t.map(|v| v.map(|x| x * s))).collect();
    let rays = rays
        .iter()
        .map(|r| RaySpec {
            o: r.o.map(|x| x * s),
            t_min: r.t_min * s,
            t_max: r.t_max * s,
            ..*r
        })
        .collect();
    (tris, rays)
}

/// Regression (found by an earlier version of the property above, before 8615ae2): f32 reported
/// the collinear triangle 0 hit at t = 44.88676, below its own box's conservative entry
/// (44.88918); triangle 1 is hit at 44.88772, so the BVH, having found it first, culled
/// triangle 0's box and returned triangle 1 while Linear returned triangle 0.
fn degenerate_repro_cases<S: TestScalar>() {
    let tris = [
        [[-2.0, 27.75, 39.0], [-2.0, 28.0, 39.0], [-2.0, 26.5, 39.0]],
        [
            [-1.9995, 26.4, 38.0],
            [-1.9995, 28.4, 38.0],
            [-1.9995, 27.4, 40.0],
        ],
    ];
    let r = RaySpec::new(
        [11.6989, -13.685142, 27.25114],
        [-13.6989, 41.101807, 11.748859],
    );
    check_triangle_scene::<S>(&tris, &[r]).unwrap_or_else(|e| panic!("{e}"));
}

#[test]
fn bvh_equals_linear_when_zero_area_triangle_is_grazed_f32() {
    degenerate_repro_cases::<f32>();
}

#[test]
fn bvh_equals_linear_when_zero_area_triangle_is_grazed_fixed() {
    degenerate_repro_cases::<I16F16>();
}

// ---------------------------------------------------------------------------------------------
// Spheres.

#[derive(Clone, Debug)]
enum SphereSpec {
    Random([f32; 3], f32),
    /// A copy of an earlier sphere (coincident).
    Duplicate(usize),
}

fn sphere_spec() -> impl Strategy<Value = SphereSpec> {
    prop_oneof![
        6 => (point(), prop_oneof![3 => 0.0f32..20.0, 1 => Just(0.0f32), 1 => (1i32..20).prop_map(|r| r as f32)])
            .prop_map(|(c, r)| SphereSpec::Random(c, r)),
        1 => any::<usize>().prop_map(SphereSpec::Duplicate),
    ]
}

fn resolve_spheres(specs: &[SphereSpec]) -> Vec<([f32; 3], f32)> {
    let mut out: Vec<([f32; 3], f32)> = Vec::new();
    for s in specs {
        match *s {
            SphereSpec::Random(c, r) => out.push((c, r)),
            SphereSpec::Duplicate(i) => {
                if let Some(&s) = out.get(i % out.len().max(1)) {
                    out.push(s);
                }
            }
        }
    }
    if out.is_empty() {
        out.push(([0.0; 3], 1.0));
    }
    out
}

/// Rays for sphere scenes: random, axis-aligned, and aimed at centres and at points on the
/// surface (tangent-ish).
fn resolve_sphere_ray(d: &RayDesc, spheres: &[([f32; 3], f32)]) -> RaySpec {
    let n = spheres.len();
    let o = match d.origin {
        OriginSpec::Far(p) | OriginSpec::Near(p) => p,
        OriginSpec::AtVertex(i, _) => spheres[i % n].0,
    };
    let dir = match d.dir {
        DirSpec::Random(v) if v != [0.0; 3] => v,
        DirSpec::Random(_) => [1.0, 0.0, 0.0],
        DirSpec::Axis(a, negative, _) => {
            let mut v = [0.0; 3];
            v[a] = if negative { -1.0 } else { 1.0 };
            v
        }
        DirSpec::AtVertex(i, axis) | DirSpec::AtEdge(i, axis, _) => {
            let (c, r) = spheres[i % n];
            let mut t = c;
            t[axis] += r;
            dir_to(o, t)
        }
        DirSpec::AtCentroid(i) => dir_to(o, spheres[i % n].0),
    };
    let spec = RaySpec::new(o, dir);
    match d.interval {
        None => spec,
        Some((t0, len)) => spec.interval(t0, t0 + len),
    }
}

fn check_sphere_scene<S: TestScalar>(
    spheres: &[([f32; 3], f32)],
    rays: &[RaySpec],
) -> Result<(), String> {
    let prims: Vec<Sphere<S>> = spheres
        .iter()
        .map(|&(c, r)| Sphere {
            center: common::p(c),
            radius: common::c(r),
        })
        .collect();
    check_differential::<S, _>(&prims, rays)
}

proptest! {
    #![proptest_config(config(SPHERE_CASES))]

    /// Sphere sets: BVH == Linear bit for bit, occluded == hit, validate() after each build.
    #[test]
    fn bvh_equals_linear_on_spheres(
        specs in prop::collection::vec(sphere_spec(), 1..120),
        descs in prop::collection::vec(ray_desc(), RAYS_PER_CASE),
    ) {
        let spheres = resolve_spheres(&specs);
        let rays: Vec<RaySpec> = descs.iter().map(|d| resolve_sphere_ray(d, &spheres)).collect();
        check_sphere_scene::<f32>(&spheres, &rays).map_err(TestCaseError::fail)?;
        check_sphere_scene::<I16F16>(&spheres, &rays).map_err(TestCaseError::fail)?;
    }
}

// ---------------------------------------------------------------------------------------------
// Fixed regressions: structured scenes every run sees, whatever proptest generates.

/// A dense shared-edge grid with duplicates and degenerate triangles, queried by rays aimed at
/// every vertex and edge midpoint along all six axis directions and obliquely.
fn grid_scene_cases<S: TestScalar>() {
    let mut tris = resolve_scene(&[
        TriSpec::Grid {
            o: [-8.0, -8.0, 0.0],
            u: [2.0, 0.0, 0.0],
            v: [0.0, 2.0, 0.0],
            nu: 8,
            nv: 8,
        },
        TriSpec::Grid {
            o: [-5.0, -5.0, -5.0],
            u: [1.5, 0.5, 0.25],
            v: [-0.5, 1.5, 0.75],
            nu: 5,
            nv: 5,
        },
    ]);
    let dups: Vec<_> = tris.iter().step_by(7).map(|&[a, b, c]| [c, a, b]).collect();
    tris.extend(dups);
    tris.push([[0.0; 3]; 3]);
    tris.push([[-8.0, -8.0, 0.0], [8.0, 8.0, 0.0], [0.0, 0.0, 0.0]]);
    let mut rays = Vec::new();
    for t in tris.iter().step_by(3) {
        for k in 0..3 {
            let targets = [t[k], lerp(t[k], t[(k + 1) % 3], 0.5)];
            for target in targets {
                for axis in 0..3 {
                    for sign in [1.0f32, -1.0] {
                        let mut d = [0.0; 3];
                        d[axis] = sign;
                        let mut o = target;
                        o[axis] -= 20.0 * sign;
                        rays.push(RaySpec::new(o, d));
                    }
                }
                let o = [3.0, -17.0, 25.0];
                rays.push(RaySpec::new(o, dir_to(o, target)));
            }
        }
    }
    check_triangle_scene::<S>(&tris, &rays).unwrap_or_else(|e| panic!("{e}"));
}

#[test]
fn bvh_equals_linear_on_shared_edge_grid_f32() {
    grid_scene_cases::<f32>();
}

#[test]
fn bvh_equals_linear_on_shared_edge_grid_fixed() {
    grid_scene_cases::<I16F16>();
}

/// Ties at equal t go to the lowest primitive id in every accelerator: a stack of coincident
/// copies reports prim 0's hit; with a nearer copy appended last, that one wins.
fn tie_cases<S: TestScalar>() {
    let base = [[-1.0, -1.0, 5.0], [3.0, -1.0, 5.0], [-1.0, 3.0, 5.0]];
    let mut tris = vec![base; 40];
    let r = RaySpec::new([0.0, 0.0, 0.0], [0.0, 0.0, 1.0]);
    for options in all_options() {
        let prims = triangles::<S>(&tris);
        let hit = with_bvh::<S, _, _>(&prims, options, |bvh| bvh.intersect(&r.ray::<S>()));
        assert_eq!(hit.map(|h| h.prim), Some(0), "{} {options:?}", S::NAME);
    }
    tris.push([[-1.0, -1.0, 4.0], [3.0, -1.0, 4.0], [-1.0, 3.0, 4.0]]);
    let prims = triangles::<S>(&tris);
    let opts = BuildOptions::default();
    let hit = with_bvh::<S, _, _>(&prims, opts, |bvh| bvh.intersect(&r.ray::<S>()));
    assert_eq!(hit.map(|h| h.prim), Some(40), "{}", S::NAME);
}

#[test]
fn closest_hit_ties_go_to_lowest_prim_id_f32() {
    tie_cases::<f32>();
}

#[test]
fn closest_hit_ties_go_to_lowest_prim_id_fixed() {
    tie_cases::<I16F16>();
}

/// `redirected_f32` keeps the origin's data and recomputes the direction's: the ray it gives
/// must be `Ray::from_f32` from the same origin, bit for bit (compared through `Debug`, which
/// prints every `f32` exactly), errors included.
fn check_redirect<S: TestScalar>(o: [f32; 3], first: [f32; 3], d: [f32; 3]) -> Result<(), String> {
    use raykernel::Ray;
    let Ok(base) = Ray::<S>::from_f32(o, first, 0.0, f32::INFINITY) else {
        return Ok(()); // an unusable origin or first direction: nothing to redirect
    };
    let want = Ray::<S>::from_f32(o, d, 0.0, f32::INFINITY);
    let got = base.redirected_f32(d);
    if format!("{want:?}") == format!("{got:?}") {
        Ok(())
    } else {
        Err(format!(
            "{}: from_f32 {want:?}\nredirected {got:?}",
            S::NAME
        ))
    }
}

fn component() -> impl Strategy<Value = f32> {
    prop_oneof![
        4 => -1000.0f32..1000.0,
        1 => Just(0.0f32),
        1 => Just(-0.0f32),
        1 => Just(1e-30f32),
        1 => Just(f32::NAN),
        1 => Just(f32::INFINITY),
    ]
}

proptest! {
    #![proptest_config(config(2000))]

    #[test]
    fn redirected_rays_equal_fresh_ones(
        o in prop::array::uniform3(-9000.0f32..9000.0),
        first in prop::array::uniform3(component()),
        d in prop::array::uniform3(component()),
    ) {
        check_redirect::<f32>(o, first, d).map_err(TestCaseError::fail)?;
        check_redirect::<I16F16>(o, first, d).map_err(TestCaseError::fail)?;
    }
}

/// `set_from_f32` must make the ray `Ray::from_f32` of the same arguments, bit for bit
/// (compared through `Debug`), and leave it unchanged when that is an error (the same error).
fn check_set<S: TestScalar>(
    base: ([f32; 3], [f32; 3]),
    o: [f32; 3],
    d: [f32; 3],
    (t_min, t_max): (f32, f32),
) -> Result<(), String> {
    use raykernel::Ray;
    let Ok(mut ray) = Ray::<S>::from_f32(base.0, base.1, 0.0, f32::INFINITY) else {
        return Ok(()); // an unusable starting ray: nothing to overwrite
    };
    let before = format!("{ray:?}");
    let want = Ray::<S>::from_f32(o, d, t_min, t_max);
    let got = ray.set_from_f32(o, d, t_min, t_max);
    let (want, got) = match (want, got) {
        (Ok(w), Ok(())) => (format!("{w:?}"), format!("{ray:?}")),
        (Err(w), Err(g)) if w == g => (before, format!("{ray:?}")),
        (w, g) => return Err(format!("{}: from_f32 {w:?}, set_from_f32 {g:?}", S::NAME)),
    };
    if want == got {
        Ok(())
    } else {
        Err(format!("{}: want {want}\ngot {got}", S::NAME))
    }
}

fn bound() -> impl Strategy<Value = f32> {
    prop_oneof![
        4 => 0.0f32..100.0,
        1 => Just(-1.0f32),
        1 => Just(f32::NAN),
        1 => Just(f32::INFINITY),
    ]
}

proptest! {
    #![proptest_config(config(2000))]

    #[test]
    fn set_rays_equal_fresh_ones(
        base_o in prop::array::uniform3(-100.0f32..100.0),
        base_d in prop::array::uniform3(component()),
        o in prop::array::uniform3(prop_oneof![
            8 => -9000.0f32..9000.0,
            1 => Just(f32::NAN),
            1 => Just(1e30f32),
        ]),
        d in prop::array::uniform3(component()),
        t_min in bound(),
        t_max in bound(),
    ) {
        let t = (t_min, t_max);
        check_set::<f32>((base_o, base_d), o, d, t).map_err(TestCaseError::fail)?;
        check_set::<I16F16>((base_o, base_d), o, d, t).map_err(TestCaseError::fail)?;
    }
}
