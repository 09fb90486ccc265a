//! Rigid bodies (docs/bodies.md): exact free fall and rigidity, conserved angular momentum,
//! Archimedes' draft, a heavy body resting on the floor, fluid displaced at the start, and
//! bit-identical runs across thread counts and restarts.

use crate::common::{read_frame, run_scene, scene_from_text, stats_column, tank, TempDir};
use isph::io::bodies_csv;
use std::path::Path;

/// bodies.csv of `out`, body `b`: (time, numbers x … tz).
fn rows(out: &Path, b: usize) -> Vec<(f64, Vec<f64>)> {
    bodies_csv::read(out)
        .unwrap()
        .into_iter()
        .filter(|r| r.1 == b)
        .map(|(t, _, n)| (t, n))
        .collect()
}

/// Column offsets in a row's numbers (after time, body and name).
const Y: usize = 1;
const QZ: usize = 6;
const VX: usize = 7;
const VY: usize = 8;
const FX: usize = 13;
const FY: usize = 14;
const TZ: usize = 18;

/// The positions of the particles of kind 2 (bodies) in frame `frame`.
fn body_positions(out: &Path, frame: usize) -> Vec<[f64; 3]> {
    let kind: Vec<i32> = read_frame(out, frame, "kind");
    let pos: Vec<f64> = read_frame(out, frame, "position");
    (0..kind.len())
        .filter(|&i| kind[i] == 2)
        .map(|i| [pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]])
        .collect()
}

/// The height of the lowest body particle in frame `frame`.
fn lowest_body_particle(out: &Path, frame: usize) -> f64 {
    body_positions(out, frame)
        .iter()
        .map(|x| x[1])
        .fold(f64::MAX, f64::min)
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|d| (a[d] - b[d]).powi(2)).sum::<f64>().sqrt()
}

/// The smallest distance between two of `points` that lie less than `within` apart along x
/// (f64::MAX if none do): every pair closer than `within` is among them.
fn closest_pair_within(points: &[[f64; 3]], within: f64) -> f64 {
    let mut sorted = points.to_vec();
    sorted.sort_by(|a, b| a[0].total_cmp(&b[0]));
    sorted
        .iter()
        .enumerate()
        .flat_map(|(k, a)| {
            sorted[k + 1..]
                .iter()
                .take_while(move |b| b[0] - a[0] < within)
                .map(move |b| distance(*a, *b))
        })
        .fold(f64::MAX, f64::min)
}

#[test]
fn a_body_in_the_air_falls_freely_to_round_off_and_keeps_its_shape() {
    let dir = TempDir::new("bodies-fall");
    let body = r#"[[body]]
shape = "circle"
center = [0.5, 0.7]
radius = 0.05
density = 800.0
velocity = [0.3, 0.0]
"#;
    let scene = scene_from_text(&tank(2, 0.01, [1.0, 1.0, 0.0], 0.1, 0.02, body));
    run_scene(&scene, dir.path(), 0.2);
    let rows = rows(dir.path(), 0);
    let (y0, g) = (rows[0].1[Y], 9.81);
    assert_eq!(rows.len(), 11);
    for (t, r) in &rows {
        // The trapezoid of the centre is exact under a constant force (docs/bodies.md).
        assert!(
            (r[Y] - (y0 - 0.5 * g * t * t)).abs() < 1e-12,
            "t = {t}: y = {}",
            r[Y]
        );
        assert!((r[VY] + g * t).abs() < 1e-12, "t = {t}: vy = {}", r[VY]);
        assert!(
            (r[0] - (0.5 + 0.3 * t)).abs() < 1e-12,
            "t = {t}: x = {}",
            r[0]
        );
    }
    // Rigid to round-off: every distance from the first particle, at every frame.
    let first = body_positions(dir.path(), 0);
    for frame in 1..rows.len() {
        let now = body_positions(dir.path(), frame);
        for k in 1..first.len() {
            let (a, b) = (distance(first[0], first[k]), distance(now[0], now[k]));
            assert!((a - b).abs() < 1e-12 * a, "frame {frame}: {a} became {b}");
        }
    }
}

#[test]
fn a_body_under_a_constant_torque_turns_by_half_its_angular_acceleration_times_t_squared() {
    // A disc given the same angular impulse τ Δt at every step from rest (`Bodies::advance`, the
    // momentum balance of Eq. 15): ω = α t with α = τ/I, and the angle after the steps α t²/2
    // to round-off, as the centre under a constant force (the trapezoid). A turn of ωⁿ⁺¹ Δt
    // per step led that by α Δt t/2, half a step's turn, at every frame.
    let body =
        "[[body]]\nshape = \"circle\"\ncenter = [0.5, 0.7]\nradius = 0.05\ndensity = 800.0\n";
    let scene = scene_from_text(&tank(2, 0.01, [1.0, 1.0, 0.0], 0.1, 0.02, body));
    let mut bodies = isph::Simulation::<2>::new(&scene).unwrap().bodies;
    let (alpha, dt, steps) = (2.0, 1e-3, 100);
    let torque = alpha * bodies.bodies[0].inertia[2][2];
    let z = |v: f64| [0.0, 0.0, v];
    for k in 0..steps {
        let (impulses, forces) = ([[0.0; 3], z(torque * dt)], [[0.0; 3], z(torque)]);
        bodies.advance(0, impulses, forces, [[0.0; 3]; 2], false, k as f64 * dt, dt);
    }
    let t = steps as f64 * dt;
    let [qw, _, _, qz] = bodies.bodies[0].state.orientation.0;
    let angle = 2.0 * qz.atan2(qw);
    assert!(
        (angle - 0.5 * alpha * t * t).abs() < 1e-12,
        "turned by {angle} rad in {t} s, against α t²/2 = {}",
        0.5 * alpha * t * t
    );
}

#[test]
fn a_spinning_body_in_the_air_keeps_its_angular_momentum_and_shape() {
    let dir = TempDir::new("bodies-spin");
    // A 3D box spun about an axis that is no principal axis: ω changes, L does not.
    let body = r#"[[body]]
shape = "box"
min = [0.2, 0.25, 0.5]
max = [0.4, 0.35, 0.56]
density = 700.0
angular_velocity = [3.0, 5.0, 1.0]
"#;
    let scene = scene_from_text(&tank(3, 0.02, [0.6, 0.6, 0.9], 0.06, 0.02, body));
    run_scene(&scene, dir.path(), 0.1);
    let first = body_positions(dir.path(), 0);
    let frames = 5;
    for frame in 1..=frames {
        let now = body_positions(dir.path(), frame);
        for k in 1..first.len() {
            let (a, b) = (distance(first[0], first[k]), distance(now[0], now[k]));
            assert!((a - b).abs() < 1e-12 * a, "frame {frame}: {a} became {b}");
        }
    }
    let rows = rows(dir.path(), 0);
    let w0 = &rows[0].1[9..12];
    let turned = rows
        .iter()
        .any(|(_, r)| (0..3).any(|d| (r[9 + d] - w0[d]).abs() > 1e-3));
    assert!(
        turned,
        "ω of a box spun off its principal axes stayed {w0:?}"
    );
    // L itself is in the checkpoint: the angular momentum of the final state.
    let ckpt = isph::io::checkpoint_folder::list(&isph::io::checkpoint_folder::folder(dir.path()))
        .unwrap();
    let checkpoint = isph::io::checkpoint::Checkpoint::open(&ckpt.last().unwrap().1).unwrap();
    let mut sim = isph::Simulation::<3>::new(&scene).unwrap();
    let l0 = sim.bodies.bodies[0].state.angular_momentum;
    checkpoint.restore_bodies(&mut sim.bodies).unwrap();
    let l = sim.bodies.bodies[0].state.angular_momentum;
    let size = l0.iter().map(|x| x * x).sum::<f64>().sqrt();
    for d in 0..3 {
        assert!((l[d] - l0[d]).abs() < 1e-12 * size, "L {l:?} from {l0:?}");
    }
}

/// The mean of column `c` of body 0's rows with `from` ≤ t.
fn mean_after(rows: &[(f64, Vec<f64>)], c: usize, from: f64) -> f64 {
    let late: Vec<f64> = rows
        .iter()
        .filter(|r| r.0 >= from)
        .map(|r| r.1[c])
        .collect();
    late.iter().sum::<f64>() / late.len() as f64
}

#[test]
fn a_box_at_half_the_density_of_water_floats_at_half_its_height() {
    let dir = TempDir::new("bodies-float");
    // 0.2 × 0.1 m at s = 0.5: upright-stable (b/h = 2 > 1.22), draft s h = 0.05 m. It starts at
    // that draft in water 0.3 m deep: the level stays 0.3 m, so the centre belongs at 0.3 m.
    let body = r#"[[body]]
shape = "box"
min = [0.4, 0.25]
max = [0.6, 0.35]
density = 500.0
"#;
    let scene = scene_from_text(&tank(2, 0.01, [1.0, 0.6, 0.0], 0.3, 0.02, body));
    run_scene(&scene, dir.path(), 3.0);
    let rows = rows(dir.path(), 0);
    // The draft against the water's own level far from the box, averaged over the heave after
    // the start.
    let frames = rows.len();
    let drafts: Vec<f64> = ((frames / 3)..frames)
        .map(|frame| draft(dir.path(), frame, 2, 0.01, |x| x[0] < 0.2 || x[0] > 0.8))
        .collect();
    let draft = drafts.iter().sum::<f64>() / drafts.len() as f64;
    let error = draft / 0.05 - 1.0;
    eprintln!(
        "draft {draft} ({:+.2}%), fy {}",
        100.0 * error,
        mean_after(&rows, FY, 1.0)
    );
    // First order in the spacing: 5 particles in the draft here (docs/bodies.md, "Archimedes").
    assert!(
        error.abs() < 0.08,
        "draft {draft} m against 0.05 m ({:+.1}%)",
        100.0 * error
    );
    let weight = 500.0 * 0.02 * 9.81;
    let fy = mean_after(&rows, FY, 1.0);
    assert!(
        (fy / weight - 1.0).abs() < 0.05,
        "fluid force {fy} N/m against the weight {weight}"
    );
}

