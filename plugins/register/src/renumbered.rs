//! A registration run on renumbered copies of scattered meshes, and its result put back
//! in the meshes' own numbering.
//!
//! The flow gathers and scatters per-vertex values face by face at every step, and walks
//! from face to face on the target; on a mesh whose file lists its vertices in
//! scattered order nearly every access misses the cache
//! ([`beltrami_mesh::renumber`]). A mesh whose median index spread
//! ([`index_spread`]) exceeds [`SCATTERED_SPREAD`] is renumbered breadth-first before
//! anything else; the problem's vertex and face references are carried into the new
//! numbering, and the solution's out of it, so that the result is the registration of
//! the given meshes, vertex by vertex and face by face. Messages name input indices
//! either way (the renumbered meshes' input maps are composed).

use beltrami_core::{
    Constraint, Constraints, Curve, Goal, Landmark, Map, Output, Problem, Solution, Target,
};
use beltrami_mesh::{Mesh, Renumbering, index_spread, renumber_breadth_first};

use crate::{RegisterError, Side};

/// The median index spread from which a mesh is renumbered: 4096 vertices of the flow's
/// per-vertex data (position, normal, tangent basis, image: about 200 bytes) fill 800
/// KB, more than a core's 512 KB second-level cache. Meshes written by a remesher or a
/// generator have spreads of a few hundred (`beltrami remesh` output at 50,000
/// vertices: 300-320); scanned or decimated ones can have tens of thousands
/// (`g0_koala`: 20461).
pub(crate) const SCATTERED_SPREAD: usize = 4096;

/// A mesh renumbered, or `None` when its numbering was kept.
type MaybeRenumbered = Option<(Mesh, Renumbering)>;

/// The renumbered source and target of a registration (module docs).
pub(crate) struct Renumbered {
    source: MaybeRenumbered,
    target: MaybeRenumbered,
}

/// `mesh` (the registration's `side`) renumbered when its index spread exceeds
/// `spread`.
fn renumbered_if_scattered(
    mesh: &Mesh,
    side: Side,
    spread: usize,
) -> Result<MaybeRenumbered, RegisterError> {
    if index_spread(mesh) > spread {
        renumber_breadth_first(mesh)
            .map(Some)
            .map_err(|error| RegisterError::Renumbering { side, error })
    } else {
        Ok(None)
    }
}

impl Renumbered {
    /// Those of `problem`'s source and `target` whose index spread exceeds `spread`
    /// renumbered ([`SCATTERED_SPREAD`] in a registration); `None` when neither is, or
    /// when the problem has constraints other than the landmarks and curves registration
    /// reads (only those are carried over).
    pub(crate) fn new(
        problem: &Problem<'_>,
        target: &Mesh,
        spread: usize,
    ) -> Result<Option<Self>, RegisterError> {
        let carried = problem
            .constraints
            .iter()
            .all(|c| matches!(c, Constraint::Landmark(_) | Constraint::Curve(_)));
        if !carried {
            return Ok(None);
        }
        let source = renumbered_if_scattered(problem.source, Side::Source, spread)?;
        let target = renumbered_if_scattered(target, Side::Target, spread)?;
        if source.is_none() && target.is_none() {
            return Ok(None);
        }
        Ok(Some(Self { source, target }))
    }

    /// What was renumbered, with the spreads before and after, for the report.
    pub(crate) fn note(&self, problem: &Problem<'_>, target: &Mesh) -> String {
        let sides = [
            ("source", problem.source, &self.source),
            ("target", target, &self.target),
        ];
        let done: Vec<String> = sides
            .iter()
            .filter_map(|(name, mesh, side)| {
                side.as_ref().map(|(renumbered, _)| {
                    format!(
                        "the {name} (median index spread of a face {} -> {})",
                        index_spread(mesh),
                        index_spread(renumbered)
                    )
                })
            })
            .collect();
        format!(
            "renumbered breadth-first for cache locality: {}; results are in the input numbering",
            done.join(" and ")
        )
    }

