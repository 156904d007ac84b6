//! The solver `qcmc`: Algorithm 2 of Ho-Lui 2016 (crate docs).

use beltrami_core::{
    Accepts, Circle, Context, Element, Extras, Goal, GoalKind, Map, Metrics, OptionKind,
    OptionSpec, Output, Problem, Progress, Report, Settings, Solution, Solver, SolverError,
    SolverInfo, Stop, THREADS, TargetKind, Topology,
};
use beltrami_fem::beltrami::planar_map;
use beltrami_fem::element::check_planar;
use beltrami_fem::{BeltramiField, Distortion, Elements, FemError, Frame, MuError};
use beltrami_mesh::Mesh;
use beltrami_sparse::SolveOptions;
use num_complex::Complex64;

use crate::NAME;
use crate::initial::{CircleMap, Loops, initial_map};
use crate::system::{Step, StepSystem};

/// QCMC (crate docs): the map of a genus-0 mesh with `k >= 2` boundary loops onto a
/// circle domain, the centres and radii found with the map.
///
/// Reads: `goal` (`Conformal { p: 2 }` or `Prescribed(field)`), `target`
/// (`CircleDomain`), the options [`OPTIONS`]. The solution holds the planar map, the
/// circles (`extras.circles`, the outer unit circle first), `|mu|` and flips, the
/// energy after every iteration, the step sizes and why the iteration stopped, and for a
/// prescribed `mu` the error `|mu - target|`.
#[derive(Debug, Clone, Copy, Default)]
pub struct Qcmc;

/// The options of [`Qcmc`].
pub const OPTIONS: &[OptionSpec] = &[
    OptionSpec {
        name: "outer",
        kind: OptionKind::Int {
            default: 0,
            min: 0,
            max: u32::MAX as usize,
        },
        help: "the boundary loop mapped onto the unit circle: 1 + its index in the mesh's boundary-loop order (the CLI's --outer LOOP); 0 picks the longest loop",
    },
    OptionSpec {
        name: "tolerance",
        kind: OptionKind::Float {
            default: 1e-7,
            min: 0.0,
            max: 1.0,
        },
        help: "stop when no vertex, centre or radius moves more than this in a step (the outer circle has radius 1)",
    },
    OptionSpec {
        name: "max-iters",
        kind: OptionKind::Int {
            default: 200,
            min: 0,
            max: 1_000_000,
        },
        help: "iterations at most",
    },
    THREADS,
];

const ACCEPTS: Accepts = Accepts {
    elements: &[Element::Triangle],
    topologies: &[Topology::Annulus, Topology::MultiplyConnected],
    targets: &[TargetKind::CircleDomain],
    goals: &[GoalKind::Conformal, GoalKind::Prescribed],
    constraints: &[],
};

/// Halvings of the step tried before the iteration counts as stalled.
const HALVINGS: usize = 12;

/// What [`Qcmc`] is: its name, one line on what it computes, what it accepts and
/// its options.
const INFO: SolverInfo = SolverInfo {
    name: NAME,
    description: "quasiconformal map of a multiply-connected mesh onto a circle domain whose centres and radii are unknowns (Ho-Lui 2016)",
    accepts: ACCEPTS,
    options: OPTIONS,
};

