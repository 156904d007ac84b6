//! `beltrami qc --solver qc-iteration` against exact answers: the ring map between two
//! annuli is the Teichmueller map of its boundary values, `k = (K - 1) / (K + 1)`; the
//! QC iteration converges to it at second order under refinement and agrees with the
//! `extremal` solver on the same Dirichlet problems (two methods, one answer).

use std::f64::consts::TAU;
use std::path::{Path, PathBuf};

use beltrami_mesh::io::{self, VertexAttributes};
use beltrami_mesh::primitives::annulus;
use beltrami_mesh::{BuildOptions, Mesh, Point3};
use num_complex::Complex64;

mod common;
use common::{beltrami, s, text};

const R0: f64 = 0.4;
const S0: f64 = 0.25;
const S1: f64 = 1.2;

fn stretch() -> f64 {
    (S1 / S0).ln() / (1.0 / R0).ln()
}

/// The `rings`-ring annulus `R0 < r < 1`, each ring slightly twisted, and the ring map
/// at its vertices written as a boundary-map file.
fn ring_problem(dir: &Path, rings: usize) -> (PathBuf, PathBuf, Vec<Complex64>) {
    let mut soup = annulus(R0, rings, 6 * rings);
    for p in soup.positions.iter_mut() {
        let z = Complex64::new(p.x, p.y) * Complex64::from_polar(1.0, 0.02 * (TAU * p.x).sin());
        *p = Point3::new(z.re, z.im, 0.0);
    }
    let mesh = Mesh::from_soup(&soup).unwrap();
    let input = dir.join(format!("ring{rings}.obj"));
    io::write(&input, &mesh, &VertexAttributes::default()).unwrap();
    let exact: Vec<Complex64> = mesh
        .positions()
        .iter()
        .map(|p| {
            let z = Complex64::new(p.x, p.y);
            Complex64::from_polar(S0 * (z.norm() / R0).powf(stretch()), z.arg())
        })
        .collect();
    let positions: Vec<Point3<f64>> = exact.iter().map(|w| Point3::new(w.re, w.im, 0.0)).collect();
    let map = dir.join(format!("map{rings}.obj"));
    let attributes = VertexAttributes {
        positions: Some(&positions),
        ..VertexAttributes::default()
    };
    io::write(&map, &mesh, &attributes).unwrap();
    (input, map, exact)
}

/// Runs `solver` on the problem; its `k`, largest vertex error and flips.
fn run(solver: &str, input: &Path, map: &Path, exact: &[Complex64]) -> (f64, f64, u64) {
    let dir = tempfile::tempdir().unwrap();
    let (out, report) = (dir.path().join("out.obj"), dir.path().join("r.json"));
    let run = beltrami(&[
        "qc",
        s(input),
        "--solver",
        solver,
        "--boundary",
        "given",
        "--boundary-map",
        s(map),
        "-o",
        s(&out),
        "--report",
        s(&report),
    ]);
    assert!(run.status.success(), "{solver}: {}", text(&run.stderr));
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    let uv = io::read(&out, &BuildOptions::default())
        .unwrap()
        .vertex_uvs()
        .unwrap();
    let error = uv
        .iter()
        .zip(exact)
        .map(|(t, w)| (Complex64::new(t.x, t.y) - w).norm())
        .fold(0.0, f64::max);
    (
        r["k"].as_f64().unwrap(),
        error,
        r["flipped"].as_u64().unwrap(),
    )
}

#[test]
fn the_qc_iteration_reaches_the_ring_maps_k_and_agrees_with_extremal() {
    let dir = tempfile::tempdir().unwrap();
    let k_exact = (stretch() - 1.0) / (stretch() + 1.0);
    let mut last: Option<f64> = None;
    for rings in [6, 12, 24] {
        let (input, map, exact) = ring_problem(dir.path(), rings);
        let (k, error, flips) = run("qc-iteration", &input, &map, &exact);
        let (k_extremal, _, _) = run("extremal", &input, &map, &exact);
        println!(
            "{rings} rings: qc-iteration k {k:.6}, extremal k {k_extremal:.6}, exact {k_exact:.6}, vertex error {error:.3e}"
        );
        assert_eq!(flips, 0);
        assert!(
            (k - k_exact).abs() < 0.005 * k_exact,
            "k {k}, exact {k_exact}"
        );
        // Both converge to the exact k; the QC iteration is the closer at every level,
        // and the two agree to 1% once the extremal solver's coarse-mesh error is small.
        assert!(
            (k - k_exact).abs() <= (k_extremal - k_exact).abs(),
            "qc-iteration {k}, extremal {k_extremal}, exact {k_exact}"
        );
        if rings >= 12 {
            assert!(
                (k - k_extremal).abs() < 0.01 * k_exact,
                "qc-iteration {k}, extremal {k_extremal}"
            );
        }
        if let Some(e) = last {
            assert!(
                error < 0.35 * e,
                "vertex error {error} after {e}: not second order"
            );
        }
        last = Some(error);
    }
}

