//! Rendering from C: a scene of plain structs and arrays ([`RkScene`]), checked and built into
//! the caller's memory by [`rk_renderer_init`] (sized by [`rk_render_bytes`]), then rendered
//! tile by tile to 8-bit sRGB by [`rk_render_tile`]: the same bytes as the kernel's
//! `Renderer::render_tile_srgb8` on the same scene.
//!
//! Everything the renderer keeps is copied into the caller's memory at init: its state, one slot
//! per object, the primitives converted to the number mode, the materials, the lights and the
//! accelerators. The [`RkScene`] and its arrays need not outlive the call. Every object gets a
//! BVH of the scene's kind (4-wide by default), built with the SAH.

mod api;
mod build;
mod failure;
mod types;
mod view;

pub use api::*;
pub use types::*;
