//! The 3D picture: the water's surface shaded in its container, seen by the fixed camera of
//! `camera`. The container is drawn as its box's edges (the far ones faint through the water)
//! over a grey floor, rather than as wall particles that would hide the water.
//!
//! The surface is coloured by speed (the mesh's vertex velocities), by fluid when there is one
//! fluid, or pale against coloured bodies. Pressure is shown on the fluid particles instead,
//! drawn as shaded spheres: on the free surface the pressure is zero by its boundary
//! condition, so a surface coloured by pressure would be one flat colour; the particles that
//! face the camera (against the walls, in the splash) carry the pressure worth seeing. The
//! particles are also drawn when there is no surface to draw (an empty mesh) or when several
//! fluids are to be told apart.

use super::camera::Camera;
use super::colormap::{self, Rgb};
use super::depth::{DepthImage, Vertex};
use super::field::{ColorField, Legend, BODY, FLUID};
use super::overlay::{self, Style};
use super::raster::{Image, Rect};
use super::survey::Survey;
use crate::io::frames::Frame;
use crate::scene::SurfaceSettings;
use crate::surface::{self, Mesh, SurfaceError};
use plotters::prelude::*;

const FLOOR: Rgb = [226, 226, 226];
/// How much of the ink a hidden edge mixes into the water over it.
const HIDDEN_EDGE: f64 = 0.3;

/// Whether the field is shown on the surface (else on the particles).
pub fn shows_surface(survey: &Survey) -> bool {
    let c = &survey.colouring;
    match c.field {
        ColorField::Speed | ColorField::Body => true,
        ColorField::Fluid => c.fluids.len() <= 1,
        ColorField::Pressure => false,
    }
}

/// The water surface of `frame`, reconstructed from its fluid particles with the default
/// settings.
pub fn reconstruct(frame: &Frame, survey: &Survey) -> Result<Mesh, SurfaceError> {
    surface::reconstruct(
        &frame.fluid_points(3, survey.spacing),
        &SurfaceSettings::default(),
    )
}

/// The picture of `frame` with its surface `mesh`.
pub fn draw(
    frame: &Frame,
    mesh: &Mesh,
    survey: &Survey,
    size: (u32, u32),
) -> Result<Image, String> {
    super::font::register()?;
    let style = Style::for_size(size.0, size.1);
    let legend = survey.colouring.legend();
    let t = style.text;
    let right = overlay::legend_width(&legend, &style);
    // Three text heights above for the title, a margin of one on the other sides.
    let viewport = Rect {
        x: t,
        y: 3 * t,
        w: (size.0 as i32 - 2 * t - right).max(1),
        h: (size.1 as i32 - 4 * t).max(1),
    };
    let mut image = Image::new(size.0, size.1, [255; 3]);
    let (camera, shown) = centred_camera(survey, viewport, right, size.0 as i32);
    {
        let mut depth = DepthImage::new(&mut image, camera, viewport);
        floor(&mut depth, survey);
        if shows_surface(survey) && mesh.cell_count() > 0 {
            water_surface(&mut depth, mesh, survey);
        } else {
            particles(&mut depth, frame, survey, |kind| kind == FLUID);
        }
        particles(&mut depth, frame, survey, |kind| kind == BODY);
        container_edges(&mut depth, survey, style.line as i32);
    }
    let bar = overlay::bar_rect(shown, shown.h * 3 / 5, &style);
    let bar = match legend {
        Legend::Bar { .. } => {
            overlay::paint_bar(&mut image, bar);
            bar
        }
        Legend::Swatches(_) => Rect {
            y: shown.y + t,
            ..bar
        },
    };
    let root = BitMapBackend::with_buffer(&mut image.rgb, size).into_drawing_area();
    overlay::title(&root, &overlay::time_title(frame.time), shown, &style)?;
    overlay::legend(&root, &legend, bar, &style)?;
    root.present().map_err(|e| e.to_string())?;
    drop(root);
    Ok(image)
}

