//! On-target renders (defmt-test under QEMU): every built-in scene in both modes, rendered row
//! by row and hashed, must equal the host's golden hashes (`tests/golden/kernel_hashes.txt`);
//! and the stack a render uses. A binary of its own: with the kernel tests it would not fit
//! the 256 KB of flash of the smaller machines. Runs on the M4F and M3 (64 KB of RAM); a
//! render needs about 20 KB of stack, more than the M0's 16 KB.
#![no_std]
#![no_main]

use cortex_m_rt as _;
use defmt_semihosting as _;
use panic_probe as _;

use raykernel::render::scenes;
use raykernel::I16F16;
use raykernel_qemu::{cases, check_render_golden, stack};

#[defmt::panic_handler]
fn defmt_panic() -> ! {
    panic_probe::hard_fault()
}

/// The default handler spins, so QEMU would hang until the runner's timeout: exit instead.
#[cortex_m_rt::exception]
unsafe fn HardFault(_: &cortex_m_rt::ExceptionFrame) -> ! {
    semihosting::process::exit(101)
}

#[defmt_test::tests]
mod tests {
    use super::*;

    #[test]
    fn golden_render_cornell_f32() {
        check_render_golden("render_cornell_f32")
    }
    #[test]
    fn golden_render_cornell_fixed() {
        check_render_golden("render_cornell_fixed")
    }
    #[test]
    fn golden_render_spheres_f32() {
        check_render_golden("render_spheres_f32")
    }
    #[test]
    fn golden_render_spheres_fixed() {
        check_render_golden("render_spheres_fixed")
    }
    #[test]
    fn golden_render_motion_f32() {
        check_render_golden("render_motion_f32")
    }
    #[test]
    fn golden_render_motion_fixed() {
        check_render_golden("render_motion_fixed")
    }
    /// Stack used by a whole render (scene conversion, per-object BVH builds, renderer, one
    /// row of pixels) of the default scene, printed for the footprint table.
    #[test]
    fn render_stack_high_water_mark() {
        let used = |f: fn() -> bool| stack::stack_use(|| defmt::assert!(f()));
        let f = used(|| cases::render_hash::<f32>(&scenes::CORNELL).is_ok());
        let x = used(|| cases::render_hash::<I16F16>(&scenes::CORNELL).is_ok());
        defmt::println!(
            "render stack high-water: f32 {=usize} B, fixed {=usize} B",
            f,
            x
        );
        defmt::assert!(f.max(x) < 32 * 1024, "over 32 KB of stack");
    }
}
