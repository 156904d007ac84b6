//! Spreading the boundary's projection into the interior.
//!
//! A step moves boundary vertices along the tangent of their curve and then projects them
//! back onto it; on a curved boundary that pulls them inwards by `O(t^2 |V|^2)`, while
//! their interior neighbours move straight and would cross the boundary on a fine mesh.
//! Wong-Zhao (2014, section 4.4) "interpolate the projection movement to adjust the
//! interior points": here the correction `delta_j` of the boundary vertices (zero at
//! fixed vertices) is extended harmonically, `L_II delta_I = -L_IB delta_B`, with the
//! uniform graph Laplacian of the source mesh (each face edge weight 1, so positive
//! weights and a maximum principle: interior corrections are averages of boundary ones).
//! The Laplacian never changes, so it is factored once.

use beltrami_core::SolverError;
use beltrami_fem::assembly::Pattern;
use beltrami_fem::{SolveOptions, SpdSolver};
use beltrami_mesh::Vector3;
use faer::Mat;

use crate::target::Role;

/// The factored interior Laplacian and the couplings to the boundary.
pub struct HarmonicExtension {
    /// The unknown of each free vertex.
    index: Vec<Option<usize>>,
    /// `(unknown, boundary vertex)` per face edge from a free to a non-free vertex.
    couplings: Vec<(usize, usize)>,
    solver: SpdSolver<f64>,
    rhs: Mat<f64>,
}

impl std::fmt::Debug for HarmonicExtension {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("HarmonicExtension")
            .field("unknowns", &self.rhs.nrows())
            .finish_non_exhaustive()
    }
}

impl HarmonicExtension {
    /// The extension for triangles `faces` with vertex `roles`, or `None` when no vertex
    /// lies on a boundary curve (nothing to extend).
    pub fn new(
        faces: &[[usize; 3]],
        roles: &[Role],
        options: SolveOptions,
    ) -> Result<Option<Self>, SolverError> {
        if !roles.iter().any(|r| matches!(r, Role::Curve(_))) {
            return Ok(None);
        }
        let mut index = vec![None; roles.len()];
        let mut n = 0;
        for (v, role) in roles.iter().enumerate() {
            if *role == Role::Free {
                index[v] = Some(n);
                n += 1;
            }
        }
        let mut positions = Vec::new();
        let mut values = Vec::new();
        let mut couplings = Vec::new();
        for face in faces {
            for k in 0..3 {
                let (a, b) = (face[k], face[(k + 1) % 3]);
                for (from, to) in [(a, b), (b, a)] {
                    let Some(i) = index[from] else { continue };
                    positions.push((i, i));
                    values.push(1.0);
                    match index[to] {
                        Some(j) if j < i => {
                            positions.push((i, j));
                            values.push(-1.0);
                        }
                        Some(_) => {}
                        None => couplings.push((i, to)),
                    }
                }
            }
        }
        if n == 0 {
            return Ok(None);
        }
        let pattern = Pattern::new(n, n, &positions)?;
        let mut solver = SpdSolver::new(pattern.symbolic().as_ref(), options)?;
        solver.factorize(pattern.assemble(&values)?.as_ref())?;
        Ok(Some(Self {
            index,
            couplings,
            solver,
            rhs: Mat::zeros(n, 3),
        }))
    }

    /// Adds to every free vertex of `points` the harmonic extension of `delta` (read at
    /// the other vertices only).
    pub fn apply(
        &mut self,
        delta: &[Vector3<f64>],
        points: &mut [beltrami_mesh::Point3<f64>],
    ) -> Result<(), SolverError> {
        self.rhs.fill(0.0);
        let mut any = false;
        for &(i, v) in &self.couplings {
            let d = delta[v];
            if d != Vector3::zeros() {
                any = true;
                for c in 0..3 {
                    self.rhs[(i, c)] += d[c];
                }
            }
        }
        if !any {
            return Ok(());
        }
        self.solver.solve_in_place(self.rhs.as_mut())?;
        for (v, i) in self.index.iter().enumerate() {
            if let Some(i) = *i {
                points[v] += Vector3::new(self.rhs[(i, 0)], self.rhs[(i, 1)], self.rhs[(i, 2)]);
            }
        }
        Ok(())
    }
}
