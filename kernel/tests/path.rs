//! The path integrator: known answers (a white furnace, a sphere light's irradiance through
//! multiple importance sampling), MIS weights against each other, light sampling alone against
//! light and BSDF sampling combined, the direct integrator as a path of length 2, and tile
//! independence.
//!
//! Noise bounds: each test renders many pixels that all estimate the same value (a furnace is
//! uniform; a narrow camera sees one point), so the pixels are independent estimates and the
//! standard error of their mean is `σ̂ / √pixels` with `σ̂` their sample standard deviation.
//! A test accepts a difference of at most [`Z`] standard errors and asserts that the standard
//! error itself is small, so a biased estimator cannot hide in noise.
//!
//! Needs the kernel's `path-tracing` feature (`cargo test -p raykernel --features
//! path-tracing`); without it `tests/features.rs` checks the typed error and prints a
//! `skipped` line for this file.
#![cfg(feature = "path-tracing")]

use raykernel::render::sampling::power_heuristic;
use raykernel::render::scenes::{self, SceneData};
use raykernel::render::{
    memory_needed, Camera, Filter, Integrator, Light, Material, Object, ObjectSlot, RenderMemory,
    Renderer, SamplerKind, Scene, SceneError, Settings, Shape, Tile,
};
use raykernel::{
    AccelKind, AccelMemory, AnyFamily, KdNode, Node, Node4, Node8, Scalar, Sphere, Triangle, I16F16,
};

/// Standard errors a mean may lie from its expected value (a false failure has probability
/// below 1e-6 per channel; the renders are deterministic, so a test passes or fails always).
const Z: f64 = 5.0;

/// Renders `scene` into linear RGB with the default accelerator, `tile` by `tile` pixels.
fn render_tiled<S: Scalar>(
    scene: &Scene<'_, S>,
    settings: Settings,
    tile: u32,
) -> Result<Vec<[f32; 3]>, SceneError> {
    let accel = AccelKind::default();
    let n = memory_needed::<S, AnyFamily>(scene.objects, &accel);
    let mut objects = vec![ObjectSlot::<S>::EMPTY; n.objects];
    let mut nodes = vec![Node::<S>::EMPTY; n.accel.nodes];
    let mut nodes4 = vec![Node4::<S>::EMPTY; n.accel.nodes4];
    let mut nodes8 = vec![Node8::<S>::EMPTY; n.accel.nodes8];
    let mut kd_nodes = vec![KdNode::<S>::EMPTY; n.accel.kd_nodes];
    let mut words = vec![0u32; n.accel.words];
    let memory = RenderMemory {
        objects: &mut objects,
        accel: AccelMemory {
            nodes: &mut nodes,
            nodes4: &mut nodes4,
            nodes8: &mut nodes8,
            kd_nodes: &mut kd_nodes,
            words: &mut words,
        },
    };
    let r = Renderer::new(scene, settings, accel, memory)?;
    let (w, h) = (settings.width, settings.height);
    let mut out = vec![[0.0f32; 3]; (w * h) as usize];
    let mut buf = vec![[0.0f32; 3]; (tile * tile) as usize];
    for ty in (0..h).step_by(tile as usize) {
        for tx in (0..w).step_by(tile as usize) {
            let t = Tile {
                x: tx,
                y: ty,
                width: tile.min(w - tx),
                height: tile.min(h - ty),
            };
            r.render_tile(t, &mut buf)?;
            for j in 0..t.height {
                for i in 0..t.width {
                    out[((t.y + j) * w + t.x + i) as usize] = buf[(j * t.width + i) as usize];
                }
            }
        }
    }
    Ok(out)
}

fn render<S: Scalar>(scene: &Scene<'_, S>, settings: Settings) -> Vec<[f32; 3]> {
    render_tiled(scene, settings, settings.width.max(settings.height)).unwrap()
}

/// Per channel: the mean of the pixels and its standard error.
fn mean_and_error(px: &[[f32; 3]]) -> [(f64, f64); 3] {
    let n = px.len() as f64;
    core::array::from_fn(|c| {
        let mean = px.iter().map(|p| f64::from(p[c])).sum::<f64>() / n;
        let var = px
            .iter()
            .map(|p| (f64::from(p[c]) - mean).powi(2))
            .sum::<f64>()
            / (n - 1.0);
        (mean, (var / n).sqrt())
    })
}

