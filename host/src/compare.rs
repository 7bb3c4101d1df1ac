//! Agreement between two hit files, by the rule of `shared/bench/compare_hits.py`.
//!
//! Two records agree when the prim ids are equal and both miss, or both hit with
//! `|t₁ − t₂| <= rel · max(|t₁|, |t₂|)`.

use crate::rayfile::HitRecord;
use serde::Serialize;

/// The default relative tolerance on `t`, as in `compare_hits.py`.
pub const DEFAULT_REL: f64 = 1e-5;

/// Agreement of `other` with `reference`, ray by ray.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Comparison {
    /// Records compared.
    pub n: usize,
    /// % of rays with the same prim id (two misses count as the same).
    pub same_prim_pct: f64,
    /// % of rays with the same prim id and agreeing `t`.
    pub agree_pct: f64,
    /// % of rays whose `t` agrees (two misses agree), prim ignored.
    pub t_agree_pct: f64,
    /// Rays that one side hits and the other misses.
    pub hitmiss: usize,
    /// Rays whose `t` agrees but whose prim differs (ties on shared edges, duplicates).
    pub prim_only: usize,
    /// Hits in the reference.
    pub hits_ref: usize,
    /// Hits in the other file.
    pub hits_other: usize,
}

/// Compares two equally long hit lists (extra records of the longer one are ignored).
#[must_use]
pub fn compare_hits(reference: &[HitRecord], other: &[HitRecord], rel: f64) -> Comparison {
    let mut c = Comparison {
        n: reference.len().min(other.len()),
        same_prim_pct: 0.0,
        agree_pct: 0.0,
        t_agree_pct: 0.0,
        hitmiss: 0,
        prim_only: 0,
        hits_ref: 0,
        hits_other: 0,
    };
    let (mut same_prim, mut agree, mut t_agree) = (0usize, 0usize, 0usize);
    for (a, b) in reference.iter().zip(other) {
        let (ta, tb) = (f64::from(a.t), f64::from(b.t));
        let t_ok = match (a.is_hit(), b.is_hit()) {
            (true, true) => (ta - tb).abs() <= rel * ta.abs().max(tb.abs()),
            (false, false) => true,
            _ => {
                c.hitmiss += 1;
                false
            }
        };
        let same = a.prim == b.prim;
        c.hits_ref += usize::from(a.is_hit());
        c.hits_other += usize::from(b.is_hit());
        same_prim += usize::from(same);
        agree += usize::from(same && t_ok);
        t_agree += usize::from(t_ok);
        c.prim_only += usize::from(t_ok && !same);
    }
    let pct = |k: usize| {
        if c.n == 0 {
            100.0
        } else {
            100.0 * k as f64 / c.n as f64
        }
    };
    c.same_prim_pct = pct(same_prim);
    c.agree_pct = pct(agree);
    c.t_agree_pct = pct(t_agree);
    c
}

#[cfg(test)]
mod tests {
    use super::*;

    const fn hit(t: f32, prim: u32) -> HitRecord {
        HitRecord { t, prim }
    }

    #[test]
    fn counts_each_kind_of_difference() {
        let a = [
            hit(1.0, 1),
            hit(2.0, 2),
            HitRecord::MISS,
            hit(4.0, 4),
            hit(5.0, 5),
        ];
        let b = [
            hit(1.0, 1),       // agree
            hit(2.000_001, 3), // t within 1e-5, prim differs
            HitRecord::MISS,   // both miss: agree
            HitRecord::MISS,   // hit/miss
            hit(5.1, 5),       // same prim, t differs
        ];
        let c = compare_hits(&a, &b, DEFAULT_REL);
        assert_eq!((c.n, c.hitmiss, c.prim_only), (5, 1, 1));
        assert_eq!((c.hits_ref, c.hits_other), (4, 3));
        assert_eq!(c.same_prim_pct, 60.0);
        assert_eq!(c.agree_pct, 40.0);
        assert_eq!(c.t_agree_pct, 60.0);
    }
}