/// A box's draft in frame `frame` of a `dims`-dimensional run at spacing `dx`: the level of the
/// water where `far` holds (the mean over the columns there of their top particle, plus half a
/// spacing: the surface lies half a spacing above the top particles) less the box's keel (its
/// lowest particle less half a spacing).
fn draft(out: &Path, frame: usize, dims: usize, dx: f64, far: impl Fn(&[f64]) -> bool) -> f64 {
    let kind: Vec<i32> = read_frame(out, frame, "kind");
    let pos: Vec<f64> = read_frame(out, frame, "position");
    let up = dims - 1;
    let mut tops = std::collections::BTreeMap::new();
    for i in (0..kind.len()).filter(|&i| kind[i] == 0 && far(&pos[3 * i..3 * i + 3])) {
        let column: Vec<i64> = (0..up)
            .map(|d| (pos[3 * i + d] / dx).floor() as i64)
            .collect();
        let top = tops.entry(column).or_insert(f64::MIN);
        *top = pos[3 * i + up].max(*top);
    }
    let level = tops.values().sum::<f64>() / tops.len() as f64 + 0.5 * dx;
    let keel = (0..kind.len())
        .filter(|&i| kind[i] == 2)
        .map(|i| pos[3 * i + up])
        .fold(f64::MAX, f64::min)
        - 0.5 * dx;
    level - keel
}

/// The draft of a 3D box 0.2 × 0.2 × 0.1 m at s = 0.5 (b/h = 2, upright-stable), started at its
/// draft 0.05 m in water 0.12 m deep in a tank 0.3 m square, at spacing `dx`, averaged over the
/// frames from 0.5 s to `until` against the level in the 0.05 m gaps around it, within
/// `bound` (relative) of the draft s h.
fn assert_box_draft_3d(dx: f64, until: f64, bound: f64) {
    let dir = TempDir::new("bodies-float-3d");
    let body = "[[body]]\nshape = \"box\"\nmin = [0.05, 0.05, 0.07]\nmax = [0.25, 0.25, 0.17]\ndensity = 500.0\n";
    let scene = scene_from_text(&tank(3, dx, [0.3, 0.3, 0.25], 0.12, 0.05, body));
    run_scene(&scene, dir.path(), until);
    let rows = rows(dir.path(), 0);
    let gap = |x: &[f64]| x[..2].iter().any(|&c| !(0.05..=0.25).contains(&c));
    let drafts: Vec<f64> = (0..rows.len())
        .filter(|&k| rows[k].0 >= 0.5)
        .map(|frame| draft(dir.path(), frame, 3, dx, gap))
        .collect();
    let mean = drafts.iter().sum::<f64>() / drafts.len() as f64;
    eprintln!(
        "dx {dx}: draft {mean} ({:+.2}%), frames {drafts:?}",
        100.0 * (mean / 0.05 - 1.0)
    );
    assert!(
        (mean / 0.05 - 1.0).abs() < bound,
        "draft {mean} m against 0.05 m"
    );
}

#[test]
fn a_3d_box_at_half_the_density_of_water_floats_at_half_its_height() {
    // First order in the spacing: 5 particles in the draft here, −4.9% measured (docs/bodies.md,
    // "Archimedes"); `…_at_ten_particles_in_the_draft` holds the 3% asked at 10.
    assert_box_draft_3d(0.01, 1.0, 0.08);
}

#[test]
#[ignore = "about 25 minutes on 2 cores: run with --ignored"]
fn a_3d_box_at_half_the_density_of_water_floats_at_half_its_height_at_ten_particles_in_the_draft() {
    assert_box_draft_3d(0.005, 2.0, 0.03);
}

#[test]
fn a_body_denser_than_water_sinks_and_rests_on_the_floor() {
    let dir = TempDir::new("bodies-sink");
    let body = r#"[[body]]
shape = "circle"
center = [0.3, 0.2]
radius = 0.04
density = 1500.0
friction = 0.5
"#;
    let scene = scene_from_text(&tank(2, 0.01, [0.6, 0.4, 0.0], 0.3, 0.01, body));
    run_scene(&scene, dir.path(), 2.0);
    let rows = rows(dir.path(), 0);
    // At rest on the floor over the last 0.5 s: its lowest particles half a spacing above it
    // (as the lattice put the first layer of fluid at t = 0), lifted by at most 0.15 spacing as
    // the pressure's noise rocks it on its lattice polygon (docs/bodies.md, "Measured"), and held
    // in place by its friction.
    let late: Vec<usize> = (0..rows.len()).filter(|&k| rows[k].0 >= 1.5).collect();
    for &k in &late {
        let lowest = lowest_body_particle(dir.path(), k);
        assert!(
            (0.005 - 1e-9..0.005 + 0.0015).contains(&lowest),
            "t = {}: lowest body particle at {lowest}",
            rows[k].0
        );
    }
    // Still: it rests, held by its contacts (`bodies::contact`, 3.), though the water its fall
    // set sloshing still moves at 0.25 m/s and now and then rocks it on its lattice polygon past
    // what its weight and friction hold. Measured on four trajectories (frames every 0.01,
    // 0.02, 0.025 and 0.05 s): 0, 3.9e-4, 0 and 0.9e-4 m/s on average over 1.5–2 s; before it
    // rested, 0.0016–0.0072 m/s, and 0.015 with one contact impulse at the middle of the points
    // that touch.
    let speed = late
        .iter()
        .map(|&k| rows[k].1[VX].hypot(rows[k].1[VY]))
        .sum::<f64>()
        / late.len() as f64;
    assert!(
        speed < 0.001,
        "it moves at {speed} m/s on average over 1.5–2 s"
    );
    let drift = rows[*late.last().unwrap()].1[0] - rows[late[0]].1[0];
    // Frictionless, it slides off at a few cm/s; held, it creeps as it rocks (measured 0.3 and
    // 1.6 mm in 0.5 s in two builds whose rounding differed).
    assert!(drift.abs() < 0.0025, "it slid {drift} m in 0.5 s");
    // No fluid particle ever inside the body.
    for frame in 0..rows.len() {
        let centre = [rows[frame].1[0], rows[frame].1[Y]];
        let kind: Vec<i32> = read_frame(dir.path(), frame, "kind");
        let pos: Vec<f64> = read_frame(dir.path(), frame, "position");
        let nearest = (0..kind.len())
            .filter(|&i| kind[i] == 0)
            .map(|i| {
                ((pos[3 * i] - centre[0]).powi(2) + (pos[3 * i + 1] - centre[1]).powi(2)).sqrt()
            })
            .fold(f64::MAX, f64::min);
        assert!(nearest >= 0.04, "frame {frame}: a fluid particle {nearest} m from the centre of a body of radius 0.04 m");
    }
}

#[test]
fn a_body_as_dense_as_water_stays_at_rest() {
    let dir = TempDir::new("bodies-neutral");
    let body = r#"[[body]]
shape = "circle"
center = [0.3, 0.15]
radius = 0.05
density = 1000.0
"#;
    let scene = scene_from_text(&tank(2, 0.01, [0.6, 0.4, 0.0], 0.3, 0.05, body));
    run_scene(&scene, dir.path(), 2.0);
    let rows = rows(dir.path(), 0);
    // Within 1e-3 √(gD) = 0.99e-3 m/s of rest over 2 s (measured 5.5e-5 m/s at most; the
    // water around it 3e-4 m/s).
    let bound = 1e-3 * (9.81f64 * 0.1).sqrt();
    for (t, r) in &rows {
        let speed = r[VX].hypot(r[VY]);
        assert!(
            speed < bound,
            "t = {t}: a neutral body moves at {speed} m/s (bound {bound})"
        );
    }
}

#[test]
fn a_body_displaces_the_fluid_it_is_placed_in() {
    let body = r#"[[body]]
shape = "circle"
center = [0.3, 0.15]
radius = 0.05
density = 1000.0
"#;
    let with = isph::fill::build::<2>(&scene_from_text(&tank(
        2,
        0.01,
        [0.6, 0.4, 0.0],
        0.3,
        0.05,
        body,
    )));
    let without = isph::fill::build::<2>(&scene_from_text(&tank(
        2,
        0.01,
        [0.6, 0.4, 0.0],
        0.3,
        0.05,
        "",
    )));
    // The lattice points inside the circle become the body's; the water keeps every other one,
    // the nearest a spacing from a body particle (no holes beside a curved surface).
    let inside = (0..60 * 30)
        .filter(|k| {
            ((0.005 + 0.01 * (k % 60) as f64 - 0.3).powi(2)
                + (0.005 + 0.01 * (k / 60) as f64 - 0.15).powi(2))
            .sqrt()
                < 0.05
        })
        .count();
    assert_eq!(without.fluid_count() - with.fluid_count(), inside);
    let bodies = with
        .kind
        .iter()
        .filter(|k| **k == isph::particles::Kind::Body)
        .count();
    assert_eq!(bodies, inside);
}

