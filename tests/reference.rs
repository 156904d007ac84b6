//! docs/reference.md is what `beltrami reference` prints from the argument parser and
//! the solver registry: a flag, a default or a solver option changed without
//! regenerating the file fails here.

mod common;

use common::*;

#[test]
fn the_reference_page_is_the_programs_own() {
    let out = beltrami(&["reference"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let printed = text(&out.stdout);
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/reference.md");
    let written = std::fs::read_to_string(&path).unwrap();
    assert!(
        printed == written,
        "docs/reference.md is out of date: run `cargo run --release -- reference > docs/reference.md`"
    );
    // Every visible command and every registered solver has its section.
    for command in [
        "info",
        "distortion",
        "param",
        "qc",
        "register",
        "generate",
        "solvers",
        "bench",
        "render",
        "view",
        "histogram",
        "cut",
        "remesh",
        "atlas",
        "batch",
    ] {
        assert!(
            printed.contains(&format!("\n## `beltrami {command}`\n")),
            "{command}"
        );
    }
    assert!(!printed.contains("## `beltrami reference`"));
    let solvers = beltrami(&["solvers", "--json"]);
    let list: serde_json::Value = serde_json::from_slice(&solvers.stdout).unwrap();
    for solver in list.as_array().unwrap() {
        let name = solver["name"].as_str().unwrap();
        assert!(printed.contains(&format!("\n### `{name}`\n")), "{name}");
        for option in solver["options"].as_array().unwrap() {
            let option = option["name"].as_str().unwrap();
            assert!(
                printed.contains(&format!("| `{option}` |")),
                "{name}: {option}"
            );
        }
    }
    // The atlas's new flag is there with its default.
    assert!(printed.contains("| `--charts <auto\\|N>` | `auto` |"));
}
