//! `[container.trajectory]` and `[body.trajectory]`: a sinusoid or a table file.

use super::Validator;
use crate::scene::file::TrajectorySection;
use crate::scene::trajectory::{parse_table, Path, Trajectory};
use crate::scene::SceneError;

impl Validator<'_> {
    /// The trajectory of section `t` at `key` in a `dims`-dimensional scene that runs to
    /// `end_time`: a `period` (sinusoid) or a `table`, not both; `pivot` defaults to
    /// `default_pivot`; a rotation in 3D needs its `axis`.
    pub(super) fn trajectory(
        &self,
        t: &TrajectorySection,
        key: &str,
        dims: usize,
        default_pivot: &[f64],
        end_time: f64,
    ) -> Result<Trajectory, SceneError> {
        let pivot = t.pivot.clone().unwrap_or(default_pivot.to_vec());
        self.vector(&pivot, dims, &format!("{key}.pivot"))?;
        let path = match (&t.period, &t.table) {
            (Some(period), None) => {
                self.positive(*period, &format!("{key}.period"), "s")?;
                let amplitude = t.amplitude.clone().unwrap_or(vec![0.0; dims]);
                self.vector(&amplitude, dims, &format!("{key}.amplitude"))?;
                let angle = t.angle.unwrap_or(0.0);
                self.check(
                    angle.is_finite(),
                    &format!("{key}.angle"),
                    "must be a finite number [degrees]",
                )?;
                // The motion's acceleration amplitude, (2π/T)² times the largest amplitude: a
                // period so short that it overflows gives no motion a step could follow.
                let omega = 2.0 * std::f64::consts::PI / period;
                let largest = amplitude
                    .iter()
                    .map(|a| a.abs())
                    .fold(angle.to_radians().abs(), f64::max);
                self.check(
                    (omega * omega * largest).is_finite(),
                    &format!("{key}.period"),
                    format!("= {period:?} s makes the motion's acceleration (2π/period)² × amplitude overflow: give a period a time step can follow"),
                )?;
                Path::Sinusoid {
                    amplitude: std::array::from_fn(|d| amplitude.get(d).copied().unwrap_or(0.0)),
                    angle: angle.to_radians(),
                    period: *period,
                }
            }
            (None, Some(table)) => {
                for (name, given) in [("amplitude", t.amplitude.is_some()), ("angle", t.angle.is_some())] {
                    self.check(
                        !given,
                        &format!("{key}.{name}"),
                        "is for a sinusoid (with `period`); a `table` gives the displacement and angle itself",
                    )?;
                }
                self.table(table, key, dims, end_time)?
            }
            (Some(_), Some(_)) => {
                return Err(self.error(
                    &format!("{key}.table"),
                    "and `period` are both given: a trajectory is a sinusoid (`period`, `amplitude`, `angle`) or a `table`, not both",
                ))
            }
            (None, None) => {
                return Err(self.error(
                    key,
                    "has neither `period` (a sinusoid) nor `table` (a CSV file of time, displacement, angle)",
                ))
            }
        };
        let mut trajectory = Trajectory {
            pivot: std::array::from_fn(|d| pivot.get(d).copied().unwrap_or(0.0)),
            axis: [0.0, 0.0, 1.0],
            path,
        };
        let still = if key.starts_with("container") {
            "leave it out: a container without a trajectory stands still"
        } else {
            "leave it out, or make the body `fixed`"
        };
        self.check(
            trajectory.moves(),
            key,
            format!("gives no motion (zero amplitude and angle): {still}"),
        )?;
        let axis_key = format!("{key}.axis");
        match (&t.axis, dims) {
            (Some(_), 2) => {
                return Err(self.error(&axis_key, "is for 3D: a 2D trajectory turns about z"))
            }
            (Some(axis), _) => {
                self.vector(axis, 3, &axis_key)?;
                let length = axis.iter().map(|a| a * a).sum::<f64>().sqrt();
                self.check(length > 0.0, &axis_key, "must not be the zero vector")?;
                trajectory.axis = std::array::from_fn(|d| axis[d] / length);
            }
            (None, 3) => {
                let turns = match &trajectory.path {
                    Path::Sinusoid { angle, .. } => *angle != 0.0,
                    Path::Table { rows, .. } => {
                        rows.iter().any(|r| r.values[3] != rows[0].values[3])
                    }
                };
                self.check(
                    !turns,
                    &axis_key,
                    "is missing: a 3D trajectory that turns needs the direction it turns about, e.g. `axis = [0.0, 1.0, 0.0]`",
                )?;
            }
            (None, _) => {}
        }
        Ok(trajectory)
    }

    /// The motion table `file` (relative to the scene file's folder) of trajectory `key`: read,
    /// parsed, covering 0 .. `end_time`.
    fn table(&self, file: &str, key: &str, dims: usize, end_time: f64) -> Result<Path, SceneError> {
        let table_key = format!("{key}.table");
        let path = self
            .path
            .parent()
            .unwrap_or(std::path::Path::new("."))
            .join(file);
        let text = std::fs::read_to_string(&path).map_err(|e| {
            self.error(
                &table_key,
                format!("= \"{file}\": cannot read {}: {e}", path.display()),
            )
        })?;
        let rows = parse_table(&text, dims).map_err(|(line, message)| {
            self.error(
                &table_key,
                format!(
                    "= \"{file}\": line {line} of {} {message} (the file is a header line, then rows `time, {}, angle` with the angle in degrees)",
                    path.display(),
                    ["x", "y", "z"][..dims].join(", ")
                ),
            )
        })?;
        let last = rows[rows.len() - 1].time;
        self.check(
            last >= end_time,
            &table_key,
            format!(
                "= \"{file}\" ends at {last:?} s, before `simulation.end_time` = {end_time:?} s: the table must cover the whole run"
            ),
        )?;
        Ok(Path::Table {
            file: file.into(),
            rows,
        })
    }
}
