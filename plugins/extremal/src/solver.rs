//! [`Extremal`]: the solver behind `--solver extremal` (crate docs): the boundary
//! values, the start map, then Algorithm 1 of Weber, Myles and Zorin (2012).

use beltrami_core::{
    Accepts, ConstraintKind, Context, Element, Extras, Goal, GoalKind, Map, Metrics, OptionKind,
    OptionSpec, Output, Problem, Progress, QuadraticDifferential, Report, Settings, Solution,
    Solver, SolverError, SolverInfo, Stop, THREADS, Target, TargetKind, Topology,
};
use beltrami_fem::assembly::Pattern;
use beltrami_fem::beltrami::planar_map;
use beltrami_fem::element::{check_planar, is_planar};
use beltrami_fem::{
    BoundaryMap, Distortion, DofConstraints, DofMap, EdgeWeights, Elements, Frame,
    LeastSquaresSolver, WeightedMeanSystem,
};
use beltrami_mesh::closed_curve::{crosses_itself, signed_area};
use beltrami_mesh::{Mesh, VertexId};
use beltrami_sparse::SolveOptions;
use num_complex::Complex64;

use crate::flatten::{Flattening, flatten};
use crate::forms::{FormStep, HarmonicForms};
use crate::quadrilateral::{Quadrilateral, quadrilateral};

pub(crate) const NAME: &str = "extremal";

/// The extremal quasiconformal map of a planar mesh with a prescribed boundary (crate
/// docs).
///
/// Reads: `target` (`Plane(Keep | Given)`: every boundary vertex of every loop fixed;
/// or `Disk`: the four-point problem, the boundary sliding on the unit circle with four
/// `constraints` landmarks at points of it, the `quadrilateral` module), `goal`
/// (`Extremal`), `initial` (a planar start map, folded or not; its boundary values are
/// replaced by the prescribed ones) and the options `init`, `tolerance`, `max-iters`,
/// `inner-iters`, `threads`.
#[derive(Debug, Clone, Copy, Default)]
pub struct Extremal;

const OPTIONS: &[OptionSpec] = &[
    OptionSpec {
        name: "init",
        kind: OptionKind::Choice {
            default: "harmonic",
            choices: &["harmonic", "tutte"],
        },
        help: "the start map when none is given: harmonic (cotangent weights) or tutte (uniform weights), with the prescribed boundary",
    },
    OptionSpec {
        name: "tolerance",
        kind: OptionKind::Float {
            default: 1e-6,
            min: 0.0,
            max: 1.0,
        },
        help: "stop when an outer iteration lowers the least-squares Beltrami energy by less than this fraction",
    },
    OptionSpec {
        name: "max-iters",
        kind: OptionKind::Int {
            default: 200,
            min: 1,
            max: 100_000,
        },
        help: "most outer iterations (each: the h-steps, then one f-step)",
    },
    OptionSpec {
        name: "inner-iters",
        kind: OptionKind::Int {
            default: 20,
            min: 1,
            max: 1000,
        },
        help: "most h-steps (quadratic differential and k) per outer iteration",
    },
    THREADS,
];

const ACCEPTS: Accepts = Accepts {
    elements: &[Element::Triangle],
    topologies: &[
        Topology::Disk,
        Topology::Annulus,
        Topology::MultiplyConnected,
    ],
    targets: &[
        TargetKind::PlaneKeep,
        TargetKind::PlaneGiven,
        TargetKind::Disk,
    ],
    goals: &[GoalKind::Extremal],
    constraints: &[ConstraintKind::Landmark],
};

/// What [`Extremal`] is: its name, one line on what it computes, what it accepts and
/// its options.
const INFO: SolverInfo = SolverInfo {
    name: NAME,
    description: "extremal (Teichmueller) map with a prescribed boundary: constant |mu| = k, holomorphic quadratic differential (Weber-Myles-Zorin 2012)",
    accepts: ACCEPTS,
    options: OPTIONS,
};

