//! The 2D picture (as Fig. 9 of the paper): each particle a disc one spacing wide, coloured by
//! the field, walls grey, on axes in metres with equal scales in x and y, the colour bar (or
//! the fluids' swatches) on the right and the time above.

use super::field::Legend;
use super::overlay::{self, Area, Style};
use super::raster::{Image, Rect};
use super::survey::Survey;
use crate::io::frames::Frame;
use plotters::prelude::*;
use std::ops::Range;

/// Where everything goes, in pixels, and the metres the plot shows.
struct Layout {
    plot: Rect,
    /// Pixels per metre, the same on both axes.
    scale: f64,
    x: Range<f64>,
    y: Range<f64>,
    /// The label areas left of and below the plot.
    y_labels: i32,
    x_labels: i32,
    /// Where the colour bar's gradient (or the first swatch) goes.
    legend: Rect,
}

impl Layout {
    fn new(survey: &Survey, legend: &Legend, (width, height): (u32, u32), style: &Style) -> Self {
        let t = style.text;
        let margin = t;
        // Half a spacing for the discs' radius, half a spacing of air around them.
        let data = if survey.bounds.is_empty() {
            super::bounds::Bounds::of(&[[0.0; 3], [1.0, 1.0, 0.0]])
        } else {
            survey.bounds.grown(survey.spacing)
        };
        let extent = data.extent().map(|e| e.max(survey.spacing));
        let widest = [data.min[1], data.max[1], 0.025]
            .map(|v| style.width_of(&overlay::tick_label((v * 1e3).round() / 1e3)))
            .into_iter()
            .max()
            .unwrap_or(0);
        let y_labels = widest + t * 5 / 2;
        let x_labels = t * 3;
        let title = 2 * t;
        let right = overlay::legend_width(legend, style);
        let (w, h) = (width as i32, height as i32);
        let room_w = (w - 2 * margin - y_labels - right).max(1);
        let room_h = (h - 2 * margin - title - x_labels).max(1);
        let scale = (room_w as f64 / extent[0]).min(room_h as f64 / extent[1]);
        let (pw, ph) = (
            ((extent[0] * scale).floor() as i32).max(1),
            ((extent[1] * scale).floor() as i32).max(1),
        );
        // The whole figure (labels, plot, legend) centred in the picture.
        let x = margin + (w - 2 * margin - (y_labels + pw + right)) / 2 + y_labels;
        let y = margin + (h - 2 * margin - (title + ph + x_labels)) / 2 + title;
        let plot = Rect { x, y, w: pw, h: ph };
        let centre = data.centre();
        let half = |pixels: i32| pixels as f64 / scale / 2.0;
        let legend = match legend {
            Legend::Bar { .. } => overlay::bar_rect(plot, ph, style),
            Legend::Swatches(_) => Rect {
                y: plot.y,
                ..overlay::bar_rect(plot, ph, style)
            },
        };
        Self {
            plot,
            scale,
            x: centre[0] - half(pw)..centre[0] + half(pw),
            y: centre[1] - half(ph)..centre[1] + half(ph),
            y_labels,
            x_labels,
            legend,
        }
    }

    /// The pixel position of (x, y) metres (pixel corners at integers).
    fn pixel(&self, p: &[f64; 3]) -> (f64, f64) {
        (
            self.plot.x as f64 + (p[0] - self.x.start) * self.scale,
            self.plot.y as f64 + (self.y.end - p[1]) * self.scale,
        )
    }
}

/// The picture of `frame`.
pub fn draw(frame: &Frame, survey: &Survey, size: (u32, u32)) -> Result<Image, String> {
    super::font::register()?;
    let style = Style::for_size(size.0, size.1);
    let legend = survey.colouring.legend();
    let layout = Layout::new(survey, &legend, size, &style);
    let mut image = Image::new(size.0, size.1, [255; 3]);
    paint_particles(&mut image, frame, survey, &layout);
    if let Legend::Bar { .. } = legend {
        overlay::paint_bar(&mut image, layout.legend);
    }
    {
        let root = BitMapBackend::with_buffer(&mut image.rgb, size).into_drawing_area();
        axes(&root, &layout, &style)?;
        overlay::frame(&root, layout.plot, &style)?;
        overlay::title(&root, &overlay::time_title(frame.time), layout.plot, &style)?;
        overlay::legend(&root, &legend, layout.legend, &style)?;
        root.present().map_err(|e| e.to_string())?;
    }
    Ok(image)
}

/// Every particle in id order (so that where discs overlap the same one is on top every time),
/// clipped to the plot.
fn paint_particles(image: &mut Image, frame: &Frame, survey: &Survey, layout: &Layout) {
    let diameter = (survey.spacing * layout.scale).max(1.0);
    for i in 0..frame.position.len() {
        let (x, y) = layout.pixel(&frame.position[i]);
        if x.is_finite() && y.is_finite() {
            let colour = survey.colouring.particle(frame, i);
            image.disc(x, y, diameter, colour, layout.plot);
        }
    }
}

/// The x and y axes with ticks in metres.
fn axes(root: &Area, layout: &Layout, style: &Style) -> Result<(), String> {
    let err = |e: DrawingAreaErrorKind<_>| e.to_string();
    let plot = layout.plot;
    let area = root.clone().shrink(
        (plot.x - layout.y_labels, plot.y),
        (layout.y_labels + plot.w, plot.h + layout.x_labels),
    );
    let mut chart = ChartBuilder::on(&area)
        .x_label_area_size(layout.x_labels)
        .y_label_area_size(layout.y_labels)
        .build_cartesian_2d(layout.x.clone(), layout.y.clone())
        .map_err(err)?;
    let formatter = |v: &f64| overlay::tick_label(*v);
    chart
        .configure_mesh()
        .disable_mesh()
        .x_labels((plot.w / (style.text * 4)).clamp(2, 12) as usize)
        .y_labels((plot.h / (style.text * 2)).clamp(2, 12) as usize)
        .x_label_formatter(&formatter)
        .y_label_formatter(&formatter)
        .x_desc("x [m]")
        .y_desc("y [m]")
        .label_style(style.font(1.0))
        .axis_desc_style(style.font(1.0))
        .axis_style(style.ink())
        .set_all_tick_mark_size(style.text / 3)
        .draw()
        .map_err(err)?;
    Ok(())
}
