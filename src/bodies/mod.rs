//! Rigid bodies in the fluid, after Eq. (11)–(16): a body is a set of particles on the
//! particle lattice inside its shape, treated as fluid of the body's density by every stage up
//! to the corrector (so the pressure solve sees the body's inertia), then constrained to move
//! rigidly. The constraint keeps the momentum and the angular momentum the corrector gave the
//! body's particles: with m_i the particle masses, M = Σ m_i and r_ic the particle's offset from
//! the centre of mass,
//!
//!   M (Vⁿ⁺¹ − Vⁿ) = Σ m_i (u_i − u_i^rigid),                Eq. (14), as a momentum balance
//!   Lⁿ⁺¹ − Lⁿ     = Σ m_i r_ic × (u_i − u_i^rigid),          Eq. (15), angular momentum
//!   ωⁿ⁺¹ = R I⁻¹ Rᵀ Lⁿ⁺¹,  u_i = Vⁿ⁺¹ + ωⁿ⁺¹ × r_ic,          Eq. (16)
//!
//! with u_i the corrector's velocity of particle i, whose predictor carried the body's
//! external force over its mass with gravity (`step::body_forces`), and u_i^rigid its rigid
//! velocity at the start of the step (docs/bodies.md, "The coupling"). The paper's scalar I_O of Eq. (13) is the
//! polar moment, exact in 2D only; here I = Σ m_i (|r_ic|² 1 − r_ic ⊗ r_ic) in the body's own
//! frame, turned into the world's by the orientation, a unit quaternion. Angular momentum, not
//! an angle, is the integrated quantity, so a torque-free body keeps it to round-off. The state
//! is f64 and lasting (checkpointed); the particles' positions are set from it every step,
//! never advected, so a body never changes shape.

mod contact;
mod keep_out;

use crate::math::aabb::Aabb;
use crate::math::rotation::{self, cross, to_3d, Mat3, Quaternion, Vec3};
use crate::math::shape::Shape;
use crate::math::vector::dot;
use crate::particles::{Kind, Particles};
use crate::scene::{BodyMotion, Scene};

/// The lasting state of a rigid body.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RigidState {
    /// Centre of mass [m].
    pub centre: Vec3,
    /// Rotation from the body's own frame (the world's at t = 0) to the world's.
    pub orientation: Quaternion,
    /// Velocity of the centre of mass [m/s].
    pub velocity: Vec3,
    /// Angular momentum about the centre of mass, world frame [kg m²/s].
    pub angular_momentum: Vec3,
    /// The fluid's force [N] and torque [N m] on the body over the last step (pressure, the
    /// walls' ghost pressure included, and viscosity; without gravity, the external force and
    /// the contacts' impulses).
    pub force: Vec3,
    pub torque: Vec3,
    /// Whether a free body rests on the container's faces, the obstacles or a body that stands
    /// still: held still over the next step, as long as its contacts can hold it
    /// (`Bodies::resolve_contacts`).
    pub resting: bool,
    /// Whether the body moved freely over the last step in reach of the fluid or a wall: its
    /// `force` and `torque` are then the fluid's on it as it moves, from which the next step
    /// extrapolates (`Bodies::advance`).
    pub wet: bool,
}

impl RigidState {
    /// f64s of a state in a checkpoint: `resting` and `wet` are the last two, 1 or 0.
    pub const LEN: usize = 21;

    pub fn to_array(&self) -> [f64; Self::LEN] {
        let mut a = [0.0; Self::LEN];
        let parts: [&[f64]; 6] = [
            &self.centre,
            &self.orientation.0,
            &self.velocity,
            &self.angular_momentum,
            &self.force,
            &self.torque,
        ];
        let mut k = 0;
        for part in parts {
            a[k..k + part.len()].copy_from_slice(part);
            k += part.len();
        }
        a[k] = f64::from(u8::from(self.resting));
        a[k + 1] = f64::from(u8::from(self.wet));
        a
    }

    /// The state of `a`, one of `to_array` or one of the 20 or 19 f64s that checkpoints held
    /// before `wet` (not wet) and before `resting` (not resting).
    pub fn from_array(a: &[f64]) -> Self {
        let v = |k: usize| [a[k], a[k + 1], a[k + 2]];
        Self {
            centre: v(0),
            orientation: Quaternion([a[3], a[4], a[5], a[6]]),
            velocity: v(7),
            angular_momentum: v(10),
            force: v(13),
            torque: v(16),
            resting: a.get(19) == Some(&1.0),
            wet: a.get(20) == Some(&1.0),
        }
    }
}

