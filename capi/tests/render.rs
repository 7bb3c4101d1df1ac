//! Rendering through the C interface: a scene given as C structs renders the same sRGB bytes as
//! the kernel's `Renderer` on the same scene (both modes, both BVH kinds, any tiling); the
//! caller memory `rk_render_bytes` gives is exact at every alignment; bad inputs give their
//! typed status and name the value at fault. The known answers the C test and the firmware
//! check are in `examples/common/render_golden.h`, which `golden_header_matches_the_kernel`
//! regenerates from the kernel (`BLESS=1 cargo test -p raykernel-c --test render` rewrites it).

use core::ffi::c_void;
use raykernel::bvh::BuildOptions;
use raykernel::render::scenes::{ObjectData, SceneData, ShapeRange, SphereData};
use raykernel::render::{
    memory_needed, Camera, Filter, Light, Material, Object, ObjectSlot, RenderMemory, Renderer,
    SamplerKind, Settings, Shape,
};
use raykernel::spawn::SpawnScalar;
use raykernel::{AccelMemory, Bvh4Family, Node, Node4, Sphere, Triangle, I16F16};
use raykernel_c::*;
use std::path::Path;

// The test scene: `examples/common/render_scene.h` is the same scene in C.
const TRIANGLES: [[[f32; 3]; 3]; 5] = [
    // Floor (y = 0).
    [[-2.0, 0.0, -2.0], [2.0, 0.0, 2.0], [2.0, 0.0, -2.0]],
    [[-2.0, 0.0, -2.0], [-2.0, 0.0, 2.0], [2.0, 0.0, 2.0]],
    // Back wall (z = -2).
    [[-2.0, 0.0, -2.0], [2.0, 0.0, -2.0], [2.0, 2.0, -2.0]],
    [[-2.0, 0.0, -2.0], [2.0, 2.0, -2.0], [-2.0, 2.0, -2.0]],
    // A glowing triangle in front of the wall.
    [[1.0, 0.9, -1.5], [1.7, 0.9, -1.5], [1.35, 1.5, -1.5]],
];
const SPHERES: [SphereData; 3] = [
    SphereData {
        center: [-0.6, 0.5, 0.0],
        radius: 0.5,
    },
    SphereData {
        center: [0.7, 0.35, 0.4],
        radius: 0.35,
    },
    SphereData {
        center: [0.15, 0.15, 1.1],
        radius: 0.15,
    },
];
const OBJECTS: [ObjectData; 5] = [
    ObjectData {
        shape: ShapeRange::Triangles { first: 0, count: 2 },
        material: 0,
        motion: [0.0; 3],
    },
    ObjectData {
        shape: ShapeRange::Triangles { first: 2, count: 2 },
        material: 1,
        motion: [0.0; 3],
    },
    ObjectData {
        shape: ShapeRange::Spheres { first: 0, count: 1 },
        material: 2,
        motion: [0.25, 0.0, 0.0],
    },
    ObjectData {
        shape: ShapeRange::Spheres { first: 1, count: 2 },
        material: 4,
        motion: [0.0; 3],
    },
    ObjectData {
        shape: ShapeRange::Triangles { first: 4, count: 1 },
        material: 3,
        motion: [0.0; 3],
    },
];
const MATERIALS: [Material; 5] = [
    Material::Diffuse {
        albedo: [0.7, 0.7, 0.7],
    },
    Material::Glossy {
        reflectance: [0.8, 0.6, 0.4],
        exponent: 40.0,
    },
    Material::Mirror {
        reflectance: [0.9, 0.9, 0.9],
    },
    Material::Emissive {
        radiance: [2.0, 1.5, 1.0],
    },
    Material::Diffuse {
        albedo: [0.2, 0.5, 0.8],
    },
];
const LIGHTS: [Light; 2] = [
    Light::Rect {
        corner: [-0.5, 2.5, -0.5],
        edge_u: [1.0, 0.0, 0.0],
        edge_v: [0.0, 0.0, 1.0],
        radiance: [10.0, 10.0, 10.0],
    },
    Light::Point {
        position: [2.0, 2.0, 2.0],
        intensity: [1.5, 1.5, 1.5],
    },
];

fn test_scene() -> SceneData<'static> {
    SceneData {
        name: "capi",
        triangles: &TRIANGLES,
        spheres: &SPHERES,
        objects: &OBJECTS,
        materials: &MATERIALS,
        lights: &LIGHTS,
        camera: Camera {
            eye: [0.0, 1.2, 4.5],
            look_at: [0.0, 0.6, 0.0],
            up: [0.0, 1.0, 0.0],
            vfov_deg: 45.0,
            aperture_radius: 0.02,
            focus_distance: 4.5,
        },
        background: [0.05, 0.06, 0.08],
        settings: Settings {
            width: 24,
            height: 16,
            spp: 4,
            max_depth: 3,
            sampler: SamplerKind::Stratified,
            filter: Filter::Tent,
            seed: 7,
        },
    }
}

