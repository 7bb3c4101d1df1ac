//! Every bad input gives its typed error, in both number modes; degenerate but valid inputs
//! (no primitives, one, thousands of identical ones, a depth-pathological distribution) build
//! valid trees that answer like brute force.
//!
//! `BuildError::TooManyPrims` is not tested: it needs `u32::MAX` primitives (over 150 GB of
//! triangles plus arenas), and the check precedes every other, so no smaller input reaches it.

mod common;

use common::{all_options, c, p, query, same_hit, with_bvh, RaySpec, TestScalar};
use raykernel::bvh::{
    nodes_needed, BuildOptions, BuilderKind, MAX_DEPTH, MAX_LEAF_SIZE, MEDIAN_FALLBACK_DEPTH,
};
use raykernel::Arena;
use raykernel::{
    Accel, BuildError, Bvh, Linear, Node, PointError, Ray, RayError, Sphere, Triangle, VertexError,
    F32_COORD_LIMIT, FIXED_COORD_LIMIT, I16F16,
};
use raykernel_testkit::Rng;

fn tri<S: TestScalar>(v: [[f32; 3]; 3]) -> Triangle<S> {
    Triangle { v: v.map(p::<S>) }
}

/// `n` small distinct triangles along x.
fn row<S: TestScalar>(n: usize) -> Vec<Triangle<S>> {
    (0..n)
        .map(|i| {
            let x = i as f32;
            tri::<S>([[x, 0.0, 0.0], [x + 0.5, 0.0, 0.0], [x, 1.0, 0.5]])
        })
        .collect()
}

fn build_err<S: TestScalar>(
    prims: &[Triangle<S>],
    node_slots: usize,
    id_slots: usize,
    options: BuildOptions,
) -> BuildError {
    let mut nodes = vec![Node::<S>::EMPTY; node_slots];
    let mut ids = vec![0u32; id_slots];
    match Bvh::build(prims, &mut nodes, &mut ids, options) {
        Ok(_) => panic!(
            "{}: build with {node_slots} nodes / {id_slots} ids succeeded, want an error",
            S::NAME
        ),
        Err(e) => e,
    }
}

// ---------------------------------------------------------------------------------------------
// Build errors.

/// One slot short in either arena gives `ArenaTooSmall` with the exact sizes; the exact sizes
/// build.
fn arena_cases<S: TestScalar>() {
    for n in [1usize, 2, 3, 7, 100] {
        let prims = row::<S>(n);
        let (need_nodes, opts) = (nodes_needed(n), BuildOptions::default());
        assert_eq!(
            build_err(&prims, need_nodes - 1, n, opts),
            BuildError::ArenaTooSmall {
                arena: Arena::Nodes,
                needed: need_nodes,
                available: need_nodes - 1
            },
            "{} n = {n}",
            S::NAME
        );
        assert_eq!(
            build_err(&prims, need_nodes, n - 1, opts),
            BuildError::ArenaTooSmall {
                arena: Arena::PrimIds,
                needed: n,
                available: n - 1
            },
            "{} n = {n}",
            S::NAME
        );
        assert_eq!(
            build_err(&prims, 0, 0, opts),
            BuildError::ArenaTooSmall {
                arena: Arena::Nodes,
                needed: need_nodes,
                available: 0
            }
        );
        // Exactly enough builds (and larger arenas are fine too).
        with_bvh::<S, _, _>(&prims, opts, |bvh| bvh.validate().unwrap());
        let mut nodes = vec![Node::<S>::EMPTY; need_nodes + 5];
        let mut ids = vec![0u32; n + 5];
        let bvh = Bvh::build(&prims, &mut nodes, &mut ids, opts).unwrap();
        bvh.validate().unwrap();
    }
    assert_eq!((nodes_needed(0), nodes_needed(1)), (0, 1));
}