impl Solver for Extremal {
    fn info(&self) -> &'static SolverInfo {
        &INFO
    }

    fn check_problem(&self, problem: &Problem<'_>, _: &Settings) -> Result<(), SolverError> {
        setup(problem).map(|_| ())
    }

    fn run(
        &self,
        problem: &Problem<'_>,
        settings: &Settings,
        context: &mut Context<'_>,
    ) -> Result<Solution, SolverError> {
        let mesh = problem.source;
        let mut report = Report::new(NAME);
        let boundary = setup(problem)?;
        let options = SolveOptions {
            threads: settings.int("threads"),
            ..SolveOptions::default()
        };
        let flat = if is_planar(mesh) {
            None
        } else {
            let mut inner = context.inner();
            let flat = context.stage("flattening", &mut report, || flatten(mesh, &mut inner))?;
            report.notes.push(format!(
                "the surface was laid out in the plane by LSCM (|mu| of that layout: mean {:.2e}, max {:.2e}); mu is measured on the surface, in its face frames",
                flat.mu_mean, flat.mu_max
            ));
            Some(flat)
        };
        let domain = flat.as_ref().map_or(mesh, |f| &f.mesh);
        if let Boundary::Fixed(values) = &boundary {
            same_turn(domain, values)?;
        }
        let initial = context.stage("initial map", &mut report, || {
            start_map(
                domain,
                problem,
                &boundary.start(domain),
                settings.choice("init"),
                options,
            )
        })?;
        let parameters = Parameters {
            tolerance: settings.float("tolerance"),
            max_iters: settings.int("max-iters"),
            inner_iters: settings.int("inner-iters"),
            options,
        };
        let mut run = context.stage("setup", &mut report, || {
            Algorithm::new(domain, &boundary, initial, parameters)
        })?;
        let initial_distortion = measure(mesh, flat.as_ref(), &run)?.stats;
        let outcome = report.time("iterations", || run.iterate(context))?;
        let distortion = measure(mesh, flat.as_ref(), &run)?;
        if distortion.stats.flipped > 0 {
            report.notes.push(format!(
                "{} of {} faces are flipped (the discrete map is extremal only in the limit of refinement; flips stay near sharp concave boundary corners)",
                distortion.stats.flipped,
                mesh.face_count()
            ));
        }
        let metrics = Metrics {
            mu: Some(distortion.field),
            distortion: Some(distortion.stats),
            initial_distortion: Some(initial_distortion),
            k: Some(run.k),
            iterations: outcome.iterations,
            energy_history: outcome.energy_history,
            step_sizes: outcome.step_sizes,
            stop: Some(outcome.stop),
            factorizations: Some(outcome.factorizations),
            ..Metrics::default()
        };
        let mut qd = run.quadratic_differential();
        if let Some(flat) = &flat {
            // phi dz^2 carried into each face's frame by the flattening's derivative.
            for (phi, c) in qd.values.iter_mut().zip(&flat.derivative) {
                *phi *= c * c;
            }
            qd.frame = Frame::Face;
        }
        let extras = Extras {
            quadratic_differential: Some(qd),
            ..Extras::default()
        };
        Ok(Solution {
            output: Output::Map(Map::Planar(run.map)),
            metrics,
            extras,
            report,
        })
    }
}

/// The boundary condition of a problem.
enum Boundary {
    /// Every boundary vertex fixed at its image.
    Fixed(Vec<(VertexId, Complex64)>),
    /// The four-point problem: the boundary slides on the unit circle.
    Sliding(Quadrilateral),
}

impl Boundary {
    /// The boundary of the start map: the fixed values, or the landmarks at their
    /// destinations with each side spread along its arc.
    fn start(&self, mesh: &Mesh) -> Vec<(VertexId, Complex64)> {
        match self {
            Boundary::Fixed(fixed) => fixed.clone(),
            Boundary::Sliding(quad) => quad.start_boundary(mesh),
        }
    }
}

