//! Boundary first flattening of a disk with prescribed scale factors (Sawhney and Crane
//! 2017, "Boundary first flattening", sections 3 and 4).
//!
//! Given the log scale factor `u` of a conformal flattening at every vertex (the
//! interior values solving the Yamabe equation `L u = -Omega`, [`crate::cones`]):
//!
//! 1. **Boundary curvature** (the Dirichlet-to-Neumann step, their eq. 11): the target
//!    turning angle at boundary vertex `i` is `k~_i = k_i + (L u)_i`, with `k_i` the
//!    surface's turning angle ([`Mesh::angle_defect`]). By Gauss-Bonnet the `k~` sum to
//!    `2 pi` when the interior equations hold.
//! 2. **Boundary curve** (section 4.4): edge lengths `l~_ij = e^{(u_i + u_j)/2} l_ij`,
//!    tangent directions the running sums of `k~` counter-clockwise; the lengths are
//!    then changed as little as possible (least squares weighted by `1 / l~`) so that
//!    the curve closes: `l* = l~ - D T^T (T D T^T)^{-1} T l~` with `D = diag(l~)` and
//!    `T` the 2 x n matrix of unit tangents.
//! 3. **Interior** (section 4.5, their simplest extension): each coordinate extended
//!    harmonically with the cotan Laplacian, the curve held.
//!
//! The result is a flat map whose conformal distortion is that of the linearized scale
//! and the harmonic extension; [`crate::chart`] checks it for flipped faces and a boundary
//! that crosses itself.

use beltrami_fem::assembly::Pattern;
use beltrami_fem::operators::cotan_laplacian;
use beltrami_mesh::{Mesh, VertexId};
use beltrami_sparse::{SolveOptions, solve_spd};
use faer::Mat;
use faer::sparse::SparseColMat;

use crate::AtlasError;

/// Why a disk could not be laid flat.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FlattenFailure {
    /// The mesh is not a disk (one boundary loop, Euler characteristic 1).
    NotADisk,
    /// Closing the boundary curve needed a non-positive edge length.
    CurveDoesNotClose,
    /// A face came out with a non-positive area.
    Folded,
}

/// The flat positions of the vertices of `disk` for the log scale factors `u` (see the
/// module docs), or why there are none.
pub fn flatten_disk(
    disk: &Mesh,
    u: &[f64],
) -> Result<Result<Vec<[f64; 2]>, FlattenFailure>, AtlasError> {
    if !is_disk(disk) {
        return Ok(Err(FlattenFailure::NotADisk));
    }
    let laplacian = cotan_laplacian(disk)?;
    let lu = multiply(&laplacian, u);
    let ring = counter_clockwise_ring(disk);
    let n = ring.len();
    let turning: Vec<f64> = ring
        .iter()
        .map(|&v| disk.angle_defect(v) + lu[v.idx()])
        .collect();
    let lengths: Vec<f64> = (0..n)
        .map(|i| {
            let (a, b) = (ring[i], ring[(i + 1) % n]);
            ((u[a.idx()] + u[b.idx()]) / 2.0).exp() * (disk.position(b) - disk.position(a)).norm()
        })
        .collect();
    let mut heading = 0.0;
    let tangents: Vec<[f64; 2]> = (0..n)
        .map(|i| {
            if i > 0 {
                heading += turning[i];
            }
            [heading.cos(), heading.sin()]
        })
        .collect();
    let Some(closed) = close_curve(&lengths, &tangents) else {
        return Ok(Err(FlattenFailure::CurveDoesNotClose));
    };
    let mut position = vec![[0.0; 2]; disk.vertex_count()];
    let mut at = [0.0, 0.0];
    for i in 0..n {
        position[ring[i].idx()] = at;
        at = [
            at[0] + closed[i] * tangents[i][0],
            at[1] + closed[i] * tangents[i][1],
        ];
    }
    extend_harmonically(disk, &laplacian, &mut position)?;
    Ok(Ok(position))
}

/// The boundary vertices of a disk in counter-clockwise order (the interior on the
/// left): boundary halfedges run clockwise, so their loop is walked backwards.
pub(crate) fn counter_clockwise_ring(disk: &Mesh) -> Vec<VertexId> {
    let mut ring: Vec<VertexId> = disk
        .boundary_loops()
        .next()
        .map(|b| disk.loop_vertices(b).collect())
        .unwrap_or_default();
    ring.reverse();
    ring
}

