//! The C scene description and the values naming its tags, items and sizes.

use core::ffi::c_char;
use raykernel::render::MAX_LIGHTS;

/// `RkObject::shape`: a triangle mesh, nine floats per triangle (x y z of three vertices).
pub const RK_SHAPE_TRIANGLES: u32 = 1;
/// `RkObject::shape`: spheres, four floats each (centre x y z, radius).
pub const RK_SHAPE_SPHERES: u32 = 2;

/// `RkMaterial::kind`: Lambertian, `color` is the albedo (each channel in `[0, 1]`).
pub const RK_MATERIAL_DIFFUSE: u32 = 1;
/// `RkMaterial::kind`: perfect mirror, `color` is the reflectance.
pub const RK_MATERIAL_MIRROR: u32 = 2;
/// `RkMaterial::kind`: glossy (Phong lobe of `exponent >= 1`), `color` is the reflectance.
pub const RK_MATERIAL_GLOSSY: u32 = 3;
/// `RkMaterial::kind`: emits `color` (radiance, `>= 0`) and reflects nothing.
pub const RK_MATERIAL_EMISSIVE: u32 = 4;

/// `RkLight::kind`: a point at `position` of radiant intensity `color`.
pub const RK_LIGHT_POINT: u32 = 1;
/// `RkLight::kind`: the parallelogram `position + a·edge_u + b·edge_v` (`a, b` in `[0, 1]`)
/// emitting radiance `color` towards `edge_u × edge_v`.
pub const RK_LIGHT_RECT: u32 = 2;
/// `RkLight::kind`: a sphere at `position` of `radius` emitting radiance `color`.
pub const RK_LIGHT_SPHERE: u32 = 3;
/// Most lights a scene may have.
pub const RK_MAX_LIGHTS: u32 = 8;

/// `RkRenderSettings::sampler`: a hash per random value.
pub const RK_SAMPLER_INDEPENDENT: u32 = 1;
/// `RkRenderSettings::sampler`: stratified (jittered) samples (the default).
pub const RK_SAMPLER_STRATIFIED: u32 = 2;
/// `RkRenderSettings::sampler`: Owen-scrambled Sobol points.
pub const RK_SAMPLER_SOBOL: u32 = 3;

/// `RkRenderSettings::filter`: uniform over the pixel (the default).
pub const RK_FILTER_BOX: u32 = 1;
/// `RkRenderSettings::filter`: triangle filter of radius one pixel.
pub const RK_FILTER_TENT: u32 = 2;

/// `RkSceneError::item`: a field of the `RkScene` itself (mode, kind, an array pointer).
pub const RK_ITEM_SCENE: u32 = 0;
/// `RkSceneError::item`: `objects[index]`.
pub const RK_ITEM_OBJECT: u32 = 1;
/// `RkSceneError::item`: `materials[index]`.
pub const RK_ITEM_MATERIAL: u32 = 2;
/// `RkSceneError::item`: `lights[index]`.
pub const RK_ITEM_LIGHT: u32 = 3;
/// `RkSceneError::item`: the camera.
pub const RK_ITEM_CAMERA: u32 = 4;
/// `RkSceneError::item`: the settings or the background.
pub const RK_ITEM_SETTINGS: u32 = 5;

/// Bytes of `RkSceneError::field`, its NUL included.
pub const RK_FIELD_LEN: usize = 32;
/// 64-bit words of an [`RkRenderer`].
pub const RK_RENDERER_WORDS: usize = 4;

const _: () = assert!(RK_MAX_LIGHTS as usize == MAX_LIGHTS);

/// One object: a triangle mesh or a set of spheres with one material, static or moving
/// linearly over the shutter interval.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct RkObject {
    /// `RK_SHAPE_TRIANGLES` or `RK_SHAPE_SPHERES`.
    pub shape: u32,
    /// Index into `RkScene::materials`.
    pub material: u32,
    /// Triangles or spheres in `data`.
    pub count: u32,
    /// Nine floats per triangle or four per sphere (see `shape`), at shutter open.
    pub data: *const f32,
    /// Displacement from shutter open to shutter close (zero: static).
    pub motion: [f32; 3],
}

/// A material, tagged by `kind` (`RK_MATERIAL_*`).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct RkMaterial {
    /// `RK_MATERIAL_DIFFUSE`, `_MIRROR`, `_GLOSSY` or `_EMISSIVE`.
    pub kind: u32,
    /// Albedo, reflectance or emitted radiance (linear RGB), as `kind` says.
    pub color: [f32; 3],
    /// Glossy lobe exponent (`>= 1`); ignored by the other kinds.
    pub exponent: f32,
}

