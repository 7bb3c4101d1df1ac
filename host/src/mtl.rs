//! Wavefront MTL materials for OBJ meshes: each `usemtl` group renders with its material's
//! diffuse colour `Kd`, or, when its `Ke` is not black, as an emitter of radiance `Ke` (the
//! kernel's emissive material reflects nothing, so `Kd` is then unused).
//!
//! Read from an MTL file: `newmtl NAME`, `Kd r g b` and `Ke r g b` (one number means grey);
//! every other statement (`Ka`, `Ks`, `Ns`, `illum`, texture maps, ...) is ignored, as is
//! anything after `#`. A material without `Kd` gets the host's white [`OBJ_ALBEDO`], as do the
//! triangles before the first `usemtl`.

use crate::error::Error;
use crate::input::read_limited;
use crate::limits::MAX_MATERIALS;
use crate::scene::OBJ_ALBEDO;
use crate::spec::{ObjectSource, SceneSpec};
use raykernel::render::scenes::{ObjectData, ShapeRange};
use raykernel::render::{Material, Rgb};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Largest MTL file read (bytes): far above any hand-written or exported library.
pub const MAX_MTL_BYTES: u64 = 64 << 20;

/// The material statements of an OBJ file, collected by
/// [`crate::obj::parse_obj_with_materials`].
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct MaterialRefs {
    /// `mtllib` file names (relative to the OBJ's directory) with the line naming each.
    pub libraries: Vec<(String, usize)>,
    /// `usemtl` statements in file order.
    pub groups: Vec<Group>,
}

/// One `usemtl` statement: the triangles from `first_triangle` up to the next group's use
/// `material`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Group {
    /// The material's name.
    pub material: String,
    /// The line of the `usemtl`.
    pub line: usize,
    /// The first triangle (in the mesh's output order) of the group.
    pub first_triangle: usize,
}

impl MaterialRefs {
    /// Records an `mtllib` statement's file names.
    pub(crate) fn add_libraries<'t>(&mut self, names: impl Iterator<Item = &'t [u8]>, line: usize) {
        for name in names {
            self.libraries
                .push((String::from_utf8_lossy(name).into_owned(), line));
        }
    }

    /// Records a `usemtl` statement (its name is the rest of the line) before triangle
    /// `first_triangle`.
    pub(crate) fn start_group<'t>(
        &mut self,
        words: impl Iterator<Item = &'t [u8]>,
        line: usize,
        first_triangle: usize,
    ) {
        let words: Vec<String> = words
            .map(|w| String::from_utf8_lossy(w).into_owned())
            .collect();
        self.groups.push(Group {
            material: words.join(" "),
            line,
            first_triangle,
        });
    }

    /// True if the file has neither `mtllib` nor `usemtl`.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.libraries.is_empty() && self.groups.is_empty()
    }
}

/// One `newmtl` entry of an MTL file.
#[derive(Clone, Debug, PartialEq)]
pub struct MtlMaterial {
    /// Its name.
    pub name: String,
    /// The file it came from and the line of its `newmtl`.
    pub origin: (PathBuf, usize),
    /// `Kd`, if given.
    pub diffuse: Option<Rgb>,
    /// `Ke`, if given.
    pub emission: Option<Rgb>,
}

impl MtlMaterial {
    /// The kernel's material: emissive if `Ke` is not black, else diffuse with `Kd` (or
    /// [`OBJ_ALBEDO`]).
    #[must_use]
    pub fn to_kernel(&self) -> Material {
        match self.emission {
            Some(radiance) if radiance.iter().any(|&c| c > 0.0) => Material::Emissive { radiance },
            _ => Material::Diffuse {
                albedo: self.diffuse.unwrap_or(OBJ_ALBEDO),
            },
        }
    }
}

/// Parses MTL text; `path` labels errors and origins. Never panics.
///
/// # Errors
/// [`Error::Scene`] naming `path:line`: a colour that is not 1 or 3 finite numbers, a `Kd`
/// outside `[0, 1]`, a negative `Ke`, a colour before any `newmtl`, or a name defined twice.
pub fn parse_mtl(bytes: &[u8], path: &Path) -> Result<Vec<MtlMaterial>, Error> {
    let bytes = bytes.strip_prefix(b"\xef\xbb\xbf").unwrap_or(bytes);
    let err = |line: usize, msg: String| Error::Scene {
        file: format!("{}:{line}", path.display()),
        field: String::new(),
        msg,
    };
    let mut out: Vec<MtlMaterial> = Vec::new();
    let mut first_line: HashMap<String, usize> = HashMap::new();
    for (i, raw) in bytes.split(|&b| b == b'\n').enumerate() {
        let line = i + 1;
        let text = String::from_utf8_lossy(raw);
        let body = text.split('#').next().unwrap_or_default();
        let mut words = body.split_whitespace();
        let Some(key) = words.next() else { continue };
        match key {
            "newmtl" => {
                let name = words.collect::<Vec<_>>().join(" ");
                if name.is_empty() {
                    return Err(err(line, "`newmtl` needs a name".into()));
                }
                if let Some(first) = first_line.insert(name.clone(), line) {
                    return Err(err(
                        line,
                        format!(
                            "material `{}` is defined twice (first at line {first})",
                            show(&name)
                        ),
                    ));
                }
                out.push(MtlMaterial {
                    name,
                    origin: (path.to_path_buf(), line),
                    diffuse: None,
                    emission: None,
                });
            }
            "Kd" | "Ke" => {
                let rgb = colour(words)
                    .ok_or_else(|| err(line, format!("`{key}` needs 1 or 3 finite numbers")))?;
                let Some(m) = out.last_mut() else {
                    return Err(err(line, format!("`{key}` before any `newmtl`")));
                };
                if key == "Kd" {
                    if rgb.iter().any(|&c| !(0.0..=1.0).contains(&c)) {
                        return Err(err(line, "`Kd` values must lie in [0, 1]".into()));
                    }
                    m.diffuse = Some(rgb);
                } else {
                    if rgb.iter().any(|&c| c < 0.0) {
                        return Err(err(line, "`Ke` values must not be negative".into()));
                    }
                    m.emission = Some(rgb);
                }
            }
            _ => {}
        }
    }
    Ok(out)
}