/// A bad coordinate in any vertex of any triangle names that triangle and vertex.
fn bad_vertex_cases<S: TestScalar>() {
    for (bad, error) in S::bad_coords() {
        for prim in [0usize, 4, 9] {
            for vertex in 0..3 {
                for axis in 0..3 {
                    let mut prims = row::<S>(10);
                    prims[prim].v[vertex][axis] = bad;
                    let got = build_err(&prims, nodes_needed(10), 10, BuildOptions::default());
                    let want = BuildError::BadPrimitive {
                        prim,
                        vertex,
                        error,
                    };
                    assert_eq!(
                        got,
                        want,
                        "{} {bad:?} at prim {prim} v{vertex}[{axis}]",
                        S::NAME
                    );
                }
            }
        }
    }
    // The first bad primitive is reported.
    let mut prims = row::<S>(10);
    let (bad, error) = S::bad_coords()[0];
    prims[7].v[1][2] = bad;
    prims[3].v[2][0] = bad;
    let got = build_err(&prims, nodes_needed(10), 10, BuildOptions::default());
    assert_eq!(
        got,
        BuildError::BadPrimitive {
            prim: 3,
            vertex: 2,
            error
        }
    );
}

/// `Triangle::from_f32` rejects what the mode cannot hold, naming the vertex.
fn from_f32_cases<S: TestScalar>() {
    let ok = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let out_fixed = PointError::OutOfRange {
        limit: FIXED_COORD_LIMIT,
    };
    let out_f32 = PointError::OutOfRange {
        limit: F32_COORD_LIMIT,
    };
    let fixed = S::NAME == "fixed";
    let cases: [(f32, Option<PointError>); 9] = [
        (f32::NAN, Some(PointError::NonFinite)),
        (f32::INFINITY, Some(PointError::NonFinite)),
        (f32::NEG_INFINITY, Some(PointError::NonFinite)),
        (FIXED_COORD_LIMIT, None),
        (-FIXED_COORD_LIMIT, None),
        (
            common::next_up(FIXED_COORD_LIMIT),
            fixed.then_some(out_fixed),
        ),
        (-FIXED_COORD_LIMIT - 0.25, fixed.then_some(out_fixed)),
        (F32_COORD_LIMIT, fixed.then_some(out_fixed)),
        (
            common::next_up(F32_COORD_LIMIT),
            Some(if fixed { out_fixed } else { out_f32 }),
        ),
    ];
    for (x, want) in cases {
        for vertex in 0..3 {
            let mut v = ok;
            v[vertex][1] = x;
            let got = Triangle::<S>::from_f32(v).err();
            assert_eq!(
                got,
                want.map(|e| VertexError::new(vertex, e)),
                "{} from_f32 with {x} at v{vertex}",
                S::NAME
            );
        }
    }
}

/// Spheres: a negative radius is field 1, a bad centre field 0, and a sphere whose box leaves
/// the coordinate range (fixed point) field 1.
fn sphere_cases<S: TestScalar>() {
    let good = |i: usize| Sphere::<S> {
        center: p([i as f32 * 3.0, 0.0, 0.0]),
        radius: c(1.0),
    };
    let build = |prims: &[Sphere<S>]| {
        let mut nodes = vec![Node::<S>::EMPTY; nodes_needed(prims.len())];
        let mut ids = vec![0u32; prims.len()];
        Bvh::build(prims, &mut nodes, &mut ids, BuildOptions::default()).map(|b| b.validate())
    };
    let mut prims: Vec<_> = (0..5).map(good).collect();
    prims[3].radius = S::from_f32_saturating(-0.5);
    assert_eq!(
        build(&prims).err(),
        Some(BuildError::BadPrimitive {
            prim: 3,
            vertex: 1,
            error: PointError::NegativeRadius
        }),
        "{}",
        S::NAME
    );
    for (bad, error) in S::bad_coords() {
        let mut prims: Vec<_> = (0..5).map(good).collect();
        prims[2].center[1] = bad;
        assert_eq!(
            build(&prims).err(),
            Some(BuildError::BadPrimitive {
                prim: 2,
                vertex: 0,
                error
            }),
            "{} centre {bad:?}",
            S::NAME
        );
    }
    // A radius of zero is fine.
    let mut prims: Vec<_> = (0..5).map(good).collect();
    prims[0].radius = c(0.0);
    assert!(matches!(build(&prims), Ok(Ok(_))));
    if S::NAME == "fixed" {
        // Centre in range, but the box is not.
        let mut prims: Vec<_> = (0..5).map(good).collect();
        prims[4].center = p([FIXED_COORD_LIMIT - 1.0, 0.0, 0.0]);
        prims[4].radius = c(2.0);
        assert_eq!(
            build(&prims).err(),
            Some(BuildError::BadPrimitive {
                prim: 4,
                vertex: 1,
                error: PointError::OutOfRange {
                    limit: FIXED_COORD_LIMIT
                }
            })
        );
    }
}

