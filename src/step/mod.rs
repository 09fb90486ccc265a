//! One projection step, Eq. (5)–(8), as a sequence of stages over the particles sorted by
//! cell: summation density → free surface → kernel corrections → eddy viscosity → predictor →
//! pressure Poisson equation → corrector → wall pressure → shifting → advection (`stages`).
//! The stages of the effects a scene turns off (`scene::Effects`) are skipped. Each stage reads
//! the particles and writes its own workspace arrays, which it allocates when it first runs and
//! reuses after, so the arrays of a stage that does not run are never allocated
//! (`Workspace::arrays` lists them all by stage). The fluid particles come first in the sorted
//! order (`grid`), and every workspace array holds the fluid particles only: the walls are
//! fixed, hold no unknown and need none of them. The step copies the new velocity, pressure
//! and density of the fluid into the particles.

pub mod timings;

use crate::boundary::faces::Faces;
use crate::boundary::ghosts;
use crate::effects::les;
use crate::effects::shifting::Shifting;
use crate::math::kernel::Quintic;
use crate::math::lanes::F64s;
use crate::math::memory::{ArraySize, Holds};
use crate::math::reduce::{
    self, fill, fill_scalar_and_vector, fill_vector, fill_vector_and_update,
};
use crate::math::vector::unit;
use crate::neighbours::cell_list::CellList;
use crate::neighbours::Lanes;
use crate::neighbours::Neighbours;
use crate::particles::{components, Kind, Particles};
use crate::scene::Effects;
use crate::scene::LesSettings;
use crate::scene::ShiftingSettings;
use crate::solver::krylov::{BiCgStab, Preconditioner, SolveInfo, SolverError, SolverParams};
use crate::solver::multigrid::Multigrid;
use crate::solver::ppe::{self, PressureOperator, Role};
use crate::sph::free_surface::Support;
use crate::sph::interface::{self, Interfaces};
use crate::sph::{self, Correction, Corrections, NO_SLOT};
use crate::step::timings::{Stage, Timings};
use rayon::iter::Either;
use rayon::prelude::*;
use std::time::Instant;

/// The constants of a step that come from the scene.
#[derive(Clone, Copy, Debug)]
pub struct StepSettings<const D: usize> {
    pub gravity: [f64; D],
    /// The gravity the wall ghosts' pressures carry: `gravity` with the scene's hydrostatic
    /// ghosts, zero with mirror ghosts (`scene::GhostPressure`).
    pub ghost_gravity: [f64; D],
    pub spacing: f64,
    /// Relaxation α of the density-invariance term of Eq. (6).
    pub alpha: f64,
    pub solver: SolverParams,
    /// The optional stages and their constants.
    pub effects: Effects,
    /// The fluid fills a closed or periodic container (`lattice::fills_container`): it has no
    /// free surface, and none is looked for.
    pub confined: bool,
    /// ρ/ρ0 below which fluid is spray, for the scene's h/dx (`free_surface::spray_density`).
    pub spray_density: f64,
    /// det M_i at or below which the kernel gradient correction is not applied, for the
    /// scene's h/dx (`sph::min_correction_determinant`).
    pub min_correction_determinant: f64,
}

/// The stages of a step of a scene with `effects`, in order: those of `Workspace::project`,
/// with the cell sort before it and the diagnostics after it (run by `Simulation`).
pub fn stages(effects: &Effects) -> Vec<Stage> {
    Stage::ALL
        .into_iter()
        .filter(|stage| match stage {
            Stage::KernelCorrection => effects.kernel_correction,
            Stage::EddyViscosity => effects.les.is_some(),
            Stage::Shifting => effects.shifting.is_some(),
            Stage::CellList
            | Stage::Density
            | Stage::FreeSurface
            | Stage::Predictor
            | Stage::PressureSolve
            | Stage::Corrector
            | Stage::WallPressure
            | Stage::Advection
            | Stage::Diagnostics => true,
        })
        .collect()
}

/// The length of a step and the limit it was cut from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepLength {
    /// Δt of this step [s].
    pub dt: f64,
    /// Δt_max, the limit of the CFL, viscous and body-force conditions [s]: Δt is shorter
    /// only where the step is cut to land on a frame time. The density-invariance term of the
    /// PPE relaxes the density error over Δt_max, not Δt (`ppe::source`).
    pub limit: f64,
}

/// What a step measured.
#[derive(Clone, Copy, Debug)]
pub struct StepReport {
    pub solve: SolveInfo,
    /// Mean |ρ/ρ0 − 1| over fluid particles with no free surface in reach.
    pub density_error: f64,
    /// Spread of the nearest-neighbour distance over the same particles (`disorder`).
    pub disorder: f64,
}