/// The tile the firmware renders (also in the golden header).
const TILE: [u32; 4] = [8, 4, 8, 8];

fn fnv1a(bytes: &[u8]) -> u32 {
    bytes.iter().fold(0x811c_9dc5, |h, b| {
        (h ^ u32::from(*b)).wrapping_mul(0x0100_0193)
    })
}

/// The kernel's render of `data` (4-wide BVHs), whole image, sRGB.
fn kernel_render<S: SpawnScalar>(data: &SceneData<'_>) -> Vec<u8> {
    let zero = [S::ZERO; 3];
    let mut tris = vec![Triangle { v: [zero; 3] }; data.triangles.len()];
    let sphere = Sphere {
        center: zero,
        radius: S::ZERO,
    };
    let mut spheres = vec![sphere; data.spheres.len()];
    data.triangles_into(&mut tris).unwrap();
    data.spheres_into(&mut spheres).unwrap();
    let mut objects = vec![Object::new(Shape::Triangles(&[]), 0); data.objects.len()];
    let scene = data.scene(&tris, &spheres, &mut objects).unwrap();
    let options = BuildOptions::default();
    let need = memory_needed::<S, Bvh4Family>(scene.objects, &options);
    let mut slots = vec![ObjectSlot::<S, Bvh4Family>::EMPTY; need.objects];
    let mut nodes = vec![Node::EMPTY; need.accel.nodes];
    let mut nodes4 = vec![Node4::EMPTY; need.accel.nodes4];
    let mut words = vec![0u32; need.accel.words];
    let memory = RenderMemory {
        objects: &mut slots,
        accel: AccelMemory {
            nodes: &mut nodes,
            nodes4: &mut nodes4,
            kd_nodes: &mut [],
            words: &mut words,
        },
    };
    let r = Renderer::new(&scene, data.settings, options, memory).unwrap();
    let s = data.settings;
    let mut out = vec![0u8; 3 * (s.width * s.height) as usize];
    r.render_srgb8(&mut out).unwrap();
    out
}

/// `data` as C structs, each kernel value mapped field by field.
struct CScene {
    objects: Vec<RkObject>,
    floats: Vec<Vec<f32>>,
    materials: Vec<RkMaterial>,
    lights: Vec<RkLight>,
    scene: RkScene,
}

impl CScene {
    fn new(data: &SceneData<'_>, mode: u32, kind: u32) -> Self {
        let floats: Vec<Vec<f32>> = data
            .objects
            .iter()
            .map(|o| match o.shape {
                ShapeRange::Triangles { first, count } => data.triangles
                    [first as usize..(first + count) as usize]
                    .iter()
                    .flat_map(|t| t.iter().flatten().copied())
                    .collect(),
                ShapeRange::Spheres { first, count } => data.spheres
                    [first as usize..(first + count) as usize]
                    .iter()
                    .flat_map(|s| [s.center[0], s.center[1], s.center[2], s.radius])
                    .collect(),
            })
            .collect();
        let objects = data
            .objects
            .iter()
            .zip(&floats)
            .map(|(o, f)| {
                let (shape, count) = match o.shape {
                    ShapeRange::Triangles { count, .. } => (RK_SHAPE_TRIANGLES, count),
                    ShapeRange::Spheres { count, .. } => (RK_SHAPE_SPHERES, count),
                };
                RkObject {
                    shape,
                    material: o.material,
                    count,
                    data: f.as_ptr(),
                    motion: o.motion,
                }
            })
            .collect();
        let materials = data.materials.iter().map(c_material).collect();
        let lights = data.lights.iter().map(c_light).collect();
        let c = data.camera;
        let s = data.settings;
        let mut settings = rk_render_settings_default();
        settings.width = s.width;
        settings.height = s.height;
        settings.spp = s.spp;
        settings.max_depth = s.max_depth;
        settings.sampler = match s.sampler {
            SamplerKind::Independent => RK_SAMPLER_INDEPENDENT,
            SamplerKind::Stratified => RK_SAMPLER_STRATIFIED,
            SamplerKind::Sobol => RK_SAMPLER_SOBOL,
        };
        settings.filter = match s.filter {
            Filter::Box => RK_FILTER_BOX,
            Filter::Tent => RK_FILTER_TENT,
        };
        settings.seed = s.seed;
        let mut out = Self {
            objects,
            floats,
            materials,
            lights,
            scene: RkScene {
                mode,
                kind,
                objects: std::ptr::null(),
                object_count: 0,
                materials: std::ptr::null(),
                material_count: 0,
                lights: std::ptr::null(),
                light_count: 0,
                camera: RkCamera {
                    eye: c.eye,
                    look_at: c.look_at,
                    up: c.up,
                    vfov_deg: c.vfov_deg,
                    aperture_radius: c.aperture_radius,
                    focus_distance: c.focus_distance,
                },
                background: data.background,
                settings,
            },
        };
        out.point();
        out
    }

