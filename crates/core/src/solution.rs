//! The result of a solve: an [`Output`] (a map of the source's vertices, or a new mesh
//! located on the source), typed [`Metrics`] (distortion, errors, histories), typed
//! [`Extras`] (what some solvers compute beside the map) and the [`Report`] (timings
//! and prose notes).

use beltrami_fem::{BeltramiField, DistortionStats, Frame, MuError};
use beltrami_mesh::{Mesh, SurfacePoint, VertexId};
use num_complex::Complex64;

use crate::{Map, Report};

/// What a solver produces.
#[derive(Debug, Clone)]
pub enum Output {
    /// Images of the source's vertices.
    Map(Map),
    /// A new mesh (remeshing) with each of its vertices located on the source (boxed:
    /// a mesh is much larger than a map's vector header).
    Mesh(Box<Remeshed>),
}

/// A new mesh and where its vertices lie on the source surface.
#[derive(Debug, Clone)]
pub struct Remeshed {
    /// The new mesh.
    pub mesh: Mesh,
    /// Per vertex of the new mesh (by id), its point on the source.
    pub on_source: Vec<SurfacePoint>,
}

/// Why an iterative solver stopped.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Stop {
    /// The largest update fell below the tolerance (absolute, in the target's units).
    Converged {
        /// The tolerance reached.
        tolerance: f64,
    },
    /// No step above the tolerance decreased the error further.
    Stalled,
    /// The iteration limit was reached first.
    IterationLimit,
    /// Cancelled by the user; the map is the best one so far.
    Cancelled,
}

impl Stop {
    /// The stable name in reports: `converged`, `stalled`, `iteration-limit` or
    /// `cancelled`.
    pub fn name(&self) -> &'static str {
        match self {
            Stop::Converged { .. } => "converged",
            Stop::Stalled => "stalled",
            Stop::IterationLimit => "iteration-limit",
            Stop::Cancelled => "cancelled",
        }
    }
}

/// What a solve measured, typed. Fields a solver does not compute stay `None` or empty.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Metrics {
    /// The result's Beltrami coefficient per face.
    pub mu: Option<BeltramiField>,
    /// Statistics of `|mu|` and the flipped-face count of the result.
    pub distortion: Option<DistortionStats>,
    /// The same for the map an iterative solver started from.
    pub initial_distortion: Option<DistortionStats>,
    /// `|mu - target|` for a prescribed Beltrami coefficient (area-weighted RMS, squared
    /// L2, sup and where).
    pub mu_error: Option<MuError>,
    /// The dilatation `k = |mu|` of an extremal (Teichmueller) map.
    pub k: Option<f64>,
    /// The smallest `sup |mu|` of any map in the result's homotopy class, when known
    /// (a registration between two tori: from their conformal moduli).
    pub teichmueller_bound: Option<f64>,
    /// Iterations done (0 for direct solvers).
    pub iterations: usize,
    /// Energy or error after each iteration (direct solvers: the final energy, if any).
    pub energy_history: Vec<f64>,
    /// The step size of each iteration of an iterative solver.
    pub step_sizes: Vec<f64>,
    /// Why an iterative solver stopped.
    pub stop: Option<Stop>,
    /// Numeric factorizations done.
    pub factorizations: Option<usize>,
    /// Conjugate-gradient iterations done on steps that reused a factorization.
    pub cg_iterations: Option<usize>,
}

impl Metrics {
    /// Number of flipped faces of the result, when measured.
    pub fn flipped(&self) -> Option<usize> {
        self.distortion.as_ref().map(|d| d.flipped)
    }
}

/// The inner radius of an annulus target when it was an unknown (the conformal modulus
/// `(1/2 pi) log(1/r)` of the map).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AnnulusRadius {
    /// The radius found.
    pub radius: f64,
    /// The radius the solve started from.
    pub initial: f64,
}

/// A circle of a circle domain: the image of boundary loop `boundary_loop` (an index
/// into the source's [`Mesh::boundary_loop_list`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Circle {
    /// The boundary loop.
    pub boundary_loop: usize,
    /// The centre.
    pub center: Complex64,
    /// The radius.
    pub radius: f64,
}

/// A holomorphic quadratic differential `phi dz^2` of an extremal map, one value per
/// face in a stated frame (a frame rotation by `theta` multiplies `phi` by
/// `e^{-2 i theta}`, like `mu`).
#[derive(Debug, Clone, PartialEq)]
pub struct QuadraticDifferential {
    /// The frame of the values.
    pub frame: Frame,
    /// `phi` per face.
    pub values: Vec<Complex64>,
}

/// How far a landmark's image ended from its target: `|f(v) - p|` for the landmark on
/// source vertex `vertex` with target point `p` (on a target mesh, the closest point of
/// the target to the given point).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LandmarkResidual {
    /// The landmark's index among the problem's landmarks.
    pub index: usize,
    /// Its source vertex.
    pub vertex: VertexId,
    /// The distance, in the target's units.
    pub distance: f64,
}

/// How far a registration's feature match brought the fields together: the mean squared
/// difference of the standardized fields (source field minus the target field at each
/// image, area-weighted) before and after, and the steps kept.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FeatureMismatch {
    /// At the conformal registration the match started from.
    pub before: f64,
    /// At the result.
    pub after: f64,
    /// Steps kept.
    pub steps: usize,
}

