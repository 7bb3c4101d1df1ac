//! Optional parts of the renderer: with the `path-tracing` feature the path integrator renders;
//! without it, selecting it is a typed error naming the setting, and the suites that need it
//! say they were skipped. Parts named at compile time (`RenderFeatures`): a renderer linking
//! fewer renders what it links to the same bytes and refuses the rest with a typed error.

use raykernel::bvh::BuildOptions;
use raykernel::render::scenes::{self, SceneData};
use raykernel::render::{
    AllFeatures, Camera, Filter, Integrator, Item, Light, Problem, RenderFeatures, Renderer, Scene,
    SceneError, Settings,
};
use raykernel::BvhFamily;
use raykernel_testkit::golden::{self, Fail};

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
    let e = path_renderer().unwrap_err();
    assert_eq!(
        (e.item, e.index, e.field, e.problem),
        (Item::Settings, 0, "integrator", Problem::NotLinked)
    );
    eprintln!("skipped tests/path.rs: the path integrator needs `--features path-tracing`");
}

/// Links the parts of the renderer named by the seven flags, in `RenderFeatures` order.
#[derive(Clone, Copy, Debug)]
struct Only<const BITS: u8>;

impl<const BITS: u8> RenderFeatures for Only<BITS> {
    const FILTERS: bool = BITS & 1 != 0;
    const POINT_LIGHTS: bool = BITS & 2 != 0;
    const SPHERE_LIGHTS: bool = BITS & 4 != 0;
    const EMISSIVE_GEOMETRY: bool = BITS & 8 != 0;
    const ONE_SIDED: bool = BITS & 16 != 0;
    const SMOOTH_SHADING: bool = BITS & 32 != 0;
    const FIRST_HIT_LOOP: bool = BITS & 64 != 0;
}

/// The core alone.
type Core = Only<0>;

fn hash<K: RenderFeatures>(data: &SceneData<'_>) -> Result<u64, Fail> {
    golden::render_hash_with::<f32, BvhFamily, K>(data, BuildOptions::default())
}

/// Renders `data` with the core and one part more at a time, and with every part: each
/// renderer that links what the scene needs gives the bytes of the full one, the others
/// refuse it; `needs` is the set of parts the scene needs.
fn same_bytes_or_refused(data: &SceneData<'_>, needs: u8) {
    let want = hash::<AllFeatures>(data).unwrap();
    let results = [
        (0, hash::<Core>(data)),
        (1, hash::<Only<1>>(data)),
        (2, hash::<Only<2>>(data)),
        (4, hash::<Only<4>>(data)),
        (8, hash::<Only<8>>(data)),
        (16, hash::<Only<16>>(data)),
        (32, hash::<Only<32>>(data)),
        (64, hash::<Only<64>>(data)),
        (needs, hash::<Only<127>>(data)),
    ];
    for (bits, got) in results {
        if bits & needs == needs {
            assert_eq!(got, Ok(want), "{} with parts {bits:#b}", data.name);
        } else {
            assert_eq!(
                got,
                Err(Fail::NotLinked),
                "{} with parts {bits:#b}",
                data.name
            );
        }
    }
}

#[test]
fn fewer_parts_render_the_same_bytes_or_refuse_the_scene() {
    // Rectangle light, box filter, nothing emitting or one-sided: the core renders it.
    same_bytes_or_refused(&scenes::CORNELL, 0);
    // Point lights and a tent filter.
    same_bytes_or_refused(&scenes::SPHERES, 1 | 2);
    // Emitting, one-sided objects.
    same_bytes_or_refused(&golden::EMITTERS, 8 | 16);
    // Vertex normals on every triangle.
    const UP: [[[f32; 3]; 3]; 20] = [[[0.0, 1.0, 0.0]; 3]; 20];
    let smooth = SceneData {
        vertex_normals: &UP,
        ..scenes::CORNELL
    };
    same_bytes_or_refused(&smooth, 32);
    // One sample at each pixel centre of a pinhole with nothing lit: the first-hit loop's
    // plan, which the general loop renders to the same bytes without it.
    let first_hit = SceneData {
        lights: &[],
        camera: Camera {
            aperture_radius: 0.0,
            ..scenes::CORNELL.camera
        },
        settings: Settings {
            spp: 1,
            ..scenes::CORNELL.settings
        },
        objects: &scenes::CORNELL.objects[..4],
        ..scenes::CORNELL
    };
    same_bytes_or_refused(&first_hit, 0);
}

#[test]
fn a_part_left_out_is_a_typed_error_naming_it() {
    let scene = Scene::<f32> {
        objects: &[],
        materials: &[],
        lights: &[
            Light::Rect {
                corner: [0.0; 3],
                edge_u: [1.0, 0.0, 0.0],
                edge_v: [0.0, 0.0, 1.0],
                radiance: [1.0; 3],
            },
            Light::Point {
                position: [0.0; 3],
                intensity: [1.0; 3],
            },
        ],
        camera: scenes::CORNELL.camera,
        background: [0.0; 3],
    };
    let new = |settings| {
        Renderer::<f32, BvhFamily, Core>::with_features(
            &scene,
            settings,
            BuildOptions::default(),
            Default::default(),
        )
        .map(|_| ())
    };
    let e = new(Settings::default()).unwrap_err();
    assert_eq!(
        (e.item, e.index, e.field, e.problem),
        (Item::Light, 1, "point", Problem::NotLinked)
    );
    let settings = Settings {
        filter: Filter::Tent,
        ..Settings::default()
    };
    let e = new(settings).unwrap_err();
    assert_eq!(
        (e.item, e.index, e.field, e.problem),
        (Item::Settings, 0, "filter", Problem::NotLinked)
    );
}
