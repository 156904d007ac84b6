//! [`BeltramiFlow`]: the solver behind `--solver beltrami-flow` (crate docs).

use beltrami_core::{
    Context, Goal, Map, PlanarBoundary, Position, Problem, Report, Solution, Solver, SolverError,
    Target, topology,
};
use beltrami_fem::element::is_planar;
use beltrami_fem::{BeltramiField, DistortionStats, Elements, Frame, SolveOptions};
use beltrami_init::{Sphere, Tutte};
use beltrami_mesh::{Mesh, Point3, VertexId};
use beltrami_spatial::SurfaceIndex;
use num_complex::Complex64;

use crate::NAME;
use crate::flow::{self, FlowOptions, FlowRun, Stop};
use crate::measure::Objective;
use crate::mesh_target::{MeshTarget, TargetCurve};
use crate::system::FlowSystem;
use crate::target::{
    Annulus, INNER, OUTER, PlaneRegion, Role, Side, TargetGeometry, UnitDisk, UnitSphere,
};

/// Discrete Beltrami flow onto a fixed target (crate docs).
///
/// Reads: `goal` (`Conformal { p >= 2 }` or `Prescribed(field)`), `target`
/// (`Plane(Keep | Square | Polygon | Circle)`, `Disk`, `Annulus`, `Sphere`, `Mesh` with
/// an initial map onto it — the register solver builds one — and `constraints.curves`),
/// `constraints.pins` (held where the initial map puts them), `initial` (a planar or
/// spatial map to start from; its images are projected onto the target first),
/// `params.tolerance` (largest vertex update, relative to the target's size),
/// `params.max_iterations` and `params.threads`.
#[derive(Debug, Clone, Copy, Default)]
pub struct BeltramiFlow;

/// Boundary vertices whose boundary turns by less than this (radians) slide along a
/// straight side of a planar region; the others are corners and stay.
const CORNER_ANGLE: f64 = 1e-6;

/// On a target mesh, the largest vertex move tried in one step, relative to the target's
/// bounding-box diagonal ([`FlowOptions::max_move`]).
const MESH_MAX_MOVE: f64 = 0.05;

/// How far (relative) a vertex may be off the unit circle or sphere for the source to be
/// taken as already on the target.
const ON_TARGET: f64 = 1e-9;

