//! The optimal-step non-rigid ICP of Amberg, Romdhani and Vetter (CVPR 2007): the
//! placed source deformed onto the target by one affine map per vertex.
//!
//! With `h_i = (v_i, 1)` a source vertex in homogeneous coordinates and `X_i` its 4 x 3
//! affine map (so the vertex moves to `h_i^T X_i`), each round minimizes
//!
//! `E(X) = alpha^2 sum_{edges ij} |G (X_i - X_j)|_F^2 + sum_i w_i^2 |h_i^T X_i - u_i|^2`
//!
//! (their eq. 2-4 without landmarks, `G = diag(1, 1, 1, gamma)` with `gamma = 1`), `u_i`
//! the closest point of the target to the vertex's current image and `w_i` 1, or 0 for a
//! pair whose normals differ by more than 60 degrees (a closest point across a thin
//! fold; far pairs are kept: the stiffness carries them, and leaving them out measured
//! worse, 0.015 -> 0.021 on `g0_spot` at 2.5 median distances). Its normal
//! equations `(alpha^2 L (x) G^2 + blockdiag(w_i^2 h_i h_i^T)) X = blockdiag(w_i^2 h_i)
//! U` (`L` the graph Laplacian of the source's edges) are one sparse symmetric positive
//! definite system of `4n` unknowns with three right-hand sides, of one pattern for
//! every round (the symbolic Cholesky factorization is done once). The stiffness `alpha`
//! falls over the rounds ([`ALIGNED_SCHEDULE`], times `sqrt(n)` so that a schedule means
//! the same smoothness at any resolution), each held until the maps change little. The
//! rounds of one stiffness are a fixed-point iteration (closest points, then the solve);
//! for a placed source they are Anderson-accelerated (module `anderson`).
//!
//! The equations of the stiff levels are factored in `f64`, those of the supple ones
//! (where most rounds are) in `f32`, their solutions refined in `f64` only where the
//! first solve of a factorization shows they need it (`MixedSpdSolver`, [`MIXED_BELOW`]).
//!
//! The weights are judged at the first round of each stiffness and kept for its other
//! rounds, which then only move the closest points `U`: one numeric factorization per
//! stiffness instead of one per round (the same distances to the truth as judging them
//! every round, the paper's loop, at two thirds of the time).
//!
//! The schedule ends supple (`0.002 sqrt(n)`): the template then follows the target
//! closely where the stiff rounds brought it, which is what the shape match pulls the
//! images towards. On fsaverage5 pial onto white the match lands 1.47 mm from the true
//! correspondence with the schedule down to 0.002, 1.51 mm down to 0.0075 and 1.72 mm
//! down to 0.03; `g0_spot` onto its deformation 0.0142, 0.0143 and 0.0148
//! (docs/benchmarks.md; measured with the plain rounds).

//! Positions are taken relative to the placed source's centroid and divided by its
//! root-mean-square radius, so that `gamma = 1` weighs the translations like the linear
//! parts.

use beltrami_fem::FemError;
use beltrami_fem::assembly::Pattern;
use beltrami_fem::vertex_graph::vertex_graph_pattern;
use beltrami_mesh::{FaceId, Mesh, Point3, Vector3};
use beltrami_sparse::{
    Kernel, MixedSpdSolver, SolveError, SolveOptions, SpdSolver, two_core_order,
};
use beltrami_spatial::{Located, SurfaceIndex};
use faer::Mat;

use crate::anderson::AndersonMixing;
use crate::error::{RegisterError, Side};
use crate::shape::{centroid_and_spread, vertex_normals_at};

/// The stiffnesses of a run (per `sqrt(n)`, stiff to supple), the rounds each may take,
/// and how the rounds are accelerated.
pub(crate) struct Schedule {
    /// The stiffnesses, per `sqrt(n)` (module docs).
    pub(crate) stiffness: &'static [f64],
    /// Rounds per stiffness at most.
    pub(crate) rounds: usize,
    /// Differences kept by the Anderson acceleration of the rounds (module `anderson`;
    /// 0: the plain rounds).
    pub(crate) acceleration: usize,
    /// A level ends when no vertex's map moves a point of the unit-radius source by
    /// more than this in a round ...
    pub(crate) settled: f64,
    /// ... or, for the levels below this stiffness, ...
    pub(crate) supple_below: f64,
    /// ... by more than this.
    pub(crate) supple_settled: f64,
}

impl Schedule {
    /// The largest move of a settled round at the level `stiffness`.
    fn settled_at(&self, stiffness: f64) -> f64 {
        if stiffness < self.supple_below {
            self.supple_settled
        } else {
            self.settled
        }
    }
}

