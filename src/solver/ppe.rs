//! The pressure Poisson equation of Eq. (6), assembled matrix-free. The unknowns are the fluid
//! pressures; wall particles are ghosts of them (see `boundary::ghosts`) and hold no unknown.
//!
//! * interior rows:  −∇²P_i = −(ρ0/Δt) ∇·u*_i (`projection_source`), or for the density
//!   correction's P_α the density-invariance term −α (ρ0 − ρ_i)/Δt² alone (`density_source`);
//!   Eq. (6) is their sum. The Laplacian of Eq. (27) is made first-order consistent where the
//!   free surface truncates the kernel. The wall pairs of the Laplacian are known ghost
//!   differences and move to the right-hand side (the projection's; P_α's walls are mirrors).
//! * free-surface rows: P_i + δ_i up·∇P_i = 0 (`surface_row_vector`): P = 0 holds on the
//!   surface itself, δ_i beyond the centre of the outermost particle along the way up, where
//!   the volume that particle stands for ends: half its thickness across the surface, plus the
//!   particle's rise over half a step (`surface_depth`); in still water P_i = ρ0 |g| δ_i. (P_i
//!   = 0 at the particle would put the surface half a spacing too low and the hydrostatic
//!   pressure ρ g dx/2 short everywhere below.) The row couples the particle to its fluid
//!   neighbours through the corrected gradient; the walls' ghosts are its right-hand side.
//! * splash rows (particles too isolated for a gradient): P_i = 0.
//! * ghost rows (a fixed or prescribed body's particles with fluid in reach): the fluid's
//!   pressure continued into the body, a wall moving with it (`Role::Ghost`). The fluid rows
//!   see these ghosts as the walls' are seen, known differences in their right-hand side
//!   (`PressureOperator::ghost_differences`), so the fluid block is the operator of a scene
//!   without the body and the ghost rows follow from it.
//!
//! The walls have no row: their pressures for output are computed after the solve from their
//! fluid neighbours (`ghosts::Ghosts::wall_pressure`). Row i is fluid particle i (the fluid comes
//! first in the sorted order).

use crate::boundary::ghosts::{
    body_ghost_velocity, ghost_pressure_difference, ghost_velocity, BodyForce,
};
use crate::math::lanes::{F64s, Sum};
use crate::math::reduce::{fill, fill_pair};
use crate::neighbours::Lanes;
use crate::neighbours::Neighbours;
use crate::particles::{Kind, Particles};
use crate::solver::krylov::LinearOperator;
use crate::solver::multigrid::{stencil_slot, Aggregated};
use crate::sph::free_surface::Support;
use crate::sph::interface::{Field, Side};
use crate::sph::{
    corrected_gradient, mass_at_density, velocity_gradient, velocity_gradient_and, Correction,
    Corrections, VelocityGradientSum,
};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};

/// The role of a particle in the pressure solve.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// Fluid with a full neighbourhood: the Laplacian row.
    Interior,
    /// Fluid on the free surface: P + δ up·∇P = 0, the surface δ above its centre, δ about
    /// dx/2 (`surface_row_vector`); in still water P = ρ0 |g| δ.
    Surface,
    /// Fluid too isolated to have a pressure gradient (spray, drops): P = 0.
    Splash,
    /// The one fluid particle pinned to P = 0 where the fluid has no free surface at all (a
    /// closed or periodic box), whose PPE fixes the pressure only up to a constant.
    Reference,
    /// A fixed or prescribed body's particle with fluid in reach: the ghost of the fluid's pressure beside
    /// it, P_b = Σ_f W_bf (P_f + ρ0_f (f_f − a_b)·r_bf) / Σ_f W_bf (`ghost_source`), so that
    /// the fluid sees a wall moving at the body's acceleration a_b (Adami, Hu & Adams 2012).
    Ghost,
}

impl Role {
    /// Whether the particle bounds the fluid at a free surface.
    pub fn is_free(self) -> bool {
        matches!(self, Role::Surface | Role::Splash)
    }

    /// The role's code in the frames' `free_surface` dataset (`Particles::free_surface`):
    /// 1 free surface, 2 splash, 0 interior (walls have 0 too).
    pub fn code(self) -> u8 {
        match self {
            Role::Surface => 1,
            Role::Splash => 2,
            Role::Interior | Role::Reference | Role::Ghost => 0,
        }
    }

    /// The role of a fluid particle whose `free_surface` code is `code` (see `code`).
    pub fn from_code(code: u8) -> Role {
        match code {
            1 => Role::Surface,
            2 => Role::Splash,
            _ => Role::Interior,
        }
    }
}

/// V_i = m_i/ρ0_i of the `nf` fluid particles: the volumes the PPE rows couple.
pub fn fluid_volumes<const D: usize>(p: &Particles<D>, nf: usize, out: &mut Vec<f64>) {
    out.resize(nf, 0.0);
    fill(out, |i| p.mass[i] / p.rest_density[i]);
}

/// The role of particle i: fluid on the free surface (see `free_surface`) takes the surface
/// row, or P = 0 where it has no consistent gradient (`gradient_defined` false: the moment
/// matrix of its pressure gradient is near-singular, whether or not the scene applies the
/// kernel correction). `fluid_neighbours` counts the fluid particles in its kernel support;
/// `density_ratio` is its summation density over its rest density, `spray_density` the
/// kernel's `free_surface::spray_density`.
pub fn role<const D: usize>(
    nb: &Neighbours<D>,
    support: &Support<D>,
    fluid_neighbours: usize,
    gradient_defined: bool,
    density_ratio: f64,
    spray_density: f64,
    i: usize,
) -> Role {
    if fluid_neighbours == 0 || !gradient_defined {
        Role::Splash
    } else if support.is_free_surface(nb, i, density_ratio, spray_density) {
        Role::Surface
    } else {
        Role::Interior
    }
}

/// Whether a fluid particle (not a body's) lies within the kernel support of particle i.
pub fn has_fluid_in_reach<const D: usize>(nb: &Neighbours<D>, p: &Particles<D>, i: usize) -> bool {
    let mut found = false;
    nb.for_each_of(i, &[Kind::Fluid], |j, _, _| {
        found = found || p.kind[j] == Kind::Fluid
    });
    found
}

