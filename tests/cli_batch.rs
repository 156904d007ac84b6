//! End-to-end runs of `beltrami batch`: good jobs beside a broken one, the report lines,
//! the exit code, and `--resume` after outputs were removed (as after a kill).

use std::path::Path;

mod common;
use common::{beltrami, s, text};

fn report_lines(path: &Path) -> Vec<serde_json::Value> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

#[test]
fn a_broken_job_is_reported_and_the_others_finish_then_resume_skips_them() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let out = |name: &str| d.join(name).to_str().unwrap().to_string();
    let jobs = d.join("jobs.jsonl");
    let lines = [
        format!(
            r#"{{"command": "param", "input": "meshes/spot.obj", "output": "{}", "options": {{"solver": "sphere"}}}}"#,
            out("spot_sphere.obj")
        ),
        "# a comment line".to_string(),
        format!(
            r#"{{"command": "param", "input": "meshes/disk_hemisphere.obj", "output": "{}", "options": {{"solver": "tutte", "boundary": "square"}}}}"#,
            out("hemi_tutte.obj")
        ),
        format!(
            r#"{{"command": "param", "input": "{}", "output": "{}", "options": {{"solver": "lscm"}}}}"#,
            out("missing.obj"),
            out("never.obj")
        ),
        format!(
            r#"{{"command": "register", "input": ["meshes/spot.obj", "meshes/blob.obj"], "output": "{}"}}"#,
            out("spot_on_blob.obj")
        ),
    ];
    std::fs::write(&jobs, lines.join("\n") + "\n").unwrap();
    let report = d.join("report.jsonl");
    let run = beltrami(&["batch", s(&jobs), "--jobs", "2", "--report", s(&report)]);
    assert!(!run.status.success(), "one job fails, so the batch does");
    assert!(
        text(&run.stderr).contains("1 of 4 jobs failed"),
        "{}",
        text(&run.stderr)
    );
    let lines = report_lines(&report);
    assert_eq!(lines.len(), 4);
    let status: Vec<&str> = lines
        .iter()
        .map(|l| l["status"].as_str().unwrap())
        .collect();
    assert_eq!(status, ["ok", "ok", "error", "ok"]);
    assert_eq!(lines[2]["line"], 4);
    assert!(
        lines[2]["message"]
            .as_str()
            .unwrap()
            .contains("missing.obj"),
        "{}",
        lines[2]
    );
    assert_eq!(lines[0]["report"]["solver"], "sphere");
    assert_eq!(lines[3]["report"]["flipped"], 0);
    for name in ["spot_sphere.obj", "hemi_tutte.obj", "spot_on_blob.obj"] {
        assert!(d.join(name).exists(), "{name}");
    }
    assert!(!d.join("never.obj").exists());

    // As after a kill: one output gone; --resume redoes only that job.
    std::fs::remove_file(d.join("hemi_tutte.obj")).unwrap();
    let run = beltrami(&["batch", s(&jobs), "--resume", "--report", s(&report)]);
    assert!(!run.status.success());
    let status: Vec<String> = report_lines(&report)
        .iter()
        .map(|l| l["status"].as_str().unwrap().to_string())
        .collect();
    assert_eq!(status, ["skipped", "ok", "error", "skipped"]);
    assert!(d.join("hemi_tutte.obj").exists());
}

#[test]
fn a_malformed_jobs_file_is_refused_before_any_job_runs() {
    let dir = tempfile::tempdir().unwrap();
    let jobs = dir.path().join("jobs.jsonl");
    let output = dir.path().join("a.obj");
    std::fs::write(
        &jobs,
        format!(
            "{{\"command\": \"param\", \"input\": \"meshes/spot.obj\", \"output\": \"{}\", \"options\": {{\"solver\": \"sphere\"}}}}\n{{\"command\": \"paint\"}}\n",
            s(&output)
        ),
    )
    .unwrap();
    let run = beltrami(&["batch", s(&jobs)]);
    assert!(!run.status.success());
    let stderr = text(&run.stderr);
    assert!(stderr.contains("line 2"), "{stderr}");
    assert!(!output.exists(), "no job ran");
}

/// A jobs file of `lines` in a fresh folder; the folder and the file.
fn jobs_file(lines: &[String]) -> (tempfile::TempDir, std::path::PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let jobs = dir.path().join("jobs.jsonl");
    std::fs::write(&jobs, lines.join("\n")).unwrap();
    (dir, jobs)
}

fn tutte_job(output: &str) -> String {
    format!(
        r#"{{"command": "param", "input": "meshes/disk_hemisphere.obj", "output": "{output}", "options": {{"solver": "tutte"}}}}"#
    )
}

