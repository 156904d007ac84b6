//! Bad input of the hardening campaign, end to end: the regression corpus of crashing
//! and misleading inputs (`tests/corpus/TARGET/`) through the fuzz targets, and the CLI
//! cases (options, outputs, signals). Every case ends in a clear error; none panics,
//! overflows the stack, runs out of memory or leaves a partial output.

mod common;
#[path = "../examples/fuzz/targets.rs"]
mod targets;

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};

use common::{beltrami, s, text};

/// The names of the files in `dir`.
fn entries(dir: &Path) -> Vec<std::ffi::OsString> {
    std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name())
        .collect()
}

fn corpus(target: &str) -> Vec<PathBuf> {
    let folder = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/corpus")
        .join(target);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&folder)
        .map(|entries| entries.flatten().map(|e| e.path()).collect())
        .unwrap_or_default();
    files.sort();
    files
}

/// The result of target `target` on the corpus file `name`, which must not panic.
fn run_corpus_file(target: &str, name: &str) -> Result<(), String> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/corpus")
        .join(target)
        .join(name);
    let data = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    catch_unwind(AssertUnwindSafe(|| targets::run(target, &data)))
        .unwrap_or_else(|_| panic!("{target} panicked on {}", path.display()))
}

#[test]
fn no_corpus_input_panics_in_any_target() {
    let mut files = 0;
    for target in targets::TARGETS {
        for path in corpus(target) {
            let data = std::fs::read(&path).expect("corpus file");
            let outcome = catch_unwind(AssertUnwindSafe(|| targets::run(target, &data)));
            assert!(outcome.is_ok(), "{target} panicked on {}", path.display());
            files += 1;
        }
    }
    assert!(files >= 15, "the corpus has {files} files");
    // The targets accept valid input (a target refusing everything would find nothing).
    targets::run("correspondence", targets::correspondence_seed().as_bytes())
        .expect("a valid correspondence file is accepted");
}

#[test]
fn a_jobs_line_cannot_end_the_flags_or_set_the_output_through_an_option_name() {
    for (name, expected) in [
        (
            "empty-option-name-ends-the-flags.jsonl",
            "line 1: \"\" is not a job option",
        ),
        (
            "output-set-through-an-option-name.jsonl",
            "line 1: \"output=c.obj\" is not a job option",
        ),
    ] {
        let error = run_corpus_file("jobs", name).unwrap_err();
        assert!(error.contains(expected), "{name}: {error}");
    }
}

#[test]
fn a_long_flat_sum_is_not_deep() {
    // 1,000 terms: a chain is one level, however long.
    let sum = vec!["0.0001*z"; 1000].join("+");
    targets::run("expr", sum.as_bytes()).expect("a flat sum of 1000 terms is accepted");
}

#[test]
fn deep_expressions_are_refused_by_depth_not_by_stack_overflow() {
    for name in [
        "nested-parentheses-10000.txt",
        "leading-minus-30000.txt",
        "chained-power-20000.txt",
    ] {
        let e = run_corpus_file("expr", name).unwrap_err();
        assert!(e.contains("nests more than 64 levels deep"), "{name}: {e}");
    }
}

#[test]
fn coordinates_that_overflow_or_underflow_say_so() {
    for (name, words) in [
        ("coordinate-1e308.obj", ["vertex 1", "overflows"]),
        ("coordinate-1e200.obj", ["vertex 1", "overflows"]),
        ("coordinate-1e-308.obj", ["diagonal", "underflows"]),
    ] {
        let e = run_corpus_file("obj", name).unwrap_err();
        assert!(!e.contains("degenerate"), "{name}: {e}");
        for w in words {
            assert!(e.contains(w), "{name}: {e}");
        }
    }
}

#[test]
fn face_indices_are_quoted_as_written_in_the_file() {
    for (name, quoted) in [
        ("face-index-zero.obj", "`0`"),
        ("face-index-minus-9.obj", "`-9`"),
    ] {
        let e = run_corpus_file("obj", name).unwrap_err();
        assert!(e.contains(quoted) && e.contains(":5:"), "{name}: {e}");
    }
}