impl Solver for Qcmc {
    fn info(&self) -> &'static SolverInfo {
        &INFO
    }

    fn check_problem(&self, problem: &Problem<'_>, settings: &Settings) -> Result<(), SolverError> {
        setup(problem, settings).map(|_| ())
    }

    fn run(
        &self,
        problem: &Problem<'_>,
        settings: &Settings,
        context: &mut Context<'_>,
    ) -> Result<Solution, SolverError> {
        let mesh = problem.source;
        let (field, loops) = setup(problem, settings)?;
        let mut report = Report::new(NAME);
        let mut metrics = Metrics::default();
        let options = SolveOptions {
            threads: settings.int("threads"),
            ..SolveOptions::default()
        };
        let tolerance = settings.float("tolerance");
        let max_iters = settings.int("max-iters");
        let held = loops.vertices[0][0];

        let (elements, mut state) = context.stage("initial map", &mut report, || {
            let elements = Elements::new(mesh, field.frame)?;
            let state = initial_map(mesh, &loops, options)?;
            Ok((elements, state))
        })?;
        let mut system = context.stage("assembly", &mut report, || {
            StepSystem::new(&elements, mesh.vertex_count(), &loops, held, options)
        })?;

        let mu = &field.mu;
        let energy = StepSystem::energy(&elements, mu, &state.map);
        metrics.energy_history.push(energy);
        let triangles = oriented_triangles(mesh, field.frame);
        if triangles.iter().map(|(_, s)| s).sum::<f64>() < 0.0 {
            // A planar mesh listed clockwise with a field in the global frame: the start
            // follows the faces' orientation, the energy the plane's; mirror the start.
            state.mirror();
        }
        metrics.initial_distortion = Some(measure(mesh, &elements, &state.map)?.stats);
        let mut current = Current {
            flips: flipped(&triangles, &state.map),
            near: near_folds(&elements, &state.map)?,
            state,
            energy,
        };
        let iterate = std::time::Instant::now();
        let descent = Descent {
            elements: &elements,
            mu,
            triangles: &triangles,
            tolerance,
            max_iters,
        };
        let (stop, factorizations) =
            descent.run(&mut system, &mut current, &mut metrics, context)?;
        let state = current.state;
        report
            .timings
            .push(("iterations".to_string(), iterate.elapsed().as_secs_f64()));
        metrics.stop = Some(stop);
        metrics.factorizations = Some(factorizations);

        // Not a cancellable stage: a cancelled run still returns its map, measured.
        let distortion = report.time("distortion", || measure(mesh, &elements, &state.map))?;
        if let Goal::Prescribed(_) = &problem.goal {
            metrics.mu_error = Some(MuError::new(&elements, &distortion.field.mu, &field.mu)?);
        }
        let input = |v| mesh.vertex_map().to_input(v);
        if loops.len() > 1 {
            report.notes.push(format!(
                "Moebius normalization: the circle of boundary loop {} is centred at 0 and vertex {} (input index) of the outer loop {} is at 1",
                loops.index[1],
                input(held),
                loops.index[0]
            ));
        }
        metrics.mu = Some(distortion.field);
        metrics.distortion = Some(distortion.stats);
        let circles = loops
            .index
            .iter()
            .zip(&state.circles)
            .map(|(&boundary_loop, c)| Circle {
                boundary_loop,
                center: c.center,
                radius: c.radius,
            })
            .collect();
        Ok(Solution {
            output: Output::Map(Map::Planar(state.map)),
            metrics,
            extras: Extras {
                circles: Some(circles),
                ..Extras::default()
            },
            report,
        })
    }
}

/// Every face's vertex indices and the sign its image must turn by: along the face's
/// own orientation (face frames), or along the source's own turn in the plane (global
/// frame).
fn oriented_triangles(mesh: &Mesh, frame: Frame) -> Vec<([usize; 3], f64)> {
    mesh.faces()
        .map(|f| {
            let (v, _) = mesh.face_vertex_array(f);
            let sign = match frame {
                Frame::Global => mesh.face_vector_area(f).z.signum(),
                Frame::Face => 1.0,
            };
            ([v[0].idx(), v[1].idx(), v[2].idx()], sign)
        })
        .collect()
}

/// Where the descent stands: the map, its energy, and its flips and near-folds, which
/// a step may not add to.
struct Current {
    /// The map and its circles.
    state: CircleMap,
    /// Its least-squares Beltrami energy.
    energy: f64,
    /// Its flipped triangles ([`flipped`]).
    flips: usize,
    /// Its near-folds ([`near_folds`]).
    near: usize,
}