/// Per-step arrays, allocated once and reused.
pub struct Workspace<const D: usize> {
    /// Summation density of the step (swapped into the particles).
    density: Vec<f64>,
    /// Where the fluids differ in rest density, the kernel's table of distances to an
    /// interface (`interface`), and each fluid particle's distance to the nearest one and
    /// normal across it: the PPE rows and the pressure gradient weigh the pairs across it.
    interface_table: Option<Interfaces>,
    interface_distance: Vec<f64>,
    interface_normal: [Vec<f64>; D],
    /// The free surface's outward normal of each fluid particle, where shifting keeps to the
    /// tangential direction (with shifting).
    surface_normal: Vec<[f64; D]>,
    roles: Vec<Role>,
    /// The particle pinned to P = 0 where the fluid has no free surface (`ppe::pin_reference`;
    /// None: the fluid has one, its pressure is absolute and cannot hold a tension).
    reference: Option<usize>,
    /// No free-surface particle in the kernel support.
    full_support: Vec<bool>,
    /// Kernel gradient correction L_i of each particle, Eq. (25) (with the kernel correction).
    corrections: Vec<Correction<D>>,
    /// Each particle's slot in `corrections` (`sph::NO_SLOT`: none, the particle has no free
    /// surface in reach) and the particle of each slot (with the kernel correction).
    correction_slot: Vec<u32>,
    corrected: Vec<u32>,
    /// The correction L'_i of the pressure gradient, whose wall ghosts carry the normal part
    /// of the gradient only (see `sph::Moments`) (with the kernel correction).
    pressure_corrections: Vec<Correction<D>>,
    /// Smagorinsky eddy viscosity ν_t (with LES).
    eddy: Vec<f64>,
    /// u* of Eq. (5), from the predictor to the corrector, which leaves ∇Pⁿ⁺¹ in its place
    /// for the shifting's Taylor step (Eq. 9): the same gradient, not computed twice.
    u_star: [Vec<f64>; D],
    /// The per-row vectors of the PPE operator (`ppe::row_vectors`).
    row_vectors: [Vec<f64>; D],
    /// V_j = m_j/ρ0_j of fluid particles, zero for walls (the unknowns of the PPE).
    fluid_volume: Vec<f64>,
    rhs: Vec<f64>,
    pressure: Vec<f64>,
    bicgstab: BiCgStab,
    multigrid: Multigrid<D>,
    velocity: [Vec<f64>; D],
    /// Shifting displacement δr of each particle (with shifting).
    shift: [Vec<f64>; D],
}

impl<const D: usize> Workspace<D> {
    /// The workspace of a scene whose fluids differ in rest density (`interfaces`: the
    /// kernel's table) or share one (None).
    pub fn new(interfaces: Option<Interfaces>) -> Self {
        Self {
            density: Vec::new(),
            interface_table: interfaces,
            interface_distance: Vec::new(),
            interface_normal: components(),
            surface_normal: Vec::new(),
            roles: Vec::new(),
            reference: None,
            full_support: Vec::new(),
            corrections: Vec::new(),
            correction_slot: Vec::new(),
            corrected: Vec::new(),
            pressure_corrections: Vec::new(),
            eddy: Vec::new(),
            u_star: components(),
            row_vectors: components(),
            fluid_volume: Vec::new(),
            rhs: Vec::new(),
            pressure: Vec::new(),
            bicgstab: BiCgStab::default(),
            multigrid: Multigrid::default(),
            velocity: components(),
            shift: components(),
        }
    }
}

