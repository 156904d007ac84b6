//! Remeshing in place by reference angles (Gruber-Aulisa 2022, section 6.2): the same
//! vertices and faces, the vertices moved along the surface so that the elements take
//! the shapes of reference polygons as closely as a quasiconformal map allows.
//!
//! The QC iteration (the `qc-iteration` solver, Algorithms 2-4) looks for the
//! Teichmueller map from the conformal structure of the reference shapes
//! ([`crate::reference_angles`]) to the surface, the boundary held in place and the
//! image kept on the surface by the normal constraint (section 4.1, every displacement
//! tangent to the surface to first order) or near it by the area constraint (section
//! 4.2, the first variation of the area vanishes; a closed surface is then held at one
//! vertex). Vertices on sharp features (an edge whose faces' normals differ by more
//! than `feature_angle`) are held too: the linearized constraint sees a crease only
//! through the averaged vertex normal and would let vertices slide across it. The
//! image is the new vertex positions; with `project`, each moved vertex
//! then goes to its closest point on the input surface (the linearized constraint
//! leaves it on its tangent plane, off a curved surface by the square of the move).
//!
//! The least-squares map is not bijective by construction: the vertices of a face
//! turned against the input surface (and not turned in the input) are pulled back
//! towards their input positions, their moves halved up to six times, then undone. If
//! faces stay turned, the iteration runs again with [`RETRY_FACTOR`] times the
//! iterations (a more even `|mu|` folds less); faces turned after that are
//! [`RemeshError::Turned`] unless `allow_flips`.

use beltrami_core::{
    Constraint, Context, Goal, Map, OptionValue, Pin, Position, Problem, Solution, Solver,
    SolverError, Stop, Target,
};
use beltrami_mesh::{FaceId, Mesh, Point3, Vector3, VertexId};
use beltrami_spatial::SurfaceIndex;

use crate::RemeshError;
use crate::reference_angles::{Reference, reference_angles};

/// How the image is kept near the surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Keep {
    /// The normal constraint (section 4.1): displacements tangent to the surface.
    Normal,
    /// The area constraint (section 4.2): the area kept to first order.
    Area,
}

impl Keep {
    /// `normal` or `area`.
    pub fn name(self) -> &'static str {
        match self {
            Keep::Normal => "normal",
            Keep::Area => "area",
        }
    }
}

/// The weight of the normal constraint times the squared mean edge length: a normal
/// move of a vertex by `d` costs `NORMAL_STIFFNESS (d / h)^2` times its area, ten
/// thousand times what a tangential move of the same size costs the distortion energy.
pub const NORMAL_STIFFNESS: f64 = 1e4;

/// The options of [`remesh_in_place`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InPlaceOptions {
    /// The reference shapes.
    pub reference: Reference,
    /// How the image stays near the surface.
    pub keep: Keep,
    /// Most iterations of the QC iteration.
    pub max_iters: usize,
    /// Its tolerance (the largest change of `mu` in an iteration).
    pub tolerance: f64,
    /// Move the vertices onto the input surface afterwards.
    pub project: bool,
    /// Vertices on an edge whose faces' normals differ by more than this (degrees) stay
    /// in place, so that sharp creases and corners keep their shape.
    pub feature_angle: f64,
    /// Return the result even when faces end turned that were not turned in the input
    /// (otherwise [`RemeshError::Turned`]).
    pub allow_flips: bool,
}

impl Default for InPlaceOptions {
    fn default() -> Self {
        Self {
            reference: Reference::Optimized,
            keep: Keep::Normal,
            max_iters: 10,
            tolerance: 1e-4,
            project: true,
            feature_angle: 60.0,
            allow_flips: false,
        }
    }
}

/// The result of [`remesh_in_place`].
#[derive(Debug)]
pub struct InPlace {
    /// The input's connectivity at the new positions.
    pub mesh: Mesh,
    /// The QC iteration's solution (iterations, `k`, `|mu|` from the reference shapes).
    pub solution: Solution,
    /// Faces turned against the input surface: the normal of the face and the input's
    /// normal (interpolated from its vertex normals) at the point of the input closest
    /// to the face's centroid make an angle of 90 degrees or more.
    pub flipped: usize,
    /// Faces of the input turned against its own surface in the same sense (slivers
    /// whose normal disagrees with the vertex normals): the pull-back never makes a
    /// face turn that was not turned in the input.
    pub input_flipped: usize,
    /// Vertices held on sharp features.
    pub features: usize,
    /// Vertices pulled back towards their input position (halving their move up to six
    /// times, then to the input) because a face of theirs had turned against the
    /// surface: the least-squares map is not bijective by construction.
    pub pulled: usize,
}