fn path(max_length: u32, width: u32, spp: u32, seed: u32) -> Settings {
    Settings {
        width,
        height: width,
        spp,
        integrator: Integrator::Path { max_length },
        sampler: SamplerKind::Independent,
        filter: Filter::Box,
        seed,
        ..Settings::default()
    }
}

fn sphere<S: Scalar>(c: [f32; 3], r: f32) -> Sphere<S> {
    Sphere {
        center: c.map(|x| S::coord_from_f32(x).unwrap()),
        radius: S::coord_from_f32(r).unwrap(),
    }
}

/// Camera inside a closed sphere whose surface is diffuse of albedo `a` and emits `Le`: the
/// radiance everywhere is `Le · Σ aᵏ = Le / (1 − a)` (the path length, 256 segments, cuts
/// off a share `a²⁵⁶` of it, far below the noise).
fn furnace_case<S: Scalar>() {
    let albedo = [0.5f32, 0.7, 0.3];
    let emission = [1.0f32, 0.5, 2.0];
    let shell = [sphere::<S>([0.1, -0.2, 0.3], 1.5)];
    let objects = [Object {
        emission,
        ..Object::new(Shape::Spheres(&shell), 0)
    }];
    let scene = Scene {
        objects: &objects,
        materials: &[Material::Diffuse { albedo }],
        lights: &[],
        camera: Camera {
            eye: [0.3, 0.1, -0.2],
            look_at: [0.0, 0.0, 1.0],
            up: [0.0, 1.0, 0.0],
            vfov_deg: 90.0,
            aperture_radius: 0.0,
            focus_distance: 1.0,
        },
        background: [0.0; 3],
    };
    let px = render(&scene, path(256, 24, 32, 7));
    for (c, (mean, se)) in mean_and_error(&px).into_iter().enumerate() {
        let want = f64::from(emission[c]) / (1.0 - f64::from(albedo[c]));
        assert!(
            se < 0.01 * want,
            "{} channel {c}: standard error {se} too large to test",
            S::NAME
        );
        assert!(
            (mean - want).abs() <= Z * se,
            "{} channel {c}: mean {mean}, want {want} ± {}",
            S::NAME,
            Z * se
        );
    }
    // The direct integrator sees the emission and nothing it reflects.
    let direct = render(
        &scene,
        Settings {
            integrator: Integrator::Direct,
            ..path(1, 4, 1, 7)
        },
    );
    assert!(direct.iter().all(|p| *p == emission), "{}", S::NAME);
}

#[test]
fn white_furnace_converges_to_emission_over_one_minus_albedo() {
    furnace_case::<f32>();
    furnace_case::<I16F16>();
}

#[test]
fn mis_weights_of_two_strategies_sum_to_one() {
    // Densities over 60 decades, both orders, and the edge cases.
    let mut x = 0x2545_f491u32;
    let mut next = || {
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        x
    };
    let mut pdfs: Vec<f32> = (0..4000)
        .map(|_| 10f32.powf((next() as f32 / u32::MAX as f32) * 60.0 - 30.0))
        .collect();
    pdfs.extend([0.0, f32::MIN_POSITIVE, 1.0, f32::MAX, f32::INFINITY]);
    for (i, &a) in pdfs.iter().enumerate() {
        let b = pdfs[(i * 7 + 3) % pdfs.len()];
        for (a, b) in [(a, b), (a, a), (b, 0.0), (f32::INFINITY, b)] {
            if a == 0.0 && b == 0.0 {
                // Neither strategy produces the sample: no weight is needed.
                assert_eq!(power_heuristic(a, b), 0.0);
                continue;
            }
            let (wa, wb) = (power_heuristic(a, b), power_heuristic(b, a));
            assert!(
                (0.0..=1.0).contains(&wa) && (0.0..=1.0).contains(&wb),
                "{a} {b}"
            );
            assert!(
                (wa + wb - 1.0).abs() <= 2.0 * f32::EPSILON,
                "{a} {b}: {wa} + {wb}"
            );
        }
    }
    // The heuristic itself: a² / (a² + b²) where that does not overflow.
    assert_eq!(power_heuristic(3.0, 4.0), 9.0 / 25.0);
    assert_eq!(power_heuristic(2.0, 0.0), 1.0);
    assert_eq!(power_heuristic(0.0, 0.0), 0.0);
}

