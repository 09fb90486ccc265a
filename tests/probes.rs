//! `[[probe]]` and probes.csv: the Shepard interpolation reads a constant field exactly and a
//! smooth one to the kernel's smoothing; still water's probes read ρ0 g (H − y); a probe on a
//! wall's face reads the pressure at the centroid of the fluid beside it; probes.csv has its
//! columns and one row per step. (Thread counts and resume: tests/determinism.rs and
//! tests/checkpoint.rs; bad probes: tests/bad_input.rs.)

use crate::common::{run_scene, scene_from_text, Lattice, TempDir};
use isph::io::probes;
use isph::sph::probe::sample;
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

#[test]
fn a_uniform_flow_is_read_exactly_and_no_fluid_reads_zero() {
    let l = lattice_with(|_| [0.7, -0.3], |_| 1234.5);
    for point in [[0.0, 0.0], [0.0113, -0.2], [0.49, 0.49]] {
        let s = sample(&l.particles, &l.kernel, &[None, None], point);
        assert!((s.velocity[0] - 0.7).abs() < 1e-13, "{point:?}: {s:?}");
        assert!((s.velocity[1] + 0.3).abs() < 1e-13, "{point:?}: {s:?}");
        assert!((s.pressure - 1234.5).abs() < 1e-9, "{point:?}: {s:?}");
    }
    // The lattice ends at 0.475 m; the support is 3h = 0.09 m.
    let far = sample(&l.particles, &l.kernel, &[None, None], [0.6, 0.0]);
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
        let s = sample(&l.particles, &l.kernel, &[None, None], point);
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
"#;
    let scene = scene_from_text(&text);
    let dir = TempDir::new("probes-hydrostatic");
    let summary = run_scene(&scene, dir.path(), 0.5);
    let (columns, rows) = probes::read(dir.path()).unwrap();
    assert_eq!(columns, ["time", "deep", "middle", "floor", "u_x", "u_y"]);
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
}
