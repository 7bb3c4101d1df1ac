//! A small Wavefront OBJ reader for triangle meshes, with `file:line` in every error.
//!
//! Accepted: `v x y z [w]` (also `v x y z r g b`, the common vertex-colour extension), and `f`
//! with entries `v`, `v/vt`, `v//vn` or `v/vt/vn`, 1-based or negative (relative) indices.
//! Polygons are fan-triangulated: (v0,v1,v2), (v0,v2,v3), ... `vn x y z` normals are kept
//! for faces whose every entry names one (smooth shading); a face with none, or with some
//! entries lacking one, is shaded flat. `mtllib` and `usemtl` are collected by
//! [`parse_obj_with_materials`] ([`crate::mtl`] reads the libraries). Every other statement
//! (`vt`, `o`, `g`, `s`, `l`, ...) is ignored, as is anything after `#`.
//!
//! The triangle id used in hit files is the 0-based index of a triangle in this output order.
//! A positive index may point at a vertex defined later in the file (checked once the whole file
//! is read); a negative one counts back from the vertices defined so far. A leading UTF-8
//! byte-order mark is skipped. Files are read only if regular and at most
//! [`MAX_OBJ_FILE_BYTES`] long; a mesh holds at most [`MAX_TRIANGLES`] triangles.
//!
//! [`parse_obj`] never panics, whatever the bytes.

use crate::input::{read_limited, InputError};
use crate::limits::{MAX_OBJ_FILE_BYTES, MAX_TRIANGLES};
use crate::mtl::MaterialRefs;
use raykernel::{PointError, Scalar, Triangle, F32_COORD_LIMIT, FIXED_COORD_LIMIT};
use std::fmt;
use std::path::{Path, PathBuf};

/// A triangle mesh as read from an OBJ file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions, in file order.
    pub positions: Vec<[f32; 3]>,
    /// The line (1-based) each position was read from.
    pub position_lines: Vec<usize>,
    /// Triangles as 0-based indices into `positions`, in file order.
    pub triangles: Vec<[u32; 3]>,
    /// The line (1-based) of the face each triangle came from.
    pub triangle_lines: Vec<usize>,
    /// Vertex normals (`vn`), in file order.
    pub normals: Vec<[f32; 3]>,
    /// Per triangle, its corners' indices into `normals`, or `None` (flat). Empty when the file
    /// has no face with normals.
    pub triangle_normals: Vec<Option<[u32; 3]>>,
}

impl Mesh {
    /// Number of triangles.
    #[must_use]
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// The three vertices of triangle `id` (which must be in range).
    #[must_use]
    pub fn triangle_f32(&self, id: usize) -> [[f32; 3]; 3] {
        self.triangles[id].map(|i| self.positions[i as usize])
    }

    /// The normals at the three corners of triangle `id` (which must be in range), zero where
    /// the triangle is shaded flat.
    #[must_use]
    pub fn vertex_normals(&self, id: usize) -> [[f32; 3]; 3] {
        match self.triangle_normals.get(id) {
            Some(Some(corners)) => corners.map(|i| self.normals[i as usize]),
            _ => [[0.0; 3]; 3],
        }
    }

    /// True if some triangle has vertex normals.
    #[must_use]
    pub fn has_normals(&self) -> bool {
        self.triangle_normals.iter().any(Option::is_some)
    }

    /// Converts every triangle to the kernel's type in mode `S`.
    ///
    /// # Errors
    /// [`ObjErrorKind::UnusableVertex`] at the line of the first vertex that mode `S` cannot
    /// represent (fixed point rejects coordinates beyond ±8192).
    pub fn kernel_triangles<S: Scalar>(&self, path: &Path) -> Result<Vec<Triangle<S>>, ObjError> {
        (0..self.triangles.len())
            .map(|id| {
                Triangle::from_f32(self.triangle_f32(id)).map_err(|e| {
                    let vertex = self.triangles[id][e.vertex] as usize;
                    ObjError::at(
                        path,
                        self.position_lines[vertex],
                        ObjErrorKind::UnusableVertex {
                            triangle: id,
                            mode: S::NAME,
                            error: e.error,
                        },
                    )
                })
            })
            .collect()
    }
}

