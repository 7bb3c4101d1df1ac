//! One-sided surfaces ([`Object::one_sided`]): a quad whose front (the side its winding's
//! normal points to) faces the camera and a light renders exactly as a two-sided quad; seen
//! from behind it is black; and its back still blocks light. Both number modes, both
//! integrators (the path integrator with the `path-tracing` feature). Point lights only: the
//! images are exact, no noise bound needed.

mod common;

use raykernel::render::{Camera, Integrator, Light, Material, Object, Scene, Settings, Shape};
use raykernel::{Scalar, Triangle, I16F16};

/// The quad `[-h, h]²` at height `z`, wound counter-clockwise seen from `+z` (front `+z`) or,
/// with `flip`, from `-z`.
fn quad<S: Scalar>(h: f32, z: f32, flip: bool) -> [Triangle<S>; 2] {
    let p = |x: f32, y: f32| [x, y, z].map(|c| S::coord_from_f32(c).unwrap());
    let (a, b, c, d) = (p(-h, -h), p(h, -h), p(h, h), p(-h, h));
    if flip {
        [Triangle { v: [a, c, b] }, Triangle { v: [a, d, c] }]
    } else {
        [Triangle { v: [a, b, c] }, Triangle { v: [a, c, d] }]
    }
}

/// A camera on the z axis at `z`, looking at the origin.
fn camera(z: f32) -> Camera {
    Camera {
        eye: [0.0, 0.0, z],
        look_at: [0.0; 3],
        up: [0.0, 1.0, 0.0],
        vfov_deg: 30.0,
        aperture_radius: 0.0,
        focus_distance: 1.0,
    }
}

fn integrators() -> Vec<Integrator> {
    let mut v = vec![Integrator::Direct];
    if cfg!(feature = "path-tracing") {
        v.push(Integrator::Path { max_length: 3 });
    } else {
        println!("skipped the path integrator: needs `--features path-tracing`");
    }
    v
}

fn settings(integrator: Integrator) -> Settings {
    Settings {
        width: 8,
        height: 8,
        spp: 1,
        integrator,
        ..Settings::default()
    }
}

const MATERIALS: [Material; 1] = [Material::Diffuse {
    albedo: [0.8, 0.6, 0.4],
}];

/// The quad (front `+z`) seen and lit from `side` (`+1`: the front, `-1`: the back), one-sided
/// or not.
fn quad_image<S: Scalar>(side: f32, one_sided: bool, i: Integrator) -> Vec<[f32; 3]> {
    let tris = quad::<S>(1.0, 0.0, false);
    let objects = [Object {
        one_sided,
        ..Object::new(Shape::Triangles(&tris), 0)
    }];
    let lights = [Light::Point {
        position: [0.3, 0.2, 2.0 * side],
        intensity: [4.0; 3],
    }];
    let scene = Scene {
        objects: &objects,
        materials: &MATERIALS,
        lights: &lights,
        camera: camera(3.0 * side),
        background: [0.0; 3],
    };
    common::render_linear(&scene, settings(i)).unwrap()
}

fn lit(px: &[[f32; 3]]) -> usize {
    px.iter().filter(|p| p.iter().any(|&c| c > 0.0)).count()
}

fn quad_case<S: Scalar>() {
    for i in integrators() {
        let front = quad_image::<S>(1.0, true, i);
        assert_eq!(lit(&front), front.len(), "{i:?}: the quad fills the view");
        assert_eq!(
            front,
            quad_image::<S>(1.0, false, i),
            "{i:?}: front = two-sided"
        );
        let back = quad_image::<S>(-1.0, true, i);
        assert!(back.iter().all(|p| *p == [0.0; 3]), "{i:?}: back is black");
        // Two-sided, the back is lit as the front is.
        let two = quad_image::<S>(-1.0, false, i);
        assert_eq!(lit(&two), two.len(), "{i:?}: a two-sided back is lit");
    }
}

#[test]
fn one_sided_quad_is_black_from_behind_f32() {
    quad_case::<f32>();
}

#[test]
fn one_sided_quad_is_black_from_behind_fixed() {
    quad_case::<I16F16>();
}

/// A two-sided floor at `z = 0` seen from above, a light above it, and between them a
/// one-sided quad at `z = 1` (wound with `flip`): with its front or its back to the light, the
/// floor below it is in shadow.
fn occluder_case<S: Scalar>() {
    for i in integrators() {
        let floor = quad::<S>(4.0, 0.0, false);
        let image = |occluder: Option<bool>| {
            let blocker = quad::<S>(1.0, 1.0, occluder.unwrap_or(false));
            let mut objects = vec![Object::new(Shape::Triangles(&floor), 0)];
            if occluder.is_some() {
                objects.push(Object {
                    one_sided: true,
                    ..Object::new(Shape::Triangles(&blocker), 0)
                });
            }
            let lights = [Light::Point {
                position: [0.0, 0.0, 2.0],
                intensity: [4.0; 3],
            }];
            let scene = Scene {
                objects: &objects,
                materials: &MATERIALS,
                lights: &lights,
                camera: Camera {
                    eye: [0.0, -0.2, 0.5],
                    look_at: [0.0, 0.0, 0.0],
                    up: [0.0, 1.0, 0.0],
                    vfov_deg: 20.0,
                    aperture_radius: 0.0,
                    focus_distance: 1.0,
                },
                background: [0.0; 3],
            };
            common::render_linear(&scene, settings(i)).unwrap()
        };
        let open = image(None);
        assert_eq!(
            lit(&open),
            open.len(),
            "{i:?}: the floor is lit without the quad"
        );
        for flip in [false, true] {
            let shadowed = image(Some(flip));
            assert!(
                shadowed.iter().all(|p| *p == [0.0; 3]),
                "{i:?}: the quad (front to the light: {}) casts a shadow",
                !flip
            );
        }
    }
}

#[test]
fn one_sided_quad_blocks_light_from_both_sides_f32() {
    occluder_case::<f32>();
}

#[test]
fn one_sided_quad_blocks_light_from_both_sides_fixed() {
    occluder_case::<I16F16>();
}
