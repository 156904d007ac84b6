//! `beltrami qc`: a quasiconformal map with a prescribed Beltrami coefficient, given
//! per face (`--mu FILE`, the `distortion` field format) or as an expression of
//! `z = x + i y` evaluated at the face centroids (`--mu-expr "0.6*z"`, global frame).

use std::path::PathBuf;

use anyhow::{Context as _, bail};
use beltrami_core::{Goal, Map, PlanarBoundary, Problem, Target};
use beltrami_fem::{BeltramiField, Elements};
use beltrami_lsqc::{Expr, MuError};
use beltrami_mesh::Mesh;
use clap::{ArgGroup, Args, ValueEnum};
use serde_json::json;

use super::load::load_mesh;
use super::mapping;
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
    /// Also draw the result (source and image side by side, |mu| colors) as PNG.
    #[arg(long, value_parser = mapping::png_path)]
    pub png: Option<PathBuf>,
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
    mapping::check_output_format(&args.output)?;
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
    problem.constraints.pins = mapping::resolve_pins(&args.pins, mesh)?;

    let (solution, seconds) = mapping::solve(solver, &problem, !quiet && !args.json)?;
    let error = match &solution.report.mu {
        Some(measured) if measured.frame == field.frame => {
            let elements = Elements::new(mesh, field.frame)?;
            Some(MuError::new(&elements, &measured.mu, &field.mu)?)
        }
        _ => None,
    };
    if !matches!(solution.map, Map::Planar(_)) {
        bail!("this command writes planar maps only");
    }
    mapping::write_map(&args.output, mesh, &solution)?;
    mapping::write_png(args.png.as_deref(), mesh, &solution)?;

    let mut report = mapping::report_json(&args.mesh, &args.output, &solution, seconds);
    report.insert("mu_error_l2".into(), json!(error.as_ref().map(|e| e.rms)));
    report.insert(
        "mu_error_l2_squared".into(),
        json!(error.as_ref().map(|e| e.l2_squared)),
    );
    report.insert("mu_error_sup".into(), json!(error.as_ref().map(|e| e.sup)));
    report.insert(
        "mu_error_sup_face".into(),
        json!(error.as_ref().map(|e| e.sup_face.idx())),
    );
    let extra: Vec<String> = error
        .iter()
        .map(|e| {
            format!(
                "|mu - target|   L2 (RMS) {:.4e}  sup {:.4e} (face {})",
                e.rms, e.sup, e.sup_face
            )
        })
        .collect();
    mapping::finish(
        report,
        args.report.as_deref(),
        args.json,
        quiet,
        (&args.mesh, &args.output, &solution, seconds),
        &extra,
    )
}
