//! `beltrami qc`: a quasiconformal map with a prescribed Beltrami coefficient, given
//! per face (`--mu FILE`, the `distortion` field format) or as an expression of
//! `z = x + i y` evaluated at the face centroids (`--mu-expr "0.6*z"`, global frame).

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context as _, bail};
use beltrami_core::{Context, Goal, Map, Pin, PlanarBoundary, Problem, Solution, Target};
use beltrami_fem::{BeltramiField, Elements};
use beltrami_lsqc::{Expr, MuError};
use beltrami_mesh::io::{self, Format, VertexAttributes};
use beltrami_mesh::{Mesh, Vector2};
use clap::{ArgGroup, Args, ValueEnum};
use serde_json::json;

use super::load::load_mesh;
use super::pins::PinSpec;

/// Boundary conditions of `--boundary`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum QcBoundaryArg {
    /// Keep the input's own boundary positions (a mesh in the plane z = 0).
    Keep,
    /// Free boundary with pins (two boundary vertices far apart by default).
    Free,
}

#[derive(Debug, Args)]
#[command(group(ArgGroup::new("coefficient").required(true).args(["mu", "mu_expr"])))]
pub struct QcArgs {
    /// Mesh file (.obj, .gltf, .glb).
    pub mesh: PathBuf,
    /// Solver name: lsqc.
    #[arg(long, default_value = "lsqc")]
    pub solver: String,
    /// The Beltrami coefficient per face, in the field format (`# mu frame=... faces=N`).
    #[arg(long)]
    pub mu: Option<PathBuf>,
    /// The Beltrami coefficient as an expression of z (e.g. "0.6*z", "0.3+0.3i"),
    /// evaluated at the face centroids of a mesh in the plane z = 0.
    #[arg(long = "mu-expr")]
    pub mu_expr: Option<String>,
    /// Boundary condition.
    #[arg(long, value_enum, default_value = "free")]
    pub boundary: QcBoundaryArg,
    /// Pin a vertex where it is: `v12` by its 0-based index, or `x,y[,z]` for the
    /// nearest vertex; repeatable.
    #[arg(long = "pin")]
    pub pins: Vec<PinSpec>,
    /// Output mesh: .obj (the input's vertices and faces, one `vt` per vertex with its
    /// image) or .glb/.gltf.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Write the JSON report here.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Print the JSON report on stdout instead of the summary.
    #[arg(long)]
    pub json: bool,
    /// Repair what can be repaired safely in the input (see `beltrami info --repair`).
    #[arg(long)]
    pub repair: bool,
}

/// The prescribed field from `--mu` or `--mu-expr`.
fn field_of(args: &QcArgs, mesh: &Mesh) -> anyhow::Result<BeltramiField> {
    if let Some(path) = &args.mu {
        return Ok(BeltramiField::read(path, mesh.face_count())?);
    }
    let Some(text) = &args.mu_expr else {
        bail!("give the Beltrami coefficient with --mu FILE or --mu-expr EXPR");
    };
    let expr = Expr::parse(text).with_context(|| format!("--mu-expr `{text}`"))?;
    expr.field(mesh).with_context(|| {
        "--mu-expr evaluates mu at z = x + i y and needs a mesh in the plane z = 0; give a per-face field with --mu"
    })
}

pub fn run(args: &QcArgs, quiet: bool) -> anyhow::Result<()> {
    if Format::from_path(&args.output).is_none() {
        bail!(
            "{}: unknown output format (expected .obj, .gltf or .glb)",
            args.output.display()
        );
    }
    let registry = beltrami::registry();
    let solver = registry.get(&args.solver)?;
    let loaded = load_mesh(&args.mesh, args.repair, quiet || args.json)?;
    let mesh = &loaded.mesh.mesh;
    let field = field_of(args, mesh)?;

    let boundary = match args.boundary {
        QcBoundaryArg::Keep => PlanarBoundary::Keep,
        QcBoundaryArg::Free => PlanarBoundary::Free,
    };
    let mut problem = Problem::new(mesh, Target::Plane(boundary));
    problem.goal = Goal::Prescribed(field.clone());
    for spec in &args.pins {
        problem.constraints.pins.push(Pin {
            vertex: spec.resolve(mesh)?,
            position: None,
        });
    }
    solver.check(&problem)?;

    let start = Instant::now();
    let solution = solver.solve(&problem, &mut Context::new())?;
    let seconds = start.elapsed().as_secs_f64();
    let error = match &solution.report.mu {
        Some(measured) if measured.frame == field.frame => {
            let elements = Elements::new(mesh, field.frame)?;
            Some(MuError::new(&elements, &measured.mu, &field.mu)?)
        }
        _ => None,
    };

    let Map::Planar(z) = &solution.map else {
        bail!("this command writes planar maps only");
    };
    let uv: Vec<Vector2<f64>> = z.iter().map(|z| Vector2::new(z.re, z.im)).collect();
    io::write(
        &args.output,
        mesh,
        &VertexAttributes {
            uvs: Some(&uv),
            ..Default::default()
        },
    )?;

    let report = report_json(args, &solution, error.as_ref(), seconds);
    if let Some(path) = &args.report {
        let text = serde_json::to_string_pretty(&report)?;
        io::write_atomically(path, |w| std::io::Write::write_all(w, text.as_bytes()))
            .with_context(|| format!("cannot write the report {}", path.display()))?;
    }
    if args.json {
        println!("{report}");
    } else if !quiet {
        print_summary(args, &solution, error.as_ref(), seconds);
    }
    Ok(())
}

fn report_json(
    args: &QcArgs,
    solution: &Solution,
    error: Option<&MuError>,
    seconds: f64,
) -> serde_json::Value {
    let r = &solution.report;
    let d = r.distortion.as_ref();
    json!({
        "solver": r.solver,
        "mesh": args.mesh.display().to_string(),
        "output": args.output.display().to_string(),
        "seconds": seconds,
        "iterations": r.iterations,
        "flipped": d.map(|d| d.flipped),
        "mu_mean": d.map(|d| d.mu_mean),
        "mu_max": d.map(|d| d.mu_max),
        "mu_error_l2": error.map(|e| e.rms),
        "mu_error_l2_squared": error.map(|e| e.l2_squared),
        "mu_error_sup": error.map(|e| e.sup),
        "mu_error_sup_face": error.map(|e| e.sup_face.idx()),
        "energy_history": r.energy_history,
        "timings": r.timings.iter().map(|(k, v)| json!({"stage": k, "seconds": v})).collect::<Vec<_>>(),
        "notes": r.notes,
    })
}

fn print_summary(args: &QcArgs, solution: &Solution, error: Option<&MuError>, seconds: f64) {
    let r = &solution.report;
    println!(
        "{} -> {} ({}, {seconds:.3} s)",
        args.mesh.display(),
        args.output.display(),
        r.solver
    );
    if let Some(d) = &r.distortion {
        println!("  flipped faces   {}", d.flipped);
    }
    if let Some(e) = error {
        println!(
            "  |mu - target|   L2 (RMS) {:.4e}  sup {:.4e} (face {})",
            e.rms, e.sup, e.sup_face
        );
    }
    for (stage, s) in &r.timings {
        println!("  {stage:<15} {s:.3} s");
    }
    for note in &r.notes {
        println!("  note: {note}");
    }
}
