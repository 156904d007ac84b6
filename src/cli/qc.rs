//! `beltrami qc`: a quasiconformal map with a prescribed Beltrami coefficient — per face
//! (`--mu FILE`, the `distortion` field format) or as an expression of `z`
//! (`--mu-expr "0.6*z"`) — or the most conformal one (`--conformal [--p P]`), by lsqc
//! (one linear solve into the plane) or beltrami-flow (onto the input's own planar
//! region, the unit disk, an annulus or the unit sphere); or, with `--solver extremal`
//! and no goal flag, the extremal map of the boundary condition (`--init`, `--qd`).
//!
//! `z` in `--mu-expr` is `x + i y` of the face centroids for planar targets (a mesh in
//! the plane z = 0), and the stereographic coordinate from the north pole,
//! `z = (x + i y) / (1 - z3)`, of the centroids for the sphere.

use std::path::PathBuf;

use anyhow::{Context as _, bail};
use beltrami::map_file;
use beltrami::problem_spec::{
    BoundaryDefault, BoundaryMap, BoundaryName, GoalSpec, ProblemSpec, TargetName,
};
use beltrami_core::{Constraint, Goal, GoalKind, Map, OptionValue, Solution, Solver, Target};
use beltrami_fem::BeltramiField;
use beltrami_mesh::Mesh;
use clap::{ArgGroup, Args, ValueEnum};
use num_complex::Complex64;
use serde_json::json;

use super::load::load_mesh;
use super::mapping;
use super::pins::PinSpec;

/// Where `--target` maps to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum TargetArg {
    /// The plane, with the boundary condition of `--boundary` (beltrami-flow keeps the
    /// input's own planar region: boundary sliding along its straight sides, corners
    /// fixed).
    Plane,
    /// The unit disk (boundary sliding on the circle).
    Disk,
    /// The annulus `r <= |z| <= 1` (the input must be such an annulus; see
    /// `--free-radius`).
    Annulus,
    /// The unit sphere (closed genus-0 meshes).
    Sphere,
    /// Points of R^3 (lsqc): the quaternionic least-squares map of the surface, its
    /// boundary held at the positions (`v`) of `--boundary-map` (`--boundary given`).
    Space,
}

/// Boundary conditions of `--boundary` (plane target).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum QcBoundaryArg {
    /// Keep the input's own boundary positions (a mesh in the plane z = 0).
    Keep,
    /// Free boundary with pins (two boundary vertices far apart by default).
    Free,
    /// The boundary of the map in `--boundary-map`.
    Given,
}

/// The `--solver` help: the registered solvers of a prescribed or extremal map into a
/// domain.
fn solver_help() -> String {
    let names = beltrami::catalog::domain_solvers(|goals| {
        goals.contains(&GoalKind::Prescribed) || goals.contains(&GoalKind::Extremal)
    });
    format!(
        "Solver name ({}; `beltrami solvers` describes them). Default: lsqc onto the plane and into space, beltrami-flow onto the disk, an annulus or the sphere",
        names.join(", ")
    )
}

