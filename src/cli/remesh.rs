//! `beltrami remesh`: a new triangle mesh of a surface with the asked edge length, made
//! through a parameterization, or its own vertices moved towards reference angles: the
//! registered solver `remesh` (the `beltrami-remesh-solver` plugin over the
//! `beltrami-remesh` crate; docs/remesh.md), its options set from the flags.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context as _, anyhow, bail};
use beltrami::remesh_solver::{self, OPTIONS, RemeshOptionError};
use beltrami_core::{
    Context, InPlaceSummary, OptionError, OptionValue, Options, Output, ParamSummary, Problem,
    RemeshSummary, Report, Solution, SolverError, Target,
};
use beltrami_mesh::Mesh;
use beltrami_mesh::io::{self, VertexAttributes};
use beltrami_remesh::{Quality, RemeshError};
use beltrami_render::{ColorBy, Scene, Style, View};
use clap::{Args, ValueEnum};
use serde_json::{Value, json};

use super::load::{ComponentsArg, load_mesh};
use super::mapping::{LateBar, check_output_format, png_path};

/// Remeshing methods of `--method`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum MethodArg {
    /// Parameterize, triangulate the parameter domain (spade), lift back.
    Param,
    /// Same vertices and faces, the vertices moved along the surface towards reference
    /// angles by the QC iteration (Gruber-Aulisa 2022, section 6.2).
    QcAngles,
}

/// Reference shapes of `--reference`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ReferenceArg {
    /// Angles adapted to the vertex valences (Gruber-Aulisa 2022, Algorithm 5).
    Optimized,
    /// Equilateral triangles and squares.
    Equiangular,
}

/// Constraints of `--constraint`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum KeepArg {
    /// Every displacement tangent to the surface (section 4.1).
    Normal,
    /// The area kept to first order (section 4.2).
    Area,
}

/// Size fields of `--size-field`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum SizeFieldArg {
    /// The asked edge length everywhere.
    Uniform,
    /// Shorter edges where the surface bends (down to a quarter of the asked length).
    Curvature,
}

#[derive(Debug, Args)]
#[command(group(clap::ArgGroup::new("resolution").args(["edge_length", "vertices"])))]
pub struct RemeshArgs {
    /// Mesh file (.obj, .ply, .stl, .off, .gltf, .glb): one connected surface of any genus, with or
    /// without boundary.
    pub mesh: PathBuf,
    /// The edge length on the surface, in the mesh's units.
    #[arg(long = "edge-length", value_name = "L", allow_hyphen_values = true)]
    pub edge_length: Option<f64>,
    /// About this many vertices (the edge length of an equilateral mesh of the
    /// surface's area with N vertices).
    #[arg(long, value_name = "N")]
    pub vertices: Option<usize>,
    /// How to remesh: `param` makes a new mesh with the asked edge length (needs
    /// --edge-length or --vertices); `qc-angles` moves the vertices of this one.
    #[arg(long, value_enum, default_value = "param")]
    pub method: MethodArg,
    /// qc-angles: the reference shapes the elements move towards.
    #[arg(long, value_enum, default_value = "optimized")]
    pub reference: ReferenceArg,
    /// qc-angles: how the moved vertices stay on the surface.
    #[arg(long, value_enum, default_value = "normal")]
    pub constraint: KeepArg,
    /// qc-angles: most QC iterations.
    #[arg(long = "max-iters", value_name = "N", default_value_t = 10)]
    pub max_iters: usize,
    /// qc-angles: stop when no face's mu moves by more than this in an iteration.
    #[arg(long, value_name = "T", default_value_t = 1e-4)]
    pub tolerance: f64,
    /// qc-angles: leave the moved vertices where the map puts them instead of moving
    /// them onto the input surface.
    #[arg(long = "no-project")]
    pub no_project: bool,
    /// qc-angles: hold the vertices of edges whose faces' normals differ by more than A
    /// degrees (sharp creases and corners); 180 holds none.
    #[arg(long = "feature-angle", value_name = "A", default_value_t = 60.0)]
    pub feature_angle: f64,
    /// qc-angles: write the result even when faces end turned against the surface that
    /// were not turned in the input (otherwise an error names the first).
    #[arg(long = "allow-flips")]
    pub allow_flips: bool,
    /// The parameterizer, any registered solver that maps into the plane (`beltrami
    /// solvers` lists them), `sphere` for a closed genus-0 surface (two stereographic
    /// charts), or `auto`: lscm on a disk, on a closed genus-0 surface slit open, on a
    /// genus-0 surface with several boundary loops with its holes closed (then qcmc),
    /// on any other surface cut to a disk, with tutte when the map folds or overlaps.
    #[arg(long, value_name = "NAME", default_value = "auto")]
    pub param: String,
    /// The smallest angle refinement enforces, in degrees (at most 33.8).
    #[arg(
        long = "min-angle",
        value_name = "A",
        default_value_t = 30.0,
        allow_hyphen_values = true
    )]
    pub min_angle: f64,
    /// How the edge length varies over the surface.
    #[arg(long = "size-field", value_enum, default_value = "uniform")]
    pub size_field: SizeFieldArg,
    /// The most vertices the result may have.
    #[arg(long = "max-vertices", value_name = "N", default_value_t = 5_000_000)]
    pub max_vertices: usize,
    /// How far the result may pass an input vertex, as a fraction of the edge length,
    /// before that vertex is inserted (creases and boundary corners kept); `inf` inserts
    /// none (the asked length on rough input, at the price of the distance).
    #[arg(
        long = "feature-tolerance",
        value_name = "T",
        default_value_t = beltrami_remesh::FEATURE_TOLERANCE,
        allow_hyphen_values = true
    )]
    pub feature_tolerance: f64,
    /// Output mesh (.obj, .ply, .stl, .off, .gltf, .glb).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Write the JSON report here.
    #[arg(long, value_name = "R.json")]
    pub report: Option<PathBuf>,
    /// Print the JSON report on stdout instead of the summary.
    #[arg(long)]
    pub json: bool,
    /// Also draw the result in 3D with its edges as PNG.
    #[arg(long, value_parser = png_path)]
    pub png: Option<PathBuf>,
    /// Repair what can be repaired safely in the input (see `beltrami info --repair`).
    #[arg(long)]
    pub repair: bool,
    /// --method param, a mesh in several connected components (a scan in pieces):
    /// `each` remeshes every component on its own (--vertices shared out by area) and
    /// joins the results in the order of each component's first face; `largest`
    /// remeshes only the largest. Without it such a mesh is refused.
    #[arg(long, value_enum)]
    pub components: Option<ComponentsArg>,
}

