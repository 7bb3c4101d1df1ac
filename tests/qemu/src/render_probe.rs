//! The renderer's panic-freedom check, shared by `panic_never_render` (`f32`) and
//! `panic_never_render_fixed` (`I16F16`), as `panic_never.rs` does for the BVH: the built-in
//! scene data converted into caller buffers, `Renderer::new` with every accelerator, every
//! render entry point, on values the optimiser cannot see (`black_box`: scene, settings,
//! buffer lengths, tiles), linked with the panic handler of `panic_check.rs`.
//! One mode per binary: both in one no longer fit the Cortex-M0's 256 KB of flash. Build:
//! `cargo build --release --bin panic_never_render --features panic-check` in tests/qemu
//! (`cargo xtask panic-check`). Never run: it only has to link.

use core::hint::black_box;
use raykernel::render::scenes::{self, SceneData};
use raykernel::render::{
    encode_srgb8, memory_needed, Object, ObjectSlot, RenderMemory, RenderStats, Renderer, Settings,
    Shape, Tile,
};
use raykernel::{AccelKind, AccelMemory, AnyFamily, KdNode, Node, Node4, Scalar, Sphere, Triangle};

const TRIS: usize = 24;
const SPHERES: usize = 4;
const OBJECTS: usize = 8;
const WORDS: usize = 512;

fn exercise<S: Scalar>(data: &SceneData<'_>, settings: Settings, accel: AccelKind) {
    let mut tris = [Triangle::<S> {
        v: [[S::ZERO; 3]; 3],
    }; TRIS];
    let mut spheres = [Sphere::<S> {
        center: [S::ZERO; 3],
        radius: S::ZERO,
    }; SPHERES];
    let nt = black_box(data.triangles.len()).min(TRIS);
    let ns = black_box(data.spheres.len()).min(SPHERES);
    let (tris, spheres) = (&mut tris[..nt], &mut spheres[..ns]);
    black_box(data.triangles_into(tris).is_ok());
    black_box(data.spheres_into(spheres).is_ok());
    let mut objects = [Object::new(Shape::Triangles(&[]), 0); OBJECTS];
    let Ok(scene) = data.scene(tris, spheres, &mut objects) else {
        return;
    };
    black_box(memory_needed::<S, AnyFamily>(scene.objects, &accel).bytes::<S, AnyFamily>());
    let mut slots = [ObjectSlot::<S>::EMPTY; OBJECTS];
    let mut nodes = [Node::<S>::EMPTY; 2 * (TRIS + SPHERES) + 4 * OBJECTS];
    let mut nodes4 = [Node4::<S>::EMPTY; TRIS + SPHERES + OBJECTS];
    let mut kd_nodes = [KdNode::<S>::EMPTY; 4 * (TRIS + SPHERES) + OBJECTS];
    let mut words = [0u32; WORDS];
    let n = black_box(usize::MAX);
    let memory = RenderMemory {
        objects: &mut slots[..n.min(OBJECTS)],
        accel: AccelMemory {
            nodes: &mut nodes[..n.min(2 * (TRIS + SPHERES) + 4 * OBJECTS)],
            nodes4: &mut nodes4[..n.min(TRIS + SPHERES + OBJECTS)],
            nodes8: &mut [],
            kd_nodes: &mut kd_nodes[..n.min(4 * (TRIS + SPHERES) + OBJECTS)],
            words: &mut words[..n.min(WORDS)],
        },
    };
    let Ok(r) = Renderer::new(&scene, settings, accel, memory) else {
        return;
    };
    black_box((r.plan(), r.settings()));
    let mut stats = RenderStats::default();
    let (x, y) = black_box((3u32, 5u32));
    black_box(r.pixel(x, y, &mut stats));
    let tile = black_box(Tile {
        x: 0,
        y: 0,
        width: 4,
        height: 2,
    });
    let mut linear = [[0.0f32; 3]; 8];
    let len = black_box(8usize).min(linear.len());
    black_box(r.render_tile(tile, &mut linear[..len]).ok());
    let mut bytes = [0u8; 3 * 64];
    let len = black_box(3 * 64usize).min(bytes.len());
    black_box(r.render_tile_srgb8(tile, &mut bytes[..len]).ok());
    black_box(r.render_srgb8(&mut bytes[..len]).ok());
    black_box(stats.rays());
}

/// Every accelerator on the built-in Cornell box in mode `S`; never returns.
pub fn run<S: Scalar>() -> ! {
    let data = black_box(&scenes::CORNELL);
    let settings = black_box(data.settings);
    for accel in black_box(AccelKind::ALL) {
        exercise::<S>(data, settings, accel);
    }
    black_box(encode_srgb8(black_box(0.5)));
    loop {
        cortex_m::asm::nop();
    }
}
