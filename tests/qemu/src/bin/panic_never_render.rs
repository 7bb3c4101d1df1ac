//! Panic-freedom check for the renderer in `f32` mode: see `src/render_probe.rs`.
#![no_std]
#![no_main]

#[path = "../panic_check.rs"]
mod panic_check;
#[path = "../render_probe.rs"]
mod render_probe;

#[cortex_m_rt::entry]
fn main() -> ! {
    render_probe::run::<f32>()
}
