//! Effects (issue 3, item 6): a scene runs only the stages of the effects it asks for and
//! allocates only their arrays, `isph plan` says so, parameters of an effect that is off are
//! refused, and a scene without `[effects]` runs as with every default spelled out.

use crate::common::{run_scene, water_block_scene, TempDir};
use isph::math::memory::Holds;
use isph::scene::Scene;
use isph::simulation::Simulation;
use isph::tools::plan::Plan;
use std::path::Path;

/// A 10 × 10 block of water in a 20 × 15 box (`water_block_scene`), then `effects` appended.
fn scene_text(effects: &str) -> String {
    water_block_scene(0.2) + effects
}

fn parse(effects: &str) -> Result<Scene, String> {
    Scene::parse(&scene_text(effects), Path::new("scene.toml")).map_err(|e| e.to_string())
}

fn scene(effects: &str) -> Scene {
    parse(effects).unwrap_or_else(|e| panic!("{e}"))
}

const ALL_OFF: &str = r#"
[effects.shifting]
enabled = false

[effects.les]
enabled = false

[effects.kernel_correction]
enabled = false
"#;

/// Runs one step of `scene` and checks that the stages that ran, the arrays the step
/// allocated and the plan agree; returns the planned stages.
fn check_plan_against_a_step(scene: &Scene) -> Vec<&'static str> {
    let plan = Plan::new(scene).unwrap();
    let planned: Vec<&'static str> = plan.stages.iter().map(|s| s.stage).collect();
    let mut sim = Simulation::<2>::new(scene).unwrap();
    // A step that lands on a frame time: it runs every stage, the frame's wall pressure too.
    let (dt, _) = sim.time_step_limit().unwrap();
    sim.advance_towards(dt).unwrap();
    let n = sim.particles.len();
    assert_eq!(plan.particles(), n);

    let ran: Vec<&'static str> = sim
        .timings
        .names()
        .filter(|&s| sim.timings.runs(s) > 0)
        .collect();
    assert_eq!(ran, planned, "stages run vs plan");
    for &s in &ran {
        assert_eq!(sim.timings.runs(s), 1, "{s} ran more than once");
    }

    let arrays = sim.arrays();
    let fluid = sim.particles.fluid_count();
    for (stage, a) in &arrays {
        if planned.contains(stage) {
            // A sparse list (some particles only) may be empty; an array of every particle or
            // of every fluid particle is full.
            let elements = a.elements(n, fluid);
            if a.holds != Holds::Some {
                assert_eq!(a.len, elements, "{} ({stage}) not allocated", a.name,);
                assert!(a.allocated >= elements * a.bytes_per_element, "{}", a.name);
            }
        } else {
            assert_eq!(
                a.allocated, 0,
                "{} allocated, but {stage} is not planned",
                a.name,
            );
        }
    }
    for s in &plan.stages {
        let allocated: usize = arrays
            .iter()
            .filter(|(stage, a)| *stage == s.stage && a.holds != Holds::Some)
            .map(|(_, a)| a.len * a.bytes_per_element)
            .sum();
        assert_eq!(allocated, s.bytes, "{}", s.stage);
    }
    planned
}

/// Whether the step holds an allocated array of this name after a step (an effect that is off
/// has no stage, and so no array to list).
fn allocated_after_a_step(scene: &Scene, name: &str) -> bool {
    let mut sim = Simulation::<2>::new(scene).unwrap();
    sim.advance_towards(scene.output_interval).unwrap();
    let arrays = sim.arrays();
    arrays
        .iter()
        .find(|(_, a)| a.name == name)
        .is_some_and(|(_, a)| a.allocated > 0)
}

#[test]
fn the_plan_lists_the_stages_and_arrays_a_step_uses() {
    let optional = ["kernel correction", "eddy viscosity", "shifting"];
    let default = check_plan_against_a_step(&scene(""));
    assert!(optional.iter().all(|s| default.contains(s)));

    let cases = [
        ("[effects.les]\nenabled = false\n", "eddy viscosity"),
        ("[effects.shifting]\nenabled = false\n", "shifting"),
        (
            "[effects.kernel_correction]\nenabled = false\n",
            "kernel correction",
        ),
    ];
    for (effects, off) in cases {
        let stages = check_plan_against_a_step(&scene(effects));
        let expected: Vec<&str> = default.iter().copied().filter(|&s| s != off).collect();
        assert_eq!(stages, expected, "{effects}");
    }
    let all_off = check_plan_against_a_step(&scene(ALL_OFF));
    assert!(optional.iter().all(|s| !all_off.contains(s)));

    let no_wall_function = scene("[effects.les]\nwall_function = false\n");
    assert_eq!(check_plan_against_a_step(&no_wall_function), default);
}

#[test]
fn an_effect_that_is_off_allocates_no_array() {
    let cases = [
        ("les", "ν_t"),
        ("shifting", "δr"),
        ("shifting", "surface normal"),
        ("kernel_correction", "L"),
        ("kernel_correction", "L'"),
    ];
    for (effect, array) in cases {
        assert!(allocated_after_a_step(&scene(""), array), "{array}");
        let off = scene(&format!("[effects.{effect}]\nenabled = false\n"));
        assert!(
            !allocated_after_a_step(&off, array),
            "{array} with {effect} off"
        );
    }
}

