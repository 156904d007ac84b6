//! Running the flow on a problem from an initial map: what every solver that flows a
//! map on a target composes ([`solve`]), with its options ([`OPTIONS`]) and what it
//! accepts ([`ACCEPTS`]).

use beltrami_core::{
    Accepts, AnnulusRadius, ConstraintKind, Context, Element, Extras, GoalKind, Map, Metrics,
    OptionKind, OptionSpec, Output, Problem, Report, Settings, Solution, SolverError, THREADS,
    Target, TargetKind, Topology,
};
use beltrami_fem::{BeltramiField, DistortionStats, Elements, Frame, MuError};
use beltrami_mesh::{Mesh, Point3, VertexId};
use beltrami_sparse::SolveOptions;
use beltrami_spatial::SurfaceIndex;
use num_complex::Complex64;

use crate::flow::{self, FlatRule, FlowOptions, FlowProblem, FlowRun, Stop};
use crate::measure::{Barrier, ImageFace, Objective, image_faces};
use crate::mesh_target::MeshTarget;
use crate::setup::{Domain, curve_roles, diagonal, domain, goals, mesh_roles, pins, region_roles};
use crate::system::{FlowSystem, VertexOrder};
use crate::target::{INNER, OUTER, Role, TargetGeometry};
use crate::untangle::{UntangleRounds, Untangled, untangle, untangle_patches};
use crate::validate::validate;

/// The flow's options.
pub const OPTIONS: &[OptionSpec] = &[
    OptionSpec {
        name: "tolerance",
        kind: OptionKind::Float {
            default: 1e-6,
            min: 0.0,
            max: 1.0,
        },
        help: "stop when the largest vertex update is below this, relative to the target's size",
    },
    OptionSpec {
        name: "max-iters",
        kind: OptionKind::Int {
            default: 500,
            min: 0,
            max: 1_000_000,
        },
        help: "flow steps at most",
    },
    OptionSpec {
        name: "max-move",
        kind: OptionKind::Float {
            default: 0.05,
            min: 1e-9,
            max: 1.0,
        },
        help: "on a target mesh, the largest vertex move tried in one step, relative to the target's bounding-box diagonal",
    },
    OptionSpec {
        name: "min-step",
        kind: OptionKind::Float {
            default: 8.881_784_197_001_252e-16,
            min: 0.0,
            max: 1.0,
        },
        help: "the smallest step size tried (2^-50: below it a step is lost in rounding)",
    },
    OptionSpec {
        name: "tilt-penalty",
        kind: OptionKind::Float {
            default: 0.0,
            min: 0.0,
            max: 1e6,
        },
        help: "on curved targets, how strongly each step keeps the area of faces tilted over 66 degrees from the target's normal (0: not at all; 1 halves the four-boundary faces' time, flows stall less and run longer)",
    },
    OptionSpec {
        name: "step-threads",
        kind: OptionKind::Int {
            default: 0,
            min: 0,
            max: 256,
        },
        help: "threads that move, project and measure each trial step (0: one per core; the map is the same for any number)",
    },
    THREADS,
];

/// What the flow accepts.
pub const ACCEPTS: Accepts = Accepts {
    elements: &[Element::Triangle],
    topologies: Topology::CONNECTED,
    targets: &[
        TargetKind::PlaneKeep,
        TargetKind::PlaneCircle,
        TargetKind::PlaneSquare,
        TargetKind::PlanePolygon,
        TargetKind::Disk,
        TargetKind::Annulus,
        TargetKind::Sphere,
        TargetKind::Mesh,
    ],
    goals: &[
        GoalKind::Conformal,
        GoalKind::ConformalLp,
        GoalKind::Prescribed,
    ],
    constraints: &[
        ConstraintKind::Hold,
        ConstraintKind::Landmark,
        ConstraintKind::OpenCurve,
    ],
};