/// The capability check: a planar triangle mesh (or a curved disk), the extremal goal,
/// fixed values for every boundary vertex or the four landmarks of the sliding disk.
fn setup(problem: &Problem<'_>) -> Result<Boundary, SolverError> {
    let mesh = problem.source;
    if problem.goal != Goal::Extremal {
        return Err(SolverError::unsupported(
            NAME,
            "extremal computes the extremal map of a boundary condition; for a prescribed mu use lsqc or beltrami-flow",
        ));
    }
    if check_planar(mesh).is_err() && mesh.genus() != Some(0) {
        return Err(SolverError::unsupported(
            NAME,
            format!(
                "extremal maps planar meshes (z = 0) and curved surfaces of genus 0 (laid out conformally first), but this curved mesh has {}",
                beltrami_core::topology::describe(mesh)
            ),
        ));
    }
    let landmarks = problem.constraints.landmarks().count();
    let boundary = match problem.planar_boundary_values() {
        Some(_) if landmarks > 0 => {
            return Err(SolverError::unsupported(
                NAME,
                "landmarks move boundary points of the sliding disk (`--target disk`); with a prescribed boundary every boundary vertex is already placed",
            ));
        }
        Some(values) => {
            let values = values.map_err(|message| SolverError::invalid(NAME, message))?;
            for (k, curve) in loop_curves(mesh, &values).iter().enumerate() {
                if crosses_itself(curve) {
                    return Err(SolverError::invalid(
                        NAME,
                        format!(
                            "the boundary map takes boundary loop {k} onto a curve that crosses itself: the boundary of a one-to-one map is a simple curve"
                        ),
                    ));
                }
            }
            Boundary::Fixed(values)
        }
        None if matches!(problem.target, Target::Disk) => {
            Boundary::Sliding(quadrilateral(problem)?)
        }
        None => {
            return Err(SolverError::unsupported(
                NAME,
                "extremal needs the boundary values: keep the source's boundary or give a boundary map (`--boundary given --boundary-map MAP`), or slide on the unit disk with four landmarks (`--target disk --landmarks FILE`)",
            ));
        }
    };
    if let Some(Map::Planar(z)) = &problem.initial {
        if z.len() != mesh.vertex_count() {
            return Err(SolverError::invalid(
                NAME,
                format!(
                    "the initial map has {} values, but the mesh has {} vertices",
                    z.len(),
                    mesh.vertex_count()
                ),
            ));
        }
        if let Some(v) = z.iter().position(|z| !z.is_finite()) {
            return Err(SolverError::invalid(
                NAME,
                format!("the initial map is not finite at vertex {v}"),
            ));
        }
    } else if problem.initial.is_some() {
        return Err(SolverError::unsupported(
            NAME,
            "extremal starts from a planar map",
        ));
    }
    Ok(boundary)
}

/// The images of each boundary loop of `mesh` under the boundary values `values` (every
/// boundary vertex has one), in the loop's order.
fn loop_curves(mesh: &Mesh, values: &[(VertexId, Complex64)]) -> Vec<Vec<[f64; 2]>> {
    let mut at = vec![None; mesh.vertex_count()];
    for &(v, z) in values {
        at[v.idx()] = Some([z.re, z.im]);
    }
    mesh.boundary_loop_list()
        .iter()
        .map(|l| l.vertices.iter().filter_map(|v| at[v.idx()]).collect())
        .collect()
}

/// Refuses boundary values that turn a boundary loop the other way than `domain` (the
/// planar source or its flat layout) does: the map would reverse the orientation.
fn same_turn(domain: &Mesh, values: &[(VertexId, Complex64)]) -> Result<(), SolverError> {
    let own: Vec<(VertexId, Complex64)> = domain
        .vertices()
        .filter(|&v| domain.is_boundary_vertex(v))
        .map(|v| {
            let p = domain.position(v);
            (v, Complex64::new(p.x, p.y))
        })
        .collect();
    let given = loop_curves(domain, values);
    for (k, (curve, layout)) in given.iter().zip(loop_curves(domain, &own)).enumerate() {
        let (a, b) = (signed_area(curve), signed_area(&layout));
        if a * b < 0.0 {
            return Err(SolverError::invalid(
                NAME,
                format!(
                    "the boundary map turns boundary loop {k} the other way than the surface does (signed area {a:.3e} against {b:.3e} in the loop's order): the map would reverse the orientation; mirror the map or reverse the surface's faces"
                ),
            ));
        }
    }
    Ok(())
}

/// The start map on `mesh` (the source or its flat copy): the given one with the
/// prescribed boundary values, or the harmonic (cotangent) or Tutte (uniform) map with
/// those values.
fn start_map(
    mesh: &Mesh,
    problem: &Problem<'_>,
    fixed: &[(VertexId, Complex64)],
    init: &str,
    options: SolveOptions,
) -> Result<Vec<Complex64>, SolverError> {
    if let Some(Map::Planar(z)) = &problem.initial {
        let mut z = z.clone();
        for &(v, w) in fixed {
            z[v.idx()] = w;
        }
        return Ok(z);
    }
    let weights = if init == "tutte" {
        EdgeWeights::uniform(mesh)
    } else {
        EdgeWeights::cotangent(mesh).map_err(|error| SolverError::Weights {
            solver: NAME,
            error,
        })?
    };
    let boundary = BoundaryMap {
        vertices: fixed.iter().map(|&(v, _)| v).collect(),
        positions: fixed.iter().map(|&(_, z)| z).collect(),
    };
    Ok(WeightedMeanSystem::new(&weights, &boundary)?.solve(options)?)
}

