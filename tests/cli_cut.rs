//! End-to-end runs of `beltrami cut`: a generated torus becomes a square disk with the
//! same faces, a genus-0 surface and a bad output name fail with a clear message.

use std::f64::consts::TAU;
use std::path::Path;

use beltrami_mesh::io::{self, VertexAttributes};
use beltrami_mesh::primitives::{Cells, icosphere, torus};
use beltrami_mesh::{BuildOptions, Mesh, PolygonSoup};

mod common;
use common::{beltrami, s, text};

fn write_soup(path: &Path, soup: &PolygonSoup) -> Mesh {
    let mesh = Mesh::from_soup(soup).unwrap();
    io::obj::write(path, &mesh, &VertexAttributes::default()).unwrap();
    mesh
}

#[test]
fn a_torus_is_cut_into_a_disk_with_the_same_faces() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("torus.obj");
    let output = dir.path().join("torus_cut.obj");
    let (major, minor) = (3.0, 1.0);
    let mesh = write_soup(&input, &torus(32, 12, major, minor, Cells::Triangles));

    let out = beltrami(&["cut", s(&input), "-o", s(&output)]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    for line in [
        "genus           1 (closed)",
        "generators      2: ",
        "torus sides     a ",
    ] {
        assert!(stdout.contains(line), "missing `{line}` in\n{stdout}");
    }

    let cut = io::read(&output, &BuildOptions::default()).unwrap().mesh;
    assert!(cut.is_disk(), "{:?}", cut.components());
    assert_eq!(cut.face_count(), mesh.face_count());
    assert_eq!(cut.euler_characteristic(), 1);

    let out = beltrami(&["cut", "--json", s(&input), "-o", s(&output)]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["genus"], 1);
    assert_eq!(v["faces"], mesh.face_count());
    assert_eq!(v["vertices"], cut.vertex_count());
    let generators = v["generators"].as_array().unwrap();
    assert_eq!(generators.len(), 2);
    let shortest = generators[0]["length"].as_f64().unwrap();
    assert!(
        (shortest - TAU * minor).abs() < 0.1 * TAU * minor,
        "shortest loop {shortest}"
    );
    let sides = &v["torus_sides"];
    let side = |k: &str| sides[k].as_f64().unwrap();
    assert!((side("a") - side("a_inv")).abs() < 1e-9);
    assert!((side("b") - side("b_inv")).abs() < 1e-9);
    let boundary = v["boundary_length"].as_f64().unwrap();
    let total = side("a") + side("b") + side("a_inv") + side("b_inv");
    assert!((boundary - total).abs() < 1e-9 * boundary);
    assert!((boundary - 2.0 * v["cut_length"].as_f64().unwrap()).abs() < 1e-9 * boundary);
}

#[test]
fn a_sphere_fails_with_a_clear_error_and_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("sphere.obj");
    let output = dir.path().join("sphere_cut.obj");
    write_soup(&input, &icosphere(1));
    let out = beltrami(&["cut", s(&input), "-o", s(&output)]);
    assert!(!out.status.success());
    assert!(out.stdout.is_empty());
    let err = text(&out.stderr);
    assert!(
        err.contains("cannot cut") && err.contains("genus 0") && err.contains("sphere"),
        "{err}"
    );
    assert!(!output.exists());
}

#[test]
fn the_output_must_be_obj() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("torus.obj");
    write_soup(&input, &torus(8, 5, 3.0, 1.0, Cells::Quads));
    let out = beltrami(&["cut", s(&input), "-o", s(&dir.path().join("cut.glb"))]);
    assert!(!out.status.success());
    assert!(text(&out.stderr).contains(".obj"), "{}", text(&out.stderr));
}
