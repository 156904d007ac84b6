//! A map of a mesh into the plane that takes given vertices exactly to given points and
//! flips no face: the landmark-matching quasiconformal map of Lam and Lui (K. C. Lam,
//! L. M. Lui, "Landmark- and intensity-based registration with large deformations via
//! quasi-conformal maps", SIAM J. Imaging Sci. 7, 2014, section 4, algorithm 1).
//!
//! Each step solves the linear Beltrami equation `f_zbar = nu f_z` in the least-squares
//! sense, `min sum_q w_q |f_zbar(q) - nu_q f_z(q)|^2` with the fixed vertices as
//! Dirichlet values (`beltrami_fem::operators::beltrami_operator`, one symbolic
//! factorization for all steps). The first step takes the coefficient of a given
//! initial map (a conformal parameterization, whose `mu` is its discretization error):
//! with every fixed vertex where the initial map puts it, the equation holds exactly on
//! every face and the solution is the initial map itself; moved fixed vertices bend it
//! as little as the least-squares sense allows. While faces are flipped, the coefficient of the map just
//! found is smoothed (each face averaged with its edge neighbours, weighted by area, the
//! neighbours' values carried into the face's frame) and cut to `|nu| <= K_MAX`, and the
//! equation solved again: a map with `|mu| < 1` on every face is a local homeomorphism,
//! and with its boundary fixed a bijection. The first map without flips is returned.
//!
//! Coefficients live in each face's own frame ([`Frame::Face`]) or in the plane's
//! ([`Frame::Global`]); across an edge a neighbour's value is rotated into the face's
//! frame by `mu e^{-2 i theta}` (Gruber-Aulisa 2022, Lemma 3.4), `theta` the angle
//! between the two frames' real axes once the faces are unfolded about the edge.

use beltrami_fem::beltrami::{face_mu, flipped_faces, planar_map, point_mu};
use beltrami_fem::operators::beltrami_operator;
use beltrami_fem::{DofBuilder, DofError, DofMap, Elements, Frame, LeastSquaresSolver};
use beltrami_mesh::{FaceId, Mesh, VertexId};
use beltrami_sparse::SolveOptions;
use num_complex::Complex64;

use crate::error::{RegisterError, Side};

/// The largest `|nu|` a step solves for: below 1 with a margin, so that the least-squares
/// solution (which only approximates `nu`) stays orientation-preserving.
const K_MAX: f64 = 0.8;

/// Steps after the first at most.
const MAX_STEPS: usize = 60;

/// Relative residual at which a rebuild solved by conjugate gradients, preconditioned
/// with the factorization of an earlier step's system and started from the last
/// rebuild, is taken ([`Reconstruction::solve`]). A rebuild is a step's map, measured
/// (its own coefficient, its flips) and judged as it is, so a looser solve only makes
/// a slightly different step. fsaverage5 pial onto white, mean distance to the truth and
/// seconds of the feature match, at 1e-7, 1e-5 and 1e-4: by the sulcal depth 0.5844,
/// 0.5801 and 0.6099 mm in 1.80, 1.47-1.54 and 1.19-1.25 s; with 24 landmarks and the
/// sulcal depth 0.3924, 0.3915 and 0.4094 mm in 4.2-4.5, 3.7-3.8 and 2.5-2.6 s; by
/// shape 1.2747, 1.2746 and 1.2743 mm (`g0_spot` by shape 0.01386, 0.01382, 0.01423).
const CG_TOLERANCE: f64 = 1e-5;

/// Conjugate-gradient iterations a rebuild tries before it factors its own system: the
/// steps change `nu` a little, and three in four rebuilds of a feature match converge
/// within it (fsaverage5 pial onto white by the sulcal depth: 141 of 187, 787
/// iterations, the rebuilds 1.95 s -> 1.56 s, the same mean distance to the truth, 0.625 mm).
const CG_ITERATIONS: usize = 5;

/// Smoothing passes applied to the coefficient between two steps.
const SMOOTHING_PASSES: usize = 2;

/// Two vertices that move as one up to a translation: `x_b = x_a + offset`. The two
/// copies of a seam vertex of a torus cut into its square, in the universal cover
/// `R^2` of `R^2 / Z^2`, differ by a lattice vector.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Glue {
    pub a: VertexId,
    pub b: VertexId,
    pub offset: Complex64,
}

