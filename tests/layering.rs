//! The layers of `src/` hold (lib.rs's module doc, README "Layout"): every `crate::` path of
//! every source file is checked against the modules its layer may use, and the graph of
//! file-to-file imports has no circle. The checker itself is tested on a forbidden import.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// Each layer (a module path prefix) with the paths it may use; the most specific prefix
/// wins. A module may always use its own folder.
const RULES: &[(&str, &[&str])] = &[
    ("math", &[]),
    ("scene", &["math"]),
    ("particles", &["math"]),
    (
        "bodies",
        &["math", "scene::BodyMotion", "scene::Scene", "particles"],
    ),
    ("neighbours", &["math", "particles"]),
    (
        "boundary",
        &["math", "scene::trajectory", "particles", "neighbours"],
    ),
    ("sph", &["math", "particles", "neighbours", "boundary"]),
    // The Krylov solver and the multigrid never see particles.
    ("solver::krylov", &["math"]),
    ("solver::multigrid", &["math", "solver::krylov"]),
    (
        "solver",
        &["math", "particles", "neighbours", "boundary", "sph"],
    ),
    // An effect reads its own settings only, and no other effect (checked below).
    (
        "effects",
        &[
            "math",
            "particles",
            "neighbours",
            "boundary",
            "sph",
            "scene::ShiftingSettings",
            "scene::LesSettings",
        ],
    ),
    ("fill", &["math", "scene", "particles", "boundary::faces"]),
    // Only the step orders the stages: its stage files are private to it.
    (
        "step",
        &[
            "math",
            "scene::Effects",
            "scene::GhostPressure",
            "scene::ShiftingSettings",
            "scene::LesSettings",
            "particles",
            "bodies",
            "neighbours",
            "boundary",
            "sph",
            "solver",
            "effects",
        ],
    ),
    // The surface sees particle positions as slices, never the simulation.
    (
        "surface",
        &[
            "math",
            "scene::SurfaceSettings",
            "scene::SurfaceKernel",
            "scene::CubeRule",
        ],
    ),
    // io never imports the step or the solver.
    ("io", &["math", "scene", "particles", "bodies", "surface"]),
    (
        "simulation",
        &[
            "math",
            "scene",
            "fill",
            "particles",
            "bodies",
            "neighbours",
            "boundary",
            "sph",
            "solver",
            "step",
            "io::stats",
        ],
    ),
    (
        "run",
        &[
            "math",
            "scene",
            "particles",
            "bodies",
            "simulation",
            "step::timings",
            "surface",
            "io",
        ],
    ),
    // Pictures of a run's files: frames and meshes, never the simulation.
    ("render", &["math", "scene", "surface", "io"]),
    (
        "tools",
        &[
            "math",
            "scene",
            "fill",
            "particles",
            "bodies",
            "neighbours",
            "boundary",
            "sph",
            "solver",
            "effects",
            "step",
            "simulation",
            "surface",
            "io",
            "run",
            "render",
        ],
    ),
];

/// The module path of a file under `src/` ("step::density", "step" for step/mod.rs).
fn module_of(file: &Path) -> String {
    let mut parts: Vec<String> = file
        .iter()
        .map(|c| c.to_string_lossy().trim_end_matches(".rs").to_string())
        .collect();
    if parts.last().is_some_and(|p| p == "mod") {
        parts.pop();
    }
    parts.join("::")
}

/// Every `crate::…` path a source text uses, one per imported item: `use` statements
/// (their braces expanded, nested ones too, across lines) and paths written inline in code.
/// Comments are skipped.
fn crate_paths(source: &str) -> Vec<String> {
    let code: String = source
        .lines()
        .map(|l| match l.find("//") {
            Some(k) => &l[..k],
            None => l,
        })
        .collect::<Vec<_>>()
        .join("\n");
    let mut paths = Vec::new();
    let mut rest = code.as_str();
    while let Some(k) = rest.find("crate::") {
        let after = &rest[k + "crate::".len()..];
        let taken = use_tree("", after, &mut paths);
        rest = &after[taken..];
    }
    paths
}