/// The iteration of Algorithm 2 (crate docs): what every step reads.
struct Descent<'a> {
    /// The mesh's elements in the field's frame.
    elements: &'a Elements,
    /// The Beltrami coefficient the energy follows.
    mu: &'a [Complex64],
    /// Every face's vertex indices and the sign its image must turn by.
    triangles: &'a [([usize; 3], f64)],
    /// Stop when the largest move is at most this.
    tolerance: f64,
    /// Stop after this many iterations.
    max_iters: usize,
}

impl Descent<'_> {
    /// Steps from `current` until the iteration limit, a cancel, a step that finds no
    /// lower energy, or a move within the tolerance, each step recorded in `metrics`
    /// and reported to `context`: why it stopped and the factorizations made.
    fn run(
        &self,
        system: &mut StepSystem,
        current: &mut Current,
        metrics: &mut Metrics,
        context: &mut Context<'_>,
    ) -> Result<(Stop, usize), SolverError> {
        let mut factorizations = 0;
        let stop = loop {
            if metrics.iterations >= self.max_iters {
                break Stop::IterationLimit;
            }
            if context.is_cancelled() {
                break Stop::Cancelled;
            }
            let (step, _) = system.step(self.elements, self.mu, &current.state)?;
            factorizations += 1;
            let Some((trial, e, t)) = self.line_search(&step, system.loop_of(), current)? else {
                break Stop::Stalled;
            };
            let moved = largest_move(&current.state, &trial);
            current.flips = flipped(self.triangles, &trial.map);
            current.near = near_folds(self.elements, &trial.map)?;
            current.state = trial;
            current.energy = e;
            metrics.iterations += 1;
            metrics.energy_history.push(current.energy);
            metrics.step_sizes.push(t);
            context.report(&Progress {
                stage: "iteration",
                done: metrics.iterations,
                total: Some(self.max_iters),
                energy: Some(current.energy),
            });
            if moved <= self.tolerance {
                break Stop::Converged {
                    tolerance: self.tolerance,
                };
            }
        };
        Ok((stop, factorizations))
    }

    /// The first of the step lengths 1, 1/2, .. (`HALVINGS` halvings) whose map still
    /// bounds a circle domain, adds no flip nor near-fold and lowers the energy: that
    /// map, its energy and the step length; `None` when none does.
    fn line_search(
        &self,
        step: &Step,
        loop_of: &[Option<usize>],
        current: &Current,
    ) -> Result<Option<(CircleMap, f64, f64)>, SolverError> {
        let mut t = 1.0;
        for _ in 0..=HALVINGS {
            let trial = step.apply(&current.state, t, loop_of);
            if admissible(&trial)
                && flipped(self.triangles, &trial.map) <= current.flips
                && near_folds(self.elements, &trial.map)? <= current.near
            {
                let e = StepSystem::energy(self.elements, self.mu, &trial.map);
                if e < current.energy {
                    return Ok(Some((trial, e, t)));
                }
            }
            t *= 0.5;
        }
        Ok(None)
    }
}

