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
//!
//! The unknowns can be limited to the free vertices within a number of rings of edges
//! of a boundary vertex ([`crate::target::TargetGeometry::correction_rings`]); the
//! correction is zero beyond them (their Laplacian rows keep every edge, so the band's
//! inner edge is a zero Dirichlet condition).

use beltrami_core::SolverError;
use beltrami_fem::assembly::Pattern;
use beltrami_mesh::Vector3;
use beltrami_sparse::{SolveOptions, SpdSolver};
use faer::Mat;

use crate::target::Role;
use crate::untangle::Stars;

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
    /// The extension for triangles `faces` with vertex `roles` over the free vertices
    /// within `rings` rings of edges of a boundary vertex (`None`: every free vertex), or
    /// `None` when no vertex lies on a boundary curve (nothing to extend).
    pub fn new(
        faces: &[[usize; 3]],
        roles: &[Role],
        rings: Option<usize>,
        options: SolveOptions,
    ) -> Result<Option<Self>, SolverError> {
        if !roles.iter().any(|r| matches!(r, Role::Curve(_))) {
            return Ok(None);
        }
        let within = match rings {
            Some(rings) => band(faces, roles, rings),
            None => vec![true; roles.len()],
        };
        let mut index = vec![None; roles.len()];
        let mut n = 0;
        for (v, role) in roles.iter().enumerate() {
            if *role == Role::Free && within[v] {
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
                        // A free vertex beyond the band: its correction is zero.
                        None if roles[to] == Role::Free => {}
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

    /// Adds to every free vertex of `points` within the band the harmonic extension of
    /// `delta` (read at the other vertices only).
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

/// Whether each vertex is within `rings` edges of a boundary-curve vertex.
fn band(faces: &[[usize; 3]], roles: &[Role], rings: usize) -> Vec<bool> {
    let stars = Stars::new(faces, roles.len());
    let mut inside: Vec<bool> = roles.iter().map(|r| matches!(r, Role::Curve(_))).collect();
    let mut front: Vec<usize> = (0..roles.len()).filter(|&v| inside[v]).collect();
    for _ in 0..rings {
        let mut reached = Vec::new();
        for &v in &front {
            for &f in stars.of(v) {
                for &w in &faces[f] {
                    if !inside[w] {
                        inside[w] = true;
                        reached.push(w);
                    }
                }
            }
        }
        front = reached;
    }
    inside
}

#[cfg(test)]
mod tests {
    use beltrami_mesh::Point3;
    use beltrami_mesh::primitives::{Cells, grid};

    use super::*;

    /// The triangles and roles (boundary on curve 0) of the `n x n` unit-square grid.
    fn square(n: usize) -> (Vec<[usize; 3]>, Vec<Role>) {
        let soup = grid(n, n, Cells::Triangles);
        let faces = soup
            .faces()
            .map(|f| [f[0] as usize, f[1] as usize, f[2] as usize])
            .collect();
        let roles = soup
            .positions
            .iter()
            .map(|p| {
                let on = |x: f64| x.abs() < 1e-12 || (x - 1.0).abs() < 1e-12;
                if on(p.x) || on(p.y) {
                    Role::Curve(0)
                } else {
                    Role::Free
                }
            })
            .collect();
        (faces, roles)
    }

    /// The band of [`extend`]'s tests.
    const RINGS: usize = 8;

    fn extend(
        n: usize,
        rings: Option<usize>,
        shift: Vector3<f64>,
    ) -> (Vec<Role>, Vec<Vector3<f64>>) {
        let (faces, roles) = square(n);
        let mut extension = HarmonicExtension::new(&faces, &roles, rings, SolveOptions::default())
            .unwrap()
            .unwrap();
        let delta: Vec<Vector3<f64>> = roles
            .iter()
            .map(|r| {
                if *r == Role::Free {
                    Vector3::zeros()
                } else {
                    shift
                }
            })
            .collect();
        let mut points = vec![Point3::origin(); roles.len()];
        extension.apply(&delta, &mut points).unwrap();
        (roles, points.iter().map(|p| p.coords).collect())
    }

    #[test]
    fn a_shift_of_the_whole_boundary_shifts_an_interior_within_the_band() {
        // 12 x 12 cells: every vertex is within 6 rings of the boundary; 40 x 40 with the
        // whole interior.
        let shift = Vector3::new(0.3, -0.2, 0.1);
        for (n, rings) in [(12, Some(RINGS)), (40, None)] {
            let (roles, moved) = extend(n, rings, shift);
            for (v, m) in moved.iter().enumerate() {
                if roles[v] == Role::Free {
                    assert!((m - shift).norm() < 1e-12, "vertex {v} moved by {m}");
                }
            }
        }
    }

    #[test]
    fn beyond_the_band_nothing_moves_and_within_it_the_shift_fades() {
        let n = 40;
        let shift = Vector3::new(1.0, 0.0, 0.0);
        let (_, moved) = extend(n, Some(RINGS), shift);
        // Along the middle row, from the left boundary inwards.
        let row = n / 2;
        let along: Vec<f64> = (0..=n).map(|i| moved[row * (n + 1) + i].x).collect();
        // (`along[0]` is the boundary vertex itself, which `apply` leaves alone.)
        let fading = &along[1..=RINGS];
        assert!(fading.iter().all(|&x| x > 0.0), "{along:?}");
        assert!(fading.windows(2).all(|w| w[1] < w[0]), "{along:?}");
        assert!(
            along[1] > 0.5,
            "the first ring follows the boundary: {along:?}"
        );
        let beyond = &along[RINGS + 1..=n / 2];
        assert!(beyond.iter().all(|&x| x == 0.0), "{along:?}");
    }
}