/// Flows `initial` (the images of the source's vertices in R^3: `z = 0` for planar
/// targets; on the target for the sphere and target meshes) on `problem`'s target
/// towards its goal, and measures the result. `report` receives the stage timings and
/// notes (a solver's own stages before this one stay first).
///
/// Reads: `goal` (`Conformal { 2 <= p <= 100 }` or `Prescribed(field)`), `target`
/// (`Plane(Keep | Square | Polygon | Circle)`, `Disk`, `Annulus`, `Sphere`, `Mesh` with
/// `problem.initial` a map onto it, open feature curves and landmarks), pins without
/// positions (held where `initial` puts them) and the options ([`OPTIONS`], resolved in
/// `settings`). Checks the problem first ([`crate::validate()`]). `vertex_order`, when
/// given, is the [`VertexOrder`] of the source (one the caller computed alongside its
/// initial map); without it the flow orders the vertices itself.
pub fn solve(
    problem: &Problem<'_>,
    settings: &Settings,
    initial: Vec<Point3<f64>>,
    vertex_order: Option<&VertexOrder>,
    mut report: Report,
    context: &mut Context<'_>,
) -> Result<Solution, SolverError> {
    let goal = validate(problem)?;
    let mesh = problem.source;
    let mut metrics = Metrics::default();
    let mut extras = Extras::default();
    let elements = context.stage("elements", &mut report, || {
        Ok(Elements::new(mesh, goal.frame)?)
    })?;
    if initial.len() != mesh.vertex_count() {
        return Err(SolverError::invalid(
            crate::NAME,
            format!(
                "the initial map has {} images for {} vertices",
                initial.len(),
                mesh.vertex_count()
            ),
        ));
    }
    let threads = settings.int("threads");
    let step_threads = match settings.int("step-threads") {
        0 => beltrami_mesh::parallel::available_threads(),
        n => n,
    };
    let barrier = match problem.target {
        Target::Sphere | Target::Mesh(_) => Barrier::AREA_WEIGHTED,
        _ => Barrier::PLANAR,
    };
    let objective = Objective::new(elements.face_areas(), goal.sigma.clone(), goal.p, barrier);
    let options = SolveOptions {
        threads,
        ..SolveOptions::default()
    };
    let runner = Runner {
        elements: &elements,
        objective: &objective,
        problem,
        settings,
        options,
        untangle_trials: false,
        step_threads,
        vertex_order,
    };
    let input = |v: VertexId| mesh.vertex_map().to_input(v);
    let pins = pins(problem, &initial);
    let given = problem.constraints.pins().count() + problem.constraints.landmarks().count();
    if given == 0 && !pins.is_empty() {
        let names: Vec<String> = pins.iter().map(|&v| input(v).to_string()).collect();
        report.notes.push(format!(
                "pinned vertices {} (input indices) where the initial map puts them, to fix the target's conformal automorphisms",
                names.join(", ")
            ));
    }
    let (map, faces_mu, flipped) = if let Target::Mesh(target) = &problem.target {
        runner.solve_on_mesh(target, initial, &pins, context, (&mut report, &mut metrics))?
    } else {
        runner.solve_on_domain(
            initial,
            &pins,
            context,
            (&mut report, &mut metrics),
            &mut extras,
        )?
    };
    finish_solution(
        (report, metrics, extras),
        goal.frame,
        &objective,
        faces_mu,
        &flipped,
        map,
    )
}

/// The number of faces `run` leaves flipped.
fn flipped_faces(run: &FlowRun<MeshTarget<'_>>) -> usize {
    run.faces.iter().filter(|f| f.flipped()).count()
}

/// Whether the error fell by at least [`STILL_FALLING`] of itself over the last
/// [`FALLING_STEPS`] steps, or the flow stopped within them: a flow stopped while still
/// falling, or at once, was blocked (by a face edge-on to the target); one that had
/// flattened out was done.
fn still_falling(history: &[f64]) -> bool {
    let n = history.len();
    n <= FALLING_STEPS
        || history[n - 1 - FALLING_STEPS] - history[n - 1]
            >= STILL_FALLING * history[n - 1 - FALLING_STEPS]
}

/// Steps over which [`still_falling`] measures the fall.
const FALLING_STEPS: usize = 3;

/// The relative fall of the error over [`FALLING_STEPS`] steps above which a stalled
/// flow counts as blocked (spot onto bunny: 8e-4 when it stalled; the koala onto a
/// sphere mesh: 9e-6 after 74 steps, where flowing on gained 1e-4 of the error in 12 s).
const STILL_FALLING: f64 = 1e-4;

