//! End-to-end runs of `beltrami qc --solver beltrami-flow`: each target, the report's
//! iteration history and errors, Ctrl-C writing the map so far, and the errors of bad
//! requests.

use std::path::{Path, PathBuf};

use beltrami_mesh::io::{self, VertexAttributes};
use beltrami_mesh::{BuildOptions, Mesh, primitives};

mod common;
use common::{beltrami, s, text};

fn write(dir: &Path, name: &str, mesh: &Mesh) -> PathBuf {
    let path = dir.join(name);
    io::write(&path, mesh, &VertexAttributes::default()).unwrap();
    path
}

fn read_json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn vt_lines(path: &Path) -> Vec<(f64, f64)> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter_map(|l| l.strip_prefix("vt "))
        .map(|l| {
            let mut it = l.split_whitespace().map(|x| x.parse::<f64>().unwrap());
            (it.next().unwrap(), it.next().unwrap())
        })
        .collect()
}

#[test]
fn conformal_flow_onto_the_disk_writes_the_map_and_its_history() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("disk.obj");
    let report = dir.path().join("report.json");
    let run = beltrami(&[
        "qc",
        "meshes/disk_hemisphere.obj",
        "--solver",
        "beltrami-flow",
        "--target",
        "disk",
        "--conformal",
        "-o",
        s(&out),
        "--report",
        s(&report),
    ]);
    assert!(run.status.success(), "{}", text(&run.stderr));
    let r = read_json(&report);
    assert_eq!(r["solver"], "beltrami-flow");
    assert_eq!(r["flipped"], 0);
    let iterations = r["iterations"].as_u64().unwrap() as usize;
    assert!(iterations > 0);
    assert_eq!(r["step_sizes"].as_array().unwrap().len(), iterations);
    let history = r["energy_history"].as_array().unwrap();
    assert_eq!(history.len(), iterations + 1);
    assert!(history.last().unwrap().as_f64().unwrap() < history[0].as_f64().unwrap());
    assert!(r["mu_error_sup"].as_f64().unwrap() < 0.05);
    let uv = vt_lines(&out);
    let mesh = io::read(
        Path::new("meshes/disk_hemisphere.obj"),
        &BuildOptions::default(),
    )
    .unwrap()
    .mesh;
    assert_eq!(uv.len(), mesh.vertex_count());
    for l in mesh.boundary_loop_list() {
        for v in l.vertices {
            let (x, y) = uv[v.idx()];
            assert!((x.hypot(y) - 1.0).abs() < 1e-9);
        }
    }
}

#[test]
fn sphere_target_takes_a_stereographic_expression() {
    let dir = tempfile::tempdir().unwrap();
    let sphere = Mesh::from_soup(&primitives::octahedral_sphere(3)).unwrap();
    let input = write(dir.path(), "sphere.obj", &sphere);
    let out = dir.path().join("image.obj");
    let report = dir.path().join("report.json");
    let run = beltrami(&[
        "qc",
        s(&input),
        "--solver",
        "beltrami-flow",
        "--target",
        "sphere",
        "--mu-expr",
        "0.3+0.3i",
        "-o",
        s(&out),
        "--report",
        s(&report),
    ]);
    assert!(run.status.success(), "{}", text(&run.stderr));
    let image = io::read(&out, &BuildOptions::default()).unwrap().mesh;
    for p in image.positions() {
        assert!((p.coords.norm() - 1.0).abs() < 1e-9);
    }
    let r = read_json(&report);
    assert_eq!(r["flipped"], 0);
    // Table 5.2, level 3: the paper's squared L2 error is 0.1145.
    assert!(r["mu_error_l2_squared"].as_f64().unwrap() < 0.1145);
    let notes = r["notes"].as_array().unwrap();
    assert!(
        notes
            .iter()
            .any(|n| n.as_str().unwrap().contains("pinned vertices 0, 1, 5"))
    );
}

