//! Dependencies point down: a module of the core may `use` modules of its own layer or of the
//! layers below it, never one above. The table of layers is [`LAYERS`] (the one place it is kept);
//! this test reads the crate's source and fails on a reference to a layer above (and on a module
//! the table does not place). Test code (`#[cfg(test)]` modules, `tests*.rs`, `*_tests.rs`) and
//! comments are not looked at.

use std::collections::BTreeMap;
use std::path::Path;

/// The layers from the bottom up, each with the modules (or sub-modules: the longest prefix
/// wins) it holds.
const LAYERS: &[(&str, &[&str])] = &[
    ("base", &["time", "error", "events", "output"]),
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
const KNOWN: &[(&str, &str, &str)] = &[(
    "profile::sections",
    "device",
    "[device] is validated against the part declarations (device::part) and the error-model presets",
)];

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
