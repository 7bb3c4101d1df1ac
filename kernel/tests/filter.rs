//! The Gaussian pixel filter: the offsets it draws follow the truncated normal (mean 0, the
//! truncated variance, never past the radius), a render places its samples by it (a sharp
//! emitter edge seen through pixels at known distances gives the filter's known mass past the
//! edge), and bad parameters are typed errors.

mod common;

use raykernel::render::sampling::gaussian;
use raykernel::render::{
    Camera, Filter, Integrator, Item, Material, Object, Problem, SamplerKind, Scene, Settings,
    Shape,
};
use raykernel::Triangle;

/// Standard errors a mean may lie from its expected value.
const Z: f64 = 5.0;

/// `Φ`, the standard normal CDF.
fn phi(x: f64) -> f64 {
    0.5 * (1.0 + libm::erf(x / std::f64::consts::SQRT_2))
}

/// The CDF at `x` of the normal of deviation `sigma` truncated to `[-radius, radius]`.
fn truncated_cdf(x: f64, sigma: f64, radius: f64) -> f64 {
    let lo = phi(-radius / sigma);
    ((phi(x.clamp(-radius, radius) / sigma) - lo) / (phi(radius / sigma) - lo)).clamp(0.0, 1.0)
}

#[test]
fn gaussian_offsets_have_the_truncated_normal_moments() {
    const N: usize = 200_000;
    for (sigma, radius) in [
        (0.5f32, 1.5f32),
        (0.3, 2.0),
        (1.0, 1.0),
        (2.0, 16.0),
        (0.25, 0.1),
    ] {
        let (s, r) = (f64::from(sigma), f64::from(radius));
        let mut previous = f32::NEG_INFINITY;
        let (mut sum, mut sum2) = (0.0f64, 0.0f64);
        for i in 0..N {
            // Midpoints of N equal cells of [0, 1): a quadrature of the inverse CDF.
            let u = ((i as f64 + 0.5) / N as f64) as f32;
            let x = gaussian(u, sigma, radius);
            assert!(x.abs() < radius, "σ {sigma} r {radius}: u {u} gives {x}");
            assert!(x >= previous, "σ {sigma} r {radius}: not monotone at u {u}");
            previous = x;
            sum += f64::from(x);
            sum2 += f64::from(x) * f64::from(x);
        }
        let mean = sum / N as f64;
        let var = sum2 / N as f64;
        // Variance of the normal truncated to [-a, a] in units of σ:
        // σ²·(1 − 2a·φ(a) / (2Φ(a) − 1)).
        let a = r / s;
        let density = (-a * a / 2.0).exp() / (2.0 * std::f64::consts::PI).sqrt();
        let want = s * s * (1.0 - 2.0 * a * density / (2.0 * phi(a) - 1.0));
        assert!(mean.abs() < 1e-5 * s, "σ {sigma} r {radius}: mean {mean}");
        assert!(
            (var - want).abs() < 1e-3 * want,
            "σ {sigma} r {radius}: variance {var}, want {want}"
        );
    }
    // The ends of [0, 1) stay finite and inside the radius, however wide it is against σ.
    for (sigma, radius) in [(0.5f32, 1.5f32), (0.01, 16.0), (1e-6, 16.0), (16.0, 0.5)] {
        for u in [0.0f32, 1.0 - f32::EPSILON / 2.0, 0.5] {
            let x = gaussian(u, sigma, radius);
            assert!(x.abs() < radius, "σ {sigma} r {radius} u {u}: {x}");
        }
    }
    // Untruncated in effect (radius 16σ): the variance is σ².
    let v: f64 = (0..N)
        .map(|i| f64::from(gaussian(((i as f64 + 0.5) / N as f64) as f32, 0.5, 8.0)).powi(2))
        .sum::<f64>()
        / N as f64;
    assert!((v - 0.25).abs() < 1e-3 * 0.25, "{v}");
}