/// The schedule of a placed source: ten stiffnesses from `sqrt(n)` down, each until its
/// maps settle, its rounds accelerated (Anderson, three differences) and up to 20 of
/// them. The stiff rounds converge slowly where the source slides along the target, and
/// what they leave unsettled the supple ones cannot undo: fsaverage5 pial onto white by
/// shape, 1.477 mm from the truth with plain rounds up to 10 per stiffness, 1.407 mm with
/// plain rounds up to 20 (84 rounds), 1.352 mm accelerated up to 20 (68 rounds), 1.379
/// accelerated up to 10; `g0_spot` onto its deformation 0.0147, 0.0146 (63 rounds) and
/// 0.0141 (43 rounds, against 59 plain).
pub(crate) const ALIGNED_SCHEDULE: Schedule = Schedule {
    stiffness: &[
        1.0, 0.5, 0.25, 0.12, 0.06, 0.03, 0.015, 0.0075, 0.004, 0.002,
    ],
    rounds: 20,
    acceleration: 3,
    settled: SETTLED,
    supple_below: SUPPLE_BELOW,
    supple_settled: SUPPLE_SETTLED,
};

/// The schedule of a source already in place (the register option `in-place`): its two
/// most supple stiffnesses only. The stiff ones fit the source to the target as a whole
/// (one affine map nearly), which slides a surface that is an offset of the other (pial
/// onto white: the cortex's thickness) along it: fsaverage5 pial onto white in place,
/// the template lies 0.37 mm from the true correspondence with these two, 0.48 mm with
/// the last alone, 1.37 mm from 0.03 down and 1.48 mm with the whole schedule
/// (docs/benchmarks.md). On a pair that is not in place (`g0_spot` onto its smooth
/// deformation, not moved first) it ends 0.107 from the truth against 0.0139 with the
/// whole schedule: the stiff rounds are what find such a correspondence. Its rounds are
/// the plain ones, up to 10 per stiffness: the true correspondence lies near the start,
/// and rounds run to convergence carry each vertex to its closest point instead (the
/// pial surface in place 0.48 mm from the truth so, 0.94 mm accelerated).
pub(crate) const IN_PLACE_SCHEDULE: Schedule = Schedule {
    stiffness: &[0.004, 0.002],
    rounds: 10,
    acceleration: 0,
    settled: SETTLED,
    supple_below: 0.0,
    supple_settled: SETTLED,
};

/// A level ends when no vertex's map moves a point of the unit-radius source by more
/// than this in a round.
const SETTLED: f64 = 1e-3;

/// [`SETTLED`] of the supple levels of a placed source (below the stiffness
/// `SUPPLE_BELOW`), where the template comes to lie on the target: they converge slowly
/// (on fsaverage5 the levels 0.015 to 0.004 run to their 20 rounds), and what they leave
/// unsettled stays in the template, which the registration follows to within 0.004 mm.
/// Registration by shape of fsaverage5 pial onto white, white onto pial, and the right
/// hemisphere's two, and `g0_spot` onto its deformation, from the truth: with these
/// levels ended at 1e-3 1.345, 1.363, 1.332, 1.353 mm and 0.0140 (70 rounds on
/// fsaverage5); at 2.5e-4 1.291, 1.315, 1.278, 1.289 mm and 0.0135 (about 110 rounds,
/// solved in `f32`: [`MIXED_BELOW`]). The stiff levels ended at 2.5e-4 as well gain
/// nothing (1.342, 1.372, 1.324, 1.357 mm).
const SUPPLE_SETTLED: f64 = 2.5e-4;

/// The stiffness (per `sqrt(n)`) below which a placed source's levels end at
/// [`SUPPLE_SETTLED`].
const SUPPLE_BELOW: f64 = 0.05;

/// Stiffnesses (per `sqrt(n)`) from which a level's equations are factored in `f64`;
/// below, in `f32` with the solutions refined in `f64` (`MixedSpdSolver`) only where
/// that is needed to [`REFINED`]. The error of an `f32` solve grows with the
/// stiffness (the condition number with `alpha^2 n`): measured as the relative size of
/// the first refinement's correction, fsaverage5 pial onto white from the stiffness 1.0
/// down 6.5e-3, 3.0e-3, 1.9e-3, 5.7e-4, 1.8e-4, 3.3e-5 and at most 1e-4 after;
/// `g0_spot` 2.2e-3, 1.4e-3, 5.4e-4 and at most 1.8e-4 after. The stiff levels
/// refined would take two `f32` solves and a product where one `f64` solve does. With
/// [`SUPPLE_SETTLED`], a registration by shape of fsaverage5 pial onto white took
/// 4.45-5.06 s against 5.30-5.84 s with every level in `f64` (interleaved runs);
/// `g0_spot` 1.03-1.14 s against 1.02-1.25 s.
const MIXED_BELOW: f64 = 0.2;

