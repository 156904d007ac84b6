#![warn(missing_docs)]
//! # beltrami-remesh-solver
//!
//! `remesh`: the remeshing of the `beltrami-remesh` library as a registered solver, so
//! that every front end (the command line's `beltrami remesh` and batch jobs, Python's
//! `remesh` and `remesh_in_place`, a library user with the registry) reaches it by name,
//! with typed options checked before any work.
//!
//! The problem is the source mesh with the target
//! [`Target::Surface`](beltrami_core::Target::Surface) (the new mesh lies
//! on the source surface itself) and the default goal; the option `method` chooses:
//!
//! - `param`: a new triangle mesh with the asked edge length (or about the asked vertex
//!   count), made through a parameterization: the surface opened into a chart, mapped
//!   into the plane by a registered solver (option `param`), its parameter domain
//!   triangulated by spade's constrained Delaunay refinement with the edge lengths
//!   measured on the surface, and lifted back ([`beltrami_remesh::remesh`]). A mesh in
//!   several connected components is remeshed component by component or its largest
//!   alone (option `components`, [`beltrami_remesh::components::remesh_covering`]).
//! - `qc-angles`: the source's own vertices and faces, the vertices moved along the
//!   surface so that the elements take the shapes of reference polygons as closely as a
//!   quasiconformal map allows: the Teichmueller map from the reference shapes' conformal
//!   structure to the surface by the QC iteration into R^3 (Gruber-Aulisa 2022, section
//!   6.2; [`beltrami_remesh::in_place`]), through the registered `qc-iteration` solver.
//!
//! The solution's output is [`Output::Mesh`]: the new mesh with each vertex's point on
//! the source (for `qc-angles` the source point closest to the vertex, the vertex itself
//! when it was projected). [`Extras::remesh`] says how it was made ([`RemeshSummary`]);
//! the report holds the timings per stage and the notes; with `qc-angles` the metrics
//! are the QC iteration's (`k`, `|mu|` from the reference shapes, iterations, why it
//! stopped).
//!
//! The parameterizers and the QC iteration are other registered solvers, and the
//! registry of every solver is built above this crate (a plugin depends on no plugin but
//! `init`): [`Remesh`] holds the function that builds it, called when it checks or runs
//! a problem. Registering it is one line in the function that builds the registry,
//! `beltrami_remesh_solver::register(&mut registry, crate::registry)` in
//! `beltrami::registry()`: the solver calls the function only when it checks or runs a
//! problem, so the function may build the very registry the solver is in.
//!
//! Options of the other method, given explicitly, are refused before any work
//! ([`RemeshOptionError::OtherMethod`]), as is method `param` without a size.
//!
//! ```
//! use beltrami_core::{Context, Output, Problem, Registry, Solver, Target};
//! use beltrami_mesh::{Mesh, primitives::{grid, Cells}};
//!
//! fn solvers() -> Registry {
//!     let mut registry = Registry::new();
//!     beltrami_init::register(&mut registry);
//!     beltrami_remesh_solver::register(&mut registry, solvers);
//!     registry
//! }
//!
//! let square = Mesh::from_soup(&grid(10, 10, Cells::Triangles)).unwrap();
//! let mut problem = Problem::new(&square, Target::Surface);
//! problem.options.set_text("edge-length", "0.05");
//! let registry = solvers();
//! let solution = registry.get("remesh").unwrap().solve(&problem, &mut Context::new()).unwrap();
//! let Output::Mesh(remeshed) = &solution.output else { panic!("a mesh") };
//! assert!(remeshed.mesh.vertex_count() > 400);
//! ```

mod options;

use std::borrow::Cow;

use beltrami_core::components::parts;
use beltrami_core::{
    Accepts, ComponentSummary, Context, Element, Extras, GoalKind, InPlaceSummary, Metrics,
    Options, Output, ParamSummary, Problem, Registry, RemeshSummary, Remeshed, Report, Settings,
    Solution, Solver, SolverError, SolverInfo, TargetKind, Topology,
};
use beltrami_mesh::{Mesh, MeshError};
use beltrami_remesh::components::{ComponentRemeshing, Coverage, remesh_covering};
use beltrami_remesh::in_place::{InPlace, remesh_in_place};
use beltrami_remesh::{RemeshError, param};
use beltrami_spatial::SurfaceIndex;