/// An OBJ error: where (file and, except for read errors, line) and what.
#[derive(Debug)]
pub struct ObjError {
    /// The file.
    pub path: PathBuf,
    /// 1-based line, `None` when the error is not about one line (unreadable file).
    pub line: Option<usize>,
    /// What is wrong.
    pub kind: ObjErrorKind,
}

/// What is wrong with an OBJ file.
#[derive(Debug)]
pub enum ObjErrorKind {
    /// The file could not be read (missing, not a regular file, too large).
    Read(InputError),
    /// A vertex line does not hold 3, 4 (`x y z w`) or 6 (`x y z r g b`) numbers.
    VertexArity {
        /// Numbers found.
        count: usize,
    },
    /// A token that should be a number is not one.
    BadNumber {
        /// The token (shortened, lossy UTF-8).
        token: String,
    },
    /// A number is NaN or infinite once parsed as `f32` (e.g. `1e39`).
    NonFinite {
        /// The token.
        token: String,
    },
    /// A face entry is not `v`, `v/vt`, `v//vn` or `v/vt/vn` with integer indices.
    BadIndex {
        /// The entry.
        token: String,
    },
    /// An index is 0 (OBJ indices start at 1).
    ZeroIndex,
    /// A vertex index points outside the vertex list.
    IndexOutOfRange {
        /// The index as written.
        index: i64,
        /// Vertices available to it (defined so far for negative indices, in the file otherwise).
        vertex_count: usize,
    },
    /// A `vn` line does not hold 3 numbers.
    NormalArity {
        /// Numbers found.
        count: usize,
    },
    /// A normal index (`v//vn`) points outside the normal list.
    NormalIndexOutOfRange {
        /// The index as written.
        index: i64,
        /// Normals available to it (defined so far for negative indices, in the file otherwise).
        normal_count: usize,
    },
    /// A face with fewer than 3 vertices.
    TooFewVertices {
        /// Vertices given.
        count: usize,
    },
    /// The file holds no face at all.
    NoTriangles,
    /// The faces so far make more triangles than a mesh may hold.
    TooManyTriangles {
        /// The limit, [`MAX_TRIANGLES`].
        limit: usize,
    },
    /// A vertex cannot be used in the requested number mode (reported at the vertex's line).
    UnusableVertex {
        /// The first triangle using it.
        triangle: usize,
        /// The mode, `f32` or `fixed`.
        mode: &'static str,
        /// What the kernel objects to.
        error: PointError,
    },
}

impl ObjError {
    /// An error at `line` of `path`.
    pub(crate) fn at(path: &Path, line: usize, kind: ObjErrorKind) -> Self {
        Self {
            path: path.to_path_buf(),
            line: Some(line),
            kind,
        }
    }
}

impl fmt::Display for ObjError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(line) => write!(f, "{}:{line}: {}", self.path.display(), self.kind),
            None => write!(f, "{}: {}", self.path.display(), self.kind),
        }
    }
}