/// The relative size of the correction (to the affine maps' largest entry) up to which
/// an `f32` solve of a level is taken unrefined.
const REFINED: f64 = 1e-3;

/// A pair is used only where the normals agree to this cosine (60 degrees).
const NORMAL_AGREEMENT: f64 = 0.5;

/// The placed source `placed` (per source vertex) deformed onto the target of `index`
/// (module docs) with the stiffness schedule `schedule` ([`ALIGNED_SCHEDULE`] or
/// [`IN_PLACE_SCHEDULE`]), its rounds solved with `equations` (of `source`).
/// `stopped` is asked before each round.
///
/// # Errors
/// [`RegisterError::Spatial`] when a closest point cannot be found,
/// [`RegisterError::Solve`] when a round's system cannot be solved, and
/// [`RegisterError::Stopped`] when `stopped` says so.
pub(crate) fn nonrigid_icp(
    source: &Mesh,
    equations: &mut NormalEquations,
    index: &SurfaceIndex<'_>,
    placed: &[Point3<f64>],
    schedule: &Schedule,
    stopped: &dyn Fn() -> bool,
) -> Result<Vec<Point3<f64>>, RegisterError> {
    let (centre, radius) = centroid_and_spread(placed);
    if radius.is_nan() || radius <= 0.0 {
        return Ok(placed.to_vec());
    }
    let to_unit = |p: &Point3<f64>| (p.coords - centre) / radius;
    let from_unit = |x: &Vector3<f64>| Point3::from(x * radius + centre);
    let mut images: Vec<Vector3<f64>> = placed.iter().map(to_unit).collect();
    equations.place(&images);
    let n = images.len();
    // Each round's closest points start their search from the last round's faces: the
    // images move little between rounds (the answer does not depend on the start).
    let mut hints: Option<Vec<FaceId>> = None;
    for &stiffness in schedule.stiffness {
        let alpha2 = (stiffness * stiffness) * n as f64;
        let mut weights = None;
        // Each stiffness is its own fixed-point map: its rounds are accelerated afresh.
        let mut mixing = AndersonMixing::new(schedule.acceleration);
        for _ in 0..schedule.rounds {
            if stopped() {
                return Err(RegisterError::Stopped);
            }
            let positions: Vec<Point3<f64>> = images.iter().map(from_unit).collect();
            let closest = match &hints {
                Some(faces) => index.locate_all_near(&positions, faces)?,
                None => index.locate_all(&positions)?,
            };
            hints = Some(closest.iter().map(|l| l.point.face).collect());
            let weights = match &weights {
                Some(w) => w,
                None => {
                    let judged = agreeing_pairs(source, index.mesh(), &positions, &closest);
                    equations.factorize(stiffness, alpha2, &judged)?;
                    weights.insert(judged)
                }
            };
            let goals: Vec<Vector3<f64>> = closest.iter().map(|l| to_unit(&l.position)).collect();
            let next = equations.solve(weights, &goals)?;
            let moved = next
                .iter()
                .zip(&images)
                .map(|(a, b)| (a - b).norm())
                .fold(0.0, f64::max);
            images = mixing.next(&images, next);
            if moved < schedule.settled_at(stiffness) {
                break;
            }
        }
    }
    Ok(images.iter().map(from_unit).collect())
}

/// The weight `w_i` of each pair (module docs): 1 where the target's face at the closest
/// point faces the way the source does at the vertex (`NORMAL_AGREEMENT`), else 0.
fn agreeing_pairs(
    source: &Mesh,
    target: &Mesh,
    positions: &[Point3<f64>],
    closest: &[Located],
) -> Vec<f64> {
    let normals = vertex_normals_at(source, positions);
    closest
        .iter()
        .zip(&normals)
        .map(|(l, normal)| {
            if target.face_normal(l.point.face).dot(normal) >= NORMAL_AGREEMENT {
                1.0
            } else {
                0.0
            }
        })
        .collect()
}

