//! The link-kind registry is complete in a crate that links `sins-core` as a library, as the binding
//! and the C ABI do: every `LinkKind` a source file under `src/` submits with `inventory::submit!`
//! (test-only files aside) is in `profile::link_kinds()`. The registry is built from linker sections
//! (`inventory`); a linker that drops an object file nothing else refers to would drop its kind, and
//! a profile placing a device on that kind's link would then be refused.

use std::path::Path;

use sins_core::board::links::{known_parts, BoardLinks};
use sins_core::profile::{link_kind, link_kinds, Profile};

/// The kinds the sources submit: `(name, links)` read from each `inventory::submit!` block of a
/// `LinkKind` in the files under `src/` that are not test modules (`tests*.rs`, compiled only with
/// `cfg(test)`, so absent from this build).
fn submitted_in_sources() -> Vec<(String, Vec<String>)> {
    fn walk(dir: &Path, out: &mut Vec<(String, Vec<String>)>) {
        let mut entries: Vec<_> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().path()).collect();
        entries.sort();
        for path in entries {
            let file = path.file_name().unwrap().to_string_lossy().to_string();
            if path.is_dir() {
                walk(&path, out);
            } else if file.ends_with(".rs") && !file.starts_with("tests") {
                let text = std::fs::read_to_string(&path).unwrap();
                for block in text.split("inventory::submit!").skip(1) {
                    // `{ LinkKind {` and its first field, `name:` (a mention in a comment has no field).
                    let block = block.trim_start().trim_start_matches('{').trim_start();
                    let Some(fields) = block.strip_prefix("LinkKind {") else { continue };
                    if !fields.trim_start().starts_with("name:") {
                        continue;
                    }
                    let field = |key: &str| -> &str {
                        let at = block.find(&format!("{key}:")).unwrap_or_else(|| panic!("{file}: no `{key}:`"));
                        block[at + key.len() + 1..].split(",\n").next().unwrap().trim()
                    };
                    let strings = |s: &str| -> Vec<String> {
                        s.split('"').skip(1).step_by(2).map(str::to_string).collect::<Vec<_>>()
                    };
                    let name = strings(field("name")).remove(0);
                    out.push((name, strings(field("links"))));
                }
            }
        }
    }
    let mut out = Vec::new();
    walk(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src"), &mut out);
    out.sort();
    out
}

#[test]
fn every_link_kind_the_sources_submit_is_registered() {
    let submitted = submitted_in_sources();
    let names: Vec<&str> = submitted.iter().map(|(n, _)| n.as_str()).collect();
    // The scan itself must find the kinds the board uses (else it proves nothing).
    for kind in ["i2c", "spi", "uart"] {
        assert!(names.contains(&kind), "the source scan found {names:?}, not `{kind}`");
    }
    let registered: Vec<(String, Vec<String>)> =
        link_kinds().iter().map(|k| (k.name.to_string(), k.links.iter().map(|l| l.to_string()).collect())).collect();
    assert_eq!(registered, submitted, "registered link kinds (left) against those the sources submit (right)");
    for (name, links) in &submitted {
        for link in links {
            assert_eq!(link_kind(link).map(|k| k.name), Some(name.as_str()), "the link `{link}`");
        }
    }
}

/// A profile placing a device on each kind's link is accepted and its board built: the profile and
/// the board find every kind.
#[test]
fn a_board_with_an_i2c_and_a_uart_device_is_built() {
    let text =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../../firmware_model/reference.toml"))
            .unwrap()
            + "\n[[board.devices]]\npart = \"HMC6343\"\nlink = \"i2c-a\"\naddress = 0x19\n\
           \n[[board.devices]]\npart = \"GR-87\"\nlink = \"sci-a\"\n";
    let p = Profile::from_toml(&text, "reference.toml + I²C and UART devices", &[]).unwrap();
    let links: Vec<&str> = p.board.devices.iter().map(|d| d.link.as_str()).collect();
    assert_eq!(links, ["spi-a", "i2c-a", "sci-a"]);
    let mut built = BoardLinks::from_profile(&p, &known_parts, true).unwrap();
    for link in ["i2c-a", "sci-a"] {
        assert!(built.link(link).is_some(), "the board has no `{link}`");
    }
}