/// If the fluid has no free surface at all (a full closed or periodic box) the PPE is singular;
/// the highest fluid particle (the first in index order among equals) is then the reference,
/// pinned to P = 0. Returns it (None: the fluid has a free surface, and no reference).
pub fn pin_reference<const D: usize>(
    p: &Particles<D>,
    gravity: [f64; D],
    roles: &mut [Role],
) -> Option<usize> {
    if roles.iter().any(|r| r.is_free()) {
        return None;
    }
    let top = highest(
        p,
        gravity,
        (0..roles.len()).filter(|&i| roles[i] == Role::Interior),
    )?;
    roles[top] = Role::Reference;
    Some(top)
}

/// The highest of the particles `among` against gravity, the first in index order among equals.
pub fn highest<const D: usize>(
    p: &Particles<D>,
    gravity: [f64; D],
    among: impl Iterator<Item = usize>,
) -> Option<usize> {
    let height = |i: usize| -(0..D).map(|d| gravity[d] * p.pos[d][i]).sum::<f64>();
    among.max_by(|&a, &b| height(a).total_cmp(&height(b)).then(b.cmp(&a)))
}

/// Marks fluid particles whose kernel support holds no free-surface particle: there the
/// summation density measures compression, not the truncation of the kernel at the surface.
/// The free-surface particles (a small part of the fluid) mark the fluid they reach, instead of
/// every interior row looking for one: the same pairs, as r_ji = −r_ij to the bit. Across a
/// periodic boundary the two images of a pair round apart, so there a pair at the very edge of
/// the support may be found from one side only. `reached` is the marks' scratch.
pub fn full_support<const D: usize>(
    nb: &Neighbours<D>,
    roles: &[Role],
    reached: &mut Vec<AtomicBool>,
    full: &mut Vec<bool>,
) {
    reached.clear();
    reached.resize_with(roles.len(), || AtomicBool::new(false));
    let reached = &*reached;
    roles
        .par_iter()
        .enumerate()
        .filter(|(_, role)| role.is_free())
        .for_each(|(s, _)| {
            nb.for_each_lanes_of(s, &[Kind::Fluid], |l| {
                // The neighbours among the lanes (fluid rows: a fluid range holds fluid and
                // body particles).
                let mut lanes = l.mask.to_bitmask();
                while lanes != 0 {
                    reached[l.j0 + lanes.trailing_zeros() as usize].store(true, Ordering::Relaxed);
                    lanes &= lanes - 1;
                }
            });
        });
    full.resize(roles.len(), false);
    fill(full, |i| {
        roles[i] == Role::Interior && !reached[i].load(Ordering::Relaxed)
    });
}

/// The per-row vector of the operator ĉ_i = L'_iᵀ c_i of the consistent Laplacian (see
/// `LaplacianTruncation`), with L'_i the correction of the pressure gradient
/// (`sph::Moments::m_neumann`; None, the identity, where the kernel correction is off), for
/// interior rows; zero for the others (the free-surface rows take theirs in the pressure
/// solve, `surface_row_vector`).
/// Deep inside the fluid c_i measures the disorder of the particles, and the row is corrected
/// all the same: left uncorrected, those rows let still water go unstable within seconds, and
/// with the correction the tank stays at rest (docs/stabilisation.md, "The free-surface and
/// interior rows of the PPE").
pub fn row_vector<const D: usize>(
    role: Role,
    truncation: &LaplacianTruncation<D>,
    l: &Correction<D>,
) -> [f64; D] {
    match role {
        Role::Interior => {
            let c = truncation.c.map(|x| x.total());
            match l {
                Some(l) => std::array::from_fn(|a| (0..D).map(|b| l[b][a] * c[b]).sum()),
                None => c,
            }
        }
        Role::Surface | Role::Splash | Role::Reference | Role::Ghost => [0.0; D],
    }
}

/// The depth δ_i of free-surface particle i under the surface, along `up` (the unit vector
/// against the body force), at the midpoint of the step's drift, as the divergence is taken
/// (`divergence_source`): half its thickness across the surface (`Particles::surface_thickness`,
/// dx at rest) plus its rise over half a step above the water it stands on,
/// δ = (dx/2) τ_i + (Δt/2) up·(uⁿ_i − ūⁿ_i), with ūⁿ_i the W-weighted mean velocity of its fluid
/// neighbours (`rise_over_neighbours`). With the rise left out the pressure under a surface
/// particle rising out of the water answers where it started the step, half a step behind where
/// the projection applies it: a surface wave about 7 dx long was pushed on a little late in
/// every period and grew, 8% a period on `hydrostatic_2d`, until the still tank sloshed after
/// 40 s; with the rise the tank keeps its lattice's noise (docs/stabilisation.md, "The surface
/// row at the midpoint of the drift"). The rise is taken relative to the water beneath, so water
/// moving as a whole (a surge, a jet) carries its pressures unchanged: with uⁿ_i itself the light
/// discs of `dam_break_solids_2d` stayed on the floor twice as often. δ stays in
/// [0.05, 0.95] dx at CFL 0.4: τ ∈ [0.5, 1.5] and Δt|uⁿ_j| ≤ 0.4 dx for every particle
/// (`time_step`, on the same uⁿ).
/// A body's particle at the free surface is in the air, with its body's own surface half a
/// spacing beyond it and the air beyond that: δ = 0, its pressure is the air's. The body holds
/// its own weight rigidly, so the water-like weight of a half spacing above it would be a
/// pressure the body's rows above the waterline pass on to the water beside it: a box held at
/// its draft then read 8.7% less than its buoyancy at dx = 0.01 m and 4.2% at 0.005 m, and kept
/// the water at its waterline moving at 0.16 m/s; with 0, +1.7% and +0.7%, 0.075 m/s
/// (docs/bodies.md, "The coupling").
pub fn surface_depth<const D: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    up: [f64; D],
    spacing: f64,
    dt: f64,
    i: usize,
) -> f64 {
    match p.kind[i] {
        Kind::Body => 0.0,
        Kind::Fluid | Kind::Wall => {
            let rise = rise_over_neighbours(nb, p, i);
            let up_rise: f64 = (0..D).map(|d| up[d] * rise[d]).sum();
            0.5 * spacing * p.surface_thickness[i] + 0.5 * dt * up_rise
        }
    }
}

