//! The `beltrami._native` extension module: the Rust side of the `beltrami` Python
//! package (`python/beltrami/`), which gives every solver of the workspace numpy arrays
//! in and out.
//!
//! The Python package owns the call signatures (keyword arguments named like the
//! command-line flags, with the command line's defaults) and the exception hierarchy
//! (`beltrami/_errors.py`); this module builds meshes from arrays (`arrays`), turns a
//! call's description into a [`beltrami_core::Problem`] and solves it with the GIL
//! released (`solve`), and measures (`measure`), remeshes and cuts
//! (`surgery`), makes texture atlases (`atlas`), repairs (`repair`) and reads and writes files (`files`). Errors become the package's
//! exceptions with the command line's messages (`errors`).

use pyo3::prelude::*;

mod arrays;
mod atlas;
mod errors;
mod files;
mod measure;
mod repair;
mod solve;
mod surgery;

/// The extension module.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(files::read_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(files::write_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(measure::mesh_info, m)?)?;
    m.add_function(wrap_pyfunction!(measure::beltrami_coefficient, m)?)?;
    m.add_function(wrap_pyfunction!(measure::distortion, m)?)?;
    m.add_function(wrap_pyfunction!(solve::solve, m)?)?;
    m.add_function(wrap_pyfunction!(solve::solvers, m)?)?;
    m.add_function(wrap_pyfunction!(atlas::atlas, m)?)?;
    m.add_function(wrap_pyfunction!(surgery::remesh, m)?)?;
    m.add_function(wrap_pyfunction!(surgery::remesh_in_place, m)?)?;
    m.add_function(wrap_pyfunction!(surgery::cut_to_disk, m)?)?;
    m.add_function(wrap_pyfunction!(repair::repair, m)?)?;
    Ok(())
}
