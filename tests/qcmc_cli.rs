//! End-to-end runs of the solver qcmc: `beltrami param --solver qcmc` and `beltrami qc
//! --solver qcmc` onto circle domains, the report's circles, `--outer`.

mod common;

use common::{beltrami, s, text};

fn read_json(path: &std::path::Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// A generated annulus `0.4 <= |z| <= 1` (level 3: 64 sectors, 16 rings).
fn annulus(dir: &std::path::Path) -> std::path::PathBuf {
    let path = dir.join("annulus.obj");
    let run = beltrami(&[
        "generate",
        "annulus",
        "--level",
        "3",
        "--inner",
        "0.4",
        "-o",
        s(&path),
    ]);
    assert!(run.status.success(), "{}", text(&run.stderr));
    path
}

/// `beltrami param MESH --solver qcmc -o DIR/out.obj --report DIR/report.json`; the
/// run, and the report's path.
fn param_qcmc(
    dir: &std::path::Path,
    mesh: &std::path::Path,
) -> (std::process::Output, std::path::PathBuf) {
    let out = dir.join("out.obj");
    let report = dir.join("report.json");
    let run = beltrami(&[
        "param",
        s(mesh),
        "--solver",
        "qcmc",
        "-o",
        s(&out),
        "--report",
        s(&report),
    ]);
    assert!(run.status.success(), "{}", text(&run.stderr));
    (run, report)
}

#[test]
fn param_maps_an_annulus_onto_its_own_circles() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = annulus(dir.path());
    let (run, report) = param_qcmc(dir.path(), &mesh);
    let stdout = text(&run.stdout);
    assert!(
        stdout.contains("circle centre") && stdout.contains("Moebius normalization"),
        "{stdout}"
    );
    let json = read_json(&report);
    assert_eq!(json["solver"], "qcmc");
    assert_eq!(json["flipped"], 0);
    let circles = json["circles"].as_array().unwrap();
    assert_eq!(circles.len(), 2);
    assert_eq!(circles[0]["radius"], 1.0);
    // The conformal module of 0.4 < |z| < 1 is its own: the inner circle comes back.
    let r = circles[1]["radius"].as_f64().unwrap();
    assert!((r - 0.4).abs() < 2e-3, "{r}");
    assert!(circles[1]["deviation"].as_f64().unwrap() < 1e-12);
    assert!(
        std::fs::read_to_string(dir.path().join("out.obj"))
            .unwrap()
            .lines()
            .any(|l| l.starts_with("vt "))
    );
}

#[test]
fn qc_follows_a_prescribed_mu_onto_a_circle_domain() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = annulus(dir.path());
    let out = dir.path().join("out.obj");
    let report = dir.path().join("report.json");
    let run = beltrami(&[
        "qc",
        s(&mesh),
        "--solver",
        "qcmc",
        "--mu-expr",
        "0.3*z",
        "-o",
        s(&out),
        "--report",
        s(&report),
    ]);
    assert!(run.status.success(), "{}", text(&run.stderr));
    let json = read_json(&report);
    assert_eq!(json["flipped"], 0);
    assert_eq!(json["circles"].as_array().unwrap().len(), 2);
    let rms = json["mu_error_l2"].as_f64().unwrap();
    assert!(rms < 0.02, "|mu - target| RMS {rms}");
    assert!(json["iterations"].as_u64().unwrap() > 0);
}

