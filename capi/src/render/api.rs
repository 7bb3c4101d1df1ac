//! The C functions: settings defaults, sizing, init, tiles; and the opaque renderer handle.

use super::build::{init, layout, ALIGN};
use super::failure::{status_of, Failure};
use super::types::*;
use super::view::{view, Which};
use crate::RkStatus;
use core::ffi::c_void;
use core::mem::{align_of, size_of};
use raykernel::render::{Filter, Renderer, SamplerKind, Settings, Tile};
use raykernel::{Bvh4Family, BvhFamily, I16F16};

/// The kernel's default settings (its `Settings::default()`), to start from.
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
            // Not a default, and not offered by the C interface.
            Filter::Gaussian { .. } => RK_FILTER_BOX,
        },
        seed: s.seed,
    }
}

/// Bytes of memory `rk_renderer_init` needs for `scene` (any alignment: 127 bytes of it are
/// slack for aligning), or 0 if `scene` is null or unusable before any value is checked
/// (unknown mode, kind or shape, a mode and kind the crate's features leave out, a null array,
/// sizes beyond the address space).
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
    // The guards are constants: a pair the features leave out is not linked (and never stored).
    let rendered = match handle.renderer {
        AnyRenderer::F32Bvh(r) if Which::F32Bvh.linked() => {
            unsafe { &*r }.render_tile_srgb8(tile, out)
        }
        AnyRenderer::F32Bvh4(r) if Which::F32Bvh4.linked() => {
            unsafe { &*r }.render_tile_srgb8(tile, out)
        }
        AnyRenderer::FixedBvh(r) if Which::FixedBvh.linked() => {
            unsafe { &*r }.render_tile_srgb8(tile, out)
        }
        AnyRenderer::FixedBvh4(r) if Which::FixedBvh4.linked() => {
            unsafe { &*r }.render_tile_srgb8(tile, out)
        }
        _ => return RkStatus::ErrNotInitialised,
    };
    match rendered {
        Ok(_) => RkStatus::Ok,
        Err(e) => status_of(&e, false),
    }
}

const TAG: u32 = 0x524b_524e; // "RKRN"

/// A renderer in the caller's memory, in one of the four mode and family pairs.
#[derive(Clone, Copy)]
pub(super) enum AnyRenderer {
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
