//! The renderer's top-level BVH over its objects: a scene of many one-sphere objects renders
//! the same bytes as one object holding the same spheres, with every accelerator family, and
//! as brute force.

mod common;

use raykernel::bvh::BuildOptions;
use raykernel::render::{
    memory_needed, Camera, Light, Material, Object, ObjectSlot, RenderMemory, Renderer, Scene,
    Settings, Shape,
};
use raykernel::{
    AccelFamily, AccelKind, AccelMemory, AnyFamily, BvhFamily, KdNode, LinearFamily, Node, Node4,
    Node8, Scalar, Sphere, I16F16,
};
use raykernel_testkit::Rng;

/// `n` small spheres scattered in a box in front of the camera (some overlapping).
fn spheres<S: Scalar>(n: usize, seed: u64) -> Vec<Sphere<S>> {
    let mut rng = Rng::new(seed);
    (0..n)
        .map(|_| {
            let c = [
                rng.range(-4.0, 4.0),
                rng.range(-4.0, 4.0),
                rng.range(6.0, 14.0),
            ];
            let r = rng.range(0.05, 0.4);
            Sphere {
                center: c.map(|x| S::coord_from_f32(x).unwrap()),
                radius: S::coord_from_f32(r).unwrap(),
            }
        })
        .collect()
}

/// The sRGB bytes of `objects` rendered with family `F` and `options`, lit by one point light
/// (so shadow rays run the any-hit walk too).
fn render<S: Scalar, F: AccelFamily<S>>(objects: &[Object<'_, S>], options: F::Options) -> Vec<u8> {
    let materials = [Material::Diffuse {
        albedo: [0.8, 0.7, 0.6],
    }];
    let lights = [Light::Point {
        position: [3.0, 5.0, 0.0],
        intensity: [40.0; 3],
    }];
    let scene = Scene {
        objects,
        materials: &materials,
        lights: &lights,
        camera: Camera {
            eye: [0.0, 0.0, 0.0],
            look_at: [0.0, 0.0, 10.0],
            up: [0.0, 1.0, 0.0],
            vfov_deg: 50.0,
            aperture_radius: 0.0,
            focus_distance: 10.0,
        },
        background: [0.1, 0.1, 0.2],
    };
    let settings = Settings {
        width: 32,
        height: 32,
        spp: 1,
        ..Settings::default()
    };
    let need = memory_needed::<S, F>(objects, &options);
    let mut nodes = vec![Node::<S>::EMPTY; need.accel.nodes];
    let mut nodes4 = vec![Node4::<S>::EMPTY; need.accel.nodes4];
    let mut nodes8 = vec![Node8::<S>::EMPTY; need.accel.nodes8];
    let mut kd_nodes = vec![KdNode::<S>::EMPTY; need.accel.kd_nodes];
    let mut words = vec![0u32; need.accel.words];
    // Leaked: generic over `F`, a vector of slots borrowing from itself for the renderer's
    // lifetime could not be dropped (a named family's slots can live in a vector).
    let slots = Vec::leak(vec![ObjectSlot::<S, F>::EMPTY; need.objects]);
    let memory = RenderMemory {
        objects: slots,
        accel: AccelMemory {
            nodes: &mut nodes,
            nodes4: &mut nodes4,
            nodes8: &mut nodes8,
            kd_nodes: &mut kd_nodes,
            words: &mut words,
        },
    };
    let r: Renderer<'_, S, F> = Renderer::new(&scene, settings, options, memory).unwrap();
    let mut out = vec![0u8; 3 * 32 * 32];
    r.render_srgb8(&mut out).unwrap();
    out
}

fn many_objects_equal_one_object<S: Scalar>() {
    let all = spheres::<S>(300, 0x5EED);
    // One object per sphere, with empty objects between some of them (no ids of their own).
    let mut many = Vec::new();
    for (i, s) in all.iter().enumerate() {
        if i % 7 == 0 {
            many.push(Object::new(Shape::Spheres(&[]), 0));
        }
        many.push(Object::new(Shape::Spheres(core::slice::from_ref(s)), 0));
    }
    let one = [Object::new(Shape::Spheres(&all), 0)];
    let reference = render::<S, LinearFamily>(&one, ());
    let corner = &reference[..3];
    assert!(
        reference.chunks(3).filter(|p| p != &corner).count() > 100,
        "the spheres are in view"
    );
    let bvh = BuildOptions::default();
    let images = [
        ("one object, bvh", render::<S, BvhFamily>(&one, bvh)),
        ("many objects, linear", render::<S, LinearFamily>(&many, ())),
        ("many objects, bvh", render::<S, BvhFamily>(&many, bvh)),
    ];
    for (what, image) in images {
        assert!(image == reference, "{} {what}", S::NAME);
    }
    for kind in AccelKind::ALL {
        let image = render::<S, AnyFamily>(&many, kind);
        assert!(image == reference, "{} many objects, {kind}", S::NAME);
    }
}

#[test]
fn many_one_sphere_objects_render_as_one_object_f32() {
    many_objects_equal_one_object::<f32>();
}

#[test]
fn many_one_sphere_objects_render_as_one_object_fixed() {
    many_objects_equal_one_object::<I16F16>();
}
