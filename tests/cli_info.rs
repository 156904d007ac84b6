//! End-to-end runs of `beltrami info` on the bundled mesh and on bad input.

use std::path::{Path, PathBuf};

mod common;
use common::{beltrami, text};

fn write(dir: &Path, name: &str, content: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, content).unwrap();
    p
}

#[test]
fn info_prints_the_topology_of_the_bundled_mesh() {
    let out = beltrami(&["info", "meshes/disk_hemisphere.obj"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    for line in [
        "vertices        1861",
        "edges           5460",
        "faces           3600 (3600 triangles, 0 quads)",
        "components      1",
        "boundary        1 loop with 120 vertices",
        "euler char.     1",
        "genus           0",
        "manifold        yes",
        "orientable      yes (0 faces re-oriented)",
    ] {
        assert!(stdout.contains(line), "missing `{line}` in\n{stdout}");
    }
}

#[test]
fn info_json_has_the_documented_keys() {
    let out = beltrami(&["info", "--json", "meshes/disk_hemisphere.obj"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["vertices"], 1861);
    assert_eq!(v["edges"], 5460);
    assert_eq!(v["faces"], 3600);
    assert_eq!(v["triangles"], 3600);
    assert_eq!(v["quads"], 0);
    assert_eq!(v["components"], 1);
    assert_eq!(v["boundary_loops"], serde_json::json!([120]));
    assert_eq!(v["euler_characteristic"], 1);
    assert_eq!(v["genus"], 0);
    // A spherical cap of the unit sphere above z = 0.098: area 2 pi (1 - 0.098), less
    // the chordal loss of the triangulation.
    let area = v["area"].as_f64().unwrap();
    let cap = 2.0 * std::f64::consts::PI * (1.0 - 0.0980170965);
    assert!(area < cap && area > 0.99 * cap, "area {area} vs cap {cap}");
}

#[test]
fn a_non_manifold_mesh_fails_with_the_edge_and_its_faces() {
    let dir = tempfile::tempdir().unwrap();
    // Three triangles on the edge (0, 1).
    let path = write(
        dir.path(),
        "fin.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n",
    );
    let out = beltrami(&["info", path.to_str().unwrap()]);
    assert!(!out.status.success());
    assert!(out.stdout.is_empty());
    let err = text(&out.stderr);
    assert!(
        err.contains("edge (0, 1) is non-manifold") && err.contains("[0, 1, 2]"),
        "{err}"
    );
}

#[test]
fn repair_is_offered_and_reported_never_silent() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(
        dir.path(),
        "dup.obj",
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\nf 1 2 3\n",
    );
    let path = path.to_str().unwrap();
    let out = beltrami(&["info", path]);
    assert!(!out.status.success());
    let err = text(&out.stderr);
    assert!(err.contains("face 2 duplicates face 0"), "{err}");
    assert!(err.contains("--repair"), "{err}");

    let out = beltrami(&["info", "--repair", path]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(
        text(&out.stderr).contains("dropped 1 duplicate faces [2]"),
        "{}",
        text(&out.stderr)
    );
    assert!(text(&out.stdout).contains("faces           2"));
}

#[test]
fn unreadable_and_unknown_files_fail_cleanly() {
    let out = beltrami(&["info", "no/such/mesh.obj"]);
    assert!(!out.status.success());
    assert!(text(&out.stderr).contains("cannot read no/such/mesh.obj"));

    let out = beltrami(&["info", "Cargo.toml"]);
    assert!(!out.status.success());
    assert!(text(&out.stderr).contains("unknown mesh format"));
}

#[test]
fn every_command_has_help() {
    for args in [
        &["--help"][..],
        &["info", "--help"],
        &["bench", "load", "--help"],
    ] {
        let out = beltrami(args);
        assert!(out.status.success(), "{args:?}");
        assert!(text(&out.stdout).contains("Usage"), "{args:?}");
    }
}

/// The `--solver` help of `param` and `qc` names every registered solver of their
/// goals, as `solvers --json` describes them: a solver added to the registry shows up
/// without editing the help.
#[test]
fn the_solver_help_lists_every_registered_solver_of_the_command() {
    let out = beltrami(&["solvers", "--json"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let solvers: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let list = |value: &serde_json::Value, key: &str| -> Vec<String> {
        value["accepts"][key]
            .as_array()
            .unwrap()
            .iter()
            .map(|k| k.as_str().unwrap().to_owned())
            .collect()
    };
    let mut expected = [(vec![], "param"), (vec![], "qc")];
    for solver in solvers.as_array().unwrap() {
        let name = solver["name"].as_str().unwrap().to_owned();
        let goals = list(solver, "goals");
        // A registration (onto a mesh) and a remeshing (on the source surface itself)
        // map into no parameter domain.
        if list(solver, "targets")
            .iter()
            .all(|t| t == "mesh" || t == "surface")
        {
            continue;
        }
        if goals.iter().any(|g| g == "conformal") {
            expected[0].0.push(name.clone());
        }
        if goals
            .iter()
            .any(|g| g == "prescribed-mu" || g == "extremal")
        {
            expected[1].0.push(name);
        }
    }
    assert!(expected[1].0.contains(&"qc-iteration".to_owned()));
    for (names, command) in expected {
        let out = beltrami(&[command, "--help"]);
        let help = text(&out.stdout)
            .split_whitespace()
            .collect::<Vec<_>>()
            .join(" ");
        let listed = format!("Solver name ({};", names.join(", "));
        assert!(help.contains(&listed), "`{listed}` missing in\n{help}");
    }
}