/// One rigid body: what the scene and its particles at t = 0 fix, and its state.
#[derive(Clone, Debug)]
pub struct RigidBody {
    pub name: String,
    /// The shape where the body starts (its frame then the world's).
    pub shape: Shape,
    /// The centre of mass at t = 0: the origin of the offsets in the shape's coordinates.
    pub centre_at_start: Vec3,
    /// The largest distance of the shape's surface from the centre of mass (a bound for the
    /// contact's search).
    pub reach: f64,
    pub motion: BodyMotion,
    /// The time a fixed or prescribed body is let go (`scene::Body::release`).
    pub release: Option<f64>,
    /// M = Σ m_i [kg] (per metre of depth in 2D).
    pub mass: f64,
    /// Each of its particles' mass m_i and rest density ρ0_i = m_i/V_i when it moves freely
    /// (`Bodies::set_solve_densities`).
    pub particle_mass: f64,
    pub particle_density: f64,
    /// Inertia tensor about the centre of mass in the body's own frame [kg m²]; in 2D only
    /// the zz part, the polar moment of Eq. (13).
    pub inertia: Mat3,
    pub external_force: Vec3,
    pub restitution: f64,
    /// Coulomb friction coefficient of its contacts.
    pub friction: f64,
    /// The body's particles are those with ids first_id .. first_id + offsets.len().
    pub first_id: u64,
    /// Each particle's offset from the centre of mass in the body's own frame, by id − first_id.
    pub offsets: Vec<Vec3>,
    /// Each particle's depth below the body's surface and the surface's outward normal there,
    /// in the body's own frame, by id − first_id (`SurfacePoint`).
    pub surface: Vec<SurfacePoint>,
    pub state: RigidState,
}

/// Where a body particle lies under its body's surface: the fluid's no-slip at the body
/// (`step::body_surfaces`) puts the body's velocity on the surface itself, as at a wall.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfacePoint {
    /// Distance from the particle's centre to the surface [m] (> 0).
    pub depth: f64,
    /// The surface's outward unit normal nearest the particle, in the body's own frame; zero
    /// for a particle deeper than `SURFACE_REACH` spacings, which no fluid reaches.
    pub normal: Vec3,
}

/// Depth, in particle spacings, down to which a body particle keeps its surface normal: the
/// widest kernel support (the quintic at h/dx = 2 reaches 6 spacings).
const SURFACE_REACH: f64 = 6.0;

/// Where a fixed or prescribed body is taken by the end of a step: its pose and velocities.
#[derive(Clone, Copy, Debug)]
pub struct RigidTarget {
    pub centre: Vec3,
    pub orientation: Quaternion,
    pub velocity: Vec3,
    pub angular_velocity: Vec3,
}

impl RigidBody {
    /// How the body moves over the step from time t: as the scene says, or free once released.
    pub fn motion_at(&self, t: f64) -> &BodyMotion {
        match self.release {
            Some(release) if t >= release => &BodyMotion::Free,
            _ => &self.motion,
        }
    }

    /// Whether the body is held over the step from t: fixed, prescribed, or resting on its
    /// supports (`RigidState::resting`).
    pub fn is_held(&self, t: f64) -> bool {
        match self.motion_at(t) {
            BodyMotion::Free => self.state.resting,
            BodyMotion::Fixed | BodyMotion::Prescribed(_) => true,
        }
    }

    /// Whether the body's motion over the step from t is given, fixed or prescribed (held, and
    /// not resting): the fluid then sees its particles as the ghosts of a moving wall
    /// (`ppe::Role::Ghost`).
    pub fn is_driven(&self, t: f64) -> bool {
        matches!(
            self.motion_at(t),
            BodyMotion::Fixed | BodyMotion::Prescribed(_)
        )
    }

