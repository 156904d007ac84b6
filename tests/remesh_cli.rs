//! End-to-end runs of `beltrami remesh`: generated surfaces of every topology class
//! keep their topology and get the asked edge length, the report and the picture are
//! written, and bad options fail before any output is written. The shared meshes (one
//! per class) run when `../shared` is there.

use std::path::Path;

use beltrami_core::topology::describe;
use beltrami_mesh::io::{self, VertexAttributes};
use beltrami_mesh::primitives::{Cells, annulus, disk, icosphere, torus};
use beltrami_mesh::{BuildOptions, Mesh, PolygonSoup};

mod common;
use common::{beltrami, s, shared_meshes, text};

fn write_soup(path: &Path, soup: &PolygonSoup) -> Mesh {
    let mesh = Mesh::from_soup(soup).unwrap();
    io::obj::write(path, &mesh, &VertexAttributes::default()).unwrap();
    mesh
}

fn read(path: &Path) -> Mesh {
    io::read(path, &BuildOptions::default()).unwrap().mesh
}

/// Runs `remesh INPUT --edge-length L -o OUT --report R`, checks the output's topology
/// against the input's and the report's numbers against the output; returns the report.
fn remesh_and_check(input: &Path, mesh: &Mesh, l: f64, extra: &[&str]) -> serde_json::Value {
    let dir = tempfile::tempdir().unwrap();
    let output = dir.path().join("out.obj");
    let report = dir.path().join("report.json");
    let length = l.to_string();
    let mut args = vec![
        "remesh",
        s(input),
        "--edge-length",
        &length,
        "-o",
        s(&output),
        "--report",
        s(&report),
    ];
    args.extend_from_slice(extra);
    let out = beltrami(&args);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let result = read(&output);
    assert_eq!(
        describe(&result),
        describe(mesh),
        "topology of {}",
        input.display()
    );
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(r["vertices"], result.vertex_count());
    assert_eq!(r["faces"], result.face_count());
    assert_eq!(r["topology"], describe(mesh));
    for key in [
        "min_angle",
        "share_below_30",
        "edge_spread",
        "hausdorff",
        "mean_distance",
    ] {
        assert!(
            r[key].as_f64().is_some_and(f64::is_finite),
            "{key}: {}",
            r[key]
        );
    }
    r
}

#[test]
fn every_topology_class_keeps_its_topology_and_the_asked_edge_length() {
    let dir = tempfile::tempdir().unwrap();
    let cases: [(&str, PolygonSoup, f64); 4] = [
        ("disk", disk(5), 0.05),
        ("sphere", icosphere(4), 0.1),
        ("torus", torus(48, 20, 1.0, 0.4, Cells::Triangles), 0.08),
        ("annulus", annulus(0.3, 12, 64), 0.05),
    ];
    for (name, soup, l) in cases {
        let input = dir.path().join(format!("{name}.obj"));
        let mesh = write_soup(&input, &soup);
        let r = remesh_and_check(&input, &mesh, l, &[]);
        let ratio = r["edge_mean_over_asked"].as_f64().unwrap();
        assert!(
            (ratio - 1.0).abs() < 0.1,
            "{name}: mean edge {ratio} of the asked"
        );
        assert!(
            r["min_angle"].as_f64().unwrap() > 20.0,
            "{name}: {}",
            r["min_angle"]
        );
    }
}