/// `mu` of the iteration's map: in the global frame of a planar source, or measured on
/// the curved source in its face frames when the map was computed on its flattening.
fn measure(
    mesh: &Mesh,
    flat: Option<&Flattening>,
    run: &Algorithm<'_>,
) -> Result<Distortion, SolverError> {
    if flat.is_none() {
        return run.distortion();
    }
    let elements = Elements::new(mesh, Frame::Face)?;
    let d = planar_map(&elements, mesh.vertex_count(), &run.map)?;
    Ok(Distortion::from_derivatives(&elements, &d)?)
}

/// The stopping rule and the linear-solver options of Algorithm 1.
#[derive(Debug, Clone, Copy)]
struct Parameters {
    tolerance: f64,
    max_iters: usize,
    inner_iters: usize,
    options: SolveOptions,
}

/// What the iteration did.
struct Outcome {
    iterations: usize,
    energy_history: Vec<f64>,
    step_sizes: Vec<f64>,
    stop: Stop,
    factorizations: usize,
}

/// The state of Algorithm 1: the map `f`, the harmonic form `x` with its per-face
/// values `psi = conj(phi)`, the dilatation `k`, and the two reusable systems.
struct Algorithm<'a> {
    mesh: &'a Mesh,
    elements: Elements,
    areas: Vec<f64>,
    forms: HarmonicForms,
    form_step: FormStep,
    pattern: Pattern,
    /// Per entry of the f-step operator: `(d/dz, d/dzbar)` of the shape function.
    derivative_entries: Vec<(Complex64, Complex64)>,
    map_step: MapStep,
    parameters: Parameters,
    map: Vec<Complex64>,
    fz: Vec<Complex64>,
    fzbar: Vec<Complex64>,
    x: Vec<f64>,
    psi: Vec<Complex64>,
    k: f64,
    factorizations: usize,
}

/// `psi / |psi|`, and 0 where `psi` vanishes (a zero of the quadratic differential,
/// where the direction of stretch is undefined).
fn direction(psi: Complex64, floor: f64) -> Complex64 {
    let r = psi.norm();
    if r > floor {
        psi / r
    } else {
        Complex64::new(0.0, 0.0)
    }
}

/// `1e-14 max |psi|`: below it `psi` counts as zero.
fn floor_of(psi: &[Complex64]) -> f64 {
    1e-14 * psi.iter().fold(0.0_f64, |m, p| m.max(p.norm()))
}

/// The f-step's least-squares system.
enum MapStep {
    /// Every boundary vertex fixed: one complex system, factored symbolically once.
    Fixed(Box<LeastSquaresSolver<Complex64>>),
    /// The four-point problem: the real form with the landmarks fixed and the other
    /// boundary vertices sliding.
    Sliding(Box<SlidingStep>),
}

/// The f-step of the sliding disk: `x = [re, im]` per vertex, the landmarks fixed, every
/// other boundary vertex `p` moving along the tangent `i p` of the unit circle and
/// projected back onto it after the solve. The slide directions change with the map, so
/// each step builds its DOF map anew; the unknowns stay, so the symbolic factorization
/// of the first step is kept ([`LeastSquaresSolver::update_dofs`]).
struct SlidingStep {
    /// The real operator's pattern: four entries per complex entry.
    pattern: Pattern,
    landmarks: Vec<(VertexId, Complex64)>,
    sliding: Vec<VertexId>,
    /// The face areas, once per real row.
    weights: Vec<f64>,
    options: SolveOptions,
    solver: Option<LeastSquaresSolver<f64>>,
}

impl SlidingStep {
    fn new(
        rows: usize,
        nodes: usize,
        positions: &[(usize, usize)],
        quad: &Quadrilateral,
        areas: &[f64],
        options: SolveOptions,
    ) -> Result<Self, SolverError> {
        let real: Vec<(usize, usize)> = positions
            .iter()
            .flat_map(|&(r, c)| {
                [
                    (2 * r, 2 * c),
                    (2 * r, 2 * c + 1),
                    (2 * r + 1, 2 * c),
                    (2 * r + 1, 2 * c + 1),
                ]
            })
            .collect();
        Ok(Self {
            pattern: Pattern::new(2 * rows, 2 * nodes, &real)?,
            landmarks: quad.landmarks(),
            sliding: quad.sliding(),
            weights: areas.iter().flat_map(|&a| [a, a]).collect(),
            options,
            solver: None,
        })
    }

