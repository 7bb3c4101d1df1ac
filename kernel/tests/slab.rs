//! Known answers for the conservative slab test `Aabb::slab`, in both number modes.
//!
//! Every case states whether the ray meets the box; an exact `f64` oracle (computed from the
//! same inputs) double-checks the statement and gives the exact entry distance. The kernel's
//! entry distance must be a lower bound of the exact one (conservative), within a tolerance.
//! Boundaries are inclusive: a ray lying in a face, running along an edge, starting on the box,
//! or touching it at a single `t` hits.

mod common;

use common::{c, p, RaySpec, TestScalar};
use raykernel::{Aabb, I16F16};
use raykernel_testkit::Rng;

/// The exact entry distance of the ray into the closed box over `[t_min, t_max]`, if any.
fn exact_entry(lo: [f32; 3], hi: [f32; 3], r: &RaySpec) -> Option<f64> {
    let d = r.d.map(f64::from);
    let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    let (mut near, mut far) = (r.t_min as f64, r.t_max as f64);
    for i in 0..3 {
        let (o, u) = (r.o[i] as f64, d[i] / n);
        let (l, h) = (lo[i] as f64, hi[i] as f64);
        if u == 0.0 {
            if o < l || o > h {
                return None;
            }
        } else {
            let (t1, t2) = ((l - o) / u, (h - o) / u);
            near = near.max(t1.min(t2));
            far = far.min(t1.max(t2));
        }
    }
    (near <= far).then_some(near)
}

/// How far below the exact entry a conservative entry may be: the modes' documented margins
/// (f32: the origin is moved by 2^-19 of its largest coordinate; fixed: by one raw unit, plus a
/// 2-unit pad) divided by the smallest non-zero direction component, with room to spare, plus
/// the mode's rounding tolerance.
fn entry_tol<S: TestScalar>(exact: f64, lo: [f32; 3], hi: [f32; 3], r: &RaySpec) -> f64 {
    let d = r.d.map(f64::from);
    let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    let u_min = d
        .iter()
        .map(|x| x.abs() / n)
        .filter(|&x| x > 0.0)
        .fold(1.0, f64::min);
    let scale =
        r.o.iter()
            .chain(&lo)
            .chain(&hi)
            .fold(1.0f64, |m, &x| m.max(x.abs() as f64));
    let margin = if S::NAME == "f32" {
        4.0 * scale / 524_288.0
    } else {
        4.0 / 65536.0
    };
    S::tol(exact) + margin / u_min
}

/// Checks one case: `hits` is the expected answer, confirmed by the oracle first.
fn check<S: TestScalar>(lo: [f32; 3], hi: [f32; 3], r: RaySpec, hits: bool, what: &str) {
    // The oracle sees the interval as the mode stores it (fixed point rounds it to 2^-16).
    let in_mode = |t: f32| S::from_f32_saturating(t).to_f32();
    let exact = exact_entry(lo, hi, &r.interval(in_mode(r.t_min), in_mode(r.t_max)));
    assert_eq!(
        exact.is_some(),
        hits,
        "test case wrong (oracle disagrees): {what}: box {lo:?}..{hi:?}, ray {r}"
    );
    let bx = Aabb::<S>::new(p(lo), p(hi));
    let got = bx.slab(&r.ray::<S>());
    let ctx = || format!("{} {what}: box {lo:?}..{hi:?}, ray {r}", S::NAME);
    match (got, exact) {
        (None, None) => {}
        (Some(t), Some(e)) => {
            let t = t.to_f32() as f64;
            // A conservative entry is never beyond the exact one (the tiny slack covers the
            // oracle's own rounding of the unit direction).
            assert!(
                t <= e + 1e-7 * (1.0 + e),
                "{}: entry {t} beyond exact {e}",
                ctx()
            );
            let tol = entry_tol::<S>(e, lo, hi, &r);
            assert!(
                t >= e - tol,
                "{}: entry {t} too far below exact {e} (tol {tol})",
                ctx()
            );
            assert!(
                t >= in_mode(r.t_min) as f64,
                "{}: entry {t} below t_min",
                ctx()
            );
        }
        (got, _) => panic!(
            "{}: got {got:?}, want {}",
            ctx(),
            if hits { "a hit" } else { "a miss" }
        ),
    }
}

const LO: [f32; 3] = [0.0; 3];
const HI: [f32; 3] = [1.0; 3];
const SIGNS: [f32; 2] = [1.0, -1.0];

