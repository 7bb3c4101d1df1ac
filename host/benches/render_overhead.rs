//! The render plan's promise: unused features cost (almost) nothing. Two comparisons on the
//! same BVH, single thread, 256×256 pixels, a level-5 icosphere (20,480 triangles) on a floor:
//!
//! - `primary`: a scene that uses none of the distribution effects (1 spp, pinhole, static, no
//!   lights, no reflecting material: the objects are emissive) against a bare primary-ray caster
//!   (camera ray, closest hit, the hit object's colour or the background, sRGB encoding). The
//!   issue's bound: within 5%.
//! - `shadow`: the same with a diffuse material and one point light against a hand-written
//!   caster that also casts the shadow ray (the kernel's spawn rule) and shades Lambert.
//!
//! Both casters write the same bytes as the renderer (checked before timing).
//! `cargo bench -p raykernel-host --bench render_overhead`.

use criterion::{criterion_group, criterion_main, Criterion};
use raykernel::bvh::{nodes_needed, BuildOptions};
use raykernel::geom::spawn::{spawn_shadow_ray, SpawnScalar};
use raykernel::glam::Vec3;
use raykernel::render::{
    encode_srgb8, AccelChoice, AccelMemory, Camera, Light, Material, Object, ObjectSlot, Renderer,
    Scene, Settings, Shape,
};
use raykernel::{Accel, Bvh, Node, Ray, Triangle, I16F16};
use std::hint::black_box;

const SIZE: u32 = 256;
const ALBEDO: f32 = 0.7;
const LIGHT: [f32; 3] = [2.0, 4.0, 3.0];
const INTENSITY: f32 = 20.0;
/// Emitted radiance of the `primary` scene's objects, and its background.
const GLOW: [f32; 3] = [0.9, 0.6, 0.3];
const BACKGROUND: [f32; 3] = [0.05, 0.1, 0.2];
const CAMERA: Camera = Camera {
    eye: [0.0, 1.2, 3.5],
    look_at: [0.0, 0.6, 0.0],
    up: [0.0, 1.0, 0.0],
    vfov_deg: 40.0,
    aperture_radius: 0.0,
    focus_distance: 1.0,
};

fn geometry<S: SpawnScalar>() -> Vec<Triangle<S>> {
    let (verts, faces) = host::mesh::unit_icosphere(5);
    let p = |i: usize| {
        let v = verts[i];
        [
            v[0] as f32 * 0.6,
            v[1] as f32 * 0.6 + 0.6,
            v[2] as f32 * 0.6,
        ]
    };
    let mut t: Vec<[[f32; 3]; 3]> = faces.iter().map(|f| [p(f[0]), p(f[1]), p(f[2])]).collect();
    t.push([[-5.0, 0.0, -5.0], [-5.0, 0.0, 5.0], [5.0, 0.0, 5.0]]);
    t.push([[-5.0, 0.0, -5.0], [5.0, 0.0, 5.0], [5.0, 0.0, -5.0]]);
    t.iter().map(|v| Triangle::from_f32(*v).unwrap()).collect()
}

/// The hand-written caster: the same camera model, BVH, spawn rule and shading as the
/// renderer's plan for this scene, with nothing else.
fn bare_caster<S: SpawnScalar>(
    bvh: &Bvh<'_, S, Triangle<S>>,
    tris: &[Triangle<S>],
    out: &mut [u8],
) {
    let (w, u, v) = camera_frame();
    let light = LIGHT.map(|x| S::coord_from_f32(x).unwrap());
    for y in 0..SIZE {
        for x in 0..SIZE {
            let sx = 2.0 * (x as f32 + 0.5) / SIZE as f32 - 1.0;
            let sy = 1.0 - 2.0 * (y as f32 + 0.5) / SIZE as f32;
            let d = w + u * sx + v * sy;
            let ray = Ray::<S>::from_f32(CAMERA.eye, d.to_array(), 0.0, f32::INFINITY).unwrap();
            let mut c = 0.0f32;
            if let Some(hit) = bvh.intersect(&ray) {
                let tri = &tris[hit.prim as usize];
                let vf = tri.v.map(|p| Vec3::from_array(p.map(S::to_f32)));
                let mut n = (vf[1] - vf[0]).cross(vf[2] - vf[0]).normalize();
                let dir = d.normalize();
                if n.dot(dir) > 0.0 {
                    n = -n;
                }
                let (hu, hv) = (hit.u.to_f32(), hit.v.to_f32());
                let p = vf[0] + (vf[1] - vf[0]) * hu + (vf[2] - vf[0]) * hv;
                let to = Vec3::from_array(LIGHT) - p;
                let d2 = to.length_squared();
                let cos = n.dot(to) / d2.sqrt();
                if cos > 0.0 {
                    let shadow = spawn_shadow_ray(&ray, &hit, tri, light).unwrap();
                    if !bvh.occluded(&shadow) {
                        c = ALBEDO / std::f32::consts::PI * INTENSITY * cos / d2;
                    }
                }
            }
            let i = 3 * (y * SIZE + x) as usize;
            out[i..i + 3].fill(encode_srgb8(c));
        }
    }
}