/// The slope of body 0's vy over the frames from `from` to `to` s: its acceleration.
fn acceleration(rows: &[(f64, Vec<f64>)], from: f64, to: f64) -> f64 {
    let at = |t: f64| {
        rows.iter()
            .find(|r| (r.0 - t).abs() < 1e-9)
            .unwrap_or_else(|| panic!("no row at t = {t}"))
            .1[VY]
    };
    (at(to) - at(from)) / (to - from)
}

/// The added-mass coefficients of the circle of radius 0.05 m at (0.3, 0.25) m in the tank
/// 0.6 m wide of the added-mass tests, its water 0.5131 m deep (0.5 m and the circle's volume),
/// moving along x and along y: potential flow with the free surface at φ = 0, as an impulsive
/// start sees it (`tools/added_mass_bem.py 0.6 0.5131 0.3 0.25 0.05`, to four digits at two
/// resolutions). The floor and the walls raise Ca above the unbounded 1, the surface lowers it.
const TANK_CA: [f64; 2] = [1.0233, 1.0475];

#[test]
fn a_cylinder_lifted_by_its_weight_starts_at_the_added_mass_acceleration() {
    // The paper's water exit at release: a 2D circle deep in still water (D/dx = 20) lifted by
    // a constant force equal to its weight accelerates at a0 = ρf g/(ρs + Ca ρf), Ca the
    // circle's along y in this tank (`TANK_CA`): the added mass is in the pressure solve, so no
    // density ratio needs a smaller step, from the light end of the range the coupling is built
    // for (0.3) to the heavy end (3). Measured between the second and the fourth 0.01 s frame
    // (the first steps close the half-spacing gap the fill leaves around a body).
    for density in [300.0, 500.0, 1000.0, 2000.0, 3000.0] {
        let dir = TempDir::new("bodies-added-mass");
        let weight = density * std::f64::consts::PI * 0.05 * 0.05 * 9.81;
        let body = format!(
            "[[body]]\nshape = \"circle\"\ncenter = [0.3, 0.25]\nradius = 0.05\ndensity = {density:?}\nforce = [0.0, {weight:?}]\n"
        );
        let scene = scene_from_text(&tank(2, 0.005, [0.6, 0.6, 0.0], 0.5, 0.01, &body));
        run_scene(&scene, dir.path(), 0.04);
        let a = acceleration(&rows(dir.path(), 0), 0.02, 0.04);
        let a0 = 1000.0 * 9.81 / (density + TANK_CA[Y] * 1000.0);
        eprintln!(
            "s = {}: a = {a} against {a0} ({:+.2}%)",
            density / 1000.0,
            100.0 * (a / a0 - 1.0)
        );
        assert!(
            (a / a0 - 1.0).abs() < 0.05,
            "s = {}: a = {a} m/s² against ρf g/(ρs + Ca ρf) = {a0}",
            density / 1000.0
        );
    }
}

#[test]
fn a_cylinder_oscillated_in_still_water_follows_its_trajectory_and_feels_its_added_mass() {
    // x = A sin ωt with A = D/20: KC = 2πA/D = 0.3, so the force is the added mass's,
    // F = −Ca ρ V ẍ with Ca the circle's along x in this tank (`TANK_CA`; drag and vortex
    // shedding are of order KC smaller).
    let dir = TempDir::new("bodies-oscillating");
    let (amplitude, period, radius) = (0.005, 0.5, 0.05);
    let body = format!(
        "[[body]]\nshape = \"circle\"\ncenter = [0.3, 0.25]\nradius = {radius:?}\ndensity = 1000.0\nmotion = \"prescribed\"\n\n[body.trajectory]\nperiod = {period:?}\namplitude = [{amplitude:?}, 0.0]\n"
    );
    let scene = scene_from_text(&tank(2, 0.005, [0.6, 0.6, 0.0], 0.5, 0.01, &body));
    run_scene(&scene, dir.path(), 1.0);
    let rows = rows(dir.path(), 0);
    let omega = 2.0 * std::f64::consts::PI / period;
    let (mut fa, mut aa) = (0.0, 0.0);
    for (t, r) in &rows {
        let x = rows[0].1[0] + amplitude * (omega * t).sin();
        assert!(
            (r[0] - x).abs() < 1e-12,
            "t = {t}: x = {} against {x}",
            r[0]
        );
        assert!(r[Y] == rows[0].1[Y], "t = {t}: y = {}", r[Y]);
        // The second half: after the start-up of the first period.
        if *t >= 0.5 * rows.last().unwrap().0 {
            let a = -amplitude * omega * omega * (omega * t).sin();
            fa += r[FX] * a;
            aa += a * a;
        }
    }
    let volume = std::f64::consts::PI * radius * radius;
    let ca = -fa / aa / (1000.0 * volume);
    eprintln!("Ca = {ca}");
    assert!(
        (ca / TANK_CA[0] - 1.0).abs() < 0.05,
        "added-mass coefficient {ca} against {}",
        TANK_CA[0]
    );
}

/// The water's largest speed [m/s] over the steps of the run in `out`.
fn largest_speed(out: &Path) -> f64 {
    let fastest = stats_column(out, "max_speed")
        .into_iter()
        .fold(0.0, f64::max);
    eprintln!("the water's largest speed {fastest} m/s");
    fastest
}

#[test]
fn a_fixed_body_in_still_water_feels_its_buoyancy_and_leaves_the_water_still() {
    let dir = TempDir::new("bodies-fixed");
    let body = r#"[[body]]
shape = "circle"
center = [0.3, 0.25]
radius = 0.05
density = 1000.0
motion = "fixed"
"#;
    let scene = scene_from_text(&tank(2, 0.005, [0.6, 0.6, 0.0], 0.5, 0.01, body));
    run_scene(&scene, dir.path(), 0.5);
    let rows = rows(dir.path(), 0);
    let particles = body_positions(dir.path(), 0).len() as f64;
    let buoyancy = 1000.0 * 9.81 * particles * 0.005 * 0.005;
    let fy = mean_after(&rows, FY, 0.1);
    eprintln!("fy {fy} against {buoyancy}");
    assert!(
        (fy / buoyancy - 1.0).abs() < 0.02,
        "fy {fy} N/m against the buoyancy {buoyancy}"
    );
    for (t, r) in &rows {
        assert!(r[..2] == rows[0].1[..2], "t = {t}: moved to {:?}", &r[..2]);
    }
    // The body's particles are the ghosts of a wall: the water's hydrostatic pressure runs into
    // it exactly and the water beside it stays still. Measured: 1.5e-4 m/s at most over 0.5 s
    // (2026-12-07; the water about the lattice's circle settles
    // to 1.5e-3 m/s by 6 s and stays there to 10 s). Before the ghosts, 0.023 m/s.
    let fastest = largest_speed(dir.path());
    assert!(
        fastest < 1e-3,
        "the water around a fixed body moved at {fastest} m/s"
    );
}

#[test]
fn a_body_held_in_still_water_leaves_it_still_whatever_its_density() {
    // A box 0.08 m square held in mid-water: its density cannot change the flow around it, and
    // at 1.5 and 0.5 times the water's the water moves exactly as around a neutral one (a held
    // body takes the water's density in the pressure solve: `Bodies::set_solve_densities`),
    // at 0.030 m/s at most over 0.5 s (the fill's gaps at its corners closing). With the body's
    // own density there, a heavy box drew the water down its sides and a light one up, at up
    // to 0.25 and 0.42 m/s within 0.5 s (docs/bodies.md, "The coupling").
    let speeds = |density: f64| {
        let dir = TempDir::new("bodies-held-box");
        let body = format!(
            "[[body]]\nshape = \"box\"\nmin = [0.26, 0.1]\nmax = [0.34, 0.18]\ndensity = {density:?}\nmotion = \"fixed\"\n"
        );
        let scene = scene_from_text(&tank(2, 0.01, [0.6, 0.4, 0.0], 0.3, 0.05, &body));
        run_scene(&scene, dir.path(), 0.5);
        stats_column(dir.path(), "max_speed")
    };
    let neutral = speeds(1000.0);
    let fastest = neutral.iter().fold(0.0, |m: f64, s| m.max(*s));
    eprintln!("the water's largest speed {fastest} m/s");
    assert!(
        fastest < 0.05,
        "the water beside a held body reached {fastest} m/s"
    );
    for density in [1500.0, 500.0] {
        assert_eq!(
            speeds(density),
            neutral,
            "the water's speed beside a held body of density {density}"
        );
    }
}