/// Leaf sizes outside 1..=MAX_LEAF_SIZE are rejected by value, for every builder.
fn leaf_size_cases<S: TestScalar>() {
    let prims = row::<S>(10);
    for builder in BuilderKind::ALL {
        for bad in [0, MAX_LEAF_SIZE + 1, u32::MAX] {
            let opts = BuildOptions {
                builder,
                max_leaf_size: bad,
                reinsertion: true,
            };
            assert_eq!(
                build_err(&prims, nodes_needed(10), 10, opts),
                BuildError::BadLeafSize { max_leaf_size: bad },
                "{} {builder:?}",
                S::NAME
            );
        }
        let opts = BuildOptions {
            builder,
            max_leaf_size: MAX_LEAF_SIZE,
            reinsertion: true,
        };
        with_bvh::<S, _, _>(&prims, opts, |bvh| {
            let stats = bvh.validate().unwrap();
            assert!(stats.max_leaf_size <= MAX_LEAF_SIZE);
        });
    }
}

fn build_error_cases<S: TestScalar>() {
    arena_cases::<S>();
    bad_vertex_cases::<S>();
    from_f32_cases::<S>();
    sphere_cases::<S>();
    leaf_size_cases::<S>();
}

#[test]
fn bad_build_input_gives_typed_error_f32() {
    build_error_cases::<f32>();
}

#[test]
fn bad_build_input_gives_typed_error_fixed() {
    build_error_cases::<I16F16>();
}

// ---------------------------------------------------------------------------------------------
// Ray errors.

fn ray_error_cases<S: TestScalar>() {
    let from = |o: [f32; 3], d: [f32; 3], t0: f32, t1: f32| Ray::<S>::from_f32(o, d, t0, t1).err();
    let (o, d) = ([1.0, 2.0, 3.0], [0.0, 0.0, 1.0]);
    // Directions.
    for zero in [[0.0, 0.0, 0.0], [-0.0, 0.0, -0.0], [-0.0; 3]] {
        assert_eq!(
            from(o, zero, 0.0, 1.0),
            Some(RayError::ZeroDirection),
            "{} {zero:?}",
            S::NAME
        );
    }
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        for axis in 0..3 {
            let mut dir = [1.0, 1.0, 1.0];
            dir[axis] = bad;
            assert_eq!(
                from(o, dir, 0.0, 1.0),
                Some(RayError::NonFiniteDirection),
                "{} {dir:?}",
                S::NAME
            );
        }
    }
    // Tiny and huge directions are fine: they are normalised in f64 after scaling.
    for dir in [
        [f32::from_bits(1), 0.0, 0.0],
        [f32::MAX, f32::MAX, -f32::MAX],
        [1e-30, -1e-38, 0.0],
    ] {
        assert_eq!(from(o, dir, 0.0, 1.0), None, "{} {dir:?}", S::NAME);
    }
    // Origins.
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        for axis in 0..3 {
            let mut org = o;
            org[axis] = bad;
            assert_eq!(
                from(org, d, 0.0, 1.0),
                Some(RayError::Origin(PointError::NonFinite)),
                "{} {org:?}",
                S::NAME
            );
        }
    }
    let limit = if S::NAME == "fixed" {
        FIXED_COORD_LIMIT
    } else {
        F32_COORD_LIMIT
    };
    let far = common::next_up(limit);
    assert_eq!(
        from([0.0, -far, 0.0], d, 0.0, 1.0),
        Some(RayError::Origin(PointError::OutOfRange { limit })),
        "{}",
        S::NAME
    );
    assert_eq!(
        from([0.0, -limit, limit], d, 0.0, 1.0),
        None,
        "{} origin at the limit",
        S::NAME
    );
    // Intervals (from_f32).
    for (t0, t1) in [
        (f32::NAN, 1.0),
        (0.0, f32::NAN),
        (f32::NAN, f32::NAN),
        (-1.0, 1.0),
        (-f32::from_bits(1), 1.0),
        (2.0, 1.0),
        (f32::INFINITY, f32::INFINITY),
        (f32::NEG_INFINITY, 1.0),
    ] {
        assert_eq!(
            from(o, d, t0, t1),
            Some(RayError::InvalidInterval),
            "{} [{t0}, {t1}]",
            S::NAME
        );
    }
    for (t0, t1) in [
        (0.0, 0.0),
        (-0.0, 0.0),
        (1.0, 1.0),
        (0.0, f32::INFINITY),
        (5.0, 1e30),
    ] {
        assert_eq!(from(o, d, t0, t1), None, "{} [{t0}, {t1}]", S::NAME);
    }
    // The interval is checked before the ray data.
    assert_eq!(
        from([f32::NAN; 3], [0.0; 3], 2.0, 1.0),
        Some(RayError::InvalidInterval)
    );
    // Intervals (with_interval, in the mode).
    let ray = Ray::<S>::from_f32(o, d, 0.0, f32::INFINITY).unwrap();
    let neg = S::from_f32_saturating(-1.0);
    let far_t = S::FAR;
    for (t0, t1) in [(neg, c(1.0)), (c(2.0), c(1.0)), (far_t, far_t)] {
        assert_eq!(
            ray.with_interval(t0, t1).err(),
            Some(RayError::InvalidInterval),
            "{} with_interval({t0:?}, {t1:?})",
            S::NAME
        );
    }
    for (t0, t1) in [(c(0.0), c(0.0)), (c(1.0), far_t), (c(0.5), c(0.5))] {
        let r = ray.with_interval(t0, t1).unwrap();
        assert_eq!((r.t_min(), r.t_max()), (t0, t1));
    }
    // Ray::new in the mode's own vectors.
    let zero = S::array_to_vec([c(0.0); 3]);
    assert_eq!(
        Ray::<S>::new(zero, zero).err(),
        Some(RayError::ZeroDirection)
    );
    for (bad, error) in S::bad_coords() {
        let org = S::array_to_vec([c(0.0), bad, c(0.0)]);
        let dir = S::array_to_vec([c(0.0), c(0.0), c(1.0)]);
        assert_eq!(
            Ray::<S>::new(org, dir).err(),
            Some(RayError::Origin(error)),
            "{} {bad:?}",
            S::NAME
        );
        // Both wrong: the origin is reported first, in every mode.
        let zero = S::array_to_vec([c(0.0); 3]);
        assert_eq!(
            Ray::<S>::new(org, zero).err(),
            Some(RayError::Origin(error)),
            "{}",
            S::NAME
        );
    }
}