/// Reads and parses an MTL file (a regular file of at most [`MAX_MTL_BYTES`]).
///
/// # Errors
/// An unreadable or oversized file, or as [`parse_mtl`].
pub fn load_mtl(path: &Path) -> Result<Vec<MtlMaterial>, Error> {
    let bytes = read_limited(path, MAX_MTL_BYTES).map_err(|e| Error::Scene {
        file: path.display().to_string(),
        field: String::new(),
        msg: format!("cannot read MTL file: {e}"),
    })?;
    parse_mtl(&bytes, path)
}

/// Which material each triangle of a mesh uses.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshMaterials {
    /// The materials used, in order of first use.
    pub materials: Vec<Material>,
    /// Their names.
    pub names: Vec<String>,
    /// `of_triangle[t]`: the index into `materials` of triangle `t`.
    pub of_triangle: Vec<u32>,
}

/// Name of the material of triangles before the first `usemtl`.
const UNNAMED: &str = "(no usemtl)";

/// Resolves an OBJ's material statements: reads its `mtllib` files (relative to the OBJ) and
/// assigns each of its `triangle_count` triangles a material. `None` without any `mtllib` or
/// `usemtl`.
///
/// # Errors
/// An unreadable or bad MTL file, or a `usemtl` naming a material no library defines (at the
/// OBJ's line).
pub fn resolve(
    obj_path: &Path,
    refs: &MaterialRefs,
    triangle_count: usize,
) -> Result<Option<MeshMaterials>, Error> {
    if refs.is_empty() {
        return Ok(None);
    }
    let dir = obj_path.parent().unwrap_or_else(|| Path::new(""));
    let mut library: HashMap<String, MtlMaterial> = HashMap::new();
    for (name, _) in &refs.libraries {
        for m in load_mtl(&dir.join(name))? {
            // The first library defining a name wins, as in common OBJ readers.
            library.entry(m.name.clone()).or_insert(m);
        }
    }
    let mut out = MeshMaterials {
        materials: Vec::new(),
        names: Vec::new(),
        of_triangle: vec![0; triangle_count],
    };
    let mut index_of: HashMap<String, u32> = HashMap::new();
    let mut use_material = |name: &str, line: usize, out: &mut MeshMaterials| {
        if let Some(&i) = index_of.get(name) {
            return Ok(i);
        }
        let material = if name == UNNAMED {
            Material::Diffuse { albedo: OBJ_ALBEDO }
        } else {
            library
                .get(name)
                .ok_or_else(|| Error::Scene {
                    file: format!("{}:{line}", obj_path.display()),
                    field: String::new(),
                    msg: format!(
                        "`usemtl {}`: no such material in {}",
                        show(name),
                        if refs.libraries.is_empty() {
                            "the file's MTL libraries (it has no `mtllib`)".to_string()
                        } else {
                            refs.libraries
                                .iter()
                                .map(|(l, _)| l.as_str())
                                .collect::<Vec<_>>()
                                .join(", ")
                        }
                    ),
                })?
                .to_kernel()
        };
        if out.materials.len() >= MAX_MATERIALS {
            return Err(Error::Scene {
                file: format!("{}:{line}", obj_path.display()),
                field: String::new(),
                msg: format!("more than {MAX_MATERIALS} materials in use"),
            });
        }
        let i = u32::try_from(out.materials.len()).unwrap_or(u32::MAX);
        out.materials.push(material);
        out.names.push(name.to_string());
        index_of.insert(name.to_string(), i);
        Ok::<u32, Error>(i)
    };
    let first_group = refs
        .groups
        .first()
        .map_or(triangle_count, |g| g.first_triangle);
    if first_group > 0 {
        let i = use_material(UNNAMED, 0, &mut out)?;
        out.of_triangle[..first_group.min(triangle_count)].fill(i);
    }
    for (k, g) in refs.groups.iter().enumerate() {
        let end = refs
            .groups
            .get(k + 1)
            .map_or(triangle_count, |n| n.first_triangle)
            .min(triangle_count);
        if g.first_triangle >= end {
            continue; // a group without faces names no material
        }
        let i = use_material(&g.material, g.line, &mut out)?;
        out.of_triangle[g.first_triangle..end].fill(i);
    }
    Ok(Some(out))
}

