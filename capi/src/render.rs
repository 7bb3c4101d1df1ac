//! Rendering from C: a scene of plain structs and arrays ([`RkScene`]), checked and built into
//! the caller's memory by [`rk_renderer_init`] (sized by [`rk_render_bytes`]), then rendered
//! tile by tile to 8-bit sRGB by [`rk_render_tile`]: the same bytes as the kernel's
//! `Renderer::render_tile_srgb8` on the same scene.
//!
//! Everything the renderer keeps is copied into the caller's memory at init: its state, one slot
//! per object, the primitives converted to the number mode, the materials, the lights and the
//! accelerators. The [`RkScene`] and its arrays need not outlive the call. Every object gets a
//! BVH of the scene's kind (4-wide by default), built with the SAH.

use crate::{RkStatus, RK_KIND_BVH, RK_KIND_BVH4, RK_MODE_F32, RK_MODE_FIXED};
use core::ffi::{c_char, c_void};
use core::mem::{align_of, size_of};
use raykernel::bvh::BuildOptions;
use raykernel::render::{
    memory_needed, Camera, Filter, Item, Light, Material, Object, ObjectSlot, Problem,
    RenderMemory, Renderer, SamplerKind, Scene, SceneError, Settings, Shape, Tile, MAX_LIGHTS,
};
use raykernel::spawn::SpawnScalar;
use raykernel::{
    AccelFamily, AccelMemory, BuildError, Bvh4Family, BvhFamily, MemoryNeeded, Node, Node4, Sphere,
    Triangle, I16F16, MAX_PRIMS,
};

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

/// The kernel's defaults: 64 × 64 pixels, 16 spp, depth 4, stratified, box filter, seed 0.
#[no_mangle]
pub extern "C" fn rk_render_settings_default() -> RkRenderSettings {
    let s = Settings::default();
    RkRenderSettings {
        width: s.width,
        height: s.height,
        spp: s.spp,
        max_depth: s.max_depth,
        sampler: match s.sampler {
            SamplerKind::Independent => RK_SAMPLER_INDEPENDENT,
            SamplerKind::Stratified => RK_SAMPLER_STRATIFIED,
            SamplerKind::Sobol => RK_SAMPLER_SOBOL,
        },
        filter: match s.filter {
            Filter::Box => RK_FILTER_BOX,
            Filter::Tent => RK_FILTER_TENT,
        },
        seed: s.seed,
    }
}

/// Bytes of memory `rk_renderer_init` needs for `scene` (any alignment: 127 bytes of it are
/// slack for aligning), or 0 if `scene` is null or unusable before any value is checked
/// (unknown mode, kind or shape, a null array, sizes beyond the address space).
#[no_mangle]
pub unsafe extern "C" fn rk_render_bytes(scene: *const RkScene) -> usize {
    let Ok(view) = view(scene) else {
        return 0;
    };
    view.counts()
        .and_then(|c| {
            let layout = match view.which()? {
                Which::F32Bvh => layout::<f32, BvhFamily>(&c),
                Which::F32Bvh4 => layout::<f32, Bvh4Family>(&c),
                Which::FixedBvh => layout::<I16F16, BvhFamily>(&c),
                Which::FixedBvh4 => layout::<I16F16, Bvh4Family>(&c),
            };
            layout
                .and_then(|l| l.end.checked_add(ALIGN - 1))
                .ok_or(Failure::scene(RkStatus::ErrTooLarge, "objects"))
        })
        .unwrap_or(0)
}

/// Checks `scene` and builds a renderer for it into `memory` (`memory_bytes >=
/// rk_render_bytes(scene)`), filling `out`. On an error, `*error` (when not null) names the
/// value at fault, `out` is left uninitialised (`RK_STATUS_ERR_NOT_INITIALISED` if used) and
/// `memory` holds nothing of use. `memory` must stay valid, unmoved and unmodified while
/// `out` (or a copy) is used.
#[no_mangle]
pub unsafe extern "C" fn rk_renderer_init(
    scene: *const RkScene,
    memory: *mut c_void,
    memory_bytes: usize,
    out: *mut RkRenderer,
    error: *mut RkSceneError,
) -> RkStatus {
    if out.is_null() {
        return RkStatus::ErrNull;
    }
    let result = init(scene, memory, memory_bytes);
    let fail = match result {
        Ok(renderer) => {
            store(out, renderer);
            return RkStatus::Ok;
        }
        Err(f) => f,
    };
    // SAFETY: `out` is non-null and valid for writes (contract); all-zero is "uninitialised".
    unsafe {
        out.write(RkRenderer {
            opaque: [0; RK_RENDERER_WORDS],
        });
    }
    if !error.is_null() {
        // SAFETY: non-null, valid for writes (contract).
        unsafe { error.write(fail.to_c()) };
    }
    fail.status
}

