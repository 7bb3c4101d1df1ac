//! The 4-wide BVH beyond the random differential tests of `properties.rs`:
//! - `Numerics::slab4` gives, box by box, exactly `Numerics::slab`'s decisions and entry bits
//!   (random boxes and rays, zero and signed-zero direction components, origins on box
//!   planes, flat boxes, intervals);
//! - why unused slots are masked by their count rather than by an "empty" box: the slab test
//!   accepts an inverted box for some ray;
//! - the collapse: arena sizes (`nodes4_needed` is reached, one slot less is a typed error),
//!   empty and one-primitive scenes, leaf order, and a deeper tree (a 5120-triangle sphere)
//!   answering like the BVH2 and brute force bit for bit in both modes.

mod common;

use common::{
    c, query, same_hit, with_bvh, with_bvh4, with_bvh_in_leaf_order, RaySpec, TestScalar,
    LEAF_SIZES,
};
use raykernel::bvh::{nodes_needed, BuildOptions, BuilderKind};
use raykernel::bvh4::nodes4_needed;
use raykernel::Arena;
use raykernel::{Aabb, Accel, BuildError, Bvh, Bvh4, Linear, Node, Node4, Ray, Triangle, I16F16};
use raykernel_testkit::icosphere::unit_icosphere;
use raykernel_testkit::Rng;

fn tri<S: TestScalar>(v: [[f32; 3]; 3]) -> Triangle<S> {
    Triangle::from_f32(v).unwrap_or_else(|e| panic!("{} {v:?}: {e:?}", S::NAME))
}

// ---------------------------------------------------------------------------------------------
// slab4 == slab, box by box

/// A random ray direction with some components +0 or -0 (never all zero).
fn direction(rng: &mut Rng) -> [f32; 3] {
    let mut d = rng.unit_vec();
    for x in &mut d {
        match rng.below(5) {
            0 => *x = 0.0,
            1 => *x = -0.0,
            _ => {}
        }
    }
    if d.iter().all(|&x| x == 0.0) {
        d[rng.below(3)] = if rng.below(2) == 0 { 1.0 } else { -1.0 };
    }
    d
}

// Fixed point's 4-wide box test runs in `f32` lanes where there are vector lanes and is
// conservative rather than equal to `slab` there: tested against exact rational distances in
// `scalar/fixed.rs` (`slab4_is_conservative_and_tight`). Elsewhere it is `slab` per box.

fn slab4_cases<S: TestScalar>() {
    let mut rng = Rng::new(0x51ab_4444);
    let (mut accepted, mut rejected) = (0usize, 0usize);
    for case in 0..40_000 {
        // Quarter-valued origins, so box planes can sit exactly on them.
        let o = [0, 1, 2].map(|_| (rng.range(-20.0, 20.0) * 4.0).round() / 4.0);
        let d = direction(&mut rng);
        let (t_min, t_max) = match rng.below(4) {
            0 | 1 => (0.0, f32::INFINITY),
            2 => (rng.range(0.0, 10.0), f32::INFINITY),
            _ => {
                let a = rng.range(0.0, 30.0);
                (a, a + rng.range(0.0, 30.0))
            }
        };
        let ray = Ray::<S>::from_f32(o, d, t_min, t_max).unwrap();
        let mut lo = [[S::ZERO; 4]; 3];
        let mut hi = [[S::ZERO; 4]; 3];
        for b in 0..4 {
            for k in 0..3 {
                // Planes on the origin (rays in a face), random quarters, arbitrary values,
                // and flat boxes (lo == hi).
                let pick = |rng: &mut Rng| match rng.below(5) {
                    0 => o[k],
                    1 | 2 => (rng.range(-25.0, 25.0) * 4.0).round() / 4.0,
                    _ => rng.range(-25.0, 25.0),
                };
                let a = pick(&mut rng);
                let bb = if rng.below(6) == 0 { a } else { pick(&mut rng) };
                lo[k][b] = c::<S>(a.min(bb));
                hi[k][b] = c::<S>(a.max(bb));
            }
        }
        let (t_lo, t_hi) = (ray.t_min(), ray.t_max());
        let (mask, t) = S::slab4(ray.data(), &lo, &hi, t_lo, t_hi);
        assert!(mask < 16, "{} case {case}: mask {mask:#b}", S::NAME);
        for b in 0..4 {
            let l = [lo[0][b], lo[1][b], lo[2][b]];
            let h = [hi[0][b], hi[1][b], hi[2][b]];
            let want = S::slab(ray.data(), &l, &h, t_lo, t_hi);
            let got = (mask & (1 << b) != 0).then_some(t[b]);
            assert_eq!(
                got.map(|x| x.bits()),
                want.map(|x| x.bits()),
                "{} case {case} box {b}: origin {o:?} dir {d:?} (bits {:x?}) t [{t_min}, {t_max}] \
                 box {l:?} {h:?}",
                S::NAME,
                d.map(f32::to_bits)
            );
            if want.is_some() {
                accepted += 1;
            } else {
                rejected += 1;
            }
        }
    }
    // Both outcomes are well represented.
    assert!(
        accepted > 20_000 && rejected > 20_000,
        "{accepted} {rejected}"
    );
}