/// The vector v_i = δ_i L'_iᵀ up_i of free-surface row i, P_i + δ_i up_i·∇P_i = 0, with ∇P_i
/// the corrected pressure gradient L'_i Σ_j V_j (P_j − P_i) ∇W_ij of the corrector and δ_i
/// its depth under the surface along up_i, the unit vector against the body force
/// (`surface_depth`): P = 0 on the surface, extrapolated to the particle. The row is Σ_j V_j
/// (v_i·∇W_ij)(P_j − P_i) + P_i, and the walls' known ghost differences its right-hand side.
///
/// In still water −up·∇P = ρ0 |g| and the row gives P_i = ρ0 |g| δ_i, the weight of the water
/// above the particle's centre. In a wave it also carries the pressure's dynamic part between
/// the particle and the surface, which the weight alone leaves out: with P_i = ρ0 |g| δ_i (and
/// the thickness τ ≡ 1) the first sloshing mode of a tank read 1.5% long at 15 particles in
/// shallow water, the period of water half a spacing shallower; with the weight of a thickness
/// that follows the strain but no dynamic part, 0.6% short in deep water; with this row, both
/// within 0.1% (docs/bodies.md, "Sloshing period"). The row follows the body force's direction,
/// not the detected surface normal: with the normal, the surface particles beside a side wall
/// (whose normals the dry wall above them tilts) pushed still water into motion at 7e-3 m/s
/// within a second and it sloshed at 0.3 m/s by 40 s. Along the body force the two agree to
/// second order in the surface's slope. On a steep face of water (a run-up film, a jet) the row
/// gives δ_i (−up·∇P_i), near zero where the water falls freely, where the weight gave
/// ρ0 |g| δ_i.
/// Without a body force or without a corrected gradient (the kernel correction off) a row
/// keeps a zero vector and is P_i = ρ0 |g| δ_i (`projection_source`).
pub fn surface_row_vector<const D: usize>(l: &[[f64; D]; D], up: [f64; D], depth: f64) -> [f64; D] {
    std::array::from_fn(|a| depth * (0..D).map(|b| l[b][a] * up[b]).sum::<f64>())
}

/// uⁿ_i − ūⁿ_i, particle i's velocity relative to the W-weighted mean ūⁿ_i of its fluid
/// neighbours' (i left out; uⁿ_i where it has none).
fn rise_over_neighbours<const D: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    i: usize,
) -> [f64; D] {
    let mut w_sum = Sum::ZERO;
    let mut wu = [Sum::ZERO; D];
    nb.for_each_lanes_of(i, &[Kind::Fluid], |l| {
        let w = nb.kernel.w_lanes(l.r) & l.mask;
        w_sum += w;
        for d in 0..D {
            wu[d] = wu[d].mul_add(w, l.load(&p.vel[d]) & l.mask);
        }
    });
    let w = w_sum.total();
    std::array::from_fn(|d| {
        let mean = if w > 0.0 { wu[d].total() / w } else { 0.0 };
        p.vel[d][i] - mean
    })
}

/// Right-hand side b of the projection's PPE rows (same sign convention as
/// `PressureOperator`): −(ρ0/Δt)∇·u*, its part carried into the step, ∇·uⁿ, taken out over
/// `carried_dt` (`StepLength::carried_time`, `divergence_source`), with the walls' known differences in the interior rows,
/// the surface pressure in the free-surface rows. `closed`: the fluid has no free surface (a
/// particle is pinned as the reference); `sealed`: the unknowns of each region sealed off from
/// the free surface where the rest has one (its highest particle pinned), whose compression is
/// balanced like a closed box's.
#[allow(clippy::too_many_arguments)]
pub fn projection_source<const D: usize>(
    op: &PressureOperator<D>,
    closed: bool,
    sealed: &[Vec<usize>],
    spacing: f64,
    corrections: Corrections<D>,
    u_star: &[Vec<f64>; D],
    dt: f64,
    carried_dt: f64,
    b: &mut Vec<f64>,
) {
    let (nb, p) = (op.nb, op.p);
    let g = op.gravity.iter().map(|x| x * x).sum::<f64>().sqrt();
    b.resize(op.roles.len(), 0.0);
    fill(b, |i| match op.roles[i] {
        Role::Interior => {
            let ghosts = op.ghosts.map(|g| g.is_ghost);
            divergence_source(nb, p, corrections.of(i), ghosts, u_star, dt, carried_dt, i)
        }
        Role::Surface if op.row_vectors[i] != [0.0; D] => op.surface_wall_source(i),
        Role::Surface => {
            let up = op.gravity.map(|x| if g > 0.0 { -x / g } else { 0.0 });
            p.rest_density[i] * g * surface_depth(nb, p, up, spacing, dt, i)
        }
        Role::Ghost => op.ghost_source(i),
        Role::Splash | Role::Reference => 0.0,
    });
    balance_compression(op.roles, closed, sealed, b);
    // The walls' known differences (the Neumann ghosts) complete the interior rows.
    b.par_iter_mut()
        .zip(op.roles)
        .enumerate()
        .for_each(|(i, (b, &role))| {
            if role == Role::Interior {
                *b += op.wall_source(i);
            }
        });
}

/// Right-hand side b of the density correction's PPE rows: −α (ρ0 − ρ_i)/(Δt Δt_max) in the
/// interior rows of fluid particles (zero in a rigid body's) (`density_rate` = α/Δt_max; where the free surface truncates the kernel, only
/// compression counts: the summation density is low there because neighbours are missing),
/// zero on the free surface, and no wall term: the correction's walls are mirror ghosts
/// (∂P/∂n = 0), so their differences vanish. `closed` and `sealed` as in `projection_source`.
/// A full step (Δt = Δt_max) relaxes the fraction α of the density error, as Eq. (6) printed; a
/// step cut short to land on a frame relaxes α Δt/Δt_max of it, at the same rate per unit time
/// (with α/Δt² a short last step, an end time just past a frame, would jolt the particles:
/// `tests/frame_times.rs`, `a_short_last_step_does_not_kick_the_flow`; docs/stabilisation.md,
/// "A short step relaxes less").
pub fn density_source<const D: usize>(
    op: &PressureOperator<D>,
    closed: bool,
    sealed: &[Vec<usize>],
    full: &[bool],
    dt: f64,
    density_rate: f64,
    b: &mut Vec<f64>,
) {
    let p = op.p;
    b.resize(op.roles.len(), 0.0);
    fill(b, |i| match op.roles[i] {
        // A body does not compress: its summation density is not corrected.
        Role::Interior if p.kind[i] == Kind::Body => 0.0,
        Role::Interior => {
            let deviation = p.rest_density[i] - p.density[i];
            let deviation = if full[i] {
                deviation
            } else {
                deviation.min(0.0)
            };
            -density_rate * deviation / dt
        }
        Role::Surface | Role::Splash | Role::Reference | Role::Ghost => 0.0,
    });
    balance_compression(op.roles, closed, sealed, b);
}

