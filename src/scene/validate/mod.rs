//! Checks a parsed scene file and turns it into a `Scene`: every error names the file, the
//! key and, where it can be found, the line.

mod trajectory;

use super::mesh_file;
use crate::math::mesh::TriangleMesh;

use super::file::{
    BodySection, BoxSection, CheckpointSection, EffectsSection, InitialVelocitySection, LesSection,
    ProbeSection, SceneFile, ShapeSection, ShiftingSection, SimulationSection, SolverSection,
    SurfaceSection,
};
use super::{
    Aabb, Block, Body, BodyMass, BodyMotion, CheckpointSettings, Effects, InitialVelocity,
    LesSettings, Probe, ProbeField, Scene, SceneError, Shape, ShiftingSettings, SolverSettings,
    SurfaceRequest, SurfaceSettings,
};
use crate::math::kernel::KernelKind;
use crate::scene::BYTES_PER_CONTAINER_POINT;
use std::path::Path;

/// Frames a scene may ask for, at most (end_time / output_interval).
const MAX_FRAMES: f64 = 1e5;
/// `simulation.perturbation` when the scene gives none and the fluid feels no body force, in
/// spacings: the measured choice of docs/accuracy.md ("The start-up error of the Taylor–Green
/// vortex"). Under a body force (gravity, a moving container's frame) the default is the lattice:
/// the density correction then relaxes the perturbed start and stirs still water
/// (`default_perturbation`).
const PERTURBATION_WITHOUT_BODY_FORCE: f64 = 0.1;
/// The largest `simulation.perturbation`: a quarter spacing keeps every fluid particle more
/// than a quarter spacing off the walls (the lattice sits half a spacing inside the faces).
const MAX_PERTURBATION: f64 = 0.25;

/// Peak resident memory of a run per particle, walls included, with a margin over the peaks
/// `isph bench` measures on the 3D dam break (480 B at 10⁵, 571–575 B at 10⁶ fluid particles;
/// docs/performance.md, "Memory per particle").
const PEAK_BYTES_PER_PARTICLE: f64 = 650.0;

/// Checks a parsed file and turns it into a `Scene`, locating bad keys in the source text.
pub(super) struct Validator<'a> {
    pub(super) text: &'a str,
    pub(super) path: &'a Path,
}