#[test]
fn the_cut_reproducer_is_refused_by_the_builder_and_its_scaled_copy_cuts() {
    let e = run_corpus_file("cut", "coordinates-1e300-tolerance-0-repair-all.obj").unwrap_err();
    assert!(e.contains("overflows"), "{e}");
    let e = run_corpus_file("build", "coordinates-1e300-tolerance-0-repair-all.bin").unwrap_err();
    assert!(e.contains("overflows"), "{e}");
    // Scaled into range, its quad folds (its far corner crosses the opposite side): the
    // builder names it. With that corner at (1, 1, 0) the quad is convex, and the same
    // disk (a quad and a triangle sharing an edge), under the same build options, cuts.
    let e = run_corpus_file("cut", "scaled-into-range-tolerance-0-repair-all.obj").unwrap_err();
    assert!(
        e.contains("face 0 is a quad that folds at its vertex 3"),
        "{e}"
    );
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/corpus/cut/scaled-into-range-tolerance-0-repair-all.obj");
    let convex = std::fs::read_to_string(path).unwrap().replace("1e75", "1");
    targets::run("cut", convex.as_bytes()).expect("the mesh with a convex quad cuts");
    // A torus cuts under every build option.
    let torus = targets::torus_obj();
    for byte in 0..32u8 {
        let mut data = vec![byte];
        data.extend_from_slice(torus.as_bytes());
        targets::run("cut", &data).expect("the torus cuts");
    }
}

#[test]
fn gltf_buffers_on_devices_or_longer_than_their_file_are_refused() {
    if Path::new("/dev/zero").exists() {
        let e = run_corpus_file("gltf", "buffer-uri-dev-zero.gltf").unwrap_err();
        assert!(
            e.contains("/dev/zero") && e.contains("not a regular file"),
            "{e}"
        );
    }
    // The corpus file names `huge.bin` beside it, which does not exist: copy it next to
    // a 36-byte file to see the declared length refused before any read.
    let dir = tempfile::tempdir().unwrap();
    let gltf = dir.path().join("huge.gltf");
    std::fs::copy(corpus_path("gltf", "buffer-huge-byte-length.gltf"), &gltf).unwrap();
    std::fs::write(dir.path().join("huge.bin"), [0u8; 36]).unwrap();
    let out = beltrami(&["info", s(&gltf)]);
    assert!(!out.status.success());
    let err = text(&out.stderr);
    assert!(err.contains("buffer 0 has 36 bytes"), "{err}");
}

fn corpus_path(target: &str, name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/corpus")
        .join(target)
        .join(name)
}

/// The unit square as two triangles, written into `dir`.
fn square(dir: &Path) -> PathBuf {
    let path = dir.join("square.obj");
    std::fs::write(
        &path,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n",
    )
    .unwrap();
    path
}

fn sphere(dir: &Path) -> PathBuf {
    let path = dir.join("sphere.obj");
    let out = beltrami(&["-q", "generate", "sphere", "--level", "1", "-o", s(&path)]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    path
}

fn fails_with(args: &[&str], words: &[&str]) {
    let out = beltrami(args);
    assert!(!out.status.success(), "{args:?} succeeded");
    let err = text(&out.stderr);
    for w in words {
        assert!(err.contains(w), "{args:?}: {err}");
    }
}

#[test]
fn a_nan_pin_is_refused_instead_of_becoming_vertex_0() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = square(dir.path());
    let out = dir.path().join("out.obj");
    for pin in ["nan,nan", "0,inf", "1,2,nan"] {
        fails_with(
            &[
                "param",
                s(&mesh),
                "--solver",
                "tutte",
                "--pin",
                pin,
                "-o",
                s(&out),
            ],
            &["finite"],
        );
    }
    assert!(!out.exists());
}

#[test]
fn numeric_options_out_of_range_and_ignored_options_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = square(dir.path());
    let ball = sphere(dir.path());
    let out = dir.path().join("out.obj");
    for tolerance in ["nan", "-1"] {
        fails_with(
            &[
                "register",
                s(&ball),
                s(&ball),
                &format!("--tolerance={tolerance}"),
                "-o",
                s(&out),
            ],
            &["tolerance", "must lie in"],
        );
        fails_with(
            &[
                "qc",
                s(&mesh),
                "--conformal",
                "--solver",
                "beltrami-flow",
                &format!("--tolerance={tolerance}"),
                "-o",
                s(&out),
            ],
            &["tolerance", "must lie in"],
        );
    }
    fails_with(
        &[
            "param",
            s(&ball),
            "--solver",
            "sphere",
            "--boundary",
            "square",
            "-o",
            s(&out),
        ],
        &["sphere"],
    );
    // Flags that the other flags make meaningless are refused, not ignored.
    for (args, words) in [
        (vec!["--free-radius"], ["--free-radius", "annulus"]),
        (
            vec!["--boundary-map", s(&mesh)],
            ["--boundary-map", "given"],
        ),
        (
            vec![
                "--solver",
                "beltrami-flow",
                "--target",
                "disk",
                "--boundary",
                "keep",
            ],
            ["--boundary", "disk"],
        ),
    ] {
        let mut all = vec!["qc", s(&mesh), "--conformal", "-o", s(&out)];
        all.extend(args);
        fails_with(&all, &words);
    }
    let field = dir.path().join("zero.mu");
    std::fs::write(&field, "# mu frame=face faces=32\n").unwrap();
    fails_with(
        &[
            "register",
            s(&ball),
            s(&ball),
            "--mu",
            s(&field),
            "--p",
            "3",
            "-o",
            s(&out),
        ],
        &["--p", "--mu"],
    );
    assert!(!out.exists());
}

