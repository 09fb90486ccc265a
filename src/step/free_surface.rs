//! How each kernel support is filled, from its moments (`sph::support_moments_and`) and its
//! summation density (`sph::DensitySum`, with the nearest neighbour's distance), summed in one
//! walk: the free surface and the role of each fluid particle in the PPE (`ppe::role`), the
//! particles with no free surface in reach, and what the same walk gives at no extra pass: the
//! pressure gradient's L'_i of Eq. (25) with the kernel correction, the surface normal with
//! shifting, the PPE's row vectors ĉ_i (`ppe::row_vector`), and with LES the strain rate of the velocity
//! gradient (`sph::VelocityGradientSum`: the same neighbours with the same V_j ∇W_ij factor as
//! the moments) both as summed and corrected by L_i = M_i⁻¹ of the same moments, for the eddy
//! viscosity to take the one the kernel correction asks for once the free surface is known.

use super::{Stage, StepSettings};
use crate::effects::les;
use crate::math::memory::ArraySize;
use crate::neighbours::Neighbours;
use crate::particles::{Kind, Particles};
use crate::scene::Effects;
use crate::solver::ppe::{self, LaplacianTruncation, Role};
use crate::sph::free_surface::Support;
use crate::sph::{self, Correction, Corrections, DensitySum, VelocityGradientSum};
use rayon::iter::Either;
use rayon::prelude::*;
use std::sync::atomic::AtomicBool;

pub const NAME: &str = "free surface";

pub struct FreeSurface<const D: usize> {
    /// Summation density of the step (copied into the particles).
    density: Vec<f64>,
    /// Distance to the nearest neighbour (the disorder of `stats.csv`).
    nearest: Vec<f64>,
    roles: Vec<Role>,
    /// The particle pinned to P = 0 where the fluid has no free surface (`ppe::pin_reference`;
    /// None: the fluid has one, its pressure is absolute and cannot hold a tension).
    reference: Option<usize>,
    /// No free-surface particle in the kernel support.
    full_support: Vec<bool>,
    /// Whether a free-surface particle reaches it (`ppe::full_support`'s scratch).
    reached: Vec<AtomicBool>,
    /// The correction L'_i of the pressure gradient, whose wall ghosts carry the normal part
    /// of the gradient only (see `sph::Moments`) (with the kernel correction).
    pressure_corrections: Option<Vec<Correction<D>>>,
    /// The free surface's outward normal of each fluid particle, where shifting keeps to the
    /// tangential direction (with shifting).
    surface_normal: Option<Vec<[f64; D]>>,
    /// The PPE's row vectors ĉ_i (`ppe::row_vector`).
    row_vectors: Vec<[f64; D]>,
    /// |S| of each fluid particle's velocity gradient (`les::strain_rate`), the walls free-slip
    /// ghosts: [uncorrected, corrected by L_i = M_i⁻¹] (with LES).
    strain_rates: Option<Vec<[f64; 2]>>,
}

/// What the stage found, for the stages after it.
#[derive(Clone, Copy)]
pub struct Surface<'a, const D: usize> {
    pub roles: &'a [Role],
    pub reference: Option<usize>,
    pub full_support: &'a [bool],
    /// L'_i (the identity without the kernel correction).
    pub pressure_corrections: Corrections<'a, D>,
    /// The outward normals (with shifting).
    pub normals: Option<&'a [[f64; D]]>,
    /// The PPE's row vectors ĉ_i.
    pub row_vectors: &'a [[f64; D]],
}

impl<const D: usize> FreeSurface<D> {
    pub fn new(effects: &Effects) -> Self {
        Self {
            density: Vec::new(),
            nearest: Vec::new(),
            roles: Vec::new(),
            reference: None,
            full_support: Vec::new(),
            reached: Vec::new(),
            pressure_corrections: effects.kernel_correction.then(Vec::new),
            surface_normal: effects.shifting.map(|_| Vec::new()),
            row_vectors: Vec::new(),
            strain_rates: effects.les.map(|_| Vec::new()),
        }
    }