impl fmt::Display for ObjErrorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Read(e) => write!(f, "cannot read OBJ file: {e}"),
            Self::VertexArity { count } => write!(
                f,
                "vertex has {count} numbers, expected `v x y z [w]` (or `v x y z r g b`)"
            ),
            Self::BadNumber { token } => write!(f, "malformed number `{token}`"),
            Self::NonFinite { token } => write!(f, "number `{token}` is not a finite f32"),
            Self::BadIndex { token } => write!(
                f,
                "malformed face entry `{token}`, expected v, v/vt, v//vn or v/vt/vn"
            ),
            Self::ZeroIndex => write!(f, "index 0 in face (OBJ indices start at 1)"),
            Self::IndexOutOfRange {
                index,
                vertex_count,
            } => write!(
                f,
                "vertex index {index} out of range ({vertex_count} vertices available)"
            ),
            Self::NormalArity { count } => {
                write!(f, "normal has {count} numbers, expected `vn x y z`")
            }
            Self::NormalIndexOutOfRange {
                index,
                normal_count,
            } => write!(
                f,
                "normal index {index} out of range ({normal_count} normals available)"
            ),
            Self::TooFewVertices { count } => {
                write!(f, "face has {count} vertices, at least 3 are needed")
            }
            Self::NoTriangles => write!(f, "no faces: the file holds no triangles"),
            Self::TooManyTriangles { limit } => {
                write!(f, "too many triangles: a mesh holds at most {limit}")
            }
            Self::UnusableVertex {
                triangle,
                mode,
                error,
            } => write!(
                f,
                "vertex unusable in {mode} mode (triangle {triangle}): {}",
                point_error_text(*error, mode)
            ),
        }
    }
}

impl std::error::Error for ObjError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match &self.kind {
            ObjErrorKind::Read(e) => Some(e),
            _ => None,
        }
    }
}

/// What the kernel's [`PointError`] means in `mode` (`f32` or `fixed`): the range it names is
/// that mode's, not always the fixed-point one.
#[must_use]
pub fn point_error_text(error: PointError, mode: &str) -> String {
    match error {
        PointError::OutOfRange { .. } => {
            format!("coordinate outside {}", coordinate_range(mode))
        }
        other => other.to_string(),
    }
}

/// `[-8192, 8192], the coordinate range of fixed mode` (or of `f32` mode).
#[must_use]
pub fn coordinate_range(mode: &str) -> String {
    let limit = if mode == "fixed" {
        FIXED_COORD_LIMIT
    } else {
        F32_COORD_LIMIT
    };
    format!("[-{limit:.0}, {limit:.0}], the coordinate range of {mode} mode")
}

/// Reads and parses an OBJ file.
///
/// # Errors
/// [`ObjErrorKind::Read`] if the file cannot be read, is not a regular file or is larger
/// than [`MAX_OBJ_FILE_BYTES`], else as [`parse_obj`].
pub fn load_obj(path: &Path) -> Result<Mesh, ObjError> {
    let bytes = read_limited(path, MAX_OBJ_FILE_BYTES).map_err(|e| ObjError {
        path: path.to_path_buf(),
        line: None,
        kind: ObjErrorKind::Read(e),
    })?;
    parse_obj(&bytes, path)
}

/// Reads and parses an OBJ file with its `mtllib` and `usemtl` statements.
///
/// # Errors
/// As [`load_obj`].
pub fn load_obj_with_materials(path: &Path) -> Result<(Mesh, MaterialRefs), ObjError> {
    let bytes = read_limited(path, MAX_OBJ_FILE_BYTES).map_err(|e| ObjError {
        path: path.to_path_buf(),
        line: None,
        kind: ObjErrorKind::Read(e),
    })?;
    parse_obj_with_materials(&bytes, path)
}

/// Parses OBJ text; `path_for_errors` only labels errors. Never panics.
///
/// # Errors
/// The first problem found, with its line.
pub fn parse_obj(bytes: &[u8], path_for_errors: &Path) -> Result<Mesh, ObjError> {
    parse_obj_with_materials(bytes, path_for_errors).map(|(mesh, _)| mesh)
}

