//! Known answers for the slab, triangle and sphere tests in either mode: each case returns
//! the name of the first check that failed. Exact values where both modes represent them
//! exactly (the triangle hits), bounds where the test is conservative by design (the slab's
//! entry distance is a lower bound within 1e-4).

use crate::cases::Bits;
use raykernel::{Aabb, Primitive, Ray, Scalar, Sphere, Triangle};

/// A check that failed, by name.
pub type Failed = &'static str;

fn check(ok: bool, name: Failed) -> Result<(), Failed> {
    if ok {
        Ok(())
    } else {
        Err(name)
    }
}

/// The unit box entered along the axis, through a face, along an edge, from inside and
/// diagonally; missed when parallel outside, behind, or when the interval ends first.
pub fn slab<S: Scalar>() -> Result<(), Failed> {
    let unit = Aabb::<S>::new([S::ZERO; 3], [S::from_f32_saturating(1.0); 3]);
    let entry = |o: [f32; 3], d: [f32; 3], t_max: f32| {
        let r = Ray::<S>::from_f32(o, d, 0.0, t_max).ok()?;
        unit.slab(&r).map(S::to_f32)
    };
    let x = [1.0, 0.0, 0.0];
    let inf = f32::INFINITY;
    let near = |t: Option<f32>, exact: f32| t.is_some_and(|t| t <= exact && t >= exact - 1e-4);
    check(near(entry([-1.0, 0.5, 0.5], x, inf), 1.0), "slab head-on")?;
    check(near(entry([-1.0, 1.0, 0.5], x, inf), 1.0), "slab in a face")?;
    check(
        near(entry([-1.0, 1.0, 1.0], x, inf), 1.0),
        "slab along an edge",
    )?;
    check(
        near(entry([0.5, 0.5, 0.5], x, inf), 0.0),
        "slab from inside",
    )?;
    let diagonal = entry([-1.0, -1.0, -1.0], [1.0, 1.0, 1.0], inf);
    check(near(diagonal, 1.732_050_8), "slab diagonal")?;
    check(
        entry([-1.0, 2.0, 0.5], x, inf).is_none(),
        "slab parallel outside",
    )?;
    check(entry([2.0, 0.5, 0.5], x, inf).is_none(), "slab box behind")?;
    check(
        entry([-1.0, 0.5, 0.5], x, 0.5).is_none(),
        "slab interval ends first",
    )
}

/// One triangle at z = 5 hit inside, from behind (two-sided), on a vertex and an edge
/// (inclusive), with exact `t` and barycentrics; missed outside, beyond `t_max`, behind the
/// origin; a zero-area triangle is never hit. A unit sphere at z = 5 from outside and inside.
pub fn triangle_and_sphere<S: Scalar + Bits>() -> Result<(), Failed> {
    let tri = Triangle::<S>::from_f32([[-1.0, -1.0, 5.0], [1.0, -1.0, 5.0], [0.0, 1.0, 5.0]])
        .map_err(|_| "triangle rejected")?;
    let f = S::from_f32_saturating;
    let hit = |o: [f32; 3], d: [f32; 3], t_max: f32| {
        let r = Ray::<S>::from_f32(o, d, 0.0, t_max).ok()?;
        tri.intersect(&r)
            .map(|h| [h.t.bits(), h.u.bits(), h.v.bits()])
    };
    let want = |t: f32, u: f32, v: f32| Some([f(t).bits(), f(u).bits(), f(v).bits()]);
    let (z, inf) = ([0.0, 0.0, 1.0], f32::INFINITY);
    check(
        hit([0.0; 3], z, inf) == want(5.0, 0.25, 0.5),
        "triangle front",
    )?;
    let back = hit([0.0, 0.0, 10.0], [0.0, 0.0, -1.0], inf);
    check(back == want(5.0, 0.25, 0.5), "triangle back (two-sided)")?;
    let vertex = hit([1.0, -1.0, 0.0], z, inf);
    check(vertex == want(5.0, 1.0, 0.0), "triangle vertex (inclusive)")?;
    let edge = hit([0.0, -1.0, 0.0], z, inf);
    check(edge == want(5.0, 0.5, 0.0), "triangle edge (inclusive)")?;
    check(hit([2.0, 0.0, 0.0], z, inf).is_none(), "triangle outside")?;
    check(hit([0.0; 3], z, 4.0).is_none(), "triangle beyond t_max")?;
    check(
        hit([0.0; 3], [0.0, 0.0, -1.0], inf).is_none(),
        "triangle behind",
    )?;
    let flat = Triangle::<S>::from_f32([[0.0, 0.0, 5.0], [1.0, 0.0, 5.0], [2.0, 0.0, 5.0]])
        .map_err(|_| "zero-area triangle rejected")?;
    let r = Ray::<S>::from_f32([0.5, 0.0, 0.0], z, 0.0, inf).map_err(|_| "ray rejected")?;
    check(flat.intersect(&r).is_none(), "zero-area triangle hit")?;
    let s = Sphere::<S> {
        center: [S::ZERO, S::ZERO, f(5.0)],
        radius: f(1.0),
    };
    for (o, t) in [([0.0, 0.0, 0.0], 4.0), ([0.0, 0.0, 5.0], 1.0)] {
        let r = Ray::<S>::from_f32(o, z, 0.0, inf).map_err(|_| "ray rejected")?;
        let got = s.hit_t(r.data(), r.t_min(), r.t_max()).map(S::to_f32);
        check(
            got.is_some_and(|g| libm::fabsf(g - t) <= 1e-4),
            "sphere distance",
        )?;
    }
    Ok(())
}
