//! [`Report`]: how a solve went, in timings and prose.

use std::time::Instant;

/// Timings and notes of a solve. Measured quantities live in
/// [`Metrics`](crate::Metrics) and [`Extras`](crate::Extras); notes are prose for people.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Report {
    /// The solver's name.
    pub solver: String,
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

    /// The time recorded under `name` (the sum, if it was recorded several times).
    pub fn timing(&self, name: &str) -> Option<f64> {
        let mut found = self.timings.iter().filter(|(n, _)| n == name).peekable();
        found.peek()?;
        Some(found.map(|(_, s)| s).sum())
    }
}