    /// Points the scene at the (possibly edited) arrays.
    fn point(&mut self) -> &RkScene {
        for (o, f) in self.objects.iter_mut().zip(&self.floats) {
            o.data = f.as_ptr();
        }
        self.scene.objects = self.objects.as_ptr();
        self.scene.object_count = self.objects.len() as u32;
        self.scene.materials = self.materials.as_ptr();
        self.scene.material_count = self.materials.len() as u32;
        self.scene.lights = self.lights.as_ptr();
        self.scene.light_count = self.lights.len() as u32;
        &self.scene
    }
}

fn c_material(m: &Material) -> RkMaterial {
    let (kind, color, exponent) = match *m {
        Material::Diffuse { albedo } => (RK_MATERIAL_DIFFUSE, albedo, 0.0),
        Material::Mirror { reflectance } => (RK_MATERIAL_MIRROR, reflectance, 0.0),
        Material::Glossy {
            reflectance,
            exponent,
        } => (RK_MATERIAL_GLOSSY, reflectance, exponent),
        Material::Emissive { radiance } => (RK_MATERIAL_EMISSIVE, radiance, 0.0),
    };
    RkMaterial {
        kind,
        color,
        exponent,
    }
}

fn c_light(l: &Light) -> RkLight {
    let none = RkLight {
        kind: 0,
        position: [0.0; 3],
        edge_u: [0.0; 3],
        edge_v: [0.0; 3],
        radius: 0.0,
        color: [0.0; 3],
    };
    match *l {
        Light::Point {
            position,
            intensity,
        } => RkLight {
            kind: RK_LIGHT_POINT,
            position,
            color: intensity,
            ..none
        },
        Light::Rect {
            corner,
            edge_u,
            edge_v,
            radiance,
        } => RkLight {
            kind: RK_LIGHT_RECT,
            position: corner,
            edge_u,
            edge_v,
            color: radiance,
            ..none
        },
        Light::Sphere {
            center,
            radius,
            radiance,
        } => RkLight {
            kind: RK_LIGHT_SPHERE,
            position: center,
            radius,
            color: radiance,
            ..none
        },
    }
}

/// Caller memory of `bytes` bytes starting `offset` bytes past a 128-byte boundary.
struct Memory {
    buf: Vec<u8>,
    offset: usize,
}

impl Memory {
    fn new(bytes: usize, offset: usize) -> Self {
        let buf = vec![0xa5u8; bytes + 256];
        let skip = buf.as_ptr().align_offset(128);
        Self {
            buf,
            offset: skip + offset,
        }
    }
    fn ptr(&mut self) -> *mut c_void {
        self.buf[self.offset..].as_mut_ptr().cast()
    }
}

fn no_error() -> RkSceneError {
    RkSceneError {
        item: u32::MAX,
        index: u32::MAX,
        field: [0; RK_FIELD_LEN],
        min: 0.0,
        max: 0.0,
    }
}

fn field(e: &RkSceneError) -> String {
    let bytes: Vec<u8> = e
        .field
        .iter()
        .take_while(|c| **c != 0)
        .map(|c| *c as u8)
        .collect();
    String::from_utf8(bytes).unwrap()
}

fn init(
    scene: &RkScene,
    memory: &mut Memory,
    bytes: usize,
) -> Result<RkRenderer, (RkStatus, RkSceneError)> {
    let mut r = RkRenderer {
        opaque: [7; RK_RENDERER_WORDS],
    };
    let mut e = no_error();
    // SAFETY: every pointer is valid for the access the contract names.
    let s = unsafe { rk_renderer_init(scene, memory.ptr(), bytes, &mut r, &mut e) };
    if s == RkStatus::Ok {
        Ok(r)
    } else {
        // A failed init leaves `out` uninitialised.
        let mut px = [0u8; 3];
        // SAFETY: as above.
        let t = unsafe { rk_render_tile(&r, 0, 0, 1, 1, px.as_mut_ptr(), 3) };
        assert_eq!(t, RkStatus::ErrNotInitialised);
        Err((s, e))
    }
}

