//! Known answers for the ray/triangle and ray/sphere tests, in both number modes.
//!
//! Triangles are two-sided and their edges and vertices are inclusive; degenerate (zero-area)
//! triangles and rays lying in a triangle's plane never hit. Expected distances and
//! barycentrics come from an `f64` oracle over the mode's (rounded) vertices, compared within
//! the mode's tolerance.

mod common;

use common::{c, dir_to, p, RaySpec, TestScalar};
use raykernel::{Primitive, Sphere, Triangle, TriangleHit, I16F16};
use raykernel_testkit::vec3::{cross, dot, normalize, sub};
use raykernel_testkit::Rng;

fn tri<S: TestScalar>(v: [[f32; 3]; 3]) -> Triangle<S> {
    Triangle::from_f32(v).unwrap_or_else(|e| panic!("{} triangle {v:?}: {e:?}", S::NAME))
}

fn unit(d: [f32; 3]) -> [f64; 3] {
    normalize(d.map(f64::from))
}

/// Two-sided Möller–Trumbore in `f64` over the triangle as the mode stores it: (t, u, v) of
/// the supporting plane's intersection and its barycentrics, without any range check.
fn oracle<S: TestScalar>(t: &Triangle<S>, r: &RaySpec) -> Option<(f64, f64, f64)> {
    let v = t.v.map(|p| p.map(|x| x.to_f32() as f64));
    let o = r.o.map(|x| S::from_f32_saturating(x).to_f32() as f64);
    let d = unit(r.d);
    let (e1, e2) = (sub(v[1], v[0]), sub(v[2], v[0]));
    let pv = cross(d, e2);
    let det = dot(e1, pv);
    if det == 0.0 {
        return None;
    }
    let tv = sub(o, v[0]);
    let u = dot(tv, pv) / det;
    let qv = cross(tv, e1);
    let w = dot(d, qv) / det;
    Some((dot(e2, qv) / det, u, w))
}

/// The ray hits at the oracle's (t, u, v), which must equal `want` where given.
fn expect_hit<S: TestScalar>(
    t: &Triangle<S>,
    r: RaySpec,
    want: Option<(f64, f64, f64)>,
    what: &str,
) {
    let ctx = || format!("{} {what}: triangle {:?}, ray {r}", S::NAME, t.v);
    let exact = oracle(t, &r).unwrap_or_else(|| panic!("test case wrong (parallel): {}", ctx()));
    if let Some(w) = want {
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * (1.0 + a.abs());
        assert!(
            close(w.0, exact.0) && close(w.1, exact.1) && close(w.2, exact.2),
            "test case wrong: stated {w:?}, oracle {exact:?}: {}",
            ctx()
        );
    }
    let Some(TriangleHit {
        t: ht,
        u: hu,
        v: hv,
    }) = t.intersect(&r.ray::<S>())
    else {
        panic!("{}: missed, want a hit at {exact:?}", ctx());
    };
    let got = (ht.to_f32() as f64, hu.to_f32() as f64, hv.to_f32() as f64);
    let (et, eu, ev) = exact;
    // Barycentrics of slivers are ill-conditioned: scale by (longest edge)² / (2·area).
    let w = t.v.map(|q| q.map(|x| x.to_f32() as f64));
    let (e0, e1, e2) = (sub(w[1], w[0]), sub(w[2], w[1]), sub(w[0], w[2]));
    let longest = dot(e0, e0).max(dot(e1, e1)).max(dot(e2, e2));
    let n = cross(e0, sub(w[2], w[0]));
    let cond = (longest / dot(n, n).sqrt()).max(1.0);
    assert!(
        (got.0 - et).abs() <= S::tol(et)
            && (got.1 - eu).abs() <= S::tol(1.0) * cond
            && (got.2 - ev).abs() <= S::tol(1.0) * cond,
        "{}: got (t, u, v) = {got:?}, want {exact:?}",
        ctx()
    );
}