pub use options::{
    MAX_EDGE_LENGTH, MAX_FEATURE_TOLERANCE, Method, OPTIONS, RemeshOptionError, coverage,
    in_place_options, remesh_options,
};

/// The solver's name.
pub const NAME: &str = "remesh";

/// Every source a remeshing takes: any connected surface, and a mesh in several
/// components for method `param` with the option `components` set to `each` or
/// `largest`.
const ACCEPTS: Accepts = Accepts {
    elements: &[Element::Triangle, Element::Quad],
    topologies: Topology::ANY,
    targets: &[TargetKind::Surface],
    goals: &[GoalKind::Conformal],
    constraints: &[],
};

/// What [`Remesh`] is: its name, one line on what it computes, what it accepts and its
/// options.
const INFO: SolverInfo = SolverInfo {
    name: NAME,
    description: "a new triangle mesh of the surface with the asked edge length, through any registered parameterizer and spade's constrained Delaunay refinement (method param), or its own vertices moved towards reference angles by the QC iteration (method qc-angles)",
    accepts: ACCEPTS,
    options: OPTIONS,
};

/// The remeshing solver (crate docs).
#[derive(Debug, Clone, Copy)]
pub struct Remesh {
    /// Builds the registry the parameterizers and the QC iteration come from.
    solvers: fn() -> Registry,
}

impl Remesh {
    /// The solver, with `solvers` building the registry its parameterizers (option
    /// `param`) and the `qc-iteration` solver (method `qc-angles`) are taken from:
    /// typically the function that builds the registry it is registered in.
    pub fn new(solvers: fn() -> Registry) -> Self {
        Self { solvers }
    }

    /// Method `param`: the components the option `components` names remeshed through
    /// the chosen parameterizers.
    fn through_parameterization(
        &self,
        problem: &Problem<'_>,
        settings: &Settings,
        context: &mut Context<'_>,
    ) -> Result<Solution, SolverError> {
        let registry = (self.solvers)();
        let name = settings.choice("param");
        let choose = |part: &Mesh| param::chosen(&registry, part, name);
        let options = remesh_options(&problem.options, settings);
        let covered = remesh_covering(
            problem.source,
            coverage(settings),
            choose,
            &options,
            context,
        )
        .map_err(remesh_error)?;
        let summary = covered.summary;
        let extras = Extras {
            remesh: Some(RemeshSummary::Param(ParamSummary {
                parameterizer: summary.parameterizer,
                opening: summary.opening,
                edge_length: summary.edge_length,
                size_passes: summary.size_passes,
                components: covered.components.iter().map(component_summary).collect(),
                component: covered.component,
            })),
            ..Extras::default()
        };
        let mut report = Report::new(NAME);
        report.timings = summary
            .timings
            .iter()
            .map(|&(stage, seconds)| (stage.to_string(), seconds))
            .collect();
        report.notes = summary.notes;
        Ok(Solution {
            output: Output::Mesh(Box::new(Remeshed {
                mesh: covered.mesh,
                on_source: covered.on_source,
            })),
            metrics: Metrics::default(),
            extras,
            report,
        })
    }

    /// Method `qc-angles`: the vertices moved by the registered `qc-iteration` solver,
    /// each then located on the source.
    fn in_place(
        &self,
        problem: &Problem<'_>,
        settings: &Settings,
        context: &mut Context<'_>,
    ) -> Result<Solution, SolverError> {
        let registry = (self.solvers)();
        let solver = registry.get("qc-iteration")?;
        let options = in_place_options(settings);
        let InPlace {
            mesh,
            mut solution,
            flipped,
            input_flipped,
            features,
            pulled,
        } = remesh_in_place(problem.source, solver, &options, context).map_err(remesh_error)?;
        let on_source = SurfaceIndex::new(problem.source)
            .and_then(|index| index.locate_all(mesh.positions()))
            .map_err(|error| SolverError::plugin(NAME, error))?
            .into_iter()
            .map(|located| located.point)
            .collect();
        solution.output = Output::Mesh(Box::new(Remeshed { mesh, on_source }));
        solution.extras.remesh = Some(RemeshSummary::InPlace(InPlaceSummary {
            reference: options.reference.name(),
            constraint: options.keep.name(),
            projected: options.project,
            feature_angle: options.feature_angle,
            flipped,
            input_flipped,
            features,
            pulled,
        }));
        solution.report.solver = NAME.to_string();
        Ok(solution)
    }
}

