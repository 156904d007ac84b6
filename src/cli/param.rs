//! `beltrami param`: parameterize a mesh with one of the registered solvers.

use std::path::PathBuf;

use beltrami::map_file;
use beltrami::problem_spec::{BoundaryDefault, BoundaryName, ProblemSpec, TargetName};
use beltrami_core::{Constraint, GoalKind, OptionValue, components};
use clap::{Args, ValueEnum};

use super::load::{ComponentsArg, load_mesh};
use super::mapping;
use super::pins::PinSpec;

/// Boundary shapes of `--boundary`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum BoundaryArg {
    /// The unit circle, by arc length.
    Circle,
    /// The unit square, corners a quarter of the boundary apart.
    Square,
    /// Free (LSCM).
    Free,
}

/// Edge weights of `--weights`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum WeightsArg {
    /// Tutte's uniform weights.
    Uniform,
    /// Floater's mean-value weights.
    MeanValue,
    /// Cotangent weights.
    Cotan,
}

/// The `--solver` help: the registered solvers of a conformal map into a domain.
fn solver_help() -> String {
    let names = beltrami::catalog::domain_solvers(|goals| goals.contains(&GoalKind::Conformal));
    format!(
        "Solver name ({}; `beltrami solvers` describes them)",
        names.join(", ")
    )
}

#[derive(Debug, Args)]
pub struct ParamArgs {
    /// Mesh file (.obj, .ply, .stl, .off, .gltf, .glb).
    pub mesh: PathBuf,
    #[arg(long, help = solver_help())]
    pub solver: String,
    /// Boundary of the parameter domain (default: the first of these the solver takes:
    /// circle for tutte and harmonic, free for lscm; the sphere solver maps onto the
    /// unit sphere without it).
    #[arg(long, value_enum)]
    pub boundary: Option<BoundaryArg>,
    /// Edge weights (tutte: uniform or mean-value; harmonic: cotan).
    #[arg(long, value_enum)]
    pub weights: Option<WeightsArg>,
    /// qcmc: the boundary loop mapped onto the unit circle, by its 0-based index in the
    /// mesh's boundary-loop order (the report's `loop`) [default: the longest].
    #[arg(long)]
    pub outer: Option<usize>,
    /// Pin a vertex: `v12` by its 0-based index, or `x,y[,z]` for the nearest vertex;
    /// repeatable. LSCM's two pins go to (0,0) and (1,0).
    #[arg(long = "pin")]
    pub pins: Vec<PinSpec>,
    /// A mesh in several connected components (a scan in pieces): `each` maps every
    /// component on its own and places the maps side by side, left to right in the
    /// order of each component's first face (maps into the plane only); `largest` maps
    /// only the largest. Without it such a mesh is refused.
    #[arg(long, value_enum)]
    pub components: Option<ComponentsArg>,
    /// Output mesh: .obj (the input's vertices and faces, one `vt` per vertex; for the
    /// sphere, the sphere positions) or .glb/.gltf (UVs and |mu| colors).
    #[arg(short, long)]
    pub output: PathBuf,
    #[command(flatten)]
    pub common: mapping::CommonArgs,
}

/// The problem's words from the flags: the plane with the boundary of `--boundary`, by
/// default the first of circle, square and free the solver takes (the unit sphere or a
/// circle domain for a solver that maps only onto one), `--weights`, `--outer` and
/// `--option`.
fn spec_of(args: &ParamArgs) -> ProblemSpec {
    let mut spec = ProblemSpec::new(TargetName::Plane);
    spec.solver = Some(args.solver.clone());
    spec.boundary = args.boundary.map(|b| match b {
        BoundaryArg::Circle => BoundaryName::Circle,
        BoundaryArg::Square => BoundaryName::Square,
        BoundaryArg::Free => BoundaryName::Free,
    });
    spec.boundary_default = BoundaryDefault::Shaped;
    let weights = args.weights.map(|w| match w {
        WeightsArg::Uniform => "uniform",
        WeightsArg::MeanValue => "mean-value",
        WeightsArg::Cotan => "cotan",
    });
    if let Some(weights) = weights {
        spec.options
            .set("weights", OptionValue::Choice(weights.to_string()));
    }
    if let Some(outer) = args.outer {
        spec.options.set("outer", OptionValue::Int(outer + 1));
    }
    for (name, value) in &args.common.options {
        spec.options.set_text(name, value);
    }
    spec
}

pub fn run(args: &ParamArgs, quiet: bool) -> anyhow::Result<()> {
    mapping::check_outputs(&args.output, &args.common, &[])?;
    let mut spec = spec_of(args);
    let registry = beltrami::registry();
    let solver = registry.get(spec.solver_name())?;
    let loaded = load_mesh(&args.mesh, args.common.repair, quiet || args.common.json)?;
    let mesh = &loaded.mesh.mesh;
    spec.constraints.extend(
        mapping::resolve_pins(&args.pins, mesh)?
            .into_iter()
            .map(Constraint::Pin),
    );
    let problem = spec.problem(mesh, None, solver)?;
    mapping::check_output_holds_map(&args.output, &problem.target)?;

    let progress = args.common.progress(quiet);
    let parts;
    let groups = loaded.mesh.obj_groups.as_slice();
    let (mesh, solution, seconds, sections, groups) = match args.components {
        Some(ComponentsArg::Largest) if mesh.component_count() > 1 => {
            parts = components::parts(mesh)?;
            let part = components::largest(&parts).map(|k| &parts[k]);
            let part = part.ok_or_else(|| anyhow::anyhow!("the mesh has no faces"))?;
            let problem = part.problem(&problem, solver.name())?;
            let (mut solution, seconds) = mapping::solve(solver, &problem, progress)?;
            solution.report.notes.push(format!(
                "the largest of {} components mapped ({} of {} faces); OUT holds it alone",
                parts.len(),
                part.mesh.face_count(),
                mesh.face_count()
            ));
            // The part's faces are not the input's: its groups are not written.
            (&part.mesh, solution, seconds, None, &[][..])
        }
        Some(ComponentsArg::Each) => {
            let (solution, seconds) = mapping::run_with_progress(progress, |context| {
                components::solve_each(solver, &problem, context)
            })?;
            (mesh, solution, seconds, None, groups)
        }
        _ => {
            let (solution, seconds, sections) =
                mapping::solve_formatting_output(solver, &problem, progress, &args.output)
                    .map_err(|e| {
                        if mesh.component_count() > 1 {
                            anyhow::anyhow!(
                                "{}\nhint: `--components each` maps every connected component on its own (side by side), `--components largest` the largest alone",
                                beltrami::report::error_message(e.as_ref())
                            )
                        } else {
                            e
                        }
                    })?;
            (mesh, solution, seconds, sections, groups)
        }
    };
    map_file::write(
        &args.output,
        mesh,
        &solution,
        None,
        sections.as_ref(),
        groups,
    )?;
    mapping::write_png(args.common.png.as_deref(), mesh, &solution, None)?;
    let mut report = mapping::report_json(&args.mesh, &args.output, &solution, seconds);
    let mut circles = super::qc::circles(mesh, &solution, &mut report);
    if let Some(stop) = solution.metrics.stop {
        circles.push(format!(
            "iterations      {} ({})",
            solution.metrics.iterations,
            stop.name()
        ));
    }
    mapping::finish(
        report,
        args.common.report.as_deref(),
        args.common.json,
        quiet,
        (&args.mesh, &args.output, &solution, seconds),
        &circles,
    )
}