/// Expands the `use` tree at the start of `text` (a path, optionally ending in `{…}` groups)
/// under `prefix` into `out`; returns how much of `text` it took.
fn use_tree(prefix: &str, text: &str, out: &mut Vec<String>) -> usize {
    let text_start = text.len() - text.trim_start().len();
    let text = text.trim_start();
    let end = text
        .find(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
        .unwrap_or(text.len());
    let head = text[..end].trim_end_matches(':');
    let path = match (prefix, head) {
        (p, "self") | (p, "") => p.to_string(),
        ("", h) => h.to_string(),
        (p, h) => format!("{p}::{h}"),
    };
    if !text[end..].starts_with('{') {
        out.push(path);
        return text_start + end;
    }
    // The group's items, split at the commas outside nested braces.
    let (mut depth, mut item_start, mut k) = (0, end + 1, end);
    for (i, c) in text[end..].char_indices() {
        k = end + i;
        match c {
            '{' => depth += 1,
            '}' => depth -= 1,
            ',' if depth == 1 => {
                use_tree(&path, &text[item_start..k], out);
                item_start = k + 1;
            }
            _ => {}
        }
        if depth == 0 {
            break;
        }
    }
    if !text[item_start..k].trim().is_empty() {
        use_tree(&path, &text[item_start..k], out);
    }
    text_start + k + 1
}

fn starts_with_path(path: &str, prefix: &str) -> bool {
    path == prefix || path.starts_with(&format!("{prefix}::"))
}

/// The imports of `module` that its layer forbids.
fn forbidden(module: &str, paths: &[String]) -> Vec<String> {
    let Some((layer, allowed)) = RULES
        .iter()
        .filter(|(layer, _)| starts_with_path(module, layer))
        .max_by_key(|(layer, _)| layer.len())
    else {
        return Vec::new(); // lib.rs and the binary: checked apart.
    };
    let folder = layer.split("::").next().unwrap_or(layer);
    paths
        .iter()
        .filter(|path| {
            let own = starts_with_path(path, folder);
            // An effect never imports another effect.
            let other_effect =
                folder == "effects" && own && path.split("::").nth(1) != module.split("::").nth(1);
            // Inside the solver the layering of its files holds as between folders.
            let solver_inner = folder == "solver" && *layer != "solver";
            let inside = own && !other_effect && !solver_inner;
            !(inside || allowed.iter().any(|a| starts_with_path(path, a)))
        })
        .cloned()
        .collect()
}

fn source_files(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            source_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// Every module under `src/` with the `crate::` paths it uses.
fn modules() -> BTreeMap<String, Vec<String>> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    source_files(&src, &mut files);
    files
        .iter()
        .map(|f| {
            let module = module_of(f.strip_prefix(&src).unwrap());
            (module, crate_paths(&std::fs::read_to_string(f).unwrap()))
        })
        .collect()
}

/// The module a path names: its longest prefix that is a module.
fn target(path: &str, modules: &BTreeMap<String, Vec<String>>) -> Option<String> {
    let parts: Vec<&str> = path.split("::").collect();
    (1..=parts.len())
        .rev()
        .map(|k| parts[..k].join("::"))
        .find(|m| modules.contains_key(m))
}

/// A circle in the graph of imports between modules, if any (a module's imports of itself
/// and of its own parent folder's facade do not count).
fn circle(modules: &BTreeMap<String, Vec<String>>) -> Option<Vec<String>> {
    let edges: BTreeMap<&str, BTreeSet<String>> = modules
        .iter()
        .map(|(m, paths)| {
            let to = paths
                .iter()
                .filter_map(|p| target(p, modules))
                .filter(|t| t != m && !starts_with_path(m, t))
                .collect();
            (m.as_str(), to)
        })
        .collect();
    // Depth-first search with the path on the stack.
    fn visit<'a>(
        m: &'a str,
        edges: &'a BTreeMap<&'a str, BTreeSet<String>>,
        stack: &mut Vec<&'a str>,
        done: &mut BTreeSet<&'a str>,
    ) -> Option<Vec<String>> {
        if let Some(k) = stack.iter().position(|&s| s == m) {
            let mut c: Vec<String> = stack[k..].iter().map(|s| s.to_string()).collect();
            c.push(m.to_string());
            return Some(c);
        }
        if !done.insert(m) {
            return None;
        }
        stack.push(m);
        for t in edges.get(m).into_iter().flatten() {
            if let Some((key, _)) = edges.get_key_value(t.as_str()) {
                if let Some(c) = visit(key, edges, stack, done) {
                    return Some(c);
                }
            }
        }
        stack.pop();
        None
    }
    let mut done = BTreeSet::new();
    for &m in edges.keys() {
        if let Some(c) = visit(m, &edges, &mut Vec::new(), &mut done) {
            return Some(c);
        }
    }
    None
}

