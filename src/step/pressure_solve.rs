//! The pressure Poisson equation, Eq. (6), assembled matrix-free (`solver::ppe`) and solved by
//! BiCGSTAB preconditioned by the aggregation multigrid (the unknowns are the fluid pressures,
//! walls hold none), as two solves on one operator: the projection's, from the divergence of
//! u*, warm-started from the last pressure; and with α > 0 the density correction's, from the
//! density-invariance term, started from zero (`density_correction` turns it into a
//! displacement). Neither right-hand side depends on the other's solution, so the two run in
//! lockstep (`BiCgStab::solve_two`): while both iterate, each apply of the operator walks the
//! neighbours once for both, at 0.56 of the cost of two walks (docs/performance.md, "The
//! pressure solve"), with the same bits as two solves one after the other.

use super::free_surface::{FreeSurface, Surface};
use super::time_step::StepLength;
use super::{Stage, StepSettings};
use crate::boundary::ghosts::BodyForce;
use crate::math::memory::ArraySize;
use crate::math::reduce::{self, fill};
use crate::neighbours::Neighbours;
use crate::particles::{Kind, Particles};
use crate::scene::GhostPressure;
use crate::solver::krylov::{BiCgStab, Preconditioner, SolveInfo, SolverError, SolverParams};
use crate::solver::multigrid::Multigrid;
use crate::solver::ppe::{self, GhostRows, PressureOperator, Role};
use crate::sph::interface;
use crate::sph::Corrections;
use rayon::prelude::*;

pub const NAME: &str = "pressure solve";

/// The relative residual at which the density correction's solve stops (or the scene's
/// tolerance, if looser). P_α relaxes the fraction α of a density error of a few tenths of a
/// per cent each step: 1% of it is far below what the next step sees, and from a zero start the
/// solve at the projection's 1e-6 costs as many iterations as the projection itself
/// (docs/stabilisation.md, "The density correction moves positions, not velocities").
const DENSITY_TOLERANCE: f64 = 1e-2;

pub struct PressureSolve<const D: usize> {
    /// V_j = m_j/ρ0_j of fluid particles (the unknowns of the PPE).
    fluid_volume: Vec<f64>,
    /// 1 at a fluid particle and 0 at a body's, where some rows are held bodies' ghosts
    /// (`ppe::GhostRows`); empty otherwise.
    is_fluid: Vec<f64>,
    /// 1 at a ghost row, 0 elsewhere, with `is_fluid`.
    is_ghost: Vec<f64>,
    rhs: Vec<f64>,
    /// The projection's solution (before the cavitation clip that the particles' pressure takes).
    pressure: Vec<f64>,
    bicgstab: BiCgStab,
    /// The density correction's solve, with α > 0 (`density_correction`).
    density: Option<DensitySolve>,
    multigrid: Multigrid<D>,
}

/// The density correction's right-hand side, its solution P_α and its BiCGSTAB vectors (its
/// own, as it runs beside the projection's).
#[derive(Default)]
struct DensitySolve {
    rhs: Vec<f64>,
    pressure: Vec<f64>,
    bicgstab: BiCgStab,
}

impl DensitySolve {
    /// Solves for P_α from zero, to `DENSITY_TOLERANCE`, in lockstep with the `projection`
    /// (right-hand side, warm-started solution, parameters) on the projection's `bicgstab`
    /// vectors; reports both solves together: their iterations summed, the larger residual.
    fn solve_beside<const D: usize>(
        &mut self,
        bicgstab: &mut BiCgStab,
        op: &PressureOperator<D>,
        mg: &mut Multigrid<D>,
        projection: (&[f64], &mut [f64], SolverParams),
    ) -> Result<SolveInfo, SolverError> {
        self.pressure.clear();
        self.pressure.resize(op.roles.len(), 0.0);
        let params = SolverParams {
            tolerance: projection.2.tolerance.max(DENSITY_TOLERANCE),
            ..projection.2
        };
        let correction = (&self.rhs[..], &mut self.pressure[..], params);
        let (info, density) =
            bicgstab.solve_two(&mut self.bicgstab, op, mg, projection, correction)?;
        Ok(SolveInfo {
            iterations: info.iterations + density.iterations,
            relative_residual: info.relative_residual.max(density.relative_residual),
            converged: info.converged && density.converged,
        })
    }
}

impl<const D: usize> PressureSolve<D> {
    /// The solve of a step whose density-invariance term is (`density_correction`) or is not
    /// (α = 0) solved for.
    pub fn new(density_correction: bool) -> Self {
        Self {
            fluid_volume: Vec::new(),
            is_fluid: Vec::new(),
            is_ghost: Vec::new(),
            rhs: Vec::new(),
            pressure: Vec::new(),
            bicgstab: BiCgStab::default(),
            density: density_correction.then(DensitySolve::default),
            multigrid: Multigrid::default(),
        }
    }

