//! Smooth shading from vertex normals: the shading normal is the corners' normals blended by
//! the hit's barycentrics (known answers for the cosine of a point light on a floor), the
//! geometric normal still decides which directions leave the surface, and bad normal lists are
//! typed errors.

mod common;

use raykernel::render::{
    Camera, Item, Light, Material, Object, Problem, Scene, SceneError, Settings, Shape,
};
use raykernel::{Scalar, Triangle, I16F16};

/// The floor: one triangle in `y = 0` whose corners are chosen so the origin has barycentrics
/// `(u, v) = (1/4, 1/4)`; its winding makes the geometric normal point down (`-y`).
const FLOOR: [[f32; 3]; 3] = [[-1.0, 0.0, -1.0], [3.0, 0.0, -1.0], [-1.0, 0.0, 3.0]];
const ALBEDO: f32 = 0.5;
const INTENSITY: f32 = 4.0;

/// The linear radiance of the one pixel of a 1×1, 1-sample render looking straight down at the
/// origin from `(0, 1, 0)`, the floor lit by a point light at `light`.
fn pixel<S: Scalar>(normals: &[[[f32; 3]; 3]], light: [f32; 3]) -> Result<[f32; 3], SceneError> {
    let floor = [Triangle::<S>::from_f32(FLOOR).unwrap()];
    let objects = [Object {
        vertex_normals: normals,
        ..Object::new(Shape::Triangles(&floor), 0)
    }];
    let materials = [Material::Diffuse {
        albedo: [ALBEDO; 3],
    }];
    let lights = [Light::Point {
        position: light,
        intensity: [INTENSITY; 3],
    }];
    let camera = Camera {
        eye: [0.0, 1.0, 0.0],
        look_at: [0.0, 0.0, 0.0],
        up: [0.0, 0.0, 1.0],
        vfov_deg: 1.0,
        aperture_radius: 0.0,
        focus_distance: 1.0,
    };
    let scene = Scene {
        objects: &objects,
        materials: &materials,
        lights: &lights,
        camera,
        background: [0.0; 3],
    };
    let settings = Settings {
        width: 1,
        height: 1,
        spp: 1,
        ..Settings::default()
    };
    Ok(common::render_linear(&scene, settings)?[0])
}

/// The radiance of the floor at the origin under the light at `(0, 2, 0)` for a shading normal
/// whose cosine with `+y` is `cos`: albedo/π · I · cos / d².
fn expected(cos: f64) -> f64 {
    f64::from(ALBEDO) / std::f64::consts::PI * f64::from(INTENSITY) * cos / 4.0
}

fn assert_close(got: [f32; 3], want: f64, what: &str) {
    for c in got {
        let err = (f64::from(c) - want).abs() / want;
        assert!(
            err < 1e-5,
            "{what}: {c} against {want} (relative error {err:e})"
        );
    }
}

fn tilted() -> [f32; 3] {
    let h = core::f32::consts::FRAC_1_SQRT_2;
    [h, h, 0.0]
}

fn known_answers<S: Scalar>() {
    let above = [0.0, 2.0, 0.0];
    let up = [0.0, 1.0, 0.0];
    // No normals: flat, cosine 1.
    assert_close(pixel::<S>(&[], above).unwrap(), expected(1.0), "flat");
    // Normals equal to the face's: the same answer (their sign does not matter).
    assert_close(pixel::<S>(&[[up; 3]], above).unwrap(), expected(1.0), "up");
    let down = [0.0, -1.0, 0.0];
    assert_close(
        pixel::<S>(&[[down; 3]], above).unwrap(),
        expected(1.0),
        "down",
    );
    // All three tilted by 45°: cosine 1/√2, whatever their length.
    let t = tilted();
    let long = t.map(|x| x * 7.0);
    let n = [t, long, t];
    assert_close(
        pixel::<S>(&[n], above).unwrap(),
        expected(0.5f64.sqrt()),
        "tilted",
    );
    // Corner 0 up, corners 1 and 2 tilted, at barycentrics (1/4, 1/4): the blend is
    // (up + tilted) / 2, whose cosine with up is cos 22.5°.
    let blend = pixel::<S>(&[[up, t, t]], above).unwrap();
    assert_close(blend, expected((std::f64::consts::PI / 8.0).cos()), "blend");
    // All-zero normals: that triangle is flat.
    let zero = pixel::<S>(&[[[0.0; 3]; 3]], above).unwrap();
    assert_close(zero, expected(1.0), "zero normals");
}

#[test]
fn shading_normal_is_the_blend_of_the_corner_normals_f32() {
    known_answers::<f32>();
}

#[test]
fn shading_normal_is_the_blend_of_the_corner_normals_fixed() {
    known_answers::<I16F16>();
}

/// A light below the floor's plane: the tilted shading normal faces it, but a shadow ray
/// towards it would leave through the back of the surface, so it adds nothing.
fn light_behind_the_surface<S: Scalar>() {
    let below = [5.0, -0.5, 0.0];
    let n = [1.0, 0.1, 0.0];
    assert_eq!(pixel::<S>(&[[n; 3]], below).unwrap(), [0.0; 3]);
    // The same light lights the floor from its own side (seen from below it would be lit).
    let beside = [5.0, 0.5, 0.0];
    assert!(pixel::<S>(&[[n; 3]], beside).unwrap()[0] > 0.0);
}

#[test]
fn a_light_behind_the_geometric_surface_adds_nothing_f32() {
    light_behind_the_surface::<f32>();
}

#[test]
fn a_light_behind_the_geometric_surface_adds_nothing_fixed() {
    light_behind_the_surface::<I16F16>();
}

#[test]
fn bad_normal_lists_are_typed_errors() {
    let up = [0.0, 1.0, 0.0];
    let above = [0.0, 2.0, 0.0];
    let e = pixel::<f32>(&[[up; 3], [up; 3]], above).unwrap_err();
    assert_eq!(
        (e.item, e.index, e.field, e.problem),
        (
            Item::Object,
            0,
            "vertex_normals",
            Problem::Length { expected: 1 }
        )
    );
    let e = pixel::<f32>(&[[up, [f32::NAN, 0.0, 0.0], up]], above).unwrap_err();
    assert_eq!((e.field, e.problem), ("vertex_normals", Problem::NonFinite));
}
