//! What a solver is asked to compute: source, target, goal, constraints, initial map and
//! parameters.
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

use crate::Map;

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

/// What the map should achieve.
#[derive(Debug, Clone, PartialEq)]
pub enum Goal {
    /// As conformal as the constraints allow: minimize the `L^p` norm of `mu` (`p = 2`
    /// for least squares).
    Conformal {
        /// The exponent `p >= 2`.
        p: f64,
    },
    /// A prescribed Beltrami coefficient per face.
    Prescribed(BeltramiField),
    /// The extremal (Teichmueller) map for the boundary condition.
    Extremal,
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
}

/// A vertex held at a position (`position: None` lets the solver choose, e.g. LSCM's
/// default (0, 0) and (1, 0)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pin {
    /// The pinned vertex.
    pub vertex: VertexId,
    /// Where it goes, if prescribed.
    pub position: Option<Position>,
}

/// A chain of source vertices that must map onto a target curve, ends fixed, sliding
/// in between.
#[derive(Debug, Clone, PartialEq)]
pub struct Curve {
    /// Source vertices, in order.
    pub source: Vec<VertexId>,
    /// The target curve: vertices of the target mesh (or of the source, for maps of the
    /// surface into itself), in order.
    pub target: Vec<VertexId>,
}

/// Constraints shared by all solvers.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Constraints {
    /// Pinned vertices (pins and landmarks).
    pub pins: Vec<Pin>,
    /// Curve correspondences.
    pub curves: Vec<Curve>,
}

/// Edge weights of linear initializations.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Weights {
    /// Every neighbour counts the same (Tutte's barycentric embedding).
    Uniform,
    /// Floater's mean-value weights (positive on any mesh).
    MeanValue,
    /// Cotangent weights (harmonic; may be negative on obtuse meshes).
    Cotan,
}

/// Numerical parameters common to the solvers; each documents which it reads.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Params {
    /// Edge weights of linear maps (`None`: the solver's default).
    pub weights: Option<Weights>,
    /// Convergence tolerance of iterative solvers (largest vertex update).
    pub tolerance: f64,
    /// Iteration limit of iterative solvers.
    pub max_iterations: usize,
    /// Threads for sparse factorizations (1: sequential).
    pub threads: usize,
}

impl Default for Params {
    fn default() -> Self {
        Self {
            weights: None,
            tolerance: 1e-6,
            max_iterations: 500,
            threads: 1,
        }
    }
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
    /// Pins and curves.
    pub constraints: Constraints,
    /// A starting map for iterative solvers.
    pub initial: Option<Map>,
    /// Numerical parameters.
    pub params: Params,
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
            params: Params::default(),
        }
    }
}