/// Renders the tile of columns `x..x + width` and rows `y..y + height` as 8-bit sRGB into
/// `out` (3 bytes per pixel, row-major within the tile, `out_len >= 3·width·height`): the same
/// bytes as rendering the whole image and cutting the tile out. Tiles may be rendered in any
/// order and at the same time from several threads or cores (the renderer is only read).
#[no_mangle]
pub unsafe extern "C" fn rk_render_tile(
    renderer: *const RkRenderer,
    x: u32,
    y: u32,
    width: u32,
    height: u32,
    out: *mut u8,
    out_len: usize,
) -> RkStatus {
    if renderer.is_null() || out.is_null() {
        return RkStatus::ErrNull;
    }
    // SAFETY: non-null, valid for reads of an `RkRenderer` (contract); the first word is read as
    // a `u32`, valid for any bits.
    if unsafe { renderer.cast::<u32>().read() } != TAG {
        return RkStatus::ErrNotInitialised;
    }
    // SAFETY: the tag shows `store` wrote a `Handle` here.
    let handle = unsafe { renderer.cast::<Handle>().read() };
    // SAFETY: valid for writes of `out_len` bytes (contract).
    let out = unsafe { core::slice::from_raw_parts_mut(out, out_len) };
    let tile = Tile {
        x,
        y,
        width,
        height,
    };
    // SAFETY (each arm): the pointer is the renderer `init` wrote into the caller's memory,
    // which is still valid and unmodified (contract); it is only read.
    let rendered = match handle.renderer {
        AnyRenderer::F32Bvh(r) => unsafe { &*r }.render_tile_srgb8(tile, out),
        AnyRenderer::F32Bvh4(r) => unsafe { &*r }.render_tile_srgb8(tile, out),
        AnyRenderer::FixedBvh(r) => unsafe { &*r }.render_tile_srgb8(tile, out),
        AnyRenderer::FixedBvh4(r) => unsafe { &*r }.render_tile_srgb8(tile, out),
    };
    match rendered {
        Ok(_) => RkStatus::Ok,
        Err(e) => status_of(&e, false),
    }
}

/// Alignment of the start of the laid-out memory (the 4-wide BVH's nodes need 128).
const ALIGN: usize = 128;
const TAG: u32 = 0x524b_524e; // "RKRN"