/// A large diffuse floor of albedo `ρ` at `y = 0`.
fn floor_tris<S: Scalar>() -> Vec<Triangle<S>> {
    let s = 50.0;
    [
        [[-s, 0.0, -s], [-s, 0.0, s], [s, 0.0, s]],
        [[-s, 0.0, -s], [s, 0.0, s], [s, 0.0, -s]],
    ]
    .iter()
    .map(|v| Triangle::from_f32(*v).unwrap())
    .collect()
}

/// A camera whose whole image sees the floor's origin.
fn narrow_camera(eye: [f32; 3]) -> Camera {
    Camera {
        eye,
        look_at: [0.0; 3],
        up: [0.0, 1.0, 0.0],
        vfov_deg: 0.001,
        aperture_radius: 0.0,
        focus_distance: 1.0,
    }
}

/// A sphere light of radius `R` at height `h` above a diffuse point (fully above its horizon)
/// gives irradiance `π·L·(R/h)²`, so radiance `ρ·L·(R/h)²`. With path length 3 the point's
/// light sample and its cosine-sampled ray (which hits the light with probability `(R/h)²`)
/// are combined by MIS; counting either strategy's share twice or dropping it is off by far
/// more than the bound. Length 2 (light samples alone) must give the same answer.
fn sphere_light_case<S: Scalar>() {
    let (rho, radiance, r, h) = (0.6f32, 3.0f32, 0.8f32, 1.0f32);
    let t = floor_tris::<S>();
    let objects = [Object::new(Shape::Triangles(&t), 0)];
    let lights = [Light::Sphere {
        center: [0.0, h, 0.0],
        radius: r,
        radiance: [radiance; 3],
    }];
    let scene = Scene {
        objects: &objects,
        materials: &[Material::Diffuse { albedo: [rho; 3] }],
        lights: &lights,
        camera: narrow_camera([3.0, 0.4, 0.5]),
        background: [0.0; 3],
    };
    let want = f64::from(rho) * f64::from(radiance) * f64::from(r / h).powi(2);
    for length in [2, 3, 6] {
        let px = render(&scene, path(length, 32, 8, 11));
        let (mean, se) = mean_and_error(&px)[0];
        assert!(se < 0.01 * want, "{} length {length}: error {se}", S::NAME);
        assert!(
            (mean - want).abs() <= Z * se + 1e-4 * want,
            "{} length {length}: mean {mean}, want {want} ± {}",
            S::NAME,
            Z * se
        );
    }
}

#[test]
fn sphere_light_irradiance_through_mis_matches_the_formula() {
    sphere_light_case::<f32>();
    sphere_light_case::<I16F16>();
}

/// A glossy floor under a rectangle and a sphere light, seen at an angle: light samples alone
/// (length 2) and light samples with BSDF samples (length 3, MIS) estimate the same radiance,
/// so their means agree within the noise of both.
fn glossy_mis_case<S: Scalar>() {
    let t = floor_tris::<S>();
    let objects = [Object::new(Shape::Triangles(&t), 0)];
    let lights = [
        Light::Rect {
            corner: [-1.4, 0.9, -0.6],
            edge_u: [0.5, 0.3, 0.0],
            edge_v: [0.0, 0.0, 1.2],
            radiance: [4.0, 3.0, 2.0],
        },
        Light::Sphere {
            center: [-1.0, 0.6, 0.8],
            radius: 0.3,
            radiance: [1.0, 2.0, 6.0],
        },
    ];
    let scene = Scene {
        objects: &objects,
        materials: &[Material::Glossy {
            reflectance: [0.8, 0.7, 0.6],
            exponent: 8.0,
        }],
        lights: &lights,
        camera: narrow_camera([2.0, 1.0, 0.1]),
        background: [0.0; 3],
    };
    let nee = mean_and_error(&render(&scene, path(2, 40, 16, 3)));
    let mis = mean_and_error(&render(&scene, path(3, 40, 16, 4)));
    for c in 0..3 {
        let ((a, sa), (b, sb)) = (nee[c], mis[c]);
        let se = (sa * sa + sb * sb).sqrt();
        assert!(
            a > 0.05,
            "{} channel {c}: the lights must reach the point",
            S::NAME
        );
        assert!(se < 0.02 * a, "{} channel {c}: error {se}", S::NAME);
        assert!(
            (a - b).abs() <= Z * se,
            "{} channel {c}: lights alone {a}, with MIS {b}, bound {}",
            S::NAME,
            Z * se
        );
    }
}

