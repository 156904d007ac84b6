//! `beltrami batch JOBS.jsonl`: many param, qc, register and remesh jobs, run in
//! parallel, one JSON report line per job.
//!
//! A job is one JSON object per line (blank lines and lines starting with `#` are
//! skipped):
//!
//! ```text
//! {"command": "param", "input": "a.obj", "output": "a_uv.obj", "options": {"solver": "lscm"}}
//! {"command": "register", "input": ["face_a.obj", "face_b.obj"], "output": "a_on_b.obj"}
//! {"command": "remesh", "input": "bunny.obj", "output": "bunny_2k.obj", "options": {"vertices": 2000}}
//! ```
//!
//! `input` is the command's positional argument or list of them, `output` its `-o`, and
//! each `options` entry a flag: `"name": value` is `--name value`, `true` is `--name`
//! alone, `false` omits it, and an array repeats the flag (`"pin": ["v0", "v9"]`). Paths
//! are taken as written, relative to the current directory. Every job runs as its own
//! `beltrami` process (in its own process group, so that a Ctrl-C of the batch does not
//! cut a job short), with `--json`: its JSON report becomes the `report` of the job's
//! line. Outputs are written atomically by the commands, so an output that exists is
//! complete: `--resume` skips those jobs. A failing job is reported with the command's
//! error message and never stops the others; the batch exits with an error when any job
//! failed.

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use anyhow::{Context as _, bail};
use clap::Args;
use serde_json::{Value, json};

/// Arguments of `beltrami batch`.
#[derive(Debug, Args)]
pub struct BatchArgs {
    /// The jobs: one JSON object per line (`command`, `input`, `output`, `options`).
    #[arg(value_name = "JOBS.jsonl")]
    pub file: PathBuf,
    /// Jobs run at once (default: the number of cores).
    #[arg(long, value_name = "N")]
    pub jobs: Option<usize>,
    /// Skip the jobs whose output exists already (outputs are written atomically, so an
    /// existing one is complete).
    #[arg(long)]
    pub resume: bool,
    /// Also write the report lines to this file (JSON Lines, in the jobs' order).
    #[arg(long, value_name = "R.jsonl")]
    pub report: Option<PathBuf>,
}

/// The commands a job may run.
const COMMANDS: &[&str] = &["param", "qc", "register", "remesh"];

/// One job of the file.
#[derive(Debug, Clone, PartialEq)]
pub struct Job {
    /// 1-based line of the jobs file.
    pub line: usize,
    /// `param`, `qc`, `register` or `remesh`.
    pub command: String,
    /// The output path (`-o`).
    pub output: PathBuf,
    /// The arguments after the command name.
    pub args: Vec<String>,
}

