//! The distribution ray tracer: known-answer renders (radiance from analytic formulas),
//! sampling functions against their known integrals and stratification properties, tile and
//! order independence, the render plan, and every typed scene error.
#![allow(clippy::disallowed_methods)] // glam's lengths are the independent reference here

use raykernel::bvh::{BuildOptions, BuilderKind};
use raykernel::render::sampling::{
    ceil_sqrt, concentric_disk, cosine_hemisphere, owen_scramble, permute, phong_lobe,
    sin_cos_turns, sobol_0, sobol_1, tent, to_world, uniform_cone, SampleStream,
};
use raykernel::render::scenes::{self, SceneData};
use raykernel::render::{
    memory_needed, Camera, Filter, Item, Light, Material, Object, ObjectSlot, Problem,
    RenderMemory, RenderMemoryNeeded, Renderer, SamplerKind, Scene, SceneError, Settings, Shape,
    Tile, MAX_LIGHTS,
};
use raykernel::{
    grid::GridOptions, kdtree::KdOptions, AccelKind, AccelMemory, AnyFamily, KdNode, MemoryNeeded,
    Node, Node4, Node8, Scalar, Sphere, Triangle, I16F16,
};
use std::f64::consts::PI;

/// Renders `scene` into linear RGB with a BVH (or brute force).
fn render<S: Scalar>(
    scene: &Scene<'_, S>,
    settings: Settings,
    accel: AccelKind,
) -> Result<Vec<[f32; 3]>, SceneError> {
    let mut memory = Memory::new(scene, accel);
    let r = Renderer::new(scene, settings, accel, memory.lend())?;
    let mut out = vec![[0.0f32; 3]; (settings.width * settings.height) as usize];
    let tile = Tile {
        x: 0,
        y: 0,
        width: settings.width,
        height: settings.height,
    };
    r.render_tile(tile, &mut out)?;
    Ok(out)
}

/// The closed cube `[-half, half]³` moved by `x_offset` along x, two triangles per face.
fn cube(half: f32, x_offset: f32) -> Vec<[[f32; 3]; 3]> {
    let mut out = Vec::new();
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let corner = |u: f32, v: f32| {
                let mut p = [0.0; 3];
                p[axis] = sign * half;
                p[(axis + 1) % 3] = u * half;
                p[(axis + 2) % 3] = v * half;
                p[0] += x_offset;
                p
            };
            let q = [
                corner(-1.0, -1.0),
                corner(1.0, -1.0),
                corner(1.0, 1.0),
                corner(-1.0, 1.0),
            ];
            out.push([q[0], q[1], q[2]]);
            out.push([q[0], q[2], q[3]]);
        }
    }
    out
}

/// Accelerator buffers of the sizes [`memory_needed`] gives.
struct Memory<'m, S: Scalar> {
    objects: Vec<ObjectSlot<'m, S>>,
    nodes: Vec<Node<S>>,
    nodes4: Vec<Node4<S>>,
    nodes8: Vec<Node8<S>>,
    kd_nodes: Vec<KdNode<S>>,
    words: Vec<u32>,
}

