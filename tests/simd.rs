//! The SIMD operators (`wide` lanes over the cell list's ranges) against their slow, obvious
//! twins: scalar sums over every pair of particles (O(N²)) with the scalar kernel, on a
//! disordered block of fluid over a floor of wall particles, in 2D and 3D.

use isph::boundary::ghosts::BodyForce;
use isph::math::kernel::{Kernel, KernelKind};
use isph::neighbours::cell_list::CellList;
use isph::neighbours::Neighbours;
use isph::particles::{Kind, NewParticle, Particles};
use isph::solver::krylov::LinearOperator;
use isph::solver::multigrid::Aggregated;
use isph::solver::ppe::{self, LaplacianTruncation, PressureOperator, Role};
use isph::sph;

const DX: f64 = 0.01;
const H_OVER_DX: f64 = 1.2;

/// A small deterministic pseudo-random sequence in [0, 1).
fn lcg(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*state >> 11) as f64 / (1u64 << 53) as f64
}

/// n^D fluid particles on a lattice moved by up to ±0.3 dx each, above four layers of wall
/// particles (normal +y), sorted by kind and cell; with `periodic_x`, in a period of n dx
/// along x.
fn disordered_block<const D: usize>(
    n: i64,
    periodic_x: bool,
) -> (Particles<D>, CellList<D>, Kernel<D>) {
    let mut seed = 7;
    let mut p = Particles::<D>::default();
    let total = (n as usize).pow(D as u32);
    for k in 0..total {
        let mut rest = k as i64;
        let index: [i64; D] = std::array::from_fn(|_| {
            let c = rest % n;
            rest /= n;
            c
        });
        // Layers 0..4 along y are the floor.
        let wall = index[1] < 4;
        let pos = std::array::from_fn(|d| {
            let jitter = if wall {
                0.0
            } else {
                0.6 * (lcg(&mut seed) - 0.5)
            };
            (index[d] as f64 + jitter) * DX
        });
        let mut normal = [0.0; D];
        normal[1] = if wall { 1.0 } else { 0.0 };
        p.push(NewParticle {
            pos,
            kind: if wall { Kind::Wall } else { Kind::Fluid },
            normal,
            fluid: 0,
            mass: 1000.0 * DX.powi(D as i32),
            rest_density: 1000.0,
            viscosity: 1e-6,
        });
    }
    let kernel = Kernel::<D>::new(KernelKind::Quintic, DX, H_OVER_DX);
    let extent = n as f64 * DX;
    let (mut lo, mut periodic) = ([-DX; D], [false; D]);
    if periodic_x {
        (lo[0], periodic[0]) = (0.0, true);
    }
    let mut grid = CellList::new(lo, [extent; D], kernel.support(), periodic);
    grid.wrap(&mut p.pos);
    let (mut cells, mut order, mut scratch) = (Vec::new(), Vec::new(), Vec::new());
    grid.sort(&p.pos, &p.kind, &mut cells, &mut order).unwrap();
    p.permute(&order, &mut scratch);
    (p, grid, kernel)
}

/// Every j ≠ i within the support of i, by brute force, with r_ij and |r_ij|.
fn pairs<const D: usize>(
    p: &Particles<D>,
    kernel: &Kernel<D>,
    i: usize,
) -> Vec<(usize, [f64; D], f64)> {
    (0..p.len())
        .filter(|&j| j != i)
        .filter_map(|j| {
            let rij: [f64; D] = std::array::from_fn(|d| p.pos[d][i] - p.pos[d][j]);
            let r = rij.iter().map(|x| x * x).sum::<f64>().sqrt();
            (r < kernel.support()).then_some((j, rij, r))
        })
        .collect()
}

fn close(a: f64, b: f64, scale: f64) -> bool {
    (a - b).abs() <= 1e-12 * scale
}