/// Takes the net compression out of the interior rows of a closed box and of each sealed
/// region (`net_compression`).
fn balance_compression(roles: &[Role], closed: bool, sealed: &[Vec<usize>], b: &mut [f64]) {
    for region in sealed {
        let net = net_compression(roles, b, region.len(), |k| region[k]);
        for &i in region {
            if roles[i] == Role::Interior {
                b[i] -= net;
            }
        }
    }
    if closed {
        let net = net_compression(roles, b, b.len(), |k| k);
        b.par_iter_mut().zip(roles).for_each(|(b, &role)| {
            if role == Role::Interior {
                *b -= net;
            }
        });
    }
}

/// In a closed box the interior rows' compression must sum to zero: the volume cannot change,
/// and a net source would have nowhere to go but the reference particle's row (a spurious
/// point source of pressure there). The SPH divergence and the density term leave a small net
/// sum (from the disorder of the particles); its mean over the interior rows `b` (their
/// compression only), which `source` removes from each. The walls' known differences are not
/// compression and stay out of it: under gravity they are what holds the hydrostatic pressure
/// up, and taking their net sum out as well drives a flow towards the reference
/// (`tests/hydrostatic.rs`, `a_closed_box_full_of_water_stays_at_rest`; docs/stabilisation.md,
/// "Water sealed off from the free surface"). Water sealed off from the free surface is such a
/// box of its own: the mean is over the interior rows among `count` rows, row k being
/// `row(k)`.
fn net_compression(
    roles: &[Role],
    b: &[f64],
    count: usize,
    row: impl Fn(usize) -> usize + Sync,
) -> f64 {
    let [count, sum] = crate::math::reduce::sums(count, |k| {
        let i = row(k);
        if roles[i] == Role::Interior {
            [1.0, b[i]]
        } else {
            [0.0; 2]
        }
    });
    if count > 0.0 {
        sum / count
    } else {
        0.0
    }
}

/// −(ρ0/Δt) ∇·u*, the projection's part of Eq. (6), with ∇·u* corrected by Eq. (24)–(25) so
/// that it is exact for linear velocity fields also where the free surface truncates the kernel,
/// and taken at the midpoint of the advection's drift, Eq. (8), rather than at its start: the
/// velocity uⁿ⁺¹ is made divergence-free where the particles are halfway through the step.
///
/// During the drift each particle keeps its velocity, so the divergence of the field the
/// particles carry changes at the rate d(∇·u)/dt = −∂_a u_b ∂_b u_a
/// (`divergence_rate_in_drift`), and ∇·u at rⁿ + (Δt/2)uⁿ⁺¹ is ∇·u(rⁿ) − (Δt/2) ∂_a u_b ∂_b u_a.
/// Made divergence-free at the start of the drift (Eq. (6) as printed), the velocity is
/// compressive by Δt ∂_a u_b ∂_b u_a at its end, and the next step's pressure answers that:
/// the pressure lags the flow by half a step. In a vortex the lagging pressure gradient points
/// half a step behind the centre of curvature and brakes the flow at a rate ∝ Δt|u|²/R²,
/// independent of the viscosity: at CFL 0.24 the Taylor–Green vortex at 40 particles across lost
/// 1% of its kinetic energy to it every 0.1 L/U (docs/accuracy.md, "The time lag of the
/// projection"). At the midpoint the volume change over the drift cancels to second order and
/// the pressure is the one of the time the velocity is applied at. The ∂_a u_b ∂_b u_a of u*
/// stands for the one of uⁿ⁺¹ (they differ by Δt∇P/ρ, one order higher).
///
/// The divergence the particles carry into the step, ∇·uⁿ, is mostly the last drift's second
/// half, −(Δt_prev/2) ∂_a u_b ∂_b u_a. Taken out over Δt, the step's pressure reads
/// (1 + Δt_prev/Δt)/2 times the flow's (its impulse P Δt is the flow's); the steps cut to land
/// on a frame share the cut, so that ratio stays near 1 (`time_step::length`). On a sliver of
/// a step (`StepLength::carried_time`: a last step just past a frame) it is taken out over the
/// last step's Δt_prev instead: ∇·u* − (1 − Δt/Δt_prev) ∇·uⁿ. The sliver's pressure is then the
/// flow's, and it leaves the next step the divergence the last step left it, as if it had not
/// been taken. Over the sliver, a 1e-5 s tail after 3e-4 s steps read 4.6 times the flow's mean
/// pressure in the frame it ends on (docs/stabilisation.md, "A short step relaxes less"). The
/// velocity keeps (1 − Δt/Δt_prev) ∇·uⁿ at the midpoint of the sliver's drift, which costs
/// nothing over a sliver; on every step cut to land on a frame that braked the Taylor–Green
/// vortex by 0.6% of its kinetic energy in 0.3 L/U, so those take it out over Δt. What the step itself adds to u* (its forces; a held body's hold) is taken out over
/// Δt.
#[allow(clippy::too_many_arguments)]
fn divergence_source<const D: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    l: &Correction<D>,
    ghosts: Option<&[f64]>,
    u_star: &[Vec<f64>; D],
    dt: f64,
    carried_dt: f64,
    i: usize,
) -> f64 {
    // Walls take the fluid's own u*_i less its normal velocity of the last step: the body force
    // is carried by the wall ghosts' Neumann condition, the wall's kinematic condition by the
    // divergence (see `ghosts::ghost_velocity`).
    let u_star_i: [f64; D] = std::array::from_fn(|d| u_star[d][i]);
    let u_i = p.velocity(i);
    let velocity = |field: &[Vec<f64>; D], u_own: [f64; D], l: &Lanes<D>| -> [F64s; D] {
        match l.kind {
            Kind::Wall => ghost_velocity(p, l, u_own, u_i),
            Kind::Fluid | Kind::Body => {
                let own: [F64s; D] = std::array::from_fn(|d| l.load(&field[d]));
                match ghosts {
                    Some(ghosts) => {
                        let ghost = l.load(ghosts).simd_ne(F64s::ZERO);
                        let held = body_ghost_velocity(p, l, u_own, u_i);
                        std::array::from_fn(|d| ghost.select(held[d], own[d]))
                    }
                    None => own,
                }
            }
        }
    };
    // ∇·u* = trace of the corrected velocity gradient, Eq. (22) with Eq. (24)–(25).
    let carried_over = 1.0 - dt / carried_dt;
    let (grad_u, div) = if carried_over > 0.0 {
        let mut carried = VelocityGradientSum::new(u_i);
        let grad_u = velocity_gradient_and(
            nb,
            p,
            l,
            u_star_i,
            |l| velocity(u_star, u_star_i, l),
            i,
            |l, vf| carried.add(l, vf, velocity(&p.vel, u_i, l)),
        );
        let grad_carried = corrected_gradient(l, carried.total());
        (grad_u, trace(&grad_u) - carried_over * trace(&grad_carried))
    } else {
        let grad_u = velocity_gradient(nb, p, l, u_star_i, |l| velocity(u_star, u_star_i, l), i);
        (grad_u, trace(&grad_u))
    };
    -p.rest_density[i] / dt * (div + 0.5 * dt * divergence_rate_in_drift(&grad_u))
}

