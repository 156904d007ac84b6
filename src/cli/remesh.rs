//! `beltrami remesh`: a new triangle mesh of a surface with the asked edge length, made
//! through a parameterization (see the `beltrami-remesh` crate and docs/remesh.md).

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context as _, bail};
use beltrami_core::Context;
use beltrami_mesh::Mesh;
use beltrami_mesh::io::{self, VertexAttributes};
use beltrami_remesh::components::{Coverage, remesh_covering};
use beltrami_remesh::in_place::{InPlaceOptions, Keep, remesh_in_place};
use beltrami_remesh::reference_angles::Reference;
use beltrami_remesh::{Quality, RemeshError, RemeshOptions, Resolution, SizeField, Summary};
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

impl RemeshArgs {
    fn options(&self) -> RemeshOptions {
        RemeshOptions {
            resolution: match (self.edge_length, self.vertices) {
                (Some(l), _) => Resolution::EdgeLength(l),
                (None, Some(n)) => Resolution::Vertices(n),
                (None, None) => Resolution::EdgeLength(f64::NAN),
            },
            min_angle: self.min_angle,
            size_field: match self.size_field {
                SizeFieldArg::Uniform => SizeField::Uniform,
                SizeFieldArg::Curvature => SizeField::Curvature,
            },
            max_vertices: self.max_vertices,
            feature_tolerance: self.feature_tolerance,
        }
    }
}