/// The whole image through the C interface, in tiles of `tw × th` (edge tiles smaller).
fn c_render(scene: &RkScene, tw: u32, th: u32) -> Vec<u8> {
    // SAFETY: the scene and its arrays are valid.
    let bytes = unsafe { rk_render_bytes(scene) };
    assert!(bytes > 0);
    let mut memory = Memory::new(bytes, 3);
    let r = init(scene, &mut memory, bytes).unwrap_or_else(|(s, e)| {
        panic!(
            "init: {s:?} item {} index {} field {}",
            e.item,
            e.index,
            field(&e)
        )
    });
    let (w, h) = (scene.settings.width, scene.settings.height);
    let mut image = vec![0u8; 3 * (w * h) as usize];
    for y0 in (0..h).step_by(th as usize) {
        for x0 in (0..w).step_by(tw as usize) {
            let (cw, ch) = (tw.min(w - x0), th.min(h - y0));
            let mut tile = vec![0u8; 3 * (cw * ch) as usize];
            // SAFETY: `r` came from init, its memory is alive; `tile` holds `tile.len()` bytes.
            let s = unsafe { rk_render_tile(&r, x0, y0, cw, ch, tile.as_mut_ptr(), tile.len()) };
            assert_eq!(s, RkStatus::Ok);
            for row in 0..ch {
                let at = 3 * ((y0 + row) * w + x0) as usize;
                let from = 3 * (row * cw) as usize;
                image[at..at + 3 * cw as usize]
                    .copy_from_slice(&tile[from..from + 3 * cw as usize]);
            }
        }
    }
    image
}

#[test]
fn c_render_equals_the_kernel_renderer_in_both_modes_and_kinds() {
    let data = test_scene();
    for mode in [RK_MODE_F32, RK_MODE_FIXED] {
        let want = if mode == RK_MODE_F32 {
            kernel_render::<f32>(&data)
        } else {
            kernel_render::<I16F16>(&data)
        };
        assert!(
            want.chunks(3).any(|p| p != want[..3].as_ref()),
            "the reference image is uniform: the scene is not in view"
        );
        for kind in [0, RK_KIND_BVH, RK_KIND_BVH4] {
            let mut c = CScene::new(&data, mode, kind);
            let scene = *c.point();
            let whole = c_render(&scene, data.settings.width, data.settings.height);
            assert!(
                whole == want,
                "mode {mode} kind {kind}: one tile differs from the kernel"
            );
            for (tw, th) in [(5, 3), (8, 8), (1, 16), (24, 1)] {
                let tiled = c_render(&scene, tw, th);
                assert!(
                    tiled == want,
                    "mode {mode} kind {kind}: {tw}x{th} tiles differ"
                );
            }
        }
    }
}

/// The golden header the C test and the firmware check against.
fn golden_header() -> String {
    let data = test_scene();
    let s = data.settings;
    let [tx, ty, tw, th] = TILE;
    let tile_of = |image: &[u8]| -> Vec<u8> {
        (ty..ty + th)
            .flat_map(|y| {
                let at = 3 * (y * s.width + tx) as usize;
                image[at..at + 3 * tw as usize].to_vec()
            })
            .collect()
    };
    let f32_image = kernel_render::<f32>(&data);
    let fixed_image = kernel_render::<I16F16>(&data);
    format!(
        "/* Generated by capi/tests/render.rs from the kernel's renderer: do not edit\n \
         * (BLESS=1 cargo test -p raykernel-c --test render rewrites it). FNV-1a (32-bit) of the\n \
         * 8-bit sRGB bytes of render_scene.h's scene ({w} x {h}, {spp} spp): the whole image, and\n \
         * the tile of RK_TEST_TILE_W x RK_TEST_TILE_H pixels at (RK_TEST_TILE_X, RK_TEST_TILE_Y). */\n\
         #ifndef RAYKERNEL_RENDER_GOLDEN_H\n\
         #define RAYKERNEL_RENDER_GOLDEN_H\n\
         \n\
         #define RK_TEST_TILE_X {tx}u\n\
         #define RK_TEST_TILE_Y {ty}u\n\
         #define RK_TEST_TILE_W {tw}u\n\
         #define RK_TEST_TILE_H {th}u\n\
         #define RK_TEST_IMAGE_HASH_F32 0x{:08x}u\n\
         #define RK_TEST_IMAGE_HASH_FIXED 0x{:08x}u\n\
         #define RK_TEST_TILE_HASH_F32 0x{:08x}u\n\
         #define RK_TEST_TILE_HASH_FIXED 0x{:08x}u\n\
         \n\
         #endif\n",
        fnv1a(&f32_image),
        fnv1a(&fixed_image),
        fnv1a(&tile_of(&f32_image)),
        fnv1a(&tile_of(&fixed_image)),
        w = s.width,
        h = s.height,
        spp = s.spp,
    )
}

