//! Baked trees: bake, load in place, and check untrusted bytes.
//! - round trip: for both modes, both tree kinds, leaf order and several leaf sizes, the loaded
//!   tree is the built one (same nodes, ids, triangles, depth) and answers every ray bit for bit
//!   as the built tree and brute force do;
//! - every header byte and a sample of node, id and triangle bytes corrupted (checksum fixed
//!   up, so the deeper checks are reached): a typed error, or a tree that answers like brute
//!   force over its own triangles;
//! - alignment, length, checksum, mode and kind are refused with their errors.

mod common;

use common::{query, same_hit, TestScalar};
use raykernel::baked::{
    checksum, load_bvh, load_bvh4, read_header, BakedKind, BakedScalar, HEADER_LEN, MAX_ALIGN,
};
use raykernel::bvh::{nodes_needed, BuildOptions};
use raykernel::{Accel, AnyAccel, BakeError, Baked, Bvh, Linear, Node, Ray, Triangle, I16F16};
use raykernel_testkit::memory::OwnedMemory;
use raykernel_testkit::Rng;

/// A byte buffer whose `bytes()` start at a multiple of [`MAX_ALIGN`] (plus `shift`).
struct Aligned {
    buf: Vec<u8>,
    start: usize,
    len: usize,
}

impl Aligned {
    fn new(bytes: &[u8], shift: usize) -> Self {
        let mut buf = vec![0u8; bytes.len() + 2 * MAX_ALIGN];
        let start = buf.as_ptr().align_offset(MAX_ALIGN) + shift;
        buf[start..start + bytes.len()].copy_from_slice(bytes);
        Self {
            buf,
            start,
            len: bytes.len(),
        }
    }
    fn bytes(&self) -> &[u8] {
        &self.buf[self.start..self.start + self.len]
    }
}

/// Random triangles in a 10-unit cube, some small, some long, a few degenerate.
fn soup<S: TestScalar>(rng: &mut Rng, n: usize) -> Vec<Triangle<S>> {
    (0..n)
        .map(|i| {
            let a = [0; 3].map(|_| rng.range(-5.0, 5.0));
            let size = if i % 7 == 0 { 4.0 } else { 0.6 };
            let mut v = [a, a, a];
            for p in &mut v[1..] {
                for k in 0..3 {
                    p[k] = (a[k] + rng.range(-size, size)).clamp(-6.0, 6.0);
                }
            }
            if i % 31 == 0 {
                v[2] = v[1];
            }
            Triangle::from_f32(v).unwrap()
        })
        .collect()
}

/// Rays through the soup's cube from outside and inside.
fn rays(rng: &mut Rng, n: usize) -> Vec<(String, [f32; 3], [f32; 3])> {
    (0..n)
        .map(|i| {
            let o = if i % 2 == 0 {
                [0; 3].map(|_| rng.range(-5.0, 5.0))
            } else {
                rng.unit_vec().map(|x| x * 12.0)
            };
            let target = [0; 3].map(|_| rng.range(-4.0, 4.0));
            let d = [0, 1, 2].map(|k| target[k] - o[k]);
            (format!("ray {i}: {o:?} -> {d:?}"), o, d)
        })
        .collect()
}

/// The triangles in id order (undoing leaf order), for brute force.
fn by_id<S: TestScalar>(
    prim_ids: &[u32],
    prims: &[Triangle<S>],
    leaf_order: bool,
) -> Vec<Triangle<S>> {
    if !leaf_order {
        return prims.to_vec();
    }
    let mut out = prims.to_vec();
    for (slot, &id) in prim_ids.iter().enumerate() {
        out[id as usize] = prims[slot];
    }
    out
}

/// Every ray: `a` and `b` answer bit for bit alike (closest with barycentrics, any hit).
fn same_answers<S: TestScalar, A: Accel<S>, B: Accel<S>>(
    a: &A,
    b: &B,
    rays: &[(String, [f32; 3], [f32; 3])],
) -> Result<(), String> {
    for (name, o, d) in rays {
        let Ok(ray) = Ray::<S>::from_f32(*o, *d, 0.0, f32::INFINITY) else {
            continue;
        };
        let got = query(a, &ray).map_err(|e| format!("{name}: {e}"))?;
        let want = query(b, &ray).map_err(|e| format!("{name}: {e}"))?;
        same_hit(&got, &want).map_err(|e| format!("{} {name}: {e}", S::NAME))?;
    }
    Ok(())
}

