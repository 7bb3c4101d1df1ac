//! Arbitrary bytes -> the host's OBJ reader, ray/hit file readers and scene-file reader. None
//! may panic; what the OBJ and ray/hit readers accept must convert to kernel triangles (or give
//! a typed error) and re-encode to the same bytes; a scene file that loads must pass or fail
//! the render request checks with a message. (Structure-aware scene-file mutations:
//! host/tests/scene_mutation.rs.)
#![no_main]

use host::rayfile::{encode_hits, encode_rays, parse_hits, parse_rays};
use libfuzzer_sys::fuzz_target;
use raykernel::I16F16;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let path = Path::new("fuzz.obj");
    if let Ok(mesh) = host::parse_obj(data, path) {
        assert_eq!(mesh.triangles.len(), mesh.triangle_lines.len());
        assert_eq!(mesh.positions.len(), mesh.position_lines.len());
        for t in &mesh.triangles {
            for &i in t {
                assert!(
                    (i as usize) < mesh.positions.len(),
                    "index {i} out of range"
                );
            }
        }
        let _ = mesh.kernel_triangles::<f32>(path);
        let _ = mesh.kernel_triangles::<I16F16>(path);
    }
    if let Ok(rays) = parse_rays(data, Path::new("fuzz.rays")) {
        assert_eq!(encode_rays(&rays), data, "ray file does not round-trip");
    }
    if let Ok(hits) = parse_hits(data, Path::new("fuzz.hits")) {
        assert_eq!(encode_hits(&hits), data, "hit file does not round-trip");
    }
    if let Ok(text) = std::str::from_utf8(data) {
        if let Ok(spec) = host::scenefile::parse_scene_file(text, Path::new("fuzz.json")) {
            for mode in [host::trace::Mode::F32, host::trace::Mode::Fixed] {
                if let Err(e) = host::cli::check_render_request(&spec, mode, false) {
                    assert!(!e.to_string().is_empty());
                }
            }
        }
    }
});