#[test]
fn bad_ray_input_gives_typed_error_f32() {
    ray_error_cases::<f32>();
    // NaN and infinite intervals and directions in f32's own type.
    let ray = Ray::<f32>::from_f32([0.0; 3], [1.0, 0.0, 0.0], 0.0, 1.0).unwrap();
    for (t0, t1) in [
        (f32::NAN, 1.0),
        (0.0, f32::NAN),
        (f32::INFINITY, f32::INFINITY),
        (-0.5, 1.0),
    ] {
        assert_eq!(
            ray.with_interval(t0, t1).err(),
            Some(RayError::InvalidInterval),
            "[{t0}, {t1}]"
        );
    }
    let v = raykernel::glam::Vec3::new;
    assert_eq!(
        Ray::<f32>::new(v(0.0, 0.0, 0.0), v(f32::NAN, 0.0, 1.0)).err(),
        Some(RayError::NonFiniteDirection)
    );
    assert_eq!(
        Ray::<f32>::new(v(f32::INFINITY, 0.0, 0.0), v(0.0, 0.0, 1.0)).err(),
        Some(RayError::Origin(PointError::NonFinite))
    );
}

#[test]
fn bad_ray_input_gives_typed_error_fixed() {
    ray_error_cases::<I16F16>();
}

// ---------------------------------------------------------------------------------------------
// Degenerate but valid inputs.

/// The mode's coordinate limit.
fn coord_limit<S: TestScalar>() -> f32 {
    if S::NAME == "fixed" {
        FIXED_COORD_LIMIT
    } else {
        F32_COORD_LIMIT
    }
}