#[derive(Debug, Args)]
#[command(group(ArgGroup::new("goal").args(["mu", "mu_expr", "conformal"])))]
pub struct QcArgs {
    /// Mesh file (.obj, .ply, .stl, .off, .gltf, .glb).
    pub mesh: PathBuf,
    #[arg(long, help = solver_help())]
    pub solver: Option<String>,
    /// The Beltrami coefficient per face, in the field format (`# mu frame=... faces=N`).
    #[arg(long)]
    pub mu: Option<PathBuf>,
    /// The Beltrami coefficient as an expression of z (e.g. "0.6*z", "0.3+0.3i"), at the
    /// face centroids (module docs: z on the sphere is stereographic).
    #[arg(long = "mu-expr")]
    pub mu_expr: Option<String>,
    /// The most conformal map instead: the smallest L^p norm of mu.
    #[arg(long)]
    pub conformal: bool,
    /// The exponent of `--conformal` (beltrami-flow: 2 <= p <= 100; lsqc: 2 only) [default: 2].
    #[arg(long)]
    pub p: Option<f64>,
    /// Where the map goes.
    #[arg(long, value_enum, default_value = "plane")]
    pub target: TargetArg,
    /// The boundary condition of `--target plane` [default: free for solvers that take a
    /// free boundary (lsqc), else keep].
    #[arg(long, value_enum)]
    pub boundary: Option<QcBoundaryArg>,
    /// With `--boundary given`: a mesh of the same vertices whose texture coordinates
    /// (or, without them, x and y) give the boundary positions.
    #[arg(long = "boundary-map")]
    pub boundary_map: Option<PathBuf>,
    /// Annulus target: let the inner radius move (the prescribed mu fixes the conformal
    /// modulus); by default the input's inner radius is kept.
    #[arg(long = "free-radius")]
    pub free_radius: bool,
    /// qcmc: the boundary loop mapped onto the unit circle, by its 0-based index in the
    /// mesh's boundary-loop order (the report's `loop`) [default: the longest].
    #[arg(long)]
    pub outer: Option<usize>,
    /// Pin a vertex where it is: `v12` by its 0-based index, or `x,y[,z]` for the
    /// nearest vertex; repeatable.
    #[arg(long = "pin")]
    pub pins: Vec<PinSpec>,
    /// extremal with `--target disk`: the four-point problem's landmarks, lines `p INDEX x
    /// y` (a boundary vertex, 0-based, and its point on the unit circle); the rest of the
    /// boundary slides on the circle.
    #[arg(long)]
    pub landmarks: Option<PathBuf>,
    /// extremal: the start map, `harmonic` or `tutte` with the prescribed boundary, or a
    /// mesh file whose texture coordinates (or x, y) give it (it may be folded).
    #[arg(long)]
    pub init: Option<String>,
    /// space: keep the displacement of every vertex tangent to the surface (Gruber-Aulisa
    /// 2022, section 4.1, linearized), a penalty of weight W > 0 (e.g. 1e4).
    #[arg(long = "normal-constraint", value_name = "W")]
    pub normal_constraint: Option<f64>,
    /// space: keep the surface's area to first order (Gruber-Aulisa 2022, section 4.2:
    /// the first variation of the area vanishes), one equality for the whole surface.
    #[arg(long = "area-constraint")]
    pub area_constraint: bool,
    /// extremal: write the quadratic differential phi per face here (`# qd
    /// frame=global faces=N`, then `re im` per face in the input's face order).
    #[arg(long)]
    pub qd: Option<PathBuf>,
    /// Iterative solvers: stop when the largest vertex update is below this (relative
    /// to the target's size) [default: 1e-6].
    #[arg(long)]
    pub tolerance: Option<f64>,
    /// Iterative solvers: most iterations [default: 200].
    #[arg(long = "max-iters")]
    pub max_iters: Option<usize>,
    /// Threads for the sparse factorizations [default: 1].
    #[arg(long)]
    pub threads: Option<usize>,
    /// Output mesh: .obj (the input's vertices and faces, one `vt` per vertex with its
    /// planar image, or the image positions for the sphere) or .glb/.gltf.
    #[arg(short, long)]
    pub output: PathBuf,
    #[command(flatten)]
    pub common: mapping::CommonArgs,
}

/// The goal of `--mu`, `--mu-expr` or `--conformal`; without one, the solver's
/// extremal map (a solver that computes none needs a goal flag).
fn goal_of(args: &QcArgs, mesh: &Mesh, solver: &dyn Solver) -> anyhow::Result<Option<GoalSpec>> {
    if args.mu.is_none() && args.mu_expr.is_none() && !args.conformal {
        if solver.accepts().goals.contains(&GoalKind::Extremal) {
            return Ok(None);
        }
        bail!("give the goal with --mu FILE, --mu-expr EXPR or --conformal");
    }
    if args.conformal {
        return Ok(Some(GoalSpec::Conformal { p: args.p }));
    }
    if args.p.is_some() {
        bail!("--p is the exponent of --conformal; a prescribed mu has no exponent");
    }
    Ok(Some(match (&args.mu, &args.mu_expr) {
        (Some(path), _) => GoalSpec::Mu(BeltramiField::read(path, mesh.face_count())?),
        (None, Some(text)) => GoalSpec::MuExpr(text.clone()),
        (None, None) => bail!("give the goal with --mu FILE, --mu-expr EXPR or --conformal"),
    }))
}

/// The planar map of the file `path` given to `flag` (`--boundary-map` or `--init`),
/// named in errors ([`beltrami::mapped::read_planar`]).
fn planar_map_file(
    flag: &str,
    path: &std::path::Path,
    mesh: &Mesh,
) -> anyhow::Result<Vec<Complex64>> {
    beltrami::mapped::read_planar(path, mesh, false)
        .with_context(|| format!("{flag} {}", path.display()))
}

/// The problem's words from the flags, before any mesh is read: the target, boundary,
/// radius, normal and area constraints and the solver's name.
fn spec_of(args: &QcArgs) -> ProblemSpec {
    let mut spec = ProblemSpec::new(match args.target {
        TargetArg::Plane => TargetName::Plane,
        TargetArg::Disk => TargetName::Disk,
        TargetArg::Annulus => TargetName::Annulus,
        TargetArg::Sphere => TargetName::Sphere,
        TargetArg::Space => TargetName::Space,
    });
    spec.solver = args.solver.clone();
    spec.boundary = args.boundary.map(|b| match b {
        QcBoundaryArg::Keep => BoundaryName::Keep,
        QcBoundaryArg::Free => BoundaryName::Free,
        QcBoundaryArg::Given => BoundaryName::Given,
    });
    spec.boundary_default = BoundaryDefault::FreeOrKeep;
    spec.free_radius = args.free_radius;
    spec.normal_constraint = args.normal_constraint;
    spec.area_constraint = args.area_constraint;
    spec
}

