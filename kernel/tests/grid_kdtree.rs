//! The uniform grid and the kd-tree beyond the random differential tests of `properties.rs`:
//! - `Numerics::slab_axis` recombines to exactly `Numerics::slab` (the grid walk's foundation);
//! - degenerate scenes (no primitives, one, all in one cell, flat, a single huge triangle among
//!   small ones, zero-area triangles, coincident spheres) build without panicking, validate,
//!   and answer like brute force bit for bit, in both modes;
//! - too-small memory and bad options give typed errors with exact numbers; the counting pass
//!   is exact (one slot less fails).

mod common;

use common::{c, p, query, same_hit, with_grid, with_kdtree, RaySpec, TestScalar};
use raykernel::grid::{GridSize, MAX_DENSITY};
use raykernel::kdtree::{nodes_needed, refs_needed, MAX_DEPTH};
use raykernel::Arena;
use raykernel::{
    grid::GridOptions, kdtree::KdOptions, Accel, BuildError, Grid, KdNode, KdTree, Linear,
    Primitive, Ray, Sphere, Triangle, I16F16,
};
use raykernel_testkit::Rng;

fn tri<S: TestScalar>(v: [[f32; 3]; 3]) -> Triangle<S> {
    Triangle { v: v.map(p::<S>) }
}

// ---------------------------------------------------------------------------------------------
// slab_axis == slab

/// Random boxes (some with planes exactly at the origin's coordinates) and rays (some with ±0
/// components): `slab` accepts iff the per-axis intervals do, with the same entry.
fn slab_axis_cases<S: TestScalar>() {
    let mut rng = Rng::new(0x51ab_a815);
    for case in 0..20_000 {
        let o = [0, 1, 2].map(|_| (rng.range(-20.0, 20.0) * 4.0).round() / 4.0);
        let mut d = rng.unit_vec();
        for x in &mut d {
            match rng.below(6) {
                0 => *x = 0.0,
                1 => *x = -0.0,
                _ => {}
            }
        }
        if d.iter().all(|&x| x == 0.0) {
            d[rng.below(3)] = 1.0;
        }
        let (t_min, t_max) = match rng.below(3) {
            0 => (0.0, f32::INFINITY),
            1 => (rng.range(0.0, 10.0), f32::INFINITY),
            _ => {
                let a = rng.range(0.0, 30.0);
                (a, a + rng.range(0.0, 30.0))
            }
        };
        let ray = Ray::<S>::from_f32(o, d, t_min, t_max).unwrap();
        let mut lo = [S::ZERO; 3];
        let mut hi = [S::ZERO; 3];
        for k in 0..3 {
            let pick = |rng: &mut Rng| match rng.below(4) {
                0 => o[k],
                _ => (rng.range(-25.0, 25.0) * 4.0).round() / 4.0,
            };
            let (a, b) = (pick(&mut rng), pick(&mut rng));
            lo[k] = c::<S>(a.min(b));
            hi[k] = c::<S>(a.max(b));
        }
        let want = S::slab(ray.data(), &lo, &hi, ray.t_min(), ray.t_max());
        let mut entry = ray.t_min();
        let mut exit = S::widen(ray.t_max());
        for k in 0..3 {
            let (n, x) = S::slab_axis(ray.data(), k, lo[k], hi[k]);
            entry = entry.max_of(n);
            exit = exit.min_of(x);
        }
        let got = (entry <= exit).then_some(entry);
        assert_eq!(
            got.map(|t| t.bits()),
            want.map(|t| t.bits()),
            "{} case {case}: origin {o:?} dir {d:?} t [{t_min}, {t_max}] box {lo:?} {hi:?}",
            S::NAME
        );
    }
}

#[test]
fn slab_axis_recombines_to_slab_f32() {
    slab_axis_cases::<f32>();
}

#[test]
fn slab_axis_recombines_to_slab_fixed() {
    slab_axis_cases::<I16F16>();
}

// ---------------------------------------------------------------------------------------------
// Degenerate scenes

