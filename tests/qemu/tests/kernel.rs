//! On-target tests (defmt-test under QEMU): known answers, BVH vs brute force for every
//! builder and leaf size in both modes, typed errors, the golden hashes the host computes, and
//! the stack high-water mark of a build and a traversal.
#![no_std]
#![no_main]

use cortex_m_rt as _; // defmt-test doesn't link it; the vector table and reset handler
use defmt_semihosting as _; // global logger: defmt frames to semihosting stdout
use panic_probe as _; // prints the panic via defmt, then `udf` -> HardFault

use raykernel::bvh::{nodes_needed, BuildOptions, BuilderKind};
use raykernel::{Accel, Bvh, Linear, Node, Primitive, Scalar, Triangle};
use raykernel_qemu::cases::{self, Bits, ICO_TRIS};
use raykernel_qemu::golden;
use raykernel_qemu::{check_golden, fail_name, stack};

#[defmt::panic_handler]
fn defmt_panic() -> ! {
    panic_probe::hard_fault()
}

/// The default handler spins, so QEMU would hang until the runner's timeout: exit instead.
#[cortex_m_rt::exception]
unsafe fn HardFault(_: &cortex_m_rt::ExceptionFrame) -> ! {
    semihosting::process::exit(101)
}

fn near(x: f32, want: f32, tol: f32) -> bool {
    x >= want - tol && x <= want + tol
}

fn slab_cases<S: Scalar>() {
    use raykernel::{Aabb, Ray};
    let unit = Aabb::<S>::new([S::ZERO; 3], [S::from_f32_saturating(1.0); 3]);
    let entry = |o: [f32; 3], d: [f32; 3], t_max: f32| {
        let r = Ray::<S>::from_f32(o, d, 0.0, t_max).ok()?;
        unit.slab(&r).map(S::to_f32)
    };
    let x = [1.0, 0.0, 0.0];
    let inf = f32::INFINITY;
    // Conservative: the entry is a lower bound within a small margin of the exact one.
    let hit = |t: Option<f32>, exact: f32| t.is_some_and(|t| t <= exact && t >= exact - 1e-4);
    defmt::assert!(
        hit(entry([-1.0, 0.5, 0.5], x, inf), 1.0),
        "{} head-on",
        S::NAME
    );
    defmt::assert!(
        hit(entry([-1.0, 1.0, 0.5], x, inf), 1.0),
        "{} in a face",
        S::NAME
    );
    defmt::assert!(
        hit(entry([-1.0, 1.0, 1.0], x, inf), 1.0),
        "{} along an edge",
        S::NAME
    );
    defmt::assert!(
        hit(entry([0.5, 0.5, 0.5], x, inf), 0.0),
        "{} from inside",
        S::NAME
    );
    let diag = entry([-1.0, -1.0, -1.0], [1.0, 1.0, 1.0], inf);
    defmt::assert!(hit(diag, 1.732_050_8), "{} diagonal", S::NAME);
    defmt::assert!(
        entry([-1.0, 2.0, 0.5], x, inf).is_none(),
        "{} parallel outside",
        S::NAME
    );
    defmt::assert!(
        entry([2.0, 0.5, 0.5], x, inf).is_none(),
        "{} box behind",
        S::NAME
    );
    defmt::assert!(
        entry([-1.0, 0.5, 0.5], x, 0.5).is_none(),
        "{} interval ends before",
        S::NAME
    );
}