impl<'m, S: Scalar> Memory<'m, S> {
    fn new(scene: &Scene<'_, S>, accel: AccelKind) -> Self {
        Self::sized(memory_needed::<S, AnyFamily>(scene.objects, &accel))
    }
    fn sized(n: RenderMemoryNeeded) -> Self {
        Self {
            objects: vec![ObjectSlot::EMPTY; n.objects],
            nodes: vec![Node::EMPTY; n.accel.nodes],
            nodes4: vec![Node4::EMPTY; n.accel.nodes4],
            nodes8: vec![Node8::EMPTY; n.accel.nodes8],
            kd_nodes: vec![KdNode::EMPTY; n.accel.kd_nodes],
            words: vec![0; n.accel.words],
        }
    }
    fn lend(&'m mut self) -> RenderMemory<'m, S> {
        RenderMemory {
            objects: &mut self.objects,
            accel: AccelMemory {
                nodes: &mut self.nodes,
                nodes4: &mut self.nodes4,
                nodes8: &mut self.nodes8,
                kd_nodes: &mut self.kd_nodes,
                words: &mut self.words,
            },
        }
    }
}

fn tris<S: Scalar>(t: &[[[f32; 3]; 3]]) -> Vec<Triangle<S>> {
    t.iter().map(|v| Triangle::from_f32(*v).unwrap()).collect()
}

fn sphere<S: Scalar>(c: [f32; 3], r: f32) -> Sphere<S> {
    Sphere {
        center: c.map(|x| S::coord_from_f32(x).unwrap()),
        radius: S::coord_from_f32(r).unwrap(),
    }
}

/// A square floor `[-s, s]²` at height 0.
fn floor(s: f32) -> Vec<[[f32; 3]; 3]> {
    vec![
        [[-s, 0.0, -s], [-s, 0.0, s], [s, 0.0, s]],
        [[-s, 0.0, -s], [s, 0.0, s], [s, 0.0, -s]],
    ]
}

/// A camera looking at the origin from `eye` with a tiny field of view (the whole image sees
/// one point of the floor).
fn narrow_camera(eye: [f32; 3]) -> Camera {
    Camera {
        eye,
        look_at: [0.0; 3],
        up: [0.0, 0.0, -1.0],
        vfov_deg: 0.001,
        aperture_radius: 0.0,
        focus_distance: 1.0,
    }
}

fn one_pixel(spp: u32, sampler: SamplerKind) -> Settings {
    Settings {
        width: 1,
        height: 1,
        spp,
        max_depth: 4,
        sampler,
        filter: Filter::Box,
        seed: 5,
        ..Settings::default()
    }
}

fn rel_err(got: f32, want: f64) -> f64 {
    (f64::from(got) - want).abs() / want
}

/// Point light straight above the seen point: `L = ρ/π · I / h²`.
fn point_light_case<S: Scalar>() {
    let t = tris::<S>(&floor(4.0));
    let objects = [Object::new(Shape::Triangles(&t), 0)];
    let (rho, intensity, h) = (0.6f32, 5.0f32, 1.5f32);
    let scene = Scene {
        objects: &objects,
        materials: &[Material::Diffuse { albedo: [rho; 3] }],
        lights: &[Light::Point {
            position: [0.0, h, 0.0],
            intensity: [intensity; 3],
        }],
        camera: narrow_camera([2.0, 2.0, 0.0]),
        background: [0.0; 3],
    };
    let px = render(
        &scene,
        one_pixel(1, SamplerKind::Stratified),
        AccelKind::default(),
    )
    .unwrap();
    let want = f64::from(rho) / PI * f64::from(intensity) / f64::from(h * h);
    for c in px[0] {
        assert!(rel_err(c, want) < 2e-4, "{}: got {c}, want {want}", S::NAME);
    }
}

#[test]
fn known_answer_point_light() {
    point_light_case::<f32>();
    point_light_case::<I16F16>();
}

/// Sphere light of radius `r` at height `d` above the seen point: `E = π·L·(r/d)²`, so
/// `L_out = ρ·L·(r/d)²`.
fn sphere_light_case<S: Scalar>(sampler: SamplerKind) {
    let t = tris::<S>(&floor(4.0));
    let objects = [Object::new(Shape::Triangles(&t), 0)];
    let (rho, radiance, r, d) = (0.5f32, 3.0f32, 0.5f32, 2.0f32);
    let scene = Scene {
        objects: &objects,
        materials: &[Material::Diffuse { albedo: [rho; 3] }],
        lights: &[Light::Sphere {
            center: [0.0, d, 0.0],
            radius: r,
            radiance: [radiance; 3],
        }],
        camera: narrow_camera([3.0, 1.0, 0.0]),
        background: [0.0; 3],
    };
    let px = render(&scene, one_pixel(1024, sampler), AccelKind::default()).unwrap();
    let want = f64::from(rho * radiance) * f64::from(r / d).powi(2);
    for c in px[0] {
        assert!(
            rel_err(c, want) < 2e-3,
            "{} {sampler:?}: got {c}, want {want}",
            S::NAME
        );
    }
}

#[test]
fn known_answer_sphere_light() {
    for s in SamplerKind::ALL {
        sphere_light_case::<f32>(s);
        sphere_light_case::<I16F16>(s);
    }
}

/// Irradiance at a point below the corner of a parallel `a × b` rectangle at height `h`, per
/// unit radiance: `π·F` with the point-to-rectangle form factor
/// `F = 1/(2π)·[X/√(1+X²)·atan(Y/√(1+X²)) + Y/√(1+Y²)·atan(X/√(1+Y²))]`, `X = a/h`, `Y = b/h`.
fn corner_irradiance(a: f64, b: f64, h: f64) -> f64 {
    let (x, y) = (a / h, b / h);
    let sx = (1.0 + x * x).sqrt();
    let sy = (1.0 + y * y).sqrt();
    0.5 * (x / sx * (y / sx).atan() + y / sy * (x / sy).atan())
}

fn rect_light_case<S: Scalar>() {
    let t = tris::<S>(&floor(4.0));
    let objects = [Object::new(Shape::Triangles(&t), 0)];
    let (rho, radiance, half, h) = (0.7f32, 2.0f32, 0.5f32, 1.0f32);
    let scene = Scene {
        objects: &objects,
        materials: &[Material::Diffuse { albedo: [rho; 3] }],
        // Centred above the origin, facing down (edge_u × edge_v = -y).
        lights: &[Light::Rect {
            corner: [-half, h, -half],
            edge_u: [2.0 * half, 0.0, 0.0],
            edge_v: [0.0, 0.0, 2.0 * half],
            radiance: [radiance; 3],
        }],
        camera: narrow_camera([3.0, 0.5, 0.0]),
        background: [0.0; 3],
    };
    let px = render(
        &scene,
        one_pixel(4096, SamplerKind::Sobol),
        AccelKind::default(),
    )
    .unwrap();
    let e = 4.0 * corner_irradiance(f64::from(half), f64::from(half), f64::from(h));
    // L_out = ρ/π · E, E = L · Σ corner irradiances.
    let want = f64::from(rho * radiance) * e / PI;
    for c in px[0] {
        assert!(rel_err(c, want) < 2e-3, "{}: got {c}, want {want}", S::NAME);
    }
}

#[test]
fn known_answer_rect_light() {
    rect_light_case::<f32>();
    rect_light_case::<I16F16>();
}

/// Furnace for reflections: inside a closed emissive box of radiance `L`, a mirror of
/// reflectance `ρ` shows exactly `ρ·L`; a glossy sphere at most `ρ·L`, and `ρ·L` wherever no
/// lobe sample falls below the surface; with no bounces left, a mirror is black.
fn furnace_case<S: Scalar>() {
    let t = tris::<S>(&cube(3.0, 0.0));
    let mirror = [sphere::<S>([0.0, 0.0, 0.0], 1.0)];
    let (rho, l) = (0.8f32, 1.5f32);
    let objects = [
        Object::new(Shape::Triangles(&t), 0),
        Object::new(Shape::Spheres(&mirror), 1),
    ];
    for (material, exact) in [
        (
            Material::Mirror {
                reflectance: [rho; 3],
            },
            true,
        ),
        (
            Material::Glossy {
                reflectance: [rho; 3],
                exponent: 2000.0,
            },
            false,
        ),
    ] {
        let materials = [Material::Emissive { radiance: [l; 3] }, material];
        let scene = Scene {
            objects: &objects,
            materials: &materials,
            lights: &[],
            camera: Camera {
                eye: [0.0, 0.0, 2.5],
                look_at: [0.0; 3],
                up: [0.0, 1.0, 0.0],
                vfov_deg: 90.0,
                aperture_radius: 0.0,
                focus_distance: 1.0,
            },
            background: [0.0; 3],
        };
        let settings = Settings {
            width: 9,
            height: 9,
            spp: 16,
            max_depth: 3,
            ..Settings::default()
        };
        let px = render(&scene, settings, AccelKind::default()).unwrap();
        let centre = px[4 * 9 + 4];
        let want = rho * l;
        for c in centre {
            if exact {
                assert_eq!(c, want, "{} mirror: ρ·L exactly", S::NAME);
            } else {
                assert!(
                    c <= want * (1.0 + 1e-6) && c > want * 0.999,
                    "{} glossy: {c} vs {want}",
                    S::NAME
                );
            }
        }
        // A corner pixel sees the wall directly: L.
        assert_eq!(px[0], [l; 3]);
        let none = render(
            &scene,
            Settings {
                max_depth: 0,
                ..settings
            },
            AccelKind::default(),
        );
        assert_eq!(
            none.unwrap()[4 * 9 + 4],
            [0.0; 3],
            "max_depth 0: no reflection"
        );
    }
}

#[test]
fn known_answer_furnace() {
    furnace_case::<f32>();
    furnace_case::<I16F16>();
}

/// Mean of `f` over an `n × n` grid of cell centres in `[0, 1)²`.
fn grid_mean(n: u32, f: impl Fn(f32, f32) -> f64) -> f64 {
    let mut sum = 0.0;
    for i in 0..n {
        for j in 0..n {
            sum += f((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
        }
    }
    sum / f64::from(n * n)
}

#[test]
fn ceil_sqrt_is_the_least_root_at_or_above() {
    let is_ceil = |n: u32, c: u32| {
        let (c, n) = (u64::from(c), u64::from(n));
        c * c >= n && (c == 1 || (c - 1) * (c - 1) < n)
    };
    assert_eq!(ceil_sqrt(0), 1);
    let squares = (1..=65_535u32).flat_map(|r| [r * r - 1, r * r, r * r + 1]);
    for n in (1..100_000)
        .chain(squares)
        .chain(u32::MAX - 100_000..=u32::MAX)
    {
        assert!(
            is_ceil(n, ceil_sqrt(n)),
            "ceil_sqrt({n}) = {}",
            ceil_sqrt(n)
        );
    }
}

#[test]
fn sin_cos_turns_is_within_two_tenths_of_a_millionth() {
    // Every quarter turn exactly; then a dense sweep over two turns either way and the
    // ranges the samplers use, against `f64` trigonometry.
    for (t, want) in [
        (0.0, (0.0, 1.0)),
        (0.25, (1.0, 0.0)),
        (0.5, (0.0, -1.0)),
        (-0.25, (-1.0, 0.0)),
    ] {
        let (s, c) = sin_cos_turns(t);
        assert_eq!(
            (s.abs(), c.abs()),
            (f32::abs(want.0), f32::abs(want.1)),
            "t = {t}"
        );
        assert!(
            s * want.0 >= 0.0 && c * want.1 >= 0.0,
            "t = {t}: signs of {s}, {c}"
        );
    }
    let mut worst = 0.0f64;
    for i in -400_000..=400_000 {
        let t = i as f32 / 200_000.0;
        let (s, c) = sin_cos_turns(t);
        let x = std::f64::consts::TAU * f64::from(t);
        worst = worst
            .max((f64::from(s) - x.sin()).abs())
            .max((f64::from(c) - x.cos()).abs());
    }
    assert!(worst <= 2e-7, "worst error {worst:e}");
    let (s, c) = sin_cos_turns(f32::NAN);
    assert!(s.is_nan() && c.is_nan());
}

#[test]
fn warps_integrate_to_known_values() {
    // Area-uniform disk: E[r²] = 1/2, E[x] = 0, every point inside.
    let r2 = grid_mean(400, |u, v| {
        let (x, y) = concentric_disk(u, v);
        assert!(x * x + y * y <= 1.0 + 1e-6);
        f64::from(x * x + y * y)
    });
    assert!((r2 - 0.5).abs() < 1e-4, "disk E[r²] = {r2}");
    // Cosine-weighted hemisphere: E[cos θ] = 2/3.
    let c = grid_mean(400, |u, v| f64::from(cosine_hemisphere(u, v).z));
    assert!((c - 2.0 / 3.0).abs() < 1e-4, "cosine E[cos] = {c}");
    // Phong lobe of exponent n: E[cos θ] = (n+1)/(n+2).
    for n in [1.0f32, 10.0, 100.0] {
        let c = grid_mean(400, |u, v| f64::from(phong_lobe(u, v, n).z));
        let want = f64::from(n + 1.0) / f64::from(n + 2.0);
        assert!(
            (c - want).abs() < 1e-4,
            "phong {n}: E[cos] = {c}, want {want}"
        );
    }
    // Uniform cone: E[cos θ] = (1 + cos_max)/2; every direction inside the cone, unit length.
    for cm in [0.0f32, 0.5, 0.99] {
        let c = grid_mean(300, |u, v| {
            let d = uniform_cone(u, v, cm);
            assert!(d.z >= cm - 1e-6 && (d.length() - 1.0).abs() < 1e-5);
            f64::from(d.z)
        });
        assert!(
            (c - f64::from(1.0 + cm) / 2.0).abs() < 1e-4,
            "cone {cm}: {c}"
        );
    }
    // Tent: mean 0, variance 1/6, inside (-1, 1).
    let m = grid_mean(300, |u, _| f64::from(tent(u)));
    let var = grid_mean(300, |u, _| f64::from(tent(u)).powi(2));
    assert!(
        m.abs() < 1e-6 && (var - 1.0 / 6.0).abs() < 1e-4,
        "tent {m} {var}"
    );
    // Frames: to_world keeps unit vectors unit and maps +z to the normal.
    for n in [
        [0.0f32, 0.0, 1.0],
        [0.0, 0.0, -1.0],
        [0.6, 0.0, 0.8],
        [0.0, -1.0, 0.0],
    ] {
        let n = glam::Vec3::from_array(n);
        assert!((to_world(glam::Vec3::Z, n) - n).length() < 1e-6);
        let d = to_world(glam::Vec3::new(0.6, 0.0, 0.8), n);
        assert!((d.length() - 1.0).abs() < 1e-6 && (d.dot(n) - 0.8).abs() < 1e-6);
    }
}

#[test]
fn permute_is_a_bijection() {
    for n in 1..300u32 {
        for seed in [0u32, 1, 0xdead_beef, 12345] {
            let mut seen = vec![false; n as usize];
            for i in 0..n {
                let j = permute(i, n, seed);
                assert!(j < n && !seen[j as usize], "n {n} seed {seed}: {i} -> {j}");
                seen[j as usize] = true;
            }
        }
    }
}

/// Every elementary interval `[a/2^k, (a+1)/2^k) × [b/2^(m-k), (b+1)/2^(m-k))` holds exactly
/// one of the points.
fn is_02_net(points: &[(u32, u32)], m: u32) -> bool {
    (0..=m).all(|k| {
        let mut seen = vec![false; 1 << m];
        points.iter().all(|&(x, y)| {
            // The top k bits of x and the top m - k bits of y (u64 so shifts by 32 are defined).
            let (x, y) = (u64::from(x), u64::from(y));
            let cell = ((x >> (32 - k)) << (m - k) | (y >> (32 - (m - k)))) as usize;
            !std::mem::replace(&mut seen[cell], true)
        })
    })
}

#[test]
fn owen_scrambled_sobol_is_a_02_net_at_powers_of_two() {
    for m in 1..=8u32 {
        for seed in [1u32, 77, 0x1234_5678] {
            let pts: Vec<(u32, u32)> = (0..1u32 << m)
                .map(|i| {
                    let j = owen_scramble(i, seed);
                    (
                        owen_scramble(sobol_0(j), seed ^ 0xa5a5),
                        owen_scramble(sobol_1(j), seed ^ 0x5a5a),
                    )
                })
                .collect();
            assert!(is_02_net(&pts, m), "m {m} seed {seed}");
        }
    }
}

#[test]
fn stratified_samples_fill_every_cell_once() {
    for spp in [1u32, 4, 9, 16, 64] {
        let n = (spp as f32).sqrt() as u32;
        for pixel in [0u32, 17, 4242] {
            for pair in 0..3 {
                let mut seen = vec![false; spp as usize];
                for s in 0..spp {
                    let mut st = SampleStream::new(SamplerKind::Stratified, pixel, s, spp, 9);
                    for _ in 0..pair {
                        st.next_2d();
                    }
                    let (u, v) = st.next_2d();
                    assert!((0.0..1.0).contains(&u) && (0.0..1.0).contains(&v));
                    let cell = (v * n as f32) as usize * n as usize + (u * n as f32) as usize;
                    assert!(
                        !std::mem::replace(&mut seen[cell], true),
                        "spp {spp} pair {pair}"
                    );
                }
            }
        }
    }
}

/// Converts a built-in scene into the mode and hands it to `f`.
fn with_scene<S: Scalar, R>(d: &SceneData<'_>, f: impl FnOnce(&Scene<'_, S>) -> R) -> R {
    let mut t = vec![Triangle::<S>::from_f32([[0.0; 3]; 3]).unwrap(); d.triangles.len()];
    let mut s = vec![sphere::<S>([0.0; 3], 0.0); d.spheres.len()];
    d.triangles_into(&mut t).unwrap();
    d.spheres_into(&mut s).unwrap();
    let mut o = vec![Object::new(Shape::Triangles(&[]), 0); d.objects.len()];
    let scene = d.scene(&t, &s, &mut o).unwrap();
    f(&scene)
}

fn tiles_equal_whole<S: Scalar>(d: &SceneData<'_>) {
    with_scene::<S, _>(d, |scene| {
        let st = d.settings;
        let whole = render(scene, st, AccelKind::default()).unwrap();
        let mut memory = Memory::new(scene, AccelKind::default());
        let r = Renderer::new(scene, st, AccelKind::default(), memory.lend()).unwrap();
        // Odd tiles, rendered bottom-right first.
        let mut tiled = vec![[0.0f32; 3]; whole.len()];
        let (tw, th) = (7u32, 5u32);
        let mut tiles = Vec::new();
        for y in (0..st.height).step_by(th as usize) {
            for x in (0..st.width).step_by(tw as usize) {
                tiles.push(Tile {
                    x,
                    y,
                    width: tw.min(st.width - x),
                    height: th.min(st.height - y),
                });
            }
        }
        for t in tiles.iter().rev() {
            let mut buf = vec![[0.0f32; 3]; (t.width * t.height) as usize];
            r.render_tile(*t, &mut buf).unwrap();
            for (k, px) in buf.iter().enumerate() {
                let (x, y) = (t.x + k as u32 % t.width, t.y + k as u32 / t.width);
                tiled[(y * st.width + x) as usize] = *px;
            }
        }
        let bits = |v: &[[f32; 3]]| v.iter().flatten().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&whole), bits(&tiled), "{} {}", d.name, S::NAME);
        // Brute force, the wide BVHs, the grid and the kd-tree give the same bits.
        for accel in [
            AccelKind::Linear,
            AccelKind::Bvh4(BuildOptions::default()),
            AccelKind::Bvh8(BuildOptions::default()),
            AccelKind::Grid(GridOptions::default()),
            AccelKind::KdTree(KdOptions::default()),
        ] {
            let other = render(scene, st, accel).unwrap();
            assert_eq!(
                bits(&whole),
                bits(&other),
                "{} {} {accel:?}",
                d.name,
                S::NAME
            );
        }
    });
}

