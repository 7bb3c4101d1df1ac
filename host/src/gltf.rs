//! glTF 2.0 scenes (`.gltf` with its buffers, or binary `.glb`) through the `gltf` crate: every
//! triangle primitive of every mesh in the default scene (else the first), placed by its node's
//! world transform; each primitive's material as the kernel's diffuse material (base colour
//! factor) or, when its emissive factor times `KHR_materials_emissive_strength` is not black,
//! as an emitter; the first perspective camera met in the node tree, if any. Lights, background
//! and settings are those of an OBJ mesh ([`crate::scene::lit_mesh_scene`]). Textures,
//! normals, skins, morph targets and animations are not read.
//!
//! Buffers come from the `.glb`'s binary chunk, files beside the scene (relative URIs), or
//! base64 `data:` URIs. Every buffer, view and accessor range is checked against the data before
//! it is read. The `gltf` crate's own validation can panic on some malformed index references;
//! that panic is caught and reported as an error naming the file.

use crate::error::Error;
use crate::input::read_limited;
use crate::limits::{MAX_MATERIALS, MAX_OBJ_FILE_BYTES, MAX_TRIANGLES};
use crate::mtl::{split_by_material, MeshMaterials};
use crate::scene::{lit_mesh_scene, PinholeCamera};
use crate::spec::{ObjectSource, SceneSpec};
use base64::Engine as _;
use gltf::mesh::Mode;
use raykernel::render::Material;
use std::path::Path;

/// Largest `.gltf`/`.glb` file, and largest external buffer, read (bytes): as for OBJ files.
pub const MAX_GLTF_BYTES: u64 = MAX_OBJ_FILE_BYTES;

/// A column-major 4×4 matrix, as glTF stores them.
type Mat4 = [[f64; 4]; 4];

const IDENTITY: Mat4 = [
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
    [0.0, 0.0, 0.0, 1.0],
];

/// Loads a glTF 2.0 file as a scene.
///
/// # Errors
/// [`Error::Scene`] naming the file: unreadable, not glTF, a missing or short buffer, an
/// accessor outside its data, an index past the vertices, no triangles, or too many.
pub fn gltf_scene(path: &Path) -> Result<SceneSpec, Error> {
    std::panic::catch_unwind(|| load(path)).unwrap_or_else(|_| {
        Err(Error::Scene {
            file: path.display().to_string(),
            field: String::new(),
            msg: "malformed glTF (the glTF reader gave up on it)".into(),
        })
    })
}

