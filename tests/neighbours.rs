//! The cell-list pair loop against a brute-force O(N²) search (its slow, obvious twin).

use isph::math::kernel::{Kernel, KernelKind};
use isph::neighbours::cell_list::{CellList, KINDS};
use isph::neighbours::Neighbours;
use isph::particles::{Kind, NewParticle, Particles};

/// A small deterministic pseudo-random sequence in [0, 1).
fn lcg(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*state >> 11) as f64 / (1u64 << 53) as f64
}

/// The cell-list neighbours of n pseudo-random particles in the box [0, size]^D, a third of
/// them walls, against a brute-force search, with the minimum image along the periodic axes
/// (and the pair vector r_ij too); and the neighbours of one kind only.
fn check<const D: usize>(n: usize, h: f64, periodic: [bool; D], size: f64) {
    let mut seed = 42;
    let mut p = Particles::<D>::default();
    for k in 0..n {
        let pos = std::array::from_fn(|_| size * lcg(&mut seed));
        p.push(NewParticle {
            pos,
            kind: if k % 3 == 0 { Kind::Wall } else { Kind::Fluid },
            normal: [0.0; D],
            fluid: 0,
            mass: 1.0,
            rest_density: 1.0,
            viscosity: 0.0,
        });
    }
    let kernel = Kernel::<D>::new(KernelKind::Quintic, 1.0, h);
    let mut grid = CellList::new([0.0; D], [size; D], kernel.support(), periodic);
    let (mut cells, mut order, mut scratch) = (Vec::new(), Vec::new(), Vec::new());
    grid.sort(&p.pos, &p.kind, &mut cells, &mut order).unwrap();
    p.permute(&order, &mut scratch);
    // Sorted by kind: the fluid first, then the walls.
    let fluid = grid.range_of(Kind::Fluid);
    assert!(fluid.start == 0 && (0..n).all(|i| p.is_fluid(i) == fluid.contains(&i)));
    let nb = Neighbours::new(&grid, &p.pos, kernel);
    let s2 = kernel.support().powi(2);
    // r_ij with the nearest image of j along the periodic axes.
    let image = |i: usize, j: usize| -> [f64; D] {
        std::array::from_fn(|d| {
            let r = p.pos[d][i] - p.pos[d][j];
            if periodic[d] {
                r - size * (r / size).round()
            } else {
                r
            }
        })
    };
    // A fluid particle's ranges come from the runs the sort found, a wall particle's from a
    // search of the grid: the same ranges and images in the same order (the pair loops' sums,
    // and so the runs' bits, depend on that order).
    for i in 0..n {
        let x = std::array::from_fn(|d| p.pos[d][i]);
        let (mut around, mut searched) = (Vec::new(), Vec::new());
        grid.for_each_range_around(i, x, &KINDS, |r, image, kind| around.push((r, image, kind)));
        grid.for_each_neighbour_range(x, &KINDS, |r, image, kind| searched.push((r, image, kind)));
        assert_eq!(around, searched, "ranges around particle {i}");
        // The multigrid's aggregate of a particle: its block, x fastest in a grid of blocks.
        let (blocks, mut block, mut stride) = (grid.blocks(), 0, 1);
        for d in 0..D {
            block += grid.block_along(d, x[d]) as usize * stride;
            stride *= blocks[d];
        }
        assert_eq!(grid.block_of_sorted(i), block, "block of particle {i}");
    }
    for i in 0..n {
        let mut fast = Vec::new();
        nb.for_each(i, |j, rij, _| fast.push((j, rij)));
        fast.sort_by_key(|&(j, _)| j);
        let slow: Vec<usize> = (0..n)
            .filter(|&j| j != i && image(i, j).iter().map(|x| x * x).sum::<f64>() < s2)
            .collect();
        let found: Vec<usize> = fast.iter().map(|&(j, _)| j).collect();
        assert_eq!(found, slow, "neighbours of particle {i}");
        for kind in [Kind::Fluid, Kind::Wall] {
            let mut of_kind = Vec::new();
            nb.for_each_of(i, &[kind], |j, _, _| of_kind.push(j));
            of_kind.sort();
            let expected: Vec<usize> = slow
                .iter()
                .copied()
                .filter(|&j| p.kind[j] == kind)
                .collect();
            assert_eq!(of_kind, expected, "{kind:?} neighbours of particle {i}");
        }
        for (j, rij) in fast {
            let expected = image(i, j);
            assert!(
                (0..D).all(|d| (rij[d] - expected[d]).abs() < 1e-12),
                "r_ij of pair {i}, {j}"
            );
        }
    }
}

