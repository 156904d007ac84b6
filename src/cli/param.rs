//! `beltrami param`: parameterize a mesh with one of the registered solvers.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::{Context as _, bail};
use beltrami_core::{
    Context, Map, Pin, PlanarBoundary, Problem, Progress, Solution, Target, Weights,
};
use beltrami_mesh::io::{self, Format, VertexAttributes};
use beltrami_mesh::{Mesh, Vector2};
use clap::{Args, ValueEnum};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use serde_json::json;

use super::colormap::viridis;
use super::load::load_mesh;
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

#[derive(Debug, Args)]
pub struct ParamArgs {
    /// Mesh file (.obj, .gltf, .glb).
    pub mesh: PathBuf,
    /// Solver name (`beltrami solvers` lists them): tutte, harmonic, lscm, sphere.
    #[arg(long)]
    pub solver: String,
    /// Boundary of the parameter domain (default: circle for tutte and harmonic, free
    /// for lscm).
    #[arg(long, value_enum)]
    pub boundary: Option<BoundaryArg>,
    /// Edge weights (tutte: uniform or mean-value; harmonic: cotan).
    #[arg(long, value_enum)]
    pub weights: Option<WeightsArg>,
    /// Pin a vertex: `v12` by its 0-based index, or `x,y[,z]` for the nearest vertex;
    /// repeatable. LSCM's two pins go to (0,0) and (1,0).
    #[arg(long = "pin")]
    pub pins: Vec<PinSpec>,
    /// Output mesh: .obj (the input's vertices and faces, one `vt` per vertex; for the
    /// sphere, the sphere positions) or .glb/.gltf (UVs and |mu| colors).
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

/// A progress bar that appears only once a run has lasted a second.
struct LateBar {
    bar: ProgressBar,
    start: Instant,
    shown: bool,
    enabled: bool,
}

impl LateBar {
    fn new(enabled: bool) -> Self {
        let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::hidden());
        bar.set_style(
            ProgressStyle::with_template("{spinner} {msg} [{elapsed}]")
                .unwrap_or_else(|_| ProgressStyle::default_spinner()),
        );
        Self {
            bar,
            start: Instant::now(),
            shown: false,
            enabled,
        }
    }

    fn update(&mut self, p: &Progress) {
        if !self.enabled {
            return;
        }
        if !self.shown && self.start.elapsed() > Duration::from_secs(1) {
            self.bar.set_draw_target(ProgressDrawTarget::stderr());
            self.bar.enable_steady_tick(Duration::from_millis(120));
            self.shown = true;
        }
        let mut msg = p.stage.to_string();
        if let Some(total) = p.total {
            msg.push_str(&format!(" {}/{total}", p.done));
        }
        if let Some(e) = p.energy {
            msg.push_str(&format!(" energy {e:.3e}"));
        }
        self.bar.set_message(msg);
    }

    fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

fn target_of(args: &ParamArgs) -> anyhow::Result<Target<'static>> {
    if args.solver == "sphere" {
        return Ok(Target::Sphere);
    }
    let default = if args.solver == "lscm" {
        BoundaryArg::Free
    } else {
        BoundaryArg::Circle
    };
    Ok(Target::Plane(match args.boundary.unwrap_or(default) {
        BoundaryArg::Circle => PlanarBoundary::Circle,
        BoundaryArg::Square => PlanarBoundary::Square { corners: None },
        BoundaryArg::Free => PlanarBoundary::Free,
    }))
}

pub fn run(args: &ParamArgs, quiet: bool) -> anyhow::Result<()> {
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

    let mut problem = Problem::new(mesh, target_of(args)?);
    problem.params.weights = args.weights.map(|w| match w {
        WeightsArg::Uniform => Weights::Uniform,
        WeightsArg::MeanValue => Weights::MeanValue,
        WeightsArg::Cotan => Weights::Cotan,
    });
    for spec in &args.pins {
        problem.constraints.pins.push(Pin {
            vertex: spec.resolve(mesh)?,
            position: None,
        });
    }
    solver.check(&problem)?;

    let mut bar = LateBar::new(!quiet && !args.json);
    let start = Instant::now();
    let solution = {
        let mut context = Context::new().with_progress(|p: &Progress| bar.update(p));
        solver.solve(&problem, &mut context)
    };
    bar.finish();
    let solution = solution?;
    let seconds = start.elapsed().as_secs_f64();

    write_output(args, mesh, &solution)?;
    let report = report_json(args, &solution, seconds);
    if let Some(path) = &args.report {
        let text = serde_json::to_string_pretty(&report)?;
        io::write_atomically(path, |w| std::io::Write::write_all(w, text.as_bytes()))
            .with_context(|| format!("cannot write the report {}", path.display()))?;
    }
    if args.json {
        println!("{report}");
    } else if !quiet {
        print_summary(args, &solution, seconds);
    }
    Ok(())
}

fn write_output(args: &ParamArgs, mesh: &Mesh, solution: &Solution) -> anyhow::Result<()> {
    let face_mu = solution.report.mu.as_ref().map(|f| &f.mu);
    // Per-vertex |mu| for colors: the mean over the incident faces.
    let colors: Option<Vec<[f32; 3]>> = face_mu.map(|mu| {
        mesh.vertices()
            .map(|v| {
                let (sum, n) = mesh
                    .vertex_faces(v)
                    .fold((0.0, 0usize), |(s, n), f| (s + mu[f.idx()].norm(), n + 1));
                viridis(if n > 0 { sum / n as f64 } else { 0.0 })
            })
            .collect()
    });
    let glb = matches!(
        Format::from_path(&args.output),
        Some(Format::Glb | Format::Gltf)
    );
    match &solution.map {
        Map::Planar(z) => {
            let uv: Vec<Vector2<f64>> = z.iter().map(|z| Vector2::new(z.re, z.im)).collect();
            io::write(
                &args.output,
                mesh,
                &VertexAttributes {
                    uvs: Some(&uv),
                    colors: if glb { colors.as_deref() } else { None },
                    ..Default::default()
                },
            )?;
        }
        Map::Spatial(p) => {
            io::write(
                &args.output,
                mesh,
                &VertexAttributes {
                    positions: Some(p),
                    colors: if glb { colors.as_deref() } else { None },
                    ..Default::default()
                },
            )?;
        }
        Map::OnMesh(_) => bail!("this command writes planar and spatial maps only"),
    }
    Ok(())
}

fn report_json(args: &ParamArgs, solution: &Solution, seconds: f64) -> serde_json::Value {
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
        "mu_std": d.map(|d| d.mu_std),
        "mu_l2": d.map(|d| d.mu_l2),
        "energy_history": r.energy_history,
        "timings": r.timings.iter().map(|(k, v)| json!({"stage": k, "seconds": v})).collect::<Vec<_>>(),
        "notes": r.notes,
    })
}

fn print_summary(args: &ParamArgs, solution: &Solution, seconds: f64) {
    let r = &solution.report;
    println!(
        "{} -> {} ({}, {seconds:.3} s)",
        args.mesh.display(),
        args.output.display(),
        r.solver
    );
    if let Some(d) = &r.distortion {
        println!("  flipped faces   {}", d.flipped);
        println!(
            "  |mu|            mean {:.4e}  max {:.4e}  std {:.4e}",
            d.mu_mean, d.mu_max, d.mu_std
        );
    }
    for (stage, s) in &r.timings {
        println!("  {stage:<15} {s:.3} s");
    }
    for note in &r.notes {
        println!("  note: {note}");
    }
}