/// [`parse_obj`], also returning the material statements (which triangles each `usemtl` names).
///
/// # Errors
/// As [`parse_obj`].
pub fn parse_obj_with_materials(
    bytes: &[u8],
    path_for_errors: &Path,
) -> Result<(Mesh, MaterialRefs), ObjError> {
    let err = |line: usize, kind| ObjError::at(path_for_errors, line, kind);
    // A byte-order mark is not part of the first statement.
    let bytes = bytes.strip_prefix(b"\xef\xbb\xbf").unwrap_or(bytes);
    let mut mesh = Mesh::default();
    let mut materials = MaterialRefs::default();
    let mut face: Vec<u32> = Vec::new();
    let mut face_normals: Vec<Option<u32>> = Vec::new();
    let mut line_no = 0usize;
    for raw_line in bytes.split(|&b| b == b'\n') {
        line_no += 1;
        let content = match raw_line.iter().position(|&b| b == b'#') {
            Some(hash) => &raw_line[..hash],
            None => raw_line,
        };
        let mut tokens = content
            .split(|b| b.is_ascii_whitespace())
            .filter(|t| !t.is_empty());
        match tokens.next() {
            Some(b"v") => {
                let (xyz, count) = parse_numbers(tokens).map_err(|kind| err(line_no, kind))?;
                if !matches!(count, 3 | 4 | 6) {
                    return Err(err(line_no, ObjErrorKind::VertexArity { count }));
                }
                mesh.positions.push(xyz);
                mesh.position_lines.push(line_no);
            }
            Some(b"vn") => {
                let (xyz, count) = parse_numbers(tokens).map_err(|kind| err(line_no, kind))?;
                if count != 3 {
                    return Err(err(line_no, ObjErrorKind::NormalArity { count }));
                }
                mesh.normals.push(xyz);
            }
            Some(b"f") => {
                face.clear();
                face_normals.clear();
                for token in tokens {
                    let (index, normal) =
                        parse_face_entry(token, mesh.positions.len(), mesh.normals.len())
                            .map_err(|kind| err(line_no, kind))?;
                    face.push(index);
                    face_normals.push(normal);
                }
                if face.len() < 3 {
                    return Err(err(
                        line_no,
                        ObjErrorKind::TooFewVertices { count: face.len() },
                    ));
                }
                if mesh.triangles.len() + (face.len() - 2) > MAX_TRIANGLES {
                    return Err(err(
                        line_no,
                        ObjErrorKind::TooManyTriangles {
                            limit: MAX_TRIANGLES,
                        },
                    ));
                }
                let normals: Option<Vec<u32>> = face_normals.iter().copied().collect();
                if normals.is_some() && mesh.triangle_normals.len() < mesh.triangles.len() {
                    // The first face with normals: the ones before it are flat.
                    mesh.triangle_normals.resize(mesh.triangles.len(), None);
                }
                for k in 1..face.len() - 1 {
                    mesh.triangles.push([face[0], face[k], face[k + 1]]);
                    mesh.triangle_lines.push(line_no);
                    if let Some(n) = &normals {
                        mesh.triangle_normals.push(Some([n[0], n[k], n[k + 1]]));
                    } else if !mesh.triangle_normals.is_empty() {
                        mesh.triangle_normals.push(None);
                    }
                }
            }
            Some(b"mtllib") => materials.add_libraries(tokens, line_no),
            Some(b"usemtl") => materials.start_group(tokens, line_no, mesh.triangles.len()),
            _ => {}
        }
    }
    if mesh.triangles.is_empty() {
        // The last line: a final newline ends it rather than starting another.
        let last = line_no - usize::from(line_no > 1 && bytes.ends_with(b"\n"));
        return Err(err(last, ObjErrorKind::NoTriangles));
    }
    // Positive indices may point forward; check them now that every vertex is known.
    let normal_count = mesh.normals.len();
    for (tri, &line) in mesh.triangle_normals.iter().zip(&mesh.triangle_lines) {
        let Some(tri) = tri else { continue };
        if let Some(&bad) = tri.iter().find(|&&i| i as usize >= normal_count) {
            return Err(err(
                line,
                ObjErrorKind::NormalIndexOutOfRange {
                    index: i64::from(bad) + 1,
                    normal_count,
                },
            ));
        }
    }
    let vertex_count = mesh.positions.len();
    for (tri, &line) in mesh.triangles.iter().zip(&mesh.triangle_lines) {
        if let Some(&bad) = tri.iter().find(|&&i| i as usize >= vertex_count) {
            return Err(err(
                line,
                ObjErrorKind::IndexOutOfRange {
                    index: i64::from(bad) + 1,
                    vertex_count,
                },
            ));
        }
    }
    Ok((mesh, materials))
}