/// Refuses, before any work, `--qd` off the extremal solver; the flags that the others
/// make meaningless are refused by [`ProblemSpec::check_words`] once their files are
/// read.
fn check_qd(args: &QcArgs, spec: &ProblemSpec) -> anyhow::Result<()> {
    let name = spec.solver_name();
    if args.qd.is_some() && name != "extremal" {
        bail!("--qd writes the quadratic differential of --solver extremal; {name} computes none");
    }
    Ok(())
}

pub fn run(args: &QcArgs, quiet: bool) -> anyhow::Result<()> {
    mapping::check_outputs(&args.output, &args.common, &[("--qd", args.qd.as_deref())])?;
    let mut spec = spec_of(args);
    check_qd(args, &spec)?;
    let registry = beltrami::registry();
    let solver = registry.get(spec.solver_name())?;
    let loaded = load_mesh(&args.mesh, args.common.repair, quiet || args.common.json)?;
    let mesh = &loaded.mesh.mesh;
    spec.goal = goal_of(args, mesh, solver)?;
    spec.boundary_map = boundary_map_of(args, mesh)?;
    spec.initial = initial_of(args, mesh)?;
    add_constraints(args, mesh, &mut spec)?;
    set_options(args, &mut spec);
    let problem = spec.problem(mesh, None, solver)?;
    mapping::check_output_holds_map(&args.output, &problem.target)?;

    let (solution, seconds, sections) = mapping::solve_formatting_output(
        solver,
        &problem,
        args.common.progress(quiet),
        &args.output,
    )?;
    if let (Some(Map::Spatial(_)), false) = (
        solution.map(),
        matches!(problem.target, Target::Sphere | Target::Surface),
    ) {
        bail!("{} gave points in space for a planar target", solver.name());
    }
    map_file::write(
        &args.output,
        mesh,
        &solution,
        None,
        sections.as_ref(),
        &loaded.mesh.obj_groups,
    )?;
    if let Some(path) = &args.qd {
        write_quadratic_differential(path, mesh, &solution)?;
    }
    mapping::write_png(args.common.png.as_deref(), mesh, &solution, None)?;

    let (report, extra) = report_and_summary(args, mesh, &problem.goal, &solution, seconds);
    mapping::finish(
        report,
        args.common.report.as_deref(),
        args.common.json,
        quiet,
        (&args.mesh, &args.output, &solution, seconds),
        &extra,
    )
}

/// The map of `--boundary-map`: planar for the plane's `given` boundary, points of R^3
/// into space.
fn boundary_map_of(args: &QcArgs, mesh: &Mesh) -> anyhow::Result<Option<BoundaryMap>> {
    let Some(path) = &args.boundary_map else {
        return Ok(None);
    };
    Ok(Some(if args.target == TargetArg::Space {
        BoundaryMap::Spatial(
            beltrami::mapped::read_spatial(path, mesh, false)
                .with_context(|| format!("--boundary-map {}", path.display()))?,
        )
    } else {
        BoundaryMap::Planar(planar_map_file("--boundary-map", path, mesh)?)
    }))
}

/// The start map of `--init` read from a file (a name, `harmonic` or `tutte`, is the
/// solver's `init` option instead).
fn initial_of(args: &QcArgs, mesh: &Mesh) -> anyhow::Result<Option<Vec<Complex64>>> {
    match args.init.as_deref() {
        None | Some("harmonic" | "tutte") => Ok(None),
        Some(path) => Ok(Some(planar_map_file(
            "--init",
            std::path::Path::new(path),
            mesh,
        )?)),
    }
}

/// The constraints of `--pin` and `--landmarks`.
fn add_constraints(args: &QcArgs, mesh: &Mesh, spec: &mut ProblemSpec) -> anyhow::Result<()> {
    spec.constraints.extend(
        mapping::resolve_pins(&args.pins, mesh)?
            .into_iter()
            .map(Constraint::Pin),
    );
    if let Some(path) = &args.landmarks {
        spec.constraints.extend(
            beltrami::landmarks::read_planar(path, mesh)?
                .into_iter()
                .map(Constraint::Landmark),
        );
    }
    Ok(())
}

