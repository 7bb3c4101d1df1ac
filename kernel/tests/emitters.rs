//! Emissive geometry as area lights: an emissive quad mesh (two triangles) lights a scene as
//! the equivalent rectangle light does, under both integrators and in both modes; and next-event
//! estimation with MIS on an emissive mesh converges to the mean of BSDF sampling alone.
//!
//! Noise bounds come from the renders themselves: pixels are independent estimates (each
//! pixel's samples come from its own stream), so over a block of pixels the mean of the
//! per-pixel differences between two renders has standard error `σ̂ / √pixels`. A test accepts
//! [`Z`] standard errors and asserts the error itself is small, so a biased estimator cannot
//! hide in noise.

mod common;

use raykernel::render::{
    Camera, Filter, Integrator, Light, Material, Object, SamplerKind, Scene, Settings, Shape,
};
use raykernel::{Scalar, Sphere, Triangle, I16F16};

/// Standard errors a mean may lie from its expected value.
const Z: f64 = 5.0;

/// The rectangle both scenes use: it emits downwards (`edge_u × edge_v` is `-y`).
const CORNER: [f32; 3] = [-0.7, 1.5, -0.3];
const EDGE_U: [f32; 3] = [1.0, 0.0, 0.0];
const EDGE_V: [f32; 3] = [0.0, 0.0, 0.8];
const RADIANCE: [f32; 3] = [6.0, 4.0, 2.5];

