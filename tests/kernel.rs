//! The quintic kernel of Eq. (19): normalisation and the gradient of a linear field.

use crate::common::Lattice;
use isph::math::kernel::Quintic;
use isph::neighbours::Neighbours;

/// ∫W dV by the midpoint rule on a lattice of `n` points per h.
fn integral<const D: usize>(n: i64) -> f64 {
    let h = 1.0;
    let k = Quintic::<D>::new(h);
    let step = h / n as f64;
    let m = 3 * n;
    let count = (2 * m) as usize;
    let mut sum = 0.0;
    for idx in 0..count.pow(D as u32) {
        let mut rest = idx;
        let mut r2 = 0.0;
        for _ in 0..D {
            let c = (rest % count) as f64 - m as f64 + 0.5;
            rest /= count;
            r2 += (c * step).powi(2);
        }
        sum += k.w(r2.sqrt());
    }
    sum * step.powi(D as i32)
}

#[test]
fn integrates_to_one_in_2d_and_3d() {
    let i2 = integral::<2>(60);
    let i3 = integral::<3>(30);
    assert!((i2 - 1.0).abs() < 1e-6, "2D integral {i2}");
    assert!((i3 - 1.0).abs() < 1e-6, "3D integral {i3}");
}

#[test]
fn gradient_factor_is_the_derivative() {
    let k = Quintic::<3>::new(0.7);
    for r in [0.05, 0.3, 0.69, 0.71, 1.2, 1.5, 2.05] {
        let e = 1e-6;
        let dw = (k.w(r + e) - k.w(r - e)) / (2.0 * e);
        assert!(
            (k.grad_factor(r) * r - dw).abs() < 1e-6 * dw.abs().max(1e-3),
            "r = {r}"
        );
    }
}

/// Σ_j V_j (φ_j − φ_i) ∇W_ij of φ = a·x at the centre of a lattice (kernel sums, no correction).
fn linear_gradient<const D: usize>(n: i64) -> ([f64; D], [f64; D]) {
    let lat = Lattice::<D>::new(n, 0.01, 1.2);
    let a: [f64; D] = std::array::from_fn(|d| 1.0 + d as f64);
    let p = &lat.particles;
    let phi: Vec<f64> = (0..p.len())
        .map(|i| (0..D).map(|d| a[d] * p.pos[d][i]).sum())
        .collect();
    let nb = Neighbours::new(&lat.grid, &p.pos, lat.kernel);
    let i = lat.centre();
    let mut g = [0.0; D];
    nb.for_each(i, |j, rij, r| {
        let c = p.mass[j] / p.density[j] * (phi[j] - phi[i]) * lat.kernel.grad_factor(r);
        for d in 0..D {
            g[d] += c * rij[d];
        }
    });
    (g, a)
}

#[test]
fn gradient_of_a_linear_field_is_exact_inside_a_lattice() {
    let (g2, a2) = linear_gradient::<2>(15);
    let (g3, a3) = linear_gradient::<3>(11);
    for (g, a) in g2.iter().zip(&a2).chain(g3.iter().zip(&a3)) {
        assert!((g - a).abs() < 1e-3 * a.abs(), "gradient {g} vs {a}");
    }
}
