//! Hard cases that must stay numerically stable (the stabilised scheme with its default
//! settings): still water for 30 s, a violent impact with overturning, high viscosity at the
//! viscous time-step limit, large CFL numbers, a 3D dam break over an obstacle, and particle
//! disorder with and without shifting.

use crate::common::{read_frame, run_scene, scene_from_text as scene, stats_column, TempDir};
use isph::scene::Scene;
use isph::tools::validation::Case;
use std::path::Path;

const G: f64 = 9.81;

/// The width a of the column of `scenes/violent_impact_2d.toml`.
const WIDTH: f64 = 0.05715;

/// `scenes/violent_impact_2d.toml`: a column a × 2a of water at the left of a tank 4a long, so
/// that the surge hits the far wall, runs up it and overturns; at `spacing`, with `extra`
/// appended to the scene's text.
fn dam_break(spacing: f64, extra: &str) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/violent_impact_2d.toml");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut s = scene(&format!("{text}{extra}"));
    s.spacing = spacing;
    s
}

/// Σ m (|u|²/2 + g y) over the fluid of a frame, per unit mass of fluid: kinetic plus potential
/// energy [J/kg] (every particle has the same mass).
fn specific_energy(out: &Path, frame: usize) -> f64 {
    let kind: Vec<i32> = read_frame(out, frame, "kind");
    let pos: Vec<f64> = read_frame(out, frame, "position");
    let vel: Vec<f64> = read_frame(out, frame, "velocity");
    let (mut e, mut n) = (0.0, 0);
    for i in (0..kind.len()).filter(|&i| kind[i] == 0) {
        let u2: f64 = (0..3).map(|d| vel[3 * i + d].powi(2)).sum();
        e += 0.5 * u2 + G * pos[3 * i + 1];
        n += 1;
    }
    e / n as f64
}

fn fluid_count(out: &Path, frame: usize) -> usize {
    let kind: Vec<i32> = read_frame(out, frame, "kind");
    kind.iter().filter(|&&k| k == 0).count()
}

/// Face crossings per fluid particle and step: `penetrations` counts the particles a step's
/// advection put beyond a wall face, before the hard contact (`Faces::contact`) puts them
/// back. At large CFL numbers a particle can move farther than the half spacing between the
/// fluid and a face in one step, and a few cross (of 1,800 particles, CFL 0.5 on h: 2 in 1,347
/// steps, 1.0 on h: 37 in 630, 2026-12-02; on the spacing, CFL 0.75: 10 in 1,039 steps, 1.0: 40
/// in 704, 5e-6 and 3.2e-5 per particle-step, 2026-12-06); this bound (one crossing per 5,000
/// particle-steps) says the walls still stop almost every approach. Also checks that no particle is left beyond a face.
fn assert_rare_crossings(out: &Path, frames: usize, what: &str) {
    let crossings: f64 = stats_column(out, "penetrations").iter().sum();
    let steps = stats_column(out, "step").len() as f64;
    let rate = crossings / (steps * fluid_count(out, 0) as f64);
    eprintln!("{what}: {crossings} face crossings in {steps} steps, {rate:e} per particle-step");
    assert!(
        rate < 2e-4,
        "{what}: {crossings} face crossings in {steps} steps, {rate} per particle-step"
    );
    assert_eq!(fluid_count(out, frames - 1), fluid_count(out, 0));
}

fn assert_no_penetration(out: &Path) {
    let p = stats_column(out, "penetrations");
    assert!(
        p.iter().all(|&p| p == 0.0),
        "penetrations: max {}",
        p.iter().cloned().fold(0.0, f64::max)
    );
}