#[test]
fn a_body_held_through_the_surface_leaves_still_water_still_and_feels_the_buoyancy_of_its_wet_part()
{
    // A box 0.1 m square held with half its height under the surface of still water. Its ghosts
    // above the waterline continue the water's pressure upwards, negative there: a ghost's value
    // is not a pressure of water and takes no cavitation clip. Clipped, the water at the contact
    // line was pushed off the box every step, and the tank sloshed ever more: 0.12 m/s within
    // 1 s, the kinetic energy from 2e-3 to 9e-2 J/m over 6 s (2026-12-07). Measured unclipped:
    // 1.8e-4 m/s at most over 1 s (1.4e-3 at most over 20 s: the solve's tolerance), the force
    // 0.05% under the wet part's buoyancy (1.3% while its dry faces counted).
    let dir = TempDir::new("bodies-held-through-the-surface");
    let body = "[[body]]\nshape = \"box\"\nmin = [0.25, 0.25]\nmax = [0.35, 0.35]\ndensity = 500.0\nmotion = \"fixed\"\n";
    let scene = scene_from_text(&tank(2, 0.01, [0.6, 0.5, 0.0], 0.3, 0.1, body));
    run_scene(&scene, dir.path(), 1.0);
    let fastest = largest_speed(dir.path());
    assert!(
        fastest < 1e-3,
        "the water beside a body held through its surface moved at {fastest} m/s"
    );
    let wet = body_positions(dir.path(), 0)
        .iter()
        .filter(|x| x[Y] < 0.3)
        .count() as f64;
    let buoyancy = 1000.0 * 9.81 * wet * 0.01 * 0.01;
    let fy = mean_after(&rows(dir.path(), 0), FY, 0.2);
    eprintln!("fy {fy} against {buoyancy}");
    assert!(
        (fy / buoyancy - 1.0).abs() < 0.03,
        "fy {fy} N/m against the buoyancy of the wet part {buoyancy}"
    );
}

#[test]
fn a_piston_held_in_still_water_feels_the_water_on_its_wet_face_only() {
    // A wave maker's piston 0.04 m thick stands on the floor of a flume of still water
    // h = 0.2 m deep and rises above it: water in front, air behind and above, the floor
    // under it. The water's force is the hydrostatic thrust on the wet face, ρ g h²/2 along −x
    // at h/3 above the floor, and nothing along y. The body's particles on its dry faces hold
    // the water's pressure continued through it; counted as wet, they gave fx 27% too large
    // and fy = +64 N/m (the floor's face pushed up by water that is not there). Measured at
    // h/dx = 20, 40, 80: fx −3.0%, −1.5%, −0.8% of the thrust (first order in dx), the
    // torque −5.2%, −2.6%, −1.3% (2026-12-07).
    let dir = TempDir::new("bodies-piston-still");
    let (h, dx, rho, g) = (0.2, 0.01, 1000.0, 9.81);
    let scene = scene_from_text(&format!(
        "[simulation]\ndimensions = 2\nspacing = {dx:?}\nend_time = 0.25\noutput_interval = 0.05\ngravity = [0.0, {:?}]\n\n\
         [[fluid]]\nname = \"water\"\ndensity = {rho:?}\nviscosity = 1.0e-6\n\n\
         [[fluid_block]]\nfluid = \"water\"\nmin = [0.09, 0.0]\nmax = [1.0, {h:?}]\n\n\
         [container]\nmin = [0.0, 0.0]\nmax = [1.0, 0.35]\n\n\
         [[body]]\nshape = \"box\"\nmin = [0.05, 0.0]\nmax = [0.09, 0.3]\ndensity = 1000.0\nmotion = \"fixed\"\n",
        -g
    ));
    run_scene(&scene, dir.path(), 0.25);
    let rows = rows(dir.path(), 0);
    let thrust = 0.5 * rho * g * h * h;
    let (fx, fy) = (mean_after(&rows, FX, 0.1), mean_after(&rows, FY, 0.1));
    // About the body's centre at 0.15 m: −(h/3 − 0.15) × (−thrust).
    let moment = -(0.15 - h / 3.0) * thrust;
    let tz = mean_after(&rows, TZ, 0.1);
    eprintln!("fx {fx}, fy {fy}, tz {tz} against {}, 0, {moment}", -thrust);
    assert!(
        (-fx / thrust - 1.0).abs() < 0.05,
        "fx {fx} N/m against the thrust {}",
        -thrust
    );
    assert!(
        fy.abs() < 0.01 * thrust,
        "fy {fy} N/m on a body with no water above or below it"
    );
    assert!(
        (tz / moment - 1.0).abs() < 0.08,
        "tz {tz} N against the thrust's moment {moment}"
    );
}

#[test]
fn held_bodies_on_the_floor_and_through_the_surface_feel_the_water_on_their_wet_faces_only() {
    // In still water 0.3 m deep: a box 0.1 × 0.05 m held on the floor, which no water reaches
    // under it: the water above presses it down, ρ g (h − 0.05) × 0.1 m (its buoyancy, 49 N/m
    // up, would count the floor's face as wet); and a circle of radius 0.05 m held with its
    // centre on the surface: the buoyancy of its wet half, ρ g π r²/2. Measured at dx = 0.01
    // m: −0.04% and +1.5% (the lattice's half disc), at 0.005 m −0.06% and +0.4% (2026-12-07).
    let dir = TempDir::new("bodies-held-dry-faces");
    let bodies = "[[body]]\nshape = \"box\"\nmin = [0.25, 0.0]\nmax = [0.35, 0.05]\ndensity = 2000.0\nmotion = \"fixed\"\n\n\
                  [[body]]\nshape = \"circle\"\ncenter = [0.1, 0.3]\nradius = 0.05\ndensity = 500.0\nmotion = \"fixed\"\n";
    let scene = scene_from_text(&tank(2, 0.01, [0.6, 0.5, 0.0], 0.3, 0.05, bodies));
    run_scene(&scene, dir.path(), 0.3);
    let (rho, g) = (1000.0, 9.81);
    let pressed = -rho * g * (0.3 - 0.05) * 0.1;
    let fy = mean_after(&rows(dir.path(), 0), FY, 0.1);
    eprintln!("box on the floor: fy {fy} against {pressed}");
    assert!(
        (fy / pressed - 1.0).abs() < 0.01,
        "fy {fy} N/m on a box on the floor against {pressed}"
    );
    let half = rho * g * std::f64::consts::PI * 0.05 * 0.05 / 2.0;
    let fy = mean_after(&rows(dir.path(), 1), FY, 0.1);
    eprintln!("circle through the surface: fy {fy} against {half}");
    assert!(
        (fy / half - 1.0).abs() < 0.03,
        "fy {fy} N/m on a circle half under water against {half}"
    );
}

/// Heavy bodies lying on the floor of still water 0.3 m deep from the start (`body` their
/// sections): the water's kinetic energy [J/m] at every frame from 1 s to 2 s, and the bodies'
/// largest speed [m/s] over the whole run.
fn resting_on_the_floor(name: &str, body: &str) -> (Vec<f64>, f64) {
    let dir = TempDir::new(name);
    let scene = scene_from_text(&tank(2, 0.01, [0.6, 0.4, 0.0], 0.3, 0.01, body));
    run_scene(&scene, dir.path(), 2.0);
    let time = stats_column(dir.path(), "time");
    let energy = stats_column(dir.path(), "kinetic_energy");
    let late = (0..time.len())
        .filter(|&k| time[k] >= 1.0)
        .map(|k| energy[k])
        .collect();
    let fastest = (0..scene.bodies.len())
        .flat_map(|b| rows(dir.path(), b))
        .map(|r| r.1[VX].hypot(r.1[VY]) + r.1[12].abs() * 0.06)
        .fold(0.0, f64::max);
    (late, fastest)
}

#[test]
fn a_heavy_body_resting_on_the_floor_stays_at_rest_and_leaves_the_water_still() {
    // A box 0.08 m square and a circle of D = 0.08 m at s = 1.5 lying on the floor: once their
    // contacts stop them they rest, held still in the pressure solve while their supports hold
    // them (`bodies::contact`, 3.), so the water beside them is as still as beside a body of
    // the water's density. Measured: exactly at rest throughout; the water's kinetic energy
    // over 1–2 s at most 1.4e-8 J/m beside the box and 5.1e-8 beside the circle. Before bodies
    // rested, the solve moved them by their excess weight every step and their contacts
    // stopped them after: 0.0051 and 0.0067 J/m on average, the water moving at up to 0.18 and
    // 0.29 m/s, the bodies at 0.0005 and 0.001 m/s on average. A box lying on another rests
    // on it as on the floor: the water 1.2e-8 J/m; before, the top box jittered at 0.02 m/s on
    // average and the water held 0.0094 J/m.
    let bottom = "shape = \"box\"\nmin = [0.26, 0.0]\nmax = [0.34, 0.08]";
    let on_top = "shape = \"box\"\nmin = [0.27, 0.08]\nmax = [0.33, 0.14]";
    let circle = "shape = \"circle\"\ncenter = [0.3, 0.04]\nradius = 0.04";
    for (name, shapes) in [
        ("box", vec![bottom]),
        ("circle", vec![circle]),
        ("stack", vec![bottom, on_top]),
    ] {
        let body: String = shapes
            .iter()
            .map(|shape| format!("[[body]]\n{shape}\ndensity = 1500.0\nfriction = 0.5\n\n"))
            .collect();
        let (energy, fastest) = resting_on_the_floor(&format!("bodies-resting-{name}"), &body);
        let most = energy.iter().fold(0.0, |m: f64, e| m.max(*e));
        eprintln!("{name}: the water's kinetic energy over 1–2 s at most {most} J/m; the body at {fastest} m/s at most");
        assert!(
            most < 1e-5,
            "the water beside a resting {name} holds {most} J/m"
        );
        assert!(
            fastest < 1e-12,
            "a {name} resting on the floor moved at {fastest} m/s"
        );
    }
}

