//! `[[probe]]` and probes.csv: the Shepard interpolation reads a constant field exactly and a
//! smooth one to the kernel's smoothing; still water's probes read ρ0 g (H − y); a probe on a
//! wall's face reads the pressure at the centroid of the fluid beside it; probes.csv has its
//! columns and one row per step; a wave gauge reads the free surface's height. (Thread counts and resume: tests/determinism.rs and
//! tests/checkpoint.rs; bad probes: tests/bad_input.rs.)

use crate::common::{run_scene, scene_from_text, Lattice, TempDir};
use isph::io::probes;
use isph::math::kernel::{Kernel, KernelKind};
use isph::scene::Aabb;
use isph::sph::probe::{full_fraction, sample, surface_height, Sample, SURFACE_FRACTION};
use std::f64::consts::PI;

/// The particles of a 40 × 40 lattice (dx = 0.025 m) with the velocity `u` and pressure `p`.
fn lattice_with(u: impl Fn([f64; 2]) -> [f64; 2], p: impl Fn([f64; 2]) -> f64) -> Lattice<2> {
    let mut l = Lattice::<2>::new(40, 0.025, 1.2);
    for i in 0..l.particles.len() {
        let x = l.particles.position(i);
        let v = u(x);
        l.particles.vel[0][i] = v[0];
        l.particles.vel[1][i] = v[1];
        l.particles.pressure[i] = p(x);
    }
    l
}

/// The probe's reading at `point` of the lattice's particles where they stand, in an open plane.
fn sample_at(l: &Lattice<2>, point: [f64; 2], wet: f64) -> Sample<2> {
    sample(
        &l.particles,
        &l.particles.pos,
        &l.kernel,
        &[None, None],
        point,
        wet,
    )
}

#[test]
fn a_uniform_flow_is_read_exactly_and_no_fluid_reads_zero() {
    let l = lattice_with(|_| [0.7, -0.3], |_| 1234.5);
    for point in [[0.0, 0.0], [0.0113, -0.2], [0.49, 0.49]] {
        let s = sample_at(&l, point, 0.0);
        assert!((s.velocity[0] - 0.7).abs() < 1e-13, "{point:?}: {s:?}");
        assert!((s.velocity[1] + 0.3).abs() < 1e-13, "{point:?}: {s:?}");
        assert!((s.pressure - 1234.5).abs() < 1e-9, "{point:?}: {s:?}");
    }
    // The lattice ends at 0.475 m; the support is 3h = 0.09 m.
    let far = sample_at(&l, [0.6, 0.0], 0.0);
    assert_eq!((far.pressure, far.velocity), (0.0, [0.0, 0.0]));
}

/// The largest velocity error of the Shepard reading of the Taylor–Green field of a 1 m square
/// (U = 1) on a lattice of `n` × `n` particles, at points away from the lattice's edges.
fn taylor_green_reading_error(n: i64) -> f64 {
    let k = 2.0 * PI;
    let field = |x: [f64; 2]| {
        [
            (k * x[0]).sin() * (k * x[1]).cos(),
            -(k * x[0]).cos() * (k * x[1]).sin(),
        ]
    };
    let mut l = Lattice::<2>::new(n, 1.0 / n as f64, 1.2);
    for i in 0..l.particles.len() {
        let u = field(l.particles.position(i));
        l.particles.vel[0][i] = u[0];
        l.particles.vel[1][i] = u[1];
    }
    let mut worst = 0.0_f64;
    for point in [
        [0.1, 0.2],
        [-0.13, 0.07],
        [0.25, -0.3],
        [0.0, 0.0],
        [0.31, 0.33],
    ] {
        let s = sample_at(&l, point, 0.0);
        let exact = field(point);
        for d in 0..2 {
            worst = worst.max((s.velocity[d] - exact[d]).abs());
        }
    }
    worst
}