/// Parses one line of the jobs file (module docs), naming the line in errors.
pub fn parse_job(line: usize, text: &str) -> anyhow::Result<Job> {
    let value: Value =
        serde_json::from_str(text).with_context(|| format!("line {line}: not a JSON object"))?;
    let object = value
        .as_object()
        .with_context(|| format!("line {line}: not a JSON object"))?;
    let command = object
        .get("command")
        .and_then(Value::as_str)
        .with_context(|| {
            format!(
                "line {line}: no \"command\" (one of {})",
                COMMANDS.join(", ")
            )
        })?;
    if !COMMANDS.contains(&command) {
        bail!(
            "line {line}: the command \"{command}\" is not one of {}",
            COMMANDS.join(", ")
        );
    }
    let output = object
        .get("output")
        .and_then(Value::as_str)
        .with_context(|| format!("line {line}: no \"output\" path"))?;
    let dashed = |what: &str, text: &str| -> anyhow::Result<()> {
        if text.starts_with('-') {
            bail!(
                "line {line}: {what} \"{text}\" starts with `-`, which the command would read as a flag"
            );
        }
        Ok(())
    };
    dashed("the output", output)?;
    let inputs: Vec<String> = match object.get("input") {
        Some(Value::String(s)) => vec![s.clone()],
        Some(Value::Array(items)) => items
            .iter()
            .map(|v| {
                v.as_str()
                    .map(str::to_string)
                    .with_context(|| format!("line {line}: \"input\" holds a non-string {v}"))
            })
            .collect::<anyhow::Result<_>>()?,
        _ => bail!("line {line}: no \"input\" (a path or a list of paths)"),
    };
    for input in &inputs {
        dashed("the input", input)?;
    }
    for key in object.keys() {
        if !["command", "input", "output", "options"].contains(&key.as_str()) {
            bail!("line {line}: unknown key \"{key}\" (command, input, output, options)");
        }
    }
    let mut args = vec![command.to_string()];
    args.extend(inputs);
    args.extend(["-o".to_string(), output.to_string()]);
    if let Some(options) = object.get("options") {
        let options = options
            .as_object()
            .with_context(|| format!("line {line}: \"options\" is not an object"))?;
        for (name, value) in options {
            if matches!(name.as_str(), "help" | "version" | "output" | "o") || name.starts_with('-')
            {
                bail!(
                    "line {line}: \"{name}\" is not a job option (the output is the job's \"output\"; help and version are not jobs)"
                );
            }
            let flag = format!("--{name}");
            let items = match value {
                Value::Array(items) => items.clone(),
                other => vec![other.clone()],
            };
            for item in items {
                match item {
                    Value::Bool(true) => args.push(flag.clone()),
                    Value::Bool(false) => {}
                    Value::String(s) if s.starts_with("--") => bail!(
                        "line {line}: option \"{name}\" has the value \"{s}\", which the command would read as a flag"
                    ),
                    Value::String(s) => args.extend([flag.clone(), s]),
                    Value::Number(n) => args.extend([flag.clone(), n.to_string()]),
                    other => bail!("line {line}: option \"{name}\" has the value {other}"),
                }
            }
        }
    }
    Ok(Job {
        line,
        command: command.to_string(),
        output: PathBuf::from(output),
        args,
    })
}

/// Fails, before any job runs, when two jobs write the same file, or a job writes the
/// jobs file or the `--report` file, or the report would overwrite the jobs file: each
/// would destroy another's result (and `--resume` would then skip a job whose output
/// belongs to another). Paths are compared after making them absolute and resolving
/// `.` and `..` (and the folders' links, where the folder exists).
fn check_collisions(file: &Path, report: Option<&Path>, jobs: &[Job]) -> anyhow::Result<()> {
    let key = |path: &Path| -> PathBuf {
        let absolute = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
        match (absolute.parent(), absolute.file_name()) {
            (Some(folder), Some(name)) => folder
                .canonicalize()
                .map_or_else(|_| absolute.clone(), |f| f.join(name)),
            _ => absolute,
        }
    };
    let mut seen: std::collections::HashMap<PathBuf, String> = std::collections::HashMap::new();
    seen.insert(key(file), "the jobs file".to_string());
    if let Some(report) = report
        && let Some(other) = seen.insert(key(report), "the --report file".to_string())
    {
        bail!("--report {} is {other}", report.display());
    }
    for job in jobs {
        let name = format!("the output of the job on line {}", job.line);
        if let Some(other) = seen.insert(key(&job.output), name) {
            bail!(
                "line {}: the output {} is also {other}: every job needs its own output",
                job.line,
                job.output.display()
            );
        }
    }
    Ok(())
}

