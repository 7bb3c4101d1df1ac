//! The wide BVHs (4-wide and 8-wide) beyond the random differential tests of `properties.rs`:
//! - `Numerics::slab4` gives, box by box, exactly `Numerics::slab`'s decisions and entry bits
//!   (random boxes and rays, zero and signed-zero direction components, origins on box
//!   planes, flat boxes, intervals);
//! - `Numerics::slab8` gives each of its eight boxes exactly the decision and entry bits
//!   `slab4` gives it in its half, in both modes (so `slab`'s in `f32`), on the same kinds of
//!   cases; where the CPU has AVX2, `Numerics::slab8_avx2` (256-bit lanes) gives `slab8`'s,
//!   also for intervals that end just short of a box's entry (where the exit's slack decides);
//! - why unused slots are masked by their count rather than by an "empty" box: the slab test
//!   accepts an inverted box for some ray;
//! - the collapse, for both widths: arena sizes (`wide_nodes_needed` bounds every collapse and
//!   is reached, one slot less is a typed error), its values and growth, empty and
//!   one-primitive scenes, leaf order, and a deeper tree (a 5120-triangle sphere) answering
//!   like the BVH2 and brute force bit for bit in both modes, by both walks (`Coherent`);
//! - the same through `AnyAccel` (`AccelKind::Bvh4`, `AccelKind::Bvh8`), built as is and in
//!   leaf order into exactly the memory `AccelKind::memory_needed` gives.

mod common;

use common::{
    c, query, same_hit, with_bvh, with_bvh_in_leaf_order, with_wide, RaySpec, TestScalar, WideTree,
    LEAF_SIZES,
};
use raykernel::bvh::{nodes_needed, BuildOptions, BuilderKind};
use raykernel::bvh4::nodes4_needed;
use raykernel::bvh8::{collapse_words_needed, nodes8_needed, wide_nodes_needed};
use raykernel::Arena;
use raykernel::{
    Aabb, Accel, AccelKind, AnyAccel, BuildError, Bvh, Coherent, Linear, Node, Ray, Triangle,
    WideBvh, WideNode, I16F16,
};
use raykernel_testkit::icosphere::unit_icosphere;
use raykernel_testkit::memory::OwnedMemory;
use raykernel_testkit::Rng;

fn tri<S: TestScalar>(v: [[f32; 3]; 3]) -> Triangle<S> {
    Triangle::from_f32(v).unwrap_or_else(|e| panic!("{} {v:?}: {e:?}", S::NAME))
}

// ---------------------------------------------------------------------------------------------
// slab4 == slab, slab8 == slab4, box by box

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

/// `N` boxes in structure of arrays: `lo[axis][box]`, `hi[axis][box]`.
type Boxes<S, const N: usize> = ([[S; N]; 3], [[S; N]; 3]);

/// Box `b` of `boxes` as `(lo, hi)` points.
fn box_at<S: Copy, const N: usize>((lo, hi): &Boxes<S, N>, b: usize) -> ([S; 3], [S; 3]) {
    (
        [lo[0][b], lo[1][b], lo[2][b]],
        [hi[0][b], hi[1][b], hi[2][b]],
    )
}