    /// Classifies the `nf` fluid particles, inverting L'_i from the same moments (once per step
    /// for every operator after it); `fluids_differ`: the scene's fluids differ in rest density;
    /// `driven(b)`: body b's motion over the step is given (fixed or prescribed), so that its
    /// particles with fluid in reach are the fluid's ghosts (`ppe::Role::Ghost`).
    pub fn run(
        &mut self,
        nb: &Neighbours<D>,
        p: &Particles<D>,
        set: &StepSettings<D>,
        fluids_differ: bool,
        driven: impl Fn(usize) -> bool + Sync,
        nf: usize,
    ) {
        let n = nf;
        let (corrected, les) = (
            self.pressure_corrections.is_some(),
            self.strain_rates.is_some(),
        );
        self.density.resize(n, 0.0);
        self.nearest.resize(n, 0.0);
        self.roles.resize(n, Role::Interior);
        self.row_vectors.resize(n, [0.0; D]);
        let corrections = match &mut self.pressure_corrections {
            Some(l) => {
                l.resize(n, None);
                Either::Left(l.par_iter_mut().map(Some))
            }
            None => Either::Right((0..n).into_par_iter().map(|_| None)),
        };
        let normals = match &mut self.surface_normal {
            Some(normals) => {
                normals.resize(n, [0.0; D]);
                Either::Left(normals.par_iter_mut().map(Some))
            }
            None => Either::Right((0..n).into_par_iter().map(|_| None)),
        };
        let strain_rates = match &mut self.strain_rates {
            Some(rates) => {
                rates.resize(n, [0.0; 2]);
                Either::Left(rates.par_iter_mut().map(Some))
            }
            None => Either::Right((0..n).into_par_iter().map(|_| None)),
        };
        self.density
            .par_iter_mut()
            .zip(&mut self.nearest)
            .zip(&mut self.roles)
            .zip(&mut self.row_vectors)
            .zip(normals.zip(corrections).zip(strain_rates))
            .enumerate()
            .for_each(|(i, ((((density, nearest), role), row_vector), outputs))| {
                let ((normal, correction), strain_rate) = outputs;
                let s = particle_support(nb, p, set, fluids_differ, corrected, les, i);
                (*density, *nearest, *role, *row_vector) =
                    (s.density, s.nearest, s.role, s.row_vector);
                if let Some(normal) = normal {
                    *normal = s.normal;
                }
                if let Some(lp) = correction {
                    *lp = s.pressure_correction;
                }
                if let (Some(rate), Some(found)) = (strain_rate, s.strain_rate) {
                    *rate = found;
                }
            });
        self.roles
            .par_iter_mut()
            .zip(&mut self.row_vectors)
            .enumerate()
            .filter(|(i, _)| p.kind[*i] == Kind::Body && driven(p.fluid[*i] as usize))
            .for_each(|(i, (role, row_vector))| {
                if ppe::has_fluid_in_reach(nb, p, i) {
                    (*role, *row_vector) = (Role::Ghost, [0.0; D]);
                }
            });
        self.reference = ppe::pin_reference(p, set.gravity, &mut self.roles);
        if let Some(reference) = self.reference {
            self.row_vectors[reference] = [0.0; D];
        }
        ppe::full_support(nb, &self.roles, &mut self.reached, &mut self.full_support);
    }

    /// The summation density of the last `run`.
    pub fn density(&self) -> &[f64] {
        &self.density
    }

    /// Each fluid particle's distance to its nearest neighbour, from the last `run`.
    pub fn nearest(&self) -> &[f64] {
        &self.nearest
    }

    pub fn full_support(&self) -> &[bool] {
        &self.full_support
    }

    /// The strain rates of the velocity gradients, [uncorrected, corrected] (with LES).
    pub fn strain_rates(&self) -> Option<&[[f64; 2]]> {
        self.strain_rates.as_deref()
    }

    /// Pins fluid particle `i` to P = 0, the role the free surface plays elsewhere (the
    /// pressure solve's sealed regions).
    pub fn pin(&mut self, i: usize) {
        self.roles[i] = Role::Reference;
        self.row_vectors[i] = [0.0; D];
    }

    /// Sets the row vector of every free-surface row to `row(i, L'_i)` (`ppe::surface_row_vector`;
    /// L'_i None without the kernel correction).
    pub fn set_surface_rows(&mut self, row: impl Fn(usize, &Correction<D>) -> [f64; D] + Sync) {
        let corrections = stored_corrections(&self.pressure_corrections);
        let roles = &self.roles;
        self.row_vectors
            .par_iter_mut()
            .enumerate()
            .filter(|(i, _)| roles[*i] == Role::Surface)
            .for_each(|(i, v)| *v = row(i, corrections.of(i)));
    }