impl<const D: usize> Workspace<D> {
    /// Advances the particles (sorted by cell in `grid`) by one step of `step.dt`, running the
    /// stages of `stages(&set.effects)` between the cell sort and the diagnostics. The wall
    /// particles' pressure, which only the frames hold, is computed when `ends_on_frame`: in a
    /// large tank with a small block of water most wall particles are dry, and visiting them
    /// at every step cost 20% of the step.
    #[allow(clippy::too_many_arguments)]
    pub fn project(
        &mut self,
        p: &mut Particles<D>,
        grid: &CellList<D>,
        kernel: Quintic<D>,
        set: &StepSettings<D>,
        faces: &Faces,
        step: StepLength,
        ends_on_frame: bool,
        timings: &mut Timings,
    ) -> Result<StepReport, SolverError> {
        let (effects, dt) = (&set.effects, step.dt);
        let fluid = grid.range_of(Kind::Fluid);
        debug_assert_eq!(fluid.start, 0, "the fluid comes first in the sorted order");
        let nf = fluid.end;
        let report = {
            let nb = Neighbours::new(grid, &p.pos, kernel);
            let mut clock = Instant::now();
            let mut lap = |stage: Stage| {
                let now = Instant::now();
                match stage {
                    Stage::Diagnostics => timings.add_part(stage, now - clock),
                    _ => timings.add(stage, now - clock),
                }
                clock = now;
            };
            self.summation_density(&nb, p, nf);
            p.density[..nf].copy_from_slice(&self.density);
            self.interface_distances(&nb, p, faces, nf);
            lap(Stage::Density);
            self.classify(&nb, p, set, nf);
            lap(Stage::FreeSurface);
            if effects.kernel_correction {
                self.near_surface_corrections(&nb, p, set.min_correction_determinant);
                lap(Stage::KernelCorrection);
            }
            if let Some(les) = &effects.les {
                self.eddy_viscosity(&nb, p, set, les);
                lap(Stage::EddyViscosity);
            }
            self.predict(&nb, p, set, dt);
            lap(Stage::Predictor);
            let solve = self.solve_pressure(&nb, p, set, step)?;
            let (clip, pressure) = (self.reference.is_none(), &self.pressure);
            fill(&mut p.pressure[..nf], |i| cavitation(clip, pressure[i]));
            let roles = &self.roles;
            fill(&mut p.free_surface[..nf], |i| roles[i].code());
            lap(Stage::PressureSolve);
            self.correct(&nb, p, set, faces, dt);
            copy_vector(&self.velocity, &mut p.vel);
            lap(Stage::Corrector);
            let (density_error, disorder) = self.full_support_statistics(&nb, p);
            lap(Stage::Diagnostics);
            if ends_on_frame {
                let ghosts = ghosts::Ghosts {
                    rest_density: &p.rest_density,
                    normal: &p.normal,
                    gravity: set.ghost_gravity,
                };
                wall_pressure(&nb, &ghosts, &mut p.pressure, nf);
                lap(Stage::WallPressure);
            }
            if let Some(shifting) = &effects.shifting {
                self.shift(&nb, p, set, faces, shifting, dt);
                copy_vector(&self.velocity, &mut p.vel);
                p.pressure[..nf].copy_from_slice(&self.pressure);
                lap(Stage::Shifting);
            }
            StepReport {
                solve,
                density_error,
                disorder,
            }
        };
        let clock = Instant::now();
        self.advect(p, nf, dt, effects.shifting.is_some());
        timings.add(Stage::Advection, clock.elapsed());
        Ok(report)
    }

    /// Every per-particle array of the workspace with the stage that allocates it, as it is
    /// now (the exhaustive destructuring makes leaving out a new field a compile error).
    pub fn arrays(&self) -> Vec<(Stage, ArraySize)> {
        let Workspace {
            density,
            interface_table,
            interface_distance,
            interface_normal,
            surface_normal,
            roles,
            reference: _,
            full_support,
            corrections,
            correction_slot,
            corrected,
            pressure_corrections,
            eddy,
            u_star,
            row_vectors,
            fluid_volume,
            rhs,
            pressure,
            bicgstab,
            multigrid,
            velocity,
            shift,
        } = self;
        let mut arrays = vec![
            (Stage::Density, ArraySize::of("density", density)),
            (Stage::FreeSurface, ArraySize::of("PPE role", roles)),
            (
                Stage::FreeSurface,
                ArraySize::of("full support", full_support),
            ),
            (Stage::KernelCorrection, ArraySize::sparse("L", corrections)),
            (
                Stage::KernelCorrection,
                ArraySize::of("slot of L", correction_slot),
            ),
            (
                Stage::KernelCorrection,
                ArraySize::sparse("particle of L", corrected),
            ),
            (
                Stage::KernelCorrection,
                ArraySize::of("L'", pressure_corrections),
            ),
            (Stage::EddyViscosity, ArraySize::of("ν_t", eddy)),
            (
                Stage::Predictor,
                ArraySize::of_components("u*, then ∇P", u_star),
            ),
            (
                Stage::PressureSolve,
                ArraySize::of_components("row vector", row_vectors),
            ),
            (
                Stage::PressureSolve,
                ArraySize::of("fluid volume", fluid_volume),
            ),
            (Stage::PressureSolve, ArraySize::of("right-hand side", rhs)),
            (Stage::PressureSolve, ArraySize::of("pressure", pressure)),
            (
                Stage::Corrector,
                ArraySize::of_components("velocity", velocity),
            ),
            (
                Stage::Shifting,
                ArraySize::of("surface normal", surface_normal),
            ),
            (Stage::Shifting, ArraySize::of_components("δr", shift)),
        ];
        let solver = bicgstab.arrays().into_iter().chain(multigrid.fine_arrays());
        arrays.extend(solver.map(|a| (Stage::PressureSolve, a)));
        if interface_table.is_some() {
            let distance = ArraySize::of("interface distance", interface_distance);
            arrays.push((Stage::Density, distance));
            let normal = ArraySize::of_components("interface normal", interface_normal);
            arrays.push((Stage::Density, normal));
        }
        // Every array of the workspace holds the fluid particles only (see the module doc).
        for (_, a) in &mut arrays {
            if a.holds == Holds::EveryParticle {
                *a = a.clone().fluid();
            }
        }
        arrays
    }