    /// The least-squares map of the complex operator entries `values` (in the order of
    /// the complex pattern) from `map`, written into `map`.
    fn solve(&mut self, values: &[Complex64], map: &mut [Complex64]) -> Result<(), SolverError> {
        // (c) (x + i y) = (c.re x - c.im y) + i (c.im x + c.re y).
        let real: Vec<f64> = values
            .iter()
            .flat_map(|c| [c.re, -c.im, c.im, c.re])
            .collect();
        let operator = self.pattern.assemble(&real)?;
        let mut constraints = DofConstraints::new();
        for &(v, w) in &self.landmarks {
            constraints.fix(v, w);
        }
        for &v in &self.sliding {
            let p = map[v.idx()] / map[v.idx()].norm();
            constraints.slide(v, p, Complex64::i() * p);
        }
        let dofs = DofMap::real(map.len(), &constraints)?;
        let solver = match &mut self.solver {
            Some(solver) => {
                solver.update_dofs(&dofs)?;
                solver
            }
            None => self.solver.insert(LeastSquaresSolver::new(
                self.pattern.symbolic().as_ref(),
                &dofs,
                self.options,
            )?),
        };
        let mut x: Vec<f64> = map.iter().flat_map(|z| [z.re, z.im]).collect();
        let zero = vec![0.0; operator.nrows()];
        solver.solve_into(operator.as_ref(), Some(&self.weights), &zero, &mut x)?;
        for (z, xy) in map.iter_mut().zip(x.chunks_exact(2)) {
            *z = Complex64::new(xy[0], xy[1]);
        }
        for &v in &self.sliding {
            map[v.idx()] /= map[v.idx()].norm();
        }
        Ok(())
    }
}

impl<'a> Algorithm<'a> {
    fn new(
        mesh: &'a Mesh,
        boundary: &Boundary,
        map: Vec<Complex64>,
        parameters: Parameters,
    ) -> Result<Self, SolverError> {
        let elements = Elements::new(mesh, Frame::Global)?;
        let areas: Vec<f64> = elements.points().iter().map(|q| q.weight).collect();
        let weights = EdgeWeights::cotangent(mesh).map_err(|error| SolverError::Weights {
            solver: NAME,
            error,
        })?;
        let forms = HarmonicForms::new(mesh, &elements, &weights);
        let form_step = FormStep::new(&forms)?;
        let mut positions = Vec::with_capacity(3 * elements.point_count());
        let mut derivative_entries = Vec::with_capacity(3 * elements.point_count());
        for (row, q) in elements.points().iter().enumerate() {
            for (k, v) in elements.nodes(q.face).iter().enumerate() {
                let g = q.grad[k];
                positions.push((row, v.idx()));
                derivative_entries.push((
                    Complex64::new(0.5 * g.x, -0.5 * g.y),
                    Complex64::new(0.5 * g.x, 0.5 * g.y),
                ));
            }
        }
        let pattern = Pattern::new(elements.point_count(), mesh.vertex_count(), &positions)?;
        let map_step = match boundary {
            Boundary::Fixed(fixed) => {
                let mut constraints = DofConstraints::new();
                for &(v, z) in fixed {
                    constraints.fix(v, z);
                }
                let dofs = DofMap::complex(mesh.vertex_count(), &constraints)?;
                MapStep::Fixed(Box::new(LeastSquaresSolver::new(
                    pattern.symbolic().as_ref(),
                    &dofs,
                    parameters.options,
                )?))
            }
            Boundary::Sliding(quad) => MapStep::Sliding(Box::new(SlidingStep::new(
                elements.point_count(),
                mesh.vertex_count(),
                &positions,
                quad,
                &areas,
                parameters.options,
            )?)),
        };
        let mut algorithm = Self {
            mesh,
            elements,
            areas,
            forms,
            form_step,
            pattern,
            derivative_entries,
            map_step,
            parameters,
            map,
            fz: Vec::new(),
            fzbar: Vec::new(),
            x: Vec::new(),
            psi: Vec::new(),
            k: 0.0,
            factorizations: 0,
        };
        algorithm.update_derivatives()?;
        if let Boundary::Sliding(quad) = boundary {
            algorithm.psi =
                quad.quadratic_differential(mesh, &algorithm.elements, parameters.options)?;
            algorithm.x = Vec::new();
        } else {
            // Algorithm 1's start: h minimizing the energy with s = 1 and k = 1.
            let b = algorithm.fz.clone();
            algorithm.x = algorithm.solve_form(&b)?;
            algorithm.psi = algorithm.forms.psi(&algorithm.x);
        }
        algorithm.update_k();
        Ok(algorithm)
    }

