//! `beltrami register`: a map of one mesh onto another of the same topology, bijective
//! and as conformal as the constraints allow (or with a prescribed mu), by an initial
//! bijection through a common parameter domain and the Beltrami flow on the target mesh.

use std::path::PathBuf;

use anyhow::bail;
use beltrami::landmarks::Landmarks;
use beltrami::problem_spec::{GoalSpec, ProblemSpec, TargetName};
use beltrami::{correspondence, map_file, report, vertex_field};
use beltrami_core::{Features, Goal, Map, OptionValue, Problem, Solution, Target};
use beltrami_fem::BeltramiField;
use beltrami_mesh::Mesh;
use beltrami_register::{InverseConsistency, inverse_consistency};
use clap::Args;
use serde_json::json;

use super::load::load_mesh;
use super::mapping;

#[derive(Debug, Args)]
pub struct RegisterArgs {
    /// The mesh to map (.obj, .ply, .stl, .off, .gltf, .glb).
    pub source: PathBuf,
    /// The mesh to map onto, of the same topology.
    pub target: PathBuf,
    /// Minimize the L^p norm of mu (2 <= p <= 100) [default: 2].
    #[arg(long)]
    pub p: Option<f64>,
    /// A prescribed Beltrami coefficient per source face instead (the field format,
    /// face frame).
    #[arg(long)]
    pub mu: Option<PathBuf>,
    /// Landmarks and feature curves (`v SRC TGT`, `p SRC x y z`, `c SRC,.. TGT,..`).
    #[arg(long)]
    pub landmarks: Option<PathBuf>,
    /// Match a scalar field given on both meshes (one value per vertex per line, or the
    /// computed `mean-curvature`): the initial map bent in the common domain until the
    /// fields agree, landmarks held (disks and closed genus-0 surfaces).
    #[arg(long, num_args = 2, value_names = ["SOURCE_FIELD", "TARGET_FIELD"])]
    pub features: Option<Vec<PathBuf>>,
    /// Match the shapes: from the initial map, pull each image towards where
    /// the source, placed on the target by the similarity that best fits the map, lies
    /// (a non-rigid ICP that stays a bijection; disks and closed genus-0 surfaces). For
    /// surfaces that overlap in space once aligned, such as two scans or two cortical
    /// surfaces of one subject. With --features, both are matched together.
    #[arg(long = "match-shape")]
    pub match_shape: bool,
    /// With --match-shape: the meshes lie in one frame and the source already near its
    /// correspondence (two surfaces of one scan, such as a subject's pial and white
    /// surfaces): the source is taken where it is, not aligned, and deformed with the
    /// supple end of the non-rigid ICP's schedule only, so that it is not slid along
    /// the target by a fit as a whole.
    #[arg(long = "in-place", requires = "match_shape")]
    pub in_place: bool,
    /// Most flow iterations [default: 100].
    #[arg(long = "max-iters")]
    pub max_iters: Option<usize>,
    /// Stop when the largest vertex update is below this (relative to the target's
    /// size) [default: 1e-5].
    #[arg(long)]
    pub tolerance: Option<f64>,
    /// Threads for the sparse factorizations [default: 1].
    #[arg(long)]
    pub threads: Option<usize>,
    /// Write the map even if flipped faces remain after the flow (they are named in the
    /// notes); without it such a registration fails, naming them, and writes nothing.
    #[arg(long = "allow-flips")]
    pub allow_flips: bool,
    /// Write the map even if some landmarks are not exact (their distances are in the
    /// report); without it such a registration fails, naming the farthest, and writes
    /// nothing.
    #[arg(long = "allow-missed-landmarks")]
    pub allow_missed_landmarks: bool,
    /// Also register TARGET onto SOURCE (the landmarks' `v` and `c` lines reversed, the
    /// features exchanged) and report how far the two maps are from inverses: each
    /// source vertex carried there and back, its distance from where it started.
    #[arg(long = "inverse-consistency")]
    pub inverse_consistency: bool,
    /// Output mesh: the source's vertices and faces, every vertex at its image on the
    /// target (so `beltrami distortion SOURCE OUT` measures the map).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Write one line per source vertex, `face b0 b1 b2`: its image as a target face
    /// (0-based, the target file's order) and barycentric coordinates.
    #[arg(long)]
    pub correspondence: Option<PathBuf>,
    #[command(flatten)]
    pub common: mapping::CommonArgs,
}

