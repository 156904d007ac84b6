//! What every mapping command shares: the output-format check, pins, the solve with a
//! late progress bar, the picture, the JSON report and the summary.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::{Context as _, bail};
use beltrami::map_file::{self, Image};
use beltrami::report;
use beltrami_core::{Context, Pin, Problem, Progress, Solution, Solver, Target};
use beltrami_fem::ReferenceNormal;
use beltrami_mesh::Mesh;
use beltrami_mesh::io::obj::MeshSections;
use beltrami_mesh::io::{self, Format};
use beltrami_render::{Layout, Scene, Style, check_png_path};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use serde_json::{Map as JsonMap, Value, json};

use super::pins::PinSpec;

/// The options every mapping command has besides its output mesh.
#[derive(Debug, clap::Args)]
pub struct CommonArgs {
    /// Also draw the result (source and image side by side, |mu| colors) as PNG.
    #[arg(long, value_parser = png_path)]
    pub png: Option<PathBuf>,
    /// Write the JSON report here.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Print the JSON report on stdout instead of the summary.
    #[arg(long)]
    pub json: bool,
    /// Repair what can be repaired safely in the input meshes (see `beltrami info
    /// --repair`).
    #[arg(long)]
    pub repair: bool,
    /// Print one progress line per solver step on stderr instead of the progress bar
    /// (for logs and pipes, where the bar does not show).
    #[arg(long = "progress-lines")]
    pub progress_lines: bool,
    /// Set a solver option, `NAME=VALUE` (repeatable; `beltrami solvers` lists each
    /// solver's options with types, defaults and ranges).
    #[arg(short = 'O', long = "option", value_name = "NAME=VALUE", value_parser = option_pair)]
    pub options: Vec<(String, String)>,
}

/// Parses `NAME=VALUE` of `--option`.
fn option_pair(text: &str) -> Result<(String, String), String> {
    match text.split_once('=') {
        Some((name, value)) if !name.trim().is_empty() => {
            Ok((name.trim().to_string(), value.trim().to_string()))
        }
        _ => Err(format!("expected NAME=VALUE, got `{text}`")),
    }
}

/// How a solve reports progress.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProgressStyleArg {
    /// Nothing.
    Quiet,
    /// A bar on stderr, once a run has lasted a second.
    Bar,
    /// One line per step on stderr.
    Lines,
}

impl CommonArgs {
    /// The progress style for these options (`quiet`: the global `-q`).
    pub fn progress(&self, quiet: bool) -> ProgressStyleArg {
        if self.progress_lines {
            ProgressStyleArg::Lines
        } else if quiet || self.json {
            ProgressStyleArg::Quiet
        } else {
            ProgressStyleArg::Bar
        }
    }
}

/// Fails, before any work, when `output` is not a mesh format beltrami writes.
pub fn check_output_format(output: &Path) -> anyhow::Result<()> {
    if Format::from_path(output).is_none() {
        bail!(
            "{}: unknown output format (expected {})",
            output.display(),
            Format::EXTENSIONS
        );
    }
    Ok(())
}

/// Fails, before the solve, when a map onto `target` is planar (written as texture
/// coordinates) and `output`'s format holds none (STL).
pub fn check_output_holds_map(output: &Path, target: &Target<'_>) -> anyhow::Result<()> {
    match Format::from_path(output) {
        Some(format) if target.is_planar() && !format.holds_uvs() => {
            Err(anyhow::Error::new(io::WriteError::Unsupported {
                path: output.to_path_buf(),
                format,
                what: "texture coordinates",
            }))
        }
        _ => Ok(()),
    }
}