    /// Summation density of the `nf` fluid particles (walls keep their rest density).
    fn summation_density(&mut self, nb: &Neighbours<D>, p: &Particles<D>, nf: usize) {
        self.density.resize(nf, 0.0);
        fill(&mut self.density, |i| sph::density(nb, p, i));
    }

    /// Each of the `nf` fluid particles' distance to the nearest interface between fluids of
    /// different rest density (`interface`), where they differ.
    fn interface_distances(
        &mut self,
        nb: &Neighbours<D>,
        p: &Particles<D>,
        faces: &Faces,
        nf: usize,
    ) {
        let Some(table) = &self.interface_table else {
            return;
        };
        let support = nb.kernel.support();
        self.interface_distance.resize(nf, 0.0);
        for n in &mut self.interface_normal {
            n.resize(nf, 0.0);
        }
        fill_scalar_and_vector(
            &mut self.interface_distance,
            &mut self.interface_normal,
            |i| {
                let mirrors = faces.container_faces_within(p.position(i), support);
                let (share, gradient) = interface::other_fluid_share(nb, p, mirrors, i);
                (table.distance(share), unit(gradient))
            },
        );
    }

    /// How each support is filled, from its moments (`sph::support_moments`): the free surface
    /// and the role of each particle in the PPE (`ppe::role`), and with shifting the surface
    /// normal. With the kernel correction the corrections L_i and L'_i of Eq. (25) are inverted
    /// here from the same moments, once per step for every operator below.
    fn classify(&mut self, nb: &Neighbours<D>, p: &Particles<D>, set: &StepSettings<D>, nf: usize) {
        let n = nf;
        self.roles.resize(n, Role::Interior);
        let corrections = if set.effects.kernel_correction {
            self.pressure_corrections.resize(n, None);
            Either::Left(self.pressure_corrections.par_iter_mut().map(Some))
        } else {
            Either::Right((0..n).into_par_iter().map(|_| None))
        };
        let normals = if set.effects.shifting.is_some() {
            self.surface_normal.resize(n, [0.0; D]);
            Either::Left(self.surface_normal.par_iter_mut().map(Some))
        } else {
            Either::Right((0..n).into_par_iter().map(|_| None))
        };
        self.roles
            .par_iter_mut()
            .zip(normals)
            .zip(corrections)
            .enumerate()
            .for_each(|(i, ((role, normal), corrections))| {
                let mo = sph::support_moments(nb, p, i);
                let l_pressure =
                    sph::gradient_correction(mo.m_neumann, set.min_correction_determinant);
                let support = Support::new(&mo.m, mo.grad_c);
                // Fluid that fills its container has no free surface: every row is interior
                // (a disordered patch of a periodic flow can look like a surface to the
                // detection).
                *role = if set.confined {
                    Role::Interior
                } else {
                    ppe::role(
                        nb,
                        p,
                        &support,
                        mo.fluid_neighbours,
                        l_pressure.is_some(),
                        set.spray_density,
                        i,
                    )
                };
                if let Some(normal) = normal {
                    *normal = support.normal;
                }
                if let Some(lp) = corrections {
                    *lp = l_pressure;
                }
            });
        self.reference = ppe::pin_reference(p, set.gravity, &mut self.roles);
        ppe::full_support(nb, &self.roles, &mut self.full_support);
    }