#[test]
fn golden_header_matches_the_kernel() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/common/render_golden.h");
    let generated = golden_header();
    if std::env::var_os("BLESS").is_some() {
        std::fs::write(&path, &generated).expect("golden header written");
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == generated,
        "{} differs from the kernel's renders; run BLESS=1 cargo test -p raykernel-c --test render",
        path.display()
    );
}

#[test]
fn render_bytes_are_exact_at_every_alignment() {
    let data = test_scene();
    for mode in [RK_MODE_F32, RK_MODE_FIXED] {
        for kind in [RK_KIND_BVH, RK_KIND_BVH4] {
            let mut c = CScene::new(&data, mode, kind);
            let scene = *c.point();
            // SAFETY: the scene and its arrays are valid.
            let bytes = unsafe { rk_render_bytes(&scene) };
            for offset in 0..128 {
                let mut memory = Memory::new(bytes, offset);
                assert!(init(&scene, &mut memory, bytes).is_ok(), "offset {offset}");
            }
            // From an aligned start, the 127 bytes of slack are not needed, one byte more is.
            let mut memory = Memory::new(bytes, 0);
            assert!(init(&scene, &mut memory, bytes - 127).is_ok());
            let (s, e) = init(&scene, &mut memory, bytes - 128).unwrap_err();
            assert_eq!(
                (s, e.item, field(&e).as_str()),
                (RkStatus::ErrMemoryTooSmall, RK_ITEM_SCENE, "memory")
            );
        }
    }
}

/// Initialises `c` after `edit` and returns the status and error.
fn rejected(mode: u32, edit: impl FnOnce(&mut CScene)) -> (RkStatus, RkSceneError) {
    let mut c = CScene::new(&test_scene(), mode, 0);
    edit(&mut c);
    let scene = *c.point();
    let bytes = 1 << 20;
    let mut memory = Memory::new(bytes, 0);
    init(&scene, &mut memory, bytes).expect_err("the edited scene is rejected")
}

fn expect(
    mode: u32,
    edit: impl FnOnce(&mut CScene),
    status: RkStatus,
    item: u32,
    index: u32,
    name: &str,
) {
    let (s, e) = rejected(mode, edit);
    assert_eq!(
        (s, e.item, e.index, field(&e).as_str()),
        (status, item, index, name),
        "mode {mode}"
    );
    // SAFETY: returns a static string.
    let text = unsafe { std::ffi::CStr::from_ptr(rk_status_name(s as i32)) };
    assert_ne!(text.to_str().unwrap(), "unknown status");
}

