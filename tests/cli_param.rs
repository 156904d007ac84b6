//! End-to-end runs of `beltrami param` and `beltrami solvers` on the bundled mesh and
//! on bad input: the written OBJ/GLB, the JSON report, pins, boundaries and errors.

use std::collections::HashMap;
use std::path::Path;
use std::process::Output;

use beltrami_mesh::Mesh;
use beltrami_mesh::io::{self, VertexAttributes};
use beltrami_mesh::primitives::{Cells, torus};

mod common;
use common::{beltrami, s, text};

const HEMISPHERE: &str = "meshes/disk_hemisphere.obj";

/// Runs `beltrami param` and fails the test (with its stderr) unless it succeeds.
fn param(args: &[&str]) -> Output {
    let mut all = vec!["param"];
    all.extend_from_slice(args);
    let out = beltrami(&all);
    assert!(
        out.status.success(),
        "beltrami {all:?} failed:\n{}",
        text(&out.stderr)
    );
    out
}

/// The parts of an OBJ file the tests look at.
#[derive(Debug, Default)]
struct Obj {
    positions: Vec<[f64; 3]>,
    /// The `v` lines' coordinates as written, to pass them back on the command line.
    position_text: Vec<String>,
    uvs: Vec<[f64; 2]>,
    /// Every face corner as (vertex, texture coordinate), both 0-based.
    faces: Vec<Vec<(usize, Option<usize>)>>,
}

fn read_obj(path: &Path) -> Obj {
    let content = std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    let mut obj = Obj::default();
    let numbers = |rest: &str| -> Vec<f64> {
        rest.split_whitespace()
            .map(|t| {
                t.parse::<f64>()
                    .unwrap_or_else(|_| panic!("bad number {t}"))
            })
            .collect()
    };
    for line in content.lines() {
        if let Some(rest) = line.strip_prefix("v ") {
            let c = numbers(rest);
            assert_eq!(c.len(), 3, "`{line}`");
            obj.positions.push([c[0], c[1], c[2]]);
            obj.position_text
                .push(rest.split_whitespace().collect::<Vec<_>>().join(","));
        } else if let Some(rest) = line.strip_prefix("vt ") {
            let c = numbers(rest);
            assert_eq!(c.len(), 2, "`{line}`");
            obj.uvs.push([c[0], c[1]]);
        } else if let Some(rest) = line.strip_prefix("f ") {
            let corners = rest
                .split_whitespace()
                .map(|corner| {
                    let mut parts = corner.split('/');
                    let v = parts.next().unwrap().parse::<usize>().unwrap() - 1;
                    let t = parts
                        .next()
                        .filter(|t| !t.is_empty())
                        .map(|t| t.parse::<usize>().unwrap() - 1);
                    (v, t)
                })
                .collect();
            obj.faces.push(corners);
        }
    }
    obj
}

