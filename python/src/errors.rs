//! Library errors as the package's Python exceptions (`beltrami/_errors.py`), with the
//! message the command-line program prints for the same error
//! ([`beltrami::report::error_message`]).

use std::error::Error;

use beltrami_core::SolverError;
use beltrami_fem::FemError;
use beltrami_mesh::io::{ReadError, WriteError};
use pyo3::exceptions::PyKeyboardInterrupt;
use pyo3::prelude::*;

/// The exception classes of `beltrami._errors`, by what went wrong.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// An invalid mesh: bad arrays, non-manifold, degenerate, non-finite (`MeshError`).
    Mesh,
    /// A file that cannot be read or written (`MeshFileError`, an `OSError`).
    File,
    /// A keyword argument or solver option out of range or of the wrong type
    /// (`OptionError`).
    Option,
    /// A pin, landmark or boundary map that does not fit the mesh (`ConstraintError`).
    Constraint,
    /// A Beltrami coefficient with `|mu| >= 1`, a NaN or the wrong length (`FieldError`).
    Field,
    /// A mesh the solver does not take: wrong topology, element or target
    /// (`UnsupportedError`).
    Unsupported,
    /// A solve that failed (`SolverError`, a `RuntimeError`).
    Solver,
}

impl Kind {
    fn class_name(self) -> &'static str {
        match self {
            Kind::Mesh => "MeshError",
            Kind::File => "MeshFileError",
            Kind::Option => "OptionError",
            Kind::Constraint => "ConstraintError",
            Kind::Field => "FieldError",
            Kind::Unsupported => "UnsupportedError",
            Kind::Solver => "SolverError",
        }
    }
}

/// The command line's advice in the library's messages and what a Python user does
/// instead.
const IN_PYTHON_TERMS: [(&str, &str); 6] = [
    ("`beltrami cut`", "`beltrami.cut_to_disk(V, F)`"),
    (
        "`--allow-missed-landmarks` (option `allow-missed-landmarks`)",
        "`allow_missed_landmarks=True`",
    ),
    (
        "`--allow-flips`, option `allow-flips`",
        "`allow_flips=True`",
    ),
    ("(`--pin v0`)", "(`pins=[0]`)"),
    ("add --normal-constraint", "give normal_constraint="),
    ("use beltrami-flow", "use beltrami.beltrami_flow"),
];

/// `message` with the command line's advice in Python terms ([`IN_PYTHON_TERMS`]).
fn in_python_terms(message: String) -> String {
    IN_PYTHON_TERMS
        .iter()
        .fold(message, |text, (cli, python)| text.replace(cli, python))
}

/// The Python exception of `kind` with `message` (its command-line advice put in Python
/// terms).
pub fn raise(kind: Kind, message: impl Into<String>) -> PyErr {
    let message = in_python_terms(message.into());
    Python::attach(|py| {
        let class = py
            .import("beltrami._errors")
            .and_then(|m| m.getattr(kind.class_name()));
        match class {
            Ok(class) => match class.call1((message.clone(),)) {
                Ok(value) => PyErr::from_value(value),
                Err(e) => e,
            },
            Err(e) => e,
        }
    })
}

/// `error` as the exception of `kind`, with its message and causes.
pub fn from_error(kind: Kind, error: &(dyn Error + 'static)) -> PyErr {
    raise(kind, beltrami::report::error_message(error))
}

/// A solver's error as its exception: cancellation (Ctrl-C) as `KeyboardInterrupt`,
/// the others by their kind.
pub fn from_solver(error: &SolverError) -> PyErr {
    let kind = match error {
        SolverError::Cancelled => return PyKeyboardInterrupt::new_err("the solve was cancelled"),
        SolverError::Mesh(_) => Kind::Mesh,
        SolverError::Field(_) => Kind::Field,
        SolverError::Option(_) | SolverError::UnknownSolver { .. } => Kind::Option,
        SolverError::Weights { .. } => Kind::Option,
        SolverError::Constraint { .. } | SolverError::Boundary { .. } => Kind::Constraint,
        SolverError::Unsupported { .. } | SolverError::InvalidInput { .. } => Kind::Unsupported,
        SolverError::Fem(FemError::DegenerateElement { .. } | FemError::NonFinite { .. }) => {
            Kind::Mesh
        }
        _ => Kind::Solver,
    };
    from_error(kind, error)
}

/// A file read error: a missing or unreadable file is `MeshFileError`, a file whose mesh
/// is invalid is `MeshError`.
pub fn from_read(error: &ReadError) -> PyErr {
    let kind = match error {
        ReadError::Mesh { .. } => Kind::Mesh,
        _ => Kind::File,
    };
    from_error(kind, error)
}

/// A file write error (`MeshFileError`).
pub fn from_write(error: &WriteError) -> PyErr {
    from_error(Kind::File, error)
}