/// Whether `new` ends with a lower error than `old`, without a flip, and with its
/// largest `|mu|` below the barrier's start or not above `old`'s.
fn lower_without_new_near_folds<G>(
    new: &FlowRun<G>,
    old: &FlowRun<G>,
    objective: &Objective,
) -> bool {
    let largest = |run: &FlowRun<G>| {
        run.faces
            .iter()
            .map(|f| f.own_mu().norm())
            .fold(0.0, f64::max)
    };
    !new.faces.iter().any(ImageFace::flipped)
        && new.final_energy() < old.final_energy()
        && largest(new) <= largest(old).max(objective.barrier_start)
}

/// The image faces of `image` on a target mesh (normals interpolated at the images).
fn mesh_image_faces(
    elements: &Elements,
    geometry: &MeshTarget<'_>,
    image: &[Point3<f64>],
) -> Vec<ImageFace> {
    let normals: Vec<_> = image.iter().map(|p| geometry.normal(p)).collect();
    let mut faces = Vec::with_capacity(elements.face_count());
    image_faces(elements, &normals, image, &mut faces, 1);
    faces
}

/// Untangles the faces of `image` marked flipped ([`untangle`], `faces` its image
/// faces) and notes what it did, naming them by `which` ("flipped", ...).
fn untangle_noted(
    which: &str,
    elements: &Elements,
    geometry: &MeshTarget<'_>,
    roles: &[Role],
    image: &mut [Point3<f64>],
    faces: &mut [ImageFace],
    report: &mut Report,
) -> Untangled {
    let mut normals: Vec<_> = image.iter().map(|p| geometry.normal(p)).collect();
    let done = untangle(
        elements,
        geometry,
        roles,
        image,
        &mut normals,
        faces,
        UntangleRounds {
            rounds: UNTANGLE_ROUNDS,
            previous: None,
        },
    );
    report.notes.push(format!(
        "untangled {}{which} faces to {} by moving {} vertices into the kernels of their stars",
        done.before, done.after, done.moves
    ));
    done
}

/// The solution with its measured `mu`, statistics, `|mu - target|` for a prescribed
/// goal, and a note on remaining flips.
fn finish_solution(
    (mut report, mut metrics, extras): (Report, Metrics, Extras),
    frame: Frame,
    objective: &Objective,
    faces_mu: Vec<Complex64>,
    flipped: &[bool],
    map: Map,
) -> Result<Solution, SolverError> {
    let stats = DistortionStats::new(&faces_mu, &objective.areas, flipped)?;
    if stats.flipped > 0 {
        report.notes.push(format!(
            "{} faces are flipped: the initial map had flips the flow could not remove",
            stats.flipped
        ));
    }
    let zero;
    let sigma = match &objective.sigma {
        Some(sigma) => sigma,
        None => {
            zero = vec![Complex64::default(); faces_mu.len()];
            &zero
        }
    };
    metrics.mu_error = Some(MuError::from_areas(&objective.areas, &faces_mu, sigma)?);
    metrics.mu = Some(BeltramiField::new(frame, faces_mu));
    metrics.distortion = Some(stats);
    Ok(Solution {
        output: Output::Map(map),
        metrics,
        extras,
        report,
    })
}

/// The relative damping of flows on a target mesh ([`FlowSystem::set_damping`]): there
/// nothing the user can pin fixes the target's conformal automorphisms (registration
/// gives no default pins), and a step along them must stay finite.
const MESH_DAMPING: f64 = 1e-9;

/// How often flips left by the flow on a target mesh are untangled
/// ([`crate::untangle`]) and the flow restarted.
const UNTANGLE_RESTARTS: usize = 3;

/// Rounds of one untangling.
const UNTANGLE_ROUNDS: usize = 8;

/// What every flow run of one solve shares.
#[derive(Clone, Copy)]
struct Runner<'a, 'p> {
    elements: &'a Elements,
    objective: &'a Objective,
    problem: &'a Problem<'p>,
    settings: &'a Settings,
    options: SolveOptions,
    /// [`FlowOptions::untangle_trials`] of the runs.
    untangle_trials: bool,
    /// [`FlowOptions::threads`] of the runs (option `step-threads`, 0 resolved).
    step_threads: usize,
    /// The source's vertex order, if the caller gave one.
    vertex_order: Option<&'a VertexOrder>,
}

