//! The conformal energy of a P1 triangle mesh's map into the plane as a Hermitian
//! matrix built from the edges of the faces: the normal equations of LSCM without
//! elements, `D_zbar` or scatter maps.
//!
//! # The formula
//!
//! On a triangle with corners `p_0, p_1, p_2` (counterclockwise about the face normal
//! `(p_1 - p_0) x (p_2 - p_0)`), area `A`, and `e_k = p_(k+2) - p_(k+1)` the side
//! opposite corner `k` (indices mod 3), written as a complex number in any
//! counterclockwise orthonormal frame of the face's plane, the P1 shape function of
//! corner `k` has `d_x N_k + i d_y N_k = i e_k / (2 A)`. So a map with vertex images
//! `x_k` has
//!
//! ```text
//! f_zbar = (f_x + i f_y) / 2 = i / (4 A) sum_k e_k x_k,
//! A |f_zbar|^2 = x^H C_f x,   C_f[j, k] = conj(e_j) e_k / (16 A)
//!                                       = (e_j . e_k) / (16 A) + i s_jk / 8,
//! ```
//!
//! since `conj(e_j) e_k = e_j . e_k + i (e_j x e_k)` and `e_j x e_k = 2 A s_jk`, with
//! `s_jk = 1` when `k = j + 1`, `-1` when `k = j - 1`, `0` when `k = j`. The real part
//! needs only dot products of the sides in R^3 (no frame); it is a quarter of the P1
//! stiffness (cotangent Laplacian, `(e_j . e_k) / (4 A) = -cot(theta_l) / 2` at the
//! third corner `l`). The imaginary part is `+-1/8` on every side of every face,
//! opposite on the two faces of an interior edge (they run it in opposite directions):
//! summed over the mesh, it cancels exactly (the same binary value) except on boundary
//! edges, the discrete form of
//!
//! ```text
//! E_C = sum_f A_f |f_zbar|^2 = E_D / 2 - Area(f),   E_D = 1/2 sum_f A_f |grad f|^2
//! ```
//!
//! (Levy, Petitjean, Ray, Maillot 2002, LSCM; Mullen, Tong, Alliez, Desbrun 2008: the
//! signed area of the image is a boundary integral). With one quadrature point per
//! triangle, `C = sum_f C_f` is exactly `D_zbar^H W D_zbar` of
//! [`crate::operators::beltrami_operator`] at `mu = 0` ([`Elements`](crate::Elements) in
//! [`Frame::Face`](crate::Frame::Face)), up to rounding.
//!
//! # Through a DOF map
//!
//! With `x = K y + x0` ([`DofMap`], complex form), `LSCM` minimizes `x^H C x` over
//! `y`: the normal equations are `(K^H C K) y = -K^H C x0`. Each node's terms
//! `x_v = sum_t kappa_t y_(dof t)` give `N[c, d] = sum conj(kappa_j) C[j, k] kappa_k` over
//! the corners `j` with a term on `c` and `k` with a term on `d`.

use std::ops::Range;

use beltrami_mesh::parallel::{available_threads, map_blocks};
use beltrami_mesh::{FaceId, Mesh, Point3, Vector3, VertexId};
use faer::sparse::SymbolicSparseColMatRef;
use num_complex::Complex64;

use crate::FemError;
use crate::dof::DofMap;

/// `(K^H C K, -K^H C x0)` of a DOF map: the lower triangle of the Hermitian matrix,
/// its values in the order of a given pattern, and the right-hand side.
#[derive(Debug, Clone, PartialEq)]
pub struct ConformalSystem {
    /// The values of the lower triangle of `K^H C K`, in the order of the pattern
    /// given to [`conformal_system`] (its diagonal exactly real).
    pub values: Vec<Complex64>,
    /// `-K^H C x0`, one value per reduced unknown.
    pub rhs: Vec<Complex64>,
}

/// The geometry of one triangle the energy needs: the sides opposite its corners and
/// `1 / (16 A)`.
struct Face {
    sides: [Vector3<f64>; 3],
    scale: f64,
}

