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
//! Coriolis forces. It is exact, not an approximation of the moving walls: it is Newton's
//! second law written in the container's frame. A wall particle then needs neither a velocity
//! nor an acceleration (u_b = a_b = 0 in `ghosts::Motion`), and the Neumann condition of its
//! ghost pressure carries f: ∂P/∂n = ρ0 f·n (`ghosts::ghost_pressure_difference`).

use crate::math::rotation::{apply_transposed, cross, Quaternion, Vec3};
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
    /// The body force of the frame at time t.
    pub fn at(&self, t: f64) -> FrameForce {
        let k = self.trajectory.at(t);
        let e = self.trajectory.axis;
        let rotation = Quaternion::from_rotation_vector(e.map(|c| c * k.angle)).matrix();
        let lab: Vec3 = std::array::from_fn(|d| self.gravity[d] - k.acceleration[d]);
        FrameForce {
            uniform: apply_transposed(&rotation, lab),
            omega: e.map(|c| c * k.angular_velocity),
            alpha: e.map(|c| c * k.angular_acceleration),
            pivot: self.trajectory.pivot,
        }
    }
}

impl FrameForce {
    /// f at position x with velocity u, both in the frame.
    pub fn at<const D: usize>(&self, x: [f64; D], u: [f64; D]) -> [f64; D] {
        let r: Vec3 = std::array::from_fn(|d| if d < D { x[d] - self.pivot[d] } else { 0.0 });
        let u: Vec3 = std::array::from_fn(|d| if d < D { u[d] } else { 0.0 });
        let euler = cross(self.alpha, r);
        let centrifugal = cross(self.omega, cross(self.omega, r));
        let coriolis = cross(self.omega, u);
        std::array::from_fn(|d| self.uniform[d] - euler[d] - centrifugal[d] - 2.0 * coriolis[d])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::trajectory::Path;

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
        let f = rolling(angle, period).at(0.5).at([0.5, 0.0], [0.0, 0.0]);
        assert!((f[0] - (-9.81 * angle.sin())).abs() < 1e-12, "{f:?}");
        assert!((f[1] - (-9.81 * angle.cos())).abs() < 1e-12, "{f:?}");
    }

    #[test]
    fn a_particle_at_rest_in_the_lab_follows_the_frame() {
        // A point fixed in the laboratory moves in the frame by u = −Ω × r; with no gravity
        // its acceleration in the frame, d/dt(−Ω × r) = −α × r − Ω × u, must be what f gives.
        let mut frame = rolling(0.3, 1.5);
        frame.gravity = [0.0; 3];
        let t = 0.2;
        let force = frame.at(t);
        let k = frame.trajectory.at(t);
        let r = [0.3, 0.2, 0.0];
        let omega = [0.0, 0.0, k.angular_velocity];
        let u = cross(omega, r).map(|c| -c);
        let f = force.at([0.8, 0.2], [u[0], u[1]]);
        let du = cross([0.0, 0.0, k.angular_acceleration], r);
        let turn = cross(omega, u);
        for d in 0..2 {
            assert!((f[d] - (-du[d] - turn[d])).abs() < 1e-12, "{f:?}");
        }
    }
}