/// The vertices on a boundary edge (an edge used by exactly one face).
fn boundary_vertices(obj: &Obj) -> Vec<bool> {
    let mut edges: HashMap<(usize, usize), usize> = HashMap::new();
    for face in &obj.faces {
        for k in 0..face.len() {
            let (a, b) = (face[k].0, face[(k + 1) % face.len()].0);
            *edges.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    let mut on = vec![false; obj.positions.len()];
    for ((a, b), n) in edges {
        if n == 1 {
            on[a] = true;
            on[b] = true;
        }
    }
    on
}

fn read_json(path: &Path) -> serde_json::Value {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_slice(&bytes).unwrap()
}

#[test]
fn lscm_writes_the_input_with_one_uv_per_vertex_and_a_report() {
    let dir = tempfile::tempdir().unwrap();
    let out_path = dir.path().join("out.obj");
    let report_path = dir.path().join("report.json");
    param(&[
        HEMISPHERE,
        "--solver",
        "lscm",
        "-o",
        s(&out_path),
        "--report",
        s(&report_path),
    ]);

    let input = read_obj(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join(HEMISPHERE)
            .as_path(),
    );
    let output = read_obj(&out_path);
    assert_eq!(input.positions.len(), 1861);
    assert_eq!(output.positions, input.positions, "the `v` lines changed");
    assert_eq!(
        output.uvs.len(),
        output.positions.len(),
        "one vt per vertex"
    );
    assert!(output.uvs.iter().flatten().all(|x| x.is_finite()));
    assert_eq!(output.faces.len(), input.faces.len());
    for (k, (o, i)) in output.faces.iter().zip(&input.faces).enumerate() {
        let vertices: Vec<usize> = o.iter().map(|c| c.0).collect();
        let expected: Vec<usize> = i.iter().map(|c| c.0).collect();
        assert_eq!(vertices, expected, "face {k}");
        assert!(
            o.iter().all(|&(v, t)| t == Some(v)),
            "face {k} is not written `f a/a b/b c/c`: {o:?}"
        );
    }
    // The map is not degenerate: the uvs span a region of size about the mesh's.
    let (min, max) = output.uvs.iter().fold(
        ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]),
        |(lo, hi), t| {
            (
                [lo[0].min(t[0]), lo[1].min(t[1])],
                [hi[0].max(t[0]), hi[1].max(t[1])],
            )
        },
    );
    assert!(
        max[0] - min[0] > 0.5 && max[1] - min[1] > 0.5,
        "{min:?} {max:?}"
    );

    let report = read_json(&report_path);
    for key in [
        "solver", "seconds", "flipped", "mu_mean", "mu_max", "mu_std",
    ] {
        assert!(!report[key].is_null(), "report lacks `{key}`: {report}");
    }
    assert_eq!(report["solver"], "lscm");
    assert_eq!(report["flipped"], 0);
    assert!(report["seconds"].as_f64().unwrap() >= 0.0);
    let (mean, max, std) = (
        report["mu_mean"].as_f64().unwrap(),
        report["mu_max"].as_f64().unwrap(),
        report["mu_std"].as_f64().unwrap(),
    );
    assert!(mean > 0.0 && mean < 0.02, "mu_mean {mean}");
    assert!(max >= mean && max < 1.0, "mu_max {max}");
    assert!(std >= 0.0 && std <= max, "mu_std {std}");
}

#[test]
fn tutte_on_the_square_puts_the_boundary_on_the_square_and_the_rest_inside() {
    let dir = tempfile::tempdir().unwrap();
    let out_path = dir.path().join("square.obj");
    let report_path = dir.path().join("square.json");
    param(&[
        HEMISPHERE,
        "--solver",
        "tutte",
        "--boundary",
        "square",
        "--weights",
        "mean-value",
        "-o",
        s(&out_path),
        "--report",
        s(&report_path),
    ]);
    let output = read_obj(&out_path);
    let boundary = boundary_vertices(&output);
    assert_eq!(boundary.iter().filter(|&&b| b).count(), 120);
    assert_eq!(output.uvs.len(), output.positions.len());
    let mut corners = 0;
    for (v, (t, &on)) in output.uvs.iter().zip(&boundary).enumerate() {
        let [x, y] = *t;
        let inside = |c: f64| (-1e-12..=1.0 + 1e-12).contains(&c);
        assert!(
            inside(x) && inside(y),
            "vertex {v} at {t:?} is off the square"
        );
        let dist = x
            .abs()
            .min((1.0 - x).abs())
            .min(y.abs())
            .min((1.0 - y).abs());
        if on {
            assert!(
                dist < 1e-12,
                "boundary vertex {v} at {t:?} is off the square's sides"
            );
            let corner = |c: f64| c.abs() < 1e-12 || (1.0 - c).abs() < 1e-12;
            if corner(x) && corner(y) {
                corners += 1;
            }
        } else {
            assert!(
                dist > 1e-9,
                "interior vertex {v} at {t:?} is on the square's sides"
            );
        }
    }
    assert_eq!(corners, 4, "the four corners of the square are taken");
    let report = read_json(&report_path);
    assert_eq!(report["solver"], "tutte");
    assert_eq!(report["flipped"], 0);
}