/// A token for error messages: lossy UTF-8, at most 40 characters.
fn show(token: &[u8]) -> String {
    let s = String::from_utf8_lossy(token);
    let mut out: String = s.chars().take(40).collect();
    if s.chars().nth(40).is_some() {
        out.push('…');
    }
    out
}

/// A statement's numbers: the first three, and how many there were.
fn parse_numbers<'t>(
    tokens: impl Iterator<Item = &'t [u8]>,
) -> Result<([f32; 3], usize), ObjErrorKind> {
    let mut xyz = [0.0f32; 3];
    let mut count = 0usize;
    for token in tokens {
        let x = parse_f32(token)?;
        if let Some(slot) = xyz.get_mut(count) {
            *slot = x;
        }
        count += 1;
    }
    Ok((xyz, count))
}

fn parse_f32(token: &[u8]) -> Result<f32, ObjErrorKind> {
    let bad = || ObjErrorKind::BadNumber { token: show(token) };
    let text = std::str::from_utf8(token).map_err(|_| bad())?;
    // Rust also accepts "inf", "NaN" and "infinity"; OBJ numbers are plain decimals.
    if !text
        .bytes()
        .all(|b| b.is_ascii_digit() || matches!(b, b'+' | b'-' | b'.' | b'e' | b'E'))
    {
        return Err(bad());
    }
    let x: f32 = text.parse().map_err(|_| bad())?;
    if x.is_finite() {
        Ok(x)
    } else {
        Err(ObjErrorKind::NonFinite { token: show(token) })
    }
}

/// Parses a non-zero OBJ index (`Ok(None)` for an empty field).
fn parse_index(field: &[u8], entry: &[u8]) -> Result<Option<i64>, ObjErrorKind> {
    if field.is_empty() {
        return Ok(None);
    }
    let bad = || ObjErrorKind::BadIndex { token: show(entry) };
    let text = std::str::from_utf8(field).map_err(|_| bad())?;
    let i: i64 = text.parse().map_err(|_| bad())?;
    if i == 0 {
        return Err(ObjErrorKind::ZeroIndex);
    }
    Ok(Some(i))
}

/// One face entry (`v`, `v/vt`, `v//vn`, `v/vt/vn`) to a 0-based vertex index and, if it
/// names one, a 0-based normal index. Positive indices are returned unchecked (see
/// [`parse_obj`]); negative ones are resolved against the vertices (`vertices`) and normals
/// (`normals`) defined so far.
fn parse_face_entry(
    entry: &[u8],
    vertices: usize,
    normals: usize,
) -> Result<(u32, Option<u32>), ObjErrorKind> {
    let mut fields = entry.split(|&b| b == b'/');
    let v = fields.next().unwrap_or_default();
    let vt = fields.next().unwrap_or_default();
    let vn = fields.next().unwrap_or_default();
    let bad = || ObjErrorKind::BadIndex { token: show(entry) };
    if fields.next().is_some() {
        return Err(bad());
    }
    // vt is not used, but must be well-formed when present.
    parse_index(vt, entry)?;
    let normal = match parse_index(vn, entry)? {
        None => None,
        Some(index) => Some(zero_based(index, normals).ok_or(
            ObjErrorKind::NormalIndexOutOfRange {
                index,
                normal_count: normals,
            },
        )?),
    };
    let index = parse_index(v, entry)?.ok_or_else(bad)?;
    let vertex = zero_based(index, vertices).ok_or(ObjErrorKind::IndexOutOfRange {
        index,
        vertex_count: vertices,
    })?;
    Ok((vertex, normal))
}

