//! The study's result: the Pareto front of error against wall time, a log-log SVG plot
//! (`plotters`, SVG backend only: text stays SVG text, no font library) and a text table.

use super::StudyError;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::fmt::Write as _;
use std::path::Path;

pub const FILE_NAME: &str = "study.svg";

/// One point's outcome, as study.csv holds it.
#[derive(Clone, Debug)]
pub struct Outcome {
    pub id: String,
    pub label: String,
    /// None for a failed point.
    pub error: Option<f64>,
    pub seconds: Option<f64>,
    pub steps: Option<f64>,
    pub ppe_iterations: Option<f64>,
    pub peak_bytes: Option<f64>,
    pub status: String,
}

impl Outcome {
    /// (seconds, error) when both are positive and finite: what a log-log plot can show.
    fn plotted(&self) -> Option<(f64, f64)> {
        let positive = |v: Option<f64>| v.filter(|v| v.is_finite() && *v > 0.0);
        Some((positive(self.seconds)?, positive(self.error)?))
    }
}

/// For each outcome, whether it is on the Pareto front: plotted, and no other plotted outcome
/// is at least as good in both error and time and better in one.
pub fn pareto(outcomes: &[Outcome]) -> Vec<bool> {
    let points: Vec<Option<(f64, f64)>> = outcomes.iter().map(Outcome::plotted).collect();
    points
        .iter()
        .map(|p| {
            p.is_some_and(|(t, e)| {
                !points
                    .iter()
                    .flatten()
                    .any(|&(t2, e2)| t2 <= t && e2 <= e && (t2 < t || e2 < e))
            })
        })
        .collect()
}

/// The log-log plot of error against wall time, the front marked, connected and labelled,
/// written atomically to `path`.
pub fn write_svg(path: &Path, title: &str, outcomes: &[Outcome]) -> Result<(), StudyError> {
    let private = path.with_extension(format!("svg.new-{}", std::process::id()));
    draw(&private, title, outcomes).map_err(|message| StudyError::Plot {
        path: path.to_owned(),
        message,
    })?;
    std::fs::rename(&private, path).map_err(|source| StudyError::Write {
        path: path.to_owned(),
        source,
    })
}

/// The whole decades around `values`, for a log axis with a labelled tick at each end.
fn log_range(values: impl Iterator<Item = f64> + Clone) -> std::ops::Range<f64> {
    let lo = values.clone().fold(f64::INFINITY, f64::min);
    let hi = values.fold(0.0, f64::max);
    let lo = 10f64.powf(lo.log10().floor());
    let hi = 10f64.powf(hi.log10().ceil()).max(10.0 * lo);
    lo..hi
}

fn draw(path: &Path, title: &str, outcomes: &[Outcome]) -> Result<(), String> {
    // plotters has no font of its own: the embedded one, as `isph render` draws with.
    crate::render::font::register()?;
    let front = pareto(outcomes);
    let points: Vec<(f64, f64, &str, bool)> = outcomes
        .iter()
        .zip(&front)
        .filter_map(|(o, &f)| o.plotted().map(|(t, e)| (t, e, o.label.as_str(), f)))
        .collect();
    if points.is_empty() {
        return Err("no point has a positive error and wall time to plot".into());
    }
    let root = SVGBackend::new(path, (1000, 700)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 20))
        .margin(20)
        .x_label_area_size(50)
        .y_label_area_size(80)
        .build_cartesian_2d(
            log_range(points.iter().map(|p| p.0)).log_scale(),
            log_range(points.iter().map(|p| p.1)).log_scale(),
        )
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .x_desc("wall time [s]")
        .y_desc("relative error")
        .x_label_formatter(&|v| format!("{v:.1e}"))
        .y_label_formatter(&|v| format!("{v:.1e}"))
        .draw()
        .map_err(|e| e.to_string())?;
    let mut on_front: Vec<(f64, f64)> = points.iter().filter(|p| p.3).map(|p| (p.0, p.1)).collect();
    on_front.sort_by(|a, b| a.0.total_cmp(&b.0));
    chart
        .draw_series(LineSeries::new(
            on_front.iter().copied(),
            RED.stroke_width(2),
        ))
        .map_err(|e| e.to_string())?
        .label("Pareto front")
        .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], RED.stroke_width(2)));
    chart
        .draw_series(points.iter().map(|&(t, e, _, f)| {
            let colour = if f { RED } else { BLUE };
            Circle::new((t, e), if f { 6 } else { 4 }, colour.filled())
        }))
        .map_err(|e| e.to_string())?
        .label("other points (study.csv)")
        .legend(|(x, y)| Circle::new((x + 10, y), 4, BLUE.filled()));
    // The front's points are labelled with their settings (the others are in study.csv), on
    // the side of the point away from the plot's right edge.
    let x_range = log_range(points.iter().map(|p| p.0));
    let middle = (x_range.start * x_range.end).sqrt();
    chart
        .draw_series(points.iter().filter(|p| p.3).map(|&(t, e, label, _)| {
            let (text, anchor) = if t < middle {
                (format!("  {label}"), HPos::Left)
            } else {
                (format!("{label}  "), HPos::Right)
            };
            let style =
                TextStyle::from(("sans-serif", 12).into_font()).pos(Pos::new(anchor, VPos::Center));
            Text::new(text, (t, e), style)
        }))
        .map_err(|e| e.to_string())?;
    // Nothing is below and left of the front: the legend goes there.
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerLeft)
        .border_style(BLACK)
        .background_style(WHITE)
        .draw()
        .map_err(|e| e.to_string())?;
    root.present().map_err(|e| e.to_string())
}

/// The outcomes as a text table, the Pareto points marked with `*`.
pub fn table(outcomes: &[Outcome]) -> String {
    let front = pareto(outcomes);
    let number = |v: Option<f64>, digits: usize| match v {
        Some(v) => format!("{v:.digits$e}"),
        None => "-".into(),
    };
    let mut t = String::new();
    let _ = writeln!(
        t,
        "  {:<12} {:>10} {:>10} {:>8} {:>7} {:>9}  {:<40} status",
        "point", "error", "wall [s]", "steps", "PPE it", "peak MB", "settings"
    );
    for (o, &f) in outcomes.iter().zip(&front) {
        let _ = writeln!(
            t,
            "{} {:<12} {:>10} {:>10} {:>8} {:>7} {:>9}  {:<40} {}",
            if f { "*" } else { " " },
            o.id,
            number(o.error, 3),
            number(o.seconds, 3),
            o.steps.map_or("-".into(), |s| s.to_string()),
            o.ppe_iterations.map_or("-".into(), |p| format!("{p:.1}")),
            o.peak_bytes
                .map_or("-".into(), |b| format!("{:.1}", b / 1e6)),
            o.label,
            o.status
        );
    }
    let _ = writeln!(
        t,
        "* on the Pareto front: no other point has both a smaller error and a shorter wall time"
    );
    t
}