impl Face {
    /// The triangle `f` of `mesh`. Errors: [`FemError::Length`] for a quad,
    /// [`FemError::DegenerateElement`] where the area vanishes relative to the squared
    /// size of the face (the test of [`Elements::new`](crate::Elements::new)).
    fn new(mesh: &Mesh, f: FaceId) -> Result<(Self, [usize; 3]), FemError> {
        let (v, n) = mesh.face_vertex_array(f);
        if n != 3 {
            return Err(FemError::Length {
                what: "the corners of a face of the conformal energy (triangles only)",
                expected: 3,
                got: n,
            });
        }
        let p: [Point3<f64>; 3] = std::array::from_fn(|k| mesh.position(v[k]));
        let sides = [p[2] - p[1], p[0] - p[2], p[1] - p[0]];
        // `det` is twice the area, as the Jacobian determinant of `Elements`.
        let det = sides[2].cross(&(p[2] - p[0])).norm();
        let size2 = sides[2].norm_squared().max(sides[1].norm_squared());
        if crate::element::is_degenerate(det, size2) {
            return Err(FemError::DegenerateElement { face: f, det });
        }
        Ok((
            Self {
                sides,
                scale: 0.125 / det,
            },
            [v[0].idx(), v[1].idx(), v[2].idx()],
        ))
    }

    /// `C_f[j, k]` (module docs).
    #[inline]
    fn entry(&self, j: usize, k: usize) -> Complex64 {
        let re = self.sides[j].dot(&self.sides[k]) * self.scale;
        let im = match (k + 3 - j) % 3 {
            0 => 0.0,
            1 => 0.125,
            _ => -0.125,
        };
        Complex64::new(re, im)
    }
}

/// The normal equations of the conformal energy through `dofs` (module docs), the
/// matrix's values in the order of `pattern`: the lower triangle (rows `>=` columns,
/// each column's rows increasing) of a pattern holding every pair of reduced unknowns
/// of the corners of one face, as
/// [`normal_pattern_of_cells`](crate::least_squares::normal_pattern_of_cells) of the faces gives.
///
/// Errors: [`FemError::Length`] for a quad, a mesh with other than `dofs.n_nodes()`
/// vertices or a pattern of other than `dofs.reduced_len()` columns,
/// [`FemError::DegenerateElement`] for a face of (nearly) zero area,
/// [`FemError::Assembly`] when `pattern` lacks an entry the faces couple.
pub fn conformal_system(
    mesh: &Mesh,
    dofs: &DofMap<Complex64>,
    pattern: SymbolicSparseColMatRef<'_, usize>,
) -> Result<ConformalSystem, FemError> {
    let n = dofs.reduced_len();
    if dofs.n_nodes() != mesh.vertex_count() {
        return Err(FemError::Length {
            what: "the nodes of the DOF map",
            expected: mesh.vertex_count(),
            got: dofs.n_nodes(),
        });
    }
    if pattern.ncols() != n || pattern.nrows() != n {
        return Err(FemError::Length {
            what: "the columns of the pattern",
            expected: n,
            got: pattern.ncols(),
        });
    }
    let zero = Complex64::new(0.0, 0.0);
    let mut values = vec![zero; pattern.row_idx().len()];
    let mut rhs = vec![zero; n];
    let x0 = dofs.x0();
    // The terms of the face's corners: (corner, unknown, coefficient).
    let mut terms: Vec<(usize, usize, Complex64)> = Vec::with_capacity(6);
    for f in mesh.faces() {
        let (face, nodes) = Face::new(mesh, f)?;
        terms.clear();
        for (k, &v) in nodes.iter().enumerate() {
            let range = dofs
                .terms(VertexId::from_usize(v))
                .map_err(|_| FemError::Length {
                    what: "the nodes of the DOF map",
                    expected: mesh.vertex_count(),
                    got: dofs.n_nodes(),
                })?;
            for t in range {
                // A complex-form map has one component per node.
                if let Some(term) = dofs.term(t) {
                    terms.push((k, term.dof, term.direction[0]));
                }
            }
        }
        for &(j, c, kappa_j) in &terms {
            let conj_j = kappa_j.conj();
            for &(k, d, kappa_k) in &terms {
                if c < d {
                    continue;
                }
                let value = conj_j * face.entry(j, k) * kappa_k;
                let column = pattern.row_idx_of_col_raw(d);
                let Some(position) = column.iter().position(|&row| row == c) else {
                    return Err(FemError::Assembly(format!(
                        "the pattern has no entry at row {c}, column {d}, which face {f} couples"
                    )));
                };
                let at = pattern.col_ptr()[d] + position;
                // The diagonal of a Hermitian matrix is real; only rounding adds to its
                // imaginary part.
                values[at] += if c == d {
                    Complex64::new(value.re, 0.0)
                } else {
                    value
                };
            }
            for (k, &v) in nodes.iter().enumerate() {
                let x0_k = x0[v];
                if x0_k != zero {
                    rhs[c] -= conj_j * face.entry(j, k) * x0_k;
                }
            }
        }
    }
    Ok(ConformalSystem { values, rhs })
}