#[test]
fn bad_scenes_give_typed_errors_naming_the_value() {
    use RkStatus::*;
    for mode in [RK_MODE_F32, RK_MODE_FIXED] {
        let obj = |i: usize, f: fn(&mut RkObject)| move |c: &mut CScene| f(&mut c.objects[i]);
        expect(
            mode,
            obj(1, |o| o.material = 5),
            ErrBadIndex,
            RK_ITEM_OBJECT,
            1,
            "material",
        );
        expect(
            mode,
            obj(3, |o| o.shape = 9),
            ErrBadArgument,
            RK_ITEM_OBJECT,
            3,
            "shape",
        );
        expect(
            mode,
            obj(2, |o| o.motion[1] = f32::NAN),
            ErrNonFinite,
            RK_ITEM_OBJECT,
            2,
            "motion",
        );
        expect(
            mode,
            |c| c.floats[1][4] = f32::INFINITY,
            ErrBadTriangle,
            RK_ITEM_OBJECT,
            1,
            "data",
        );
        expect(
            mode,
            |c| c.floats[3][7] = -1.0,
            ErrBadSphere,
            RK_ITEM_OBJECT,
            3,
            "data",
        );
        expect(
            mode,
            |c| c.floats[2][0] = f32::NAN,
            ErrBadSphere,
            RK_ITEM_OBJECT,
            2,
            "data",
        );
        let mat = |i: usize, f: fn(&mut RkMaterial)| move |c: &mut CScene| f(&mut c.materials[i]);
        expect(
            mode,
            mat(4, |m| m.color[2] = 1.5),
            ErrAboveOne,
            RK_ITEM_MATERIAL,
            4,
            "color",
        );
        expect(
            mode,
            mat(3, |m| m.color[0] = -1.0),
            ErrNegative,
            RK_ITEM_MATERIAL,
            3,
            "color",
        );
        expect(
            mode,
            mat(0, |m| m.color[1] = f32::NAN),
            ErrNonFinite,
            RK_ITEM_MATERIAL,
            0,
            "color",
        );
        expect(
            mode,
            mat(1, |m| m.exponent = 0.5),
            ErrOutOfRange,
            RK_ITEM_MATERIAL,
            1,
            "exponent",
        );
        expect(
            mode,
            mat(2, |m| m.kind = 0),
            ErrBadArgument,
            RK_ITEM_MATERIAL,
            2,
            "kind",
        );
        let light = |i: usize, f: fn(&mut RkLight)| move |c: &mut CScene| f(&mut c.lights[i]);
        expect(
            mode,
            light(0, |l| l.edge_v = l.edge_u),
            ErrZeroArea,
            RK_ITEM_LIGHT,
            0,
            "edge_v",
        );
        expect(
            mode,
            light(1, |l| l.color[0] = -2.0),
            ErrNegative,
            RK_ITEM_LIGHT,
            1,
            "color",
        );
        expect(
            mode,
            light(1, |l| l.position[2] = f32::NAN),
            ErrNonFinite,
            RK_ITEM_LIGHT,
            1,
            "position",
        );
        expect(
            mode,
            light(1, |l| l.kind = 4),
            ErrBadArgument,
            RK_ITEM_LIGHT,
            1,
            "kind",
        );
        let nine = |c: &mut CScene| c.lights = vec![c.lights[1]; 9];
        expect(mode, nine, ErrTooMany, RK_ITEM_SCENE, 0, "light_count");
        expect(
            mode,
            |c| c.scene.camera.up = [0.0, -0.6, -4.5],
            ErrDegenerate,
            RK_ITEM_CAMERA,
            0,
            "up",
        );
        let (s, e) = rejected(mode, |c| c.scene.camera.vfov_deg = 200.0);
        assert_eq!(
            (s, e.item, field(&e).as_str()),
            (ErrOutOfRange, RK_ITEM_CAMERA, "vfov_deg")
        );
        assert!(
            e.min < e.max && e.max <= 180.0,
            "range [{}, {}]",
            e.min,
            e.max
        );
        expect(
            mode,
            |c| c.scene.background[0] = f32::INFINITY,
            ErrNonFinite,
            RK_ITEM_SCENE,
            0,
            "background",
        );
        expect(
            mode,
            |c| c.scene.settings.width = 0,
            ErrNotPositive,
            RK_ITEM_SETTINGS,
            0,
            "width",
        );
        expect(
            mode,
            |c| c.scene.settings.spp = 0,
            ErrNotPositive,
            RK_ITEM_SETTINGS,
            0,
            "spp",
        );
        expect(
            mode,
            |c| c.scene.settings.sampler = 0,
            ErrBadArgument,
            RK_ITEM_SETTINGS,
            0,
            "sampler",
        );
        expect(
            mode,
            |c| c.scene.settings.filter = 3,
            ErrBadArgument,
            RK_ITEM_SETTINGS,
            0,
            "filter",
        );
        expect(
            mode,
            |c| c.scene.kind = 3,
            ErrBadArgument,
            RK_ITEM_SCENE,
            0,
            "kind",
        );
    }
    // A vertex beyond the fixed-point range: fine in f32, refused in fixed point.
    let far = |c: &mut CScene| c.floats[0][0] = 9000.0;
    expect(
        RK_MODE_FIXED,
        far,
        RkStatus::ErrBadTriangle,
        RK_ITEM_OBJECT,
        0,
        "data",
    );
    expect(
        7,
        |_| {},
        RkStatus::ErrBadArgument,
        RK_ITEM_SCENE,
        0,
        "mode",
    );
}