/// Fails, before any work, when `output` is not a mesh format beltrami writes or when
/// any output of the command cannot be written ([`super::outputs::check`]): `output`
/// (`-o`), `--png` and `--report` of `common`, and the command's `extra` outputs given as
/// `(flag, path)`.
pub fn check_outputs(
    output: &Path,
    common: &CommonArgs,
    extra: &[(&str, Option<&Path>)],
) -> anyhow::Result<()> {
    check_output_format(output)?;
    let mut paths = vec![
        ("-o", Some(output)),
        ("--png", common.png.as_deref()),
        ("--report", common.report.as_deref()),
    ];
    paths.extend_from_slice(extra);
    super::outputs::check(&paths)
}

/// The pins of `--pin` flags, without positions (the solver places them).
pub fn resolve_pins(specs: &[PinSpec], mesh: &Mesh) -> anyhow::Result<Vec<Pin>> {
    specs
        .iter()
        .map(|spec| {
            Ok(Pin {
                vertex: spec.resolve(mesh)?,
                position: None,
            })
        })
        .collect()
}

/// `, at most ~T left` for a stage with a known step count, from the time its steps so far
/// took (`elapsed`). "At most": iterative solvers count up to their iteration limit and
/// usually stop before it.
fn time_left(p: &Progress, elapsed: Duration) -> Option<String> {
    let total = p.total?;
    if p.done == 0 || p.done >= total || elapsed < Duration::from_secs(1) {
        return None;
    }
    let left = elapsed.as_secs_f64() * (total - p.done) as f64 / p.done as f64;
    Some(if left < 90.0 {
        format!(", at most ~{left:.0} s left")
    } else {
        format!(", at most ~{:.0} min left", left / 60.0)
    })
}

/// `stage done/total energy E` of a progress report.
fn progress_line(p: &Progress) -> String {
    let mut line = p.stage.to_string();
    if let Some(total) = p.total {
        line.push_str(&format!(" {}/{total}", p.done));
    }
    if let Some(e) = p.energy {
        line.push_str(&format!(" energy {e:.3e}"));
    }
    line
}

/// A progress bar that appears only once a run has lasted a second.
pub(super) struct LateBar {
    bar: ProgressBar,
    start: Instant,
    shown: bool,
    enabled: bool,
    /// The current stage and when it began, for the time left.
    stage: Option<(&'static str, Instant)>,
}

impl LateBar {
    pub(super) fn new(enabled: bool) -> Self {
        let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::hidden());
        bar.set_style(
            ProgressStyle::with_template("{spinner} {msg} [{elapsed}]")
                .unwrap_or_else(|_| ProgressStyle::default_spinner()),
        );
        Self {
            bar,
            start: Instant::now(),
            shown: false,
            enabled,
            stage: None,
        }
    }

    pub(super) fn update(&mut self, p: &Progress) {
        if !self.enabled {
            return;
        }
        if !self.shown && self.start.elapsed() > Duration::from_secs(1) {
            self.bar.set_draw_target(ProgressDrawTarget::stderr());
            self.bar.enable_steady_tick(Duration::from_millis(120));
            self.shown = true;
        }
        let since = match self.stage {
            Some((stage, since)) if stage == p.stage => since,
            _ => {
                let now = Instant::now();
                self.stage = Some((p.stage, now));
                now
            }
        };
        let mut line = progress_line(p);
        if let Some(left) = time_left(p, since.elapsed()) {
            line.push_str(&left);
        }
        self.bar.set_message(line);
    }