/// The tilt [degrees] of a tank tilted to 10° along a half-cosine ramp over 2 s, at time t.
fn ramp_tilt(t: f64) -> f64 {
    10.0 * 0.5 * (1.0 - (std::f64::consts::PI * t.clamp(0.0, 2.0) / 2.0).cos())
}

/// A box 0.08 × 0.04 m at s = 2 with friction `friction` on the floor of water 0.2 m deep in a
/// tank tilted by `ramp_tilt`: bodies.csv of the run to `until`, frames every 0.01 s.
fn box_on_a_tilting_floor(dir: &Path, friction: f64, until: f64) -> Vec<(f64, Vec<f64>)> {
    let mut table = String::from("time,x,y,angle\n");
    for k in -2..=40 {
        let t = k as f64 * 0.05;
        table += &format!("{t:?},0,0,{:?}\n", ramp_tilt(t));
    }
    table += "10.0,0,0,10.0\n";
    std::fs::write(dir.join("tilt.csv"), table).unwrap();
    let sections = format!("[container.trajectory]\npivot = [0.3, 0.0]\ntable = \"tilt.csv\"\n\n[[body]]\nshape = \"box\"\nmin = [0.26, 0.0]\nmax = [0.34, 0.04]\ndensity = 2000.0\nfriction = {friction:?}\n");
    let path = dir.join("tilt.toml");
    std::fs::write(&path, tank(2, 0.01, [0.6, 0.4, 0.0], 0.2, 0.01, &sections)).unwrap();
    let scene = isph::scene::Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let out = dir.join("out");
    run_scene(&scene, &out, until);
    rows(&out, 0)
}

#[test]
fn a_box_on_a_tilting_floor_starts_to_slide_where_the_tilt_passes_its_friction_angle() {
    // Coulomb: a body resting on a floor tilted by θ slides once tan θ > μ, in water as in air
    // (its weight in the water gives both the pull along the floor and the normal force).
    // Resting, it is held in the pressure solve and its contacts hold it while they can
    // (`bodies::contact`, 3.). Measured: it starts at 6.2–6.3° at μ = 0.1 (5.7° asked; the
    // water still sloshing up the ramp) and at 8.59–8.64° at μ = 0.15 (8.53°); at μ = 0.3
    // (16.7°) it stays exactly where it was.
    for friction in [0.1, 0.15] {
        let dir = TempDir::new("bodies-tilt");
        let rows = box_on_a_tilting_floor(dir.path(), friction, 2.0);
        let k = rows
            .iter()
            .position(|r| r.1[VX].hypot(r.1[VY]) > 0.0)
            .unwrap_or_else(|| panic!("μ = {friction}: it never slid"));
        let (still, moving) = (ramp_tilt(rows[k - 1].0), ramp_tilt(rows[k].0));
        let expected = friction.atan().to_degrees();
        eprintln!("μ = {friction}: still at {still}°, sliding at {moving}° ({expected}° asked)");
        assert!(
            moving > expected && still < expected + 1.0,
            "μ = {friction}: still at {still}°, sliding at {moving}°, against {expected}°"
        );
    }
    let dir = TempDir::new("bodies-tilt");
    let rows = box_on_a_tilting_floor(dir.path(), 0.3, 3.0);
    // At rest from the first step on, where its contact stopped it.
    let x0 = rows[1].1[0];
    for (t, r) in &rows[1..] {
        assert!(
            r[VX] == 0.0 && r[VY] == 0.0 && r[0] == x0,
            "μ = 0.3, t = {t}: moved to {} at {} m/s",
            r[0],
            r[VX].hypot(r[VY])
        );
    }
}

#[test]
fn a_box_set_sliding_on_the_floor_stops_where_coulomb_friction_stops_it() {
    // A box 0.08 × 0.04 m at s = 2 on the floor of still water 0.2 m deep, started along the
    // floor at v0 = 0.3 m/s, friction μ = 0.3. The friction μ (W − B) is the one force on the
    // body and the water it carries along that takes their momentum M v0 away (the water
    // takes its share of the body's speed in the first step, the added mass, and keeps it as
    // the body slows), so it stops at t = M v0 / (μ (W − B)) = 0.204 s. Measured: 0.20–0.21 s,
    // after 0.021 m. While the walls' ghost pressures held up the body's own weight, its
    // contact took little of it and the friction bound μ λ with it: it slid 0.038 m in 1 s and
    // was still sliding.
    let dir = TempDir::new("bodies-slide");
    let body = "[[body]]\nshape = \"box\"\nmin = [0.16, 0.0]\nmax = [0.24, 0.04]\ndensity = 2000.0\nfriction = 0.3\nvelocity = [0.3, 0.0]\n";
    let scene = scene_from_text(&tank(2, 0.01, [0.6, 0.4, 0.0], 0.2, 0.01, body));
    run_scene(&scene, dir.path(), 0.5);
    let rows = rows(dir.path(), 0);
    let area = 0.08 * 0.04;
    let (mass, excess) = (2000.0 * area, (2000.0 - 1000.0) * area * 9.81);
    let expected = mass * 0.3 / (0.3 * excess);
    let k = rows
        .iter()
        .position(|r| r.1[VX] == 0.0 && r.0 > 0.0)
        .unwrap_or_else(|| panic!("still sliding at 0.5 s: {:?}", rows.last()));
    eprintln!(
        "stopped by {} s after {} m ({expected} s asked)",
        rows[k].0,
        rows[k].1[0] - rows[0].1[0]
    );
    assert!(
        (rows[k - 1].0 - expected).abs() < 0.15 * expected,
        "stopped between {} and {} s against {expected} s",
        rows[k - 1].0,
        rows[k].0
    );
    for (t, r) in &rows[k..] {
        assert!(
            r[VX] == 0.0 && r[VY] == 0.0,
            "t = {t}: moving again at {}",
            r[VX]
        );
    }
}

#[test]
fn the_sinking_cylinder_stays_inside_the_band_of_its_two_references() {
    // scenes/sinking_cylinder_2d.toml (D/dx = 20): R = 1 m at s = 1.2 held half submerged for
    // 1 s, then let go. Its displacement at T = (t − 1) √(g/R) = 1 … 4 against Fekken (2004)
    // and Moyo & Greenhow (2000), at the scene's CFL 0.1: inside their band in the median of
    // three draws (frames every 0.01, 0.02, 0.025 s: each lands a frame on the release). T = 2 lies at Fekken's edge of the band
    // [−0.657, −0.649]: over five draws it reads −0.6487 to −0.6498, the scene's own draw 0.3 mm
    // beyond it (docs/bodies.md, "Sinking cylinder").
    let scene = crate::common::shipped_scene("sinking_cylinder_2d.toml");
    let release = 1.0;
    let until = release + 4.0 / 9.81f64.sqrt();
    let at_t: Vec<f64> = (1..=4)
        .map(|k| release + k as f64 / 9.81f64.sqrt())
        .collect();
    let draws = crate::common::over_draws(&scene, &[0.01, 0.02, 0.025], |scene| {
        let dir = TempDir::new("bodies-sinking-cylinder");
        run_scene(scene, dir.path(), until + 0.05);
        let rows = rows(dir.path(), 0);
        let y_at = |t: f64| {
            let k = rows.iter().position(|r| r.0 > t).unwrap();
            let ((t0, a), (t1, b)) = ((rows[k - 1].0, rows[k - 1].1[Y]), (rows[k].0, rows[k].1[Y]));
            a + (b - a) * (t - t0) / (t1 - t0)
        };
        let held = y_at(release);
        assert!((held - 14.0).abs() < 1e-9, "held at {held}");
        at_t.iter().map(|&t| y_at(t) - held).collect::<Vec<f64>>()
    });
    let fekken: [f64; 4] = [-0.198, -0.649, -1.166, -1.630];
    let moyo_greenhow = [-0.154, -0.657, -1.292, -1.965];
    for k in 0..4 {
        let mut d: Vec<f64> = draws.iter().map(|draw| draw[k]).collect();
        d.sort_by(f64::total_cmp);
        let (a, b) = (fekken[k], moyo_greenhow[k]);
        let (lo, hi) = (a.min(b), a.max(b));
        eprintln!("T = {}: {d:?} m (Fekken {a}, Moyo & Greenhow {b})", k + 1);
        assert!(
            (lo..=hi).contains(&d[1]),
            "T = {}: median displacement {} m outside [{lo}, {hi}]",
            k + 1,
            d[1]
        );
    }
}