#[test]
fn slab4_equals_slab_per_box_f32() {
    slab4_cases::<f32>();
}

/// Rays along the axes with ±0 components, on and off the faces of a unit box: every slab4
/// lane agrees with slab (the 0 · inf = NaN paths of `f32`).
fn slab4_axis_cases<S: TestScalar>() {
    let boxes: [([f32; 3], [f32; 3]); 4] = [
        ([0.0, 0.0, 0.0], [1.0, 1.0, 1.0]),
        ([0.0, 0.0, 0.0], [0.0, 1.0, 1.0]),
        ([-1.0, 1.0, 0.0], [0.0, 1.0, 2.0]),
        ([1.0, 1.0, 1.0], [1.0, 1.0, 1.0]),
    ];
    let mut lo = [[S::ZERO; 4]; 3];
    let mut hi = [[S::ZERO; 4]; 3];
    for (b, (l, h)) in boxes.iter().enumerate() {
        for k in 0..3 {
            lo[k][b] = c::<S>(l[k]);
            hi[k][b] = c::<S>(h[k]);
        }
    }
    let coords = [-1.0, 0.0, 0.5, 1.0, 2.0];
    for &x in &coords {
        for &y in &coords {
            for &z in &coords {
                for axis in 0..3 {
                    for sign in [1.0f32, -1.0] {
                        for zeros in [0.0f32, -0.0] {
                            let mut d = [zeros; 3];
                            d[axis] = sign;
                            let ray = Ray::<S>::from_f32([x, y, z], d, 0.0, f32::INFINITY).unwrap();
                            let (mask, t) =
                                S::slab4(ray.data(), &lo, &hi, ray.t_min(), ray.t_max());
                            for b in 0..4 {
                                let l = [lo[0][b], lo[1][b], lo[2][b]];
                                let h = [hi[0][b], hi[1][b], hi[2][b]];
                                let want = S::slab(ray.data(), &l, &h, ray.t_min(), ray.t_max());
                                let got = (mask & (1 << b) != 0).then_some(t[b]);
                                assert_eq!(
                                    got.map(|v| v.bits()),
                                    want.map(|v| v.bits()),
                                    "{} origin {:?} dir {d:?} box {b}",
                                    S::NAME,
                                    [x, y, z]
                                );
                            }
                        }
                    }
                }
            }
        }
    }
}

#[test]
fn slab4_equals_slab_on_axis_rays_f32() {
    slab4_axis_cases::<f32>();
}

/// The reason unused slots are masked by `count`: an inverted box (`lo = +inf`, `hi = -inf`)
/// is not empty to the slab test, whose `min`/`max` swap its planes. A ray along +x from the
/// origin enters it.
#[test]
fn slab_accepts_an_inverted_infinite_box_so_unused_slots_need_a_mask() {
    let ray = Ray::<f32>::from_f32([0.0; 3], [1.0, 0.0, 0.0], 0.0, f32::INFINITY).unwrap();
    let lo = [f32::INFINITY; 3];
    let hi = [f32::NEG_INFINITY; 3];
    assert!(Aabb::new(lo, hi).slab(&ray).is_some());
}

// ---------------------------------------------------------------------------------------------
// Collapse: sizes, errors, small scenes