fn expect_miss<S: TestScalar>(t: &Triangle<S>, r: RaySpec, what: &str) {
    let got = t.intersect(&r.ray::<S>());
    assert!(
        got.is_none(),
        "{} {what}: triangle {:?}, ray {r}: got {got:?}, want a miss",
        S::NAME,
        t.v
    );
}

/// The reference triangle, in the plane `axis = 4` (the other coordinates rotated into place):
/// (-1,-1), (3,-1), (-1,3); its hypotenuse is `x + y = 2`.
fn reference<S: TestScalar>(axis: usize) -> Triangle<S> {
    tri::<S>([[-1.0, -1.0, 4.0], [3.0, -1.0, 4.0], [-1.0, 3.0, 4.0]].map(|q| rot(q, axis)))
}

/// Moves coordinate 2 to `axis` (a cyclic rotation, so winding and barycentrics are kept).
fn rot(q: [f32; 3], axis: usize) -> [f32; 3] {
    let mut out = [0.0; 3];
    for (i, &x) in q.iter().enumerate() {
        out[(i + axis + 1) % 3] = x;
    }
    out
}

/// Points of the reference triangle's plane (x, y) with their barycentrics (u, v) and whether
/// they are on the closed triangle.
const PLANE_POINTS: [([f32; 2], [f64; 2], &str); 11] = [
    ([0.0, 0.0], [0.25, 0.25], "interior"),
    ([0.5, -0.5], [0.375, 0.125], "interior"),
    ([1.0, -1.0], [0.5, 0.0], "midpoint of edge v0-v1"),
    ([1.0, 1.0], [0.5, 0.5], "midpoint of edge v1-v2"),
    ([-1.0, 1.0], [0.0, 0.5], "midpoint of edge v2-v0"),
    ([0.0, -1.0], [0.25, 0.0], "quarter point of edge v0-v1"),
    (
        [2.0, 0.0],
        [0.75, 0.25],
        "three-quarter point of edge v1-v2",
    ),
    (
        [-1.0, 2.0],
        [0.0, 0.75],
        "three-quarter point of edge v2-v0",
    ),
    ([-1.0, -1.0], [0.0, 0.0], "vertex v0"),
    ([3.0, -1.0], [1.0, 0.0], "vertex v1"),
    ([-1.0, 3.0], [0.0, 1.0], "vertex v2"),
];

/// Points just outside the closed triangle (by 2^-10) and clearly beside it.
const OUTSIDE_POINTS: [([f32; 2], &str); 7] = [
    ([3.0, 3.0], "beside the hypotenuse"),
    ([1.0, -1.0 - 1.0 / 1024.0], "just beside edge v0-v1"),
    ([-1.0 - 1.0 / 1024.0, 1.0], "just beside edge v2-v0"),
    ([1.0 + 1.0 / 1024.0, 1.0], "just beside edge v1-v2"),
    ([3.0 + 1.0 / 1024.0, -1.0], "just beyond vertex v1"),
    ([-1.0, -1.0 - 1.0 / 1024.0], "just beyond vertex v0"),
    ([-5.0, 7.0], "far beside"),
];