/// A non-zero OBJ index as a 0-based one: positive ones unchecked against `defined`, negative
/// ones counted back from the `defined` entries so far. `None` if it cannot be an index.
fn zero_based(index: i64, defined: usize) -> Option<u32> {
    let zero_based = if index > 0 {
        index - 1
    } else {
        // -1 is the last entry defined so far.
        let back = index.unsigned_abs();
        match u64::try_from(defined) {
            Ok(d) if back <= d => (d - back) as i64,
            _ => return None,
        }
    };
    // u32::MAX is the hit files' "miss" id, so ids stay below it.
    u32::try_from(zero_based).ok().filter(|&i| i < u32::MAX)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn face_entry_forms_resolve_to_the_vertex_index() {
        for entry in [
            "3", "3/1", "3//2", "3/1/2", "-2", "-2/1", "-2//1", "-2/-1/-1",
        ] {
            assert!(
                matches!(parse_face_entry(entry.as_bytes(), 4, 2), Ok((2, _))),
                "{entry}"
            );
        }
    }

    #[test]
    fn face_entry_rejects_malformed_fields() {
        for entry in [
            "", "/", "//", "1/2/3/4", "x", "1/x", "1//x", "1.5", "+", "1/ 2",
        ] {
            assert!(
                matches!(
                    parse_face_entry(entry.as_bytes(), 4, 2),
                    Err(ObjErrorKind::BadIndex { .. })
                ),
                "{entry}"
            );
        }
        assert!(matches!(
            parse_face_entry(b"1/0", 4, 2),
            Err(ObjErrorKind::ZeroIndex)
        ));
        assert!(matches!(
            parse_face_entry(b"-5", 4, 2),
            Err(ObjErrorKind::IndexOutOfRange {
                index: -5,
                vertex_count: 4
            })
        ));
        assert!(matches!(
            parse_face_entry(b"-9223372036854775808", 4, 2),
            Err(ObjErrorKind::IndexOutOfRange { .. })
        ));
        assert!(matches!(
            parse_face_entry(b"4294967296", 4, 2),
            Err(ObjErrorKind::IndexOutOfRange { .. })
        ));
    }

    #[test]
    fn face_entries_name_their_normal() {
        assert!(matches!(parse_face_entry(b"3", 4, 2), Ok((2, None))));
        assert!(matches!(parse_face_entry(b"3/1", 4, 2), Ok((2, None))));
        assert!(matches!(parse_face_entry(b"3//2", 4, 2), Ok((2, Some(1)))));
        assert!(matches!(
            parse_face_entry(b"3/1/-2", 4, 2),
            Ok((2, Some(0)))
        ));
        assert!(matches!(
            parse_face_entry(b"3//-3", 4, 2),
            Err(ObjErrorKind::NormalIndexOutOfRange {
                index: -3,
                normal_count: 2
            })
        ));
    }

    #[test]
    fn numbers_are_plain_finite_decimals() {
        assert!(matches!(parse_f32(b"-1.5e2"), Ok(x) if x == -150.0));
        assert!(matches!(parse_f32(b"+.5"), Ok(x) if x == 0.5));
        for bad in ["inf", "NaN", "1,5", "0x10", "--1", ""] {
            assert!(
                matches!(
                    parse_f32(bad.as_bytes()),
                    Err(ObjErrorKind::BadNumber { .. })
                ),
                "{bad}"
            );
        }
        assert!(matches!(
            parse_f32(b"1e39"),
            Err(ObjErrorKind::NonFinite { .. })
        ));
    }

    #[test]
    fn long_tokens_are_shortened_in_messages() {
        let long = [b'a'; 100];
        assert_eq!(show(&long).chars().count(), 41);
        assert_eq!(show(b"\xff1"), "\u{fffd}1");
    }
}
