//! What the flow checks before any work: the mesh, the target's topology, the goal, the
//! pins, curves and initial map.

use beltrami_core::{
    Constraint, Goal, Map, PlanarBoundary, Position, Problem, SolverError, Target, topology,
};
use beltrami_fem::Frame;
use beltrami_fem::element::is_planar;
use beltrami_mesh::Mesh;
use num_complex::Complex64;

use crate::NAME;

/// The largest exponent of the `L^p` goal: `|mu|^p` must stay a normal double for the
/// distortions a flow meets (`0.001^100 = 1e-300`).
pub(crate) const MAX_P: f64 = 100.0;

/// How far (relative) a vertex may be off the unit circle or sphere for the source to be
/// taken as already on the target.
pub const ON_TARGET: f64 = 1e-9;

/// The goal, checked: the frame `mu` is measured in, the target per face and `p`.
pub(crate) struct CheckedGoal {
    pub(crate) frame: Frame,
    pub(crate) sigma: Option<Vec<Complex64>>,
    pub(crate) p: f64,
}

/// Everything that can be checked before any work.
pub(crate) fn validate(problem: &Problem<'_>) -> Result<CheckedGoal, SolverError> {
    let mesh = problem.source;
    if let Some(f) = mesh.faces().find(|&f| mesh.face_degree(f) != 3) {
        return Err(SolverError::unsupported(
            NAME,
            format!(
                "the flow works on triangle meshes; face {} (input index) has {} vertices: split quads into triangles first",
                mesh.face_to_input(f),
                mesh.face_degree(f)
            ),
        ));
    }
    let planar = is_planar(mesh);
    check_target(problem, planar)?;
    check_constraints(problem)?;
    check_initial(problem)?;
    check_goal(problem, planar)
}

/// The target: one the flow maps onto, and a source whose topology (and, for the plane
/// keeping its region, position) fits it.
fn check_target(problem: &Problem<'_>, planar: bool) -> Result<(), SolverError> {
    let mesh = problem.source;
    match &problem.target {
        Target::Plane(PlanarBoundary::Keep) => {
            if !planar {
                return Err(SolverError::unsupported(
                    NAME,
                    "the target `plane` keeps the input's own planar region; this mesh is not in the plane z = 0: use the disk target",
                ));
            }
            topology::require_disk(
                NAME,
                mesh,
                "use the annulus or sphere targets, or `beltrami cut`",
            )?;
        }
        Target::Plane(
            PlanarBoundary::Circle | PlanarBoundary::Square { .. } | PlanarBoundary::Polygon(_),
        )
        | Target::Disk => {
            topology::require_disk(
                NAME,
                mesh,
                "use the annulus or sphere targets, or `beltrami cut`",
            )?;
        }
        Target::Plane(PlanarBoundary::Free | PlanarBoundary::Given(_)) => {
            return Err(SolverError::unsupported(
                NAME,
                "the flow needs a target region; for a free or given boundary use lsqc",
            ));
        }
        Target::Annulus { inner_radius } => check_annulus(problem, *inner_radius)?,
        Target::Sphere => {
            topology::require_sphere(
                NAME,
                mesh,
                "use the disk or annulus targets for meshes with boundary",
            )?;
        }
        Target::Mesh(target) => check_target_mesh(problem, target)?,
        Target::CircleDomain | Target::Surface => {
            return Err(SolverError::unsupported(
                NAME,
                "targets here: plane, disk, annulus, sphere, a target mesh (circle domains come with another solver)",
            ));
        }
    }
    Ok(())
}

/// The annulus target: a connected genus-0 source with two boundary loops, an inner
/// radius (when given) in `(0, 1)`, and without an initial map a source already in
/// the annulus ([`annulus_of`]).
fn check_annulus(problem: &Problem<'_>, inner_radius: Option<f64>) -> Result<(), SolverError> {
    let mesh = problem.source;
    if mesh.boundary_loop_count() != 2 || mesh.component_count() != 1 || mesh.genus() != Some(0) {
        return Err(SolverError::unsupported(
            NAME,
            format!(
                "the annulus target needs a connected genus-0 mesh with two boundary loops; this mesh has {}",
                topology::describe(mesh)
            ),
        ));
    }
    if let Some(r) = inner_radius
        && !(r > 0.0 && r < 1.0)
    {
        return Err(SolverError::invalid(
            NAME,
            format!("the inner radius must be in (0, 1), got {r}"),
        ));
    }
    if problem.initial.is_none() {
        annulus_of(mesh)?;
    }
    Ok(())
}