/// Runs `job` as a child `beltrami` process; its report line.
fn run_job(exe: &Path, job: &Job, resume: bool) -> Value {
    if resume && job.output.exists() {
        return json!({
            "line": job.line, "command": job.command, "output": job.output,
            "status": "skipped", "message": "the output exists (--resume)",
        });
    }
    let start = Instant::now();
    let mut command = Command::new(exe);
    command.arg("--quiet").args(&job.args).arg("--json");
    #[cfg(unix)]
    {
        use std::os::unix::process::CommandExt as _;
        command.process_group(0);
    }
    #[cfg(target_os = "linux")]
    end_with_the_batch(&mut command);
    let outcome = command.output();
    let seconds = start.elapsed().as_secs_f64();
    match outcome {
        Ok(out) if out.status.success() => {
            let report: Value = serde_json::from_slice(&out.stdout).unwrap_or(Value::Null);
            json!({
                "line": job.line, "command": job.command, "output": job.output,
                "status": "ok", "seconds": seconds, "report": report,
            })
        }
        Ok(out) => {
            let stderr = String::from_utf8_lossy(&out.stderr);
            let message = error_message(&stderr).unwrap_or_else(|| match out.status.code() {
                Some(code) => format!("exit code {code}"),
                None => "killed by a signal".to_string(),
            });
            json!({
                "line": job.line, "command": job.command, "output": job.output,
                "status": "error", "seconds": seconds, "message": message,
            })
        }
        Err(error) => json!({
            "line": job.line, "command": job.command, "output": job.output,
            "status": "error", "seconds": seconds,
            "message": format!("cannot start {}: {error}", exe.display()),
        }),
    }
}

/// Makes the job end when the batch does, however it ends (KILL included, which the
/// batch cannot catch): the kernel sends the job SIGTERM when the thread that started it
/// exits (`PR_SET_PDEATHSIG`). The worker thread waits for its job, so it outlives it
/// unless the whole batch dies. A batch that died between starting the job and the call
/// leaves the job an orphan, so the job checks that its parent is still the batch.
#[cfg(target_os = "linux")]
fn end_with_the_batch(command: &mut Command) {
    use std::os::unix::process::CommandExt as _;
    let batch = libc::pid_t::try_from(std::process::id()).unwrap_or(libc::pid_t::MAX);
    // SAFETY: the closure runs between fork and exec and makes only async-signal-safe
    // system calls (prctl, getppid); its errors are raw codes, nothing is allocated.
    unsafe {
        command.pre_exec(move || {
            if libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGTERM) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            if libc::getppid() != batch {
                // No allocation between fork and exec: a raw error code (no such process).
                return Err(std::io::Error::from_raw_os_error(libc::ESRCH));
            }
            Ok(())
        });
    }
}

/// The error a command printed: from its first `error:` line to the next blank line
/// (clap's usage errors continue on indented lines), joined into one line.
fn error_message(stderr: &str) -> Option<String> {
    let mut lines = stderr.lines().skip_while(|l| !l.starts_with("error: "));
    let first = lines.next()?.trim_start_matches("error: ").to_string();
    let rest: Vec<&str> = lines
        .take_while(|l| !l.trim().is_empty())
        .map(str::trim)
        .collect();
    Some(if rest.is_empty() {
        first
    } else {
        format!("{first} {}", rest.join(" "))
    })
}

