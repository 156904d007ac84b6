//! The weighted-mean (Tutte) linear system of a fixed boundary: every vertex that is not
//! fixed sits at the weighted mean of its neighbours,
//!
//! ```text
//! sum_j w_ij (x_i - x_j) = 0            for every unknown vertex i,
//! ```
//!
//! with edge weights `w_ij` ([`EdgeWeights`]) and the boundary vertices fixed at the
//! positions `x_b` of a [`BoundaryMap`]. This is the sparse system
//! `L_II x_I = L_IB x_B` with `(L_II)_ii = sum_j w_ij`, `(L_II)_ij = -w_ij` and
//! right-hand side `sum_{j fixed} w_ij x_j`, solved once for the real and once for the
//! imaginary parts. Symmetric weights (uniform, cotangent) make `L_II` symmetric positive
//! definite (a Laplacian with Dirichlet rows removed), solved by sparse Cholesky
//! ([`solve_spd`]); mean-value weights are not symmetric and go through a sparse LU with
//! partial pivoting (faer). For positive weights `L_II` is an irreducibly diagonally
//! dominant M-matrix, so the system is nonsingular.
//!
//! It is the linear system of Tutte's embedding (W. T. Tutte, "How to draw a graph",
//! Proc. London Math. Soc. 13, 1963; M. S. Floater, "One-to-one piecewise linear
//! mappings over triangulations", Math. Comp. 72, 2003) and, with cotangent weights, of
//! the discrete harmonic map with a fixed boundary.

use beltrami_mesh::VertexId;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::LuError;
use faer::sparse::linalg::lu::{NumericLu, factorize_symbolic_lu};
use faer::sparse::{FaerError, SparseColMat, Triplet};
use faer::{Conj, Mat, Par};
use num_complex::Complex64;

use crate::boundary::BoundaryMap;
use crate::weights::EdgeWeights;
use beltrami_sparse::solve_spd;
use beltrami_sparse::{SolveError, SolveOptions};

/// The weighted-mean system of a fixed boundary (module docs): `L_II x_I = b`, with one
/// right-hand side column for the real and one for the imaginary parts.
#[derive(Debug, Clone)]
pub struct WeightedMeanSystem {
    /// `L_II` (rows and columns in the order of `interior`).
    matrix: SparseColMat<usize, f64>,
    /// `sum_{j fixed} w_ij x_j`, real parts in column 0, imaginary parts in column 1.
    rhs: Mat<f64>,
    /// The unknown vertices, in unknown order.
    interior: Vec<VertexId>,
    /// The map so far: the fixed values, zero elsewhere.
    map: Vec<Complex64>,
    symmetric: bool,
}

impl WeightedMeanSystem {
    /// Assembles the system of `weights` with the vertices of `boundary` fixed; every
    /// other vertex is an unknown.
    ///
    /// Errors: [`SolveError::Length`] if the weights are not of a mesh with a vertex for
    /// every boundary vertex, [`SolveError::Faer`] if the matrix cannot be built.
    pub fn new(weights: &EdgeWeights, boundary: &BoundaryMap) -> Result<Self, SolveError> {
        let n = weights.vertex_count();
        let mut slot = vec![usize::MAX; n];
        let mut map = vec![Complex64::new(0.0, 0.0); n];
        let mut fixed = vec![false; n];
        for (&v, &z) in boundary.vertices.iter().zip(&boundary.positions) {
            if v.idx() >= n {
                return Err(SolveError::Length {
                    what: "the vertex count of the weights",
                    expected: v.idx() + 1,
                    got: n,
                });
            }
            fixed[v.idx()] = true;
            map[v.idx()] = z;
        }
        let interior: Vec<VertexId> = (0..n)
            .filter(|&i| !fixed[i])
            .map(VertexId::from_usize)
            .collect();
        for (k, v) in interior.iter().enumerate() {
            slot[v.idx()] = k;
        }
        let mut triplets = Vec::new();
        let mut rhs = Mat::<f64>::zeros(interior.len(), 2);
        for (k, &v) in interior.iter().enumerate() {
            let mut diagonal = 0.0;
            for (j, w) in weights.row(v) {
                diagonal += w;
                if fixed[j.idx()] {
                    rhs[(k, 0)] += w * map[j.idx()].re;
                    rhs[(k, 1)] += w * map[j.idx()].im;
                } else {
                    triplets.push(Triplet::new(k, slot[j.idx()], -w));
                }
            }
            triplets.push(Triplet::new(k, k, diagonal));
        }
        let matrix = SparseColMat::try_new_from_triplets(interior.len(), interior.len(), &triplets)
            .map_err(|e| match e {
                faer::sparse::CreationError::Generic(e) => SolveError::Faer(e),
                // Indices are below the interior count by construction.
                faer::sparse::CreationError::OutOfBounds { .. } => {
                    SolveError::Faer(FaerError::IndexOverflow)
                }
            })?;
        Ok(Self {
            matrix,
            rhs,
            interior,
            map,
            symmetric: weights.is_symmetric(),
        })
    }

