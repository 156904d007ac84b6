//! A new solver is one folder under `plugins/` and one line in `beltrami::registry()`
//! (with its path in the root manifest): `affine` (docs/adding-a-solver.md) was added so,
//! and every front end reaches it with no edit of its own. The command line lists it,
//! runs it and measures it; a batch job runs it; Python's `beltrami.solve` reaches it
//! (python/tests/test_solve.py).

mod common;

use common::{beltrami, s, text};
use serde_json::Value;

/// A planar disk: the generated square at level 1 (its boundary is free for `affine`).
fn square(dir: &std::path::Path) -> std::path::PathBuf {
    let path = dir.join("square.obj");
    let out = beltrami(&["generate", "square", "--level", "1", "-o", s(&path)]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    path
}

#[test]
fn the_affine_solver_is_listed_run_and_measured_by_the_command_line() {
    let out = beltrami(&["solvers", "--json"]);
    assert!(out.status.success());
    let solvers: Value = serde_json::from_slice(&out.stdout).unwrap();
    let affine = solvers
        .as_array()
        .and_then(|list| list.iter().find(|s| s["name"] == "affine"))
        .expect("affine in `solvers --json`");
    assert_eq!(
        affine["accepts"]["goals"],
        serde_json::json!(["prescribed-mu"])
    );
    let help = text(&beltrami(&["qc", "--help"]).stdout);
    assert!(help.contains("affine"), "qc --help: {help}");

    let dir = tempfile::tempdir().unwrap();
    let mesh = square(dir.path());
    let output = dir.path().join("affine.obj");
    let out = beltrami(&[
        "qc",
        s(&mesh),
        "--solver",
        "affine",
        "--mu-expr",
        "0.3+0.4i",
        "-o",
        s(&output),
        "--json",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let report: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["solver"], "affine");
    let measured = beltrami(&["distortion", s(&mesh), s(&output), "--json"]);
    assert!(measured.status.success(), "{}", text(&measured.stderr));
    let measured: Value = serde_json::from_slice(&measured.stdout).unwrap();
    for key in ["mu_mean", "mu_max"] {
        let value = measured[key].as_f64().unwrap_or(f64::NAN);
        assert!((value - 0.5).abs() < 1e-12, "{key} {value}: {measured}");
    }
}

#[test]
fn a_batch_job_runs_the_affine_solver() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = square(dir.path());
    let output = dir.path().join("out.obj");
    let jobs = dir.path().join("jobs.jsonl");
    let job = serde_json::json!({
        "command": "qc", "input": s(&mesh), "output": s(&output),
        "options": {"solver": "affine", "mu-expr": "0.2"},
    });
    std::fs::write(&jobs, format!("{job}\n")).unwrap();
    let report = dir.path().join("report.jsonl");
    let out = beltrami(&["-q", "batch", s(&jobs), "--report", s(&report)]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let line: Value =
        serde_json::from_str(std::fs::read_to_string(&report).unwrap().trim()).unwrap();
    assert_eq!(line["status"], "ok", "{line}");
    assert_eq!(line["report"]["solver"], "affine", "{line}");
    assert!(output.exists());
}