/// The bare primary-ray caster: camera ray, closest hit, the emitter's colour or the background.
fn bare_primary<S: SpawnScalar>(bvh: &Bvh<'_, S, Triangle<S>>, out: &mut [u8]) {
    let (w, u, v) = camera_frame();
    for y in 0..SIZE {
        for x in 0..SIZE {
            let sx = 2.0 * (x as f32 + 0.5) / SIZE as f32 - 1.0;
            let sy = 1.0 - 2.0 * (y as f32 + 0.5) / SIZE as f32;
            let d = w + u * sx + v * sy;
            let ray = Ray::<S>::from_f32(CAMERA.eye, d.to_array(), 0.0, f32::INFINITY).unwrap();
            // Through `black_box`: a caster's colours come from its shading, so the compiler
            // must not pre-encode the two constants.
            let c = black_box(if bvh.intersect(&ray).is_some() {
                GLOW
            } else {
                BACKGROUND
            });
            let i = 3 * (y * SIZE + x) as usize;
            for (o, c) in out[i..i + 3].iter_mut().zip(c) {
                *o = encode_srgb8(c);
            }
        }
    }
}

/// The camera's forward, right and up vectors, the half-height scaled: the renderer's model.
fn camera_frame() -> (Vec3, Vec3, Vec3) {
    let eye = Vec3::from_array(CAMERA.eye);
    let w = (Vec3::from_array(CAMERA.look_at) - eye).normalize();
    let right = w.cross(Vec3::from_array(CAMERA.up)).normalize();
    let up = right.cross(w);
    let h = (CAMERA.vfov_deg.to_radians() * 0.5).tan();
    (w, right * h, up * h)
}

/// Renders `materials`/`lights` over `tris` with the renderer (1 spp, default BVH).
fn with_renderer<S: SpawnScalar>(
    tris: &[Triangle<S>],
    material: Material,
    lights: &[Light],
    background: [f32; 3],
    f: impl FnOnce(&Renderer<'_, S>),
) {
    let objects = [Object::new(Shape::Triangles(tris), 0)];
    let scene = Scene {
        objects: &objects,
        materials: &[material],
        lights,
        camera: CAMERA,
        background,
    };
    let settings = Settings {
        width: SIZE,
        height: SIZE,
        spp: 1,
        ..Settings::default()
    };
    let mut nodes = vec![Node::EMPTY; nodes_needed(tris.len())];
    let mut ids = vec![0u32; tris.len()];
    let mut slots = [ObjectSlot::EMPTY; 1];
    let memory = AccelMemory {
        objects: &mut slots,
        bvh_nodes: &mut nodes,
        kd_nodes: &mut [],
        words: &mut ids,
    };
    let r = Renderer::new(&scene, settings, AccelChoice::default(), memory).unwrap();
    let p = r.plan();
    assert!(p.pixel_centre && !p.reflections && !p.lens && !p.motion && p.area_lights == 0);
    f(&r);
}

fn bench_mode<S: SpawnScalar>(c: &mut Criterion) {
    let tris = geometry::<S>();
    let mut nodes = vec![Node::EMPTY; nodes_needed(tris.len())];
    let mut ids = vec![0u32; tris.len()];
    let bvh = Bvh::build(&tris, &mut nodes, &mut ids, BuildOptions::default()).unwrap();
    let pixels = (3 * SIZE * SIZE) as usize;
    let (mut bare, mut rendered) = (vec![0u8; pixels], vec![0u8; pixels]);

    let mut group = c.benchmark_group(format!("render_overhead_primary_{}", S::NAME));
    group.sample_size(20);
    let glow = Material::Emissive { radiance: GLOW };
    with_renderer(&tris, glow, &[], BACKGROUND, |r| {
        assert_eq!(r.plan().point_lights, 0);
        bare_primary(&bvh, &mut bare);
        r.render_srgb8(&mut rendered).unwrap();
        assert!(
            bare == rendered,
            "the bare primary caster differs from the renderer"
        );
        group.bench_function("bare_caster", |b| {
            b.iter(|| bare_primary(black_box(&bvh), &mut bare));
        });
        group.bench_function("renderer", |b| {
            b.iter(|| r.render_srgb8(black_box(&mut rendered)).unwrap());
        });
    });
    group.finish();

    let mut group = c.benchmark_group(format!("render_overhead_shadow_{}", S::NAME));
    group.sample_size(20);
    let diffuse = Material::Diffuse {
        albedo: [ALBEDO; 3],
    };
    let light = [Light::Point {
        position: LIGHT,
        intensity: [INTENSITY; 3],
    }];
    with_renderer(&tris, diffuse, &light, [0.0; 3], |r| {
        bare_caster(&bvh, &tris, &mut bare);
        r.render_srgb8(&mut rendered).unwrap();
        let differ = bare.iter().zip(&rendered).filter(|(a, b)| a != b).count();
        // The hand-written caster shades in f32 where the renderer uses f64 surface points:
        // a few bytes may differ by rounding; the work is the same.
        assert!(differ * 100 < pixels, "{differ} bytes differ");
        group.bench_function("bare_caster", |b| {
            b.iter(|| bare_caster(black_box(&bvh), &tris, &mut bare));
        });
        group.bench_function("renderer", |b| {
            b.iter(|| r.render_srgb8(black_box(&mut rendered)).unwrap());
        });
    });
    group.finish();
}

fn benches(c: &mut Criterion) {
    bench_mode::<f32>(c);
    bench_mode::<I16F16>(c);
}

criterion_group!(overhead, benches);
criterion_main!(overhead);