/// A landmark-matching map and how it was found.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Matched {
    /// The image of every vertex; fixed vertices exactly at their values.
    pub map: Vec<Complex64>,
    /// Solves of the Beltrami equation after the first (0: the conformal one had no flip).
    pub steps: usize,
    /// Faces flipped in `map` that were not flipped in the initial map and have a free
    /// corner (0 unless the steps ran out).
    pub flipped: usize,
    /// Area-weighted mean `|mu|` of `map`.
    pub mean_mu: f64,
}

impl Matched {
    /// The matching, or [`RegisterError::LandmarkFolds`] (naming `domain`) when its steps
    /// ran out with faces still flipped.
    pub(crate) fn without_folds(self, domain: &'static str) -> Result<Self, RegisterError> {
        if self.flipped > 0 {
            return Err(RegisterError::LandmarkFolds {
                domain,
                flipped: self.flipped,
                steps: self.steps,
            });
        }
        Ok(self)
    }
}

/// The landmark-matching map of `mesh` bent from `initial` (one value per vertex) so
/// that the vertices of `fixed` are at their values (module docs), each pair of `glued`
/// moving as one (a fixed vertex fixes its glued partners at their offsets). Faces whose
/// corners are all fixed, and faces the initial map flips, are not judged: the steps
/// mend only the flips the matching makes. `side` names the mesh in errors.
///
/// # Errors
/// [`RegisterError::Elements`] for a degenerate face, [`RegisterError::Measure`] for an
/// initial map of the wrong length or with a non-finite value, [`RegisterError::Solve`]
/// when the fixed vertices leave the system singular (a part of the mesh with no fixed
/// vertex).
pub(crate) fn match_landmarks(
    mesh: &Mesh,
    frame: Frame,
    initial: &[Complex64],
    fixed: &[(VertexId, Complex64)],
    glued: &[Glue],
    side: Side,
) -> Result<Matched, RegisterError> {
    let (mut reconstruction, initial_nu) =
        Reconstruction::new(mesh, frame, initial, fixed, glued, side)?;
    let mut map = reconstruction.solve(&initial_nu)?;
    let mut steps = 0;
    loop {
        let (mu, flipped) = reconstruction.measure(&map)?;
        if flipped == 0 || steps == MAX_STEPS {
            let mean_mu = reconstruction.mean_mu(&mu);
            return Ok(Matched {
                map,
                steps,
                flipped,
                mean_mu,
            });
        }
        map = reconstruction.solve(&reconstruction.regularized(mu, SMOOTHING_PASSES))?;
        steps += 1;
    }
}

/// Planar maps of a mesh rebuilt from Beltrami coefficients with some vertices held:
/// the least-squares solution of `f_zbar = nu f_z` (module docs) for any `nu`, one
/// symbolic factorization for all.
pub(crate) struct Reconstruction<'m> {
    mesh: &'m Mesh,
    elements: Elements,
    solver: LeastSquaresSolver<Complex64>,
    weights: Vec<f64>,
    rhs: Vec<Complex64>,
    /// Faces judged for flips: not flipped by the initial map, with a free corner.
    solved: Vec<bool>,
    areas: Vec<f64>,
    neighbours: FaceNeighbours,
    side: Side,
}

