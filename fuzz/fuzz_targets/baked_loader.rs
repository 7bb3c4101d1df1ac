//! Baked files, arbitrary and mutated, through the in-place loader, in both number modes.
//!
//! The first byte steers: bit 0 the mode (f32 / fixed), bit 1 the tree kind, bit 2 whether the
//! rest is the file itself (arbitrary bytes) or a recipe (a small scene built and baked, then
//! overwritten at chosen positions), bit 3 whether the checksum is recomputed afterwards (so
//! mutations reach the checks behind it), bit 4 leaf order. Whatever loads must answer every
//! ray exactly as brute force over its own triangles does (closest hit bits, any hit); nothing
//! may panic.
#![no_main]

use libfuzzer_sys::fuzz_target;
use raykernel::baked::{checksum, BakedKind, BakedScalar, MAX_ALIGN};
use raykernel::bvh::BuildOptions;
use raykernel::{Accel, AnyAccel, Baked, Hit, Linear, Ray, Scalar, Triangle, I16F16};
use raykernel_testkit::memory::OwnedMemory;

/// Reads the input front to back; past the end everything is zero.
struct Bytes<'a> {
    data: &'a [u8],
    pos: usize,
}

impl Bytes<'_> {
    fn u8(&mut self) -> u8 {
        let b = self.data.get(self.pos).copied().unwrap_or(0);
        self.pos += 1;
        b
    }
    fn u16(&mut self) -> u16 {
        u16::from_le_bytes([self.u8(), self.u8()])
    }
    /// A quarter-unit grid coordinate: ties, shared vertices, axis-aligned edges.
    fn coord(&mut self) -> f32 {
        f32::from(self.u8() as i8) * 0.25
    }
    fn left(&self) -> bool {
        self.pos < self.data.len()
    }
}

fuzz_target!(|data: &[u8]| {
    let Some((&ctl, rest)) = data.split_first() else {
        return;
    };
    if ctl & 1 == 0 {
        run::<f32>(ctl, rest);
    } else {
        run::<I16F16>(ctl, rest);
    }
});

fn run<S: BakedScalar>(ctl: u8, rest: &[u8]) {
    let kind = if ctl & 2 == 0 {
        BakedKind::Bvh
    } else {
        BakedKind::Bvh4
    };
    let mut input = Bytes { data: rest, pos: 0 };
    let mut file = if ctl & 4 != 0 {
        rest.to_vec()
    } else {
        let n = 1 + usize::from(input.u8() % 40);
        let tris: Vec<Triangle<S>> = (0..n)
            .filter_map(|_| {
                let v = [0; 3].map(|_| [0; 3].map(|_| input.coord()));
                Triangle::from_f32(v).ok()
            })
            .collect();
        let leaf = 1 + u32::from(input.u8() % 8);
        let Some(mut file) = bake(&tris, kind, leaf, ctl & 16 != 0) else {
            return;
        };
        // Overwrite: (position, value) pairs until the input runs out.
        while input.left() {
            let at = usize::from(input.u16());
            let value = input.u8();
            if !file.is_empty() {
                let len = file.len();
                file[at % len] = value;
            }
        }
        file
    };
    if ctl & 8 != 0 && file.len() >= 56 {
        let sum = checksum(&file);
        file[52..56].copy_from_slice(&sum.to_le_bytes());
    }
    let mut buf = vec![0u8; file.len() + MAX_ALIGN];
    let start = buf.as_ptr().align_offset(MAX_ALIGN);
    buf[start..start + file.len()].copy_from_slice(&file);
    let bytes = &buf[start..start + file.len()];
    let Ok(tree) = Baked::<S>::load(bytes) else {
        return;
    };
    let (ids, prims, leaf_order) = (tree.prim_ids(), tree.prims(), tree.is_leaf_order());
    let mut by_id = prims.to_vec();
    if leaf_order {
        for (slot, &id) in ids.iter().enumerate() {
            by_id[id as usize] = prims[slot];
        }
    }
    let linear = Linear::new(&by_id);
    for i in 0..24u32 {
        let o = [
            (i % 5) as f32 * 9.0 - 18.0,
            (i % 3) as f32 * 7.0 - 7.0,
            -40.0,
        ];
        let d = [
            ((i * 7) % 11) as f32 - 5.0,
            ((i * 5) % 9) as f32 - 4.0,
            20.0,
        ];
        let Ok(ray) = Ray::<S>::from_f32(o, d, 0.0, f32::INFINITY) else {
            continue;
        };
        let (got, want) = (tree.intersect(&ray), linear.intersect(&ray));
        assert_eq!(
            bits(&got),
            bits(&want),
            "ray {i}: {got:?} vs brute force {want:?}"
        );
        assert_eq!(tree.occluded(&ray), want.is_some(), "ray {i}: any hit");
    }
}

/// The bits of a hit (t, prim, u, v).
fn bits<S: Scalar>(h: &Option<Hit<S>>) -> Option<(u32, u32, u32, u32)> {
    h.map(|h| {
        (
            h.t.to_f32().to_bits(),
            h.prim,
            h.u.to_f32().to_bits(),
            h.v.to_f32().to_bits(),
        )
    })
}

/// A baked tree of `kind` over `tris`.
fn bake<S: BakedScalar>(
    tris: &[Triangle<S>],
    kind: BakedKind,
    leaf: u32,
    leaf_order: bool,
) -> Option<Vec<u8>> {
    let options = BuildOptions {
        max_leaf_size: leaf,
        ..BuildOptions::default()
    };
    let accel = kind.accel(options);
    let mut own = tris.to_vec();
    let mut arena = OwnedMemory::<S>::sized(accel.memory_needed(tris).ok()?);
    let mut memory = arena.memory();
    let built = if leaf_order {
        AnyAccel::build_in_leaf_order(accel, &mut own, &mut memory)
    } else {
        AnyAccel::build(accel, tris, &mut memory)
    }
    .ok()?;
    let tree = Baked::from_any(built)?;
    let mut out = vec![0u8; tree.baked_len()?];
    tree.bake(&mut out).ok()?;
    Some(out)
}
