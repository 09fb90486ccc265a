//! BiCGSTAB against a dense direct solve on a non-symmetric sparse system, and with the
//! multigrid preconditioner on rows that couple to nothing.

use isph::solver::krylov::{BiCgStab, Jacobi, LinearOperator, Preconditioner, SolverParams};
use isph::solver::multigrid::{stencil_slot, Aggregated, Multigrid};

/// 1D convection–diffusion: −x_{i−1}(1 + c) + 2 x_i (1 + s_i) − x_{i+1}(1 − c), non-symmetric.
struct ConvectionDiffusion {
    n: usize,
    c: f64,
}

impl ConvectionDiffusion {
    fn entry(&self, i: usize, j: usize) -> f64 {
        let shift = 0.01 * (i % 7) as f64;
        if i == j {
            2.0 * (1.0 + shift)
        } else if j + 1 == i {
            -(1.0 + self.c)
        } else if i + 1 == j {
            -(1.0 - self.c)
        } else {
            0.0
        }
    }
}

impl LinearOperator for ConvectionDiffusion {
    fn len(&self) -> usize {
        self.n
    }
    fn apply(&self, x: &[f64], y: &mut [f64]) {
        for i in 0..self.n {
            let lo = i.saturating_sub(1);
            let hi = (i + 1).min(self.n - 1);
            y[i] = (lo..=hi).map(|j| self.entry(i, j) * x[j]).sum();
        }
    }
    fn diagonal(&self, d: &mut [f64]) {
        for (i, d) in d.iter_mut().enumerate() {
            *d = self.entry(i, i);
        }
    }
}

/// Gaussian elimination with partial pivoting.
fn dense_solve(a: &ConvectionDiffusion, b: &[f64]) -> Vec<f64> {
    let n = a.n;
    let mut m: Vec<Vec<f64>> = (0..n)
        .map(|i| (0..n).map(|j| a.entry(i, j)).collect())
        .collect();
    let mut x = b.to_vec();
    for c in 0..n {
        let p = (c..n)
            .max_by(|&r, &s| m[r][c].abs().total_cmp(&m[s][c].abs()))
            .unwrap();
        m.swap(c, p);
        x.swap(c, p);
        for r in c + 1..n {
            let f = m[r][c] / m[c][c];
            for k in c..n {
                m[r][k] -= f * m[c][k];
            }
            x[r] -= f * x[c];
        }
    }
    for c in (0..n).rev() {
        x[c] = (x[c] - (c + 1..n).map(|k| m[c][k] * x[k]).sum::<f64>()) / m[c][c];
    }
    x
}

#[test]
fn bicgstab_matches_a_dense_solve_of_a_nonsymmetric_system() {
    let a = ConvectionDiffusion { n: 300, c: 0.4 };
    let b: Vec<f64> = (0..a.n)
        .map(|i| ((i * 37 % 11) as f64 - 5.0) / 5.0)
        .collect();
    let exact = dense_solve(&a, &b);
    let mut x = vec![0.0; a.n];
    let params = SolverParams {
        tolerance: 1e-10,
        max_iterations: 2000,
    };
    let mut jacobi = Jacobi::default();
    jacobi.setup(&a).unwrap();
    let info = BiCgStab::default()
        .solve(&a, &mut jacobi, &b, &mut x, params)
        .unwrap();
    assert!(info.converged && info.relative_residual <= 1e-9, "{info:?}");
    let err = x
        .iter()
        .zip(&exact)
        .map(|(x, e)| (x - e).powi(2))
        .sum::<f64>()
        .sqrt();
    let norm = exact.iter().map(|e| e * e).sum::<f64>().sqrt();
    assert!(err / norm < 1e-7, "relative error {}", err / norm);

    // A warm start from the solution needs one iteration at most (one unless it is exact).
    let info = BiCgStab::default()
        .solve(&a, &mut jacobi, &b, &mut x, params)
        .unwrap();
    assert!(info.iterations <= 1, "{info:?}");
}

