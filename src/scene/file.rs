//! The scene file as TOML sections (serde), unknown keys rejected; `validate` turns it into a
//! `Scene`.

use super::{Fluid, WallSettings};
use serde::Deserialize;

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct SceneFile {
    pub(super) simulation: SimulationSection,
    #[serde(default)]
    pub(super) fluid: Vec<Fluid>,
    #[serde(default)]
    pub(super) fluid_block: Vec<FluidBlock>,
    pub(super) container: ContainerSection,
    #[serde(default)]
    pub(super) obstacle: Vec<BoxSection>,
    pub(super) initial_velocity: Option<InitialVelocitySection>,
    #[serde(default)]
    pub(super) solver: SolverSection,
    #[serde(default)]
    pub(super) checkpoint: CheckpointSection,
    #[serde(default)]
    pub(super) effects: EffectsSection,
    #[serde(default)]
    pub(super) walls: WallSettings,
    #[serde(default)]
    pub(super) output: OutputSection,
    #[serde(default)]
    pub(super) probe: Vec<ProbeSection>,
    #[serde(default)]
    pub(super) body: Vec<BodySection>,
}

/// `[solver]` as written; `validate` fills what it leaves out from `SolverSettings::default`
/// and the kernel's h/dx.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct SolverSection {
    pub(super) tolerance: Option<f64>,
    pub(super) max_iterations: Option<usize>,
    pub(super) alpha: Option<f64>,
    pub(super) cfl: Option<f64>,
    pub(super) kernel: Option<String>,
    pub(super) h_over_dx: Option<f64>,
}

/// `[[body]]` as written: the keys of every shape and motion, each optional here; `validate`
/// asks for the ones the shape needs and refuses the others (docs/scene-format.md).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct BodySection {
    pub(super) name: Option<String>,
    pub(super) shape: String,
    pub(super) min: Option<Vec<f64>>,
    pub(super) max: Option<Vec<f64>>,
    pub(super) center: Option<Vec<f64>>,
    pub(super) radius: Option<f64>,
    pub(super) axis: Option<String>,
    pub(super) length: Option<f64>,
    pub(super) mesh: Option<String>,
    pub(super) offset: Option<Vec<f64>>,
    pub(super) density: Option<f64>,
    pub(super) mass: Option<f64>,
    pub(super) motion: Option<String>,
    pub(super) force: Option<Vec<f64>>,
    pub(super) restitution: Option<f64>,
    pub(super) friction: Option<f64>,
    pub(super) velocity: Option<Vec<f64>>,
    pub(super) angular_velocity: Option<Vec<f64>>,
    pub(super) trajectory: Option<TrajectorySection>,
    pub(super) release: Option<f64>,
    pub(super) part: Option<Vec<ShapeSection>>,
}

impl BodySection {
    /// The keys that place the body's own shape. They are repeated in `BodySection` rather than
    /// a `ShapeSection` flattened into it: serde does not refuse unknown keys through a flatten.
    pub(super) fn shape_keys(&self) -> ShapeSection {
        ShapeSection {
            shape: self.shape.clone(),
            min: self.min.clone(),
            max: self.max.clone(),
            center: self.center.clone(),
            radius: self.radius,
            axis: self.axis.clone(),
            length: self.length,
            mesh: self.mesh.clone(),
            offset: self.offset.clone(),
        }
    }
}

/// The keys that place a shape: a `[[body]]`'s own, or a `[[body.part]]` of a union.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ShapeSection {
    pub(super) shape: String,
    pub(super) min: Option<Vec<f64>>,
    pub(super) max: Option<Vec<f64>>,
    pub(super) center: Option<Vec<f64>>,
    pub(super) radius: Option<f64>,
    pub(super) axis: Option<String>,
    pub(super) length: Option<f64>,
    pub(super) mesh: Option<String>,
    pub(super) offset: Option<Vec<f64>>,
}

/// `[container.trajectory]` and `[body.trajectory]` as written: a sinusoid (`period`,
/// `amplitude`, `angle`) or a `table` file (docs/scene-format.md).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct TrajectorySection {
    pub(super) pivot: Option<Vec<f64>>,
    pub(super) axis: Option<Vec<f64>>,
    pub(super) period: Option<f64>,
    pub(super) amplitude: Option<Vec<f64>>,
    pub(super) angle: Option<f64>,
    pub(super) table: Option<String>,
}

/// `[[probe]]` as written (docs/scene-format.md).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ProbeSection {
    pub(super) name: Option<String>,
    pub(super) point: Vec<f64>,
    pub(super) field: String,
}

/// `[output]`: what a run writes besides the particles.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct OutputSection {
    pub(super) surface: Option<SurfaceSection>,
}

/// `[output.surface]`: every key optional (docs/scene-format.md).
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct SurfaceSection {
    pub(super) kernel: Option<String>,
    pub(super) radius: Option<f64>,
    pub(super) cube_size: Option<f64>,
    pub(super) max_cubes: Option<i64>,
    pub(super) iso: Option<f64>,
    pub(super) obj: Option<bool>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct SimulationSection {
    pub(super) name: Option<String>,
    pub(super) dimensions: i64,
    pub(super) spacing: f64,
    pub(super) end_time: f64,
    pub(super) output_interval: f64,
    pub(super) gravity: Vec<f64>,
    pub(super) perturbation: Option<f64>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct FluidBlock {
    pub(super) fluid: String,
    pub(super) min: Option<Vec<f64>>,
    pub(super) max: Option<Vec<f64>>,
    pub(super) mesh: Option<String>,
    pub(super) offset: Option<Vec<f64>>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct BoxSection {
    pub(super) min: Vec<f64>,
    pub(super) max: Vec<f64>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ContainerSection {
    pub(super) min: Vec<f64>,
    pub(super) max: Vec<f64>,
    pub(super) periodic: Option<Vec<bool>>,
    pub(super) trajectory: Option<TrajectorySection>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct InitialVelocitySection {
    pub(super) field: String,
    pub(super) amplitude: f64,
}

#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct CheckpointSection {
    pub(super) interval: Option<f64>,
    pub(super) wall_interval: Option<f64>,
    pub(super) keep: Option<i64>,
}

/// The `[effects]` section as written: each effect a sub-table, every key optional.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct EffectsSection {
    #[serde(default)]
    pub(super) shifting: ShiftingSection,
    #[serde(default)]
    pub(super) les: LesSection,
    #[serde(default)]
    pub(super) kernel_correction: KernelCorrectionSection,
}

#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ShiftingSection {
    pub(super) enabled: Option<bool>,
    pub(super) coefficient: Option<f64>,
    pub(super) max_shift: Option<f64>,
    pub(super) clustering_weight: Option<f64>,
}

#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct LesSection {
    pub(super) enabled: Option<bool>,
    pub(super) cs: Option<f64>,
    pub(super) wall_function: Option<bool>,
}

#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct KernelCorrectionSection {
    pub(super) enabled: Option<bool>,
}
