//! A moving container, solved in its own frame. The container, its obstacles and everything in
//! them are written in the frame that moves with the walls: x_lab = X(t) + c + R(t)(x − c),
//! with X the prescribed displacement of the pivot c and R the rotation by θ(t) about the axis
//! e (`scene::trajectory`). In that frame the walls stay where the scene puts them, at rest
//! and axis-aligned, so every wall term of `ghosts` and `faces` holds unchanged, and the motion
//! enters as the frame's body force on each particle at r = x − c with velocity u:
//!
//!   f = Rᵀ (g − Ẍ) − α × r − Ω × (Ω × r) − 2 Ω × u,      Ω = θ̇ e,  α = θ̈ e,
//!
//! gravity and the pivot's acceleration turned into the frame, the Euler, centrifugal and
//! Coriolis forces, each step taking Ẍ and α as their means over it (`MovingFrame::over`). It
//! is exact, not an approximation of the moving walls: it is Newton's second law written in the
//! container's frame. A wall particle then needs neither a velocity nor an acceleration
//! (u_b = a_b = 0 in `ghosts::Motion`), and the Neumann condition of its ghost pressure carries
//! f: ∂P/∂n = ρ0 f·n (`ghosts::ghost_pressure_difference`).

use crate::math::rotation::{apply_transposed, cross, to_3d, Quaternion, Vec3};
use crate::scene::trajectory::Trajectory;

/// The container's motion and the gravity it moves in.
#[derive(Clone, Debug)]
pub struct MovingFrame {
    pub trajectory: Trajectory,
    /// Gravity in the laboratory [m/s²] (z = 0 in 2D).
    pub gravity: Vec3,
}

/// The frame's body force at one time: what f above needs besides r and u.
#[derive(Clone, Copy, Debug)]
pub struct FrameForce {
    /// Rᵀ (g − Ẍ).
    uniform: Vec3,
    omega: Vec3,
    alpha: Vec3,
    pivot: Vec3,
}

impl MovingFrame {
    /// The frame's body force over the step from t to t + dt: the pivot's acceleration and the
    /// angular acceleration as their means over the step, (Ẋ(t + dt) − Ẋ(t))/dt and
    /// (Ω(t + dt) − Ω(t))/dt, and the rotation and Ω at the step's middle. The frame's impulse
    /// over the steps is then the change of its velocity exactly, whatever the step (second
    /// order in dt where the motion is smooth): a table that changes faster than a step (a
    /// recorded motion, a roll stopped at a finite rate) moves the water by what the tank did,
    /// and the water's relative vorticity follows −2Ω as Kelvin's theorem asks. Sampled at the
    /// step's start, a roll stopped within 5 ms by steps of 7 ms left the water turning at twice
    /// the rate it should (docs/bodies.md, "Moving containers").
    pub fn over(&self, t: f64, dt: f64) -> FrameForce {
        let (start, middle, end) = (
            self.trajectory.at(t),
            self.trajectory.at(t + 0.5 * dt),
            self.trajectory.at(t + dt),
        );
        let e = self.trajectory.axis;
        let rotation = Quaternion::from_rotation_vector(e.map(|c| c * middle.angle)).matrix();
        let lab: Vec3 =
            std::array::from_fn(|d| self.gravity[d] - (end.velocity[d] - start.velocity[d]) / dt);
        let alpha = (end.angular_velocity - start.angular_velocity) / dt;
        FrameForce {
            uniform: apply_transposed(&rotation, lab),
            omega: e.map(|c| c * middle.angular_velocity),
            alpha: e.map(|c| c * alpha),
            pivot: self.trajectory.pivot,
        }
    }
}