/// What the flows onto a target mesh in one solve share besides their unknowns: the
/// target, the roles of the source's vertices, and the target's bounding-box diagonal
/// (the tolerances are relative to it).
struct MeshFlow<'a, 't> {
    geometry: &'a MeshTarget<'t>,
    roles: &'a [Role],
    scale: f64,
}

/// The map a solve found, ready for [`finish_solution`]: the map, the per-face `mu`
/// and flip flags.
type Outcome = (Map, Vec<Complex64>, Vec<bool>);

impl Runner<'_, '_> {
    /// Flows `initial` on the target mesh `target` (pinning `pins`): from the initial
    /// map untangled first when it has flips, and from it as it was if that leaves
    /// flips ([`Runner::run_on_mesh`]); then the patches of the faces still flipped
    /// ([`Runner::untangle_patches_and_flow`]).
    fn solve_on_mesh(
        &self,
        target: &Mesh,
        initial: Vec<Point3<f64>>,
        pins: &[VertexId],
        context: &mut Context<'_>,
        (report, metrics): (&mut Report, &mut Metrics),
    ) -> Result<Outcome, SolverError> {
        let index = context.stage("target index", report, || {
            SurfaceIndex::new(target)
                .map(|index| index.with_threads(self.step_threads))
                .map_err(|e| SolverError::invalid(crate::NAME, format!("the target mesh: {e}")))
        })?;
        let (curves, roles) = mesh_roles(self.problem, target, &initial, pins)?;
        let geometry = MeshTarget::new(&index, curves);
        let scale = diagonal(target.positions());
        // The flow takes no step that flips a face, so from a map without flips it keeps
        // none: a flipped initial map is untangled first. From the flipped start itself
        // the flow ended no lower on 6 of the 10 registration pairs of docs/register.md
        // and took up to four times as long (the bent 100K `g4_fertility` pair: 54 s
        // against 14 s, its flow dragging a flipped face's neighbours the wrong way past
        // a fixed landmark for 55 steps); it stays the fallback when flips remain.
        let faces = mesh_image_faces(self.elements, &geometry, &initial);
        let flipped_start = faces.iter().any(ImageFace::flipped);
        // One symbolic factorization serves every flow below (the roles do not change).
        let mut system = self.system(&geometry, &initial, roles.clone(), context, report)?;
        let mesh = MeshFlow {
            geometry: &geometry,
            roles: &roles,
            scale,
        };
        let mut run = self.run_on_mesh(
            &mut system,
            &mesh,
            initial.clone(),
            flipped_start.then_some(faces),
            context,
            (report, metrics),
        )?;
        let first = flipped_faces(&run);
        if first > 0 && flipped_start && !context.is_cancelled() {
            let again = self.run_on_mesh(
                &mut system,
                &mesh,
                initial,
                None,
                context,
                (report, metrics),
            )?;
            let second = flipped_faces(&again);
            let better =
                second < first || (second == first && again.final_energy() < run.final_energy());
            report.notes.push(format!(
                "the flow from the initial map untangled first left {first} flipped faces; from the initial map as it was, {second}: kept the {}",
                if better { "second" } else { "first" }
            ));
            if better {
                run = again;
            }
        }
        let run =
            self.untangle_patches_and_flow(&mut system, &mesh, run, context, (report, metrics))?;
        let points = geometry.locate_all(&run.image)?;
        let (_, faces_mu, flipped) = run.finish(false);
        Ok((Map::OnMesh(points), faces_mu, flipped))
    }

