//! The SPH Laplacian of Eq. (27) on a lattice, as the PPE applies it.

use crate::common::Lattice;
use isph::sph::{laplacian_coefficient, Neighbours};

/// −Σ_j a_ij (φ_i − φ_j) at the lattice centre for φ = |x|², whose Laplacian is 2D.
fn laplacian_of_quadratic<const D: usize>(n: i64, h_over_dx: f64) -> f64 {
    let lat = Lattice::<D>::new(n, 0.01, h_over_dx);
    let p = &lat.particles;
    let phi: Vec<f64> = (0..p.len())
        .map(|i| (0..D).map(|d| p.pos[d][i].powi(2)).sum())
        .collect();
    let nb = Neighbours::new(&lat.grid, &p.pos, lat.kernel);
    let i = lat.centre();
    let mut lap = 0.0;
    nb.for_each(i, |j, _, r| {
        lap -= laplacian_coefficient(&nb, p, i, j, r) * (phi[i] - phi[j])
    });
    lap
}

#[test]
fn laplacian_of_a_quadratic_is_the_exact_constant() {
    for h_over_dx in [1.0, 1.2, 1.5] {
        let l2 = laplacian_of_quadratic::<2>(15, h_over_dx);
        let l3 = laplacian_of_quadratic::<3>(13, h_over_dx);
        assert!(
            (l2 / 4.0 - 1.0).abs() < 0.02,
            "2D h/dx {h_over_dx}: {l2} vs 4"
        );
        assert!(
            (l3 / 6.0 - 1.0).abs() < 0.02,
            "3D h/dx {h_over_dx}: {l3} vs 6"
        );
    }
}