    fn update_derivatives(&mut self) -> Result<(), SolverError> {
        let d = planar_map(&self.elements, self.mesh.vertex_count(), &self.map)?;
        self.fz = d.iter().map(|d| d.fz).collect();
        self.fzbar = d.iter().map(|d| d.fzbar).collect();
        Ok(())
    }

    fn solve_form(&mut self, b: &[Complex64]) -> Result<Vec<f64>, SolverError> {
        self.factorizations += 1;
        Ok(self
            .form_step
            .solve(&self.forms, &self.fzbar, b, &self.areas)?)
    }

    /// `E = sum_m A_m |f_zbar - k psi_m/|psi_m| f_z|^2` (eq. 9) for the per-face values
    /// `psi` and `k`.
    fn energy_of(&self, psi: &[Complex64], k: f64) -> f64 {
        let floor = floor_of(psi);
        psi.iter()
            .zip(&self.fz)
            .zip(&self.fzbar)
            .zip(&self.areas)
            .map(|(((&p, &fz), &fzbar), &a)| a * (fzbar - k * direction(p, floor) * fz).norm_sqr())
            .sum()
    }

    fn energy(&self) -> f64 {
        self.energy_of(&self.psi, self.k)
    }

    /// The optimal `k` for the current map and directions (eq. 12, Proposition 3):
    /// `k = sum A Re(conj(mu_hat f_z) f_zbar) / sum A |f_z|^2`. A negative `k` is the
    /// same map with the opposite form: the form's sign is flipped to keep `k >= 0`.
    fn update_k(&mut self) {
        let floor = floor_of(&self.psi);
        let (mut num, mut den) = (0.0, 0.0);
        for (((&p, &fz), &fzbar), &a) in self
            .psi
            .iter()
            .zip(&self.fz)
            .zip(&self.fzbar)
            .zip(&self.areas)
        {
            num += a * ((direction(p, floor) * fz).conj() * fzbar).re;
            den += a * fz.norm_sqr();
        }
        let k = if den > 0.0 { num / den } else { 0.0 };
        if k < 0.0 {
            self.x.iter_mut().for_each(|x| *x = -*x);
            self.psi.iter_mut().for_each(|p| *p = -*p);
        }
        self.k = k.abs();
    }

    /// One h-step: the new form for the current `s = 1/|psi|`, `k` and map, the line
    /// search between the old and the new form with `s` projected back to `1/|psi(t)|`,
    /// then `k` (eq. 12). Returns the step `t`.
    fn form_step(&mut self) -> Result<f64, SolverError> {
        let floor = floor_of(&self.psi);
        let b: Vec<Complex64> = self
            .psi
            .iter()
            .zip(&self.fz)
            .map(|(&p, &fz)| self.k * fz / p.norm().max(floor.max(f64::MIN_POSITIVE)))
            .collect();
        let x_new = self.solve_form(&b)?;
        let psi_new = self.forms.psi(&x_new);
        let blend = |t: f64| -> Vec<Complex64> {
            self.psi
                .iter()
                .zip(&psi_new)
                .map(|(&a, &b)| a * (1.0 - t) + b * t)
                .collect()
        };
        let energy = |t: f64| self.energy_of(&blend(t), self.k);
        let t = golden_section(energy, 40);
        let t = [t, 1.0]
            .into_iter()
            .fold((0.0, energy(0.0)), |best, t| {
                let e = energy(t);
                if e < best.1 { (t, e) } else { best }
            })
            .0;
        self.psi = blend(t);
        self.x = self
            .x
            .iter()
            .zip(&x_new)
            .map(|(&a, &b)| a * (1.0 - t) + b * t)
            .collect();
        self.update_k();
        Ok(t)
    }