impl<'m> Reconstruction<'m> {
    /// The reconstruction with the vertices of `fixed` at their values and those of
    /// `glued` moving as one, and the coefficient of `initial` (per face). Faces whose
    /// corners are all fixed, and faces `initial` flips, are not judged by
    /// [`Self::measure`].
    ///
    /// # Errors
    /// As [`match_landmarks`].
    pub(crate) fn new(
        mesh: &'m Mesh,
        frame: Frame,
        initial: &[Complex64],
        fixed: &[(VertexId, Complex64)],
        glued: &[Glue],
        side: Side,
    ) -> Result<(Self, Vec<Complex64>), RegisterError> {
        let elements =
            Elements::new(mesh, frame).map_err(|error| RegisterError::Elements { side, error })?;
        let initial_derivatives =
            planar_map(&elements, mesh.vertex_count(), initial).map_err(RegisterError::Measure)?;
        let initial_nu = face_mu(&elements, &point_mu(&initial_derivatives));
        let (dofs, is_fixed) = glued_dofs(mesh.vertex_count(), fixed, glued)
            .map_err(|error| RegisterError::Dofs { side, error })?;
        // A face with every corner fixed is the caller's: the map cannot change it; nor
        // are the initial map's own flips the matching's to mend (they stay with it).
        let flipped_before = flipped_faces(&elements, &initial_derivatives);
        let solved: Vec<bool> = mesh
            .faces()
            .map(|f| !flipped_before[f.idx()] && mesh.face_vertices(f).any(|v| !is_fixed[v.idx()]))
            .collect();
        let operator =
            beltrami_operator(mesh, &elements, &initial_nu).map_err(RegisterError::Measure)?;
        let solver = LeastSquaresSolver::new(operator.symbolic(), &dofs, SolveOptions::default())
            .map_err(|error| RegisterError::Solve { side, error })?;
        let weights: Vec<f64> = elements.points().iter().map(|q| q.weight).collect();
        let rhs = vec![Complex64::new(0.0, 0.0); operator.nrows()];
        let areas = elements.face_areas();
        let neighbours = FaceNeighbours::new(mesh, &elements);
        Ok((
            Self {
                mesh,
                elements,
                solver,
                weights,
                rhs,
                solved,
                areas,
                neighbours,
                side,
            },
            initial_nu,
        ))
    }

    /// The map whose coefficient is `nu` (per face) in the least-squares sense, with the
    /// held vertices at their values. Successive calls reuse the last factorization as a
    /// preconditioner ([`CG_ITERATIONS`]) and factor only when that does not converge.
    pub(crate) fn solve(&mut self, nu: &[Complex64]) -> Result<Vec<Complex64>, RegisterError> {
        let operator =
            beltrami_operator(self.mesh, &self.elements, nu).map_err(RegisterError::Measure)?;
        let side = self.side;
        let mut map = vec![Complex64::new(0.0, 0.0); self.mesh.vertex_count()];
        self.solver
            .solve_into_reusing(
                operator.as_ref(),
                Some(&self.weights),
                &self.rhs,
                &mut map,
                CG_TOLERANCE,
                CG_ITERATIONS,
            )
            .map_err(|error| RegisterError::Solve { side, error })?;
        Ok(map)
    }

    /// The coefficient of `map` per face and the number of judged faces it flips.
    pub(crate) fn measure(
        &self,
        map: &[Complex64],
    ) -> Result<(Vec<Complex64>, usize), RegisterError> {
        let (mu, folded) = self.measure_folds(map)?;
        Ok((mu, folded.iter().filter(|&&f| f).count()))
    }

    /// The coefficient of `map` per face and which judged faces it flips, by face index.
    pub(crate) fn measure_folds(
        &self,
        map: &[Complex64],
    ) -> Result<(Vec<Complex64>, Vec<bool>), RegisterError> {
        let derivatives = planar_map(&self.elements, self.mesh.vertex_count(), map)
            .map_err(RegisterError::Measure)?;
        let folded = flipped_faces(&self.elements, &derivatives)
            .into_iter()
            .zip(&self.solved)
            .map(|(f, &s)| f && s)
            .collect();
        Ok((face_mu(&self.elements, &point_mu(&derivatives)), folded))
    }

    /// `mu` smoothed over edge neighbours (`passes` times) and cut to `|nu| <= K_MAX`
    /// (module docs): a coefficient whose map is a local homeomorphism.
    pub(crate) fn regularized(&self, mu: Vec<Complex64>, passes: usize) -> Vec<Complex64> {
        let mut nu = mu;
        for _ in 0..passes {
            nu = self.neighbours.smooth(&nu, &self.areas);
        }
        nu.into_iter().map(cut).collect()
    }

