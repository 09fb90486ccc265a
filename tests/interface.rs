//! Interfaces between fluids of different rest density (src/sph/interface.rs): the distance each
//! particle reads off the other fluid's share of its kernel, and the pair density between two.

use crate::common::Lattice;
use isph::boundary::faces::Faces;
use isph::math::kernel::{Kernel, KernelKind};
use isph::math::lanes::F64s;
use isph::math::vector::unit;
use isph::neighbours::Neighbours;
use isph::particles::Kind;
use isph::scene::Aabb;
use isph::sph::interface::{other_fluid_share, pair_weight, Interfaces};

const DX: f64 = 0.01;

/// A block of lattice particles, those above the plane half a spacing over the middle row
/// of twice the density: a flat interface. A particle k rows from it reads its distance off
/// the other fluid's share of its kernel against the share a lattice beyond a plane holds
/// (`Interfaces`): k + ½ spacings, to the table's interpolation, for every row whose other
/// fluid lies inside the support (a continuum's half space read 0.53, 1.60 and 2.73 spacings
/// for 0.5, 1.5 and 2.5 in 2D). The normal points straight across the interface into the other
/// fluid.
fn distances_on_a_lattice<const D: usize>(n: i64, h_over_dx: f64) {
    let mut lat = Lattice::<D>::part(n, DX, h_over_dx, |_| true);
    let p = &mut lat.particles;
    for i in 0..p.len() {
        if p.pos[D - 1][i] > 0.5 * DX {
            p.rest_density[i] = 2000.0;
            p.mass[i] *= 2.0;
        }
    }
    let table = Interfaces::new(&lat.kernel, DX);
    let nb = Neighbours::new(&lat.grid, &p.pos, lat.kernel);
    let support = 3.0 * h_over_dx;
    let reach = support.ceil() as i64;
    let mut checked = 0;
    for i in 0..p.len() {
        let index: Vec<i64> = (0..D).map(|d| (p.pos[d][i] / DX).round() as i64).collect();
        // Inside the block, beyond the kernel's reach from its sides.
        if index.iter().any(|c| c.abs() > n / 2 - reach) {
            continue;
        }
        // Rows from the interface (0: the two rows beside it) and the way across it.
        let (row, across) = match index[D - 1] <= 0 {
            true => (-index[D - 1], 1.0),
            false => (index[D - 1] - 1, -1.0),
        };
        // The other fluid's first row, row + 1 spacings away, inside the support.
        if ((row + 1) as f64) < support {
            let (share, gradient) = other_fluid_share(&nb, p, [None; D], i);
            let distance = table.distance(share) / DX;
            assert!(
                (distance - (row as f64 + 0.5)).abs() < 1e-3,
                "D = {D}, h/dx = {h_over_dx}: row {row} at {distance} spacings"
            );
            let normal = unit(gradient);
            for (d, component) in normal.into_iter().enumerate() {
                let expected = if d == D - 1 { across } else { 0.0 };
                assert!((component - expected).abs() < 1e-12, "normal {normal:?}");
            }
            checked += 1;
        }
    }
    assert!(checked > 0);
}

/// The same flat interface meeting the side walls: four layers of wall particles at x ≤ −dx
/// (the face at x = −½ dx), and in 3D at y ≤ −dx too (an edge of two walls), the fluid beyond.
/// The particles beside the walls and at the edge read the distances of those beyond the
/// walls' reach, to round-off: the walls stand for the mirror images of the fluid, and the
/// image of a lattice is the lattice. Without the images the column beside a side wall misses
/// part of the other fluid's share and reads the first row 37% farther from the interface
/// (0.73 spacings against 0.53 in 2D).
fn distances_beside_side_walls<const D: usize>(n: i64) {
    let half = n / 2;
    let walled = |d: usize| d == 0 || (D == 3 && d == 1);
    let points = (0..n.pow(D as u32)).filter_map(|k| {
        let index: [i64; D] = std::array::from_fn(|d| (k / n.pow(d as u32)) % n - half);
        let wall = (0..D).any(|d| walled(d) && index[d] < 0);
        let inside = (0..D).all(|d| !walled(d) || index[d] >= -4);
        inside.then_some((index, if wall { Kind::Wall } else { Kind::Fluid }))
    });
    let mut lat = Lattice::<D>::from_indices(points, DX, 1.2);
    let p = &mut lat.particles;
    for i in 0..p.len() {
        if p.kind[i] == Kind::Fluid && p.pos[D - 1][i] > 0.5 * DX {
            p.rest_density[i] = 2000.0;
            p.mass[i] *= 2.0;
        }
    }
    let p = &lat.particles;
    let container = Aabb {
        min: (0..D)
            .map(|d| if walled(d) { -0.5 * DX } else { -1.0 })
            .collect(),
        max: vec![1.0; D],
    };
    let faces = Faces {
        container,
        periodic: vec![false; D],
        obstacles: Vec::new(),
    };
    let table = Interfaces::new(&lat.kernel, DX);
    let nb = Neighbours::new(&lat.grid, &p.pos, lat.kernel);
    let support = lat.kernel.support();
    // Distance in spacings of the fluid particle `column` lattice points from the walls (0:
    // beside them) along the walled axes and `row` rows below the interface (0: the row
    // beside it), in the middle of the other axes.
    let distance = |column: i64, row: i64| {
        let target = |d: usize| match d {
            _ if walled(d) => column as f64 * DX,
            _ if d == D - 1 => -(row as f64) * DX,
            _ => 0.0,
        };
        let i = (0..p.len())
            .find(|&i| (0..D).all(|d| (p.pos[d][i] - target(d)).abs() < 0.25 * DX))
            .expect("a lattice particle there");
        let mirrors = faces.container_faces_within(std::array::from_fn(|d| p.pos[d][i]), support);
        table.distance(other_fluid_share(&nb, p, mirrors, i).0) / DX
    };
    for row in 0..3 {
        let far = distance(6, row);
        for column in 0..4 {
            let near = distance(column, row);
            assert!(
                (near / far - 1.0).abs() < 1e-9,
                "D = {D}, row {row}: column {column} at {near} spacings, far from the walls {far}"
            );
        }
    }
}