    pub(super) fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

/// Checks and solves `problem`, with a progress bar on stderr for runs over a second
/// when `show_progress`, Ctrl-C asking the solver to stop ([`super::interrupt`]);
/// returns the solution and the wall-clock seconds of the solve.
pub fn solve(
    solver: &dyn Solver,
    problem: &Problem<'_>,
    progress: ProgressStyleArg,
) -> anyhow::Result<(Solution, f64)> {
    let settings = solver.check(problem)?;
    run_with_progress(progress, |context| solver.run(problem, &settings, context))
}

/// Runs `run` with a context that shows progress as asked and stops on Ctrl-C; returns
/// its solution and the seconds it took.
pub fn run_with_progress(
    progress: ProgressStyleArg,
    run: impl FnOnce(&mut Context<'_>) -> Result<Solution, beltrami_core::SolverError>,
) -> anyhow::Result<(Solution, f64)> {
    let mut bar = LateBar::new(progress == ProgressStyleArg::Bar);
    let start = Instant::now();
    let solution = {
        let mut context = Context::new()
            .with_progress(|p: &Progress| {
                if progress == ProgressStyleArg::Lines {
                    eprintln!("{}", progress_line(p));
                } else {
                    bar.update(p);
                }
            })
            .with_cancel_flag(super::interrupt::cancel_flag());
        run(&mut context)
    };
    bar.finish();
    Ok((solution?, start.elapsed().as_secs_f64()))
}

/// [`solve`], formatting meanwhile the parts of an OBJ output that do not depend on the
/// map (its `v` and `f` lines, [`MeshSections`]) on a background thread of the lowest
/// priority, so that they take only the time the solver leaves a core idle (most
/// solvers factor and step on one core). The `f` lines name texture coordinates when the
/// target is planar ([`beltrami_core::Target::is_planar`]: the map is written as `vt`
/// lines); were the map of another kind, only the early formatting would be lost.
/// Nothing is formatted ahead for other output formats.
pub fn solve_formatting_output(
    solver: &dyn Solver,
    problem: &Problem<'_>,
    progress: ProgressStyleArg,
    output: &Path,
) -> anyhow::Result<(Solution, f64, Option<MeshSections>)> {
    let with_uvs = problem.target.is_planar();
    if Format::from_path(output) != Some(Format::Obj) {
        return solve(solver, problem, progress)
            .map(|(solution, seconds)| (solution, seconds, None));
    }
    let mesh = problem.source;
    std::thread::scope(|scope| {
        let sections = scope.spawn(move || {
            lower_this_threads_priority();
            MeshSections::format(mesh, with_uvs)
        });
        let solved = solve(solver, problem, progress);
        // A panic while formatting is a bug; pass it on as one.
        let sections = sections
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic));
        solved.map(|(solution, seconds)| (solution, seconds, Some(sections)))
    })
}

/// Gives the calling thread the lowest scheduling priority (nice 19; on Linux the nice
/// value is per thread), best effort: only speed depends on it.
fn lower_this_threads_priority() {
    #[cfg(target_os = "linux")]
    // SAFETY: gettid and setpriority take no pointers; setpriority on the caller's own
    // thread id changes only that thread's nice value.
    unsafe {
        let tid = libc::syscall(libc::SYS_gettid);
        libc::setpriority(libc::PRIO_PROCESS, tid as libc::id_t, 19);
    }
}

/// Parses `--png`: a path ending in `.png`, so that a wrong name fails before the solve.
pub fn png_path(text: &str) -> Result<PathBuf, String> {
    let path = PathBuf::from(text);
    check_png_path(&path).map_err(|e| e.to_string())?;
    Ok(path)
}

/// With `--png`, writes the picture of the result: source and image side by side,
/// faces colored by |mu|, with the color bar and the legend (the picture is made only
/// when asked, after the solve). `target` is the target mesh of a map onto one.
pub fn write_png(
    png: Option<&Path>,
    mesh: &Mesh,
    solution: &Solution,
    target: Option<&Mesh>,
) -> anyhow::Result<()> {
    let Some(path) = png else {
        return Ok(());
    };
    let Some(map) = solution.map() else {
        bail!("--png draws maps of the source's vertices only");
    };
    // A map onto a target mesh is judged against the target's normals at the images,
    // as the report judges it.
    let (image, normals) = match map_file::image(mesh, map, target)? {
        Image::Uv(uv) => (Layout::plane_from_vertices(mesh, &uv)?, None),
        Image::Positions(p) => {
            let normals = match target {
                Some(target) => Some(beltrami::mapped::target_normals(target, mesh, &p)?.normals),
                None => None,
            };
            (Layout::space(mesh, p)?, normals)
        }
    };
    let reference = normals.as_deref().map(ReferenceNormal::PerFace);
    let scene = Scene::with_reference(mesh, Some(image), reference)?;
    beltrami_render::render(&scene, &Style::default())?
        .write_png(path)
        .with_context(|| format!("cannot write the picture {}", path.display()))?;
    Ok(())
}

