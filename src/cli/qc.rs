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
use beltrami_core::{
    Constraint, Goal, GoalKind, Map, OptionValue, Options, PlanarBoundary, Position, Problem,
    Solution, Solver, Target, TargetKind,
};
use beltrami_fem::{BeltramiField, Expr};
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

/// The goal of `--mu`, `--mu-expr` or `--conformal`; without one, the extremal map for
/// a solver that computes extremal maps.
fn goal_of(args: &QcArgs, mesh: &Mesh, solver: &dyn Solver) -> anyhow::Result<Goal> {
    if args.mu.is_none() && args.mu_expr.is_none() && !args.conformal {
        if solver.accepts().goals.contains(&GoalKind::Extremal) {
            return Ok(Goal::Extremal);
        }
        bail!("give the goal with --mu FILE, --mu-expr EXPR or --conformal");
    }
    if args.conformal {
        return Ok(Goal::Conformal {
            p: args.p.unwrap_or(2.0),
        });
    }
    if args.p.is_some() {
        bail!("--p is the exponent of --conformal; a prescribed mu has no exponent");
    }
    let field = if let Some(path) = &args.mu {
        BeltramiField::read(path, mesh.face_count())?
    } else {
        let Some(text) = &args.mu_expr else {
            bail!("give the goal with --mu FILE, --mu-expr EXPR or --conformal");
        };
        let expr = Expr::parse(text).with_context(|| format!("--mu-expr `{text}`"))?;
        if args.target == TargetArg::Sphere {
            beltrami_flow::stereographic::field(mesh, |z| expr.eval(z))
                .with_context(|| format!("--mu-expr `{text}` on the sphere"))?
        } else {
            expr.field(mesh).with_context(|| {
                "--mu-expr evaluates mu at z = x + i y and needs a mesh in the plane z = 0; give a per-face field with --mu"
            })?
        }
    };
    Ok(Goal::Prescribed(field))
}

/// The planar map of `--boundary-map` ([`beltrami::mapped::read_planar`]).
/// The planar map of the file `path` given to `flag` (`--boundary-map` or `--init`),
/// named in errors.
fn planar_map_file(
    flag: &str,
    path: &std::path::Path,
    mesh: &Mesh,
) -> anyhow::Result<Vec<Complex64>> {
    beltrami::mapped::read_planar(path, mesh, false)
        .with_context(|| format!("{flag} {}", path.display()))
}

/// The target of `--target` (and `--boundary`, `--free-radius`). `--target plane` is
/// the plane with the boundary condition of `--boundary` for every solver (a solver that
/// cannot take it refuses it in its check); without `--boundary`, a free boundary when
/// the solver takes one, else the input's own.
fn target_of(args: &QcArgs, mesh: &Mesh, solver: &dyn Solver) -> anyhow::Result<Target<'static>> {
    if args.target == TargetArg::Plane && solver.accepts().targets == [TargetKind::CircleDomain] {
        return Ok(Target::CircleDomain);
    }
    Ok(match args.target {
        TargetArg::Plane => {
            let free = solver.accepts().targets.contains(&TargetKind::PlaneFree);
            let default = if free {
                QcBoundaryArg::Free
            } else {
                QcBoundaryArg::Keep
            };
            Target::Plane(match args.boundary.unwrap_or(default) {
                QcBoundaryArg::Keep => PlanarBoundary::Keep,
                QcBoundaryArg::Free => PlanarBoundary::Free,
                QcBoundaryArg::Given => {
                    let Some(path) = &args.boundary_map else {
                        bail!("--boundary given needs --boundary-map FILE");
                    };
                    PlanarBoundary::Given(planar_map_file("--boundary-map", path, mesh)?)
                }
            })
        }
        TargetArg::Disk => Target::Disk,
        TargetArg::Annulus => Target::Annulus {
            inner_radius: if args.free_radius {
                None
            } else {
                beltrami_flow_engine::annulus_inner_radius(mesh)
            },
        },
        TargetArg::Sphere => Target::Sphere,
        TargetArg::Space => Target::Surface,
    })
}

/// The solver of `--solver`, or the one that maps onto `--target`: lsqc onto the plane
/// (one linear solve), beltrami-flow onto the disk, an annulus or the sphere (lsqc maps
/// into the plane only).
fn solver_name(args: &QcArgs) -> &str {
    match (&args.solver, args.target) {
        (Some(name), _) => name,
        (None, TargetArg::Plane) => "lsqc",
        (None, TargetArg::Disk | TargetArg::Annulus | TargetArg::Sphere) => "beltrami-flow",
        (None, TargetArg::Space) => "lsqc",
    }
}

