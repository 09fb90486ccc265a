//! The SPH Laplacian of Eq. (27) on a lattice, as the PPE applies it, and the linear fit the
//! pressure gradient takes its reference from near a free surface.

use crate::common::Lattice;
use isph::neighbours::Neighbours;
use isph::particles::Kind;
use isph::sph::{field_laplacian, fitted_value, fitted_values, laplacian_coefficient};

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

/// The lattice's sums of Eq. (27) give the constant to within 1e-3 at h/dx 1.0, 1.2 and 1.5 in
/// 2D and 3D (measured 7e-5 to 9.9e-4, 2026-12-06): the kernel's discrete second moment.
#[test]
fn laplacian_of_a_quadratic_is_its_constant_to_two_tenths_of_a_per_cent() {
    for h_over_dx in [1.0, 1.2, 1.5] {
        let l2 = laplacian_of_quadratic::<2>(15, h_over_dx);
        let l3 = laplacian_of_quadratic::<3>(13, h_over_dx);
        assert!(
            (l2 / 4.0 - 1.0).abs() < 2e-3,
            "2D h/dx {h_over_dx}: {l2} vs 4"
        );
        assert!(
            (l3 / 6.0 - 1.0).abs() < 2e-3,
            "3D h/dx {h_over_dx}: {l3} vs 6"
        );
    }
}