/// A target mesh: the source's topology, an initial map onto it, triangles, and open
/// feature curves whose target chains follow its edges.
fn check_target_mesh(problem: &Problem<'_>, target: &Mesh) -> Result<(), SolverError> {
    let mesh = problem.source;
    if target.boundary_loop_count() != mesh.boundary_loop_count()
        || target.genus() != mesh.genus()
        || target.component_count() != mesh.component_count()
    {
        return Err(SolverError::unsupported(
            NAME,
            format!(
                "the source and the target mesh differ in topology: source has {}, target has {}",
                topology::describe(mesh),
                topology::describe(target)
            ),
        ));
    }
    if problem.initial.is_none() {
        return Err(SolverError::unsupported(
            NAME,
            "a target mesh needs an initial map onto it: use the register solver, which builds one",
        ));
    }
    if let Some(f) = target.faces().find(|&f| target.face_degree(f) != 3) {
        return Err(SolverError::unsupported(
            NAME,
            format!(
                "the target mesh must be made of triangles; its face {} (input index) is not",
                target.face_to_input(f)
            ),
        ));
    }
    // Lengths and vertex ids were checked with every constraint
    // (`Constraints::validate`).
    for (k, curve) in problem.constraints.curves().enumerate() {
        if curve.closed {
            return Err(SolverError::unsupported(
                NAME,
                format!("curve {k} is closed; the flow slides open feature curves with fixed ends"),
            ));
        }
        // The chain slides along its segments, which must lie on the target.
        for pair in curve.target.windows(2) {
            if !target.vertex_neighbors(pair[0]).any(|w| w == pair[1]) {
                return Err(SolverError::invalid(
                    NAME,
                    format!(
                        "curve {k}: target vertices {} and {} (input indices) are not joined by an edge",
                        target.vertex_map().to_input(pair[0]),
                        target.vertex_map().to_input(pair[1])
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// The constraints: pins without positions, landmarks (at points in space or target
/// vertices) and curves only on a target mesh.
fn check_constraints(problem: &Problem<'_>) -> Result<(), SolverError> {
    let on_mesh = matches!(problem.target, Target::Mesh(_));
    for constraint in problem.constraints.iter() {
        let refused = match constraint {
            Constraint::Pin(pin) => pin.position.is_some(),
            Constraint::Landmark(mark) => {
                !on_mesh
                    || !matches!(
                        mark.position,
                        Position::Spatial(_) | Position::TargetVertex(_)
                    )
            }
            _ => false,
        };
        if refused {
            return Err(SolverError::unsupported(
                NAME,
                "pins hold their vertex where the initial map puts it; pins at given positions (landmarks) are for target meshes",
            ));
        }
    }
    if problem.constraints.curves().next().is_some() && !on_mesh {
        return Err(SolverError::unsupported(
            NAME,
            "curve constraints come with target meshes (register)",
        ));
    }
    Ok(())
}

/// The initial map, when given: one image per source vertex.
fn check_initial(problem: &Problem<'_>) -> Result<(), SolverError> {
    let mesh = problem.source;
    if let Some(initial) = &problem.initial {
        let n = match initial {
            Map::Planar(z) => z.len(),
            Map::Spatial(p) => p.len(),
            Map::OnMesh(p) => p.len(),
        };
        if n != mesh.vertex_count() {
            return Err(SolverError::invalid(
                NAME,
                format!(
                    "the initial map has {n} images for {} vertices",
                    mesh.vertex_count()
                ),
            ));
        }
    }
    Ok(())
}

/// The goal: conformal with `2 <= p <= MAX_P`, or a prescribed field (in the global
/// frame only on a planar source, `planar`); checked into the frame, the target `mu`
/// per face and `p`.
fn check_goal(problem: &Problem<'_>, planar: bool) -> Result<CheckedGoal, SolverError> {
    let mesh = problem.source;
    match &problem.goal {
        Goal::Conformal { p } => {
            if !(*p >= 2.0 && *p <= MAX_P) {
                return Err(SolverError::invalid(
                    NAME,
                    format!(
                        "the L^p goal needs 2 <= p <= {MAX_P} (|mu|^p of a larger p underflows to zero), got {p}"
                    ),
                ));
            }
            Ok(CheckedGoal {
                frame: if planar { Frame::Global } else { Frame::Face },
                sigma: None,
                p: *p,
            })
        }
        Goal::Prescribed(field) => {
            field.check(mesh.face_count())?;
            if field.frame == Frame::Global && !planar {
                return Err(SolverError::invalid(
                    NAME,
                    "a field in the global frame needs a mesh in the plane z = 0; give it in the face frame",
                ));
            }
            Ok(CheckedGoal {
                frame: field.frame,
                sigma: Some(field.mu.clone()),
                p: 2.0,
            })
        }
        Goal::Extremal => Err(SolverError::unsupported(
            NAME,
            "extremal (Teichmueller) maps come with their own solver",
        )),
        Goal::Features(_) => Err(SolverError::unsupported(
            NAME,
            "features are matched by register, in the parameter domain",
        )),
    }
}

/// The inner radius of a planar annulus source centred at 0, and which boundary loop is
/// the outer one (index in `boundary_loop_list`).
pub fn annulus_of(mesh: &Mesh) -> Result<(f64, usize), SolverError> {
    let loops = mesh.boundary_loop_list();
    let radii: Vec<(f64, f64)> = loops
        .iter()
        .map(|l| {
            let r: Vec<f64> = l
                .vertices
                .iter()
                .map(|&v| mesh.position(v).coords.xy().norm())
                .collect();
            let lo = r.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = r.iter().copied().fold(0.0, f64::max);
            (lo, hi)
        })
        .collect();
    let outer = usize::from(radii[1].1 > radii[0].1);
    let inner = 1 - outer;
    let on = |(lo, hi): (f64, f64), r: f64| {
        (lo - r).abs() <= ON_TARGET * r.max(1.0) && (hi - r).abs() <= ON_TARGET * r.max(1.0)
    };
    let r = radii[inner].1;
    if !(is_planar(mesh) && on(radii[outer], 1.0) && on(radii[inner], r) && r > 0.0 && r < 1.0) {
        return Err(SolverError::unsupported(
            NAME,
            "the annulus target starts from a mesh already in an annulus r <= |z| <= 1 centred at 0 (both boundary loops on their circles), or from a given initial map",
        ));
    }
    Ok((r, outer))
}

/// The inner radius of the annulus target `r <= |z| <= 1` that keeps the shape of
/// `mesh`, a planar annulus centred at the origin (`beltrami qc --target annulus`
/// without `--free-radius`): per boundary loop the mean distance of its vertices from
/// the origin in the x-y plane, the smallest over the loops. `None` for a mesh without
/// boundary loops. The solver's own check then requires both loops on their circles.
pub fn annulus_inner_radius(mesh: &Mesh) -> Option<f64> {
    mesh.boundary_loop_list()
        .iter()
        .map(|l| {
            l.vertices
                .iter()
                .map(|&v| mesh.position(v).coords.xy().norm())
                .sum::<f64>()
                / l.vertices.len() as f64
        })
        .min_by(f64::total_cmp)
}

#[cfg(test)]
mod tests {
    use super::*;
    use beltrami_mesh::primitives;

    #[test]
    fn the_inner_radius_is_the_innermost_loops_mean_radius() {
        let annulus = Mesh::from_soup(&primitives::annulus(0.4, 3, 24)).unwrap();
        let r = annulus_inner_radius(&annulus).unwrap();
        assert!((r - 0.4).abs() < 1e-12, "{r}");
        assert!((annulus_of(&annulus).unwrap().0 - r).abs() < 1e-12);
        // Scaled by 2 and moved off the x-y plane: radii in the x-y plane, about the origin.
        let mut soup = primitives::annulus(0.4, 3, 24);
        for p in &mut soup.positions {
            p.x *= 2.0;
            p.y *= 2.0;
            p.z = 5.0;
        }
        let r = annulus_inner_radius(&Mesh::from_soup(&soup).unwrap()).unwrap();
        assert!((r - 0.8).abs() < 1e-12, "{r}");
        let sphere = Mesh::from_soup(&primitives::octahedral_sphere(1)).unwrap();
        assert_eq!(annulus_inner_radius(&sphere), None);
    }
}
