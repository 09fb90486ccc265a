//! The length of a step: the CFL, viscous and body-force limits, and the cut that lands a step
//! on the next frame's time.

use super::{StepError, StepSettings};
use crate::particles::Particles;

/// Viscous time-step limit Δt ≤ C_ν h²/ν.
const VISCOUS_NUMBER: f64 = 0.125;
/// Body-force time-step limit Δt ≤ C_g √(h/|g|).
const BODY_FORCE_NUMBER: f64 = 0.25;
/// A CFL time step below this fraction of the body-force or viscous step (the smaller) is a
/// blow-up.
const COLLAPSE_FRACTION: f64 = 1.0e-3;

/// The length of a step and the limit it was cut from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepLength {
    /// Δt of this step [s].
    pub dt: f64,
    /// Δt_max, the limit of the CFL, viscous and body-force conditions [s]: Δt is shorter
    /// only where the step is cut to land on a frame time. The density-invariance term of the
    /// PPE relaxes the density error over Δt_max, not Δt (`ppe::density_source`).
    pub limit: f64,
    /// Δt of the last step [s] (Δt_max on a run's first step).
    pub previous: f64,
}

/// A step shorter than this fraction of its limit is a sliver (`StepLength::carried_time`):
/// the steps that share a cut (`length`) are never one.
const SLIVER: f64 = 0.5;

impl StepLength {
    /// The time over which the projection takes out the divergence the particles carry into
    /// the step (`ppe::divergence_source`): Δt, but on a sliver of a step (a last step just past
    /// a frame, a frame just before a body's release) the last step's Δt, which made most of it.
    /// Over the sliver the step's pressure would read (1 + Δt_prev/Δt)/2 times the flow's.
    pub fn carried_time(&self) -> f64 {
        if self.dt < SLIVER * self.limit {
            self.previous.max(self.dt)
        } else {
            self.dt
        }
    }
}

/// Which condition sets Δt_max.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Limit {
    /// Δt ≤ CFL dx / max |u|.
    Cfl,
    /// Δt ≤ C_ν h²/ν, with ν the largest viscosity of the scene's fluids.
    Viscous,
    /// Δt ≤ C_g √(h/|g|).
    BodyForce,
}

impl Limit {
    /// The condition in words, with its constant.
    pub fn describe(self) -> String {
        match self {
            Limit::Cfl => "the CFL condition (solver.cfl × dx / the largest fluid speed)".into(),
            Limit::Viscous => format!(
                "the viscous condition ({VISCOUS_NUMBER} h²/ν with the largest fluid viscosity)"
            ),
            Limit::BodyForce => format!("the body-force condition ({BODY_FORCE_NUMBER} √(h/|g|))"),
        }
    }
}

/// Largest stable Δt of particles `p` with kernel width `h` (`Kernel::width`, the quintic's
/// smoothing length): CFL (on the particle spacing), viscous and body-force limits, and the one
/// that sets it. A CFL step far below the smaller of the body-force and viscous steps means the
/// flow has blown up: that is reported, not integrated at ever smaller steps (without gravity
/// the viscous step is the reference; an inviscid flow without gravity has none, and only a
/// non-finite velocity stops it).
pub fn limiting<const D: usize>(
    p: &Particles<D>,
    h: f64,
    set: &StepSettings<D>,
) -> Result<(f64, Limit), StepError> {
    let max_speed = p.max_fluid_speed();
    let g = set.gravity.iter().map(|g| g * g).sum::<f64>().sqrt();
    let (cfl, body_force) = (
        set.cfl * set.spacing / max_speed,
        BODY_FORCE_NUMBER * (h / g).sqrt(),
    );
    let viscous = VISCOUS_NUMBER * h * h / set.max_viscosity;
    let dt = cfl.min(body_force).min(viscous);
    let reference = body_force.min(viscous);
    if reference.is_finite() && cfl < COLLAPSE_FRACTION * reference {
        return Err(StepError::Collapse { dt, max_speed });
    }
    let limit = if dt == cfl {
        Limit::Cfl
    } else if dt == body_force {
        Limit::BodyForce
    } else {
        Limit::Viscous
    };
    Ok((dt, limit))
}

/// The last steps before a target share its cut: within this many steps of it, they are all
/// of one length. A step then follows one at most CUT_SPREAD/(CUT_SPREAD − 1) times as long.
const CUT_SPREAD: f64 = 8.0;

/// The step of at most `limit` towards a target `remaining` ahead, and whether it lands on
/// it: steps of `limit`, and within `CUT_SPREAD` steps of the target the fewest steps of one
/// length that reach it. `previous`: the last step's Δt (none on a run's first step).
///
/// The projection takes out the divergence the last step's drift left over this step's Δt
/// (`ppe::divergence_source`): a step a fraction of the one before reads (1 + Δt_prev/Δt)/2 of
/// the flow's pressure, and the step after a frame (1 + Δt/Δt_prev)/2. Spread over eight
/// steps, a cut reads at most 1.07 and at least 0.94 of it; cut over the last two, up to 1.5
/// and down to 0.75, a spike at each frame time in `probes.csv`. A limit that falls within
/// the spread (a flow speeding up) can take one step more to the frame: on `dam_break_2d`'s
/// limits 0.2% more steps than a cut over two, 2% spread over the whole way to each frame
/// (docs/stabilisation.md, "A short step relaxes less").
pub fn length(limit: f64, remaining: f64, previous: Option<f64>) -> (StepLength, bool) {
    let steps_left = (remaining / limit).ceil().max(1.0);
    let dt = if steps_left == 1.0 {
        remaining
    } else if steps_left <= CUT_SPREAD {
        remaining / steps_left
    } else {
        limit
    };
    let previous = previous.unwrap_or(limit);
    (
        StepLength {
            dt,
            limit,
            previous,
        },
        dt == remaining,
    )
}