    pub fn output(&self) -> Surface<'_, D> {
        Surface {
            roles: &self.roles,
            reference: self.reference,
            full_support: &self.full_support,
            pressure_corrections: stored_corrections(&self.pressure_corrections),
            normals: self.surface_normal.as_deref(),
            row_vectors: &self.row_vectors,
        }
    }
}

/// The stored L'_i as `Corrections` (the identity without the kernel correction).
fn stored_corrections<const D: usize>(l: &Option<Vec<Correction<D>>>) -> Corrections<'_, D> {
    match l {
        Some(l) => Corrections::new(true, l),
        None => Corrections::new(false, &[]),
    }
}

/// What the walk of fluid particle i's kernel support gives (`FreeSurface::run`).
struct ParticleSupport<const D: usize> {
    density: f64,
    nearest: f64,
    role: Role,
    row_vector: [f64; D],
    normal: [f64; D],
    /// L'_i.
    pressure_correction: Correction<D>,
    /// |S| of the velocity gradient, [uncorrected, corrected by L_i] (with LES).
    strain_rate: Option<[f64; 2]>,
}

/// Walks the kernel support of fluid particle i once for its summation density, its moments,
/// its PPE row vector and (with `les`) its velocity gradient, and classifies it; `corrected`:
/// the kernel correction is on.
fn particle_support<const D: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    set: &StepSettings<D>,
    fluids_differ: bool,
    corrected: bool,
    les: bool,
    i: usize,
) -> ParticleSupport<D> {
    let mut density = DensitySum::new(p, i);
    let mut truncation = LaplacianTruncation::new(p, fluids_differ, i);
    let u_i = p.velocity(i);
    let mut grad_u = les.then(|| VelocityGradientSum::new(u_i));
    let mo = sph::support_moments_and(nb, p, i, |l, vf, followed| {
        density.add(nb, p, l);
        truncation.add(nb, p, l, followed);
        if let Some(grad_u) = &mut grad_u {
            grad_u.add(l, vf, sph::fluid_velocity(p, u_i, l));
        }
    });
    let (density, nearest) = density.total(nb, p, i);
    let strain_rate = grad_u.map(|grad_u| {
        let g = grad_u.total();
        // L_i exactly as the kernel correction inverts it (`KernelCorrection::run`: the same
        // moments and bound), where it corrects the particle's gradients.
        let l = if corrected {
            sph::gradient_correction(mo.m, set.min_correction_determinant)
        } else {
            None
        };
        [
            les::strain_rate(g),
            les::strain_rate(sph::corrected_gradient(&l, g)),
        ]
    });
    let pressure_correction =
        sph::gradient_correction(mo.m_neumann, set.min_correction_determinant);
    let support = Support::new(&mo.m, mo.grad_c);
    // Fluid that fills its container has no free surface: every row is interior (a disordered
    // patch of a periodic flow can look like a surface to the detection).
    let role = if set.confined {
        Role::Interior
    } else {
        let gradient_defined = pressure_correction.is_some();
        let ratio = density / p.rest_density[i];
        let (neighbours, spray) = (mo.fluid_neighbours, set.spray_density);
        ppe::role(nb, &support, neighbours, gradient_defined, ratio, spray, i)
    };
    // ĉ_i = L'_iᵀ c_i with the kernel correction, c_i without it.
    let l_row = if corrected {
        &pressure_correction
    } else {
        &None
    };
    ParticleSupport {
        density,
        nearest,
        role,
        row_vector: ppe::row_vector(role, &truncation, l_row),
        normal: support.normal,
        pressure_correction,
        strain_rate,
    }
}

