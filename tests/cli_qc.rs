//! End-to-end runs of `beltrami qc`: a constant `mu` from an expression is met exactly
//! with a free boundary, the written OBJ has one `vt` per vertex, the report has the
//! `|mu - target|` errors, and bad coefficients fail with the column, line or face.

use std::path::{Path, PathBuf};

use beltrami_mesh::Mesh;
use beltrami_mesh::io::{self, VertexAttributes};
use beltrami_mesh::primitives::{Cells, jittered_grid};

mod common;
use common::{beltrami, s, text};

/// Writes a jittered planar grid of the unit square as OBJ into `dir`.
fn planar_grid(dir: &Path, cells: Cells) -> (PathBuf, Mesh) {
    let mesh = Mesh::from_soup(&jittered_grid(8, 8, cells, 0.3, 71)).unwrap();
    let path = dir.join("grid.obj");
    io::write(&path, &mesh, &VertexAttributes::default()).unwrap();
    (path, mesh)
}

fn read_json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn constant_mu_expression_is_met_exactly_with_a_free_boundary() {
    let dir = tempfile::tempdir().unwrap();
    for cells in [Cells::Triangles, Cells::Quads] {
        let (mesh_path, mesh) = planar_grid(dir.path(), cells);
        let out_path = dir.path().join("out.obj");
        let report_path = dir.path().join("report.json");
        let out = beltrami(&[
            "qc",
            s(&mesh_path),
            "--solver",
            "lsqc",
            "--mu-expr",
            "0.2+0.1i",
            "--pin",
            "0,0",
            "--pin",
            "1,1",
            "-o",
            s(&out_path),
            "--report",
            s(&report_path),
        ]);
        assert!(out.status.success(), "{}", text(&out.stderr));
        assert!(text(&out.stdout).contains("|mu - target|"));
        let obj = std::fs::read_to_string(&out_path).unwrap();
        let vt = obj.lines().filter(|l| l.starts_with("vt ")).count();
        assert_eq!(vt, mesh.vertex_count());
        let report = read_json(&report_path);
        assert_eq!(report["solver"], "lsqc");
        assert_eq!(report["flipped"], 0);
        let l2 = report["mu_error_l2"].as_f64().unwrap();
        let sup = report["mu_error_sup"].as_f64().unwrap();
        assert!(l2 < 1e-10 && sup < 1e-10, "{cells:?}: {l2:e} {sup:e}");
    }
}

#[test]
fn varying_mu_prints_a_json_report() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh_path, _) = planar_grid(dir.path(), Cells::Triangles);
    let out_path = dir.path().join("out.obj");
    let out = beltrami(&[
        "qc",
        s(&mesh_path),
        "--mu-expr",
        "0.6*(z - 0.5 - 0.5i)",
        "-o",
        s(&out_path),
        "--json",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let report: serde_json::Value = serde_json::from_str(&text(&out.stdout)).unwrap();
    let l2 = report["mu_error_l2"].as_f64().unwrap();
    assert!(l2 > 0.0 && l2 < 0.05, "{l2:e}");
    assert!(out_path.exists());
}

#[test]
fn bad_coefficients_fail_with_the_column_the_line_or_the_face() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh_path, mesh) = planar_grid(dir.path(), Cells::Triangles);
    let out_path = dir.path().join("out.obj");
    let run = |extra: &[&str]| {
        let mut args = vec!["qc", s(&mesh_path), "-o", s(&out_path)];
        args.extend_from_slice(extra);
        beltrami(&args)
    };
    // A parse error gives the column.
    let out = run(&["--mu-expr", "0.6*z^0.5"]);
    assert!(!out.status.success());
    assert!(
        text(&out.stderr).contains("column 7"),
        "{}",
        text(&out.stderr)
    );
    // |mu| >= 1 from an expression names the face.
    let out = run(&["--mu-expr", "2*z"]);
    assert!(!out.status.success());
    assert!(text(&out.stderr).contains(">= 1"), "{}", text(&out.stderr));
    // |mu| >= 1 in a file names the line and the face.
    let field = dir.path().join("mu.txt");
    let mut lines = vec![format!("# mu frame=global faces={}", mesh.face_count())];
    lines.extend((0..mesh.face_count()).map(|f| if f == 3 { "1.5 0" } else { "0.1 0" }.into()));
    std::fs::write(&field, lines.join("\n")).unwrap();
    let out = run(&["--mu", s(&field)]);
    assert!(!out.status.success());
    let stderr = text(&out.stderr);
    assert!(
        stderr.contains(":5:") && stderr.contains(">= 1"),
        "{stderr}"
    );
    // Neither or both of --mu and --mu-expr.
    assert!(!run(&[]).status.success());
    assert!(!out_path.exists());
}