/// Whether `disk` is a topological disk: one boundary loop, Euler characteristic 1.
pub(crate) fn is_disk(disk: &Mesh) -> bool {
    let euler = disk.vertex_count() as i64 - disk.edge_count() as i64 + disk.face_count() as i64;
    disk.boundary_loop_count() == 1 && euler == 1
}

/// The lengths nearest to `lengths` (weights `1 / l`) for which the polygon with unit
/// edge directions `tangents` closes; `None` if one comes out non-positive.
fn close_curve(lengths: &[f64], tangents: &[[f64; 2]]) -> Option<Vec<f64>> {
    // M = T D T^T (2 x 2), r = T l.
    let (mut m00, mut m01, mut m11, mut r0, mut r1) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for (&l, t) in lengths.iter().zip(tangents) {
        m00 += l * t[0] * t[0];
        m01 += l * t[0] * t[1];
        m11 += l * t[1] * t[1];
        r0 += l * t[0];
        r1 += l * t[1];
    }
    let det = m00 * m11 - m01 * m01;
    if det.abs() <= f64::EPSILON * (m00 * m11).abs() {
        return None;
    }
    let (y0, y1) = ((m11 * r0 - m01 * r1) / det, (m00 * r1 - m01 * r0) / det);
    let closed: Vec<f64> = lengths
        .iter()
        .zip(tangents)
        .map(|(&l, t)| l - l * (t[0] * y0 + t[1] * y1))
        .collect();
    closed
        .iter()
        .all(|&l| l > 0.0 && l.is_finite())
        .then_some(closed)
}

/// Replaces the interior positions by the harmonic extension of the boundary's.
pub(crate) fn extend_harmonically(
    disk: &Mesh,
    laplacian: &SparseColMat<usize, f64>,
    position: &mut [[f64; 2]],
) -> Result<(), AtlasError> {
    let mut interior = vec![usize::MAX; disk.vertex_count()];
    let mut count = 0;
    for v in disk.vertices() {
        if !disk.is_boundary_vertex(v) {
            interior[v.idx()] = count;
            count += 1;
        }
    }
    if count == 0 {
        return Ok(());
    }
    let symbolic = laplacian.symbolic();
    let (col_ptr, rows, values) = (symbolic.col_ptr(), symbolic.row_idx(), laplacian.val());
    let mut entries = Vec::new();
    let mut entry_values = Vec::new();
    let mut rhs = Mat::<f64>::zeros(count, 2);
    for col in 0..laplacian.ncols() {
        for k in col_ptr[col]..col_ptr[col + 1] {
            let (row, value) = (rows[k], values[k]);
            let Some(&r) = interior.get(row).filter(|&&r| r != usize::MAX) else {
                continue;
            };
            match interior[col] {
                usize::MAX => {
                    rhs[(r, 0)] -= value * position[col][0];
                    rhs[(r, 1)] -= value * position[col][1];
                }
                c => {
                    entries.push((r, c));
                    entry_values.push(value);
                }
            }
        }
    }
    let block = Pattern::new(count, count, &entries)?.assemble(&entry_values)?;
    let solution = solve_spd(block.as_ref(), rhs.as_ref(), SolveOptions::default())?;
    for v in disk.vertices() {
        if let Some(&r) = interior.get(v.idx()).filter(|&&r| r != usize::MAX) {
            position[v.idx()] = [solution[(r, 0)], solution[(r, 1)]];
        }
    }
    Ok(())
}

/// `L x` for a sparse `L`.
pub(crate) fn multiply(matrix: &SparseColMat<usize, f64>, x: &[f64]) -> Vec<f64> {
    let symbolic = matrix.symbolic();
    let (col_ptr, rows, values) = (symbolic.col_ptr(), symbolic.row_idx(), matrix.val());
    let mut out = vec![0.0; matrix.nrows()];
    for col in 0..matrix.ncols() {
        for k in col_ptr[col]..col_ptr[col + 1] {
            out[rows[k]] += values[k] * x[col];
        }
    }
    out
}