/// 30 s, not the 20: two surface modes grew in this tank before their causes were
/// found. Without the near-surface pressure reference (`step::corrector::pressure_references`)
/// it sloshed between 25 and 30 s (docs/stabilisation.md, "The pressure reference near the free
/// surface"); with the surface rows' pressure taken where the particles start the step, not at
/// the midpoint of the drift (`ppe::surface_depth`), a surface wave grew at 0.27/s from the
/// solver's noise (docs/stabilisation.md, "The surface row at the midpoint of the drift"): the
/// largest speed over 20–30 s was 180 times the one over 1–10 s at tolerance 1e-6, 1,700 times
/// at 1e-4. A third was the solver's stop: a solve whose warm start already met the tolerance
/// stopped at once, and the last pressure's error, the same in every step, lifted the whole
/// water off the floor at a steady 4.4e-6 m/s (at tolerance 1e-4 its mean height rose by 4.7e-4 of itself
/// over 5–30 s and about 1e-3 by 60 s, where it stayed; the largest speed 9.9e-5 m/s over
/// 1–10 s and 1.25e-4 over 20–30 s). Every solve now takes an iteration (`krylov`,
/// `Run::after_residual`). The test asks no growth (the largest speed over 20–30 s at most
/// twice the one over 1–10 s), 1e-4 √(gH) = 2.2e-4 m/s throughout and 1e-5 √(gH) from 1 s on,
/// and the mean height within 2e-5 of itself over 5–30 s. Measured at the default tolerance 1e-4: 2.0e-5
/// m/s in the first second, 2.6e-6 m/s over 1–10 s and over 20–30 s, the mean height 5.6e-7
/// higher; the pressure at 30 s, the bottom's and the rms error below the surface layer both
/// 5.1e-5 of ρgH (2.2e-4 before), bounded at 2e-3 (2026-12-06).
#[test]
fn still_water_stays_at_rest_for_30_s() {
    // hydrostatic_2d.toml: 40 particles deep, H = 0.5 m.
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/hydrostatic_2d.toml"),
    )
    .unwrap();
    let s = scene(&text.replace("output_interval = 0.05", "output_interval = 5.0"));
    let (dx, depth) = (s.spacing, s.blocks[0].region.max[1]);
    assert!(depth / dx >= 40.0);
    let dir = TempDir::new("still_water");
    let summary = run_scene(&s, dir.path(), 30.0);
    let out = dir.path();
    let last = summary.frames.len() - 1;
    let rho_g_h = s.fluids[0].density * G * depth;
    let kind: Vec<i32> = read_frame(out, last, "kind");
    let pos: Vec<f64> = read_frame(out, last, "position");
    let pressure: Vec<f64> = read_frame(out, last, "pressure");
    let fluid: Vec<usize> = (0..kind.len()).filter(|&i| kind[i] == 0).collect();
    let y = |i: usize| pos[3 * i + 1];
    // Bottom pressure: the lowest row, carried to y = 0 by its own hydrostatic gradient.
    let bottom: Vec<f64> = fluid
        .iter()
        .filter(|&&i| y(i) < dx)
        .map(|&i| pressure[i] + s.fluids[0].density * G * y(i))
        .collect();
    let bottom = bottom.iter().sum::<f64>() / bottom.len() as f64;
    eprintln!("30 s: bottom {:e} of ρgH", bottom / rho_g_h - 1.0);
    assert!(
        (bottom / rho_g_h - 1.0).abs() < 2e-3,
        "bottom pressure {bottom} Pa against ρgH = {rho_g_h}"
    );
    let deep: Vec<f64> = fluid
        .iter()
        .filter(|&&i| depth - y(i) > 0.15 * depth)
        .map(|&i| pressure[i] - s.fluids[0].density * G * (depth - y(i)))
        .collect();
    let rms = (deep.iter().map(|e| e * e).sum::<f64>() / deep.len() as f64).sqrt();
    eprintln!("30 s: rms {:e} of ρgH", rms / rho_g_h);
    assert!(
        rms < 2e-3 * rho_g_h,
        "rms pressure noise {} of ρgH",
        rms / rho_g_h
    );
    let (time, speed) = (stats_column(out, "time"), stats_column(out, "max_speed"));
    let largest = |from: f64, to: f64| {
        (0..time.len())
            .filter(|&k| time[k] >= from && time[k] <= to)
            .map(|k| speed[k])
            .fold(0.0, f64::max)
    };
    let (early, late) = (largest(1.0, 10.0), largest(20.0, 30.0));
    eprintln!("largest speed {early:e} m/s over 1–10 s, {late:e} over 20–30 s");
    assert!(
        late < 2.0 * early,
        "the largest speed grew from {early} m/s over 1–10 s to {late} over 20–30 s"
    );
    let max_speed = largest(0.0, 30.0);
    assert!(
        max_speed < 1e-4 * (G * depth).sqrt(),
        "max speed {max_speed} m/s"
    );
    let settled = largest(1.0, 30.0);
    assert!(
        settled < 1e-5 * (G * depth).sqrt(),
        "max speed {settled} m/s over 1–30 s"
    );
    let mean_height = |frame: usize| {
        let kind: Vec<i32> = read_frame(out, frame, "kind");
        let pos: Vec<f64> = read_frame(out, frame, "position");
        let heights: Vec<f64> = (0..kind.len())
            .filter(|&i| kind[i] == 0)
            .map(|i| pos[3 * i + 1])
            .collect();
        heights.iter().sum::<f64>() / heights.len() as f64
    };
    // From 5 s on (frame 1): the lattice's settling under its weight is over by then.
    let rise = mean_height(last) / mean_height(1) - 1.0;
    eprintln!("the water's mean height rose by {rise:e} over 5–30 s");
    assert!(rise.abs() < 2e-5, "the water's mean height rose by {rise}");
    let level = |frame: usize| {
        let kind: Vec<i32> = read_frame(out, frame, "kind");
        let pos: Vec<f64> = read_frame(out, frame, "position");
        (0..kind.len())
            .filter(|&i| kind[i] == 0)
            .map(|i| pos[3 * i + 1])
            .fold(f64::MIN, f64::max)
    };
    assert!(
        (level(last) - level(0)).abs() < dx,
        "surface level moved {} m",
        level(last) - level(0)
    );
    assert_no_penetration(out);
}