/// The name of a value of a `ValueEnum` flag, as the command line and the `remesh`
/// solver's options spell it.
fn value_name(value: impl ValueEnum) -> String {
    value
        .to_possible_value()
        .map(|v| v.get_name().to_string())
        .unwrap_or_default()
}

impl RemeshArgs {
    /// The options of the `remesh` solver these flags set: the method, the size and
    /// `--components` when given, and every other flag whose value differs from the
    /// solver's default (a flag left at its default is not given, so that the flags of
    /// the other method are refused only when set); `--feature-tolerance inf` is
    /// `keep-features=false`.
    fn solver_options(&self) -> Options {
        let mut options = Options::new();
        options.set("method", OptionValue::Choice(value_name(self.method)));
        if let Some(l) = self.edge_length {
            options.set("edge-length", OptionValue::Float(l));
        }
        if let Some(n) = self.vertices {
            options.set("vertices", OptionValue::Int(n));
        }
        if let Some(components) = self.components {
            options.set("components", OptionValue::Choice(value_name(components)));
        }
        let features = if self.feature_tolerance == f64::INFINITY {
            ("keep-features", OptionValue::Bool(false))
        } else {
            (
                "feature-tolerance",
                OptionValue::Float(self.feature_tolerance),
            )
        };
        let flags = [
            ("param", OptionValue::Choice(self.param.clone())),
            ("min-angle", OptionValue::Float(self.min_angle)),
            (
                "size-field",
                OptionValue::Choice(value_name(self.size_field)),
            ),
            ("max-vertices", OptionValue::Int(self.max_vertices)),
            features,
            ("reference", OptionValue::Choice(value_name(self.reference))),
            (
                "constraint",
                OptionValue::Choice(value_name(self.constraint)),
            ),
            ("max-iters", OptionValue::Int(self.max_iters)),
            ("tolerance", OptionValue::Float(self.tolerance)),
            ("feature-angle", OptionValue::Float(self.feature_angle)),
            ("project", OptionValue::Bool(!self.no_project)),
            ("allow-flips", OptionValue::Bool(self.allow_flips)),
        ];
        for (name, value) in flags {
            let default = OPTIONS
                .iter()
                .find(|spec| spec.name == name)
                .map(|spec| spec.kind.default_value());
            if default.as_ref() != Some(&value) {
                options.set(name, value);
            }
        }
        options
    }
}

