//! The SPH Laplacian of Eq. (27) on a lattice, as the PPE applies it, and the linear fit the
//! pressure gradient takes its reference from near a free surface.

use crate::common::Lattice;
use isph::particles::Kind;
use isph::sph::{fitted_value, laplacian_coefficient, Neighbours};

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

/// A half lattice, y ≤ 0 (the row at y = 0 the free surface), in 2D and 3D.
fn half_lattice<const D: usize>(n: i64) -> Lattice<D> {
    let half = n / 2;
    let points = (0..(n as usize).pow(D as u32)).filter_map(|k| {
        let mut rest = k as i64;
        let index: [i64; D] = std::array::from_fn(|_| {
            let c = rest % n;
            rest /= n;
            c - half
        });
        (index[1] <= 0).then_some((index, Kind::Fluid))
    });
    Lattice::from_indices(points, 0.01, 1.2)
}

fn fitted_value_is_exact_for_linear_fields_and_blind_to_its_own<const D: usize>(n: i64) {
    let lat = half_lattice::<D>(n);
    let p = &lat.particles;
    let nb = Neighbours::new(&lat.grid, &p.pos, lat.kernel);
    // A hydrostatic-like field, P = 1000 − 9810 y + 300 x, at the surface row's centre and a
    // row below it (both truncated supports).
    let mut pressure: Vec<f64> = (0..p.len())
        .map(|i| 1000.0 - 9810.0 * p.pos[1][i] + 300.0 * p.pos[0][i])
        .collect();
    let centre = lat.centre();
    let below = (0..p.len())
        .find(|&i| {
            (p.pos[1][i] + 0.01).abs() < 1e-9 && (0..D).all(|d| d == 1 || p.pos[d][i].abs() < 1e-9)
        })
        .unwrap();
    for i in [centre, below] {
        let exact = pressure[i];
        let fitted = fitted_value(&nb, &pressure, i).expect("a full half support fixes a plane");
        assert!(
            (fitted - exact).abs() < 1e-9 * exact.abs(),
            "{D}D: {fitted} vs {exact}"
        );
        pressure[i] += 500.0;
        let blind = fitted_value(&nb, &pressure, i).unwrap();
        assert!(
            (blind - exact).abs() < 1e-9 * exact.abs(),
            "{D}D: own value leaked: {blind}"
        );
        pressure[i] = exact;
    }
}

#[test]
fn fitted_value_is_exact_for_linear_fields_and_ignores_the_particle_itself() {
    fitted_value_is_exact_for_linear_fields_and_blind_to_its_own::<2>(15);
    fitted_value_is_exact_for_linear_fields_and_blind_to_its_own::<3>(11);
}

#[test]
fn fitted_value_is_none_where_the_neighbours_fix_no_plane() {
    // Three particles on a line: the neighbours of the middle one cannot fix the slope across.
    let lat = Lattice::<2>::from_indices(
        [
            ([-1, 0], Kind::Fluid),
            ([0, 0], Kind::Fluid),
            ([1, 0], Kind::Fluid),
        ],
        0.01,
        1.2,
    );
    let p = &lat.particles;
    let nb = Neighbours::new(&lat.grid, &p.pos, lat.kernel);
    assert_eq!(fitted_value(&nb, &[1.0, 2.0, 3.0], lat.centre()), None);
}