/// Seeded rays around the scene's bounds (origins clamped to `±limit`): random, axis-aligned,
/// and aimed at triangle centroids.
fn probe_rays(tris: &[[[f32; 3]; 3]], count: usize, seed: u64, limit: f32) -> Vec<RaySpec> {
    let mut rng = Rng::new(seed);
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for v in tris.iter().flatten() {
        for i in 0..3 {
            lo[i] = lo[i].min(v[i]);
            hi[i] = hi[i].max(v[i]);
        }
    }
    (0..count)
        .map(|k| {
            let o: [f32; 3] = [0, 1, 2].map(|i| {
                let pad = (hi[i] - lo[i]).max(1.0);
                rng.range(lo[i] - pad, hi[i] + pad).clamp(-limit, limit)
            });
            let d = match k % 3 {
                0 => rng.unit_vec(),
                1 => {
                    let mut d = [0.0; 3];
                    d[rng.below(3)] = if rng.unit() < 0.5 { -1.0 } else { 1.0 };
                    d
                }
                _ => {
                    let [a, b, c] = tris[rng.below(tris.len())];
                    common::dir_to(o, [0, 1, 2].map(|i| (a[i] + b[i] + c[i]) / 3.0))
                }
            };
            RaySpec::new(o, d)
        })
        .collect()
}

/// Every builder and leaf size: the tree validates, is within the depth cap, and answers the
/// probe rays exactly like Linear.
fn check_against_linear<S: TestScalar>(what: &str, v: &[[[f32; 3]; 3]], rays: &[RaySpec]) {
    let prims: Vec<Triangle<S>> = v.iter().map(|&t| Triangle::from_f32(t).unwrap()).collect();
    let linear = Linear::new(&prims);
    let want: Vec<_> = rays
        .iter()
        .map(|r| query(&linear, &r.ray::<S>()).unwrap())
        .collect();
    for options in all_options() {
        with_bvh::<S, _, _>(&prims, options, |bvh| {
            let stats = bvh
                .validate()
                .unwrap_or_else(|e| panic!("{} {what} {options:?}: {e}", S::NAME));
            assert!(
                bvh.depth() as usize <= MAX_DEPTH && stats.depth <= MAX_DEPTH,
                "{} {what} {options:?}: depth {}",
                S::NAME,
                bvh.depth()
            );
            for (r, want) in rays.iter().zip(&want) {
                let got =
                    query(bvh, &r.ray::<S>()).unwrap_or_else(|e| panic!("{what}: {e}, ray {r}"));
                same_hit(&got, want)
                    .unwrap_or_else(|e| panic!("{} {what} {options:?}: {e}, ray {r}", S::NAME));
            }
        });
    }
}

/// No primitives: an empty tree that validates and never hits; arenas may be empty.
fn empty_cases<S: TestScalar>() {
    let prims: [Triangle<S>; 0] = [];
    for options in all_options() {
        let (mut nodes, mut ids) = ([Node::<S>::EMPTY; 0], [0u32; 0]);
        let bvh = Bvh::build(&prims, &mut nodes, &mut ids, options).unwrap();
        let stats = bvh.validate().unwrap();
        assert_eq!((stats.node_count, stats.leaf_count, bvh.depth()), (0, 0, 0));
        let r = RaySpec::new([0.0; 3], [1.0, 2.0, 3.0]).ray::<S>();
        assert_eq!(bvh.intersect(&r), None);
        assert!(!bvh.occluded(&r));
        assert_eq!(bvh.bytes_used(), 0);
    }
}

/// One primitive: a single leaf.
fn single_cases<S: TestScalar>() {
    let v = [[[-1.0, -1.0, 5.0], [3.0, -1.0, 5.0], [-1.0, 3.0, 5.0]]];
    for options in all_options() {
        let prims = [Triangle::<S>::from_f32(v[0]).unwrap()];
        with_bvh::<S, _, _>(&prims, options, |bvh| {
            let stats = bvh.validate().unwrap();
            assert_eq!((stats.node_count, stats.leaf_count, stats.depth), (1, 1, 0));
            let hit = bvh
                .intersect(&RaySpec::new([0.0; 3], [0.0, 0.0, 1.0]).ray::<S>())
                .unwrap();
            assert_eq!(
                (hit.t, hit.prim, hit.u, hit.v),
                (c(5.0), 0, c(0.25), c(0.25))
            );
        });
    }
    check_against_linear::<S>(
        "one triangle",
        &v,
        &probe_rays(&v, 300, 1, coord_limit::<S>()),
    );
}

