//! The [`Solver`] trait, the solve [`Context`] (progress and cancellation), and the
//! [`Solution`] with its [`Report`].

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use beltrami_fem::{BeltramiField, DistortionStats};

use crate::{Map, Problem, SolverError};

/// A mapping algorithm behind a stable name.
pub trait Solver: Send + Sync {
    /// The stable name users select it by (`--solver NAME`).
    fn name(&self) -> &'static str;

    /// One line on what it computes.
    fn description(&self) -> &'static str;

    /// What it accepts (topology, targets, goals, constraints), for listings.
    fn accepts(&self) -> &'static str;

    /// Answers, before any work, whether the solver can take `problem`; the error says
    /// in plain words why not and what to do instead.
    fn check(&self, problem: &Problem<'_>) -> Result<(), SolverError>;

    /// Computes the map. Implementations call [`Solver::check`] first.
    fn solve(
        &self,
        problem: &Problem<'_>,
        context: &mut Context<'_>,
    ) -> Result<Solution, SolverError>;
}

/// Progress of a running solve.
#[derive(Debug, Clone, PartialEq)]
pub struct Progress {
    /// What is being done ("assembly", "iteration", ...).
    pub stage: &'static str,
    /// Steps done in this stage.
    pub done: usize,
    /// Steps expected, if known (iterative solvers give their iteration limit).
    pub total: Option<usize>,
    /// The current energy or error, if the stage has one.
    pub energy: Option<f64>,
}

/// A progress callback.
type ProgressFn<'a> = Box<dyn FnMut(&Progress) + 'a>;

/// What a solve may use beside the problem: a progress callback and a cancellation flag.
pub struct Context<'a> {
    progress: Option<ProgressFn<'a>>,
    cancel: Arc<AtomicBool>,
}

impl Default for Context<'_> {
    fn default() -> Self {
        Self::new()
    }
}

impl<'a> Context<'a> {
    /// No progress reporting, never cancelled.
    pub fn new() -> Self {
        Self {
            progress: None,
            cancel: Arc::new(AtomicBool::new(false)),
        }
    }

    /// Calls `f` on every progress report.
    pub fn with_progress(mut self, f: impl FnMut(&Progress) + 'a) -> Self {
        self.progress = Some(Box::new(f));
        self
    }

    /// Uses `flag` for cancellation (set it from another thread, e.g. a Ctrl-C handler).
    pub fn with_cancel_flag(mut self, flag: Arc<AtomicBool>) -> Self {
        self.cancel = flag;
        self
    }

    /// The cancellation flag, to share with a signal handler.
    pub fn cancel_flag(&self) -> Arc<AtomicBool> {
        Arc::clone(&self.cancel)
    }

    /// Reports progress to the callback, if any.
    pub fn report(&mut self, progress: &Progress) {
        if let Some(f) = &mut self.progress {
            f(progress);
        }
    }

    /// True once cancellation was requested.
    pub fn is_cancelled(&self) -> bool {
        self.cancel.load(Ordering::Relaxed)
    }

    /// Runs one stage of a solve: checks for cancellation, reports the stage's start and
    /// end (`done` 0 then 1 of 1) and records its duration in `report` under `name`.
    pub fn stage<T>(
        &mut self,
        name: &'static str,
        report: &mut Report,
        f: impl FnOnce() -> Result<T, SolverError>,
    ) -> Result<T, SolverError> {
        self.check_cancelled()?;
        let progress = |done| Progress {
            stage: name,
            done,
            total: Some(1),
            energy: None,
        };
        self.report(&progress(0));
        let out = report.time(name, f)?;
        self.report(&progress(1));
        Ok(out)
    }

    /// `Err(SolverError::Cancelled)` once cancellation was requested; iterative solvers
    /// call it between steps (and return their best map so far instead, when they can).
    pub fn check_cancelled(&self) -> Result<(), SolverError> {
        if self.is_cancelled() {
            Err(SolverError::Cancelled)
        } else {
            Ok(())
        }
    }
}

/// How a solve went.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Report {
    /// The solver's name.
    pub solver: String,
    /// Iterations done (0 for direct solvers).
    pub iterations: usize,
    /// Energy or error after each iteration (direct solvers: the final energy, if any).
    pub energy_history: Vec<f64>,
    /// The step size taken at each iteration of an iterative solver (empty for direct
    /// solvers).
    pub step_sizes: Vec<f64>,
    /// Beltrami coefficient of the result per face, when measured.
    pub mu: Option<BeltramiField>,
    /// Statistics of `|mu|` and the flipped-face count, when measured.
    pub distortion: Option<DistortionStats>,
    /// The same for the map an iterative solver started from, when measured.
    pub initial_distortion: Option<DistortionStats>,
    /// Named timings in seconds, in the order they happened.
    pub timings: Vec<(String, f64)>,
    /// Remarks for the user (e.g. "3 faces flipped: cotangent weights are negative on
    /// obtuse triangles").
    pub notes: Vec<String>,
}

impl Report {
    /// An empty report for `solver`.
    pub fn new(solver: &str) -> Self {
        Self {
            solver: solver.to_string(),
            ..Self::default()
        }
    }

    /// Runs `f`, recording its duration under `name`.
    pub fn time<T>(&mut self, name: &str, f: impl FnOnce() -> T) -> T {
        let start = Instant::now();
        let out = f();
        self.timings
            .push((name.to_string(), start.elapsed().as_secs_f64()));
        out
    }

    /// Total of the recorded timings.
    pub fn seconds(&self) -> f64 {
        self.timings.iter().map(|(_, s)| s).sum()
    }

    /// Number of flipped faces, when measured.
    pub fn flipped(&self) -> Option<usize> {
        self.distortion.as_ref().map(|d| d.flipped)
    }
}

/// The result of a solve: the map and its report.
#[derive(Debug, Clone, PartialEq)]
pub struct Solution {
    /// Images of the source vertices.
    pub map: Map,
    /// How it went.
    pub report: Report,
}