    /// Inside the fluid (no free surface in reach) the moment matrix measures the disorder of
    /// the particles, not a truncated support: corrected there, the divergence of the PPE
    /// source amplifies that disorder into the pressure (measured: a collision of two blocks
    /// gains energy instead of losing it). So L_i is kept only where the free surface is in
    /// reach, and stored for those particles only (a few per cent of a large run): their slots
    /// are given out in index order, then L_i is inverted from the moments of each. The pressure
    /// gradient keeps its correction L'_i everywhere, which inside the fluid corrects the wall
    /// ghosts' missing tangential gradient.
    fn near_surface_corrections(
        &mut self,
        nb: &Neighbours<D>,
        p: &Particles<D>,
        min_determinant: f64,
    ) {
        self.correction_slot
            .resize(self.full_support.len(), NO_SLOT);
        self.corrected.clear();
        for (i, slot) in self.correction_slot.iter_mut().enumerate() {
            *slot = if !self.full_support[i] {
                self.corrected.push(i as u32);
                (self.corrected.len() - 1) as u32
            } else {
                NO_SLOT
            };
        }
        self.corrections.resize(self.corrected.len(), None);
        self.corrections
            .par_iter_mut()
            .zip(&self.corrected)
            .for_each(|(l, &i)| {
                let moments = sph::support_moments(nb, p, i as usize);
                *l = sph::gradient_correction(moments.m, min_determinant);
            });
    }

    /// The Smagorinsky eddy viscosity ν_t of Eq. (3)–(4), Δ = dx.
    fn eddy_viscosity(
        &mut self,
        nb: &Neighbours<D>,
        p: &Particles<D>,
        set: &StepSettings<D>,
        les: &LesSettings,
    ) {
        self.eddy.resize(self.roles.len(), 0.0);
        let corrections = Corrections::sparse(
            set.effects.kernel_correction,
            &self.correction_slot,
            &self.corrections,
        );
        fill(&mut self.eddy, |i| {
            les::eddy_viscosity(nb, p, corrections.of(i), les.cs, set.spacing, i)
        });
    }

    /// Predictor, Eq. (5): u* = uⁿ + Δt (∇·((ν + ν_t)∇uⁿ) + τ_w + g), with ν_t the Smagorinsky
    /// eddy viscosity (Eq. 3–4) and τ_w the turbulent wall shear where the scene runs LES (and
    /// its wall function); walls stay at rest.
    fn predict(&mut self, nb: &Neighbours<D>, p: &Particles<D>, set: &StepSettings<D>, dt: f64) {
        for a in &mut self.u_star {
            a.resize(self.roles.len(), 0.0);
        }
        let (spacing, gravity, les) = (set.spacing, set.gravity, set.effects.les);
        let eddy = les.is_some().then_some(&self.eddy[..]);
        let wall_function = les.is_some_and(|les| les.wall_function);
        let support = nb.kernel.support();
        fill_vector(&mut self.u_star, |i| {
            // The nearest wall, for the no-slip wall velocity and the wall function.
            let face = ghosts::nearest_face(nb, p, spacing, support, i);
            let visc = sph::viscous_acceleration(nb, p, eddy, face, i);
            let wall = if wall_function {
                les::wall_shear(p, spacing, face, i)
            } else {
                [0.0; D]
            };
            std::array::from_fn(|d| p.vel[d][i] + dt * (visc[d] + wall[d] + gravity[d]))
        });
    }

