//! What plotters draws over the raster: the title, the colour bar or the category swatches,
//! and the sizes of text and lines, which grow with the picture so that a 4K frame reads like
//! a 1080p one.

use super::colormap::{self, Rgb};
use super::field::Legend;
use super::font::FAMILY;
use super::raster::{Image, Rect};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

pub type Area<'a> = DrawingArea<BitMapBackend<'a>, Shift>;

/// Sizes in pixels that follow from the picture's size.
#[derive(Clone, Copy, Debug)]
pub struct Style {
    /// The height of label text.
    pub text: i32,
    /// The width of axis and frame lines.
    pub line: u32,
}

impl Style {
    /// Text 1/40 of the height (27 px at 1080p), less for a narrow portrait picture.
    pub fn for_size(width: u32, height: u32) -> Self {
        let base = (height as f64).min(width as f64 * 0.75);
        let text = (base / 40.0).round().clamp(8.0, 400.0) as i32;
        Self {
            text,
            line: ((text as f64 / 14.0).round() as u32).max(1),
        }
    }

    pub fn font(&self, scale: f64) -> TextStyle<'static> {
        (FAMILY, self.text as f64 * scale)
            .into_font()
            .color(&rgb(colormap::INK))
    }

    /// The width `text` takes in the label font (an estimate where the font cannot say).
    pub fn width_of(&self, text: &str) -> i32 {
        self.font(1.0)
            .font
            .box_size(text)
            .map(|(w, _)| w as i32)
            .unwrap_or(text.len() as i32 * self.text * 6 / 10)
    }

    pub fn ink(&self) -> ShapeStyle {
        rgb(colormap::INK).stroke_width(self.line)
    }
}

pub fn rgb(c: Rgb) -> RGBColor {
    RGBColor(c[0], c[1], c[2])
}

/// A number as a tick label: at most four decimals, no trailing zeros ("0.05", "1200").
pub fn tick_label(v: f64) -> String {
    let text = format!("{v:.4}");
    let text = text.trim_end_matches('0').trim_end_matches('.');
    match text {
        "-0" | "" => "0".to_owned(),
        t => t.to_owned(),
    }
}

/// "t = 0.400 s".
pub fn time_title(time: f64) -> String {
    format!("t = {time:.3} s")
}

/// Draws `title` centred above `over`, its baseline band ending at `over.y`.
pub fn title(root: &Area, text: &str, over: Rect, style: &Style) -> Result<(), String> {
    let font = style.font(1.15).pos(Pos::new(HPos::Center, VPos::Bottom));
    let at = (over.x + over.w / 2, over.y - style.text / 2);
    root.draw_text(text, &font, at).map_err(|e| e.to_string())
}

/// The width the legend takes to the right of the picture, its gap included.
pub fn legend_width(legend: &Legend, style: &Style) -> i32 {
    let t = style.text;
    match legend {
        Legend::Bar { factor, max, .. } => {
            let widest = widest_tick_label(max * factor, style);
            t + bar_width(style) + tick_area(style, widest) + t / 2
        }
        Legend::Swatches(items) => {
            let widest = items
                .iter()
                .map(|(n, _)| style.width_of(n))
                .max()
                .unwrap_or(0);
            t + swatch_size(style) + t / 2 + widest
        }
    }
}

/// The width of the widest label a colour bar from 0 to `top` may get: plotters picks the ticks,
/// so a few values across the scale (a third decimal where they are not round) stand for them.
fn widest_tick_label(top: f64, style: &Style) -> i32 {
    [0.0, 0.55, 0.75, 1.0]
        .map(|f| style.width_of(&tick_label(f * top)))
        .into_iter()
        .max()
        .unwrap_or(0)
}

fn bar_width(style: &Style) -> i32 {
    style.text
}

/// The room right of the bar for the tick marks, the labels and the rotated title.
fn tick_area(style: &Style, widest_label: i32) -> i32 {
    widest_label + style.text * 5 / 2
}

fn swatch_size(style: &Style) -> i32 {
    style.text
}

/// The rectangle the colour bar's gradient fills, right of `plot` and as tall as `height`
/// around its middle.
pub fn bar_rect(plot: Rect, height: i32, style: &Style) -> Rect {
    Rect {
        x: plot.right() + style.text,
        y: plot.y + (plot.h - height) / 2,
        w: bar_width(style),
        h: height,
    }
}

/// Paints the colour bar's gradient into the raster (plotters then draws its frame and ticks
/// over it): row by row, so the bar shows the colour map with no banding.
pub fn paint_bar(image: &mut Image, bar: Rect) {
    for row in 0..bar.h {
        let t = 1.0 - (row as f64 + 0.5) / bar.h as f64;
        let colour = colormap::viridis(t);
        image.fill(
            Rect {
                x: bar.x,
                y: bar.y + row,
                w: bar.w,
                h: 1,
            },
            colour,
        );
    }
}

/// The legend right of `plot`: the colour bar's frame, ticks and title over the painted
/// gradient, or one swatch with its name per category.
pub fn legend(root: &Area, legend: &Legend, bar: Rect, style: &Style) -> Result<(), String> {
    let err = |e: DrawingAreaErrorKind<_>| e.to_string();
    match legend {
        Legend::Bar { factor, max, .. } => {
            let widest = widest_tick_label(max * factor, style);
            let ticks = tick_area(style, widest);
            let area = root.clone().shrink((bar.x, bar.y), (bar.w + ticks, bar.h));
            let top = max * factor;
            let mut chart = ChartBuilder::on(&area)
                .right_y_label_area_size(ticks)
                .build_cartesian_2d(0.0..1.0, 0.0..top)
                .map_err(err)?;
            let labels = (bar.h / (style.text * 2)).clamp(2, 10) as usize;
            let formatter = |v: &f64| tick_label(*v);
            chart
                .configure_mesh()
                .disable_mesh()
                .disable_x_axis()
                .y_labels(labels)
                .y_label_formatter(&formatter)
                .label_style(style.font(1.0))
                .axis_style(style.ink())
                .set_all_tick_mark_size(style.text / 3)
                .draw()
                .map_err(err)?;
            // The bar's title reads upwards beside the labels, as the y axis's does.
            let title = style
                .font(1.0)
                .transform(FontTransform::Rotate270)
                .pos(Pos::new(HPos::Center, VPos::Center));
            let x = bar.right() + widest + style.text * 19 / 10;
            root.draw_text(&legend.title(), &title, (x, bar.y + bar.h / 2))
                .map_err(err)?;
            frame(root, bar, style)
        }
        Legend::Swatches(items) => {
            let size = swatch_size(style);
            for (k, (name, colour)) in items.iter().enumerate() {
                let y = bar.y + k as i32 * size * 8 / 5;
                let square = [(bar.x, y), (bar.x + size, y + size)];
                root.draw(&Rectangle::new(square, rgb(*colour).filled()))
                    .map_err(err)?;
                root.draw(&Rectangle::new(square, style.ink()))
                    .map_err(err)?;
                let font = style.font(1.0).pos(Pos::new(HPos::Left, VPos::Center));
                root.draw_text(name, &font, (bar.x + size + size / 2, y + size / 2))
                    .map_err(err)?;
            }
            Ok(())
        }
    }
}

/// A frame of the picture's line width just around `rect`.
pub fn frame(root: &Area, rect: Rect, style: &Style) -> Result<(), String> {
    let corners = [(rect.x - 1, rect.y - 1), (rect.right(), rect.bottom())];
    root.draw(&Rectangle::new(corners, style.ink()))
        .map_err(|e| e.to_string())
}