fn load(path: &Path) -> Result<SceneSpec, Error> {
    let fail = |msg: String| Error::Scene {
        file: path.display().to_string(),
        field: String::new(),
        msg,
    };
    let bytes = read_capped(path).map_err(&fail)?;
    let gltf =
        gltf::Gltf::from_slice(&bytes).map_err(|e| fail(format!("not a glTF 2.0 file: {e}")))?;
    let dir = path.parent().unwrap_or_else(|| Path::new(""));
    let buffers = load_buffers(&gltf, dir).map_err(&fail)?;
    let doc = &gltf.document;
    let scene = doc
        .default_scene()
        .or_else(|| doc.scenes().next())
        .ok_or_else(|| fail("the file has no scene".into()))?;

    let mut triangles: Vec<[[f32; 3]; 3]> = Vec::new();
    let mut of_triangle: Vec<u32> = Vec::new();
    let mut materials = MaterialTable::default();
    let mut camera: Option<(PinholeCamera, Option<f32>)> = None;
    // Depth-first over the node tree with an explicit stack; a node deeper than the node count
    // means a cycle.
    let node_count = doc.nodes().len();
    let mut stack: Vec<(gltf::Node<'_>, Mat4, usize)> =
        scene.nodes().map(|n| (n, IDENTITY, 0)).collect();
    stack.reverse();
    while let Some((node, parent, depth)) = stack.pop() {
        if depth > node_count {
            return Err(fail("the node hierarchy has a cycle".into()));
        }
        let world = mul(&parent, &to_f64(node.transform().matrix()));
        if camera.is_none() {
            if let Some(c) = node.camera() {
                camera = perspective_camera(&c, &world);
            }
        }
        if let Some(mesh) = node.mesh() {
            for prim in mesh.primitives() {
                let Some(corners) = primitive_triangles(&prim, &buffers).map_err(&fail)? else {
                    continue;
                };
                if triangles.len() + corners.len() > MAX_TRIANGLES {
                    return Err(fail(format!(
                        "more than {MAX_TRIANGLES} triangles (instances counted)"
                    )));
                }
                let m = materials.index_of(&prim.material());
                if materials.names.len() > MAX_MATERIALS {
                    return Err(fail(format!("more than {MAX_MATERIALS} materials")));
                }
                for tri in corners {
                    triangles.push(tri.map(|p| transform_point(&world, p)));
                    of_triangle.push(m);
                }
            }
        }
        let mut children: Vec<_> = node.children().map(|c| (c, world, depth + 1)).collect();
        children.reverse();
        stack.extend(children);
    }
    if triangles.is_empty() {
        return Err(fail("no triangles in the scene".into()));
    }
    let mut spec = lit_mesh_scene(
        path,
        triangles,
        ObjectSource::Inline,
        camera.map(|(c, _)| c),
    );
    if let Some(aspect) = camera
        .and_then(|(_, a)| a)
        .filter(|a| a.is_finite() && *a > 0.0)
    {
        let h = (f64::from(spec.settings.width) / f64::from(aspect)).round();
        spec.settings.height = h.clamp(1.0, 16384.0) as u32;
    }
    split_by_material(
        &mut spec,
        &MeshMaterials {
            materials: materials.materials,
            names: materials.names,
            of_triangle,
        },
    );
    Ok(spec)
}

/// The materials met so far, in order of first use, with unique names.
#[derive(Default)]
struct MaterialTable {
    /// glTF material index (`None`: the default material) of each entry.
    keys: Vec<Option<usize>>,
    materials: Vec<Material>,
    names: Vec<String>,
}

impl MaterialTable {
    fn index_of(&mut self, m: &gltf::Material<'_>) -> u32 {
        let key = m.index();
        if let Some(i) = self.keys.iter().position(|k| *k == key) {
            return i as u32;
        }
        let base = m.name().map_or_else(
            || key.map_or("(default)".to_string(), |i| format!("material {i}")),
            str::to_string,
        );
        let name = if self.names.contains(&base) {
            format!("{base} #{}", key.map_or(0, |i| i + 1))
        } else {
            base
        };
        self.keys.push(key);
        self.materials.push(kernel_material(m));
        self.names.push(name);
        (self.keys.len() - 1) as u32
    }
}

/// Emissive if the emissive factor (times its strength) is not black, else diffuse with the
/// base colour factor (alpha ignored).
fn kernel_material(m: &gltf::Material<'_>) -> Material {
    let strength = m.emissive_strength().unwrap_or(1.0);
    let radiance = m.emissive_factor().map(|c| c * strength);
    if radiance.iter().any(|&c| c > 0.0) {
        return Material::Emissive { radiance };
    }
    let [r, g, b, _] = m.pbr_metallic_roughness().base_color_factor();
    Material::Diffuse { albedo: [r, g, b] }
}

/// The camera at `world` (glTF cameras look down their −z with +y up), if perspective.
fn perspective_camera(c: &gltf::Camera<'_>, world: &Mat4) -> Option<(PinholeCamera, Option<f32>)> {
    let gltf::camera::Projection::Perspective(p) = c.projection() else {
        return None;
    };
    let eye = transform_point_f64(world, [0.0; 3]);
    let dir = transform_dir(world, [0.0, 0.0, -1.0]);
    let up = transform_dir(world, [0.0, 1.0, 0.0]);
    let camera = PinholeCamera {
        eye,
        target: std::array::from_fn(|k| eye[k] + dir[k]),
        up,
        vfov_deg: f64::from(p.yfov()).to_degrees(),
    };
    camera.is_usable().then_some((camera, p.aspect_ratio()))
}

/// The triangles of one primitive in model space (`None` for points and lines).
fn primitive_triangles(
    prim: &gltf::Primitive<'_>,
    buffers: &[Vec<u8>],
) -> Result<Option<Vec<[[f32; 3]; 3]>>, String> {
    let mode = prim.mode();
    if !matches!(
        mode,
        Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
    ) {
        return Ok(None);
    }
    let positions = prim
        .get(&gltf::Semantic::Positions)
        .ok_or("a triangle primitive without POSITION")?;
    check_accessor(&positions, buffers)?;
    if let Some(ix) = prim.indices() {
        check_accessor(&ix, buffers)?;
    }
    let reader = prim.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
    let points: Vec<[f32; 3]> = reader
        .read_positions()
        .ok_or("unreadable POSITION accessor")?
        .collect();
    if let Some(bad) = points.iter().flatten().find(|x| !x.is_finite()) {
        return Err(format!("a vertex coordinate is not finite ({bad})"));
    }
    let indices: Vec<u32> = match reader.read_indices() {
        Some(ix) => ix.into_u32().collect(),
        None => (0..u32::try_from(points.len()).map_err(|_| "too many vertices")?).collect(),
    };
    let corner = |i: u32| {
        points
            .get(i as usize)
            .copied()
            .ok_or_else(|| format!("index {i} past the {} vertices", points.len()))
    };
    let n = indices.len();
    let mut out = Vec::new();
    let mut push = |a: u32, b: u32, c: u32| -> Result<(), String> {
        out.push([corner(a)?, corner(b)?, corner(c)?]);
        Ok(())
    };
    match mode {
        Mode::Triangles => {
            for t in indices.chunks_exact(3) {
                push(t[0], t[1], t[2])?;
            }
        }
        // Triangles are two-sided, so the strip's alternating winding needs no swap.
        Mode::TriangleStrip => {
            for k in 2..n {
                push(indices[k - 2], indices[k - 1], indices[k])?;
            }
        }
        _ => {
            for k in 2..n {
                push(indices[0], indices[k - 1], indices[k])?;
            }
        }
    }
    Ok(Some(out))
}

/// Checks that an accessor's elements lie inside its view and the view inside its buffer's
/// data (the reader slices without checking).
fn check_accessor(a: &gltf::Accessor<'_>, buffers: &[Vec<u8>]) -> Result<(), String> {
    let Some(view) = a.view() else {
        return Err("sparse or view-less accessors are not supported".into());
    };
    let data = buffers
        .get(view.buffer().index())
        .ok_or("an accessor names a missing buffer")?;
    view.offset()
        .checked_add(view.length())
        .filter(|&e| e <= data.len())
        .ok_or("a buffer view reaches past its buffer")?;
    let size = a.size();
    let stride = view.stride().unwrap_or(size);
    if a.count() == 0 {
        return Ok(());
    }
    let end = (a.count() - 1)
        .checked_mul(stride)
        .and_then(|x| x.checked_add(a.offset()))
        .and_then(|x| x.checked_add(size))
        .ok_or("an accessor's range overflows")?;
    if end > view.length() || stride < size {
        return Err(format!(
            "accessor {} reaches past its buffer view ({end} > {} bytes)",
            a.index(),
            view.length()
        ));
    }
    Ok(())
}

/// Every buffer's bytes: the `.glb` binary chunk, a file beside the scene, or a `data:` URI;
/// each at least as long as the file declares.
fn load_buffers(gltf: &gltf::Gltf, dir: &Path) -> Result<Vec<Vec<u8>>, String> {
    let mut out = Vec::new();
    for b in gltf.document.buffers() {
        let data = match b.source() {
            gltf::buffer::Source::Bin => gltf
                .blob
                .clone()
                .ok_or("buffer 0 refers to a binary chunk the file does not have")?,
            gltf::buffer::Source::Uri(uri) if uri.starts_with("data:") => {
                let (_, payload) = uri
                    .split_once(";base64,")
                    .ok_or("a data: URI buffer that is not base64")?;
                base64::engine::general_purpose::STANDARD
                    .decode(payload)
                    .map_err(|e| format!("buffer {}: bad base64: {e}", b.index()))?
            }
            gltf::buffer::Source::Uri(uri) => {
                let p = dir.join(percent_decode(uri));
                read_capped(&p).map_err(|e| format!("buffer {} ({uri}): {e}", b.index()))?
            }
        };
        if data.len() < b.length() {
            return Err(format!(
                "buffer {} holds {} bytes, the file declares {}",
                b.index(),
                data.len(),
                b.length()
            ));
        }
        out.push(data);
    }
    Ok(out)
}

/// A relative URI's `%XX` escapes decoded (other bytes as they are).
fn percent_decode(uri: &str) -> String {
    let b = uri.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = |c: u8| (c as char).to_digit(16);
        if b[i] == b'%' && i + 2 < b.len() {
            if let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2])) {
                out.push((h * 16 + l) as u8);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Reads a regular file of at most [`MAX_GLTF_BYTES`].
fn read_capped(path: &Path) -> Result<Vec<u8>, String> {
    read_limited(path, MAX_GLTF_BYTES).map_err(|e| format!("cannot read: {e}"))
}

fn to_f64(m: [[f32; 4]; 4]) -> Mat4 {
    m.map(|c| c.map(f64::from))
}

/// `a · b` (column-major: `m[column][row]`).
fn mul(a: &Mat4, b: &Mat4) -> Mat4 {
    std::array::from_fn(|c| std::array::from_fn(|r| (0..4).map(|k| a[k][r] * b[c][k]).sum()))
}

fn transform_point_f64(m: &Mat4, p: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|r| m[0][r] * p[0] + m[1][r] * p[1] + m[2][r] * p[2] + m[3][r])
}