fn add(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// The parallelogram `corner + a·u + b·v` as two triangles wound as the rectangle light's
/// (front `u × v`).
fn quad<S: Scalar>(corner: [f32; 3], u: [f32; 3], v: [f32; 3]) -> [Triangle<S>; 2] {
    let (a, b, c, d) = (
        corner,
        add(corner, u),
        add(add(corner, u), v),
        add(corner, v),
    );
    [
        Triangle::from_f32([a, b, c]).unwrap(),
        Triangle::from_f32([a, c, d]).unwrap(),
    ]
}

fn sphere<S: Scalar>(c: [f32; 3], r: f32) -> Sphere<S> {
    Sphere {
        center: c.map(|x| S::coord_from_f32(x).unwrap()),
        radius: S::coord_from_f32(r).unwrap(),
    }
}

/// A large floor at `y = 0`, front up.
fn floor<S: Scalar>() -> [Triangle<S>; 2] {
    quad([-50.0, 0.0, 50.0], [100.0, 0.0, 0.0], [0.0, 0.0, -100.0])
}

fn settings(integrator: Integrator, width: u32, spp: u32, seed: u32) -> Settings {
    Settings {
        width,
        height: width,
        spp,
        integrator,
        sampler: SamplerKind::Independent,
        filter: Filter::Box,
        seed,
        ..Settings::default()
    }
}

fn integrators() -> Vec<Integrator> {
    let mut v = vec![Integrator::Direct];
    if cfg!(feature = "path-tracing") {
        v.push(Integrator::Path { max_length: 4 });
    } else {
        println!("skipped the path integrator: needs `--features path-tracing`");
    }
    v
}

/// Per channel: the mean of `a − b` over the pixels `(x, y)` of `block` and its standard error.
fn difference(a: &[[f32; 3]], b: &[[f32; 3]], pixels: &[usize]) -> [(f64, f64); 3] {
    let n = pixels.len() as f64;
    core::array::from_fn(|c| {
        let d: Vec<f64> = pixels
            .iter()
            .map(|&i| f64::from(a[i][c]) - f64::from(b[i][c]))
            .collect();
        let mean = d.iter().sum::<f64>() / n;
        let var = d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
        (mean, (var / n).sqrt())
    })
}

/// The floor, a diffuse sphere on it, and the rectangle above them: as a [`Light::Rect`]
/// (`mesh` false) or as a one-sided emissive mesh of two triangles.
fn lit_scene_image<S: Scalar>(mesh: bool, settings: Settings) -> Vec<[f32; 3]> {
    let floor = floor::<S>();
    let ball = [sphere::<S>([0.3, 0.35, 0.0], 0.35)];
    let lamp = quad::<S>(CORNER, EDGE_U, EDGE_V);
    let mut objects = vec![
        Object::new(Shape::Triangles(&floor), 0),
        Object::new(Shape::Spheres(&ball), 1),
    ];
    let mut lights = Vec::new();
    if mesh {
        objects.push(Object {
            one_sided: true,
            ..Object::new(Shape::Triangles(&lamp), 2)
        });
    } else {
        lights.push(Light::Rect {
            corner: CORNER,
            edge_u: EDGE_U,
            edge_v: EDGE_V,
            radiance: RADIANCE,
        });
    }
    let scene = Scene {
        objects: &objects,
        materials: &[
            Material::Diffuse {
                albedo: [0.7, 0.7, 0.7],
            },
            Material::Diffuse {
                albedo: [0.3, 0.6, 0.8],
            },
            Material::Emissive { radiance: RADIANCE },
        ],
        lights: &lights,
        camera: Camera {
            eye: [0.0, 1.2, 3.5],
            look_at: [0.0, 0.0, 0.0],
            up: [0.0, 1.0, 0.0],
            vfov_deg: 40.0,
            aperture_radius: 0.0,
            focus_distance: 1.0,
        },
        background: [0.0; 3],
    };
    common::render_linear(&scene, settings).unwrap()
}

/// In blocks of 8×8 pixels, the emissive mesh's image and the rectangle light's agree within
/// the noise of their difference; over the whole image that noise is below 2% of the mean.
fn mesh_matches_rect_case<S: Scalar>() {
    const W: u32 = 32;
    for integrator in integrators() {
        let rect = lit_scene_image::<S>(false, settings(integrator, W, 16, 5));
        let mesh = lit_scene_image::<S>(true, settings(integrator, W, 16, 6));
        let all: Vec<usize> = (0..(W * W) as usize).collect();
        for (c, (d, se)) in difference(&mesh, &rect, &all).into_iter().enumerate() {
            let mean = rect.iter().map(|p| f64::from(p[c])).sum::<f64>() / all.len() as f64;
            assert!(
                mean > 0.02,
                "{} {integrator:?} channel {c}: lit ({mean})",
                S::NAME
            );
            assert!(
                se < 0.02 * mean,
                "{} {integrator:?} channel {c}: error {se}",
                S::NAME
            );
            assert!(
                d.abs() <= Z * se,
                "{} {integrator:?} channel {c}: mesh − rect {d}, bound {}",
                S::NAME,
                Z * se
            );
        }
        for by in 0..W / 8 {
            for bx in 0..W / 8 {
                let block: Vec<usize> = (0..64)
                    .map(|i| ((by * 8 + i / 8) * W + bx * 8 + i % 8) as usize)
                    .collect();
                for (c, (d, se)) in difference(&mesh, &rect, &block).into_iter().enumerate() {
                    assert!(
                        d.abs() <= Z * se + 1e-6,
                        "{} {integrator:?} block ({bx}, {by}) channel {c}: mesh − rect {d}, \
                         bound {}",
                        S::NAME,
                        Z * se
                    );
                }
            }
        }
    }
}

#[test]
fn emissive_mesh_and_rect_light_give_the_same_image_f32() {
    mesh_matches_rect_case::<f32>();
}

#[test]
fn emissive_mesh_and_rect_light_give_the_same_image_fixed() {
    mesh_matches_rect_case::<I16F16>();
}

/// A tilted one-sided emissive quad above the floor's origin, seen by a camera whose whole
/// image sees that point.
const TILTED: ([f32; 3], [f32; 3], [f32; 3]) =
    ([-0.5, 1.0, -0.4], [1.0, 0.3, 0.0], [0.0, 0.0, 0.9]);
const ALBEDO: f32 = 0.6;

/// Radiance at the floor's origin by cosine-weighted BSDF sampling alone, computed here in
/// `f64` (`ρ` times the mean emitted radiance seen along `n` cosine-distributed directions),
/// with its standard error.
fn bsdf_sampling_alone(n: usize) -> (f64, f64) {
    let (c, u, v) = TILTED;
    let f = |a: [f32; 3]| a.map(f64::from);
    let (c, u, v) = (f(c), f(u), f(v));
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let normal = cross(u, v);
    let mut rng = raykernel_testkit::Rng::new(0x5eed);
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    for _ in 0..n {
        // Cosine-weighted about +y (Malley: a uniform disk point lifted to the hemisphere).
        let (r1, r2) = (rng.unit_f64(), rng.unit_f64());
        let (rad, phi) = (r1.sqrt(), 2.0 * std::f64::consts::PI * r2);
        let d = [rad * phi.cos(), (1.0 - r1).sqrt(), rad * phi.sin()];
        // The ray from the origin against the plane of the parallelogram, then its (a, b).
        let facing = dot(d, normal);
        let mut l = 0.0;
        if facing < 0.0 {
            let t = dot(c, normal) / facing;
            let p = d.map(|x| x * t);
            let q = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
            // q = a·u + b·v: solve with the normal's dual basis.
            let nn = dot(normal, normal);
            let a = dot(cross(q, v), normal) / nn;
            let b = dot(cross(u, q), normal) / nn;
            if t > 0.0 && (0.0..=1.0).contains(&a) && (0.0..=1.0).contains(&b) {
                l = f64::from(RADIANCE[0]);
            }
        }
        let x = f64::from(ALBEDO) * l;
        sum += x;
        sum2 += x * x;
    }
    let mean = sum / n as f64;
    let var = (sum2 / n as f64 - mean * mean) * n as f64 / (n as f64 - 1.0);
    (mean, (var / n as f64).sqrt())
}

/// The tilted quad as an emissive mesh over the floor, rendered under `integrator`; the mean
/// of the red channel over the pixels and its standard error.
fn tilted_mesh_radiance<S: Scalar>(integrator: Integrator) -> (f64, f64) {
    let floor = floor::<S>();
    let (c, u, v) = TILTED;
    let lamp = quad::<S>(c, u, v);
    let objects = [
        Object::new(Shape::Triangles(&floor), 0),
        Object {
            one_sided: true,
            ..Object::new(Shape::Triangles(&lamp), 1)
        },
    ];
    let scene = Scene {
        objects: &objects,
        materials: &[
            Material::Diffuse {
                albedo: [ALBEDO; 3],
            },
            Material::Emissive { radiance: RADIANCE },
        ],
        lights: &[],
        camera: Camera {
            eye: [2.0, 0.7, 1.5],
            look_at: [0.0; 3],
            up: [0.0, 1.0, 0.0],
            vfov_deg: 0.001,
            aperture_radius: 0.0,
            focus_distance: 1.0,
        },
        background: [0.0; 3],
    };
    let px = common::render_linear(&scene, settings(integrator, 32, 16, 9)).unwrap();
    let n = px.len() as f64;
    let mean = px.iter().map(|p| f64::from(p[0])).sum::<f64>() / n;
    let var = px
        .iter()
        .map(|p| (f64::from(p[0]) - mean).powi(2))
        .sum::<f64>()
        / (n - 1.0);
    (mean, (var / n).sqrt())
}

/// Next-event estimation on the mesh with MIS (path length 3: the floor point's light sample
/// and its BSDF ray, which may hit the mesh, combined), next-event estimation alone (the direct
/// integrator) and BSDF sampling alone converge to the same radiance.
fn nee_matches_bsdf_case<S: Scalar>() {
    let (want, want_se) = bsdf_sampling_alone(400_000);
    assert!(want > 0.1, "the quad must light the point: {want}");
    let mut cases = vec![Integrator::Direct];
    if cfg!(feature = "path-tracing") {
        cases.extend([
            Integrator::Path { max_length: 2 },
            Integrator::Path { max_length: 3 },
        ]);
    } else {
        println!("skipped the path integrator: needs `--features path-tracing`");
    }
    for integrator in cases {
        let (mean, se) = tilted_mesh_radiance::<S>(integrator);
        let bound = Z * (se * se + want_se * want_se).sqrt();
        assert!(
            bound < 0.03 * want,
            "{} {integrator:?}: bound {bound}",
            S::NAME
        );
        assert!(
            (mean - want).abs() <= bound,
            "{} {integrator:?}: {mean}, BSDF sampling alone {want}, bound {bound}",
            S::NAME
        );
    }
}

#[test]
fn emitter_sampling_with_mis_converges_to_bsdf_sampling_alone_f32() {
    nee_matches_bsdf_case::<f32>();
}

#[test]
fn emitter_sampling_with_mis_converges_to_bsdf_sampling_alone_fixed() {
    nee_matches_bsdf_case::<I16F16>();
}
