//! A solve on renumbered copies of scattered meshes, and its result put back in the
//! meshes' own numbering.
//!
//! Solvers gather and scatter per-vertex values face by face (assembly, image faces,
//! measures) and walk from face to face on a target mesh; on a mesh whose file lists its
//! vertices in scattered order nearly every such access misses the cache
//! ([`beltrami_mesh::renumber`]). A solver that opts in ([`solve_renumbered`] around
//! its run) renumbers each mesh of the problem whose median index spread
//! ([`index_spread`]) exceeds [`SCATTERED_SPREAD`] breadth-first, solves the problem
//! carried into the new numbering ([`Renumbered::problem`]) and carries the solution
//! back ([`Renumbered::solution_to_old`]), so that the result is the solution of the
//! given problem, vertex by vertex and face by face; messages name input indices either
//! way (the renumbered meshes' input maps are composed).
//!
//! Carried over: pins, landmarks and slides (their vertex), curves (the source chain;
//! the target chain on the target mesh, or on the source when there is none), normal
//! and area constraints, a prescribed field (per face), the initial map (per vertex;
//! a point's face on the target mesh); back: the map, a new mesh's points on the
//! source, the `mu` field, the face of `mu`'s largest error, a quadratic differential.
//! Problems with boundary-loop matches or per-halfedge reference angles, and problems
//! onto planar domains (whose conventions follow the numbering: a circle parameterized
//! from the first vertex of a loop, per-vertex boundary values), are solved as given:
//! renumbering serves maps onto the sphere and onto target meshes.

use beltrami_mesh::{
    Mesh, MeshError, Renumbering, SurfacePoint, index_spread, renumber_breadth_first,
};

use crate::{
    Constraint, Constraints, Curve, Goal, Landmark, Map, Output, Pin, Position, Problem, Slide,
    Solution, SolverError, Target,
};

/// The median index spread from which a mesh is renumbered: 4096 vertices of a flow's
/// per-vertex data (position, normal, tangent basis, image: about 200 bytes) fill 800
/// KB, more than a core's 512 KB second-level cache. Meshes written by a remesher or a
/// generator have spreads of a few hundred (`beltrami remesh` output at 50,000
/// vertices: 300-320); scanned or decimated ones can have tens of thousands
/// (`g0_koala`: 20461).
pub const SCATTERED_SPREAD: usize = 4096;

/// A mesh renumbered, its index spread before, or `None` when its numbering was kept.
type MaybeRenumbered = Option<(Mesh, Renumbering, usize)>;

/// The renumbered meshes of a problem (module docs).
#[derive(Debug)]
pub struct Renumbered {
    source: MaybeRenumbered,
    target: MaybeRenumbered,
}

/// `mesh` renumbered when its index spread exceeds `spread`.
fn renumbered_if_scattered(mesh: &Mesh, spread: usize) -> Result<MaybeRenumbered, MeshError> {
    let before = index_spread(mesh);
    if before > spread {
        let (renumbered, numbering) = renumber_breadth_first(mesh)?;
        Ok(Some((renumbered, numbering, before)))
    } else {
        Ok(None)
    }
}

/// `values[old]` by vertex, in the new order.
fn vertices_to_new<T: Clone>(numbering: Option<&Renumbering>, values: &[T]) -> Vec<T> {
    numbering.map_or_else(|| values.to_vec(), |n| n.vertex_values_to_new(values))
}

/// `values[new]` by vertex, in the old order.
fn vertices_to_old<T: Clone>(numbering: Option<&Renumbering>, values: &mut Vec<T>) {
    if let Some(n) = numbering {
        *values = n.vertex_values_to_old(values);
    }
}