impl Solver for Remesh {
    fn info(&self) -> &'static SolverInfo {
        &INFO
    }

    /// The options' rules ([`check_options`]), then for method `param` a parameterizer
    /// that is registered and, unless the option `components` says how, a source in one
    /// piece.
    fn check_problem(&self, problem: &Problem<'_>, settings: &Settings) -> Result<(), SolverError> {
        options::check(&problem.options, settings)?;
        if Method::of(settings) == Method::QcAngles {
            return Ok(());
        }
        let name = settings.choice("param");
        if name != "auto" {
            param::chosen(&(self.solvers)(), problem.source, name).map_err(remesh_error)?;
        }
        let components = problem.source.component_count();
        if coverage(settings) == Coverage::Whole && components > 1 {
            return Err(remesh_error(RemeshError::Components { components }));
        }
        Ok(())
    }

    fn run(
        &self,
        problem: &Problem<'_>,
        settings: &Settings,
        context: &mut Context<'_>,
    ) -> Result<Solution, SolverError> {
        match Method::of(settings) {
            Method::Param => self.through_parameterization(problem, settings, context),
            Method::QcAngles => self.in_place(problem, settings, context),
        }
    }
}

/// Registers [`Remesh`], its parameterizers and QC iteration taken from the registry
/// `solvers` builds.
pub fn register(registry: &mut Registry, solvers: fn() -> Registry) {
    registry.register(Box::new(Remesh::new(solvers)));
}

/// The checks of [`Remesh`] that need no mesh: the values `options` set resolved
/// against [`OPTIONS`] and the rules of their method ([`RemeshOptionError`], and the
/// library's checks of method `param`'s options). A front end that reads the source from
/// a file calls it first, to refuse bad options before reading; [`Solver::check`] runs
/// it again.
pub fn check_options(options: &Options) -> Result<Settings, SolverError> {
    let settings = Settings::resolve(NAME, OPTIONS, options)?;
    options::check(options, &settings)?;
    Ok(settings)
}

/// The surface a [`ParamSummary`] of `source` remeshed, the one the new mesh replaces
/// and is measured against: its [`ParamSummary::component`] as a mesh of its own
/// (rebuilt by [`parts`], as the remeshing built it), or `source` itself when the whole
/// was remeshed (or the index is not one of `source`'s components).
pub fn remeshed_input<'a>(
    source: &'a Mesh,
    summary: &ParamSummary,
) -> Result<Cow<'a, Mesh>, MeshError> {
    let Some(k) = summary.component else {
        return Ok(Cow::Borrowed(source));
    };
    Ok(parts(source)?
        .into_iter()
        .nth(k)
        .map_or(Cow::Borrowed(source), |part| Cow::Owned(part.mesh)))
}

/// One component's remeshing, summed up.
fn component_summary(c: &ComponentRemeshing) -> ComponentSummary {
    let r = &c.remeshing;
    ComponentSummary {
        input_faces: c.input_faces,
        parameterizer: r.parameterizer,
        opening: r.opening.name(),
        edge_length: r.edge_length,
        vertices: r.remeshed.mesh.vertex_count(),
        faces: r.remeshed.mesh.face_count(),
    }
}

/// A remeshing error as the solver's: a cancellation (of the remeshing or of a
/// parameterization inside it) as [`SolverError::Cancelled`], every other error kept
/// typed as the source of [`SolverError::Plugin`].
fn remesh_error(error: RemeshError) -> SolverError {
    match error {
        RemeshError::Cancelled
        | RemeshError::Solve {
            error: SolverError::Cancelled,
            ..
        } => SolverError::Cancelled,
        error => SolverError::plugin(NAME, error),
    }
}