/// A renderer in the caller's memory, in one of the four mode and family pairs.
#[derive(Clone, Copy)]
enum AnyRenderer {
    F32Bvh(*const Renderer<'static, f32, BvhFamily>),
    F32Bvh4(*const Renderer<'static, f32, Bvh4Family>),
    FixedBvh(*const Renderer<'static, I16F16, BvhFamily>),
    FixedBvh4(*const Renderer<'static, I16F16, Bvh4Family>),
}

/// What an [`RkRenderer`] holds. `tag` first, so an uninitialised value is recognised by
/// reading one `u32`.
#[repr(C)]
#[derive(Clone, Copy)]
struct Handle {
    tag: u32,
    renderer: AnyRenderer,
}

const _: () = assert!(size_of::<Handle>() <= size_of::<RkRenderer>());
const _: () = assert!(align_of::<Handle>() <= align_of::<RkRenderer>());

fn store(out: *mut RkRenderer, renderer: AnyRenderer) {
    // SAFETY: callers checked `out` for null; valid for writes (contract), size and alignment
    // asserted above.
    unsafe {
        out.write(RkRenderer {
            opaque: [0; RK_RENDERER_WORDS],
        });
        out.cast::<Handle>().write(Handle { tag: TAG, renderer });
    }
}

/// The mode and accelerator family a scene names.
#[derive(Clone, Copy)]
enum Which {
    F32Bvh,
    F32Bvh4,
    FixedBvh,
    FixedBvh4,
}

/// A rejected input: the status and where.
#[derive(Clone, Copy, Debug)]
struct Failure {
    status: RkStatus,
    item: u32,
    index: usize,
    field: &'static str,
    range: (f32, f32),
}

impl Failure {
    const fn new(status: RkStatus, item: u32, index: usize, field: &'static str) -> Self {
        Self {
            status,
            item,
            index,
            field,
            range: (0.0, 0.0),
        }
    }

    const fn scene(status: RkStatus, field: &'static str) -> Self {
        Self::new(status, RK_ITEM_SCENE, 0, field)
    }

    fn to_c(self) -> RkSceneError {
        let mut field = [0 as c_char; RK_FIELD_LEN];
        for (slot, b) in field[..RK_FIELD_LEN - 1].iter_mut().zip(self.field.bytes()) {
            *slot = b as c_char;
        }
        RkSceneError {
            item: self.item,
            index: u32::try_from(self.index).unwrap_or(u32::MAX),
            field,
            min: self.range.0,
            max: self.range.1,
        }
    }
}

/// The status for a kernel error (`sphere`: the object named is a set of spheres).
fn status_of(e: &SceneError, sphere: bool) -> RkStatus {
    let tile = e.item == Item::Tile;
    match e.problem {
        Problem::NonFinite => RkStatus::ErrNonFinite,
        Problem::Negative => RkStatus::ErrNegative,
        Problem::AboveOne => RkStatus::ErrAboveOne,
        Problem::NotPositive => RkStatus::ErrNotPositive,
        Problem::OutOfRange { .. } if tile => RkStatus::ErrBadTile,
        Problem::OutOfRange { .. } => RkStatus::ErrOutOfRange,
        Problem::ZeroArea => RkStatus::ErrZeroArea,
        Problem::Degenerate => RkStatus::ErrDegenerate,
        Problem::Index { .. } => RkStatus::ErrBadIndex,
        Problem::TooMany { .. } => RkStatus::ErrTooMany,
        Problem::TooSmall { .. } if tile => RkStatus::ErrBufferTooSmall,
        Problem::TooSmall { .. } => RkStatus::ErrMemoryTooSmall,
        Problem::Build(BuildError::BadPrimitive { .. }) if sphere => RkStatus::ErrBadSphere,
        Problem::Build(BuildError::BadPrimitive { .. }) => RkStatus::ErrBadTriangle,
        Problem::Build(BuildError::TooManyPrims { .. }) => RkStatus::ErrTooLarge,
        Problem::Build(BuildError::ArenaTooSmall { .. }) => RkStatus::ErrMemoryTooSmall,
        Problem::Build(_) | Problem::NotLinked => RkStatus::ErrBadArgument,
    }
}

fn failure_of(e: &SceneError, objects: &[RkObject]) -> Failure {
    let sphere = e.item == Item::Object
        && objects
            .get(e.index)
            .is_some_and(|o| o.shape == RK_SHAPE_SPHERES);
    // The kernel's item and field, renamed to the C struct and field holding the value.
    let (item, field) = match (e.item, e.field) {
        (Item::Object, "shape") => (RK_ITEM_OBJECT, "data"),
        (Item::Object, "material" | "motion") => (RK_ITEM_OBJECT, e.field),
        (Item::Object, _) => (RK_ITEM_SCENE, "memory"),
        (Item::Material, "albedo" | "reflectance" | "radiance") => (RK_ITEM_MATERIAL, "color"),
        (Item::Material, _) => (RK_ITEM_MATERIAL, e.field),
        (Item::Light, "lights") => (RK_ITEM_SCENE, "light_count"),
        (Item::Light, "corner" | "center") => (RK_ITEM_LIGHT, "position"),
        (Item::Light, "intensity" | "radiance") => (RK_ITEM_LIGHT, "color"),
        (Item::Light, _) => (RK_ITEM_LIGHT, e.field),
        (Item::Camera, _) => (RK_ITEM_CAMERA, e.field),
        (Item::Settings, "background") => (RK_ITEM_SCENE, "background"),
        (Item::Settings | Item::Tile, _) => (RK_ITEM_SETTINGS, e.field),
    };
    let mut f = Failure::new(status_of(e, sphere), item, e.index, field);
    if let Problem::OutOfRange { min, max } = e.problem {
        f.range = (min, max);
    }
    f
}

/// The caller's scene, its arrays as slices (valid for the call).
struct View<'s> {
    scene: RkScene,
    objects: &'s [RkObject],
    materials: &'s [RkMaterial],
    lights: &'s [RkLight],
}

/// `count` values at `p` (null allowed when `count` is 0), checked for null and alignment.
///
/// # Safety
/// `p` is null or valid for reads of `count` values of `T` for `'s` (the caller's contract).
unsafe fn array<'s, T>(p: *const T, count: usize, fail: Failure) -> Result<&'s [T], Failure> {
    if count == 0 {
        return Ok(&[]);
    }
    if p.is_null() {
        return Err(Failure {
            status: RkStatus::ErrNull,
            ..fail
        });
    }
    if !p.is_aligned() {
        return Err(Failure {
            status: RkStatus::ErrMisaligned,
            ..fail
        });
    }
    // SAFETY: non-null, aligned, valid for `count` reads (function contract).
    Ok(unsafe { core::slice::from_raw_parts(p, count) })
}

fn view<'s>(scene: *const RkScene) -> Result<View<'s>, Failure> {
    if scene.is_null() {
        return Err(Failure::scene(RkStatus::ErrNull, "scene"));
    }
    // SAFETY: non-null, valid for reads (contract); every bit pattern is a valid `RkScene`.
    let scene = unsafe { scene.read() };
    let at = |field| Failure::scene(RkStatus::ErrNull, field);
    // SAFETY (all three): the arrays are valid for their counts during the call (contract).
    let objects = unsafe { array(scene.objects, scene.object_count as usize, at("objects")) }?;
    let materials = unsafe {
        array(
            scene.materials,
            scene.material_count as usize,
            at("materials"),
        )
    }?;
    let lights = unsafe { array(scene.lights, scene.light_count as usize, at("lights")) }?;
    Ok(View {
        scene,
        objects,
        materials,
        lights,
    })
}

/// How many of each thing a scene's memory holds.
#[derive(Clone, Copy, Debug)]
struct Counts {
    triangles: usize,
    spheres: usize,
    objects: usize,
    materials: usize,
    lights: usize,
    accel: MemoryNeeded,
}

impl View<'_> {
    fn which(&self) -> Result<Which, Failure> {
        let bvh4 = match self.scene.kind {
            0 | RK_KIND_BVH4 => true,
            RK_KIND_BVH => false,
            _ => return Err(Failure::scene(RkStatus::ErrBadArgument, "kind")),
        };
        match (self.scene.mode, bvh4) {
            (RK_MODE_F32, false) => Ok(Which::F32Bvh),
            (RK_MODE_F32, true) => Ok(Which::F32Bvh4),
            (RK_MODE_FIXED, false) => Ok(Which::FixedBvh),
            (RK_MODE_FIXED, true) => Ok(Which::FixedBvh4),
            _ => Err(Failure::scene(RkStatus::ErrBadArgument, "mode")),
        }
    }

    /// The floats of object `o` (index `i`): nine per triangle or four per sphere.
    fn data(&self, i: usize, o: &RkObject) -> Result<&[f32], Failure> {
        let per = match o.shape {
            RK_SHAPE_TRIANGLES => 9,
            RK_SHAPE_SPHERES => 4,
            _ => {
                return Err(Failure::new(
                    RkStatus::ErrBadArgument,
                    RK_ITEM_OBJECT,
                    i,
                    "shape",
                ))
            }
        };
        let Some(n) = (o.count as usize).checked_mul(per) else {
            return Err(Failure::new(
                RkStatus::ErrTooLarge,
                RK_ITEM_OBJECT,
                i,
                "count",
            ));
        };
        let fail = Failure::new(RkStatus::ErrNull, RK_ITEM_OBJECT, i, "data");
        // SAFETY: `data` is valid for `count` primitives during the call (contract).
        unsafe { array(o.data, n, fail) }
    }

    /// The counts, and the accelerator memory as the kernel's `memory_needed` gives it for a
    /// BVH (or 4-wide BVH) per object and a top-level BVH over two objects or more.
    fn counts(&self) -> Result<Counts, Failure> {
        let bvh4 = matches!(self.which()?, Which::F32Bvh4 | Which::FixedBvh4);
        let (mut triangles, mut spheres, mut accel) = (0usize, 0usize, MemoryNeeded::NONE);
        let too_large = |i| Failure::new(RkStatus::ErrTooLarge, RK_ITEM_OBJECT, i, "count");
        for (i, o) in self.objects.iter().enumerate() {
            self.data(i, o)?;
            let n = o.count as usize;
            // The kernel refuses these too; refused here, the sizes below are the kernel's.
            if n > MAX_PRIMS {
                return Err(too_large(i));
            }
            let sum = if o.shape == RK_SHAPE_SPHERES {
                &mut spheres
            } else {
                &mut triangles
            };
            *sum = sum.checked_add(n).ok_or(too_large(i))?;
            let need = if bvh4 {
                MemoryNeeded::bvh4(n)
            } else {
                MemoryNeeded::bvh(n)
            };
            accel = accel.add(need);
        }
        if self.objects.len() >= 2 {
            accel = accel.add(MemoryNeeded::bvh(self.objects.len()));
        }
        Ok(Counts {
            triangles,
            spheres,
            objects: self.objects.len(),
            materials: self.materials.len(),
            lights: self.lights.len(),
            accel,
        })
    }
}

/// Byte offsets of everything in the caller's memory, from an [`ALIGN`]-aligned start; the
/// renderer's state sits at offset 0.
struct Layout {
    triangles: usize,
    spheres: usize,
    objects: usize,
    materials: usize,
    lights: usize,
    slots: usize,
    nodes: usize,
    nodes4: usize,
    words: usize,
    end: usize,
}

/// Places arrays one after the other, each aligned for its type.
struct Cursor(usize);

impl Cursor {
    fn place<T>(&mut self, count: usize) -> Option<usize> {
        let align = align_of::<T>();
        if align > ALIGN {
            return None;
        }
        let start = self.0.checked_add(align - 1)? / align * align;
        self.0 = start.checked_add(count.checked_mul(size_of::<T>())?)?;
        Some(start)
    }
}

fn layout<S: SpawnScalar, F: AccelFamily<S>>(c: &Counts) -> Option<Layout> {
    let mut at = Cursor(0);
    let state = at.place::<Renderer<'static, S, F>>(1)?;
    debug_assert_eq!(state, 0);
    Some(Layout {
        triangles: at.place::<Triangle<S>>(c.triangles)?,
        spheres: at.place::<Sphere<S>>(c.spheres)?,
        objects: at.place::<Object<'static, S>>(c.objects)?,
        materials: at.place::<Material>(c.materials)?,
        lights: at.place::<Light>(c.lights)?,
        slots: at.place::<ObjectSlot<'static, S, F>>(c.objects)?,
        nodes: at.place::<Node<S>>(c.accel.nodes)?,
        nodes4: at.place::<Node4<S>>(c.accel.nodes4)?,
        words: at.place::<u32>(c.accel.words)?,
        end: at.0,
    })
}

fn init(scene: *const RkScene, memory: *mut c_void, bytes: usize) -> Result<AnyRenderer, Failure> {
    let view = view(scene)?;
    if memory.is_null() {
        return Err(Failure::scene(RkStatus::ErrNull, "memory"));
    }
    let counts = view.counts()?;
    let memory = memory.cast::<u8>();
    Ok(match view.which()? {
        Which::F32Bvh => AnyRenderer::F32Bvh(init_in(&view, &counts, memory, bytes)?),
        Which::F32Bvh4 => AnyRenderer::F32Bvh4(init_in(&view, &counts, memory, bytes)?),
        Which::FixedBvh => AnyRenderer::FixedBvh(init_in(&view, &counts, memory, bytes)?),
        Which::FixedBvh4 => AnyRenderer::FixedBvh4(init_in(&view, &counts, memory, bytes)?),
    })
}

/// `count` values of `T`, each set to `value`, at `at`.
///
/// # Safety
/// `at` is aligned for `T`, valid for writes of `count` values for the rest of the program's
/// use of the renderer, and no other reference to that memory is used meanwhile.
unsafe fn filled<T: Copy>(at: *mut u8, count: usize, value: T) -> &'static mut [T] {
    let p = at.cast::<T>();
    for i in 0..count {
        // SAFETY: within the `count` values (function contract).
        unsafe { p.add(i).write(value) };
    }
    // SAFETY: all `count` values were just initialised (function contract).
    unsafe { core::slice::from_raw_parts_mut(p, count) }
}

fn init_in<S: SpawnScalar, F: AccelFamily<S, Options = BuildOptions>>(
    view: &View<'_>,
    counts: &Counts,
    memory: *mut u8,
    bytes: usize,
) -> Result<*const Renderer<'static, S, F>, Failure> {
    let too_large = Failure::scene(RkStatus::ErrTooLarge, "objects");
    let l = layout::<S, F>(counts).ok_or(too_large)?;
    let skip = memory.align_offset(ALIGN);
    if skip >= ALIGN || skip.saturating_add(l.end) > bytes {
        return Err(Failure::scene(RkStatus::ErrMemoryTooSmall, "memory"));
    }
    // SAFETY: `skip + l.end <= bytes`, so the region lies in the caller's memory, valid for
    // writes while the renderer is used (contract).
    let start = unsafe { memory.add(skip) };
    // SAFETY (every `filled` and `add` below): the offsets come from `layout`, which aligns
    // each array for its type from the `ALIGN`-aligned `start` and keeps them apart within
    // `l.end` bytes.
    let (tris, spheres) = unsafe {
        let zero = [S::ZERO; 3];
        (
            filled(
                start.add(l.triangles),
                counts.triangles,
                Triangle { v: [zero; 3] },
            ),
            filled(
                start.add(l.spheres),
                counts.spheres,
                Sphere {
                    center: zero,
                    radius: S::ZERO,
                },
            ),
        )
    };
    convert_primitives(view, tris, spheres)?;
    let (tris, spheres): (&'static [Triangle<S>], &'static [Sphere<S>]) = (tris, spheres);
    let empty = Object::new(Shape::Triangles(&[]), 0);
    // SAFETY: as above.
    let objects = unsafe { filled(start.add(l.objects), counts.objects, empty) };
    let (mut t, mut s) = (0usize, 0usize);
    for (slot, o) in objects.iter_mut().zip(view.objects) {
        let n = o.count as usize;
        // The ranges lie within the arrays (sized by the same counts): `get` never fails.
        let shape = if o.shape == RK_SHAPE_SPHERES {
            s += n;
            Shape::Spheres(spheres.get(s - n..s).unwrap_or_default())
        } else {
            t += n;
            Shape::Triangles(tris.get(t - n..t).unwrap_or_default())
        };
        *slot = Object {
            shape,
            material: o.material,
            motion: o.motion,
        };
    }
    let options = BuildOptions::default();
    debug_assert_eq!(
        memory_needed::<S, F>(objects, &options).accel,
        counts.accel,
        "`counts` sizes the accelerators as the kernel does"
    );
    let placeholder = Material::Diffuse { albedo: [0.0; 3] };
    // SAFETY: as above.
    let materials = unsafe { filled(start.add(l.materials), counts.materials, placeholder) };
    for (i, (slot, m)) in materials.iter_mut().zip(view.materials).enumerate() {
        *slot = material(m).ok_or(Failure::new(
            RkStatus::ErrBadArgument,
            RK_ITEM_MATERIAL,
            i,
            "kind",
        ))?;
    }
    let placeholder = Light::Point {
        position: [0.0; 3],
        intensity: [0.0; 3],
    };
    // SAFETY: as above.
    let lights = unsafe { filled(start.add(l.lights), counts.lights, placeholder) };
    for (i, (slot, light)) in lights.iter_mut().zip(view.lights).enumerate() {
        *slot = light_of(light).ok_or(Failure::new(
            RkStatus::ErrBadArgument,
            RK_ITEM_LIGHT,
            i,
            "kind",
        ))?;
    }
    let settings = settings(&view.scene.settings)?;
    // SAFETY: as above.
    let memory = unsafe {
        RenderMemory {
            objects: filled(start.add(l.slots), counts.objects, ObjectSlot::EMPTY),
            accel: AccelMemory {
                nodes: filled(start.add(l.nodes), counts.accel.nodes, Node::EMPTY),
                nodes4: filled(start.add(l.nodes4), counts.accel.nodes4, Node4::EMPTY),
                kd_nodes: &mut [],
                words: filled(start.add(l.words), counts.accel.words, 0u32),
            },
        }
    };
    let c = &view.scene.camera;
    let scene = Scene {
        objects,
        materials,
        lights,
        camera: Camera {
            eye: c.eye,
            look_at: c.look_at,
            up: c.up,
            vfov_deg: c.vfov_deg,
            aperture_radius: c.aperture_radius,
            focus_distance: c.focus_distance,
        },
        background: view.scene.background,
    };
    let renderer = Renderer::<'static, S, F>::new(&scene, settings, options, memory)
        .map_err(|e| failure_of(&e, view.objects))?;
    let state = start.cast::<Renderer<'static, S, F>>();
    // SAFETY: offset 0 of the region is reserved for the state, aligned for it (`layout`).
    unsafe { state.write(renderer) };
    Ok(state)
}