fn triangle_cases<S: Scalar + Bits>() {
    use raykernel::{Ray, Sphere, TriangleHit};
    let tri = Triangle::<S>::from_f32([[-1.0, -1.0, 5.0], [1.0, -1.0, 5.0], [0.0, 1.0, 5.0]]);
    defmt::assert!(tri.is_ok());
    let Ok(tri) = tri else { return };
    let f = S::from_f32_saturating;
    let hit = |o: [f32; 3], d: [f32; 3], t_max: f32| {
        let r = Ray::<S>::from_f32(o, d, 0.0, t_max).ok()?;
        tri.intersect(&r)
    };
    let bits = |h: Option<TriangleHit<S>>| h.map(|h| (h.t.bits(), h.u.bits(), h.v.bits()));
    // Interior point (0, 0) = 0.25·b + 0.5·c + 0.25·a: exact in both modes.
    let want = Some((f(5.0).bits(), f(0.25).bits(), f(0.5).bits()));
    let inf = f32::INFINITY;
    defmt::assert_eq!(
        bits(hit([0.0; 3], [0.0, 0.0, 1.0], inf)),
        want,
        "{} front",
        S::NAME
    );
    let back = hit([0.0, 0.0, 10.0], [0.0, 0.0, -1.0], inf);
    defmt::assert_eq!(bits(back), want, "{} back (two-sided)", S::NAME);
    let vertex = hit([1.0, -1.0, 0.0], [0.0, 0.0, 1.0], inf);
    let want_v = Some((f(5.0).bits(), f(1.0).bits(), f(0.0).bits()));
    defmt::assert_eq!(bits(vertex), want_v, "{} vertex (inclusive)", S::NAME);
    let edge = hit([0.0, -1.0, 0.0], [0.0, 0.0, 1.0], inf);
    let want_e = Some((f(5.0).bits(), f(0.5).bits(), f(0.0).bits()));
    defmt::assert_eq!(bits(edge), want_e, "{} edge (inclusive)", S::NAME);
    defmt::assert!(
        hit([2.0, 0.0, 0.0], [0.0, 0.0, 1.0], inf).is_none(),
        "{} outside",
        S::NAME
    );
    defmt::assert!(
        hit([0.0; 3], [0.0, 0.0, 1.0], 4.0).is_none(),
        "{} t_max",
        S::NAME
    );
    defmt::assert!(
        hit([0.0; 3], [0.0, 0.0, -1.0], inf).is_none(),
        "{} behind",
        S::NAME
    );
    let flat = Triangle::<S>::from_f32([[0.0, 0.0, 5.0], [1.0, 0.0, 5.0], [2.0, 0.0, 5.0]]);
    let r = Ray::<S>::from_f32([0.5, 0.0, 0.0], [0.0, 0.0, 1.0], 0.0, inf);
    if let (Ok(flat), Ok(r)) = (flat, r) {
        defmt::assert!(flat.intersect(&r).is_none(), "{} degenerate", S::NAME);
    } else {
        defmt::panic!("{} degenerate case rejected", S::NAME);
    }
    // Sphere of radius 1 at z = 5: t = 4 from outside, 1 from the centre.
    let s = Sphere::<S> {
        center: [S::ZERO, S::ZERO, f(5.0)],
        radius: f(1.0),
    };
    for (o, t) in [([0.0, 0.0, 0.0], 4.0), ([0.0, 0.0, 5.0], 1.0)] {
        let r = Ray::<S>::from_f32(o, [0.0, 0.0, 1.0], 0.0, inf);
        let got = r.ok().and_then(|r| s.hit_t(r.data(), r.t_min(), r.t_max()));
        defmt::assert!(
            got.is_some_and(|g| near(g.to_f32(), t, 1e-4)),
            "{} sphere",
            S::NAME
        );
    }
}

/// Every builder and leaf size, arena sized by `nodes_needed`: validate, then every query
/// equals brute force bit for bit; the leaf-order build reproduces the golden brute-force hash.
fn bvh_vs_linear<S: Bits>(linear_golden: &str) {
    let mut tris = cases::empty_mesh::<S>();
    if let Err(e) = cases::icosphere(&mut tris) {
        defmt::panic!("{}", fail_name(e));
    }
    let mut nodes = [Node::<S>::EMPTY; nodes_needed(ICO_TRIS)];
    let mut ids = [0u32; ICO_TRIS];
    let mut builds = 0;
    for builder in BuilderKind::ALL {
        for max_leaf_size in [1, 2, 4, 8] {
            let options = BuildOptions {
                builder,
                max_leaf_size,
                reinsertion: true,
            };
            let bvh = Bvh::build(&tris, &mut nodes, &mut ids, options);
            defmt::assert!(
                bvh.is_ok(),
                "{} {} leaf {}: build",
                S::NAME,
                builder.name(),
                max_leaf_size
            );
            let Ok(bvh) = bvh else { return };
            defmt::assert!(
                bvh.validate().is_ok(),
                "{} {}: validate",
                S::NAME,
                builder.name()
            );
            if let Err(e) = cases::same_queries(&bvh, &Linear::new(&tris)) {
                defmt::panic!(
                    "{} {} leaf {}: {}",
                    S::NAME,
                    builder.name(),
                    max_leaf_size,
                    fail_name(e)
                );
            }
            builds += 1;
        }
    }
    defmt::assert_eq!(builds, 12);
    let want = golden::expected(linear_golden);
    let bvh = Bvh::build_in_leaf_order(&mut tris, &mut nodes, &mut ids, BuildOptions::default());
    defmt::assert!(bvh.is_ok(), "{} leaf-order build", S::NAME);
    if let Ok(bvh) = bvh {
        defmt::assert!(bvh.validate().is_ok() && bvh.is_leaf_order());
        defmt::assert_eq!(
            cases::hash_queries(&bvh).ok(),
            want,
            "{} leaf order vs brute force",
            S::NAME
        );
    }
}

