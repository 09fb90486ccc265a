//! Prescribed motions: a translation X(t) and a rotation by θ(t) about a fixed axis through a
//! pivot, given as a sinusoid or as a table of time → displacement and angle. The container
//! (`[container.trajectory]`, sloshing) and a prescribed body (`[body.trajectory]`) move on one
//! (docs/scene-format.md). The scene's geometry is the pose at t = 0: X(0) = 0 and θ(0) = 0.

use crate::math::rotation::{self, Mat3, Quaternion, Vec3};
use std::f64::consts::PI;
use std::path::PathBuf;

/// A motion prescribed as a function of time.
#[derive(Clone, Debug, PartialEq)]
pub struct Trajectory {
    /// The point the rotation turns about, where the scene puts it at t = 0 [m] (3 components,
    /// z = 0 in 2D).
    pub pivot: [f64; 3],
    /// The unit axis of the rotation (z in 2D).
    pub axis: [f64; 3],
    pub path: Path,
}

/// How the displacement and the angle go with time.
#[derive(Clone, Debug, PartialEq)]
pub enum Path {
    /// X(t) = A sin(2πt/T), θ(t) = Θ sin(2πt/T).
    Sinusoid {
        /// A [m].
        amplitude: [f64; 3],
        /// Θ [rad].
        angle: f64,
        /// T [s].
        period: f64,
    },
    /// Rows of time [s], displacement [m] and angle [rad], the times increasing; a cubic
    /// Hermite curve with finite-difference slopes (Catmull–Rom) through them, taken relative to
    /// its value at t = 0, so its velocity is continuous and its acceleration bounded. After
    /// the last row the pose stays the last row's, at rest.
    Table {
        /// As the scene names it, relative to the scene file's folder (the scene's hash then
        /// holds the rows, not where the scene was read from).
        file: PathBuf,
        rows: Vec<TableRow>,
    },
}

/// A pose of a trajectory (`Trajectory::placement`).
pub struct Placement {
    /// The turn by θ about the axis, and its matrix.
    pub orientation: Quaternion,
    rotation: Mat3,
    /// The pivot at t = 0, and where it has moved.
    start: Vec3,
    pub pivot: Vec3,
}

impl Placement {
    /// R(θ)(x − pivot₀): the arm from the moved pivot to where the point at x at t = 0 is.
    pub fn arm(&self, x: Vec3) -> Vec3 {
        rotation::apply(
            &self.rotation,
            std::array::from_fn(|d| x[d] - self.start[d]),
        )
    }

    /// Where the point at x at t = 0 is.
    pub fn place(&self, x: Vec3) -> Vec3 {
        let arm = self.arm(x);
        std::array::from_fn(|d| self.pivot[d] + arm[d])
    }
}

/// One row of a motion table: time [s], displacement [m] (z = 0 in 2D) and angle [rad].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TableRow {
    pub time: f64,
    pub values: [f64; 4],
}

/// A prescribed pose and its first two time derivatives at one time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Kinematics {
    /// Displacement X, velocity Ẋ and acceleration Ẍ of the pivot [m, m/s, m/s²].
    pub displacement: [f64; 3],
    pub velocity: [f64; 3],
    pub acceleration: [f64; 3],
    /// θ, θ̇ and θ̈ about the axis [rad, rad/s, rad/s²].
    pub angle: f64,
    pub angular_velocity: f64,
    pub angular_acceleration: f64,
}

impl Trajectory {
    /// The pose and its derivatives at time t.
    pub fn at(&self, t: f64) -> Kinematics {
        match &self.path {
            Path::Sinusoid {
                amplitude,
                angle,
                period,
            } => {
                let omega = 2.0 * PI / period;
                let (s, c) = (omega * t).sin_cos();
                Kinematics {
                    displacement: amplitude.map(|a| a * s),
                    velocity: amplitude.map(|a| a * omega * c),
                    acceleration: amplitude.map(|a| -a * omega * omega * s),
                    angle: angle * s,
                    angular_velocity: angle * omega * c,
                    angular_acceleration: -angle * omega * omega * s,
                }
            }
            Path::Table { rows, .. } => {
                let start = hermite(rows, 0.0);
                let last = rows[rows.len() - 1].time;
                // After its last row the table holds its last pose.
                let [x, v, a] = if t < last {
                    hermite(rows, t)
                } else {
                    [hermite(rows, last)[0], [0.0; 4], [0.0; 4]]
                };
                Kinematics {
                    displacement: std::array::from_fn(|d| x[d] - start[0][d]),
                    velocity: [v[0], v[1], v[2]],
                    acceleration: [a[0], a[1], a[2]],
                    angle: x[3] - start[0][3],
                    angular_velocity: v[3],
                    angular_acceleration: a[3],
                }
            }
        }
    }