/// Converts every object's floats into the mode, triangles and spheres in scene order.
fn convert_primitives<S: SpawnScalar>(
    view: &View<'_>,
    tris: &mut [Triangle<S>],
    spheres: &mut [Sphere<S>],
) -> Result<(), Failure> {
    let (mut tris, mut spheres) = (tris.iter_mut(), spheres.iter_mut());
    for (i, o) in view.objects.iter().enumerate() {
        let data = view.data(i, o)?;
        if o.shape == RK_SHAPE_SPHERES {
            let bad = Failure::new(RkStatus::ErrBadSphere, RK_ITEM_OBJECT, i, "data");
            // The data first: `zip` stops on it without taking a slot past the object's.
            for (c, slot) in data.chunks_exact(4).zip(spheres.by_ref()) {
                *slot = sphere(c).ok_or(bad)?;
            }
        } else {
            let bad = Failure::new(RkStatus::ErrBadTriangle, RK_ITEM_OBJECT, i, "data");
            for (c, slot) in data.chunks_exact(9).zip(tris.by_ref()) {
                let c: &[f32; 9] = c.try_into().map_err(|_| bad)?;
                let v = [[c[0], c[1], c[2]], [c[3], c[4], c[5]], [c[6], c[7], c[8]]];
                *slot = Triangle::from_f32(v).map_err(|_| bad)?;
            }
        }
    }
    Ok(())
}