fn error_cases<S: Scalar>() {
    use raykernel::{Arena, BuildError, PointError, Ray, RayError};
    const N: usize = 6;
    let t = |z: f32| Triangle::<S>::from_f32([[0.0, 0.0, z], [1.0, 0.0, z], [0.0, 1.0, z]]);
    let mut tris = [Triangle {
        v: [[S::ZERO; 3]; 3],
    }; N];
    for (i, tri) in tris.iter_mut().enumerate() {
        match t(i as f32) {
            Ok(x) => *tri = x,
            Err(_) => defmt::panic!("{} triangle rejected", S::NAME),
        }
    }
    let mut nodes = [Node::<S>::EMPTY; nodes_needed(N)];
    let mut ids = [0u32; N];
    let opt = BuildOptions::default();
    let short = nodes_needed(N) - 1;
    let e = Bvh::build(&tris, &mut nodes[..short], &mut ids, opt).err();
    let want = BuildError::ArenaTooSmall {
        arena: Arena::Nodes,
        needed: nodes_needed(N),
        available: short,
    };
    defmt::assert!(e == Some(want), "{} node arena too small", S::NAME);
    let e = Bvh::build(&tris, &mut nodes, &mut ids[..N - 1], opt).err();
    let want = BuildError::ArenaTooSmall {
        arena: Arena::PrimIds,
        needed: N,
        available: N - 1,
    };
    defmt::assert!(e == Some(want), "{} id arena too small", S::NAME);
    for max_leaf_size in [0, raykernel::bvh::MAX_LEAF_SIZE + 1] {
        let o = BuildOptions {
            max_leaf_size,
            reinsertion: true,
            ..opt
        };
        let e = Bvh::build(&tris, &mut nodes, &mut ids, o).err();
        defmt::assert!(
            e == Some(BuildError::BadLeafSize { max_leaf_size }),
            "{} leaf size",
            S::NAME
        );
    }
    // A vertex outside the mode's range (f32: NaN; fixed point: beyond 8192).
    let (bad, err) = if S::NAME == "f32" {
        (S::from_f32_saturating(f32::INFINITY), PointError::NonFinite)
    } else {
        (
            S::from_f32_saturating(9000.0),
            PointError::OutOfRange {
                limit: raykernel::FIXED_COORD_LIMIT,
            },
        )
    };
    tris[3].v[1][2] = bad;
    let e = Bvh::build(&tris, &mut nodes, &mut ids, opt).err();
    let want = BuildError::BadPrimitive {
        prim: 3,
        vertex: 1,
        error: err,
    };
    defmt::assert!(e == Some(want), "{} bad vertex", S::NAME);
    let r = |o: [f32; 3], d: [f32; 3], t0: f32, t1: f32| Ray::<S>::from_f32(o, d, t0, t1).err();
    let (z, x) = ([0.0; 3], [1.0, 0.0, 0.0]);
    defmt::assert!(
        r(z, z, 0.0, 1.0) == Some(RayError::ZeroDirection),
        "{} zero dir",
        S::NAME
    );
    let nan = [f32::NAN, 0.0, 0.0];
    defmt::assert!(r(z, nan, 0.0, 1.0) == Some(RayError::NonFiniteDirection));
    defmt::assert!(r(nan, x, 0.0, 1.0) == Some(RayError::Origin(PointError::NonFinite)));
    defmt::assert!(r(z, x, 2.0, 1.0) == Some(RayError::InvalidInterval));
    defmt::assert!(r(z, x, -1.0, 1.0) == Some(RayError::InvalidInterval));
}

fn stack_case<S: Bits>() -> (usize, usize) {
    let mut tris = cases::empty_mesh::<S>();
    if let Err(e) = cases::icosphere(&mut tris) {
        defmt::panic!("{}", fail_name(e));
    }
    let mut nodes = [Node::<S>::EMPTY; nodes_needed(ICO_TRIS)];
    let mut ids = [0u32; ICO_TRIS];
    let build = stack::stack_use(|| {
        let b = Bvh::build(&tris, &mut nodes, &mut ids, BuildOptions::default());
        core::hint::black_box(b.is_ok());
    });
    let bvh = Bvh::build(&tris, &mut nodes, &mut ids, BuildOptions::default());
    let Ok(bvh) = bvh else {
        defmt::panic!("build failed")
    };
    let mut hits = 0;
    let trace = stack::stack_use(|| {
        for i in 0..cases::RAY_COUNT {
            if let Ok(r) = cases::ray::<S>(i) {
                hits += bvh.intersect(&r).is_some() as u32;
                hits += bvh.occluded(&r) as u32;
            }
        }
    });
    defmt::assert!(hits > 0);
    (build, trace)
}

#[defmt_test::tests]
mod tests {
    use super::*;
    use raykernel::I16F16;