    /// The last resort for the faces `run` leaves flipped: their patches untangled at
    /// once, then the flow again from there, kept with fewer flips, or as few and a
    /// lower error; `run` otherwise.
    fn untangle_patches_and_flow<'t>(
        &self,
        system: &mut FlowSystem,
        mesh: &MeshFlow<'_, 't>,
        run: FlowRun<MeshTarget<'t>>,
        context: &mut Context<'_>,
        (report, metrics): (&mut Report, &mut Metrics),
    ) -> Result<FlowRun<MeshTarget<'t>>, SolverError> {
        let before = flipped_faces(&run);
        if before == 0 || context.is_cancelled() {
            return Ok(run);
        }
        let mut image = run.image.clone();
        let mut faces = run.faces.clone();
        let mut normals: Vec<_> = image.iter().map(|p| mesh.geometry.normal(p)).collect();
        let done = untangle_patches(
            self.elements,
            mesh.geometry,
            mesh.roles,
            &mut image,
            &mut normals,
            &mut faces,
        );
        report.notes.push(format!(
            "untangled the {} faces the flow left flipped to {} by moving {} vertices of the patches around them at once",
            done.before, done.after, done.moves
        ));
        if done.after >= done.before {
            return Ok(run);
        }
        let again = self.run_on_mesh(system, mesh, image, None, context, (report, metrics))?;
        let after = flipped_faces(&again);
        let kept = after < before || (after == before && again.final_energy() < run.final_energy());
        report.notes.push(format!(
            "the flow from the untangled patches left {after} flipped faces: kept {}",
            if kept { "it" } else { "the map before" }
        ));
        Ok(if kept { again } else { run })
    }

    /// Flows `initial` on the region, disk, annulus or sphere of the problem's target
    /// (pinning `pins`); a free inner radius of an annulus goes to `extras`.
    fn solve_on_domain(
        &self,
        initial: Vec<Point3<f64>>,
        pins: &[VertexId],
        context: &mut Context<'_>,
        (report, metrics): (&mut Report, &mut Metrics),
        extras: &mut Extras,
    ) -> Result<Outcome, SolverError> {
        let (problem, mesh) = (self.problem, self.problem.source);
        let planar = !matches!(problem.target, Target::Sphere);
        let domain = domain(problem, &initial)?;
        let image = initial;
        Ok(match domain {
            Domain::Region(g) => {
                let scale = diagonal(&image);
                let roles = region_roles(mesh, &g, &image, pins);
                self.run(g, roles, image, scale, context, (report, metrics))?
                    .finish(planar)
            }
            Domain::Disk(g) => {
                let roles = curve_roles(mesh, pins, |_| 0);
                self.run(g, roles, image, 1.0, context, (report, metrics))?
                    .finish(planar)
            }
            Domain::Annulus(g, outer) => {
                let roles = curve_roles(mesh, pins, |l| if l == outer { OUTER } else { INNER });
                let run = self.run(g, roles, image, 1.0, context, (report, metrics))?;
                if g.free_inner {
                    extras.annulus_radius = Some(AnnulusRadius {
                        radius: run.target.inner_radius,
                        initial: g.inner_radius,
                    });
                }
                run.finish(planar)
            }
            Domain::Sphere(g) => {
                let roles = curve_roles(mesh, pins, |_| 0);
                self.run(g, roles, image, 1.0, context, (report, metrics))?
                    .finish(planar)
            }
        })
    }

    /// Runs the flow on a target mesh from `image`, untangling its flips (the image's
    /// before the flow when `untangle_first` gives its image faces) and flowing again
    /// while the untangling removes some ([`UNTANGLE_RESTARTS`] times at most), every
    /// flow with the unknowns of `system` (built for `mesh.roles`).
    fn run_on_mesh<'t>(
        &self,
        system: &mut FlowSystem,
        mesh: &MeshFlow<'_, 't>,
        mut image: Vec<Point3<f64>>,
        untangle_first: Option<Vec<ImageFace>>,
        context: &mut Context<'_>,
        (report, metrics): (&mut Report, &mut Metrics),
    ) -> Result<FlowRun<MeshTarget<'t>>, SolverError> {
        let MeshFlow {
            geometry,
            roles,
            scale,
        } = *mesh;
        let elements = self.elements;
        // The first flow may untangle the flips of its trial steps: a sliver near a fold
        // blocks every step size otherwise. The flows after an untangling go without:
        // there it bought 2% of the mean for twice the time (koala onto spot 0.0260 ->
        // 0.0255 in 52 s instead of 26 s).
        let mut flow = |image,
                        untangle_trials,
                        context: &mut Context<'_>,
                        report: &mut Report,
                        metrics: &mut Metrics| {
            let runner = Runner {
                untangle_trials,
                ..*self
            };
            runner.run_with(
                system,
                geometry.clone(),
                image,
                scale,
                context,
                (report, metrics),
            )
        };
        if let Some(mut faces) = untangle_first {
            untangle_noted(
                " of the initial map's flipped",
                elements,
                geometry,
                roles,
                &mut image,
                &mut faces,
                report,
            );
        }
        let mut run = flow(image, true, context, report, metrics)?;
        for _ in 0..UNTANGLE_RESTARTS {
            let flipped = run.faces.iter().any(ImageFace::flipped);
            // A flow stalled without flips while its error still fell: a face edge-on to
            // the target flips under a step of any size along the flow. Untangled like a
            // flip, its vertices go into the kernels of their stars in the tangent
            // plane, and the flow goes on from there when that ends lower without a new
            // near-fold.
            let blocked = !flipped
                && matches!(run.stop, Stop::Stalled)
                && still_falling(&run.energy_history)
                && run.faces.iter().any(ImageFace::edge_on);
            if context.is_cancelled() || !(flipped || blocked) {
                break;
            }
            let mut image = run.image.clone();
            let mut faces = run.faces.clone();
            if blocked {
                for face in faces.iter_mut().filter(|f| f.edge_on()) {
                    face.mark_flipped();
                }
            }
            let which = if blocked {
                " edge-on (where the flow stalled)"
            } else {
                " flipped"
            };
            let done = untangle_noted(
                which, elements, geometry, roles, &mut image, &mut faces, report,
            );
            if done.after >= done.before || (blocked && done.after > 0) {
                break;
            }
            let again = flow(image, false, context, report, metrics)?;
            if blocked && !lower_without_new_near_folds(&again, &run, self.objective) {
                report.notes.push(
                    "the flow from the relaxed map did not end lower: kept the stalled one".into(),
                );
                break;
            }
            run = again;
        }
        Ok(run)
    }

    /// The flow's unknowns and symbolic factorization for `roles` on `target` (the
    /// stage "symbolic"), damped on a target mesh, with the tilt penalty of the
    /// settings.
    fn system<G: TargetGeometry>(
        &self,
        target: &G,
        image: &[Point3<f64>],
        roles: Vec<Role>,
        context: &mut Context<'_>,
        report: &mut Report,
    ) -> Result<FlowSystem, SolverError> {
        let mut system = context.stage("symbolic", report, || match self.vertex_order {
            Some(order) => FlowSystem::with_vertex_order(
                self.elements,
                target,
                image,
                roles,
                self.options,
                order,
            ),
            None => FlowSystem::new(self.elements, target, image, roles, self.options),
        })?;
        if matches!(self.problem.target, Target::Mesh(_)) {
            system.set_damping(MESH_DAMPING);
        }
        system.set_tilt_penalty(self.settings.float("tilt-penalty"));
        Ok(system)
    }

    /// Runs the flow on `target` from `image` with `roles` (tolerances relative to
    /// `scale`) and records its history in `report`.
    fn run<G: TargetGeometry>(
        &self,
        target: G,
        roles: Vec<Role>,
        image: Vec<Point3<f64>>,
        scale: f64,
        context: &mut Context<'_>,
        (report, metrics): (&mut Report, &mut Metrics),
    ) -> Result<FlowRun<G>, SolverError> {
        let mut system = self.system(&target, &image, roles, context, report)?;
        self.run_with(
            &mut system,
            target,
            image,
            scale,
            context,
            (report, metrics),
        )
    }

    /// [`Runner::run`] with the unknowns of `system`, built by [`Runner::system`] for
    /// this target's roles (a flow started again after an untangling reuses them).
    fn run_with<G: TargetGeometry>(
        &self,
        system: &mut FlowSystem,
        target: G,
        image: Vec<Point3<f64>>,
        scale: f64,
        context: &mut Context<'_>,
        (report, metrics): (&mut Report, &mut Metrics),
    ) -> Result<FlowRun<G>, SolverError> {
        let (elements, objective, problem) = (self.elements, self.objective, self.problem);
        let flow_options = self.flow_options(scale);
        let run = report.time("flow", || {
            flow::run(
                FlowProblem {
                    elements,
                    objective,
                    goals: &goals(problem),
                },
                target,
                system,
                image,
                flow_options,
                context,
            )
        });
        let run = run.map_err(undetermined)?;
        record_run(&run, &flow_options, report, metrics);
        Ok(run)
    }

    /// The options of a flow from the settings, with the tolerance and (on a target
    /// mesh) the largest move relative to `scale`.
    fn flow_options(&self, scale: f64) -> FlowOptions {
        let (problem, settings) = (self.problem, self.settings);
        FlowOptions {
            tolerance: settings.float("tolerance") * scale,
            max_iterations: settings.int("max-iters"),
            solve: self.options,
            max_move: if matches!(problem.target, Target::Mesh(_)) {
                settings.float("max-move") * scale
            } else {
                f64::INFINITY
            },
            min_step: settings.float("min-step"),
            untangle_trials: self.untangle_trials,
            threads: self.step_threads,
            flat: match problem.target {
                Target::Sphere | Target::Mesh(_) => FlatRule::CURVED,
                _ => FlatRule::PLANAR,
            },
        }
    }
}

