//! PLY, STL and OFF through the commands: `info` reports an STL weld, a parameterization
//! reads and writes PLY and OFF and `distortion` measures what it wrote, a planar map is
//! refused for STL before any work, and a registration goes from STL to STL.

use std::path::Path;

mod common;
use common::{beltrami, s, text};

/// The bundled hemisphere converted to `name`'s format by `generate`-free means: read
/// and written by the library.
fn bundled_as(dir: &Path, name: &str) -> std::path::PathBuf {
    use beltrami_mesh::BuildOptions;
    use beltrami_mesh::io::{self, VertexAttributes};
    let loaded = io::read(
        Path::new("meshes/disk_hemisphere.obj"),
        &BuildOptions::default(),
    )
    .unwrap();
    let path = dir.join(name);
    io::write(&path, &loaded.mesh, &VertexAttributes::default()).unwrap();
    path
}

#[test]
fn info_reports_the_weld_of_an_stl_file() {
    let dir = tempfile::tempdir().unwrap();
    let stl = bundled_as(dir.path(), "hemi.stl");
    let out = beltrami(&["info", s(&stl)]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    assert!(stdout.contains("vertices        1861"), "{stdout}");
    assert!(
        stdout.contains("STL weld        10800 corners into 1861 vertices"),
        "{stdout}"
    );
    assert!(text(&out.stderr).contains("10800 triangle corners welded into 1861 vertices"));

    let out = beltrami(&["info", "--json", s(&stl)]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["stl_weld"]["corners"], 10800);
    assert_eq!(v["stl_weld"]["vertices"], 1861);
}

#[test]
fn a_parameterization_goes_from_ply_to_ply_and_off_and_distortion_agrees() {
    let dir = tempfile::tempdir().unwrap();
    let ply = bundled_as(dir.path(), "hemi.ply");
    for out_name in ["uv.ply", "uv.off"] {
        let output = dir.path().join(out_name);
        let report = dir.path().join(format!("{out_name}.json"));
        let out = beltrami(&[
            "param",
            s(&ply),
            "-o",
            s(&output),
            "--solver",
            "lscm",
            "--report",
            s(&report),
            "--quiet",
        ]);
        assert!(out.status.success(), "{}", text(&out.stderr));
        let reported: serde_json::Value =
            serde_json::from_slice(&std::fs::read(&report).unwrap()).unwrap();
        let out = beltrami(&["distortion", s(&ply), s(&output), "--json"]);
        assert!(out.status.success(), "{}", text(&out.stderr));
        let measured: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let (a, b) = (&reported["mu_max"], &measured["mu_max"]);
        assert!(
            a.is_f64() && (a.as_f64().unwrap() - b.as_f64().unwrap()).abs() < 1e-12,
            "{out_name}: report {a} distortion {b}"
        );
    }
}

#[test]
fn a_planar_map_is_refused_for_stl_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let output = dir.path().join("uv.stl");
    let out = beltrami(&[
        "param",
        "meshes/disk_hemisphere.obj",
        "--solver",
        "lscm",
        "-o",
        s(&output),
    ]);
    assert!(!out.status.success());
    let stderr = text(&out.stderr);
    assert!(stderr.contains("STL files cannot hold texture coordinates; write .obj, .ply, .off, .gltf or .glb instead"), "{stderr}");
    assert!(!output.exists());
}

#[test]
fn an_unknown_extension_lists_every_format() {
    let out = beltrami(&[
        "param",
        "meshes/disk_hemisphere.obj",
        "--solver",
        "lscm",
        "-o",
        "x.xyz",
    ]);
    assert!(!out.status.success());
    assert!(text(&out.stderr).contains("expected .obj, .ply, .stl, .off, .gltf or .glb"));
}