/// The solver's options from the command's flags (`--init` naming a start the solver
/// computes) with the command's defaults, and `--option`.
fn set_options(args: &QcArgs, spec: &mut ProblemSpec) {
    let init = args
        .init
        .as_deref()
        .filter(|name| matches!(*name, "harmonic" | "tutte"));
    spec.defaults = vec![
        ("tolerance".into(), OptionValue::Float(1e-6)),
        ("max-iters".into(), OptionValue::Int(200)),
    ];
    let given = [
        ("tolerance", args.tolerance.map(OptionValue::Float)),
        ("max-iters", args.max_iters.map(OptionValue::Int)),
        ("threads", args.threads.map(OptionValue::Int)),
        ("outer", args.outer.map(|l| OptionValue::Int(l + 1))),
        ("init", init.map(|s| OptionValue::Choice(s.into()))),
    ];
    for (name, value) in given {
        if let Some(value) = value {
            spec.options.set(name, value);
        }
    }
    for (name, value) in &args.common.options {
        spec.options.set_text(name, value);
    }
}

/// The JSON report of a run and the summary's lines after the common ones: the target
/// and goal, the circles of a circle domain, `k`, the error against a prescribed `mu`
/// and the iterations.
fn report_and_summary(
    args: &QcArgs,
    mesh: &Mesh,
    goal: &Goal,
    solution: &Solution,
    seconds: f64,
) -> (serde_json::Map<String, serde_json::Value>, Vec<String>) {
    let error = solution.metrics.mu_error;
    let mut report = mapping::report_json(&args.mesh, &args.output, solution, seconds);
    report.insert(
        "target".into(),
        json!(format!("{:?}", args.target).to_lowercase()),
    );
    report.insert(
        "goal".into(),
        json!(match goal {
            Goal::Conformal { p } => format!("conformal L^{p}"),
            Goal::Prescribed(_) => "prescribed mu".into(),
            Goal::Extremal => "extremal".into(),
            Goal::Features(_) => "features".into(),
        }),
    );
    report.extend(beltrami::report::mu_error_keys(error.as_ref()));
    let mut extra = circles(mesh, solution, &mut report);
    extra.extend(
        solution
            .metrics
            .k
            .map(|k| format!("k               {k:.6}")),
    );
    extra.extend(error.iter().map(|e| {
        format!(
            "|mu - target|   L2 (RMS) {:.4e}  sup {:.4e} (face {})",
            e.rms, e.sup, e.sup_face
        )
    }));
    if solution.metrics.iterations > 0 {
        extra.push(format!(
            "iterations      {} (error {:.4e} -> {:.4e})",
            solution.metrics.iterations,
            solution
                .metrics
                .energy_history
                .first()
                .copied()
                .unwrap_or(0.0),
            solution
                .metrics
                .energy_history
                .last()
                .copied()
                .unwrap_or(0.0)
        ));
    }
    (report, extra)
}

/// The circles of a circle-domain map (`extras.circles`): the report's `circles`
/// ([`beltrami::report::circles`]) and a summary line per circle.
pub(super) fn circles(
    mesh: &Mesh,
    solution: &beltrami_core::Solution,
    report: &mut serde_json::Map<String, serde_json::Value>,
) -> Vec<String> {
    let fits = beltrami::report::circle_fits(mesh, solution);
    if fits.is_empty() {
        return Vec::new();
    }
    report.insert("circles".into(), beltrami::report::circles(&fits));
    fits.iter()
        .map(|f| {
            let c = &f.circle;
            format!(
                "loop {:<3} circle centre ({:+.6}, {:+.6})  radius {:.6}  deviation {:.1e}",
                c.boundary_loop, c.center.re, c.center.im, c.radius, f.deviation
            )
        })
        .collect()
}

/// Writes `--qd`: the solution's quadratic differential, one face per line in the
/// input's face order, atomically.
fn write_quadratic_differential(
    path: &std::path::Path,
    mesh: &Mesh,
    solution: &beltrami_core::Solution,
) -> anyhow::Result<()> {
    let Some(qd) = &solution.extras.quadratic_differential else {
        bail!(
            "--qd: {} computes no quadratic differential",
            solution.report.solver
        );
    };
    let faces = mesh
        .faces()
        .map(|f| mesh.face_to_input(f) + 1)
        .max()
        .unwrap_or(0);
    let mut by_input = vec![Complex64::new(0.0, 0.0); faces];
    for (f, &phi) in mesh.faces().zip(&qd.values) {
        by_input[mesh.face_to_input(f)] = phi;
    }
    beltrami_mesh::io::write_atomically(path, |w| {
        use std::io::Write as _;
        writeln!(w, "# qd frame={} faces={}", qd.frame.name(), by_input.len())?;
        for phi in &by_input {
            writeln!(w, "{} {}", phi.re, phi.im)?;
        }
        Ok(())
    })
    .with_context(|| format!("cannot write --qd {}", path.display()))
}
