//! The OBJ reader: accepted forms, triangle order, every error with its line, and no panic on
//! any input.

mod common;

use common::{temp_dir, Rng};
use host::obj::{load_obj, parse_obj, Mesh, ObjError, ObjErrorKind};
use raykernel::I16F16;
use std::path::Path;

fn parse(text: &str) -> Result<Mesh, ObjError> {
    parse_obj(text.as_bytes(), Path::new("scene.obj"))
}

fn mesh(text: &str) -> Mesh {
    parse(text).unwrap_or_else(|e| panic!("{e}"))
}

fn error(text: &str) -> ObjError {
    match parse(text) {
        Ok(m) => panic!("parsed, expected an error: {m:?}"),
        Err(e) => e,
    }
}

const QUAD: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";

#[test]
fn every_face_entry_form_gives_the_same_triangle() {
    for face in [
        "f 1 2 3",
        "f 1/1 2/2 3/3",
        "f 1//1 2//2 3//3",
        "f 1/1/1 2/2/2 3/3/3",
        "f -4 -3 -2",
        "f -4/-1 -3/-1 -2/-1",
        "f -4//-1 -3//-1 -2//-1",
        "f -4/-1/-1 -3/-1/-1 -2/-1/-1",
        "f 1/1 -3//2 3/3/3",
    ] {
        let m = mesh(&format!("{QUAD}vn 0 0 1\nvn 0 1 0\nvn 1 0 0\n{face}\n"));
        assert_eq!(m.triangles, vec![[0, 1, 2]], "{face}");
        assert_eq!(m.triangle_lines, vec![8], "{face}");
    }
}