    /// PPE, Eq. (6), solved by BiCGSTAB from the last pressure (warm start; the unknowns are
    /// the fluid pressures, walls hold none). The solution is left in `self.pressure`.
    fn solve_pressure(
        &mut self,
        nb: &Neighbours<D>,
        p: &Particles<D>,
        set: &StepSettings<D>,
        step: StepLength,
    ) -> Result<SolveInfo, SolverError> {
        let n = self.roles.len();
        for a in &mut self.row_vectors {
            a.resize(n, 0.0);
        }
        self.pressure.resize(n, 0.0);
        let kernel_correction = set.effects.kernel_correction;
        let interfaces = interfaces(
            &self.interface_table,
            &self.interface_distance,
            &self.interface_normal,
        );
        ppe::row_vectors(
            nb,
            p,
            interfaces,
            &self.roles,
            Corrections::new(kernel_correction, &self.pressure_corrections),
            &mut self.row_vectors,
        );
        ppe::fluid_volumes(p, n, &mut self.fluid_volume);
        // Water sealed off from the free surface (a compartment under a lid, a pocket against
        // a wall) has no pressure level of its own: its highest particle is pinned to P = 0,
        // the role the free surface plays elsewhere, and the hierarchy rebuilt (a pinned
        // region is anchored, so the second pass finds none).
        let mut sealed = Vec::new();
        let op = loop {
            let op = PressureOperator {
                nb,
                p,
                roles: &self.roles,
                row_vectors: &self.row_vectors,
                fluid_volume: &self.fluid_volume,
                gravity: set.gravity,
                ghost_gravity: set.ghost_gravity,
                interfaces,
            };
            self.multigrid.setup(&op)?;
            let unanchored = self.multigrid.unanchored_regions();
            if unanchored.is_empty() {
                break op;
            }
            for region in &unanchored {
                let top = ppe::highest(p, set.gravity, region.iter().copied())
                    .expect("a region holds unknowns");
                self.roles[top] = Role::Reference;
            }
            sealed.extend(unanchored);
        };
        ppe::source(
            &op,
            self.reference.is_some(),
            &sealed,
            &self.full_support,
            set.spacing,
            Corrections::sparse(kernel_correction, &self.correction_slot, &self.corrections),
            &self.u_star,
            step.dt,
            set.alpha / step.limit,
            &mut self.rhs,
        );
        let roles = &self.roles;
        // In a closed box the last pressure is shifted to the new reference's level.
        let level = self.reference.map_or(0.0, |r| p.pressure[r]);
        fill(&mut self.pressure, |i| match roles[i] {
            Role::Interior | Role::Surface => p.pressure[i] - level,
            Role::Splash | Role::Reference => 0.0,
        });
        let info = self.bicgstab.solve(
            &op,
            &mut self.multigrid,
            &self.rhs,
            &mut self.pressure,
            set.solver,
        )?;
        if self.reference.is_some() {
            zero_mean_pressure(p, &mut self.pressure);
        }
        Ok(info)
    }

    /// Corrector, Eq. (7): uⁿ⁺¹ = u* − (Δt/ρ0)∇Pⁿ⁺¹ with the corrected gradient and the walls
    /// as ghosts; particles touching a wall face keep no velocity into it
    /// (`Faces::no_penetration`). ∇Pⁿ⁺¹ is left in place of u*.
    fn correct(
        &mut self,
        nb: &Neighbours<D>,
        p: &Particles<D>,
        set: &StepSettings<D>,
        faces: &Faces,
        dt: f64,
    ) {
        let n = self.roles.len();
        for a in &mut self.velocity {
            a.resize(n, 0.0);
        }
        let corrections =
            Corrections::new(set.effects.kernel_correction, &self.pressure_corrections);
        let touch = touching_distance(set.spacing);
        let (roles, full) = (&self.roles, &self.full_support);
        let interfaces = interfaces(
            &self.interface_table,
            &self.interface_distance,
            &self.interface_normal,
        );
        let ghost = set.ghost_gravity;
        fill_vector_and_update(&mut self.velocity, &mut self.u_star, |i, u_star| {
            let p_ref = pressure_reference(nb, p, roles[i], full[i], i);
            let grad = pressure_gradient(nb, p, ghost, interfaces, corrections.of(i), p_ref, i);
            let rho0 = p.rest_density[i];
            let u = std::array::from_fn(|d| u_star[d] - dt * grad[d] / rho0);
            (faces.no_penetration(p.position(i), u, touch), grad)
        });
    }

    /// Two measures over the fluid particles with no free surface in reach (where the
    /// summation density is not truncated), in one pass:
    /// - the density error, mean |ρ/ρ0 − 1|;
    /// - the particle disorder, the coefficient of variation (standard deviation over mean) of
    ///   the distance from each particle to its nearest neighbour: zero on a lattice, a few per
    ///   cent when particles stay well spread, growing as they cluster into lines and gaps
    ///   (tensile instability, no shifting).
    fn full_support_statistics(&self, nb: &Neighbours<D>, p: &Particles<D>) -> (f64, f64) {
        let full = &self.full_support;
        let [count, density, distance, square] = reduce::sums(full.len(), |i| {
            if !full[i] {
                return [0.0; 4];
            }
            let mut nearest = F64s::splat(f64::INFINITY);
            nb.for_each_lanes(i, |l| {
                nearest = nearest.fast_min(l.mask.select(l.r, F64s::splat(f64::INFINITY)));
            });
            let nearest = nearest.to_array().into_iter().fold(f64::INFINITY, f64::min);
            let error = (p.density[i] / p.rest_density[i] - 1.0).abs();
            [1.0, error, nearest, nearest * nearest]
        });
        if count == 0.0 {
            // Nothing measured (a layer too thin for a full support anywhere): not a zero error.
            return (f64::NAN, f64::NAN);
        }
        let mean = distance / count;
        let variance = (square / count - mean * mean).max(0.0);
        (density / count, variance.sqrt() / mean)
    }