pub fn run(args: &RemeshArgs, quiet: bool) -> anyhow::Result<()> {
    check_output_format(&args.output)?;
    super::outputs::check(&[
        ("-o", Some(&args.output)),
        ("--png", args.png.as_deref()),
        ("--report", args.report.as_deref()),
    ])?;
    let options = args.solver_options();
    remesh_solver::check_options(&options).map_err(flag_error)?;
    let registry = beltrami::registry();
    let solver = registry.get(remesh_solver::NAME)?;
    let loaded = load_mesh(&args.mesh, args.repair, quiet || args.json)?;
    let source = &loaded.mesh.mesh;
    let mut problem = Problem::new(source, Target::Surface);
    problem.options = options;
    let start = Instant::now();
    let mut bar = LateBar::new(args.method == MethodArg::QcAngles && !(quiet || args.json));
    let solved = {
        let mut context = Context::new()
            .with_progress(|p: &beltrami_core::Progress| bar.update(p))
            .with_cancel_flag(super::interrupt::cancel_flag());
        solver.solve(&problem, &mut context)
    };
    bar.finish();
    let solution = solved
        .map_err(flag_error)
        .with_context(|| format!("cannot remesh {}", args.mesh.display()))?;
    let seconds = start.elapsed().as_secs_f64();
    let (Output::Mesh(remeshed), Some(summary)) = (&solution.output, &solution.extras.remesh)
    else {
        bail!("{} gave no new mesh", solver.name());
    };
    let out = &remeshed.mesh;
    io::write(&args.output, out, &VertexAttributes::default())?;
    write_png(args.png.as_deref(), out)?;
    match summary {
        RemeshSummary::Param(summary) => {
            let input = remesh_solver::remeshed_input(source, summary)?;
            let quality = beltrami_remesh::quality::measure(&input, out)?;
            let report = report_json(
                args,
                beltrami::report::remesh(&input, summary, &solution.report, &quality, seconds),
            );
            finish(args, &report, quiet, || {
                print_summary(args, summary, &solution.report, &quality, seconds)
            })
        }
        RemeshSummary::InPlace(summary) => {
            let before = beltrami_remesh::quality::shape(source);
            let after = beltrami_remesh::quality::measure(source, out)?;
            let report = report_json(
                args,
                beltrami::report::remesh_in_place(
                    source, summary, &solution, &before, &after, seconds,
                ),
            );
            finish(args, &report, quiet, || {
                let quality = [("before", &before), ("after", &after)];
                print_in_place(args, source, summary, &solution, &quality, seconds)
            })
        }
    }
}

/// The command-line spelling of the `remesh` solver's option `option`.
fn flag(option: &str) -> String {
    match option {
        "project" => "--no-project".to_string(),
        "keep-features" => "--feature-tolerance".to_string(),
        other => format!("--{other}"),
    }
}

/// The `remesh` solver's refusal `error` in the words of the command line: its option
/// errors name the flags, a remeshing error is shown as it is (with the `--components`
/// flags named when the mesh has several components).
fn flag_error(error: SolverError) -> anyhow::Error {
    let error = match error {
        SolverError::Option(OptionError::Range {
            option,
            min,
            max,
            got,
            ..
        }) => return anyhow!("{} {got}: give a value in [{min}, {max}]", flag(option)),
        SolverError::Plugin { solver, error } => match error.downcast::<RemeshOptionError>() {
            Ok(refusal) => return anyhow!(flag_message(&refusal)),
            Err(error) => match error.downcast::<RemeshError>() {
                Ok(error) => return with_hint(*error),
                Err(error) => SolverError::Plugin { solver, error },
            },
        },
        other => other,
    };
    anyhow::Error::new(error)
}

/// [`RemeshOptionError`] with the flags of the command line.
fn flag_message(error: &RemeshOptionError) -> String {
    match error {
        RemeshOptionError::OtherMethod {
            option: "edge-length" | "vertices",
            method: "qc-angles",
            ..
        } => "--method qc-angles keeps the input's vertices and faces: drop --edge-length and --vertices".to_string(),
        RemeshOptionError::OtherMethod { option, method, of } => format!(
            "{} is a flag of --method {of}; --method {method} does not read it",
            flag(option)
        ),
        RemeshOptionError::NoSize => {
            "--method param makes a new mesh: give its size with --edge-length L or --vertices N"
                .to_string()
        }
        RemeshOptionError::Value {
            option,
            got,
            expected,
        } => format!("{} {got}: give {expected}", flag(option)),
        other => other.to_string(),
    }
}

/// `error`, with the `--components` flags named when the mesh has several components.
fn with_hint(error: RemeshError) -> anyhow::Error {
    match error {
        RemeshError::Components { .. } => anyhow::anyhow!(
            "{error}\nhint: `--components each` remeshes every connected component on its own, `--components largest` the largest alone"
        ),
        other => anyhow::Error::new(other),
    }
}