#[test]
fn beside_side_walls_the_distance_to_an_interface_is_that_far_from_them() {
    distances_beside_side_walls::<2>(31);
    distances_beside_side_walls::<3>(19);
}

#[test]
fn the_distance_to_a_flat_interface_is_read_off_the_kernel() {
    distances_on_a_lattice::<2>(31, 1.2);
    distances_on_a_lattice::<3>(19, 1.2);
    distances_on_a_lattice::<2>(31, 2.0);
}

#[test]
fn far_from_any_other_fluid_the_distance_is_the_support_and_inside_it_zero() {
    let table = Interfaces::new(&Kernel::<3>::new(KernelKind::Quintic, 0.01, 1.2), 0.01);
    assert!((table.distance(0.0) - 0.036).abs() < 1e-15);
    assert!(table.distance(0.5) < 1e-4 * 0.012);
    assert_eq!(table.distance(0.8), 0.0);
}

/// ρ0_i/ρ̄_ij for ρ0_i, ρ0_j, d_i, d_j and the length L across the interface.
fn weight(rest_i: f64, rest_j: f64, distance_i: f64, distance_j: f64, length: f64) -> f64 {
    let w = pair_weight(
        F64s::splat(rest_i),
        F64s::splat(rest_j),
        F64s::splat(distance_i),
        F64s::splat(distance_j),
        F64s::splat(length),
    )
    .to_array();
    assert!(w.iter().all(|&x| x == w[0]), "every lane alike");
    w[0]
}

#[test]
fn the_pair_density_is_exact_for_a_stable_layering_and_one_within_a_fluid() {
    // i in the light fluid half a spacing above the interface, j in the heavy one 2.5 below:
    // P_j − P_i = g (500 · 0.5 + 1000 · 2.5) dx = g · 3 dx · ρ̄, ρ̄ = 2750/3.
    let expected = 500.0 / (2750.0 / 3.0);
    assert!((weight(500.0, 1000.0, 0.5, 2.5, 3.0) - expected).abs() < 1e-15);
    // From j's side the same density: ρ0_j/ρ̄ = 1000/(2750/3).
    assert!((weight(1000.0, 500.0, 2.5, 0.5, 3.0) - 3000.0 / 2750.0).abs() < 1e-15);
    // Two layers closing in: each reads itself nearer than it is (0.3 and 0.5 spacings over a
    // length of 1), and the interface is taken halfway between the two places they give it,
    // 0.4 from i: ρ̄ = 0.4 · 500 + 0.6 · 1000.
    assert!((weight(500.0, 1000.0, 0.3, 0.5, 1.0) - 500.0 / 800.0).abs() < 1e-15);
    // Within one fluid exactly one; with no length across the interface the harmonic mean.
    assert_eq!(weight(800.0, 800.0, 0.3, 1.7, 2.0), 1.0);
    assert!((weight(500.0, 1000.0, 0.0, 0.0, 0.0) - 2.0 / 3.0).abs() < 1e-15);
    assert!((weight(500.0, 1000.0, 0.4, 0.2, -1.0) - 2.0 / 3.0).abs() < 1e-15);
}