/// `count` random rays, each with `N` random boxes: quarter-valued origins (so box planes can
/// sit exactly on them), directions with ±0 components, intervals `[0, inf)`, `[t, inf)` and
/// bounded ones; box planes on the origin (rays in a face), random quarters, arbitrary values,
/// and flat boxes (`lo == hi`).
fn random_cases<S: TestScalar, const N: usize>(
    seed: u64,
    count: usize,
) -> impl Iterator<Item = (RaySpec, Boxes<S, N>)> {
    let mut rng = Rng::new(seed);
    (0..count).map(move |_| {
        let o = [0, 1, 2].map(|_| (rng.range(-20.0, 20.0) * 4.0).round() / 4.0);
        let d = direction(&mut rng);
        let spec = match rng.below(4) {
            0 | 1 => RaySpec::new(o, d),
            2 => RaySpec::new(o, d).interval(rng.range(0.0, 10.0), f32::INFINITY),
            _ => {
                let a = rng.range(0.0, 30.0);
                RaySpec::new(o, d).interval(a, a + rng.range(0.0, 30.0))
            }
        };
        let mut lo = [[S::ZERO; N]; 3];
        let mut hi = [[S::ZERO; N]; 3];
        for b in 0..N {
            for k in 0..3 {
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
        (spec, (lo, hi))
    })
}

/// Rays along the axes with ±0 components from every origin on the grid `coords`³, each with
/// `boxes`.
fn axis_cases<S: TestScalar, const N: usize>(
    boxes: [([f32; 3], [f32; 3]); N],
    coords: [f32; 5],
) -> Vec<(RaySpec, Boxes<S, N>)> {
    let mut planes = ([[S::ZERO; N]; 3], [[S::ZERO; N]; 3]);
    for (b, (l, h)) in boxes.iter().enumerate() {
        for k in 0..3 {
            planes.0[k][b] = c::<S>(l[k]);
            planes.1[k][b] = c::<S>(h[k]);
        }
    }
    let mut out = Vec::new();
    for x in coords {
        for y in coords {
            for z in coords {
                for axis in 0..3 {
                    for sign in [1.0f32, -1.0] {
                        for zeros in [0.0f32, -0.0] {
                            let mut d = [zeros; 3];
                            d[axis] = sign;
                            out.push((RaySpec::new([x, y, z], d), planes));
                        }
                    }
                }
            }
        }
    }
    out
}

/// Origins for [`axis_cases`] on, inside and outside the faces of the `AXIS_BOXES`.
const AXIS_COORDS: [f32; 5] = [-1.0, 0.0, 0.5, 1.0, 2.0];

/// The smallest positive `f32`: how far the slab test shifts an origin of coordinates this
/// small off itself (towards each plane, `lo - (o + d)` and `hi - (o - d)`).
const T: f32 = f32::from_bits(1);

/// Origins for [`axis_cases`] with the `TINY_BOXES`: planes of those lie exactly on the shifted
/// origins of a zero direction component, where `f32`'s slab test meets `0 · inf = NaN` and
/// decides by the operand order of `min` and `max`.
const TINY_COORDS: [f32; 5] = [-T, -0.0, 0.0, T, 2.0 * T];

/// Eight boxes with planes on, just inside and just outside origins a few steps `u` from
/// zero (for [`axis_cases`]).
const fn boxes_around_origins(u: f32) -> [([f32; 3], [f32; 3]); 8] {
    [
        ([u, u, u], [1.0, 1.0, 1.0]),
        ([-1.0, -1.0, -1.0], [-u, -u, -u]),
        ([2.0 * u, 2.0 * u, 2.0 * u], [1.0, 1.0, 1.0]),
        ([-1.0, -1.0, -1.0], [-2.0 * u, -2.0 * u, -2.0 * u]),
        ([0.0, 0.0, 0.0], [1.0, 1.0, 1.0]),
        ([-u, -u, -u], [u, u, u]),
        ([u, -1.0, -1.0], [1.0, 1.0, 1.0]),
        ([-1.0, u, -1.0], [1.0, 1.0, -u]),
    ]
}

/// Boxes around [`TINY_COORDS`].
const TINY_BOXES8: [([f32; 3], [f32; 3]); 8] = boxes_around_origins(T);

/// One raw unit of fixed point (2^-16): how far its slab test shifts an origin.
const R: f32 = 1.0 / 65_536.0;

/// [`TINY_COORDS`] for fixed point: origins one raw unit around the planes of
/// [`RAW_BOXES8`], where its lanes meet `0 · inf = NaN` too.
const RAW_COORDS: [f32; 5] = [-R, 0.0, R, 2.0 * R, 3.0 * R];

/// [`TINY_BOXES8`] in raw units of fixed point.
const RAW_BOXES8: [([f32; 3], [f32; 3]); 8] = boxes_around_origins(R);

/// The first four [`TINY_BOXES8`].
const TINY_BOXES4: [([f32; 3], [f32; 3]); 4] = [
    TINY_BOXES8[0],
    TINY_BOXES8[1],
    TINY_BOXES8[2],
    TINY_BOXES8[3],
];

/// Four boxes for [`axis_cases`]: a unit box, a flat one, one beside it, a point.
const AXIS_BOXES4: [([f32; 3], [f32; 3]); 4] = [
    ([0.0, 0.0, 0.0], [1.0, 1.0, 1.0]),
    ([0.0, 0.0, 0.0], [0.0, 1.0, 1.0]),
    ([-1.0, 1.0, 0.0], [0.0, 1.0, 2.0]),
    ([1.0, 1.0, 1.0], [1.0, 1.0, 1.0]),
];

/// Eight boxes for [`axis_cases`]: [`AXIS_BOXES4`], then one around every origin, one flat
/// between the origins' planes, a point on the far corner and one below the unit box.
const AXIS_BOXES8: [([f32; 3], [f32; 3]); 8] = [
    AXIS_BOXES4[0],
    AXIS_BOXES4[1],
    AXIS_BOXES4[2],
    AXIS_BOXES4[3],
    ([-1.0, -1.0, -1.0], [2.0, 2.0, 2.0]),
    ([0.5, 0.0, 0.0], [0.5, 1.0, 1.0]),
    ([2.0, 2.0, 2.0], [2.0, 2.0, 2.0]),
    ([0.0, 0.0, -1.0], [1.0, 1.0, 0.0]),
];

/// Per box: the entry's bits if accepted (bit `b` of `mask`), `None` if rejected (rejected
/// boxes' entries are unspecified).
fn decisions<S: TestScalar>(mask: u32, t: &[S]) -> Vec<Option<u32>> {
    let n = t.len();
    assert!(mask >> n == 0, "mask {mask:#b} has bits beyond box {n}");
    t.iter()
        .enumerate()
        .map(|(b, t)| (mask >> b & 1 != 0).then(|| t.bits()))
        .collect()
}

/// `Numerics::slab`'s decision for each box.
fn slab_per_box<S: TestScalar, const N: usize>(
    ray: &Ray<S>,
    boxes: &Boxes<S, N>,
) -> Vec<Option<u32>> {
    (0..N)
        .map(|b| {
            let (l, h) = box_at(boxes, b);
            S::slab(ray.data(), &l, &h, ray.t_min(), ray.t_max()).map(|t| t.bits())
        })
        .collect()
}

/// `Numerics::slab4`'s decisions for boxes 0..4, then for boxes 4..8.
fn slab4_per_half<S: TestScalar>(ray: &Ray<S>, (lo, hi): &Boxes<S, 8>) -> Vec<Option<u32>> {
    let half = |planes: &[[S; 8]; 3], h: usize| {
        planes.map(|axis| std::array::from_fn::<S, 4, _>(|i| axis[4 * h + i]))
    };
    (0..2)
        .flat_map(|h| {
            let (mask, t) = S::slab4(
                ray.data(),
                &half(lo, h),
                &half(hi, h),
                ray.t_min(),
                ray.t_max(),
            );
            decisions(mask, &t)
        })
        .collect()
}

/// Counts accepted and rejected boxes, so a test can show both outcomes are well represented.
#[derive(Default)]
struct Outcomes {
    accepted: usize,
    rejected: usize,
}

impl Outcomes {
    fn add(&mut self, d: &[Option<u32>]) {
        let accepted = d.iter().filter(|x| x.is_some()).count();
        self.accepted += accepted;
        self.rejected += d.len() - accepted;
    }
    fn assert_both_above(&self, n: usize) {
        assert!(
            self.accepted > n && self.rejected > n,
            "accepted {}, rejected {}",
            self.accepted,
            self.rejected
        );
    }
}

// Fixed point's 4-wide box test runs in `f32` lanes where there are vector lanes and is
// conservative rather than equal to `slab` there: tested against exact rational distances in
// `scalar/fixed.rs` (`slab4_is_conservative_and_tight`). Elsewhere it is `slab` per box.

/// `slab4`'s decisions and entries are `slab`'s, box by box. Returns the outcomes.
fn slab4_equals_slab<S: TestScalar>(
    cases: impl IntoIterator<Item = (RaySpec, Boxes<S, 4>)>,
) -> Outcomes {
    let mut outcomes = Outcomes::default();
    for (i, (spec, boxes)) in cases.into_iter().enumerate() {
        let ray = spec.ray::<S>();
        let (lo, hi) = &boxes;
        let (mask, t) = S::slab4(ray.data(), lo, hi, ray.t_min(), ray.t_max());
        let want = slab_per_box(&ray, &boxes);
        assert_eq!(
            decisions(mask, &t),
            want,
            "{} case {i}: {spec}, boxes {boxes:?}",
            S::NAME
        );
        outcomes.add(&want);
    }
    outcomes
}

#[test]
fn slab4_equals_slab_per_box_f32() {
    slab4_equals_slab::<f32>(random_cases(0x51ab_4444, 40_000)).assert_both_above(20_000);
}

#[test]
fn slab4_equals_slab_on_axis_rays_f32() {
    slab4_equals_slab::<f32>(axis_cases(AXIS_BOXES4, AXIS_COORDS)).assert_both_above(500);
    slab4_equals_slab::<f32>(axis_cases(TINY_BOXES4, TINY_COORDS)).assert_both_above(500);
}

/// `slab8`'s decisions and entries are those `slab4` gives each half, and, where
/// `equals_slab`, `slab`'s per box. Returns the outcomes.
fn slab8_equals_slab4<S: TestScalar>(
    cases: impl IntoIterator<Item = (RaySpec, Boxes<S, 8>)>,
    equals_slab: bool,
) -> Outcomes {
    let mut outcomes = Outcomes::default();
    for (i, (spec, boxes)) in cases.into_iter().enumerate() {
        let ray = spec.ray::<S>();
        let (lo, hi) = &boxes;
        let (mask, t) = S::slab8(ray.data(), lo, hi, ray.t_min(), ray.t_max());
        let got = decisions(mask, &t);
        let want = slab4_per_half(&ray, &boxes);
        let ctx = || format!("{} case {i}: {spec}, boxes {boxes:?}", S::NAME);
        assert_eq!(got, want, "slab8 vs slab4: {}", ctx());
        if equals_slab {
            assert_eq!(got, slab_per_box(&ray, &boxes), "slab8 vs slab: {}", ctx());
        }
        outcomes.add(&got);
    }
    outcomes
}

#[test]
fn slab8_equals_slab4_per_half_f32() {
    slab8_equals_slab4::<f32>(random_cases(0x51ab_8888, 20_000), true).assert_both_above(20_000);
    slab8_equals_slab4::<f32>(axis_cases(AXIS_BOXES8, AXIS_COORDS), true).assert_both_above(1000);
    slab8_equals_slab4::<f32>(axis_cases(TINY_BOXES8, TINY_COORDS), true).assert_both_above(1000);
}

#[test]
fn slab8_equals_slab4_per_half_fixed() {
    slab8_equals_slab4::<I16F16>(random_cases(0x51ab_8888, 20_000), false)
        .assert_both_above(20_000);
    slab8_equals_slab4::<I16F16>(axis_cases(AXIS_BOXES8, AXIS_COORDS), false)
        .assert_both_above(1000);
}

/// `slab8_avx2` (the eight boxes in the 256-bit lanes of one AVX2 vector, in both modes) gives
/// every box exactly `slab8`'s decision and entry.
#[cfg(target_arch = "x86_64")]
fn slab8_avx2_equals_slab8<S: TestScalar>(cases: impl IntoIterator<Item = (RaySpec, Boxes<S, 8>)>) {
    assert!(std::is_x86_feature_detected!("avx2"));
    let mut outcomes = Outcomes::default();
    for (i, (spec, (lo, hi))) in cases.into_iter().enumerate() {
        let ray = spec.ray::<S>();
        let (t_min, t_max) = (ray.t_min(), ray.t_max());
        let (mask, t) = S::slab8(ray.data(), &lo, &hi, t_min, t_max);
        // SAFETY: the CPU has AVX2 (asserted above), the one thing `slab8_avx2` requires.
        let (avx_mask, avx_t) = unsafe { S::slab8_avx2(ray.data(), &lo, &hi, t_min, t_max) };
        let want = decisions(mask, &t);
        assert_eq!(
            decisions(avx_mask, &avx_t),
            want,
            "{} case {i}: {spec}, boxes {:?}",
            S::NAME,
            (lo, hi)
        );
        outcomes.add(&want);
    }
    outcomes.assert_both_above(1000);
}

/// [`random_cases`] again, each followed by copies whose interval ends just short of the entry
/// `slab8` gives one of the boxes it accepts: by 1 to 4 units of the last place of that entry
/// (one raw unit in fixed point) and by 2^-21 to 2^-18 of it relatively, so that the slack a
/// box test grants at the end of the interval (a widened or grown exit, fixed point's
/// `t_max + 2`) decides boxes there.
fn near_entry_cases<S: TestScalar>(
    seed: u64,
    count: usize,
) -> impl Iterator<Item = (RaySpec, Boxes<S, 8>)> {
    random_cases::<S, 8>(seed, count).flat_map(|(spec, (lo, hi))| {
        let ray = spec.ray::<S>();
        let (mask, t) = S::slab8(ray.data(), &lo, &hi, ray.t_min(), ray.t_max());
        let mut cases = vec![(spec, (lo, hi))];
        for (b, &stored) in t.iter().enumerate() {
            let entry = stored.to_f32();
            if mask >> b & 1 == 0 || entry <= spec.t_min || !entry.is_finite() {
                continue;
            }
            let unit = stored.step_above();
            let short = (1..=4)
                .map(|k| entry - k as f32 * unit)
                .chain((18..=21).map(|e| entry * (1.0 - 0.5f32.powi(e))));
            for t_max in short.filter(|&t| t >= spec.t_min) {
                cases.push((spec.interval(spec.t_min, t_max), (lo, hi)));
            }
        }
        cases
    })
}

/// Where the CPU has AVX2: [`slab8_avx2_equals_slab8`] on random, near-entry and axis cases,
/// both modes.
#[test]
fn slab8_avx2_equals_slab8_where_the_cpu_has_avx2() {
    #[cfg(target_arch = "x86_64")]
    if std::is_x86_feature_detected!("avx2") {
        slab8_avx2_equals_slab8::<f32>(random_cases(0xa7c8, 20_000));
        slab8_avx2_equals_slab8::<f32>(near_entry_cases(0xe7e8, 3_000));
        slab8_avx2_equals_slab8::<I16F16>(near_entry_cases(0xe7e8, 3_000));
        slab8_avx2_equals_slab8::<f32>(axis_cases(AXIS_BOXES8, AXIS_COORDS));
        slab8_avx2_equals_slab8::<f32>(axis_cases(TINY_BOXES8, TINY_COORDS));
        slab8_avx2_equals_slab8::<I16F16>(random_cases(0xa7c8, 20_000));
        slab8_avx2_equals_slab8::<I16F16>(axis_cases(AXIS_BOXES8, AXIS_COORDS));
        slab8_avx2_equals_slab8::<I16F16>(axis_cases(RAW_BOXES8, RAW_COORDS));
        return;
    }
    eprintln!("skipped: slab8_avx2 needs an x86_64 CPU with AVX2");
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

/// For a `W`-wide collapse: one slot short of [`wide_nodes_needed`] is a typed error naming
/// the exact bound; collapses of rows of every size up to 300 (median and SAH, one primitive
/// per leaf) stay within it. (That the greedy collapse reaches it is a unit test of
/// `collapse.rs`.)
fn collapse_size_cases<const W: usize, S: TestScalar>()
where
    for<'a> WideBvh<'a, S, Triangle<S>, W>: WideTree<S>,
{
    for n in [1usize, 2, 5, 8, 9, 13, 16, 17, 100] {
        let tris = row::<S>(n);
        let options = BuildOptions {
            max_leaf_size: 1,
            ..BuildOptions::default()
        };
        with_bvh::<S, _, _>(&tris, options, |bvh| {
            let needed = wide_nodes_needed(n, W);
            let mut short = vec![WideNode::<S, W>::EMPTY; needed - 1];
            let mut scratch = vec![0u32; collapse_words_needed(n, W)];
            assert_eq!(
                WideBvh::collapse(bvh, &mut short, &mut scratch).err(),
                Some(BuildError::ArenaTooSmall {
                    arena: Arena::Nodes,
                    needed,
                    available: needed - 1,
                }),
                "{} {W}-wide, n = {n}",
                S::NAME
            );
            with_wide::<W, _, _, _>(bvh, |wide| {
                let stats = wide.check().unwrap();
                assert!(stats.node_count <= needed);
                assert_eq!(wide.bytes_used(), stats.node_count * 32 * W + n * 4);
            });
        });
    }
    let all = row::<S>(300);
    for n in 1..=all.len() {
        for builder in [BuilderKind::Median, BuilderKind::Sah] {
            let options = BuildOptions {
                builder,
                max_leaf_size: 1,
                reinsertion: true,
            };
            with_bvh::<S, _, _>(&all[..n], options, |bvh| {
                with_wide::<W, _, _, _>(bvh, |wide| {
                    let used = wide.check().unwrap().node_count;
                    let bound = wide_nodes_needed(n, W);
                    assert!(
                        used <= bound,
                        "{} {W}-wide, n = {n}: {used} > {bound}",
                        S::NAME
                    );
                });
            });
        }
    }
}

#[test]
fn collapse_arena_sizes_and_errors_f32() {
    collapse_size_cases::<4, f32>();
    collapse_size_cases::<8, f32>();
}

#[test]
fn collapse_arena_sizes_and_errors_fixed() {
    collapse_size_cases::<4, I16F16>();
    collapse_size_cases::<8, I16F16>();
}

/// `wide_nodes_needed` at points worked out from its proof's inequalities, per width
/// (`nodes4_needed` and `nodes8_needed` are it at 4 and 8); nondecreasing, at most one node
/// per primitive, and about `W·n / 2(W - 1)` nodes: `(W - 1)·w <= (W / 2)·n + W - 1`.
#[test]
fn wide_nodes_needed_values_and_growth() {
    let known4 = [
        (0, 0),
        (1, 1),
        (2, 1),
        (4, 1),
        (5, 2),
        (7, 4),
        (8, 5),
        (14, 9),
    ];
    // Width 8: 9 leaves need a node below the root; 15 fit a root over seven nodes of two
    // leaves and a leaf; 16 a full root over eight such nodes; 17 no more (a second full node
    // needs 23); 30 and 44: two and three full nodes over 15 and 22 others.
    let known8 = [
        (0, 0),
        (1, 1),
        (8, 1),
        (9, 2),
        (15, 8),
        (16, 9),
        (17, 9),
        (30, 17),
        (44, 25),
    ];
    for (n, w) in known4 {
        assert_eq!(nodes4_needed(n), w, "4-wide, n = {n}");
    }
    for (n, w) in known8 {
        assert_eq!(nodes8_needed(n), w, "8-wide, n = {n}");
    }
    for width in [4, 8] {
        let c = width - 1;
        let mut prev = 0;
        for n in 0..200_000 {
            let w = wide_nodes_needed(n, width);
            assert!(
                w >= prev && w <= n.max(1) && c * w <= width / 2 * n + c,
                "{width}-wide, n = {n}: {w}"
            );
            let named = if width == 4 {
                nodes4_needed(n)
            } else {
                nodes8_needed(n)
            };
            assert_eq!(named, w, "{width}-wide, n = {n}");
            prev = w;
        }
        // Large counts do not overflow.
        let _ = wide_nodes_needed(usize::MAX, width);
    }
}

/// No primitives: no nodes, every ray misses. One primitive: a root with one leaf child.
fn small_scene_cases<const W: usize, S: TestScalar>()
where
    for<'a> WideBvh<'a, S, Triangle<S>, W>: WideTree<S>,
{
    let r = RaySpec::new([0.25, 0.25, 0.0], [0.0, 0.0, 1.0]).ray::<S>();
    let none: Vec<Triangle<S>> = Vec::new();
    let mut nodes: Vec<Node<S>> = Vec::new();
    let mut ids: Vec<u32> = Vec::new();
    let bvh = Bvh::build(&none, &mut nodes, &mut ids, BuildOptions::default()).unwrap();
    let mut wide_nodes: Vec<WideNode<S, W>> = Vec::new();
    let wide = WideBvh::collapse(&bvh, &mut wide_nodes, &mut []).unwrap();
    assert!(wide.nodes().is_empty());
    assert_eq!(wide.check().unwrap().node_count, 0);
    assert!(wide.intersect(&r).is_none() && !wide.occluded(&r));

    let one = row::<S>(1);
    let mut nodes = vec![Node::<S>::EMPTY; nodes_needed(1)];
    let mut ids = vec![0u32; 1];
    let bvh = Bvh::build(&one, &mut nodes, &mut ids, BuildOptions::default()).unwrap();
    let mut wide_nodes = vec![WideNode::<S, W>::EMPTY; wide_nodes_needed(1, W)];
    let mut scratch = vec![0u32; collapse_words_needed(1, W)];
    let wide = WideBvh::collapse(&bvh, &mut wide_nodes, &mut scratch).unwrap();
    assert_eq!(wide.nodes().len(), 1);
    assert_eq!(wide.nodes()[0].child_count(), 1);
    let stats = wide.check().unwrap();
    assert_eq!((stats.leaf_count, stats.depth), (1, 0));
    let hit = wide.intersect(&r).unwrap();
    assert_eq!((hit.t.bits(), hit.prim), (c::<S>(5.0).bits(), 0));
    assert!(wide.occluded(&r));
    let miss = RaySpec::new([0.25, 0.25, 0.0], [0.0, 0.0, -1.0]).ray::<S>();
    assert!(wide.intersect(&miss).is_none() && !wide.occluded(&miss));
}

#[test]
fn empty_and_one_primitive_scenes_f32() {
    small_scene_cases::<4, f32>();
    small_scene_cases::<8, f32>();
}

#[test]
fn empty_and_one_primitive_scenes_fixed() {
    small_scene_cases::<4, I16F16>();
    small_scene_cases::<8, I16F16>();
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

/// The `W`-wide tree over the sphere, for every builder and leaf size, with and without leaf
/// order: valid, within [`wide_nodes_needed`], no deeper than the BVH2, and answering every ray
/// as brute force does.
fn deep_tree_cases<const W: usize, S: TestScalar>()
where
    for<'a> WideBvh<'a, S, Triangle<S>, W>: WideTree<S>,
{
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
            let ctx = |what: &str, e: String, r: &RaySpec| {
                format!("{} {W}-wide{what} {options:?}: {e}, ray {r}", S::NAME)
            };
            with_bvh::<S, _, _>(&tris, options, |bvh| {
                with_wide::<W, _, _, _>(bvh, |wide| {
                    let stats = wide.check().unwrap();
                    assert!(stats.node_count <= wide_nodes_needed(tris.len(), W));
                    assert!(stats.depth <= bvh.depth() as usize);
                    for (r, w) in rays.iter().zip(&want) {
                        let got = query(wide, &r.ray::<S>()).unwrap();
                        same_hit(&got, w).unwrap_or_else(|e| panic!("{}", ctx("", e, r)));
                        let got = query(&Coherent(wide), &r.ray::<S>()).unwrap();
                        same_hit(&got, w).unwrap_or_else(|e| panic!("{}", ctx(" coherent", e, r)));
                    }
                });
            });
            // Leaf order: the same answers through permuted primitives.
            let mut own = tris.clone();
            with_bvh_in_leaf_order(&mut own, options, |bvh| {
                with_wide::<W, _, _, _>(bvh, |wide| {
                    assert!(wide.is_leaf_order());
                    wide.check().unwrap();
                    for (r, w) in rays.iter().zip(&want) {
                        let got = query(wide, &r.ray::<S>()).unwrap();
                        same_hit(&got, w)
                            .unwrap_or_else(|e| panic!("{}", ctx(" leaf order", e, r)));
                    }
                })
            });
        }
    }
}

#[test]
fn deep_bvh4_answers_like_brute_force_f32() {
    deep_tree_cases::<4, f32>();
}

#[test]
fn deep_bvh4_answers_like_brute_force_fixed() {
    deep_tree_cases::<4, I16F16>();
}

#[test]
fn deep_bvh8_answers_like_brute_force_f32() {
    deep_tree_cases::<8, f32>();
}

#[test]
fn deep_bvh8_answers_like_brute_force_fixed() {
    deep_tree_cases::<8, I16F16>();
}

/// `AccelKind::Bvh4` and `AccelKind::Bvh8` through `AnyAccel`, as is and in leaf order
/// (`AnyAccel::build_in_leaf_order` permutes the primitives): built into exactly the memory
/// `memory_needed` gives, the structure asked for, valid, and answering like brute force over
/// the primitives in their original order.
fn any_accel_cases<S: TestScalar>() {
    let tris = sphere::<S>(10.0);
    let rays = sphere_rays(0xa11, 300);
    let linear = Linear::new(&tris);
    let want: Vec<_> = rays
        .iter()
        .map(|r| query(&linear, &r.ray::<S>()).unwrap())
        .collect();
    let options = BuildOptions::default();
    for kind in [AccelKind::Bvh4(options), AccelKind::Bvh8(options)] {
        for leaf_order in [false, true] {
            let ctx = format!("{} {kind}, leaf order {leaf_order}", S::NAME);
            let mut own = tris.clone();
            let mut arena = OwnedMemory::<S>::for_kind(kind, &tris);
            let accel = if leaf_order {
                AnyAccel::build_in_leaf_order(kind, &mut own, &mut arena.memory())
            } else {
                AnyAccel::build(kind, &own, &mut arena.memory())
            }
            .unwrap_or_else(|e| panic!("{ctx}: {e}"));
            assert_eq!(accel.name(), kind.name(), "{ctx}");
            accel.validate().unwrap_or_else(|e| panic!("{ctx}: {e}"));
            for (r, w) in rays.iter().zip(&want) {
                let got = query(&accel, &r.ray::<S>()).unwrap();
                same_hit(&got, w).unwrap_or_else(|e| panic!("{ctx}: {e}, ray {r}"));
                let got = query(&Coherent(&accel), &r.ray::<S>()).unwrap();
                same_hit(&got, w).unwrap_or_else(|e| panic!("{ctx} coherent: {e}, ray {r}"));
            }
            assert_eq!(own != tris, leaf_order, "{ctx}: primitives permuted");
        }
    }
}

#[test]
fn any_accel_builds_wide_trees_as_is_and_in_leaf_order_f32() {
    any_accel_cases::<f32>();
}

#[test]
fn any_accel_builds_wide_trees_as_is_and_in_leaf_order_fixed() {
    any_accel_cases::<I16F16>();
}
