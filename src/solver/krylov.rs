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
    /// y = A x and y₂ = A x₂, the same bits as two applies (an operator that walks its rows
    /// applies both in one walk).
    fn apply_two(&self, x: &[f64], y: &mut [f64], x2: &[f64], y2: &mut [f64]) {
        self.apply(x, y);
        self.apply(x2, y2);
    }
    /// The diagonal of A (for the Jacobi preconditioner).
    fn diagonal(&self, diag: &mut [f64]);
}

/// z ≈ A⁻¹ r: a fixed linear map built once per solve from the operator; z depends on r alone,
/// never on earlier calls (`BiCgStab::solve_two` interleaves two solves' calls).
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
    /// Stop when the residual ‖b − Ax‖, as BiCGSTAB updates it recursively, is at most
    /// tolerance ‖b‖.
    pub tolerance: f64,
    pub max_iterations: usize,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolveInfo {
    pub iterations: usize,
    /// Relative residual ‖b − Ax‖/‖b‖ at exit: BiCGSTAB's recursively updated residual where
    /// the solve converged, the true one where it stopped at its iteration limit.
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
        let mut run = Run::new(self, a.len(), b, x, params);
        loop {
            match run.prepare(a, m) {
                Some((input, output)) => a.apply(input, output),
                None => return run.outcome(),
            }
            run.absorb();
        }
    }

    /// Solves A x = b with `self`'s vectors and A x₂ = b₂ with `other`'s, in lockstep: while
    /// both run, each apply of A is one `LinearOperator::apply_two` for both systems (one walk
    /// of a matrix-free operator's rows instead of two). Each system's arithmetic is that of
    /// `solve`: the same iterates and bits as two solves one after the other, as `m`'s
    /// `precondition` depends on its input alone, never on its earlier calls. The first error
    /// of either system ends both.
    pub fn solve_two<A: LinearOperator>(
        &mut self,
        other: &mut BiCgStab,
        a: &A,
        m: &mut impl Preconditioner<A>,
        (b, x, params): (&[f64], &mut [f64], SolverParams),
        (b2, x2, params2): (&[f64], &mut [f64], SolverParams),
    ) -> Result<(SolveInfo, SolveInfo), SolverError> {
        let n = a.len();
        let (mut first, mut second) = (
            Run::new(self, n, b, x, params),
            Run::new(other, n, b2, x2, params2),
        );
        loop {
            match (first.prepare(a, m), second.prepare(a, m)) {
                (Some((x, y)), Some((x2, y2))) => a.apply_two(x, y, x2, y2),
                (Some((x, y)), None) | (None, Some((x, y))) => a.apply(x, y),
                (None, None) => return Ok((first.outcome()?, second.outcome()?)),
            }
            first.absorb();
            second.absorb();
            for run in [&mut first, &mut second] {
                if let Some(Err(_)) = run.outcome {
                    return Err(run.outcome().expect_err("the run failed"));
                }
            }
        }
    }
}

/// Where a BiCGSTAB run stands: each phase but `Done` waits for one apply of A.
#[derive(Clone, Copy)]
enum Phase {
    /// r = A x₀, for r = b − A x₀.
    Start,
    /// v = A p̂, p̂ the preconditioned search direction.
    Search,
    /// t = A ŝ, ŝ the preconditioned intermediate residual.
    Stabilise,
    /// t = A x, for the true residual reported by a solve that stopped at its iteration
    /// limit (a converged one reports its last recursive residual, without this apply).
    Finish,
    Done,
}

/// One BiCGSTAB solve (van der Vorst 1992, right preconditioning) cut at its applies of A, so
/// that two solves can share them (`BiCgStab::solve_two`). `prepare` does the work before the
/// next apply and names its input and output; `absorb` the work after it.
struct Run<'a> {
    work: &'a mut BiCgStab,
    b: &'a [f64],
    x: &'a mut [f64],
    params: SolverParams,
    b_norm: f64,
    tol: f64,
    phase: Phase,
    iterations: usize,
    rho: f64,
    rho_old: f64,
    alpha: f64,
    omega: f64,
    outcome: Option<Result<SolveInfo, SolverError>>,
}

impl<'a> Run<'a> {
    fn new(
        work: &'a mut BiCgStab,
        n: usize,
        b: &'a [f64],
        x: &'a mut [f64],
        params: SolverParams,
    ) -> Self {
        work.resize(n);
        let b_norm = norm(b);
        let mut run = Self {
            work,
            b,
            x,
            params,
            b_norm,
            tol: params.tolerance * b_norm,
            phase: Phase::Start,
            iterations: 0,
            rho: 1.0,
            rho_old: 1.0,
            alpha: 1.0,
            omega: 1.0,
            outcome: None,
        };
        if b_norm == 0.0 {
            run.x.fill(0.0);
            run.finish(Ok(SolveInfo {
                iterations: 0,
                relative_residual: 0.0,
                converged: true,
            }));
        } else if run.x.iter().all(|&x| x == 0.0) {
            // A start from zero: A x₀ = 0 without an apply (the density correction's solve).
            run.work.r.fill(0.0);
            run.absorb();
        }
        run
    }

    fn finish(&mut self, outcome: Result<SolveInfo, SolverError>) {
        self.phase = Phase::Done;
        self.outcome = Some(outcome);
    }

    fn outcome(&mut self) -> Result<SolveInfo, SolverError> {
        self.outcome
            .take()
            .expect("a run is done before its outcome")
    }