/// The operator of `ConvectionDiffusion` that counts its applies.
struct Counted<'a> {
    a: &'a ConvectionDiffusion,
    applies: std::sync::atomic::AtomicUsize,
}

impl LinearOperator for Counted<'_> {
    fn len(&self) -> usize {
        self.a.len()
    }
    fn apply(&self, x: &[f64], y: &mut [f64]) {
        self.applies
            .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        self.a.apply(x, y);
    }
    fn diagonal(&self, d: &mut [f64]) {
        self.a.diagonal(d);
    }
}

fn true_relative_residual(a: &impl LinearOperator, b: &[f64], x: &[f64]) -> f64 {
    let mut ax = vec![0.0; a.len()];
    a.apply(x, &mut ax);
    let norm = |v: &mut dyn Iterator<Item = f64>| v.map(|e| e * e).sum::<f64>().sqrt();
    norm(&mut b.iter().zip(&ax).map(|(b, ax)| b - ax)) / norm(&mut b.iter().copied())
}

/// A converged solve reports its recursively updated residual, which stays within rounding of
/// the true one, and spends no apply on it: two per iteration and one for the start. A solve
/// cut at its iteration limit reports the true residual, after one more apply.
#[test]
fn a_solve_reports_its_residual_without_an_apply_once_converged() {
    let a = ConvectionDiffusion { n: 300, c: 0.4 };
    let b: Vec<f64> = (0..a.n)
        .map(|i| ((i * 29 % 13) as f64 - 6.0) / 6.0)
        .collect();
    let mut jacobi = Jacobi::default();
    jacobi.setup(&a).unwrap();
    for tolerance in [1e-3, 1e-6, 1e-10] {
        let counted = Counted {
            a: &a,
            applies: 0.into(),
        };
        let mut x = vec![0.5; a.n];
        let params = SolverParams {
            tolerance,
            max_iterations: 2000,
        };
        let info = BiCgStab::default()
            .solve(&counted, &mut jacobi, &b, &mut x, params)
            .unwrap();
        let applies = counted.applies.into_inner();
        let truth = true_relative_residual(&a, &b, &x);
        assert!(
            info.converged && info.relative_residual <= tolerance,
            "{info:?}"
        );
        assert!(
            (info.relative_residual - truth).abs() <= 1e-12,
            "reported {} against the true {truth}",
            info.relative_residual
        );
        // The last iteration may stop halfway, after its first apply.
        let full = 1 + 2 * info.iterations;
        assert!(
            applies == full || applies == full - 1,
            "{applies} applies, {info:?}"
        );
    }
    let counted = Counted {
        a: &a,
        applies: 0.into(),
    };
    let mut x = vec![0.5; a.n];
    let params = SolverParams {
        tolerance: 1e-10,
        max_iterations: 5,
    };
    let info = BiCgStab::default()
        .solve(&counted, &mut jacobi, &b, &mut x, params)
        .unwrap();
    assert!(!info.converged && info.iterations == 5, "{info:?}");
    assert_eq!(counted.applies.into_inner(), 1 + 2 * 5 + 1);
    let truth = true_relative_residual(&a, &b, &x);
    assert!(
        (info.relative_residual - truth).abs() <= 1e-12 * truth,
        "reported {} against the true {truth}",
        info.relative_residual
    );
}

