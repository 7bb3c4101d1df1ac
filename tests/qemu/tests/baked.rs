//! On-target test of baked trees: a 4-wide BVH baked on the host (`tests/golden/baked_ico.bvh4`,
//! written and checked by host/tests/bake.rs) is loaded in place from flash, with every check,
//! and the check grid traced through it gives the host's grid hash
//! (`tests/golden/baked_ico.grid_hash`); truncated or misaligned bytes are refused.
#![no_std]
#![no_main]

use cortex_m_rt as _; // defmt-test doesn't link it; the vector table and reset handler
use defmt_semihosting as _; // global logger: defmt frames to semihosting stdout
use panic_probe as _; // prints the panic via defmt, then `udf` -> HardFault

use raykernel::baked::load_bvh4;
use raykernel::{Accel, BakeError, Ray, Scalar};

#[defmt::panic_handler]
fn defmt_panic() -> ! {
    panic_probe::hard_fault()
}

/// The default handler spins, so QEMU would hang until the runner's timeout: exit instead.
#[cortex_m_rt::exception]
unsafe fn HardFault(_: &cortex_m_rt::ExceptionFrame) -> ! {
    semihosting::process::exit(101)
}

/// The baked bytes in flash, aligned as the loader needs.
#[repr(C, align(128))]
struct Aligned<T: ?Sized>(T);
static BAKED: &Aligned<[u8]> = &Aligned(*include_bytes!("../../golden/baked_ico.bvh4"));
const HASH: &str = include_str!("../../golden/baked_ico.grid_hash");

/// The check grid's hash (`capi/examples/common/grid_hash.h`, `host::bake::grid_hash`).
fn grid_hash<S: Scalar, A: Accel<S>>(accel: &A) -> u32 {
    const N: u32 = 32;
    let at = |i: u32| -1.5f32 + 3.0f32 * (i as f32 + 0.5) / N as f32;
    let mut h = 0x811c_9dc5u32;
    let mut eat = |word: u32, bytes: usize| {
        for b in word.to_le_bytes().into_iter().take(bytes) {
            h = (h ^ u32::from(b)).wrapping_mul(0x0100_0193);
        }
    };
    for k in 0..N * N {
        let d = [at(k % N), at(k / N), 10.0];
        let Ok(ray) = Ray::<S>::from_f32([0.0, 0.0, -10.0], d, 0.0, f32::INFINITY) else {
            continue;
        };
        let (prim, t) = accel
            .intersect(&ray)
            .map_or((u32::MAX, 0), |hit| (hit.prim, hit.t.to_f32().to_bits()));
        eat(prim, 4);
        eat(t, 4);
        eat(u32::from(accel.occluded(&ray)), 1);
    }
    h
}

#[defmt_test::tests]
mod tests {
    use super::*;

    #[test]
    fn baked_mesh_from_flash_gives_the_hosts_grid_hash() {
        let tree = load_bvh4::<f32>(&BAKED.0);
        defmt::assert!(tree.is_ok(), "load_bvh4 refused the baked file");
        let want = u32::from_str_radix(HASH.trim(), 16).unwrap_or(0);
        if let Ok(tree) = tree {
            let got = grid_hash(&tree);
            defmt::assert_eq!(got, want, "grid hash {=u32:x}, host {=u32:x}", got, want);
        }
    }

    #[test]
    fn truncated_and_misaligned_bytes_are_refused() {
        let bytes = &BAKED.0;
        let short = load_bvh4::<f32>(&bytes[..bytes.len() - 1]).map(|_| ());
        defmt::assert!(matches!(short, Err(BakeError::WrongLength { .. })));
        let shifted = load_bvh4::<f32>(&bytes[4..]).map(|_| ());
        defmt::assert!(shifted.is_err());
    }
}
