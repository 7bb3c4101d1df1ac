//! Panic-freedom check for the renderer in fixed-point (`I16F16`) mode: see `src/render_probe.rs`.
#![no_std]
#![no_main]

use raykernel::I16F16;

#[path = "../panic_check.rs"]
mod panic_check;
#[path = "../render_probe.rs"]
mod render_probe;

#[cortex_m_rt::entry]
fn main() -> ! {
    render_probe::run::<I16F16>()
}