/// A warm start that already meets the tolerance still takes one iteration, so that solves
/// warm-started one from the other drive the residual down instead of leaving the first one's
/// error standing (`Run::after_residual`); an exact start takes none.
#[test]
fn a_warm_start_within_the_tolerance_still_takes_an_iteration() {
    let a = ConvectionDiffusion { n: 20, c: 0.4 };
    let b: Vec<f64> = (0..a.n)
        .map(|i| ((i * 29 % 13) as f64 - 6.0) / 6.0)
        .collect();
    let mut jacobi = Jacobi::default();
    jacobi.setup(&a).unwrap();
    let tight = SolverParams {
        tolerance: 1e-12,
        max_iterations: 2000,
    };
    let mut solution = vec![0.0; a.n];
    BiCgStab::default()
        .solve(&a, &mut jacobi, &b, &mut solution, tight)
        .unwrap();
    let mut x: Vec<f64> = solution
        .iter()
        .enumerate()
        .map(|(i, v)| v + 1e-6 * (0.3 * i as f64).sin())
        .collect();
    let before = true_relative_residual(&a, &b, &x);
    let loose = SolverParams {
        tolerance: 1e-3,
        ..tight
    };
    assert!(before < loose.tolerance, "the start's residual {before}");
    // Solved again from its last solution, as each step of a run is warm-started: each solve
    // takes its one iteration and the residual falls from solve to solve.
    for _ in 0..10 {
        let info = BiCgStab::default()
            .solve(&a, &mut jacobi, &b, &mut x, loose)
            .unwrap();
        assert_eq!(info.iterations, 1, "{info:?}");
        assert!(info.relative_residual <= loose.tolerance, "{info:?}");
    }
    // With Jacobi on this system ten such solves halve it (0.48); the multigrid cuts a PPE's by
    // about 0.4 an iteration.
    let after = true_relative_residual(&a, &b, &x);
    assert!(
        after < 0.75 * before,
        "the residual {before} became {after}"
    );
    // b = A x₀ to the bit: the start's residual is exactly zero.
    let mut exact = x.clone();
    let mut b_exact = vec![0.0; a.n];
    a.apply(&exact, &mut b_exact);
    let info = BiCgStab::default()
        .solve(&a, &mut jacobi, &b_exact, &mut exact, loose)
        .unwrap();
    assert_eq!(info.iterations, 0, "{info:?}");
    assert_eq!(exact, x);
}

/// Two systems solved in lockstep (`BiCgStab::solve_two`) end with the bits, iterations and
/// residuals of the two solved one after the other, whichever is given first: here a tight
/// solve from zero beside a loose one from a warm start, and a solve beside one whose
/// right-hand side is zero (done before its first apply).
#[test]
fn lockstep_solves_have_the_bits_of_solves_in_turn() {
    let a = ConvectionDiffusion { n: 300, c: 0.4 };
    let b: Vec<f64> = (0..a.n)
        .map(|i| ((i * 37 % 11) as f64 - 5.0) / 5.0)
        .collect();
    let b2: Vec<f64> = (0..a.n).map(|i| (0.05 * i as f64).sin()).collect();
    let tight = SolverParams {
        tolerance: 1e-10,
        max_iterations: 2000,
    };
    let loose = SolverParams {
        tolerance: 1e-2,
        ..tight
    };
    let warm: Vec<f64> = (0..a.n).map(|i| 0.1 * (i % 5) as f64).collect();
    let zero = vec![0.0; a.n];
    let mut jacobi = Jacobi::default();
    jacobi.setup(&a).unwrap();
    for (b2, params2) in [(&b2, loose), (&zero, tight)] {
        let (mut x, mut x2) = (vec![0.0; a.n], warm.clone());
        let info = BiCgStab::default()
            .solve(&a, &mut jacobi, &b, &mut x, tight)
            .unwrap();
        let info2 = BiCgStab::default()
            .solve(&a, &mut jacobi, b2, &mut x2, params2)
            .unwrap();
        let (mut y, mut y2) = (vec![0.0; a.n], warm.clone());
        let (both, both2) = BiCgStab::default()
            .solve_two(
                &mut BiCgStab::default(),
                &a,
                &mut jacobi,
                (&b, &mut y, tight),
                (b2, &mut y2, params2),
            )
            .unwrap();
        assert_eq!((both, both2), (info, info2));
        assert!(info.iterations > info2.iterations, "{info:?} {info2:?}");
        assert!(x.iter().zip(&y).all(|(a, b)| a.to_bits() == b.to_bits()));
        assert!(x2.iter().zip(&y2).all(|(a, b)| a.to_bits() == b.to_bits()));
        // The same two, the one that finishes first given first.
        let (mut z2, mut z) = (warm.clone(), vec![0.0; a.n]);
        let swapped = BiCgStab::default()
            .solve_two(
                &mut BiCgStab::default(),
                &a,
                &mut jacobi,
                (b2, &mut z2, params2),
                (&b, &mut z, tight),
            )
            .unwrap();
        assert_eq!(swapped, (info2, info));
        assert!(x.iter().zip(&z).all(|(a, b)| a.to_bits() == b.to_bits()));
        assert!(x2.iter().zip(&z2).all(|(a, b)| a.to_bits() == b.to_bits()));
    }
}

