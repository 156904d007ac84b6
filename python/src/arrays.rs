//! numpy arrays to meshes and back.
//!
//! Rows of `V` and `F` are the input's vertices and faces; every array the package
//! returns is indexed the same way (a vertex no face uses gets a row of NaN), so that a
//! result lines up with the caller's own arrays. Inside, the halfedge mesh numbers its
//! vertices and faces itself ([`beltrami_mesh::VertexMap`], [`Mesh::face_to_input`]).

use beltrami_mesh::{Mesh, MeshError, Point3, PolygonSoup, VertexId};
use num_complex::Complex64;
use numpy::ndarray::{Array1, Array2, ArrayView1, ArrayView2};
use pyo3::prelude::*;

use crate::errors::{self, Kind};

/// Positions `V` (`(n, 3)`, or `(n, 2)` for a planar mesh in z = 0) and faces `F`
/// (`(m, 3)` triangles or `(m, 4)` quads, 0-based) as a polygon soup, checked for shape
/// and index sign (the builder checks the rest and names the element).
pub fn soup(v: ArrayView2<'_, f64>, f: ArrayView2<'_, i64>) -> PyResult<PolygonSoup> {
    let (n, dim) = v.dim();
    if dim != 2 && dim != 3 {
        return Err(errors::raise(
            Kind::Mesh,
            format!("V has shape ({n}, {dim}): give positions as an (n, 3) or (n, 2) array"),
        ));
    }
    let (m, corners) = f.dim();
    if corners != 3 && corners != 4 {
        return Err(errors::raise(
            Kind::Mesh,
            format!(
                "F has shape ({m}, {corners}): give triangles as an (m, 3) array or quads as an (m, 4) array"
            ),
        ));
    }
    let positions = v
        .rows()
        .into_iter()
        .map(|r| Point3::new(r[0], r[1], if dim == 3 { r[2] } else { 0.0 }))
        .collect();
    let mut soup = PolygonSoup::new(positions);
    soup.reserve(m, m * corners);
    let mut face = Vec::with_capacity(corners);
    for (i, row) in f.rows().into_iter().enumerate() {
        face.clear();
        for &index in row {
            let Ok(index) = u32::try_from(index) else {
                return Err(errors::raise(
                    Kind::Mesh,
                    format!(
                        "face {i} refers to vertex {index}, but vertex indices run from 0 to {}",
                        n.saturating_sub(1)
                    ),
                ));
            };
            face.push(index);
        }
        soup.push_face(&face);
    }
    Ok(soup)
}

/// The halfedge mesh of a soup (no repair: a degenerate or duplicate face is an error
/// naming it, as on the command line without `--repair`).
pub fn build(soup: &PolygonSoup) -> PyResult<Mesh> {
    Mesh::from_soup(soup).map_err(|e| {
        if matches!(e, MeshError::VertexIndexOutOfRange { .. }) && soup.looks_one_based() {
            errors::raise(
                Kind::Mesh,
                format!(
                    "{e}; F looks 1-based (no face uses vertex 0, and the largest index is len(V)): give F - 1"
                ),
            )
        } else {
            errors::from_error(Kind::Mesh, &e)
        }
    })
}

/// The mesh of `V` and `F` ([`soup`], then [`build`]).
pub fn mesh(v: ArrayView2<'_, f64>, f: ArrayView2<'_, i64>) -> PyResult<Mesh> {
    build(&soup(v, f)?)
}

/// Rows in the input's vertex order from values per mesh vertex: row `i` is the value
/// of the mesh vertex of input vertex `i` (`columns` numbers from `row`), NaN for an
/// input vertex no face uses.
pub fn vertex_rows<T>(
    mesh: &Mesh,
    values: &[T],
    columns: usize,
    row: impl Fn(&T) -> Vec<f64>,
) -> Array2<f64> {
    let map = mesh.vertex_map();
    let mut out = Array2::from_elem((map.input_len(), columns), f64::NAN);
    for (v, value) in values.iter().enumerate() {
        let i = map.to_input(VertexId(v as u32));
        for (c, x) in row(value).into_iter().enumerate().take(columns) {
            out[[i, c]] = x;
        }
    }
    out
}