/// 1000 copies of one triangle: any builder, leaf size 1 included, stays within the depth cap
/// and returns the lowest id on the tie.
fn identical_cases<S: TestScalar>() {
    let v = vec![[[-1.0, -1.0, 5.0], [3.0, -1.0, 5.0], [-1.0, 3.0, 5.0]]; 1000];
    check_against_linear::<S>(
        "1000 identical triangles",
        &v,
        &probe_rays(&v, 60, 2, coord_limit::<S>()),
    );
    let prims: Vec<Triangle<S>> = v.iter().map(|&t| Triangle::from_f32(t).unwrap()).collect();
    for options in all_options() {
        let hit = with_bvh::<S, _, _>(&prims, options, |bvh| {
            bvh.intersect(&RaySpec::new([0.0; 3], [0.0, 0.0, 1.0]).ray::<S>())
        });
        assert_eq!(hit.map(|h| h.prim), Some(0), "{} {options:?}", S::NAME);
    }
}

/// Zero-thickness unit triangles in the planes `axis = 2^(top - j)`, `j < levels` (then
/// `axis = 0`), the axis cycling x, y, z: the midpoint builder peels one triangle per level
/// (the widest centroid extent alternates between the axes), so without the depth cap the
/// tree would be about `3 · levels` deep.
fn exponential_scene(n: usize, top: i32, levels: usize) -> Vec<[[f32; 3]; 3]> {
    (0..n)
        .map(|i| {
            let (axis, j) = (i % 3, i / 3);
            let x = if j < levels {
                2f32.powi(top - j as i32)
            } else {
                0.0
            };
            let mut base = [0.0; 3];
            base[axis] = x;
            let (mut b, mut c) = (base, base);
            b[(axis + 1) % 3] = 1.0;
            c[(axis + 2) % 3] = 1.0;
            [base, b, c]
        })
        .collect()
}

fn depth_cap_cases<S: TestScalar>(top: i32, levels: usize) {
    let v = exponential_scene(5000, top, levels);
    let mut rays = probe_rays(&v, 200, 3, coord_limit::<S>());
    // Along each axis through the planes, from below and from the top plane downwards.
    for axis in 0..3 {
        for (lo, a, b) in [
            (-1.0, 0.25, 0.25),
            (0.5, 0.1, 0.1),
            (-1.0, 0.0, 0.0),
            (-1.0, 0.5, 0.5),
        ] {
            let mut o = [0.0; 3];
            o[axis] = lo;
            o[(axis + 1) % 3] = a;
            o[(axis + 2) % 3] = b;
            let mut d = [0.0; 3];
            d[axis] = 1.0;
            rays.push(RaySpec::new(o, d));
            o[axis] = 2f32.powi(top);
            d[axis] = -1.0;
            rays.push(RaySpec::new(o, d));
        }
    }
    check_against_linear::<S>("exponential centroids", &v, &rays);
    let prims: Vec<Triangle<S>> = v.iter().map(|&t| Triangle::from_f32(t).unwrap()).collect();
    // The builder's own depth (reinsertion, which may only keep within the cap, is checked
    // above through `all_options`).
    for max_leaf_size in [1, 4] {
        let opts = BuildOptions {
            builder: BuilderKind::Midpoint,
            max_leaf_size,
            reinsertion: false,
        };
        with_bvh::<S, _, _>(&prims, opts, |bvh| {
            let depth = bvh.depth() as usize;
            println!(
                "{}: midpoint/{max_leaf_size} depth {depth} (cap {MAX_DEPTH})",
                S::NAME
            );
            assert!(depth <= MAX_DEPTH, "{} depth {depth}", S::NAME);
            // The input really is pathological: the cap, not the data, bounds the depth.
            assert!(
                depth > MEDIAN_FALLBACK_DEPTH,
                "{} depth {depth}: input too tame",
                S::NAME
            );
        });
    }
}

fn degenerate_input_cases<S: TestScalar>() {
    empty_cases::<S>();
    single_cases::<S>();
    identical_cases::<S>();
}

#[test]
fn empty_single_and_identical_builds_are_valid_f32() {
    degenerate_input_cases::<f32>();
}

#[test]
fn empty_single_and_identical_builds_are_valid_fixed() {
    degenerate_input_cases::<I16F16>();
}

#[test]
fn depth_stays_capped_for_exponential_centroids_f32() {
    // 2^40 down to 2^-109 (normal f32 values); the rest at 0.
    depth_cap_cases::<f32>(40, 150);
}

#[test]
fn depth_stays_capped_for_exponential_centroids_fixed() {
    // 2^13 down to 2^-16 (one raw unit); the rest at 0.
    depth_cap_cases::<I16F16>(13, 30);
}