/// A singular or indefinite flow system: too few vertices are pinned, which the error
/// says; other errors pass unchanged.
fn undetermined(e: SolverError) -> SolverError {
    match e {
        SolverError::Solve(
            beltrami_sparse::SolveError::Singular { .. }
            | beltrami_sparse::SolveError::NotPositiveDefinite { .. },
        ) => SolverError::invalid(
            crate::NAME,
            "the flow is not determined: pin more vertices (disk: one interior and one boundary vertex; annulus: one boundary vertex; sphere: three vertices)",
        ),
        e => e,
    }
}

/// Records `run` (made with `flow_options`): its timings and stop note in `report`, its
/// work, history and stop in `metrics` (a restarted flow, after untangling, continues
/// the history of the first).
fn record_run<G>(
    run: &FlowRun<G>,
    flow_options: &FlowOptions,
    report: &mut Report,
    metrics: &mut Metrics,
) {
    report
        .timings
        .push(("flow: solves".into(), run.solve_seconds));
    report
        .timings
        .push(("flow: steps".into(), run.step_seconds));
    metrics.iterations += run.iterations();
    metrics.factorizations = Some(metrics.factorizations.unwrap_or(0) + run.factorizations);
    metrics.cg_iterations = Some(metrics.cg_iterations.unwrap_or(0) + run.cg_iterations);
    metrics.energy_history.extend(&run.energy_history);
    metrics.step_sizes.extend(&run.step_sizes);
    metrics.stop = Some(match run.stop {
        Stop::Converged => beltrami_core::Stop::Converged {
            tolerance: flow_options.tolerance,
        },
        Stop::Stalled | Stop::Flat => beltrami_core::Stop::Stalled,
        Stop::IterationLimit => beltrami_core::Stop::IterationLimit,
        Stop::Cancelled => beltrami_core::Stop::Cancelled,
    });
    report.notes.push(stop_note(run, flow_options));
}