#[test]
fn harmonic_on_the_circle_puts_the_boundary_on_the_unit_circle() {
    let dir = tempfile::tempdir().unwrap();
    let out_path = dir.path().join("circle.obj");
    let report_path = dir.path().join("circle.json");
    param(&[
        HEMISPHERE,
        "--solver",
        "harmonic",
        "--boundary",
        "circle",
        "-o",
        s(&out_path),
        "--report",
        s(&report_path),
    ]);
    let output = read_obj(&out_path);
    let boundary = boundary_vertices(&output);
    for (v, (t, &on)) in output.uvs.iter().zip(&boundary).enumerate() {
        let r = t[0].hypot(t[1]);
        if on {
            assert!((r - 1.0).abs() < 1e-9, "boundary vertex {v}: |vt| = {r}");
        } else {
            assert!(r < 1.0 - 1e-9, "interior vertex {v}: |vt| = {r}");
        }
    }
    assert_eq!(read_json(&report_path)["solver"], "harmonic");
}

#[test]
fn lscm_pins_go_to_zero_and_one() {
    let dir = tempfile::tempdir().unwrap();
    let out_path = dir.path().join("pinned.obj");
    param(&[
        HEMISPHERE,
        "--solver",
        "lscm",
        "--pin",
        "v5",
        "--pin",
        "v100",
        "-o",
        s(&out_path),
    ]);
    let uv = read_obj(&out_path).uvs;
    let near = |t: [f64; 2], x: f64, y: f64| (t[0] - x).abs() <= 1e-12 && (t[1] - y).abs() <= 1e-12;
    assert!(near(uv[5], 0.0, 0.0), "vertex 5 at {:?}", uv[5]);
    assert!(near(uv[100], 1.0, 0.0), "vertex 100 at {:?}", uv[100]);
    // Only the pinned vertex sits at the origin.
    assert!(
        uv.iter().filter(|t| near(**t, 0.0, 0.0)).count() == 1,
        "only vertex 5 is at the origin"
    );
}

#[test]
fn a_pin_given_as_a_point_picks_the_nearest_vertex() {
    let dir = tempfile::tempdir().unwrap();
    let input = read_obj(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join(HEMISPHERE)
            .as_path(),
    );
    // A point typed exactly as the file has vertex 37.
    let vertex = 37;
    let point = input.position_text[vertex].clone();
    assert_eq!(point.split(',').count(), 3);
    let out_path = dir.path().join("near.obj");
    param(&[
        HEMISPHERE,
        "--solver",
        "lscm",
        "--pin",
        &point,
        "--pin",
        "v100",
        "-o",
        s(&out_path),
    ]);
    let uv = read_obj(&out_path).uvs;
    let at_origin: Vec<usize> = (0..uv.len())
        .filter(|&v| uv[v][0].abs() <= 1e-12 && uv[v][1].abs() <= 1e-12)
        .collect();
    assert_eq!(at_origin, vec![vertex], "pin {point}");
    assert!((uv[100][0] - 1.0).abs() <= 1e-12 && uv[100][1].abs() <= 1e-12);
}

#[test]
fn glb_output_has_the_magic_and_reads_back() {
    let dir = tempfile::tempdir().unwrap();
    let out_path = dir.path().join("out.glb");
    param(&[HEMISPHERE, "--solver", "lscm", "-o", s(&out_path)]);
    let bytes = std::fs::read(&out_path).unwrap();
    assert!(bytes.len() > 12 && &bytes[..4] == b"glTF", "no GLB magic");

    let info = |path: &str| {
        let out = beltrami(&["info", "--json", path]);
        assert!(out.status.success(), "{}", text(&out.stderr));
        serde_json::from_slice::<serde_json::Value>(&out.stdout).unwrap()
    };
    let (back, original) = (info(s(&out_path)), info(HEMISPHERE));
    assert_eq!(back["faces"], 3600);
    assert_eq!(back["faces"], original["faces"]);
    assert_eq!(back["vertices"], original["vertices"]);
    assert_eq!(back["genus"], 0);
}

/// Writes a genus-1 torus as OBJ.
fn write_torus(path: &Path) {
    let mesh = Mesh::from_soup(&torus(16, 8, 3.0, 1.0, Cells::Triangles)).unwrap();
    io::obj::write(path, &mesh, &VertexAttributes::default()).unwrap();
}

