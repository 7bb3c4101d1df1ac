//! Ray and hit files: exact round trips, little-endian layout, and length errors.

mod common;

use common::{temp_dir, Rng};
use host::rayfile::{
    encode_hits, encode_rays, every, parse_hits, parse_rays, read_hits, read_rays, write_hits,
    write_rays, FileError,
};
use host::{HitRecord, RayRecord};
use std::path::Path;

fn some_rays() -> Vec<RayRecord> {
    let mut rng = Rng::new(7);
    let mut rays: Vec<RayRecord> = (0..100)
        .map(|_| RayRecord {
            origin: [0, 1, 2].map(|_| rng.range_f64(-100.0, 100.0) as f32),
            dir: rng.direction(),
            t_min: rng.range_f64(0.0, 1.0) as f32,
            t_max: f32::INFINITY,
        })
        .collect();
    rays.push(RayRecord {
        origin: [-0.0, f32::MIN_POSITIVE, f32::MAX],
        dir: [0.0; 3],
        t_min: 0.0,
        t_max: 1e-30,
    });
    rays
}

fn bits(r: &RayRecord) -> [u32; 8] {
    let f = [r.origin, r.dir, [r.t_min, r.t_max, 0.0]].concat();
    std::array::from_fn(|i| f[i].to_bits())
}

#[test]
fn ray_records_are_eight_little_endian_f32() {
    let r = RayRecord {
        origin: [1.0, 2.0, 3.0],
        dir: [0.0, 0.0, -1.0],
        t_min: 0.5,
        t_max: f32::INFINITY,
    };
    let b = r.to_bytes();
    assert_eq!(&b[0..4], &1.0f32.to_le_bytes());
    assert_eq!(&b[20..24], &(-1.0f32).to_le_bytes());
    assert_eq!(&b[28..32], &[0x00, 0x00, 0x80, 0x7F]);
    assert_eq!(RayRecord::from_bytes(&b), r);
}

#[test]
fn hit_records_are_t_then_prim_and_misses_are_inf_and_max() {
    assert_eq!(
        HitRecord::MISS.to_bytes(),
        [0x00, 0x00, 0x80, 0x7F, 0xFF, 0xFF, 0xFF, 0xFF]
    );
    let h = HitRecord {
        t: 2.5,
        prim: 0x0102_0304,
    };
    assert_eq!(h.to_bytes(), [0, 0, 0x20, 0x40, 4, 3, 2, 1]);
    assert_eq!(HitRecord::from_bytes(&h.to_bytes()), h);
    assert!(h.is_hit() && !HitRecord::MISS.is_hit());
}

#[test]
fn rays_round_trip_through_files_bit_for_bit() {
    let dir = temp_dir("ray_files_rays");
    let rays = some_rays();
    let path = dir.join("a.rays");
    write_rays(&path, &rays).unwrap();
    assert_eq!(
        std::fs::metadata(&path).unwrap().len(),
        32 * rays.len() as u64
    );
    let back = read_rays(&path).unwrap();
    assert_eq!(back.len(), rays.len());
    for (a, b) in rays.iter().zip(&back) {
        assert_eq!(bits(a), bits(b));
    }
    assert_eq!(encode_rays(&back), std::fs::read(&path).unwrap());
    // Empty files are valid: no rays.
    write_rays(&path, &[]).unwrap();
    assert!(read_rays(&path).unwrap().is_empty());
}

#[test]
fn hits_round_trip_through_files_bit_for_bit() {
    let dir = temp_dir("ray_files_hits");
    let hits = vec![
        HitRecord { t: 1.25, prim: 0 },
        HitRecord::MISS,
        HitRecord {
            t: 3e-7,
            prim: 69_629,
        },
        HitRecord {
            t: 0.0,
            prim: u32::MAX - 1,
        },
    ];
    let path = dir.join("a.hits");
    write_hits(&path, &hits).unwrap();
    assert_eq!(read_hits(&path).unwrap(), hits);
    assert_eq!(encode_hits(&hits), std::fs::read(&path).unwrap());
}

#[test]
fn lengths_that_are_not_whole_records_are_rejected() {
    let rays = encode_rays(&some_rays()[..3]);
    for cut in [1, 4, 31] {
        let e = parse_rays(&rays[..rays.len() - cut], Path::new("x.rays")).unwrap_err();
        assert!(
            matches!(e, FileError::Length { len, record: 32, what: "ray", .. } if len == 96 - cut),
            "{e:?}"
        );
        let shown = e.to_string();
        assert!(
            shown.starts_with("x.rays: ") && shown.contains("not a multiple of 32"),
            "{shown}"
        );
    }
    let e = parse_hits(&[0u8; 12], Path::new("y.hits")).unwrap_err();
    assert!(e.to_string().contains("not a multiple of 8"), "{e}");
    assert_eq!(
        parse_hits(&[0u8; 16], Path::new("y.hits")).unwrap().len(),
        2
    );
}

#[test]
fn missing_and_unwritable_files_name_the_path() {
    let dir = temp_dir("ray_files_missing");
    let e = read_rays(&dir.join("none.rays")).unwrap_err();
    assert!(matches!(e, FileError::Read { .. }), "{e:?}");
    assert!(e.to_string().contains("none.rays: cannot read"), "{e}");
    let e = write_hits(&dir.join("no/such/dir.hits"), &[]).unwrap_err();
    assert!(matches!(e, FileError::Write { .. }), "{e:?}");
    assert!(e.to_string().contains("dir.hits: cannot write"), "{e}");
}

#[test]
fn every_gathers_the_records_a_stride_traces_in_order() {
    let rays = some_rays();
    let picked: Vec<[u32; 8]> = every(&rays, 7).iter().map(bits).collect();
    let expected: Vec<[u32; 8]> = (0..rays.len()).step_by(7).map(|i| bits(&rays[i])).collect();
    assert_eq!(picked.len(), rays.len().div_ceil(7));
    assert_eq!(picked, expected);
    // Stride 1 keeps every record, and stride 0 counts as 1.
    for stride in [0, 1] {
        let all: Vec<[u32; 8]> = every(&rays, stride).iter().map(bits).collect();
        assert_eq!(all, rays.iter().map(bits).collect::<Vec<_>>());
    }
}
