//! Measuring meshes and maps: `mesh_info`, `beltrami_coefficient`, `distortion`.
//!
//! A map is given by its images per vertex: `(n, 2)` is a map into the plane, measured
//! in the plane's frame when the source lies in z = 0 and in each face's frame otherwise;
//! `(n, 3)` is a map into R^3, measured in the face frames with the orientation judged
//! against the plane, the sphere about the origin or the source's normals, whichever the
//! image is ([`ReferenceNormal::for_image`]) — the rules of `beltrami distortion`.

use beltrami_fem::distortion::{Distortion, measure_planar, measure_surface};
use beltrami_fem::{Frame, ReferenceNormal, element};
use beltrami_mesh::Mesh;
use num_complex::Complex64;
use numpy::{IntoPyArray, PyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::arrays;
use crate::errors::{self, Kind};

/// Sizes and topology of the mesh `V`, `F`: `vertices`, `faces`, `edges`,
/// `boundary_loops`, `components`, `euler_characteristic`, `genus` (None for several
/// components), `topology` (the text the solvers use in errors).
#[pyfunction]
pub fn mesh_info<'py>(
    py: Python<'py>,
    v: PyReadonlyArray2<'_, f64>,
    f: PyReadonlyArray2<'_, i64>,
) -> PyResult<Bound<'py, PyDict>> {
    let mesh = arrays::mesh(v.as_array(), f.as_array())?;
    let info = PyDict::new(py);
    info.set_item("vertices", mesh.vertex_count())?;
    info.set_item("faces", mesh.face_count())?;
    info.set_item("edges", mesh.edge_count())?;
    info.set_item("boundary_loops", mesh.boundary_loop_count())?;
    info.set_item("components", mesh.components().len())?;
    info.set_item("euler_characteristic", mesh.euler_characteristic())?;
    info.set_item("genus", mesh.genus())?;
    info.set_item("topology", beltrami_core::topology::describe(&mesh))?;
    Ok(info)
}

/// The distortion of the map of `mesh` with images `x` (module docs) and the frame its
/// `mu` is in.
fn measure(mesh: &Mesh, x: PyReadonlyArray2<'_, f64>) -> PyResult<(Distortion, Frame)> {
    let x = x.as_array();
    let measuring = |e: beltrami_fem::FemError| errors::from_error(Kind::Mesh, &e);
    if x.ncols() == 2 {
        let frame = if element::is_planar(mesh) {
            Frame::Global
        } else {
            Frame::Face
        };
        let map = arrays::planar(mesh, x, "the map")?;
        Ok((measure_planar(mesh, &map, frame).map_err(measuring)?, frame))
    } else {
        let image = arrays::spatial(mesh, x, "the map")?;
        let reference = ReferenceNormal::for_image(&image);
        Ok((
            measure_surface(mesh, &image, reference).map_err(measuring)?,
            Frame::Face,
        ))
    }
}

/// The Beltrami coefficient `mu = f_zbar / f_z` per face (rows of `F`) of the map with
/// images `X`: `(n, 2)` into the plane, `(n, 3)` into R^3 (module docs for the frames).
#[pyfunction]
pub fn beltrami_coefficient<'py>(
    py: Python<'py>,
    v: PyReadonlyArray2<'_, f64>,
    f: PyReadonlyArray2<'_, i64>,
    x: PyReadonlyArray2<'_, f64>,
) -> PyResult<(Bound<'py, PyArray1<Complex64>>, &'static str)> {
    let mesh = arrays::mesh(v.as_array(), f.as_array())?;
    let (measured, frame) = measure(&mesh, x)?;
    let nan = Complex64::new(f64::NAN, f64::NAN);
    Ok((
        arrays::face_rows(&mesh, &measured.field.mu, nan).into_pyarray(py),
        frame.name(),
    ))
}

/// The statistics of `beltrami distortion --json` for the map with images `X`:
/// `faces`, `flipped`, `mu_mean`, `mu_max`, `mu_std`, `mu_l2`, `frame`, and the flipped
/// faces' rows `flipped_faces`.
#[pyfunction]
pub fn distortion<'py>(
    py: Python<'py>,
    v: PyReadonlyArray2<'_, f64>,
    f: PyReadonlyArray2<'_, i64>,
    x: PyReadonlyArray2<'_, f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let mesh = arrays::mesh(v.as_array(), f.as_array())?;
    let (measured, frame) = measure(&mesh, x)?;
    let s = &measured.stats;
    let out = PyDict::new(py);
    out.set_item("faces", s.faces)?;
    out.set_item("flipped", s.flipped)?;
    out.set_item("mu_mean", s.mu_mean)?;
    out.set_item("mu_max", s.mu_max)?;
    out.set_item("mu_std", s.mu_std)?;
    out.set_item("mu_l2", s.mu_l2)?;
    out.set_item("frame", frame.name())?;
    let flipped: Vec<usize> = mesh
        .faces()
        .zip(&measured.flipped)
        .filter(|(_, flip)| **flip)
        .map(|(face, _)| mesh.face_to_input(face))
        .collect();
    out.set_item("flipped_faces", flipped)?;
    Ok(out)
}