pub fn run(args: &RegisterArgs, quiet: bool) -> anyhow::Result<()> {
    mapping::check_outputs(
        &args.output,
        &args.common,
        &[("--correspondence", args.correspondence.as_deref())],
    )?;
    let registry = beltrami::registry();
    let solver = registry.get("register")?;
    let source_loaded = load_mesh(&args.source, args.common.repair, quiet || args.common.json)?;
    let target_loaded = load_mesh(&args.target, args.common.repair, quiet || args.common.json)?;
    let source = &source_loaded.mesh.mesh;
    let target = &target_loaded.mesh.mesh;

    let mut spec = spec_of(args);
    spec.goal = Some(goal_of(args, source, target)?);
    let marks = match &args.landmarks {
        Some(path) => Landmarks::read(path, source, target)?,
        None => Landmarks::default(),
    };
    spec.constraints = marks.constraints();
    let problem = spec.problem(source, Some(target), solver)?;

    let (solution, seconds) = mapping::solve(solver, &problem, args.common.progress(quiet))?;
    // The way back runs before anything is written: a failure there writes nothing.
    let round_trip = if args.inverse_consistency {
        let Some(Map::OnMesh(points)) = solution.map() else {
            bail!("the register solver did not give points on the target mesh");
        };
        Some(round_trip(args, &problem, &marks, points, quiet)?)
    } else {
        None
    };
    map_file::write(
        &args.output,
        source,
        &solution,
        Some(target),
        None,
        &source_loaded.mesh.obj_groups,
    )?;
    if let Some(path) = &args.correspondence {
        let Some(Map::OnMesh(points)) = solution.map() else {
            bail!("the register solver did not give points on the target mesh");
        };
        correspondence::write(path, source, target, points)?;
    }
    mapping::write_png(args.common.png.as_deref(), source, &solution, Some(target))?;

    let (report, extra) = report_and_summary(args, source, &solution, seconds, round_trip);
    mapping::finish(
        report,
        args.common.report.as_deref(),
        args.common.json,
        quiet,
        (&args.source, &args.output, &solution, seconds),
        &extra,
    )
}

/// The goal of `--mu`, `--p` and `--features`, refused when they are combined.
fn goal_of(args: &RegisterArgs, source: &Mesh, target: &Mesh) -> anyhow::Result<GoalSpec> {
    Ok(match (&args.mu, args.p, args.features.as_deref()) {
        (Some(_), Some(_), _) => {
            bail!("--p is the exponent of the conformal goal; a prescribed --mu has no exponent")
        }
        (_, Some(_), Some(_)) | (Some(_), _, Some(_)) => {
            bail!(
                "--features matches fields with the least-squares conformal map as its start; it takes neither --p nor --mu"
            )
        }
        (None, None, Some([source_field, target_field])) => GoalSpec::Features(Features {
            source: vertex_field::read(source_field, source)?,
            target: vertex_field::read(target_field, target)?,
        }),
        (None, None, Some(_)) => bail!("--features takes two fields: SOURCE_FIELD TARGET_FIELD"),
        (Some(path), None, None) => GoalSpec::Mu(BeltramiField::read(path, source.face_count())?),
        (None, p, None) => GoalSpec::Conformal { p },
    })
}

/// The problem's words from the flags: onto the target mesh, the command's defaults
/// (`tolerance` 1e-5, `max-iters` 100), the option flags and `--option`.
fn spec_of(args: &RegisterArgs) -> ProblemSpec {
    let mut spec = ProblemSpec::new(TargetName::Mesh);
    spec.defaults = vec![
        ("tolerance".into(), OptionValue::Float(1e-5)),
        ("max-iters".into(), OptionValue::Int(100)),
    ];
    let given = [
        ("tolerance", args.tolerance.map(OptionValue::Float)),
        ("max-iters", args.max_iters.map(OptionValue::Int)),
        ("threads", args.threads.map(OptionValue::Int)),
        (
            "allow-flips",
            args.allow_flips.then_some(OptionValue::Bool(true)),
        ),
        (
            "allow-missed-landmarks",
            args.allow_missed_landmarks
                .then_some(OptionValue::Bool(true)),
        ),
        (
            "match-shape",
            args.match_shape.then_some(OptionValue::Bool(true)),
        ),
        ("in-place", args.in_place.then_some(OptionValue::Bool(true))),
    ];
    for (name, value) in given {
        if let Some(value) = value {
            spec.options.set(name, value);
        }
    }
    for (name, value) in &args.common.options {
        spec.options.set_text(name, value);
    }
    spec
}

