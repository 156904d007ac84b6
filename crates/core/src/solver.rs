//! The [`Solver`] trait, its [`SolverInfo`] record and the solve [`Context`] (progress
//! and cancellation).

use crate::{Accepts, OptionSpec, Problem, Report, Settings, Solution, SolverError, Target};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// What a solver is, as one constant record: its name, one line on what it computes,
/// what it accepts and its options. The registry, the command line's help and
/// reference, `beltrami solvers --json`, Python and batch jobs read it (through
/// [`Solver::info`] or the provided [`Solver::name`], [`Solver::description`],
/// [`Solver::accepts`] and [`Solver::options`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolverInfo {
    /// The stable name users select it by (`--solver NAME`).
    pub name: &'static str,
    /// One line on what it computes.
    pub description: &'static str,
    /// What it accepts: element types, topologies, targets, goals, constraint kinds.
    pub accepts: Accepts,
    /// Its options with types, defaults and ranges (`&[]` for none).
    pub options: &'static [OptionSpec],
}

/// A mapping algorithm behind a stable name.
///
/// An implementation states what it is as data ([`Solver::info`]: its name, what it
/// accepts and its options), checks what is particular to it
/// ([`Solver::check_problem`]) and computes ([`Solver::run`]). Callers use the provided
/// [`Solver::check`] and [`Solver::solve`], which run one validation: the options
/// ([`Settings::resolve`]), the constraints ([`crate::Constraints::validate`]), the
/// solver's own check, then the accepted kinds ([`Accepts::check`]), all before any work.
pub trait Solver: Send + Sync {
    /// Its record: name, description, what it accepts and its options.
    fn info(&self) -> &'static SolverInfo;

    /// The stable name users select it by (`--solver NAME`): [`SolverInfo::name`].
    fn name(&self) -> &'static str {
        self.info().name
    }

    /// One line on what it computes: [`SolverInfo::description`].
    fn description(&self) -> &'static str {
        self.info().description
    }

    /// What it accepts: [`SolverInfo::accepts`].
    fn accepts(&self) -> Accepts {
        self.info().accepts
    }

    /// Its options with types, defaults and ranges: [`SolverInfo::options`].
    fn options(&self) -> &'static [OptionSpec] {
        self.info().options
    }

    /// The checks particular to this solver, after the options and constraints were
    /// found well-formed; the error says in plain words why not and what to do instead.
    fn check_problem(&self, problem: &Problem<'_>, settings: &Settings) -> Result<(), SolverError>;

    /// Computes the solution of a problem that passed [`Solver::check`].
    fn run(
        &self,
        problem: &Problem<'_>,
        settings: &Settings,
        context: &mut Context<'_>,
    ) -> Result<Solution, SolverError>;

    /// Answers, before any work, whether the solver can take `problem`, and returns its
    /// resolved settings (module docs of [`Solver`] list the steps).
    fn check(&self, problem: &Problem<'_>) -> Result<Settings, SolverError> {
        let settings = Settings::resolve(self.name(), self.options(), &problem.options)?;
        let target = match &problem.target {
            Target::Mesh(mesh) => Some(*mesh),
            _ => None,
        };
        problem
            .constraints
            .validate(problem.source, target)
            .map_err(|error| SolverError::Constraint {
                solver: self.name(),
                error,
            })?;
        self.check_problem(problem, &settings)?;
        self.accepts().check(self.name(), problem)?;
        Ok(settings)
    }

    /// Checks `problem` ([`Solver::check`]) and computes its solution.
    fn solve(
        &self,
        problem: &Problem<'_>,
        context: &mut Context<'_>,
    ) -> Result<Solution, SolverError> {
        let settings = self.check(problem)?;
        self.run(problem, &settings, context)
    }
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

    /// A context for a solve run inside this one (an initial map, a flattening): the
    /// same cancellation flag, so a Ctrl-C stops the inner solve too; no progress
    /// callback (the caller's [`stage`](Self::stage) reports the inner solve's start and
    /// end).
    pub fn inner(&self) -> Context<'static> {
        Context::new().with_cancel_flag(self.cancel_flag())
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_inner_context_is_cancelled_with_its_caller() {
        let caller = Context::new().with_progress(|_| {});
        let inner = caller.inner();
        assert!(!inner.is_cancelled());
        caller.cancel_flag().store(true, Ordering::Relaxed);
        assert!(matches!(
            inner.check_cancelled(),
            Err(SolverError::Cancelled)
        ));
    }
}