#[test]
fn vertices_curvature_and_png_are_honoured() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("sphere.obj");
    let output = dir.path().join("out.glb");
    let png = dir.path().join("out.png");
    write_soup(&input, &icosphere(4));
    let out = beltrami(&[
        "remesh",
        s(&input),
        "--vertices",
        "1500",
        "--size-field",
        "curvature",
        "--param",
        "lscm",
        "-o",
        s(&output),
        "--png",
        s(&png),
        "--json",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let r: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let n = r["vertices"].as_f64().unwrap();
    assert!((n / 1500.0 - 1.0).abs() < 0.15, "{n} vertices for 1500");
    assert_eq!(r["parameterizer"], "lscm");
    assert_eq!(r["opening"], "slit");
    assert!(read(&output).vertex_count() == n as usize);
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
}

#[test]
fn bad_options_fail_with_the_option_named_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("disk.obj");
    let torus_file = dir.path().join("torus.obj");
    let output = dir.path().join("out.obj");
    write_soup(&input, &disk(3));
    write_soup(&torus_file, &torus(24, 8, 1.0, 0.4, Cells::Triangles));
    let cases: [(&[&str], &str); 19] = [
        (&["--edge-length", "0"], "edge-length"),
        (
            &["--edge-length", "0.1", "--feature-tolerance", "0"],
            "feature-tolerance",
        ),
        (
            &["--edge-length", "0.1", "--feature-tolerance", "NaN"],
            "feature-tolerance",
        ),
        (&["--edge-length", "-0.1"], "edge-length"),
        (&["--edge-length", "NaN"], "edge-length"),
        (&["--edge-length", "inf"], "edge-length"),
        (&["--vertices", "2"], "vertices"),
        (&["--edge-length", "0.1", "--min-angle", "35"], "min-angle"),
        (
            &["--edge-length", "0.1", "--param", "nosuch"],
            "no solver named `nosuch`",
        ),
        (
            &["--edge-length", "0.1", "--method", "qc-angles"],
            "drop --edge-length",
        ),
        (
            &["--method", "qc-angles", "--tolerance", "0"],
            "--tolerance",
        ),
        (
            &["--method", "qc-angles", "--feature-angle", "200"],
            "--feature-angle",
        ),
        (
            &["--method", "qc-angles", "--min-angle", "25"],
            "--min-angle is a flag of --method param",
        ),
        (
            &["--edge-length", "0.1", "--reference", "equiangular"],
            "--reference is a flag of --method qc-angles",
        ),
        (&[], "--edge-length L or --vertices N"),
        // Sizes refused before any work (they ran for minutes or aborted on a 150 GB
        // allocation).
        (
            &["--edge-length", "1e-9", "--max-vertices", "1000"],
            "more than the most allowed (1000, option `max-vertices`)",
        ),
        (&["--edge-length", "1e-300"], "option `max-vertices`"),
        (&["--edge-length", "1e-5"], "option `max-vertices`"),
        (
            &["--vertices", "1000000000000"],
            "would make about 1.000e12 vertices",
        ),
    ];
    for (extra, expected) in cases {
        let mut args = vec!["remesh", s(&input), "-o", s(&output)];
        args.extend_from_slice(extra);
        let out = beltrami(&args);
        assert!(!out.status.success(), "{extra:?} succeeded");
        let stderr = text(&out.stderr);
        assert!(
            stderr.contains(expected),
            "{extra:?}: `{expected}` not in\n{stderr}"
        );
        assert!(!output.exists(), "{extra:?} wrote an output");
    }
    // A spherical map serves closed genus-0 surfaces only.
    let out = beltrami(&[
        "remesh",
        s(&torus_file),
        "--edge-length",
        "0.2",
        "--param",
        "sphere",
        "-o",
        s(&output),
    ]);
    assert!(!out.status.success());
    assert!(
        text(&out.stderr).contains("maps closed genus-0 surfaces onto the sphere"),
        "{}",
        text(&out.stderr)
    );
    assert!(!output.exists());
}