#[test]
fn a_torus_fails_with_the_genus_and_the_advice_and_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("torus.obj");
    write_torus(&input);
    for solver in ["lscm", "tutte", "harmonic"] {
        let output = dir.path().join(format!("torus_{solver}.obj"));
        let out = beltrami(&["param", s(&input), "--solver", solver, "-o", s(&output)]);
        assert!(!out.status.success(), "{solver} succeeded on a torus");
        let err = text(&out.stderr);
        assert!(
            err.contains("genus 1") && err.contains("beltrami cut"),
            "{solver}: {err}"
        );
        assert!(!output.exists(), "{solver} wrote {}", output.display());
    }
}

#[test]
fn an_unknown_solver_lists_the_available_ones() {
    let dir = tempfile::tempdir().unwrap();
    let output = dir.path().join("out.obj");
    let out = beltrami(&["param", HEMISPHERE, "--solver", "nope", "-o", s(&output)]);
    assert!(!out.status.success());
    let err = text(&out.stderr);
    assert!(err.contains("nope"), "{err}");
    for name in ["tutte", "harmonic", "lscm"] {
        assert!(err.contains(name), "`{name}` missing in: {err}");
    }
    assert!(!output.exists());
}

#[test]
fn a_pin_beyond_the_mesh_names_the_index() {
    let dir = tempfile::tempdir().unwrap();
    let output = dir.path().join("out.obj");
    let out = beltrami(&[
        "param",
        HEMISPHERE,
        "--solver",
        "lscm",
        "--pin",
        "v999999",
        "--pin",
        "v1",
        "-o",
        s(&output),
    ]);
    assert!(!out.status.success());
    let err = text(&out.stderr);
    assert!(err.contains("v999999") && err.contains("1861"), "{err}");
    assert!(!output.exists());

    let out = beltrami(&[
        "param",
        HEMISPHERE,
        "--solver",
        "lscm",
        "--pin",
        "w3",
        "-o",
        s(&output),
    ]);
    assert!(!out.status.success());
    assert!(text(&out.stderr).contains("w3"), "{}", text(&out.stderr));
}

#[test]
fn an_unknown_output_format_fails_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let output = dir.path().join("out.xyz");
    let out = beltrami(&["param", HEMISPHERE, "--solver", "lscm", "-o", s(&output)]);
    assert!(!out.status.success());
    let err = text(&out.stderr);
    assert!(
        err.contains("out.xyz") && err.contains("unknown output format"),
        "{err}"
    );
    assert!(!output.exists());
    assert!(out.stdout.is_empty(), "{}", text(&out.stdout));

    // The format is checked before the solver looks at the mesh: a torus, which every
    // solver rejects, still gets the format error.
    let input = dir.path().join("torus.obj");
    write_torus(&input);
    let out = beltrami(&["param", s(&input), "--solver", "lscm", "-o", s(&output)]);
    assert!(!out.status.success());
    let err = text(&out.stderr);
    assert!(
        err.contains("unknown output format") && !err.contains("genus"),
        "{err}"
    );
}