impl Solver for BeltramiFlow {
    fn name(&self) -> &'static str {
        NAME
    }

    fn description(&self) -> &'static str {
        "discrete Beltrami flow: a bijective map onto a fixed target with a prescribed mu or the smallest L^p norm of mu"
    }

    fn accepts(&self) -> &'static str {
        "triangle meshes; targets: plane (the input's own polygon, square, polygon), disk, annulus (fixed or free inner radius) for disks/annuli, sphere for closed genus 0; goals: prescribed mu (global or face frame), conformal L^p (p >= 2); pins"
    }

    fn check(&self, problem: &Problem<'_>) -> Result<(), SolverError> {
        validate(problem).map(|_| ())
    }

    fn solve(
        &self,
        problem: &Problem<'_>,
        context: &mut Context<'_>,
    ) -> Result<Solution, SolverError> {
        let goal = validate(problem)?;
        let mesh = problem.source;
        let mut report = Report::new(NAME);
        let elements = context.stage("elements", &mut report, || {
            Ok(Elements::new(mesh, goal.frame)?)
        })?;
        let initial = context.stage("initial map", &mut report, || initial_map(problem))?;
        let objective = Objective {
            areas: (0..mesh.face_count())
                .map(|f| elements.face_points(beltrami_mesh::FaceId(f as u32))[0].weight)
                .collect(),
            sigma: goal.sigma.clone(),
            p: goal.p,
        };
        let options = SolveOptions {
            threads: problem.params.threads,
            ..SolveOptions::default()
        };
        let planar = !matches!(problem.target, Target::Sphere);
        let runner = Runner {
            elements: &elements,
            objective: &objective,
            problem,
            options,
        };
        let input = |v: VertexId| mesh.vertex_map().to_input(v);
        let pins = pins(problem, &initial);
        if problem.constraints.pins.is_empty() && !pins.is_empty() {
            let names: Vec<String> = pins.iter().map(|&v| input(v).to_string()).collect();
            report.notes.push(format!(
                "pinned vertices {} (input indices) where the initial map puts them, to fix the target's conformal automorphisms",
                names.join(", ")
            ));
        }
        if let Target::Mesh(target) = &problem.target {
            let index = context.stage("target index", &mut report, || {
                SurfaceIndex::new(target).map_err(|e| invalid(format!("the target mesh: {e}")))
            })?;
            let (curves, roles) = mesh_roles(problem, target, &initial, &pins)?;
            let geometry = MeshTarget::new(&index, curves);
            let scale = diagonal(target.positions());
            let run = runner.run(
                geometry.clone(),
                roles,
                initial,
                scale,
                context,
                &mut report,
            )?;
            let points = geometry.locate_all(&run.image)?;
            let (_, faces_mu, flipped) = run.finish(false);
            return finish_solution(
                report,
                goal.frame,
                &objective,
                faces_mu,
                &flipped,
                Map::OnMesh(points),
            );
        }
        let domain = domain(problem, &initial)?;
        let image = initial;
        let outcome = match domain {
            Domain::Region(g) => {
                let scale = diagonal(&image);
                let roles = region_roles(mesh, &g, &image, &pins);
                runner
                    .run(g, roles, image, scale, context, &mut report)?
                    .finish(planar)
            }
            Domain::Disk(g) => {
                let roles = curve_roles(mesh, &pins, |_| 0);
                runner
                    .run(g, roles, image, 1.0, context, &mut report)?
                    .finish(planar)
            }
            Domain::Annulus(g, outer) => {
                let roles = curve_roles(mesh, &pins, |l| if l == outer { OUTER } else { INNER });
                let run = runner.run(g, roles, image, 1.0, context, &mut report)?;
                if g.free_inner {
                    report.notes.push(format!(
                        "inner radius {:.6} (free; started at {:.6})",
                        run.target.inner_radius, g.inner_radius
                    ));
                }
                run.finish(planar)
            }
            Domain::Sphere(g) => {
                let roles = curve_roles(mesh, &pins, |_| 0);
                runner
                    .run(g, roles, image, 1.0, context, &mut report)?
                    .finish(planar)
            }
        };
        let (map, faces_mu, flipped) = outcome;
        finish_solution(report, goal.frame, &objective, faces_mu, &flipped, map)
    }
}

/// The solution with its measured `mu`, statistics and a note on remaining flips.
fn finish_solution(
    mut report: Report,
    frame: Frame,
    objective: &Objective,
    faces_mu: Vec<Complex64>,
    flipped: &[bool],
    map: Map,
) -> Result<Solution, SolverError> {
    let stats = DistortionStats::new(&faces_mu, &objective.areas, flipped)?;
    if stats.flipped > 0 {
        report.notes.push(format!(
            "{} faces are flipped: the initial map had flips the flow could not remove",
            stats.flipped
        ));
    }
    report.mu = Some(BeltramiField::new(frame, faces_mu));
    report.distortion = Some(stats);
    Ok(Solution { map, report })
}

/// The curves of a target mesh (its boundary loops, then the problem's feature curves)
/// and the roles of the source vertices: each source boundary loop slides on the target
/// loop nearest to its initial image, each feature curve's inner vertices on its target
/// chain (ends fixed), pins fixed, the rest free.
fn mesh_roles(
    problem: &Problem<'_>,
    target: &Mesh,
    image: &[Point3<f64>],
    pins: &[VertexId],
) -> Result<(Vec<TargetCurve>, Vec<Role>), SolverError> {
    let mesh = problem.source;
    let mut curves = TargetCurve::boundary_loops(target);
    let mut roles = vec![Role::Free; mesh.vertex_count()];
    for l in mesh.boundary_loop_list() {
        let nearest = (0..curves.len()).min_by(|&a, &b| {
            let d = |c: usize| curves[c].mean_distance(l.vertices.iter().map(|v| &image[v.idx()]));
            d(a).total_cmp(&d(b))
        });
        let Some(c) = nearest else {
            return Err(unsupported(
                "the source has a boundary and the target mesh none",
            ));
        };
        for &v in &l.vertices {
            roles[v.idx()] = Role::Curve(c);
        }
    }
    for curve in &problem.constraints.curves {
        let c = curves.len();
        curves.push(TargetCurve::through(target, &curve.target, false));
        let n = curve.source.len();
        for (k, &v) in curve.source.iter().enumerate() {
            roles[v.idx()] = if k == 0 || k + 1 == n {
                Role::Fixed
            } else {
                Role::Curve(c)
            };
        }
    }
    for &v in pins {
        roles[v.idx()] = Role::Fixed;
    }
    Ok((curves, roles))
}