#[test]
fn shared_meshes_of_every_class_keep_their_topology() {
    let Some(dir) = shared_meshes("shared_meshes_of_every_class_keep_their_topology") else {
        return;
    };
    for name in [
        "disk_hemisphere",
        "g0_spot",
        "g1_bob",
        "g2_eight",
        "mc4_face_b",
        "mc2_sophie",
    ] {
        let input = dir.join(format!("{name}.obj"));
        let mesh = read(&input);
        let l = 0.015 * mesh.bounding_box().diagonal();
        let r = remesh_and_check(&input, &mesh, l, &[]);
        let ratio = r["edge_mean_over_asked"].as_f64().unwrap();
        assert!(
            (ratio - 1.0).abs() < 0.1,
            "{name}: mean edge {ratio} of the asked"
        );
        let hausdorff = r["hausdorff_over_diagonal"].as_f64().unwrap();
        assert!(
            hausdorff < 0.005,
            "{name}: Hausdorff {hausdorff} of the diagonal"
        );
        // The angle limit holds on the surface too, after the flips across seams and the
        // relaxation of the worst stars (without them, at 1% of the diagonal: g2_eight
        // 14.3 degrees, disk_human_face 14.8).
        let min_angle = r["min_angle"].as_f64().unwrap();
        println!("{name}: smallest angle {min_angle}, Hausdorff {hausdorff}");
        assert!(min_angle >= 20.0, "{name}: smallest angle {min_angle}");
    }
}

#[test]
fn the_scanned_face_stays_within_the_hausdorff_goal() {
    let Some(dir) = shared_meshes("the_scanned_face_stays_within_the_hausdorff_goal") else {
        return;
    };
    // Issue 16's goal is a Hausdorff distance of at most 0.3% of the diagonal at an edge
    // length of 1% of it. The scan's creases bound it: before the feature check ran
    // again after the smoothing, and before the star relaxation kept the features, its
    // distance was 0.31-0.46% for lengths of 0.9-1.1% of the diagonal.
    let input = dir.join("disk_human_face.obj");
    let mesh = read(&input);
    for fraction in [0.009, 0.01, 0.011] {
        let l = fraction * mesh.bounding_box().diagonal();
        let r = remesh_and_check(&input, &mesh, l, &[]);
        let hausdorff = r["hausdorff_over_diagonal"].as_f64().unwrap();
        let min_angle = r["min_angle"].as_f64().unwrap();
        println!("at {fraction}: Hausdorff {hausdorff}, smallest angle {min_angle}");
        assert!(hausdorff <= 0.003, "at {fraction}: Hausdorff {hausdorff}");
        assert!(
            min_angle >= 20.0,
            "at {fraction}: smallest angle {min_angle}"
        );
    }
}

#[test]
fn eight_small_holes_are_remeshed_with_their_holes_closed() {
    let Some(dir) = shared_meshes("eight_small_holes_are_remeshed_with_their_holes_closed") else {
        return;
    };
    // `auto` maps mc8_peaks by LSCM with its seven holes closed by scaffold faces. Its
    // circle domain (`qcmc`) squeezes a face at a 20-vertex hole to a near-fold, and the
    // remesh through it had 19,823 vertices (mean edge 0.51 L) and a smallest angle of
    // 1.1 degrees; once refinement around such a face passed 100,000 vertices.
    let input = dir.join("mc8_peaks.obj");
    let mesh = read(&input);
    let l = 0.01 * mesh.bounding_box().diagonal();
    let r = remesh_and_check(&input, &mesh, l, &["--max-vertices", "100000"]);
    assert_eq!(r["parameterizer"], "lscm");
    assert_eq!(r["opening"], "filled");
    let vertices = r["vertices"].as_u64().unwrap();
    let min_angle = r["min_angle"].as_f64().unwrap();
    let ratio = r["edge_mean_over_asked"].as_f64().unwrap();
    let hausdorff = r["hausdorff_over_diagonal"].as_f64().unwrap();
    println!(
        "mc8_peaks: {vertices} vertices, min angle {min_angle}, mean edge {ratio} L, Hausdorff {hausdorff}"
    );
    assert!((ratio - 1.0).abs() < 0.1, "mean edge {ratio} of the asked");
    assert!(min_angle > 15.0, "smallest angle {min_angle}");
    assert!(hausdorff < 0.003, "Hausdorff {hausdorff} of the diagonal");
}