    /// Solves for Pⁿ⁺¹ from u* (`u_star`), and with α > 0 for P_α from the density error,
    /// with the roles of `surface` (sealed regions are pinned there), the divergence corrected
    /// by `corrections`, the wall ghosts carrying `ghost` where the body force varies
    /// (`body_forces`); `probe`, if any, is handed the operator first. The report sums both
    /// solves' iterations and keeps the larger residual.
    #[allow(clippy::too_many_arguments)]
    pub fn run(
        &mut self,
        nb: &Neighbours<D>,
        p: &Particles<D>,
        set: &StepSettings<D>,
        surface: &mut FreeSurface<D>,
        corrections: Corrections<D>,
        interfaces: Option<interface::Field<D>>,
        ghost: Option<&[Vec<f64>; D]>,
        force: BodyForce<D>,
        u_star: &[Vec<f64>; D],
        step: StepLength,
        probe: Option<&mut dyn FnMut(&PressureOperator<D>)>,
    ) -> Result<SolveInfo, SolverError> {
        let nf = surface.full_support().len();
        let Self {
            fluid_volume,
            is_fluid,
            is_ghost,
            rhs,
            pressure,
            bicgstab,
            density,
            multigrid,
        } = self;
        pressure.resize(nf, 0.0);
        let (spacing, dt) = (set.spacing, step.dt);
        surface.set_surface_rows(|i, l| match (l, force.up(i)) {
            (Some(l), Some(up)) => {
                ppe::surface_row_vector(l, up, ppe::surface_depth(nb, p, up, spacing, dt, i))
            }
            _ => [0.0; D],
        });
        is_fluid.clear();
        is_ghost.clear();
        let roles = surface.output().roles;
        if roles.contains(&Role::Ghost) {
            is_fluid.extend((0..nf).map(|i| f64::from(p.kind[i] == Kind::Fluid)));
            is_ghost.extend(roles.iter().map(|&r| f64::from(r == Role::Ghost)));
        }
        let ghosts = (!is_fluid.is_empty()).then_some(GhostRows {
            is_fluid,
            is_ghost,
            force,
        });
        with_operator(
            fluid_volume,
            multigrid,
            nb,
            p,
            set,
            surface,
            interfaces,
            ghost,
            ghosts,
            |op, mg, sealed, s| {
                if let Some(probe) = probe {
                    probe(op);
                }
                let reference = s.reference;
                let closed = reference.is_some();
                ppe::projection_source(
                    op,
                    closed,
                    sealed,
                    set.spacing,
                    corrections,
                    u_star,
                    step.dt,
                    step.carried_time(),
                    rhs,
                );
                let roles = op.roles;
                // In a closed box the last pressure is shifted to the new reference's level.
                let level = reference.map_or(0.0, |r| p.pressure[r]);
                fill(pressure, |i| match roles[i] {
                    Role::Interior | Role::Surface | Role::Ghost => p.pressure[i] - level,
                    Role::Splash | Role::Reference => 0.0,
                });
                let info = match density {
                    None => bicgstab.solve(op, mg, rhs, pressure, set.solver)?,
                    Some(d) => {
                        let rate = set.alpha / step.limit;
                        let full = s.full_support;
                        ppe::density_source(op, closed, sealed, full, step.dt, rate, &mut d.rhs);
                        d.solve_beside(bicgstab, op, mg, (rhs, pressure, set.solver))?
                    }
                };
                if closed {
                    zero_mean_pressure(p, pressure);
                }
                Ok(info)
            },
        )
    }

    /// The projection's solution of the last `run` (before the cavitation clip the particles'
    /// pressure takes).
    pub fn pressure(&self) -> &[f64] {
        &self.pressure
    }

    /// The density correction's solution P_α of the last `run` (empty with α = 0).
    pub fn density_pressure(&self) -> &[f64] {
        self.density.as_ref().map_or(&[], |d| &d.pressure)
    }
}