/// The PPE's rows over the fluid of a block, every one interior: their roles, their row vectors
/// as the free-surface stage sums them, in the moments' walk (no kernel correction: ĉ_i = c_i),
/// and the fluid volumes.
struct InteriorRows<const D: usize> {
    roles: Vec<Role>,
    row_vectors: Vec<[f64; D]>,
    fluid_volume: Vec<f64>,
}

impl<const D: usize> InteriorRows<D> {
    fn of(nb: &Neighbours<D>, p: &Particles<D>, nf: usize) -> Self {
        let row_vectors = (0..nf)
            .map(|i| {
                let mut truncation = LaplacianTruncation::new(p, false, i);
                sph::support_moments_and(nb, p, i, |l, _, followed| {
                    truncation.add(nb, p, l, followed)
                });
                ppe::row_vector(Role::Interior, &truncation, &None)
            })
            .collect();
        let mut fluid_volume = Vec::new();
        ppe::fluid_volumes(p, nf, &mut fluid_volume);
        Self {
            roles: vec![Role::Interior; nf],
            row_vectors,
            fluid_volume,
        }
    }

    /// The operator of these rows, without gravity or interfaces.
    fn operator<'a>(
        &'a self,
        nb: &'a Neighbours<'a, D>,
        p: &'a Particles<D>,
    ) -> PressureOperator<'a, D> {
        PressureOperator {
            nb,
            p,
            roles: &self.roles,
            row_vectors: &self.row_vectors,
            fluid_volume: &self.fluid_volume,
            gravity: [0.0; D],
            ghost_force: BodyForce::Uniform([0.0; D]),
            interfaces: None,
            ghosts: None,
        }
    }
}

/// Each coarse row of the multigrid (`Aggregated::add_coarse_row`) is row i of A summed over
/// each neighbouring block, so for a coarse vector c the rows give A P c, P c the value c of
/// each unknown's block (zero on the rows held fixed, here every seventh), with a block's
/// neighbours across a periodic boundary in the slots of their adjacency.
fn check_coarse_rows<const D: usize>(op: &PressureOperator<'_, D>, nf: usize) {
    let held: Vec<Role> = (0..nf)
        .map(|i| {
            if i % 7 == 3 {
                Role::Surface
            } else {
                Role::Interior
            }
        })
        .collect();
    let op = PressureOperator {
        roles: &held,
        ..*op
    };
    let (dims, periodic) = (op.dims(), op.periodic());
    let coarse: Vec<f64> = (0..dims.iter().product::<usize>())
        .map(|k| (k * 7919 % 13) as f64 / 13.0 - 0.5)
        .collect();
    let fine: Vec<f64> = (0..nf)
        .map(|j| op.aggregate(j).map_or(0.0, |c| coarse[c]))
        .collect();
    let mut a_fine = vec![0.0; nf];
    op.apply(&fine, &mut a_fine);
    let mut stencil = vec![0.0; 3usize.pow(D as u32)];
    for i in (0..nf).filter(|&i| held[i] == Role::Interior) {
        stencil.fill(0.0);
        op.add_coarse_row(i, &mut stencil);
        let cell = op.aggregate(i).expect("an interior row is aggregated");
        let (mut sum, mut size) = (0.0, 0.0);
        for (slot, &a) in stencil.iter().enumerate() {
            // The block at the slot's offset (x fastest), inside the grid or wrapped around a
            // periodic axis.
            let (mut n, mut stride, mut rest, mut c) = (0, 1, slot, cell);
            for d in 0..D {
                let mut k = (c % dims[d]) as i64 + (rest % 3) as i64 - 1;
                (c, rest) = (c / dims[d], rest / 3);
                if periodic[d] {
                    k = k.rem_euclid(dims[d] as i64);
                }
                assert!(
                    k >= 0 && k < dims[d] as i64 || a == 0.0,
                    "row {i} slot {slot}"
                );
                n += k.clamp(0, dims[d] as i64 - 1) as usize * stride;
                stride *= dims[d];
            }
            sum += a * coarse[n];
            size += (a * coarse[n]).abs();
        }
        assert!(
            close(sum, a_fine[i], size),
            "coarse row {i}: {sum} against (A P c)_i {}",
            a_fine[i]
        );
    }
}