#[test]
fn info_hints_at_repair_for_a_triangle_soup_and_the_repair_welds_it() {
    // Two triangles of a square, each with its own three corners: an STL-like soup.
    let dir = tempfile::tempdir().unwrap();
    let soup = dir.path().join("soup.off");
    std::fs::write(
        &soup,
        "OFF\n6 2 0\n0 0 0\n1 0 0\n1 1 0\n0 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 3 4 5\n",
    )
    .unwrap();
    let out = beltrami(&["info", s(&soup)]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    assert!(
        stdout.contains("hint: 2 vertices lie exactly on another vertex"),
        "{stdout}"
    );
    assert!(
        stdout.contains("2 components with 2 boundary loops; `--repair` merges them"),
        "{stdout}"
    );
    let out = beltrami(&["info", "--repair", s(&soup)]);
    let stdout = text(&out.stdout);
    assert!(stdout.contains("components      1"), "{stdout}");
    assert!(!stdout.contains("hint:"), "{stdout}");
}

#[test]
fn one_based_faces_in_an_off_file_get_a_hint() {
    let dir = tempfile::tempdir().unwrap();
    let off = dir.path().join("one.off");
    std::fs::write(&off, "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 1 2 3\n").unwrap();
    let out = beltrami(&["info", s(&off)]);
    assert!(!out.status.success());
    let stderr = text(&out.stderr);
    assert!(stderr.contains(":6: face 0 refers to vertex 3"), "{stderr}");
    assert!(stderr.contains("hint: the faces look 1-based"), "{stderr}");
}

#[test]
fn info_lists_at_most_a_dozen_components() {
    let dir = tempfile::tempdir().unwrap();
    let many = dir.path().join("many.off");
    let mut text_file = String::from("OFF\n60 20 0\n");
    for k in 0..20 {
        let x = 2.0 * k as f64;
        text_file.push_str(&format!("{x} 0 0\n{} 0 0\n{x} 1 0\n", x + 1.0));
    }
    for k in 0..20 {
        text_file.push_str(&format!("3 {} {} {}\n", 3 * k, 3 * k + 1, 3 * k + 2));
    }
    std::fs::write(&many, text_file).unwrap();
    let out = beltrami(&["info", s(&many)]);
    let stdout = text(&out.stdout);
    assert!(
        stdout.contains(
            "genus           0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, ... (8 more; --json lists all)"
        ),
        "{stdout}"
    );
    let out = beltrami(&["info", "--json", s(&many)]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["genus"].as_array().unwrap().len(), 20);
}

#[test]
fn a_parameterization_keeps_the_inputs_groups_and_materials() {
    let dir = tempfile::tempdir().unwrap();
    let bundled = std::fs::read_to_string("meshes/disk_hemisphere.obj").unwrap();
    let mut grouped = String::new();
    let mut faces = 0;
    for line in bundled.lines() {
        if line.starts_with("f ") {
            if faces == 0 {
                grouped.push_str("mtllib skin.mtl\ng top\nusemtl skin\n");
            }
            if faces == 1000 {
                grouped.push_str("g rim\n");
            }
            faces += 1;
        }
        grouped.push_str(line);
        grouped.push('\n');
    }
    let input = dir.path().join("grouped.obj");
    std::fs::write(&input, grouped).unwrap();
    let output = dir.path().join("uv.obj");
    let out = beltrami(&[
        "param",
        s(&input),
        "--solver",
        "lscm",
        "-o",
        s(&output),
        "-q",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let written = std::fs::read_to_string(&output).unwrap();
    let lines: Vec<&str> = written.lines().filter(|l| !l.starts_with("v")).collect();
    let at = |wanted: &str| lines.iter().position(|l| *l == wanted).unwrap();
    assert_eq!(
        &lines[at("mtllib skin.mtl")..at("mtllib skin.mtl") + 3],
        ["mtllib skin.mtl", "g top", "usemtl skin"]
    );
    assert!(lines[at("usemtl skin") + 1].starts_with("f "));
    // 1000 faces between `g top` and `g rim`, as in the input.
    assert_eq!(at("g rim") - at("usemtl skin") - 1, 1000);
}