#[test]
fn outer_picks_the_loop_on_the_unit_circle() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = annulus(dir.path());
    let mut outer_loops = Vec::new();
    for l in ["0", "1"] {
        let out = dir.path().join(format!("out{l}.obj"));
        let report = dir.path().join(format!("report{l}.json"));
        let run = beltrami(&[
            "param",
            s(&mesh),
            "--solver",
            "qcmc",
            "--outer",
            l,
            "-o",
            s(&out),
            "--report",
            s(&report),
        ]);
        assert!(run.status.success(), "{}", text(&run.stderr));
        let json = read_json(&report);
        outer_loops.push(json["circles"][0]["loop"].as_u64().unwrap());
    }
    assert_eq!(outer_loops, [0, 1]);
    let out = dir.path().join("bad.obj");
    let run = beltrami(&[
        "param",
        s(&mesh),
        "--solver",
        "qcmc",
        "--outer",
        "2",
        "-o",
        s(&out),
    ]);
    assert!(!run.status.success());
    assert!(
        text(&run.stderr).contains("no loop 2"),
        "{}",
        text(&run.stderr)
    );
    assert!(!out.exists());
}

#[test]
fn qcmc_and_the_flow_find_the_same_annulus_for_a_prescribed_mu() {
    // k = 2 is the flow's annulus with a free inner radius: for mu = 0.3 z on the annulus
    // 0.4 <= |z| <= 1 (no closed form), the two methods must agree on the radius, closer
    // and closer under refinement.
    let dir = tempfile::tempdir().unwrap();
    let mut gaps = Vec::new();
    for level in ["3", "4"] {
        let mesh = dir.path().join(format!("annulus{level}.obj"));
        let run = beltrami(&[
            "generate",
            "annulus",
            "--level",
            level,
            "--inner",
            "0.4",
            "-o",
            s(&mesh),
        ]);
        assert!(run.status.success(), "{}", text(&run.stderr));
        let radius = |solver: &[&str], key: fn(&serde_json::Value) -> f64| {
            let out = dir.path().join("out.obj");
            let report = dir.path().join("report.json");
            let args = [
                &["qc", s(&mesh), "--mu-expr", "0.3*z"][..],
                solver,
                &["-o", s(&out), "--report", s(&report)],
            ]
            .concat();
            let run = beltrami(&args);
            assert!(run.status.success(), "{}", text(&run.stderr));
            let json = read_json(&report);
            assert_eq!(json["flipped"], 0);
            key(&json)
        };
        let flow = radius(
            &[
                "--solver",
                "beltrami-flow",
                "--target",
                "annulus",
                "--free-radius",
            ],
            |j| j["annulus_radius"].as_f64().unwrap(),
        );
        let qcmc = radius(&["--solver", "qcmc"], |j| {
            j["circles"][1]["radius"].as_f64().unwrap()
        });
        println!("level {level}: flow {flow:.6}, qcmc {qcmc:.6}");
        gaps.push((flow - qcmc).abs());
    }
    assert!(gaps[0] < 5e-4 && gaps[1] < 0.5 * gaps[0], "{gaps:?}");
}

#[test]
fn a_generated_circle_domain_maps_onto_a_circle_domain() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = dir.path().join("domain.obj");
    let run = beltrami(&[
        "generate",
        "circle-domain",
        "--level",
        "2",
        // The documented form, a separate value that starts with a minus sign.
        "--holes",
        "-0.4,0,0.2;0.35,0.3,0.15",
        "-o",
        s(&mesh),
    ]);
    assert!(run.status.success(), "{}", text(&run.stderr));
    let (_, report) = param_qcmc(dir.path(), &mesh);
    let json = read_json(&report);
    assert_eq!(json["circles"].as_array().unwrap().len(), 3);
    assert_eq!(json["flipped"], 0);
    // A circle domain is conformally a circle domain: only discretization error remains
    // (edges of 1/16 here).
    let mean = json["mu_mean"].as_f64().unwrap();
    assert!(mean < 0.03, "mean |mu| {mean}");
    for holes in ["0,0,0.99", "-0.2,0,0.2;0.2,0,0.2", "0,0", "0,0,1e-12"] {
        let run = beltrami(&[
            "generate",
            "circle-domain",
            &format!("--holes={holes}"),
            "-o",
            s(&dir.path().join("bad.obj")),
        ]);
        assert!(!run.status.success(), "{holes} was accepted");
        assert!(text(&run.stderr).contains("hole"), "{}", text(&run.stderr));
    }
}
