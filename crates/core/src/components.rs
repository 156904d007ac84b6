//! Meshes in several pieces (a scan in parts): each connected component as a problem of
//! its own, and the maps joined.
//!
//! [`parts`] gives the components as meshes, in the order of their first face, each
//! with its vertices and faces in the whole mesh's order. [`Part::problem`] carries a
//! problem onto one part: the target, goal and options as they are, the pins on the
//! part's own vertices, the normal and area constraints, a prescribed `mu` restricted to
//! the part's faces. Constraints tied to vertices of several parts or to a numbering
//! (landmarks, slides, curves, loop matches, reference angles), an initial map and
//! targets that are not a region of the plane with a circle, square or free boundary are
//! refused, naming what: they have no meaning per part.
//!
//! [`solve_each`] solves every part and joins the planar maps side by side: part `k`'s
//! image is moved right so that its bounding box begins [`GAP`] times the tallest part's
//! height after part `k - 1`'s ends, bottoms aligned. The joined map's distortion is
//! measured again on the whole mesh (face frames), so the report agrees with
//! `distortion` on the written map.

use beltrami_fem::distortion::measure_planar;
use beltrami_fem::{BeltramiField, Frame};
use beltrami_mesh::{FaceId, Mesh, MeshError, PolygonSoup, VertexId};
use num_complex::Complex64;

use crate::{
    Constraint, Context, Goal, Map, Metrics, PlanarBoundary, Problem, Report, Solution, Solver,
    SolverError, Stop, Target,
};

/// The space between joined parts, as a fraction of the tallest part's height.
pub const GAP: f64 = 0.05;

/// A connected component of a mesh as a mesh of its own.
#[derive(Debug, Clone)]
pub struct Part {
    /// The component.
    pub mesh: Mesh,
    /// For each vertex of [`Part::mesh`], the vertex of the whole mesh it is (increasing).
    pub vertices: Vec<VertexId>,
    /// For each face of [`Part::mesh`], the face of the whole mesh it is (increasing).
    pub faces: Vec<FaceId>,
}

/// The connected components of `mesh` as meshes, in the order of their first face.
///
/// Fails only if a component does not rebuild as a mesh, which cannot happen for a
/// component of a valid mesh.
pub fn parts(mesh: &Mesh) -> Result<Vec<Part>, MeshError> {
    let count = mesh.component_count();
    let mut faces: Vec<Vec<FaceId>> = vec![Vec::new(); count];
    let mut order = Vec::with_capacity(count);
    for f in mesh.faces() {
        let c = mesh.face_component(f).idx();
        if faces[c].is_empty() {
            order.push(c);
        }
        faces[c].push(f);
    }
    let mut local = vec![u32::MAX; mesh.vertex_count()];
    order
        .into_iter()
        .map(|c| {
            let faces = std::mem::take(&mut faces[c]);
            let mut vertices: Vec<VertexId> =
                faces.iter().flat_map(|&f| mesh.face_vertices(f)).collect();
            vertices.sort_unstable();
            vertices.dedup();
            for (k, v) in vertices.iter().enumerate() {
                local[v.idx()] = k as u32;
            }
            let positions = vertices.iter().map(|&v| mesh.position(v)).collect();
            let mut soup = PolygonSoup::new(positions);
            for &f in &faces {
                let face: Vec<u32> = mesh.face_vertices(f).map(|v| local[v.idx()]).collect();
                soup.push_face(&face);
            }
            Ok(Part {
                mesh: Mesh::from_soup(&soup)?,
                vertices,
                faces,
            })
        })
        .collect()
}

/// The index of the part with the most faces (the first of equals).
pub fn largest(parts: &[Part]) -> Option<usize> {
    (0..parts.len()).max_by_key(|&k| (parts[k].mesh.face_count(), std::cmp::Reverse(k)))
}