    /// Particle shifting δr = −D ∇C (Eq. 10) at rⁿ, then velocity and pressure carried to the
    /// shifted position by Eq. (9); the new velocity and pressure are left in `self.velocity`
    /// and `self.pressure`.
    fn shift(
        &mut self,
        nb: &Neighbours<D>,
        p: &Particles<D>,
        set: &StepSettings<D>,
        faces: &Faces,
        settings: &ShiftingSettings,
        dt: f64,
    ) {
        let n = self.roles.len();
        for a in &mut self.shift {
            a.resize(n, 0.0);
        }
        let max_speed = reduce::max(n, |i| speed(p, i));
        let shifting = Shifting::new(nb, settings, set.spacing, max_speed, dt);
        let (roles, normals, full) = (&self.roles, &self.surface_normal, &self.full_support);
        let touch = touching_distance(set.spacing);
        fill_vector(&mut self.shift, |i| match roles[i] {
            // Splashes are left in place: neither ∇C nor the Taylor correction means anything
            // there.
            Role::Interior | Role::Surface | Role::Reference => {
                let dr = shifting.displacement(nb, p, normals[i], full[i], i);
                faces.no_penetration(p.position(i), dr, touch)
            }
            Role::Splash => [0.0; D],
        });
        let shift = &self.shift;
        let corrections = Corrections::sparse(
            set.effects.kernel_correction,
            &self.correction_slot,
            &self.corrections,
        );
        fill_vector(&mut self.velocity, |i| {
            // Where the free surface is in reach the velocity gradient is no longer that of a
            // filled support, and shifting moves particles into the thinning, faster parts of a
            // stretching flow: the Taylor step there feeds the flow energy (measured).
            if !full[i] {
                return p.velocity(i);
            }
            let u_i = p.velocity(i);
            let u = |l: &Lanes<D>| sph::fluid_velocity(p, u_i, l);
            let g = sph::velocity_gradient(nb, p, corrections.of(i), u_i, u, i);
            let dr = vector(shift, i);
            std::array::from_fn(|a| p.vel[a][i] + (0..D).map(|b| dr[b] * g[b][a]).sum::<f64>())
        });
        // ∇Pⁿ⁺¹ at rⁿ, left by the corrector (the walls' pressures for a frame do not enter it).
        let grad_p = &self.u_star;
        let clip = self.reference.is_none();
        fill(&mut self.pressure, |i| {
            let (g, dr) = (vector(grad_p, i), vector(shift, i));
            cavitation(
                clip,
                p.pressure[i] + (0..D).map(|d| g[d] * dr[d]).sum::<f64>(),
            )
        });
    }

    /// Advection, Eq. (8), of the `nf` fluid particles, plus the shift of the step when
    /// shifting ran.
    fn advect(&self, p: &mut Particles<D>, nf: usize, dt: f64, shifted: bool) {
        for d in 0..D {
            let (vel, shift) = (&p.vel[d], &self.shift[d]);
            p.pos[d][..nf]
                .par_iter_mut()
                .enumerate()
                .for_each(|(i, x)| {
                    let s = if shifted { shift[i] } else { 0.0 };
                    *x += dt * vel[i] + s;
                });
        }
    }
}

/// The interfaces' distances and normals, where the fluids differ in rest density (`table`;
/// `interface::Side::across`).
fn interfaces<'a, const D: usize>(
    table: &Option<Interfaces>,
    distance: &'a [f64],
    normal: &'a [Vec<f64>; D],
) -> Option<interface::Field<'a, D>> {
    table
        .as_ref()
        .map(|_| interface::Field { distance, normal })
}

/// The pressures of the wall particles (from index `nf` on), for the frames: the
/// ghost pressures their fluid neighbours give them (`ghosts::wall_pressure`), zero where no fluid
/// is in reach. A wall particle visits only its fluid neighbours (the fluid and the walls are
/// sorted apart): in a large tank most walls are dry, and cost no more than finding their fluid
/// cells empty.
fn wall_pressure<const D: usize>(
    nb: &Neighbours<D>,
    ghosts: &ghosts::Ghosts<D>,
    pressure: &mut [f64],
    nf: usize,
) {
    let (fluid, walls) = pressure.split_at_mut(nf);
    fill(walls, |k| ghosts.wall_pressure(nb, fluid, nf + k));
}

