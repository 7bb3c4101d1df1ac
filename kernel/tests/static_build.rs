//! Build settings named at compile time (`StaticBuild`) give, bit for bit, the tree the run-time
//! `BuildOptions` with the same split rule, reinsertion and leaf size give, in both modes.

mod common;

use common::TestScalar;
use raykernel::bvh::{
    nodes_needed, BuildOptions, BuildSettings, BuilderKind, Median, Midpoint, Sah, StaticBuild,
};
use raykernel::{Bvh, Node, Triangle, I16F16};
use raykernel_testkit::Rng;

/// Random triangles in a box, some large and overlapping, some tiny: every rule splits them
/// differently, and reinsertion has work to do.
fn soup<S: TestScalar>(rng: &mut Rng, n: usize) -> Vec<Triangle<S>> {
    (0..n)
        .map(|i| {
            let c = [
                rng.range(-8.0, 8.0),
                rng.range(-8.0, 8.0),
                rng.range(-8.0, 8.0),
            ];
            let size = if i % 7 == 0 { 4.0 } else { 0.3 };
            let v = core::array::from_fn(|_| {
                let o = rng.in_ball(size);
                [c[0] + o[0], c[1] + o[1], c[2] + o[2]]
            });
            Triangle::from_f32(v).unwrap()
        })
        .collect()
}

/// A node as the bits of its box, `first` and `count`.
type NodeBits = ([u32; 6], u32, u32);

/// The tree's nodes, ids and depth.
fn tree<S: TestScalar, B: BuildSettings>(
    tris: &[Triangle<S>],
    settings: B,
) -> (Vec<NodeBits>, Vec<u32>, u32) {
    let mut nodes = vec![Node::<S>::EMPTY; nodes_needed(tris.len())];
    let mut ids = vec![0u32; tris.len()];
    let bvh = Bvh::build(tris, &mut nodes, &mut ids, settings).unwrap();
    let bits = |n: &Node<S>| {
        let b = n.bounds();
        let c = |x: S| x.bits();
        (
            [
                c(b.lo[0]),
                c(b.lo[1]),
                c(b.lo[2]),
                c(b.hi[0]),
                c(b.hi[1]),
                c(b.hi[2]),
            ],
            n.first(),
            n.count(),
        )
    };
    (
        bvh.nodes().iter().map(bits).collect(),
        bvh.prim_ids().to_vec(),
        bvh.depth(),
    )
}

fn same_trees<S: TestScalar>() {
    let mut rng = Rng::new(0x0057_A71C);
    for n in [1, 2, 3, 17, 200, 1500] {
        let tris = soup::<S>(&mut rng, n);
        for leaf in [1, 3, 8] {
            let options = |builder, reinsertion| BuildOptions {
                builder,
                max_leaf_size: leaf,
                reinsertion,
            };
            let case = |b: BuilderKind, r: bool| format!("{} n={n} leaf={leaf} {b:?} {r}", S::NAME);
            let pairs = [
                (
                    tree(&tris, options(BuilderKind::Sah, false)),
                    tree(&tris, StaticBuild::<Sah, false>::new(leaf)),
                    case(BuilderKind::Sah, false),
                ),
                (
                    tree(&tris, options(BuilderKind::Sah, true)),
                    tree(&tris, StaticBuild::<Sah, true>::new(leaf)),
                    case(BuilderKind::Sah, true),
                ),
                (
                    tree(&tris, options(BuilderKind::Median, false)),
                    tree(&tris, StaticBuild::<Median, false>::new(leaf)),
                    case(BuilderKind::Median, false),
                ),
                (
                    tree(&tris, options(BuilderKind::Median, true)),
                    tree(&tris, StaticBuild::<Median, true>::new(leaf)),
                    case(BuilderKind::Median, true),
                ),
                (
                    tree(&tris, options(BuilderKind::Midpoint, false)),
                    tree(&tris, StaticBuild::<Midpoint, false>::new(leaf)),
                    case(BuilderKind::Midpoint, false),
                ),
                (
                    tree(&tris, options(BuilderKind::Midpoint, true)),
                    tree(&tris, StaticBuild::<Midpoint, true>::new(leaf)),
                    case(BuilderKind::Midpoint, true),
                ),
            ];
            for (run_time, compile_time, case) in &pairs {
                assert!(run_time == compile_time, "{case}");
            }
            // The rules really differ here (reinsertion needs spare arena slots: leaves of
            // more than one), so the comparison above can tell them apart.
            if n >= 200 && leaf > 1 {
                assert!(pairs[0].0 != pairs[2].0, "n={n} leaf={leaf}: sah = median");
                let reinserted = (0..3).any(|k| pairs[2 * k].0 != pairs[2 * k + 1].0);
                assert!(reinserted, "n={n} leaf={leaf}: reinsertion changed nothing");
            }
        }
    }
}

#[test]
fn static_settings_build_the_run_time_trees_f32() {
    same_trees::<f32>();
}

#[test]
fn static_settings_build_the_run_time_trees_fixed() {
    same_trees::<I16F16>();
}

#[test]
fn static_settings_refuse_bad_leaf_sizes_as_the_run_time_ones() {
    let tris = soup::<f32>(&mut Rng::new(3), 10);
    let mut nodes = vec![Node::<f32>::EMPTY; nodes_needed(tris.len())];
    let mut ids = vec![0u32; tris.len()];
    for leaf in [0, raykernel::bvh::MAX_LEAF_SIZE + 1] {
        let want = Bvh::build(
            &tris,
            &mut nodes,
            &mut ids,
            BuildOptions {
                max_leaf_size: leaf,
                ..BuildOptions::default()
            },
        )
        .err();
        let got = Bvh::build(
            &tris,
            &mut nodes,
            &mut ids,
            StaticBuild::<Sah, true>::new(leaf),
        )
        .err();
        assert!(want.is_some() && got == want, "leaf {leaf}: {got:?}");
    }
}

/// A renderer whose BVH family names its settings at compile time renders every built-in scene
/// to the bytes of the run-time default, in both modes.
#[test]
fn static_family_renders_the_default_bytes() {
    use raykernel::render::{scenes, AllFeatures};
    use raykernel::BvhFamily;
    use raykernel_testkit::golden::{render_hash, render_hash_with, Bits, EMITTERS};

    fn check<S: Bits + raykernel::Scalar>() {
        for data in [scenes::CORNELL, scenes::SPHERES, scenes::MOTION, EMITTERS] {
            let want = render_hash::<S>(&data).unwrap();
            let got = render_hash_with::<S, BvhFamily<StaticBuild<Sah, false>>, AllFeatures>(
                &data,
                StaticBuild::default(),
            );
            assert_eq!(got.unwrap(), want, "{}", data.name);
            let got = render_hash_with::<S, BvhFamily<StaticBuild<Median, true>>, AllFeatures>(
                &data,
                StaticBuild::new(1),
            );
            assert_eq!(got.unwrap(), want, "{}", data.name);
        }
    }
    check::<f32>();
    check::<I16F16>();
}