/// The conformal energy `E_C = sum_f A_f |f_zbar|^2` of the planar map `map` (one image
/// per vertex) of a triangle mesh, `f_zbar` in an orthonormal frame of each face
/// (module docs): `A |f_zbar|^2 = |sum_k e_k x_k|^2 / (16 A)`, summed face by face, so it
/// is never negative and vanishes to rounding on a conformal map.
///
/// Errors: as [`conformal_system`] for the faces, [`FemError::Length`] when `map` has
/// not one value per vertex, [`FemError::NonFinite`] for a non-finite image.
pub fn conformal_energy(mesh: &Mesh, map: &[Complex64]) -> Result<f64, FemError> {
    crate::beltrami::check_planar_map(mesh.vertex_count(), map)?;
    let faces = |range: Range<usize>| {
        range.map(FaceId::from_usize).try_fold(0.0, |energy, f| {
            let (face, nodes) = Face::new(mesh, f)?;
            // A frame of the face: `u` along side 2, `w` a quarter turn from it.
            let u = face.sides[2].normalize();
            let w = face.sides[2]
                .cross(&face.sides[0])
                .cross(&face.sides[2])
                .normalize();
            let sum: Complex64 = (0..3)
                .map(|k| {
                    Complex64::new(face.sides[k].dot(&u), face.sides[k].dot(&w)) * map[nodes[k]]
                })
                .sum();
            Ok::<_, FemError>(energy + sum.norm_sqr() * face.scale)
        })
    };
    // Blocks of faces on all cores, summed in block order: the same value for any
    // number of threads.
    map_blocks(mesh.face_count(), ENERGY_BLOCK, available_threads(), faces)
        .into_iter()
        .sum()
}

