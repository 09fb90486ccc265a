//! Arithmetic of the small fixed-size vectors of one particle: positions, velocities, normals.

/// a·b.
pub fn dot<const D: usize>(a: [f64; D], b: [f64; D]) -> f64 {
    (0..D).map(|d| a[d] * b[d]).sum()
}

/// |a|.
pub fn norm<const D: usize>(a: [f64; D]) -> f64 {
    dot(a, a).sqrt()
}

/// a/|a|, or zero.
pub fn unit<const D: usize>(a: [f64; D]) -> [f64; D] {
    let len = norm(a);
    if len > 0.0 {
        a.map(|v| v / len)
    } else {
        a
    }
}