#[test]
fn annulus_with_a_free_radius_reports_it() {
    let dir = tempfile::tempdir().unwrap();
    let annulus = Mesh::from_soup(&primitives::annulus(0.4, 6, 48)).unwrap();
    let input = write(dir.path(), "annulus.obj", &annulus);
    let out = dir.path().join("image.obj");
    let run = beltrami(&[
        "qc",
        s(&input),
        "--solver",
        "beltrami-flow",
        "--target",
        "annulus",
        "--free-radius",
        "--mu-expr",
        "0.6*z^3",
        "--pin",
        "1,0",
        "-o",
        s(&out),
    ]);
    assert!(run.status.success(), "{}", text(&run.stderr));
    let summary = text(&run.stdout);
    assert!(summary.contains("inner radius 0.4"), "{summary}");
    assert!(summary.contains("flipped faces   0"), "{summary}");
}

#[test]
fn ctrl_c_writes_the_map_so_far() {
    use std::io::{BufRead, BufReader, Read};
    let dir = tempfile::tempdir().unwrap();
    let sphere = Mesh::from_soup(&primitives::octahedral_sphere(6)).unwrap();
    let input = write(dir.path(), "sphere.obj", &sphere);
    let out = dir.path().join("image.obj");
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_beltrami"))
        .args([
            "qc",
            s(&input),
            "--solver",
            "beltrami-flow",
            "--target",
            "sphere",
            "--mu-expr",
            "0.3+0.3i",
            "--tolerance",
            "1e-12",
            "--progress-lines",
            "-o",
            s(&out),
        ])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // Interrupt once the first flow step is done (the progress lines say so).
    let mut stderr = BufReader::new(child.stderr.take().unwrap());
    let mut seen = String::new();
    loop {
        let mut line = String::new();
        if stderr.read_line(&mut line).unwrap() == 0 {
            panic!("the run ended before its first step: {seen}");
        }
        seen.push_str(&line);
        if line.starts_with("flow 1/") {
            break;
        }
    }
    // SAFETY: signalling our own child process.
    unsafe {
        libc::kill(child.id() as libc::pid_t, libc::SIGINT);
    }
    stderr.read_to_string(&mut seen).unwrap();
    let status = child.wait().unwrap();
    assert!(!status.success());
    assert!(seen.contains("interrupted after"), "{seen}");
    assert!(seen.contains("the map so far was written"), "{seen}");
    let image = io::read(&out, &BuildOptions::default()).unwrap().mesh;
    assert_eq!(image.vertex_count(), sphere.vertex_count());
    for p in image.positions() {
        assert!((p.coords.norm() - 1.0).abs() < 1e-9);
    }
}

#[test]
fn bad_requests_fail_with_a_reason() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.obj");
    let run = beltrami(&[
        "qc",
        "meshes/disk_hemisphere.obj",
        "--solver",
        "beltrami-flow",
        "--target",
        "sphere",
        "--conformal",
        "-o",
        s(&out),
    ]);
    assert!(!run.status.success());
    assert!(
        text(&run.stderr).contains("closed genus-0"),
        "{}",
        text(&run.stderr)
    );
    assert!(!out.exists(), "nothing written");

    let run = beltrami(&[
        "qc",
        "meshes/disk_hemisphere.obj",
        "--boundary",
        "given",
        "--conformal",
        "-o",
        s(&out),
    ]);
    assert!(!run.status.success());
    assert!(text(&run.stderr).contains("--boundary-map"));

    let run = beltrami(&[
        "qc",
        "meshes/disk_hemisphere.obj",
        "--mu-expr",
        "0",
        "--p",
        "3",
        "-o",
        s(&out),
    ]);
    assert!(!run.status.success());
    assert!(text(&run.stderr).contains("--conformal"));
}

