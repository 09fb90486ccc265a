//! BiCGSTAB against a dense direct solve on a non-symmetric sparse system.

use isph::linsolve::{BiCgStab, Jacobi, LinearOperator, SolverParams};

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
    let info = BiCgStab::default()
        .solve(&a, &mut Jacobi::default(), &b, &mut x, params)
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

    // A warm start from the solution needs (almost) no iteration.
    let info = BiCgStab::default()
        .solve(&a, &mut Jacobi::default(), &b, &mut x, params)
        .unwrap();
    assert!(info.iterations <= 1, "{info:?}");
}