/// A light, tagged by `kind` (`RK_LIGHT_*`); the fields a kind does not name are ignored.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct RkLight {
    /// `RK_LIGHT_POINT`, `_RECT` or `_SPHERE`.
    pub kind: u32,
    /// Point position, rectangle corner or sphere centre.
    pub position: [f32; 3],
    /// Rectangle: first edge.
    pub edge_u: [f32; 3],
    /// Rectangle: second edge.
    pub edge_v: [f32; 3],
    /// Sphere: radius (`> 0`).
    pub radius: f32,
    /// Point: radiant intensity; rectangle and sphere: emitted radiance (linear RGB, `>= 0`).
    pub color: [f32; 3],
}

/// A thin-lens camera; `aperture_radius == 0` is a pinhole.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct RkCamera {
    /// Eye (lens centre).
    pub eye: [f32; 3],
    /// A point on the optical axis.
    pub look_at: [f32; 3],
    /// Up hint (not parallel to the view direction).
    pub up: [f32; 3],
    /// Full vertical field of view, degrees, in `(0, 180)`.
    pub vfov_deg: f32,
    /// Lens radius, `>= 0`.
    pub aperture_radius: f32,
    /// Distance to the plane in focus, `> 0` (ignored for a pinhole).
    pub focus_distance: f32,
}

/// Image and sampling settings. Start from `rk_render_settings_default()` and set what you
/// need: fields added later then keep their defaults.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RkRenderSettings {
    /// Image width, pixels (`>= 1`).
    pub width: u32,
    /// Image height, pixels (`>= 1`).
    pub height: u32,
    /// Samples per pixel (`>= 1`); 1 samples each pixel centre.
    pub spp: u32,
    /// Most reflection bounces after the camera ray.
    pub max_depth: u32,
    /// `RK_SAMPLER_*`.
    pub sampler: u32,
    /// `RK_FILTER_*`.
    pub filter: u32,
    /// Seed of every random value: equal seeds give equal images, bit for bit.
    pub seed: u32,
}

/// A whole scene, borrowed for the duration of `rk_render_bytes` and `rk_renderer_init`.
/// Arrays may be null when their count is 0.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct RkScene {
    /// `RK_MODE_F32` or `RK_MODE_FIXED`: the number mode of the geometry.
    pub mode: u32,
    /// Each object's accelerator: `RK_KIND_BVH4` (or 0, the default) or `RK_KIND_BVH`.
    /// Every kind gives the same image.
    pub kind: u32,
    /// Objects, in the order that breaks ties between equal hits (lowest first).
    pub objects: *const RkObject,
    /// Entries of `objects`.
    pub object_count: u32,
    /// Materials, indexed by `RkObject::material`.
    pub materials: *const RkMaterial,
    /// Entries of `materials`.
    pub material_count: u32,
    /// Lights (at most `RK_MAX_LIGHTS`).
    pub lights: *const RkLight,
    /// Entries of `lights`.
    pub light_count: u32,
    /// Camera.
    pub camera: RkCamera,
    /// Radiance of rays that leave the scene (linear RGB, `>= 0`).
    pub background: [f32; 3],
    /// Image and sampling settings.
    pub settings: RkRenderSettings,
}

/// Which value `rk_renderer_init` rejected: `item` (`RK_ITEM_*`), its `index` in its list (0
/// for the scene, camera and settings), the name of the C field holding it (NUL-terminated;
/// `memory` when the memory is too small), and for `RK_STATUS_ERR_OUT_OF_RANGE` the accepted
/// range.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct RkSceneError {
    /// `RK_ITEM_*`.
    pub item: u32,
    /// Index within the item's list.
    pub index: u32,
    /// The field's name.
    pub field: [c_char; RK_FIELD_LEN],
    /// Lowest accepted value (`RK_STATUS_ERR_OUT_OF_RANGE` only, else 0).
    pub min: f32,
    /// Highest accepted value (`RK_STATUS_ERR_OUT_OF_RANGE` only, else 0).
    pub max: f32,
}

/// A renderer ready for tiles, filled by `rk_renderer_init`. Opaque; copy it freely (copies
/// share the caller's memory).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct RkRenderer {
    /// Private.
    pub opaque: [u64; RK_RENDERER_WORDS],
}
