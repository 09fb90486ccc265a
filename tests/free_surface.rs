//! Free-surface detection (src/sph/free_surface.rs) on blocks, a tank, sheets and a lone particle,
//! in 2D and 3D: exactly the particles on the outside of the fluid take P = 0.

use crate::common::Lattice;
use isph::math::kernel::KernelKind;
use isph::neighbours::Neighbours;
use isph::particles::Kind;
use isph::sph::free_surface::{spray_density, Support};
use isph::sph::{density, support_moments};

const DX: f64 = 0.01;
const H_OVER_DX: f64 = 1.2;

/// Lattice index of each fluid particle with whether it is detected as free surface.
fn detect<const D: usize>(lat: &Lattice<D>) -> Vec<([i64; D], bool)> {
    let p = &lat.particles;
    let nb = Neighbours::new(&lat.grid, &p.pos, lat.kernel);
    let spray = spray_density::<D>(lat.kernel.kind(), lat.kernel.h() / DX);
    (0..p.len())
        .filter(|&i| p.is_fluid(i))
        .map(|i| {
            let mo = support_moments(&nb, p, i);
            let ratio = density(&nb, p, i) / p.rest_density[i];
            let surface = Support::new(&mo.m, mo.grad_c).is_free_surface(&nb, i, ratio, spray);
            (p.position(i).map(|x| (x / DX).round() as i64), surface)
        })
        .collect()
}

/// Every lattice index of a box [lo, hi) per axis.
fn box_indices<const D: usize>(lo: [i64; D], hi: [i64; D]) -> Vec<[i64; D]> {
    let mut all = vec![[0; D]];
    for d in 0..D {
        all = all
            .into_iter()
            .flat_map(|base| {
                (lo[d]..hi[d]).map(move |c| {
                    let mut x = base;
                    x[d] = c;
                    x
                })
            })
            .collect();
    }
    all
}

fn assert_detected<const D: usize>(lat: &Lattice<D>, expected: impl Fn([i64; D]) -> bool) {
    let wrong: Vec<_> = detect(lat)
        .into_iter()
        .filter(|&(x, surface)| surface != expected(x))
        .collect();
    assert!(wrong.is_empty(), "{} misdetected: {wrong:?}", wrong.len());
}

fn block_outer_layer_only<const D: usize>(n: i64, h_over_dx: f64) {
    let lat = Lattice::<D>::new(n, DX, h_over_dx);
    let half = n / 2;
    assert_detected(&lat, |x| x.iter().any(|c| c.abs() == half));
}

#[test]
fn a_block_has_exactly_its_outer_layer_on_the_surface() {
    block_outer_layer_only::<2>(15, H_OVER_DX);
    block_outer_layer_only::<3>(11, H_OVER_DX);
}

/// The whole range of h/dx a scene may ask for: a wider kernel reaches further out of the
/// water, and the summation density of the second layer falls (0.86 ρ0 on a flat second row,
/// 0.65 ρ0 at a 3D block's second-layer corner at h/dx = 2.0), but that layer is not spray.
/// (A spray threshold fixed at 0.9 ρ0 would take the corners for free surface from
/// h/dx ≈ 1.3 on in 3D, and whole second rows from h/dx ≈ 1.75 on.)
#[test]
fn the_outer_layer_only_at_every_smoothing_length() {
    for h_over_dx in [1.0, 1.5, 1.8, 2.0] {
        block_outer_layer_only::<2>(21, h_over_dx);
        block_outer_layer_only::<3>(15, h_over_dx);
        tank_top_row_only::<2>(21, h_over_dx);
        tank_top_row_only::<3>(15, h_over_dx);
    }
}

#[test]
fn the_spray_density_is_0_9_where_it_was_set_and_falls_with_the_kernel_s_reach() {
    assert_eq!(spray_density::<2>(KernelKind::Quintic, 1.2), 0.9);
    assert_eq!(spray_density::<3>(KernelKind::Quintic, 1.2), 0.9);
    // 0.9 × the second-layer corner's lattice density over its value at h/dx = 1.2.
    let d = spray_density::<2>(KernelKind::Quintic, 2.0);
    assert!((d - 0.9 * 0.740 / 0.947).abs() < 0.003, "{d}");
    let d = spray_density::<3>(KernelKind::Quintic, 2.0);
    assert!((d - 0.9 * 0.645 / 0.928).abs() < 0.003, "{d}");
}

/// Water `n` particles wide and deep in a tank with wall layers on the sides and below, as
/// many as a scene's container has (4 at h/dx = 1.2).
fn tank<const D: usize>(n: i64, h_over_dx: f64) -> Lattice<D> {
    let walls = (3.0 * h_over_dx - 1e-9).ceil() as i64;
    let lo = [-walls; D];
    let mut hi = [n + walls; D];
    hi[D - 1] = n;
    let points = box_indices(lo, hi).into_iter().map(|x| {
        let fluid = x.iter().all(|&c| (0..n).contains(&c));
        (x, if fluid { Kind::Fluid } else { Kind::Wall })
    });
    Lattice::<D>::from_indices(points, DX, h_over_dx)
}

/// In the `tank`, only the top row is free surface, also where it meets the side walls; fluid
/// against the walls never is.
fn tank_top_row_only<const D: usize>(n: i64, h_over_dx: f64) {
    assert_detected(&tank::<D>(n, h_over_dx), |x| x[D - 1] == n - 1);
}

#[test]
fn in_a_tank_only_the_top_row_is_surface() {
    tank_top_row_only::<2>(16, H_OVER_DX);
    tank_top_row_only::<3>(10, H_OVER_DX);
}

#[test]
fn sheets_and_a_lone_particle_are_surface() {
    // A sheet one particle thick, in 2D a row, in 3D a plate.
    let row = Lattice::<2>::from_indices((-10..=10).map(|c| ([c, 0], Kind::Fluid)), DX, H_OVER_DX);
    assert_detected(&row, |_| true);
    let plate = box_indices([-7, -7, 0], [8, 8, 1]).into_iter();
    let plate = Lattice::<3>::from_indices(plate.map(|x| (x, Kind::Fluid)), DX, H_OVER_DX);
    assert_detected(&plate, |_| true);
    // A sheet two particles thick: both rows are surface.
    let sheet = box_indices([-10, 0], [11, 2]).into_iter();
    let sheet = Lattice::<2>::from_indices(sheet.map(|x| (x, Kind::Fluid)), DX, H_OVER_DX);
    assert_detected(&sheet, |_| true);
    let lone = Lattice::<3>::from_indices([([0, 0, 0], Kind::Fluid)], DX, H_OVER_DX);
    assert_detected(&lone, |_| true);
}

/// The tank of `in_a_tank_only_the_top_row_is_surface` with its top row three times as heavy,
/// as if a second row had been squeezed into it: the top row now holds more mass than a full
/// support at rest (its emptiest direction, upwards, is still empty, so the moments alone call
/// it surface), so it is compressed fluid that must push back, not free surface (whose row
/// fixes the pressure).
#[test]
fn compressed_fluid_is_never_free_surface() {
    let n = 16;
    let mut lat = tank::<2>(n, H_OVER_DX);
    let p = &mut lat.particles;
    for i in 0..p.len() {
        if p.is_fluid(i) && (p.pos[1][i] / DX).round() as i64 == n - 1 {
            p.mass[i] *= 3.0;
        }
    }
    assert_detected(&lat, |_| false);
}