/// `n` unit triangles along x, one per unit step.
fn row<S: TestScalar>(n: usize) -> Vec<Triangle<S>> {
    (0..n)
        .map(|i| {
            let x = i as f32 * 2.0;
            tri::<S>([[x, 0.0, 5.0], [x + 1.0, 0.0, 5.0], [x, 1.0, 5.0]])
        })
        .collect()
}

fn collapse_size_cases<S: TestScalar>() {
    // Too small by one: a typed error naming the exact bound, for every size.
    for n in [1usize, 2, 5, 8, 13, 100] {
        let tris = row::<S>(n);
        let options = BuildOptions {
            max_leaf_size: 1,
            ..BuildOptions::default()
        };
        with_bvh::<S, _, _>(&tris, options, |bvh| {
            let needed = nodes4_needed(n);
            let mut short = vec![Node4::<S>::EMPTY; needed - 1];
            assert_eq!(
                Bvh4::collapse(bvh, &mut short).err(),
                Some(BuildError::ArenaTooSmall {
                    arena: Arena::Nodes,
                    needed,
                    available: needed - 1,
                }),
                "{} n = {n}",
                S::NAME
            );
            with_bvh4(bvh, |wide| {
                let stats = wide.validate().unwrap();
                assert!(stats.node_count <= needed);
                assert_eq!(wide.bytes_used(), stats.node_count * 128 + n * 4);
            });
        });
    }
    // The bound is reached: a perfect binary tree of 8 leaves collapses into 5 wide nodes.
    let tris = row::<S>(8);
    let options = BuildOptions {
        builder: BuilderKind::Median,
        max_leaf_size: 1,
        reinsertion: false,
    };
    with_bvh::<S, _, _>(&tris, options, |bvh| {
        assert_eq!(bvh.depth(), 3);
        with_bvh4(bvh, |wide| {
            assert_eq!(wide.nodes().len(), nodes4_needed(8));
            assert_eq!(wide.nodes().len(), 5);
            assert_eq!(wide.validate().unwrap().depth, 1);
        });
    });
}

#[test]
fn collapse_arena_sizes_and_errors_f32() {
    collapse_size_cases::<f32>();
}

#[test]
fn collapse_arena_sizes_and_errors_fixed() {
    collapse_size_cases::<I16F16>();
}

#[test]
fn nodes4_needed_values_and_growth() {
    let known = [
        (0, 0),
        (1, 1),
        (2, 1),
        (4, 1),
        (5, 2),
        (7, 4),
        (8, 5),
        (14, 9),
    ];
    for (n, w) in known {
        assert_eq!(nodes4_needed(n), w, "n = {n}");
    }
    let mut prev = 0;
    for n in 0..200_000 {
        let w = nodes4_needed(n);
        assert!(
            w >= prev && w <= n.max(1) && 3 * w <= 2 * n + 3,
            "n = {n}: {w}"
        );
        prev = w;
    }
    // Large counts do not overflow.
    let _ = nodes4_needed(usize::MAX);
}

fn small_scene_cases<S: TestScalar>() {
    let r = RaySpec::new([0.25, 0.25, 0.0], [0.0, 0.0, 1.0]).ray::<S>();
    // No primitives: no nodes, every ray misses.
    let none: Vec<Triangle<S>> = Vec::new();
    let mut nodes: Vec<Node<S>> = Vec::new();
    let mut ids: Vec<u32> = Vec::new();
    let bvh = Bvh::build(&none, &mut nodes, &mut ids, BuildOptions::default()).unwrap();
    let mut wide_nodes: Vec<Node4<S>> = Vec::new();
    let wide = Bvh4::collapse(&bvh, &mut wide_nodes).unwrap();
    assert!(wide.nodes().is_empty());
    assert_eq!(wide.validate().unwrap().node_count, 0);
    assert!(wide.intersect(&r).is_none() && !wide.occluded(&r));

    // One primitive: a root with one leaf child.
    let one = row::<S>(1);
    let mut nodes = vec![Node::<S>::EMPTY; nodes_needed(1)];
    let mut ids = vec![0u32; 1];
    let bvh = Bvh::build(&one, &mut nodes, &mut ids, BuildOptions::default()).unwrap();
    let mut wide_nodes = vec![Node4::<S>::EMPTY; nodes4_needed(1)];
    let wide = Bvh4::collapse(&bvh, &mut wide_nodes).unwrap();
    assert_eq!(wide.nodes().len(), 1);
    assert_eq!(wide.nodes()[0].child_count(), 1);
    let stats = wide.validate().unwrap();
    assert_eq!((stats.leaf_count, stats.depth), (1, 0));
    let hit = wide.intersect(&r).unwrap();
    assert_eq!((hit.t.bits(), hit.prim), (c::<S>(5.0).bits(), 0));
    assert!(wide.occluded(&r));
    let miss = RaySpec::new([0.25, 0.25, 0.0], [0.0, 0.0, -1.0]).ray::<S>();
    assert!(wide.intersect(&miss).is_none() && !wide.occluded(&miss));
}