/// Boxes the octant cases run on: the unit box, a shifted one far from the origin, a flat box
/// (zero thickness, as around an axis-aligned triangle) and a single point.
const BOXES: [([f32; 3], [f32; 3]); 4] = [
    (LO, HI),
    ([1000.0, 2000.0, -3000.0], [1001.0, 2001.0, -2999.0]),
    ([0.0, 0.0, 0.5], [1.0, 1.0, 0.5]),
    ([0.5, 0.5, 0.5], [0.5, 0.5, 0.5]),
];

fn center(lo: [f32; 3], hi: [f32; 3]) -> [f32; 3] {
    [0, 1, 2].map(|i| (lo[i] + hi[i]) * 0.5)
}

/// Each of the 8 direction octants, aimed through the box centre from outside: hits; the same
/// ray reversed (box behind) misses.
fn octant_cases<S: TestScalar>() {
    for (lo, hi) in BOXES {
        let m = center(lo, hi);
        for sx in SIGNS {
            for sy in SIGNS {
                for sz in SIGNS {
                    let d = [sx, 2.0 * sy, 3.0 * sz];
                    let o = [0, 1, 2].map(|i| m[i] - 0.75 * d[i]);
                    check::<S>(lo, hi, RaySpec::new(o, d), true, "octant towards the box");
                    let back = d.map(|x| -x);
                    check::<S>(lo, hi, RaySpec::new(o, back), false, "box behind the ray");
                    // Axis-aligned, through the centre along each axis, both ways.
                    for axis in 0..3 {
                        let mut d = [0.0; 3];
                        d[axis] = sx;
                        let mut o = m;
                        o[axis] -= 2.0 * sx;
                        check::<S>(
                            lo,
                            hi,
                            RaySpec::new(o, d),
                            true,
                            "axis-aligned through centre",
                        );
                        o[axis] = m[axis] + 2.0 * sx;
                        check::<S>(
                            lo,
                            hi,
                            RaySpec::new(o, d),
                            false,
                            "axis-aligned, box behind",
                        );
                    }
                }
            }
        }
    }
}

/// Coordinates of the origin along an axis whose direction component is ±0, and whether the
/// ray stays in the slab [0, 1]: inside, on the lo plane, on the hi plane (inclusive), outside,
/// and just outside by 2^-10.
const ZERO_AXIS_POSITIONS: [(f32, bool); 7] = [
    (0.5, true),
    (0.0, true),
    (1.0, true),
    (-0.5, false),
    (1.5, false),
    (-1.0 / 1024.0, false),
    (1.0 + 1.0 / 1024.0, false),
];

/// One direction component is +0 or -0: the ray hits iff its origin lies in that slab
/// (faces included).
fn one_zero_component_cases<S: TestScalar>() {
    for zero in [0.0f32, -0.0] {
        for axis in 0..3 {
            let (b, cc) = ((axis + 1) % 3, (axis + 2) % 3);
            for (pos, inside) in ZERO_AXIS_POSITIONS {
                for flip in SIGNS {
                    // Along b the ray enters the box at s = 0.5 (unnormalised parameter); along
                    // cc it starts inside and leaves at s = 0.75.
                    let (mut o, mut d) = ([0.0; 3], [0.0; 3]);
                    o[axis] = pos;
                    d[axis] = zero;
                    o[b] = if flip > 0.0 { -1.0 } else { 2.0 };
                    d[b] = 2.0 * flip;
                    o[cc] = if flip > 0.0 { 0.25 } else { 0.75 };
                    d[cc] = flip;
                    check::<S>(LO, HI, RaySpec::new(o, d), inside, "one zero component");
                }
            }
        }
    }
}

/// Two direction components are ±0 (all sign combinations): the ray is parallel to an axis and
/// hits iff its other two coordinates lie in the box's face (edges and faces included: a ray
/// along a box edge or lying in a face hits).
fn two_zero_component_cases<S: TestScalar>() {
    for axis in 0..3 {
        let (b, cc) = ((axis + 1) % 3, (axis + 2) % 3);
        for sign in SIGNS {
            for zb in [0.0f32, -0.0] {
                for zc in [0.0f32, -0.0] {
                    for (pb, ib) in ZERO_AXIS_POSITIONS {
                        for (pc, ic) in ZERO_AXIS_POSITIONS {
                            let (mut o, mut d) = ([0.0; 3], [0.0; 3]);
                            o[axis] = if sign > 0.0 { -2.0 } else { 3.0 };
                            d[axis] = sign;
                            (o[b], d[b]) = (pb, zb);
                            (o[cc], d[cc]) = (pc, zc);
                            check::<S>(
                                LO,
                                HI,
                                RaySpec::new(o, d),
                                ib && ic,
                                "axis-parallel ray (face/edge/outside)",
                            );
                        }
                    }
                }
            }
        }
    }
}