#[test]
fn tiles_in_any_order_equal_the_whole_image() {
    for d in scenes::ALL {
        tiles_equal_whole::<f32>(&d);
        tiles_equal_whole::<I16F16>(&d);
    }
}

#[test]
fn plans_follow_the_scenes() {
    let plan = |d: &SceneData<'_>| {
        with_scene::<f32, _>(d, |scene| {
            let mut memory = Memory::new(scene, AccelKind::default());
            let plan = *Renderer::new(scene, d.settings, AccelKind::default(), memory.lend())
                .unwrap()
                .plan();
            plan
        })
    };
    let c = plan(&scenes::CORNELL);
    assert!(!c.pixel_centre && c.lens && c.motion && c.reflections && c.glossy);
    assert_eq!((c.point_lights, c.area_lights, c.max_depth), (0, 1, 4));
    let s = plan(&scenes::SPHERES);
    assert!(!s.lens && !s.motion && s.reflections && !s.glossy);
    assert_eq!((s.point_lights, s.area_lights), (2, 0));
    // Nothing needed: one spp, pinhole, static, diffuse only.
    let bare = SceneData {
        settings: Settings {
            spp: 1,
            ..scenes::SPHERES.settings
        },
        materials: &[Material::Diffuse { albedo: [0.5; 3] }; 4],
        ..scenes::SPHERES
    };
    let b = plan(&bare);
    assert!(b.pixel_centre && !b.lens && !b.motion && !b.reflections && b.max_depth == 0);
    let text = b.to_string();
    assert!(
        text.contains("anti-aliasing off") && text.contains("reflections off"),
        "{text}"
    );
    // Its two point lights still need shadow rays; without them only camera rays are left.
    assert!(!b.camera_rays_only() && !text.contains("camera rays only"));
    let unlit = plan(&SceneData {
        lights: &[],
        ..bare
    });
    assert!(unlit.camera_rays_only());
    assert!(unlit.to_string().contains("camera rays only"), "{unlit}");
}