#[test]
fn every_import_keeps_to_its_layer() {
    let modules = modules();
    assert!(
        modules.contains_key("step::pressure_solve"),
        "src/ not found"
    );
    let bad: Vec<String> = modules
        .iter()
        .flat_map(|(m, paths)| {
            forbidden(m, paths)
                .into_iter()
                .map(move |p| format!("{m} uses crate::{p}"))
        })
        .collect();
    assert!(
        bad.is_empty(),
        "imports the layering forbids:\n{}",
        bad.join("\n")
    );
}

#[test]
fn no_module_imports_itself_in_a_circle() {
    let modules = modules();
    assert_eq!(circle(&modules), None, "an import circle");
}

#[test]
fn the_command_line_uses_the_facade_only() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let main = std::fs::read_to_string(root.join("main.rs")).unwrap();
    let lib = std::fs::read_to_string(root.join("lib.rs")).unwrap();
    let modules: Vec<&str> = lib
        .lines()
        .filter_map(|l| l.strip_prefix("pub mod "))
        .map(|m| m.trim_end_matches(';'))
        .collect();
    let deep: Vec<&str> = main
        .match_indices("isph::")
        .map(|(k, _)| {
            let after = &main[k + "isph::".len()..];
            let end = after
                .find(|c: char| !(c.is_alphanumeric() || c == '_'))
                .unwrap_or(after.len());
            &after[..end]
        })
        .filter(|name| {
            let re_exported = lib.contains(&format!(" {name},"))
                || lib.contains(&format!(" {name};"))
                || lib.contains(&format!("::{name},"))
                || lib.contains(&format!("::{name};"))
                || lib.contains(&format!("{{{name},"));
            modules.contains(name) && !re_exported
        })
        .collect();
    assert!(
        deep.is_empty(),
        "main.rs reaches past the facade: isph::{deep:?}"
    );
}

#[test]
fn the_checker_finds_a_forbidden_import_and_a_circle() {
    // The PPE's Krylov solver may not see particles; io may not see the step.
    let krylov =
        crate_paths("use crate::math::reduce::dot;\nuse crate::particles::{Kind, Particles};\n");
    assert_eq!(
        forbidden("solver::krylov", &krylov),
        ["particles::Kind", "particles::Particles"]
    );
    let io = crate_paths("use crate::particles::Particles;\nfn f() { crate::step::StepSettings::<2>::ghost_gravity; }\n");
    assert_eq!(forbidden("io::stats", &io), ["step::StepSettings"]);
    // An effect may not use another; a comment is not an import.
    let les = crate_paths("// crate::step::Step\nuse crate::effects::shifting::Shifting;\n");
    // Nested groups: every item is seen.
    let nested =
        crate_paths("use crate::{sph::{self, interface::Field}, step::{Step, time_step::Limit}};");
    assert_eq!(
        nested,
        [
            "sph",
            "sph::interface::Field",
            "step::Step",
            "step::time_step::Limit"
        ]
    );
    assert_eq!(
        forbidden("effects::les", &les),
        ["effects::shifting::Shifting"]
    );
    assert!(forbidden(
        "effects::les",
        &crate_paths("use crate::effects::les::KARMAN;")
    )
    .is_empty());
    // a → b → a.
    let mut modules = BTreeMap::new();
    modules.insert("a".to_string(), vec!["b::f".to_string()]);
    modules.insert("b".to_string(), vec!["a::g".to_string()]);
    assert_eq!(
        circle(&modules),
        Some(vec!["a".into(), "b".into(), "a".into()])
    );
    modules.insert("b".to_string(), vec![]);
    assert_eq!(circle(&modules), None);
}
