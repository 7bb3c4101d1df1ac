//! Nearest-first order of an 8-wide node's hit children, in the integer lanes of one AVX2
//! vector: a bitonic sorting network (six compare-exchange steps of shuffle, `min`, `max` and
//! blend) instead of an insertion whose data-dependent branches incoherent rays mispredict.
//!
//! A child's sort key is the order bits of its entry distance (`Numerics::order_bits`) with
//! their lowest three replaced by its slot number: distinct for distinct slots, so entries that
//! differ in those three bits alone go by slot. Visit order is a matter of speed only: closest
//! hit keeps the lowest primitive id among equal distances whatever the order, and any hit asks
//! only whether something is hit.

/// The bitonic network, step by step: `(distance, takes_max)`. In a step each lane meets the
/// lane `distance` away within its aligned group of `2·distance` (lane `i ^ distance`), and
/// keeps the larger key where bit `i` of `takes_max` is set, else the smaller. Pairs are sorted
/// up, down, up, down; then each half merged, up and down; then the whole merged up.
const NETWORK: [(usize, i32); 6] = [
    (1, 0b0110_0110),
    (2, 0b0011_1100),
    (1, 0b0101_1010),
    (4, 0b1111_0000),
    (2, 0b1100_1100),
    (1, 0b1010_1010),
];

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
        // A step of `NETWORK`: the partner by an in-lane shuffle (distance 1 or 2) or by
        // swapping the 128-bit halves (4).
        macro_rules! exchange {
            ($step:literal) => {
                let partner = match NETWORK[$step].0 {
                    1 => _mm256_shuffle_epi32::<0b10_11_00_01>(v),
                    2 => _mm256_shuffle_epi32::<0b01_00_11_10>(v),
                    _ => _mm256_permute2x128_si256::<0x01>(v, v),
                };
                v = _mm256_blend_epi32::<{ NETWORK[$step].1 }>(
                    _mm256_min_epu32(v, partner),
                    _mm256_max_epu32(v, partner),
                );
            };
        }
        exchange!(0);
        exchange!(1);
        exchange!(2);
        exchange!(3);
        exchange!(4);
        exchange!(5);
        let mut out = [0u32; 8];
        _mm256_storeu_si256(out.as_mut_ptr().cast(), v);
        out
    }
}

#[cfg(test)]
mod tests {
    use super::{slot_of, NETWORK};
    use crate::scalar::xorshift;

    /// The sort key of `slot` entered at order bits `bits` (module docs).
    fn key(bits: u32, slot: u32) -> u32 {
        (bits & !7) | slot
    }

    /// The keys [`super::sorted8_avx2`] sorts: the hit slots' keys, `u32::MAX` elsewhere.
    fn keys(bits: &[u32; 8], hit: u32) -> [u32; 8] {
        core::array::from_fn(|i| {
            if hit >> i & 1 == 1 {
                key(bits[i], i as u32)
            } else {
                u32::MAX
            }
        })
    }

    /// [`NETWORK`] run lane by lane, as its docs read.
    fn network(mut v: [u32; 8]) -> [u32; 8] {
        for (distance, takes_max) in NETWORK {
            let before = v;
            for (i, x) in v.iter_mut().enumerate() {
                let partner = before[i ^ distance];
                *x = if takes_max >> i & 1 == 1 {
                    before[i].max(partner)
                } else {
                    before[i].min(partner)
                };
            }
        }
        v
    }

    /// Every hit mask, random order bits (a third from four values: ties, which the slot
    /// number breaks): `(bits, hit)`.
    fn cases() -> impl Iterator<Item = ([u32; 8], u32)> {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        (0u32..256).flat_map(move |hit| {
            let all: [[u32; 8]; 200] = core::array::from_fn(|_| {
                core::array::from_fn(|_| {
                    let r = xorshift(&mut state);
                    if r % 3 == 0 {
                        ((r >> 8) % 4) as u32 * 8
                    } else {
                        (r >> 32) as u32
                    }
                })
            });
            all.into_iter().map(move |bits| (bits, hit))
        })
    }

    /// The network sorts: its output is the keys in ascending order, whose first
    /// `hit.count_ones()` name every hit slot once.
    #[test]
    fn network_sorts_the_hit_keys() {
        for (bits, hit) in cases() {
            let got = network(keys(&bits, hit));
            let mut want = keys(&bits, hit);
            want.sort_unstable();
            assert_eq!(got, want, "hit {hit:08b}, bits {bits:x?}");
            let n = hit.count_ones() as usize;
            let seen = got[..n].iter().fold(0u32, |m, &k| m | 1 << slot_of(k));
            assert_eq!(seen, hit);
        }
    }

    /// The AVX2 lanes do what the network's table says, on a CPU that has them (the only
    /// CPUs the traversal calls them on; on others `network_sorts_the_hit_keys` still checks
    /// the table).
    #[test]
    fn avx2_lanes_run_the_network() {
        if !crate::cpu::avx2_present() {
            return;
        }
        for (bits, hit) in cases() {
            #[allow(unsafe_code)]
            // SAFETY: the CPU has AVX2 (checked above).
            let got = unsafe { super::sorted8_avx2(&bits, hit) };
            assert_eq!(
                got,
                network(keys(&bits, hit)),
                "hit {hit:08b}, bits {bits:x?}"
            );
        }
    }

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
}