/// Origin on a face: entering, leaving (touches the box at t = 0), and lying in the face.
fn origin_on_face_cases<S: TestScalar>() {
    let o = [0.0, 0.5, 0.5];
    check::<S>(
        LO,
        HI,
        RaySpec::new(o, [1.0, 0.0, 0.0]),
        true,
        "on lo face, entering",
    );
    check::<S>(
        LO,
        HI,
        RaySpec::new(o, [1.0, 2.0, -3.0]),
        true,
        "on lo face, entering obliquely",
    );
    check::<S>(
        LO,
        HI,
        RaySpec::new(o, [-1.0, 0.0, 0.0]),
        true,
        "on lo face, leaving (touch at 0)",
    );
    check::<S>(
        LO,
        HI,
        RaySpec::new(o, [0.0, 1.0, 0.0]),
        true,
        "on lo face, lying in it",
    );
    check::<S>(
        LO,
        HI,
        RaySpec::new(o, [-0.0, -1.0, 1.0]),
        true,
        "on lo face, in it obliquely",
    );
    let o = [0.5, 1.0, 0.5];
    check::<S>(
        LO,
        HI,
        RaySpec::new(o, [0.0, -1.0, 0.0]),
        true,
        "on hi face, entering",
    );
    check::<S>(
        LO,
        HI,
        RaySpec::new(o, [0.0, 1.0, 0.0]),
        true,
        "on hi face, leaving (touch at 0)",
    );
    // A corner, leaving diagonally: touches at t = 0 only.
    check::<S>(
        LO,
        HI,
        RaySpec::new(HI, [1.0, 1.0, 1.0]),
        true,
        "on hi corner, leaving",
    );
    // On a face, but the interval starts later: the box is behind.
    let r = RaySpec::new([0.0, 0.5, 0.5], [-1.0, 0.0, 0.0]).interval(0.5, 10.0);
    check::<S>(LO, HI, r, false, "on lo face, leaving, t_min > 0");
}

/// Origin inside: the entry distance is `t_min` itself.
fn origin_inside_cases<S: TestScalar>() {
    let o = [0.25, 0.5, 0.75];
    let dirs = [
        [1.0, 2.0, 3.0],
        [-1.0, 2.0, -3.0],
        [-1.0, -1.0, -1.0],
        [0.0, -0.0, 1.0],
        [-0.0, -1.0, 0.0],
    ];
    for d in dirs {
        for t_min in [0.0f32, 0.125] {
            let r = RaySpec::new(o, d).interval(t_min, f32::INFINITY);
            check::<S>(LO, HI, r, true, "origin inside");
            let got = Aabb::<S>::new(p(LO), p(HI)).slab(&r.ray::<S>()).unwrap();
            assert_eq!(
                got,
                c::<S>(t_min),
                "{} origin inside: entry must be t_min, ray {r}",
                S::NAME
            );
        }
    }
}

/// The ray's interval: `t_min == t_max` inside [entry, exit] hits (the ends are inclusive),
/// outside misses; an interval ending before the box or starting after it misses.
fn interval_cases<S: TestScalar>() {
    // Enters at t = 2, leaves at t = 3.
    let r = RaySpec::new([0.5, 0.5, -2.0], [0.0, 0.0, 1.0]);
    // Enters through z = 0 at t = 1.75·√5, leaves through z = 1 at t = 2.25·√5.
    let oblique = RaySpec::new([-1.5, 0.25, -3.5], [1.0, 0.0, 2.0]);
    for (t0, t1, hits) in [
        (2.5, 2.5, true),
        (2.0, 2.0, true),
        (3.0, 3.0, true),
        (1.0, 1.0, false),
        (4.0, 4.0, false),
        (0.0, 0.0, false),
        (0.0, 1.5, false),
        (3.5, f32::INFINITY, false),
        (0.0, 2.5, true),
        (2.5, 100.0, true),
    ] {
        check::<S>(LO, HI, r.interval(t0, t1), hits, "interval");
    }
    let e = 1.75 * 5f32.sqrt();
    for (t0, t1, hits) in [
        (e + 0.1, e + 0.1, true),
        (e - 0.1, e - 0.1, false),
        (0.0, e - 0.1, false),
        (e + 0.1, f32::INFINITY, true),
    ] {
        check::<S>(LO, HI, oblique.interval(t0, t1), hits, "interval, oblique");
    }
}

fn slab_cases<S: TestScalar>() {
    octant_cases::<S>();
    one_zero_component_cases::<S>();
    two_zero_component_cases::<S>();
    origin_on_face_cases::<S>();
    origin_inside_cases::<S>();
    interval_cases::<S>();
}