/// The violent impact of the issue: the column at `per_width` particles across, run to
/// t = 8 √(H/g) with `extra` appended to the scene; returns the run's directory, its frame count
/// and the scene it ran.
fn violent_impact(per_width: f64, extra: &str, name: &str) -> (TempDir, usize, Scene) {
    let s = dam_break(WIDTH / per_width, extra);
    let dir = TempDir::new(name);
    let until = 8.0 * (2.0 * WIDTH / G).sqrt();
    let frames = run_scene(&s, dir.path(), until).frames.len();
    (dir, frames, s)
}

/// The violent impact at a/40. After the plunge the flow is chaotic, so the worst step
/// is one draw of a trajectory: a step cut short to land on a frame, or any change to the
/// arithmetic, draws another. Measured over perturbed trajectories (frames every 0.05 s, the
/// test, and 0.04, 0.03, 0.025 s) at the defaults (CFL 0.4, α = 0.3): the worst step is
/// 0.70–0.80% over four, the mean over the steps 0.37–0.39%; at α = 0.1 the bound was broken on
/// three of four (0.89–1.37%) (docs/stabilisation.md, "The violent impact over its
/// trajectories"). With the LES's wall layer (2026-12-07) the four read 0.74–0.80% and
/// 0.34–0.35%, the test's draw 0.74% and 0.34%.
#[test]
fn violent_impact_keeps_density_and_volume() {
    let (dir, frames, scene) = violent_impact(40.0, "", "impact");
    let out = dir.path();
    let density = isph::tools::validation::measure(Case::Density, &scene, out).unwrap();
    let (worst, average) = (density.error, density.details[0].1);
    assert!(worst < 0.01, "mean density error reached {worst}");
    assert!(
        average < 0.006,
        "mean density error {average} on average over the steps"
    );
    assert_no_penetration(out);
    // Volume: every particle stands for dx² of water at ρ0, none is lost, and the bulk's
    // density, the mean of ρ/ρ0 − 1 (`compression`; the density error above also counts the
    // summation's scatter about it), stays within 0.2% of ρ0 on average over the steps
    // (measured: |compression| 0.096% on average, all of it expansion, 0.41% at the largest
    // step).
    assert_eq!(fluid_count(out, frames - 1), fluid_count(out, 0));
    let compression: Vec<f64> = stats_column(out, "compression")
        .into_iter()
        .filter(|c| !c.is_nan())
        .collect();
    let bulk = compression.iter().map(|c| c.abs()).sum::<f64>() / compression.len() as f64;
    assert!(
        bulk < 0.002,
        "the bulk's density off ρ0 by {bulk} on average"
    );
    // No energy is created: the scheme may only dissipate.
    let (e0, e1) = (specific_energy(out, 0), specific_energy(out, frames - 1));
    assert!(e1 <= e0, "specific energy grew from {e0} to {e1} J/kg");
}