/// The JSON report of a mapping command: the solution's keys
/// ([`beltrami::report::solution_json`]) and the input mesh, the output file and the
/// wall-clock seconds of the solve.
pub fn report_json(
    mesh: &Path,
    output: &Path,
    solution: &Solution,
    seconds: f64,
) -> JsonMap<String, Value> {
    let mut report = report::solution_json(solution);
    report.insert("mesh".into(), json!(mesh.display().to_string()));
    report.insert("output".into(), json!(output.display().to_string()));
    report.insert("seconds".into(), json!(seconds));
    report
}

/// Writes the report to `--report` (atomically) and prints it with `--json`; otherwise
/// prints the summary unless `quiet`. `extra` lines go into the summary after the |mu|
/// statistics.
pub fn finish(
    report: JsonMap<String, Value>,
    report_path: Option<&Path>,
    json: bool,
    quiet: bool,
    summary: (&Path, &Path, &Solution, f64),
    extra: &[String],
) -> anyhow::Result<()> {
    let report = Value::Object(report);
    if let Some(path) = report_path {
        let text = serde_json::to_string_pretty(&report)?;
        io::write_atomically(path, |w| std::io::Write::write_all(w, text.as_bytes()))
            .with_context(|| format!("cannot write the report {}", path.display()))?;
    }
    if json {
        println!("{report}");
    } else if !quiet {
        let (mesh, output, solution, seconds) = summary;
        let (r, m) = (&solution.report, &solution.metrics);
        println!(
            "{} -> {} ({}, {seconds:.3} s)",
            mesh.display(),
            output.display(),
            r.solver
        );
        if let Some(d) = &m.initial_distortion {
            println!(
                "  initial map     flipped {}  |mu| mean {:.4e}  max {:.4e}",
                d.flipped, d.mu_mean, d.mu_max
            );
        }
        if let Some(d) = &m.distortion {
            println!("  flipped faces   {}", d.flipped);
            println!(
                "  |mu|            mean {:.4e}  max {:.4e}  std {:.4e}",
                d.mu_mean, d.mu_max, d.mu_std
            );
        }
        if let Some(a) = solution.extras.annulus_radius {
            println!(
                "  inner radius {:.6} (free; started at {:.6})",
                a.radius, a.initial
            );
        }
        for line in extra {
            println!("  {line}");
        }
        for (stage, s) in &r.timings {
            println!("  {stage:<15} {s:.3} s");
        }
        for note in &r.notes {
            println!("  note: {note}");
        }
    }
    if super::interrupt::interrupted() {
        let (_, output, solution, _) = summary;
        bail!(
            "interrupted after {} iterations: the map so far was written to {}",
            solution.metrics.iterations,
            output.display()
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn progress(done: usize, total: Option<usize>) -> Progress {
        Progress {
            stage: "iteration",
            done,
            total,
            energy: None,
        }
    }

    #[test]
    fn time_left_scales_the_time_per_step_by_the_steps_left() {
        let ten = Duration::from_secs(10);
        assert_eq!(
            time_left(&progress(10, Some(40)), ten).as_deref(),
            Some(", at most ~30 s left")
        );
        assert_eq!(
            time_left(&progress(2, Some(100)), ten).as_deref(),
            Some(", at most ~8 min left")
        );
        assert_eq!(time_left(&progress(10, None), ten), None);
        assert_eq!(time_left(&progress(0, Some(40)), ten), None);
        assert_eq!(time_left(&progress(40, Some(40)), ten), None);
    }
}