    /// The pose and velocities a held body (`is_held`) has at t + dt (None for a body that
    /// moves freely over the step): where its motion takes it, or for a resting body where it
    /// is, at rest.
    pub fn target(&self, t: f64, dt: f64) -> Option<RigidTarget> {
        match self.motion_at(t) {
            BodyMotion::Free if !self.state.resting => None,
            BodyMotion::Free | BodyMotion::Fixed => Some(RigidTarget {
                centre: self.state.centre,
                orientation: self.state.orientation,
                velocity: [0.0; 3],
                angular_velocity: [0.0; 3],
            }),
            BodyMotion::Prescribed(trajectory) => {
                // The pivot moves by X and the body turns by θ about it (`scene::trajectory`).
                let k = trajectory.at(t + dt);
                let placement = trajectory.placement(&k);
                let arm = placement.arm(self.centre_at_start);
                let angular_velocity = trajectory.axis.map(|e| e * k.angular_velocity);
                let turn = cross(angular_velocity, arm);
                Some(RigidTarget {
                    centre: std::array::from_fn(|d| placement.pivot[d] + arm[d]),
                    orientation: placement.orientation,
                    velocity: std::array::from_fn(|d| k.velocity[d] + turn[d]),
                    angular_velocity,
                })
            }
        }
    }

    /// The rotation matrix of the orientation.
    pub fn rotation(&self) -> Mat3 {
        self.state.orientation.matrix()
    }

    /// ω = R I⁻¹ Rᵀ L.
    pub fn angular_velocity(&self) -> Vec3 {
        let r = self.rotation();
        let inverse = rotation::inverse_on_span(&self.inertia);
        let body_l = rotation::apply_transposed(&r, self.state.angular_momentum);
        rotation::apply(&r, rotation::apply(&inverse, body_l))
    }

    /// The signed distance of a world point from the body's surface as it lies now (negative
    /// inside), in a `dims`-dimensional scene: its rotation built once for every point asked.
    pub fn surface_distance(&self, dims: usize) -> impl Fn(&Vec3) -> f64 + '_ {
        let r = self.rotation();
        move |x| {
            let arm: Vec3 = std::array::from_fn(|d| x[d] - self.state.centre[d]);
            let local = rotation::apply_transposed(&r, arm);
            let at_start: Vec3 = std::array::from_fn(|d| self.centre_at_start[d] + local[d]);
            self.shape.signed_distance(&at_start[..dims])
        }
    }

    /// Offset of particle `id` from the centre, in the world frame, for rotation `r`.
    pub fn arm(&self, r: &Mat3, id: u64) -> Vec3 {
        rotation::apply(r, self.offsets[(id - self.first_id) as usize])
    }

    /// Where particle `id` lies under the surface (in the body's own frame).
    pub fn surface_point(&self, id: u64) -> SurfacePoint {
        self.surface[(id - self.first_id) as usize]
    }

    /// The outward surface normal at particle `id` (`SurfacePoint`), in the world frame, for
    /// rotation `r`.
    pub fn normal(&self, r: &Mat3, id: u64) -> Vec3 {
        rotation::apply(r, self.surface[(id - self.first_id) as usize].normal)
    }

    /// Moves the pose over a step of `dt` over which the centre's velocity went from `start` to
    /// the state's and the angular velocity from `start_spin` to the state's: both by the
    /// trapezoid, the centre by (Vⁿ + Vⁿ⁺¹) Δt/2, exact under a constant force (free fall), and
    /// the orientation by a turn of (ωⁿ + ωⁿ⁺¹) Δt/2, exact under a constant torque (Eq. 15–16).
    /// So a frame holds a body's pose and velocities at one time, as it holds the fluid's
    /// (`Simulation::present_positions`).
    fn drift(&mut self, start: Vec3, start_spin: Vec3, dt: f64) {
        let s = &mut self.state;
        for d in 0..3 {
            s.centre[d] += 0.5 * dt * (start[d] + s.velocity[d]);
        }
        let w = self.angular_velocity();
        let turn: Vec3 = std::array::from_fn(|d| 0.5 * dt * (start_spin[d] + w[d]));
        self.state.orientation = Quaternion::from_rotation_vector(turn)
            .then_after(self.state.orientation)
            .normalised();
    }

    /// Its weight less the weight of the water (of density `water_density`) it displaces, in
    /// `gravity` [N].
    fn weight_in_water(&self, gravity: Vec3, water_density: f64) -> Vec3 {
        let buoyant = 1.0 - water_density / self.particle_density;
        gravity.map(|g| g * self.mass * buoyant)
    }

    /// The largest speed of a point of the body, |V| + |ω| times its reach [m/s].
    fn largest_speed(&self) -> f64 {
        let (v, w) = (self.state.velocity, self.angular_velocity());
        dot(v, v).sqrt() + dot(w, w).sqrt() * self.reach
    }

    /// Kinetic energy ½ M V² + ½ ω·L [J].
    pub fn kinetic_energy(&self) -> f64 {
        let (v, w, l) = (
            self.state.velocity,
            self.angular_velocity(),
            self.state.angular_momentum,
        );
        0.5 * self.mass * dot(v, v) + 0.5 * dot(w, l)
    }
}