/// The goal, checked: the frame `mu` is measured in, the target per face and `p`.
struct CheckedGoal {
    frame: Frame,
    sigma: Option<Vec<Complex64>>,
    p: f64,
}

fn unsupported(message: impl Into<String>) -> SolverError {
    SolverError::Unsupported {
        solver: NAME,
        message: message.into(),
    }
}

fn invalid(message: impl Into<String>) -> SolverError {
    SolverError::InvalidInput {
        solver: NAME,
        message: message.into(),
    }
}

/// Everything that can be checked before any work.
fn validate(problem: &Problem<'_>) -> Result<CheckedGoal, SolverError> {
    let mesh = problem.source;
    if let Some(f) = mesh.faces().find(|&f| mesh.face_degree(f) != 3) {
        return Err(unsupported(format!(
            "the flow works on triangle meshes; face {} (input index) has {} vertices: split quads into triangles first",
            mesh.face_to_input(f),
            mesh.face_degree(f)
        )));
    }
    let planar = is_planar(mesh);
    match &problem.target {
        Target::Plane(PlanarBoundary::Keep) => {
            if !planar {
                return Err(unsupported(
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
            return Err(unsupported(
                "the flow needs a target region; for a free or given boundary use lsqc",
            ));
        }
        Target::Annulus { inner_radius } => {
            if mesh.boundary_loop_count() != 2
                || mesh.component_count() != 1
                || mesh.genus() != Some(0)
            {
                return Err(unsupported(format!(
                    "the annulus target needs a connected genus-0 mesh with two boundary loops; this mesh has {}",
                    topology::describe(mesh)
                )));
            }
            if let Some(r) = inner_radius
                && !(*r > 0.0 && *r < 1.0)
            {
                return Err(invalid(format!(
                    "the inner radius must be in (0, 1), got {r}"
                )));
            }
            if problem.initial.is_none() {
                annulus_of(mesh)?;
            }
        }
        Target::Sphere => {
            topology::require_sphere(
                NAME,
                mesh,
                "use the disk or annulus targets for meshes with boundary",
            )?;
        }
        Target::Mesh(target) => {
            if target.boundary_loop_count() != mesh.boundary_loop_count()
                || target.genus() != mesh.genus()
                || target.component_count() != mesh.component_count()
            {
                return Err(unsupported(format!(
                    "the source and the target mesh differ in topology: source has {}, target has {}",
                    topology::describe(mesh),
                    topology::describe(target)
                )));
            }
            if problem.initial.is_none() {
                return Err(unsupported(
                    "a target mesh needs an initial map onto it: use the register solver, which builds one",
                ));
            }
            if let Some(f) = target.faces().find(|&f| target.face_degree(f) != 3) {
                return Err(unsupported(format!(
                    "the target mesh must be made of triangles; its face {} (input index) is not",
                    target.face_to_input(f)
                )));
            }
            for (k, curve) in problem.constraints.curves.iter().enumerate() {
                if curve.source.len() < 2 || curve.target.len() < 2 {
                    return Err(invalid(format!(
                        "curve {k} needs at least two source and two target vertices"
                    )));
                }
                if let Some(v) = curve.source.iter().find(|v| v.idx() >= mesh.vertex_count()) {
                    return Err(invalid(format!(
                        "curve {k}: source vertex {v} does not exist"
                    )));
                }
                if let Some(v) = curve
                    .target
                    .iter()
                    .find(|v| v.idx() >= target.vertex_count())
                {
                    return Err(invalid(format!(
                        "curve {k}: target vertex {v} does not exist"
                    )));
                }
                // The chain slides along its segments, which must lie on the target.
                for pair in curve.target.windows(2) {
                    if !target.vertex_neighbors(pair[0]).any(|w| w == pair[1]) {
                        return Err(invalid(format!(
                            "curve {k}: target vertices {} and {} (input indices) are not joined by an edge",
                            target.vertex_map().to_input(pair[0]),
                            target.vertex_map().to_input(pair[1])
                        )));
                    }
                }
            }
        }
        Target::CircleDomain | Target::Surface => {
            return Err(unsupported(
                "targets here: plane, disk, annulus, sphere, a target mesh (circle domains come with another solver)",
            ));
        }
    }
    for pin in &problem.constraints.pins {
        if pin.vertex.idx() >= mesh.vertex_count() {
            return Err(invalid(format!(
                "pinned vertex {} does not exist (the mesh has {} vertices)",
                pin.vertex,
                mesh.vertex_count()
            )));
        }
        match (&pin.position, &problem.target) {
            (None, _) | (Some(Position::Spatial(_)), Target::Mesh(_)) => {}
            _ => {
                return Err(unsupported(
                    "pins hold their vertex where the initial map puts it; pins at given positions (landmarks) are for target meshes",
                ));
            }
        }
    }
    if !problem.constraints.curves.is_empty() && !matches!(problem.target, Target::Mesh(_)) {
        return Err(unsupported(
            "curve constraints come with target meshes (register)",
        ));
    }
    if let Some(initial) = &problem.initial {
        let n = match initial {
            Map::Planar(z) => z.len(),
            Map::Spatial(p) => p.len(),
            Map::OnMesh(p) => p.len(),
        };
        if n != mesh.vertex_count() {
            return Err(invalid(format!(
                "the initial map has {n} images for {} vertices",
                mesh.vertex_count()
            )));
        }
    }
    match &problem.goal {
        Goal::Conformal { p } => {
            if !(p.is_finite() && *p >= 2.0) {
                return Err(invalid(format!("the L^p goal needs p >= 2, got {p}")));
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
                return Err(invalid(
                    "a field in the global frame needs a mesh in the plane z = 0; give it in the face frame",
                ));
            }
            Ok(CheckedGoal {
                frame: field.frame,
                sigma: Some(field.mu.clone()),
                p: 2.0,
            })
        }
        Goal::Extremal => Err(unsupported(
            "extremal (Teichmueller) maps come with their own solver",
        )),
    }
}

/// The inner radius of a planar annulus source centred at 0, and which boundary loop is
/// the outer one (index in `boundary_loop_list`).
fn annulus_of(mesh: &Mesh) -> Result<(f64, usize), SolverError> {
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
        return Err(unsupported(
            "the annulus target starts from a mesh already in an annulus r <= |z| <= 1 centred at 0 (both boundary loops on their circles), or from a given initial map",
        ));
    }
    Ok((r, outer))
}

/// The map the flow starts from, as points of R^3 (z = 0 for planar targets).
fn initial_map(problem: &Problem<'_>) -> Result<Vec<Point3<f64>>, SolverError> {
    let mesh = problem.source;
    if let Some(map) = &problem.initial {
        return Ok(match (map, &problem.target) {
            (Map::Planar(z), _) => z.iter().map(|z| Point3::new(z.re, z.im, 0.0)).collect(),
            (Map::Spatial(p), _) => p.clone(),
            (Map::OnMesh(points), Target::Mesh(target)) => points
                .iter()
                .enumerate()
                .map(|(v, p)| {
                    p.validate(target)
                        .map(|()| p.position(target))
                        .map_err(|e| invalid(format!("the initial map at vertex {v}: {e}")))
                })
                .collect::<Result<_, _>>()?,
            (Map::OnMesh(_), _) => {
                return Err(unsupported(
                    "an initial map on a mesh needs that mesh as the target",
                ));
            }
        });
    }
    let planar_points = |map: Map| match map {
        Map::Planar(z) => Ok(z.iter().map(|z| Point3::new(z.re, z.im, 0.0)).collect()),
        _ => Err(invalid("the initial map is not planar")),
    };
    let identity = || {
        mesh.positions()
            .iter()
            .map(|p| Point3::new(p.x, p.y, 0.0))
            .collect()
    };
    let mut init = Problem::new(mesh, problem.target.clone());
    init.params = problem.params;
    init.constraints.pins = problem.constraints.pins.clone();
    match &problem.target {
        Target::Plane(PlanarBoundary::Keep) => Ok(identity()),
        Target::Plane(b @ (PlanarBoundary::Square { .. } | PlanarBoundary::Polygon(_))) => {
            init.target = Target::Plane(b.clone());
            init.constraints.pins.clear();
            planar_points(Tutte.solve(&init, &mut Context::new())?.map)
        }
        Target::Plane(_) | Target::Disk => {
            let on_circle = is_planar(mesh)
                && mesh.boundary_loop_list()[0]
                    .vertices
                    .iter()
                    .all(|&v| (mesh.position(v).coords.xy().norm() - 1.0).abs() <= ON_TARGET);
            if on_circle {
                return Ok(identity());
            }
            init.target = Target::Plane(PlanarBoundary::Circle);
            init.constraints.pins.clear();
            planar_points(Tutte.solve(&init, &mut Context::new())?.map)
        }
        Target::Annulus { inner_radius } => {
            let (r0, _) = annulus_of(mesh)?;
            let r = inner_radius.unwrap_or(r0);
            // Radial stretch of [r0, 1] onto [r, 1]: a homeomorphism onto the target.
            Ok(mesh
                .positions()
                .iter()
                .map(|p| {
                    let rho = p.coords.xy().norm();
                    let new = r + (rho - r0) * (1.0 - r) / (1.0 - r0);
                    let s = if rho > 0.0 { new / rho } else { 1.0 };
                    Point3::new(p.x * s, p.y * s, 0.0)
                })
                .collect())
        }
        Target::Sphere => {
            let on_sphere = mesh
                .positions()
                .iter()
                .all(|p| (p.coords.norm() - 1.0).abs() <= ON_TARGET);
            if on_sphere {
                return Ok(mesh.positions().to_vec());
            }
            init.constraints.pins.clear();
            match Sphere.solve(&init, &mut Context::new())?.map {
                Map::Spatial(p) => Ok(p),
                _ => Err(invalid(
                    "the sphere initialization did not give points of R^3",
                )),
            }
        }
        _ => Err(unsupported("no initial map for this target")),
    }
}

/// The target geometry, ready for the flow.
enum Domain {
    Region(PlaneRegion),
    Disk(UnitDisk),
    /// The annulus and the index of its outer loop in `boundary_loop_list`.
    Annulus(Annulus, usize),
    Sphere(UnitSphere),
}

fn domain(problem: &Problem<'_>, image: &[Point3<f64>]) -> Result<Domain, SolverError> {
    let mesh = problem.source;
    Ok(match &problem.target {
        Target::Plane(
            PlanarBoundary::Keep | PlanarBoundary::Square { .. } | PlanarBoundary::Polygon(_),
        ) => Domain::Region(region(mesh, image)),
        Target::Plane(_) | Target::Disk => Domain::Disk(UnitDisk),
        Target::Annulus { inner_radius } => {
            let loops = mesh.boundary_loop_list();
            let radius = |k: usize| {
                loops[k]
                    .vertices
                    .iter()
                    .map(|&v| image[v.idx()].coords.xy().norm())
                    .sum::<f64>()
                    / loops[k].vertices.len() as f64
            };
            let outer = usize::from(radius(1) > radius(0));
            let inner = inner_radius.unwrap_or_else(|| radius(1 - outer));
            Domain::Annulus(
                Annulus {
                    inner_radius: inner,
                    free_inner: inner_radius.is_none(),
                },
                outer,
            )
        }
        Target::Sphere => Domain::Sphere(UnitSphere),
        _ => return Err(unsupported("no flow for this target")),
    })
}

/// The straight sides of the image's boundary: runs of boundary vertices between
/// corners, where the boundary turns by more than [`CORNER_ANGLE`].
fn region(mesh: &Mesh, image: &[Point3<f64>]) -> PlaneRegion {
    let mut sides = Vec::new();
    for l in mesh.boundary_loop_list() {
        let corners = loop_corners(&l.vertices, image);
        for (k, &c) in corners.iter().enumerate() {
            let next = corners[(k + 1) % corners.len()];
            sides.push(Side {
                a: image[l.vertices[c].idx()],
                b: image[l.vertices[next].idx()],
            });
        }
    }
    PlaneRegion { sides }
}

/// Positions in `vertices` (a boundary loop) of its corners (at least one).
fn loop_corners(vertices: &[VertexId], image: &[Point3<f64>]) -> Vec<usize> {
    let n = vertices.len();
    let at = |k: usize| image[vertices[k % n].idx()];
    let mut corners: Vec<usize> = (0..n)
        .filter(|&k| {
            let incoming = at(k) - at(k + n - 1);
            let outgoing = at(k + 1) - at(k);
            let cross = incoming.x * outgoing.y - incoming.y * outgoing.x;
            let dot = incoming.x * outgoing.x + incoming.y * outgoing.y;
            cross.atan2(dot).abs() > CORNER_ANGLE
        })
        .collect();
    if corners.is_empty() {
        corners.push(0);
    }
    corners
}

/// Roles on a planar region: corners and pins fixed, other boundary vertices on the side
/// between their corners, interior vertices free.
fn region_roles(
    mesh: &Mesh,
    region: &PlaneRegion,
    image: &[Point3<f64>],
    pins: &[VertexId],
) -> Vec<Role> {
    let mut roles = vec![Role::Free; mesh.vertex_count()];
    let mut side = 0;
    for l in mesh.boundary_loop_list() {
        let corners = loop_corners(&l.vertices, image);
        for (k, &c) in corners.iter().enumerate() {
            roles[l.vertices[c].idx()] = Role::Fixed;
            let next = corners[(k + 1) % corners.len()];
            let mut j = (c + 1) % l.vertices.len();
            while j != next {
                roles[l.vertices[j].idx()] = Role::Curve(side);
                j = (j + 1) % l.vertices.len();
            }
            side += 1;
        }
    }
    debug_assert_eq!(side, region.sides.len());
    for &v in pins {
        roles[v.idx()] = Role::Fixed;
    }
    roles
}

/// Roles on a domain whose boundary loop `k` lies on curve `curve_of(k)`: boundary
/// vertices on their curve, pins fixed, the rest free.
fn curve_roles(mesh: &Mesh, pins: &[VertexId], curve_of: impl Fn(usize) -> usize) -> Vec<Role> {
    let mut roles = vec![Role::Free; mesh.vertex_count()];
    for (k, l) in mesh.boundary_loop_list().iter().enumerate() {
        for &v in &l.vertices {
            roles[v.idx()] = Role::Curve(curve_of(k));
        }
    }
    for &v in pins {
        roles[v.idx()] = Role::Fixed;
    }
    roles
}

/// The pinned vertices: the problem's, or the default ones of the target (the vertex
/// nearest to each normalization point of the initial map).
fn pins(problem: &Problem<'_>, image: &[Point3<f64>]) -> Vec<VertexId> {
    let mesh = problem.source;
    if !problem.constraints.pins.is_empty() {
        return problem.constraints.pins.iter().map(|p| p.vertex).collect();
    }
    let nearest = |candidates: &mut dyn Iterator<Item = VertexId>, q: Point3<f64>| {
        candidates.min_by(|&a, &b| {
            (image[a.idx()] - q)
                .norm()
                .total_cmp(&(image[b.idx()] - q).norm())
        })
    };
    let boundary = |l: usize| mesh.boundary_loop_list()[l].vertices.clone();
    let mut out = Vec::new();
    match &problem.target {
        Target::Plane(PlanarBoundary::Circle) | Target::Disk => {
            out.extend(nearest(&mut mesh.vertices(), Point3::origin()));
            out.extend(nearest(
                &mut boundary(0).into_iter(),
                Point3::new(1.0, 0.0, 0.0),
            ));
        }
        Target::Annulus { .. } => {
            let loops = mesh.boundary_loop_list();
            let mean = |k: usize| {
                loops[k]
                    .vertices
                    .iter()
                    .map(|&v| image[v.idx()].coords.norm())
                    .sum::<f64>()
                    / loops[k].vertices.len() as f64
            };
            let outer = usize::from(mean(1) > mean(0));
            out.extend(nearest(
                &mut boundary(outer).into_iter(),
                Point3::new(1.0, 0.0, 0.0),
            ));
        }
        Target::Sphere => {
            for q in [
                Point3::new(0.0, 0.0, -1.0),
                Point3::new(1.0, 0.0, 0.0),
                Point3::new(0.0, 0.0, 1.0),
            ] {
                if let Some(v) = nearest(&mut mesh.vertices().filter(|v| !out.contains(v)), q) {
                    out.push(v);
                }
            }
        }
        _ => {}
    }
    out
}

fn diagonal(image: &[Point3<f64>]) -> f64 {
    beltrami_mesh::BoundingBox::around(image)
        .map_or(1.0, |b| b.diagonal())
        .max(f64::MIN_POSITIVE)
}

/// Per source vertex, the point a landmark pulls it to (pins with a position on a target
/// mesh: the vertex is moved there by the flow, then held).
fn goals(problem: &Problem<'_>) -> Vec<Option<Point3<f64>>> {
    let mut goals = vec![None; problem.source.vertex_count()];
    for pin in &problem.constraints.pins {
        if let Some(Position::Spatial(p)) = pin.position {
            goals[pin.vertex.idx()] = Some(p);
        }
    }
    goals
}

/// What every flow run of one solve shares.
struct Runner<'a, 'p> {
    elements: &'a Elements,
    objective: &'a Objective,
    problem: &'a Problem<'p>,
    options: SolveOptions,
}

impl Runner<'_, '_> {
    /// Runs the flow on `target` from `image` with `roles` (tolerances relative to
    /// `scale`) and records its history in `report`.
    fn run<G: TargetGeometry>(
        &self,
        target: G,
        roles: Vec<Role>,
        image: Vec<Point3<f64>>,
        scale: f64,
        context: &mut Context<'_>,
        report: &mut Report,
    ) -> Result<FlowRun<G>, SolverError> {
        let (elements, objective, problem, options) =
            (self.elements, self.objective, self.problem, self.options);
        let mut system = context.stage("symbolic", report, || {
            FlowSystem::new(elements, &target, &image, roles, options)
        })?;
        let flow_options = FlowOptions {
            tolerance: problem.params.tolerance * scale,
            max_iterations: problem.params.max_iterations,
            solve: options,
            max_move: if matches!(problem.target, Target::Mesh(_)) {
                MESH_MAX_MOVE * scale
            } else {
                f64::INFINITY
            },
        };
        let run = report.time("flow", || {
        flow::run(
            elements,
            target,
            &mut system,
            image,
            &goals(problem),
            objective,
            flow_options,
            context,
        )
    })
    .map_err(|e| match e {
        SolverError::Solve(beltrami_fem::SolveError::Singular { .. } | beltrami_fem::SolveError::NotPositiveDefinite { .. }) => invalid(
            "the flow is not determined: pin more vertices (disk: one interior and one boundary vertex; annulus: one boundary vertex; sphere: three vertices)",
        ),
        e => e,
    })?;
        report
            .timings
            .push(("flow: solves".into(), run.solve_seconds));
        report
            .timings
            .push(("flow: steps".into(), run.step_seconds));
        report.iterations = run.iterations();
        report.notes.push(format!(
            "{} numeric factorizations; {} conjugate-gradient iterations on steps that reused one",
            run.factorizations, run.cg_iterations
        ));
        report.energy_history = run.energy_history.clone();
        report.step_sizes = run.step_sizes.clone();
        report.notes.push(match run.stop {
        Stop::Converged => format!(
            "converged after {} iterations: largest vertex update below {:.1e}",
            run.iterations(),
            flow_options.tolerance
        ),
        Stop::Stalled => format!(
            "stopped after {} iterations: no step above the tolerance decreased the error further",
            run.iterations()
        ),
        Stop::IterationLimit => format!(
            "stopped at the iteration limit ({}) before converging",
            run.iterations()
        ),
        Stop::Cancelled => format!(
            "cancelled after {} iterations: the map is the best one so far",
            run.iterations()
        ),
    });
        Ok(run)
    }
}

impl<G> FlowRun<G> {
    /// The map, the per-face `mu` and flip flags.
    fn finish(self, planar: bool) -> (Map, Vec<Complex64>, Vec<bool>) {
        let mu = self.faces.iter().map(|f| f.mu()).collect();
        let flipped = self.faces.iter().map(|f| f.flipped()).collect();
        let map = if planar {
            Map::Planar(
                self.image
                    .iter()
                    .map(|p| Complex64::new(p.x, p.y))
                    .collect(),
            )
        } else {
            Map::Spatial(self.image)
        };
        (map, mu, flipped)
    }
}