fn check<const D: usize>(n: i64) {
    let (p, grid, kernel) = disordered_block::<D>(n, false);
    let nb = Neighbours::new(&grid, &p.pos, kernel);
    let nf = grid.range_of(Kind::Fluid).end;
    let phi = |j: usize| 3.0 * p.pos[0][j] - 2.0 * p.pos[1][j] + 1.0;
    let rows = InteriorRows::of(&nb, &p, nf);
    let (row_vectors, fluid_volume) = (&rows.row_vectors, &rows.fluid_volume);
    let op = rows.operator(&nb, &p);
    let x: Vec<f64> = (0..nf).map(|i| phi(i) * phi(i)).collect();
    let mut ax = vec![0.0; nf];
    op.apply(&x, &mut ax);
    // Two applies in one walk (the lockstep solves) have the bits of two walks.
    let x2: Vec<f64> = (0..nf).map(phi).collect();
    let (mut ax2, mut both, mut both2) = (vec![0.0; nf], vec![0.0; nf], vec![0.0; nf]);
    op.apply(&x2, &mut ax2);
    op.apply_two(&x, &mut both, &x2, &mut both2);
    assert!(both
        .iter()
        .zip(&ax)
        .all(|(a, b)| a.to_bits() == b.to_bits()));
    assert!(both2
        .iter()
        .zip(&ax2)
        .all(|(a, b)| a.to_bits() == b.to_bits()));
    // The multigrid takes the fine diagonal from the coarse-row pass: it must have the bits of
    // the operator's own diagonal (the weights summed in the same order).
    let mut diagonal = vec![0.0; nf];
    op.diagonal(&mut diagonal);
    let mut stencil = vec![0.0; 3usize.pow(D as u32)];
    for i in 0..nf {
        let a_ii = op.add_coarse_row(i, &mut stencil);
        assert_eq!(a_ii.to_bits(), diagonal[i].to_bits(), "a_ii of row {i}");
    }
    check_coarse_rows(&op, nf);

    for i in 0..nf {
        let neighbours = pairs(&p, &kernel, i);
        // Summation density.
        let rho = p.mass[i] * kernel.w(0.0)
            + neighbours
                .iter()
                .map(|&(j, _, r)| p.mass[j] * kernel.w(r))
                .sum::<f64>();
        let fast = sph::density(&nb, &p, i);
        assert!(close(fast, rho, rho), "density of {i}: {fast} vs {rho}");
        // The uncorrected gradient of a linear field (Eq. 20), walls included.
        let mut grad = [0.0; D];
        for &(j, rij, r) in &neighbours {
            let c = p.mass[j] / p.rest_density[j] * (phi(j) - phi(i)) * kernel.grad_factor(r);
            for d in 0..D {
                grad[d] += c * rij[d];
            }
        }
        let phi_i = phi(i);
        let fast = sph::gradient(&nb, &p, &None, i, |l| {
            let x0 = l.load(&p.pos[0]);
            let x1 = l.load(&p.pos[1]);
            x0 * isph::math::lanes::F64s::splat(3.0) - x1 * isph::math::lanes::F64s::splat(2.0)
                + isph::math::lanes::F64s::splat(1.0 - phi_i)
        });
        for d in 0..D {
            assert!(
                close(fast[d], grad[d], 3.0),
                "gradient of {i}, axis {d}: {fast:?} vs {grad:?}"
            );
        }
        // The row vector c_i = 2 Σ_j (m_j/ρ_i) r_ij·∇W_ij/(r_ij² + η²) r_ij, a wall neighbour's
        // r_ij cut to its part across the wall (`ppe::LaplacianTruncation`).
        let c = row_vectors[i];
        let (mut twin, mut size) = ([0.0; D], 0.0);
        for &(j, rij, r) in &neighbours {
            let a = 2.0 * p.mass[j] / p.rest_density[i] * nb.laplacian_factor(r);
            for d in 0..D {
                let followed = match p.kind[j] {
                    Kind::Wall if p.normal[d][j] == 0.0 => 0.0,
                    _ => rij[d],
                };
                twin[d] += a * followed;
                size += (a * followed).abs();
            }
        }
        for d in 0..D {
            assert!(
                close(c[d], twin[d], size),
                "row vector of {i}, axis {d}: {c:?} vs {twin:?}"
            );
        }
        // The PPE row of Eq. (27) with its consistency correction, fluid neighbours only.
        let mut row = 0.0;
        let mut scale = 0.0;
        for &(j, rij, r) in neighbours.iter().filter(|&&(j, _, _)| j < nf) {
            let a = sph::laplacian_coefficient(&nb, &p, i, j, r);
            let c_r: f64 = (0..D).map(|d| c[d] * rij[d]).sum();
            let w = (a - fluid_volume[j] * kernel.grad_factor(r) * c_r).max(0.0);
            row += w * (x[i] - x[j]);
            scale += w * x[j].abs();
        }
        assert!(close(ax[i], row, scale), "PPE row {i}: {} vs {row}", ax[i]);
    }
}