/// Rays at the scene: from around it towards random points of it, along the axes (±0
/// components) through vertices, and from inside.
fn rays_at(points: &[[f32; 3]], seed: u64) -> Vec<RaySpec> {
    let mut rng = Rng::new(seed);
    let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
    for q in points {
        for k in 0..3 {
            lo[k] = lo[k].min(q[k]);
            hi[k] = hi[k].max(q[k]);
        }
    }
    // Origins stay within the fixed-point range even around the huge triangle.
    let size = (0..3)
        .map(|k| hi[k] - lo[k])
        .fold(1.0f32, f32::max)
        .min(1000.0);
    let centre: [f32; 3] = core::array::from_fn(|k| 0.5 * (lo[k] + hi[k]));
    let mut rays = Vec::new();
    for i in 0..200 {
        let target = points[rng.below(points.len())];
        let o = match i % 3 {
            0 => {
                let u = rng.unit_vec();
                core::array::from_fn(|k| centre[k] + 2.0 * size * u[k])
            }
            1 => core::array::from_fn(|k| rng.range(lo[k] - 0.1, hi[k] + 0.1)),
            _ => {
                let mut o = target;
                let axis = rng.below(3);
                o[axis] -= 3.0 * size;
                rays.push(RaySpec::new(o, {
                    let mut d = [0.0; 3];
                    d[axis] = 1.0;
                    d
                }));
                o
            }
        };
        rays.push(RaySpec::new(o, common::dir_to(o, target)));
        rays.push(RaySpec::new(o, rng.unit_vec()));
    }
    rays
}

/// A closest hit, or why the query was inconsistent (see `common::query`).
type QueryResult<S> = Result<Option<raykernel::Hit<S>>, String>;

/// Grid (three densities) and kd-tree (three depth limits) answer every ray like `Linear`.
fn agree<S: TestScalar, P: Primitive<S> + std::fmt::Debug>(
    name: &str,
    prims: &[P],
    rays: &[RaySpec],
) {
    let linear = Linear::new(prims);
    let want: Vec<_> = rays
        .iter()
        .map(|r| query(&linear, &r.ray::<S>()).unwrap())
        .collect();
    let check = |accel: &dyn Fn(&Ray<S>) -> QueryResult<S>, what: &str| {
        for (r, w) in rays.iter().zip(&want) {
            let got = accel(&r.ray::<S>()).unwrap_or_else(|e| panic!("{name} {what}: {e}"));
            same_hit(&got, w).unwrap_or_else(|e| panic!("{} {name} {what}: {e}, ray {r}", S::NAME));
        }
    };
    for density in [0.25, 2.0, MAX_DENSITY] {
        let options = GridOptions { density };
        with_grid::<S, P, _>(prims, options, |g| {
            check(&|r| query(g, r), &format!("{options:?}"))
        });
    }
    for max_depth in [0, 2, MAX_DEPTH] {
        let options = KdOptions { max_depth };
        with_kdtree::<S, P, _>(prims, options, |k| {
            check(&|r| query(k, r), &format!("{options:?}"))
        });
    }
}