impl Validator<'_> {
    fn error(&self, key: &str, message: impl Into<String>) -> SceneError {
        SceneError::Invalid {
            path: self.path.to_owned(),
            line: line_of_key(self.text, key),
            key: key.to_owned(),
            message: message.into(),
        }
    }

    fn check(&self, ok: bool, key: &str, message: impl Into<String>) -> Result<(), SceneError> {
        if ok {
            Ok(())
        } else {
            Err(self.error(key, message))
        }
    }

    fn positive(&self, value: f64, key: &str, unit: &str) -> Result<(), SceneError> {
        self.check(
            value.is_finite() && value > 0.0,
            key,
            format!("= {value:?} must be a positive number [{unit}]"),
        )
    }

    fn vector(&self, v: &[f64], dims: usize, key: &str) -> Result<(), SceneError> {
        self.check(
            v.len() == dims,
            key,
            format!(
                "has {} components but the scene has `simulation.dimensions = {dims}`",
                v.len()
            ),
        )?;
        self.check(
            v.iter().all(|x| x.is_finite()),
            key,
            "must hold finite numbers",
        )
    }

    fn aabb(
        &self,
        b: &BoxSection,
        dims: usize,
        key: &str,
        spacing: f64,
    ) -> Result<Aabb, SceneError> {
        self.vector(&b.min, dims, &format!("{key}.min"))?;
        self.vector(&b.max, dims, &format!("{key}.max"))?;
        for d in 0..dims {
            self.check(
                // (0.21 − 0.2 = 0.00999… is one spacing of 0.01)
                b.max[d] - b.min[d] >= spacing * (1.0 - 1e-9),
                &format!("{key}.max"),
                format!(
                    "must exceed `{key}.min` by at least one particle spacing ({spacing:?} m) in every axis; axis {d} has {:?} .. {:?}",
                    b.min[d], b.max[d]
                ),
            )?;
        }
        Ok(Aabb {
            min: b.min.clone(),
            max: b.max.clone(),
        })
    }

    /// A box section that must lie inside the container.
    fn region_inside(
        &self,
        b: &BoxSection,
        container: &Aabb,
        dims: usize,
        key: &str,
        spacing: f64,
        what: &str,
    ) -> Result<Aabb, SceneError> {
        let region = self.aabb(b, dims, key, spacing)?;
        self.check(
            region.within(container),
            &format!("{key}.min"),
            format!(
                "the {what} {:?} .. {:?} is not inside the container {:?} .. {:?}",
                region.min, region.max, container.min, container.max
            ),
        )?;
        Ok(region)
    }

    pub(super) fn scene(&self, f: SceneFile) -> Result<Scene, SceneError> {
        let s = &f.simulation;
        self.check(
            s.dimensions == 2 || s.dimensions == 3,
            "simulation.dimensions",
            format!("= {} is not supported: use 2 or 3", s.dimensions),
        )?;
        let dims = s.dimensions as usize;
        self.positive(s.spacing, "simulation.spacing", "m")?;
        self.positive(s.end_time, "simulation.end_time", "s")?;
        self.positive(s.output_interval, "simulation.output_interval", "s")?;
        let frames = s.end_time / s.output_interval;
        self.check(
            frames <= MAX_FRAMES,
            "simulation.output_interval",
            format!(
                "= {:?} makes {frames:.3e} frames to end_time = {:?} s; at most {MAX_FRAMES} (each frame holds every particle)",
                s.output_interval, s.end_time
            ),
        )?;
        self.vector(&s.gravity, dims, "simulation.gravity")?;
        if let Some(perturbation) = s.perturbation {
            self.check(
                (0.0..=MAX_PERTURBATION).contains(&perturbation),
                "simulation.perturbation",
                format!("= {perturbation:?} must be in [0, {MAX_PERTURBATION}] particle spacings"),
            )?;
        }

        self.check(
            !f.fluid.is_empty(),
            "fluid",
            "is missing: define at least one [[fluid]]",
        )?;
        for (k, fl) in f.fluid.iter().enumerate() {
            let key = format!("fluid[{k}]");
            self.positive(fl.density, &format!("{key}.density"), "kg/m^3")?;
            self.check(
                fl.viscosity.is_finite() && fl.viscosity >= 0.0,
                &format!("{key}.viscosity"),
                format!("= {:?} must be a non-negative number [m^2/s]", fl.viscosity),
            )?;
            self.check(
                f.fluid[..k].iter().all(|o| o.name != fl.name),
                &format!("{key}.name"),
                format!("= \"{}\" is defined twice", fl.name),
            )?;
        }

        let container_box = BoxSection {
            min: f.container.min.clone(),
            max: f.container.max.clone(),
        };
        let container = self.aabb(&container_box, dims, "container", s.spacing)?;
        let solver = self.solver(&f.solver)?;
        let periodic = self.periodic(
            f.container.periodic.as_deref(),
            &container,
            s.spacing,
            &solver,
        )?;
        self.check(
            !f.fluid_block.is_empty(),
            "fluid_block",
            "is missing: define at least one [[fluid_block]]",
        )?;
        let mut blocks = Vec::new();
        for (k, b) in f.fluid_block.iter().enumerate() {
            let key = format!("fluid_block[{k}]");
            let fluid = f
                .fluid
                .iter()
                .position(|fl| fl.name == b.fluid)
                .ok_or_else(|| {
                    let names: Vec<_> = f
                        .fluid
                        .iter()
                        .map(|fl| format!("\"{}\"", fl.name))
                        .collect();
                    self.error(
                        &format!("{key}.fluid"),
                        format!(
                            "= \"{}\" names no [[fluid]]; defined fluids: {}",
                            b.fluid,
                            names.join(", ")
                        ),
                    )
                })?;
            let block = match (&b.mesh, &b.min, &b.max) {
                (None, Some(min), Some(max)) => {
                    self.check(
                        b.offset.is_none(),
                        &format!("{key}.offset"),
                        "is for a block from a `mesh`",
                    )?;
                    let section = BoxSection {
                        min: min.clone(),
                        max: max.clone(),
                    };
                    let region =
                        self.region_inside(&section, &container, dims, &key, s.spacing, "block")?;
                    Block {
                        fluid,
                        region,
                        mesh: None,
                    }
                }
                (Some(file), None, None) => {
                    self.check(dims == 3, &format!("{key}.mesh"), "is for 3D scenes")?;
                    let mesh = self.mesh(file, b.offset.as_ref(), &key, s.spacing)?;
                    let region = mesh.bounds().clone();
                    self.check(
                        region.within(&container),
                        &format!("{key}.mesh"),
                        format!(
                            "= \"{file}\" spans {:?} .. {:?}, which is not inside the container {:?} .. {:?}",
                            region.min, region.max, container.min, container.max
                        ),
                    )?;
                    Block {
                        fluid,
                        region,
                        mesh: Some(mesh),
                    }
                }
                _ => {
                    return Err(self.error(
                        &key,
                        "needs either `min` and `max` (a box) or `mesh` (a closed triangle mesh), not both",
                    ))
                }
            };
            blocks.push(block);
        }
        let mut obstacles = Vec::new();
        for (k, o) in f.obstacle.iter().enumerate() {
            let key = format!("obstacle[{k}]");
            let region = self.region_inside(o, &container, dims, &key, s.spacing, "obstacle")?;
            obstacles.push(region);
        }

        let initial_velocity = f
            .initial_velocity
            .as_ref()
            .map(|v| self.initial_velocity(v, &container, &periodic))
            .transpose()?;
        let checkpoint = self.checkpoint(&f.checkpoint)?;
        let effects = self.effects(&f.effects)?;
        let surface = f
            .output
            .surface
            .as_ref()
            .map(|s| self.surface(s))
            .transpose()?;
        let probes = self.probes(&f.probe, &container)?;
        let container_motion = f
            .container
            .trajectory
            .as_ref()
            .map(|t| {
                let centre: Vec<f64> = (0..dims)
                    .map(|d| 0.5 * (container.min[d] + container.max[d]))
                    .collect();
                self.trajectory(t, "container.trajectory", dims, &centre, s.end_time)
            })
            .transpose()?;
        self.check(
            container_motion.is_none() || !periodic.contains(&true),
            "container.trajectory",
            "is for a closed container: a periodic one cannot move (its frame's forces would not be periodic)",
        )?;
        let bodies = self.bodies(&f.body, &container, &obstacles, s)?;
        if periodic.contains(&true) {
            // A held body stays inside the box; a free one could cross the period, and a
            // body's particles are not wrapped.
            if let Some(k) = bodies
                .iter()
                .position(|b| b.motion == BodyMotion::Free || b.release.is_some())
            {
                return Err(self.error(
                    &format!("body[{k}].motion"),
                    "is free (or `release` lets it go) in a periodic container: only bodies held for the whole run, \"fixed\" or \"prescribed\" without `release`, may be in one (a free body crossing the period is not supported); close the container or hold the body",
                ));
            }
        }

        let name = match &s.name {
            Some(n) => {
                // The run goes to out/<name>: one plain directory name, not a path.
                let plain = !n.is_empty()
                    && n != "."
                    && n != ".."
                    && !n.contains(['/', '\\'])
                    && n.trim() == n;
                self.check(
                    plain,
                    "simulation.name",
                    format!("= \"{n}\" must be a plain directory name (the run goes to out/<name>): not empty, no '/', not \".\" or \"..\", no surrounding spaces"),
                )?;
                n.clone()
            }
            None => self
                .path
                .file_stem()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_else(|| "scene".into()),
        };
        let scene = Scene {
            path: self.path.to_owned(),
            text: self.text.to_owned(),
            name,
            dimensions: dims,
            spacing: s.spacing,
            perturbation: s
                .perturbation
                .unwrap_or_else(|| default_perturbation(&s.gravity, container_motion.is_some())),
            end_time: s.end_time,
            output_interval: s.output_interval,
            gravity: s.gravity.clone(),
            fluids: f.fluid,
            blocks,
            container,
            periodic,
            obstacles,
            container_motion,
            initial_velocity,
            solver,
            checkpoint,
            effects,
            walls: f.walls,
            surface,
            probes,
            bodies,
        };
        self.fits_in_memory(&scene)?;
        Ok(scene)
    }

    /// Refuses a scene whose particles could not be held: more than the u32 indices of the
    /// cell sort reach, or more memory at the peak of a run than the machine has in all (not
    /// what is free now: a study measures its finished points while others run).
    fn fits_in_memory(&self, scene: &Scene) -> Result<(), SceneError> {
        let (particles, points) = (scene.particle_bound(), scene.container_points());
        self.memory_holds(
            "simulation.spacing",
            &format!(
                "= {:?} puts up to {particles:.3e} particles and {points:.3e} lattice points in the container and its walls",
                scene.spacing
            ),
            particles,
            points,
        )
    }

    /// Refuses `particles` particles over a container of `points` lattice points (`what` says
    /// where they come from, `key` names the key): more than u32 indices reach, or more memory
    /// than the machine has in all, at `PEAK_BYTES_PER_PARTICLE` per particle and
    /// `BYTES_PER_CONTAINER_POINT` per lattice point of the container.
    fn memory_holds(
        &self,
        key: &str,
        what: &str,
        particles: f64,
        points: f64,
    ) -> Result<(), SceneError> {
        self.check(
            particles.max(points) < u32::MAX as f64,
            key,
            format!("{what}, more than the {} isph can index", u32::MAX),
        )?;
        let needed = particles * PEAK_BYTES_PER_PARTICLE + points * BYTES_PER_CONTAINER_POINT;
        // The machine's memory in all (MemTotal); no check where /proc/meminfo cannot be read.
        if let Ok(memory) = crate::math::memory::proc_bytes("/proc/meminfo", "MemTotal") {
            let memory = memory as f64;
            const GIB: f64 = (1u64 << 30) as f64;
            let container = if points > 0.0 {
                format!(" and {BYTES_PER_CONTAINER_POINT} B per lattice point of the container")
            } else {
                String::new()
            };
            self.check(
                needed <= memory,
                key,
                format!(
                    "{what}: about {:.1} GiB at {PEAK_BYTES_PER_PARTICLE} B per particle{container}, more than the {:.1} GiB of memory this machine has",
                    needed / GIB,
                    memory / GIB
                ),
            )?;
        }
        Ok(())
    }

    /// `[solver]`: each key in its range, the ones left out at their defaults (h/dx the
    /// kernel's).
    fn solver(&self, sv: &SolverSection) -> Result<SolverSettings, SceneError> {
        let defaults = SolverSettings::default();
        let kernel = match &sv.kernel {
            None => defaults.kernel,
            Some(name) => KernelKind::from_name(name).ok_or_else(|| {
                self.error(
                    "solver.kernel",
                    format!(
                        "= \"{name}\" is not a kernel: one of {}",
                        KernelKind::NAMES.join(", ")
                    ),
                )
            })?,
        };
        let solver = SolverSettings {
            tolerance: sv.tolerance.unwrap_or(defaults.tolerance),
            max_iterations: sv.max_iterations.unwrap_or(defaults.max_iterations),
            alpha: sv.alpha.unwrap_or(defaults.alpha),
            cfl: sv.cfl.unwrap_or(defaults.cfl),
            kernel,
            h_over_dx: sv.h_over_dx.unwrap_or(kernel.default_h_over_dx()),
        };
        let sv = &solver;
        self.check(
            sv.tolerance > 0.0 && sv.tolerance < 1.0,
            "solver.tolerance",
            format!("= {:?} must lie in (0, 1)", sv.tolerance),
        )?;
        self.check(
            sv.max_iterations >= 1,
            "solver.max_iterations",
            "must be at least 1",
        )?;
        self.check(
            (0.0..=1.0).contains(&sv.alpha),
            "solver.alpha",
            format!(
                "= {:?} must lie in [0, 1] (0: divergence-free only, 1: density-invariant only)",
                sv.alpha
            ),
        )?;
        self.check(
            sv.cfl > 0.0 && sv.cfl <= 1.0,
            "solver.cfl",
            format!("= {:?} must lie in (0, 1]", sv.cfl),
        )?;
        let range = kernel.h_over_dx_range();
        self.check(
            range.contains(&sv.h_over_dx),
            "solver.h_over_dx",
            format!(
                "= {:?} must lie in [{:?}, {:?}] with the {} kernel",
                sv.h_over_dx,
                range.start(),
                range.end(),
                kernel.name()
            ),
        )?;
        Ok(solver)
    }

    /// `container.periodic`: one flag per axis. A periodic axis must hold a whole number of
    /// particle spacings (the lattice must close on itself) and at least three kernel supports
    /// (so that a particle never meets two images of another).
    fn periodic(
        &self,
        flags: Option<&[bool]>,
        container: &Aabb,
        spacing: f64,
        solver: &SolverSettings,
    ) -> Result<Vec<bool>, SceneError> {
        let dims = container.min.len();
        let Some(flags) = flags else {
            return Ok(vec![false; dims]);
        };
        let key = "container.periodic";
        self.check(
            flags.len() == dims,
            key,
            format!(
                "has {} flags but the scene has `simulation.dimensions = {dims}`",
                flags.len()
            ),
        )?;
        let support = solver.support_in_dx() * spacing;
        for d in (0..dims).filter(|&d| flags[d]) {
            let length = container.max[d] - container.min[d];
            let spacings = length / spacing;
            self.check(
                (spacings - spacings.round()).abs() < 1e-6 * spacings,
                key,
                format!("axis {d} is periodic, so its length {length:?} m must be a whole number of spacings ({spacing:?} m); it is {spacings:.4} spacings"),
            )?;
            // Above three supports by more than rounding: the cell list divides the period
            // into cells of a third or a quarter of a support and needs three supports' worth.
            self.check(
                length >= 3.0 * support * (1.0 + 1e-9),
                key,
                format!("axis {d} is periodic, so its length {length:?} m must be longer than three kernel supports (3 × {support:?} m): lengthen the axis or lower `solver.h_over_dx`"),
            )?;
        }
        Ok(flags.to_vec())
    }

    /// `[initial_velocity]`: a named analytic field and its amplitude.
    fn initial_velocity(
        &self,
        v: &InitialVelocitySection,
        container: &Aabb,
        periodic: &[bool],
    ) -> Result<InitialVelocity, SceneError> {
        self.check(
            v.field == "taylor_green",
            "initial_velocity.field",
            format!(
                "= \"{}\" is not a known field; known: \"taylor_green\"",
                v.field
            ),
        )?;
        let lengths: Vec<f64> = (0..container.min.len())
            .map(|d| container.max[d] - container.min[d])
            .collect();
        self.check(
            lengths.len() == 2
                && periodic.iter().all(|&p| p)
                && (lengths[0] - lengths[1]).abs() <= 1e-9 * lengths[0],
            "initial_velocity.field",
            "= \"taylor_green\" needs a 2D container periodic in both axes (`container.periodic = [true, true]`) and square",
        )?;
        self.check(
            v.amplitude.is_finite(),
            "initial_velocity.amplitude",
            format!("= {:?} must be a finite number [m/s]", v.amplitude),
        )?;
        Ok(InitialVelocity::TaylorGreen {
            amplitude: v.amplitude,
        })
    }

    fn effects(&self, e: &EffectsSection) -> Result<Effects, SceneError> {
        Ok(Effects {
            shifting: self.shifting(&e.shifting)?,
            les: self.les(&e.les)?,
            kernel_correction: e.kernel_correction.enabled.unwrap_or(true),
        })
    }

    /// Whether effect `name` is on (`enabled`, default true); an effect turned off must not be
    /// given parameters, which it would silently ignore: `given` lists them (key, present).
    fn enabled(
        &self,
        name: &str,
        enabled: Option<bool>,
        given: &[(&str, bool)],
    ) -> Result<bool, SceneError> {
        let on = enabled.unwrap_or(true);
        if !on {
            if let Some((key, _)) = given.iter().find(|(_, present)| *present) {
                return Err(self.error(
                    &format!("effects.{name}.{key}"),
                    format!("is given but `effects.{name}.enabled = false` turns the effect off: remove the key or the `enabled = false`"),
                ));
            }
        }
        Ok(on)
    }

    fn shifting(&self, s: &ShiftingSection) -> Result<Option<ShiftingSettings>, SceneError> {
        let given = [
            ("coefficient", s.coefficient.is_some()),
            ("max_shift", s.max_shift.is_some()),
            ("clustering_weight", s.clustering_weight.is_some()),
        ];
        if !self.enabled("shifting", s.enabled, &given)? {
            return Ok(None);
        }
        let default = ShiftingSettings::default();
        let settings = ShiftingSettings {
            coefficient: s.coefficient.unwrap_or(default.coefficient),
            max_shift: s.max_shift.unwrap_or(default.max_shift),
            clustering_weight: s.clustering_weight.unwrap_or(default.clustering_weight),
        };
        self.check(
            settings.coefficient.is_finite() && settings.coefficient > 0.0,
            "effects.shifting.coefficient",
            format!(
                "= {:?} must be a positive number (A of D = A h U Δt)",
                settings.coefficient
            ),
        )?;
        self.check(
            settings.max_shift > 0.0 && settings.max_shift <= 1.0,
            "effects.shifting.max_shift",
            format!(
                "= {:?} must lie in (0, 1] [particle spacings]",
                settings.max_shift
            ),
        )?;
        self.check(
            settings.clustering_weight.is_finite() && settings.clustering_weight >= 0.0,
            "effects.shifting.clustering_weight",
            format!(
                "= {:?} must be a non-negative number",
                settings.clustering_weight
            ),
        )?;
        Ok(Some(settings))
    }

    fn les(&self, l: &LesSection) -> Result<Option<LesSettings>, SceneError> {
        let given = [
            ("cs", l.cs.is_some()),
            ("wall_function", l.wall_function.is_some()),
        ];
        if !self.enabled("les", l.enabled, &given)? {
            return Ok(None);
        }
        let default = LesSettings::default();
        let settings = LesSettings {
            cs: l.cs.unwrap_or(default.cs),
            wall_function: l.wall_function.unwrap_or(default.wall_function),
        };
        self.check(
            settings.cs > 0.0 && settings.cs <= 1.0,
            "effects.les.cs",
            format!(
                "= {:?} must lie in (0, 1] (to turn LES off, set `effects.les.enabled = false`)",
                settings.cs
            ),
        )?;
        Ok(Some(settings))
    }

    fn surface(&self, s: &SurfaceSection) -> Result<SurfaceSettings, SceneError> {
        let request = SurfaceRequest {
            kernel: s.kernel.clone(),
            radius: s.radius,
            cube_size: s.cube_size,
            max_cubes: s.max_cubes,
            iso: s.iso,
            obj: s.obj,
        };
        request
            .settings()
            .map_err(|(key, message)| self.error(&format!("output.surface.{key}"), message))
    }

    /// `[[probe]]`: each a point inside the container (its faces included: a wall sensor sits on
    /// the face), a known field, and a name that makes columns of its own in `probes.csv`.
    fn probes(
        &self,
        sections: &[ProbeSection],
        container: &Aabb,
    ) -> Result<Vec<Probe>, SceneError> {
        let dims = container.min.len();
        let mut probes: Vec<Probe> = Vec::new();
        for (k, section) in sections.iter().enumerate() {
            let key = format!("probe[{k}]");
            let name = section
                .name
                .clone()
                .unwrap_or_else(|| format!("probe_{}", k + 1));
            let plain = !name.is_empty()
                && name != "time"
                && !name.contains(|c: char| {
                    c == ',' || c == '"' || c.is_whitespace() || c.is_control()
                });
            self.check(
                plain,
                &format!("{key}.name"),
                format!("= \"{name}\" must be a plain column name for probes.csv: not empty, not \"time\", no comma, quote or space"),
            )?;
            let point_key = format!("{key}.point");
            self.vector(&section.point, dims, &point_key)?;
            let inside = (0..dims)
                .all(|d| (container.min[d]..=container.max[d]).contains(&section.point[d]));
            self.check(
                inside,
                &point_key,
                format!(
                    "= {:?} is not inside the container {:?} .. {:?} (a wall sensor sits on the container's face)",
                    section.point, container.min, container.max
                ),
            )?;
            let field = ProbeField::from_name(&section.field).ok_or_else(|| {
                self.error(
                    &format!("{key}.field"),
                    format!(
                        "= \"{}\" is not a field a probe records: one of {}",
                        section.field,
                        ProbeField::NAMES.map(|n| format!("\"{n}\"")).join(", ")
                    ),
                )
            })?;
            let probe = Probe {
                name,
                point: section.point.clone(),
                field,
            };
            let taken: Vec<String> = probes.iter().flat_map(Probe::columns).collect();
            let clash = probe.columns().into_iter().find(|c| taken.contains(c));
            self.check(
                clash.is_none(),
                &format!("{key}.name"),
                format!(
                    "= \"{}\" gives the column `{}` of probes.csv, which an earlier [[probe]] already has: give each probe its own name",
                    probe.name,
                    clash.unwrap_or_default()
                ),
            )?;
            probes.push(probe);
        }
        Ok(probes)
    }

    /// `[[body]]`: each a known shape with the keys it needs and no others, inside the
    /// container, holding particles, clear of the obstacles and of the other bodies, with a
    /// positive density or mass, a known motion.
    fn bodies(
        &self,
        sections: &[BodySection],
        container: &Aabb,
        obstacles: &[Aabb],
        s: &SimulationSection,
    ) -> Result<Vec<Body>, SceneError> {
        let dims = container.min.len();
        let mut bodies: Vec<Body> = Vec::new();
        for (k, b) in sections.iter().enumerate() {
            let key = format!("body[{k}]");
            let name = b.name.clone().unwrap_or_else(|| format!("body_{}", k + 1));
            let plain = !name.is_empty()
                && !name.contains(|c: char| {
                    c == ',' || c == '"' || c.is_whitespace() || c.is_control()
                });
            self.check(
                plain,
                &format!("{key}.name"),
                format!("= \"{name}\" must be a plain name for bodies.csv: not empty, no comma, quote or space"),
            )?;
            self.check(
                bodies.iter().all(|o| o.name != name),
                &format!("{key}.name"),
                format!("= \"{name}\" is the name of an earlier [[body]]: give each body its own"),
            )?;
            let shape = self.body_shape(b, &key, dims, s.spacing)?;
            let bounds = shape.bounds();
            self.check(
                bounds.within(container),
                &format!("{key}.shape"),
                format!(
                    "the {} spans {:?} .. {:?}, which is not inside the container {:?} .. {:?}",
                    shape.name(dims),
                    bounds.min,
                    bounds.max,
                    container.min,
                    container.max
                ),
            )?;
            let points = bounds.lattice_points_bound(s.spacing, |_| 0.0);
            self.memory_holds(
                &format!("{key}.shape"),
                &format!(
                    "the {} spans up to {points:.3e} lattice points of the spacing {:?} m",
                    shape.name(dims),
                    s.spacing
                ),
                points,
                0.0,
            )?;
            let lattice = lattice_points_in(&bounds, container, s.spacing);
            // The body's particles at t = 0: its lattice points, found once for every check.
            let particles: Vec<&Vec<f64>> = lattice.iter().filter(|x| shape.contains(x)).collect();
            self.check(
                !particles.is_empty(),
                &format!("{key}.shape"),
                format!(
                    "the {} holds no lattice point of the spacing {:?} m: make it larger than a spacing",
                    shape.name(dims),
                    s.spacing
                ),
            )?;
            if let Shape::Union(parts) = &shape {
                // A part that holds no lattice point adds nothing to the body.
                for (m, part) in parts.iter().enumerate() {
                    self.check(
                        lattice.iter().any(|x| part.contains(x)),
                        &format!("{key}.part[{m}].shape"),
                        format!(
                            "the {} holds no lattice point of the spacing {:?} m and adds nothing to the union: make it larger than a spacing, or leave it out",
                            part.name(dims),
                            s.spacing
                        ),
                    )?;
                }
            }
            if let Some(o) = obstacles.iter().position(|o| {
                particles
                    .iter()
                    .any(|x| o.contains_within(x, 0.5 * s.spacing))
            }) {
                return Err(self.error(
                    &format!("{key}.shape"),
                    format!("the {} overlaps obstacle[{o}] at t = 0: bodies start clear of the obstacles", shape.name(dims)),
                ));
            }
            if let Some(o) = bodies
                .iter()
                .position(|o| particles.iter().any(|x| o.shape.contains(x)))
            {
                return Err(self.error(
                    &format!("{key}.shape"),
                    format!(
                        "the {} overlaps body[{o}] (\"{}\") at t = 0: bodies start apart",
                        shape.name(dims),
                        bodies[o].name
                    ),
                ));
            }
            let mass = match (b.density, b.mass) {
                (Some(density), None) => {
                    self.positive(density, &format!("{key}.density"), "kg/m^3")?;
                    BodyMass::Density(density)
                }
                (None, Some(mass)) => {
                    self.positive(mass, &format!("{key}.mass"), "kg")?;
                    BodyMass::Total(mass)
                }
                (Some(_), Some(_)) => {
                    return Err(self.error(
                        &format!("{key}.mass"),
                        "and `density` are both given: give one of them",
                    ))
                }
                (None, None) => {
                    return Err(self.error(
                        &key,
                        "has neither `density` [kg/m^3] nor `mass` [kg]: give one of them",
                    ))
                }
            };
            let motion = self.body_motion(b, &key, dims, &shape, s)?;
            if let BodyMotion::Prescribed(trajectory) = &motion {
                let until = b.release.map_or(s.end_time, |r| r.min(s.end_time));
                self.prescribed_path_clear(
                    trajectory, &particles, &key, &shape, container, obstacles, s.spacing, until,
                )?;
            }
            let force = b.force.clone().unwrap_or(vec![0.0; dims]);
            self.vector(&force, dims, &format!("{key}.force"))?;
            let restitution = b.restitution.unwrap_or(0.0);
            self.check(
                (0.0..=1.0).contains(&restitution),
                &format!("{key}.restitution"),
                format!("= {restitution:?} must lie in [0, 1]"),
            )?;
            let friction = b.friction.unwrap_or(0.0);
            self.check(
                friction.is_finite() && friction >= 0.0,
                &format!("{key}.friction"),
                format!("= {friction:?} must be a coefficient ≥ 0"),
            )?;
            let velocity = b.velocity.clone().unwrap_or(vec![0.0; dims]);
            self.vector(&velocity, dims, &format!("{key}.velocity"))?;
            let turns = if dims == 2 { 1 } else { 3 };
            let angular_velocity = b.angular_velocity.clone().unwrap_or(vec![0.0; turns]);
            let spin_key = format!("{key}.angular_velocity");
            self.check(
                angular_velocity.len() == turns,
                &spin_key,
                format!(
                    "has {} components; a {dims}D body takes {turns} (about z in 2D) [rad/s]",
                    angular_velocity.len()
                ),
            )?;
            self.vector(&angular_velocity, turns, &spin_key)?;
            self.check(
                motion == BodyMotion::Free
                    || (velocity.iter().chain(&angular_velocity).all(|v| *v == 0.0)),
                &format!("{key}.velocity"),
                "and `angular_velocity` are for a free body: a fixed or prescribed body starts as its motion says",
            )?;
            if let Some(release) = b.release {
                let release_key = format!("{key}.release");
                self.check(
                    motion != BodyMotion::Free,
                    &release_key,
                    "is for a fixed or prescribed body (the time it is let go): a free body is free from the start",
                )?;
                self.check(
                    release.is_finite() && release >= 0.0,
                    &release_key,
                    format!("= {release:?} must be a time ≥ 0 [s]"),
                )?;
            }
            bodies.push(Body {
                name,
                shape,
                mass,
                motion,
                release: b.release,
                force,
                restitution,
                friction,
                velocity,
                angular_velocity,
            });
        }
        Ok(bodies)
    }

    /// Refuses a prescribed body's trajectory that takes one of its `particles` (its lattice
    /// points at t = 0) out of the container or within half a spacing of an obstacle before
    /// `until`: neither yields to it. Sampled at `PATH_SAMPLES` times and every table row.
    #[allow(clippy::too_many_arguments)]
    fn prescribed_path_clear(
        &self,
        trajectory: &crate::scene::trajectory::Trajectory,
        particles: &[&Vec<f64>],
        key: &str,
        shape: &Shape,
        container: &Aabb,
        obstacles: &[Aabb],
        spacing: f64,
        until: f64,
    ) -> Result<(), SceneError> {
        let dims = container.min.len();
        let rows = match &trajectory.path {
            crate::scene::trajectory::Path::Table { rows, .. } => {
                rows.iter().map(|r| r.time).collect()
            }
            crate::scene::trajectory::Path::Sinusoid { .. } => Vec::new(),
        };
        let samples = (0..=PATH_SAMPLES).map(|j| until * j as f64 / PATH_SAMPLES as f64);
        let mut times: Vec<f64> = samples
            .chain(rows.into_iter().filter(|&t| (0.0..=until).contains(&t)))
            .collect();
        times.sort_by(f64::total_cmp);
        let margin = 0.5 * spacing * (1.0 - 1e-9);
        let key = format!("{key}.trajectory");
        for t in times {
            let placement = trajectory.placement(&trajectory.at(t));
            for x in particles {
                let at =
                    placement.place(std::array::from_fn(|d| if d < dims { x[d] } else { 0.0 }));
                let at = &at[..dims];
                let inside = (0..dims).all(|d| {
                    at[d] >= container.min[d] + margin && at[d] <= container.max[d] - margin
                });
                if !inside {
                    return Err(self.error(
                        &key,
                        format!("takes the {} out of the container at t = {t:?} s (a particle to {at:?}): the container's walls do not yield to a prescribed body", shape.name(dims)),
                    ));
                }
                if let Some(o) = obstacles.iter().position(|o| o.contains_within(at, margin)) {
                    return Err(self.error(
                        &key,
                        format!("takes the {} into obstacle[{o}] at t = {t:?} s (a particle to {at:?}): an obstacle does not yield to a prescribed body", shape.name(dims)),
                    ));
                }
            }
        }
        Ok(())
    }

    /// The motion of `[[body]]` section `b` with `shape`: a known name, and a trajectory for a
    /// prescribed body only (its pivot the shape's centre unless given).
    fn body_motion(
        &self,
        b: &BodySection,
        key: &str,
        dims: usize,
        shape: &Shape,
        s: &SimulationSection,
    ) -> Result<BodyMotion, SceneError> {
        let name = b.motion.as_deref().unwrap_or("free");
        let unknown = || {
            self.error(
                &format!("{key}.motion"),
                format!(
                    "= \"{name}\" is not a motion: one of {}",
                    BodyMotion::NAMES.map(|n| format!("\"{n}\"")).join(", ")
                ),
            )
        };
        match (name, &b.trajectory) {
            ("free", None) => Ok(BodyMotion::Free),
            ("fixed", None) => Ok(BodyMotion::Fixed),
            ("prescribed", Some(t)) => {
                let bounds = shape.bounds();
                let centre: Vec<f64> = (0..dims)
                    .map(|d| 0.5 * (bounds.min[d] + bounds.max[d]))
                    .collect();
                let key = format!("{key}.trajectory");
                Ok(BodyMotion::Prescribed(
                    self.trajectory(t, &key, dims, &centre, s.end_time)?,
                ))
            }
            ("prescribed", None) => Err(self.error(
                key,
                "has `motion = \"prescribed\"` but no [body.trajectory]: give its `period` (a sinusoid) or `table`",
            )),
            ("free" | "fixed", Some(_)) => Err(self.error(
                &format!("{key}.trajectory"),
                format!("is for a prescribed body: this one is `{name}`; set `motion = \"prescribed\"` or leave the trajectory out"),
            )),
            _ => Err(unknown()),
        }
    }

    /// The shape of `[[body]]` section `b`: its own (`shape`), or with `shape = "union"` the
    /// union of its `[[body.part]]`s, each a shape of its own keys and none a union.
    fn body_shape(
        &self,
        b: &BodySection,
        key: &str,
        dims: usize,
        spacing: f64,
    ) -> Result<Shape, SceneError> {
        let keys = b.shape_keys();
        if b.shape != "union" {
            self.check(
                b.part.is_none(),
                &format!("{key}.part"),
                format!("is for a union: this body is a {}; set `shape = \"union\"` or leave the parts out", b.shape),
            )?;
            return self.shape(&keys, key, dims, spacing, false);
        }
        let offset = ("offset", keys.offset.is_some());
        for (name, present) in shape_keys_given(&keys).into_iter().chain([offset]) {
            self.check(
                !present,
                &format!("{key}.{name}"),
                "is not a key of a union: each [[body.part]] takes its own shape's keys",
            )?;
        }
        let parts = b.part.as_deref().unwrap_or_default();
        self.check(
            parts.len() >= 2,
            &format!("{key}.part"),
            format!(
                "has {} [[body.part]]: a union joins two shapes or more",
                parts.len()
            ),
        )?;
        let shapes = parts
            .iter()
            .enumerate()
            .map(|(m, part)| self.shape(part, &format!("{key}.part[{m}]"), dims, spacing, true))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Shape::Union(shapes))
    }

    /// The shape of section `b`, a body's own or (`part`) a union's part: its `shape` known in
    /// `dims` dimensions, the keys it needs given and valid, the keys of other shapes absent. A
    /// body may also be a union (`body_shape` builds it), a part not: the message says which.
    fn shape(
        &self,
        b: &ShapeSection,
        key: &str,
        dims: usize,
        spacing: f64,
        part: bool,
    ) -> Result<Shape, SceneError> {
        let shapes: &[&str] = if dims == 2 {
            &["box", "circle"]
        } else {
            &["box", "sphere", "cylinder", "mesh"]
        };
        self.check(
            shapes.contains(&b.shape.as_str()),
            &format!("{key}.shape"),
            format!(
                "= \"{}\" is not a shape {} {dims}D scene: one of {}",
                b.shape,
                if part {
                    "a union's part takes in a"
                } else {
                    "of a"
                },
                shapes
                    .iter()
                    .chain(if part { &[][..] } else { &["union"][..] })
                    .map(|n| format!("\"{n}\""))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        )?;
        let given = shape_keys_given(b);
        let needs: &[&str] = match b.shape.as_str() {
            "box" => &["min", "max"],
            "cylinder" => &["center", "radius", "axis", "length"],
            "mesh" => &["mesh"],
            _ => &["center", "radius"],
        };
        self.check(
            b.offset.is_none() || b.shape == "mesh",
            &format!("{key}.offset"),
            format!("is not a key of a {}: it moves a mesh", b.shape),
        )?;
        for (name, present) in given {
            let needed = needs.contains(&name);
            self.check(
                present == needed,
                &format!("{key}.{name}"),
                if needed {
                    format!("is missing: a {} needs {}", b.shape, needs.join(", "))
                } else {
                    format!(
                        "is not a key of a {}: it takes {}",
                        b.shape,
                        needs.join(", ")
                    )
                },
            )?;
        }
        let vector = |v: &Option<Vec<f64>>, name: &str| -> Result<Vec<f64>, SceneError> {
            let v = v.clone().unwrap_or_default();
            self.vector(&v, dims, &format!("{key}.{name}"))?;
            Ok(v)
        };
        let positive = |v: Option<f64>, name: &str| -> Result<f64, SceneError> {
            let v = v.unwrap_or_default();
            self.positive(v, &format!("{key}.{name}"), "m")?;
            Ok(v)
        };
        Ok(match b.shape.as_str() {
            "box" => {
                let section = BoxSection {
                    min: vector(&b.min, "min")?,
                    max: vector(&b.max, "max")?,
                };
                let region = self.aabb(&section, dims, key, spacing)?;
                Shape::Box {
                    min: region.min,
                    max: region.max,
                }
            }
            "cylinder" => {
                let axis_name = b.axis.as_deref().unwrap_or_default();
                let axis = ["x", "y", "z"]
                    .iter()
                    .position(|a| *a == axis_name)
                    .ok_or_else(|| {
                        self.error(
                            &format!("{key}.axis"),
                            format!("= \"{axis_name}\" is not an axis: one of \"x\", \"y\", \"z\""),
                        )
                    })?;
                Shape::Cylinder {
                    center: vector(&b.center, "center")?,
                    radius: positive(b.radius, "radius")?,
                    axis,
                    length: positive(b.length, "length")?,
                }
            }
            "mesh" => Shape::Mesh(self.mesh(
                b.mesh.as_deref().unwrap_or_default(),
                b.offset.as_ref(),
                key,
                spacing,
            )?),
            _ => Shape::Ball {
                center: vector(&b.center, "center")?,
                radius: positive(b.radius, "radius")?,
            },
        })
    }

    /// The mesh of section `key` (a `shape = "mesh"` body, a fluid block): its `file` (relative
    /// to the scene file's folder) read, closed, moved by `offset`.
    fn mesh(
        &self,
        file: &str,
        offset: Option<&Vec<f64>>,
        key: &str,
        spacing: f64,
    ) -> Result<TriangleMesh, SceneError> {
        let mesh_key = format!("{key}.mesh");
        let path = self.path.parent().unwrap_or(Path::new(".")).join(file);
        let mesh = mesh_file::read(&path).map_err(|message| {
            self.error(
                &mesh_key,
                format!("= \"{file}\": {} {message}", path.display()),
            )
        })?;
        let open = mesh.open_edges();
        self.check(
            open == 0,
            &mesh_key,
            format!("= \"{file}\" is not closed: {open} of its edges do not join exactly two triangles (a body's inside must be bounded)"),
        )?;
        let offset = offset.cloned().unwrap_or(vec![0.0; 3]);
        self.vector(&offset, 3, &format!("{key}.offset"))?;
        let mesh = mesh.moved(&offset);
        let bounds = mesh.bounds();
        self.check(
            (0..3).all(|d| bounds.max[d] - bounds.min[d] >= spacing),
            &mesh_key,
            format!("= \"{file}\" spans {:?} .. {:?}: less than a spacing in some axis (are its units metres?)", bounds.min, bounds.max),
        )?;
        Ok(mesh)
    }

    fn checkpoint(&self, c: &CheckpointSection) -> Result<CheckpointSettings, SceneError> {
        let default = CheckpointSettings::default();
        if let Some(interval) = c.interval {
            self.positive(interval, "checkpoint.interval", "s")?;
        }
        let wall_interval = c.wall_interval.unwrap_or(default.wall_interval);
        self.positive(wall_interval, "checkpoint.wall_interval", "s")?;
        let keep = c.keep.unwrap_or(default.keep as i64);
        self.check(
            keep >= 1,
            "checkpoint.keep",
            format!("= {keep} must be at least 1 (the newest checkpoint is always kept)"),
        )?;
        Ok(CheckpointSettings {
            interval: c.interval,
            wall_interval,
            keep: keep as usize,
        })
    }
}