#[test]
fn simd_operators_match_their_scalar_twins() {
    check::<2>(16);
    check::<3>(9);
}

/// The coarse rows across a periodic boundary, on periods that split into whole blocks and a
/// few cells more (the last block takes them).
#[test]
fn coarse_rows_wrap_around_a_periodic_axis() {
    fn periodic<const D: usize>(n: i64) {
        let (p, grid, kernel) = disordered_block::<D>(n, true);
        let nb = Neighbours::new(&grid, &p.pos, kernel);
        let nf = grid.range_of(Kind::Fluid).end;
        let rows = InteriorRows::of(&nb, &p, nf);
        assert!(grid.dims()[0] % 4 != 0, "{:?}", grid.dims());
        check_coarse_rows(&rows.operator(&nb, &p), nf);
    }
    periodic::<2>(16);
    periodic::<3>(12);
}

/// `lanes::Sum` adds the lanes of every chunk four at a time in index order: the sums of a
/// build of any width have the bits of a build of four lanes (checked here against four-lane
/// sums written out, over chunks of pseudo-random terms).
#[test]
fn lane_sums_have_the_bits_of_four_lanes() {
    use isph::math::lanes::{F64s, Sum, LANES};
    let mut seed = 7;
    let terms: Vec<(f64, f64)> = (0..64 * LANES)
        .map(|_| (lcg(&mut seed) - 0.5, 1e3 * lcg(&mut seed)))
        .collect();
    let (mut sum, mut fused) = (Sum::ZERO, Sum::ZERO);
    for chunk in terms.chunks(LANES) {
        let a = F64s::from(std::array::from_fn::<f64, LANES, _>(|k| chunk[k].0));
        let b = F64s::from(std::array::from_fn::<f64, LANES, _>(|k| chunk[k].1));
        sum += a;
        fused = fused.mul_add(a, b);
    }
    let (mut lanes_sum, mut lanes_fused) = ([0.0f64; 4], [0.0f64; 4]);
    for four in terms.chunks(4) {
        for k in 0..4 {
            lanes_sum[k] += four[k].0;
            lanes_fused[k] = four[k].0.mul_add(four[k].1, lanes_fused[k]);
        }
    }
    // f64x4::reduce_add's order.
    let total = |l: [f64; 4]| wide::f64x4::from(l).reduce_add();
    assert_eq!(sum.total().to_bits(), total(lanes_sum).to_bits());
    assert_eq!(fused.total().to_bits(), total(lanes_fused).to_bits());
}