    /// `mu` smoothed over edge neighbours (`passes` times) on the faces within `rings`
    /// edge steps of a face marked in `folded` only, and cut to `|nu| <= K_MAX`: the
    /// mending of a step that folds a few faces, which keeps the step's change of
    /// coefficient away from the folds (where [`Self::regularized`] smooths it all).
    pub(crate) fn regularized_near(
        &self,
        mu: Vec<Complex64>,
        folded: &[bool],
        rings: usize,
        passes: usize,
    ) -> Vec<Complex64> {
        let near = self.neighbours.grown(folded, rings);
        let mut nu = mu;
        for _ in 0..passes {
            let smooth = self.neighbours.smooth(&nu, &self.areas);
            for ((value, smoothed), &near) in nu.iter_mut().zip(smooth).zip(&near) {
                if near {
                    *value = smoothed;
                }
            }
        }
        nu.into_iter().map(cut).collect()
    }

    /// The coefficient of a step from a map with coefficient `current` towards one with
    /// `moved`: the change smoothed over edge neighbours (`passes` times) and added to
    /// `current`, each face cut to `|nu| <= K_MAX`. Only the change is smoothed: the
    /// map's own fine structure (a folded surface's conformal map has much) is kept, and
    /// a step of zero gives `current` back wherever `|current| <= K_MAX`.
    pub(crate) fn regularized_step(
        &self,
        current: &[Complex64],
        moved: &[Complex64],
        passes: usize,
    ) -> Vec<Complex64> {
        let mut change: Vec<Complex64> = moved.iter().zip(current).map(|(m, c)| m - c).collect();
        for _ in 0..passes {
            change = self.neighbours.smooth(&change, &self.areas);
        }
        current
            .iter()
            .zip(change)
            .map(|(&c, d)| cut(c + d))
            .collect()
    }

    /// The area-weighted mean of `|mu|` (each face's value capped at 1).
    pub(crate) fn mean_mu(&self, mu: &[Complex64]) -> f64 {
        let total: f64 = self.areas.iter().sum();
        mu.iter()
            .zip(&self.areas)
            .map(|(m, a)| m.norm().min(1.0) * a)
            .sum::<f64>()
            / total.max(f64::MIN_POSITIVE)
    }
}

/// The unknowns of a matching: vertices joined by `glued` form groups, each group one
/// unknown moving all its vertices alike (every vertex at its offset from the group's
/// first), or no unknown when one of its vertices is in `fixed`; and which vertices are
/// fixed. Vertices out of range are [`DofError`]s.
fn glued_dofs(
    n: usize,
    fixed: &[(VertexId, Complex64)],
    glued: &[Glue],
) -> Result<(DofMap<Complex64>, Vec<bool>), DofError> {
    let mut builder = DofBuilder::<Complex64>::new(n, 1)?;
    let mut partners: Vec<Vec<(usize, Complex64)>> = vec![Vec::new(); n];
    for g in glued {
        for (v, w, offset) in [(g.a, g.b, g.offset), (g.b, g.a, -g.offset)] {
            let slot = partners.get_mut(v.idx()).ok_or(DofError::NodeOutOfRange {
                node: v,
                n_nodes: n,
            })?;
            slot.push((w.idx(), offset));
        }
    }
    // Each group by a walk from its smallest vertex, with every vertex's offset from it.
    let mut group = vec![usize::MAX; n];
    let mut offset = vec![Complex64::new(0.0, 0.0); n];
    let mut members: Vec<Vec<usize>> = Vec::new();
    for start in 0..n {
        if group[start] != usize::MAX {
            continue;
        }
        let g = members.len();
        group[start] = g;
        let mut list = vec![start];
        let mut k = 0;
        while let Some(&v) = list.get(k) {
            for &(w, step) in &partners[v] {
                if group[w] == usize::MAX {
                    group[w] = g;
                    offset[w] = offset[v] + step;
                    list.push(w);
                }
            }
            k += 1;
        }
        members.push(list);
    }
    let mut value: Vec<Option<Complex64>> = vec![None; members.len()];
    for &(v, z) in fixed {
        let g = *group.get(v.idx()).ok_or(DofError::NodeOutOfRange {
            node: v,
            n_nodes: n,
        })?;
        value[g] = Some(z - offset[v.idx()]);
    }
    let mut is_fixed = vec![false; n];
    for (list, value) in members.iter().zip(&value) {
        for &v in list {
            let node = VertexId::from_usize(v);
            builder.origin(node, &[value.unwrap_or_default() + offset[v]])?;
            is_fixed[v] = value.is_some();
        }
        if value.is_none() {
            builder.unknown(
                list.iter()
                    .map(|&v| (VertexId::from_usize(v), [Complex64::new(1.0, 0.0)])),
            )?;
        }
    }
    Ok((builder.build()?, is_fixed))
}

