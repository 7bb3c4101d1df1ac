//! Instructions executed, as QEMU counts them.
//!
//! The runners (`.cargo/config.toml`) start QEMU with `-icount shift=0`: the virtual clock then
//! advances exactly one nanosecond per guest instruction, independent of the host. Each core
//! reads that clock through what it has:
//!
//! - RISC-V: the `instret` CSR, which QEMU derives from the instruction count under `-icount`.
//! - Cortex-M: SysTick, a 24-bit down-counter clocked from the virtual clock at the machine's
//!   core frequency, so one tick is a fixed whole number of instructions; a SysTick exception
//!   counts the wraps.
//!
//! [`calibrate`] runs a loop of a known instruction count and returns the rate the programs
//! then convert ticks with (one instruction per tick on RISC-V; 1e9 / core clock on the
//! Cortex-M machines, e.g. 62.5 at 16 MHz), so the result does not rest on a documented
//! frequency. QEMU models no pipeline:
//! there is no cycle count beyond this.

/// Starts the counter (idempotent).
pub fn start() {
    imp::start();
}

/// Ticks since [`start`]: a monotonic count, a fixed number of instructions per tick.
#[must_use]
pub fn ticks() -> u64 {
    imp::ticks()
}

/// Runs exactly `2 * n` instructions (a two-instruction count-down loop), `n >= 1`.
#[inline(never)]
pub fn spin(n: u32) {
    imp::spin(n.max(1));
}

/// The counter's rate, measured by [`calibrate`]: `instructions` took `ticks`.
#[derive(Clone, Copy, Debug)]
pub struct Rate {
    pub instructions: u64,
    pub ticks: u64,
}

impl Rate {
    /// Instructions in `ticks` ticks, rounded to the nearest (exact on RISC-V, where a tick
    /// is an instruction; within one tick's worth on the Cortex-M machines).
    #[must_use]
    pub fn instructions(self, ticks: u64) -> u64 {
        let (i, t) = (u128::from(self.instructions), u128::from(self.ticks.max(1)));
        ((u128::from(ticks) * i + t / 2) / t) as u64
    }

    /// Instructions per tick in tenths, rounded.
    #[must_use]
    pub fn per_tick_tenths(self) -> u64 {
        self.instructions(10)
    }
}

/// Runs `spin(n)` and returns the rate it shows: `2 * n` instructions in the ticks it took.
#[must_use]
pub fn calibrate(n: u32) -> Rate {
    let t0 = ticks();
    spin(n);
    let dt = ticks() - t0;
    Rate {
        instructions: 2 * u64::from(n),
        ticks: dt,
    }
}

#[cfg(target_arch = "riscv32")]
mod imp {
    pub fn start() {}

    pub fn ticks() -> u64 {
        loop {
            let (hi, lo, hi2): (u32, u32, u32);
            // SAFETY: reading the user-level `instret`/`instreth` CSRs has no side effect.
            unsafe {
                core::arch::asm!(
                    "csrr {0}, instreth",
                    "csrr {1}, instret",
                    "csrr {2}, instreth",
                    out(reg) hi, out(reg) lo, out(reg) hi2,
                    options(nomem, nostack)
                );
            }
            if hi == hi2 {
                return (u64::from(hi) << 32) | u64::from(lo);
            }
        }
    }

    pub fn spin(n: u32) {
        // SAFETY: a register-only loop.
        unsafe {
            core::arch::asm!(
                "2:",
                "addi {0}, {0}, -1",
                "bnez {0}, 2b",
                inout(reg) n => _,
                options(nomem, nostack)
            );
        }
    }
}

#[cfg(target_arch = "arm")]
mod imp {
    use core::sync::atomic::{AtomicBool, AtomicU32, Ordering};
    use cortex_m::peripheral::{syst::SystClkSource, SCB, SYST};

    /// SysTick wraps (reloads from 0) counted by its exception.
    static WRAPS: AtomicU32 = AtomicU32::new(0);
    static STARTED: AtomicBool = AtomicBool::new(false);
    const RELOAD: u32 = 0x00ff_ffff;

    #[cortex_m_rt::exception]
    fn SysTick() {
        WRAPS.store(WRAPS.load(Ordering::Relaxed) + 1, Ordering::Relaxed);
    }

    pub fn start() {
        if STARTED.load(Ordering::Relaxed) {
            return;
        }
        let Some(mut p) = cortex_m::Peripherals::take() else {
            return;
        };
        p.SYST.set_clock_source(SystClkSource::Core);
        p.SYST.set_reload(RELOAD);
        p.SYST.clear_current();
        p.SYST.enable_interrupt();
        p.SYST.enable_counter();
        // Leave the cleared state: from here on every wrap is a 1 -> 0 step of the counter.
        while SYST::get_current() == 0 {}
        STARTED.store(true, Ordering::Relaxed);
    }

    pub fn ticks() -> u64 {
        loop {
            let w = WRAPS.load(Ordering::Relaxed);
            let pending = SCB::is_pendst_pending();
            let current = SYST::get_current();
            if SCB::is_pendst_pending() != pending || WRAPS.load(Ordering::Relaxed) != w {
                continue; // a wrap or its exception in between: read again
            }
            // Ticks into the current period: the step to 0 starts a period (and pends the
            // exception that counts it), so 0 is the period's first tick and 1 its last.
            let into_period = (RELOAD + 1 - current) & RELOAD;
            let periods = u64::from(w) + u64::from(pending);
            return (periods << 24) + u64::from(into_period);
        }
    }

    pub fn spin(n: u32) {
        // SAFETY: a register-only loop (`subs` with a low register: valid on Thumb-1 too).
        unsafe {
            core::arch::asm!(
                "2:",
                "subs r0, r0, #1",
                "bne 2b",
                inout("r0") n => _,
                options(nomem, nostack)
            );
        }
    }
}