/// The trace of a velocity gradient: the divergence.
fn trace<const D: usize>(grad_u: &[[f64; D]; D]) -> f64 {
    (0..D).map(|a| grad_u[a][a]).sum()
}

/// d(∇·u)/dt = −∂_a u_b ∂_b u_a of a velocity field carried by particles that each keep their
/// velocity (the drift of Eq. (8)), from the velocity gradient `grad_u`.
fn divergence_rate_in_drift<const D: usize>(grad_u: &[[f64; D]; D]) -> f64 {
    -(0..D)
        .map(|a| (0..D).map(|b| grad_u[a][b] * grad_u[b][a]).sum::<f64>())
        .sum::<f64>()
}

/// ρ0_i V_j, the mass of neighbour j's volume at i's rest density: m_j where the fluids share
/// one (`interfaces` false), every neighbour counted as one of i's own fluid where they do not.
#[inline(always)]
fn volume_mass<const D: usize>(
    p: &Particles<D>,
    interfaces: bool,
    rest_density_i: F64s,
    l: &Lanes<D>,
) -> F64s {
    if interfaces {
        mass_at_density(p, rest_density_i, l)
    } else {
        l.load(&p.mass)
    }
}

/// First-order consistency of the Laplacian of Eq. (27). Where the free surface truncates the
/// kernel support, Eq. (27) applied to a linear field P is not zero but −c_i·∇P_i, with c_i = 2 Σ_j
/// (m_j/ρ_i) r_ij r_ij·∇W_ij/(r_ij² + η²) (zero for a full support; every neighbour counted as one
/// of i's own fluid, m_j = ρ0_i V_j, where the fluids differ). A wall ghost continues only the
/// normal part of the field, so a wall neighbour contributes N_b r_ij (see `boundary::ghosts`):
/// beside a plane wall the wall supplies what the missing fluid would, but in a corner or where the
/// surface meets a wall the support is truncated for the tangential part too. Subtracting that
/// term, with ∇P_i the corrected gradient L_i Σ_j V_j (P_j − P_i)∇W_ij, gives the row Σ_j (a_ij −
/// V_j (L_iᵀc_i)·∇W_ij)(P_i − P_j), still one pass over the neighbours. Without it the pressure
/// bends under the free surface and pushes a still surface off its rest position.
///
/// c_i is summed in the walk of the support's moments (`sph::support_moments_and`, the free
/// surface stage), which visits the same neighbours and finds the part of r_ij a wall ghost
/// follows: no walk of its own.
pub struct LaplacianTruncation<const D: usize> {
    c: [Sum; D],
    /// 2/ρ0_i.
    scale: F64s,
    rest_density: F64s,
    fluids_differ: bool,
}

impl<const D: usize> LaplacianTruncation<D> {
    /// The sum for particle i; `fluids_differ`: the scene's fluids differ in rest density.
    pub fn new(p: &Particles<D>, fluids_differ: bool, i: usize) -> Self {
        let rest_density = p.rest_density[i];
        Self {
            c: [Sum::ZERO; D],
            scale: F64s::splat(2.0 / rest_density),
            rest_density: F64s::splat(rest_density),
            fluids_differ,
        }
    }

    /// Adds the neighbours `l`, whose r_ij a pressure field follows as `followed`.
    #[inline(always)]
    pub fn add(
        &mut self,
        nb: &Neighbours<D>,
        p: &Particles<D>,
        l: &Lanes<D>,
        followed: &[F64s; D],
    ) {
        let (_, laplacian_factor) = nb.gradient_and_laplacian_factors_lanes(l.r);
        // −a_ij of Eq. (27) (`sph::laplacian_coefficient`) for the kernel's truncation alone:
        // across an interface the pairs are weighted by design (`interior_weights`), and taken
        // for truncation that weighting would be undone, leaving one fluid's pressure gradient
        // through both.
        let mass = volume_mass(p, self.fluids_differ, self.rest_density, l);
        let cl = (self.scale * mass * laplacian_factor) & l.mask;
        for d in 0..D {
            self.c[d] = self.c[d].mul_add(cl, followed[d]);
        }
    }
}