/// Builds the operator of the PPE rows of `surface`'s roles and sets the multigrid up on it,
/// then calls `solve` with the operator, the multigrid, the sealed regions and the surface.
///
/// Water sealed off from the free surface (a compartment under a lid, a pocket against a wall)
/// has no pressure level of its own: its highest particle is pinned to P = 0, the role the
/// free surface plays elsewhere, and the hierarchy rebuilt (a pinned region is anchored, so
/// the second pass finds none).
#[allow(clippy::too_many_arguments)]
fn with_operator<const D: usize, R>(
    fluid_volume: &mut Vec<f64>,
    multigrid: &mut Multigrid<D>,
    nb: &Neighbours<D>,
    p: &Particles<D>,
    set: &StepSettings<D>,
    surface: &mut FreeSurface<D>,
    interfaces: Option<interface::Field<D>>,
    ghost: Option<&[Vec<f64>; D]>,
    ghosts: Option<GhostRows<D>>,
    solve: impl FnOnce(
        &PressureOperator<D>,
        &mut Multigrid<D>,
        &[Vec<usize>],
        &Surface<D>,
    ) -> Result<R, SolverError>,
) -> Result<R, SolverError> {
    let n = surface.full_support().len();
    ppe::fluid_volumes(p, n, fluid_volume);
    let mut sealed = Vec::new();
    let (op, s) = loop {
        let s = surface.output();
        let op = PressureOperator {
            nb,
            p,
            roles: s.roles,
            row_vectors: s.row_vectors,
            fluid_volume,
            gravity: set.gravity,
            ghost_force: set.ghost_force(ghost),
            interfaces,
            ghosts,
        };
        multigrid.setup(&op)?;
        let unanchored = multigrid.unanchored_regions();
        if unanchored.is_empty() {
            break (op, s);
        }
        for region in &unanchored {
            let top = ppe::highest(p, set.gravity, region.iter().copied())
                .expect("a region holds unknowns");
            surface.pin(top);
        }
        sealed.extend(unanchored);
    };
    solve(&op, multigrid, &sealed, &s)
}

/// Shifts the fluid pressures of a closed box to a zero mean (walls hold no unknown): the
/// PPE fixes them only up to a constant, and a pressure level that does not depend on which
/// particle happened to be the reference keeps the frames comparable.
fn zero_mean_pressure<const D: usize>(p: &Particles<D>, pressure: &mut [f64]) {
    let [volume, integral] = reduce::sums(pressure.len(), |i| {
        let v = p.mass[i] / p.rest_density[i];
        [v, v * pressure[i]]
    });
    let mean = integral / volume;
    pressure.par_iter_mut().for_each(|x| *x -= mean);
}

impl<const D: usize> Stage<D> for PressureSolve<D> {
    fn name(&self) -> &'static str {
        NAME
    }

    fn describe(&self, set: &StepSettings<D>) -> String {
        let density = if set.alpha > 0.0 {
            format!("; a second solve, from zero, of the density correction's P_α, source −α(ρ0 − ρ)/Δt², α = {}, mirror walls, P_α = 0 on the free surface, in lockstep with the projection's (one walk of the neighbours for both applies)", set.alpha)
        } else {
            String::new()
        };
        format!(
            "Eq. (6): the projection's source −(ρ0/Δt)(∇·u* − (Δt/2)∂_a u_b ∂_b u_a){}, the divergence at the midpoint of the drift; Eq. (27) Laplacian made first-order consistent near walls and the free surface, matrix-free; walls: {} (no unknowns); free surface: P + δ e·∇P = 0, the surface δ beyond the particle's centre along the way up e (half its thickness, which follows the strain, plus its rise over half a step; in still water P = ρ0|g|δ); BiCGSTAB preconditioned by additive two-level aggregation multigrid (Jacobi + a coarse V-cycle over the cell blocks), warm start{density}",
            if set.effects.kernel_correction { " (corrected by L_i)" } else { "" },
            match set.ghost_pressure {
                GhostPressure::Hydrostatic => "Neumann ghosts of the fluid pressure, P_b = P_i + ρ0 g·N_b r_bi",
                GhostPressure::Mirror => "mirror ghosts of the fluid pressure, P_b = P_i (∂P/∂n = 0)",
            }
        )
    }

    fn arrays(&self) -> Vec<ArraySize> {
        let mut arrays = vec![
            ArraySize::of("fluid volume", &self.fluid_volume),
            ArraySize::sparse("fluid flags of the ghost rows", &self.is_fluid),
            ArraySize::sparse("ghost flags", &self.is_ghost),
            ArraySize::of("right-hand side", &self.rhs),
            ArraySize::of("pressure", &self.pressure),
        ];
        arrays.extend(self.bicgstab.arrays());
        if let Some(d) = &self.density {
            arrays.push(ArraySize::of("density correction right-hand side", &d.rhs));
            arrays.push(ArraySize::of("density correction pressure", &d.pressure));
            arrays.extend(d.bicgstab.arrays());
        }
        arrays.extend(self.multigrid.fine_arrays());
        arrays
    }
}
