//! Cases found on the shared scenes, kept so they stay fixed. Values are copied as printed
//! (more digits than f32 holds), so they parse to the exact bits of the failing cases.
#![allow(clippy::excessive_precision)]

use raykernel::{Ray, Triangle, TriangleHit};

/// Long, thin, axis-flat slivers from sponza (triangles 10474 and 62480): the f32 edge
/// functions keep too few bits for an accurate `t`, which once pushed the hit point outside
/// the triangle's own box and dropped a real hit. Expected values are from an f64 solve.
#[test]
fn sponza_slivers_are_hit_with_accurate_t() {
    let cases = [
        (
            [
                [0.00724, 5.86330986, -2.41851091],
                [-10.8127594, 5.86330986, -2.41850996],
                [-10.8127594, 5.84830999, -2.41850996],
            ],
            [0.655276358127594, 0.6132783889770508, -0.4410243332386017],
            5.4838475f64,
        ),
        (
            [
                [-0.58286798, 4.89562082, -2.5185101],
                [-0.290360004, 4.95380402, -2.5185101],
                [-10.9127598, 5.72331095, -2.5185101],
            ],
            [0.6343224048614502, 0.5914830565452576, -0.49777793884277344],
            5.0595053,
        ),
    ];
    for (verts, dir, t_exact) in cases {
        let tri = Triangle::<f32>::from_f32(verts).unwrap();
        let ray = Ray::<f32>::from_f32([-11.0, 2.5, 0.0], dir, 0.0, f32::INFINITY).unwrap();
        let TriangleHit { t, .. } = tri
            .intersect(&ray)
            .unwrap_or_else(|| panic!("missed {verts:?}"));
        assert!(
            (t as f64 - t_exact).abs() < 2e-6 * t_exact,
            "t = {t}, want {t_exact}"
        );
    }
}

/// Found by the fuzz target `accel_equivalence`: a ray through a vertex of a triangle with
/// subnormal coordinates got `v = -9.7e-44` (the candidate solve's sign disagreed with the f32
/// edge functions that accepted the hit). Barycentrics of a hit are now clamped to `[0, 1]`, as
/// the fixed-point mode already did. The exact edge functions decide that the fuzzer's own
/// ray passes just outside the vertex, so the rays tried sweep its direction over 64 ulps
/// each way and start at the origin or behind vertex 1 along themselves: some hit, and every
/// hit's barycentrics lie in `[0, 1]`.
#[test]
fn barycentrics_of_a_hit_stay_in_unit_interval() {
    let tri = Triangle::<f32>::from_f32([
        [8192.0, -25.25, -2.5743157e-22],
        [2.2864516e-37, 9.1482e-41, 0.0],
        [8192.0, 8192.0, 8192.0],
    ])
    .unwrap();
    let d = [0.99999523f32, -0.0030822607, -3.1424604e-26];
    let mut hits = 0;
    for step in -64i32..=64 {
        let dy = f32::from_bits((d[1].to_bits() as i32 + step) as u32);
        // From the origin, and from points behind vertex 1 along the ray.
        let back = [0.0, 1e-36, 1e-30, 1e-20, 1e-3][(step & 3) as usize + (step == 0) as usize];
        let o = [-back * d[0], -back * dy, -back * d[2]];
        let ray = Ray::<f32>::from_f32(o, [d[0], dy, d[2]], 0.0, f32::INFINITY).unwrap();
        if let Some(TriangleHit { t, u, v }) = tri.intersect(&ray) {
            hits += 1;
            assert!(t >= 0.0);
            for w in [u, v] {
                assert!(
                    (0.0..=1.0).contains(&w),
                    "barycentric {w} (u {u}, v {v}), y {dy:e}"
                );
            }
        }
    }
    assert!(hits > 0, "no ray of the sweep hits the triangle");
}