    /// Where the motion at kinematics `k` (`at`) has taken what it moves: turned by θ about the
    /// pivot, which has moved by X.
    pub fn placement(&self, k: &Kinematics) -> Placement {
        let orientation = Quaternion::from_rotation_vector(self.axis.map(|e| e * k.angle));
        Placement {
            orientation,
            rotation: orientation.matrix(),
            start: self.pivot,
            pivot: std::array::from_fn(|d| self.pivot[d] + k.displacement[d]),
        }
    }

    /// One line for `isph plan`.
    pub fn describe(&self) -> String {
        let about = format!("about {:?} through {:?}", self.axis, self.pivot);
        match &self.path {
            Path::Sinusoid {
                amplitude,
                angle,
                period,
            } => format!(
                "sinusoid of period {period} s, displacement amplitude {amplitude:?} m, angle amplitude {:.3}° {about}",
                angle.to_degrees()
            ),
            Path::Table { file, rows } => format!(
                "table {} of {} rows to {} s, {about}",
                file.display(),
                rows.len(),
                rows[rows.len() - 1].time
            ),
        }
    }

    /// Whether it moves at all.
    pub fn moves(&self) -> bool {
        match &self.path {
            Path::Sinusoid {
                amplitude, angle, ..
            } => *angle != 0.0 || amplitude.iter().any(|a| *a != 0.0),
            Path::Table { rows, .. } => rows.windows(2).any(|w| w[0].values != w[1].values),
        }
    }
}

/// The value, slope and second derivative at t of the Catmull–Rom curve through `rows` (at
/// least two, times increasing, t within them), each of the four columns.
fn hermite(rows: &[TableRow], t: f64) -> [[f64; 4]; 3] {
    let n = rows.len();
    let k = rows
        .partition_point(|r| r.time <= t)
        .clamp(1, n - 1)
        .saturating_sub(1);
    let (r0, r1) = (&rows[k], &rows[k + 1]);
    let h = r1.time - r0.time;
    let slope = |j: usize| -> [f64; 4] {
        let (a, b) = (&rows[j.saturating_sub(1)], &rows[(j + 1).min(n - 1)]);
        std::array::from_fn(|c| (b.values[c] - a.values[c]) / (b.time - a.time))
    };
    let (m0, m1) = (slope(k), slope(k + 1));
    let s = (t - r0.time) / h;
    let (s2, s3) = (s * s, s * s * s);
    // The cubic Hermite basis h00, h10, h01, h11 and its first and second derivatives in s.
    let basis = [
        [
            2.0 * s3 - 3.0 * s2 + 1.0,
            s3 - 2.0 * s2 + s,
            -2.0 * s3 + 3.0 * s2,
            s3 - s2,
        ],
        [
            6.0 * s2 - 6.0 * s,
            3.0 * s2 - 4.0 * s + 1.0,
            -6.0 * s2 + 6.0 * s,
            3.0 * s2 - 2.0 * s,
        ],
        [
            12.0 * s - 6.0,
            6.0 * s - 4.0,
            -12.0 * s + 6.0,
            6.0 * s - 2.0,
        ],
    ];
    std::array::from_fn(|order| {
        let [b00, b10, b01, b11] = basis[order];
        let scale = h.powi(order as i32);
        std::array::from_fn(|c| {
            (b00 * r0.values[c] + b10 * h * m0[c] + b01 * r1.values[c] + b11 * h * m1[c]) / scale
        })
    })
}

