//! Bad input to the C renderer: every typed status with the value it names, null pointers,
//! small memory, bad tiles and buffers, and random bad values anywhere in the scene (a status,
//! never a panic).

#![cfg(all(
    feature = "render-f32",
    feature = "render-fixed",
    feature = "render-bvh",
    feature = "render-bvh4"
))] // renders in every mode and kind

mod common;

use common::*;
use raykernel_c::*;

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
