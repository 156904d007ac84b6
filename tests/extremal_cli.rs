//! End-to-end runs of `beltrami qc --solver extremal`: the ring map between two annuli
//! (the exact extremal map for its boundary values, Weber-Myles-Zorin 2012 section 5)
//! through the command line, with the quadratic differential of `--qd`, a folded start
//! given as a file, and refusals that write nothing.

use std::f64::consts::TAU;
use std::path::{Path, PathBuf};

use beltrami_mesh::io::{self, VertexAttributes};
use beltrami_mesh::primitives::annulus;
use beltrami_mesh::{BuildOptions, Mesh, Point3};
use num_complex::Complex64;

mod common;
use common::{beltrami, s, text};

/// The ring map `(r, t) -> (S0 (r/R0)^K, t)` from `R0 < r < 1` onto `S0 < s < S1`.
const R0: f64 = 0.4;
const S0: f64 = 0.25;
const S1: f64 = 1.2;

fn stretch() -> f64 {
    (S1 / S0).ln() / (1.0 / R0).ln()
}

fn ring_map(z: Complex64) -> Complex64 {
    Complex64::from_polar(S0 * (z.norm() / R0).powf(stretch()), z.arg())
}

/// The annulus mesh (`rings` by `6 rings` sectors), written to `dir`, with a slight
/// twist of every ring so that the mesh is not symmetric under reflections.
fn ring_of(dir: &Path, rings: usize) -> (PathBuf, Mesh) {
    let mut soup = annulus(R0, rings, 6 * rings);
    for p in soup.positions.iter_mut() {
        let z = Complex64::new(p.x, p.y);
        let twist = 0.02 * (TAU * z.norm()).sin();
        let w = z * Complex64::from_polar(1.0, twist);
        *p = Point3::new(w.re, w.im, 0.0);
    }
    let mesh = Mesh::from_soup(&soup).unwrap();
    let path = dir.join(format!("ring{rings}.obj"));
    io::write(&path, &mesh, &VertexAttributes::default()).unwrap();
    (path, mesh)
}

/// The `rings`-ring annulus, the ring map at its vertices, and that map written as the
/// boundary-map file `map.obj`.
fn ring_with_map(dir: &Path, rings: usize) -> (PathBuf, Mesh, Vec<Complex64>, PathBuf) {
    let (input, mesh) = ring_of(dir, rings);
    let exact: Vec<Complex64> = mesh
        .positions()
        .iter()
        .map(|p| ring_map(Complex64::new(p.x, p.y)))
        .collect();
    let map = dir.join("map.obj");
    write_map(&map, &mesh, &exact);
    (input, mesh, exact, map)
}

/// `mesh` with its vertices moved to `image` (a map file: positions x, y).
fn write_map(path: &Path, mesh: &Mesh, image: &[Complex64]) {
    let positions: Vec<Point3<f64>> = image.iter().map(|w| Point3::new(w.re, w.im, 0.0)).collect();
    let attributes = VertexAttributes {
        positions: Some(&positions),
        ..VertexAttributes::default()
    };
    io::write(path, mesh, &attributes).unwrap();
}

fn read_uv(path: &Path) -> Vec<Complex64> {
    let loaded = io::read(path, &BuildOptions::default()).unwrap();
    let uv = loaded
        .vertex_uvs()
        .expect("the output has one vt per vertex");
    uv.iter().map(|t| Complex64::new(t.x, t.y)).collect()
}