/// Remeshes `mesh` in place (module docs) with `solver` (the `qc-iteration` solver of
/// the registry).
pub fn remesh_in_place(
    mesh: &Mesh,
    solver: &dyn Solver,
    options: &InPlaceOptions,
    context: &mut Context<'_>,
) -> Result<InPlace, RemeshError> {
    let mut problem = Problem::new(mesh, Target::Surface);
    problem.goal = Goal::Extremal;
    problem
        .constraints
        .push(Constraint::ReferenceAngles(reference_angles(
            mesh,
            options.reference,
        )));
    problem.constraints.hold_boundary(mesh, mesh.positions());
    let held = feature_vertices(mesh, options.feature_angle);
    for &v in &held {
        problem.constraints.push(Constraint::Pin(Pin {
            vertex: v,
            position: Some(Position::Spatial(mesh.position(v))),
        }));
    }
    match options.keep {
        Keep::Normal => {
            let lengths = mesh.edge_lengths();
            let mean = lengths.iter().sum::<f64>() / lengths.len().max(1) as f64;
            problem.constraints.push(Constraint::Normal {
                weight: NORMAL_STIFFNESS / (mean * mean),
            });
        }
        Keep::Area => {
            problem.constraints.push(Constraint::Area);
            if mesh.boundary_loop_list().is_empty() {
                problem.constraints.push(Constraint::Pin(Pin {
                    vertex: VertexId(0),
                    position: Some(Position::Spatial(mesh.position(VertexId(0)))),
                }));
            }
        }
    }
    problem
        .options
        .set("tolerance", OptionValue::Float(options.tolerance));
    let index = SurfaceIndex::new(mesh)?;
    let was_flipped = flipped_faces(mesh, &index, mesh.positions())?;
    // More iterations even out |mu|, which removes the folds of a hard mesh: a result
    // with faces turned is tried again with RETRY_FACTOR times the iterations.
    let mut attempts = vec![options.max_iters];
    if options.max_iters > 0 && !options.allow_flips {
        attempts.push(RETRY_FACTOR * options.max_iters);
    }
    let mut earlier = None;
    for (attempt, &iterations) in attempts.iter().enumerate() {
        problem
            .options
            .set("max-iters", OptionValue::Int(iterations));
        let mut solution = solver
            .solve(&problem, context)
            .map_err(|error| match error {
                SolverError::Cancelled => RemeshError::Cancelled,
                error => RemeshError::Solve {
                    solver: solver.name(),
                    error,
                },
            })?;
        if let Some(Stop::Cancelled) = solution.metrics.stop {
            return Err(RemeshError::Cancelled);
        }
        let Some(Map::Spatial(image)) = solution.map() else {
            return Err(RemeshError::Parameterizer {
                solver: solver.name(),
                message: "it gave no map into space".to_string(),
            });
        };
        let settled = settle(mesh, &index, image, &was_flipped, options.project)?;
        let count = |faces: &[bool]| faces.iter().filter(|&&f| f).count();
        let (flipped, input_flipped) = (count(&settled.flipped), count(&was_flipped));
        let new = mesh
            .faces()
            .find(|f| settled.flipped[f.idx()] && !was_flipped[f.idx()]);
        if let (Some(first), false) = (new, options.allow_flips) {
            if attempt + 1 < attempts.len() {
                earlier = Some((iterations, flipped));
                continue;
            }
            return Err(RemeshError::Turned {
                turned: flipped,
                input: input_flipped,
                first,
            });
        }
        if let Some((iterations, turned)) = earlier {
            solution.report.notes.push(format!(
                "with {iterations} iterations {turned} faces ended turned against the surface; {} iterations left none",
                solution.metrics.iterations
            ));
        }
        let remeshed =
            mesh.with_positions(settled.positions)
                .map_err(|error| RemeshError::Build {
                    what: "moved mesh",
                    error,
                })?;
        return Ok(InPlace {
            mesh: remeshed,
            solution,
            flipped,
            input_flipped,
            features: held.len(),
            pulled: settled.pulled,
        });
    }
    unreachable!("the last attempt returns")
}

/// How many times the iterations a second attempt runs when faces end turned.
pub const RETRY_FACTOR: usize = 3;

/// The vertex positions of a map's image after the projection onto the input and the
/// pull-back of turned faces, with the faces still turned and the vertices pulled.
struct Settled {
    positions: Vec<Point3<f64>>,
    flipped: Vec<bool>,
    pulled: usize,
}

