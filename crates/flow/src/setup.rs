//! Setting up a flow: the initial map, the target geometry, the role of every vertex,
//! the pins and the landmark goals.

use beltrami_core::{Constraint, Map, PlanarBoundary, Problem, SolverError, Target};
use beltrami_mesh::{Mesh, Point3, VertexId};

use crate::mesh_target::TargetCurve;
use crate::target::{Annulus, PlaneRegion, Role, Side, UnitDisk, UnitSphere};

/// Boundary vertices whose boundary turns by less than this (radians) slide along a
/// straight side of a planar region; the others are corners and stay.
const CORNER_ANGLE: f64 = 1e-6;

/// The images of a given initial map (`problem.initial`) as points of R^3 (`z = 0` for a
/// planar map; a map on a target mesh at its surface points), or `None` without one.
pub fn given_initial(problem: &Problem<'_>) -> Result<Option<Vec<Point3<f64>>>, SolverError> {
    let Some(map) = &problem.initial else {
        return Ok(None);
    };
    Ok(Some(match (map, &problem.target) {
        (Map::Planar(z), _) => z.iter().map(|z| Point3::new(z.re, z.im, 0.0)).collect(),
        (Map::Spatial(p), _) => p.clone(),
        (Map::OnMesh(points), Target::Mesh(target)) => points
            .iter()
            .enumerate()
            .map(|(v, p)| {
                p.validate(target)
                    .map(|()| p.position(target))
                    .map_err(|e| {
                        SolverError::invalid(
                            crate::NAME,
                            format!("the initial map at vertex {v}: {e}"),
                        )
                    })
            })
            .collect::<Result<_, _>>()?,
        (Map::OnMesh(_), _) => {
            return Err(SolverError::unsupported(
                crate::NAME,
                "an initial map on a mesh needs that mesh as the target",
            ));
        }
    }))
}

/// The target geometry, ready for the flow.
pub(crate) enum Domain {
    Region(PlaneRegion),
    Disk(UnitDisk),
    /// The annulus and the index of its outer loop in `boundary_loop_list`.
    Annulus(Annulus, usize),
    Sphere(UnitSphere),
}

pub(crate) fn domain(problem: &Problem<'_>, image: &[Point3<f64>]) -> Result<Domain, SolverError> {
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
        _ => {
            return Err(SolverError::unsupported(
                crate::NAME,
                "no flow for this target",
            ));
        }
    })
}

/// The straight sides of the image's boundary: runs of boundary vertices between
/// corners, where the boundary turns by more than [`CORNER_ANGLE`].
pub(crate) fn region(mesh: &Mesh, image: &[Point3<f64>]) -> PlaneRegion {
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
pub(crate) fn loop_corners(vertices: &[VertexId], image: &[Point3<f64>]) -> Vec<usize> {
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
pub(crate) fn region_roles(
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
pub(crate) fn curve_roles(
    mesh: &Mesh,
    pins: &[VertexId],
    curve_of: impl Fn(usize) -> usize,
) -> Vec<Role> {
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

/// The held vertices: the problem's pins and landmarks (a landmark is held once it has
/// arrived), or, with neither, the default ones of the target (the vertex nearest to
/// each normalization point of the initial map).
pub(crate) fn pins(problem: &Problem<'_>, image: &[Point3<f64>]) -> Vec<VertexId> {
    let mesh = problem.source;
    let given: Vec<VertexId> = problem
        .constraints
        .iter()
        .filter_map(|c| match c {
            Constraint::Pin(p) => Some(p.vertex),
            Constraint::Landmark(l) => Some(l.vertex),
            _ => None,
        })
        .collect();
    if !given.is_empty() {
        return given;
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

pub(crate) fn diagonal(image: &[Point3<f64>]) -> f64 {
    beltrami_mesh::BoundingBox::around(image)
        .map_or(1.0, |b| b.diagonal())
        .max(f64::MIN_POSITIVE)
}

/// Per source vertex, the point a landmark pulls it to (the vertex is moved there by
/// the flow, then held).
pub(crate) fn goals(problem: &Problem<'_>) -> Vec<Option<Point3<f64>>> {
    let target = match problem.target {
        Target::Mesh(target) => Some(target),
        _ => None,
    };
    let mut goals = vec![None; problem.source.vertex_count()];
    for mark in problem.constraints.landmarks() {
        goals[mark.vertex.idx()] = mark.position.point(target);
    }
    goals
}

/// The curves of a target mesh (its boundary loops, then the problem's feature curves)
/// and the roles of the source vertices: each source boundary loop slides on the target
/// loop nearest to its initial image, each feature curve's inner vertices on its target
/// chain (ends fixed), pins fixed, the rest free.
pub(crate) fn mesh_roles(
    problem: &Problem<'_>,
    target: &Mesh,
    image: &[Point3<f64>],
    pins: &[VertexId],
) -> Result<(Vec<TargetCurve>, Vec<Role>), SolverError> {
    let mesh = problem.source;
    let mut curves = TargetCurve::boundary_loops(target)?;
    let mut roles = vec![Role::Free; mesh.vertex_count()];
    for l in mesh.boundary_loop_list() {
        let nearest = (0..curves.len()).min_by(|&a, &b| {
            let d = |c: usize| curves[c].mean_distance(l.vertices.iter().map(|v| &image[v.idx()]));
            d(a).total_cmp(&d(b))
        });
        let Some(c) = nearest else {
            return Err(SolverError::unsupported(
                crate::NAME,
                "the source has a boundary and the target mesh none",
            ));
        };
        for &v in &l.vertices {
            roles[v.idx()] = Role::Curve(c);
        }
    }
    for curve in problem.constraints.curves() {
        let c = curves.len();
        curves.push(TargetCurve::through(target, &curve.target, false)?);
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