/// Two equal circles falling side by side in the air, their centres 0.4 m apart, thrown at each
/// other at ±`speed` with restitution `restitution`: bodies.csv of the run to 0.3 s.
fn head_on(dir: &Path, restitution: f64, speed: f64) -> Vec<Vec<(f64, Vec<f64>)>> {
    let circle = |name: &str, x: f64, v: f64| {
        format!("[[body]]\nname = \"{name}\"\nshape = \"circle\"\ncenter = [{x:?}, 0.8]\nradius = 0.05\ndensity = 800.0\nvelocity = [{v:?}, 0.0]\nrestitution = {restitution:?}\n")
    };
    let bodies = circle("left", 0.3, speed) + &circle("right", 0.7, -speed);
    let text = tank(2, 0.01, [1.0, 1.0, 0.0], 0.05, 0.01, &bodies);
    run_scene(&scene_from_text(&text), dir, 0.3);
    (0..2).map(|b| rows(dir, b)).collect()
}

#[test]
fn two_bodies_that_collide_bounce_by_their_restitution_and_keep_their_momentum() {
    for (restitution, expected) in [(1.0, -1.0), (0.0, 0.0)] {
        let dir = TempDir::new("bodies-collide");
        let rows = head_on(dir.path(), restitution, 1.0);
        let (left, right) = (&rows[0], &rows[1]);
        let last = left.len() - 1;
        // Momentum: equal masses, equal and opposite velocities at every frame.
        for k in 0..=last {
            assert!(
                (left[k].1[VX] + right[k].1[VX]).abs() < 1e-12,
                "e = {restitution}, t = {}: vx {} and {}",
                left[k].0,
                left[k].1[VX],
                right[k].1[VX]
            );
        }
        // They meet 0.15 s in (0.4 m apart less two radii at 2 m/s); after the impact the left
        // body moves at e times its speed, backwards.
        let after = left[last].1[VX];
        assert!(
            (after - expected).abs() < 1e-9,
            "e = {restitution}: vx after the impact {after}, expected {expected}"
        );
        // Never closer than touching: no particle of one within half a spacing of the other's
        // circle (where the lattice puts a body's outer particles inside its own surface).
        for k in 0..=last {
            let body: Vec<i32> = read_frame(dir.path(), k, "body");
            let pos: Vec<f64> = read_frame(dir.path(), k, "position");
            for (b, other) in [(0, &right[k].1), (1, &left[k].1)] {
                let nearest = (0..body.len())
                    .filter(|&i| body[i] == b)
                    .map(|i| {
                        ((pos[3 * i] - other[0]).powi(2) + (pos[3 * i + 1] - other[Y]).powi(2))
                            .sqrt()
                    })
                    .fold(f64::MAX, f64::min);
                assert!(
                    nearest >= 0.05 + 0.005 - 1e-9,
                    "t = {}: a particle of body {b} {nearest} m from the other's centre",
                    left[k].0
                );
            }
        }
    }
}

#[test]
fn a_body_dropped_on_an_obstacle_rests_on_it() {
    let dir = TempDir::new("bodies-on-obstacle");
    let body = r#"[[obstacle]]
min = [0.4, 0.1]
max = [0.6, 0.3]

[[body]]
shape = "box"
min = [0.45, 0.6]
max = [0.55, 0.7]
density = 1500.0
friction = 0.5
"#;
    let scene = scene_from_text(&tank(2, 0.01, [1.0, 1.0, 0.0], 0.05, 0.05, body));
    run_scene(&scene, dir.path(), 1.0);
    let rows = rows(dir.path(), 0);
    let (t, last) = rows.last().unwrap();
    // On the obstacle's top: its lowest particles half a spacing above 0.3.
    let lowest = lowest_body_particle(dir.path(), rows.len() - 1);
    assert!(
        (lowest - 0.305).abs() < 1e-9,
        "t = {t}: lowest particle at {lowest}"
    );
    assert!(
        last[VY].abs() < 1e-9 && last[VX].abs() < 1e-9,
        "t = {t}: still moving {:?}",
        &last[VX..=VY]
    );
    assert!(last[12].abs() < 1e-9, "t = {t}: turning at {}", last[12]);
}

#[test]
fn fluid_put_back_off_bodies_keeps_its_particles_apart_and_outside() {
    // Two discs side by side just off the floor, 1 mm apart (a tenth of a spacing): the
    // crevices between them and between each and the floor are narrower than the contact's
    // gap (a quarter spacing) from both of their surfaces. Fluid particles anywhere around the
    // crevices, put back off the bodies (`Bodies::keep_out`), land outside both discs and no
    // two on one point; particles along one normal keep their distances. Put on the gap
    // surface instead, every particle on a normal lands on one point, and every particle in a
    // crevice converges to the point at the gap from both surfaces: particles the flow drives
    // there pile onto one another for good (coincident particles take the same steps), which
    // blew up a pile of discs in a surge.
    let (radius, spacing) = (0.05, 0.01);
    let gap = 0.25 * spacing;
    let discs = format!(
        "[[body]]\nshape = \"circle\"\ncenter = [0.45, {y}]\nradius = {radius}\ndensity = 1500.0\n\n\
         [[body]]\nshape = \"circle\"\ncenter = [0.551, {y}]\nradius = {radius}\ndensity = 1500.0\n",
        y = radius + 0.1 * spacing,
    );
    let scene = scene_from_text(&tank(2, spacing, [1.0, 0.4, 0.0], 0.2, 0.1, &discs));
    let bodies = isph::Simulation::<2>::new(&scene).unwrap().bodies;
    let outside = |x: &[f64; 3]| {
        bodies
            .bodies
            .iter()
            .map(|b| b.surface_distance(2)(x))
            .fold(f64::MAX, f64::min)
    };
    let put_back = |x: [f64; 3]| {
        let (mut x, mut u) = (x, [0.0, -0.5, 0.0]);
        let (moved, _) = bodies.keep_out(&mut x, &mut u, gap, 2);
        moved.then_some(x)
    };
    // Points 0.37 mm apart over the crevices (an irregular step, no lattice line on a
    // surface), those the contact moves.
    let step = 0.037 * spacing;
    let moved: Vec<[f64; 3]> = (0..160)
        .flat_map(|i| (0..330).map(move |j| [0.47 + i as f64 * step, j as f64 * step, 0.0]))
        .filter(|x| outside(x) > -0.5 * spacing && x[1] > 0.0)
        .filter_map(put_back)
        .collect();
    assert!(moved.len() > 1000, "only {} points in reach", moved.len());
    for x in &moved {
        assert!(
            outside(x) >= 0.0,
            "put back at {x:?}, {} m inside a disc",
            -outside(x)
        );
    }
    let closest = closest_pair_within(&moved, 1e-3 * spacing);
    assert!(
        closest > 1e-6 * spacing,
        "two of {} particles put back {closest} m apart",
        moved.len()
    );
    // Along the normal of the first disc at 30° from its lowest point, at depths 0.1 … 0.9 of
    // the gap: as far apart after as before.
    let (c, angle) = ([0.45, radius + 0.1 * spacing], -60f64.to_radians());
    let on_normal = |depth: f64| {
        let r = radius + gap - depth;
        [c[0] + r * angle.cos(), c[1] + r * angle.sin(), 0.0]
    };
    let landed: Vec<[f64; 3]> = (1..10)
        .map(|k| put_back(on_normal(0.1 * k as f64 * gap)).expect("in reach"))
        .collect();
    for pair in landed.windows(2) {
        let apart = distance(pair[0], pair[1]);
        assert!(
            (apart - 0.1 * gap).abs() < 1e-3 * gap,
            "particles 0.1 gap apart on a normal land {apart} m apart: {landed:?}"
        );
    }
}

#[test]
fn in_a_dam_break_heavy_solids_stay_down_light_ones_float_and_nothing_passes_through_them() {
    // scenes/dam_break_solids_2d.toml at twice its spacing (D/dx = 5), to 3 s: four discs at
    // s = 1.5 and four at s = 0.8 in the surge. Once the surge has passed (2–3 s), in still
    // water 0.1 m deep the light discs would float with their centres near 0.075 m and the heavy
    // ones rest at 0.025 m. The surge piles them up as it likes (a heavy disc on two others, a
    // light one wedged under a heavy one, light ones in a row on the floor with no water under
    // them, one pressed into the corner of the floor and the end wall), and where they end is
    // one draw of a chaotic flow: frames every 0.02 (the scene's), 0.025 and 0.03 s land other
    // steps on them and pile the discs otherwise. So: every heavy disc down, on the floor or on
    // another disc (a heavy disc does not float), and over the three draws three quarters of
    // the light ones afloat or held down by a disc resting on them; a light disc lying on the
    // floor with nothing on it is the known limitation of a pocket under a pile (docs/bodies.md,
    // "Known limitation: light bodies under a pile stay on the floor"). Measured: heavy on the
    // floor 2, 2, 2 of 4 and the others on a disc; light afloat 2, 3, 2 and held down 2, 1, 2
    // (with the fluid put on the contact's gap surface instead of mirrored across it, and the
    // bodies turned by ωⁿ⁺¹ Δt: heavy on the floor 1, 4, 2, light afloat 1, 4, 1).
    let mut scene = crate::common::shipped_scene("dam_break_solids_2d.toml");
    scene.spacing = 0.01;
    let draws: Vec<Vec<[f64; 2]>> =
        crate::common::over_draws(&scene, &crate::common::THREE_DRAWS, solids_centres);
    // Centres within two spacings of touching: the contact's gap and the lattice's offset from
    // the circle at D/dx = 5.
    let touching =
        |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]) < 2.0 * (0.025 + scene.spacing);
    for centres in &draws {
        eprintln!(
            "mean centres over 2–3 s: heavy {:?} m, light {:?} m",
            &centres[..4],
            &centres[4..]
        );
        for (k, c) in centres[..4].iter().enumerate() {
            let on_a_disc = centres
                .iter()
                .enumerate()
                .any(|(j, d)| j != k && d[1] < c[1] && touching(*c, *d));
            assert!(
                c[1] < 0.03 || on_a_disc,
                "heavy disc {k} afloat at {c:?}: {centres:?}"
            );
        }
    }
    // A light disc is afloat, or held down by a disc that rests on it.
    let free_or_held: usize = draws
        .iter()
        .map(|centres| {
            (4..8)
                .filter(|&k| {
                    let c = centres[k];
                    c[1] > 0.06
                        || centres
                            .iter()
                            .enumerate()
                            .any(|(j, d)| j != k && d[1] > c[1] && touching(c, *d))
                })
                .count()
        })
        .sum();
    assert!(
        free_or_held >= 9,
        "{free_or_held} of 12 light discs afloat or held down by a disc on them: {draws:?}"
    );
}

