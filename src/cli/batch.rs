//! `beltrami batch JOBS.jsonl`: many param, qc, register and remesh jobs, run in
//! parallel, one JSON report line per job.
//!
//! A job is one JSON object per line (`command`, `input`, `output`, `options`), read by
//! [`beltrami::batch_job`], which says how each becomes a command line. Paths
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
use beltrami::batch_job::{Job, parse_jobs};
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
    // A malformed line is a mistake in the file, found before any job runs.
    let jobs = parse_jobs(&text).with_context(|| format!("in {}", args.file.display()))?;
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
}