    /// The f-step: the least-squares map for `mu = k psi / |psi|` with the boundary
    /// fixed (the LSQC system, refilled into its fixed pattern).
    fn map_step(&mut self) -> Result<(), SolverError> {
        let floor = floor_of(&self.psi);
        let mut values = Vec::with_capacity(self.derivative_entries.len());
        for (q, p) in self.elements.points().iter().zip(&self.psi) {
            let mu = self.k * direction(*p, floor);
            let start = values.len();
            let n = self.elements.nodes(q.face).len();
            for &(dz, dzbar) in &self.derivative_entries[start..start + n] {
                values.push(dzbar - mu * dz);
            }
        }
        match &mut self.map_step {
            MapStep::Fixed(solver) => {
                let operator = self.pattern.assemble(&values)?;
                let zero = vec![Complex64::new(0.0, 0.0); operator.nrows()];
                solver.solve_into(operator.as_ref(), Some(&self.areas), &zero, &mut self.map)?;
            }
            MapStep::Sliding(step) => step.solve(&values, &mut self.map)?,
        }
        self.factorizations += 1;
        self.update_derivatives()?;
        self.update_k();
        Ok(())
    }

    /// The outer loop of Algorithm 1, until the relative energy decrease of an outer
    /// iteration falls below the tolerance, the iteration limit, or cancellation.
    fn iterate(&mut self, context: &mut Context<'_>) -> Result<Outcome, SolverError> {
        let Parameters {
            tolerance,
            max_iters,
            inner_iters,
            ..
        } = self.parameters;
        let mut energy = self.energy();
        let mut energy_history = vec![energy];
        let mut step_sizes = Vec::new();
        let mut stop = Stop::IterationLimit;
        let mut iterations = 0;
        while iterations < max_iters {
            if context.is_cancelled() {
                stop = Stop::Cancelled;
                break;
            }
            let before = energy;
            // The four-point problem's quadratic differential is fixed by the source
            // ([`crate::quadrilateral`]): no h-steps.
            let sliding = matches!(self.map_step, MapStep::Sliding(_));
            let inner_iters = if sliding { 0 } else { inner_iters };
            for _ in 0..inner_iters {
                let inner_before = energy;
                step_sizes.push(self.form_step()?);
                energy = self.energy();
                if inner_before - energy <= tolerance * inner_before {
                    break;
                }
            }
            self.map_step()?;
            energy = self.energy();
            iterations += 1;
            energy_history.push(energy);
            context.report(&Progress {
                stage: "extremal",
                done: iterations,
                total: Some(max_iters),
                energy: Some(energy),
            });
            if before - energy <= tolerance * before {
                stop = Stop::Converged { tolerance };
                break;
            }
        }
        Ok(Outcome {
            iterations,
            energy_history,
            step_sizes,
            stop,
            factorizations: self.factorizations,
        })
    }

    fn distortion(&self) -> Result<Distortion, SolverError> {
        let d = planar_map(&self.elements, self.mesh.vertex_count(), &self.map)?;
        Ok(Distortion::from_derivatives(&self.elements, &d)?)
    }

    /// `phi = conj(psi)` per face, scaled to an area-weighted mean `|phi|` of 1 (a
    /// quadratic differential of a Teichmueller map is fixed up to a positive factor).
    fn quadratic_differential(&self) -> QuadraticDifferential {
        let total: f64 = self.areas.iter().sum();
        let mean: f64 = self
            .psi
            .iter()
            .zip(&self.areas)
            .map(|(p, a)| a * p.norm())
            .sum::<f64>()
            / total;
        let scale = if mean > 0.0 { 1.0 / mean } else { 1.0 };
        QuadraticDifferential {
            frame: Frame::Global,
            values: self.psi.iter().map(|p| p.conj() * scale).collect(),
        }
    }
}

/// The minimizer of `f` on `[0, 1]` by golden-section search (`steps` reductions).
fn golden_section(f: impl Fn(f64) -> f64, steps: usize) -> f64 {
    let ratio = (5.0_f64.sqrt() - 1.0) / 2.0;
    let (mut a, mut b) = (0.0, 1.0);
    let mut c = b - ratio * (b - a);
    let mut d = a + ratio * (b - a);
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..steps {
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - ratio * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + ratio * (b - a);
            fd = f(d);
        }
    }
    0.5 * (a + b)
}