/// Each disc's mean centre over 2–3 s (the lattice particles' centre of mass) in a run of
/// `scene`, checking every frame that no fluid particle lies inside a disc and that the discs
/// keep off each other and the floor.
fn solids_centres(scene: &isph::scene::Scene) -> Vec<[f64; 2]> {
    let dir = TempDir::new("bodies-solids");
    run_scene(scene, dir.path(), 3.0);
    // Once the surge has passed (1.5 s), no particle faster than three times its speed √(2gH)
    // (H = 0.25 m): measured 2.3–3.8 m/s over six draws; coincident fluid particles squeezed
    // in a crevice once blew a pile up to 79 m/s.
    let (time, speed) = (
        stats_column(dir.path(), "time"),
        stats_column(dir.path(), "max_speed"),
    );
    let fastest = time
        .iter()
        .zip(&speed)
        .filter(|(t, _)| **t > 1.5)
        .fold(0.0, |m: f64, (_, v)| m.max(*v));
    let surge = (2.0 * 9.81 * 0.25f64).sqrt();
    assert!(
        fastest < 3.0 * surge,
        "a particle at {fastest} m/s after the surge"
    );
    let discs: Vec<Vec<(f64, Vec<f64>)>> = (0..8).map(|b| rows(dir.path(), b)).collect();
    let (radius, spacing) = (0.025, scene.spacing);
    let circles: Vec<[f64; 2]> = scene
        .bodies
        .iter()
        .map(|b| match &b.shape {
            isph::scene::Shape::Ball { center, .. } => [center[0], center[1]],
            other => panic!("a disc expected, not {other:?}"),
        })
        .collect();
    for (k, row) in discs[0].iter().enumerate() {
        // Each disc's particles keep half a spacing outside every other disc's circle and above
        // the floor (the contact's rule); allowed a quarter, for a pile that four passes leave
        // unresolved.
        let body: Vec<i32> = read_frame(dir.path(), k, "body");
        let kind: Vec<i32> = read_frame(dir.path(), k, "kind");
        let pos: Vec<f64> = read_frame(dir.path(), k, "position");
        // No two fluid particles on one point: the contact once put every particle squeezed
        // into a crevice between discs on one point, where they stayed together.
        let fluid: Vec<[f64; 3]> = (0..kind.len())
            .filter(|&i| kind[i] == 0)
            .map(|i| [pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]])
            .collect();
        let closest = closest_pair_within(&fluid, 1e-6 * spacing);
        assert!(
            closest >= 1e-6 * spacing,
            "t = {}: coincident fluid particles, {closest} m apart",
            row.0
        );
        // No fluid particle inside a disc.
        for b in 0..8 {
            let centre = circle_centre(&discs[b], k, circles[b]);
            let inside = (0..kind.len())
                .filter(|&i| kind[i] == 0)
                .filter(|&i| (pos[3 * i] - centre.0).hypot(pos[3 * i + 1] - centre.1) < radius)
                .count();
            assert_eq!(
                inside, 0,
                "t = {}: {inside} fluid particles inside disc {b}",
                row.0
            );
        }
        let lowest = (0..body.len())
            .filter(|&i| body[i] >= 0)
            .map(|i| pos[3 * i + 1])
            .fold(f64::MAX, f64::min);
        assert!(
            lowest > 0.25 * spacing,
            "t = {}: a disc's particle at y = {lowest}",
            row.0
        );
        for a in 0..8 {
            for b in (0..8).filter(|&b| b != a) {
                let centre = circle_centre(&discs[b], k, circles[b]);
                let nearest = (0..body.len())
                    .filter(|&i| body[i] == a as i32)
                    .map(|i| (pos[3 * i] - centre.0).hypot(pos[3 * i + 1] - centre.1) - radius)
                    .fold(f64::MAX, f64::min);
                assert!(
                    nearest > 0.25 * spacing,
                    "t = {}: a particle of disc {a} {nearest} m outside disc {b}'s circle",
                    row.0
                );
            }
        }
    }
    (0..8)
        .map(|b| [mean_after(&discs[b], 0, 2.0), mean_after(&discs[b], Y, 2.0)])
        .collect()
}

/// Where the circle of a 2D body whose rows are `rows` is at frame `k`, `start` its centre at
/// t = 0: the lattice particles' centre of mass (the rows' x, y) is off the circle's centre by
/// a fraction of a spacing, and that offset turns with the body.
fn circle_centre(rows: &[(f64, Vec<f64>)], k: usize, start: [f64; 2]) -> (f64, f64) {
    let (first, now) = (&rows[0].1, &rows[k].1);
    let offset = [start[0] - first[0], start[1] - first[Y]];
    // The quaternion of a turn about z by θ: w = cos(θ/2), z = sin(θ/2).
    let angle = 2.0 * now[6].atan2(now[3]);
    let (sin, cos) = angle.sin_cos();
    (
        now[0] + cos * offset[0] - sin * offset[1],
        now[Y] + sin * offset[0] + cos * offset[1],
    )
}

/// A UV sphere of `radius` about `centre` as an ASCII STL: `rings` × 2 `rings` quads, the caps
/// fans, faces wound outwards.
fn sphere_stl(centre: [f64; 3], radius: f64, rings: usize) -> String {
    let point = |i: usize, j: usize| -> [f64; 3] {
        // The seam and the poles exactly shared: an STL's facets join at equal vertices.
        let j = j % (2 * rings);
        if i == 0 || i == rings {
            let sign = if i == 0 { 1.0 } else { -1.0 };
            return [centre[0], centre[1], centre[2] + sign * radius];
        }
        let (theta, phi) = (
            std::f64::consts::PI * i as f64 / rings as f64,
            std::f64::consts::PI * j as f64 / rings as f64,
        );
        [
            centre[0] + radius * theta.sin() * phi.cos(),
            centre[1] + radius * theta.sin() * phi.sin(),
            centre[2] + radius * theta.cos(),
        ]
    };
    let mut text = String::from("solid sphere\n");
    let mut facet = |a: [f64; 3], b: [f64; 3], c: [f64; 3]| {
        text += "facet normal 0 0 0\nouter loop\n";
        for v in [a, b, c] {
            text += &format!("vertex {:?} {:?} {:?}\n", v[0], v[1], v[2]);
        }
        text += "endloop\nendfacet\n";
    };
    for i in 0..rings {
        for j in 0..2 * rings {
            let (a, b, c, d) = (
                point(i, j),
                point(i + 1, j),
                point(i + 1, j + 1),
                point(i, j + 1),
            );
            if i > 0 {
                facet(a, b, d);
            }
            if i + 1 < rings {
                facet(b, c, d);
            }
        }
    }
    text + "endsolid sphere\n"
}

