//! `affine`: the exact map of a planar disk mesh for a constant prescribed Beltrami
//! coefficient.
//!
//! With `mu = f_zbar / f_z` (DESIGN.md's convention), `f(z) = z + k conj(z)` has
//! `f_z = 1` and `f_zbar = k`, so its coefficient is the constant `k` on every face of any
//! mesh in the plane, exactly (the map is affine, so it is exact on P1 and Q1 elements
//! alike). It is the answer to a prescribed constant `mu` with a free boundary, up to a
//! conformal map of its image: a solver whose result is known to rounding, for checking a
//! pipeline end to end (`|mu|` measured by `distortion` equals `|k|`), and the solver that
//! docs/adding-a-solver.md builds.

use beltrami_core::Goal;
use beltrami_core::{
    Accepts, Context, Element, GoalKind, Map, Problem, Report, Settings, Solution, Solver,
    SolverError, SolverInfo, TargetKind, Topology,
};
use beltrami_fem::beltrami::planar_map;
use beltrami_fem::distortion::{Distortion, MuError};
use beltrami_fem::{Elements, Frame};
use num_complex::Complex64;

/// The solver's name.
const NAME: &str = "affine";

/// A constant coefficient may differ between faces by rounding of this much (a field
/// read from a file, or carried between frames).
const CONSTANT: f64 = 1e-12;

const ACCEPTS: Accepts = Accepts {
    elements: &[Element::Triangle, Element::Quad],
    topologies: &[Topology::Disk],
    targets: &[TargetKind::PlaneFree],
    goals: &[GoalKind::Prescribed],
    constraints: &[],
};

/// The affine solver (module docs).
pub struct Affine;

impl Affine {
    /// The constant `k` of the prescribed field in the plane's frame, or the refusal
    /// naming the first face that differs.
    fn constant_mu(problem: &Problem<'_>) -> Result<Complex64, SolverError> {
        let Goal::Prescribed(field) = &problem.goal else {
            return Err(SolverError::unsupported(
                NAME,
                "affine takes a prescribed mu (--mu or --mu-expr)",
            ));
        };
        let global = field.to_frame(problem.source, Frame::Global)?;
        let mesh = problem.source;
        let first = global.mu.first().copied().unwrap_or_default();
        let differing = mesh
            .faces()
            .zip(&global.mu)
            .find(|(_, mu)| (*mu - first).norm() > CONSTANT);
        if let (Some((face, mu)), Some(face0)) = (differing, mesh.faces().next()) {
            return Err(SolverError::unsupported(
                NAME,
                format!(
                    "affine takes a constant mu, and face {} has {mu} where face {} has {first} (in the plane's frame): use lsqc or beltrami-flow for a varying one",
                    mesh.face_to_input(face),
                    mesh.face_to_input(face0),
                ),
            ));
        }
        Ok(first)
    }
}

/// What [`Affine`] is: its name, one line on what it computes, what it accepts and
/// its options.
const INFO: SolverInfo = SolverInfo {
    name: NAME,
    description: "the affine map z + k conj(z) of a planar disk, exact for a constant prescribed mu = k",
    accepts: ACCEPTS,
    options: &[],
};

impl Solver for Affine {
    fn info(&self) -> &'static SolverInfo {
        &INFO
    }

    /// The source in the plane `z = 0` and the prescribed field constant.
    fn check_problem(&self, problem: &Problem<'_>, _: &Settings) -> Result<(), SolverError> {
        beltrami_fem::element::check_planar(problem.source)?;
        Self::constant_mu(problem).map(|_| ())
    }

    fn run(
        &self,
        problem: &Problem<'_>,
        _: &Settings,
        context: &mut Context<'_>,
    ) -> Result<Solution, SolverError> {
        let mesh = problem.source;
        let k = Self::constant_mu(problem)?;
        let mut report = Report::new(NAME);
        let map: Vec<Complex64> = context.stage("map", &mut report, || {
            Ok(mesh
                .positions()
                .iter()
                .map(|p| {
                    let z = Complex64::new(p.x, p.y);
                    z + k * z.conj()
                })
                .collect())
        })?;
        let (distortion, elements) = context.stage("distortion", &mut report, || {
            let elements = Elements::new(mesh, Frame::Global)?;
            let derivatives = planar_map(&elements, mesh.vertex_count(), &map)?;
            Ok((
                Distortion::from_derivatives(&elements, &derivatives)?,
                elements,
            ))
        })?;
        let prescribed = vec![k; mesh.face_count()];
        let mut solution = Solution::from_map(Map::Planar(map), report);
        solution.metrics.mu_error =
            Some(MuError::new(&elements, &distortion.field.mu, &prescribed)?);
        solution.metrics.mu = Some(distortion.field);
        solution.metrics.distortion = Some(distortion.stats);
        Ok(solution)
    }
}

/// Adds the solver to `registry`.
pub fn register(registry: &mut beltrami_core::Registry) {
    registry.register(Box::new(Affine));
}