#[test]
fn colliding_outputs_are_refused_before_any_job_runs() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a.obj");
    let same_a = dir.path().join("sub/../a.obj");
    std::fs::create_dir(dir.path().join("sub")).unwrap();
    let (_keep, jobs) = jobs_file(&[tutte_job(s(&a)), tutte_job(s(&same_a))]);
    let out = beltrami(&["batch", s(&jobs)]);
    assert!(!out.status.success());
    let stderr = text(&out.stderr);
    assert!(
        stderr.contains("line 2: the output")
            && stderr.contains("is also the output of the job on line 1"),
        "{stderr}"
    );
    assert!(!a.exists(), "a job ran");

    // The report may not overwrite the jobs file or a job's output.
    let (_keep, jobs) = jobs_file(&[tutte_job(s(&a))]);
    let out = beltrami(&["batch", s(&jobs), "--report", s(&jobs)]);
    assert!(
        text(&out.stderr).contains("is the jobs file"),
        "{}",
        text(&out.stderr)
    );
    let out = beltrami(&["batch", s(&jobs), "--report", s(&a)]);
    assert!(!out.status.success());
    assert!(
        text(&out.stderr).contains("is also the --report file"),
        "{}",
        text(&out.stderr)
    );
    assert!(!a.exists());
}

#[test]
fn a_byte_order_mark_and_flags_disguised_as_paths_or_values() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a.obj");
    let (_keep, jobs) = jobs_file(&[format!("\u{feff}{}", tutte_job(s(&a)))]);
    let out = beltrami(&["batch", s(&jobs), "-q"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(a.exists());

    for (line, expected) in [
        (
            r#"{"command": "param", "input": "--help", "output": "x.obj"}"#,
            "the input \"--help\" starts with `-`",
        ),
        (
            r#"{"command": "param", "input": "a.obj", "output": "x.obj", "options": {"help": true}}"#,
            "\"help\" is not a job option",
        ),
        (
            r#"{"command": "param", "input": "a.obj", "output": "x.obj", "options": {"solver": "--help"}}"#,
            "which the command would read as a flag",
        ),
    ] {
        let (_keep, jobs) = jobs_file(&[line.to_string()]);
        let out = beltrami(&["batch", s(&jobs)]);
        assert!(!out.status.success(), "{line}");
        assert!(
            text(&out.stderr).contains(expected),
            "{line}: {}",
            text(&out.stderr)
        );
    }
}

/// The processes whose parent is `pid`, from `/proc`.
#[cfg(target_os = "linux")]
fn children_of(pid: u32) -> Vec<u32> {
    let mut children = Vec::new();
    for entry in std::fs::read_dir("/proc").unwrap().flatten() {
        let Ok(child) = entry.file_name().to_string_lossy().parse::<u32>() else {
            continue;
        };
        let Ok(stat) = std::fs::read_to_string(entry.path().join("stat")) else {
            continue;
        };
        // `pid (comm) state ppid ...`: the command name may hold spaces, so read after ')'.
        let after = stat.rsplit_once(')').map_or("", |(_, rest)| rest);
        if after.split_whitespace().nth(1) == Some(pid.to_string().as_str()) {
            children.push(child);
        }
    }
    children
}

/// A batch killed with SIGKILL (which it cannot catch) takes its running job with it:
/// the job does not go on to write its output after the batch is gone.
#[cfg(target_os = "linux")]
#[test]
fn a_killed_batch_ends_its_running_jobs() {
    use std::time::{Duration, Instant};
    let dir = tempfile::tempdir().unwrap();
    let output = dir.path().join("slow.obj");
    // A remesh that would run for minutes (two million vertices).
    let (_jobs_dir, jobs) = jobs_file(&[format!(
        r#"{{"command": "remesh", "input": "meshes/disk_hemisphere.obj", "output": "{}", "options": {{"vertices": 2000000, "max-vertices": 3000000}}}}"#,
        s(&output)
    )]);
    let mut batch = std::process::Command::new(env!("CARGO_BIN_EXE_beltrami"))
        .args(["batch", s(&jobs)])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let start = Instant::now();
    let job = loop {
        if let Some(&job) = children_of(batch.id()).first() {
            break job;
        }
        assert!(
            start.elapsed() < Duration::from_secs(30),
            "the job never started"
        );
        std::thread::sleep(Duration::from_millis(20));
    };
    batch.kill().unwrap();
    batch.wait().unwrap();
    let killed = Instant::now();
    while Path::new(&format!("/proc/{job}")).exists() {
        // The job is reaped by init once it ends; a zombie entry is gone as soon as it is.
        let state = std::fs::read_to_string(format!("/proc/{job}/stat")).unwrap_or_default();
        if state
            .rsplit_once(')')
            .is_some_and(|(_, r)| r.trim_start().starts_with('Z'))
        {
            break;
        }
        assert!(
            killed.elapsed() < Duration::from_secs(10),
            "job {job} still runs 10 s after its batch was killed"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    assert!(
        !output.exists(),
        "the job wrote its output after the batch was killed"
    );
}