/// Builds a tree of `kind` over `tris` (through [`AnyAccel`], into exactly the memory it
/// needs) and hands it to `f`.
fn with_tree<S: TestScalar + BakedScalar, R>(
    tris: &[Triangle<S>],
    kind: BakedKind,
    options: BuildOptions,
    leaf_order: bool,
    f: impl FnOnce(&Baked<'_, S>) -> R,
) -> R {
    let accel = kind.accel(options);
    let mut own = tris.to_vec();
    let mut arena = OwnedMemory::<S>::for_kind(accel, tris);
    let mut memory = arena.memory();
    let built = if leaf_order {
        AnyAccel::build_in_leaf_order(accel, &mut own, &mut memory)
    } else {
        AnyAccel::build(accel, tris, &mut memory)
    }
    .unwrap_or_else(|e| panic!("{} build {accel}: {e}", S::NAME));
    f(&Baked::from_any(built).expect("a BVH kind builds a BVH"))
}

/// Builds over `tris` and bakes a tree of `kind`.
fn bake<S: TestScalar + BakedScalar>(
    tris: &[Triangle<S>],
    kind: BakedKind,
    options: BuildOptions,
    leaf_order: bool,
) -> Vec<u8> {
    with_tree(tris, kind, options, leaf_order, |tree| {
        let mut out = vec![0u8; tree.baked_len().unwrap()];
        assert_eq!(tree.bake(&mut out), Ok(out.len()));
        out
    })
}

fn round_trip<S: TestScalar + BakedScalar>() {
    let mut rng = Rng::new(0xBA4E_D001);
    let rays = rays(&mut rng, 400);
    for n in [0usize, 1, 2, 5, 300] {
        let tris = soup::<S>(&mut rng, n);
        let linear = Linear::new(&tris);
        for leaf in [1, 3, 8] {
            let options = BuildOptions {
                max_leaf_size: leaf,
                ..BuildOptions::default()
            };
            for leaf_order in [false, true] {
                let case = format!("{} n={n} leaf={leaf} leaf_order={leaf_order}", S::NAME);
                // Binary tree: the loaded one is the built one.
                let bytes = bake::<S>(&tris, BakedKind::Bvh, options, leaf_order);
                let file = Aligned::new(&bytes, 0);
                let loaded = load_bvh::<S>(file.bytes()).unwrap_or_else(|e| panic!("{case}: {e}"));
                let mut own = tris.clone();
                let mut nodes = vec![Node::<S>::EMPTY; nodes_needed(n)];
                let mut ids = vec![0u32; n];
                let built = if leaf_order {
                    Bvh::build_in_leaf_order(&mut own, &mut nodes, &mut ids, options)
                } else {
                    Bvh::build(&tris, &mut nodes, &mut ids, options)
                }
                .unwrap();
                assert_eq!(loaded.nodes(), built.nodes(), "{case}");
                assert_eq!(loaded.prim_ids(), built.prim_ids(), "{case}");
                assert_eq!(loaded.prims(), built.prims(), "{case}");
                assert_eq!(loaded.depth(), built.depth(), "{case}");
                same_answers(&loaded, &linear, &rays).unwrap_or_else(|e| panic!("{case}: {e}"));
                // 4-wide tree, also through `Baked::load`.
                let bytes4 = bake::<S>(&tris, BakedKind::Bvh4, options, leaf_order);
                let file4 = Aligned::new(&bytes4, 0);
                let wide = load_bvh4::<S>(file4.bytes()).unwrap_or_else(|e| panic!("{case}: {e}"));
                assert_eq!(wide.prim_ids(), built.prim_ids(), "{case}");
                same_answers(&wide, &linear, &rays).unwrap_or_else(|e| panic!("{case}: {e}"));
                let any = Baked::<S>::load(file4.bytes()).unwrap();
                assert_eq!(any.kind(), BakedKind::Bvh4, "{case}");
                same_answers(&any, &linear, &rays).unwrap_or_else(|e| panic!("{case}: {e}"));
            }
        }
    }
}

#[test]
fn loaded_trees_are_the_built_trees_f32() {
    round_trip::<f32>();
}

#[test]
fn loaded_trees_are_the_built_trees_fixed() {
    round_trip::<I16F16>();
}

/// Loads `bytes` as either kind; if it loads, it must answer like brute force over its own
/// triangles. Returns whether it loaded.
fn loads_and_agrees<S: TestScalar + BakedScalar>(
    bytes: &[u8],
    rays: &[(String, [f32; 3], [f32; 3])],
) -> Result<bool, String> {
    match Baked::<S>::load(bytes) {
        Err(_) => Ok(false),
        Ok(tree) => {
            let reference = by_id(tree.prim_ids(), tree.prims(), tree.is_leaf_order());
            same_answers(&tree, &Linear::new(&reference), rays)?;
            Ok(true)
        }
    }
}

/// Writes the checksum the bytes need.
fn fix_checksum(bytes: &mut [u8]) {
    let sum = checksum(bytes);
    bytes[52..56].copy_from_slice(&sum.to_le_bytes());
}

fn corruption<S: TestScalar + BakedScalar>() {
    let mut rng = Rng::new(0xC0_44_u64);
    let rays = rays(&mut rng, 120);
    let tris = soup::<S>(&mut rng, 40);
    for kind in [BakedKind::Bvh, BakedKind::Bvh4] {
        for leaf_order in [false, true] {
            let good = bake::<S>(&tris, kind, BuildOptions::default(), leaf_order);
            let (mut loaded, mut refused) = (0usize, 0usize);
            let mut check = |bytes: &[u8], what: &str| {
                let file = Aligned::new(bytes, 0);
                match loads_and_agrees::<S>(file.bytes(), &rays) {
                    Ok(true) => loaded += 1,
                    Ok(false) => refused += 1,
                    Err(e) => panic!("{} {kind:?} leaf_order={leaf_order} {what}: {e}", S::NAME),
                }
            };
            // Every header byte: a few values each, with and without the checksum fixed.
            for at in 0..HEADER_LEN {
                for value in [
                    good[at] ^ 1,
                    good[at] ^ 0x80,
                    0,
                    0xFF,
                    good[at].wrapping_add(2),
                ] {
                    let mut bad = good.clone();
                    bad[at] = value;
                    check(&bad, &format!("header byte {at} = {value:#x}"));
                    if !(52..56).contains(&at) {
                        fix_checksum(&mut bad);
                        check(
                            &bad,
                            &format!("header byte {at} = {value:#x}, checksum fixed"),
                        );
                    }
                }
            }
            // A sample of the node, id and triangle bytes (about 600 positions), bit flips and
            // byte values, checksum fixed.
            let step = ((good.len() - HEADER_LEN) / 600).max(1);
            for at in (HEADER_LEN..good.len()).step_by(step) {
                for value in [good[at] ^ (1 << rng.below(8)), 0, 0xFF, 0x7F] {
                    let mut bad = good.clone();
                    bad[at] = value;
                    let mut unfixed = bad.clone();
                    if bad != good {
                        let file = Aligned::new(&unfixed, 0);
                        assert!(
                            matches!(
                                Baked::<S>::load(file.bytes()),
                                Err(BakeError::BadChecksum { .. })
                            ),
                            "byte {at} changed without the checksum"
                        );
                    }
                    fix_checksum(&mut bad);
                    check(&bad, &format!("byte {at} = {value:#x}, checksum fixed"));
                    unfixed.clear();
                }
            }
            // Truncated and extended files.
            for len in [0, 8, HEADER_LEN - 1, HEADER_LEN, good.len() - 1] {
                check(&good[..len], &format!("first {len} bytes"));
            }
            let mut longer = good.clone();
            longer.extend([0; 4]);
            check(&longer, "4 bytes appended");
            assert!(
                refused > 0 && loaded > 0,
                "{kind:?}: {loaded} loaded, {refused} refused"
            );
        }
    }
}

#[test]
fn corrupted_files_are_refused_or_answer_like_brute_force_f32() {
    corruption::<f32>();
}

#[test]
fn corrupted_files_are_refused_or_answer_like_brute_force_fixed() {
    corruption::<I16F16>();
}

#[test]
fn alignment_length_checksum_mode_and_kind_are_checked() {
    let mut rng = Rng::new(7);
    let tris = soup::<f32>(&mut rng, 50);
    for kind in [BakedKind::Bvh, BakedKind::Bvh4] {
        let bytes = bake::<f32>(&tris, kind, BuildOptions::default(), false);
        let header = read_header(&bytes).unwrap();
        assert_eq!((header.kind, header.prim_count), (kind, 50));
        for shift in [4, 16] {
            let file = Aligned::new(&bytes, shift);
            let err = Baked::<f32>::load(file.bytes()).unwrap_err();
            let required = kind.align();
            if shift % required != 0 {
                assert_eq!(err, BakeError::Misaligned { required });
            }
        }
        let file = Aligned::new(&bytes, 0);
        assert_eq!(
            Baked::<I16F16>::load(file.bytes()).unwrap_err(),
            BakeError::WrongStructure
        );
        let other = match kind {
            BakedKind::Bvh => load_bvh4::<f32>(file.bytes()).map(|_| ()),
            BakedKind::Bvh4 => load_bvh::<f32>(file.bytes()).map(|_| ()),
        };
        assert_eq!(other.unwrap_err(), BakeError::WrongStructure);
        let short = Aligned::new(&bytes[..bytes.len() - 36], 0);
        assert!(matches!(
            Baked::<f32>::load(short.bytes()),
            Err(BakeError::WrongLength { .. })
        ));
        let mut flipped = bytes.clone();
        *flipped.last_mut().unwrap() ^= 1;
        let file = Aligned::new(&flipped, 0);
        assert!(matches!(
            Baked::<f32>::load(file.bytes()),
            Err(BakeError::BadChecksum { .. })
        ));
        let mut small = vec![0u8; bytes.len() - 1];
        let tiny = with_tree(&tris, kind, BuildOptions::default(), false, |tree| {
            tree.bake(&mut small)
        });
        assert_eq!(
            tiny,
            Err(BakeError::Truncated {
                needed: bytes.len(),
                available: bytes.len() - 1
            })
        );
    }
}
