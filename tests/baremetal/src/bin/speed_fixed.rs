//! Instructions per ray and per pixel in fixed point (see `speed.rs`).
#![no_std]
#![no_main]

#[cfg_attr(target_arch = "riscv32", riscv_rt::entry)]
#[cfg_attr(target_arch = "arm", cortex_m_rt::entry)]
fn main() -> ! {
    raykernel_baremetal::speed::run::<raykernel::I16F16>()
}