/// A plan of camera rays only takes the renderer's first-hit loop; a zero-intensity point light
/// changes nothing in the picture of black diffuse surfaces against the background but makes
/// the plan take the general path loop. Both must give the same bits, in both modes, for
/// every built-in scene made static, pinhole and one sample per pixel. (Emitters seen
/// directly: `emitters_only_case`.)
/// Returns how many values show the background.
fn camera_rays_only_case<S: Scalar>(d: &SceneData<'_>) -> usize {
    // Every material diffuse (black without lights), and a background that is not.
    let materials = vec![Material::Diffuse { albedo: [0.5; 3] }; d.materials.len()];
    let objects: Vec<_> = d
        .objects
        .iter()
        .map(|o| scenes::ObjectData {
            motion: [0.0; 3],
            ..*o
        })
        .collect();
    let dark = [Light::Point {
        position: [0.0, 0.5, 0.0],
        intensity: [0.0; 3],
    }];
    let settings = Settings {
        spp: 1,
        ..d.settings
    };
    let mut images = Vec::new();
    for lights in [&[][..], &dark[..]] {
        let data = SceneData {
            objects: &objects,
            materials: &materials,
            lights,
            camera: Camera {
                aperture_radius: 0.0,
                ..d.camera
            },
            settings,
            background: [0.2, 0.7, 0.4],
            ..*d
        };
        with_scene::<S, _>(&data, |scene| {
            let mut memory = Memory::new(scene, AccelKind::default());
            let r = Renderer::new(scene, settings, AccelKind::default(), memory.lend()).unwrap();
            assert_eq!(r.plan().camera_rays_only(), lights.is_empty(), "{}", d.name);
            let image = render(scene, settings, AccelKind::default()).unwrap();
            images.push(
                image
                    .iter()
                    .flatten()
                    .map(|x| x.to_bits())
                    .collect::<Vec<_>>(),
            );
        });
    }
    let black = images[0].iter().filter(|&&b| b == 0).count();
    assert!(black > 0, "{}: the picture shows surfaces", d.name);
    assert_eq!(images[0], images[1], "{} {}", d.name, S::NAME);
    images[0].len() - black
}