/// The Beltrami field the energy uses (in the elements' frame) and the loops: the
/// capability check.
fn setup(
    problem: &Problem<'_>,
    settings: &Settings,
) -> Result<(BeltramiField, Loops), SolverError> {
    let mesh = problem.source;
    let field = match &problem.goal {
        Goal::Prescribed(field) => {
            field.check(mesh.face_count())?;
            if field.frame == Frame::Global
                && let Err(FemError::NotPlanar { vertex, z }) = check_planar(mesh)
            {
                return Err(SolverError::unsupported(
                    NAME,
                    format!(
                        "the Beltrami field is in the global frame, which needs a mesh in the plane z = 0, but vertex {vertex} has z = {z:e}; give the field in the face frame"
                    ),
                ));
            }
            field.clone()
        }
        Goal::Conformal { p } if *p == 2.0 => BeltramiField::zero(Frame::Face, mesh.face_count()),
        Goal::Conformal { p } => {
            return Err(SolverError::unsupported(
                NAME,
                format!(
                    "qcmc minimizes the least-squares (p = 2) Beltrami energy, not the L^{p} norm of mu"
                ),
            ));
        }
        Goal::Extremal => {
            return Err(SolverError::unsupported(
                NAME,
                "qcmc follows a prescribed Beltrami coefficient or mu = 0, not an extremal map",
            ));
        }
        Goal::Features(_) => {
            return Err(SolverError::unsupported(
                NAME,
                "qcmc follows a prescribed Beltrami coefficient or mu = 0; features are matched by register",
            ));
        }
    };
    if !matches!(
        Topology::of(mesh),
        Topology::Annulus | Topology::MultiplyConnected
    ) {
        return Err(SolverError::unsupported(
            NAME,
            format!(
                "qcmc maps connected genus-0 meshes with two or more boundary loops; this mesh has {}: use tutte, lscm or beltrami-flow for a disk, sphere for a closed genus-0 mesh",
                beltrami_core::topology::describe(mesh)
            ),
        ));
    }
    let outer = settings.int("outer").checked_sub(1);
    let loops = Loops::new(mesh, outer)?;
    Ok((field, loops))
}

/// `|mu|`, flips and the field of a planar map, in the elements' frame.
fn measure(
    mesh: &Mesh,
    elements: &Elements,
    map: &[num_complex::Complex64],
) -> Result<Distortion, SolverError> {
    let derivatives = planar_map(elements, mesh.vertex_count(), map)?;
    Ok(Distortion::from_derivatives(elements, &derivatives)?)
}

/// Whether the circles still bound a circle domain: positive radii, inner disks inside
/// the unit disk and apart from one another.
fn admissible(state: &CircleMap) -> bool {
    let inner = &state.circles[1..];
    inner.iter().enumerate().all(|(j, c)| {
        c.radius > 0.0
            && c.center.norm() + c.radius < 1.0
            && inner[..j]
                .iter()
                .all(|d| (c.center - d.center).norm() > c.radius + d.radius)
    }) && state.map.iter().all(|z| z.is_finite())
}

/// Number of triangles whose image turns against their sign (`+1`: counter-clockwise,
/// positive signed area): the flips a step may not add to.
fn flipped(triangles: &[([usize; 3], f64)], map: &[num_complex::Complex64]) -> usize {
    triangles
        .iter()
        .filter(|([a, b, c], sign)| {
            sign * ((map[*b] - map[*a]).conj() * (map[*c] - map[*a])).im <= 0.0
        })
        .count()
}

/// `|mu|` from which a face counts as a near-fold: its image is within a factor 200 of
/// collapsing onto a segment (`|mu| = (s1 - s2) / (s1 + s2)` with `s1 >= s2` the
/// singular values of the face's map).
const NEAR_FOLD: f64 = 0.99;

/// Number of faces whose image is a near-fold (`NEAR_FOLD <= |mu| < 1`): the least-squares
/// energy, weighted by the faces' areas, lets a step slide two boundary vertices of a
/// small circle together (measured on `mc8_peaks`: two vertices of loop 5 ended 7e-8
/// apart, a face at `|mu|` 0.99999), so a step may not add to them, as it may not add
/// to the flips.
fn near_folds(elements: &Elements, map: &[num_complex::Complex64]) -> Result<usize, SolverError> {
    Ok(planar_map(elements, map.len(), map)?
        .iter()
        .filter(|d| {
            let m = d.mu().norm();
            (NEAR_FOLD..1.0).contains(&m)
        })
        .count())
}

/// The largest move of a vertex, centre or radius between two states.
fn largest_move(a: &CircleMap, b: &CircleMap) -> f64 {
    let vertices = a
        .map
        .iter()
        .zip(&b.map)
        .map(|(x, y)| (x - y).norm())
        .fold(0.0, f64::max);
    a.circles
        .iter()
        .zip(&b.circles)
        .map(|(x, y)| {
            (x.center - y.center)
                .norm()
                .max((x.radius - y.radius).abs())
        })
        .fold(vertices, f64::max)
}