/// How far a registration's shape match brought the source onto the target: the mean
/// distance from each source vertex, placed by the similarity that best carries the
/// source onto its images, to its image, in the target's units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShapeDistance {
    /// At the conformal registration the match started from.
    pub before: f64,
    /// At the result.
    pub after: f64,
}

/// What some solvers compute beside the map, typed.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Extras {
    /// The free inner radius of an annulus target.
    pub annulus_radius: Option<AnnulusRadius>,
    /// The circles of a circle-domain map (the outer one first).
    pub circles: Option<Vec<Circle>>,
    /// The quadratic differential of an extremal map.
    pub quadratic_differential: Option<QuadraticDifferential>,
    /// Each landmark's residual, in the order of the problem's landmarks (a
    /// registration).
    pub landmarks: Vec<LandmarkResidual>,
    /// The road a registration took, in words: the common domain, where the landmarks
    /// were matched and why.
    pub route: Option<String>,
    /// A registration's feature match (`Goal::Features`, and the shape's coordinates
    /// when it is matched).
    pub features: Option<FeatureMismatch>,
    /// A registration's shape match (its option `match-shape`).
    pub shape: Option<ShapeDistance>,
    /// How a remeshing's new mesh ([`Output::Mesh`]) was made.
    pub remesh: Option<RemeshSummary>,
}

/// How the `remesh` solver made its new mesh, by method; its timings and notes are in
/// the solution's [`Report`].
#[derive(Debug, Clone, PartialEq)]
pub enum RemeshSummary {
    /// A new mesh through a parameterization (method `param`).
    Param(ParamSummary),
    /// The source's own vertices and faces, the vertices moved along it towards
    /// reference angles (method `qc-angles`); the metrics are the QC iteration's.
    InPlace(InPlaceSummary),
}

/// A remeshing through a parameterization.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamSummary {
    /// The parameterizer: a registered solver's name, `plane` for a planar surface (its
    /// own parameterization), `per component` when the components used different ones.
    pub parameterizer: &'static str,
    /// How the surface was opened for it (`uncut`, `slit`, `cut-graph`, `filled`,
    /// `two-charts`), `per component` when the components were opened differently.
    pub opening: &'static str,
    /// The asked edge length; for components remeshed to a shared vertex count, the mean
    /// of their edge lengths weighted by area.
    pub edge_length: f64,
    /// Size passes of the refinement (the most of any component).
    pub size_passes: usize,
    /// Per connected component remeshed on its own, in the order of their first faces
    /// (empty unless the components were remeshed one by one).
    pub components: Vec<ComponentSummary>,
    /// The one component remeshed alone (the largest of a source in pieces), by its
    /// index in the order of [`crate::components::parts`]; `None` when the whole source
    /// was remeshed. The new mesh then replaces that component only.
    pub component: Option<usize>,
}

/// One connected component's remeshing within a [`ParamSummary`].
#[derive(Debug, Clone, PartialEq)]
pub struct ComponentSummary {
    /// The component's faces in the source.
    pub input_faces: usize,
    /// Its parameterizer.
    pub parameterizer: &'static str,
    /// How it was opened.
    pub opening: &'static str,
    /// Its asked edge length.
    pub edge_length: f64,
    /// The vertices of its new mesh.
    pub vertices: usize,
    /// The faces of its new mesh.
    pub faces: usize,
}

/// A remeshing in place by reference angles: its settings as used, and what became of
/// the faces that could turn against the surface.
#[derive(Debug, Clone, PartialEq)]
pub struct InPlaceSummary {
    /// The reference shapes: `optimized` or `equiangular`.
    pub reference: &'static str,
    /// How the image stayed near the surface: `normal` or `area`.
    pub constraint: &'static str,
    /// Whether the moved vertices were projected onto the source.
    pub projected: bool,
    /// Vertices of edges whose faces' normals differ by more than this (degrees) were
    /// held.
    pub feature_angle: f64,
    /// Faces turned against the source surface (their normal and the source's at the
    /// closest point to their centroid 90 degrees or more apart).
    pub flipped: usize,
    /// Faces of the source turned against its own surface by the same measure.
    pub input_flipped: usize,
    /// Vertices held on sharp features.
    pub features: usize,
    /// Vertices pulled back towards their source positions because a face of theirs had
    /// turned.
    pub pulled: usize,
}

/// The result of a solve.
#[derive(Debug, Clone)]
pub struct Solution {
    /// The map or the new mesh.
    pub output: Output,
    /// What was measured.
    pub metrics: Metrics,
    /// What the solver computed beside the map.
    pub extras: Extras,
    /// Timings and notes.
    pub report: Report,
}

impl Solution {
    /// A solution with a map, empty metrics and extras.
    pub fn from_map(map: Map, report: Report) -> Self {
        Self {
            output: Output::Map(map),
            metrics: Metrics::default(),
            extras: Extras::default(),
            report,
        }
    }

    /// The map, if the output is one.
    pub fn map(&self) -> Option<&Map> {
        match &self.output {
            Output::Map(map) => Some(map),
            Output::Mesh(_) => None,
        }
    }

    /// The planar images, if the output is a planar map.
    pub fn planar(&self) -> Option<&[Complex64]> {
        self.map().and_then(Map::as_planar)
    }
}
