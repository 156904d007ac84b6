//! DESIGN.md's dependency rule, checked on the manifests: a plugin depends on no plugin
//! but `init` (shared numerics live in crates); library crates depend on no plugin.

use std::path::{Path, PathBuf};

/// The package names of the folders under `dir` (their `Cargo.toml`'s `name`).
fn packages(dir: &Path) -> Vec<(String, PathBuf)> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let manifest = entry.unwrap().path().join("Cargo.toml");
        let Ok(text) = std::fs::read_to_string(&manifest) else {
            continue;
        };
        let name = text
            .lines()
            .find_map(|l| l.trim().strip_prefix("name = "))
            .map(|n| n.trim_matches('"').to_string())
            .unwrap();
        out.push((name, manifest));
    }
    out
}

/// The names under `[dependencies]` of a manifest (not dev-dependencies).
fn dependencies(manifest: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(manifest).unwrap();
    let mut inside = false;
    let mut out = Vec::new();
    for line in text.lines() {
        let line = line.trim();
        if line.starts_with('[') {
            inside = line == "[dependencies]";
            continue;
        }
        if inside
            && let Some((name, _)) = line.split_once(['.', '=', ' '])
            && !name.is_empty()
        {
            out.push(name.to_string());
        }
    }
    out
}

#[test]
fn plugins_depend_on_no_plugin_but_init() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let plugins = packages(&root.join("plugins"));
    let names: Vec<&str> = plugins.iter().map(|(n, _)| n.as_str()).collect();
    assert!(
        names.contains(&"beltrami-init") && names.len() >= 4,
        "{names:?}"
    );
    for (name, manifest) in &plugins {
        for dep in dependencies(manifest) {
            assert!(
                dep == "beltrami-init" || !names.contains(&dep.as_str()),
                "the plugin {name} depends on the plugin {dep}"
            );
        }
    }
    for (name, manifest) in packages(&root.join("crates")) {
        for dep in dependencies(&manifest) {
            assert!(
                !names.contains(&dep.as_str()),
                "the library crate {name} depends on the plugin {dep}"
            );
        }
    }
}