fn degenerate_cases<S: TestScalar>() {
    // No primitives: empty structures, every ray misses.
    let none: Vec<Triangle<S>> = Vec::new();
    assert_eq!(
        Grid::size_for(&none, GridOptions::default()).unwrap(),
        GridSize::default()
    );
    let r = RaySpec::new([0.0; 3], [0.0, 0.0, 1.0]).ray::<S>();
    with_grid::<S, _, _>(&none, GridOptions::default(), |g| {
        assert!(g.intersect(&r).is_none() && !g.occluded(&r));
    });
    with_kdtree::<S, _, _>(&none, KdOptions::default(), |k| {
        assert!(k.intersect(&r).is_none() && !k.occluded(&r));
    });

    // One triangle.
    let one_v = [[-1.0, -1.0, 5.0], [1.0, -1.0, 5.0], [0.0, 1.0, 5.0]];
    agree::<S, _>("one", &[tri::<S>(one_v)], &rays_at(&one_v, 1));

    // All in one cell: 300 copies of one triangle (ties: prim 0 must win everywhere).
    let copies = vec![tri::<S>(one_v); 300];
    agree::<S, _>("identical", &copies, &rays_at(&one_v, 2));

    // Flat: a 20×20 grid of triangles in z = 3 (zero extent on one axis), rays in the plane too.
    let mut flat = Vec::new();
    let mut pts = Vec::new();
    for i in 0..20 {
        for j in 0..20 {
            let (x, y) = (i as f32 * 0.5, j as f32 * 0.5);
            let v = [[x, y, 3.0], [x + 0.5, y, 3.0], [x, y + 0.5, 3.0]];
            pts.extend(v);
            flat.push(v);
        }
    }
    let flat_tris: Vec<_> = flat.iter().map(|&v| tri::<S>(v)).collect();
    let mut rays = rays_at(&pts, 3);
    rays.push(RaySpec::new([-1.0, 1.0, 3.0], [1.0, 0.0, 0.0]));
    rays.push(RaySpec::new([0.25, 0.25, 10.0], [0.0, -0.0, -1.0]));
    agree::<S, _>("flat", &flat_tris, &rays);

    // A line: triangles along x only (zero extent on two axes), all zero-area.
    let line: Vec<_> = (0..50)
        .map(|i| {
            let x = i as f32;
            tri::<S>([[x, 0.0, 0.0], [x + 2.0, 0.0, 0.0], [x + 1.0, 0.0, 0.0]])
        })
        .collect();
    agree::<S, _>("line", &line, &rays_at(&[[0.0; 3], [51.0, 0.0, 0.0]], 4));

    // A single huge triangle over 200 small ones: it spans every cell and straddles every plane.
    let huge_v = [
        [-4000.0, -4000.0, 0.5],
        [4000.0, -4000.0, 0.5],
        [0.0, 4000.0, 0.5],
    ];
    let mut mixed = vec![tri::<S>(huge_v)];
    let mut rng = Rng::new(5);
    let mut pts = Vec::new();
    for _ in 0..200 {
        let c0 = [
            rng.range(-5.0, 5.0),
            rng.range(-5.0, 5.0),
            rng.range(-1.0, 2.0),
        ];
        let v = [
            c0,
            [c0[0] + 0.3, c0[1], c0[2]],
            [c0[0], c0[1] + 0.3, c0[2] + 0.1],
        ];
        pts.extend(v);
        mixed.push(tri::<S>(v));
    }
    agree::<S, _>("huge+small", &mixed, &rays_at(&pts, 6));
    agree::<S, _>("huge alone", &mixed[..1], &rays_at(&huge_v, 7));

    // Coincident spheres of radius 0 and 1.
    let spheres: Vec<Sphere<S>> = (0..40)
        .map(|i| Sphere {
            center: p::<S>([1.0, 2.0, 3.0]),
            radius: c::<S>(if i % 2 == 0 { 1.0 } else { 0.0 }),
        })
        .collect();
    agree::<S, _>(
        "spheres",
        &spheres,
        &rays_at(&[[0.0, 1.0, 2.0], [2.0, 3.0, 4.0]], 8),
    );
}

#[test]
fn degenerate_scenes_build_and_match_brute_force_f32() {
    degenerate_cases::<f32>();
}

#[test]
fn degenerate_scenes_build_and_match_brute_force_fixed() {
    degenerate_cases::<I16F16>();
}

// ---------------------------------------------------------------------------------------------
// Typed errors

fn small_scene<S: TestScalar>() -> Vec<Triangle<S>> {
    (0..30)
        .map(|i| {
            let x = (i % 6) as f32;
            let y = (i / 6) as f32;
            tri::<S>([[x, y, 0.0], [x + 1.5, y, 0.5], [x, y + 1.5, 1.0]])
        })
        .collect()
}