fn fitted_value_is_exact_for_linear_fields_and_blind_to_its_own<const D: usize>(n: i64) {
    // A half lattice, y ≤ 0: the row at y = 0 is a free surface.
    let lat = Lattice::<D>::part(n, 0.01, 1.2, |index| index[1] <= 0);
    let p = &lat.particles;
    let nb = Neighbours::new(&lat.grid, &p.pos, lat.kernel);
    // A hydrostatic-like field with a slope along x too.
    let mut pressure: Vec<f64> = (0..p.len())
        .map(|i| 1000.0 - 9810.0 * p.pos[1][i] + 300.0 * p.pos[0][i])
        .collect();
    // On the surface row's centre, a row below it, and the surface row's corner, where the
    // neighbours lie to one side along x as well.
    let at = |x: f64, y: f64| {
        (0..p.len())
            .find(|&i| {
                (0..D).all(|d| {
                    let want = [x, y].get(d).copied().unwrap_or(0.0);
                    (p.pos[d][i] - want).abs() < 1e-9
                })
            })
            .unwrap()
    };
    let corner = -0.01 * (n / 2) as f64;
    for i in [at(0.0, 0.0), at(0.0, -0.01), at(corner, 0.0)] {
        let exact = pressure[i];
        let fitted = fitted_value(&nb, p, &pressure, i).expect("a half support fixes a plane");
        assert!(
            (fitted - exact).abs() < 1e-9 * exact.abs(),
            "{D}D: {fitted} vs {exact}"
        );
        // Two fields fitted in one walk have the bits of two fits.
        let other: Vec<f64> = pressure.iter().map(|x| 0.5 * x * x).collect();
        let both = fitted_values(&nb, p, [&pressure, &other], i).unwrap();
        let alone = [&pressure, &other].map(|v| fitted_value(&nb, p, v, i).unwrap());
        assert_eq!(both.map(f64::to_bits), alone.map(f64::to_bits));
        pressure[i] += 500.0;
        let blind = fitted_value(&nb, p, &pressure, i).unwrap();
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
    // A row of particles: the neighbours of (0, 0) fix no slope across it, also with two more
    // at the kernel's rim off the row (det C / (tr C / 2)² = 5e-4, invertible, but noise
    // across); one particle beside the row fixes the plane (0.61).
    let fit = |points: &[[i64; 2]]| {
        let lat = Lattice::<2>::from_indices(points.iter().map(|&x| (x, Kind::Fluid)), 0.01, 1.2);
        let p = &lat.particles;
        let nb = Neighbours::new(&lat.grid, &p.pos, lat.kernel);
        let values: Vec<f64> = (0..p.len()).map(|i| p.pos[0][i] + p.pos[1][i]).collect();
        fitted_value(&nb, p, &values, lat.centre())
    };
    let row = [[-2, 0], [-1, 0], [0, 0], [1, 0], [2, 0]];
    assert_eq!(fit(&row), None);
    assert_eq!(fit(&[&row[..], &[[-3, -1], [3, 1]]].concat()), None);
    let beside = fit(&[&row[..], &[[0, 1]]].concat()).expect("a plane");
    assert!(beside.abs() < 1e-12, "{beside}");
}

/// A NaN among the values is the maximum: a NaN speed stops the run as non-finite.
#[test]
fn the_maximum_keeps_a_nan() {
    use isph::math::reduce::max;
    let values = [0.5, 2.0, 1.0, 0.25];
    assert_eq!(max(values.len(), |i| values[i]), 2.0);
    assert_eq!(max(0, |_| 1.0), 0.0);
    for nan_at in 0..values.len() {
        let mut v = values;
        v[nan_at] = f64::NAN;
        assert!(max(v.len(), |i| v[i]).is_nan(), "NaN at {nan_at}");
    }
}

/// The SPH Laplacian of Eq. (26) (`sph::field_laplacian`) of the mode f = Π_d cos(k x_d), a
/// wavelength of `across` spacings along each axis, at the lattice centre: its shortfall
/// against −|k|² f, the shortfall σ²|k|²/4 predicted from the kernel's standard deviation σ, and
/// the relative error of L f − (σ²/4) L(L f), the laminar step's correction (`step::predictor`).
fn laplacian_of_a_mode<const D: usize>(n: i64, across: f64) -> [f64; 3] {
    let dx = 0.01;
    let lat = Lattice::<D>::new(n, dx, 1.2);
    let p = &lat.particles;
    let k = 2.0 * std::f64::consts::PI / (across * dx);
    let mode = |i: usize| (0..D).map(|d| (k * p.pos[d][i]).cos()).product::<f64>();
    let nb = Neighbours::new(&lat.grid, &p.pos, lat.kernel);
    let f: [Vec<f64>; D] = std::array::from_fn(|d| {
        (0..p.len())
            .map(|i| if d == 0 { mode(i) } else { 0.0 })
            .collect()
    });
    let lf: [Vec<f64>; D] = std::array::from_fn(|d| {
        (0..p.len())
            .map(|i| field_laplacian(&nb, p, &f, i)[d])
            .collect()
    });
    let i = lat.centre();
    let k2 = D as f64 * k * k;
    let exact = -k2 * mode(i);
    let smoothing = lat.kernel.deviation().powi(2) / 4.0;
    let corrected = lf[0][i] - smoothing * field_laplacian(&nb, p, &lf, i)[0];
    [
        1.0 - lf[0][i] / exact,
        smoothing * k2,
        corrected / exact - 1.0,
    ]
}

/// On a lattice, 40 spacings to a wavelength (the Taylor–Green vortex at 40 across), Eq. (26)
/// falls short of the mode's Laplacian by σ²|k|²/4 within 15% (docs/accuracy.md, "The viscous
/// operator"; measured 0.92% against 0.86% in 2D, 1.33% against 1.24% in 3D), and the laminar
/// step's correction leaves less than an eighth of that shortfall (measured −0.080% and −0.12%:
/// the lattice's shortfall is 7% above the continuum's, and the σ⁴|k|⁴ term).
#[test]
fn the_laminar_correction_takes_out_the_laplacians_smoothing() {
    for (dims, [shortfall, predicted, corrected]) in [
        (2, laplacian_of_a_mode::<2>(41, 40.0)),
        (3, laplacian_of_a_mode::<3>(25, 40.0)),
    ] {
        assert!(
            (shortfall / predicted - 1.0).abs() < 0.15,
            "{dims}D: Eq. (26) short by {shortfall:e}, σ²|k|²/4 = {predicted:e}"
        );
        assert!(
            corrected.abs() < 0.125 * shortfall,
            "{dims}D: corrected off by {corrected:e}, Eq. (26) by {shortfall:e}"
        );
    }
}