/// `nu` scaled down to `|nu| = K_MAX` where it is larger.
fn cut(nu: Complex64) -> Complex64 {
    let r = nu.norm();
    if r > K_MAX { nu * (K_MAX / r) } else { nu }
}

/// The edge neighbours of every face with the factor `e^{-2 i theta}` that carries a
/// neighbour's coefficient into the face's frame (module docs).
struct FaceNeighbours {
    /// `start[f]..start[f + 1]` indexes `faces` and `carry` for face `f`.
    start: Vec<usize>,
    faces: Vec<FaceId>,
    carry: Vec<Complex64>,
}

impl FaceNeighbours {
    fn new(mesh: &Mesh, elements: &Elements) -> Self {
        let mut start = Vec::with_capacity(mesh.face_count() + 1);
        let (mut faces, mut carry) = (Vec::new(), Vec::new());
        let unit = |s: nalgebra::Vector2<f64>| Complex64::new(s.x, s.y) / s.norm();
        for f in mesh.faces() {
            start.push(faces.len());
            for (k, h) in mesh.face_halfedges(f).enumerate() {
                let twin = mesh.twin(h);
                let Some(g) = mesh.face(twin) else {
                    continue;
                };
                let Some(j) = mesh.face_halfedges(g).position(|x| x == twin) else {
                    continue;
                };
                // The shared edge in each frame, in f's direction.
                let in_f = unit(elements.sides(f)[k]);
                let in_g = -unit(elements.sides(g)[j]);
                let turn = in_f * in_g.conj();
                faces.push(g);
                carry.push(turn * turn);
            }
        }
        start.push(faces.len());
        Self {
            start,
            faces,
            carry,
        }
    }

    /// The faces marked in `faces` and those within `rings` edge steps of one.
    fn grown(&self, faces: &[bool], rings: usize) -> Vec<bool> {
        let mut region = faces.to_vec();
        for _ in 0..rings {
            let last = region.clone();
            for (f, marked) in region.iter_mut().enumerate() {
                *marked = *marked
                    || self.faces[self.start[f]..self.start[f + 1]]
                        .iter()
                        .any(|g| last[g.idx()]);
            }
        }
        region
    }

