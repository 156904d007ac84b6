//! `beltrami bench cg`: the flow's conjugate gradients (`SpdSolver::solve_preconditioned`,
//! preconditioned with the kept factorization) against faer's
//! `matrix_free::conjugate_gradient`, on every system real flows and registrations
//! solve that way.
//!
//! Built with the feature `cg-bench`, which turns on `beltrami-sparse`'s `cg-compare`.
//! The first table runs each case once with every preconditioned solve also done, on
//! copies, by both loops with the same product, preconditioner, tolerance and iteration
//! limit (`beltrami_sparse::cg_compare`), while the flow itself goes on as usual: the
//! solves, iterations and seconds of each loop, and the solves that give up (then the
//! flow factors the new matrix; the own loop gives up as soon as the mean reduction of
//! the residual predicts more iterations than the limit, faer's runs to the limit). The
//! second runs each case whole with one loop, then the other, solving for the flow.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context as _, bail};
use beltrami_core::{
    Constraint, Context, Goal, Map, OptionValue, Pin, Problem, Solution, Solver, Target,
};
use beltrami_flow::{BeltramiFlow, stereographic};
use beltrami_mesh::primitives;
use beltrami_mesh::subdivision::subdivide;
use beltrami_mesh::{BuildOptions, Mesh, VertexId, io};
use beltrami_register::Register;
use beltrami_sparse::cg_compare::{self, Comparison, Mode, Run};
use clap::Args;
use num_complex::Complex64;

#[derive(Debug, Args)]
pub struct CgArgs {
    /// Levels of the octahedral spheres flowed to the Table 5.2 mu (0.3 + 0.3 i); the
    /// default levels 6, 7, 8 have 16K, 66K and 262K vertices.
    #[arg(long, value_delimiter = ',', default_value = "6,7,8")]
    pub levels: Vec<usize>,
    /// Disk or closed genus-0 meshes flowed conformally onto the disk or the sphere
    /// (`FILE:k`: subdivided 1-to-4 `k` times). Without --flow and --register, the
    /// shared disk_hand.obj and g0_koala.obj when `../shared/meshes` exists.
    #[arg(long = "flow")]
    pub flows: Vec<String>,
    /// Registrations `SOURCE,TARGET` (each `FILE`, `FILE:k`, or `sphere:L`, the
    /// octahedral sphere of level `L`). Without --flow and --register, the shared
    /// mc4_face_a onto mc4_face_b and g0_koala onto `sphere:7` and, subdivided once,
    /// onto `sphere:8`.
    #[arg(long = "register")]
    pub registrations: Vec<String>,
    /// Most flow iterations of a registration.
    #[arg(long = "max-iters", default_value_t = 30)]
    pub max_iters: usize,
    /// Whole runs per case with each loop solving for the flow (at least 1).
    #[arg(long, default_value_t = 3)]
    pub rounds: usize,
}

/// A mesh named by `spec`: `sphere:L`, or a file, `FILE:k` subdivided `k` times.
fn mesh_of(spec: &str) -> anyhow::Result<Mesh> {
    if let Some(level) = spec.strip_prefix("sphere:") {
        return Ok(Mesh::from_soup(&primitives::octahedral_sphere(
            level.parse()?,
        ))?);
    }
    let (file, levels) = match spec.rsplit_once(':') {
        Some((f, k)) if !k.is_empty() && k.chars().all(|c| c.is_ascii_digit()) => {
            (f, k.parse::<usize>()?)
        }
        _ => (spec, 0),
    };
    let mut mesh = io::read(&PathBuf::from(file), &BuildOptions::default())
        .with_context(|| format!("reading {file}"))?
        .mesh;
    for _ in 0..levels {
        mesh = Mesh::from_soup(&subdivide(&mesh))?;
    }
    Ok(mesh)
}

/// The last path component of every part of `spec`.
fn short_name(spec: &str) -> String {
    spec.split(',')
        .map(|part| part.rsplit('/').next().unwrap_or(part))
        .collect::<Vec<_>>()
        .join(" onto ")
}

/// What a workload solves.
enum Kind {
    /// The flow onto the sphere to the Table 5.2 mu.
    Sphere,
    /// The conformal flow onto the disk or the sphere.
    Conformal,
    /// A registration onto the target mesh, with at most this many flow iterations.
    Register(Box<Mesh>, usize),
}

/// A flow or registration and its source mesh.
struct Workload {
    name: String,
    source: Mesh,
    kind: Kind,
}

impl Workload {
    fn sphere(level: usize) -> anyhow::Result<Self> {
        Ok(Self {
            name: format!("octahedral sphere {level}, mu 0.3 + 0.3 i"),
            source: Mesh::from_soup(&primitives::octahedral_sphere(level))?,
            kind: Kind::Sphere,
        })
    }