/// Gives a mesh scene (one triangle object over all of `spec.triangles`, as
/// [`crate::scene::lit_mesh_scene`] makes) one object per material: triangles are regrouped by
/// material (stably, so each object keeps the file order). With one material the object keeps
/// its source (a dump names the mesh file); with several, each object holds part of the mesh,
/// so its source becomes [`ObjectSource::Inline`] (a dump writes its triangles).
pub fn split_by_material(spec: &mut SceneSpec, m: &MeshMaterials) {
    let n = spec.triangles.len().min(m.of_triangle.len());
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by_key(|&t| m.of_triangle[t]);
    spec.triangles = order.iter().map(|&t| spec.triangles[t]).collect();
    if !spec.vertex_normals.is_empty() {
        spec.vertex_normals = order.iter().map(|&t| spec.vertex_normals[t]).collect();
    }
    // Only kept when one material covers the mesh: the order is then the file's.
    let source = spec
        .object_sources
        .first()
        .cloned()
        .unwrap_or(ObjectSource::Inline);
    let motion = spec.objects.first().map_or([0.0; 3], |o| o.motion);
    spec.objects.clear();
    let mut first = 0usize;
    while first < n {
        let material = m.of_triangle[order[first]];
        let count = order[first..]
            .iter()
            .take_while(|&&t| m.of_triangle[t] == material)
            .count();
        spec.objects.push(ObjectData {
            shape: ShapeRange::Triangles {
                first: u32::try_from(first).unwrap_or(u32::MAX),
                count: u32::try_from(count).unwrap_or(u32::MAX),
            },
            material,
            motion,
            emission: [0.0; 3],
            one_sided: false,
        });
        first += count;
    }
    spec.object_sources = if spec.objects.len() == 1 {
        vec![source]
    } else {
        vec![ObjectSource::Inline; spec.objects.len()]
    };
    spec.materials.clone_from(&m.materials);
    spec.material_names.clone_from(&m.names);
}

/// A name for messages: at most 40 characters, control characters escaped.
fn show(name: &str) -> String {
    let mut out: String = name
        .chars()
        .take(40)
        .flat_map(char::escape_default)
        .collect();
    if name.chars().nth(40).is_some() {
        out.push('…');
    }
    out
}

/// Parses 1 (grey) or 3 finite numbers.
fn colour<'w>(words: impl Iterator<Item = &'w str>) -> Option<Rgb> {
    let v: Vec<f32> = words
        .map(|w| w.parse::<f32>().ok().filter(|x| x.is_finite()))
        .collect::<Option<_>>()?;
    match *v {
        [g] => Some([g; 3]),
        [r, g, b] => Some([r, g, b]),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colours_and_errors_name_their_line() {
        let p = Path::new("m.mtl");
        let ms = parse_mtl(
            b"\xef\xbb\xbf# lib\nnewmtl a\nKd 0.5 0.25 1\nKs 1 1 1\nnewmtl lamp\nKe 2\n",
            p,
        )
        .unwrap();
        assert_eq!(ms.len(), 2);
        assert_eq!(ms[0].diffuse, Some([0.5, 0.25, 1.0]));
        assert_eq!(
            ms[0].to_kernel(),
            Material::Diffuse {
                albedo: [0.5, 0.25, 1.0]
            }
        );
        assert_eq!(ms[1].to_kernel(), Material::Emissive { radiance: [2.0; 3] });
        assert_eq!(ms[1].origin.1, 5);
        for (text, needle) in [
            ("Kd 1 1 1\n", "m.mtl:1: `Kd` before any `newmtl`"),
            (
                "newmtl a\nKd 1 2\n",
                "m.mtl:2: `Kd` needs 1 or 3 finite numbers",
            ),
            ("newmtl a\nKd 1 x 1\n", "m.mtl:2: `Kd` needs 1 or 3"),
            (
                "newmtl a\nKd 1.5 1 1\n",
                "m.mtl:2: `Kd` values must lie in [0, 1]",
            ),
            (
                "newmtl a\nKe -1 0 0\n",
                "m.mtl:2: `Ke` values must not be negative",
            ),
            (
                "newmtl a\n\nnewmtl a\n",
                "m.mtl:3: material `a` is defined twice (first at line 1)",
            ),
            ("newmtl\n", "m.mtl:1: `newmtl` needs a name"),
        ] {
            let e = parse_mtl(text.as_bytes(), p).unwrap_err().to_string();
            assert!(e.contains(needle), "{text:?}: {e}");
        }
    }

    #[test]
    fn black_emission_keeps_the_diffuse_colour() {
        let m = MtlMaterial {
            name: "x".into(),
            origin: (PathBuf::new(), 1),
            diffuse: None,
            emission: Some([0.0; 3]),
        };
        assert_eq!(m.to_kernel(), Material::Diffuse { albedo: OBJ_ALBEDO });
    }
}