#[test]
fn glossy_light_sampling_alone_and_with_mis_agree() {
    glossy_mis_case::<f32>();
    glossy_mis_case::<I16F16>();
}

/// The Cornell box with every material diffuse: black background, no emitting surfaces.
fn diffuse_cornell<S: Scalar, R>(f: impl FnOnce(&Scene<'_, S>, Settings) -> R) -> R {
    let d: SceneData<'_> = scenes::CORNELL;
    let materials: Vec<_> = d
        .materials
        .iter()
        .map(|m| match *m {
            Material::Mirror { reflectance } | Material::Glossy { reflectance, .. } => {
                Material::Diffuse {
                    albedo: reflectance,
                }
            }
            m => m,
        })
        .collect();
    let data = SceneData {
        materials: &materials,
        ..d
    };
    with_scene(&data, f)
}

/// The kernel's scene for `data` in mode `S` (primitives converted, objects filled), handed
/// to `f` with the data's settings.
fn with_scene<S: Scalar, R>(
    data: &SceneData<'_>,
    f: impl FnOnce(&Scene<'_, S>, Settings) -> R,
) -> R {
    let mut tris = vec![
        Triangle::<S> {
            v: [[S::ZERO; 3]; 3]
        };
        data.triangles.len()
    ];
    let mut spheres = vec![sphere::<S>([0.0; 3], 1.0); data.spheres.len()];
    data.triangles_into(&mut tris).unwrap();
    data.spheres_into(&mut spheres).unwrap();
    let mut objects = vec![Object::new(Shape::Triangles(&[]), 0); data.objects.len()];
    let scene = data.scene(&tris, &spheres, &mut objects).unwrap();
    f(&scene, data.settings)
}

/// Path length 2 is direct light: on a scene without mirror or glossy surfaces, emitters seen
/// by BSDF rays or a background, the path integrator's light samples are the direct
/// integrator's, bit for bit (same random values, same operations). Length 3 adds light.
fn direct_is_length_two_case<S: Scalar>() {
    diffuse_cornell::<S, _>(|scene, st| {
        let st = Settings {
            width: 24,
            height: 24,
            ..st
        };
        let direct = render(scene, st);
        let length2 = render(
            scene,
            Settings {
                integrator: Integrator::Path { max_length: 2 },
                ..st
            },
        );
        let bits =
            |px: &[[f32; 3]]| -> Vec<[u32; 3]> { px.iter().map(|p| p.map(f32::to_bits)).collect() };
        assert!(bits(&direct) == bits(&length2), "{}", S::NAME);
        let length3 = render(
            scene,
            Settings {
                integrator: Integrator::Path { max_length: 3 },
                ..st
            },
        );
        let sum = |px: &[[f32; 3]]| {
            px.iter()
                .map(|p| f64::from(p[0] + p[1] + p[2]))
                .sum::<f64>()
        };
        assert!(sum(&length3) > 1.05 * sum(&direct), "{}", S::NAME);
    });
}

#[test]
fn direct_integrator_is_the_path_integrator_of_length_two() {
    direct_is_length_two_case::<f32>();
    direct_is_length_two_case::<I16F16>();
}

/// Any tiling gives the same bits: every random value (Russian roulette's too) depends only
/// on the pixel, the sample and the dimension.
fn tiles_case<S: Scalar>() {
    with_scene::<S, _>(&scenes::CORNELL, |scene, st| {
        let st = Settings {
            width: 20,
            height: 20,
            spp: 4,
            integrator: Integrator::Path { max_length: 8 },
            ..st
        };
        let whole = render_tiled(scene, st, 20).unwrap();
        for tile in [1, 3, 7] {
            let tiled = render_tiled(scene, st, tile).unwrap();
            let same = whole
                .iter()
                .zip(&tiled)
                .all(|(a, b)| a.map(f32::to_bits) == b.map(f32::to_bits));
            assert!(same, "{} tile {tile}", S::NAME);
        }
    });
}

#[test]
fn path_tiles_are_bit_identical_in_any_tiling() {
    tiles_case::<f32>();
    tiles_case::<I16F16>();
}

#[test]
fn plan_records_the_integrator_and_checks_the_length() {
    let t = floor_tris::<f32>();
    let objects = [Object::new(Shape::Triangles(&t), 0)];
    let scene = Scene {
        objects: &objects,
        materials: &[Material::Diffuse { albedo: [0.5; 3] }],
        lights: &[],
        camera: narrow_camera([1.0, 1.0, 1.0]),
        background: [0.0; 3],
    };
    let n = memory_needed::<f32, AnyFamily>(scene.objects, &AccelKind::default());
    let mut objects = vec![ObjectSlot::<f32>::EMPTY; n.objects];
    let mut nodes = vec![Node::<f32>::EMPTY; n.accel.nodes];
    let mut words = vec![0u32; n.accel.words];
    let memory = RenderMemory {
        objects: &mut objects,
        accel: AccelMemory {
            nodes: &mut nodes,
            words: &mut words,
            ..AccelMemory::default()
        },
    };
    let st = path(5, 4, 1, 0);
    let r = Renderer::new(&scene, st, AccelKind::default(), memory).unwrap();
    assert_eq!(r.plan().integrator, Integrator::Path { max_length: 5 });
    assert!(!r.plan().camera_rays_only());
    assert!(r
        .plan()
        .to_string()
        .contains("path tracing (max length 5 segments"));
    let mut objects = vec![ObjectSlot::<f32>::EMPTY; n.objects];
    let mut nodes = vec![Node::<f32>::EMPTY; n.accel.nodes];
    let mut words = vec![0u32; n.accel.words];
    let memory = RenderMemory {
        objects: &mut objects,
        accel: AccelMemory {
            nodes: &mut nodes,
            words: &mut words,
            ..AccelMemory::default()
        },
    };
    let e = Renderer::new(&scene, path(0, 4, 1, 0), AccelKind::default(), memory).unwrap_err();
    assert_eq!(
        (e.field, e.problem),
        ("max_length", raykernel::render::Problem::NotPositive)
    );
}

/// The default scene's ceiling, the block's side and the core shadows get no direct light:
/// black under the direct integrator, lit by interreflection under the path integrator
/// (what stays black there is the open front of the box reflected in the spheres).
#[test]
fn the_default_scene_ceiling_is_lit_under_the_path_integrator() {
    with_scene::<f32, _>(&scenes::CORNELL, |scene, settings| {
        let (w, h) = (48usize, 48usize);
        let st = Settings {
            width: w as u32,
            height: h as u32,
            spp: 8,
            ..settings
        };
        let direct = render(scene, st);
        let path = render(
            scene,
            Settings {
                integrator: Integrator::Path { max_length: 5 },
                ..st
            },
        );
        let black = |p: &[f32; 3]| *p == [0.0; 3];
        // The top sixth of the image is ceiling between the side walls.
        let ceiling: Vec<usize> = (0..w * h / 6).filter(|&i| black(&direct[i])).collect();
        assert!(
            ceiling.len() > w * h / 6 / 2,
            "direct: {} black ceiling pixels",
            ceiling.len()
        );
        let unlit = ceiling.iter().filter(|&&i| black(&path[i])).count();
        assert_eq!(unlit, 0, "path: ceiling pixels still black");
        let count = |px: &[[f32; 3]]| px.iter().filter(|p| black(p)).count();
        let (d_black, p_black) = (count(&direct), count(&path));
        assert!(
            4 * p_black < d_black,
            "black pixels: direct {d_black}, path {p_black}"
        );
    });
}