    fn conformal(spec: &str) -> anyhow::Result<Self> {
        Ok(Self {
            name: format!("{} (conformal flow)", short_name(spec)),
            source: mesh_of(spec)?,
            kind: Kind::Conformal,
        })
    }

    fn register(spec: &str, max_iters: usize) -> anyhow::Result<Self> {
        let Some((source, target)) = spec.split_once(',') else {
            bail!("--register takes SOURCE,TARGET, not {spec}");
        };
        Ok(Self {
            name: format!("{} (registration)", short_name(spec)),
            source: mesh_of(source)?,
            kind: Kind::Register(Box::new(mesh_of(target)?), max_iters),
        })
    }

    /// Runs the flow or the registration.
    fn solve(&self) -> anyhow::Result<Solution> {
        let mesh = &self.source;
        let solution = match &self.kind {
            Kind::Sphere => {
                let k = Complex64::new(0.3, 0.3);
                let mut problem = Problem::new(mesh, Target::Sphere);
                problem.goal = Goal::Prescribed(stereographic::field(mesh, |_| k)?);
                problem.constraints = [0, 1, 5]
                    .into_iter()
                    .map(|v| {
                        Constraint::Pin(Pin {
                            vertex: VertexId(v),
                            position: None,
                        })
                    })
                    .collect();
                problem.options.set("tolerance", OptionValue::Float(1e-5));
                BeltramiFlow.solve(&problem, &mut Context::new())?
            }
            Kind::Conformal => {
                let target = if mesh.is_closed() {
                    Target::Sphere
                } else {
                    Target::Disk
                };
                let mut problem = Problem::new(mesh, target);
                problem.goal = Goal::Conformal { p: 2.0 };
                problem.options.set("tolerance", OptionValue::Float(1e-6));
                BeltramiFlow.solve(&problem, &mut Context::new())?
            }
            Kind::Register(target, max_iters) => {
                let mut problem = Problem::new(mesh, Target::Mesh(target));
                problem
                    .options
                    .set("max-iters", OptionValue::Int(*max_iters));
                Register.solve(&problem, &mut Context::new())?
            }
        };
        Ok(solution)
    }
}

/// What a workload run once in [`Mode::Compare`] recorded.
struct Case {
    comparisons: Vec<Comparison>,
}

fn compared(workload: &Workload) -> anyhow::Result<Case> {
    cg_compare::set_mode(Mode::Compare);
    cg_compare::take();
    workload.solve()?;
    Ok(Case {
        comparisons: cg_compare::take(),
    })
}

/// A whole run with one loop solving for the flow.
struct EndToEnd {
    seconds: f64,
    solution: Solution,
    runs: Vec<Run>,
    factor_seconds: f64,
}

fn end_to_end(workload: &Workload, mode: Mode, unknowns: usize) -> anyhow::Result<EndToEnd> {
    cg_compare::set_mode(mode);
    cg_compare::take_runs();
    cg_compare::take_factorizations();
    let start = Instant::now();
    let solution = workload.solve()?;
    let seconds = start.elapsed().as_secs_f64();
    let factor_seconds = cg_compare::take_factorizations()
        .iter()
        .filter(|f| f.unknowns == unknowns)
        .map(|f| f.seconds)
        .sum();
    Ok(EndToEnd {
        seconds,
        solution,
        runs: cg_compare::take_runs(),
        factor_seconds,
    })
}

/// Sums over some of a case's comparisons.
#[derive(Default)]
struct Totals {
    solves: usize,
    own_iterations: usize,
    faer_iterations: usize,
    own_seconds: f64,
    faer_seconds: f64,
}

impl Totals {
    fn of<'a>(comparisons: impl Iterator<Item = &'a Comparison>) -> Self {
        let mut t = Self::default();
        for c in comparisons {
            t.solves += 1;
            t.own_iterations += c.own.iterations;
            t.faer_iterations += c.faer.iterations;
            t.own_seconds += c.own.seconds;
            t.faer_seconds += c.faer.seconds;
        }
        t
    }
}

fn print_solve_row(workload: &Workload, comparisons: &[Comparison]) {
    let count = |f: fn(&Comparison) -> bool| comparisons.iter().filter(|c| f(c)).count();
    let all = Totals::of(comparisons.iter());
    let gave_up = Totals::of(comparisons.iter().filter(|c| !c.own.converged));
    let both = Totals::of(
        comparisons
            .iter()
            .filter(|c| c.own.converged && c.faer.converged),
    );
    let per = |s: f64, i: usize| 1e3 * s / i.max(1) as f64;
    let difference = comparisons
        .iter()
        .filter_map(|c| c.difference)
        .fold(0.0, f64::max);
    println!(
        "| {} | {} | {} | {} / {} | {} | {} | {} / {} | {:.3} / {:.3} | {:.3} / {:.3} | {:.1} / {:.1} | {difference:.0e} |",
        workload.name,
        workload.source.vertex_count(),
        all.solves,
        count(|c| c.own.converged),
        count(|c| c.faer.converged),
        count(|c| !c.own.converged && c.own.iterations < c.max_iterations),
        count(|c| !c.own.converged && c.faer.converged),
        all.own_iterations,
        all.faer_iterations,
        all.own_seconds,
        all.faer_seconds,
        gave_up.own_seconds,
        gave_up.faer_seconds,
        per(both.own_seconds, both.own_iterations),
        per(both.faer_seconds, both.faer_iterations),
    );
}