/// The JSON report of a registration and the summary's lines after the common ones:
/// the iterations, the landmarks, the route and the inverse consistency of
/// `round_trip` (`--inverse-consistency`).
fn report_and_summary(
    args: &RegisterArgs,
    source: &Mesh,
    solution: &Solution,
    seconds: f64,
    round_trip: Option<InverseConsistency>,
) -> (serde_json::Map<String, serde_json::Value>, Vec<String>) {
    let mut report = mapping::report_json(&args.source, &args.output, solution, seconds);
    report.insert("target".into(), json!(args.target.display().to_string()));
    let per_step = report::seconds_per_step(solution).unwrap_or(0.0);
    let mut extra = vec![format!(
        "iterations      {} ({per_step:.3} s per step)",
        solution.metrics.iterations
    )];
    let marks = &solution.extras.landmarks;
    if let Some(worst) = marks.iter().map(|m| m.distance).reduce(f64::max) {
        extra.push(format!(
            "landmarks       {} (largest distance to its target {worst:.3e})",
            marks.len()
        ));
    }
    if let Some(route) = &solution.extras.route {
        extra.push(format!("route           {route}"));
    }
    if let Some(trip) = round_trip {
        let size = source.bounding_box().diagonal().max(f64::MIN_POSITIVE);
        report.insert(
            "inverse_consistency".into(),
            json!({
                "mean": trip.mean,
                "max": trip.max,
                "worst_vertex": source.vertex_map().to_input(beltrami_mesh::VertexId::from_usize(trip.worst)),
                "relative_mean": trip.mean / size,
                "relative_max": trip.max / size,
            }),
        );
        extra.push(format!(
            "inverse consistency mean {:.4e} max {:.4e} ({:.2e} / {:.2e} of the source's size)",
            trip.mean,
            trip.max,
            trip.mean / size,
            trip.max / size
        ));
    }
    (report, extra)
}

/// The registration of TARGET onto SOURCE with `problem`'s options, landmarks reversed
/// and features exchanged, measured against `forward` ([`inverse_consistency`]).
fn round_trip(
    args: &RegisterArgs,
    problem: &Problem<'_>,
    marks: &Landmarks,
    forward: &[beltrami_core::SurfacePoint],
    quiet: bool,
) -> anyhow::Result<InverseConsistency> {
    let Target::Mesh(target) = problem.target else {
        bail!("register maps onto a target mesh");
    };
    let source = problem.source;
    let mut reverse = Problem::new(target, Target::Mesh(source));
    reverse.goal = match &problem.goal {
        Goal::Features(f) => Goal::Features(Features {
            source: f.target.clone(),
            target: f.source.clone(),
        }),
        Goal::Prescribed(_) => {
            bail!(
                "--inverse-consistency: a prescribed --mu is per source face and has no inverse to run"
            )
        }
        goal => goal.clone(),
    };
    let reversed = marks.reversed().map_err(|line| {
        anyhow::anyhow!(
            "--inverse-consistency: landmarks line {line} is a `p` line, which has no target vertex to start the registration back from; give `v SRC TGT` lines"
        )
    })?;
    reverse.constraints = reversed.constraints();
    reverse.options = problem.options.clone();
    let registry = beltrami::registry();
    let solver = registry.get("register")?;
    let (back, _) = mapping::solve(solver, &reverse, args.common.progress(quiet))?;
    let Some(Map::OnMesh(points)) = back.map() else {
        bail!("the register solver did not give points on the source mesh");
    };
    let positions: Vec<_> = points.iter().map(|p| p.position(source)).collect();
    inverse_consistency(source, target, forward, &positions)
        .ok_or_else(|| anyhow::anyhow!("the two registrations do not fit the meshes"))
}