/// Rows with the structure of the PPE's (`ppe::PressureOperator`) over a row of `CELLS` cells,
/// two unknowns per cell, unknown i coupled to i ± 1 with weight 1, a_ii = Σ w (plus 1 at the
/// two ends, a fixed value outside): except in every seventh cell, whose unknowns couple to
/// nothing (every weight clipped, as spray at a large time step gets) and are rows of the
/// identity that give the coarse levels nothing, while their neighbours' rows still couple
/// into them.
struct Spray;

const CELLS: usize = 100;

impl Spray {
    fn isolated(i: usize) -> bool {
        (i / 2) % 7 == 3
    }

    /// (j, w_ij) of row i, and the extra diagonal of the ends.
    fn weights(i: usize) -> (Vec<(usize, f64)>, f64) {
        if Self::isolated(i) {
            return (Vec::new(), 0.0);
        }
        let n = 2 * CELLS;
        let neighbours = [i.checked_sub(1), (i + 1 < n).then_some(i + 1)];
        let end = if i == 0 || i + 1 == n { 1.0 } else { 0.0 };
        (
            neighbours.into_iter().flatten().map(|j| (j, 1.0)).collect(),
            end,
        )
    }
}

impl LinearOperator for Spray {
    fn len(&self) -> usize {
        2 * CELLS
    }

    fn apply(&self, x: &[f64], y: &mut [f64]) {
        for i in 0..self.len() {
            let (w, end) = Self::weights(i);
            y[i] = if Self::isolated(i) {
                x[i]
            } else {
                end * x[i] + w.iter().map(|&(j, w)| w * (x[i] - x[j])).sum::<f64>()
            };
        }
    }

    fn diagonal(&self, d: &mut [f64]) {
        for i in 0..self.len() {
            let (w, end) = Self::weights(i);
            d[i] = if Self::isolated(i) {
                1.0
            } else {
                end + w.iter().map(|&(_, w)| w).sum::<f64>()
            };
        }
    }
}

impl Aggregated<2> for Spray {
    fn dims(&self) -> [usize; 2] {
        [CELLS, 1]
    }

    fn periodic(&self) -> [bool; 2] {
        [false; 2]
    }

    fn aggregate(&self, i: usize) -> Option<usize> {
        Some(i / 2)
    }

    fn add_coarse_row(&self, i: usize, row: &mut [f64]) -> f64 {
        if Self::isolated(i) {
            return 1.0;
        }
        let (w, end) = Self::weights(i);
        let centre = stencil_slot([0, 0]);
        row[centre] += end;
        for &(j, w) in &w {
            row[centre] += w;
            row[stencil_slot([(j / 2) as i64 - (i / 2) as i64, 0])] -= w;
        }
        end + w.iter().map(|&(_, w)| w).sum::<f64>()
    }
}

/// Cells whose unknowns couple to nothing have a zero diagonal on the coarse levels: the
/// multigrid keeps them as cells holding unknowns (the a/30 impact at CFL 1.0
/// has such cells) and BiCGSTAB with it converges.
#[test]
fn multigrid_takes_cells_whose_rows_couple_to_nothing() {
    let a = Spray;
    let b: Vec<f64> = (0..a.len())
        .map(|i| ((i * 13 % 5) as f64 - 2.0) / 2.0)
        .collect();
    let mut x = vec![0.0; a.len()];
    let params = SolverParams {
        tolerance: 1e-10,
        max_iterations: 500,
    };
    let mut multigrid = Multigrid::<2>::default();
    multigrid.setup(&a).unwrap();
    let info = BiCgStab::default()
        .solve(&a, &mut multigrid, &b, &mut x, params)
        .unwrap();
    assert!(
        info.converged && info.relative_residual <= 1e-10,
        "{info:?}"
    );
    for i in (0..a.len()).filter(|&i| Spray::isolated(i)) {
        assert!(
            (x[i] - b[i]).abs() < 1e-8,
            "identity row {i}: {} against {}",
            x[i],
            b[i]
        );
    }
}