fn print_end_to_end_row(workload: &Workload, mode: Mode, run: &EndToEnd, map: &str) {
    let metrics = &run.solution.metrics;
    let converged = run.runs.iter().filter(|r| r.converged).count();
    let iterations: usize = run.runs.iter().map(|r| r.iterations).sum();
    let cg_seconds: f64 = run.runs.iter().map(|r| r.seconds).sum();
    println!(
        "| {} | {} | {:.2} | {} | {} | {} ({converged}) | {iterations} | {cg_seconds:.3} | {:.3} | {map} |",
        workload.name,
        if mode == Mode::Own { "own" } else { "faer" },
        run.seconds,
        metrics.iterations,
        metrics.factorizations.unwrap_or(0),
        run.runs.len(),
        run.factor_seconds,
    );
}

/// The workloads of `args`, or the default ones.
fn workloads(args: &CgArgs) -> anyhow::Result<Vec<Workload>> {
    let shared = PathBuf::from("../shared/meshes");
    let (mut flows, mut registrations) = (args.flows.clone(), args.registrations.clone());
    if flows.is_empty() && registrations.is_empty() && shared.exists() {
        let file = |name: &str| shared.join(name).display().to_string();
        flows = vec![file("disk_hand.obj"), file("g0_koala.obj")];
        registrations = vec![
            format!("{},{}", file("mc4_face_a.obj"), file("mc4_face_b.obj")),
            format!("{},sphere:7", file("g0_koala.obj")),
            format!("{}:1,sphere:8", file("g0_koala.obj")),
        ];
    }
    let mut out = Vec::new();
    for &level in &args.levels {
        out.push(Workload::sphere(level)?);
    }
    for spec in &flows {
        out.push(Workload::conformal(spec)?);
    }
    for spec in &registrations {
        out.push(Workload::register(spec, args.max_iters)?);
    }
    Ok(out)
}

/// Whole runs with each loop, `rounds` times alternating which goes first; the fastest
/// of each, and whether every run of both gave the same map.
fn end_to_end_table(workloads: &[Workload], cases: &[Case], rounds: usize) -> anyhow::Result<()> {
    println!("\n### Whole runs, each loop solving for the flow (fastest of {rounds})\n");
    println!(
        "| case | loop | run s | steps | factorizations | CG solves (converged) | CG iterations | CG s | factorization s | map |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for (workload, case) in workloads.iter().zip(cases) {
        let unknowns = case.comparisons.first().map_or(0, |c| c.unknowns);
        let mut best: [Option<EndToEnd>; 2] = [None, None];
        // The first map of each loop, and whether every later one equals it.
        let mut first: [Option<Option<Map>>; 2] = [None, None];
        let mut same = [true, true];
        for round in 0..rounds {
            let order = if round % 2 == 0 { [0, 1] } else { [1, 0] };
            for slot in order {
                let run = end_to_end(workload, [Mode::Own, Mode::Faer][slot], unknowns)?;
                let map = run.solution.map().cloned();
                same[slot] &= first[slot].get_or_insert_with(|| map.clone()) == &map;
                if best[slot].as_ref().is_none_or(|b| run.seconds < b.seconds) {
                    best[slot] = Some(run);
                }
            }
        }
        let own_map = if same[0] { "reproducible" } else { "varies" };
        let faer_map = if same[1] && first[0] == first[1] {
            "= own"
        } else {
            "differs"
        };
        for (slot, (mode, map)) in [(Mode::Own, own_map), (Mode::Faer, faer_map)]
            .into_iter()
            .enumerate()
        {
            let run = best[slot].as_ref().context("at least one round")?;
            print_end_to_end_row(workload, mode, run, map);
        }
    }
    cg_compare::set_mode(Mode::Compare);
    Ok(())
}

pub fn run(args: &CgArgs) -> anyhow::Result<()> {
    let workloads = workloads(args)?;
    let mut cases = Vec::new();
    for workload in &workloads {
        cases.push(compared(workload)?);
    }
    println!("\n### Preconditioned solves, each by both loops: own / faer's\n");
    println!(
        "| case | vertices | solves | converged | own gave up early | faer converged where own gave up | iterations | CG s | CG s on own's give-ups | ms per iteration where both converged | largest difference |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    for (workload, case) in workloads.iter().zip(&cases) {
        print_solve_row(workload, &case.comparisons);
    }
    end_to_end_table(&workloads, &cases, args.rounds.max(1))
}
