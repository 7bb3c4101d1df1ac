//! Linear radiance to 8-bit sRGB, exactly as the sRGB transfer function (IEC 61966-2-1) rounded to the nearest
//! byte (`round(255 · oetf(clamp(x, 0, 1)))`, with `libm::powf`), without calling `powf`: the
//! encoding is a non-decreasing step function of `x`, so it is the number of its 255 steps at or
//! below `x`, found from a bucket of `x`'s bits and a short count. The steps were found by
//! evaluating the formula on every `f32` in `[0, 1]`, and a test does so again against this
//! function.

/// `STEP_BITS[k - 1]` (as `f32` bits) is the least linear value that encodes to byte `k` or more.
const STEP_BITS: [u32; 255] = [
    0x391f22b3, 0x39eeb40e, 0x3a46eb61, 0x3a8b3e5d, 0x3ab3070b, 0x3adacfb7, 0x3b014c32, 0x3b153089,
    0x3b2914df, 0x3b3cf936, 0x3b50f2d1, 0x3b65fb9a, 0x3b7c3404, 0x3b89d05f, 0x3b962333, 0x3ba314be,
    0x3bb0a731, 0x3bbedcb7, 0x3bcdb76c, 0x3bdd3966, 0x3bed64ae, 0x3bfe3b44, 0x3c07df90, 0x3c10f919,
    0x3c1a6b32, 0x3c2436c7, 0x3c2e5cc7, 0x3c38de19, 0x3c43bba3, 0x3c4ef646, 0x3c5a8ee2, 0x3c668654,
    0x3c72dd74, 0x3c7f9512, 0x3c865703, 0x3c8d1490, 0x3c940396, 0x3c9b247c, 0x3ca277a8, 0x3ca9fd79,
    0x3cb1b654, 0x3cb9a299, 0x3cc1c2a9, 0x3cca16e3, 0x3cd29fa4, 0x3cdb5d4d, 0x3ce45034, 0x3ced78b7,
    0x3cf6d72f, 0x3d0035fc, 0x3d051bb6, 0x3d0a1cee, 0x3d0f39d1, 0x3d14728a, 0x3d19c745, 0x3d1f382c,
    0x3d24c56a, 0x3d2a6f24, 0x3d303586, 0x3d3618b9, 0x3d3c18e6, 0x3d423633, 0x3d4870cb, 0x3d4ec8d3,
    0x3d553e73, 0x3d5bd1d3, 0x3d628319, 0x3d69526a, 0x3d703fee, 0x3d774bce, 0x3d7e7627, 0x3d82df92,
    0x3d869374, 0x3d8a56cc, 0x3d8e29ad, 0x3d920c28, 0x3d95fe50, 0x3d9a0036, 0x3d9e11ed, 0x3da23385,
    0x3da66510, 0x3daaa6a1, 0x3daef847, 0x3db35a16, 0x3db7cc1c, 0x3dbc4e6c, 0x3dc0e115, 0x3dc5842a,
    0x3dca37ba, 0x3dcefbd6, 0x3dd3d08f, 0x3dd8b5f5, 0x3dddac19, 0x3de2b30a, 0x3de7cad9, 0x3decf395,
    0x3df22d4f, 0x3df7781a, 0x3dfcd3ff, 0x3e012088, 0x3e03dfaf, 0x3e06a77c, 0x3e0977f7, 0x3e0c5127,
    0x3e0f3314, 0x3e121dc6, 0x3e151144, 0x3e180d95, 0x3e1b12c2, 0x3e1e20d1, 0x3e2137cb, 0x3e2457b7,
    0x3e27809a, 0x3e2ab27c, 0x3e2ded67, 0x3e313160, 0x3e347e6f, 0x3e37d49d, 0x3e3b33ed, 0x3e3e9c68,
    0x3e420e14, 0x3e4588fa, 0x3e490d21, 0x3e4c9a8f, 0x3e50314b, 0x3e53d15c, 0x3e577ac9, 0x3e5b2d99,
    0x3e5ee9d2, 0x3e62af7c, 0x3e667e9d, 0x3e6a5740, 0x3e6e3964, 0x3e722512, 0x3e761a54, 0x3e7a192d,
    0x3e7e21a6, 0x3e8119e2, 0x3e8327c8, 0x3e853a86, 0x3e875222, 0x3e896e9d, 0x3e8b8ffc, 0x3e8db641,
    0x3e8fe170, 0x3e92118b, 0x3e944696, 0x3e968094, 0x3e98bf89, 0x3e9b0376, 0x3e9d4c61, 0x3e9f9a4b,
    0x3ea1ed38, 0x3ea4452a, 0x3ea6a226, 0x3ea9042c, 0x3eab6b43, 0x3eadd76b, 0x3eb048a9, 0x3eb2bf02,
    0x3eb53a72, 0x3eb7bb02, 0x3eba40b1, 0x3ebccb86, 0x3ebf5b81, 0x3ec1f0a8, 0x3ec48afa, 0x3ec72a7d,
    0x3ec9cf32, 0x3ecc791e, 0x3ecf2842, 0x3ed1dca3, 0x3ed49640, 0x3ed75521, 0x3eda1945, 0x3edce2b1,
    0x3edfb166, 0x3ee2856a, 0x3ee55ebc, 0x3ee83d62, 0x3eeb215c, 0x3eee0ab0, 0x3ef0f95d, 0x3ef3ed6a,
    0x3ef6e6d6, 0x3ef9e5a7, 0x3efce9e1, 0x3efff37e, 0x3f018146, 0x3f030b82, 0x3f049878, 0x3f062827,
    0x3f07ba92, 0x3f094fb9, 0x3f0ae7a0, 0x3f0c8244, 0x3f0e1fab, 0x3f0fbfd2, 0x3f1162be, 0x3f13086e,
    0x3f14b0e5, 0x3f165c22, 0x3f180a29, 0x3f19baf9, 0x3f1b6e96, 0x3f1d24fe, 0x3f1ede35, 0x3f209a3b,
    0x3f225913, 0x3f241abb, 0x3f25df37, 0x3f27a687, 0x3f2970ae, 0x3f2b3dab, 0x3f2d0d83, 0x3f2ee033,
    0x3f30b5be, 0x3f328e25, 0x3f346969, 0x3f36478c, 0x3f38288f, 0x3f3a0c74, 0x3f3bf33a, 0x3f3ddce5,
    0x3f3fc975, 0x3f41b8eb, 0x3f43ab48, 0x3f45a08f, 0x3f4798bf, 0x3f4993db, 0x3f4b91e2, 0x3f4d92d8,
    0x3f4f96bd, 0x3f519d92, 0x3f53a757, 0x3f55b410, 0x3f57c3bd, 0x3f59d65e, 0x3f5bebf6, 0x3f5e0485,
    0x3f60200d, 0x3f623e91, 0x3f64600b, 0x3f668486, 0x3f68abfa, 0x3f6ad671, 0x3f6d03e3, 0x3f6f345b,
    0x3f7167d0, 0x3f739e4d, 0x3f75d7ca, 0x3f781452, 0x3f7a53db, 0x3f7c9671, 0x3f7edc0e,
];