fn error_cases<S: TestScalar>() {
    let tris = small_scene::<S>();
    let opt = GridOptions::default();
    let size = Grid::size_for(&tris, opt).unwrap();
    assert!(size.cells > 1 && size.refs >= tris.len());
    // Exactly the counted sizes work; one slot less is a typed error with the exact need.
    let (mut cells, mut refs) = (vec![0u32; size.cells], vec![0u32; size.refs]);
    assert!(Grid::build(&tris, &mut cells, &mut refs, opt).is_ok());
    let mut short = vec![0u32; size.cells - 1];
    assert_eq!(
        Grid::build(&tris, &mut short, &mut refs, opt).err(),
        Some(BuildError::ArenaTooSmall {
            arena: Arena::Cells,
            needed: size.cells,
            available: size.cells - 1,
        })
    );
    let mut short = vec![0u32; size.refs - 1];
    assert_eq!(
        Grid::build(&tris, &mut cells, &mut short, opt).err(),
        Some(BuildError::ArenaTooSmall {
            arena: Arena::Refs,
            needed: size.refs,
            available: size.refs - 1,
        })
    );
    for density in [0.0, -1.0, f32::NAN, f32::INFINITY, MAX_DENSITY * 2.0] {
        let e = Grid::<S, _>::size_for(&tris, GridOptions { density }).err();
        assert!(
            matches!(e, Some(BuildError::BadDensity { .. })),
            "{density}: {e:?}"
        );
    }

    // Kd-tree: budgets are exact requirements.
    let n = tris.len();
    let kopt = KdOptions::default();
    let mut nodes = vec![KdNode::<S>::EMPTY; nodes_needed(n)];
    let mut krefs = vec![0u32; refs_needed(n)];
    assert!(KdTree::build(&tris, &mut nodes, &mut krefs, kopt).is_ok());
    let mut short_nodes = vec![KdNode::<S>::EMPTY; nodes_needed(n) - 1];
    assert_eq!(
        KdTree::build(&tris, &mut short_nodes, &mut krefs, kopt).err(),
        Some(BuildError::ArenaTooSmall {
            arena: Arena::Nodes,
            needed: nodes_needed(n),
            available: nodes_needed(n) - 1,
        })
    );
    let mut short_refs = vec![0u32; refs_needed(n) - 1];
    assert_eq!(
        KdTree::build(&tris, &mut nodes, &mut short_refs, kopt).err(),
        Some(BuildError::ArenaTooSmall {
            arena: Arena::Refs,
            needed: refs_needed(n),
            available: refs_needed(n) - 1,
        })
    );
    let e = KdTree::build(
        &tris,
        &mut nodes,
        &mut krefs,
        KdOptions {
            max_depth: MAX_DEPTH + 1,
        },
    )
    .err();
    assert_eq!(
        e,
        Some(BuildError::BadMaxDepth {
            max_depth: MAX_DEPTH + 1
        })
    );

    // A bad vertex is reported by both, naming the primitive and vertex.
    let mut bad = tris.clone();
    bad[7].v[2][1] = S::bad_coords()[0].0;
    let want = BuildError::BadPrimitive {
        prim: 7,
        vertex: 2,
        error: S::bad_coords()[0].1,
    };
    assert_eq!(Grid::<S, _>::size_for(&bad, opt).err(), Some(want));
    assert_eq!(
        Grid::build(&bad, &mut cells, &mut refs, opt).err(),
        Some(want)
    );
    assert_eq!(
        KdTree::build(&bad, &mut nodes, &mut krefs, kopt).err(),
        Some(want)
    );
}

#[test]
fn too_small_memory_and_bad_options_are_typed_errors_f32() {
    error_cases::<f32>();
}

#[test]
fn too_small_memory_and_bad_options_are_typed_errors_fixed() {
    error_cases::<I16F16>();
}

/// More references than a 32-bit offset can address: 8200 copies of one triangle, each in every
/// one of about 64·8200 cells, is 4.3e9 references. The counting pass says so exactly.
#[test]
fn too_many_grid_references_is_a_typed_error() {
    let t = tri::<f32>([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    let tris = vec![t; 8200];
    let opt = GridOptions {
        density: MAX_DENSITY,
    };
    match Grid::size_for(&tris, opt) {
        Err(BuildError::TooManyRefs { needed }) => assert!(needed > u32::MAX as u64, "{needed}"),
        other => panic!("{other:?}"),
    }
}