pub fn run(args: &RemeshArgs, quiet: bool) -> anyhow::Result<()> {
    check_output_format(&args.output)?;
    super::outputs::check(&[
        ("-o", Some(&args.output)),
        ("--png", args.png.as_deref()),
        ("--report", args.report.as_deref()),
    ])?;
    check_method_flags(args)?;
    match args.method {
        MethodArg::Param if args.edge_length.is_none() && args.vertices.is_none() => {
            bail!(
                "--method param makes a new mesh: give its size with --edge-length L or --vertices N"
            )
        }
        MethodArg::QcAngles if args.edge_length.is_some() || args.vertices.is_some() => {
            bail!(
                "--method qc-angles keeps the input's vertices and faces: drop --edge-length and --vertices"
            )
        }
        MethodArg::QcAngles => return run_in_place(args, quiet),
        MethodArg::Param => {}
    }
    let options = args.options();
    options.validate()?;
    let registry = beltrami::registry();
    let loaded = load_mesh(&args.mesh, args.repair, quiet || args.json)?;
    let whole = &loaded.mesh.mesh;
    let start = Instant::now();
    let mut context = Context::new().with_cancel_flag(super::interrupt::cancel_flag());
    let choose = |part: &Mesh| beltrami_remesh::param::chosen(&registry, part, &args.param);
    let coverage = match args.components {
        None => Coverage::Whole,
        Some(ComponentsArg::Each) => Coverage::Each,
        Some(ComponentsArg::Largest) => Coverage::Largest,
    };
    let covered = remesh_covering(whole, coverage, choose, &options, &mut context)
        .map_err(with_hint)
        .with_context(|| format!("cannot remesh {}", args.mesh.display()))?;
    let (out, mesh, summary) = (&covered.mesh, covered.input(whole), &covered.summary);
    let seconds = start.elapsed().as_secs_f64();
    io::write(&args.output, out, &VertexAttributes::default())?;
    let quality = beltrami_remesh::quality::measure(mesh, out)?;
    write_png(args.png.as_deref(), out)?;
    let mut report = report_json(args, mesh, summary, &quality, seconds);
    if let (false, Value::Object(map)) = (covered.components.is_empty(), &mut report) {
        map.insert(
            "components".into(),
            beltrami::report::remesh_components(&covered.components),
        );
    }
    finish(args, &report, quiet, || {
        print_summary(args, summary, &quality, seconds)
    })
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

/// Refuses, before any work, the flags of the other method (they would be ignored
/// silently): a flag counts as given when its value differs from its default.
fn check_method_flags(args: &RemeshArgs) -> anyhow::Result<()> {
    let given = |set: bool, flag: &'static str| set.then_some(flag);
    let (flags, method, other) = match args.method {
        MethodArg::QcAngles => (
            [
                given(args.param != "auto", "--param"),
                given(args.components.is_some(), "--components"),
                given(args.min_angle != 30.0, "--min-angle"),
                given(args.size_field != SizeFieldArg::Uniform, "--size-field"),
                given(args.max_vertices != 5_000_000, "--max-vertices"),
                given(
                    args.feature_tolerance != beltrami_remesh::FEATURE_TOLERANCE,
                    "--feature-tolerance",
                ),
            ]
            .into_iter()
            .flatten()
            .collect::<Vec<_>>(),
            "qc-angles",
            "param",
        ),
        MethodArg::Param => (
            [
                given(args.reference != ReferenceArg::Optimized, "--reference"),
                given(args.constraint != KeepArg::Normal, "--constraint"),
                given(args.max_iters != 10, "--max-iters"),
                given(args.tolerance != 1e-4, "--tolerance"),
                given(args.feature_angle != 60.0, "--feature-angle"),
                given(args.no_project, "--no-project"),
                given(args.allow_flips, "--allow-flips"),
            ]
            .into_iter()
            .flatten()
            .collect(),
            "param",
            "qc-angles",
        ),
    };
    if let Some(flag) = flags.first() {
        bail!("{flag} is a flag of --method {other}; --method {method} does not read it");
    }
    Ok(())
}

/// `--method qc-angles` ([`beltrami_remesh::in_place`]).
fn run_in_place(args: &RemeshArgs, quiet: bool) -> anyhow::Result<()> {
    if !(args.feature_angle > 0.0 && args.feature_angle <= 180.0) {
        bail!(
            "--feature-angle {}: give an angle in (0, 180] degrees",
            args.feature_angle
        );
    }
    if !(args.tolerance.is_finite() && args.tolerance > 0.0) {
        bail!("--tolerance {}: give a positive number", args.tolerance);
    }
    let registry = beltrami::registry();
    let solver = registry.get("qc-iteration")?;
    let loaded = load_mesh(&args.mesh, args.repair, quiet || args.json)?;
    let mesh = &loaded.mesh.mesh;
    let options = InPlaceOptions {
        reference: match args.reference {
            ReferenceArg::Optimized => Reference::Optimized,
            ReferenceArg::Equiangular => Reference::Equiangular,
        },
        keep: match args.constraint {
            KeepArg::Normal => Keep::Normal,
            KeepArg::Area => Keep::Area,
        },
        max_iters: args.max_iters,
        tolerance: args.tolerance,
        project: !args.no_project,
        feature_angle: args.feature_angle,
        allow_flips: args.allow_flips,
    };
    let start = Instant::now();
    let mut bar = LateBar::new(!(quiet || args.json));
    let result = {
        let mut context = Context::new()
            .with_progress(|p: &beltrami_core::Progress| bar.update(p))
            .with_cancel_flag(super::interrupt::cancel_flag());
        remesh_in_place(mesh, solver, &options, &mut context)
    };
    bar.finish();
    let result = result.with_context(|| format!("cannot remesh {}", args.mesh.display()))?;
    let seconds = start.elapsed().as_secs_f64();
    io::write(&args.output, &result.mesh, &VertexAttributes::default())?;
    let before = beltrami_remesh::quality::shape(mesh);
    let after = beltrami_remesh::quality::measure(mesh, &result.mesh)?;
    write_png(args.png.as_deref(), &result.mesh)?;
    let mut report = serde_json::Map::new();
    report.insert("mesh".into(), json!(args.mesh.display().to_string()));
    report.insert("output".into(), json!(args.output.display().to_string()));
    report.extend(beltrami::report::remesh_in_place(
        mesh, &result, &options, &before, &after, seconds,
    ));
    finish(args, &Value::Object(report), quiet, || {
        println!(
            "{} -> {} (qc-angles, {} reference, {} constraint, {seconds:.3} s)",
            args.mesh.display(),
            args.output.display(),
            options.reference.name(),
            options.keep.name()
        );
        println!(
            "  vertices        {}  faces {}",
            mesh.vertex_count(),
            mesh.face_count()
        );
        for (name, q) in [("before", &before), ("after", &after)] {
            println!(
                "  angles {name:<8} min {:.2}  mean {:.2}  under 30: {:.3}%",
                q.min_angle,
                q.mean_angle,
                100.0 * q.share_below_30
            );
        }
        println!(
            "  distance        Hausdorff {:.4e} ({:.3}% of the diagonal)  mean {:.4e}",
            after.hausdorff,
            100.0 * after.hausdorff / after.diagonal,
            after.mean_distance
        );
        let m = &result.solution.metrics;
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
            result.flipped, result.input_flipped, result.pulled
        );
        println!("  held features   {} vertices", result.features);
        for note in &result.solution.report.notes {
            println!("  note: {note}");
        }
    })
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

/// The JSON report: the input and output files and [`beltrami::report::remesh`].
fn report_json(
    args: &RemeshArgs,
    input: &beltrami_mesh::Mesh,
    result: &Summary,
    q: &Quality,
    seconds: f64,
) -> Value {
    let mut report = serde_json::Map::new();
    report.insert("mesh".into(), json!(args.mesh.display().to_string()));
    report.insert("output".into(), json!(args.output.display().to_string()));
    report.extend(beltrami::report::remesh(input, result, q, seconds));
    Value::Object(report)
}

fn print_summary(args: &RemeshArgs, result: &Summary, q: &Quality, seconds: f64) {
    println!(
        "{} -> {} ({}, {}, {seconds:.3} s)",
        args.mesh.display(),
        args.output.display(),
        result.parameterizer,
        result.opening
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
        result.edge_length, q.edge_mean, q.edge_min, q.edge_max, q.edge_spread
    );
    println!(
        "  distance        Hausdorff {:.4e} ({:.3}% of the diagonal)  mean {:.4e}",
        q.hausdorff,
        100.0 * q.hausdorff / q.diagonal,
        q.mean_distance
    );
    for (stage, s) in &result.timings {
        println!("  {stage:<15} {s:.3} s");
    }
    for note in &result.notes {
        println!("  note: {note}");
    }
}