#[test]
fn the_plan_prints_the_stages_in_order_with_their_memory() {
    for effects in ["", ALL_OFF] {
        let plan = Plan::new(&scene(effects)).unwrap();
        let text = plan.to_string();
        // Stage lines: "  3. free surface   44 B/particle  0.18 MiB  what …".
        let printed: Vec<(String, usize)> = text
            .lines()
            .filter_map(|l| l.trim_start().split_once(". "))
            .filter(|(k, _)| k.parse::<usize>().is_ok())
            .map(|(_, rest)| {
                let (name, rest) = rest.split_once("  ").unwrap();
                let bytes = rest.split_whitespace().next().unwrap().parse().unwrap();
                (name.to_string(), bytes)
            })
            .collect();
        let planned: Vec<(String, usize)> = plan
            .stages
            .iter()
            .map(|s| {
                let per_particle = (s.bytes as f64 / plan.particles() as f64).round() as usize;
                (s.stage.to_string(), per_particle)
            })
            .collect();
        assert_eq!(printed, planned, "{text}");
        let total = format!("memory: {} B/particle", plan.bytes_per_particle());
        assert!(text.contains(&total), "{text}");
    }
    let text = Plan::new(&scene(ALL_OFF)).unwrap().to_string();
    assert!(
        text.contains("effects: shifting off, LES off, kernel correction off"),
        "{text}"
    );
}

#[test]
fn a_parameter_of_an_effect_that_is_off_is_refused_with_its_key_and_line() {
    // The effects start on line 21 of the scene text: the parameter is on line 23.
    let cases = [
        ("les", "cs = 0.1", "effects.les.cs"),
        ("les", "wall_function = true", "effects.les.wall_function"),
        (
            "shifting",
            "coefficient = 2.0",
            "effects.shifting.coefficient",
        ),
        ("shifting", "max_shift = 0.1", "effects.shifting.max_shift"),
        (
            "shifting",
            "clustering_weight = 0.2",
            "effects.shifting.clustering_weight",
        ),
    ];
    for (effect, parameter, key) in cases {
        let effects = format!("[effects.{effect}]\nenabled = false\n{parameter}\n");
        let e = parse(&effects).expect_err(&effects);
        assert!(e.contains(&format!("scene.toml:23: `{key}`")), "{e}");
        assert!(e.contains("enabled = false"), "{e}");
    }
}

#[test]
fn bad_effect_values_and_keys_are_refused() {
    let cases = [
        (
            "[effects.les]\ncs = 0.0\n",
            "scene.toml:22: `effects.les.cs`",
        ),
        ("[effects.les]\ncs = 0.0\n", "enabled = false"),
        (
            "[effects.shifting]\ncoefficient = -1.0\n",
            "scene.toml:22: `effects.shifting.coefficient`",
        ),
        (
            "[effects.shifting]\nmax_shift = 2.0\n",
            "scene.toml:22: `effects.shifting.max_shift`",
        ),
        (
            "[effects.shifting]\nclustering_weight = -0.1\n",
            "`effects.shifting.clustering_weight`",
        ),
        (
            "[effects.les]\nsmagorinsky = 0.1\n",
            "unknown field `smagorinsky`",
        ),
        ("[effects.les]\nsmagorinsky = 0.1\n", "line 22"),
        ("[effects.turbulence]\n", "unknown field `turbulence`"),
        (
            "[effects.kernel_correction]\nenabled = \"no\"\n",
            "invalid type",
        ),
    ];
    for (effects, expected) in cases {
        let e = parse(effects).expect_err(effects);
        assert!(e.contains(expected), "`{expected}` missing from: {e}");
    }
}

#[test]
fn a_scene_without_effects_runs_as_with_every_default_spelled_out() {
    let spelled_out = r#"
[effects.shifting]
enabled = true
coefficient = 2.0
max_shift = 0.1
clustering_weight = 0.2

[effects.les]
enabled = true
cs = 0.2
wall_function = true

[effects.kernel_correction]
enabled = true
"#;
    let (default, explicit, off) = (scene(""), scene(spelled_out), scene(ALL_OFF));
    assert_eq!(default.effects, explicit.effects);
    assert_eq!(default.content_hash(), explicit.content_hash());
    assert_ne!(default.content_hash(), off.content_hash());

    let dir = TempDir::new("effects-defaults");
    let frames = |scene: &Scene, name: &str| {
        let out = dir.path().join(name);
        run_scene(scene, &out, scene.end_time);
        std::fs::read(out.join("particles.h5")).unwrap()
    };
    let reference = frames(&default, "default");
    assert!(reference == frames(&explicit, "explicit"), "frames differ");
    assert!(
        reference != frames(&off, "off"),
        "turning every effect off changed nothing"
    );
}