/// Axis-aligned rays (their arithmetic is exact in both modes) through interior points, edges
/// and vertices hit, from the front and the back, with the exact t and barycentrics; 45° rays
/// hit interior points, and points on an edge hit the triangle or its neighbour across that
/// edge (a single triangle's edge is exact only for exact arithmetic); points outside miss.
fn exact_hit_cases<S: TestScalar>() {
    for axis in 0..3 {
        let t = reference::<S>(axis);
        for ([x, y], [u, v], what) in PLANE_POINTS {
            for (z, dz, t_hit) in [(0.0, 1.0, 4.0), (8.0, -1.0, 4.0), (-2.0, 1.0, 6.0)] {
                let r = RaySpec::new(rot([x, y, z], axis), rot([0.0, 0.0, dz], axis));
                let side = if dz > 0.0 { "front" } else { "back" };
                expect_hit(
                    &t,
                    r,
                    Some((t_hit, u, v)),
                    &format!("{what}, axis ray, {side}"),
                );
            }
            // 45° in the (x, z) and (y, z) planes: o + s·d reaches the plane at s = 4.
            for d in [[1.0, 0.0, 1.0], [0.0, -1.0, 1.0], [-1.0, 0.0, -1.0]] {
                let o = [x - 4.0 * d[0], y - 4.0 * d[1], 4.0 - 4.0 * d[2]];
                let r = RaySpec::new(rot(o, axis), rot(d, axis));
                let t_hit = 4.0 * std::f64::consts::SQRT_2;
                let on_edge = [u, v, 1.0 - u - v].iter().filter(|&&w| w == 0.0).count();
                match on_edge {
                    0 => expect_hit(&t, r, Some((t_hit, u, v)), &format!("{what}, 45° ray")),
                    1 => expect_pair_hit(&t, [u, v], r, &format!("{what}, 45° ray")),
                    _ => {} // a vertex: the fan around it is not modelled here
                }
            }
        }
        for ([x, y], what) in OUTSIDE_POINTS {
            for (z, dz) in [(0.0, 1.0), (8.0, -1.0)] {
                let r = RaySpec::new(rot([x, y, z], axis), rot([0.0, 0.0, dz], axis));
                expect_miss(&t, r, what);
            }
        }
    }
}

/// A ray through a point on exactly one edge of `t` (barycentrics `[u, v]`, one weight zero)
/// hits `t` or the triangle mirrored across that edge, which shares the edge's vertices.
fn expect_pair_hit<S: TestScalar>(t: &Triangle<S>, [u, v]: [f64; 2], r: RaySpec, what: &str) {
    let [a, b, c] = t.v;
    // The edge opposite the vertex whose weight is zero.
    let (e0, e1, far) = if u == 0.0 {
        (a, c, b)
    } else if v == 0.0 {
        (a, b, c)
    } else {
        (b, c, a)
    };
    let mirror = Triangle {
        v: [e1, e0, [0, 1, 2].map(|i| e0[i] + e1[i] - far[i])],
    };
    let ray = r.ray::<S>();
    assert!(
        t.intersect(&ray).is_some() || mirror.intersect(&ray).is_some(),
        "{} {what}: ray {r} slips between {:?} and {:?}",
        S::NAME,
        t.v,
        mirror.v
    );
}

/// Oblique rays from random origins (seeded) through random interior points of random
/// triangles: hit from either side at the oracle's t and barycentrics.
fn oblique_interior_cases<S: TestScalar>() {
    const SEED: u64 = 0x7121_0001;
    let mut rng = Rng::new(SEED);
    for case in 0..2000 {
        let v: [[f32; 3]; 3] = [0; 3].map(|_| rng.in_ball(50.0));
        let t = tri::<S>(v);
        let w = t.v.map(|q| q.map(|x| x.to_f32() as f64));
        let area = dot(
            cross(sub(w[1], w[0]), sub(w[2], w[0])),
            cross(sub(w[1], w[0]), sub(w[2], w[0])),
        );
        if area < 1.0 {
            continue; // keep the barycentrics well conditioned
        }
        let (bu, bv) = (rng.range(0.05, 0.9), rng.range(0.05, 0.9));
        if bu + bv > 0.95 {
            continue;
        }
        let target: [f32; 3] = [0, 1, 2].map(|i| {
            (w[0][i] + bu as f64 * (w[1][i] - w[0][i]) + bv as f64 * (w[2][i] - w[0][i])) as f32
        });
        let o = rng.in_ball(100.0);
        let r = RaySpec::new(o, dir_to(o, target));
        // Skip grazing rays: their distance is ill-conditioned.
        let n = cross(sub(w[1], w[0]), sub(w[2], w[0]));
        let cos = dot(n, unit(r.d)).abs() / dot(n, n).sqrt();
        if cos < 0.05 {
            continue;
        }
        expect_hit(
            &t,
            r,
            None,
            &format!("oblique interior hit, seed {SEED:#x} case {case}"),
        );
    }
}