#[test]
fn camera_rays_only_loop_equals_the_general_path() {
    let mut background = 0;
    for d in scenes::ALL {
        background += camera_rays_only_case::<f32>(&d);
        background += camera_rays_only_case::<I16F16>(&d);
    }
    assert!(background > 0, "some picture shows the background");
}

/// A scene whose every object emits through an emissive material (some also through
/// [`scenes::ObjectData::emission`], some one-sided) has nothing a light could reach, so its
/// plan takes the first-hit loop whatever its lights; one diffuse sphere behind the camera,
/// never seen, makes the plan take the general loop. Both must give the same bits.
/// Returns how many values differ from zero and from the background.
fn emitters_only_case<S: Scalar>(d: &SceneData<'_>) -> usize {
    let materials: Vec<Material> = (0..d.materials.len())
        .map(|i| Material::Emissive {
            radiance: [0.3 + 0.1 * i as f32, 0.5, 0.9 - 0.1 * i as f32],
        })
        .chain([Material::Diffuse { albedo: [0.5; 3] }])
        .collect();
    let mut objects: Vec<_> = d
        .objects
        .iter()
        .enumerate()
        .map(|(i, o)| scenes::ObjectData {
            motion: [0.0; 3],
            emission: if i % 3 == 0 {
                [0.25, 0.0, 0.5]
            } else {
                [0.0; 3]
            },
            one_sided: i % 2 == 1,
            ..*o
        })
        .collect();
    let camera = Camera {
        aperture_radius: 0.0,
        ..d.camera
    };
    let behind: [f32; 3] = core::array::from_fn(|k| 2.0 * camera.eye[k] - camera.look_at[k]);
    let mut spheres = d.spheres.to_vec();
    spheres.push(scenes::SphereData {
        center: behind,
        radius: 0.01,
    });
    let hidden = scenes::ObjectData {
        shape: scenes::ShapeRange::Spheres {
            first: d.spheres.len() as u32,
            count: 1,
        },
        material: d.materials.len() as u32,
        motion: [0.0; 3],
        emission: [0.0; 3],
        one_sided: false,
    };
    let settings = Settings {
        spp: 1,
        ..d.settings
    };
    let background = [0.2, 0.7, 0.4];
    let mut images = Vec::new();
    for (extra, first_hit) in [(0, true), (1, false)] {
        if extra == 1 {
            objects.push(hidden);
        }
        let data = SceneData {
            objects: &objects,
            materials: &materials,
            spheres: &spheres,
            camera,
            settings,
            background,
            ..*d
        };
        with_scene::<S, _>(&data, |scene| {
            let mut memory = Memory::new(scene, AccelKind::default());
            let r = Renderer::new(scene, settings, AccelKind::default(), memory.lend()).unwrap();
            assert_eq!(r.plan().camera_rays_only(), first_hit, "{}", d.name);
            let image = render(scene, settings, AccelKind::default()).unwrap();
            images.push(image);
        });
    }
    let bits =
        |im: &Vec<[f32; 3]>| -> Vec<u32> { im.iter().flatten().map(|x| x.to_bits()).collect() };
    assert_eq!(bits(&images[0]), bits(&images[1]), "{} {}", d.name, S::NAME);
    images[0]
        .iter()
        .filter(|&&p| p != [0.0; 3] && p != background)
        .count()
}

