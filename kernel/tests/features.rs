//! Optional parts of the renderer: with the `path-tracing` feature the path integrator renders;
//! without it, selecting it is a typed error naming the setting, and the suites that need it
//! say they were skipped.

use raykernel::render::scenes;
use raykernel::render::{Integrator, Renderer, Scene, SceneError, Settings};

/// A renderer over an empty scene (no memory needed) with the path integrator selected.
fn path_renderer() -> Result<(), SceneError> {
    let scene = Scene::<f32> {
        objects: &[],
        materials: &[],
        lights: &[],
        camera: scenes::CORNELL.camera,
        background: [0.25; 3],
    };
    let settings = Settings {
        width: 4,
        height: 4,
        integrator: Integrator::Path { max_length: 3 },
        ..Settings::default()
    };
    let r = Renderer::<f32>::new(&scene, settings, Default::default(), Default::default())?;
    let mut out = [[0.0f32; 3]; 16];
    r.render_tile(
        raykernel::render::Tile {
            x: 0,
            y: 0,
            width: 4,
            height: 4,
        },
        &mut out,
    )?;
    // Every path leaves the empty scene at once and sees the background.
    assert!(out.iter().all(|p| *p == [0.25; 3]), "{out:?}");
    Ok(())
}

#[cfg(feature = "path-tracing")]
#[test]
fn path_integrator_renders_with_the_feature() {
    path_renderer().unwrap();
}

#[cfg(not(feature = "path-tracing"))]
#[test]
fn path_integrator_is_a_typed_error_without_the_feature() {
    use raykernel::render::{Item, Problem};
    let e = path_renderer().unwrap_err();
    assert_eq!(
        (e.item, e.index, e.field, e.problem),
        (Item::Settings, 0, "integrator", Problem::NotLinked)
    );
    eprintln!("skipped tests/path.rs: the path integrator needs `--features path-tracing`");
}
