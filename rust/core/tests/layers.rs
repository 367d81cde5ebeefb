//! Dependencies point down: a module of the core may `use` modules of its own layer or of the
//! layers below it, never one above. The table of layers is [`LAYERS`] (the one place it is kept);
//! this test reads the crate's source and fails on a reference to a layer above (and on a module
//! the table does not place). Test code (`#[cfg(test)]` modules, `tests*.rs`, `*_tests.rs`) and
//! comments are not looked at. Inside a layer the modules may use each other, but not in a circle:
//! [`no_module_cycles`] fails on a cycle of modules (as `device::adis` and `device::slave` once were).

use std::collections::BTreeMap;
use std::path::Path;

/// The layers from the bottom up, each with the modules (or sub-modules: the longest prefix
/// wins) it holds.
const LAYERS: &[(&str, &[&str])] = &[
    ("base", &["time", "error", "events", "deadline", "output"]),
    // The parts' declarations as data (register maps, burst lists, ranges, timing figures) and the
    // output words' encoding they name: the profile validates its `[device]` keys against them.
    // The links' common door (`bus::door`: `Link`, `Address`, a built `Device`), in whose terms the
    // profile's link-kind registry is written.
    ("declarations", &["device::encoding", "device::part", "device::parts", "device::spi_timing", "bus::door"]),
    // The board as data: the profile and the cost table (both read from TOML).
    ("profile", &["profile", "timing::costs"]),
    // The wires and the MCU's end of them: the link kinds with the slave-side contracts the parts
    // implement, and the F28335's peripherals (SPI-A, clocks, CPU timer).
    ("links", &["bus", "dsp"]),
    // The parts: the ADIS16xxx family and its declarations, the signal path, the replay.
    ("parts", &["device"]),
    // The board composed: its devices on their links, the static board summary; the board without
    // firmware that host-side drivers reach (the Python Board, the C ABI).
    ("board", &["board", "dsp::summary", "host"]),
    ("firmware", &["firmware", "numerics"]),
    // The timing model prices the firmware's own stages (it runs their code).
    ("timing", &["timing"]),
    ("emulator", &["emulator"]),
];

/// References that break the rule today, each with its reason; the test fails when one of them
/// disappears too (then strike it from this list).
const KNOWN: &[(&str, &str, &str)] = &[];

/// Names at the crate root that belong to a module.
const ROOT_NAMES: &[(&str, &str)] =
    &[("Error", "error"), ("Result", "error"), ("dispatch_numeric", "numerics"), ("VERSION", "base")];