impl FrameForce {
    /// f at position x with velocity u, both in the frame.
    pub fn at<const D: usize>(&self, x: [f64; D], u: [f64; D]) -> [f64; D] {
        let r: Vec3 = to_3d::<D>(|d| x[d] - self.pivot[d]);
        let u: Vec3 = to_3d::<D>(|d| u[d]);
        let euler = cross(self.alpha, r);
        let centrifugal = cross(self.omega, cross(self.omega, r));
        let coriolis = cross(self.omega, u);
        std::array::from_fn(|d| self.uniform[d] - euler[d] - centrifugal[d] - 2.0 * coriolis[d])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::trajectory::{Path, TableRow};

    fn rolling(angle: f64, period: f64) -> MovingFrame {
        MovingFrame {
            trajectory: Trajectory {
                pivot: [0.5, 0.0, 0.0],
                axis: [0.0, 0.0, 1.0],
                path: Path::Sinusoid {
                    amplitude: [0.0; 3],
                    angle,
                    period,
                },
            },
            gravity: [0.0, -9.81, 0.0],
        }
    }

    #[test]
    fn a_tilted_frame_sees_gravity_turned_back() {
        // A quarter period in, the roll is at its largest (θ = Θ), at rest (θ̇ = 0) and turning
        // back at θ̈ = −Θ ω²; at the pivot only the turned gravity remains.
        let (angle, period) = (0.1, 2.0);
        let h = 1e-4;
        let f = rolling(angle, period)
            .over(0.5 - h, 2.0 * h)
            .at([0.5, 0.0], [0.0, 0.0]);
        assert!((f[0] - (-9.81 * angle.sin())).abs() < 1e-12, "{f:?}");
        assert!((f[1] - (-9.81 * angle.cos())).abs() < 1e-12, "{f:?}");
    }

    #[test]
    fn a_particle_at_rest_in_the_lab_follows_the_frame() {
        // A point fixed in the laboratory moves in the frame by u = −Ω × r; with no gravity
        // its acceleration in the frame, d/dt(−Ω × r) = −α × r − Ω × u, must be what f gives
        // (over a step of 2e-5 s about t, α's mean is α(t) within 1e-9).
        let mut frame = rolling(0.3, 1.5);
        frame.gravity = [0.0; 3];
        let (t, h) = (0.2, 1e-5);
        let force = frame.over(t - h, 2.0 * h);
        let k = frame.trajectory.at(t);
        let r = [0.3, 0.2, 0.0];
        let omega = [0.0, 0.0, k.angular_velocity];
        let u = cross(omega, r).map(|c| -c);
        let f = force.at([0.8, 0.2], [u[0], u[1]]);
        let du = cross([0.0, 0.0, k.angular_acceleration], r);
        let turn = cross(omega, u);
        for d in 0..2 {
            assert!((f[d] - (-du[d] - turn[d])).abs() < 1e-8, "{f:?}");
        }
    }

    #[test]
    fn the_frames_impulse_over_the_steps_is_the_change_of_its_velocity() {
        // Tables that move the tank (without turning it) or turn it (about the particle's
        // place) and stop it within 5 ms, crossed by steps of 7 ms and less: the impulse Σ Δt f
        // of the frame on a particle at the pivot (no gravity) must be −ΔẊ, and the Euler part's
        // angular impulse Σ Δt α must be ΔΩ, from a start at finite speed to rest, to round-off.
        let table = |values: fn(f64) -> [f64; 4]| {
            let rows = (0..=40)
                .map(|k| {
                    let t = k as f64 * 0.005;
                    let s = 0.02 * (10.0 * t.min(0.1)).sin();
                    TableRow {
                        time: t,
                        values: values(s),
                    }
                })
                .collect();
            MovingFrame {
                trajectory: Trajectory {
                    pivot: [0.5, 0.0, 0.0],
                    axis: [0.0, 0.0, 1.0],
                    path: Path::Table {
                        file: "motion.csv".into(),
                        rows,
                    },
                },
                gravity: [0.0; 3],
            }
        };
        // (step length, the frame's force over it) from t = 0 to 0.2 s.
        let steps = |frame: &MovingFrame| {
            let (mut t, mut steps) = (0.0, Vec::new());
            for dt in [0.007_f64, 0.0065, 0.007, 0.003].into_iter().cycle() {
                if t >= 0.2 {
                    break;
                }
                let dt = dt.min(0.2 - t);
                steps.push((dt, frame.over(t, dt)));
                t += dt;
            }
            steps
        };
        let moving = table(|s| [s, 0.5 * s, 0.0, 0.0]);
        let mut impulse = [0.0; 2];
        for (dt, force) in steps(&moving) {
            let f = force.at([0.5, 0.0], [0.0, 0.0]);
            for d in 0..2 {
                impulse[d] += dt * f[d];
            }
        }
        let (start, end) = (moving.trajectory.at(0.0), moving.trajectory.at(0.2));
        for d in 0..2 {
            let expected = -(end.velocity[d] - start.velocity[d]);
            assert!(
                (impulse[d] - expected).abs() < 1e-14,
                "{impulse:?} against {expected}"
            );
        }
        let turning = table(|s| [0.0, 0.0, 0.0, 3.0 * s]);
        let turn: f64 = steps(&turning).iter().map(|(dt, f)| dt * f.alpha[2]).sum();
        let (start, end) = (turning.trajectory.at(0.0), turning.trajectory.at(0.2));
        let expected = end.angular_velocity - start.angular_velocity;
        assert!((turn - expected).abs() < 1e-14, "{turn} against {expected}");
    }
}