#[test]
fn a_prescribed_goal_or_a_curved_mesh_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let (input, map, _) = ring_problem(dir.path(), 4);
    let out = dir.path().join("out.obj");
    let run = beltrami(&[
        "qc",
        s(&input),
        "--solver",
        "qc-iteration",
        "--boundary",
        "given",
        "--boundary-map",
        s(&map),
        "--mu-expr",
        "0.2",
        "-o",
        s(&out),
    ]);
    assert!(!run.status.success());
    assert!(text(&run.stderr).contains("lsqc"), "{}", text(&run.stderr));
    assert!(!out.exists());
    let run = beltrami(&[
        "qc",
        "meshes/disk_hemisphere.obj",
        "--solver",
        "qc-iteration",
        "--boundary",
        "keep",
        "-o",
        s(&out),
    ]);
    assert!(!run.status.success());
    assert!(
        text(&run.stderr).contains("planar"),
        "{}",
        text(&run.stderr)
    );
    assert!(!out.exists());
}

#[test]
fn the_qc_iteration_maps_a_curved_patch_into_space() {
    // A cylinder patch onto a coaxial cylinder, developed the affine map
    // (s, t) -> (1.3 s, 0.4 s + 0.8 t): the Teichmueller map of its own boundary values
    // (plugins/qc-iteration/tests/surface.rs has the convergence study).
    let dir = tempfile::tempdir().unwrap();
    let mut soup = beltrami_mesh::primitives::jittered_grid(
        10,
        10,
        beltrami_mesh::primitives::Cells::Triangles,
        0.3,
        7,
    );
    let developed: Vec<(f64, f64)> = soup.positions.iter().map(|p| (1.2 * p.x, p.y)).collect();
    for (p, &(s, t)) in soup.positions.iter_mut().zip(&developed) {
        *p = Point3::new(s.cos(), s.sin(), t);
    }
    let mesh = Mesh::from_soup(&soup).unwrap();
    let exact: Vec<Point3<f64>> = developed
        .iter()
        .map(|&(s, t)| Point3::new(1.3 * s.cos(), 1.3 * s.sin(), 0.4 * s + 0.8 * t))
        .collect();
    let input = dir.path().join("patch.obj");
    let map = dir.path().join("map.obj");
    io::write(&input, &mesh, &VertexAttributes::default()).unwrap();
    let attributes = VertexAttributes {
        positions: Some(&exact),
        ..VertexAttributes::default()
    };
    io::write(&map, &mesh, &attributes).unwrap();
    let (out, report) = (dir.path().join("out.obj"), dir.path().join("r.json"));
    let run = beltrami(&[
        "qc",
        s(&input),
        "--solver",
        "qc-iteration",
        "--target",
        "space",
        "--boundary",
        "given",
        "--boundary-map",
        s(&map),
        "-o",
        s(&out),
        "--report",
        s(&report),
    ]);
    assert!(run.status.success(), "{}", text(&run.stderr));
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    let k_exact = (Complex64::new(0.5, 0.4) / Complex64::new(2.1, 0.4)).norm();
    let k = r["k"].as_f64().unwrap();
    assert!(
        (k - k_exact).abs() < 0.01 * k_exact,
        "k {k}, exact {k_exact}"
    );
    assert_eq!(r["flipped"], 0);
    let image = io::read(&out, &BuildOptions::default()).unwrap().mesh;
    let error = image
        .positions()
        .iter()
        .zip(&exact)
        .map(|(p, q)| (p - q).norm())
        .fold(0.0, f64::max);
    assert!(error < 2e-3, "vertex error {error}");
    // The area constraint is a flag of the space target only.
    let bad = dir.path().join("bad.obj");
    let run = beltrami(&[
        "qc",
        s(&input),
        "--solver",
        "qc-iteration",
        "--area-constraint",
        "-o",
        s(&bad),
    ]);
    assert!(!run.status.success());
    assert!(
        text(&run.stderr).contains("--target space"),
        "{}",
        text(&run.stderr)
    );
    assert!(!bad.exists());
}

#[test]
fn with_no_iteration_k_is_the_start_maps_mean_distortion() {
    let dir = tempfile::tempdir().unwrap();
    let (input, map, _) = ring_problem(dir.path(), 4);
    let (out, report) = (dir.path().join("out.obj"), dir.path().join("r.json"));
    let run = beltrami(&[
        "qc",
        s(&input),
        "--solver",
        "qc-iteration",
        "--boundary",
        "given",
        "--boundary-map",
        s(&map),
        "--max-iters",
        "0",
        "-o",
        s(&out),
        "--report",
        s(&report),
    ]);
    assert!(run.status.success(), "{}", text(&run.stderr));
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    // The start map (the least-squares map of mu = 0 with the ring map's boundary) is
    // far from conformal: its k is its area-weighted mean |mu|, not 0.
    let mesh = io::read(&input, &BuildOptions::default()).unwrap().mesh;
    let uv = io::read(&out, &BuildOptions::default())
        .unwrap()
        .vertex_uvs()
        .unwrap();
    let image: Vec<Complex64> = uv.iter().map(|t| Complex64::new(t.x, t.y)).collect();
    let measured =
        beltrami_fem::distortion::measure_planar(&mesh, &image, beltrami_fem::Frame::Global)
            .unwrap();
    let (mut weighted, mut area) = (0.0, 0.0);
    for f in mesh.faces() {
        weighted += mesh.face_area(f) * measured.field.mu[f.idx()].norm();
        area += mesh.face_area(f);
    }
    let (k, mean) = (r["k"].as_f64().unwrap(), weighted / area);
    assert!(mean > 0.1, "{r}");
    assert!(
        (k - mean).abs() < 1e-9,
        "k {k}, area-weighted mean |mu| {mean}"
    );
}
