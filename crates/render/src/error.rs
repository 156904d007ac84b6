//! The errors of the render crate.

use std::path::PathBuf;

use beltrami_fem::FemError;
use beltrami_mesh::io::WriteError;
use thiserror::Error;

/// Why a picture could not be made or written. Elements are named by their input index
/// (the file's 0-based order), as everywhere in beltrami.
#[derive(Debug, Error)]
pub enum RenderError {
    /// A `--size` string that is not `WIDTHxHEIGHT`.
    #[error("image size `{text}`: {reason}")]
    Size {
        /// The text given.
        text: String,
        /// What is wrong with it.
        reason: String,
    },
    /// A `--camera` string that is not `AZIMUTH,ELEVATION` in degrees.
    #[error("camera `{text}`: {reason}")]
    Camera {
        /// The text given.
        text: String,
        /// What is wrong with it.
        reason: String,
    },
    /// A `--mu-range` string that is not `LO,HI` with `0 <= LO < HI`.
    #[error("|mu| range `{text}`: {reason}")]
    MuRange {
        /// The text given.
        text: String,
        /// What is wrong with it.
        reason: String,
    },
    /// A histogram needs at least one bin.
    #[error("a histogram needs between 1 and {max} bins, not {got}")]
    Bins {
        /// Bins asked for.
        got: usize,
        /// The largest number allowed.
        max: usize,
    },
    /// The mesh has no faces.
    #[error("the mesh has no faces: nothing to draw")]
    EmptyMesh,
    /// A per-vertex, per-corner or per-face array of the wrong length.
    #[error("{what} has {got} values but the mesh needs {expected}")]
    Length {
        /// Which array.
        what: &'static str,
        /// The length the mesh needs.
        expected: usize,
        /// The length given.
        got: usize,
    },
    /// A coordinate or value that is NaN or infinite.
    #[error("{what} of {element} {index} is not finite")]
    NonFinite {
        /// Which quantity (position, texture coordinate, |mu|).
        what: &'static str,
        /// The kind of element: vertex or face.
        element: &'static str,
        /// Input index of the element.
        index: usize,
    },
    /// The chosen view or coloring needs something the input does not have.
    #[error("{0}")]
    Missing(String),
    /// Measuring the map (its Beltrami coefficients) failed.
    #[error("measuring the map: {0}")]
    Measure(#[from] FemError),
    /// The output path does not end in `.png`.
    #[error("{path}: a picture is written as PNG: give a file name ending in .png")]
    NotPng {
        /// The path given.
        path: PathBuf,
    },
    /// Encoding the PNG failed.
    #[error("encoding the PNG: {0}")]
    Encode(std::io::Error),
    /// Encoding or writing the PNG file failed; the destination is left untouched.
    #[error(transparent)]
    Write(#[from] WriteError),
}
