//! On-target renders in f32 (defmt-test under QEMU): every built-in scene, rendered row by
//! row and hashed, must equal the host's golden hash (`tests/golden/kernel_hashes.txt`); and
//! the stack a render uses. One binary per mode: both modes and every accelerator of the
//! renderer do not fit the 256 KB of flash of the smaller machines in one binary.
#![no_std]
#![no_main]

use cortex_m_rt as _;
use defmt_semihosting as _;
use panic_probe as _;

use raykernel::render::scenes;
use raykernel_qemu::{cases, check_render_golden, render_hash, stack};

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

    /// Paints the free stack, so that a test after the renders can report their peak.
    #[init]
    fn init() {
        stack::paint(cortex_m::register::msp::read() as usize - 256);
    }

    #[test]
    fn golden_render_cornell_f32() {
        check_render_golden::<f32>("render_cornell_f32", &scenes::CORNELL)
    }
    #[test]
    fn golden_render_spheres_f32() {
        check_render_golden::<f32>("render_spheres_f32", &scenes::SPHERES)
    }
    #[test]
    fn golden_render_motion_f32() {
        check_render_golden::<f32>("render_motion_f32", &scenes::MOTION)
    }
    #[test]
    fn golden_render_cornell_path_f32() {
        check_render_golden::<f32>("render_cornell_path_f32", &cases::CORNELL_PATH)
    }
    #[test]
    fn golden_render_emitters_f32() {
        check_render_golden::<f32>("render_emitters_f32", &cases::EMITTERS)
    }
    #[test]
    fn golden_render_emitters_path_f32() {
        check_render_golden::<f32>("render_emitters_path_f32", &cases::EMITTERS_PATH)
    }
    /// How much of the RAM the golden renders left free (the stack was painted by `init`).
    /// Fails when less than 512 bytes stay free, before an overflow would.
    #[test]
    fn stack_headroom_of_the_golden_renders() {
        let top = stack::stack_top();
        let low = stack::lowest_used(top);
        let free = low - stack::stack_bottom();
        defmt::info!(
            "stack peak of the renders: {=usize} B used, {=usize} B free",
            top - low,
            free
        );
        defmt::assert!(free >= 512, "only {=usize} bytes of stack left", free);
    }
    /// Stack used by a whole render (scene conversion, per-object BVH builds, renderer, one
    /// row of pixels) of the default scene, printed for the footprint table.
    #[test]
    fn render_stack_high_water_mark() {
        let used =
            stack::stack_use(
                || defmt::assert!(render_hash::<f32>(&scenes::CORNELL).is_ok()),
            );
        defmt::println!("render stack high-water (f32): {=usize} B", used);
    }
}