#[test]
fn qc_angles_moves_the_vertices_towards_better_angles() {
    // spot (bundled): the same vertices and faces, the smallest angle up from 10
    // degrees, few angles under 30, the cow still where it was.
    let dir = tempfile::tempdir().unwrap();
    let input = Path::new("meshes/spot.obj");
    let output = dir.path().join("out.obj");
    let report = dir.path().join("r.json");
    let run = beltrami(&[
        "remesh",
        s(input),
        "--method",
        "qc-angles",
        "-o",
        s(&output),
        "--report",
        s(&report),
    ]);
    assert!(run.status.success(), "{}", text(&run.stderr));
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    let (mesh, result) = (read(input), read(&output));
    assert_eq!(result.vertex_count(), mesh.vertex_count());
    assert!(
        mesh.faces()
            .all(|f| mesh.face_vertices(f).eq(result.face_vertices(f)))
    );
    let number = |path: &[&str]| {
        path.iter()
            .fold(&r, |v, k| &v[*k])
            .as_f64()
            .unwrap_or_else(|| panic!("{path:?} in {r}"))
    };
    let (before, after) = (
        number(&["before", "min_angle"]),
        number(&["after", "min_angle"]),
    );
    let (share_before, share_after) = (
        number(&["before", "share_below_30"]),
        number(&["after", "share_below_30"]),
    );
    println!("min angle {before:.2} -> {after:.2}, under 30 {share_before:.4} -> {share_after:.4}");
    assert!(after > before + 5.0);
    assert!(share_after < 0.2 * share_before);
    assert!(number(&["hausdorff_over_diagonal"]) < 0.006);
    assert_eq!(r["flipped"], 0);
    assert_eq!(r["reference"], "optimized");
    assert_eq!(r["constraint"], "normal");
    assert!(number(&["k"]) > 0.0 && number(&["iterations"]) >= 1.0);
}