#[test]
fn slab_known_answers_f32() {
    slab_cases::<f32>();
}

#[test]
fn slab_known_answers_fixed() {
    slab_cases::<I16F16>();
}

/// The conservative margin never makes a clearly separated box a hit: a ray passing 2^-10
/// beside a face (relative 1e-3 of the coordinates) misses in both modes, also far from the
/// origin.
fn near_miss_cases<S: TestScalar>() {
    for (lo, hi) in BOXES {
        let m = center(lo, hi);
        for axis in 0..3 {
            let b = (axis + 1) % 3;
            let mut o = m;
            o[axis] -= 5.0;
            o[b] = hi[b] + hi[b].abs().max(1.0) / 1024.0;
            let mut d = [0.0; 3];
            d[axis] = 1.0;
            check::<S>(
                lo,
                hi,
                RaySpec::new(o, d),
                false,
                "passing just beside a face",
            );
        }
    }
}

#[test]
fn slab_near_miss_is_a_miss_f32() {
    near_miss_cases::<f32>();
}

#[test]
fn slab_near_miss_is_a_miss_fixed() {
    near_miss_cases::<I16F16>();
}

/// Seeded random boxes (some flat or a single point) and rays: whenever the exact oracle
/// meets the box, the kernel does too, with an entry no later than the exact one and within
/// the tolerance; a ray aimed at the box centre from outside hits, and reversed it misses.
fn random_cases<S: TestScalar>() {
    const SEED: u64 = 0x51ab_0001;
    let mut rng = Rng::new(SEED);
    let grid = |rng: &mut Rng, r: f32| (rng.range(-r, r) * 16.0).round() / 16.0;
    for case in 0..20_000 {
        let scale = [1.0f32, 100.0, 4000.0][case % 3];
        let mut lo = [0.0f32; 3];
        let mut hi = [0.0f32; 3];
        for i in 0..3 {
            let (a, b) = (grid(&mut rng, scale), grid(&mut rng, scale));
            // Some boxes are flat on an axis (as around an axis-aligned triangle).
            let b = if rng.below(6) == 0 { a } else { b };
            (lo[i], hi[i]) = (a.min(b), a.max(b));
        }
        let what = format!("random box, seed {SEED:#x} case {case}");
        let inside = |p: [f32; 3]| (0..3).all(|i| lo[i] <= p[i] && p[i] <= hi[i]);
        // A random ray, with an integer-ish origin and sometimes ±0 direction components.
        let o = [0; 3].map(|_| grid(&mut rng, 1.5 * scale));
        let mut d = rng.unit_vec();
        for x in &mut d {
            if rng.below(5) == 0 {
                *x = if rng.below(2) == 0 { 0.0 } else { -0.0 };
            }
        }
        if d.iter().all(|&x| x == 0.0) {
            d[rng.below(3)] = 1.0;
        }
        let r = RaySpec::new(o, d);
        let hits = exact_entry(lo, hi, &r).is_some();
        if hits {
            check::<S>(lo, hi, r, true, &what);
        }
        // Aimed at the centre from outside: hits; reversed: misses.
        let m = center(lo, hi);
        if !inside(o) && m != o {
            let d = common::dir_to(o, m);
            // The oracle is ill-conditioned for boxes flat on two axes, so check directly:
            // the box is met no later than the centre.
            let r = RaySpec::new(o, d);
            let dist = (0..3)
                .map(|i| (m[i] as f64 - o[i] as f64).powi(2))
                .sum::<f64>()
                .sqrt();
            let got = Aabb::<S>::new(p(lo), p(hi)).slab(&r.ray::<S>());
            assert!(
                got.is_some_and(|t| (t.to_f32() as f64) <= dist * (1.0 + 1e-6)),
                "{} {what}, at the centre (distance {dist}): got {got:?}, ray {r}",
                S::NAME
            );
            let back = d.map(|x| -x);
            let r = RaySpec::new(o, back);
            if exact_entry(lo, hi, &r).is_none() {
                let got = Aabb::<S>::new(p(lo), p(hi)).slab(&r.ray::<S>());
                // Conservative: a miss may only be reported as a hit at the origin, by the margin.
                assert!(
                    got.is_none()
                        || got.unwrap().to_f32() <= entry_tol::<S>(0.0, lo, hi, &r) as f32,
                    "{} {what}, reversed: got {got:?}, ray {r}",
                    S::NAME
                );
            }
        }
    }
}

#[test]
fn slab_is_conservative_on_random_boxes_f32() {
    random_cases::<f32>();
}

#[test]
fn slab_is_conservative_on_random_boxes_fixed() {
    random_cases::<I16F16>();
}
