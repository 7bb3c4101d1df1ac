//! Nearest-first order of an 8-wide node's hit children, in the integer lanes of one AVX2
//! vector: a bitonic sorting network (six compare-exchange steps of shuffle, `min`, `max` and
//! blend) instead of an insertion whose data-dependent branches incoherent rays mispredict.
//!
//! A child's sort key is the order bits of its entry distance (`Numerics::order_bits`) with
//! their lowest three replaced by its slot number: distinct for distinct slots, so entries that
//! differ in those three bits alone go by slot. Visit order is a matter of speed only: closest
//! hit keeps the lowest primitive id among equal distances whatever the order, and any hit asks
//! only whether something is hit.

/// The slot number a [`sorted8_avx2`] key stands for.
#[inline(always)]
pub(super) fn slot_of(key: u32) -> u32 {
    key & 7
}

/// The keys of the slots in `hit` (`bits[slot]` made a key, module docs) in ascending order, then
/// `u32::MAX` for the slots not in `hit`: the first `hit.count_ones()` entries name the hit
/// slots nearest first.
///
/// # Safety
/// The CPU must have AVX2.
#[allow(unsafe_code)]
#[target_feature(enable = "avx,avx2")]
#[inline]
pub(super) unsafe fn sorted8_avx2(bits: &[u32; 8], hit: u32) -> [u32; 8] {
    use core::arch::x86_64::{
        _mm256_and_si256, _mm256_andnot_si256, _mm256_blend_epi32, _mm256_cmpeq_epi32,
        _mm256_loadu_si256, _mm256_max_epu32, _mm256_min_epu32, _mm256_or_si256,
        _mm256_permute2x128_si256, _mm256_set1_epi32, _mm256_setr_epi32, _mm256_shuffle_epi32,
        _mm256_storeu_si256,
    };
    // SAFETY: AVX2 is present (the caller's guarantee); the load and the store are of eight
    // `u32` inside an `[u32; 8]`.
    unsafe {
        let slot = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
        let bit = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
        let is_hit = _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(hit as i32), bit), bit);
        // `key` in every lane, then all ones where the slot is not hit.
        let keys = _mm256_or_si256(
            _mm256_and_si256(
                _mm256_loadu_si256(bits.as_ptr().cast()),
                _mm256_set1_epi32(!7),
            ),
            slot,
        );
        let mut v = _mm256_or_si256(keys, _mm256_andnot_si256(is_hit, _mm256_set1_epi32(-1)));
        // One compare-exchange step: each lane meets its partner at distance 1 or 2 (within
        // 128-bit halves) or 4 (across them), and keeps the larger key where `takes_max` has
        // its bit, else the smaller.
        macro_rules! exchange {
            ($distance:literal, $takes_max:literal) => {
                let partner = match $distance {
                    1 => _mm256_shuffle_epi32::<0b10_11_00_01>(v),
                    2 => _mm256_shuffle_epi32::<0b01_00_11_10>(v),
                    _ => _mm256_permute2x128_si256::<0x01>(v, v),
                };
                v = _mm256_blend_epi32::<$takes_max>(
                    _mm256_min_epu32(v, partner),
                    _mm256_max_epu32(v, partner),
                );
            };
        }
        // Pairs sorted up, down, up, down; then each half merged, up and down; then the whole
        // merged up.
        exchange!(1, 0b0110_0110);
        exchange!(2, 0b0011_1100);
        exchange!(1, 0b0101_1010);
        exchange!(4, 0b1111_0000);
        exchange!(2, 0b1100_1100);
        exchange!(1, 0b1010_1010);
        let mut out = [0u32; 8];
        _mm256_storeu_si256(out.as_mut_ptr().cast(), v);
        out
    }
}

#[cfg(test)]
mod tests {
    extern crate std;

    use super::{slot_of, sorted8_avx2};
    use crate::scalar::xorshift;

    /// `Numerics::order_bits` orders non-negative distances as they are ordered, in both
    /// modes (random pairs, many of them close or equal).
    #[test]
    fn order_bits_follow_the_distances() {
        use crate::scalar::sealed::Numerics;
        use crate::scalar::I16F16;
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        for _ in 0..100_000 {
            let r = xorshift(&mut state);
            let a = f32::from_bits((r >> 33) as u32 % 0x7f80_0001); // +0 to +inf
            let b = match r % 3 {
                0 => a,
                1 => f32::from_bits((a.to_bits() + (r >> 8) as u32 % 16).min(0x7f80_0000)),
                _ => f32::from_bits((r >> 1) as u32 % 0x7f80_0001),
            };
            assert_eq!(
                a.partial_cmp(&b).map(|o| o.is_le()),
                Some(f32::order_bits(a) <= f32::order_bits(b)),
                "{a:e} {b:e}"
            );
            let (x, y) = (I16F16((r >> 33) as i32), I16F16((r >> 2) as i32 & i32::MAX));
            assert_eq!(
                x <= y,
                I16F16::order_bits(x) <= I16F16::order_bits(y),
                "{x:?} {y:?}"
            );
        }
    }

    /// The sort key of `slot` entered at order bits `bits` (module docs).
    fn key(bits: u32, slot: u32) -> u32 {
        (bits & !7) | slot
    }

    /// The network against a plain sort of the same keys, on every hit mask and random order
    /// bits (many equal, to exercise the slot tie-break).
    #[test]
    fn network_sorts_the_hit_keys() {
        if !std::is_x86_feature_detected!("avx2") {
            // The traversal calls the network only on a CPU with AVX2.
            std::println!("skipped: no AVX2 on this CPU");
            return;
        }
        let mut state = 0x2545_f491_4f6c_dd1du64;
        for hit in 0u32..256 {
            for _ in 0..200 {
                let bits: [u32; 8] = core::array::from_fn(|_| {
                    let r = xorshift(&mut state);
                    // A third of the lanes from a handful of values (ties), the rest anything.
                    if r % 3 == 0 {
                        ((r >> 8) % 4) as u32 * 8
                    } else {
                        (r >> 32) as u32
                    }
                });
                let mut want: [u32; 8] = core::array::from_fn(|i| {
                    if hit >> i & 1 == 1 {
                        key(bits[i], i as u32)
                    } else {
                        u32::MAX
                    }
                });
                want.sort_unstable();
                // SAFETY: AVX2 is present (checked above).
                #[allow(unsafe_code)]
                let got = unsafe { sorted8_avx2(&bits, hit) };
                assert_eq!(got, want, "hit {hit:08b}, bits {bits:x?}");
                let n = hit.count_ones() as usize;
                let mut seen = 0u32;
                for &k in &got[..n] {
                    seen |= 1 << slot_of(k);
                }
                assert_eq!(seen, hit);
            }
        }
    }
}