/// The Shepard sum smooths sin(kx) by the kernel's second moment, a factor 1 − k²σ²/2 with σ of
/// the order of h: second order in the spacing (measured: 1.3% of U at 40 particles across,
/// 0.33% at 80).
#[test]
fn a_taylor_green_field_is_read_to_second_order() {
    let (coarse, fine) = (
        taylor_green_reading_error(40),
        taylor_green_reading_error(80),
    );
    assert!(
        coarse < 0.02,
        "largest velocity error {coarse} of U at 40 across"
    );
    assert!(
        coarse / fine > 3.5,
        "errors {coarse} and {fine} at 40 and 80 across: not second order"
    );
}

/// Still water 0.5 m deep at dx = 0.025 m after 0.5 s: probes inside the water read
/// ρ0 g (H − y); a probe on the floor's face reads the pressure at the kernel-weighted centroid
/// of the fluid above it, 0.72 dx up at h/dx = 1.2 on the lattice (a Shepard sum reads a linear
/// field's value at that centroid exactly).
#[test]
fn still_water_probes_read_the_hydrostatic_pressure() {
    let text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/hydrostatic_2d.toml"),
    )
    .unwrap()
    .replace("spacing = 0.0125                # [m]", "spacing = 0.025")
        + r#"
[[probe]]
name = "deep"
point = [0.25, 0.1]
field = "pressure"

[[probe]]
name = "middle"
point = [0.2, 0.25]
field = "pressure"

[[probe]]
name = "floor"
point = [0.25, 0.0]
field = "pressure"

[[probe]]
name = "u"
point = [0.25, 0.25]
field = "velocity"

[[probe]]
name = "level"
point = [0.4, 0.0]
field = "elevation"
"#;
    let scene = scene_from_text(&text);
    let dir = TempDir::new("probes-hydrostatic");
    let summary = run_scene(&scene, dir.path(), 0.5);
    let (columns, rows) = probes::read(dir.path()).unwrap();
    assert_eq!(
        columns,
        ["time", "deep", "middle", "floor", "u_x", "u_y", "level"]
    );
    assert_eq!(rows.len() as u64, summary.steps, "one row per step");
    let last = rows.last().unwrap();
    assert_eq!(last[0], summary.time);
    let rho_g = 1000.0 * 9.81;
    let (depth, dx) = (0.5, 0.025);
    for (value, y) in [(last[1], 0.1), (last[2], 0.25), (last[3], 0.72 * dx)] {
        let exact = rho_g * (depth - y);
        assert!(
            (value - exact).abs() < 0.005 * rho_g * depth,
            "{value} Pa at y = {y} m, hydrostatic {exact} Pa"
        );
    }
    assert!(
        last[4].hypot(last[5]) < 1e-3,
        "still water moves at {last:?}"
    );
    eprintln!("level {} m", last[6]);
    assert!(
        (last[6] - depth).abs() < 0.01 * dx,
        "the gauge reads {} m",
        last[6]
    );
}

/// A wave gauge on a lattice of water (dx = 0.025 m, columns from x = −0.5 to 0.475 m, the fill
/// of the container from −0.5125 to 0.4875 m along both axes) whose top row in each column is
/// `top(column)`, with the particles `extra` accepts besides: the surface height it reads at x.
fn gauge_reading(
    top: impl Fn(i64) -> i64,
    extra: impl Fn(&[i64; 2]) -> bool,
    x: f64,
) -> Option<f64> {
    let dx = 0.025;
    let l = Lattice::<2>::part(40, dx, 1.2, |&[i, j]| j <= top(i) || extra(&[i, j]));
    let container = Aabb {
        min: vec![-20.5 * dx; 2],
        max: vec![19.5 * dx; 2],
    };
    surface_height(
        &l.particles,
        &l.particles.pos,
        &l.kernel,
        &[None, None],
        [x, 0.0],
        &container,
        dx,
    )
}