/// Rows with the structure of the PPE's around a periodic axis: `2 CELLS` unknowns on a ring,
/// two per cell of a periodic row of cells, unknown i coupled to i ± 1 (around the ring) with
/// weight 1 and a_ii = 2; unknown `fixed`, if any, a row of the identity outside every
/// aggregate (a free-surface or reference particle), whose neighbours' rows then sum above
/// zero on the coarse levels.
struct Ring {
    fixed: Option<usize>,
}

impl Ring {
    fn neighbours(i: usize) -> [usize; 2] {
        let n = 2 * CELLS;
        [(i + n - 1) % n, (i + 1) % n]
    }
}

impl LinearOperator for Ring {
    fn len(&self) -> usize {
        2 * CELLS
    }

    fn apply(&self, x: &[f64], y: &mut [f64]) {
        for i in 0..self.len() {
            y[i] = if self.fixed == Some(i) {
                x[i]
            } else {
                let [l, r] = Self::neighbours(i);
                2.0 * x[i] - x[l] - x[r]
            };
        }
    }

    fn diagonal(&self, d: &mut [f64]) {
        for (i, d) in d.iter_mut().enumerate() {
            *d = if self.fixed == Some(i) { 1.0 } else { 2.0 };
        }
    }
}

impl Aggregated<2> for Ring {
    fn dims(&self) -> [usize; 2] {
        [CELLS, 1]
    }

    fn periodic(&self) -> [bool; 2] {
        [true, false]
    }

    fn aggregate(&self, i: usize) -> Option<usize> {
        (self.fixed != Some(i)).then_some(i / 2)
    }

    fn add_coarse_row(&self, i: usize, row: &mut [f64]) -> f64 {
        row[stencil_slot([0, 0])] += 2.0;
        for j in Self::neighbours(i)
            .into_iter()
            .filter(|&j| self.fixed != Some(j))
        {
            // The neighbour's cell one cell away around the ring.
            let offset = match (j / 2) as i64 - (i / 2) as i64 {
                o if o > 1 => o - CELLS as i64,
                o if o < -1 => o + CELLS as i64,
                o => o,
            };
            row[stencil_slot([offset, 0])] -= 1.0;
        }
        2.0
    }
}

/// The coarse levels couple the cells at the two ends of a periodic axis: on a ring with no
/// fixed unknown every row of level 1 sums to zero (one singular region, every unknown), with
/// one it is anchored, and the multigrid solves it.
#[test]
fn multigrid_couples_cells_across_a_periodic_boundary() {
    let mut multigrid = Multigrid::<2>::default();
    multigrid.setup(&Ring { fixed: None }).unwrap();
    assert_eq!(
        multigrid.unanchored_regions(),
        vec![(0..2 * CELLS).collect::<Vec<_>>()]
    );
    let a = Ring { fixed: Some(0) };
    multigrid.setup(&a).unwrap();
    assert!(multigrid.unanchored_regions().is_empty());
    let b: Vec<f64> = (0..a.len())
        .map(|i| {
            if i == 0 {
                0.0
            } else {
                ((i * 13 % 5) as f64 - 2.0) / 2.0
            }
        })
        .collect();
    let mut x = vec![0.0; a.len()];
    let params = SolverParams {
        tolerance: 1e-10,
        max_iterations: 500,
    };
    let info = BiCgStab::default()
        .solve(&a, &mut multigrid, &b, &mut x, params)
        .unwrap();
    assert!(info.converged, "{info:?}");
    let truth = true_relative_residual(&a, &b, &x);
    assert!(truth <= 1e-9, "{truth}");
}