#[test]
fn cell_list_finds_exactly_the_brute_force_neighbours() {
    check::<2>(3000, 0.04, [false; 2], 1.0);
    check::<3>(3000, 0.04, [false; 3], 1.0);
}

#[test]
fn periodic_axes_find_the_nearest_images_across_the_boundary() {
    check::<2>(3000, 0.04, [true, true], 1.0);
    check::<2>(3000, 0.04, [true, false], 1.0);
    check::<3>(3000, 0.04, [false, true, true], 1.0);
    // Three cells per periodic axis, the fewest allowed: no neighbour is met twice.
    check::<2>(400, 0.1, [true, true], 1.0);
    check::<3>(400, 0.1, [true, true, true], 1.0);
}

/// A period of 2.01 m at h = 0.01 m (a scene at dx = 0.01 m, h/dx = 1.0) is 134 cells of
/// half a support whose width rounds one ulp below it: the reach across those cells must not
/// round up to three, which fails an assertion before any step runs.
#[test]
fn periodic_cells_a_rounding_short_of_half_a_support() {
    check::<2>(3000, 0.01, [false, true], 2.01);
    check::<2>(3000, 0.01, [true, true], 2.01);
}

#[test]
fn sort_keeps_ids_and_reports_particles_outside() {
    let mut p = Particles::<2>::default();
    for x in [0.9, 0.1, 0.5] {
        p.push(NewParticle {
            pos: [x, 0.5],
            kind: Kind::Fluid,
            normal: [0.0; 2],
            fluid: 0,
            mass: 1.0,
            rest_density: 1.0,
            viscosity: 0.0,
        });
    }
    let mut grid = CellList::new([0.0; 2], [1.0; 2], 0.1, [false; 2]);
    let (mut cells, mut order, mut scratch) = (Vec::new(), Vec::new(), Vec::new());
    grid.sort(&p.pos, &p.kind, &mut cells, &mut order).unwrap();
    p.permute(&order, &mut scratch);
    assert_eq!(p.id, vec![1, 2, 0]);
    assert_eq!(p.pos[0], vec![0.1, 0.5, 0.9]);
    p.pos[0][1] = 7.0;
    assert_eq!(
        grid.sort(&p.pos, &p.kind, &mut cells, &mut order)
            .unwrap_err()
            .index,
        1
    );
}

/// The multigrid's coarse rows find their neighbours' blocks in lanes
/// (`CellList::block_along_lanes`): the same blocks as `block_along` for points all over the
/// grid, the grid's faces and the last cell of each axis (where the cell is clamped) included.
#[test]
fn blocks_in_lanes_are_the_blocks_of_single_points() {
    use isph::math::lanes::{F64s, LANES};
    let grid = CellList::<3>::new(
        [-0.3, 0.0, 0.1],
        [0.7, 0.45, 0.9],
        0.036,
        [true, false, false],
    );
    let (lo, hi) = ([-0.3, 0.0, 0.1], [0.7, 0.45, 0.9]);
    let mut state = 7;
    for d in 0..3 {
        let mut points: Vec<f64> = (0..4000)
            .map(|_| lo[d] + (hi[d] - lo[d]) * lcg(&mut state))
            .collect();
        points.extend([lo[d], hi[d], hi[d] - 1e-12, lo[d] + 1e-12]);
        for chunk in points.chunks(LANES) {
            let mut lanes = [lo[d]; LANES];
            lanes[..chunk.len()].copy_from_slice(chunk);
            let blocks = grid.block_along_lanes(d, F64s::from(lanes)).to_array();
            for (k, &x) in chunk.iter().enumerate() {
                assert_eq!(
                    blocks[k],
                    grid.block_along(d, x) as f64,
                    "axis {d}, x = {x}"
                );
            }
        }
    }
}