#[test]
fn solvers_lists_the_registered_solvers() {
    let out = beltrami(&["solvers"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    for name in ["tutte", "harmonic", "lscm"] {
        assert!(
            stdout.lines().any(|l| l.starts_with(name)),
            "`{name}` missing in\n{stdout}"
        );
    }

    let out = beltrami(&["solvers", "--json"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let list = v.as_array().expect("a JSON array");
    let names: Vec<&str> = list.iter().map(|s| s["name"].as_str().unwrap()).collect();
    for name in ["tutte", "harmonic", "lscm"] {
        assert!(names.contains(&name), "{names:?}");
    }
    for s in list {
        let description = s["description"].as_str().unwrap_or_default();
        assert!(!description.is_empty(), "{} has no description", s["name"]);
        // What it accepts, as data: non-empty lists of stable kind names.
        for key in ["elements", "topologies", "targets", "goals"] {
            let list = s["accepts"][key].as_array();
            assert!(
                list.is_some_and(|l| !l.is_empty() && l.iter().all(|x| x.is_string())),
                "{} accepts no {key}: {s}",
                s["name"]
            );
        }
        assert!(s["accepts"]["constraints"].is_array(), "{s}");
        // Its options: name, type, default, help; numbers with a range.
        for option in s["options"].as_array().expect("an options array") {
            for key in ["name", "type", "help"] {
                assert!(option[key].is_string(), "{option}");
            }
            assert!(!option["default"].is_null(), "{option}");
            if matches!(option["type"].as_str(), Some("float" | "int")) {
                assert!(
                    option["min"].is_number() && option["max"].is_number(),
                    "{option}"
                );
            }
        }
    }
    let by_name = |name: &str| list.iter().find(|s| s["name"] == name).unwrap();
    let lscm = by_name("lscm");
    assert_eq!(
        lscm["accepts"]["targets"],
        serde_json::json!(["plane-free"])
    );
    assert_eq!(
        lscm["accepts"]["constraints"],
        serde_json::json!(["hold", "pin"])
    );
    let weights = &by_name("tutte")["options"][0];
    assert_eq!(weights["name"], "weights");
    assert_eq!(weights["default"], "uniform");
    assert_eq!(
        weights["choices"],
        serde_json::json!(["uniform", "mean-value"])
    );
    let flow = by_name("beltrami-flow");
    let tolerance = flow["options"]
        .as_array()
        .unwrap()
        .iter()
        .find(|o| o["name"] == "tolerance")
        .expect("the flow declares its tolerance");
    assert_eq!(tolerance["type"], "float");
    assert_eq!(tolerance["default"], 1e-6);
}

#[test]
fn solver_options_are_checked_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let out_path = dir.path().join("out.obj");
    let out = beltrami(&[
        "param",
        HEMISPHERE,
        "--solver",
        "tutte",
        "--option",
        "weights=cotan",
        "-o",
        out_path.to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    let err = text(&out.stderr);
    assert!(
        err.contains("option `weights` is one of uniform, mean-value, got `cotan`"),
        "{err}"
    );
    assert!(!out_path.exists(), "no output after a refused option");
    let out = beltrami(&[
        "param",
        HEMISPHERE,
        "--solver",
        "lscm",
        "-O",
        "treads=2",
        "-o",
        out_path.to_str().unwrap(),
    ]);
    let err = text(&out.stderr);
    assert!(
        !out.status.success() && err.contains("lscm has no option `treads`; its options: threads"),
        "{err}"
    );
    let out = beltrami(&[
        "param",
        HEMISPHERE,
        "--solver",
        "tutte",
        "-O",
        "weights=mean-value",
        "-o",
        out_path.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
}

#[test]
fn param_and_solvers_have_help() {
    for args in [&["param", "--help"][..], &["solvers", "--help"]] {
        let out = beltrami(args);
        assert!(out.status.success(), "{args:?}");
        assert!(text(&out.stdout).contains("Usage"), "{args:?}");
    }
}

#[test]
fn the_sphere_solver_maps_onto_the_sphere_unless_a_boundary_is_asked() {
    let dir = tempfile::tempdir().unwrap();
    let sphere = dir.path().join("sphere.obj");
    let out = beltrami(&["generate", "sphere", "--level", "2", "-o", s(&sphere)]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let output = dir.path().join("out.obj");
    param(&[s(&sphere), "--solver", "sphere", "-o", s(&output)]);
    for p in read_obj(&output).positions {
        let r = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        assert!((r - 1.0).abs() < 1e-9, "|p| = {r}");
    }
    // A planar boundary goes to the solver as asked, and it refuses it.
    let output = dir.path().join("circle.obj");
    let out = beltrami(&[
        "param",
        s(&sphere),
        "--solver",
        "sphere",
        "--boundary",
        "circle",
        "-o",
        s(&output),
    ]);
    assert!(!out.status.success());
    assert!(
        text(&out.stderr).contains("maps onto the unit sphere"),
        "{}",
        text(&out.stderr)
    );
    assert!(!output.exists());
}