/// Buckets of the `f32` bit patterns from [`FIRST_BUCKET`] (2⁻¹³) up to 1.0, each 2¹⁸
/// patterns wide (1/32 of a binade): positive floats order as their bits do.
const FIRST_BUCKET: u32 = 0x3900_0000;
const BUCKET_SHIFT: u32 = 18;
const BUCKETS: usize = ((0x3f80_0000 - FIRST_BUCKET) >> BUCKET_SHIFT) as usize;

/// `START[b]`: the byte of bucket `b`'s lowest value (of 0 for bucket 0, which also takes every
/// value below it). The byte of any value in the bucket is at least this, and at most a few
/// steps more.
const START: [u8; BUCKETS] = {
    let mut out = [0u8; BUCKETS];
    let mut b = 1;
    while b < BUCKETS {
        let low = FIRST_BUCKET + ((b as u32) << BUCKET_SHIFT);
        let mut k = 0;
        while k < 255 && STEP_BITS[k] <= low {
            k += 1;
        }
        out[b] = k as u8;
        b += 1;
    }
    out
};

/// Linear radiance to an 8-bit sRGB value: 0 for NaN and values at or below 0, 255 from 1 up.
#[must_use]
#[inline]
pub fn encode_srgb8(linear: f32) -> u8 {
    if linear.is_nan() || linear <= 0.0 {
        return 0;
    }
    if linear >= 1.0 {
        return 255;
    }
    // A positive float below 1: its bits order as its value. Start at the bucket's byte and
    // count the steps between the bucket's lowest value and `linear`.
    let bits = linear.to_bits();
    let bucket = (bits.saturating_sub(FIRST_BUCKET) >> BUCKET_SHIFT) as usize;
    let mut k = START.get(bucket).map_or(255, |&b| usize::from(b));
    while STEP_BITS.get(k).is_some_and(|&step| step <= bits) {
        k += 1;
    }
    k as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The formula the table encodes.
    fn formula(linear: f32) -> u8 {
        let c = if linear > 0.0 { linear } else { 0.0 };
        let c = if c < 1.0 { c } else { 1.0 };
        let s = if c <= 0.003_130_8 {
            12.92 * c
        } else {
            1.055 * libm::powf(c, 1.0 / 2.4) - 0.055
        };
        (s * 255.0 + 0.5) as u8
    }

    #[test]
    fn table_equals_the_formula_on_every_f32_in_0_1() {
        for bits in 0..=1.0f32.to_bits() {
            let x = f32::from_bits(bits);
            assert_eq!(encode_srgb8(x), formula(x), "{x:e} ({bits:#010x})");
        }
    }

    #[test]
    fn outside_0_1() {
        for x in [-0.0, -1e-30, -1.0, f32::NEG_INFINITY, f32::NAN, -f32::NAN] {
            assert_eq!(encode_srgb8(x), 0, "{x}");
        }
        for x in [1.0, 1.0 + f32::EPSILON, 2.0, 1e30, f32::INFINITY] {
            assert_eq!(encode_srgb8(x), 255, "{x}");
            assert_eq!(formula(x), 255, "{x}");
        }
        assert!(STEP_BITS.windows(2).all(|w| w[0] < w[1]));
    }
}