/// Parses a motion table: a header line, then rows `time, x, y[, z], angle` (`dims` + 2
/// numbers; the angle in degrees), times increasing from at most 0. On error: the 1-based line
/// and what is wrong with it.
pub fn parse_table(text: &str, dims: usize) -> Result<Vec<TableRow>, (usize, String)> {
    let columns = dims + 2;
    let header = text.lines().next().unwrap_or_default();
    if !header.trim().is_empty() && header.split(',').all(|x| x.trim().parse::<f64>().is_ok()) {
        return Err((
            1,
            "holds numbers where the header line belongs: the table starts with a line naming its columns (time, x, y[, z], angle), and its first row would otherwise be lost".into(),
        ));
    }
    let mut rows: Vec<TableRow> = Vec::new();
    for (k, line) in text.lines().enumerate().skip(1) {
        let line_no = k + 1;
        if line.trim().is_empty() {
            continue;
        }
        let numbers: Result<Vec<f64>, _> = line.split(',').map(|x| x.trim().parse()).collect();
        let numbers = match numbers {
            Ok(n) if n.len() == columns && n.iter().all(|x: &f64| x.is_finite()) => n,
            _ => {
                return Err((
                    line_no,
                    format!("is not {columns} finite numbers separated by commas (time, the {dims} displacement components, the angle in degrees)"),
                ))
            }
        };
        let time = numbers[0];
        if let Some(last) = rows.last() {
            if time <= last.time {
                return Err((
                    line_no,
                    format!(
                        "has time {time:?} s, not after the row before's {:?} s: times must increase",
                        last.time
                    ),
                ));
            }
        }
        let mut values = [0.0; 4];
        values[..dims].copy_from_slice(&numbers[1..=dims]);
        values[3] = numbers[dims + 1].to_radians();
        rows.push(TableRow { time, values });
    }
    if rows.len() < 2 {
        return Err((1, "holds fewer than two rows".into()));
    }
    if rows[0].time > 0.0 {
        return Err((
            2,
            format!(
                "starts at {:?} s: the table must start at or before t = 0",
                rows[0].time
            ),
        ));
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(points: &[(f64, f64)]) -> Trajectory {
        Trajectory {
            pivot: [0.0; 3],
            axis: [0.0, 0.0, 1.0],
            path: Path::Table {
                file: PathBuf::new(),
                rows: points
                    .iter()
                    .map(|&(time, x)| TableRow {
                        time,
                        values: [x, 0.0, 0.0, 0.0],
                    })
                    .collect(),
            },
        }
    }

    #[test]
    fn a_table_of_a_parabola_gives_its_velocity_and_acceleration_inside() {
        // Catmull–Rom slopes are exact for a parabola at the interior rows, so the curve is the
        // parabola itself between them.
        let points: Vec<(f64, f64)> = (0..8)
            .map(|k| (k as f64 * 0.1, 3.0 * (k as f64 * 0.1).powi(2)))
            .collect();
        let k = table(&points).at(0.35);
        assert!((k.displacement[0] - 3.0 * 0.35 * 0.35).abs() < 1e-12);
        assert!((k.velocity[0] - 6.0 * 0.35).abs() < 1e-12);
        assert!((k.acceleration[0] - 6.0).abs() < 1e-9);
    }

    #[test]
    fn a_table_is_taken_relative_to_its_value_at_zero() {
        let k = table(&[(-1.0, 2.0), (0.0, 2.0), (1.0, 2.0)]).at(0.5);
        assert_eq!(k.displacement[0], 0.0);
        assert_eq!(k.velocity[0], 0.0);
    }

    #[test]
    fn a_table_with_a_bad_line_names_it() {
        let err = parse_table("t,x,y,angle\n0,0,0,0\n0.1,0,0,1\n0.1,0,0,2\n", 2).unwrap_err();
        assert_eq!(err.0, 4);
        let err = parse_table("t,x,y,angle\n0,0,0\n", 2).unwrap_err();
        assert_eq!(err.0, 2);
        let err = parse_table("t,x,y,angle\n0.5,0,0,0\n1,0,0,0\n", 2).unwrap_err();
        assert!(err.1.contains("at or before t = 0"), "{}", err.1);
        // A table without its header line would lose its first row.
        let err = parse_table("0,0,0,0\n0.1,0,0,1\n0.2,0,0,2\n", 2).unwrap_err();
        assert_eq!(err.0, 1);
        assert!(err.1.contains("header line"), "{}", err.1);
    }

    #[test]
    fn a_sinusoid_starts_at_the_scene_pose_moving() {
        let s = Trajectory {
            pivot: [0.0; 3],
            axis: [0.0, 0.0, 1.0],
            path: Path::Sinusoid {
                amplitude: [0.1, 0.0, 0.0],
                angle: 0.2,
                period: 2.0,
            },
        };
        let k = s.at(0.0);
        assert_eq!((k.displacement[0], k.angle), (0.0, 0.0));
        assert!((k.velocity[0] - 0.1 * PI).abs() < 1e-15);
        let k = s.at(0.5);
        assert!(
            (k.angle - 0.2).abs() < 1e-15 && (k.angular_acceleration + 0.2 * PI * PI).abs() < 1e-12
        );
    }
}