#[test]
fn null_pointers_and_small_memory_are_refused() {
    use RkStatus::*;
    let data = test_scene();
    let mut c = CScene::new(&data, RK_MODE_F32, 0);
    let scene = *c.point();
    // SAFETY (every call): pointers are null or valid.
    let bytes = unsafe { rk_render_bytes(&scene) };
    assert_eq!(unsafe { rk_render_bytes(std::ptr::null()) }, 0);
    let mut memory = Memory::new(bytes, 0);
    let mut r = RkRenderer {
        opaque: [0; RK_RENDERER_WORDS],
    };
    let null = std::ptr::null_mut::<RkSceneError>();
    assert_eq!(
        unsafe { rk_renderer_init(&scene, memory.ptr(), bytes, std::ptr::null_mut(), null) },
        ErrNull
    );
    assert_eq!(
        unsafe { rk_renderer_init(std::ptr::null(), memory.ptr(), bytes, &mut r, null) },
        ErrNull
    );
    assert_eq!(
        unsafe { rk_renderer_init(&scene, std::ptr::null_mut(), bytes, &mut r, null) },
        ErrNull
    );
    assert_eq!(
        unsafe { rk_renderer_init(&scene, memory.ptr(), 0, &mut r, null) },
        ErrMemoryTooSmall
    );
    let mut no_objects = scene;
    no_objects.objects = std::ptr::null();
    assert_eq!(unsafe { rk_render_bytes(&no_objects) }, 0);
    let (s, e) = init(&no_objects, &mut memory, bytes).unwrap_err();
    assert_eq!(
        (s, e.item, field(&e).as_str()),
        (ErrNull, RK_ITEM_SCENE, "objects")
    );
    let mut misaligned = scene;
    misaligned.materials = unsafe { scene.materials.cast::<u8>().add(1).cast() };
    let (s, _) = init(&misaligned, &mut memory, bytes).unwrap_err();
    assert_eq!(s, ErrMisaligned);
    let mut no_data = CScene::new(&data, RK_MODE_F32, 0);
    no_data.point();
    no_data.objects[4].data = std::ptr::null();
    let (s, e) = init(&no_data.scene, &mut memory, bytes).unwrap_err();
    assert_eq!(
        (s, e.item, e.index, field(&e).as_str()),
        (ErrNull, RK_ITEM_OBJECT, 4, "data")
    );
    // An empty scene renders the background.
    let mut empty = scene;
    empty.object_count = 0;
    empty.light_count = 0;
    let bytes = unsafe { rk_render_bytes(&empty) };
    let mut memory = Memory::new(bytes, 0);
    let r = init(&empty, &mut memory, bytes).unwrap();
    let mut px = [0u8; 3];
    assert_eq!(
        unsafe { rk_render_tile(&r, 3, 2, 1, 1, px.as_mut_ptr(), 3) },
        Ok
    );
    assert_eq!(
        px,
        [0.05f32, 0.06, 0.08].map(raykernel::render::encode_srgb8)
    );
}

#[test]
fn bad_tiles_and_buffers_are_refused() {
    use RkStatus::*;
    let data = test_scene();
    let mut c = CScene::new(&data, RK_MODE_FIXED, RK_KIND_BVH);
    let scene = *c.point();
    // SAFETY (every call): pointers are null or valid; `out` holds `out.len()` bytes.
    let bytes = unsafe { rk_render_bytes(&scene) };
    let mut memory = Memory::new(bytes, 0);
    let r = init(&scene, &mut memory, bytes).unwrap();
    let mut out = vec![0u8; 3 * 64];
    let p = out.as_mut_ptr();
    let (w, h) = (data.settings.width, data.settings.height);
    assert_eq!(unsafe { rk_render_tile(&r, 0, 0, 8, 8, p, 3 * 64) }, Ok);
    assert_eq!(
        unsafe { rk_render_tile(&r, 0, 0, 8, 8, p, 3 * 64 - 1) },
        ErrBufferTooSmall
    );
    assert_eq!(
        unsafe { rk_render_tile(&r, w - 4, 0, 5, 1, p, 3 * 64) },
        ErrBadTile
    );
    assert_eq!(
        unsafe { rk_render_tile(&r, 0, h, 1, 1, p, 3 * 64) },
        ErrBadTile
    );
    assert_eq!(
        unsafe { rk_render_tile(&r, u32::MAX, 0, 2, 1, p, 3 * 64) },
        ErrBadTile
    );
    assert_eq!(
        unsafe { rk_render_tile(&r, 0, 0, 1, 1, std::ptr::null_mut(), 3) },
        ErrNull
    );
    assert_eq!(
        unsafe { rk_render_tile(std::ptr::null(), 0, 0, 1, 1, p, 3) },
        ErrNull
    );
    let zero = RkRenderer {
        opaque: [0; RK_RENDERER_WORDS],
    };
    assert_eq!(
        unsafe { rk_render_tile(&zero, 0, 0, 1, 1, p, 3) },
        ErrNotInitialised
    );
    // A zero-sized tile writes nothing and succeeds.
    assert_eq!(unsafe { rk_render_tile(&r, 3, 3, 0, 0, p, 0) }, Ok);
}

#[test]
fn every_status_has_its_own_name() {
    // SAFETY: returns static strings.
    let name = |s: i32| {
        unsafe { std::ffi::CStr::from_ptr(rk_status_name(s)) }
            .to_str()
            .unwrap()
    };
    let last = RkStatus::ErrBufferTooSmall as i32;
    let names: Vec<&str> = (0..=last).map(name).collect();
    for (i, n) in names.iter().enumerate() {
        assert_ne!(*n, "unknown status", "status {i}");
        assert!(!names[..i].contains(n), "status {i} shares its name");
    }
    assert_eq!(name(last + 1), "unknown status");
}

/// A small deterministic generator (xorshift64*).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
    /// A value that breaks something often: non-finite, huge, zero, negative, out of range.
    fn float(&mut self) -> f32 {
        const SPECIAL: [f32; 10] = [
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            0.0,
            -1.0,
            1.5,
            9000.0,
            -3e38,
            1e-40,
            180.0,
        ];
        if self.below(2) == 0 {
            SPECIAL[self.below(SPECIAL.len() as u64) as usize]
        } else {
            (self.below(2001) as f32 - 1000.0) / 100.0
        }
    }
}