    /// The unknown (interior) vertices, in unknown order.
    pub fn interior(&self) -> &[VertexId] {
        &self.interior
    }

    /// Solves the system: sparse Cholesky for symmetric weights, sparse LU otherwise.
    /// Returns the image of every vertex (the fixed boundary values included).
    ///
    /// Errors: [`SolveError::NotPositiveDefinite`] or [`SolveError::Singular`] (naming
    /// the vertex where the LU broke down) for a singular system,
    /// [`SolveError::NonFiniteSolution`].
    pub fn solve(&self, options: SolveOptions) -> Result<Vec<Complex64>, SolveError> {
        let x = if self.symmetric {
            solve_spd(self.matrix.as_ref(), self.rhs.as_ref(), options)?
        } else {
            self.solve_lu()?
        };
        let mut map = self.map.clone();
        for (k, v) in self.interior.iter().enumerate() {
            map[v.idx()] = Complex64::new(x[(k, 0)], x[(k, 1)]);
        }
        Ok(map)
    }

    /// Sparse LU with partial pivoting (faer), both right-hand sides at once.
    fn solve_lu(&self) -> Result<Mat<f64>, SolveError> {
        let size = self.interior.len();
        let mut x = self.rhs.clone();
        if size == 0 {
            return Ok(x);
        }
        let symbolic = factorize_symbolic_lu(self.matrix.symbolic(), Default::default())?;
        let scratch = symbolic
            .factorize_numeric_lu_scratch::<f64>(Par::Seq, Default::default())
            .or(symbolic.solve_in_place_scratch::<f64>(2, Par::Seq));
        let mut buffer = MemBuffer::try_new(scratch).map_err(FaerError::from)?;
        let mut numeric = NumericLu::new();
        let lu = symbolic
            .factorize_numeric_lu(
                &mut numeric,
                self.matrix.as_ref(),
                Par::Seq,
                MemStack::new(&mut buffer),
                Default::default(),
            )
            .map_err(|e| match e {
                // The index counts columns in the fill-reducing column order.
                LuError::SymbolicSingular { index } => {
                    let index = symbolic.col_perm().arrays().0[index.min(size - 1)];
                    SolveError::Singular {
                        index,
                        node: Some(self.interior[index].idx()),
                        ratio: 0.0,
                    }
                }
                LuError::Generic(e) => SolveError::Faer(e),
            })?;
        lu.solve_in_place_with_conj(Conj::No, x.as_mut(), Par::Seq, MemStack::new(&mut buffer));
        for j in 0..2 {
            if let Some(i) = (0..size).find(|&i| !x[(i, j)].is_finite()) {
                return Err(SolveError::NonFiniteSolution {
                    index: i + j * size,
                });
            }
        }
        Ok(x)
    }
}