impl<const D: usize> Stage<D> for FreeSurface<D> {
    fn name(&self) -> &'static str {
        NAME
    }

    fn describe(&self, _: &StepSettings<D>) -> String {
        let mut what = "summation density ρ_i = ρ0_i Σ_j V_j W_ij (walls keep ρ0) and the distance to the nearest neighbour (the disorder in stats.csv); moment matrix M_i of each kernel support; its smallest eigenvalue and the scan region (Marrone et al. 2010) find the free surface; PPE roles: interior, free surface (P = 0 half its thickness above it), splash (P = 0: the moment matrix of its pressure gradient is near-singular)".to_string();
        if self.pressure_corrections.is_some() {
            what += "; L'_i of Eq. (25) for the pressure gradient and the PPE rows (wall ghosts carry the normal gradient only), inverted from the same moments";
        }
        if self.surface_normal.is_some() {
            what += "; the surface normal, for the shifting";
        }
        what +=
            "; the PPE rows' vectors ĉ_i of the consistent Laplacian (Eq. 27), in the same walk";
        if self.strain_rates.is_some() {
            what +=
                "; the velocity gradient's strain rate for the eddy viscosity, in the same walk";
        }
        what
    }

    fn arrays(&self) -> Vec<ArraySize> {
        let mut arrays = vec![
            ArraySize::of("density", &self.density),
            ArraySize::of("nearest neighbour", &self.nearest),
            ArraySize::of("PPE role", &self.roles),
            ArraySize::of("full support", &self.full_support),
            ArraySize::of("free surface in reach", &self.reached),
            ArraySize::of("PPE row vector", &self.row_vectors),
        ];
        if let Some(l) = &self.pressure_corrections {
            arrays.push(ArraySize::of("L'", l));
        }
        if let Some(normals) = &self.surface_normal {
            arrays.push(ArraySize::of("surface normal", normals));
        }
        if let Some(rates) = &self.strain_rates {
            arrays.push(ArraySize::of("strain rate", rates));
        }
        arrays
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::kernel::{Kernel, KernelKind};
    use crate::neighbours::cell_list::CellList;
    use crate::particles::{Kind, NewParticle};
    use crate::scene::GhostPressure;
    use crate::solver::krylov::SolverParams;

    /// ĉ_i of interior row i as the PPE needs it: L'_iᵀ c_i with the kernel correction, c_i
    /// without it (its pressure gradient is then uncorrected, and the row must match it).
    fn expected_row_vector(
        nb: &Neighbours<2>,
        p: &Particles<2>,
        i: usize,
        corrected: bool,
    ) -> [f64; 2] {
        let mut truncation = LaplacianTruncation::new(p, false, i);
        let mo = sph::support_moments_and(nb, p, i, |l, _, followed| {
            truncation.add(nb, p, l, followed)
        });
        let l = if corrected {
            sph::gradient_correction(
                mo.m_neumann,
                sph::min_correction_determinant::<2>(KernelKind::Quintic, H_OVER_DX),
            )
        } else {
            None
        };
        ppe::row_vector(Role::Interior, &truncation, &l)
    }

    const DX: f64 = 0.01;
    const H_OVER_DX: f64 = 1.2;

    /// Water 16 × 10 spacings over four rows of floor, its free surface at the top, sorted by
    /// cell, moving with a shear `u = (sin(30 y), 0.5 cos(20 x))` m/s; and its fluid count.
    fn water_over_a_floor() -> (Particles<2>, CellList<2>, Kernel<2>, usize) {
        let mut p = Particles::<2>::default();
        for ix in 0..16 {
            for iy in 0..14 {
                let wall = iy < 4;
                p.push(NewParticle {
                    pos: [(ix as f64 + 0.5) * DX, (iy as f64 - 3.5) * DX],
                    kind: if wall { Kind::Wall } else { Kind::Fluid },
                    normal: if wall { [0.0, 1.0] } else { [0.0, 0.0] },
                    fluid: 0,
                    mass: 1000.0 * DX * DX,
                    rest_density: 1000.0,
                    viscosity: 1e-6,
                });
            }
        }
        let kernel = Kernel::<2>::new(KernelKind::Quintic, DX, H_OVER_DX);
        let mut grid = CellList::new([-0.1, -0.1], [0.3, 0.3], kernel.support(), [false; 2]);
        let (mut cells, mut order, mut scratch) = (Vec::new(), Vec::new(), Vec::new());
        grid.sort(&p.pos, &p.kind, &mut cells, &mut order).unwrap();
        p.permute(&order, &mut scratch);
        let nf = grid.range_of(Kind::Fluid).end;
        for i in 0..nf {
            let (x, y) = (p.pos[0][i], p.pos[1][i]);
            (p.vel[0][i], p.vel[1][i]) = ((30.0 * y).sin(), 0.5 * (20.0 * x).cos());
        }
        (p, grid, kernel, nf)
    }

    fn settings(effects: Effects) -> StepSettings<2> {
        StepSettings {
            gravity: [0.0, -9.81],
            ghost_pressure: GhostPressure::Hydrostatic,
            spacing: DX,
            alpha: 0.3,
            solver: SolverParams {
                tolerance: 1e-6,
                max_iterations: 100,
            },
            effects,
            confined: false,
            spray_density: crate::sph::free_surface::spray_density::<2>(
                KernelKind::Quintic,
                H_OVER_DX,
            ),
            min_correction_determinant: sph::min_correction_determinant::<2>(
                KernelKind::Quintic,
                H_OVER_DX,
            ),
            cfl: 0.4,
            max_viscosity: 1e-6,
        }
    }

    #[test]
    fn the_row_vectors_take_the_pressure_correction_only_where_the_kernel_correction_is_on() {
        let (p, grid, kernel, nf) = water_over_a_floor();
        let nb = Neighbours::new(&grid, &p.pos, kernel);
        let mut corrected_rows = 0;
        for corrected in [false, true] {
            let effects = Effects {
                shifting: None,
                les: None,
                kernel_correction: corrected,
            };
            let mut stage = FreeSurface::new(&effects);
            stage.run(&nb, &p, &settings(effects), false, |_| false, nf);
            let s = stage.output();
            for i in (0..nf).filter(|&i| s.roles[i] == Role::Interior) {
                let expected = expected_row_vector(&nb, &p, i, corrected);
                assert_eq!(
                    s.row_vectors[i], expected,
                    "row {i}, kernel correction {corrected}"
                );
                corrected_rows +=
                    usize::from(corrected && expected != expected_row_vector(&nb, &p, i, false));
            }
        }
        // The surface's rows are where L'_i differs from the identity: the test compares
        // different vectors there.
        assert!(
            corrected_rows > 10,
            "{corrected_rows} rows whose L' moves ĉ"
        );
    }

    /// The sums the stage makes in its one walk have the bits of walks of their own: the
    /// summation density, the full supports (found from the surface's side) and the eddy
    /// viscosity's strain rates, as and where the kernel correction stage corrects them.
    #[test]
    fn the_walk_gives_the_bits_of_walks_of_their_own() {
        let (p, grid, kernel, nf) = water_over_a_floor();
        let nb = Neighbours::new(&grid, &p.pos, kernel);
        let effects = Effects {
            shifting: None,
            les: Some(crate::scene::LesSettings::default()),
            kernel_correction: true,
        };
        let set = settings(effects);
        let mut stage = FreeSurface::new(&effects);
        stage.run(&nb, &p, &set, false, |_| false, nf);
        let (s, rates) = (stage.output(), stage.strain_rates().unwrap());
        let mut kernel_correction = super::super::kernel_correction::KernelCorrection::default();
        let corrections =
            kernel_correction.run(&nb, &p, s.full_support, set.min_correction_determinant);
        let (mut full, mut corrected) = (0, 0);
        for i in 0..nf {
            assert_eq!(stage.density()[i], sph::density(&nb, &p, i), "ρ of {i}");
            let mut free_in_reach = false;
            nb.for_each_of(i, &[Kind::Fluid], |j, _, _| {
                free_in_reach |= s.roles[j].is_free()
            });
            let expected_full = s.roles[i] == Role::Interior && !free_in_reach;
            assert_eq!(s.full_support[i], expected_full, "full support of {i}");
            full += usize::from(expected_full);
            let u_i = p.velocity(i);
            let l = corrections.of(i);
            let grad =
                sph::velocity_gradient(&nb, &p, l, u_i, |l| sph::fluid_velocity(&p, u_i, l), i);
            let rate = if l.is_some() {
                rates[i][1]
            } else {
                rates[i][0]
            };
            assert_eq!(rate, les::strain_rate(grad), "|S| of {i}");
            corrected += usize::from(l.is_some() && rates[i][1] != rates[i][0]);
        }
        // Both kinds of support, and corrected rates that differ from the plain ones.
        assert!(full > 20 && full < nf - 20, "{full} full supports of {nf}");
        assert!(corrected > 10, "{corrected} corrected strain rates");
    }
}