    #[test]
    fn golden_table_and_case_list_agree() {
        // First test: paint the free stack, so the last test can report the peak of the run.
        stack::paint(cortex_m::register::msp::read() as usize - 256);
        defmt::assert_eq!(golden::GOLDEN.len(), cases::NAMES.len());
        for (&(name, _), &case) in golden::GOLDEN.iter().zip(cases::NAMES.iter()) {
            defmt::assert_eq!(name, case);
        }
    }
    #[test]
    fn golden_rays_f32() {
        check_golden("rays_f32")
    }
    #[test]
    fn golden_rays_fixed() {
        check_golden("rays_fixed")
    }
    #[test]
    fn golden_linear_f32() {
        check_golden("linear_f32")
    }
    #[test]
    fn golden_linear_fixed() {
        check_golden("linear_fixed")
    }
    #[test]
    fn golden_spheres_f32() {
        check_golden("spheres_f32")
    }
    #[test]
    fn golden_spheres_fixed() {
        check_golden("spheres_fixed")
    }
    #[test]
    fn golden_tree_f32_sah() {
        check_golden("tree_f32_sah")
    }
    #[test]
    fn golden_tree_f32_median() {
        check_golden("tree_f32_median")
    }
    #[test]
    fn golden_tree_f32_midpoint() {
        check_golden("tree_f32_midpoint")
    }
    #[test]
    fn golden_tree_fixed_sah() {
        check_golden("tree_fixed_sah")
    }
    #[test]
    fn golden_tree_fixed_median() {
        check_golden("tree_fixed_median")
    }
    #[test]
    fn golden_tree_fixed_midpoint() {
        check_golden("tree_fixed_midpoint")
    }
    #[test]
    fn slab_known_answers_f32() {
        slab_cases::<f32>()
    }
    #[test]
    fn slab_known_answers_fixed() {
        slab_cases::<I16F16>()
    }
    #[test]
    fn triangle_and_sphere_known_answers_f32() {
        triangle_cases::<f32>()
    }
    #[test]
    fn triangle_and_sphere_known_answers_fixed() {
        triangle_cases::<I16F16>()
    }
    #[test]
    fn bvh_every_builder_matches_brute_force_f32() {
        bvh_vs_linear::<f32>("linear_f32")
    }
    #[test]
    fn bvh_every_builder_matches_brute_force_fixed() {
        bvh_vs_linear::<I16F16>("linear_fixed")
    }
    #[test]
    fn typed_errors_f32() {
        error_cases::<f32>()
    }
    #[test]
    fn typed_errors_fixed() {
        error_cases::<I16F16>()
    }
    #[test]
    fn i16f16_arithmetic_rounds_and_saturates() {
        let f = I16F16::from_f32;
        defmt::assert!(f(1.5) * f(2.0) == f(3.0));
        defmt::assert_eq!((f(1.0) / f(3.0)).raw(), 21845);
        defmt::assert!(I16F16::MAX + I16F16::ONE == I16F16::MAX);
        defmt::assert!(I16F16::MIN - I16F16::ONE == I16F16::MIN);
        defmt::assert!(-I16F16::MIN == I16F16::MAX);
        defmt::assert!(f(20000.0) * f(20000.0) == I16F16::MAX);
        defmt::assert!(f(1.0) / I16F16::ZERO == I16F16::MAX);
        defmt::assert!(f(f32::NAN) == I16F16::ZERO);
        defmt::assert_eq!(f(-2.5).to_f32(), -2.5);
    }
    #[test]
    fn stack_high_water_mark() {
        let (bf, tf) = stack_case::<f32>();
        let (bx, tx) = stack_case::<I16F16>();
        defmt::info!("stack high-water: build f32 {=usize} B, fixed {=usize} B; trace f32 {=usize} B, fixed {=usize} B", bf, bx, tf, tx);
        // Traversal reserves MAX_DEPTH x 8 bytes but only touches the entries it pushes (the
        // zero fill is optimised away); builds keep SAH bins (4-lane boxes, 3.4 KB) and a
        // pending-node stack, and the reinsertion pass adds its own frame (search stack and
        // size histogram, about 0.8 KB; 1.3 KB on the M0) on top: 8.6 KB on the M4F, 9.1 KB on
        // the M0.
        defmt::assert!(tf > 0 && tx > 0 && bf > tf && bx > tx);
        defmt::assert!(
            bf.max(bx).max(tf).max(tx) < 10 * 1024,
            "over 10 KB of stack"
        );
    }
    /// Last test: how much of the stack the whole run used. Fails when less than 512 bytes of
    /// the target's RAM stay free, before an overflow would.
    #[test]
    fn stack_headroom_of_the_whole_run() {
        stack::assert_headroom();
    }
}