/// The summary of `--method qc-angles`: angles `before` and after, distance, `|mu|`,
/// iterations, flips and held features.
fn print_in_place(
    args: &RemeshArgs,
    mesh: &Mesh,
    summary: &InPlaceSummary,
    solution: &Solution,
    quality: &[(&str, &Quality); 2],
    seconds: f64,
) {
    println!(
        "{} -> {} (qc-angles, {} reference, {} constraint, {seconds:.3} s)",
        args.mesh.display(),
        args.output.display(),
        summary.reference,
        summary.constraint
    );
    println!(
        "  vertices        {}  faces {}",
        mesh.vertex_count(),
        mesh.face_count()
    );
    for (name, q) in quality {
        println!(
            "  angles {name:<8} min {:.2}  mean {:.2}  under 30: {:.3}%",
            q.min_angle,
            q.mean_angle,
            100.0 * q.share_below_30
        );
    }
    let after = quality[1].1;
    println!(
        "  distance        Hausdorff {:.4e} ({:.3}% of the diagonal)  mean {:.4e}",
        after.hausdorff,
        100.0 * after.hausdorff / after.diagonal,
        after.mean_distance
    );
    let m = &solution.metrics;
    if let (Some(k), Some(d)) = (m.k, &m.distortion) {
        println!(
            "  |mu|            k {k:.4}  mean {:.4}  std {:.4}  max {:.4}",
            d.mu_mean, d.mu_std, d.mu_max
        );
    }
    println!(
        "  iterations      {} ({})",
        m.iterations,
        m.stop.as_ref().map_or("", |s| s.name())
    );
    println!(
        "  flipped         {} (input {}; {} vertices pulled back)",
        summary.flipped, summary.input_flipped, summary.pulled
    );
    println!("  held features   {} vertices", summary.features);
    for note in &solution.report.notes {
        println!("  note: {note}");
    }
}

/// `--png`: the mesh in 3D with its edges.
fn write_png(path: Option<&std::path::Path>, mesh: &beltrami_mesh::Mesh) -> anyhow::Result<()> {
    let Some(path) = path else {
        return Ok(());
    };
    let scene = Scene::new(mesh, None)?;
    let style = Style {
        view: View::Surface,
        color: ColorBy::Plain,
        wire: true,
        ..Style::default()
    };
    beltrami_render::render(&scene, &style)?
        .write_png(path)
        .with_context(|| format!("cannot write the picture {}", path.display()))
}

/// Writes `--report`, prints the report (`--json`) or the summary, and fails after an
/// interruption.
fn finish(
    args: &RemeshArgs,
    report: &Value,
    quiet: bool,
    summary: impl FnOnce(),
) -> anyhow::Result<()> {
    if let Some(path) = &args.report {
        let text = serde_json::to_string_pretty(report)?;
        io::write_atomically(path, |w| std::io::Write::write_all(w, text.as_bytes()))
            .with_context(|| format!("cannot write the report {}", path.display()))?;
    }
    if args.json {
        println!("{report}");
    } else if !quiet {
        summary();
    }
    if super::interrupt::interrupted() {
        bail!("interrupted");
    }
    Ok(())
}

/// The JSON report: the input and output files, then `body`
/// ([`beltrami::report::remesh`] or [`beltrami::report::remesh_in_place`]).
fn report_json(args: &RemeshArgs, body: serde_json::Map<String, Value>) -> Value {
    let mut report = serde_json::Map::new();
    report.insert("mesh".into(), json!(args.mesh.display().to_string()));
    report.insert("output".into(), json!(args.output.display().to_string()));
    report.extend(body);
    Value::Object(report)
}

/// The summary of `--method param`: the parameterizer and opening, sizes, angles, edge
/// lengths, distance, timings and notes.
fn print_summary(
    args: &RemeshArgs,
    summary: &ParamSummary,
    report: &Report,
    q: &Quality,
    seconds: f64,
) {
    println!(
        "{} -> {} ({}, {}, {seconds:.3} s)",
        args.mesh.display(),
        args.output.display(),
        summary.parameterizer,
        summary.opening
    );
    println!("  vertices        {}", q.vertices);
    println!("  faces           {}", q.faces);
    println!(
        "  angles          min {:.2}  mean {:.2}  under 30: {:.3}%",
        q.min_angle,
        q.mean_angle,
        100.0 * q.share_below_30
    );
    println!(
        "  edges           asked {:.4e}  mean {:.4e}  min {:.4e}  max {:.4e}  spread {:.3}",
        summary.edge_length, q.edge_mean, q.edge_min, q.edge_max, q.edge_spread
    );
    println!(
        "  distance        Hausdorff {:.4e} ({:.3}% of the diagonal)  mean {:.4e}",
        q.hausdorff,
        100.0 * q.hausdorff / q.diagonal,
        q.mean_distance
    );
    for (stage, s) in &report.timings {
        println!("  {stage:<15} {s:.3} s");
    }
    for note in &report.notes {
        println!("  note: {note}");
    }
}