/// Sets one random field of `c` to a random value (floats anywhere, tags, indices, settings).
fn mutate(c: &mut CScene, rng: &mut Rng) {
    let small = |rng: &mut Rng| rng.below(6) as u32;
    match rng.below(9) {
        0 => {
            let o = rng.below(c.floats.len() as u64) as usize;
            let f = &mut c.floats[o];
            let i = rng.below(f.len() as u64) as usize;
            f[i] = rng.float();
        }
        1 => {
            let o = &mut c.objects[rng.below(5) as usize];
            match rng.below(3) {
                0 => o.material = small(rng),
                1 => o.shape = small(rng),
                _ => o.motion[rng.below(3) as usize] = rng.float(),
            }
        }
        2 => {
            let m = &mut c.materials[rng.below(5) as usize];
            match rng.below(3) {
                0 => m.kind = small(rng),
                1 => m.exponent = rng.float(),
                _ => m.color[rng.below(3) as usize] = rng.float(),
            }
        }
        3 => {
            let n = c.lights.len() as u64;
            let l = &mut c.lights[rng.below(n) as usize];
            let k = rng.below(3) as usize;
            match rng.below(6) {
                0 => l.kind = small(rng),
                1 => l.position[k] = rng.float(),
                2 => l.edge_u[k] = rng.float(),
                3 => l.edge_v[k] = rng.float(),
                4 => l.radius = rng.float(),
                _ => l.color[k] = rng.float(),
            }
        }
        4 => {
            let cam = &mut c.scene.camera;
            let k = rng.below(3) as usize;
            match rng.below(6) {
                0 => cam.eye[k] = rng.float(),
                1 => cam.look_at[k] = rng.float(),
                2 => cam.up[k] = rng.float(),
                3 => cam.vfov_deg = rng.float(),
                4 => cam.aperture_radius = rng.float(),
                _ => cam.focus_distance = rng.float(),
            }
        }
        5 => c.scene.background[rng.below(3) as usize] = rng.float(),
        6 => {
            let s = &mut c.scene.settings;
            match rng.below(7) {
                0 => s.width = rng.below(40) as u32,
                1 => s.height = rng.below(40) as u32,
                2 => s.spp = rng.below(5) as u32,
                3 => s.max_depth = rng.below(8) as u32,
                4 => s.sampler = small(rng),
                5 => s.filter = small(rng),
                _ => s.seed = rng.next() as u32,
            }
        }
        7 => {
            // Drop or repeat lights (up to past the limit).
            let n = rng.below(10) as usize;
            c.lights = (0..n)
                .map(|i| c.lights[i % c.lights.len().max(1)])
                .collect();
            if c.lights.is_empty() {
                c.lights = vec![c_light(&LIGHTS[0])];
            }
        }
        _ => c.scene.kind = small(rng),
    }
}

#[test]
fn random_bad_values_give_a_status_never_a_panic() {
    // Any panic inside the C functions aborts this test process: reaching the end is the check.
    let data = test_scene();
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let (mut accepted, mut refused) = (0, 0);
    for round in 0..6000 {
        let mode = if round % 2 == 0 {
            RK_MODE_F32
        } else {
            RK_MODE_FIXED
        };
        let mut c = CScene::new(&data, mode, 0);
        for _ in 0..1 + rng.below(3) {
            mutate(&mut c, &mut rng);
        }
        let scene = *c.point();
        // SAFETY: the scene's arrays are valid for their counts.
        let bytes = unsafe { rk_render_bytes(&scene) };
        let mut memory = Memory::new(bytes.max(1), 0);
        match init(&scene, &mut memory, bytes) {
            Ok(r) => {
                accepted += 1;
                let (w, h) = (scene.settings.width.min(4), scene.settings.height.min(4));
                let mut px = vec![0u8; 3 * (w * h) as usize];
                // SAFETY: `r` is initialised, its memory alive; `px` holds `px.len()` bytes.
                let s = unsafe { rk_render_tile(&r, 0, 0, w, h, px.as_mut_ptr(), px.len()) };
                assert_eq!(s, RkStatus::Ok, "round {round}");
            }
            Err((s, _)) => {
                refused += 1;
                assert_ne!(s, RkStatus::Ok);
            }
        }
    }
    println!("accepted {accepted}, refused {refused}");
    // Both outcomes occur, so the mutations reach the checks and the renders.
    assert!(
        accepted > 100 && refused > 100,
        "accepted {accepted}, refused {refused}"
    );
}