/// Without the density-invariance term of Eq. (6) (α = 0) the projection's drift changes the
/// water's volume, and `compression`, the mean of ρ/ρ0 − 1 over the full supports, reads it:
/// at a/20 the water expands by 5% within 0.4 s (measured −5.07% at t = 0.38 s, where the
/// density error, mean |ρ/ρ0 − 1|, is 5.07%: the drift is the whole error). With the term the
/// flow at a/40 stays within 0.2% on average (`violent_impact_keeps_density_and_volume`).
#[test]
fn without_the_density_correction_the_compression_column_reads_the_volume_drift() {
    let s = dam_break(WIDTH / 20.0, "\n[solver]\nalpha = 0.0\n");
    let dir = TempDir::new("impact_alpha0");
    run_scene(&s, dir.path(), 0.4);
    let (compression, error) = (
        stats_column(dir.path(), "compression"),
        stats_column(dir.path(), "density_error"),
    );
    let (k, drift) = compression
        .iter()
        .enumerate()
        .filter(|(_, c)| !c.is_nan())
        .map(|(k, c)| (k, c.abs()))
        .fold((0, 0.0), |best, x| if x.1 > best.1 { x } else { best });
    // Expanded: the column is negative where the water's volume exceeds its rest volume.
    assert!(
        compression[k] < -0.02,
        "the volume drifted by {} at most",
        compression[k]
    );
    assert!(
        drift >= 0.9 * error[k],
        "compression {} against density error {} at the largest drift",
        compression[k],
        error[k]
    );
}

/// The violent impact at a/20 with and without shifting: shifting keeps the particles ordered
/// through the plunge. The mean disorder over the second half is the measure: 0.074–0.083 over
/// twelve trajectories (frames every 0.05, 0.04, 0.03 and 0.025 s; α = 0.1, 0.2 and 0.3), and
/// about 5 times as much without shifting (0.394 against 0.072 on one; 0.412 against 0.075, with
/// 5 steps of 1,041 where the torn water left no particle a full support). Its worst step is one
/// draw of the chaotic flow, 0.146–0.215 over the same twelve: bounded only against a blow-up.
#[test]
fn shifting_keeps_the_violent_impact_ordered() {
    let (shifted, _, _) = violent_impact(20.0, "", "impact_shifted");
    let disorder = stats_column(shifted.path(), "disorder");
    let half = disorder.len() / 2;
    let shifted_max = disorder[half..].iter().cloned().fold(0.0, f64::max);
    let (plain, _, _) = violent_impact(
        20.0,
        "[effects.shifting]\nenabled = false\n",
        "impact_unshifted",
    );
    // Over the steps that measured it: without shifting the water can tear apart so that no
    // particle has a full support, and the step's disorder is NaN (nothing measured).
    let second_half_mean = |v: &[f64]| {
        let measured: Vec<f64> = v[v.len() / 2..]
            .iter()
            .copied()
            .filter(|d| !d.is_nan())
            .collect();
        measured.iter().sum::<f64>() / measured.len() as f64
    };
    let unshifted_end = second_half_mean(&stats_column(plain.path(), "disorder"));
    let shifted_end = second_half_mean(&disorder);
    assert!(
        shifted_end < 0.1,
        "disorder with shifting {shifted_end} on average over the second half"
    );
    assert!(
        shifted_max < 0.25,
        "disorder with shifting reached {shifted_max}"
    );
    assert!(
        unshifted_end > 1.5 * shifted_end,
        "disorder without shifting {unshifted_end}, with {shifted_end}"
    );
}

/// A 0.2 m × 0.2 m column collapsing in a 1.2 m tank at dx = 0.01 m with viscosity `nu`, run to
/// `until` (before the surge reaches the far wall): the flow stays smooth, no particle faster
/// than the inviscid dam-break front, 2√(gH) (Ritter), which viscosity can only slow down. (Free
/// fall from the column's top, √(2gH), is below it: the front of the collapsing column is
/// pushed by the pressure behind it, and at ν = 1e-3 it runs at 2.1 m/s > √(2gH) = 1.98 m/s.)
fn viscous_collapse(nu: f64, until: f64) {
    let s = scene(&format!(
        "[simulation]\ndimensions = 2\nspacing = 0.01\nend_time = {until}\n\
         output_interval = {until}\ngravity = [0.0, -9.81]\n\
         [[fluid]]\nname = \"syrup\"\ndensity = 1000.0\nviscosity = {nu}\n\
         [[fluid_block]]\nfluid = \"syrup\"\nmin = [0.0, 0.0]\nmax = [0.2, 0.2]\n\
         [container]\nmin = [0.0, 0.0]\nmax = [1.2, 0.4]\n"
    ));
    let dir = TempDir::new(&format!("viscous_{nu}"));
    run_scene(&s, dir.path(), until);
    let out = dir.path();
    let h = s.smoothing_length();
    let viscous_limit = 0.125 * h * h / nu;
    if viscous_limit < 0.25 * (h / G).sqrt() {
        // The viscous limit is the tightest: the steps run at it.
        let dt = stats_column(out, "dt");
        let at_limit = dt.iter().filter(|&&dt| dt > 0.99 * viscous_limit).count();
        assert!(
            at_limit > dt.len() / 2,
            "ν = {nu}: {at_limit} of {} steps at the viscous limit",
            dt.len()
        );
    }
    let ritter = 2.0 * (G * 0.2).sqrt();
    let max_speed = stats_column(out, "max_speed")
        .into_iter()
        .fold(0.0, f64::max);
    assert!(
        max_speed < ritter,
        "ν = {nu}: max speed {max_speed} m/s above 2√(gH) = {ritter}"
    );
    assert_no_penetration(out);
}