/// The normal equations of a round (module docs): their pattern, the source's
/// homogeneous coordinates, edges and degrees, and the factorization of the last
/// stiffness and weights given. Made from the source's connectivity alone (the
/// symbolic factorization: fsaverage5's 41K unknowns 0.22 s), before the source is
/// placed, so that a registration makes them beside its initial map.
pub(crate) struct NormalEquations {
    pattern: Pattern,
    homogeneous: Vec<[f64; 4]>,
    edges: Vec<(usize, usize)>,
    degree: Vec<f64>,
    /// The factorization of the stiff levels ([`MIXED_BELOW`]), when the schedule
    /// has any.
    precise: Option<SpdSolver<f64>>,
    /// The factorization of the other levels, in `f32`.
    mixed: MixedSpdSolver,
    /// Whether the last factorization is `precise`'s.
    in_f64: bool,
}

impl NormalEquations {
    /// The equations of `source`, its vertices still to be placed
    /// ([`NormalEquations::place`]), for the levels of `schedule`: an `f32` factor, and
    /// an `f64` one when the schedule has a level from [`MIXED_BELOW`].
    ///
    /// # Errors
    /// [`RegisterError::Solve`] when the symbolic factorization fails (memory).
    pub(crate) fn new(source: &Mesh, schedule: &Schedule) -> Result<Self, RegisterError> {
        let n = source.vertex_count();
        let edges: Vec<(usize, usize)> = source
            .edges()
            .map(|e| {
                let [a, b] = source.edge_vertices(e);
                (a.idx(), b.idx())
            })
            .collect();
        let mut degree = vec![0.0; n];
        for &(a, b) in &edges {
            degree[a] += 1.0;
            degree[b] += 1.0;
        }
        let pattern = block_pattern(n, &edges).map_err(assembly_error)?;
        // Ordered on the vertex graph, each vertex's four unknowns together: the
        // factorizations and solves of fsaverage5's 41K unknowns then run on two cores
        // (2.0 s -> 1.0 s and 1.6 s -> 1.1 s of a registration by shape).
        let vertex_split =
            two_core_order(vertex_graph_pattern(source).as_ref()).map_err(solve_error)?;
        let order = vertex_split.in_blocks(4);
        // Each vertex's four unknowns make a dense block.
        let options = SolveOptions {
            kernel: Kernel::Supernodal,
            ..SolveOptions::default()
        };
        let symbolic = pattern.symbolic();
        let precise = if schedule.stiffness.iter().any(|&s| s >= MIXED_BELOW) {
            Some(
                SpdSolver::with_split_order(symbolic.as_ref(), &order, options)
                    .map_err(solve_error)?,
            )
        } else {
            None
        };
        let mixed = MixedSpdSolver::with_split_order(symbolic.as_ref(), &order, options)
            .map_err(solve_error)?;
        Ok(Self {
            pattern,
            homogeneous: vec![[0.0, 0.0, 0.0, 1.0]; n],
            edges,
            degree,
            precise,
            mixed,
            in_f64: false,
        })
    }

    /// The source's vertices at `unit` (unit-radius coordinates, one per vertex).
    fn place(&mut self, unit: &[Vector3<f64>]) {
        self.homogeneous = unit.iter().map(|x| [x.x, x.y, x.z, 1.0]).collect();
        debug_assert_eq!(self.homogeneous.len(), self.degree.len());
    }

    /// Assembles and factors the matrix `alpha^2 L (x) I + blockdiag(w_i h_i h_i^T)` of
    /// the level `stiffness` (per `sqrt(n)`; `alpha2` is `alpha^2`): in `f64` from
    /// [`MIXED_BELOW`], else in `f32`.
    fn factorize(
        &mut self,
        stiffness: f64,
        alpha2: f64,
        weights: &[f64],
    ) -> Result<(), RegisterError> {
        let mut values = Vec::with_capacity(self.pattern.entry_count());
        for (i, h) in self.homogeneous.iter().enumerate() {
            for r in 0..4 {
                for c in 0..4 {
                    let stiff = if r == c { alpha2 * self.degree[i] } else { 0.0 };
                    values.push(stiff + weights[i] * h[r] * h[c]);
                }
            }
        }
        for _ in &self.edges {
            for r in 0..4 {
                for c in 0..4 {
                    let value = if r == c { -alpha2 } else { 0.0 };
                    values.push(value);
                    values.push(value);
                }
            }
        }
        let matrix = self.pattern.assemble(&values).map_err(assembly_error)?;
        self.in_f64 = false;
        match &mut self.precise {
            Some(precise) if stiffness >= MIXED_BELOW => {
                precise.factorize(matrix.as_ref()).map_err(solve_error)?;
                self.in_f64 = true;
                Ok(())
            }
            _ => self.mixed.factorize(matrix.as_ref()).map_err(solve_error),
        }
    }