#[test]
fn faces_keep_their_vertex_normals() {
    let normals = "vn 0 0 1\nvn 0 1 0\nvn 1 0 0\n";
    // A face without normals before the first with them, a quad with them (both fan
    // triangles), and one whose entries name normals only in part (flat).
    let m = mesh(&format!(
        "{QUAD}{normals}f 1 2 3\nf 1//3 2//2 3//1 4//-1\nf 1//1 2 3\n"
    ));
    assert_eq!(
        m.normals,
        vec![[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]]
    );
    assert_eq!(
        m.triangle_normals,
        vec![None, Some([2, 1, 0]), Some([2, 0, 2]), None]
    );
    assert_eq!(m.vertex_normals(0), [[0.0; 3]; 3]);
    assert_eq!(
        m.vertex_normals(1),
        [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    );
    assert!(m.has_normals());
    assert!(!mesh(&format!("{QUAD}{normals}f 1 2 3\n")).has_normals());
}

#[test]
fn bad_vertex_normals_name_their_line() {
    let e = error(&format!("{QUAD}vn 0 1\nf 1 2 3\n"));
    assert_eq!(e.line, Some(5));
    assert!(
        matches!(e.kind, ObjErrorKind::NormalArity { count: 2 }),
        "{e}"
    );
    let e = error(&format!("{QUAD}vn 0 1 0\nf 1//1 2//2 3//1\n"));
    assert_eq!(e.line, Some(6));
    assert!(
        matches!(
            e.kind,
            ObjErrorKind::NormalIndexOutOfRange {
                index: 2,
                normal_count: 1
            }
        ),
        "{e}"
    );
    let e = error(&format!("{QUAD}f 1//-1 2//-1 3//-1\n"));
    assert!(
        e.to_string()
            .contains("normal index -1 out of range (0 normals available)"),
        "{e}"
    );
}

#[test]
fn vertices_parse_as_f32_with_optional_w_or_colour() {
    let m = mesh("v 1.5 -2e-3 +7\nv 1 2 3 1.0\nv 4 5 6 0.1 0.2 0.3\nf 1 2 3\n");
    assert_eq!(
        m.positions,
        vec![[1.5, -2e-3, 7.0], [1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]
    );
    assert_eq!(m.position_lines, vec![1, 2, 3]);
    // The same bits as Rust's (and Python's) shortest round trip.
    let m = mesh("v 0.1 16777217 3.40282347e+38\nf 1 1 1\n");
    assert_eq!(m.positions[0], [0.1f32, 16_777_216.0, f32::MAX]);
}

#[test]
fn polygons_are_fan_triangulated_in_file_order() {
    let m = mesh(&format!(
        "{QUAD}v 0.5 2 0\nf 1 2 3\nf 1 2 3 4 5\nf 4 3 2 1\n"
    ));
    assert_eq!(
        m.triangles,
        vec![
            [0, 1, 2],
            [0, 1, 2],
            [0, 2, 3],
            [0, 3, 4],
            [3, 2, 1],
            [3, 1, 0],
        ]
    );
    assert_eq!(m.triangle_lines, vec![6, 7, 7, 7, 8, 8]);
    assert_eq!(
        m.triangle_f32(2),
        [[0.0; 3], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]]
    );
}

#[test]
fn negative_indices_count_back_from_the_vertices_so_far() {
    let m = mesh("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\nv 0 0 1\nf -1 -2 -3\n");
    assert_eq!(m.triangles, vec![[0, 1, 2], [3, 2, 1]]);
}

#[test]
fn positive_indices_may_point_forward() {
    let m = mesh("f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n");
    assert_eq!(m.triangles, vec![[0, 1, 2]]);
}

#[test]
fn other_statements_comments_and_blank_lines_are_ignored() {
    let text = "# header\r\n\
                mtllib scene.mtl\r\n\
                o thing\n\
                g group one\n\
                \n   \t\n\
                v 0 0 0 # trailing comment\n\
                v 1 0 0\n\
                v 0 1 0\n\
                vt 0.5 0.5\n\
                vn 0 0 1\n\
                vp 0.1\n\
                s off\n\
                usemtl red\n\
                l 1 2\n\
                curv2 1 2\n\
                f 1/1/1 2/1/1 3/1/1\r\n\
                #f 1 2 3\n\
                \tf\t3 2 1  \n";
    let m = mesh(text);
    assert_eq!(m.triangles, vec![[0, 1, 2], [2, 1, 0]]);
    assert_eq!(m.triangle_lines, vec![17, 19]);
}

/// One error case: OBJ text, expected line, expected kind, expected message fragment.
type ErrorCase = (&'static str, usize, fn(&ObjErrorKind) -> bool, &'static str);

/// Each error kind, at the line it is on, and its message in `path:LINE: message` form.
#[test]
fn errors_name_the_file_line_and_problem() {
    let cases: [ErrorCase; 11] = [
        (
            "v 1 2 x\nf 1 1 1\n",
            1,
            |k| matches!(k, ObjErrorKind::BadNumber { token } if token == "x"),
            "malformed number `x`",
        ),
        (
            "v 0 0 0\nv 1 2 1e39\n",
            2,
            |k| matches!(k, ObjErrorKind::NonFinite { .. }),
            "not a finite f32",
        ),
        (
            "v 0 0 0\nv 1 nan 0\n",
            2,
            |k| matches!(k, ObjErrorKind::BadNumber { .. }),
            "malformed number `nan`",
        ),
        (
            "# c\nv 1 2\n",
            2,
            |k| matches!(k, ObjErrorKind::VertexArity { count: 2 }),
            "vertex has 2 numbers",
        ),
        (
            "v 0 0 0\nf 1 1 1\nv 1 2 3 4 5\n",
            3,
            |k| matches!(k, ObjErrorKind::VertexArity { count: 5 }),
            "vertex has 5 numbers",
        ),
        (
            "v 0 0 0\n\nf 1 0 1\n",
            3,
            |k| matches!(k, ObjErrorKind::ZeroIndex),
            "index 0",
        ),
        (
            "v 0 0 0\nf 1 1/0 1\n",
            2,
            |k| matches!(k, ObjErrorKind::ZeroIndex),
            "index 0",
        ),
        (
            "v 0 0 0\nf 1 1 -2\n",
            2,
            |k| {
                matches!(
                    k,
                    ObjErrorKind::IndexOutOfRange {
                        index: -2,
                        vertex_count: 1
                    }
                )
            },
            "vertex index -2 out of range (1 vertices available)",
        ),
        (
            "v 0 0 0\nf 1 1 1\nf 1 4 1\nv 1 1 1\n",
            3,
            |k| {
                matches!(
                    k,
                    ObjErrorKind::IndexOutOfRange {
                        index: 4,
                        vertex_count: 2
                    }
                )
            },
            "vertex index 4 out of range (2 vertices available)",
        ),
        (
            "v 0 0 0\nf 1 1.0 1\n",
            2,
            |k| matches!(k, ObjErrorKind::BadIndex { token } if token == "1.0"),
            "malformed face entry `1.0`",
        ),
        (
            "v 0 0 0\nv 1 1 1\nf 1 2\n",
            3,
            |k| matches!(k, ObjErrorKind::TooFewVertices { count: 2 }),
            "face has 2 vertices",
        ),
    ];
    for (text, line, kind, message) in cases {
        let e = error(text);
        assert_eq!(e.line, Some(line), "{text:?}: {e}");
        assert!(kind(&e.kind), "{text:?}: {e:?}");
        let shown = e.to_string();
        assert!(
            shown.starts_with(&format!("scene.obj:{line}: ")) && shown.contains(message),
            "{text:?}: {shown}"
        );
    }
}

#[test]
fn a_file_without_faces_is_an_error_at_its_end() {
    for (text, line) in [
        ("", 1),
        ("v 0 0 0\nv 1 1 1\n", 2),
        ("# nothing\nv 1 2 3", 2),
    ] {
        let e = error(text);
        assert!(matches!(e.kind, ObjErrorKind::NoTriangles), "{e:?}");
        assert_eq!(e.line, Some(line), "{text:?}");
        assert!(e.to_string().contains("no faces"), "{e}");
    }
}

#[test]
fn empty_and_slashed_face_entries_are_malformed() {
    for face in [
        "f 1 2 3/4/5/6",
        "f 1 2 /",
        "f 1 2 //3",
        "f 1 2 3/x",
        "f 1 2 3//y",
    ] {
        let e = error(&format!("{QUAD}{face}\n"));
        assert!(
            matches!(e.kind, ObjErrorKind::BadIndex { .. }),
            "{face}: {e:?}"
        );
        assert_eq!(e.line, Some(5));
    }
}

#[test]
fn unreadable_file_names_the_path() {
    let missing = temp_dir("obj_missing").join("nope.obj");
    let e = load_obj(&missing).unwrap_err();
    assert!(matches!(e.kind, ObjErrorKind::Read(_)), "{e:?}");
    assert_eq!(e.line, None);
    let shown = e.to_string();
    assert!(shown.starts_with(&missing.display().to_string()), "{shown}");
    assert!(shown.contains("cannot read"), "{shown}");

    let present = missing.with_file_name("tri.obj");
    std::fs::write(&present, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    assert_eq!(load_obj(&present).unwrap().triangles, vec![[0, 1, 2]]);
}

#[test]
fn vertices_out_of_fixed_range_are_reported_at_their_line() {
    let m = mesh("v 0 0 0\nv 1 0 0\nv 9000 0 0\nv 0 1 0\nf 1 2 4\nf 1 2 3\n");
    assert!(m.kernel_triangles::<f32>(Path::new("s.obj")).is_ok());
    let e = m
        .kernel_triangles::<I16F16>(Path::new("s.obj"))
        .unwrap_err();
    assert_eq!(e.line, Some(3));
    assert!(
        matches!(
            e.kind,
            ObjErrorKind::UnusableVertex {
                triangle: 1,
                mode: "fixed",
                ..
            }
        ),
        "{e:?}"
    );
    let shown = e.to_string();
    assert!(
        shown.starts_with("s.obj:3: ") && shown.contains("fixed"),
        "{shown}"
    );
}

/// Whatever the bytes, the parser returns (no panic), and any mesh it returns is consistent.
#[test]
fn arbitrary_bytes_never_panic() {
    const PIECES: [&[u8]; 20] = [
        b"v",
        b"f",
        b" ",
        b"\n",
        b"\r\n",
        b"-",
        b"1",
        b"2",
        b"/",
        b"//",
        b"#",
        b"0",
        b".",
        b"e",
        b"9999999999",
        b"-2147483649",
        b"vt",
        b"\t",
        b"\xff",
        b"3",
    ];
    let mut rng = Rng::new(0xF022);
    let check = |bytes: &[u8]| {
        if let Ok(m) = parse_obj(bytes, Path::new("fuzz.obj")) {
            assert!(!m.triangles.is_empty());
            assert_eq!(m.triangles.len(), m.triangle_lines.len());
            assert_eq!(m.positions.len(), m.position_lines.len());
            let n = m.positions.len();
            assert!(m.triangles.iter().flatten().all(|&i| (i as usize) < n));
            assert!(m.positions.iter().flatten().all(|x| x.is_finite()));
        }
    };
    for _ in 0..20_000 {
        // Raw random bytes.
        let len = rng.below(64);
        let raw: Vec<u8> = (0..len).map(|_| rng.next_u64() as u8).collect();
        check(&raw);
        // OBJ-like token soup, which reaches the statement parsers.
        let mut soup = Vec::new();
        for _ in 0..rng.below(40) {
            soup.extend_from_slice(PIECES[rng.below(PIECES.len())]);
        }
        check(&soup);
    }
    // Mutations of a valid file.
    let valid = format!("{QUAD}f 1 2 3 4\nf -1/2/3 -2//1 -3\n").into_bytes();
    for _ in 0..20_000 {
        let mut m = valid.clone();
        for _ in 0..=rng.below(4) {
            let i = rng.below(m.len());
            match rng.below(3) {
                0 => m[i] = rng.next_u64() as u8,
                1 => {
                    m.remove(i);
                }
                _ => m.insert(i, PIECES[rng.below(PIECES.len())][0]),
            }
        }
        check(&m);
    }
}

#[test]
fn a_byte_order_mark_changes_nothing() {
    for text in [
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\nf -1 -2 -3\n",
    ] {
        let with = mesh(&format!("\u{feff}{text}"));
        assert_eq!(with, mesh(text));
        assert_eq!(with.positions[0], [0.0, 0.0, 0.0]);
    }
    let dir = temp_dir("obj_bom");
    let path = dir.join("bom.obj");
    std::fs::write(&path, b"\xef\xbb\xbfv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    assert_eq!(load_obj(&path).unwrap().triangle_count(), 1);
}

#[test]
fn special_files_are_refused_before_reading() {
    let e = load_obj(Path::new("/dev/zero")).unwrap_err();
    assert_eq!(
        e.to_string(),
        "/dev/zero: cannot read OBJ file: is a device, not a regular file"
    );
    let dir = temp_dir("obj_special");
    let e = load_obj(&dir).unwrap_err();
    assert!(
        e.to_string()
            .ends_with("is a directory, not a regular file"),
        "{e}"
    );
}