#[test]
fn given_boundary_comes_from_a_map_file() {
    // With mu = 0 and the boundary of z -> 2 z, that map itself is the least-squares
    // map of a planar mesh: every vt is twice its vertex (keeping the boundary would give
    // the vertex itself).
    let dir = tempfile::tempdir().unwrap();
    let (mesh_path, mesh) = planar_grid(dir.path(), Cells::Triangles);
    let doubled: Vec<_> = mesh.positions().iter().map(|p| p * 2.0).collect();
    let map_path = dir.path().join("doubled.obj");
    let attributes = VertexAttributes {
        positions: Some(&doubled),
        ..VertexAttributes::default()
    };
    io::write(&map_path, &mesh, &attributes).unwrap();
    let out_path = dir.path().join("out.obj");
    let out = beltrami(&[
        "qc",
        s(&mesh_path),
        "--mu-expr",
        "0",
        "--boundary",
        "given",
        "--boundary-map",
        s(&map_path),
        "-o",
        s(&out_path),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let written = std::fs::read_to_string(&out_path).unwrap();
    let vt: Vec<(f64, f64)> = written
        .lines()
        .filter_map(|l| l.strip_prefix("vt "))
        .map(|l| {
            let mut it = l.split_whitespace().map(|x| x.parse::<f64>().unwrap());
            (it.next().unwrap(), it.next().unwrap())
        })
        .collect();
    assert_eq!(vt.len(), mesh.vertex_count());
    for (v, (x, y)) in mesh.vertices().zip(vt) {
        let p = mesh.position(v);
        assert!((2.0 * p.x - x).abs() < 1e-12 && (2.0 * p.y - y).abs() < 1e-12);
    }
}

#[test]
fn the_default_solver_follows_the_target() {
    let dir = tempfile::tempdir().unwrap();
    let (grid, _) = planar_grid(dir.path(), Cells::Triangles);
    let out = dir.path().join("out.obj");
    let report = dir.path().join("report.json");
    for (target, goal, solver) in [
        ("plane", "--mu-expr=0.2", "lsqc"),
        ("disk", "--conformal", "beltrami-flow"),
    ] {
        let run = beltrami(&[
            "qc",
            s(&grid),
            "--target",
            target,
            goal,
            "-o",
            s(&out),
            "--report",
            s(&report),
        ]);
        assert!(run.status.success(), "{target}: {}", text(&run.stderr));
        assert_eq!(read_json(&report)["solver"], solver, "--target {target}");
    }
}

#[test]
fn the_space_target_maps_a_curved_surface_into_r3() {
    // The identity of a curved surface is conformal in the quaternionic sense
    // (df^- = 0): with its own boundary held, the least-squares map is the surface.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.obj");
    let report = dir.path().join("r.json");
    let hemisphere = "meshes/disk_hemisphere.obj";
    let run = beltrami(&[
        "qc",
        hemisphere,
        "--target",
        "space",
        "--boundary",
        "given",
        "--boundary-map",
        hemisphere,
        "--conformal",
        "-o",
        s(&out),
        "--report",
        s(&report),
    ]);
    assert!(run.status.success(), "{}", text(&run.stderr));
    assert_eq!(read_json(&report)["solver"], "lsqc");
    let input = io::read(Path::new(hemisphere), &Default::default())
        .unwrap()
        .mesh;
    let output = io::read(&out, &Default::default()).unwrap().mesh;
    let error = input
        .positions()
        .iter()
        .zip(output.positions())
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    assert!(error < 1e-10, "the identity came back off by {error}");
    // The normal constraint is accepted with the space target, refused elsewhere or
    // with a weight that is not positive.
    let run = beltrami(&[
        "qc",
        hemisphere,
        "--target",
        "space",
        "--boundary",
        "given",
        "--boundary-map",
        hemisphere,
        "--conformal",
        "--normal-constraint",
        "1e4",
        "-o",
        s(&out),
    ]);
    assert!(run.status.success(), "{}", text(&run.stderr));
    for (flags, message) in [
        (&["--normal-constraint", "0"][..], "positive"),
        (
            &["--normal-constraint", "1", "--target", "plane"][..],
            "--target space",
        ),
    ] {
        let bad = dir.path().join("bad.obj");
        let mut args = vec!["qc", hemisphere, "--conformal", "-o", s(&bad)];
        args.extend_from_slice(flags);
        if !flags.contains(&"plane") {
            args.extend([
                "--target",
                "space",
                "--boundary",
                "given",
                "--boundary-map",
                hemisphere,
            ]);
        }
        let run = beltrami(&args);
        assert!(!run.status.success(), "{flags:?}");
        assert!(text(&run.stderr).contains(message), "{}", text(&run.stderr));
        assert!(!bad.exists());
    }
    // Without held vertices nothing fixes the image: refused before any work.
    let none = dir.path().join("none.obj");
    let run = beltrami(&[
        "qc",
        hemisphere,
        "--target",
        "space",
        "--conformal",
        "-o",
        s(&none),
    ]);
    assert!(!run.status.success());
    assert!(
        text(&run.stderr).contains("--boundary given"),
        "{}",
        text(&run.stderr)
    );
    assert!(!none.exists());
}

#[test]
fn numbers_too_large_to_compute_with_are_named_with_their_limit() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.obj");
    let run = beltrami(&[
        "qc",
        "meshes/disk_hemisphere.obj",
        "--solver",
        "beltrami-flow",
        "--target",
        "disk",
        "--conformal",
        "--p",
        "1e308",
        "-o",
        s(&out),
    ]);
    assert!(!run.status.success());
    assert!(
        text(&run.stderr).contains("needs 2 <= p <= 100"),
        "{}",
        text(&run.stderr)
    );
    let run = beltrami(&[
        "qc",
        "meshes/disk_hemisphere.obj",
        "--target",
        "space",
        "--conformal",
        "--boundary",
        "given",
        "--boundary-map",
        "meshes/disk_hemisphere.obj",
        "--normal-constraint",
        "1e300",
        "-o",
        s(&out),
    ]);
    assert!(!run.status.success());
    assert!(
        text(&run.stderr).contains("the weight must be > 0 and at most 100000000"),
        "{}",
        text(&run.stderr)
    );
    assert!(!out.exists());
}

#[test]
fn a_closed_surface_held_at_one_vertex_with_its_area_maps_onto_itself() {
    // docs/qc-space.md: one held vertex and the area constraint fix a closed surface's
    // map into space; the conformal one is the identity.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.obj");
    let run = beltrami(&[
        "qc",
        "meshes/spot.obj",
        "--target",
        "space",
        "--conformal",
        "--pin",
        "v0",
        "--area-constraint",
        "-o",
        s(&out),
        "-q",
    ]);
    assert!(run.status.success(), "{}", text(&run.stderr));
    let source = io::read(Path::new("meshes/spot.obj"), &Default::default())
        .unwrap()
        .mesh;
    let image = io::read(&out, &Default::default()).unwrap().mesh;
    let far = source
        .positions()
        .iter()
        .zip(image.positions())
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    assert!(far < 1e-8, "the image moved up to {far}");
    // Without a pin or a boundary map nothing holds the map: refused, saying both ways.
    let run = beltrami(&[
        "qc",
        "meshes/spot.obj",
        "--target",
        "space",
        "--conformal",
        "-o",
        s(&out),
    ]);
    assert!(
        text(&run.stderr).contains("or vertices where they are (--pin)"),
        "{}",
        text(&run.stderr)
    );
}