/// Across a flat surface the fluid fraction falls from 1 to 0 symmetrically about the surface,
/// half a spacing above the top row's centres, where it is half the lattice's sum: the gauge
/// reads it to round-off. Above overhanging water it reads the highest surface; over no water
/// it reads none.
#[test]
fn a_wave_gauge_reads_the_surface_half_a_spacing_above_the_top_row() {
    let dx = 0.025;
    let flat = gauge_reading(|_| 5, |_| false, 0.0).unwrap();
    assert!(
        (flat - 5.5 * dx).abs() < 1e-9 * dx,
        "flat surface read at {flat} m"
    );
    // Read between two columns too.
    let between = gauge_reading(|_| 5, |_| false, 0.3 * dx).unwrap();
    assert!(
        (between - 5.5 * dx).abs() < 1e-9 * dx,
        "read at {between} m"
    );
    // A sheet three rows thick hanging over the gauge, above the water: its top.
    let sheet = |&[i, j]: &[i64; 2]| (-8..=8).contains(&i) && (12..=14).contains(&j);
    let over = gauge_reading(|_| 5, sheet, 0.0).unwrap();
    assert!(
        (over - 14.5 * dx).abs() < 0.05 * dx,
        "overhang read at {over} m"
    );
    // A step in the surface from 5 to 9 rows between two columns: midway between them, the two
    // sides weigh alike and the gauge reads the mean level; a support away, each side's own.
    let step = |i: i64| if i < 0 { 5 } else { 9 };
    let mid = gauge_reading(step, |_| false, -0.5 * dx).unwrap();
    assert!((mid - 7.5 * dx).abs() < 1e-9 * dx, "step read at {mid} m");
    let low = gauge_reading(step, |_| false, -5.0 * dx).unwrap();
    let high = gauge_reading(step, |_| false, 5.0 * dx).unwrap();
    assert!(
        (low - 5.5 * dx).abs() < 1e-9 * dx,
        "low side read at {low} m"
    );
    assert!(
        (high - 9.5 * dx).abs() < 1e-9 * dx,
        "high side read at {high} m"
    );
    assert_eq!(gauge_reading(|_| -30, |_| false, 0.0), None, "no water");
}

/// A probe reads where the water covers it: where the fluid fraction is at least half that of
/// water filling the container there (1 inside, 1/2 on a face, 1/4 in a corner of two faces,
/// each within the lattice sum's dependence on the point's offset from the lattice, 6e-5),
/// so a point reads as wet once the free surface is above it; a point just above the surface,
/// whose support holds water all the same, reads as dry (zero).
#[test]
fn a_probe_reads_only_where_water_covers_it() {
    let dx = 0.025;
    let container = Aabb {
        min: vec![-20.5 * dx; 2],
        max: vec![19.5 * dx; 2],
    };
    let full = |x: [f64; 2]| {
        full_fraction(
            &Kernel::<2>::new(KernelKind::Quintic, dx, 1.2),
            dx,
            &container,
            &[None, None],
            x,
        )
    };
    let inside = full([0.0, 0.0]);
    assert!((inside - 1.0).abs() < 1e-4, "{inside}");
    let face = full([0.0, -20.5 * dx]);
    assert!((face - 0.5 * inside).abs() < 1e-4, "{face} on a face");
    let corner = full([-20.5 * dx, -20.5 * dx]);
    assert!(
        (corner - 0.25 * inside).abs() < 1e-4,
        "{corner} in a corner"
    );
    // Water up to 5.5 dx (its top row at 5 dx), at 1234.5 Pa.
    let mut l = Lattice::<2>::part(40, dx, 1.2, |&[_, j]| j <= 5);
    l.particles.pressure.iter_mut().for_each(|p| *p = 1234.5);
    let read = |y: f64| {
        let wet = SURFACE_FRACTION * full([0.0, y]);
        sample_at(&l, [0.0, y], wet).pressure
    };
    assert!((read(5.2 * dx) - 1234.5).abs() < 1e-9, "under the surface");
    assert_eq!(read(5.8 * dx), 0.0, "over the surface");
    // The same water on a wall's face: the floor of the container, 25.5 spacings below.
    let floor = -20.5 * dx;
    let on_face = SURFACE_FRACTION * full([0.0, floor]);
    let s = sample_at(&l, [0.0, floor], on_face);
    assert!((s.pressure - 1234.5).abs() < 1e-9, "on the floor's face");
}
