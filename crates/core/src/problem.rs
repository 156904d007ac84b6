//! What a solver is asked to compute: source, target, goal, constraints, initial map and
//! option values.
//!
//! The types cover every solver of the design, not only the ones that exist today:
//! initial parameterizations (Tutte, harmonic, LSCM, sphere), least-squares QC maps for a
//! given mu (planar and quaternionic on the surface itself), Beltrami flow onto fixed
//! domains and target meshes, Teichmueller maps with a prescribed boundary, circle-domain
//! maps and remeshing. A solver reads the parts it needs and its capability check rejects
//! what it cannot do.

use beltrami_fem::BeltramiField;
use beltrami_mesh::{Mesh, Point3, VertexId};
use num_complex::Complex64;

use crate::{Constraints, Map, Options};

/// Where the boundary of a planar map goes.
#[derive(Debug, Clone, PartialEq)]
pub enum PlanarBoundary {
    /// Free boundary (LSCM, least-squares QC with pins).
    Free,
    /// Onto the unit circle, by arc length from the first vertex of the longest loop (or
    /// the first pinned boundary vertex).
    Circle,
    /// Onto the unit square `[0, 1]^2`; the four corners are the given boundary vertices
    /// (counter-clockwise), or four vertices a quarter of the boundary length apart.
    Square {
        /// Corner vertices, counter-clockwise, or `None` to choose them.
        corners: Option<[VertexId; 4]>,
    },
    /// Onto a convex polygon given by its corners, counter-clockwise; boundary vertices are
    /// spread by arc length.
    Polygon(Vec<Complex64>),
    /// Keep the source's own boundary positions (a planar source in z = 0).
    Keep,
    /// The boundary of a given planar map (one value per vertex; only boundary vertices
    /// are read).
    Given(Vec<Complex64>),
}

/// The domain or surface a map goes to.
#[derive(Debug, Clone)]
pub enum Target<'a> {
    /// A planar region with a boundary condition.
    Plane(PlanarBoundary),
    /// The unit disk (boundary sliding on the circle).
    Disk,
    /// An annulus `r <= |z| <= 1` (inner radius fixed or free).
    Annulus {
        /// The inner radius, or `None` when it is an unknown (the conformal modulus).
        inner_radius: Option<f64>,
    },
    /// The unit sphere.
    Sphere,
    /// A circle domain: the unit disk minus disks whose centres and radii are unknowns.
    CircleDomain,
    /// Another mesh of the same topology (registration).
    Mesh(&'a Mesh),
    /// The source surface itself in R^3 (quaternionic least-squares QC, remeshing).
    Surface,
}

impl Target<'_> {
    /// Whether maps onto this target are planar (a point of the complex plane per
    /// vertex): the plane, the disk, annuli and circle domains.
    pub fn is_planar(&self) -> bool {
        matches!(
            self,
            Target::Plane(_) | Target::Disk | Target::Annulus { .. } | Target::CircleDomain
        )
    }
}

/// What the map should achieve.
#[derive(Debug, Clone, PartialEq)]
pub enum Goal {
    /// As conformal as the constraints allow: minimize the `L^p` norm of `mu` (`p = 2`
    /// for least squares).
    Conformal {
        /// The exponent, `2 <= p <= 100`.
        p: f64,
    },
    /// A prescribed Beltrami coefficient per face.
    Prescribed(BeltramiField),
    /// The extremal (Teichmueller) map for the boundary condition.
    Extremal,
    /// A registration that matches scalar fields given on both meshes (the
    /// landmark-and-intensity registration of Lam and Lui, SIAM J. Imaging Sci. 2014),
    /// as conformal as the match allows.
    Features(crate::Features),
}

impl Default for Goal {
    fn default() -> Self {
        Goal::Conformal { p: 2.0 }
    }
}

/// Where a constrained vertex must go.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Position {
    /// A point of the plane.
    Planar(Complex64),
    /// A point of R^3 (on the sphere or a target surface).
    Spatial(Point3<f64>),
    /// A vertex of the target mesh (a registration landmark `v SRC TGT`): that vertex
    /// itself, kept as a vertex through the solve, not its position located again.
    TargetVertex(VertexId),
}