#[test]
fn an_emitters_only_scene_takes_the_first_hit_loop_with_the_same_bits() {
    for d in scenes::ALL {
        assert!(
            emitters_only_case::<f32>(&d) > 0,
            "{}: no emitter seen",
            d.name
        );
        assert!(
            emitters_only_case::<I16F16>(&d) > 0,
            "{}: no emitter seen",
            d.name
        );
    }
}

/// A valid one-object scene to corrupt field by field.
fn check_error(
    objects: &[Object<'_, f32>],
    materials: &[Material],
    lights: &[Light],
    camera: Camera,
    settings: Settings,
) -> SceneError {
    let scene = Scene {
        objects,
        materials,
        lights,
        camera,
        background: [0.0; 3],
    };
    render(&scene, settings, AccelKind::default()).unwrap_err()
}

#[test]
fn bad_scene_data_gives_typed_errors() {
    let t = tris::<f32>(&floor(1.0));
    let good_obj = [Object::new(Shape::Triangles(&t), 0)];
    let diffuse = [Material::Diffuse { albedo: [0.5; 3] }];
    let cam = narrow_camera([0.0, 2.0, 1.0]);
    let st = Settings {
        width: 2,
        height: 2,
        spp: 1,
        ..Settings::default()
    };
    let e = |item, index, field, problem| SceneError {
        item,
        index,
        field,
        problem,
    };
    let point = [Light::Point {
        position: [0.0, 1.0, 0.0],
        intensity: [1.0; 3],
    }];
    // Object material out of range.
    let obj = [Object::new(Shape::Triangles(&t), 3)];
    assert_eq!(
        check_error(&obj, &diffuse, &point, cam, st),
        e(Item::Object, 0, "material", Problem::Index { len: 1 })
    );
    // Reflectance above one, negative, NaN; glossy exponent below one.
    for (m, field, p) in [
        (
            Material::Diffuse {
                albedo: [1.5, 0.0, 0.0],
            },
            "albedo",
            Problem::AboveOne,
        ),
        (
            Material::Mirror {
                reflectance: [0.5, -0.1, 0.0],
            },
            "reflectance",
            Problem::Negative,
        ),
        (
            Material::Emissive {
                radiance: [f32::NAN, 0.0, 0.0],
            },
            "radiance",
            Problem::NonFinite,
        ),
        (
            Material::Glossy {
                reflectance: [0.5; 3],
                exponent: 0.5,
            },
            "exponent",
            Problem::OutOfRange {
                min: 1.0,
                max: f32::MAX,
            },
        ),
    ] {
        assert_eq!(
            check_error(&good_obj, &[m], &point, cam, st),
            e(Item::Material, 0, field, p)
        );
    }
    // Lights: zero-area rectangle, non-positive radius, negative intensity, out-of-range point.
    for (l, field, p) in [
        (
            Light::Rect {
                corner: [0.0; 3],
                edge_u: [1.0, 0.0, 0.0],
                edge_v: [2.0, 0.0, 0.0],
                radiance: [1.0; 3],
            },
            "edge_v",
            Problem::ZeroArea,
        ),
        (
            Light::Sphere {
                center: [0.0; 3],
                radius: -1.0,
                radiance: [1.0; 3],
            },
            "radius",
            Problem::NotPositive,
        ),
        (
            Light::Point {
                position: [0.0; 3],
                intensity: [-1.0, 0.0, 0.0],
            },
            "intensity",
            Problem::Negative,
        ),
        (
            Light::Point {
                position: [f32::INFINITY, 0.0, 0.0],
                intensity: [1.0; 3],
            },
            "position",
            Problem::NonFinite,
        ),
    ] {
        assert_eq!(
            check_error(&good_obj, &diffuse, &[l], cam, st),
            e(Item::Light, 0, field, p)
        );
    }
    // Camera.
    let bad_up = Camera {
        up: [0.0, -1.0, -0.5],
        ..cam
    };
    assert_eq!(
        check_error(&good_obj, &diffuse, &point, bad_up, st),
        e(Item::Camera, 0, "up", Problem::Degenerate)
    );
    let bad_fov = Camera {
        vfov_deg: 180.0,
        ..cam
    };
    assert_eq!(
        check_error(&good_obj, &diffuse, &point, bad_fov, st),
        e(
            Item::Camera,
            0,
            "vfov_deg",
            Problem::OutOfRange {
                min: 0.0,
                max: 180.0
            }
        )
    );
    let bad_focus = Camera {
        aperture_radius: 0.1,
        focus_distance: 0.0,
        ..cam
    };
    assert_eq!(
        check_error(&good_obj, &diffuse, &point, bad_focus, st),
        e(Item::Camera, 0, "focus_distance", Problem::NotPositive)
    );
    let bad_eye = Camera {
        eye: [f32::NAN, 0.0, 0.0],
        ..cam
    };
    assert_eq!(
        check_error(&good_obj, &diffuse, &point, bad_eye, st),
        e(Item::Camera, 0, "eye", Problem::NonFinite)
    );
    // Settings.
    assert_eq!(
        check_error(&good_obj, &diffuse, &point, cam, Settings { spp: 0, ..st }),
        e(Item::Settings, 0, "spp", Problem::NotPositive)
    );
    assert_eq!(
        check_error(
            &good_obj,
            &diffuse,
            &point,
            cam,
            Settings { width: 0, ..st }
        ),
        e(Item::Settings, 0, "width", Problem::NotPositive)
    );
    // Motion must be finite.
    let moving = [Object {
        motion: [f32::NAN, 0.0, 0.0],
        ..good_obj[0]
    }];
    assert_eq!(
        check_error(&moving, &diffuse, &point, cam, st),
        e(Item::Object, 0, "motion", Problem::NonFinite)
    );
    // Too many lights (objects are bounded by the caller's slots).
    let lights = vec![point[0]; MAX_LIGHTS + 1];
    assert_eq!(
        check_error(&good_obj, &diffuse, &lights, cam, st).problem,
        Problem::TooMany { max: MAX_LIGHTS }
    );
}

#[test]
fn buffers_and_tiles_are_checked_exactly() {
    let t = tris::<f32>(&floor(1.0));
    let t2 = tris::<f32>(&floor(2.0));
    let objects = [
        Object::new(Shape::Triangles(&t), 0),
        Object::new(Shape::Triangles(&t2), 0),
    ];
    let scene = Scene {
        objects: &objects,
        materials: &[Material::Diffuse { albedo: [0.5; 3] }],
        lights: &[],
        camera: narrow_camera([0.0, 2.0, 1.0]),
        background: [0.0; 3],
    };
    let st = Settings {
        width: 4,
        height: 3,
        spp: 1,
        ..Settings::default()
    };
    let options = BuildOptions {
        builder: BuilderKind::Median,
        max_leaf_size: 1,
        reinsertion: true,
    };
    let bvh = AccelKind::Bvh(options);
    let bvh4 = AccelKind::Bvh4(options);
    let bvh8 = AccelKind::Bvh8(options);
    let kd = AccelKind::KdTree(KdOptions::default());
    let grid = AccelKind::Grid(GridOptions::default());
    let needed = |accel| memory_needed::<f32, AnyFamily>(scene.objects, &accel);
    let (bvh_need, bvh4_need, bvh8_need, kd_need, grid_need) = (
        needed(bvh),
        needed(bvh4),
        needed(bvh8),
        needed(kd),
        needed(grid),
    );
    let need = |nodes, nodes4, nodes8, kd_nodes, words| RenderMemoryNeeded {
        objects: 2,
        accel: MemoryNeeded {
            nodes,
            nodes4,
            nodes8,
            kd_nodes,
            words,
        },
    };
    // Two objects of two triangles: BVH 2·(2n) nodes and n ids, each wide BVH one wide node
    // and its collapse's scratch, W - 1 words per BVH node, each besides, kd-tree 4n+1 nodes
    // and 6n refs; and for every structure the top-level BVH over the two objects, 4 nodes and
    // 2 ids.
    assert_eq!(bvh_need, need(8 + 4, 0, 0, 0, 4 + 2));
    assert_eq!(bvh4_need, need(8 + 4, 2, 0, 0, 4 + 2 * 3 * 4 + 2));
    assert_eq!(bvh8_need, need(8 + 4, 0, 2, 0, 4 + 2 * 7 * 4 + 2));
    assert_eq!(kd_need, need(4, 0, 0, 18, 24 + 2));
    let g = grid_need.accel;
    assert_eq!((g.nodes, g.nodes4, g.nodes8, g.kd_nodes), (4, 0, 0, 0));
    assert!(g.words > 0);
    // One element short in each buffer: a typed error naming it, with the exact sizes.
    let cases = [
        (bvh, bvh_need),
        (bvh4, bvh4_need),
        (bvh8, bvh8_need),
        (kd, kd_need),
        (grid, grid_need),
    ];
    for (accel, n) in cases {
        let a = n.accel;
        let less = |x: usize| x.wrapping_sub(1);
        let shorts = [
            ("objects", 2, RenderMemoryNeeded { objects: 1, ..n }),
            (
                "nodes",
                a.nodes,
                need(less(a.nodes), a.nodes4, a.nodes8, a.kd_nodes, a.words),
            ),
            (
                "nodes4",
                a.nodes4,
                need(a.nodes, less(a.nodes4), a.nodes8, a.kd_nodes, a.words),
            ),
            (
                "nodes8",
                a.nodes8,
                need(a.nodes, a.nodes4, less(a.nodes8), a.kd_nodes, a.words),
            ),
            (
                "kd_nodes",
                a.kd_nodes,
                need(a.nodes, a.nodes4, a.nodes8, less(a.kd_nodes), a.words),
            ),
            (
                "words",
                a.words,
                need(a.nodes, a.nodes4, a.nodes8, a.kd_nodes, a.words - 1),
            ),
        ];
        for (field, needed, short) in shorts {
            if needed == 0 {
                continue;
            }
            let mut memory = Memory::sized(short);
            let err = Renderer::new(&scene, st, accel, memory.lend()).unwrap_err();
            let available = needed - 1;
            assert_eq!(
                (err.field, err.problem),
                (field, Problem::TooSmall { needed, available }),
                "{accel:?}"
            );
        }
        let mut memory = Memory::sized(n);
        assert!(Renderer::new(&scene, st, accel, memory.lend()).is_ok());
    }
    // Brute force needs only the top-level BVH's memory.
    let (mut nodes, mut ids) = ([Node::EMPTY; 4], [0u32; 2]);
    let mut slots = [ObjectSlot::<f32>::EMPTY; 2];
    let memory = RenderMemory {
        objects: &mut slots,
        accel: AccelMemory {
            nodes: &mut nodes,
            words: &mut ids,
            ..AccelMemory::default()
        },
    };
    let r = Renderer::new(&scene, st, AccelKind::Linear, memory).unwrap();
    let mut out = vec![0u8; 4 * 3 * 3];
    r.render_srgb8(&mut out).unwrap();
    let err = r.render_srgb8(&mut out[..35]).unwrap_err();
    assert_eq!(
        (err.item, err.field, err.problem),
        (
            Item::Tile,
            "out",
            Problem::TooSmall {
                needed: 36,
                available: 35
            }
        )
    );
    let outside = Tile {
        x: 3,
        y: 0,
        width: 2,
        height: 1,
    };
    assert_eq!(
        r.render_tile_srgb8(outside, &mut out).unwrap_err().field,
        "width"
    );
    let outside = Tile {
        x: 0,
        y: u32::MAX,
        width: 1,
        height: 2,
    };
    assert_eq!(
        r.render_tile_srgb8(outside, &mut out).unwrap_err().field,
        "height"
    );
    // The message names the item, field and problem.
    assert_eq!(
        err.to_string(),
        "tile `out`: buffer too small: need 36 slots, have 35"
    );
}

/// Rays leaving sphere surfaces (outward reflections and shadow rays) never hit their own
/// sphere again: a camera ray grazing a grid of spheres at several scales sees no acne, i.e.
/// a mirror sphere in an emissive box is `ρ·L` on every pixel it covers.
fn no_sphere_acne<S: Scalar>(scale: f32, offset: f32) {
    let t = tris::<S>(&cube(3.0 * scale, offset));
    let sp = [sphere::<S>([offset, 0.0, 0.0], scale)];
    let objects = [
        Object::new(Shape::Triangles(&t), 0),
        Object::new(Shape::Spheres(&sp), 1),
    ];
    let materials = [
        Material::Emissive { radiance: [1.0; 3] },
        Material::Mirror {
            reflectance: [0.5; 3],
        },
    ];
    let scene = Scene {
        objects: &objects,
        materials: &materials,
        lights: &[],
        camera: Camera {
            eye: [offset, 0.0, 2.5 * scale],
            look_at: [offset, 0.0, 0.0],
            up: [0.0, 1.0, 0.0],
            vfov_deg: 50.0,
            aperture_radius: 0.0,
            focus_distance: 1.0,
        },
        background: [0.0; 3],
    };
    let st = Settings {
        width: 48,
        height: 48,
        spp: 1,
        max_depth: 1,
        ..Settings::default()
    };
    let px = render(&scene, st, AccelKind::default()).unwrap();
    let bad = px
        .iter()
        .filter(|p| **p != [1.0; 3] && **p != [0.5; 3])
        .count();
    assert_eq!(bad, 0, "{} scale {scale} offset {offset}", S::NAME);
}

#[test]
fn spheres_leave_their_surface_cleanly() {
    for (scale, offset) in [
        (1.0, 0.0),
        (0.01, 0.0),
        (100.0, 0.0),
        (1.0, 1000.0),
        (0.01, 10.0),
    ] {
        no_sphere_acne::<f32>(scale, offset);
    }
    for (scale, offset) in [(1.0, 0.0), (0.05, 0.0), (100.0, 0.0), (1.0, 4000.0)] {
        no_sphere_acne::<I16F16>(scale, offset);
    }
}