/// The camera fitted to the viewport, moved sideways so that the box it shows and the legend
/// (`legend_width` wide) are centred together in the picture's `width`, and the columns the
/// box takes on the screen (as tall as the viewport), beside which the legend goes.
fn centred_camera(
    survey: &Survey,
    viewport: Rect,
    legend_width: i32,
    width: i32,
) -> (Camera, Rect) {
    let drawn = survey.drawn_box();
    let mut camera = Camera::fitted(&drawn, viewport);
    let xs = drawn.corners().map(|c| camera.project(c).x);
    let left = xs.iter().copied().fold(f64::INFINITY, f64::min).floor() as i32;
    let right = xs.iter().copied().fold(f64::NEG_INFINITY, f64::max).ceil() as i32;
    let shift = (width - (right - left) - legend_width) / 2 - left;
    camera.centre.0 += shift as f64;
    let shown = Rect {
        x: left + shift,
        w: right - left,
        ..viewport
    };
    (camera, shown)
}

/// The container's floor (the bottom face of its inner box), under everything else.
fn floor(depth: &mut DepthImage, survey: &Survey) {
    let Some(b) = survey.container else {
        return;
    };
    let z = b.min[2];
    let corner = |x: f64, y: f64| Vertex {
        position: [x, y, z],
        normal: [0.0, 0.0, 1.0],
        colour: FLOOR,
    };
    let [c00, c10, c11, c01] = [
        corner(b.min[0], b.min[1]),
        corner(b.max[0], b.min[1]),
        corner(b.max[0], b.max[1]),
        corner(b.min[0], b.max[1]),
    ];
    depth.triangle([c00, c10, c11]);
    depth.triangle([c00, c11, c01]);
}

/// The mesh's triangles in order, coloured per vertex.
fn water_surface(depth: &mut DepthImage, mesh: &Mesh, survey: &Survey) {
    let c = &survey.colouring;
    let widen = |a: &[f32; 3]| a.map(f64::from);
    // A vertex with no velocity or normal (a damaged surface.h5) is drawn still and facing up
    // rather than stopping the picture; a cell naming a missing vertex is left out.
    let vertex = |v: u32| -> Option<Vertex> {
        let v = v as usize;
        let velocity = mesh.velocity.get(v).map_or([0.0; 3], widen);
        Some(Vertex {
            position: widen(mesh.positions.get(v)?),
            normal: mesh.normals.get(v).map_or([0.0, 0.0, 1.0], widen),
            colour: match c.field {
                ColorField::Speed => c.scalar(super::field::norm(velocity)),
                ColorField::Fluid => c.fluid(c.fluids.first().copied().unwrap_or(0)),
                _ => colormap::WATER,
            },
        })
    };
    for cell in mesh.cells.chunks_exact(3) {
        if let (Some(a), Some(b), Some(d)) = (vertex(cell[0]), vertex(cell[1]), vertex(cell[2])) {
            depth.triangle([a, b, d]);
        }
    }
}

/// The particles of the kinds `keep` accepts as spheres one spacing across, in id order.
fn particles(depth: &mut DepthImage, frame: &Frame, survey: &Survey, keep: impl Fn(i32) -> bool) {
    for i in (0..frame.kind.len()).filter(|&i| keep(frame.kind[i])) {
        let colour = survey.colouring.particle(frame, i);
        depth.sphere(frame.position[i], 0.5 * survey.spacing, colour);
    }
}

/// The twelve edges of the container's inner box.
fn container_edges(depth: &mut DepthImage, survey: &Survey, width: i32) {
    let Some(b) = survey.container else {
        return;
    };
    let corners = b.corners();
    // Corners k and k ^ (1 << d) differ along axis d only: each pair is an edge.
    for k in 0..8 {
        for d in 0..3 {
            let other = k ^ (1 << d);
            if other > k {
                depth.line(
                    corners[k],
                    corners[other],
                    width,
                    colormap::INK,
                    colormap::INK,
                    HIDDEN_EDGE,
                );
            }
        }
    }
}
