//! The two compiled copies of each wide BVH's traversal (`raykernel::cpu`; the 8-wide one's
//! AVX2 copy tests its boxes in 256-bit lanes) answer every query with the same bits, in both
//! modes and with and without leaf order, and the AVX2 copy is chosen exactly where the
//! standard library's feature detection finds its features. One test, in its own binary: it
//! switches the process-wide choice.

mod common;

use common::{dir_to, hit_bits, with_bvh, with_bvh_in_leaf_order, with_wide, RaySpec, TestScalar};
use raykernel::bvh::BuildOptions;
use raykernel::cpu::{set_traversal_simd, traversal_simd, Simd};
use raykernel::{Accel, Triangle, WideBvh, I16F16};
use raykernel_testkit::icosphere::unit_icosphere;
use raykernel_testkit::Rng;

/// A closed sphere of 5120 triangles, inside a cloud of 1500 small random triangles that cross
/// it and each other (nodes with three or more children hit, leaves to be popped again).
fn scene<S: TestScalar>() -> Vec<Triangle<S>> {
    let (verts, faces) = unit_icosphere(4);
    let mut tris: Vec<[[f32; 3]; 3]> = faces
        .iter()
        .map(|f| f.map(|i| verts[i as usize].map(|x| (x * 6.0) as f32)))
        .collect();
    let mut rng = Rng::new(0xc0de_a512);
    for _ in 0..1500 {
        let a = rng.in_ball(9.0);
        let corner = |rng: &mut Rng| {
            let e = rng.in_ball(1.5);
            [a[0] + e[0], a[1] + e[1], a[2] + e[2]]
        };
        tris.push([a, corner(&mut rng), corner(&mut rng)]);
    }
    tris.iter()
        .map(|&v| Triangle::from_f32(v).unwrap_or_else(|e| panic!("{v:?}: {e:?}")))
        .collect()
}

/// Rays from outside, inside and within the cloud, some axis-aligned, some with a bounded
/// interval.
fn rays() -> Vec<RaySpec> {
    let mut rng = Rng::new(0x5eed_a512);
    (0..20_000)
        .map(|i| {
            let o = match i % 3 {
                0 => rng.in_ball(4.0),
                1 => rng.in_ball(10.0),
                _ => rng.unit_vec().map(|x| x * 30.0),
            };
            let d = match i % 7 {
                0 => {
                    let mut d = [0.0; 3];
                    d[rng.below(3)] = if rng.below(2) == 0 { 1.0 } else { -1.0 };
                    d
                }
                _ => dir_to(o, rng.in_ball(8.0)),
            };
            let spec = RaySpec::new(o, d);
            if i % 5 == 0 {
                let t = rng.range(0.0, 20.0);
                spec.interval(t, t + rng.range(0.0, 20.0))
            } else {
                spec
            }
        })
        .collect()
}

/// Every ray's closest hit (t, primitive, barycentrics, as bits) and any-hit answer, traced
/// in the instruction set in effect.
type Answers = Vec<(Option<(u32, u32, u32, u32)>, bool)>;

/// [`Answers`] of the `W`-wide BVH over [`scene`].
fn answers<const W: usize, S: TestScalar>(rays: &[RaySpec], leaf_order: bool) -> Answers
where
    for<'a> WideBvh<'a, S, Triangle<S>, W>: Accel<S>,
{
    let trace = |wide: &WideBvh<'_, S, Triangle<S>, W>| -> Answers {
        rays.iter()
            .map(|spec| {
                let ray = spec.ray::<S>();
                (hit_bits(&wide.intersect(&ray)), wide.occluded(&ray))
            })
            .collect()
    };
    let mut tris = scene::<S>();
    let options = BuildOptions::default();
    if leaf_order {
        with_bvh_in_leaf_order(&mut tris, options, |bvh| with_wide(bvh, trace))
    } else {
        with_bvh(&tris, options, |bvh| with_wide(bvh, trace))
    }
}

/// All five features the AVX2 copy is compiled for, and the registers' OS support, as the
/// standard library detects them.
#[cfg(target_arch = "x86_64")]
fn std_detects_avx2() -> bool {
    std::is_x86_feature_detected!("avx2")
        && std::is_x86_feature_detected!("bmi1")
        && std::is_x86_feature_detected!("bmi2")
        && std::is_x86_feature_detected!("lzcnt")
        && std::is_x86_feature_detected!("popcnt")
}

#[cfg(not(target_arch = "x86_64"))]
fn std_detects_avx2() -> bool {
    false
}

#[test]
fn both_copies_answer_alike_and_avx2_runs_where_detected() {
    let two_copies = cfg!(all(target_arch = "x86_64", not(target_feature = "avx2")));
    let compiled_avx2 = cfg!(all(target_arch = "x86_64", target_feature = "avx2"));
    // Detection, before anything is requested.
    let detected = traversal_simd();
    assert_eq!(
        detected == Simd::Avx2,
        std_detects_avx2(),
        "kernel: {detected:?}"
    );
    assert_eq!(set_traversal_simd(Simd::Avx2), detected);
    let baseline = set_traversal_simd(Simd::Baseline);
    assert_eq!(baseline == Simd::Avx2, compiled_avx2, "{baseline:?}");
    if !two_copies || detected != Simd::Avx2 {
        eprintln!(
            "skipped: the comparison of the copies needs an x86_64 target without AVX2 and a \
             CPU with it (target has two copies: {two_copies}, detected {detected:?})"
        );
        return;
    }
    let rays = rays();
    let cases = [(4, "f32"), (4, "fixed"), (8, "f32"), (8, "fixed")];
    for leaf_order in [false, true] {
        for (width, mode) in cases {
            let trace = |simd: Simd| {
                assert_eq!(set_traversal_simd(simd), simd);
                match (width, mode) {
                    (4, "f32") => answers::<4, f32>(&rays, leaf_order),
                    (4, _) => answers::<4, I16F16>(&rays, leaf_order),
                    (_, "f32") => answers::<8, f32>(&rays, leaf_order),
                    _ => answers::<8, I16F16>(&rays, leaf_order),
                }
            };
            let (base, avx2) = (trace(Simd::Baseline), trace(Simd::Avx2));
            let hits = base.iter().filter(|a| a.0.is_some()).count();
            assert!(
                hits > rays.len() / 3 && hits < rays.len(),
                "{width}-wide {mode}: {hits} hits of {}",
                rays.len()
            );
            for (i, (b, a)) in base.iter().zip(&avx2).enumerate() {
                assert_eq!(
                    b, a,
                    "{width}-wide {mode}, leaf order {leaf_order}, ray {i}: {}",
                    rays[i]
                );
            }
        }
    }
    set_traversal_simd(detected);
}