/// Zero-area triangles: collinear (axis-parallel, diagonal, in 3D), a single point, two equal
/// vertices, an edge traversed twice.
const DEGENERATE: [[[f32; 3]; 3]; 6] = [
    [[-1.0, -1.0, 4.0], [3.0, -1.0, 4.0], [1.0, -1.0, 4.0]],
    [[0.0, 0.0, 4.0], [1.0, 1.0, 4.0], [2.0, 2.0, 4.0]],
    [[0.0, 0.0, 0.0], [1.0, 2.0, 3.0], [2.0, 4.0, 6.0]],
    [[1.0, 2.0, 4.0], [1.0, 2.0, 4.0], [1.0, 2.0, 4.0]],
    [[0.0, 0.0, 4.0], [0.0, 0.0, 4.0], [2.0, 0.0, 4.0]],
    [[-3.0, 5.0, 1.0], [5.0, -3.0, 1.0], [-3.0, 5.0, 1.0]],
];

/// Points on a degenerate triangle: its vertices, edge midpoints, quarter and third points.
fn points_on(v: &[[f32; 3]; 3]) -> Vec<[f32; 3]> {
    let mut targets: Vec<[f32; 3]> = v.to_vec();
    for (a, b) in [(0, 1), (1, 2), (2, 0)] {
        for s in [0.5f32, 0.25, 1.0 / 3.0] {
            targets.push([0, 1, 2].map(|i| v[a][i] + s * (v[b][i] - v[a][i])));
        }
    }
    targets
}

/// Zero-area triangles never hit, even for axis-aligned rays passing exactly through them.
fn degenerate_axis_cases<S: TestScalar>() {
    for v in DEGENERATE {
        let t = tri::<S>(v);
        for target in points_on(&v) {
            for axis in 0..3 {
                for sign in [1.0f32, -1.0] {
                    let mut d = [0.0; 3];
                    d[axis] = sign;
                    let mut o = target;
                    o[axis] -= 10.0 * sign;
                    expect_miss(&t, RaySpec::new(o, d), "degenerate, axis ray through it");
                }
            }
        }
    }
}

/// Zero-area triangles never hit oblique rays aimed exactly at their vertices and edge points
/// (seeded random origins, plus small integer origins). Regression: before 8615ae2 f32 hit
/// (-1,-1,4),(3,-1,4),(1,-1,4) from (2,-3,1) along (-3,2,3), and from (-3,-3,-1) along (6,2,5).
fn degenerate_oblique_cases<S: TestScalar>() {
    const SEED: u64 = 0xde9e;
    let mut rng = Rng::new(SEED);
    for v in DEGENERATE {
        let t = tri::<S>(v);
        for target in points_on(&v) {
            // The first repro found: origin (-3, -3, -1) towards (3, -1, 4).
            let mut origins = vec![[-3.0, -3.0, -1.0], [2.0, -3.0, 1.0], [0.0, 0.0, 0.0]];
            origins.extend((0..20).map(|_| rng.in_ball(30.0)));
            for o in origins {
                let what = format!("degenerate, oblique ray through it (seed {SEED:#x})");
                expect_miss(&t, RaySpec::new(o, dir_to(o, target)), &what);
            }
        }
    }
}

#[test]
fn degenerate_triangle_never_hit_by_oblique_ray_f32() {
    degenerate_oblique_cases::<f32>();
}

#[test]
fn degenerate_triangle_never_hit_by_oblique_ray_fixed() {
    degenerate_oblique_cases::<I16F16>();
}