/// The bodies of a run, in the order of the scene's `[[body]]` sections, and what their contact
/// with the container needs.
#[derive(Clone, Debug)]
pub struct Bodies {
    pub bodies: Vec<RigidBody>,
    /// The container's faces a body's particles keep half a spacing off, per axis (None along
    /// a periodic axis).
    faces: Vec<Option<(f64, f64)>>,
    /// The container's length along each periodic axis (None along a bounded one): a fluid
    /// particle near a body across the period is near its image.
    periods: Vec<Option<f64>>,
    /// The obstacles, which bodies touch as they touch each other.
    obstacles: Vec<Shape>,
    spacing: f64,
    dims: usize,
    /// The first fluid's rest density, which a held body's particles take in the pressure
    /// solve (`set_solve_densities`).
    water_density: f64,
    /// Which bodies the particles' masses and rest densities are set as held for (None: not
    /// known, as at the start of a run or a resumed one).
    held_in_solve: Option<Vec<bool>>,
    /// The scene's gravity [m/s²]: a body resting on a surface approaches it at up to |g| Δt
    /// in a step, which its contact does not take for a collision, and rests only on a support
    /// its weight in the water presses it onto (`resolve_contacts`).
    gravity: Vec3,
}

impl Bodies {
    /// The bodies of `scene` from their particles at t = 0 (`fill::build`): body particle i
    /// has kind `Body` and body index `fluid[i]`, and its index is its id.
    pub fn new<const D: usize>(scene: &Scene, p: &Particles<D>) -> Self {
        let bodies = scene
            .bodies
            .iter()
            .enumerate()
            .map(|(b, body)| {
                let members: Vec<usize> = (0..p.len())
                    .filter(|&i| p.kind[i] == Kind::Body && p.fluid[i] as usize == b)
                    .collect();
                let at = |i: usize| -> Vec3 { to_3d::<D>(|d| p.pos[d][i]) };
                let mass: f64 = members.iter().map(|&i| p.mass[i]).sum();
                let moment: Vec3 = members.iter().fold([0.0; 3], |s, &i| {
                    let x = at(i);
                    std::array::from_fn(|d| s[d] + p.mass[i] * x[d])
                });
                let centre = moment.map(|m| m / mass);
                let offsets: Vec<Vec3> = members
                    .iter()
                    .map(|&i| {
                        let x = at(i);
                        std::array::from_fn(|d| x[d] - centre[d])
                    })
                    .collect();
                let surface: Vec<SurfacePoint> = members
                    .iter()
                    .map(|&i| surface_point(&body.shape, at(i), scene.spacing, D))
                    .collect();
                let masses: Vec<f64> = members.iter().map(|&i| p.mass[i]).collect();
                let inertia = inertia_tensor(&offsets, &masses, D);
                let spin: Vec3 = match body.angular_velocity[..] {
                    [wz] => [0.0, 0.0, wz],
                    ref w => std::array::from_fn(|d| w[d]),
                };
                let first_id = p.id[members[0]];
                debug_assert!(members
                    .iter()
                    .enumerate()
                    .all(|(k, &i)| p.id[i] == first_id + k as u64));
                let bounds = body.shape.bounds();
                let reach = (0..D)
                    .map(|d| {
                        let far = (bounds.min[d] - centre[d])
                            .abs()
                            .max((bounds.max[d] - centre[d]).abs());
                        far * far
                    })
                    .sum::<f64>()
                    .sqrt();
                let mut rigid = RigidBody {
                    name: body.name.clone(),
                    shape: body.shape.clone(),
                    centre_at_start: centre,
                    reach,
                    motion: body.motion.clone(),
                    release: body.release,
                    mass,
                    particle_mass: p.mass[members[0]],
                    particle_density: p.rest_density[members[0]],
                    inertia,
                    external_force: std::array::from_fn(|d| {
                        body.force.get(d).copied().unwrap_or(0.0)
                    }),
                    restitution: body.restitution,
                    friction: body.friction,
                    first_id,
                    offsets,
                    surface,
                    state: RigidState {
                        centre,
                        orientation: Quaternion::IDENTITY,
                        velocity: std::array::from_fn(|d| {
                            body.velocity.get(d).copied().unwrap_or(0.0)
                        }),
                        // L = I ω: at t = 0 the body's frame is the world's.
                        angular_momentum: rotation::apply(&inertia, spin),
                        force: [0.0; 3],
                        torque: [0.0; 3],
                        resting: false,
                        wet: false,
                    },
                };
                // A prescribed body starts moving as its trajectory does at t = 0.
                if let Some(target) = rigid.target(0.0, 0.0) {
                    rigid.state.velocity = target.velocity;
                    rigid.state.angular_momentum =
                        rotation::apply(&inertia, target.angular_velocity);
                }
                rigid
            })
            .collect();
        let c: &Aabb = &scene.container;
        Self {
            bodies,
            faces: (0..D)
                .map(|d| (!scene.periodic[d]).then_some((c.min[d], c.max[d])))
                .collect(),
            periods: (0..D)
                .map(|d| scene.periodic[d].then_some(c.max[d] - c.min[d]))
                .collect(),
            obstacles: scene
                .obstacles
                .iter()
                .map(|o| Shape::Box {
                    min: o.min.clone(),
                    max: o.max.clone(),
                })
                .collect(),
            spacing: scene.spacing,
            dims: D,
            water_density: scene.fluids[0].density,
            held_in_solve: None,
            gravity: std::array::from_fn(|d| scene.gravity.get(d).copied().unwrap_or(0.0)),
        }
    }