/// Distance from a wall face within which a fluid particle touches it (the kinematic condition
/// of `Faces::no_penetration`): half a spacing, the distance at which the fluid's first layer
/// rests, and a hair more so that the resting layer is included. Measured: 0.35 dx (acting only
/// on particles that came closer than at rest) let the still-water tank drift, 0.011 m/s and
/// 6.1% disorder after 20 s, against 7e-4 m/s and 0.4% at 0.5001 dx; on the 2D violent impact at
/// CFL 0.5 it let 25 particles cross a face (4 at 0.5001 dx, 78 at 0.25 dx).
fn touching_distance(spacing: f64) -> f64 {
    0.5001 * spacing
}

/// `to[d][..n] = from[d]` for each component, n the length of `from`.
fn copy_vector<const D: usize>(from: &[Vec<f64>; D], to: &mut [Vec<f64>; D]) {
    for (f, t) in from.iter().zip(to) {
        t[..f.len()].copy_from_slice(f);
    }
}

/// ∇P_i of fluid particle i with the corrected gradient (Eq. 20, 24–25), the differences
/// taken from `p_ref` (`pressure_reference`), and the walls as ghosts of P_i (see `wall`)
/// carrying `ghost_gravity`: a particle whose pressure exceeds p_ref is pushed off a wall it
/// presses on, but not out through a free surface; across the interface of two fluids
/// (`interfaces`, the distances to it) each difference is weighted by ρ0_i/ρ̄_ij
/// (`interface::Side::across`).
fn pressure_gradient<const D: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    ghost_gravity: [f64; D],
    interfaces: Option<interface::Field<D>>,
    l: &Correction<D>,
    p_ref: f64,
    i: usize,
) -> [f64; D] {
    let (p_ref, side) = (F64s::splat(p_ref), interface::Side::of(p, interfaces, i));
    // A wall ghost mirrors P_i itself: P_b − p_ref = (P_i − p_ref) + (P_b − P_i).
    let own = F64s::splat(p.pressure[i]) - p_ref;
    sph::gradient(nb, p, l, i, |lanes| match lanes.kind {
        Kind::Fluid => side.across(p, interfaces, lanes, lanes.load(&p.pressure) - p_ref),
        Kind::Wall => own + ghosts::ghost_pressure_difference(p, ghost_gravity, i, lanes),
    })
}

/// The pressure at fluid particle i that its pressure gradient takes the differences
/// P_j − P_i from: P_i itself, but for an unknown of the PPE with the free surface in its
/// kernel support (`role` Interior, not `full_support`) the value P̃_i of the linear function
/// fitted to its fluid neighbours' pressures (`sph::fitted_value`; P_i where they fix none).
/// Both are exact for a linear field. Where the surface truncates the support, the difference
/// form carries the term −P_i L'_i Σ_j V_j ∇W_ij, which points out of the fluid: a particle
/// whose pressure dips below its neighbours' is pushed towards the surface, and the projection
/// feeds the velocity that lowered its pressure. On the still tank of `hydrostatic_2d` the
/// step's velocity map, u ← u − (Δt/ρ0)∇P of the PPE of u, then amplifies a zig-zag of the row
/// under the surface by 0.32% per step (its largest eigenvalue at rest, by power iteration),
/// and the tank sloshes after 28 s; with P̃_i the largest eigenvalue is 1, the divergence-free
/// fields' (docs/stabilisation.md).
fn pressure_reference<const D: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    role: Role,
    full_support: bool,
    i: usize,
) -> f64 {
    if role == Role::Interior && !full_support {
        sph::fitted_value(nb, p, &p.pressure, i).unwrap_or(p.pressure[i])
    } else {
        p.pressure[i]
    }
}

/// The pressure the fluid takes: with a free surface the pressure is absolute (zero at the
/// surface) and the water cannot hold a tension, so negative pressures are cut to zero; in a
/// closed box (`clip` false) only differences count and P is kept as solved.
#[inline]
fn cavitation(clip: bool, pressure: f64) -> f64 {
    if clip {
        pressure.max(0.0)
    } else {
        pressure
    }
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

/// Component vector i of a SoA vector field.
#[inline]
fn vector<const D: usize>(a: &[Vec<f64>; D], i: usize) -> [f64; D] {
    std::array::from_fn(|d| a[d][i])
}

/// |u_i|.
pub fn speed<const D: usize>(p: &Particles<D>, i: usize) -> f64 {
    (0..D)
        .map(|d| p.vel[d][i] * p.vel[d][i])
        .sum::<f64>()
        .sqrt()
}