#[test]
fn an_output_that_cannot_be_written_stops_the_run_before_any_output() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = square(dir.path());
    let ball = sphere(dir.path());
    let out = dir.path().join("out.obj");
    let missing = dir.path().join("missing");
    let report = missing.join("report.json");
    fails_with(
        &[
            "param",
            s(&mesh),
            "--solver",
            "tutte",
            "--report",
            s(&report),
            "-o",
            s(&out),
        ],
        &["--report", "does not exist"],
    );
    assert!(
        !out.exists(),
        "the mesh was written before the report failed"
    );
    let corr = missing.join("corr.txt");
    fails_with(
        &[
            "register",
            s(&ball),
            s(&ball),
            "--correspondence",
            s(&corr),
            "-o",
            s(&out),
        ],
        &["--correspondence", "does not exist"],
    );
    assert!(!out.exists());
    // The same file twice, and a folder as the output.
    fails_with(
        &[
            "param",
            s(&mesh),
            "--solver",
            "tutte",
            "--report",
            s(&out),
            "-o",
            s(&out),
        ],
        &["both name"],
    );
    let folder = dir.path().join("folder.obj");
    std::fs::create_dir(&folder).unwrap();
    fails_with(
        &["param", s(&mesh), "--solver", "tutte", "-o", s(&folder)],
        &["is a folder"],
    );
    assert!(!out.exists());
}

#[test]
fn a_nan_texture_coordinate_is_not_blamed_on_seams() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = square(dir.path());
    let mapped = corpus_path("obj", "nan-texture-coordinate.obj");
    let out = beltrami(&["distortion", s(&mesh), s(&mapped)]);
    assert!(!out.status.success());
    let err = text(&out.stderr);
    assert!(!err.contains("seam") && err.contains("not finite"), "{err}");
}

#[test]
fn a_deep_mu_expression_on_the_command_line_is_a_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = square(dir.path());
    let out = dir.path().join("out.obj");
    let expr = format!("--mu-expr={}z{}", "(".repeat(10_000), ")".repeat(10_000));
    let result = beltrami(&["qc", s(&mesh), &expr, "-o", s(&out)]);
    assert_eq!(result.status.code(), Some(1), "killed by a signal?");
    assert!(text(&result.stderr).contains("nests more than"));
}

#[cfg(unix)]
#[test]
fn a_file_size_limit_ends_in_an_error_and_leaves_no_temporary_file() {
    use std::process::Command;
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("big.obj");
    // `ulimit -f 8`: 8 KiB; a level-4 sphere is far larger as OBJ.
    let status = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -f 8 && exec \"$0\" -q generate sphere --level 4 -o '{}'",
            out.display()
        ))
        .arg(env!("CARGO_BIN_EXE_beltrami"))
        .output()
        .expect("sh runs");
    assert_eq!(
        status.status.code(),
        Some(1),
        "expected an error exit, not SIGXFSZ: {}",
        text(&status.stderr)
    );
    assert!(!out.exists());
    let left = entries(dir.path());
    assert!(left.is_empty(), "left behind: {left:?}");
}