/// Faces per block of [`conformal_energy`]'s sum.
const ENERGY_BLOCK: usize = 1 << 14;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dof::DofConstraints;
    use crate::least_squares::normal_pattern_of_cells;
    use crate::operators::beltrami_operator;
    use crate::{Elements, Frame};
    use beltrami_mesh::primitives::{Cells, jittered_grid};
    use faer::Mat;
    use faer::sparse::SymbolicSparseColMat;

    /// A jittered 7 x 7 grid bent into a saddle (a curved disk), with a face
    /// orientation that varies in the plane.
    fn saddle() -> Mesh {
        saddle_of(7)
    }

    /// [`saddle`] on a `k x k` grid.
    fn saddle_of(k: usize) -> Mesh {
        let mut soup = jittered_grid(k, k, Cells::Triangles, 0.3, 5);
        for p in &mut soup.positions {
            p.z = 0.6 * (p.x - 0.5) * (p.y - 0.5) + 0.2 * p.x * p.x;
        }
        Mesh::from_soup(&soup).expect("a saddle grid is a valid mesh")
    }

    fn pattern_of(mesh: &Mesh, dofs: &DofMap<Complex64>) -> SymbolicSparseColMat<usize> {
        let faces = (0..mesh.face_count()).map(|f| mesh.face_vertices(FaceId::from_usize(f)));
        normal_pattern_of_cells(faces, dofs).expect("the faces' pattern")
    }

    /// `D_zbar` of the elements (one point per triangle) and its weights, dense.
    fn dense_dzbar(mesh: &Mesh) -> (Mat<Complex64>, Vec<f64>) {
        let elements = Elements::new(mesh, Frame::Face).unwrap();
        let zero = vec![Complex64::new(0.0, 0.0); mesh.face_count()];
        let dzbar = beltrami_operator(mesh, &elements, &zero).unwrap();
        let weights = elements.points().iter().map(|q| q.weight).collect();
        (dzbar.to_dense(), weights)
    }

    /// `K^H D^H W D K` and `-K^H D^H W D x0`, the normal equations of LSCM through
    /// elements, assembled densely: the system the sides must reproduce.
    #[test]
    fn the_system_is_the_normal_equations_of_d_zbar() {
        let mesh = saddle();
        let mut constraints = DofConstraints::new();
        constraints
            .fix(VertexId(0), Complex64::new(0.0, 0.0))
            .fix(VertexId(6), Complex64::new(1.0, 0.5))
            .share(VertexId(10), VertexId(30));
        let dofs = DofMap::complex(mesh.vertex_count(), &constraints).unwrap();
        let pattern = pattern_of(&mesh, &dofs);
        let system = conformal_system(&mesh, &dofs, pattern.as_ref()).unwrap();

        let (d, w) = dense_dzbar(&mesh);
        let k = dofs.k().to_dense();
        let b = &d * &k;
        let x0 = Mat::from_fn(mesh.vertex_count(), 1, |i, _| dofs.x0()[i]);
        let r = &d * &x0;
        let n = dofs.reduced_len();
        let mut expected = Mat::<Complex64>::zeros(n, n);
        let mut expected_rhs = vec![Complex64::new(0.0, 0.0); n];
        for q in 0..b.nrows() {
            for c in 0..n {
                expected_rhs[c] -= b[(q, c)].conj() * w[q] * r[(q, 0)];
                for e in 0..n {
                    expected[(c, e)] += b[(q, c)].conj() * w[q] * b[(q, e)];
                }
            }
        }
        let scale = expected.norm_max();
        let mut stored = 0;
        for c in 0..n {
            for (row, value) in pattern
                .row_idx_of_col(c)
                .zip(&system.values[pattern.col_range(c)])
            {
                assert!(
                    (value - expected[(row, c)]).norm() <= 1e-13 * scale,
                    "({row}, {c}): {value} against {}",
                    expected[(row, c)]
                );
                if row == c {
                    assert_eq!(value.im, 0.0);
                }
                stored += 1;
            }
        }
        // Nothing the dense product holds is missing from the pattern.
        let nonzero = (0..n)
            .flat_map(|c| (c..n).map(move |row| (row, c)))
            .filter(|&(row, c)| expected[(row, c)].norm() > 1e-13 * scale)
            .count();
        assert_eq!(stored, nonzero);
        for (got, want) in system.rhs.iter().zip(&expected_rhs) {
            assert!((got - want).norm() <= 1e-13 * scale, "{got} against {want}");
        }
    }

    /// With every vertex free, the imaginary part is `+-1/8` on the boundary edges
    /// (their direction along the boundary gives the sign) and exactly zero elsewhere:
    /// the two faces of an interior edge cancel in binary.
    #[test]
    fn the_imaginary_part_lives_on_boundary_edges_only() {
        let mesh = saddle();
        let dofs = DofMap::complex(mesh.vertex_count(), &DofConstraints::new()).unwrap();
        let pattern = pattern_of(&mesh, &dofs);
        let system = conformal_system(&mesh, &dofs, pattern.as_ref()).unwrap();
        let mut boundary = std::collections::HashMap::new();
        for h in mesh.halfedges() {
            if mesh.is_boundary_halfedge(mesh.twin(h)) {
                // h runs along the boundary inside its face.
                boundary.insert((mesh.origin(h).idx(), mesh.target(h).idx()), ());
            }
        }
        let mut on_boundary = 0;
        for c in 0..pattern.ncols() {
            for (row, value) in pattern
                .row_idx_of_col(c)
                .zip(&system.values[pattern.col_range(c)])
            {
                // C[row, c] has +1/8 when c follows row in a face: the face's halfedge
                // runs row -> c.
                let expected = if boundary.contains_key(&(row, c)) {
                    0.125
                } else if boundary.contains_key(&(c, row)) {
                    -0.125
                } else {
                    0.0
                };
                assert_eq!(value.im, expected, "({row}, {c})");
                on_boundary += usize::from(expected != 0.0);
            }
        }
        assert_eq!(on_boundary, boundary.len());
    }

    /// The energy face by face equals the Hermitian form `x^H C x`, is positive on a
    /// general map and vanishes on a similarity of a planar mesh.
    #[test]
    fn the_energy_is_the_hermitian_form_and_vanishes_on_similarities() {
        // 72 faces, one block of the sum; 33,282 faces, three blocks on all cores.
        for k in [7, 130] {
            let mesh = saddle_of(k);
            let dofs = DofMap::complex(mesh.vertex_count(), &DofConstraints::new()).unwrap();
            let pattern = pattern_of(&mesh, &dofs);
            let values = conformal_system(&mesh, &dofs, pattern.as_ref())
                .unwrap()
                .values;
            let map: Vec<Complex64> = mesh
                .vertices()
                .map(|v| {
                    let p = mesh.position(v);
                    Complex64::new(p.x + 0.3 * p.y * p.y, p.y - 0.2 * p.x * p.z)
                })
                .collect();
            // The form sums terms far larger than the energy, which cancel: its rounding
            // grows with their magnitude.
            let (mut form, mut magnitude) = (0.0, 0.0);
            for c in 0..pattern.ncols() {
                for (row, value) in pattern.row_idx_of_col(c).zip(&values[pattern.col_range(c)]) {
                    let term = map[row].conj() * value * map[c];
                    let term = if row == c { term.re } else { 2.0 * term.re };
                    form += term;
                    magnitude += term.abs();
                }
            }
            let energy = conformal_energy(&mesh, &map).unwrap();
            assert!(energy > 1e-3, "{energy}");
            // Measured: 1.9e-15 and 4.2e-13 (1.3e-17 of the magnitude).
            let tolerance = if k == 7 {
                1e-12 * energy
            } else {
                1e-15 * magnitude
            };
            assert!(
                (energy - form).abs() <= tolerance,
                "{k} x {k}: {energy} against {form}"
            );
        }

        let flat = Mesh::from_soup(&jittered_grid(7, 7, Cells::Triangles, 0.3, 5)).unwrap();
        let (a, b) = (Complex64::new(0.6, -1.3), Complex64::new(2.0, 0.5));
        let similar: Vec<Complex64> = flat
            .vertices()
            .map(|v| {
                let p = flat.position(v);
                a * Complex64::new(p.x, p.y) + b
            })
            .collect();
        let energy = conformal_energy(&flat, &similar).unwrap();
        assert!(energy < 1e-28, "{energy:e}");
    }

    #[test]
    fn quads_degenerate_faces_and_short_patterns_are_refused() {
        let quads = Mesh::from_soup(&jittered_grid(3, 3, Cells::Quads, 0.2, 1)).unwrap();
        let dofs = DofMap::complex(quads.vertex_count(), &DofConstraints::new()).unwrap();
        let pattern = pattern_of(&quads, &dofs);
        assert!(matches!(
            conformal_system(&quads, &dofs, pattern.as_ref()),
            Err(FemError::Length { got: 4, .. })
        ));

        // A grid laid out again with one face's three corners on a line (the mesh
        // itself refuses such faces; a layout may make them).
        let grid = Mesh::from_soup(&jittered_grid(3, 3, Cells::Triangles, 0.0, 1)).unwrap();
        let f = FaceId(4);
        let (v, _) = grid.face_vertex_array(f);
        let mut positions = grid.positions().to_vec();
        positions[v[2].idx()] =
            Point3::from((positions[v[0].idx()].coords + positions[v[1].idx()].coords) / 2.0);
        let flat = grid.with_positions(positions).unwrap();
        let dofs = DofMap::complex(flat.vertex_count(), &DofConstraints::new()).unwrap();
        let pattern = pattern_of(&flat, &dofs);
        assert!(matches!(
            conformal_system(&flat, &dofs, pattern.as_ref()),
            Err(FemError::DegenerateElement { face, .. }) if face == f
        ));
        let zero = vec![Complex64::new(0.0, 0.0); flat.vertex_count()];
        assert!(matches!(
            conformal_energy(&flat, &zero),
            Err(FemError::DegenerateElement { .. })
        ));

        let mesh = saddle();
        let dofs = DofMap::complex(mesh.vertex_count(), &DofConstraints::new()).unwrap();
        let n = dofs.reduced_len();
        let diagonal =
            SymbolicSparseColMat::new_checked(n, n, (0..=n).collect(), None, (0..n).collect());
        match conformal_system(&mesh, &dofs, diagonal.as_ref()) {
            Err(FemError::Assembly(message)) => assert!(message.contains("face"), "{message}"),
            other => panic!("expected an assembly error, got {other:?}"),
        }
        let short = vec![Complex64::new(0.0, 0.0); 3];
        assert!(matches!(
            conformal_energy(&mesh, &short),
            Err(FemError::Length { got: 3, .. })
        ));
    }
}