    /// The first time after `t` at which a body is let go (`RigidBody::release`): the run lands
    /// a step on it, as on a frame time, so that the body moves freely from that time and not
    /// from the end of the step across it.
    pub fn next_release_after(&self, t: f64) -> Option<f64> {
        self.bodies
            .iter()
            .filter_map(|b| b.release)
            .filter(|&r| r > t)
            .min_by(f64::total_cmp)
    }

    pub fn is_empty(&self) -> bool {
        self.bodies.is_empty()
    }

    /// The first fluid's rest density, which a held body takes in the pressure solve.
    pub fn water_density(&self) -> f64 {
        self.water_density
    }

    /// Gives each body particle the mass and rest density the step from `time` takes it at:
    /// its body's own where the body moves freely, the water's (the first fluid's) with the
    /// same volume where it is held (fixed, prescribed or resting). A held body's motion does
    /// not depend on its mass, and at the water's density the pressure solve sees no interface
    /// at its surface: the water's hydrostatic pressure runs through it as through the water,
    /// whatever the body's density, and the fluid's force on it, −Σ V_i ∇P_i, is the same
    /// (docs/bodies.md, "The coupling").
    /// The particles are visited only when that changes: in a scene whose bodies move freely
    /// throughout, once.
    pub fn set_solve_densities<const D: usize>(&mut self, p: &mut Particles<D>, time: f64) {
        let held: Vec<bool> = self.bodies.iter().map(|b| b.is_held(time)).collect();
        if self.held_in_solve.as_ref() == Some(&held) {
            return;
        }
        for i in (0..p.len()).filter(|&i| p.kind[i] == Kind::Body) {
            let b = p.fluid[i] as usize;
            let body = &self.bodies[b];
            (p.mass[i], p.rest_density[i]) = if held[b] {
                let volume = body.particle_mass / body.particle_density;
                (self.water_density * volume, self.water_density)
            } else {
                (body.particle_mass, body.particle_density)
            };
        }
        self.held_in_solve = Some(held);
    }

    /// Gives the bodies' particles their bodies' rigid velocities and surface normals (at
    /// t = 0).
    pub fn set_particle_velocities<const D: usize>(&self, p: &mut Particles<D>) {
        for i in (0..p.len()).filter(|&i| p.kind[i] == Kind::Body) {
            let body = &self.bodies[p.fluid[i] as usize];
            let r = body.rotation();
            let arm = body.arm(&r, p.id[i]);
            let u = rigid_velocity(body.state.velocity, body.angular_velocity(), arm);
            let n = body.normal(&r, p.id[i]);
            for d in 0..D {
                p.vel[d][i] = u[d];
                p.normal[d][i] = n[d];
            }
        }
    }

