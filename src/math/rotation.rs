//! Rotations of rigid bodies: unit quaternions and 3 × 3 matrices in f64. A 2D body turns about
//! z only, so the same types serve both dimensions.

/// A 3-vector.
pub type Vec3 = [f64; 3];
/// A 3 × 3 matrix, row-major.
pub type Mat3 = [[f64; 3]; 3];

/// The 3-vector of a D-vector's components `f(d)`, zero beyond D (in 2D, z = 0).
#[inline]
pub fn to_3d<const D: usize>(f: impl Fn(usize) -> f64) -> Vec3 {
    std::array::from_fn(|d| if d < D { f(d) } else { 0.0 })
}

/// a × b.
pub fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// M v.
pub fn apply(m: &Mat3, v: Vec3) -> Vec3 {
    std::array::from_fn(|r| m[r][0] * v[0] + m[r][1] * v[1] + m[r][2] * v[2])
}

/// Mᵀ v.
pub fn apply_transposed(m: &Mat3, v: Vec3) -> Vec3 {
    std::array::from_fn(|c| m[0][c] * v[0] + m[1][c] * v[1] + m[2][c] * v[2])
}

/// M⁻¹ of a symmetric positive-definite M (an inertia tensor), by the adjugate; the rows and
/// columns of a zero axis (a 2D body's x and y: it only turns about z) are left zero, so the
/// inverse acts on the axes the body can turn about.
pub fn inverse_on_span(m: &Mat3) -> Mat3 {
    let planar = m[0][0] == 0.0 && m[1][1] == 0.0;
    if planar {
        let mut inv = [[0.0; 3]; 3];
        if m[2][2] != 0.0 {
            inv[2][2] = 1.0 / m[2][2];
        }
        return inv;
    }
    let c = |r: usize, c: usize| {
        let (r0, r1) = ((r + 1) % 3, (r + 2) % 3);
        let (c0, c1) = ((c + 1) % 3, (c + 2) % 3);
        m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0]
    };
    let det = m[0][0] * c(0, 0) + m[0][1] * c(0, 1) + m[0][2] * c(0, 2);
    std::array::from_fn(|r| std::array::from_fn(|k| c(k, r) / det))
}

/// A unit quaternion w + x i + y j + z k: the orientation of a body, the rotation from its own
/// frame to the world's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quaternion(pub [f64; 4]);

impl Quaternion {
    pub const IDENTITY: Quaternion = Quaternion([1.0, 0.0, 0.0, 0.0]);

    /// The rotation by the vector θ: about θ/|θ| by |θ| radians (the exponential map).
    pub fn from_rotation_vector(theta: Vec3) -> Self {
        let angle = (theta[0] * theta[0] + theta[1] * theta[1] + theta[2] * theta[2]).sqrt();
        if angle == 0.0 {
            return Self::IDENTITY;
        }
        let s = (0.5 * angle).sin() / angle;
        Quaternion([
            (0.5 * angle).cos(),
            s * theta[0],
            s * theta[1],
            s * theta[2],
        ])
    }

    /// self ⊗ other: the rotation `other` followed by `self`.
    pub fn then_after(self, other: Quaternion) -> Quaternion {
        let [a0, a1, a2, a3] = self.0;
        let [b0, b1, b2, b3] = other.0;
        Quaternion([
            a0 * b0 - a1 * b1 - a2 * b2 - a3 * b3,
            a0 * b1 + a1 * b0 + a2 * b3 - a3 * b2,
            a0 * b2 - a1 * b3 + a2 * b0 + a3 * b1,
            a0 * b3 + a1 * b2 - a2 * b1 + a3 * b0,
        ])
    }

    /// The same rotation scaled back to unit length (against the drift of rounding).
    pub fn normalised(self) -> Quaternion {
        let n = self.0.iter().map(|c| c * c).sum::<f64>().sqrt();
        Quaternion(self.0.map(|c| c / n))
    }

    /// The rotation matrix R: world = R body.
    pub fn matrix(self) -> Mat3 {
        let [w, x, y, z] = self.0;
        [
            [
                1.0 - 2.0 * (y * y + z * z),
                2.0 * (x * y - w * z),
                2.0 * (x * z + w * y),
            ],
            [
                2.0 * (x * y + w * z),
                1.0 - 2.0 * (x * x + z * z),
                2.0 * (y * z - w * x),
            ],
            [
                2.0 * (x * z - w * y),
                2.0 * (y * z + w * x),
                1.0 - 2.0 * (x * x + y * y),
            ],
        ]
    }
}

/// R I Rᵀ: the inertia tensor `body` of a body's own frame seen in the world's.
pub fn to_world(r: &Mat3, body: &Mat3) -> Mat3 {
    let ri: Mat3 = std::array::from_fn(|a| std::array::from_fn(|b| apply(body, r[a])[b]));
    // (R I Rᵀ)_ab = Σ_cd R_ac I_cd R_bd; row a of R I is Σ_c R_ac I_c· = I r_a (I symmetric).
    std::array::from_fn(|a| std::array::from_fn(|b| (0..3).map(|d| ri[a][d] * r[b][d]).sum()))
}
