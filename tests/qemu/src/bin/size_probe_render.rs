//! Size probe of the renderer: the default built-in scene (`f32`, the BVH family: one SAH BVH
//! per object, no other structure, split rule or pass linked; the renderer's parts the scene
//! uses, named at compile time) converted into caller buffers, `Renderer::with_features`, and
//! one row rendered to sRGB bytes; nothing else (no defmt, a spinning panic handler).
//! `cargo xtask size` reports its `.text`/`.rodata`/`.bss` next to the build + traverse probe
//! (`size_probe.rs`) and runs it under QEMU to measure its stack: the only measuring code is
//! the store to [`PROBE_DONE`]. The scene's buffers are statics (in
//! `.bss`, as firmware keeps them), so the stack measured is the renderer's own.
#![no_std]
#![no_main]

use core::hint::black_box;
use core::sync::atomic::{AtomicU32, Ordering};
use cortex_m_rt::entry;
use raykernel::bvh::{nodes_needed, Sah, StaticBuild};
use raykernel::render::scenes::{self, SceneData};
use raykernel::render::{
    Object, ObjectSlot, RenderFeatures, RenderMemory, Renderer, Shape, Tile,
};
use raykernel::{AccelMemory, BvhFamily, Node, Sphere, Triangle};

const TRIS: usize = 24;
const SPHERES: usize = 4;
const OBJECTS: usize = 8;
const WIDTH: usize = 64;
/// Every object's BVH, then the top-level BVH over the objects.
const NODES: usize = nodes_needed(TRIS) + nodes_needed(SPHERES) + 4 * OBJECTS;
const WORDS: usize = TRIS + SPHERES + OBJECTS;

const NO_TRIANGLE: Triangle<f32> = Triangle { v: [[0.0; 3]; 3] };
const NO_SPHERE: Sphere<f32> = Sphere {
    center: [0.0; 3],
    radius: 0.0,
};
const NO_OBJECT: Object<'static, f32> = Object::new(Shape::Triangles(&[]), 0);
/// SAH BVHs without the reinsertion pass, named at compile time: no other split rule or pass
/// is linked.
type Family = BvhFamily<StaticBuild<Sah, false>>;
type Slot = ObjectSlot<'static, f32, Family>;

/// The parts of the renderer the default scene uses: a rectangle light, two-sided surfaces
/// that do not emit, flat shading, the box filter, several samples per pixel.
#[derive(Clone, Copy, Debug)]
struct SceneFeatures;

impl RenderFeatures for SceneFeatures {
    const FILTERS: bool = false;
    const POINT_LIGHTS: bool = false;
    const SPHERE_LIGHTS: bool = false;
    const EMISSIVE_GEOMETRY: bool = false;
    const ONE_SIDED: bool = false;
    const SMOOTH_SHADING: bool = false;
    const FIRST_HIT_LOOP: bool = false;
}

/// Set to `DONE` when the row has been rendered; `cargo xtask size` polls it (in .bss).
#[no_mangle]
static PROBE_DONE: AtomicU32 = AtomicU32::new(0);
/// "DONE", as `xtask/src/size.rs` expects.
const DONE: u32 = 0x444f_4e45;

/// The scene's buffers, in statics.
struct Buffers {
    tris: &'static mut [Triangle<f32>; TRIS],
    spheres: &'static mut [Sphere<f32>; SPHERES],
    objects: &'static mut [Object<'static, f32>; OBJECTS],
    slots: &'static mut [Slot; OBJECTS],
    nodes: &'static mut [Node<f32>; NODES],
    ids: &'static mut [u32; WORDS],
}

/// Takes the statics, once. Not inlined: their initial values pass through this function's
/// frame, which is gone before the renderer runs, as in firmware that sets them up at boot.
#[inline(never)]
fn buffers() -> Option<Buffers> {
    Some(Buffers {
        tris: cortex_m::singleton!(: [Triangle<f32>; TRIS] = [NO_TRIANGLE; TRIS])?,
        spheres: cortex_m::singleton!(: [Sphere<f32>; SPHERES] = [NO_SPHERE; SPHERES])?,
        objects: cortex_m::singleton!(: [Object<'static, f32>; OBJECTS] = [NO_OBJECT; OBJECTS])?,
        slots: cortex_m::singleton!(: [Slot; OBJECTS] = [Slot::EMPTY; OBJECTS])?,
        nodes: cortex_m::singleton!(: [Node<f32>; NODES] = [Node::EMPTY; NODES])?,
        ids: cortex_m::singleton!(: [u32; WORDS] = [0; WORDS])?,
    })
}

#[inline(never)]
fn render_row(data: &SceneData<'static>, b: Buffers) -> Option<()> {
    let tris = b.tris.get_mut(..data.triangles.len())?;
    let spheres = b.spheres.get_mut(..data.spheres.len())?;
    data.triangles_into(tris).ok()?;
    data.spheres_into(spheres).ok()?;
    let scene = data.scene(tris, spheres, b.objects).ok()?;
    let memory = RenderMemory {
        objects: b.slots,
        accel: AccelMemory {
            nodes: b.nodes,
            words: b.ids,
            ..AccelMemory::default()
        },
    };
    let Ok(r) = Renderer::<f32, Family, SceneFeatures>::with_features(
        &scene,
        data.settings,
        black_box(StaticBuild::<Sah, false>::default()),
        memory,
    ) else {
        return None;
    };
    let mut row = [0u8; 3 * WIDTH];
    let tile = Tile {
        x: 0,
        y: black_box(0),
        width: data.settings.width.min(WIDTH as u32),
        height: 1,
    };
    r.render_tile_srgb8(tile, &mut row).ok()?;
    black_box(row);
    Some(())
}

#[entry]
fn main() -> ! {
    if let Some(b) = buffers() {
        black_box(render_row(black_box(&scenes::CORNELL), b));
    }
    PROBE_DONE.store(DONE, Ordering::Relaxed);
    loop {
        cortex_m::asm::wfi();
    }
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    loop {
        cortex_m::asm::wfi();
    }
}