/// Refuses, before any work, flags that the other flags make meaningless (they would be
/// ignored silently): `--boundary` and `--boundary-map` off the plane target,
/// `--boundary-map` without `--boundary given`, `--qd` off the extremal solver,
/// `--free-radius` off the annulus target.
fn check_flag_use(args: &QcArgs) -> anyhow::Result<()> {
    let target = format!("{:?}", args.target).to_lowercase();
    if args.boundary.is_some() && !matches!(args.target, TargetArg::Plane | TargetArg::Space) {
        bail!(
            "--boundary is the boundary condition of --target plane and space; --target {target} has its own"
        );
    }
    if let Some(w) = args.normal_constraint {
        if args.target != TargetArg::Space {
            bail!(
                "--normal-constraint keeps a map into space near the surface: it needs --target space"
            );
        }
        if !(w.is_finite() && w > 0.0) {
            bail!("--normal-constraint {w}: the weight must be a positive number");
        }
    }
    if args.area_constraint && args.target != TargetArg::Space {
        bail!("--area-constraint keeps the area of a map into space: it needs --target space");
    }
    if args.target == TargetArg::Space
        && args.boundary != Some(QcBoundaryArg::Given)
        && args.pins.is_empty()
    {
        bail!(
            "--target space holds vertices where they go: the boundary at the positions of a map (add --boundary given --boundary-map MAP), or vertices where they are (--pin)"
        );
    }
    if args.boundary_map.is_some() && args.boundary != Some(QcBoundaryArg::Given) {
        bail!(
            "--boundary-map gives the boundary of --boundary given; add that or drop --boundary-map"
        );
    }
    if args.qd.is_some() && solver_name(args) != "extremal" {
        bail!(
            "--qd writes the quadratic differential of --solver extremal; {} computes none",
            solver_name(args)
        );
    }
    if args.landmarks.is_some() && args.target != TargetArg::Disk {
        bail!(
            "--landmarks moves boundary points of --target disk (the four-point problem); --target {target} holds its boundary otherwise"
        );
    }
    if args.free_radius && args.target != TargetArg::Annulus {
        bail!(
            "--free-radius lets the inner radius of --target annulus move; --target {target} has none"
        );
    }
    Ok(())
}

pub fn run(args: &QcArgs, quiet: bool) -> anyhow::Result<()> {
    mapping::check_outputs(&args.output, &args.common, &[("--qd", args.qd.as_deref())])?;
    check_flag_use(args)?;
    let registry = beltrami::registry();
    let solver = registry.get(solver_name(args))?;
    let loaded = load_mesh(&args.mesh, args.common.repair, quiet || args.common.json)?;
    let mesh = &loaded.mesh.mesh;
    let goal = goal_of(args, mesh, solver)?;

    let target = target_of(args, mesh, solver)?;
    mapping::check_output_holds_map(&args.output, &target)?;
    let mut problem = Problem::new(mesh, target);
    problem.goal = goal;
    let init = initial_of(args, mesh, &mut problem)?;
    add_constraints(args, mesh, &mut problem)?;
    problem.options = options_of(args, solver, init);

    let (solution, seconds, sections) = mapping::solve_formatting_output(
        solver,
        &problem,
        args.common.progress(quiet),
        &args.output,
    )?;
    if let (Some(Map::Spatial(_)), false) = (
        solution.map(),
        matches!(args.target, TargetArg::Sphere | TargetArg::Space),
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

/// The start of an iterative solver from `--init`: the name of a start the solver
/// computes (`harmonic`, `tutte`), or a map read from a file into `problem.initial`.
fn initial_of<'a>(
    args: &'a QcArgs,
    mesh: &Mesh,
    problem: &mut Problem<'_>,
) -> anyhow::Result<Option<&'a str>> {
    Ok(match args.init.as_deref() {
        None => None,
        Some(name @ ("harmonic" | "tutte")) => Some(name),
        Some(path) => {
            let path = std::path::Path::new(path);
            problem.initial = Some(Map::Planar(planar_map_file("--init", path, mesh)?));
            None
        }
    })
}

/// The constraints of the command line: `--pin`, `--normal-constraint`,
/// `--area-constraint`, `--landmarks` and, into space, the boundary of
/// `--boundary-map` held.
fn add_constraints(args: &QcArgs, mesh: &Mesh, problem: &mut Problem<'_>) -> anyhow::Result<()> {
    // Into space a pin holds its vertex where it is (with the area constraint, one pin
    // fixes a closed surface: docs/qc-space.md).
    let space = args.target == TargetArg::Space;
    problem
        .constraints
        .extend(
            mapping::resolve_pins(&args.pins, mesh)?
                .into_iter()
                .map(|mut pin| {
                    if space {
                        pin.position = Some(Position::Spatial(mesh.position(pin.vertex)));
                    }
                    Constraint::Pin(pin)
                }),
        );
    if let Some(weight) = args.normal_constraint {
        problem.constraints.push(Constraint::Normal { weight });
    }
    if args.area_constraint {
        problem.constraints.push(Constraint::Area);
    }
    if let Some(path) = &args.landmarks {
        problem.constraints.extend(
            beltrami::landmarks::read_planar(path, mesh)?
                .into_iter()
                .map(Constraint::Landmark),
        );
    }
    if let (TargetArg::Space, Some(path)) = (args.target, &args.boundary_map) {
        let held = beltrami::mapped::read_spatial(path, mesh, false)
            .with_context(|| format!("--boundary-map {}", path.display()))?;
        problem.constraints.hold_boundary(mesh, &held);
    }
    Ok(())
}

/// The solver's options from the command's flags (`init` the start `--init` names)
/// and `--option`.
fn options_of(args: &QcArgs, solver: &dyn Solver, init: Option<&str>) -> Options {
    mapping::solver_options(
        solver,
        &[
            (
                "tolerance",
                args.tolerance.map(OptionValue::Float),
                Some(OptionValue::Float(1e-6)),
            ),
            (
                "max-iters",
                args.max_iters.map(OptionValue::Int),
                Some(OptionValue::Int(200)),
            ),
            ("threads", args.threads.map(OptionValue::Int), None),
            ("outer", args.outer.map(|l| OptionValue::Int(l + 1)), None),
            ("init", init.map(|s| OptionValue::Choice(s.into())), None),
        ],
        &args.common,
    )
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
