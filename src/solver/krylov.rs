//! Matrix-free Krylov solver: BiCGSTAB (van der Vorst 1992) with right preconditioning,
//! against small linear-operator and preconditioner traits. It knows nothing of particles.

use crate::math::memory::ArraySize;
use crate::math::reduce::{dot, fill};
use rayon::prelude::*;

/// A square linear operator y = A x that is applied, never stored.
// Its size is the number of unknowns; an operator of none is never built.
#[allow(clippy::len_without_is_empty)]
pub trait LinearOperator: Sync {
    fn len(&self) -> usize;
    fn apply(&self, x: &[f64], y: &mut [f64]);
    /// The diagonal of A (for the Jacobi preconditioner).
    fn diagonal(&self, diag: &mut [f64]);
}

/// z ≈ A⁻¹ r: a fixed linear map built once per solve from the operator.
pub trait Preconditioner<A: LinearOperator> {
    fn setup(&mut self, a: &A) -> Result<(), SolverError>;
    fn precondition(&mut self, a: &A, r: &[f64], z: &mut [f64]);
}

/// The Jacobi preconditioner z = D⁻¹ r.
#[derive(Default)]
pub struct Jacobi {
    inv_diag: Vec<f64>,
}

impl<A: LinearOperator> Preconditioner<A> for Jacobi {
    fn setup(&mut self, a: &A) -> Result<(), SolverError> {
        inverse_diagonal(a, &mut self.inv_diag)
    }

    fn precondition(&mut self, _: &A, r: &[f64], z: &mut [f64]) {
        let inv = &self.inv_diag;
        fill(z, |i| inv[i] * r[i]);
    }
}

/// 1/a_ii of every row; an error for a zero on the diagonal.
pub fn inverse_diagonal(a: &impl LinearOperator, inv: &mut Vec<f64>) -> Result<(), SolverError> {
    inv.resize(a.len(), 0.0);
    a.diagonal(inv);
    if let Some(row) = inv.iter().position(|&d| d == 0.0) {
        return Err(SolverError::ZeroDiagonal { row });
    }
    inv.par_iter_mut().for_each(|d| *d = 1.0 / *d);
    Ok(())
}

#[derive(Clone, Copy, Debug)]
pub struct SolverParams {
    /// Stop when ‖b − Ax‖ ≤ tolerance ‖b‖.
    pub tolerance: f64,
    pub max_iterations: usize,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolveInfo {
    pub iterations: usize,
    /// True relative residual ‖b − Ax‖/‖b‖ at exit.
    pub relative_residual: f64,
    pub converged: bool,
}

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum SolverError {
    #[error("BiCGSTAB produced a non-finite residual after {iterations} iterations")]
    NotFinite { iterations: usize },
    #[error("a zero on the diagonal at row {row}: the preconditioner is undefined")]
    ZeroDiagonal { row: usize },
}

/// BiCGSTAB work vectors, allocated once and reused for every solve.
#[derive(Default)]
pub struct BiCgStab {
    r: Vec<f64>,
    r_hat: Vec<f64>,
    p: Vec<f64>,
    v: Vec<f64>,
    s: Vec<f64>,
    t: Vec<f64>,
    p_hat: Vec<f64>,
    s_hat: Vec<f64>,
}

fn norm(a: &[f64]) -> f64 {
    dot(a, a).sqrt()
}

impl BiCgStab {
    /// The work vectors, one entry per unknown each.
    pub fn arrays(&self) -> Vec<ArraySize> {
        let BiCgStab {
            r,
            r_hat,
            p,
            v,
            s,
            t,
            p_hat,
            s_hat,
        } = self;
        vec![
            ArraySize::of("BiCGSTAB r", r),
            ArraySize::of("BiCGSTAB r̂", r_hat),
            ArraySize::of("BiCGSTAB p", p),
            ArraySize::of("BiCGSTAB v", v),
            ArraySize::of("BiCGSTAB s", s),
            ArraySize::of("BiCGSTAB t", t),
            ArraySize::of("BiCGSTAB p̂", p_hat),
            ArraySize::of("BiCGSTAB ŝ", s_hat),
        ]
    }

    fn resize(&mut self, n: usize) {
        for v in [
            &mut self.r,
            &mut self.r_hat,
            &mut self.p,
            &mut self.v,
            &mut self.s,
            &mut self.t,
            &mut self.p_hat,
            &mut self.s_hat,
        ] {
            v.resize(n, 0.0);
        }
    }

    /// Solves A x = b with preconditioner `m`, set up for `a` (`Preconditioner::setup`),
    /// starting from the `x` given (warm start).
    pub fn solve<A: LinearOperator>(
        &mut self,
        a: &A,
        m: &mut impl Preconditioner<A>,
        b: &[f64],
        x: &mut [f64],
        params: SolverParams,
    ) -> Result<SolveInfo, SolverError> {
        let n = a.len();
        self.resize(n);

        let b_norm = norm(b);
        if b_norm == 0.0 {
            x.fill(0.0);
            return Ok(SolveInfo {
                iterations: 0,
                relative_residual: 0.0,
                converged: true,
            });
        }
        let tol = params.tolerance * b_norm;
        let Self {
            r,
            r_hat,
            p,
            v,
            s,
            t,
            p_hat,
            s_hat,
        } = self;

        a.apply(x, r);
        r.par_iter_mut().zip(b).for_each(|(r, b)| *r = b - *r);
        r_hat.copy_from_slice(r);
        p.fill(0.0);
        v.fill(0.0);
        let (mut rho_old, mut alpha, mut omega) = (1.0, 1.0, 1.0);
        let mut iterations = 0;
        let mut converged = norm(r) <= tol;
        while !converged && iterations < params.max_iterations {
            iterations += 1;
            let mut rho = dot(r_hat, r);
            if rho.abs() < 1e-300 {
                // Breakdown of the shadow residual: restart from the current residual.
                r_hat.copy_from_slice(r);
                p.fill(0.0);
                v.fill(0.0);
                (rho_old, alpha, omega) = (1.0, 1.0, 1.0);
                rho = dot(r_hat, r);
            }
            let beta = (rho / rho_old) * (alpha / omega);
            p.par_iter_mut()
                .enumerate()
                .for_each(|(i, p)| *p = r[i] + beta * (*p - omega * v[i]));
            m.precondition(a, p, p_hat);
            a.apply(p_hat, v);
            alpha = rho / dot(r_hat, v);
            fill(s, |i| r[i] - alpha * v[i]);
            if norm(s) <= tol {
                x.par_iter_mut()
                    .zip(p_hat.par_iter())
                    .for_each(|(x, ph)| *x += alpha * ph);
                converged = true;
                break;
            }
            m.precondition(a, s, s_hat);
            a.apply(s_hat, t);
            omega = dot(t, s) / dot(t, t);
            x.par_iter_mut()
                .enumerate()
                .for_each(|(i, x)| *x += alpha * p_hat[i] + omega * s_hat[i]);
            fill(r, |i| s[i] - omega * t[i]);
            let r_norm = norm(r);
            if !r_norm.is_finite() {
                return Err(SolverError::NotFinite { iterations });
            }
            converged = r_norm <= tol;
            rho_old = rho;
        }
        // Report the true residual, not the recursively updated one.
        a.apply(x, t);
        t.par_iter_mut().zip(b).for_each(|(t, b)| *t = b - *t);
        let relative_residual = norm(t) / b_norm;
        if !relative_residual.is_finite() {
            return Err(SolverError::NotFinite { iterations });
        }
        Ok(SolveInfo {
            iterations,
            relative_residual,
            converged,
        })
    }
}