/// The PPE matrix A, applied on the fly from positions (no matrix, no per-pair list).
pub struct PressureOperator<'a, const D: usize> {
    pub nb: &'a Neighbours<'a, D>,
    pub p: &'a Particles<D>,
    pub roles: &'a [Role],
    /// The row vectors ĉ_i of `row_vector`.
    pub row_vectors: &'a [[f64; D]],
    /// V_j = m_j/ρ0_j of the fluid particles, the unknowns the rows couple (`fluid_volumes`).
    pub fluid_volume: &'a [f64],
    pub gravity: [f64; D],
    /// The body force the wall ghosts' pressures carry (zero with mirror ghosts).
    pub ghost_force: BodyForce<'a, D>,
    /// Where the fluids differ in rest density, each fluid particle's distance to the nearest
    /// interface (`interior_weights`).
    pub interfaces: Option<Field<'a, D>>,
    /// Where some rows are `Role::Ghost`: 1 at a fluid particle, 0 at a body's (the particles
    /// a ghost row averages), and the body force of each fluid and body particle (a held
    /// body's, its acceleration a_b over the step: `step::body_forces`).
    pub ghosts: Option<GhostRows<'a, D>>,
}

/// What the ghost rows of fixed and prescribed bodies' particles are made of (`Role::Ghost`).
#[derive(Clone, Copy)]
pub struct GhostRows<'a, const D: usize> {
    pub is_fluid: &'a [f64],
    /// 1 at a ghost row, 0 elsewhere.
    pub is_ghost: &'a [f64],
    pub force: BodyForce<'a, D>,
}

impl<const D: usize> GhostRows<'_, D> {
    /// W_bf of a ghost row's neighbours in lanes `l`: the kernel at the fluid particles, zero
    /// at the bodies' (the particles a ghost averages).
    #[inline(always)]
    fn weights(&self, nb: &Neighbours<D>, l: &Lanes<D>) -> F64s {
        (nb.kernel.w_lanes(l.r) & l.mask) * l.load(self.is_fluid)
    }
}

/// The constants of interior row i in lanes: −2/ρ_i of Eq. (27) and the row vector ĉ_i.
struct Row<const D: usize> {
    scale: F64s,
    c: [F64s; D],
    /// ρ0_i and i's distance to the nearest interface.
    density: Side<D>,
    /// Row i is a fluid particle's in a scene with ghost rows: its ghost neighbours are known
    /// differences (`ghost_differences`), not unknowns (`unknown_weights`).
    fluid: bool,
}