fn read_json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Runs the ring-map problem on the `rings`-ring mesh; returns k, the largest vertex
/// error and the area-weighted RMS of the error in the direction of phi.
fn ring_problem(dir: &Path, rings: usize) -> (f64, f64, f64) {
    let (input, mesh, exact, map) = ring_with_map(dir, rings);
    let (out, qd, report) = (dir.join("out.obj"), dir.join("qd.txt"), dir.join("r.json"));
    let run = beltrami(&[
        "qc",
        s(&input),
        "--solver",
        "extremal",
        "--boundary",
        "given",
        "--boundary-map",
        s(&map),
        "-o",
        s(&out),
        "--qd",
        s(&qd),
        "--report",
        s(&report),
    ]);
    assert!(run.status.success(), "{}", text(&run.stderr));
    let r = read_json(&report);
    assert_eq!(r["flipped"], 0);
    let uv = read_uv(&out);
    let error = uv
        .iter()
        .zip(&exact)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    // mu = k z / conj(z) for the radial stretch, so phi / |phi| = conj(z) / z at every
    // face (phi = c / z^2, c > 0), in the input's face order.
    let qd_text = std::fs::read_to_string(&qd).unwrap();
    let mut lines = qd_text.lines();
    assert_eq!(
        lines.next().unwrap(),
        format!("# qd frame=global faces={}", mesh.face_count())
    );
    let (mut sum, mut area) = (0.0, 0.0);
    for (f, line) in mesh.faces().zip(lines) {
        let v: Vec<f64> = line
            .split_whitespace()
            .map(|x| x.parse().unwrap())
            .collect();
        let phi = Complex64::new(v[0], v[1]);
        let c = mesh.face_centroid(f);
        let z = Complex64::new(c.x, c.y);
        let a = mesh.face_area(f);
        sum += a * (phi / phi.norm() - z.conj() / z).norm_sqr();
        area += a;
    }
    (r["k"].as_f64().unwrap(), error, (sum / area).sqrt())
}

#[test]
fn the_ring_map_comes_back_with_its_k_and_quadratic_differential() {
    let dir = tempfile::tempdir().unwrap();
    let k_exact = (stretch() - 1.0) / (stretch() + 1.0);
    let mut last: Option<(f64, f64)> = None;
    for rings in [6, 12, 24] {
        let (k, error, direction) = ring_problem(dir.path(), rings);
        println!(
            "{rings} rings: k {k} (exact {k_exact}), vertex error {error:.3e}, phi direction RMS {direction:.3e}"
        );
        if rings >= 12 {
            assert!(
                (k - k_exact).abs() < 0.01 * k_exact,
                "k {k}, exact {k_exact}"
            );
        }
        if let Some((e, d)) = last {
            assert!(error < 0.6 * e, "vertex error {error} after {e}");
            assert!(direction < 0.6 * d, "phi direction {direction} after {d}");
        }
        last = Some((error, direction));
    }
}

#[test]
fn a_folded_start_from_a_file_ends_without_flips() {
    let dir = tempfile::tempdir().unwrap();
    let (input, mesh, exact, map) = ring_with_map(dir.path(), 8);
    // The exact map with the images of the vertices within 0.2 of z0 = 0.7 mirrored
    // across the horizontal line through the image of z0: every face there turns over.
    // The fold stays inside a disk, so the start is homotopic to the exact map with the
    // boundary held (a fold across the whole annulus may add a twist, and the extremal
    // map of another homotopy class has another k).
    let z0 = Complex64::new(0.7, 0.0);
    let w0 = ring_map(z0);
    let folded: Vec<Complex64> = mesh
        .positions()
        .iter()
        .zip(&exact)
        .map(|(p, &w)| {
            if (Complex64::new(p.x, p.y) - z0).norm() < 0.2 {
                w0 + (w - w0).conj()
            } else {
                w
            }
        })
        .collect();
    let start = dir.path().join("start.obj");
    write_map(&start, &mesh, &folded);
    let (out, report) = (dir.path().join("out.obj"), dir.path().join("r.json"));
    let run = beltrami(&[
        "qc",
        s(&input),
        "--solver",
        "extremal",
        "--boundary",
        "given",
        "--boundary-map",
        s(&map),
        "--init",
        s(&start),
        "-o",
        s(&out),
        "--report",
        s(&report),
    ]);
    assert!(run.status.success(), "{}", text(&run.stderr));
    // A bad start file is named by its own flag.
    let missing = dir.path().join("no_start.obj");
    let bad = beltrami(&[
        "qc",
        s(&input),
        "--solver",
        "extremal",
        "--boundary",
        "given",
        "--boundary-map",
        s(&map),
        "--init",
        s(&missing),
        "-o",
        s(&dir.path().join("never.obj")),
    ]);
    assert!(!bad.status.success());
    let stderr = text(&bad.stderr);
    assert!(
        stderr.contains(&format!("--init {}", missing.display())),
        "{stderr}"
    );
    assert!(!stderr.contains("--boundary-map"), "{stderr}");
    let r = read_json(&report);
    let folded_flips = r["initial_flipped"].as_u64().unwrap();
    assert!(folded_flips > 10, "the start has {folded_flips} flips");
    assert_eq!(r["flipped"], 0);
    let k_exact = (stretch() - 1.0) / (stretch() + 1.0);
    let k = r["k"].as_f64().unwrap();
    assert!(
        (k - k_exact).abs() < 0.01 * k_exact,
        "k {k}, exact {k_exact}"
    );
}