/// What the report says about why `run` (made with `flow_options`) stopped.
fn stop_note<G>(run: &FlowRun<G>, flow_options: &FlowOptions) -> String {
    match run.stop {
        Stop::Converged => format!(
            "converged after {} iterations: largest vertex update below {:.1e}",
            run.iterations(),
            flow_options.tolerance
        ),
        Stop::Stalled => format!(
            "stopped after {} iterations: no step above the tolerance decreased the error further",
            run.iterations()
        ),
        Stop::Flat => match flow_options.flat.steps {
            1 => format!(
                "stopped after {} iterations: the error fell by less than {:.0e} of itself in the last step",
                run.iterations(),
                flow_options.flat.decrease,
            ),
            steps => format!(
                "stopped after {} iterations: the error fell by less than {:.0e} of itself over the last {steps} steps",
                run.iterations(),
                flow_options.flat.decrease,
            ),
        },
        Stop::IterationLimit => format!(
            "stopped at the iteration limit ({}) before converging",
            run.iterations()
        ),
        Stop::Cancelled => format!(
            "cancelled after {} iterations: the map is the best one so far",
            run.iterations()
        ),
    }
}

impl<G> FlowRun<G> {
    /// The map, the per-face `mu` and flip flags.
    fn finish(self, planar: bool) -> (Map, Vec<Complex64>, Vec<bool>) {
        let mu = self.faces.iter().map(|f| f.own_mu()).collect();
        let flipped = self.faces.iter().map(|f| f.flipped()).collect();
        let map = if planar {
            Map::Planar(
                self.image
                    .iter()
                    .map(|p| Complex64::new(p.x, p.y))
                    .collect(),
            )
        } else {
            Map::Spatial(self.image)
        };
        (map, mu, flipped)
    }
}
