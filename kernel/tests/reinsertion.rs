//! The BVH's reinsertion pass: it lowers the tree's SAH cost on scenes a top-down build splits
//! badly, keeps every answer bit for bit, honours the depth cap, and leaves the tree exactly as
//! built when the arena has no spare room for its bookkeeping.

mod common;

use common::{query, same_hit, with_bvh, RaySpec, TestScalar};
use raykernel::bvh::{BuildOptions, BuilderKind};
use raykernel::{Bvh, Linear, Node, Scalar, Triangle, I16F16};
use raykernel_testkit::Rng;

/// Summed half surface area of the inner nodes: the cost reinsertion lowers.
fn inner_area<S: Scalar, P: raykernel::Primitive<S>>(bvh: &Bvh<'_, S, P>) -> f64 {
    let half_area = |n: &Node<S>| {
        let b = n.bounds();
        let d: [f64; 3] =
            core::array::from_fn(|i| f64::from(b.hi[i].to_f32()) - f64::from(b.lo[i].to_f32()));
        d[0] * d[1] + d[1] * d[2] + d[2] * d[0]
    };
    let inner = bvh.nodes().iter().enumerate();
    inner
        .filter(|&(slot, n)| slot != 1 && !n.is_leaf())
        .map(|(_, n)| half_area(n))
        .sum()
}

/// Bundles of three long thin triangles ("sticks") in random directions, crossing each
/// other: the kind of geometry (beams, pipes, chair legs) on which top-down splits leave large
/// overlapping boxes. Bundles keep leaves above one primitive, so the arena has the spare room
/// the pass needs.
fn sticks(rng: &mut Rng, count: usize) -> Vec<[[f32; 3]; 3]> {
    let mut out = Vec::with_capacity(count);
    while out.len() < count {
        let a: [f32; 3] = core::array::from_fn(|_| rng.range(-8.0, 8.0));
        let axis = (rng.next_u64() % 3) as usize;
        let mut b = a;
        b[axis] += rng.range(-6.0, 6.0);
        let mut c = a;
        c[(axis + 1) % 3] += rng.range(-0.2, 0.2);
        c[axis] += rng.range(-0.2, 0.2);
        for k in 0..3 {
            let shift = |mut v: [f32; 3]| {
                v[(axis + 2) % 3] += 0.01 * k as f32;
                v
            };
            out.push([shift(a), shift(b), shift(c)]);
        }
    }
    out.truncate(count);
    out
}

fn options(reinsertion: bool, max_leaf_size: u32) -> BuildOptions {
    BuildOptions {
        builder: BuilderKind::Sah,
        max_leaf_size,
        reinsertion,
    }
}

fn lowers_cost_and_keeps_answers<S: TestScalar>() {
    let mut rng = Rng::new(0x5eed_0001);
    let (mut improved, scenes) = (0, 24);
    for scene in 0..scenes {
        let count = 50 + scene * 40;
        let prims: Vec<Triangle<S>> = sticks(&mut rng, count)
            .iter()
            .map(|&t| Triangle::from_f32(t).unwrap())
            .collect();
        let rays: Vec<RaySpec> = (0..400)
            .map(|_| {
                let o = core::array::from_fn(|_| rng.range(-12.0, 12.0));
                let d = core::array::from_fn(|_| rng.range(-1.0, 1.0));
                RaySpec::new(o, d)
            })
            .collect();
        let linear = Linear::new(&prims);
        let want: Vec<_> = rays
            .iter()
            .map(|r| query(&linear, &r.ray::<S>()).unwrap())
            .collect();
        let before = with_bvh::<S, _, _>(&prims, options(false, 4), |bvh| inner_area(bvh));
        let after = with_bvh::<S, _, _>(&prims, options(true, 4), |bvh| {
            bvh.validate()
                .unwrap_or_else(|e| panic!("{} scene {scene}: {e}", S::NAME));
            for (r, want) in rays.iter().zip(&want) {
                let got = query(bvh, &r.ray::<S>()).unwrap();
                same_hit(&got, want)
                    .unwrap_or_else(|e| panic!("{} scene {scene}: {e}, ray {r}", S::NAME));
            }
            inner_area(bvh)
        });
        assert!(
            after <= before * (1.0 + 1e-6),
            "{} scene {scene} ({count} sticks): cost rose from {before} to {after}",
            S::NAME
        );
        if after < before {
            improved += 1;
        }
    }
    println!(
        "{}: reinsertion lowered the cost on {improved} of {scenes} scenes",
        S::NAME
    );
    assert!(
        improved * 3 >= scenes * 2,
        "{}: only {improved} of {scenes} scenes improved",
        S::NAME
    );
}

#[test]
fn reinsertion_lowers_the_cost_and_keeps_every_answer_f32() {
    lowers_cost_and_keeps_answers::<f32>();
}

#[test]
fn reinsertion_lowers_the_cost_and_keeps_every_answer_fixed() {
    lowers_cost_and_keeps_answers::<I16F16>();
}

/// With one primitive per leaf the tree fills the arena (`2n` slots): no room for the pass's
/// bookkeeping, so the tree is exactly the builder's.
fn skipped_without_room<S: TestScalar>() {
    let mut rng = Rng::new(0x5eed_0002);
    let prims: Vec<Triangle<S>> = sticks(&mut rng, 300)
        .iter()
        .map(|&t| Triangle::from_f32(t).unwrap())
        .collect();
    let tree = |reinsertion| {
        with_bvh::<S, _, _>(&prims, options(reinsertion, 1), |bvh| {
            (bvh.nodes().to_vec(), bvh.prim_ids().to_vec(), bvh.depth())
        })
    };
    let (with, without) = (tree(true), tree(false));
    assert_eq!(with.0.len(), 600, "{}: expected a full arena", S::NAME);
    assert!(with == without, "{}: the tree changed", S::NAME);
}

#[test]
fn reinsertion_is_skipped_without_spare_arena_f32() {
    skipped_without_room::<f32>();
}

#[test]
fn reinsertion_is_skipped_without_spare_arena_fixed() {
    skipped_without_room::<I16F16>();
}
