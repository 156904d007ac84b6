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