impl<const D: usize> PressureOperator<'_, D> {
    fn row_constants(&self, i: usize) -> Row<D> {
        Row {
            scale: F64s::splat(-2.0 / self.p.rest_density[i]),
            c: self.row_vectors[i].map(F64s::splat),
            density: Side::of(self.p, self.interfaces, i),
            fluid: self.is_fluid_row(i),
        }
    }

    /// Whether row i is a fluid particle's in a scene with ghost rows (`GhostRows`).
    fn is_fluid_row(&self, i: usize) -> bool {
        self.ghosts.is_some_and(|g| g.is_fluid[i] == 1.0)
    }

    /// The weights `w` of a row's neighbours in lanes `l` without its ghosts' where the row is
    /// a fluid particle's (`fluid`): their pressures are its own continued, known differences
    /// in the right-hand side (`ghost_differences`).
    #[inline(always)]
    fn unknown_weights(&self, fluid: bool, l: &Lanes<D>, w: F64s) -> F64s {
        match self.ghosts {
            Some(g) if fluid => l.load(g.is_ghost).simd_ne(F64s::ZERO).select(F64s::ZERO, w),
            _ => w,
        }
    }

    /// Weights of (P_i − P_j) in the interior row i (constants `row`) for the lanes `l`, with
    /// `volume` the volumes V_j of the lanes: max(a_ij − V_j ĉ_i·∇W_ij, 0),
    /// a_ij = −(2 m_j/ρ_i) r_ij·∇W_ij/(r_ij² + η²) of Eq. (27) (m_j = ρ0_i V_j where the
    /// fluids differ: `volume_mass`). Across an interface between fluids of different rest
    /// density the row is ρ0_i ∇·(∇P/ρ), with 1/ρ̄_ij across a pair, ρ̄_ij the density along
    /// the segment between them (`interface::pair_weight`), which keeps ∇P/ρ continuous across
    /// the interface and a stable layering at rest. The whole corrected coefficient is
    /// weighted: the correction keeps the row exact for a field whose weighted differences are
    /// linear, the hydrostatic pressure of a layering, also where a wall or the surface
    /// truncates the support (with the coefficient alone weighted, the layering moved where
    /// its interface meets a side wall).
    #[inline(always)]
    fn interior_weights(&self, row: &Row<D>, l: &Lanes<D>, volume: F64s) -> F64s {
        let mass = volume_mass(
            self.p,
            self.interfaces.is_some(),
            row.density.rest_density,
            l,
        );
        // a_ij − V_j F ĉ_i·r_ij = k ((−2 m_j/ρ_i) r² − V_j (r² + η²) ĉ_i·r_ij), with
        // F = k (r² + η²) and the Laplacian factor k r² (`RadialTerms`).
        let radial = self.nb.radial_terms_lanes(l.r);
        let c_r = (0..D).fold(F64s::ZERO, |s, d| row.c[d].mul_add(l.rij[d], s));
        let correction = volume * radial.r2_eta2 * c_r;
        let weight = radial.k * (row.scale * mass).mul_add(radial.r2, -correction);
        let weight = row.density.across(self.p, self.interfaces, l, weight);
        // Where the support is badly truncated (a surge tip, spray) the correction can turn a
        // weight negative; clipped at zero the row keeps non-negative neighbour weights (an
        // M-matrix row) and the solve no pressure spikes. Still water never needs the clip.
        weight.fast_max(F64s::ZERO) & l.mask
    }

    /// The weights of interior row i with its fluid neighbours `l`, the unknowns among them.
    #[inline(always)]
    fn fluid_weights(&self, row: &Row<D>, l: &Lanes<D>) -> F64s {
        let w = self.interior_weights(row, l, l.load(self.fluid_volume));
        self.unknown_weights(row.fluid, l, w)
    }

    /// The weights of free-surface row i with its fluid neighbours `l`, the unknowns among
    /// them (`fluid`: `is_fluid_row(i)`).
    #[inline(always)]
    fn surface_unknown_weights(&self, i: usize, fluid: bool, l: &Lanes<D>) -> F64s {
        let w = self.surface_weights(i, l, l.load(self.fluid_volume));
        self.unknown_weights(fluid, l, w)
    }

    /// Σ_b w_ib (P_b − P_i) over the ghosts b of fluid particle i's row, `weights` their w_ib:
    /// P_b − P_i = −ρ0_i (f_i − a_b)·r_ib, fluid particle i's pressure continued into the body
    /// under the Neumann condition of a wall accelerating at a_b, as the walls' (`boundary::ghosts`)
    /// but along every direction, as the ghost rows' own average takes it (`ghost_source`).
    /// The fluid rows thus couple fluid unknowns only, and the operator keeps the symmetry and
    /// the multigrid's coarse levels of a scene without held bodies; the ghost rows, which
    /// depend on the fluid and nothing depends on, give the body's pressure.
    fn ghost_differences(&self, i: usize, weights: impl Fn(&Lanes<D>) -> F64s) -> f64 {
        let Some(g) = self.ghosts.filter(|_| self.is_fluid_row(i)) else {
            return 0.0;
        };
        let f_i = g.force.at(i).map(F64s::splat);
        let rho = F64s::splat(-self.p.rest_density[i]);
        let mut b = Sum::ZERO;
        self.nb.for_each_lanes_of(i, &[Kind::Fluid], |l| {
            let ghost = l.load(g.is_ghost);
            if ghost.simd_ne(F64s::ZERO).to_bitmask() == 0 {
                return;
            }
            let a_b = g.force.lanes(l);
            let g_r = (0..D).fold(F64s::ZERO, |s, d| (f_i[d] - a_b[d]).mul_add(l.rij[d], s));
            b = b.mul_add(weights(l) * ghost, rho * g_r);
        });
        b.total()
    }

    /// The wall part of the right-hand side of interior row i: the Neumann ghosts' known
    /// differences, the walls' and the held bodies' (`ghost_differences`).
    fn wall_source(&self, i: usize) -> f64 {
        let (p, row) = (self.p, self.row_constants(i));
        let mut b = Sum::ZERO;
        self.nb.for_each_lanes_of(i, &[Kind::Wall], |l| {
            let volume = l.load(&p.mass) / l.load(&p.rest_density);
            let w = self.interior_weights(&row, l, volume);
            b += w * ghost_pressure_difference(p, self.ghost_force.at(i), i, l);
        });
        let volume = self.fluid_volume;
        b.total() + self.ghost_differences(i, |l| self.interior_weights(&row, l, l.load(volume)))
    }

    /// (A x)_i for each of the K vectors x, in one walk of row i's neighbours: the interior
    /// rows couple fluid neighbours only (the walls' pairs are known numbers, in the
    /// right-hand side). Each vector's sum is the one a walk for it alone makes.
    #[inline(always)]
    fn rows<const K: usize>(&self, x: [&[f64]; K], i: usize) -> [f64; K] {
        match self.roles[i] {
            Role::Interior => {
                let row = self.row_constants(i);
                self.weighted_differences(x, i, |l| self.fluid_weights(&row, l))
            }
            Role::Surface => {
                // P_i + Σ_j w_ij (P_j − P_i).
                let fluid = self.is_fluid_row(i);
                let d =
                    self.weighted_differences(x, i, |l| self.surface_unknown_weights(i, fluid, l));
                std::array::from_fn(|k| x[k][i] - d[k])
            }
            Role::Ghost => self.ghost_rows(x, i),
            Role::Splash | Role::Reference => x.map(|x| x[i]),
        }
    }

    /// x_b − Σ_f W_bf x_f / Σ_f W_bf of ghost row b for each of the K vectors x, over its fluid
    /// neighbours (`Role::Ghost`), in one walk.
    #[inline(always)]
    fn ghost_rows<const K: usize>(&self, x: [&[f64]; K], b: usize) -> [f64; K] {
        let ghosts = self.ghosts.expect("ghost rows have their fluid flags");
        let mut weights = Sum::ZERO;
        let mut sums = [Sum::ZERO; K];
        self.nb.for_each_lanes_of(b, &[Kind::Fluid], |l| {
            let w = ghosts.weights(self.nb, l);
            weights += w;
            for k in 0..K {
                sums[k] = sums[k].mul_add(w, l.load(x[k]));
            }
        });
        let total = weights.total();
        std::array::from_fn(|k| x[k][b] - sums[k].total() / total)
    }

    /// The right-hand side of ghost row b: Σ_f W_bf ρ0_f (f_f − a_b)·r_bf / Σ_f W_bf, the
    /// hydrostatic and accelerating part of the fluid's pressure continued to b.
    fn ghost_source(&self, b: usize) -> f64 {
        let ghosts = self.ghosts.expect("ghost rows have their fluid flags");
        let p = self.p;
        let a_b = ghosts.force.at(b).map(F64s::splat);
        let (mut weights, mut sum) = (Sum::ZERO, Sum::ZERO);
        self.nb.for_each_lanes_of(b, &[Kind::Fluid], |l| {
            let w = ghosts.weights(self.nb, l);
            let f = ghosts.force.lanes(l);
            let g_r = (0..D).fold(F64s::ZERO, |s, d| (f[d] - a_b[d]).mul_add(l.rij[d], s));
            weights += w;
            sum = sum.mul_add(w, l.load(&p.rest_density) * g_r);
        });
        sum.total() / weights.total()
    }

    /// Σ_j w_ij (x_i − x_j) over row i's fluid neighbours for each of the K vectors x, in one
    /// walk, `weights` giving the w_ij of a lane set. Each vector's sum is the one a walk for it
    /// alone makes.
    #[inline(always)]
    fn weighted_differences<const K: usize>(
        &self,
        x: [&[f64]; K],
        i: usize,
        weights: impl Fn(&Lanes<D>) -> F64s,
    ) -> [f64; K] {
        let xi = x.map(|x| F64s::splat(x[i]));
        let mut ax = [Sum::ZERO; K];
        self.nb.for_each_lanes_of(i, &[Kind::Fluid], |l| {
            let w = weights(l);
            for k in 0..K {
                ax[k] = ax[k].mul_add(w, xi[k] - l.load(x[k]));
            }
        });
        ax.map(|a| a.total())
    }

    /// The weights V_j v_i·∇W_ij of the free-surface row i (`surface_row_vector`) for the lanes
    /// `l`, with `volume` their V_j.
    #[inline(always)]
    fn surface_weights(&self, i: usize, l: &Lanes<D>, volume: F64s) -> F64s {
        let v = self.row_vectors[i];
        let radial = self.nb.radial_terms_lanes(l.r);
        // ∇W_ij = k (r² + η²) r_ij (`RadialTerms`).
        let v_r = (0..D).fold(F64s::ZERO, |s, d| F64s::splat(v[d]).mul_add(l.rij[d], s));
        (volume * radial.k * radial.r2_eta2 * v_r) & l.mask
    }

    /// The right-hand side of free-surface row i: the known ghost differences of the walls and
    /// the held bodies, −Σ_b V_b (v_i·∇W_ib)(P_b − P_i).
    fn surface_wall_source(&self, i: usize) -> f64 {
        let p = self.p;
        let mut b = Sum::ZERO;
        self.nb.for_each_lanes_of(i, &[Kind::Wall], |l| {
            let volume = l.load(&p.mass) / l.load(&p.rest_density);
            let w = self.surface_weights(i, l, volume);
            b += w * ghost_pressure_difference(p, self.ghost_force.at(i), i, l);
        });
        let volume = self.fluid_volume;
        -b.total() - self.ghost_differences(i, |l| self.surface_weights(i, l, l.load(volume)))
    }
}