/// A ray in the triangle's plane never hits, whether it crosses the triangle or starts in it.
fn in_plane_cases<S: TestScalar>() {
    for axis in 0..3 {
        let t = reference::<S>(axis);
        for (o, d) in [
            ([-5.0, 0.0, 4.0], [1.0, 0.0, 0.0]),
            ([-5.0, -2.0, 4.0], [1.0, 0.5, 0.0]),
            ([0.0, 0.0, 4.0], [1.0, 0.0, 0.0]),
            ([0.0, 0.0, 4.0], [-1.0, -1.0, -0.0]),
            ([1.0, -1.0, 4.0], [1.0, 0.0, 0.0]), // along edge v0-v1
            ([-3.0, -3.0, 4.0], [1.0, 1.0, 0.0]), // through vertex v0 and the interior
        ] {
            expect_miss(
                &t,
                RaySpec::new(rot(o, axis), rot(d, axis)),
                "ray in the plane",
            );
        }
    }
}

/// The hit at t = 4 is reported only when 4 lies in [t_min, t_max] (both ends inclusive).
fn interval_cases<S: TestScalar>() {
    let t = reference::<S>(2);
    let r = RaySpec::new([0.0, 0.0, 0.0], [0.0, 0.0, 1.0]);
    for (t0, t1, hits) in [
        (0.0, f32::INFINITY, true),
        (4.0, 4.0, true),
        (0.0, 4.0, true),
        (4.0, f32::INFINITY, true),
        (3.9, 4.1, true),
        (0.0, 3.9, false),
        (4.1, f32::INFINITY, false),
        (4.001, 4.001, false),
        (3.999, 3.999, false),
    ] {
        let r = r.interval(t0, t1);
        if hits {
            expect_hit(&t, r, Some((4.0, 0.25, 0.25)), "interval");
            assert_eq!(
                t.intersect(&r.ray::<S>()).unwrap().t,
                c::<S>(4.0),
                "{} t exact, ray {r}",
                S::NAME
            );
        } else {
            expect_miss(&t, r, "interval");
        }
    }
}

fn triangle_cases<S: TestScalar>() {
    exact_hit_cases::<S>();
    oblique_interior_cases::<S>();
    degenerate_axis_cases::<S>();
    in_plane_cases::<S>();
    interval_cases::<S>();
}

#[test]
fn triangle_known_answers_f32() {
    triangle_cases::<f32>();
}

#[test]
fn triangle_known_answers_fixed() {
    triangle_cases::<I16F16>();
}

/// Sphere hit distance, if any, for a ray.
fn sphere_t<S: TestScalar>(s: &Sphere<S>, r: &RaySpec) -> Option<f64> {
    let ray = r.ray::<S>();
    s.hit_t(ray.data(), ray.t_min(), ray.t_max())
        .map(|t| t.to_f32() as f64)
}

fn expect_sphere<S: TestScalar>(
    s: &Sphere<S>,
    r: RaySpec,
    want: Option<f64>,
    tol_scale: f64,
    what: &str,
) {
    let got = sphere_t(s, &r);
    let ok = match (got, want) {
        (None, None) => true,
        (Some(g), Some(w)) => (g - w).abs() <= tol_scale * S::tol(w),
        _ => false,
    };
    assert!(
        ok,
        "{} sphere {what}: centre {:?} radius {:?}, ray {r}: got {got:?}, want {want:?}",
        S::NAME,
        s.center,
        s.radius
    );
}