/// Values per mesh vertex from rows in the input's vertex order (`what` names the array
/// in errors): `rows` must have one row per input vertex and `columns` columns.
pub fn rows_to_vertices<T>(
    mesh: &Mesh,
    rows: ArrayView2<'_, f64>,
    columns: &[usize],
    what: &str,
    value: impl Fn(ArrayView1<'_, f64>) -> T,
) -> PyResult<Vec<T>> {
    let map = mesh.vertex_map();
    let (n, c) = rows.dim();
    if n != map.input_len() || !columns.contains(&c) {
        let want: Vec<String> = columns
            .iter()
            .map(|c| format!("({}, {c})", map.input_len()))
            .collect();
        return Err(errors::raise(
            Kind::Constraint,
            format!(
                "{what} has shape ({n}, {c}); expected {}",
                want.join(" or ")
            ),
        ));
    }
    mesh.vertices()
        .map(|v| {
            let i = map.to_input(v);
            let row = rows.row(i);
            if row.iter().any(|x| !x.is_finite()) {
                return Err(errors::raise(
                    Kind::Constraint,
                    format!("{what}: row {i} (vertex {i}) is not finite"),
                ));
            }
            Ok(value(row))
        })
        .collect()
}

/// Planar images `x + i y` per mesh vertex from an `(n, 2)` array (a third column is
/// ignored, so positions in z = 0 are accepted).
pub fn planar(mesh: &Mesh, rows: ArrayView2<'_, f64>, what: &str) -> PyResult<Vec<Complex64>> {
    rows_to_vertices(mesh, rows, &[2, 3], what, |r| Complex64::new(r[0], r[1]))
}

/// Points of R^3 per mesh vertex from an `(n, 3)` array.
pub fn spatial(mesh: &Mesh, rows: ArrayView2<'_, f64>, what: &str) -> PyResult<Vec<Point3<f64>>> {
    rows_to_vertices(mesh, rows, &[3], what, |r| Point3::new(r[0], r[1], r[2]))
}

/// Values per input face (row of `F`) from values per mesh face.
pub fn face_rows<T: Copy>(mesh: &Mesh, values: &[T], fill: T) -> Array1<T> {
    let faces = mesh
        .faces()
        .map(|f| mesh.face_to_input(f) + 1)
        .max()
        .unwrap_or(0);
    let mut out = Array1::from_elem(faces, fill);
    for (f, value) in mesh.faces().zip(values) {
        out[mesh.face_to_input(f)] = *value;
    }
    out
}

/// Values per mesh face from one value per input face (`what` names the array).
pub fn faces_from_rows<T: Copy>(
    mesh: &Mesh,
    rows: ArrayView1<'_, T>,
    what: &str,
) -> PyResult<Vec<T>> {
    if rows.len() != mesh.face_count() {
        return Err(errors::raise(
            Kind::Field,
            format!(
                "{what} has {} values for a mesh of {} faces",
                rows.len(),
                mesh.face_count()
            ),
        ));
    }
    Ok(mesh.faces().map(|f| rows[mesh.face_to_input(f)]).collect())
}

/// The vertex index of input vertex `i` (a pin), or an error naming it.
pub fn vertex(mesh: &Mesh, i: i64, what: &str) -> PyResult<VertexId> {
    usize::try_from(i)
        .ok()
        .and_then(|i| mesh.vertex_map().from_input(i))
        .ok_or_else(|| {
            errors::raise(
                Kind::Constraint,
                format!(
                    "{what}: vertex {i} is not a vertex of the mesh (0 to {}, used by a face)",
                    mesh.vertex_map().input_len().saturating_sub(1)
                ),
            )
        })
}

/// The positions `(n, 3)` and faces `(m, k)` of a mesh by its own vertex and face ids
/// (a mesh built here, or repaired: not the input's rows), or `None` for a mesh that
/// mixes triangles and quads.
pub fn own_order(mesh: &Mesh) -> Option<(Array2<f64>, Array2<i64>)> {
    let mut v = Array2::zeros((mesh.vertex_count(), 3));
    for (i, p) in mesh.positions().iter().enumerate() {
        for c in 0..3 {
            v[[i, c]] = p[c];
        }
    }
    let k = mesh.faces().next().map_or(3, |f| mesh.face_degree(f));
    let mut f = Array2::zeros((mesh.face_count(), k));
    for face in mesh.faces() {
        if mesh.face_degree(face) != k {
            return None;
        }
        for (c, vertex) in mesh.face_vertices(face).enumerate() {
            f[[face.idx(), c]] = vertex.idx() as i64;
        }
    }
    Some((v, f))
}

/// The faces of a mesh as an `(m, k)` array in input order (`k` = 3 or 4), or `None`
/// for a mesh that mixes triangles and quads.
pub fn faces(mesh: &Mesh) -> Option<Array2<i64>> {
    let k = mesh.faces().next().map_or(3, |f| mesh.face_degree(f));
    let mut out = Array2::zeros((mesh.face_count(), k));
    for f in mesh.faces() {
        if mesh.face_degree(f) != k {
            return None;
        }
        let row = mesh.face_to_input(f);
        for (c, v) in mesh.face_vertices(f).enumerate() {
            out[[row, c]] = mesh.vertex_map().to_input(v) as i64;
        }
    }
    Some(out)
}