/// An emissive half-plane `x >= 0` at `z = -1` seen head-on by a pinhole at the origin, the
/// image 8 pixels wide, so the edge falls on the boundary between columns 3 and 4.
fn edge_image(filter: Filter, spp: u32) -> Vec<[f32; 3]> {
    let p = |x: f32, y: f32| [x, y, -1.0];
    let tris = [
        Triangle::<f32>::from_f32([p(0.0, -9.0), p(9.0, -9.0), p(9.0, 9.0)]).unwrap(),
        Triangle::<f32>::from_f32([p(0.0, -9.0), p(9.0, 9.0), p(0.0, 9.0)]).unwrap(),
    ];
    let objects = [Object::new(Shape::Triangles(&tris), 0)];
    let scene = Scene {
        objects: &objects,
        materials: &[Material::Emissive { radiance: [1.0; 3] }],
        lights: &[],
        camera: Camera {
            eye: [0.0; 3],
            look_at: [0.0, 0.0, -1.0],
            up: [0.0, 1.0, 0.0],
            vfov_deg: 60.0,
            aperture_radius: 0.0,
            focus_distance: 1.0,
        },
        background: [0.0; 3],
    };
    let settings = Settings {
        width: 8,
        height: 32,
        spp,
        integrator: Integrator::Direct,
        sampler: SamplerKind::Independent,
        filter,
        seed: 3,
        ..Settings::default()
    };
    common::render_linear(&scene, settings).unwrap()
}

#[test]
fn a_render_places_its_samples_by_the_gaussian_filter() {
    let (sigma, radius) = (0.5f32, 1.5f32);
    let image = edge_image(Filter::Gaussian { sigma, radius }, 64);
    let column =
        |x: usize| -> Vec<f64> { (0..32).map(|y| f64::from(image[y * 8 + x][0])).collect() };
    // Columns whose whole support lies on one side: exactly dark or exactly lit.
    assert!(column(2).iter().all(|&v| v == 0.0), "{:?}", column(2));
    assert!(column(5).iter().all(|&v| v == 1.0), "{:?}", column(5));
    // Column 3 (centre 0.5 left of the edge) sees the mass past +0.5, column 4 past -0.5.
    for (x, offset) in [(3usize, 0.5f64), (4, -0.5)] {
        let want = 1.0 - truncated_cdf(offset, f64::from(sigma), f64::from(radius));
        let v = column(x);
        let n = v.len() as f64;
        let mean = v.iter().sum::<f64>() / n;
        let se = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0) / n).sqrt();
        assert!(se < 0.02, "column {x}: error {se}");
        assert!(
            (mean - want).abs() <= Z * se,
            "column {x}: mean {mean}, want {want} ± {}",
            Z * se
        );
    }
    // The box filter does not reach past its pixel: columns 3 and 4 are exact.
    let boxed = edge_image(Filter::Box, 16);
    assert!((0..32).all(|y| boxed[y * 8 + 3][0] == 0.0 && boxed[y * 8 + 4][0] == 1.0));
}

#[test]
fn bad_gaussian_parameters_are_typed_errors() {
    let scene = Scene::<f32> {
        objects: &[],
        materials: &[],
        lights: &[],
        camera: raykernel::render::scenes::CORNELL.camera,
        background: [0.0; 3],
    };
    let check = |sigma: f32, radius: f32| {
        let settings = Settings {
            filter: Filter::Gaussian { sigma, radius },
            ..Settings::default()
        };
        common::render_linear(&scene, settings)
            .map(|_| ())
            .map_err(|e| {
                assert_eq!((e.item, e.index), (Item::Settings, 0));
                (e.field, e.problem)
            })
    };
    assert_eq!(check(0.5, 1.5), Ok(()));
    assert_eq!(check(0.0, 1.5), Err(("filter_sigma", Problem::NotPositive)));
    assert_eq!(
        check(f32::NAN, 1.5),
        Err(("filter_sigma", Problem::NonFinite))
    );
    assert_eq!(
        check(0.5, -1.0),
        Err(("filter_radius", Problem::NotPositive))
    );
    assert_eq!(
        check(0.5, 17.0),
        Err((
            "filter_radius",
            Problem::OutOfRange {
                min: 0.0,
                max: Filter::MAX_RADIUS
            }
        ))
    );
}