impl Part {
    /// `problem` (on the whole mesh) carried onto this part; see the module docs for
    /// what is carried and what is refused. `solver` names the solver in errors.
    pub fn problem<'a>(
        &'a self,
        problem: &Problem<'a>,
        solver: &'static str,
    ) -> Result<Problem<'a>, SolverError> {
        let refuse = |what: &str| {
            SolverError::unsupported(
                solver,
                format!(
                    "{what} cannot be split between the mesh's components: solve each component's file on its own"
                ),
            )
        };
        if problem.initial.is_some() {
            return Err(refuse("an initial map"));
        }
        let target = match &problem.target {
            Target::Plane(PlanarBoundary::Given(_)) => return Err(refuse("a given boundary map")),
            Target::Plane(PlanarBoundary::Square { corners: Some(_) }) => {
                return Err(refuse("the square's corner vertices"));
            }
            Target::Plane(PlanarBoundary::Polygon(_)) => {
                return Err(refuse("a polygon's boundary"));
            }
            other => other.clone(),
        };
        let mut part = Problem::new(&self.mesh, target);
        part.options = problem.options.clone();
        part.goal = match &problem.goal {
            Goal::Prescribed(field) => Goal::Prescribed(BeltramiField {
                frame: field.frame,
                mu: self.faces.iter().map(|f| field.mu[f.idx()]).collect(),
            }),
            Goal::Features(_) => return Err(refuse("feature fields")),
            goal => goal.clone(),
        };
        for constraint in problem.constraints.iter() {
            match constraint {
                Constraint::Pin(pin) => {
                    if let Ok(k) = self.vertices.binary_search(&pin.vertex) {
                        let mut pin = *pin;
                        pin.vertex = VertexId(k as u32);
                        part.constraints.push(Constraint::Pin(pin));
                    }
                }
                Constraint::Normal { .. } | Constraint::Area => {
                    part.constraints.push(constraint.clone());
                }
                Constraint::Landmark(_) => return Err(refuse("landmarks")),
                Constraint::Slide(_) => return Err(refuse("sliding vertices")),
                Constraint::Curve(_) => return Err(refuse("curve constraints")),
                Constraint::LoopMatch(_) => return Err(refuse("boundary-loop matches")),
                Constraint::ReferenceAngles(_) => return Err(refuse("reference angles")),
            }
        }
        Ok(part)
    }
}

/// Solves `problem` on each connected component of its mesh with `solver` and joins the
/// planar maps side by side (module docs); every component's problem is checked before
/// any is solved. A mesh of one component is solved as it is.
pub fn solve_each(
    solver: &dyn Solver,
    problem: &Problem<'_>,
    context: &mut Context<'_>,
) -> Result<Solution, SolverError> {
    let name = solver.name();
    let mesh = problem.source;
    if mesh.component_count() <= 1 {
        return solver.solve(problem, context);
    }
    if !matches!(
        problem.target,
        Target::Plane(_) | Target::Disk | Target::Annulus { .. }
    ) {
        return Err(SolverError::unsupported(
            name,
            "each component on its own joins maps into the plane side by side; maps onto the sphere, a circle domain, a mesh or a surface have no such joining: solve the largest component, or each component's file",
        ));
    }
    let parts = parts(mesh)?;
    // Every part's problem checked before any is solved.
    let problems = parts
        .iter()
        .map(|part| {
            let problem = part.problem(problem, name)?;
            let settings = solver.check(&problem)?;
            Ok((problem, settings))
        })
        .collect::<Result<Vec<_>, SolverError>>()?;
    let mut report = Report::new(name);
    let mut metrics = Metrics::default();
    let mut images: Vec<Vec<Complex64>> = Vec::with_capacity(parts.len());
    for (problem, settings) in &problems {
        let solution = solver.run(problem, settings, context)?;
        let image = solution.planar().ok_or_else(|| {
            SolverError::invalid(name, "a component's solution is not a planar map")
        })?;
        images.push(image.to_vec());
        report.timings.extend(solution.report.timings);
        report.notes.extend(solution.report.notes);
        metrics.iterations += solution.metrics.iterations;
        metrics.stop = worse_stop(metrics.stop, solution.metrics.stop);
    }
    let map = join(mesh, &parts, &images);
    let distortion = report.time("distortion", || measure_planar(mesh, &map, Frame::Face))?;
    metrics.mu = Some(distortion.field);
    metrics.distortion = Some(distortion.stats);
    report.notes.push(format!(
        "{} components solved one by one and placed side by side, left to right in the order of their first face",
        parts.len()
    ));
    let mut solution = Solution::from_map(Map::Planar(map), report);
    solution.metrics = metrics;
    Ok(solution)
}

/// The stop of a joined solve: the first part's that did not converge, else converged.
fn worse_stop(so_far: Option<Stop>, next: Option<Stop>) -> Option<Stop> {
    match (so_far, next) {
        (Some(s), _) if !matches!(s, Stop::Converged { .. }) => Some(s),
        (_, Some(n)) => Some(n),
        (s, None) => s,
    }
}

