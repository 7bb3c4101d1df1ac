//! `f64` vector arithmetic on `[f64; 3]`, for references computed beside the kernel. Each
//! function evaluates left to right, so the same inputs give the same bits everywhere.

pub fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

pub fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `a + b·s`, component by component.
pub fn add_scaled(a: [f64; 3], b: [f64; 3], s: f64) -> [f64; 3] {
    [a[0] + b[0] * s, a[1] + b[1] * s, a[2] + b[2] * s]
}

pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `v` divided by its length (`v` must not be zero).
pub fn normalize(v: [f64; 3]) -> [f64; 3] {
    let l = libm::sqrt(dot(v, v));
    v.map(|x| x / l)
}

/// Each component rounded to the nearest `f32`.
pub fn to_f32(v: [f64; 3]) -> [f32; 3] {
    v.map(|x| x as f32)
}