    /// The images `h_i^T X_i` of the affine maps that solve the factored equations with
    /// right-hand side `blockdiag(w_i h_i) U`, `U` the closest points `goals`.
    fn solve(
        &mut self,
        weights: &[f64],
        goals: &[Vector3<f64>],
    ) -> Result<Vec<Vector3<f64>>, RegisterError> {
        let mut rhs = Mat::<f64>::zeros(4 * self.homogeneous.len(), 3);
        for (i, h) in self.homogeneous.iter().enumerate() {
            if weights[i] == 0.0 {
                continue;
            }
            for r in 0..4 {
                for c in 0..3 {
                    rhs[(4 * i + r, c)] += weights[i] * h[r] * goals[i][c];
                }
            }
        }
        match (&mut self.precise, self.in_f64) {
            (Some(precise), true) => precise.solve_in_place(rhs.as_mut()).map_err(solve_error)?,
            _ => {
                self.mixed
                    .solve_in_place(rhs.as_mut(), REFINED)
                    .map_err(solve_error)?;
            }
        }
        Ok(self
            .homogeneous
            .iter()
            .enumerate()
            .map(|(i, h)| Vector3::from_fn(|c, _| (0..4).map(|r| h[r] * rhs[(4 * i + r, c)]).sum()))
            .collect())
    }
}

/// A failed solve of the source's equations.
fn solve_error(error: SolveError) -> RegisterError {
    RegisterError::Solve {
        side: Side::Source,
        error,
    }
}

/// A failed assembly: the pattern's positions lie inside the matrix and its values are
/// as many as its positions by construction, so this would be the source's elements'.
fn assembly_error(error: FemError) -> RegisterError {
    RegisterError::Elements {
        side: Side::Source,
        error,
    }
}

/// The positions of the normal equations' entries, in the order their values are
/// written: each vertex's 4 x 4 diagonal block, then each edge's two off-diagonal
/// blocks, entry by entry. Every block's 16 entries are kept, zeros too, so that one
/// pattern serves every round whatever the weights.
fn block_pattern(n: usize, edges: &[(usize, usize)]) -> Result<Pattern, FemError> {
    let mut positions = Vec::with_capacity(16 * (n + 2 * edges.len()));
    for i in 0..n {
        for r in 0..4 {
            for c in 0..4 {
                positions.push((4 * i + r, 4 * i + c));
            }
        }
    }
    for &(a, b) in edges {
        for r in 0..4 {
            for c in 0..4 {
                positions.push((4 * a + r, 4 * b + c));
                positions.push((4 * b + r, 4 * a + c));
            }
        }
    }
    Pattern::new(4 * n, 4 * n, &positions)
}

#[cfg(test)]
#[path = "../tests/fixtures/blob.rs"]
mod fixtures;

#[cfg(test)]
mod tests {
    use super::*;
    use fixtures::{blob_pair, deform};

    #[test]
    fn a_deformed_blob_is_followed_to_its_deformation() {
        // The blob onto a finer mesh of it under `deform`: the source where it is lies
        // 0.155 from the truth on average, the template 0.031.
        let (source, target) = blob_pair(3);
        let index = SurfaceIndex::new(&target).unwrap();
        let truth: Vec<Point3<f64>> = source.positions().iter().map(deform).collect();
        let error = |at: &[Point3<f64>]| {
            at.iter()
                .zip(&truth)
                .map(|(a, b)| (a - b).norm())
                .sum::<f64>()
                / at.len() as f64
        };
        let start = error(source.positions());
        let template = nonrigid_icp(
            &source,
            &mut NormalEquations::new(&source, &ALIGNED_SCHEDULE).unwrap(),
            &index,
            source.positions(),
            &ALIGNED_SCHEDULE,
            &|| false,
        )
        .unwrap();
        let end = error(&template);
        eprintln!("deformed blob: the template {start:.4} -> {end:.4} from the truth");
        assert!(
            end < 0.3 * start,
            "mean distance to the truth {start} -> {end}"
        );
    }

    #[test]
    fn a_stop_ends_the_rounds() {
        let (source, target) = blob_pair(2);
        let index = SurfaceIndex::new(&target).unwrap();
        let rounds = std::cell::Cell::new(0);
        let after_three = || {
            rounds.set(rounds.get() + 1);
            rounds.get() > 3
        };
        let stopped = nonrigid_icp(
            &source,
            &mut NormalEquations::new(&source, &ALIGNED_SCHEDULE).unwrap(),
            &index,
            source.positions(),
            &ALIGNED_SCHEDULE,
            &after_three,
        );
        assert!(
            matches!(stopped, Err(RegisterError::Stopped)),
            "{stopped:?}"
        );
        assert_eq!(rounds.get(), 4);
    }
}