    /// `problem` (onto `target`) in the new numbering.
    pub(crate) fn problem<'a>(&'a self, problem: &Problem<'a>, target: &'a Mesh) -> Problem<'a> {
        let source_numbering = self.source.as_ref().map(|(_, n)| n);
        let target_numbering = self.target.as_ref().map(|(_, n)| n);
        let vertex = |v| source_numbering.map_or(v, |n: &Renumbering| n.new_vertex(v));
        let target_vertex = |v| target_numbering.map_or(v, |n: &Renumbering| n.new_vertex(v));
        let mut constraints = Constraints::new();
        for constraint in problem.constraints.iter() {
            constraints.push(match constraint {
                Constraint::Landmark(mark) => Constraint::Landmark(Landmark {
                    vertex: vertex(mark.vertex),
                    ..*mark
                }),
                Constraint::Curve(curve) => Constraint::Curve(Curve {
                    source: curve.source.iter().map(|&v| vertex(v)).collect(),
                    target: curve.target.iter().map(|&v| target_vertex(v)).collect(),
                    closed: curve.closed,
                }),
                // `new` renumbers only problems with landmarks and curves.
                other => other.clone(),
            });
        }
        let goal = match (&problem.goal, source_numbering) {
            (Goal::Prescribed(field), Some(n)) => {
                let mut field = field.clone();
                field.mu = n.face_values_to_new(&field.mu);
                Goal::Prescribed(field)
            }
            (goal, _) => goal.clone(),
        };
        Problem {
            source: self.source.as_ref().map_or(problem.source, |(m, _)| m),
            target: Target::Mesh(self.target.as_ref().map_or(target, |(m, _)| m)),
            goal,
            constraints,
            // Registration builds its own initial map.
            initial: None,
            options: problem.options.clone(),
        }
    }

    /// `solution` (of [`Renumbered::problem`]) in the given meshes' numbering.
    pub(crate) fn solution_to_old(&self, mut solution: Solution) -> Solution {
        let source_numbering = self.source.as_ref().map(|(_, n)| n);
        let target_numbering = self.target.as_ref().map(|(_, n)| n);
        if let Output::Map(Map::OnMesh(points)) = &mut solution.output {
            if let Some(n) = target_numbering {
                for p in points.iter_mut() {
                    p.face = n.old_face(p.face);
                }
            }
            if let Some(n) = source_numbering {
                *points = n.vertex_values_to_old(points);
            }
        }
        if let Some(n) = source_numbering {
            if let Some(field) = &mut solution.metrics.mu {
                field.mu = n.face_values_to_old(&field.mu);
            }
            if let Some(error) = &mut solution.metrics.mu_error {
                error.sup_face = n.old_face(error.sup_face);
            }
        }
        solution
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Register;
    use crate::solver::register;
    use beltrami_core::{Context, Position, Solver};
    use beltrami_fem::distortion::measure_surface;
    use beltrami_fem::{BeltramiField, Frame, ReferenceNormal};
    use beltrami_mesh::primitives::{self, icosphere, octahedral_sphere};
    use beltrami_mesh::{Point3, PolygonSoup, VertexId};
    use num_complex::Complex64;

    fn scattered(soup: &PolygonSoup) -> Mesh {
        Mesh::from_soup(&primitives::scattered(soup)).unwrap()
    }

    #[test]
    fn a_registration_of_renumbered_meshes_is_the_registration_of_the_given_ones() {
        let source = scattered(&octahedral_sphere(3));
        let mut soup = icosphere(3);
        for p in &mut soup.positions {
            *p = Point3::new(1.6 * p.x, p.y + 0.2 * p.x * p.x, 0.8 * p.z);
        }
        let target = scattered(&soup);
        let mut problem = Problem::new(&source, Target::Mesh(&target));
        // Two landmarks, onto vertices of the target (apart on its surface).
        let marks = [(VertexId(3), VertexId(10)), (VertexId(40), VertexId(100))];
        for (vertex, onto) in marks {
            problem.constraints.push(Constraint::Landmark(Landmark {
                vertex,
                position: Position::Spatial(target.position(onto)),
            }));
        }
        let settings = Register.check(&problem).unwrap();
        let given = register(&problem, &settings, &mut Context::new()).unwrap();
        // Every mesh renumbered (spread 0).
        let renumbered = Renumbered::new(&problem, &target, 0).unwrap().unwrap();
        let local = renumbered.problem(&problem, &target);
        assert!(!std::ptr::eq(local.source, &source));
        let solution =
            renumbered.solution_to_old(register(&local, &settings, &mut Context::new()).unwrap());
        let Some(Map::OnMesh(points)) = solution.map() else {
            panic!("a map onto the target mesh");
        };
        let image: Vec<Point3<f64>> = points.iter().map(|p| p.position(&target)).collect();
        for (vertex, onto) in marks {
            let at = image[vertex.idx()];
            assert!(
                (at - target.position(onto)).norm() < 1e-12,
                "{vertex}: {at}"
            );
        }
        // The map, read in the given numbering, has the distortion the solution reports
        // for each face of the given numbering.
        let measured = measure_surface(&source, &image, ReferenceNormal::Radial).unwrap();
        let reported = &solution.metrics.mu.as_ref().unwrap().mu;
        for (f, (m, r)) in measured.field.mu.iter().zip(reported).enumerate() {
            assert!(
                (m.norm() - r.norm()).abs() < 1e-9,
                "face {f}: |mu| {m} against {r}"
            );
        }
        // Another numbering rounds differently and the flow stalls elsewhere (after 6
        // and 13 steps here), at about the same energy.
        let energy = |s: &Solution| *s.metrics.energy_history.last().unwrap();
        assert!((energy(&given) - energy(&solution)).abs() < 1e-2 * energy(&given));
        assert!(
            renumbered
                .note(&problem, &target)
                .contains("the source (median index spread")
        );
    }

    #[test]
    fn the_problem_s_vertices_and_field_follow_the_renumbering() {
        let source = scattered(&octahedral_sphere(2));
        let target = scattered(&icosphere(2));
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
        let mu: Vec<Complex64> = (0..source.face_count())
            .map(|f| Complex64::new(f as f64 * 1e-3, 0.0))
            .collect();
        problem.goal = Goal::Prescribed(BeltramiField::new(Frame::Face, mu.clone()));
        let renumbered = Renumbered::new(&problem, &target, 0).unwrap().unwrap();
        let local = renumbered.problem(&problem, &target);
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
        let mark = local.constraints.landmarks().next().unwrap();
        assert_eq!(
            local.source.position(mark.vertex),
            source.position(VertexId(5))
        );
        let Goal::Prescribed(field) = &local.goal else {
            panic!("a prescribed goal");
        };
        for f in local.source.faces() {
            let old = local.source.face_to_input(f);
            assert_eq!(field.mu[f.idx()], mu[old]);
        }
    }
}