#[test]
fn a_closed_mesh_fills_a_body_or_a_fluid_block_with_its_volume() {
    // A sphere 30 spacings across as a triangle mesh (an STL of 1024 facets, the poles' rows
    // merged): its particles fill N dx³ within 2% of the mesh's own volume (VALIDATION.md,
    // "Mesh filling"), and each lies inside the mesh by the winding number.
    let dir = TempDir::new("bodies-mesh");
    let rings = 16;
    std::fs::write(
        dir.path().join("sphere.stl"),
        sphere_stl([0.0; 3], 0.15, rings),
    )
    .unwrap();
    let body = "[[body]]\nshape = \"mesh\"\nmesh = \"sphere.stl\"\noffset = [0.3, 0.3, 0.4]\ndensity = 500.0\n";
    let text = tank(3, 0.01, [0.6, 0.6, 0.6], 0.1, 0.05, body);
    let path = dir.path().join("mesh.toml");
    std::fs::write(&path, text).unwrap();
    let scene = isph::Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let isph::scene::Shape::Mesh(mesh) = &scene.bodies[0].shape else {
        panic!("not a mesh")
    };
    let particles = isph::fill::build::<3>(&scene);
    let count = particles
        .kind
        .iter()
        .filter(|k| **k == isph::particles::Kind::Body)
        .count();
    let volume = count as f64 * 1e-6;
    let error = volume / mesh.volume() - 1.0;
    eprintln!(
        "{count} particles: {volume} m³ against the mesh's {} ({:+.2}%)",
        mesh.volume(),
        100.0 * error
    );
    assert!(
        error.abs() < 0.02,
        "particle volume {volume} against {}",
        mesh.volume()
    );
    // The box test of the same cube as a mesh fills the same lattice points as a box.
    let cube = "v 0.2 0.2 0.3\nv 0.4 0.2 0.3\nv 0.2 0.4 0.3\nv 0.4 0.4 0.3\nv 0.2 0.2 0.45\nv 0.4 0.2 0.45\nv 0.2 0.4 0.45\nv 0.4 0.4 0.45\nf 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
    std::fs::write(dir.path().join("cube.obj"), cube).unwrap();
    let count_of = |body: &str| {
        let path = dir.path().join("cube.toml");
        std::fs::write(&path, tank(3, 0.01, [0.6, 0.6, 0.6], 0.1, 0.05, body)).unwrap();
        let scene = isph::Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
        isph::fill::build::<3>(&scene)
            .kind
            .iter()
            .filter(|k| **k == isph::particles::Kind::Body)
            .count()
    };
    let as_mesh = count_of("[[body]]\nshape = \"mesh\"\nmesh = \"cube.obj\"\ndensity = 500.0\n");
    let as_box = count_of("[[body]]\nshape = \"box\"\nmin = [0.2, 0.2, 0.3]\nmax = [0.4, 0.4, 0.45]\ndensity = 500.0\n");
    assert_eq!(as_mesh, as_box);
    // A fluid block from the sphere's mesh (a ball of water in the air) holds the same lattice
    // points as the body did.
    let ball =
        "[[fluid_block]]\nfluid = \"water\"\nmesh = \"sphere.stl\"\noffset = [0.3, 0.3, 0.4]\n";
    let path = dir.path().join("ball.toml");
    std::fs::write(&path, tank(3, 0.01, [0.6, 0.6, 0.6], 0.1, 0.05, ball)).unwrap();
    let scene = isph::Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let water = isph::fill::build::<3>(&scene).fluid_count();
    let floor = 60 * 60 * 10;
    assert_eq!(water - floor, count, "a ball of water from the mesh");
    // `isph measure` refuses a scene whose first block, the column its references are for, is a
    // mesh: the box around it is not the water.
    let only_ball = crate::common::water_block_scene_3d([0.0; 3], [0.6, 0.6, 0.6], 1.0, 0.1, "")
        .replace(
            "min = [0.0, 0.0, 0.0]\nmax = [0.0, 0.0, 0.0]",
            "mesh = \"sphere.stl\"\noffset = [0.3, 0.3, 0.4]",
        );
    std::fs::write(&path, only_ball).unwrap();
    let scene = isph::Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    for case in [
        isph::validation::Case::Hydrostatic,
        isph::validation::Case::DamBreakFront,
    ] {
        let error = isph::validation::check(case, &scene)
            .unwrap_err()
            .to_string();
        assert!(error.contains("first fluid block is a mesh"), "{error}");
    }
}

/// The lattice positions of the body particles a scene's `[[body]]` text fills, in a 2D tank.
fn body_lattice(body: &str) -> std::collections::BTreeSet<[i64; 2]> {
    let scene = scene_from_text(&tank(2, 0.01, [1.0, 0.6, 0.0], 0.3, 0.05, body));
    let particles = isph::fill::build::<2>(&scene);
    (0..particles.kind.len())
        .filter(|&i| particles.kind[i] == isph::particles::Kind::Body)
        .map(|i| {
            particles
                .position(i)
                .map(|x| (x / 0.01 - 0.5).round() as i64)
        })
        .collect()
}

#[test]
fn a_union_fills_the_lattice_points_of_any_of_its_parts_once_and_floats_upright() {
    // A hull 0.2 × 0.08 m with a mast 0.04 × 0.08 m standing on it, overlapping it by a row:
    // the union holds each lattice point of either part once.
    let hull = "shape = \"box\"\nmin = [0.4, 0.252]\nmax = [0.6, 0.332]\n";
    let mast = "shape = \"box\"\nmin = [0.48, 0.322]\nmax = [0.52, 0.412]\n";
    let union = format!(
        "[[body]]\nshape = \"union\"\ndensity = 500.0\n[[body.part]]\n{hull}[[body.part]]\n{mast}"
    );
    let both = body_lattice(&union);
    let parts =
        [hull, mast].map(|part| body_lattice(&format!("[[body]]\n{part}density = 500.0\n")));
    assert_eq!(both, &parts[0] | &parts[1]);
    assert!(
        both.len() < parts[0].len() + parts[1].len(),
        "the parts overlap"
    );
    // At s = 0.5 it floats upright (KG 0.053 m under KM 0.093 m) with its keel at the draft
    // Archimedes gives, 9.6 kg/m over 0.2 m of water line: 0.048 m. Started there, its centre
    // belongs 0.0533 m over the keel, at 0.3053 m (the level stays at 0.3 m).
    let dir = TempDir::new("bodies-union");
    run_scene(
        &scene_from_text(&tank(2, 0.01, [1.0, 0.6, 0.0], 0.3, 0.05, &union)),
        dir.path(),
        1.5,
    );
    let rows = rows(dir.path(), 0);
    let centre = mean_after(&rows, Y, 0.5);
    let tilt = rows
        .iter()
        .map(|r| 2.0 * r.1[QZ].asin().abs().to_degrees())
        .fold(0.0, f64::max);
    eprintln!(
        "centre {centre} m (draft error {:+.1}%), tilt at most {tilt}°",
        100.0 * (0.3053 - centre) / 0.048
    );
    assert!(tilt < 3.0, "tilted by {tilt}°");
    // First order in the spacing, 5 particles in the draft (docs/bodies.md, "Archimedes"):
    // +9.3% here, +7% for the plain box of the Archimedes test measured by its centre alike.
    assert!(
        (centre - 0.3053).abs() < 0.12 * 0.048,
        "centre at {centre} m against 0.3053 m"
    );
}

/// The momentum balance takes the fluid's force at the middle of each step, extrapolated from
/// the last two (`Bodies::advance`): a force rising linearly in time, given at each step's
/// start as the step's solve gives it, moves a free body as its exact integral does (to
/// round-off), where the force of the step's start alone lags it by half a step. The first
/// wet step after one in the air takes its force as it is.
#[test]
fn a_free_body_feels_the_fluids_force_at_the_middle_of_each_step() {
    let scene = scene_from_text(&tank(
        2,
        0.01,
        [0.6, 0.4, 0.0],
        0.3,
        0.05,
        "[[body]]\nshape = \"circle\"\ncenter = [0.3, 0.15]\nradius = 0.05\ndensity = 1500.0\n",
    ));
    let mut sim = isph::Simulation::<2>::new(&scene).unwrap();
    let bodies = &mut sim.bodies;
    let (mass, v0) = (bodies.bodies[0].mass, bodies.bodies[0].state.velocity[1]);
    // F(t) = f0 + k t on the body, gravity's share of the impulse as the body forces give it.
    let (f0, k, dt, steps) = (3.0, 40.0, 1e-3, 50);
    let weight = -9.81 * mass;
    for n in 0..steps {
        let t = n as f64 * dt;
        let force = f0 + k * t;
        let impulse = [0.0, (force + weight) * dt, 0.0];
        let water = [[0.0, force, 0.0], [0.0; 3]];
        bodies.advance(0, [impulse, [0.0; 3]], water, [[0.0; 3]; 2], true, t, dt);
    }
    let end = steps as f64 * dt;
    // The first step takes F(0), the others F at their middle: the integral less k dt²/2.
    let exact = v0 + (f0 * end + 0.5 * k * end * end - 0.5 * k * dt * dt + weight * end) / mass;
    let lagged = v0 + (f0 * end + 0.5 * k * end * (end - dt) + weight * end) / mass;
    let v = bodies.bodies[0].state.velocity[1];
    assert!(
        (v - exact).abs() < 1e-12 * exact.abs().max(1.0),
        "v = {v} against {exact} (the force of each step's start: {lagged})"
    );
}

/// A held body is let go at its release time exactly, not at the end of the step across it:
/// a step lands on the release as on a frame, whatever the frames' interval.
#[test]
fn a_held_body_is_let_go_at_its_release_time() {
    let dir = TempDir::new("bodies-release");
    let body = "[[body]]\nshape = \"circle\"\ncenter = [0.3, 0.15]\nradius = 0.05\ndensity = 1500.0\nmotion = \"fixed\"\nrelease = 0.05\n";
    let scene = scene_from_text(&tank(2, 0.01, [0.6, 0.4, 0.0], 0.3, 0.03, body));
    run_scene(&scene, dir.path(), 0.09);
    let times = stats_column(dir.path(), "time");
    assert!(
        times.contains(&0.05),
        "no step ends at the release: {times:?}"
    );
    // Held to the release, moving after it.
    let rows = rows(dir.path(), 0);
    for (t, r) in &rows {
        let moving = r[VX].hypot(r[VY]) > 0.0;
        assert_eq!(moving, *t > 0.05, "t = {t}: velocity {:?}", &r[VX..VX + 2]);
    }
}