/// Projects `image` onto the input (with `project`) and pulls back the vertices of every
/// face turned that was not turned in the input (`was_flipped`): their moves halved up to
/// six times, then undone.
fn settle(
    mesh: &Mesh,
    index: &SurfaceIndex<'_>,
    image: &[Point3<f64>],
    was_flipped: &[bool],
    project_onto_input: bool,
) -> Result<Settled, RemeshError> {
    let mut positions = image.to_vec();
    if project_onto_input {
        project(mesh, index, &mut positions, mesh.vertices())?;
    }
    let mut pulled = 0;
    let mut flipped = flipped_faces(mesh, index, &positions)?;
    let target = positions.clone();
    let mut share = vec![1.0; mesh.vertex_count()];
    let mut seen = vec![usize::MAX; mesh.face_count()];
    for round in 0..PULL_BACK_ROUNDS {
        let mut moved: Vec<VertexId> = mesh
            .faces()
            .filter(|f| flipped[f.idx()] && !was_flipped[f.idx()])
            .flat_map(|f| mesh.face_vertices(f))
            .collect();
        if moved.is_empty() {
            break;
        }
        moved.sort_unstable();
        moved.dedup();
        for &v in &moved {
            let s = &mut share[v.idx()];
            if *s == 1.0 {
                pulled += 1;
            }
            *s = if *s > 1.0 / 64.0 { *s / 2.0 } else { 0.0 };
            let from = mesh.position(v);
            positions[v.idx()] = from + (target[v.idx()] - from) * *s;
        }
        if project_onto_input {
            project(mesh, index, &mut positions, moved.iter().copied())?;
        }
        // Only the faces around a moved vertex can have changed.
        let mut around = Vec::new();
        for &v in &moved {
            for h in mesh.outgoing_halfedges(v) {
                if let Some(f) = mesh.face(h)
                    && seen[f.idx()] != round
                {
                    seen[f.idx()] = round;
                    around.push(f);
                }
            }
        }
        for (f, t) in around.iter().zip(turned(mesh, index, &positions, &around)?) {
            flipped[f.idx()] = t;
        }
    }
    Ok(Settled {
        positions,
        flipped,
        pulled,
    })
}

/// Rounds of pulling the vertices of turned faces back towards the input (a vertex is
/// back at its input position after seven).
const PULL_BACK_ROUNDS: usize = 40;

/// Moves the vertices `moved` that are off the boundary to their closest points on
/// `mesh`.
fn project(
    mesh: &Mesh,
    index: &SurfaceIndex<'_>,
    positions: &mut [Point3<f64>],
    moved: impl Iterator<Item = VertexId>,
) -> Result<(), RemeshError> {
    let moved: Vec<usize> = moved
        .filter(|&v| !mesh.is_boundary_vertex(v))
        .map(|v| v.idx())
        .collect();
    let points: Vec<Point3<f64>> = moved.iter().map(|&v| positions[v]).collect();
    for (v, located) in moved.iter().zip(index.locate_all(&points)?) {
        positions[*v] = located.position;
    }
    Ok(())
}

/// Per face of `faces` (of `mesh` at `positions`): whether it is turned against the
/// surface of `index` ([`InPlace::flipped`]).
fn turned(
    mesh: &Mesh,
    index: &SurfaceIndex<'_>,
    positions: &[Point3<f64>],
    faces: &[FaceId],
) -> Result<Vec<bool>, RemeshError> {
    let corners = |f| mesh.face_vertices(f).map(|v: VertexId| positions[v.idx()]);
    let centroids: Vec<Point3<f64>> = faces
        .iter()
        .map(|&f| {
            let n = mesh.face_degree(f) as f64;
            Point3::from(corners(f).map(|p| p.coords).sum::<Vector3<f64>>() / n)
        })
        .collect();
    faces
        .iter()
        .zip(index.locate_all(&centroids)?)
        .map(|(&f, located)| {
            let p: Vec<Point3<f64>> = corners(f).collect();
            let area: Vector3<f64> = (0..p.len())
                .map(|k| p[k].coords.cross(&p[(k + 1) % p.len()].coords))
                .sum();
            Ok(area.dot(&index.normal(&located.point)?) <= 0.0)
        })
        .collect()
}

/// [`turned`] for every face.
fn flipped_faces(
    mesh: &Mesh,
    index: &SurfaceIndex<'_>,
    positions: &[Point3<f64>],
) -> Result<Vec<bool>, RemeshError> {
    turned(mesh, index, positions, &mesh.faces().collect::<Vec<_>>())
}

/// The vertices, off the boundary, of the edges whose two faces' normals differ by more
/// than `angle_degrees`: the sharp features. A face with a corner under
/// [`SLIVER_ANGLE`] makes no crease: a sliver's normal says little about the surface,
/// and the badly shaped faces are the ones to move.
fn feature_vertices(mesh: &Mesh, angle_degrees: f64) -> Vec<VertexId> {
    let limit = angle_degrees.to_radians().cos();
    let sliver = SLIVER_ANGLE.to_radians();
    let well_shaped: Vec<bool> = mesh
        .faces()
        .map(|f| {
            mesh.face_halfedges(f)
                .all(|h| mesh.corner_angle(h) >= sliver)
        })
        .collect();
    let mut on = vec![false; mesh.vertex_count()];
    for e in mesh.edges() {
        if let [Some(f), Some(g)] = mesh.edge_faces(e) {
            let (a, b) = (mesh.face_vector_area(f), mesh.face_vector_area(g));
            if well_shaped[f.idx()]
                && well_shaped[g.idx()]
                && a.dot(&b) < limit * a.norm() * b.norm()
            {
                for v in mesh.edge_vertices(e) {
                    on[v.idx()] = !mesh.is_boundary_vertex(v);
                }
            }
        }
    }
    mesh.vertices().filter(|v| on[v.idx()]).collect()
}

/// The smallest corner angle (degrees) of a face whose normal can mark a crease.
pub const SLIVER_ANGLE: f64 = 15.0;
