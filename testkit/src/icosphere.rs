//! The regular icosahedron and the icospheres subdivided from it: closed meshes whose
//! neighbouring triangles share their vertices exactly.

use core::ops::Neg;

/// The icosahedron's 20 faces as corner indices into [`corners`], wound outwards.
pub const FACES: [[u32; 3]; 20] = [
    [0, 11, 5],
    [0, 5, 1],
    [0, 1, 7],
    [0, 7, 10],
    [0, 10, 11],
    [1, 5, 9],
    [5, 11, 4],
    [11, 10, 2],
    [10, 7, 6],
    [7, 1, 8],
    [3, 9, 4],
    [3, 4, 2],
    [3, 2, 6],
    [3, 6, 8],
    [3, 8, 9],
    [4, 9, 5],
    [2, 4, 11],
    [6, 2, 10],
    [8, 6, 7],
    [9, 8, 1],
];

/// The icosahedron's 12 corners (not normalised): the cyclic permutations of `(0, ±1, ±phi)`,
/// in the number type of the caller (`phi` is the golden ratio in that type).
pub fn corners<T: Copy + Neg<Output = T>>(zero: T, one: T, phi: T) -> [[T; 3]; 12] {
    [
        [-one, phi, zero],
        [one, phi, zero],
        [-one, -phi, zero],
        [one, -phi, zero],
        [zero, -one, phi],
        [zero, one, phi],
        [zero, -one, -phi],
        [zero, one, -phi],
        [phi, zero, -one],
        [phi, zero, one],
        [-phi, zero, -one],
        [-phi, zero, one],
    ]
}

/// A unit icosahedron subdivided `level` times: each edge's midpoint is pushed onto the sphere
/// and shared by index, so the mesh is closed and neighbours share edges exactly.
/// Returns unit-sphere vertices and `20·4^level` triangles.
#[cfg(feature = "std")]
pub fn unit_icosphere(level: u32) -> (std::vec::Vec<[f64; 3]>, std::vec::Vec<[u32; 3]>) {
    use crate::vec3::normalize;
    use std::collections::HashMap;
    use std::vec::Vec;

    let phi = (1.0 + libm::sqrt(5.0)) / 2.0;
    let mut verts: Vec<[f64; 3]> = corners(0.0, 1.0, phi).map(normalize).to_vec();
    let mut faces: Vec<[u32; 3]> = FACES.to_vec();
    for _ in 0..level {
        let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
        let mut next = Vec::with_capacity(faces.len() * 4);
        for &[a, b, c] in &faces {
            let mut m = |x: u32, y: u32| {
                *mid.entry((x.min(y), x.max(y))).or_insert_with(|| {
                    let (p, q) = (verts[x as usize], verts[y as usize]);
                    verts.push(normalize([0, 1, 2].map(|i| p[i] + q[i])));
                    verts.len() as u32 - 1
                })
            };
            let (ab, bc, ca) = (m(a, b), m(b, c), m(c, a));
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        faces = next;
    }
    (verts, faces)
}
