//! lsqc into R^3 (`Target::Surface`): the quaternionic least-squares quasiconformal
//! map of a surface (Gruber-Aulisa 2022, Definition 3.3, Lemma 3.4 and Algorithm 1).
//!
//! The unknowns are the three coordinates of every vertex image; the energy is
//! `sum_q w_q |df^- - mu df^+|^2` ([`beltrami_fem::quaternionic_lsqc`]), `mu = mu1 + mu2 N`
//! from a Beltrami field in the face frames (`mu = 0` for `--conformal`). Pins with
//! positions in space hold vertices (the boundary of a boundary map, or any vertices);
//! one sparse solve (the normal equations' Cholesky, AMD order), with the normal penalty
//! of section 4.1 and the area equality of section 4.2 when asked
//! ([`beltrami_fem::quaternionic_lsqc::SpaceSystem`]). The energy is homogeneous in the
//! images (the zero map has none), so a map needs held vertices or constraints that fix
//! it ([`beltrami_fem::quaternionic_lsqc::undetermined`]): otherwise the problem is
//! refused.

use beltrami_core::{
    Constraint, Context, Extras, Goal, Map, Metrics, Output, Problem, Report, Settings, Solution,
    SolverError,
};
use beltrami_fem::beltrami::face_mu;
use beltrami_fem::distortion::measure_surface;
use beltrami_fem::quaternion::quaternionic_mu;
use beltrami_fem::quaternionic_lsqc::{
    AreaConstraint, NormalConstraint, SpaceSystem, undetermined,
};
use beltrami_fem::{BeltramiField, Elements, Frame, MuError, ReferenceNormal};
use beltrami_mesh::{Point3, VertexId};
use beltrami_sparse::SolveOptions;

use crate::lsqc::NAME;

/// What the check finds: the field in the face frames and the held vertices.
pub(crate) struct SpaceSetup {
    field: BeltramiField,
    held: Vec<(VertexId, Point3<f64>)>,
}

/// The capability check of the space target.
pub(crate) fn setup(problem: &Problem<'_>) -> Result<SpaceSetup, SolverError> {
    let mesh = problem.source;
    let field = match &problem.goal {
        Goal::Prescribed(field) => {
            field.check(mesh.face_count())?;
            if field.frame != Frame::Face {
                return Err(SolverError::unsupported(
                    NAME,
                    "a map into space takes its Beltrami field in the face frames (`# mu frame=face`), where mu1 + i mu2 is the quaternionic mu1 + mu2 N",
                ));
            }
            field.clone()
        }
        Goal::Conformal { p } if *p == 2.0 => BeltramiField::zero(Frame::Face, mesh.face_count()),
        Goal::Conformal { p } => {
            return Err(SolverError::unsupported(
                NAME,
                format!("lsqc minimizes a least-squares (p = 2) energy, not the L^{p} norm of mu"),
            ));
        }
        Goal::Extremal => {
            return Err(SolverError::unsupported(
                NAME,
                "lsqc follows a prescribed Beltrami coefficient; for extremal maps use extremal",
            ));
        }
        Goal::Features(_) => {
            return Err(SolverError::unsupported(
                NAME,
                "lsqc follows a prescribed Beltrami coefficient; features are matched by register",
            ));
        }
    };
    if problem.constraints.curves().next().is_some() {
        return Err(SolverError::unsupported(
            NAME,
            "lsqc does not make vertices follow curves yet",
        ));
    }
    let held = problem
        .spatial_pins()
        .map_err(|message| SolverError::invalid(NAME, message))?;
    let has = |kind: fn(&Constraint) -> bool| problem.constraints.iter().any(kind);
    if let Some(message) = undetermined(
        held.len(),
        has(|c| matches!(c, Constraint::Normal { .. })),
        has(|c| matches!(c, Constraint::Area)),
        mesh.boundary_loop_list().is_empty(),
    ) {
        return Err(SolverError::unsupported(NAME, message));
    }
    Ok(SpaceSetup { field, held })
}

/// Runs the space target (module docs).
pub(crate) fn run(
    problem: &Problem<'_>,
    settings: &Settings,
    context: &mut Context<'_>,
) -> Result<Solution, SolverError> {
    let mesh = problem.source;
    let mut report = Report::new(NAME);
    let mut metrics = Metrics::default();
    let SpaceSetup { field, held } = setup(problem)?;
    let n = mesh.vertex_count();
    let normal = problem.constraints.iter().find_map(|c| match c {
        Constraint::Normal { weight } => Some(NormalConstraint::new(mesh, *weight)),
        _ => None,
    });
    let area = problem
        .constraints
        .iter()
        .any(|c| matches!(c, Constraint::Area));
    let mut system = context.stage("assembly", &mut report, || {
        let elements = Elements::new(mesh, Frame::Face)?;
        let area = area.then(|| AreaConstraint::new(&elements, mesh.positions()));
        let options = SolveOptions {
            threads: settings.int("threads"),
            ..SolveOptions::default()
        };
        Ok(SpaceSystem::new(elements, n, &held, normal, area, options)?)
    })?;
    let image = context.stage("solve", &mut report, || Ok(system.solve(&field.mu)?))?;
    let elements = system.elements();
    let distortion = context.stage("distortion", &mut report, || {
        Ok(measure_surface(mesh, &image, ReferenceNormal::Source)?)
    })?;
    let quaternionic = face_mu(elements, &quaternionic_mu(elements, n, &image)?);
    metrics.mu_error = Some(MuError::new(elements, &quaternionic, &field.mu)?);
    if distortion.stats.flipped > 0 {
        report.notes.push(format!(
            "{} of {} faces turn against the source's normals: the least-squares map is not guaranteed to be a bijection",
            distortion.stats.flipped,
            mesh.face_count()
        ));
    }
    report.notes.push(
        "|mu| is the map's own distortion (in the image's tangent planes); |mu - target| compares the quaternionic mu1 + mu2 N with the field".to_string(),
    );
    metrics.mu = Some(distortion.field);
    metrics.distortion = Some(distortion.stats);
    Ok(Solution {
        output: Output::Map(Map::Spatial(image)),
        metrics,
        extras: Extras::default(),
        report,
    })
}