#[test]
fn high_viscosity_stays_smooth() {
    viscous_collapse(1e-3, 0.4);
    viscous_collapse(1e-1, 0.1);
    viscous_collapse(1.0, 0.03);
}

/// The violent impact at CFL 0.75 and 1.0 on the spacing (the default is 0.4): no NaN, rare
/// face crossings, no energy created, and the mean density error bounded — 0.96% on average over
/// the steps at 0.75, 1.33% at 1.0 (a larger step lets more compression through before the
/// projection catches it): asserted below 1% and 2.5%. The
/// test guards the near-surface pressure reference (`step::pressure_reference`) and the cap on
/// the shift's diffusion number (`shifting`), without which the mean is larger
/// (docs/stabilisation.md, "The pressure reference near the free surface" and "Particle
/// shifting").
#[test]
fn large_cfl_numbers_stay_stable() {
    for (cfl, bound) in [(0.75, 0.01), (1.0, 0.025)] {
        let s = dam_break(WIDTH / 30.0, &format!("[solver]\ncfl = {cfl}\n"));
        let dir = TempDir::new(&format!("cfl_{cfl}"));
        let until = 8.0 * (2.0 * WIDTH / G).sqrt();
        let frames = run_scene(&s, dir.path(), until).frames.len();
        let out = dir.path();
        assert_rare_crossings(out, frames, &format!("CFL {cfl}"));
        let (e0, e1) = (specific_energy(out, 0), specific_energy(out, frames - 1));
        assert!(
            e1 <= e0,
            "CFL {cfl}: specific energy grew from {e0} to {e1} J/kg"
        );
        let density = stats_column(out, "density_error");
        let mean = density.iter().sum::<f64>() / density.len() as f64;
        assert!(mean < bound, "CFL {cfl}: density error {mean} on average");
    }
}

/// The 3D dam break over an obstacle standing on the floor, coarse (dx = 0.05 m, 480 fluid
/// particles): no particle crosses a wall face. It guards the faces' geometry: the obstacle's
/// face on the floor is no face, its edge particles take the normalised sum of their faces'
/// normals, and the kinematic condition follows the faces, not the nearest wall particle's
/// normal (docs/stabilisation.md, "The kinematic wall condition and wall crossings").
#[test]
fn dam_break_3d_with_obstacle_runs_1_s() {
    let s = scene(
        "[simulation]\ndimensions = 3\nspacing = 0.05\nend_time = 1.0\noutput_interval = 0.5\n\
         gravity = [0.0, 0.0, -9.81]\n\
         [[fluid]]\nname = \"water\"\ndensity = 1000.0\nviscosity = 1.0e-6\n\
         [[fluid_block]]\nfluid = \"water\"\nmin = [0.0, 0.0, 0.0]\nmax = [0.3, 0.4, 0.5]\n\
         [[obstacle]]\nmin = [0.6, 0.1, 0.0]\nmax = [0.8, 0.3, 0.2]\n\
         [container]\nmin = [0.0, 0.0, 0.0]\nmax = [1.0, 0.4, 0.6]\n",
    );
    let dir = TempDir::new("obstacle_3d");
    let summary = run_scene(&s, dir.path(), 1.0);
    assert!((summary.time - 1.0).abs() < 1e-12);
    assert_no_penetration(dir.path());
    let frames = summary.frames.len();
    assert_eq!(
        fluid_count(dir.path(), frames - 1),
        fluid_count(dir.path(), 0)
    );
    let speed = stats_column(dir.path(), "max_speed");
    assert!(speed.iter().all(|v| v.is_finite()));
}
