//! The registry of solvers by name.

use crate::{Solver, SolverError};

/// Solvers by their stable names, in registration order.
#[derive(Default)]
pub struct Registry {
    solvers: Vec<Box<dyn Solver>>,
}

impl Registry {
    /// An empty registry.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a solver; a later solver with the same name replaces the earlier one.
    pub fn register(&mut self, solver: Box<dyn Solver>) {
        self.solvers.retain(|s| s.name() != solver.name());
        self.solvers.push(solver);
    }

    /// The solver named `name`, or [`SolverError::UnknownSolver`] listing the names.
    pub fn get(&self, name: &str) -> Result<&dyn Solver, SolverError> {
        self.solvers
            .iter()
            .find(|s| s.name() == name)
            .map(|s| s.as_ref())
            .ok_or_else(|| SolverError::UnknownSolver {
                name: name.to_string(),
                available: self.names().join(", "),
            })
    }

    /// The registered names, in order.
    pub fn names(&self) -> Vec<&'static str> {
        self.solvers.iter().map(|s| s.name()).collect()
    }

    /// The registered solvers, in order.
    pub fn iter(&self) -> impl Iterator<Item = &dyn Solver> {
        self.solvers.iter().map(|s| s.as_ref())
    }
}