/// A mapping problem.
#[derive(Debug, Clone)]
pub struct Problem<'a> {
    /// The mesh to map.
    pub source: &'a Mesh,
    /// Where to map it.
    pub target: Target<'a>,
    /// What the map should achieve.
    pub goal: Goal,
    /// Pins, landmarks, slides, curves, loop matches, normal/area constraints,
    /// reference angles.
    pub constraints: Constraints,
    /// A starting map for iterative solvers.
    pub initial: Option<Map>,
    /// Option values set by the user (the solver's declarations give the rest).
    pub options: Options,
}

impl<'a> Problem<'a> {
    /// A conformal problem onto `target` with no constraints and default parameters.
    pub fn new(source: &'a Mesh, target: Target<'a>) -> Self {
        Self {
            source,
            target,
            goal: Goal::default(),
            constraints: Constraints::default(),
            initial: None,
            options: Options::default(),
        }
    }

    /// The held boundary of a planar Dirichlet target: every vertex of every boundary
    /// loop with its image, `x + i y` of its own position for `Plane(Keep)`, `values[v]`
    /// for `Plane(Given(values))`; `None` for any other target. The error says what is
    /// wrong with the given values (their count, a non-finite value at a named vertex),
    /// for the solver to wrap in its own error.
    pub fn planar_boundary_values(&self) -> Option<Result<Vec<(VertexId, Complex64)>, String>> {
        let mesh = self.source;
        let boundary = || {
            mesh.boundary_loop_list()
                .into_iter()
                .flat_map(|l| l.vertices)
        };
        match &self.target {
            Target::Plane(PlanarBoundary::Keep) => Some(Ok(boundary()
                .map(|v| {
                    let p = mesh.position(v);
                    (v, Complex64::new(p.x, p.y))
                })
                .collect())),
            Target::Plane(PlanarBoundary::Given(values)) => {
                if values.len() != mesh.vertex_count() {
                    return Some(Err(format!(
                        "the boundary map has {} values, but the mesh has {} vertices",
                        values.len(),
                        mesh.vertex_count()
                    )));
                }
                Some(
                    boundary()
                        .map(|v| {
                            let z = values[v.idx()];
                            if z.is_finite() {
                                Ok((v, z))
                            } else {
                                Err(format!(
                                    "the boundary map is not finite at boundary vertex {v}"
                                ))
                            }
                        })
                        .collect(),
                )
            }
            _ => None,
        }
    }

    /// The vertices held at points of R^3 by the pins of a map into space
    /// (`Target::Surface`): each pin's vertex with its point. The error says which pin
    /// cannot hold a vertex in space (a vertex out of range, no position, a position in
    /// the plane, a non-finite point), for the solver to wrap in its own error.
    pub fn spatial_pins(&self) -> Result<Vec<(VertexId, Point3<f64>)>, String> {
        let count = self.source.vertex_count();
        self.constraints
            .pins()
            .map(|pin| {
                let v = pin.vertex;
                match pin.position {
                    _ if v.idx() >= count => Err(format!(
                        "a pin is on vertex {v}, but the mesh has {count} vertices"
                    )),
                    Some(Position::Spatial(p)) if p.coords.iter().all(|x| x.is_finite()) => {
                        Ok((v, p))
                    }
                    Some(Position::Spatial(_)) => Err(format!(
                        "the position of the pin on vertex {v} is not finite"
                    )),
                    Some(Position::TargetVertex(w)) => Err(format!(
                        "the pin on vertex {v} holds it at target vertex {w}, but a map into space has no target mesh"
                    )),
                    Some(Position::Planar(_)) => Err(format!(
                        "a map into space holds vertices at points of R^3, but the pin on vertex {v} has a position in the plane"
                    )),
                    None => Err(format!(
                        "a map into space holds vertices at points of R^3, but the pin on vertex {v} has no position"
                    )),
                }
            })
            .collect()
    }
}