/// A model-space vertex in world space, rounded once to `f32`.
fn transform_point(m: &Mat4, p: [f32; 3]) -> [f32; 3] {
    transform_point_f64(m, p.map(f64::from)).map(|x| x as f32)
}

fn transform_dir(m: &Mat4, d: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|r| m[0][r] * d[0] + m[1][r] * d[1] + m[2][r] * d[2])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matrices_compose_column_major() {
        // Translate by (1, 2, 3) after scaling by 2.
        let mut t = IDENTITY;
        t[3] = [1.0, 2.0, 3.0, 1.0];
        let s: Mat4 = std::array::from_fn(|c| {
            std::array::from_fn(|r| match (c, r) {
                (3, 3) => 1.0,
                (c, r) if c == r => 2.0,
                _ => 0.0,
            })
        });
        let m = mul(&t, &s);
        assert_eq!(transform_point_f64(&m, [1.0, 1.0, 1.0]), [3.0, 4.0, 5.0]);
        assert_eq!(transform_dir(&m, [0.0, 0.0, -1.0]), [0.0, 0.0, -2.0]);
    }

    #[test]
    fn uri_escapes_decode() {
        assert_eq!(percent_decode("a%20b.bin"), "a b.bin");
        assert_eq!(percent_decode("100%"), "100%");
        assert_eq!(percent_decode("x%2"), "x%2");
    }
}