impl<const D: usize> LinearOperator for PressureOperator<'_, D> {
    fn len(&self) -> usize {
        self.roles.len()
    }

    fn apply(&self, x: &[f64], y: &mut [f64]) {
        fill(y, |i| self.rows([x], i)[0]);
    }

    /// Both applies in one walk: the walk (two thirds of an apply's time, docs/performance.md,
    /// "The PPE apply") and the weights are shared.
    fn apply_two(&self, x: &[f64], y: &mut [f64], x2: &[f64], y2: &mut [f64]) {
        fill_pair(y, y2, |i| self.rows([x, x2], i));
    }

    fn diagonal(&self, diag: &mut [f64]) {
        fill(diag, |i| match self.roles[i] {
            Role::Interior => {
                let row = self.row_constants(i);
                let mut d = Sum::ZERO;
                self.nb
                    .for_each_lanes_of(i, &[Kind::Fluid], |l| d += self.fluid_weights(&row, l));
                interior_diagonal(d)
            }
            Role::Surface => {
                let (fluid, mut d) = (self.is_fluid_row(i), Sum::ZERO);
                self.nb.for_each_lanes_of(i, &[Kind::Fluid], |l| {
                    d += self.surface_unknown_weights(i, fluid, l)
                });
                1.0 - d.total()
            }
            Role::Splash | Role::Reference | Role::Ghost => 1.0,
        })
    }
}

impl<const D: usize> Aggregated<D> for PressureOperator<'_, D> {
    fn dims(&self) -> [usize; D] {
        self.nb.grid().blocks()
    }

    fn periodic(&self) -> [bool; D] {
        self.nb.grid().periodic()
    }

    fn aggregate(&self, i: usize) -> Option<usize> {
        match self.roles[i] {
            Role::Interior => Some(self.nb.grid().block_of_sorted(i)),
            Role::Surface | Role::Splash | Role::Reference | Role::Ghost => None,
        }
    }

    fn add_coarse_row(&self, i: usize, row: &mut [f64]) -> f64 {
        // Interior rows: a_ii = Σ w, a_ij = −w; the other rows are not aggregated.
        debug_assert_eq!(self.roles[i], Role::Interior, "row {i} is not aggregated");
        let (grid, p) = (self.nb.grid(), self.p);
        let block_i: [F64s; D] =
            std::array::from_fn(|d| F64s::splat(grid.block_along(d, p.pos[d][i]) as f64));
        let (centre, one, three) = (stencil_slot([0; D]), F64s::ONE, F64s::splat(3.0));
        // Along a periodic axis of n blocks (n ≥ 3) a neighbour across the boundary lies
        // n − 1 blocks away in the grid and one block away in the period.
        let (periodic, blocks) = (grid.periodic(), grid.blocks());
        let period: [Option<F64s>; D] =
            std::array::from_fn(|d| periodic[d].then(|| F64s::splat(blocks[d] as f64)));
        let constants = self.row_constants(i);
        let mut diagonal = Sum::ZERO;
        self.nb.for_each_lanes_of(i, &[Kind::Fluid], |l| {
            let w = self.fluid_weights(&constants, l);
            diagonal += w;
            // Each lane's block offset from row i's, its slot in the 3^D stencil (x fastest)
            // and whether it lies within it, computed in lanes from the absolute positions.
            // `stencil_slot` in lanes.
            let offset: [F64s; D] = std::array::from_fn(|d| {
                let o = grid.block_along_lanes(d, l.load(&p.pos[d])) - block_i[d];
                match period[d] {
                    Some(n) => o - (o.simd_gt(one) & n) + (o.simd_lt(-one) & n),
                    None => o,
                }
            });
            let (mut slot, mut within) = (F64s::ZERO, u32::MAX);
            for d in (0..D).rev() {
                within &= offset[d].abs().simd_le(one).to_bitmask();
                slot = slot.mul_add(three, offset[d] + one);
            }
            let (w, slot) = (w.to_array(), slot.to_array());
            for (k, w) in w.into_iter().enumerate() {
                // A ghost follows the water beside it: the coarse level carries a water
                // particle's correction into its ghosts, and their pair adds nothing. (A water
                // row's ghost weights are zero already, `unknown_weights`; this leaves out the
                // pairs of a body's own deeper rows with its ghosts.)
                if w == 0.0 || self.roles[l.j0 + k] == Role::Ghost {
                    continue;
                }
                row[centre] += w;
                if within >> k & 1 == 1 && self.roles[l.j0 + k] == Role::Interior {
                    debug_assert_eq!(
                        slot[k] as usize,
                        stencil_slot::<D>(std::array::from_fn(|d| offset[d].to_array()[k] as i64))
                    );
                    row[slot[k] as usize] -= w;
                }
            }
        });
        interior_diagonal(diagonal)
    }
}

/// a_ii of an interior row from the sum of its weights (`PressureOperator::interior_weights`):
/// a row whose every weight was clipped holds its particle at P = 0.
fn interior_diagonal(weights: Sum) -> f64 {
    let d = weights.total();
    if d > 0.0 {
        d
    } else {
        1.0
    }
}