/// The parts' images joined into one map of `mesh`'s vertices (module docs).
fn join(mesh: &Mesh, parts: &[Part], images: &[Vec<Complex64>]) -> Vec<Complex64> {
    let boxes: Vec<(Complex64, Complex64)> = images
        .iter()
        .map(|image| {
            image.iter().fold(
                (
                    Complex64::new(f64::INFINITY, f64::INFINITY),
                    -Complex64::new(f64::INFINITY, f64::INFINITY),
                ),
                |(lo, hi), z| {
                    (
                        Complex64::new(lo.re.min(z.re), lo.im.min(z.im)),
                        Complex64::new(hi.re.max(z.re), hi.im.max(z.im)),
                    )
                },
            )
        })
        .collect();
    let tallest = boxes
        .iter()
        .map(|(lo, hi)| hi.im - lo.im)
        .fold(0.0, f64::max);
    let mut map = vec![Complex64::new(0.0, 0.0); mesh.vertex_count()];
    let mut left = 0.0;
    for ((part, image), (lo, hi)) in parts.iter().zip(images).zip(&boxes) {
        let shift = Complex64::new(left - lo.re, -lo.im);
        for (&v, z) in part.vertices.iter().zip(image) {
            map[v.idx()] = z + shift;
        }
        left += hi.re - lo.re + GAP * tallest;
    }
    map
}

#[cfg(test)]
mod tests {
    use super::*;
    use beltrami_mesh::primitives::{Cells, grid};

    /// Two grids side by side in one soup, the second listed first by its faces' order
    /// of vertices (its vertices come after the first grid's).
    fn two_squares() -> Mesh {
        let a = grid(3, 3, Cells::Triangles);
        let mut positions = a.positions.clone();
        positions.extend(
            a.positions
                .iter()
                .map(|p| p + nalgebra::Vector3::new(5.0, 0.0, 0.0)),
        );
        let n = a.positions.len() as u32;
        let mut soup = PolygonSoup::new(positions);
        for face in a.faces() {
            soup.push_face(face);
            let shifted: Vec<u32> = face.iter().map(|i| i + n).collect();
            soup.push_face(&shifted);
        }
        Mesh::from_soup(&soup).unwrap()
    }

    #[test]
    fn parts_keep_the_whole_meshs_order_and_geometry() {
        let mesh = two_squares();
        let parts = parts(&mesh).unwrap();
        assert_eq!(parts.len(), 2);
        for (k, part) in parts.iter().enumerate() {
            assert_eq!(part.mesh.face_count(), mesh.face_count() / 2);
            assert!(part.vertices.windows(2).all(|w| w[0] < w[1]));
            // Faces alternate between the squares: part k has faces k, k + 2, ...
            assert!(
                part.faces
                    .iter()
                    .enumerate()
                    .all(|(i, f)| f.idx() == 2 * i + k)
            );
            for (f, &whole) in part.mesh.faces().zip(&part.faces) {
                let here: Vec<_> = part
                    .mesh
                    .face_vertices(f)
                    .map(|v| part.vertices[v.idx()])
                    .collect();
                let there: Vec<_> = mesh.face_vertices(whole).collect();
                assert_eq!(here, there);
            }
        }
        assert_eq!(largest(&parts), Some(0));
    }

    #[test]
    fn joined_images_sit_side_by_side_without_overlap() {
        let mesh = two_squares();
        let parts = parts(&mesh).unwrap();
        // Each part mapped by its own positions: boxes [0, 1]^2 and [5, 6] x [0, 1].
        let images: Vec<Vec<Complex64>> = parts
            .iter()
            .map(|p| {
                p.mesh
                    .positions()
                    .iter()
                    .map(|q| Complex64::new(q.x, q.y))
                    .collect()
            })
            .collect();
        let map = join(&mesh, &parts, &images);
        let (a, b): (Vec<_>, Vec<_>) = mesh.vertices().partition(|v| parts[0].vertices.contains(v));
        let right_of_a = a.iter().map(|v| map[v.idx()].re).fold(f64::MIN, f64::max);
        let left_of_b = b.iter().map(|v| map[v.idx()].re).fold(f64::MAX, f64::min);
        assert!(
            (left_of_b - right_of_a - GAP).abs() < 1e-12,
            "{right_of_a} {left_of_b}"
        );
        assert!(map.iter().all(|z| z.im >= 0.0 && z.re >= 0.0));
    }
}
