//! Instructions per closest-hit ray and per rendered pixel, counted by QEMU (`-icount
//! shift=0`, see `counter.rs`). The workloads are the golden ones, and each is checked against
//! its golden answer, so nothing is counted while giving wrong answers:
//!
//! - rays: the 80-triangle icosphere of `testkit/src/golden.rs`, SAH BVH (default options),
//!   the closest hit of its 96 rays (built and prepared outside the count), in each mode;
//! - pixels: the built-in Cornell scene at its own settings (64×64, 8 samples per pixel),
//!   rendered row by row to sRGB bytes in each mode, scene setup and per-object BVH builds
//!   included.
//!
//! Prints `calibration ...` and one `measure <name> count=<n> instructions=<i>` line per
//! workload (read by `cargo xtask speed`); exits 0 only if every workload gave its golden
//! answer. One program per mode (`speed_f32`, `speed_fixed`): the renderer in both modes
//! does not fit the 256 KB of flash of the smaller machines in one.

use crate::cases::{self, Bits, ICO_TRIS, RAY_COUNT};
use crate::counter::{self, Rate};
use crate::{exit, golden};
use raykernel::bvh::{nodes_needed, BuildOptions};
use raykernel::render::scenes::{self, SceneData};
use raykernel::{Accel, Bvh, Linear, Node, Ray, Scalar};
use semihosting::println;

/// Calibration loop length: `2 * SPIN` instructions.
const SPIN: u32 = 1_000_000;

/// Calibrates the counter, counts the ray and pixel workloads in mode `S` and exits (0 if
/// every answer was golden).
pub fn run<S: Bits + Scalar>() -> ! {
    counter::start();
    let rate = counter::calibrate(SPIN);
    let tenths = rate.per_tick_tenths();
    println!(
        "calibration instructions={} ticks={} instructions_per_tick={}.{}",
        rate.instructions,
        rate.ticks,
        tenths / 10,
        tenths % 10
    );
    let rays_ok = rays::<S>(rate);
    let pixels_ok = pixels::<S>("cornell", &scenes::CORNELL, rate);
    exit(i32::from(!(rays_ok && pixels_ok)))
}

/// Counts the closest-hit queries of the golden ray set through a SAH BVH over the icosphere;
/// true if every hit equals brute force's.
#[inline(never)]
fn rays<S: Bits>(rate: Rate) -> bool {
    let name = S::NAME;
    let mut tris = cases::empty_mesh::<S>();
    if cases::icosphere(&mut tris).is_err() {
        println!("{name}: icosphere rejected");
        return false;
    }
    let mut nodes = [Node::<S>::EMPTY; nodes_needed(ICO_TRIS)];
    let mut ids = [0u32; ICO_TRIS];
    let Ok(bvh) = Bvh::build(&tris, &mut nodes, &mut ids, BuildOptions::default()) else {
        println!("{name}: build failed");
        return false;
    };
    let Ok(first) = cases::ray::<S>(0) else {
        println!("{name}: ray rejected");
        return false;
    };
    let mut rays: [Ray<S>; RAY_COUNT] = [first; RAY_COUNT];
    for (i, r) in rays.iter_mut().enumerate() {
        match cases::ray::<S>(i) {
            Ok(ray) => *r = ray,
            Err(_) => {
                println!("{name}: ray {i} rejected");
                return false;
            }
        }
    }
    let mut hits = [None; RAY_COUNT];
    let t0 = counter::ticks();
    for (hit, r) in hits.iter_mut().zip(&rays) {
        *hit = bvh.intersect(r);
    }
    let dt = counter::ticks() - t0;
    core::hint::black_box(&hits);
    let linear = Linear::new(&tris);
    let bits = |h: &Option<raykernel::Hit<S>>| {
        h.as_ref()
            .map(|h| [h.t.bits(), h.prim, h.u.bits(), h.v.bits()])
    };
    let same = hits
        .iter()
        .zip(&rays)
        .all(|(h, r)| bits(h) == bits(&linear.intersect(r)));
    if !same {
        println!("{name}: BVH differs from brute force");
        return false;
    }
    println!(
        "measure rays_{name} count={RAY_COUNT} ticks={dt} instructions={}",
        rate.instructions(dt)
    );
    true
}

/// Counts the render of built-in scene `scene` in mode `S`, hashed row by row; true if the
/// hash equals golden case `render_<scene>_<mode>`.
#[inline(never)]
fn pixels<S: Bits + Scalar>(scene_name: &str, scene: &SceneData<'_>, rate: Rate) -> bool {
    let mut buf = [0u8; 32];
    let case = golden_name(&mut buf, scene_name, S::NAME);
    let name = S::NAME;
    let count = u64::from(scene.settings.width) * u64::from(scene.settings.height);
    let t0 = counter::ticks();
    let hash = cases::render_hash::<S>(scene);
    let dt = counter::ticks() - t0;
    if golden(case).is_none() || hash.ok() != golden(case) {
        println!("pixels {scene_name} {name}: image differs from golden {case}");
        return false;
    }
    println!(
        "measure pixels_{scene_name}_{name} count={count} ticks={dt} instructions={}",
        rate.instructions(dt)
    );
    true
}

/// `render_<scene>_<mode>` in `buf`.
fn golden_name<'a>(buf: &'a mut [u8; 32], scene: &str, mode: &str) -> &'a str {
    let mut n = 0;
    for part in ["render_", scene, "_", mode] {
        for &b in part.as_bytes() {
            if let Some(slot) = buf.get_mut(n) {
                *slot = b;
                n += 1;
            }
        }
    }
    core::str::from_utf8(buf.get(..n).unwrap_or_default()).unwrap_or("")
}