fn layer_of(module: &str) -> Option<(usize, &'static str)> {
    let mut best: Option<(usize, usize, &'static str)> = None;
    for (rank, (name, modules)) in LAYERS.iter().enumerate() {
        for m in *modules {
            let hit = module == *m || module.starts_with(&format!("{m}::"));
            if hit && best.is_none_or(|(len, _, _)| m.len() > len) {
                best = Some((m.len(), rank, name));
            }
        }
    }
    best.map(|(_, rank, name)| (rank, name))
}

/// The module paths `source` refers to through `crate::` (first two segments), non-test code only.
fn references(source: &str) -> Vec<String> {
    let code: String = source
        .lines()
        .take_while(|l| !l.trim_start().starts_with("#[cfg(test)]"))
        .map(|l| format!("{}\n", l.split("//").next().unwrap_or("")))
        .collect();
    let mut out = Vec::new();
    let mut rest = code.as_str();
    while let Some(i) = rest.find("crate::") {
        rest = &rest[i + "crate::".len()..];
        if let Some(group) = rest.strip_prefix('{') {
            // `crate::{a::b, c}`: each item at the group's top level.
            let (mut depth, mut item) = (0, String::new());
            for ch in group.chars() {
                match ch {
                    '{' => depth += 1,
                    '}' if depth == 0 => break,
                    '}' => depth -= 1,
                    ',' if depth == 0 => out.push(std::mem::take(&mut item)),
                    _ => item.push(ch),
                }
            }
            out.push(item);
        } else {
            out.push(rest.chars().take_while(|c| c.is_alphanumeric() || *c == '_' || *c == ':').collect());
        }
    }
    out.into_iter()
        .map(|r| r.split_whitespace().collect::<String>())
        .filter(|r| !r.is_empty())
        .map(|r| r.split("::").take(2).filter(|s| !s.is_empty()).collect::<Vec<_>>().join("::"))
        .map(|r| match ROOT_NAMES.iter().find(|(n, _)| r.split("::").next() == Some(*n)) {
            Some((_, m)) => m.to_string(),
            None => r,
        })
        .collect()
}

/// Every breach of the rule in `files` (module path → source): `(from, to, what)`.
fn breaches(files: &BTreeMap<String, String>) -> Vec<(String, String, String)> {
    let mut out = Vec::new();
    for (module, source) in files {
        if module == "lib" {
            continue;
        }
        let Some((rank, layer)) = layer_of(module) else {
            out.push((module.clone(), String::new(), format!("`{module}` is in no layer of LAYERS")));
            continue;
        };
        for target in references(source) {
            match layer_of(&target) {
                None if ROOT_NAMES.iter().any(|(_, m)| *m == target) => {}
                None => out.push((module.clone(), target.clone(), format!("`{target}` is in no layer of LAYERS"))),
                Some((r, l)) if r > rank => out.push((
                    module.clone(),
                    target.clone(),
                    format!("`{module}` ({layer}) uses `{target}` ({l}), a layer above"),
                )),
                Some(_) => {}
            }
        }
    }
    out.sort();
    out.dedup();
    out
}

fn is_test_file(name: &str) -> bool {
    name == "tests.rs" || name.starts_with("tests_") || name.ends_with("_tests.rs")
}

fn crate_sources() -> BTreeMap<String, String> {
    fn walk(dir: &Path, prefix: &str, out: &mut BTreeMap<String, String>) {
        let mut entries: Vec<_> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().path()).collect();
        entries.sort();
        for p in entries {
            let name = p.file_name().unwrap().to_string_lossy().to_string();
            if p.is_dir() {
                walk(&p, &format!("{prefix}{name}::"), out);
            } else if name.ends_with(".rs") && !is_test_file(&name) {
                let stem = name.trim_end_matches(".rs");
                let module =
                    if stem == "mod" { prefix.trim_end_matches("::").to_string() } else { format!("{prefix}{stem}") };
                out.insert(module, std::fs::read_to_string(&p).unwrap());
            }
        }
    }
    let mut out = BTreeMap::new();
    walk(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src"), "", &mut out);
    out
}

#[test]
fn dependencies_point_down() {
    let found = breaches(&crate_sources());
    let unknown: Vec<_> = found
        .iter()
        .filter(|(from, to, _)| !KNOWN.iter().any(|(f, t, _)| from == f && to.split("::").next() == Some(t)))
        .map(|b| b.2.clone())
        .collect();
    assert!(unknown.is_empty(), "layer breaches:\n{}", unknown.join("\n"));
    for (from, to, why) in KNOWN {
        assert!(
            found.iter().any(|(f, t, _)| f == from && t.split("::").next() == Some(to)),
            "`{from}` no longer uses `{to}` ({why}): strike it from KNOWN"
        );
    }
}

/// The checker catches a deliberate breach (the firmware reaching up into the emulator, a
/// grouped `use`, a module the table does not place) and lets the downward ones pass.
#[test]
fn a_deliberate_breach_is_caught() {
    let files: BTreeMap<String, String> = [
        ("firmware::isr", "use crate::board::Board;\nuse crate::{error::Result, emulator::Emulator};\n"),
        ("device::adis", "use crate::bus::SpiSlave; // crate::emulator in a comment\n"),
        ("bus::link", "fn f() -> crate::Result<()> { Ok(()) }\n#[cfg(test)]\nmod tests { use crate::emulator::X; }\n"),
        ("gadget", "use crate::time::Ps;\n"),
    ]
    .into_iter()
    .map(|(m, s)| (m.to_string(), s.to_string()))
    .collect();
    let found: Vec<String> = breaches(&files).into_iter().map(|b| b.2).collect();
    assert_eq!(
        found,
        [
            "`firmware::isr` (firmware) uses `emulator::Emulator` (emulator), a layer above".to_string(),
            "`gadget` is in no layer of LAYERS".to_string(),
        ]
    );
}

/// The modules (first two path segments) that module `module`'s non-test code uses, through
/// `crate::` paths or, from a module one level down, `super::` paths.
fn module_uses(module: &str, source: &str) -> Vec<String> {
    let key = |m: &str| m.split("::").take(2).collect::<Vec<_>>().join("::");
    let mut out: Vec<String> = references(source).iter().map(|r| key(r)).collect();
    let segments: Vec<&str> = module.split("::").collect();
    if segments.len() == 2 {
        let code: String = source
            .lines()
            .take_while(|l| !l.trim_start().starts_with("#[cfg(test)]"))
            .map(|l| format!("{}\n", l.split("//").next().unwrap_or("")))
            .collect();
        for (i, _) in code.match_indices("super::") {
            let name: String =
                code[i + "super::".len()..].chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
            if !name.is_empty() {
                out.push(format!("{}::{name}", segments[0]));
            }
        }
    }
    out.retain(|t| *t != key(module));
    out.sort();
    out.dedup();
    out
}

/// A cycle in the graph of module uses, if there is one (as the modules on it).
fn find_cycle(edges: &BTreeMap<String, Vec<String>>) -> Option<Vec<String>> {
    fn visit(
        node: &str,
        edges: &BTreeMap<String, Vec<String>>,
        state: &mut BTreeMap<String, u8>,
        path: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        match state.get(node) {
            Some(2) => return None,
            Some(1) => {
                let from = path.iter().position(|m| m == node).unwrap_or(0);
                return Some(path[from..].iter().cloned().chain([node.to_string()]).collect());
            }
            _ => {}
        }
        state.insert(node.to_string(), 1);
        path.push(node.to_string());
        for next in edges.get(node).into_iter().flatten() {
            if let Some(cycle) = visit(next, edges, state, path) {
                return Some(cycle);
            }
        }
        path.pop();
        state.insert(node.to_string(), 2);
        None
    }
    let mut state = BTreeMap::new();
    edges.keys().find_map(|m| visit(m, edges, &mut state, &mut Vec::new()))
}

fn module_graph(files: &BTreeMap<String, String>) -> BTreeMap<String, Vec<String>> {
    let key = |m: &str| m.split("::").take(2).collect::<Vec<_>>().join("::");
    let keys: Vec<String> = files.keys().map(|m| key(m)).collect();
    // A path names the module it is in: `board::Board` is in `board`.
    let resolve = |t: &str| {
        let first = t.split("::").next().unwrap_or("");
        [t, first].into_iter().find(|k| keys.iter().any(|m| m == k)).map(str::to_string)
    };
    let mut edges: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for (module, source) in files {
        let from = key(module);
        let uses: Vec<String> =
            // A module and its own sub-modules (declared and re-exported by it) are one unit here.
            module_uses(module, source)
                .iter()
                .filter_map(|t| resolve(t))
                .filter(|t| !(t.starts_with(&from) || from.starts_with(t.as_str())))
                .collect();
        let all = edges.entry(from).or_default();
        all.extend(uses);
        all.sort();
        all.dedup();
    }
    edges
}

#[test]
fn no_module_cycles() {
    let graph = module_graph(&crate_sources());
    assert_eq!(find_cycle(&graph), None, "modules that use each other in a circle");
}

/// The cycle check finds a cycle of two sibling modules through `super::` and one through
/// `crate::` paths, and passes a chain.
#[test]
fn a_deliberate_cycle_is_caught() {
    let files = |list: &[(&str, &str)]| -> BTreeMap<String, String> {
        list.iter().map(|(m, s)| (m.to_string(), s.to_string())).collect()
    };
    let two = files(&[("device::a", "use super::b::X;\n"), ("device::b", "use super::a::Y;\n")]);
    assert_eq!(find_cycle(&module_graph(&two)), Some(vec!["device::a".into(), "device::b".into(), "device::a".into()]));
    let three = files(&[
        ("bus::x", "use crate::dsp::spi::S;\n"),
        ("dsp::spi", "fn f() -> crate::board::B {}\n"),
        ("board", "use crate::bus::x::T;\n"),
    ]);
    assert!(find_cycle(&module_graph(&three)).is_some());
    let chain = files(&[("device::a", "use super::b::X;\n"), ("device::b", "use crate::time::Ps;\n")]);
    assert_eq!(find_cycle(&module_graph(&chain)), None);
}