/// A sphere from centre x y z and radius: finite, in the mode's range, radius not negative.
fn sphere<S: SpawnScalar>(c: &[f32]) -> Option<Sphere<S>> {
    let mut center = [S::ZERO; 3];
    for (slot, x) in center.iter_mut().zip(c) {
        *slot = S::coord_from_f32(*x).ok()?;
    }
    let r = *c.get(3)?;
    if r < 0.0 {
        return None;
    }
    Some(Sphere {
        center,
        radius: S::coord_from_f32(r).ok()?,
    })
}

fn material(m: &RkMaterial) -> Option<Material> {
    Some(match m.kind {
        RK_MATERIAL_DIFFUSE => Material::Diffuse { albedo: m.color },
        RK_MATERIAL_MIRROR => Material::Mirror {
            reflectance: m.color,
        },
        RK_MATERIAL_GLOSSY => Material::Glossy {
            reflectance: m.color,
            exponent: m.exponent,
        },
        RK_MATERIAL_EMISSIVE => Material::Emissive { radiance: m.color },
        _ => return None,
    })
}

fn light_of(l: &RkLight) -> Option<Light> {
    Some(match l.kind {
        RK_LIGHT_POINT => Light::Point {
            position: l.position,
            intensity: l.color,
        },
        RK_LIGHT_RECT => Light::Rect {
            corner: l.position,
            edge_u: l.edge_u,
            edge_v: l.edge_v,
            radiance: l.color,
        },
        RK_LIGHT_SPHERE => Light::Sphere {
            center: l.position,
            radius: l.radius,
            radiance: l.color,
        },
        _ => return None,
    })
}

/// The kernel's settings: the C fields over the kernel's defaults (fields the C struct does not
/// have keep them).
fn settings(c: &RkRenderSettings) -> Result<Settings, Failure> {
    let bad = |field| Failure::new(RkStatus::ErrBadArgument, RK_ITEM_SETTINGS, 0, field);
    let sampler = match c.sampler {
        RK_SAMPLER_INDEPENDENT => SamplerKind::Independent,
        RK_SAMPLER_STRATIFIED => SamplerKind::Stratified,
        RK_SAMPLER_SOBOL => SamplerKind::Sobol,
        _ => return Err(bad("sampler")),
    };
    let filter = match c.filter {
        RK_FILTER_BOX => Filter::Box,
        RK_FILTER_TENT => Filter::Tent,
        _ => return Err(bad("filter")),
    };
    // The kernel's `Settings` may gain fields the C struct does not have yet.
    #[allow(clippy::needless_update)]
    Ok(Settings {
        width: c.width,
        height: c.height,
        spp: c.spp,
        max_depth: c.max_depth,
        sampler,
        filter,
        seed: c.seed,
        ..Settings::default()
    })
}
