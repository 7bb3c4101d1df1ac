//! Which instruction set the traversal hot loop runs in.
//!
//! On `x86_64` targets not already compiled for AVX2, the wide BVHs' traversals
//! ([`crate::Bvh4`], [`crate::Bvh8`]) exist twice: as compiled for the target, and compiled for
//! AVX2 (with BMI1, BMI2, LZCNT and POPCNT). The first query detects the CPU's features
//! (`cpuid`, and `xgetbv` for the operating system's support of the 256-bit registers) and
//! every query from then on runs the AVX2 copy where they are present. Both copies perform the
//! same IEEE operations in the same order (the 4-wide lanes are the same 128-bit operations,
//! VEX-encoded; the 8-wide box test runs in 256-bit lanes, each doing one 128-bit lane's
//! operations; no fused multiply-add is enabled), so they return the same bits;
//! `kernel/tests/cpu.rs` compares them.
//! Other targets have one copy and [`traversal_simd`] is always [`Simd::Baseline`].

/// An instruction set the traversal can run in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Simd {
    /// What the target was compiled for (SSE2 on a plain `x86_64` build, NEON on `aarch64`,
    /// scalar code on the Cortex-M cores).
    Baseline,
    /// AVX2 code: the `x86_64` copy compiled for AVX2, BMI1, BMI2, LZCNT and POPCNT, or the
    /// target's own code where the target is compiled for AVX2.
    Avx2,
}

impl Simd {
    /// A short name for reports: `baseline` or `avx2`.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::Baseline => "baseline",
            Self::Avx2 => "avx2",
        }
    }
}

/// The instruction set queries run in on this CPU (detected on first use).
#[must_use]
pub fn traversal_simd() -> Simd {
    if avx2() || cfg!(all(target_arch = "x86_64", target_feature = "avx2")) {
        Simd::Avx2
    } else {
        Simd::Baseline
    }
}

/// Requests an instruction set for the queries that follow (every thread) and returns the one
/// now in effect: the request takes effect only where the target has both copies and, for
/// [`Simd::Avx2`], the CPU has the features. Results do not depend on the choice; this is for
/// comparing the copies, or for ruling one out.
pub fn set_traversal_simd(simd: Simd) -> Simd {
    #[cfg(all(target_arch = "x86_64", not(target_feature = "avx2")))]
    {
        let choice = match simd {
            Simd::Avx2 if detect::detected() => detect::AVX2,
            _ => detect::NO_AVX2,
        };
        detect::STATE.store(choice, core::sync::atomic::Ordering::Relaxed);
    }
    let _ = simd;
    traversal_simd()
}

/// True if queries run the AVX2 copy. A load and a compare once detection has run.
#[inline(always)]
pub(crate) fn avx2() -> bool {
    #[cfg(all(target_arch = "x86_64", not(target_feature = "avx2")))]
    {
        match detect::STATE.load(core::sync::atomic::Ordering::Relaxed) {
            detect::AVX2 => true,
            detect::NO_AVX2 => false,
            _ => detect::first_use(),
        }
    }
    #[cfg(not(all(target_arch = "x86_64", not(target_feature = "avx2"))))]
    {
        false
    }
}

/// True if the CPU has every feature the AVX2 copy is compiled for, whatever copy queries run
/// (for unit tests of code that only that copy calls).
#[cfg(all(test, target_arch = "x86_64"))]
pub(crate) fn avx2_present() -> bool {
    #[cfg(target_feature = "avx2")]
    {
        true
    }
    #[cfg(not(target_feature = "avx2"))]
    {
        detect::detected()
    }
}

#[cfg(all(target_arch = "x86_64", not(target_feature = "avx2")))]
mod detect {
    use core::arch::x86_64::{__cpuid_count, _xgetbv, CpuidResult};
    use core::sync::atomic::{AtomicU8, Ordering};

    pub(super) const UNKNOWN: u8 = 0;
    pub(super) const NO_AVX2: u8 = 1;
    pub(super) const AVX2: u8 = 2;

    /// [`UNKNOWN`] until the first query, then [`AVX2`] or [`NO_AVX2`]. Threads racing on the
    /// first use store the same value.
    pub(super) static STATE: AtomicU8 = AtomicU8::new(UNKNOWN);

    #[cold]
    #[inline(never)]
    pub(super) fn first_use() -> bool {
        let found = detected();
        STATE.store(if found { AVX2 } else { NO_AVX2 }, Ordering::Relaxed);
        found
    }

    #[allow(unsafe_code, unused_unsafe)]
    fn cpuid(leaf: u32) -> CpuidResult {
        // SAFETY: every x86_64 processor has `cpuid`; leaves above the maximum return
        // unspecified values, which the callers avoid by checking the maximum first.
        unsafe { __cpuid_count(leaf, 0) }
    }

    /// True if the CPU has AVX2, BMI1, BMI2, LZCNT and POPCNT and the operating system saves
    /// the 256-bit registers (`XCR0` bits 1 and 2). Bits as in Intel's SDM, vol. 2A, `CPUID`.
    pub(super) fn detected() -> bool {
        let bit = |word: u32, b: u32| word >> b & 1 == 1;
        if cpuid(0).eax < 7 || cpuid(0x8000_0000).eax < 0x8000_0001 {
            return false;
        }
        let basic = cpuid(1);
        let (osxsave, avx, popcnt) = (bit(basic.ecx, 27), bit(basic.ecx, 28), bit(basic.ecx, 23));
        if !(osxsave && avx && popcnt) {
            return false;
        }
        #[allow(unsafe_code)]
        // SAFETY: OSXSAVE is set, so `xgetbv` is enabled and register 0 (XCR0) readable.
        let xcr0 = unsafe { xcr0() };
        let leaf7 = cpuid(7);
        let (avx2, bmi1, bmi2) = (bit(leaf7.ebx, 5), bit(leaf7.ebx, 3), bit(leaf7.ebx, 8));
        let lzcnt = bit(cpuid(0x8000_0001).ecx, 5);
        xcr0 & 0b110 == 0b110 && avx2 && bmi1 && bmi2 && lzcnt
    }

    /// # Safety
    /// The CPU must report OSXSAVE.
    #[allow(unsafe_code)]
    #[target_feature(enable = "xsave")]
    unsafe fn xcr0() -> u64 {
        _xgetbv(0)
    }
}