/// Each key that places a shape (besides `shape` and `offset`), and whether `b` gives it.
fn shape_keys_given(b: &ShapeSection) -> [(&'static str, bool); 7] {
    [
        ("min", b.min.is_some()),
        ("max", b.max.is_some()),
        ("center", b.center.is_some()),
        ("radius", b.radius.is_some()),
        ("axis", b.axis.is_some()),
        ("length", b.length.is_some()),
        ("mesh", b.mesh.is_some()),
    ]
}

/// The times, evenly over the run, at which a prescribed body's path is checked
/// (`prescribed_path_clear`), besides its table's rows.
const PATH_SAMPLES: usize = 1000;

/// The lattice points of the scene's particle lattice (`fill`: container.min + (k + ½) dx)
/// inside `bounds`.
fn lattice_points_in(bounds: &Aabb, container: &Aabb, spacing: f64) -> Vec<Vec<f64>> {
    let dims = bounds.min.len();
    let index = |d: usize, x: f64| ((x - container.min[d]) / spacing - 0.5).floor() as i64;
    let lo: Vec<i64> = (0..dims).map(|d| index(d, bounds.min[d])).collect();
    let hi: Vec<i64> = (0..dims).map(|d| index(d, bounds.max[d]) + 1).collect();
    let mut points = Vec::new();
    let mut k = lo.clone();
    'walk: loop {
        points.push(
            (0..dims)
                .map(|d| container.min[d] + (k[d] as f64 + 0.5) * spacing)
                .collect(),
        );
        for d in 0..dims {
            k[d] += 1;
            if k[d] <= hi[d] {
                continue 'walk;
            }
            k[d] = lo[d];
        }
        break;
    }
    points
}