/// From outside the near root, from inside the far root; misses beside and behind; near
/// tangents just inside hit and just outside miss; the interval selects the root.
fn sphere_cases<S: TestScalar>() {
    for (center, radius) in [([0.0f32, 0.0, 5.0], 1.0f32), ([10.0, -20.0, 30.0], 2.5)] {
        let s = Sphere::<S> {
            center: p(center),
            radius: c(radius),
        };
        let r = radius as f64;
        let at = |dx: f32, dy: f32, dz: f32| [center[0] + dx, center[1] + dy, center[2] + dz];
        let z = RaySpec::new(at(0.0, 0.0, -5.0), [0.0, 0.0, 1.0]);
        expect_sphere(&s, z, Some(5.0 - r), 1.0, "from outside: near root");
        expect_sphere(
            &s,
            z.interval(5.0 - radius + 0.5, f32::INFINITY),
            Some(5.0 + r),
            1.0,
            "t_min past the near root: far root",
        );
        expect_sphere(
            &s,
            z.interval(0.0, 5.0 - radius - 0.5),
            None,
            1.0,
            "t_max before the near root",
        );
        expect_sphere(
            &s,
            z.interval(5.0 + radius + 0.5, f32::INFINITY),
            None,
            1.0,
            "t_min past both roots",
        );
        expect_sphere(
            &s,
            RaySpec::new(at(0.0, 0.0, 5.0), [0.0, 0.0, 1.0]),
            None,
            1.0,
            "sphere behind",
        );
        expect_sphere(
            &s,
            RaySpec::new(at(1.5 * radius, 0.0, -5.0), [0.0, 0.0, 1.0]),
            None,
            1.0,
            "beside",
        );
        for d in [
            [0.0, 0.0, 1.0],
            [-1.0, 0.0, 0.0],
            [1.0, -2.0, 3.0],
            [-0.0, 1.0, -0.0],
        ] {
            expect_sphere(
                &s,
                RaySpec::new(center, d),
                Some(r),
                1.0,
                "from the centre: far root",
            );
        }
        let h = radius * 0.5;
        let inside = at(h, 0.0, 0.0);
        let chord = (r * r - (h as f64) * (h as f64)).sqrt();
        expect_sphere(
            &s,
            RaySpec::new(inside, [1.0, 0.0, 0.0]),
            Some(r - h as f64),
            1.0,
            "inside, towards near wall",
        );
        expect_sphere(
            &s,
            RaySpec::new(inside, [-1.0, 0.0, 0.0]),
            Some(r + h as f64),
            1.0,
            "inside, towards far wall",
        );
        expect_sphere(
            &s,
            RaySpec::new(inside, [0.0, 0.0, 1.0]),
            Some(chord),
            1.0,
            "inside, sideways",
        );
        // Tangent-ish: offsets 0.999 r (hits, ill-conditioned so a wider tolerance) and 1.001 r.
        let off = 0.999 * radius;
        let depth = ((r * r) - (off as f64) * (off as f64)).sqrt();
        expect_sphere(
            &s,
            RaySpec::new(at(off, 0.0, -5.0), [0.0, 0.0, 1.0]),
            Some(5.0 - depth),
            20.0,
            "nearly tangent, inside",
        );
        expect_sphere(
            &s,
            RaySpec::new(at(1.001 * radius, 0.0, -5.0), [0.0, 0.0, 1.0]),
            None,
            1.0,
            "nearly tangent, outside",
        );
        // Oblique rays at the centre from random outside points (seeded): t = distance - r.
        let mut rng = Rng::new(0x5e7e);
        for _ in 0..200 {
            let dir = rng.unit_vec();
            let dist = rng.range(2.0, 40.0) * radius;
            let o = at(-dir[0] * dist, -dir[1] * dist, -dir[2] * dist);
            let r_spec = RaySpec::new(o, dir_to(o, center));
            let exact = (0..3)
                .map(|i| (center[i] as f64 - o[i] as f64).powi(2))
                .sum::<f64>()
                .sqrt()
                - r;
            expect_sphere(
                &s,
                r_spec,
                Some(exact),
                1.0,
                "oblique from outside at the centre",
            );
        }
    }
}

#[test]
fn sphere_known_answers_f32() {
    sphere_cases::<f32>();
}

#[test]
fn sphere_known_answers_fixed() {
    sphere_cases::<I16F16>();
}