    /// The work before the next apply of A, and that apply's input and output (None: done).
    fn prepare<A: LinearOperator>(
        &mut self,
        a: &A,
        m: &mut impl Preconditioner<A>,
    ) -> Option<(&[f64], &mut [f64])> {
        let w = &mut *self.work;
        match self.phase {
            Phase::Start => Some((&*self.x, &mut w.r)),
            Phase::Search => {
                self.iterations += 1;
                let mut rho = dot(&w.r_hat, &w.r);
                if rho.abs() < 1e-300 {
                    // Breakdown of the shadow residual: restart from the current residual.
                    w.r_hat.copy_from_slice(&w.r);
                    w.p.fill(0.0);
                    w.v.fill(0.0);
                    (self.rho_old, self.alpha, self.omega) = (1.0, 1.0, 1.0);
                    rho = dot(&w.r_hat, &w.r);
                }
                self.rho = rho;
                let beta = (rho / self.rho_old) * (self.alpha / self.omega);
                let (r, v, omega) = (&w.r, &w.v, self.omega);
                w.p.par_iter_mut()
                    .enumerate()
                    .for_each(|(i, p)| *p = r[i] + beta * (*p - omega * v[i]));
                m.precondition(a, &w.p, &mut w.p_hat);
                Some((&w.p_hat, &mut w.v))
            }
            Phase::Stabilise => {
                m.precondition(a, &w.s, &mut w.s_hat);
                Some((&w.s_hat, &mut w.t))
            }
            Phase::Finish => Some((&*self.x, &mut w.t)),
            Phase::Done => None,
        }
    }

    /// The work after the apply `prepare` asked for (a non-finite residual ends the run with
    /// an error).
    fn absorb(&mut self) {
        let w = &mut *self.work;
        match self.phase {
            Phase::Start => {
                let b = self.b;
                w.r.par_iter_mut().zip(b).for_each(|(r, b)| *r = b - *r);
                w.r_hat.copy_from_slice(&w.r);
                w.p.fill(0.0);
                w.v.fill(0.0);
                let r_norm = norm(&w.r);
                self.after_residual(r_norm);
            }
            Phase::Search => {
                self.alpha = self.rho / dot(&w.r_hat, &w.v);
                let (r, v, alpha) = (&w.r, &w.v, self.alpha);
                fill(&mut w.s, |i| r[i] - alpha * v[i]);
                let s_norm = norm(&w.s);
                if s_norm <= self.tol {
                    self.x
                        .par_iter_mut()
                        .zip(w.p_hat.par_iter())
                        .for_each(|(x, ph)| *x += alpha * ph);
                    self.after_residual(s_norm);
                } else {
                    self.phase = Phase::Stabilise;
                }
            }
            Phase::Stabilise => {
                let (t, s) = (&w.t, &w.s);
                self.omega = dot(t, s) / dot(t, t);
                let (alpha, omega, p_hat, s_hat) = (self.alpha, self.omega, &w.p_hat, &w.s_hat);
                self.x
                    .par_iter_mut()
                    .enumerate()
                    .for_each(|(i, x)| *x += alpha * p_hat[i] + omega * s_hat[i]);
                fill(&mut w.r, |i| s[i] - omega * t[i]);
                let r_norm = norm(&w.r);
                if !r_norm.is_finite() {
                    let iterations = self.iterations;
                    self.finish(Err(SolverError::NotFinite { iterations }));
                    return;
                }
                self.rho_old = self.rho;
                self.after_residual(r_norm);
            }
            Phase::Finish => {
                let b = self.b;
                w.t.par_iter_mut().zip(b).for_each(|(t, b)| *t = b - *t);
                let relative_residual = norm(&w.t) / self.b_norm;
                let iterations = self.iterations;
                let outcome = if relative_residual.is_finite() {
                    Ok(SolveInfo {
                        iterations,
                        relative_residual,
                        converged: false,
                    })
                } else {
                    Err(SolverError::NotFinite { iterations })
                };
                self.finish(outcome);
            }
            Phase::Done => {}
        }
    }

    /// Ends the run once the residual's norm `r_norm` meets the tolerance, reporting it: the
    /// recursively updated residual, which in f64 stays within rounding of the true one at
    /// the tolerances used (1e-6 of ‖b‖ and looser), so that a converged solve spends no
    /// apply of A on the report. Otherwise another iteration, or at the iteration limit the
    /// true residual.
    ///
    /// A start that already meets the tolerance still takes one iteration, unless it is exact
    /// to rounding (its residual within ε ‖b‖, or too small to square in f64) or the solve
    /// allows none. Warm-started from the last step's pressure, a solve that stopped at once
    /// would leave that pressure's error standing step after step: in water at rest the error
    /// the tolerance allows is the same in every step, a steady force that lifted the whole
    /// water off the floor at a constant speed (docs/stabilisation.md, "A solve that stops at
    /// once"). One iteration a step shrinks it step after step instead. (With an iteration
    /// limit of 1 that iteration may end above the tolerance, as BiCGSTAB's residual need not
    /// fall, and the solve then reports itself unconverged.)
    fn after_residual(&mut self, r_norm: f64) {
        let exact = r_norm <= f64::EPSILON * self.b_norm;
        let unsquarable = r_norm * r_norm < f64::MIN_POSITIVE;
        let first =
            self.iterations == 0 && !exact && !unsquarable && self.params.max_iterations > 0;
        if r_norm <= self.tol && !first {
            self.finish(Ok(SolveInfo {
                iterations: self.iterations,
                relative_residual: r_norm / self.b_norm,
                converged: true,
            }));
        } else if self.iterations >= self.params.max_iterations {
            self.phase = Phase::Finish;
        } else {
            self.phase = Phase::Search;
        }
    }
}