/// 1-based line of a dotted key such as `fluid_block[1].fluid` in TOML source, if present.
fn line_of_key(text: &str, key: &str) -> Option<usize> {
    let doc = toml_edit::ImDocument::parse(text).ok()?;
    let mut item = doc.as_item();
    for part in key.split('.') {
        let (name, index) = match part.split_once('[') {
            Some((n, rest)) => (n, rest.trim_end_matches(']').parse::<usize>().ok()),
            None => (part, None),
        };
        item = item.get(name)?;
        if let Some(k) = index {
            item = item.get(k)?;
        }
    }
    let span = item.span()?;
    Some(text[..span.start].matches('\n').count() + 1)
}

/// `simulation.perturbation` when the scene gives none. Without a body force a perturbed fluid
/// at rest stays at rest (the density correction's relaxation of the perturbed density moves
/// positions, never velocities, and no pressure gradient is there to be upset), and the
/// perturbation keeps a straining flow from breaking up its lattice at once. Under gravity or in
/// a moving container the same relaxation shifts the particles that hold the hydrostatic
/// pressure, and still water moves at about 1e-3 m/s at 0.05 dx where the lattice holds it to
/// 1e-6 m/s (docs/accuracy.md, "The start-up error of the Taylor–Green vortex").
fn default_perturbation(gravity: &[f64], moving_container: bool) -> f64 {
    let body_force = moving_container || gravity.iter().any(|&g| g != 0.0);
    if body_force {
        0.0
    } else {
        PERTURBATION_WITHOUT_BODY_FORCE
    }
}