#[test]
fn generate_writes_the_paper_meshes() {
    let dir = tempfile::tempdir().unwrap();
    for (shape, faces) in [
        ("disk", 64),
        ("sphere", 128),
        ("annulus", 2 * 2 * 8),
        ("square", 2 * 32 * 32),
    ] {
        let out = dir.path().join(format!("{shape}.obj"));
        let level = if shape == "annulus" || shape == "square" {
            "0"
        } else {
            "2"
        };
        let run = beltrami(&["generate", shape, "--level", level, "-o", s(&out)]);
        assert!(run.status.success(), "{}", text(&run.stderr));
        let mesh = io::read(&out, &BuildOptions::default()).unwrap().mesh;
        assert_eq!(mesh.face_count(), faces, "{shape}");
    }
    let run = beltrami(&[
        "generate",
        "annulus",
        "--inner",
        "1.5",
        "-o",
        s(&dir.path().join("a.obj")),
    ]);
    assert!(!run.status.success());
    assert!(text(&run.stderr).contains("--inner"));
}

#[test]
fn the_plane_target_keeps_the_inputs_region_unless_told_otherwise() {
    // beltrami-flow takes no free boundary: `--target plane` keeps the input's own
    // planar region by default, and a free boundary asked for is refused by its check.
    let dir = tempfile::tempdir().unwrap();
    let disk = dir.path().join("disk.obj");
    let run = beltrami(&["generate", "disk", "--level", "2", "-o", s(&disk)]);
    assert!(run.status.success(), "{}", text(&run.stderr));
    let out = dir.path().join("out.obj");
    let report = dir.path().join("report.json");
    let flow = ["qc", s(&disk), "--solver", "beltrami-flow", "--conformal"];
    let run = beltrami(&[&flow[..], &["-o", s(&out), "--report", s(&report)]].concat());
    assert!(run.status.success(), "{}", text(&run.stderr));
    assert_eq!(read_json(&report)["flipped"], 0);
    let out = dir.path().join("free.obj");
    let run = beltrami(&[&flow[..], &["--boundary", "free", "-o", s(&out)]].concat());
    assert!(!run.status.success());
    assert!(
        text(&run.stderr).contains("use lsqc"),
        "{}",
        text(&run.stderr)
    );
    assert!(!out.exists());
}

#[test]
fn slivers_do_not_end_near_a_fold() {
    let Some(shared) = common::shared_meshes("slivers_do_not_end_near_a_fold") else {
        return;
    };
    // The human face has 54 sliver triangles (angles of 1.5-24 degrees). Weighted by
    // area alone the flow drove them to |mu| 0.999; the near-fold barrier, which weighs
    // every face at least by the mean area, keeps every face away from the fold. The
    // bounds are the Choi-Lui disk map's mean and max |mu| on the same meshes
    // (`../shared/peers`: 0.0214 / 0.283 and 0.0195 / 0.835).
    for (mesh, mean_bound, max_bound) in [
        ("disk_human_face.obj", 0.0214, 0.283),
        ("disk_hand.obj", 0.0195, 0.835),
    ] {
        let dir = tempfile::tempdir().unwrap();
        let (out, report) = (dir.path().join("out.obj"), dir.path().join("r.json"));
        let run = beltrami(&[
            "qc",
            s(&shared.join(mesh)),
            "--solver",
            "beltrami-flow",
            "--target",
            "disk",
            "--conformal",
            "-o",
            s(&out),
            "--report",
            s(&report),
        ]);
        assert!(run.status.success(), "{}", text(&run.stderr));
        let r = read_json(&report);
        let (mean, max) = (
            r["mu_mean"].as_f64().unwrap(),
            r["mu_max"].as_f64().unwrap(),
        );
        println!("{mesh} onto the disk: mean |mu| {mean}, max {max}");
        assert_eq!(r["flipped"], 0);
        assert!(max < max_bound, "{mesh}: max |mu| {max}");
        assert!(mean < mean_bound, "{mesh}: mean |mu| {mean}");
    }
}
