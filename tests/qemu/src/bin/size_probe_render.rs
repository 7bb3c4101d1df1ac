//! Size probe of the renderer: the default built-in scene (`f32`, one BVH per object) converted
//! into caller buffers, `Renderer::new`, and one row rendered to sRGB bytes; nothing else (no
//! defmt, a spinning panic handler). `cargo xtask size` reports its `.text`/`.rodata` next to
//! the build + traverse probe (`size_probe.rs`) and runs it under QEMU to measure its stack (the
//! arrays below included): the only measuring code is the store to [`PROBE_DONE`].
#![no_std]
#![no_main]

use core::hint::black_box;
use core::sync::atomic::{AtomicU32, Ordering};
use cortex_m_rt::entry;
use raykernel::bvh::{nodes_needed, BuildOptions};
use raykernel::render::scenes::{self, SceneData};
use raykernel::render::{AccelChoice, AccelMemory, Object, ObjectSlot, Renderer, Shape, Tile};
use raykernel::{Node, Sphere, Triangle};

const TRIS: usize = 24;
const SPHERES: usize = 4;
const OBJECTS: usize = 8;
const WIDTH: usize = 64;

/// Set to `DONE` when the row has been rendered; `cargo xtask size` polls it (in .bss).
#[no_mangle]
static PROBE_DONE: AtomicU32 = AtomicU32::new(0);
/// "DONE", as `xtask/src/size.rs` expects.
const DONE: u32 = 0x444f_4e45;

#[inline(never)]
fn render_row(data: &SceneData<'_>) -> Option<()> {
    let mut tris = [Triangle::<f32> { v: [[0.0; 3]; 3] }; TRIS];
    let mut spheres = [Sphere::<f32> {
        center: [0.0; 3],
        radius: 0.0,
    }; SPHERES];
    let tris = tris.get_mut(..data.triangles.len())?;
    let spheres = spheres.get_mut(..data.spheres.len())?;
    data.triangles_into(tris).ok()?;
    data.spheres_into(spheres).ok()?;
    let mut objects = [Object::new(Shape::Triangles(&[]), 0); OBJECTS];
    let scene = data.scene(tris, spheres, &mut objects).ok()?;
    let mut slots = [ObjectSlot::EMPTY; OBJECTS];
    let mut nodes = [Node::<f32>::EMPTY; nodes_needed(TRIS) + nodes_needed(SPHERES) + 2 * OBJECTS];
    let mut ids = [0u32; TRIS + SPHERES];
    let memory = AccelMemory {
        objects: &mut slots,
        bvh_nodes: &mut nodes,
        kd_nodes: &mut [],
        words: &mut ids,
    };
    let accel = AccelChoice::Bvh(black_box(BuildOptions::default()));
    let r = Renderer::new(&scene, data.settings, accel, memory).ok()?;
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
    black_box(render_row(black_box(&scenes::CORNELL)));
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