#[test]
fn a_disk_far_from_the_origin_is_refused_before_any_work() {
    // The unit disk translated by 1e15: coordinates 0.125 apart there. `remesh` hung on
    // it, and `--method qc-angles` ended with 131 of 256 faces flipped and a face of
    // zero area (exit 0), or with a matrix of non-finite entries.
    let dir = tempfile::tempdir().unwrap();
    let disk = dir.path().join("disk.obj");
    let out = beltrami(&["-q", "generate", "disk", "--level", "3", "-o", s(&disk)]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let far = dir.path().join("far.obj");
    let moved: String = std::fs::read_to_string(&disk)
        .unwrap()
        .lines()
        .map(|line| match line.strip_prefix("v ") {
            Some(rest) => {
                let c: Vec<f64> = rest
                    .split_whitespace()
                    .map(|x| x.parse().unwrap())
                    .collect();
                format!("v {:.17e} {} {}\n", c[0] + 1e15, c[1], c[2])
            }
            None => format!("{line}\n"),
        })
        .collect();
    std::fs::write(&far, moved).unwrap();
    let output = dir.path().join("out.obj");
    for extra in [&["--vertices", "500"][..], &["--method", "qc-angles"][..]] {
        let mut args = vec!["remesh", s(&far), "-o", s(&output)];
        args.extend_from_slice(extra);
        fails_with(
            &args,
            &["from the origin", "translate the mesh near the origin"],
        );
        assert!(!output.exists());
    }
}

#[test]
fn a_generated_mesh_too_large_is_refused_from_its_level() {
    // `generate circle-domain --level 10` ran for minutes (1.2e8 faces), `square --level
    // 10` asked for 2.1e9; the face count is known from the level before any work.
    let dir = tempfile::tempdir().unwrap();
    let output = dir.path().join("out.obj");
    for (shape, level, faces, finest) in [
        ("circle-domain", "10", "1.217e8", "--level 9"),
        ("square", "10", "2.147e9", "--level 7"),
        ("disk", "40", "4.836e24", "--level 11"),
        ("sphere", "18446744073709551615", "inf", "--level 11"),
    ] {
        fails_with(
            &["generate", shape, "--level", level, "-o", s(&output)],
            &[
                &format!("about {faces} faces"),
                &format!("at most {finest} for this shape"),
            ],
        );
        assert!(!output.exists());
    }
}

#[cfg(target_os = "linux")]
#[test]
fn a_process_ended_while_writing_leaves_no_temporary_file() {
    use std::time::{Duration, Instant};
    // SIGTERM (what a batch job gets when its batch dies) in the middle of writing a
    // 44-MB mesh: the process removes the temporary file it is writing and exits with
    // 128 + 15; the destination is never created. Before, the temporary file stayed
    // until the next write into the folder.
    //
    // The write is found among the process's open files, not in the folder: where the
    // file system has unnamed files (O_TMPFILE) the content gets a name only once it is
    // complete, two system calls before the rename, and a signal sent in that window
    // finds a finished output (which is what the writer promises). The signal is sent
    // while less than half the content is written.
    let dir = tempfile::tempdir().unwrap();
    let output = dir.path().join("d9.obj");
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_beltrami"))
        .args(["generate", "disk", "--level", "9", "-o", s(&output), "-q"])
        .spawn()
        .unwrap();
    let fds = PathBuf::from(format!("/proc/{}/fd", child.id()));
    let folder = dir.path().canonicalize().unwrap();
    // The bytes of the temporary file being filled, if one is open.
    let filled = || -> Option<u64> {
        std::fs::read_dir(&fds).ok()?.flatten().find_map(|fd| {
            let target = std::fs::read_link(fd.path()).ok()?;
            let temporary = target.parent() == Some(folder.as_path())
                && target.file_name() != output.file_name();
            temporary.then(|| std::fs::metadata(fd.path()).map_or(0, |m| m.len()))
        })
    };
    const HALF: u64 = 20_000_000;
    let start = Instant::now();
    loop {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "the temporary file never appeared"
        );
        if child.try_wait().unwrap().is_some() {
            // The write ended between two looks (a fast disk): nothing to interrupt.
            println!("the write ended before it could be interrupted: not checked");
            return;
        }
        match filled() {
            Some(bytes) if bytes > 0 && bytes < HALF => break,
            Some(bytes) if bytes >= HALF => {
                println!("the write was past half when first seen: not checked");
                child.wait().unwrap();
                return;
            }
            _ => std::thread::sleep(Duration::from_millis(1)),
        }
    }
    let pid = libc::pid_t::try_from(child.id()).unwrap();
    // SAFETY: signals the child process started above.
    assert_eq!(unsafe { libc::kill(pid, libc::SIGTERM) }, 0);
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(143), "{status:?}");
    let left = entries(dir.path());
    assert!(left.is_empty(), "left behind: {left:?}");
}