    /// Each face's value averaged with its neighbours', weighted by area.
    fn smooth(&self, nu: &[Complex64], areas: &[f64]) -> Vec<Complex64> {
        (0..nu.len())
            .map(|f| {
                let mut sum = nu[f] * areas[f];
                let mut weight = areas[f];
                for i in self.start[f]..self.start[f + 1] {
                    let g = self.faces[i].idx();
                    sum += nu[g] * self.carry[i] * areas[g];
                    weight += areas[g];
                }
                sum / weight
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use beltrami_mesh::primitives;

    /// A grid of `n x n` squares on `[0, 1]^2`, each cut into two triangles.
    fn square(n: usize) -> Mesh {
        Mesh::from_soup(&primitives::grid(n, n, primitives::Cells::Triangles)).unwrap()
    }

    fn boundary_fixed(mesh: &Mesh) -> Vec<(VertexId, Complex64)> {
        mesh.vertices()
            .filter(|&v| mesh.is_boundary_vertex(v))
            .map(|v| {
                let p = mesh.position(v);
                (v, Complex64::new(p.x, p.y))
            })
            .collect()
    }

    fn identity(mesh: &Mesh) -> Vec<Complex64> {
        mesh.positions()
            .iter()
            .map(|p| Complex64::new(p.x, p.y))
            .collect()
    }

    fn vertex_at(mesh: &Mesh, x: f64, y: f64) -> VertexId {
        mesh.vertices()
            .min_by(|&a, &b| {
                let d = |v: VertexId| {
                    let p = mesh.position(v);
                    (p.x - x).powi(2) + (p.y - y).powi(2)
                };
                d(a).total_cmp(&d(b))
            })
            .unwrap()
    }

    #[test]
    fn fixed_values_of_an_affine_map_give_that_map() {
        // Every boundary vertex and one interior vertex at the image of an affine map
        // with mu = (a_zbar / a_z): the conformal step does not reproduce it (mu = 0),
        // but nothing is flipped, so it is returned as it is; and the map is exact at
        // every fixed vertex.
        let mesh = square(12);
        let affine =
            |z: Complex64| Complex64::new(1.3, 0.2) * z + Complex64::new(0.1, 0.0) * z.conj();
        let mut fixed: Vec<_> = boundary_fixed(&mesh)
            .into_iter()
            .map(|(v, z)| (v, affine(z)))
            .collect();
        let inner = vertex_at(&mesh, 0.5, 0.5);
        let p = mesh.position(inner);
        fixed.push((inner, affine(Complex64::new(p.x, p.y))));
        let matched = match_landmarks(
            &mesh,
            Frame::Global,
            &identity(&mesh),
            &fixed,
            &[],
            Side::Source,
        )
        .unwrap();
        assert_eq!(matched.flipped, 0);
        assert_eq!(matched.steps, 0);
        for &(v, z) in &fixed {
            assert_eq!(matched.map[v.idx()], z, "vertex {v}");
        }
        // The least-squares map with these values is the affine map itself: its
        // coefficient is constant and the conformal energy's minimizer with an affine
        // boundary is affine (the Euler-Lagrange equation is Laplace's, solved exactly by
        // P1 on any mesh for linear data).
        for v in mesh.vertices() {
            let p = mesh.position(v);
            let want = affine(Complex64::new(p.x, p.y));
            assert!((matched.map[v.idx()] - want).norm() < 1e-12, "vertex {v}");
        }
    }

    #[test]
    fn a_landmark_moved_far_is_matched_without_flips() {
        // The boundary held, an interior landmark moved by 0.3 of the square: the
        // conformal map through it folds the faces next to the landmark (the
        // conformal energy's minimizer has a point singularity there), and the smoothed
        // coefficients of Lam-Lui's iteration unfold them.
        let mesh = square(24);
        let mut fixed = boundary_fixed(&mesh);
        let a = vertex_at(&mesh, 0.35, 0.5);
        let b = vertex_at(&mesh, 0.7, 0.5);
        fixed.push((a, Complex64::new(0.65, 0.5)));
        fixed.push((b, Complex64::new(0.85, 0.45)));
        let matched = match_landmarks(
            &mesh,
            Frame::Global,
            &identity(&mesh),
            &fixed,
            &[],
            Side::Source,
        )
        .unwrap();
        assert_eq!(matched.flipped, 0);
        assert!(matched.steps > 0, "the conformal step alone folds");
        for &(v, z) in &fixed {
            assert_eq!(matched.map[v.idx()], z, "vertex {v}");
        }
        // Every triangle keeps its orientation.
        for f in mesh.faces() {
            let [p, q, r] = {
                let (vs, _) = mesh.face_vertex_array(f);
                [vs[0], vs[1], vs[2]].map(|v| matched.map[v.idx()])
            };
            let area = ((q - p).conj() * (r - p)).im;
            assert!(area > 0.0, "face {f} has area {area}");
        }
        assert!(matched.mean_mu < 0.5, "{}", matched.mean_mu);
    }

    #[test]
    fn fixed_vertices_where_the_initial_map_puts_them_give_the_initial_map() {
        // A smooth map that is neither conformal nor affine, on a jittered grid: with the
        // boundary and two interior vertices at its values, the solution is the map
        // itself (its own coefficient solves the equation exactly on every face).
        let mesh = Mesh::from_soup(&primitives::jittered_grid(
            16,
            16,
            primitives::Cells::Triangles,
            0.2,
            7,
        ))
        .unwrap();
        let bend = |z: Complex64| z + 0.15 * z * z + 0.1 * z.conj() * z.conj() * z;
        let initial: Vec<Complex64> = identity(&mesh).into_iter().map(bend).collect();
        let mut fixed: Vec<_> = boundary_fixed(&mesh)
            .into_iter()
            .map(|(v, _)| (v, initial[v.idx()]))
            .collect();
        for (x, y) in [(0.3, 0.4), (0.7, 0.6)] {
            let v = vertex_at(&mesh, x, y);
            fixed.push((v, initial[v.idx()]));
        }
        let matched =
            match_landmarks(&mesh, Frame::Face, &initial, &fixed, &[], Side::Source).unwrap();
        assert_eq!((matched.flipped, matched.steps), (0, 0));
        for v in mesh.vertices() {
            let d = (matched.map[v.idx()] - initial[v.idx()]).norm();
            assert!(d < 1e-12, "vertex {v}: {d}");
        }
        assert!(matched.mean_mu > 0.05, "the bend is not conformal");
    }

    #[test]
    fn mending_near_the_folds_unfolds_and_keeps_the_rest() {
        // A bend of the square (not conformal: its coefficient varies over every face)
        // with one interior vertex pushed past its neighbour, so that a few faces fold:
        // smoothing the coefficient within two rings of the folds and rebuilding
        // unfolds them, and every face farther away keeps its coefficient exactly,
        // where smoothing it all changes them.
        let mesh = square(12);
        let bend = |z: Complex64| z + 0.15 * z * z + 0.1 * z.conj() * z.conj() * z;
        let mut map: Vec<Complex64> = identity(&mesh).into_iter().map(bend).collect();
        let fixed: Vec<_> = boundary_fixed(&mesh)
            .into_iter()
            .map(|(v, _)| (v, map[v.idx()]))
            .collect();
        let (mut reconstruction, _) =
            Reconstruction::new(&mesh, Frame::Face, &map, &fixed, &[], Side::Source).unwrap();
        let (pushed, past) = (
            vertex_at(&mesh, 0.5, 0.5),
            vertex_at(&mesh, 0.5 + 2.0 / 12.0, 0.5),
        );
        map[pushed.idx()] = map[past.idx()] + Complex64::new(0.02, 0.01);
        let (mu, folded) = reconstruction.measure_folds(&map).unwrap();
        let flipped = folded.iter().filter(|&&f| f).count();
        assert!(flipped > 0);
        assert_eq!(reconstruction.measure(&map).unwrap().1, flipped);

        let nu = reconstruction.regularized_near(mu.clone(), &folded, 2, 2);
        let rebuilt = reconstruction.solve(&nu).unwrap();
        assert_eq!(reconstruction.measure(&rebuilt).unwrap().1, 0);
        let everywhere = reconstruction.regularized(mu.clone(), 2);
        let near = reconstruction.neighbours.grown(&folded, 2);
        let (mut kept, mut changed) = (0, 0);
        for f in mesh.faces().filter(|f| !near[f.idx()]) {
            assert_eq!(nu[f.idx()], cut(mu[f.idx()]), "face {f}");
            kept += 1;
            changed += usize::from((everywhere[f.idx()] - mu[f.idx()]).norm() > 1e-6);
        }
        assert!(kept > mesh.face_count() / 2, "{kept} faces kept");
        assert!(
            changed > kept / 2,
            "smoothing it all changed {changed} of {kept}"
        );
    }

    #[test]
    fn coefficients_are_carried_between_face_frames() {
        // On a bent strip (two faces on either side of a crease), a constant coefficient
        // in the plane's frame, read in each face's frame, is the same field: carried
        // across the edge it must agree with the neighbour's own value.
        let mesh = square(3);
        let global = Elements::new(&mesh, Frame::Global).unwrap();
        let local = Elements::new(&mesh, Frame::Face).unwrap();
        let neighbours = FaceNeighbours::new(&mesh, &local);
        let mu = Complex64::new(0.3, -0.2);
        // The face frame's real axis makes angle theta with the plane's x axis: mu in
        // the face frame is mu e^{-2 i theta}.
        let in_face: Vec<Complex64> = mesh
            .faces()
            .map(|f| {
                let s = local.sides(f)[0];
                let g = global.sides(f)[0];
                let theta = g.y.atan2(g.x) - s.y.atan2(s.x);
                mu * Complex64::from_polar(1.0, -2.0 * theta)
            })
            .collect();
        for f in mesh.faces() {
            for i in neighbours.start[f.idx()]..neighbours.start[f.idx() + 1] {
                let g = neighbours.faces[i];
                let carried = in_face[g.idx()] * neighbours.carry[i];
                assert!((carried - in_face[f.idx()]).norm() < 1e-12, "{g} into {f}");
            }
        }
    }
}