#[test]
fn empty_and_one_primitive_scenes_f32() {
    small_scene_cases::<f32>();
}

#[test]
fn empty_and_one_primitive_scenes_fixed() {
    small_scene_cases::<I16F16>();
}

// ---------------------------------------------------------------------------------------------
// A deeper tree: a closed sphere of 5120 triangles, every builder and leaf size, leaf order

fn sphere<S: TestScalar>(radius: f64) -> Vec<Triangle<S>> {
    let (verts, faces) = unit_icosphere(4);
    faces
        .iter()
        .map(|f| tri::<S>(f.map(|i| verts[i as usize].map(|x| (x * radius) as f32))))
        .collect()
}

fn sphere_rays(seed: u64, count: usize) -> Vec<RaySpec> {
    let mut rng = Rng::new(seed);
    (0..count)
        .map(|i| {
            let o = if i % 3 == 0 {
                rng.in_ball(5.0)
            } else {
                rng.unit_vec().map(|x| x * 30.0)
            };
            let d = if i % 5 == 0 {
                direction(&mut rng)
            } else {
                common::dir_to(o, rng.in_ball(9.0))
            };
            let r = RaySpec::new(o, d);
            if i % 7 == 0 {
                r.interval(rng.range(0.0, 20.0), rng.range(20.0, 40.0))
            } else {
                r
            }
        })
        .collect()
}

fn deep_tree_cases<S: TestScalar>() {
    let tris = sphere::<S>(10.0);
    let rays = sphere_rays(0xb0b4, 600);
    let linear = Linear::new(&tris);
    let want: Vec<_> = rays
        .iter()
        .map(|r| query(&linear, &r.ray::<S>()).unwrap())
        .collect();
    for builder in BuilderKind::ALL {
        for max_leaf_size in LEAF_SIZES {
            let options = BuildOptions {
                builder,
                max_leaf_size,
                reinsertion: true,
            };
            with_bvh::<S, _, _>(&tris, options, |bvh| {
                with_bvh4(bvh, |wide| {
                    let stats = wide.validate().unwrap();
                    assert!(stats.node_count <= nodes4_needed(tris.len()));
                    assert!(stats.depth <= bvh.depth() as usize);
                    for (r, w) in rays.iter().zip(&want) {
                        let got = query(wide, &r.ray::<S>()).unwrap();
                        same_hit(&got, w)
                            .unwrap_or_else(|e| panic!("{} {options:?}: {e}, ray {r}", S::NAME));
                    }
                });
            });
            // Leaf order: the same answers through permuted primitives.
            let mut own = tris.clone();
            with_bvh_in_leaf_order(&mut own, options, |bvh| {
                with_bvh4(bvh, |wide| {
                    assert!(wide.is_leaf_order());
                    wide.validate().unwrap();
                    for (r, w) in rays.iter().zip(&want) {
                        let got = query(wide, &r.ray::<S>()).unwrap();
                        same_hit(&got, w).unwrap_or_else(|e| {
                            panic!("{} leaf order {options:?}: {e}, ray {r}", S::NAME)
                        });
                    }
                })
            });
        }
    }
}

#[test]
fn deep_tree_answers_like_brute_force_f32() {
    deep_tree_cases::<f32>();
}

#[test]
fn deep_tree_answers_like_brute_force_fixed() {
    deep_tree_cases::<I16F16>();
}