    /// Whether a point at `x` lies within `margin` of some body's bounding sphere (across a
    /// periodic boundary too).
    pub fn near<const D: usize>(&self, x: [f64; D], margin: f64) -> bool {
        self.bodies.iter().any(|b| {
            let arm = (0..D).map(|d| {
                let a = x[d] - b.state.centre[d];
                self.periods[d].map_or(a, |l| a - l * (a / l).round())
            });
            arm.map(|a| a * a).sum::<f64>() <= (b.reach + margin).powi(2)
        })
    }

    /// The depth below its body's surface of the particle `id` of body `body`
    /// (`SurfacePoint`).
    pub fn depth(&self, body: usize, id: u64) -> f64 {
        let b = &self.bodies[body];
        b.surface[(id - b.first_id) as usize].depth
    }

    /// The states of every body, one after the other (a checkpoint's `bodies` array).
    pub fn states(&self) -> Vec<f64> {
        self.bodies
            .iter()
            .flat_map(|b| b.state.to_array())
            .collect()
    }

    /// Restores the states written by `states` (or by a checkpoint of 20 or 19 f64s a state,
    /// before `wet` and before `resting`); false if `states` does not hold one per body.
    pub fn restore(&mut self, states: &[f64]) -> bool {
        let count = self.bodies.len();
        let Some(len) = [RigidState::LEN, RigidState::LEN - 1, RigidState::LEN - 2]
            .into_iter()
            .find(|len| states.len() == count * len)
        else {
            return false;
        };
        for (body, s) in self.bodies.iter_mut().zip(states.chunks(len)) {
            body.state = RigidState::from_array(s);
        }
        self.held_in_solve = None;
        true
    }

    /// Advances body b's state over the step from `time` to `time + dt` from the momentum
    /// `impulse` and angular momentum `angular_impulse` the step's fluid stages gave its particles
    /// beyond their rigid motion, and `force` and `torque`, the fluid's over the step (the
    /// impulses per unit time less the body forces' share of them; for a held body the
    /// pressure's part taken from the water's side, `step::rigid_bodies`); a fixed or
    /// prescribed one is put where its motion says. A resting body stays where it is, and takes as its velocity
    /// what the fluid's force and `load` (the body forces on its own masses: its weight and
    /// external force, in a moving container the frame's) would give it over the step from
    /// rest; its contacts then hold it or let it go (`resolve_contacts`, after every body has
    /// moved). `wet`: its particles were in reach of the fluid or a wall over the step.
    ///
    /// The step's solve gives the fluid's force F on a free body at the configuration of the
    /// step's start, and the body's added mass implicitly. Where the body was wet over this step
    /// and the last, the momentum balance takes the force at the middle of the step,
    /// extrapolated from the last two, F + (F − F_last)/2 (second-order Adams–Bashforth, the
    /// change per step): as a body sinks or rises through the surface its buoyancy changes with
    /// its position, and the force of the step's start lags it by half a step
    /// (docs/bodies.md, "The coupling"). The same for the torque. A force that starts or jumps
    /// (the release, the entry into the water) is not extrapolated.
    #[allow(clippy::too_many_arguments)]
    pub fn advance(
        &mut self,
        b: usize,
        [impulse, angular_impulse]: [Vec3; 2],
        [force, torque]: [Vec3; 2],
        load: [Vec3; 2],
        wet: bool,
        time: f64,
        dt: f64,
    ) {
        let body = &mut self.bodies[b];
        let s = body.state;
        if let Some(target) = body.target(time, dt) {
            body.state = RigidState {
                centre: target.centre,
                orientation: target.orientation,
                velocity: target.velocity,
                angular_momentum: rotation::apply(
                    &rotation::to_world(&target.orientation.matrix(), &body.inertia),
                    target.angular_velocity,
                ),
                force,
                torque,
                resting: s.resting,
                wet: false,
            };
            if s.resting {
                body.state.velocity =
                    std::array::from_fn(|d| dt * (force[d] + load[0][d]) / body.mass);
                body.state.angular_momentum =
                    std::array::from_fn(|d| dt * (torque[d] + load[1][d]));
            }
            return;
        }
        // Eq. (14)–(15): the momentum balances, with the fluid's force and torque at the middle
        // of the step where the last step's are known.
        let half_change = |now: Vec3, last: Vec3| -> Vec3 {
            if wet && s.wet {
                std::array::from_fn(|d| 0.5 * (now[d] - last[d]) * dt)
            } else {
                [0.0; 3]
            }
        };
        let (extra, extra_angular) = (half_change(force, s.force), half_change(torque, s.torque));
        let spin = body.angular_velocity();
        body.state = RigidState {
            velocity: std::array::from_fn(|d| s.velocity[d] + (impulse[d] + extra[d]) / body.mass),
            angular_momentum: std::array::from_fn(|d| {
                s.angular_momentum[d] + angular_impulse[d] + extra_angular[d]
            }),
            force,
            torque,
            wet,
            ..s
        };
        body.drift(s.velocity, spin, dt);
    }
}