/// `run(problem)`, on renumbered copies of the problem's meshes whose index spread
/// exceeds [`SCATTERED_SPREAD`] and with the solution carried back (module docs); a
/// note in the report says what was renumbered.
pub fn solve_renumbered(
    problem: &Problem<'_>,
    run: impl FnOnce(&Problem<'_>) -> Result<Solution, SolverError>,
) -> Result<Solution, SolverError> {
    let Some(renumbered) = Renumbered::new(problem, SCATTERED_SPREAD)? else {
        return run(problem);
    };
    let mut solution = run(&renumbered.problem(problem))?;
    solution.report.notes.insert(0, renumbered.note());
    Ok(renumbered.solution_to_old(solution))
}

impl Renumbered {
    /// The meshes of `problem` (its source and a target mesh) whose index spread
    /// exceeds `spread` renumbered ([`SCATTERED_SPREAD`] for a solver); `None` when none
    /// is, or when the problem has references this module does not carry (module docs).
    ///
    /// Errors: the [`MeshError`] of a rebuild (none for a mesh built by
    /// `beltrami_mesh`).
    pub fn new(problem: &Problem<'_>, spread: usize) -> Result<Option<Self>, MeshError> {
        let carried = problem
            .constraints
            .iter()
            .all(|c| !matches!(c, Constraint::LoopMatch(_) | Constraint::ReferenceAngles(_)));
        // Planar targets' conventions follow the numbering (a circle parameterized from
        // the first vertex of a loop, per-vertex boundary values, given corners).
        let target_carried = matches!(problem.target, Target::Sphere | Target::Mesh(_));
        if !carried || !target_carried {
            return Ok(None);
        }
        let source = renumbered_if_scattered(problem.source, spread)?;
        let target = match problem.target {
            Target::Mesh(target) => renumbered_if_scattered(target, spread)?,
            _ => None,
        };
        if source.is_none() && target.is_none() {
            return Ok(None);
        }
        Ok(Some(Self { source, target }))
    }

    fn source_numbering(&self) -> Option<&Renumbering> {
        self.source.as_ref().map(|(_, n, _)| n)
    }

    fn target_numbering(&self) -> Option<&Renumbering> {
        self.target.as_ref().map(|(_, n, _)| n)
    }

    /// What was renumbered, with the spreads before and after, for the report.
    pub fn note(&self) -> String {
        let done: Vec<String> = [("source", &self.source), ("target", &self.target)]
            .iter()
            .filter_map(|(name, side)| {
                let (renumbered, _, before) = side.as_ref()?;
                Some(format!(
                    "the {name} (median index spread of a face {before} -> {})",
                    index_spread(renumbered)
                ))
            })
            .collect();
        format!(
            "renumbered breadth-first for cache locality: {}; results are in the input numbering",
            done.join(" and ")
        )
    }

    /// `problem` in the new numbering.
    pub fn problem<'a>(&'a self, problem: &Problem<'a>) -> Problem<'a> {
        let (source_numbering, target_numbering) =
            (self.source_numbering(), self.target_numbering());
        let vertex = |v| source_numbering.map_or(v, |n: &Renumbering| n.new_vertex(v));
        // A curve's target chain lies on the target mesh, or on the source itself.
        let chain_numbering = match problem.target {
            Target::Mesh(_) => target_numbering,
            _ => source_numbering,
        };
        let chain_vertex = |v| chain_numbering.map_or(v, |n: &Renumbering| n.new_vertex(v));
        let position = |p| match p {
            Position::TargetVertex(w) => Position::TargetVertex(
                target_numbering.map_or(w, |n: &Renumbering| n.new_vertex(w)),
            ),
            other => other,
        };
        let mut constraints = Constraints::new();
        for constraint in problem.constraints.iter() {
            constraints.push(match constraint {
                Constraint::Pin(pin) => Constraint::Pin(Pin {
                    vertex: vertex(pin.vertex),
                    position: pin.position.map(position),
                }),
                Constraint::Landmark(mark) => Constraint::Landmark(Landmark {
                    vertex: vertex(mark.vertex),
                    position: position(mark.position),
                }),
                Constraint::Slide(slide) => Constraint::Slide(Slide {
                    vertex: vertex(slide.vertex),
                    ..*slide
                }),
                Constraint::Curve(curve) => Constraint::Curve(Curve {
                    source: curve.source.iter().map(|&v| vertex(v)).collect(),
                    target: curve.target.iter().map(|&v| chain_vertex(v)).collect(),
                    closed: curve.closed,
                }),
                // Normal and area constraints name nothing; `new` declines the rest.
                other => other.clone(),
            });
        }
        let goal = match (&problem.goal, source_numbering) {
            (Goal::Prescribed(field), Some(n)) => {
                let mut field = field.clone();
                field.mu = n.face_values_to_new(&field.mu);
                Goal::Prescribed(field)
            }
            (Goal::Features(features), _) => Goal::Features(crate::Features {
                source: vertices_to_new(source_numbering, &features.source),
                target: vertices_to_new(target_numbering, &features.target),
            }),
            (goal, _) => goal.clone(),
        };
        let initial = problem.initial.as_ref().map(|map| match map {
            Map::Planar(z) => Map::Planar(vertices_to_new(source_numbering, z)),
            Map::Spatial(x) => Map::Spatial(vertices_to_new(source_numbering, x)),
            Map::OnMesh(points) => {
                let moved: Vec<SurfacePoint> = points
                    .iter()
                    .map(|p| SurfacePoint {
                        face: target_numbering.map_or(p.face, |n| n.new_face(p.face)),
                        ..*p
                    })
                    .collect();
                Map::OnMesh(vertices_to_new(source_numbering, &moved))
            }
        });
        let target = match &problem.target {
            Target::Mesh(target) => {
                Target::Mesh(self.target.as_ref().map_or(*target, |(m, _, _)| m))
            }
            other => other.clone(),
        };
        Problem {
            source: self.source.as_ref().map_or(problem.source, |(m, _, _)| m),
            target,
            goal,
            constraints,
            initial,
            options: problem.options.clone(),
        }
    }

    /// `solution` (of [`Renumbered::problem`]) in the given meshes' numbering.
    pub fn solution_to_old(&self, mut solution: Solution) -> Solution {
        let (source_numbering, target_numbering) =
            (self.source_numbering(), self.target_numbering());
        match &mut solution.output {
            Output::Map(Map::Planar(z)) => vertices_to_old(source_numbering, z),
            Output::Map(Map::Spatial(x)) => vertices_to_old(source_numbering, x),
            Output::Map(Map::OnMesh(points)) => {
                if let Some(n) = target_numbering {
                    for p in points.iter_mut() {
                        p.face = n.old_face(p.face);
                    }
                }
                vertices_to_old(source_numbering, points);
            }
            Output::Mesh(remeshed) => {
                if let Some(n) = source_numbering {
                    for p in &mut remeshed.on_source {
                        p.face = n.old_face(p.face);
                    }
                }
            }
        }
        if let Some(n) = source_numbering {
            if let Some(field) = &mut solution.metrics.mu {
                field.mu = n.face_values_to_old(&field.mu);
            }
            if let Some(error) = &mut solution.metrics.mu_error {
                error.sup_face = n.old_face(error.sup_face);
            }
            if let Some(phi) = &mut solution.extras.quadratic_differential {
                phi.values = n.face_values_to_old(&phi.values);
            }
            for mark in &mut solution.extras.landmarks {
                mark.vertex = n.old_vertex(mark.vertex);
            }
        }
        solution
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use beltrami_fem::{BeltramiField, Frame};
    use beltrami_mesh::primitives::{icosphere, octahedral_sphere, scattered};
    use beltrami_mesh::{Point3, VertexId};
    use num_complex::Complex64;

    fn scattered_mesh(soup: &beltrami_mesh::PolygonSoup) -> Mesh {
        Mesh::from_soup(&scattered(soup)).unwrap()
    }

    #[test]
    fn the_problem_s_vertices_and_field_follow_the_renumbering() {
        let source = scattered_mesh(&octahedral_sphere(2));
        let target = scattered_mesh(&icosphere(2));
        let mut problem = Problem::new(&source, Target::Mesh(&target));
        let chain = |ids: &[u32]| ids.iter().map(|&i| VertexId(i)).collect::<Vec<_>>();
        problem.constraints.push(Constraint::Curve(Curve::open(
            chain(&[1, 7, 20]),
            chain(&[2, 30, 41]),
        )));
        problem.constraints.push(Constraint::Landmark(Landmark {
            vertex: VertexId(5),
            position: Position::Spatial(Point3::new(0.0, 0.0, 1.0)),
        }));
        problem.constraints.push(Constraint::Landmark(Landmark {
            vertex: VertexId(9),
            position: Position::TargetVertex(VertexId(33)),
        }));
        let mu: Vec<Complex64> = (0..source.face_count())
            .map(|f| Complex64::new(f as f64 * 1e-3, 0.0))
            .collect();
        problem.goal = Goal::Prescribed(BeltramiField::new(Frame::Face, mu.clone()));
        let renumbered = Renumbered::new(&problem, 0).unwrap().unwrap();
        let local = renumbered.problem(&problem);
        let Target::Mesh(local_target) = local.target else {
            panic!("a target mesh");
        };
        // The same points, named in the new numbering.
        let curve = local.constraints.curves().next().unwrap();
        for (&old, &new) in chain(&[1, 7, 20]).iter().zip(&curve.source) {
            assert_eq!(local.source.position(new), source.position(old));
        }
        for (&old, &new) in chain(&[2, 30, 41]).iter().zip(&curve.target) {
            assert_eq!(local_target.position(new), target.position(old));
        }
        let marks: Vec<_> = local.constraints.landmarks().collect();
        assert_eq!(
            local.source.position(marks[0].vertex),
            source.position(VertexId(5))
        );
        assert_eq!(
            local.source.position(marks[1].vertex),
            source.position(VertexId(9))
        );
        let Position::TargetVertex(onto) = marks[1].position else {
            panic!("a target vertex stays a target vertex");
        };
        assert_eq!(local_target.position(onto), target.position(VertexId(33)));
        let Goal::Prescribed(field) = &local.goal else {
            panic!("a prescribed goal");
        };
        for f in local.source.faces() {
            let old = local.source.face_to_input(f);
            assert_eq!(field.mu[f.idx()], mu[old]);
        }
    }

    #[test]
    fn planar_targets_keep_the_numbering_and_sphere_maps_come_back_vertex_by_vertex() {
        let mesh = scattered_mesh(&octahedral_sphere(3));
        for target in [Target::Disk, Target::Plane(crate::PlanarBoundary::Circle)] {
            assert!(
                Renumbered::new(&Problem::new(&mesh, target), 0)
                    .unwrap()
                    .is_none()
            );
        }
        let problem = Problem::new(&mesh, Target::Sphere);
        assert!(Renumbered::new(&problem, usize::MAX).unwrap().is_none());
        let renumbered = Renumbered::new(&problem, 0).unwrap().unwrap();
        let local = renumbered.problem(&problem);
        // The identity map of the renumbered mesh is the identity of the given one.
        let identity = Map::Spatial(local.source.positions().to_vec());
        let back =
            renumbered.solution_to_old(Solution::from_map(identity, crate::Report::new("t")));
        assert_eq!(back.map().and_then(Map::as_spatial), Some(mesh.positions()));
        assert!(
            renumbered
                .note()
                .contains("the source (median index spread")
        );
    }
}