pub fn run(args: &BatchArgs, quiet: bool) -> anyhow::Result<()> {
    let text = std::fs::read_to_string(&args.file)
        .with_context(|| format!("cannot read the jobs file {}", args.file.display()))?;
    // Editors on Windows start UTF-8 files with a byte-order mark.
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    // A malformed line is a mistake in the file, found before any job runs.
    let jobs: Vec<Job> = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'))
        .map(|(i, l)| parse_job(i + 1, l))
        .collect::<anyhow::Result<_>>()
        .with_context(|| format!("in {}", args.file.display()))?;
    if let Some(path) = &args.report {
        super::outputs::check(&[("--report", Some(path.as_path()))])?;
    }
    check_collisions(&args.file, args.report.as_deref(), &jobs)?;
    let workers = args
        .jobs
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    if workers == 0 {
        bail!("--jobs must be at least 1");
    }
    let exe = std::env::current_exe().context("cannot find the beltrami executable")?;
    let next = AtomicUsize::new(0);
    let lines: Mutex<Vec<Option<Value>>> = Mutex::new(vec![None; jobs.len()]);
    let stdout = Mutex::new(std::io::stdout());
    std::thread::scope(|scope| {
        for _ in 0..workers.min(jobs.len().max(1)) {
            scope.spawn(|| {
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    let Some(job) = jobs.get(i) else { break };
                    let line = run_job(&exe, job, args.resume);
                    if let Ok(mut out) = stdout.lock() {
                        let _ = writeln!(out, "{line}");
                        let _ = out.flush();
                    }
                    if let Ok(mut lines) = lines.lock() {
                        lines[i] = Some(line);
                    }
                }
            });
        }
    });
    let lines: Vec<Value> = lines
        .into_inner()
        .unwrap_or_default()
        .into_iter()
        .flatten()
        .collect();
    if let Some(path) = &args.report {
        beltrami::mesh::io::write_atomically(path, |w| {
            for line in &lines {
                writeln!(w, "{line}")?;
            }
            Ok(())
        })
        .with_context(|| format!("cannot write --report {}", path.display()))?;
    }
    let failed = lines.iter().filter(|l| l["status"] == "error").count();
    let skipped = lines.iter().filter(|l| l["status"] == "skipped").count();
    if !quiet {
        eprintln!(
            "{} jobs: {} done, {} skipped, {} failed",
            lines.len(),
            lines.len() - failed - skipped,
            skipped,
            failed
        );
    }
    if failed > 0 {
        bail!(
            "{failed} of {} jobs failed (see their report lines)",
            lines.len()
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_job_line_becomes_the_command_line() {
        let job = parse_job(
            3,
            r#"{"command": "param", "input": "a.obj", "output": "b.obj", "options": {"solver": "tutte", "pin": ["v0", "v4"], "json": false, "repair": true, "tolerance": 1e-6}}"#,
        )
        .unwrap();
        assert_eq!(job.line, 3);
        assert_eq!(job.output, PathBuf::from("b.obj"));
        assert_eq!(
            job.args,
            [
                "param",
                "a.obj",
                "-o",
                "b.obj",
                "--pin",
                "v0",
                "--pin",
                "v4",
                "--repair",
                "--solver",
                "tutte",
                "--tolerance",
                "1e-6"
            ]
        );
        let two = parse_job(
            1,
            r#"{"command": "register", "input": ["s.obj", "t.obj"], "output": "o.obj"}"#,
        )
        .unwrap();
        assert_eq!(two.args, ["register", "s.obj", "t.obj", "-o", "o.obj"]);
    }

    #[test]
    fn the_error_message_is_the_commands_error() {
        let clap = "error: the following required arguments were not provided:\n  --solver <SOLVER>\n\nUsage: beltrami param --solver <SOLVER> <MESH>\n\nFor more information, try '--help'.\n";
        assert_eq!(
            error_message(clap).unwrap(),
            "the following required arguments were not provided: --solver <SOLVER>"
        );
        assert_eq!(
            error_message("note: x\nerror: cannot read a.obj: no such file\n").unwrap(),
            "cannot read a.obj: no such file"
        );
        assert_eq!(error_message("thread main panicked\n"), None);
    }

    #[test]
    fn bad_lines_are_named() {
        for (text, expected) in [
            ("[1, 2]", "line 7: not a JSON object"),
            (
                "{\"command\": \"render\", \"input\": \"a\", \"output\": \"b\"}",
                "\"render\" is not one of",
            ),
            ("{\"command\": \"qc\", \"input\": \"a\"}", "no \"output\""),
            ("{\"command\": \"qc\", \"output\": \"b\"}", "no \"input\""),
            (
                "{\"command\": \"qc\", \"input\": \"a\", \"output\": \"b\", \"extra\": 1}",
                "unknown key \"extra\"",
            ),
            (
                "{\"command\": \"qc\", \"input\": \"a\", \"output\": \"b\", \"options\": {\"mu\": null}}",
                "option \"mu\"",
            ),
        ] {
            let error = format!("{:#}", parse_job(7, text).unwrap_err());
            assert!(error.contains(expected), "{text}: {error}");
        }
    }
}