/// The `SurfacePoint` of a particle at x (where the body starts) of a body of shape `shape`.
fn surface_point(shape: &Shape, x: Vec3, spacing: f64, dims: usize) -> SurfacePoint {
    let distance = |y: &Vec3| shape.signed_distance(&y[..dims]);
    let depth = -distance(&x);
    let normal = if depth < SURFACE_REACH * spacing {
        outward_normal(&distance, x, spacing, dims).unwrap_or([0.0; 3])
    } else {
        [0.0; 3]
    };
    SurfacePoint { depth, normal }
}

/// I = Σ m (|r|² 1 − r ⊗ r) of point masses `masses` at `offsets` from the centre; in 2D only
/// I_zz = Σ m |r|² (a 2D body turns about z only).
fn inertia_tensor(offsets: &[Vec3], masses: &[f64], dims: usize) -> Mat3 {
    let mut inertia = [[0.0; 3]; 3];
    for (r, m) in offsets.iter().zip(masses) {
        let r2 = dot(*r, *r);
        for a in 0..3 {
            for b in 0..3 {
                let delta = if a == b { r2 } else { 0.0 };
                inertia[a][b] += m * (delta - r[a] * r[b]);
            }
        }
    }
    if dims == 2 {
        let zz = inertia[2][2];
        inertia = [[0.0; 3]; 3];
        inertia[2][2] = zz;
    }
    inertia
}

/// The outward unit normal at x of the surface whose signed distance is `distance`: its
/// gradient by central differences a thousandth of `scale` wide (None where it vanishes).
pub(crate) fn outward_normal(
    distance: &dyn Fn(&Vec3) -> f64,
    x: Vec3,
    scale: f64,
    dims: usize,
) -> Option<Vec3> {
    let eps = 1e-3 * scale;
    let gradient: Vec3 = std::array::from_fn(|d| {
        if d >= dims {
            return 0.0;
        }
        let (mut plus, mut minus) = (x, x);
        plus[d] += eps;
        minus[d] -= eps;
        (distance(&plus) - distance(&minus)) / (2.0 * eps)
    });
    let length = dot(gradient, gradient).sqrt();
    (length > 0.0).then(|| gradient.map(|g| g / length))
}

/// The rigid velocity V + ω × r of a point at arm r.
pub fn rigid_velocity(velocity: Vec3, omega: Vec3, arm: Vec3) -> Vec3 {
    let w = cross(omega, arm);
    std::array::from_fn(|d| velocity[d] + w[d])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn state(resting: bool, wet: bool) -> RigidState {
        RigidState {
            centre: [0.1, 0.2, 0.3],
            orientation: Quaternion([0.6, 0.0, 0.0, 0.8]),
            velocity: [1.0, 2.0, 3.0],
            angular_momentum: [4.0, 5.0, 6.0],
            force: [7.0, 8.0, 9.0],
            torque: [10.0, 11.0, 12.0],
            resting,
            wet,
        }
    }

    #[test]
    fn a_state_reads_back_from_its_checkpoint_array_and_an_older_one_rests_not() {
        for (resting, wet) in [(false, false), (true, false), (false, true)] {
            let a = state(resting, wet).to_array();
            assert_eq!(RigidState::from_array(&a), state(resting, wet));
            // A checkpoint written before `wet` held the first 20, before `resting` 19.
            assert_eq!(
                RigidState::from_array(&a[..RigidState::LEN - 1]),
                state(resting, false)
            );
            assert_eq!(
                RigidState::from_array(&a[..RigidState::LEN - 2]),
                state(false, false)
            );
        }
    }
}