#[test]
fn a_mesh_in_pieces_is_remeshed_piece_by_piece_or_its_largest_alone() {
    let dir = tempfile::tempdir().unwrap();
    // A disk and a torus beside it, the disk's faces first.
    let mut soup = disk(3);
    let disk_faces = soup.face_count();
    let torus = torus(64, 24, 2.0, 0.6, Cells::Triangles);
    assert!(torus.face_count() > disk_faces);
    let offset = soup.positions.len() as u32;
    soup.positions.extend(
        torus
            .positions
            .iter()
            .map(|p| p + beltrami_mesh::Vector3::new(5.0, 0.0, 0.0)),
    );
    for f in torus.faces() {
        let f: Vec<u32> = f.iter().map(|i| i + offset).collect();
        soup.push_face(&f);
    }
    let input = dir.path().join("pieces.obj");
    let mesh = write_soup(&input, &soup);
    assert_eq!(mesh.component_count(), 2);

    // Without the flag: refused, naming the flags, nothing written.
    let output = dir.path().join("out.obj");
    let out = beltrami(&[
        "remesh",
        s(&input),
        "--edge-length",
        "0.15",
        "-o",
        s(&output),
    ]);
    assert!(!out.status.success());
    let stderr = text(&out.stderr);
    assert!(
        stderr.contains("2 components") && stderr.contains("--components each"),
        "{stderr}"
    );
    assert!(!output.exists());

    // each: both pieces, each its topology, the report listing them in order.
    let r = remesh_and_check(&input, &mesh, 0.15, &["--components", "each"]);
    let pieces = r["components"].as_array().unwrap();
    assert_eq!(pieces.len(), 2);
    assert_eq!(
        (
            pieces[0]["input_faces"].as_u64(),
            pieces[1]["input_faces"].as_u64()
        ),
        (Some(disk_faces as u64), Some(torus.face_count() as u64))
    );
    assert_eq!(
        pieces[0]["vertices"].as_u64().unwrap() + pieces[1]["vertices"].as_u64().unwrap(),
        r["vertices"].as_u64().unwrap()
    );
    assert_eq!(r["opening"], "per component", "{r}");

    // largest: the torus (the most faces) alone.
    let out = beltrami(&[
        "remesh",
        s(&input),
        "--edge-length",
        "0.15",
        "--components",
        "largest",
        "-o",
        s(&output),
        "--json",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let r: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let result = read(&output);
    assert_eq!(
        describe(&result),
        describe(&Mesh::from_soup(&torus).unwrap())
    );
    assert_eq!(r["input_faces"], torus.face_count());
    assert!(
        r["notes"].to_string().contains("largest of 2 components"),
        "{r}"
    );

    // qc-angles keeps the input's vertices and does not read --components.
    let out = beltrami(&[
        "remesh",
        s(&input),
        "--method",
        "qc-angles",
        "--components",
        "each",
        "-o",
        s(&output),
    ]);
    assert!(!out.status.success());
    assert!(
        text(&out.stderr).contains("--components"),
        "{}",
        text(&out.stderr)
    );
}

#[test]
fn a_face_with_three_small_holes_is_remeshed_at_every_length() {
    // The scanned face with every face removed whose centroid lies within 0.006 of the
    // centroid of face 5000, 15000 or 25000: four boundary loops. Two flips of one sweep
    // on the assembled surface made the same edge ("face 3051 duplicates face 3050",
    // "edge .. is non-manifold") at every edge length from 0.002 to 0.02.
    let Some(dir) = shared_meshes("a_face_with_three_small_holes_is_remeshed_at_every_length")
    else {
        return;
    };
    let face = read(&dir.join("disk_human_face.obj"));
    let centroid = |f: beltrami_mesh::FaceId| face.face_centroid(f);
    let faces: Vec<_> = face.faces().collect();
    let centres = [5000, 15000, 25000].map(|k| centroid(faces[k]));
    let mut soup = PolygonSoup::new(face.positions().to_vec());
    for &f in &faces {
        if centres.iter().all(|c| (centroid(f) - c).norm() >= 0.006) {
            let corners: Vec<u32> = face.face_vertices(f).map(|v| v.0).collect();
            soup.push_face(&corners);
        }
    }
    let holes = Mesh::build(
        &soup,
        &BuildOptions {
            repair: beltrami_mesh::Repair::ALL,
            ..BuildOptions::default()
        },
    )
    .unwrap()
    .0;
    assert_eq!(holes.boundary_loop_list().len(), 4);
    let tmp = tempfile::tempdir().unwrap();
    let input = tmp.path().join("holes.obj");
    io::obj::write(&input, &holes, &VertexAttributes::default()).unwrap();
    for l in [0.02, 0.005, 0.002] {
        remesh_and_check(&input, &holes, l, &[]);
    }
}

#[test]
fn the_remesh_solver_is_listed_with_the_options_of_both_methods() {
    let out = beltrami(&["solvers"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let listing = text(&out.stdout);
    assert!(
        listing.lines().any(|l| l.starts_with("remesh ")),
        "{listing}"
    );
    let out = beltrami(&["solvers", "--json"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let solvers: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let remesh = solvers
        .as_array()
        .and_then(|list| list.iter().find(|s| s["name"] == "remesh"))
        .expect("remesh in `solvers --json`");
    assert_eq!(remesh["accepts"]["targets"], serde_json::json!(["surface"]));
    let options: Vec<&str> = remesh["options"]
        .as_array()
        .unwrap()
        .iter()
        .map(|o| o["name"].as_str().unwrap())
        .collect();
    for name in [
        "method",
        "edge-length",
        "vertices",
        "param",
        "min-angle",
        "size-field",
        "max-vertices",
        "feature-tolerance",
        "components",
        "reference",
        "constraint",
        "max-iters",
        "tolerance",
        "project",
        "feature-angle",
        "allow-flips",
    ] {
        assert!(options.contains(&name), "{name} not in {options:?}");
    }
    let method = &remesh["options"][0];
    assert_eq!(method["name"], "method");
    assert_eq!(method["choices"], serde_json::json!(["param", "qc-angles"]));
    let param = remesh["options"]
        .as_array()
        .unwrap()
        .iter()
        .find(|o| o["name"] == "param")
        .unwrap();
    assert_eq!(
        (&param["type"], &param["default"]),
        (&"name".into(), &"auto".into())
    );
    // It maps into no parameter domain: `param` does not offer it.
    let help = text(&beltrami(&["param", "--help"]).stdout);
    assert!(!help.contains("remesh"), "{help}");
}

#[test]
fn the_registered_solver_remeshes_a_generated_hemisphere() {
    // `beltrami::registry()` as every front end builds it: its `remesh` takes its
    // parameterizers from the same registry.
    let mut soup = disk(4);
    for p in &mut soup.positions {
        p.z = (1.0 - p.x * p.x - p.y * p.y).max(0.0).sqrt();
    }
    let mesh = Mesh::from_soup(&soup).unwrap();
    let registry = beltrami::registry();
    let solver = registry.get("remesh").unwrap();
    for l in [0.12, 0.06] {
        let mut problem = beltrami_core::Problem::new(&mesh, beltrami_core::Target::Surface);
        problem.options.set_text("edge-length", &l.to_string());
        let solution = solver
            .solve(&problem, &mut beltrami_core::Context::new())
            .unwrap();
        let beltrami_core::Output::Mesh(remeshed) = &solution.output else {
            panic!("remesh gave no mesh");
        };
        let q = beltrami::remesh::quality::measure(&mesh, &remeshed.mesh).unwrap();
        let ratio = q.edge_mean / l;
        assert!((ratio - 1.0).abs() < 0.1, "at {l}: mean edge {ratio} L");
        assert!(q.min_angle > 20.0, "at {l}: smallest angle {}", q.min_angle);
        assert_eq!(describe(&remeshed.mesh), describe(&mesh));
    }
}

#[test]
fn a_batch_job_remeshes_through_the_solver() {
    let dir = tempfile::tempdir().unwrap();
    let output = dir.path().join("out.obj");
    let refused = dir.path().join("refused.obj");
    let jobs = dir.path().join("jobs.jsonl");
    let lines = [
        serde_json::json!({
            "command": "remesh", "input": "meshes/disk_hemisphere.obj", "output": s(&output),
            "options": {"edge-length": 0.1, "size-field": "curvature"},
        }),
        serde_json::json!({
            "command": "remesh", "input": "meshes/disk_hemisphere.obj", "output": s(&refused),
            "options": {"method": "qc-angles", "min-angle": 25},
        }),
    ];
    let text_of = |v: &serde_json::Value| format!("{v}\n");
    std::fs::write(&jobs, lines.iter().map(text_of).collect::<String>()).unwrap();
    let report = dir.path().join("report.jsonl");
    let out = beltrami(&["-q", "batch", s(&jobs), "--report", s(&report)]);
    assert!(!out.status.success(), "the refused job fails the batch");
    let lines: Vec<serde_json::Value> = std::fs::read_to_string(&report)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let by_output = |path: &Path| {
        lines
            .iter()
            .find(|l| l["output"] == s(path))
            .unwrap_or_else(|| panic!("no report line for {}", path.display()))
    };
    let ok = by_output(&output);
    assert_eq!(ok["status"], "ok", "{ok}");
    assert_eq!(ok["report"]["method"], "param", "{ok}");
    assert!(output.exists());
    let failed = by_output(&refused);
    assert!(
        failed
            .to_string()
            .contains("--min-angle is a flag of --method param"),
        "{failed}"
    );
    assert!(!refused.exists());
}
