//! The crate's features decide which number modes and accelerator kinds the renderer links:
//! a linked pair initialises, any other is refused as a bad kind. Holds under every feature
//! set (CI runs it with the defaults and with `render-f32,render-bvh4` alone).

mod common;

use common::*;
use raykernel_c::*;

#[test]
fn linked_pairs_initialise_and_the_others_are_refused() {
    let data = test_scene();
    let f32_linked = cfg!(feature = "render-f32");
    let fixed_linked = cfg!(feature = "render-fixed");
    let bvh_linked = cfg!(feature = "render-bvh");
    let bvh4_linked = cfg!(feature = "render-bvh4");
    for (mode, mode_linked) in [(RK_MODE_F32, f32_linked), (RK_MODE_FIXED, fixed_linked)] {
        for (kind, kind_linked) in [
            (0, bvh4_linked),
            (RK_KIND_BVH, bvh_linked),
            (RK_KIND_BVH4, bvh4_linked),
        ] {
            let mut c = CScene::new(&data, mode, kind);
            let scene = *c.point();
            // SAFETY: the scene and its arrays are valid.
            let bytes = unsafe { rk_render_bytes(&scene) };
            let mut memory = Memory::new(bytes.max(1), 0);
            let got = init(&scene, &mut memory, bytes);
            if mode_linked && kind_linked {
                let r = got.unwrap_or_else(|(s, _)| panic!("mode {mode} kind {kind}: {s:?}"));
                let mut px = [0u8; 3];
                // SAFETY: `r` is initialised and its memory alive.
                let s = unsafe { rk_render_tile(&r, 0, 0, 1, 1, px.as_mut_ptr(), 3) };
                assert_eq!(s, RkStatus::Ok);
            } else {
                assert_eq!(bytes, 0, "mode {mode} kind {kind}: not linked, no size");
                let (s, e) = got.expect_err("a pair left out is refused");
                assert_eq!((s, field(&e).as_str()), (RkStatus::ErrBadArgument, "kind"));
            }
        }
    }
}