#[test]
fn refusals_name_the_problem_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let (input, _, _, _) = ring_with_map(dir.path(), 8);
    let out = dir.path().join("out.obj");
    // --qd with a solver that computes no quadratic differential.
    let run = beltrami(&[
        "qc",
        s(&input),
        "--mu-expr",
        "0.2",
        "--qd",
        s(&dir.path().join("qd.txt")),
        "-o",
        s(&out),
    ]);
    assert!(!run.status.success());
    assert!(text(&run.stderr).contains("--qd"), "{}", text(&run.stderr));
    assert!(!out.exists());
    // A boundary map on another mesh.
    let other = dir.path().join("other.obj");
    let small = Mesh::from_soup(&annulus(R0, 4, 24)).unwrap();
    io::write(&other, &small, &VertexAttributes::default()).unwrap();
    let run = beltrami(&[
        "qc",
        s(&input),
        "--solver",
        "extremal",
        "--boundary",
        "given",
        "--boundary-map",
        s(&other),
        "-o",
        s(&out),
    ]);
    assert!(!run.status.success());
    assert!(!out.exists(), "{}", text(&run.stderr));
    println!("{}", text(&run.stderr));
}

/// A curved annulus (a bowl) is laid out conformally, its inner loop filled for the
/// layout (the paper's way with several boundaries), and mapped with the ring map's
/// boundary values, without flips.
#[test]
fn a_curved_ring_is_mapped_through_its_filled_layout() {
    let dir = tempfile::tempdir().unwrap();
    let (_, mesh, _, map) = ring_with_map(dir.path(), 8);
    let out = dir.path().join("out.obj");
    let curved: Vec<Point3<f64>> = mesh
        .positions()
        .iter()
        .map(|p| Point3::new(p.x, p.y, 0.3 * (p.x * p.x + p.y * p.y)))
        .collect();
    let bowl = dir.path().join("bowl.obj");
    let attributes = VertexAttributes {
        positions: Some(&curved),
        ..VertexAttributes::default()
    };
    io::write(&bowl, &mesh, &attributes).unwrap();
    let report = dir.path().join("bowl.json");
    let run = beltrami(&[
        "qc",
        s(&bowl),
        "--solver",
        "extremal",
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
    let r = read_json(&report);
    assert_eq!(r["flipped"], 0);
    let k = r["k"].as_f64().unwrap();
    assert!(k > 0.0 && k < 1.0, "k {k}");
    assert!(r["notes"].to_string().contains("LSCM"));
}

/// `--target disk --landmarks`: the four-point problem through the command line. The
/// exact k for these points is 0.1225 (plugins/extremal/tests/four_point.rs derives it
/// from elliptic integrals); the landmarks land exactly, the boundary stays on the
/// circle, and landmark files that cannot be met are refused before any output.
#[test]
fn the_four_point_problem_slides_the_boundary_on_the_circle() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = Mesh::from_soup(&beltrami_mesh::primitives::disk(5)).unwrap();
    let input = dir.path().join("disk.obj");
    io::write(&input, &mesh, &VertexAttributes::default()).unwrap();
    let boundary = &mesh.boundary_loop_list()[0].vertices;
    let nearest = |w: Complex64| {
        *boundary
            .iter()
            .min_by(|&&a, &&b| {
                let d = |v: beltrami_mesh::VertexId| {
                    let p = mesh.position(v);
                    (Complex64::new(p.x, p.y) - w).norm()
                };
                d(a).total_cmp(&d(b))
            })
            .unwrap()
    };
    let phi = std::f64::consts::PI / 6.0;
    let marks: Vec<(usize, Complex64)> = (0..4)
        .map(|j| {
            let from = Complex64::from_polar(1.0, TAU / 8.0 + j as f64 * TAU / 4.0);
            let to = [phi, TAU / 2.0 - phi, TAU / 2.0 + phi, TAU - phi][j];
            (nearest(from).idx(), Complex64::from_polar(1.0, to))
        })
        .collect();
    let write_marks = |name: &str, marks: &[(usize, Complex64)]| {
        let path = dir.path().join(name);
        let text: String = marks
            .iter()
            .map(|(v, w)| format!("p {v} {} {}\n", w.re, w.im))
            .collect();
        std::fs::write(&path, text).unwrap();
        path
    };
    let good = write_marks("marks.txt", &marks);
    let (out, report) = (dir.path().join("out.obj"), dir.path().join("r.json"));
    let run = beltrami(&[
        "qc",
        s(&input),
        "--solver",
        "extremal",
        "--target",
        "disk",
        "--landmarks",
        s(&good),
        "-o",
        s(&out),
        "--report",
        s(&report),
    ]);
    assert!(run.status.success(), "{}", text(&run.stderr));
    let r = read_json(&report);
    let k = r["k"].as_f64().unwrap();
    assert!((k - 0.1225).abs() < 0.02 * 0.1225, "k {k}");
    assert_eq!(r["flipped"], 0);
    let uv = read_uv(&out);
    for (v, w) in &marks {
        assert!((uv[*v] - w).norm() < 1e-9, "vertex {v}");
    }
    for v in boundary {
        assert!((uv[v.idx()].norm() - 1.0).abs() < 1e-9);
    }

    let refused = |marks_file: &Path, extra: &[&str], expected: &str| {
        let out = dir.path().join("refused.obj");
        let mut args = vec![
            "qc",
            s(&input),
            "--solver",
            "extremal",
            "--landmarks",
            s(marks_file),
        ];
        args.extend_from_slice(extra);
        args.extend_from_slice(&["-o", s(&out)]);
        let run = beltrami(&args);
        assert!(!run.status.success(), "accepted; expected: {expected}");
        assert!(
            text(&run.stderr).contains(expected),
            "{}",
            text(&run.stderr)
        );
        assert!(!out.exists());
    };
    let three = write_marks("three.txt", &marks[..3]);
    refused(
        &three,
        &["--target", "disk"],
        "exactly four boundary landmarks",
    );
    let mut swapped = marks.clone();
    (swapped[1].1, swapped[3].1) = (marks[3].1, marks[1].1);
    let swapped = write_marks("swapped.txt", &swapped);
    refused(
        &swapped,
        &["--target", "disk"],
        "not in the order of their vertices",
    );
    let off = write_marks("off.txt", &[(marks[0].0, Complex64::new(0.5, 0.0))]);
    refused(&off, &["--target", "disk"], "not on the unit circle");
    refused(
        &good,
        &[],
        "--landmarks moves boundary points of --target disk",
    );
    let syntax = dir.path().join("syntax.txt");
    std::fs::write(&syntax, "p 6 1 0 0\n").unwrap();
    refused(
        &syntax,
        &["--target", "disk"],
        "syntax.txt:1: expected `p SRC x y`",
    );
}
