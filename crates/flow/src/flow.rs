//! The flow iteration: measure, transport the adjustment to the target, solve for the
//! flow, step, project.
//!
//! Step `k` starts from the image `Y` of the source vertices on the target, with
//! Beltrami coefficient `mu_T` and `f_z` per face (in the image frame of
//! [`crate::measure`]), and the objective `E = sum_T A_T |mu_T - sigma_T|^p`.
//!
//! 1. Composition (Wong-Zhao 2014, eq. 3.5, 3.16-3.17). Composing the map with a
//!    homeomorphism `g` of the target with coefficient `tau` gives, to first order in
//!    `tau`,
//!    ```text
//!    mu(g o f) = mu + (1 - |mu|^2) theta tau,    theta = conj(f_z) / f_z,
//!    ```
//!    so the error `e_T = mu_T - sigma_T` is cancelled by
//!    `rho_T = (sigma_T - mu_T) / ((1 - |mu_T|^2) theta_T)` (eq. 3.17), on the image face.
//! 2. Flow (eq. 4.4, 6.1-6.9). `g = id + t V` has `tau = t V_zbar + O(t^2)`
//!    (Theorem 3.2), and [`FlowSystem`] finds the tangent field `V` minimizing
//!    `sum_T w_T |V_zbar - rho_T|^2` with
//!    ```text
//!    w_T = A_T (1 - |mu_T|^2)^2 max(|mu_T|, 1e-3)^(p - 2).
//!    ```
//!    These weights make the flow a Gauss-Newton step for `E`: `w_T |V_zbar - rho_T|^2`
//!    is `A_T |mu_T|^(p-2) |e_T + (1 - |mu_T|^2) theta_T V_zbar|^2`, the linearized
//!    error, reweighted for `p > 2` (the gradient of `sum A |mu|^p` is that of the
//!    reweighted `p = 2` sum at the current map). The paper weights by the image area;
//!    both have the same continuous limit, and these make the flow a descent direction
//!    for the error it is judged by.
//! 3. Step (section 4.4). The largest `t` in `{1, 1/2, 1/4, ...}` (on target meshes
//!    starting below the cap of [`FlowOptions::max_move`]) for which (while a landmark
//!    is still pulled towards its goal, only the first condition)
//!    `Y' = P(Y + t V)` (each vertex projected back onto the target by its role, a
//!    curve vertex slid along its curve by `t V` first) has no
//!    more flipped faces than `Y` and a smaller `E`. When no `t` qualifies and
//!    [`FlowOptions::untangle_trials`] is set, the search runs again with each trial's
//!    new flips untangled first ([`crate::untangle`], a vertex of a flipped face trying
//!    first its place before the step, then its star's kernel): a face near a fold
//!    whose source triangle is a sliver (`g0_bunny_closed` has four, height/length
//!    1e-4) has a `mu` so sensitive to its corners that the linearized flow folds it at
//!    every step size, and the step search stalled (bunny onto spot at mean `|mu|`
//!    0.330); putting back the few vertices that fold it keeps the rest of the step.
//!    The search starts below the first fold the flow predicts: moving the corners of
//!    each image face by `t V` makes its signed area a quadratic in `t`, both in its
//!    own frame and against its reference normal (the sum of its corners' target
//!    normals, which the flip test reads), and their smallest positive root over the
//!    faces not flipped now is where the first one turns over (`first_fold`). The
//!    second catches thin image triangles across a curved part of a target mesh, which
//!    tilt over the reference while their own plane turns with them (on `mc4_face_a`
//!    onto `mc4_face_b` remeshed to 100K faces every trial that flipped had such a face
//!    at `|mu|` 0.75-0.89, 67-80 degrees from its reference). The sizes above it are
//!    tried only when none from there down qualifies, so a stall means the same as with
//!    the full search. On a target mesh most trials from `t = 1` flipped tens of faces
//!    (`g0_koala` onto a 100K remesh of `g0_bunny_closed`: 6.5 trials a step, each a
//!    walk of every vertex). The first size below the fold is not tried when the faces
//!    near the fold (`near_fold_rise`: those whose own fold is within four times the
//!    first, their corners moved by `t V`) alone would raise `E` by more than the
//!    Gauss-Newton model predicts it falls, `(2 t - t^2) Q`
//!    ([`FlowSystem::model_decrease`]): on `mc4_face_a` onto `mc4_face_b` remeshed to
//!    100K faces, 90 of the 95 rejected trials of 100 steps were such sizes, `E` rising
//!    by the barrier of a face about to fold.
//! 4. Stop when the largest vertex update `t max_i |V_i|` is below the tolerance, or no
//!    step above it decreases `E`, or (conformal goals, whose `E` has the near-fold
//!    barrier) `E` fell by less than a [`FlatRule`]'s share of itself over its last
//!    steps, or the iteration limit is reached, or the solve is
//!    cancelled (the map so far is returned; every accepted step decreased `E`, so it is
//!    the best one seen).

use std::time::Instant;

use beltrami_core::{Context, Progress, SolverError};
use beltrami_fem::Elements;
use beltrami_mesh::{FaceId, Point3, Vector2, Vector3};
use beltrami_sparse::SolveOptions;
use num_complex::Complex64;

use crate::extension::HarmonicExtension;
use crate::measure::{
    ImageFace, Objective, edges_and_reference, image_face, image_faces, triangle,
};
use crate::system::{Flow, FlowInput, FlowSystem};
use crate::target::{Role, TargetGeometry};
use crate::untangle::{UntangleRounds, untangle};

/// Rounds of the untangling of a trial step's flips (item 3).
const REPAIR_ROUNDS: usize = 4;

/// Halvings of the step size beyond which the predicted first fold is not followed
/// (item 3 of the module docs): `2^-60` is below every useful step.
const MAX_HALVINGS: u32 = 60;

/// Faces whose predicted fold is within this many times the first one are the ones
/// [`near_fold_rise`] looks at.
const NEAR_FOLD_REACH: f64 = 4.0;

/// Most faces [`near_fold_rise`] looks at.
const NEAR_FOLD_FACES: usize = 256;

/// Smallest `|mu|` used in the `L^p` reweighting (`p > 2`), so that faces that are
/// already conformal keep a positive weight.
const MU_FLOOR: f64 = 1e-3;

/// When a negligible decrease of the error ends a flow with the near-fold barrier: near
/// the minimum the barrier's large weights make the Gauss-Newton steps tiny, and they
/// would otherwise run to the iteration limit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlatRule {
    /// Accepted steps the decrease is measured over.
    pub steps: usize,
    /// The decrease of `E` over those steps, relative to `E` before them, below which
    /// the flow ends.
    pub decrease: f64,
}

impl FlatRule {
    /// Onto a target mesh or the sphere: `E` fell by less than `1e-5` of itself over the
    /// last 5 steps. Registration flows keep lowering `E` by small steps for a while
    /// after a single step's decrease first looks negligible.
    pub const CURVED: Self = Self {
        steps: 5,
        decrease: 1e-5,
    };

    /// Onto planar targets (disk, polygon, annulus): `E` fell by less than `2e-3` of
    /// itself in the last step, so the `L^2` norm of `mu` (`sqrt E` without the barrier)
    /// by less than 0.1%. From the boundary-first start of a disk map that is after 3
    /// steps (human face) or 5 (hand), with the mean `|mu|` settled to 4 digits; the rule
    /// of [`FlatRule::CURVED`] ran 13-14 steps there, moving only the max `|mu|` within
    /// its step-to-step wobble (0.250-0.263 on the face).
    pub const PLANAR: Self = Self {
        steps: 1,
        decrease: 2e-3,
    };

    /// Whether `history` (`E` before the first step and after each accepted one) has
    /// gone flat.
    pub fn is_flat(&self, history: &[f64]) -> bool {
        let Some((&now, _)) = history.split_last() else {
            return false;
        };
        history
            .iter()
            .rev()
            .nth(self.steps)
            .is_some_and(|&before| before - now <= self.decrease * before)
    }
}

/// How the iteration ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stop {
    /// The largest vertex update fell below the tolerance.
    Converged,
    /// No step above the tolerance decreased the error.
    Stalled,
    /// The error (with the near-fold barrier: conformal goals only) went flat by the
    /// [`FlowOptions::flat`] rule.
    Flat,
    /// The iteration limit was reached.
    IterationLimit,
    /// Cancellation was requested.
    Cancelled,
}

/// Parameters of [`run`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlowOptions {
    /// Stop when the largest vertex update is below this (target units).
    pub tolerance: f64,
    /// Most iterations.
    pub max_iterations: usize,
    /// Options of the sparse factorizations.
    pub solve: SolveOptions,
    /// The largest vertex move tried (target units): the step-size search starts at
    /// `t = min(1, max_move / max_i |V_i|)`. Infinite for the fixed targets, where any
    /// trial is cheap; on a target mesh a trial that moves points across much of the
    /// surface costs a long walk and is not accepted anyway.
    pub max_move: f64,
    /// The smallest step size tried; below it a step is lost in rounding (`2^-50` by
    /// default).
    pub min_step: f64,
    /// Whether a step search that finds no step size runs again with each trial's new
    /// flips untangled first (item 3 of the module docs).
    pub untangle_trials: bool,
    /// Threads of the loops over faces of each trial step (the image faces; a target
    /// mesh's own batch queries follow its index's threads). The results are the same
    /// for any number.
    pub threads: usize,
    /// When a flow with the near-fold barrier has gone flat.
    pub flat: FlatRule,
}

/// The result of [`run`].
#[derive(Debug, Clone)]
pub struct FlowRun<G> {
    /// Final images of the source vertices.
    pub image: Vec<Point3<f64>>,
    /// The target after the flow (a free annulus radius has moved).
    pub target: G,
    /// Final image faces (their `mu` and flips).
    pub faces: Vec<ImageFace>,
    /// `E` before the first step and after each accepted step.
    pub energy_history: Vec<f64>,
    /// The step size `t` of each accepted step.
    pub step_sizes: Vec<f64>,
    /// The largest vertex update `t max_i |V_i|` of each accepted step.
    pub updates: Vec<f64>,
    /// Why it stopped.
    pub stop: Stop,
    /// Seconds spent assembling and solving the flow systems.
    pub solve_seconds: f64,
    /// Seconds spent stepping, projecting and measuring (the step-size search).
    pub step_seconds: f64,
    /// Numeric factorizations of the flow's normal equations.
    pub factorizations: usize,
    /// Conjugate-gradient iterations of steps solved with a kept factorization.
    pub cg_iterations: usize,
}

impl<G> FlowRun<G> {
    /// `E` after the last accepted step (before the first when none was).
    pub fn final_energy(&self) -> f64 {
        self.energy_history.last().copied().unwrap_or(f64::INFINITY)
    }

    /// Accepted steps.
    pub fn iterations(&self) -> usize {
        self.step_sizes.len()
    }
}

/// Gauss-Newton weights and targets of the flow (module docs, items 1-2).
fn weights_and_targets(
    objective: &Objective,
    faces: &[ImageFace],
    weights: &mut Vec<f64>,
    rho: &mut Vec<Complex64>,
) {
    weights.clear();
    rho.clear();
    for (f, face) in faces.iter().enumerate() {
        let mu = face.mu();
        let fz = face.derivatives.fz;
        let shrink = 1.0 - mu.norm_sqr();
        if fz.norm_sqr() == 0.0 || shrink.abs() < 1e-12 || !mu.is_finite() {
            weights.push(0.0);
            rho.push(Complex64::default());
            continue;
        }
        let error = mu - objective.sigma(f);
        let reweight = if objective.p == 2.0 {
            1.0
        } else {
            mu.norm().max(MU_FLOOR).powf(objective.p - 2.0)
        };
        let barrier = objective.barrier_area(f) * objective.barrier_weight(mu.norm());
        weights.push((objective.areas[f] * reweight + barrier) * shrink * shrink);
        // 1 / theta = f_z / conj(f_z).
        rho.push(-error * fz / (shrink * fz.conj()));
    }
}

/// The smallest `t > 0` at which an image face not flipped now turns over when its
/// corners move by `t V` (infinite when none does), for the image `image` with target
/// normals `normals` at its vertices. Two quadratics per face, each positive at
/// `t = 0`: with `e_1, e_2` its edge vectors from the first corner and `d_1, d_2` their
/// rates under `V`, the doubled signed area
/// `A(t) = e_1 x e_2 + t (e_1 x d_2 + d_1 x e_2) + t^2 d_1 x d_2`
/// in its own frame `(r, s)` (the corners' moves projected onto it), and the same
/// triple products `((e_1 + t d_1) x (e_2 + t d_2)) . n` in space against the face's
/// reference normal `n`, the sum of its corners' normals: the flip test of
/// [`crate::measure::image_face`] is the sign of that product, and a thin face tilted
/// steeply to `n` crosses it long before its own plane sees it fold.
///
/// `near` receives the faces whose fold is within [`NEAR_FOLD_REACH`] times the first,
/// nearest first, at most [`NEAR_FOLD_FACES`] of them.
fn first_fold(
    elements: &Elements,
    faces: &[ImageFace],
    flow: &[Vector3<f64>],
    image: &[Point3<f64>],
    normals: &[Vector3<f64>],
    near: &mut Vec<(f64, usize)>,
) -> f64 {
    near.clear();
    let mut first = f64::INFINITY;
    for (f, face) in faces.iter().enumerate() {
        if face.flipped() {
            continue;
        }
        let corners = triangle(elements, FaceId::from_usize(f)).map(|v| v.idx());
        let [a, b, c] = corners.map(|v| flow[v]);
        let (d1, d2) = (b - a, c - a);
        let local = |v: &Vector3<f64>| Vector2::new(v.dot(&face.r), v.dot(&face.s));
        let (e1, e2) = (face.local[1], face.local[2]);
        let cross = |u: &Vector2<f64>, v: &Vector2<f64>| u.x * v.y - u.y * v.x;
        let (l1, l2) = (local(&d1), local(&d2));
        let planar = (
            cross(&e1, &e2),
            cross(&e1, &l2) + cross(&l1, &e2),
            cross(&l1, &l2),
        );
        let (p, q, reference) = edges_and_reference(corners, image, normals);
        let triple = |u: &Vector3<f64>, v: &Vector3<f64>| u.cross(v).dot(&reference);
        let spatial = (
            triple(&p, &q),
            triple(&p, &d2) + triple(&d1, &q),
            triple(&d1, &d2),
        );
        for (c0, c1, c2) in [planar, spatial] {
            if c0 > 0.0 {
                let root = smallest_positive_root(c0, c1, c2);
                if root.is_finite() {
                    near.push((root, f));
                }
                first = first.min(root);
            }
        }
    }
    near.retain(|&(root, _)| root < NEAR_FOLD_REACH * first);
    // A face's two roots: its nearer one.
    near.sort_by(|a, b| a.1.cmp(&b.1).then(a.0.total_cmp(&b.0)));
    near.dedup_by_key(|&mut (_, f)| f);
    near.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    near.truncate(NEAR_FOLD_FACES);
    first
}

/// An image of the source vertices with the target's normals there and its image faces.
#[derive(Clone, Copy)]
struct ImageView<'a> {
    image: &'a [Point3<f64>],
    normals: &'a [Vector3<f64>],
    faces: &'a [ImageFace],
}

/// How much the faces `near` (from [`first_fold`]) alone raise `E` when their corners
/// move by `t V` (before any projection onto the target, at the present normals of
/// `map`); `None` when one of them turns over (the trial itself decides then). `probe`
/// is scratch as long as `map.image`: only the near faces' corners are read from it,
/// each written first and put back to `map.image` afterwards.
fn near_fold_rise(
    elements: &Elements,
    objective: &Objective,
    map: ImageView<'_>,
    near: &[(f64, usize)],
    flow: &[Vector3<f64>],
    t: f64,
    probe: &mut Vec<Point3<f64>>,
) -> Option<f64> {
    let ImageView {
        image,
        normals,
        faces,
    } = map;
    if probe.len() != image.len() {
        probe.clear();
        probe.extend_from_slice(image);
    }
    let corners = |f: usize| triangle(elements, FaceId::from_usize(f)).map(|v| v.idx());
    for &(_, f) in near {
        for v in corners(f) {
            probe[v] = image[v] + t * flow[v];
        }
    }
    let mut rise = Some(0.0);
    for &(_, f) in near {
        let moved = image_face(elements, normals, probe, FaceId::from_usize(f));
        if moved.flipped() {
            rise = None;
            break;
        }
        rise = rise
            .map(|r| r + objective.face_energy(f, &moved) - objective.face_energy(f, &faces[f]));
    }
    for &(_, f) in near {
        for v in corners(f) {
            probe[v] = image[v];
        }
    }
    rise
}

/// The smallest positive root of `c0 + c1 t + c2 t^2` with `c0 > 0` (infinite when
/// there is none), by the cancellation-free form of the quadratic formula.
fn smallest_positive_root(c0: f64, c1: f64, c2: f64) -> f64 {
    if c2 == 0.0 {
        return if c1 < 0.0 { -c0 / c1 } else { f64::INFINITY };
    }
    let discriminant = c1 * c1 - 4.0 * c2 * c0;
    if discriminant < 0.0 {
        return f64::INFINITY;
    }
    // Roots q / c2 and c0 / q with q = -(c1 + sign(c1) sqrt(disc)) / 2.
    let q = -0.5 * (c1 + c1.signum() * discriminant.sqrt());
    [q / c2, c0 / q]
        .into_iter()
        .filter(|&t| t > 0.0 && t.is_finite())
        .fold(f64::INFINITY, f64::min)
}

/// A trial step's map and the scratch of its making, kept from trial to trial.
#[derive(Default)]
struct Trial {
    /// The stepped images.
    image: Vec<Point3<f64>>,
    /// The target's normals at them.
    normals: Vec<Vector3<f64>>,
    /// Their image faces.
    faces: Vec<ImageFace>,
    /// The moves of the curve vertices by their slides (zero elsewhere), which the
    /// harmonic extension spreads into the interior.
    delta: Vec<Vector3<f64>>,
}

/// `P(Y + t V)`: the stepped images (into `trial`'s images and normals), projected by
/// role onto `target` moved by the offsets `t delta`, the boundary's projection spread
/// into the interior ([`HarmonicExtension`]) before the interior is projected. A curve
/// vertex slides along its curve by `t V` ([`TargetGeometry::slide`]).
fn step<G: TargetGeometry>(
    target: &G,
    roles: &[Role],
    image: &[Point3<f64>],
    flow: &Flow,
    t: f64,
    extension: Option<&mut HarmonicExtension>,
    trial: &mut Trial,
) -> Result<G, SolverError> {
    let Trial {
        image: out,
        normals,
        delta,
        ..
    } = trial;
    let mut moved = target.clone();
    for (c, &d) in flow.offset.iter().enumerate() {
        if d != 0.0 {
            moved.offset_curve(c, t * d);
        }
    }
    out.clear();
    out.extend(image.iter().zip(&flow.vertex).map(|(p, v)| p + t * v));
    delta.clear();
    delta.resize(out.len(), Vector3::zeros());
    for (((p, d), &role), (from, v)) in out
        .iter_mut()
        .zip(delta.iter_mut())
        .zip(roles)
        .zip(image.iter().zip(&flow.vertex))
    {
        if let Role::Curve(c) = role {
            let q = moved.slide(c, from, &(t * v));
            *d = q - *p;
            *p = q;
        }
    }
    if let Some(extension) = extension {
        extension.apply(delta, out)?;
    }
    moved.project_all(roles, Some(image), out, normals)?;
    Ok(moved)
}

/// What a flow run minimizes: `objective`, measured on the source `elements`, with
/// `goals` pulling fixed vertices (one per source vertex, `None` for a vertex without
/// one; an empty list for none at all).
#[derive(Clone, Copy)]
pub struct FlowProblem<'a> {
    /// The source's elements.
    pub elements: &'a Elements,
    /// The error `E` the flow decreases.
    pub objective: &'a Objective,
    /// The goal of each fixed vertex that a known flow pulls towards one.
    pub goals: &'a [Option<Point3<f64>>],
}

/// The goals of a run that pull fixed vertices (landmarks away from their place).
struct Pull<'a> {
    goals: &'a [Option<Point3<f64>>],
    /// Per vertex, whether a goal pulls it.
    pulled: Vec<bool>,
    /// The flow prescribed to the pulled vertices (zero elsewhere).
    prescribed: Vec<Vector3<f64>>,
}

impl<'a> Pull<'a> {
    /// The goals of the `vertices` source vertices.
    fn new(goals: &'a [Option<Point3<f64>>], vertices: usize) -> Self {
        let pulled: Vec<bool> = (0..vertices)
            .map(|v| goals.get(v).is_some_and(|g| g.is_some()))
            .collect();
        Self {
            goals,
            pulled,
            prescribed: vec![Vector3::zeros(); vertices],
        }
    }

    /// The roles in a step: fixed vertices pulled towards a goal move by a known flow
    /// and are projected onto the target like free ones.
    fn step_roles(&self, roles: &[Role]) -> Vec<Role> {
        roles
            .iter()
            .zip(&self.pulled)
            .map(|(&role, &pulled)| if pulled { Role::Free } else { role })
            .collect()
    }

    /// Prescribes to `system` the flow of each pulled vertex: the tangential part (at
    /// `normals`) of its way from `image` to its goal; the projection brings the point
    /// back. True while one of them is `tolerance` or farther from its goal: then a
    /// step that brings it closer is accepted even if the distortion grows (the
    /// constraint comes first).
    fn prescribe(
        &mut self,
        image: &[Point3<f64>],
        normals: &[Vector3<f64>],
        tolerance: f64,
        system: &mut FlowSystem,
    ) -> Result<bool, SolverError> {
        let mut pulling = false;
        if self.pulled.iter().any(|&p| p) {
            for (v, goal) in self.goals.iter().enumerate() {
                if let Some(goal) = goal {
                    let d = goal - image[v];
                    pulling |= d.norm() >= tolerance;
                    self.prescribed[v] = d - normals[v] * normals[v].dot(&d);
                }
            }
            system.set_prescribed(&self.prescribed)?;
        }
        Ok(pulling)
    }
}

/// The map a run has accepted last: the target it lies on (a free annulus radius
/// moves), the images, the target's normals there, the image faces, and their `E`
/// and flips.
struct Accepted<G> {
    target: G,
    image: Vec<Point3<f64>>,
    normals: Vec<Vector3<f64>>,
    faces: Vec<ImageFace>,
    energy: f64,
    flipped: usize,
}

impl<G: TargetGeometry> Accepted<G> {
    /// The start of a run: `image` projected onto `target` by `roles`, measured.
    fn start(
        problem: FlowProblem<'_>,
        target: G,
        mut image: Vec<Point3<f64>>,
        roles: &[Role],
        threads: usize,
    ) -> Result<Self, SolverError> {
        let mut normals = Vec::new();
        target.project_all(roles, None, &mut image, &mut normals)?;
        let mut faces = Vec::with_capacity(problem.elements.face_count());
        image_faces(problem.elements, &normals, &image, &mut faces, threads);
        let (energy, flipped) = problem.objective.evaluate(&faces, threads);
        Ok(Self {
            target,
            image,
            normals,
            faces,
            energy,
            flipped,
        })
    }

    /// The images, normals and faces.
    fn view(&self) -> ImageView<'_> {
        ImageView {
            image: &self.image,
            normals: &self.normals,
            faces: &self.faces,
        }
    }

    /// Takes the step found: its target, `E` and flips, and the map in `trial` (which
    /// gets the buffers of the map it replaces, to be overwritten by the next trial).
    fn take(&mut self, step: FoundStep<G>, trial: &mut Trial) {
        self.target = step.target;
        std::mem::swap(&mut self.image, &mut trial.image);
        std::mem::swap(&mut self.faces, &mut trial.faces);
        std::mem::swap(&mut self.normals, &mut trial.normals);
        (self.energy, self.flipped) = (step.energy, step.flips);
    }
}

/// The step a search accepts: the target moved with it, its `E`, flips and size `t`
/// (its map is the search's trial).
struct FoundStep<G> {
    target: G,
    energy: f64,
    flips: usize,
    t: f64,
}

/// The step-size search of a run (module docs, item 3): what stays the same through the
/// run and the scratch of its trials.
struct StepSearch<'a> {
    problem: FlowProblem<'a>,
    options: FlowOptions,
    /// Roles in the steps ([`Pull::step_roles`]).
    step_roles: Vec<Role>,
    /// The spread of the curve vertices' slides into the interior, on curved targets
    /// with curve vertices.
    extension: Option<HarmonicExtension>,
    trial: Trial,
    /// The faces near the first fold ([`first_fold`]).
    near: Vec<(f64, usize)>,
    /// Scratch of [`near_fold_rise`].
    probe: Vec<Point3<f64>>,
}

impl<'a> StepSearch<'a> {
    /// The search of a run onto `target` with unknowns of `roles` (curve vertices slide,
    /// and on a curved target their slides spread into the interior) and steps moving
    /// the vertices by `step_roles`.
    fn new<G: TargetGeometry>(
        problem: FlowProblem<'a>,
        options: FlowOptions,
        target: &G,
        roles: &[Role],
        step_roles: Vec<Role>,
    ) -> Result<Self, SolverError> {
        let extension = if target.curved() {
            HarmonicExtension::new(
                &crate::system::triangles(problem.elements),
                roles,
                target.correction_rings(),
                options.solve,
            )?
        } else {
            None
        };
        Ok(Self {
            problem,
            options,
            step_roles,
            extension,
            trial: Trial::default(),
            near: Vec::new(),
            probe: Vec::new(),
        })
    }

    /// Tries the step sizes `first 2^-j` (`first` keeps the largest move within
    /// `max_move`), usable while `t max |V|` is at least the tolerance and `t` at least
    /// the smallest step: from the first below the predicted fold, skipping it when the
    /// near faces alone already raise `E` more than the model's decrease (a size the
    /// pull of a landmark does not need), then the larger ones; then, if asked, all of
    /// them again with each trial's new flips untangled. The first trial with no more
    /// flips than `map` and a lower `E` (any `E` while `pulling`) is the step.
    fn search<G: TargetGeometry>(
        &mut self,
        system: &FlowSystem,
        map: &Accepted<G>,
        flow: &Flow,
        largest: f64,
        pulling: bool,
    ) -> Result<Option<FoundStep<G>>, SolverError> {
        let options = self.options;
        let first = if largest > options.max_move {
            options.max_move / largest
        } else {
            1.0
        };
        let ladder = |halvings: u32| first * 0.5f64.powi(halvings as i32);
        let usable = |&halvings: &u32| {
            let t = ladder(halvings);
            t * largest >= options.tolerance && t >= options.min_step
        };
        let elements = self.problem.elements;
        let fold = first_fold(
            elements,
            &map.faces,
            &flow.vertex,
            &map.image,
            &map.normals,
            &mut self.near,
        );
        let below_fold = (0..MAX_HALVINGS)
            .find(|&j| ladder(j) < fold)
            .unwrap_or(MAX_HALVINGS);
        // The plain search, then (item 3) the search that untangles a trial's flips.
        for repair in [false, true] {
            if repair && !options.untangle_trials {
                break;
            }
            let start = if repair { 0 } else { below_fold };
            let sizes = (start..)
                .take_while(usable)
                .chain((0..start).filter(usable));
            for j in sizes {
                let t = ladder(j);
                if !repair && !pulling && j == start && start > 0 {
                    let rise = near_fold_rise(
                        elements,
                        self.problem.objective,
                        map.view(),
                        &self.near,
                        &flow.vertex,
                        t,
                        &mut self.probe,
                    );
                    if rise.is_some_and(|rise| rise > (2.0 * t - t * t) * system.model_decrease()) {
                        continue;
                    }
                }
                let (moved, e, flips) = self.trial(system, map, flow, t, repair)?;
                if flips <= map.flipped && (pulling || e < map.energy) {
                    return Ok(Some(FoundStep {
                        target: moved,
                        energy: e,
                        flips,
                        t,
                    }));
                }
            }
        }
        Ok(None)
    }

    /// The trial step of size `t` from `map` into `self.trial`, measured: returns the
    /// moved target, `E` and the flips. With `repair`, a trial with more flips than
    /// `map` has them untangled first (each vertex trying its image in `map` first),
    /// and is measured again.
    fn trial<G: TargetGeometry>(
        &mut self,
        system: &FlowSystem,
        map: &Accepted<G>,
        flow: &Flow,
        t: f64,
        repair: bool,
    ) -> Result<(G, f64, usize), SolverError> {
        let FlowProblem {
            elements,
            objective,
            ..
        } = self.problem;
        let threads = self.options.threads;
        let moved = step(
            &map.target,
            &self.step_roles,
            &map.image,
            flow,
            t,
            self.extension.as_mut(),
            &mut self.trial,
        )?;
        let trial = &mut self.trial;
        image_faces(
            elements,
            &trial.normals,
            &trial.image,
            &mut trial.faces,
            threads,
        );
        let (mut e, mut flips) = objective.evaluate(&trial.faces, threads);
        if repair && flips > map.flipped {
            untangle(
                elements,
                &moved,
                system.roles(),
                &mut trial.image,
                &mut trial.normals,
                &mut trial.faces,
                UntangleRounds {
                    rounds: REPAIR_ROUNDS,
                    previous: Some(&map.image),
                },
            );
            (e, flips) = objective.evaluate(&trial.faces, threads);
        }
        Ok((moved, e, flips))
    }
}

/// Runs the flow from `image` (one point per source vertex, projected onto `target`
/// first) with the unknowns of `system`, for `problem`'s objective measured on its
/// source elements. A system that served an earlier run serves again (its first solve
/// factors afresh); the run's work counts only its own.
pub fn run<G: TargetGeometry>(
    problem: FlowProblem<'_>,
    target: G,
    system: &mut FlowSystem,
    image: Vec<Point3<f64>>,
    options: FlowOptions,
    context: &mut Context<'_>,
) -> Result<FlowRun<G>, SolverError> {
    let FlowProblem {
        elements,
        objective,
        goals,
    } = problem;
    system.forget_factorization();
    let (factorizations, cg_iterations) = system.work();
    let mut pull = Pull::new(goals, image.len());
    let step_roles = pull.step_roles(system.roles());
    let mut search = StepSearch::new(problem, options, &target, system.roles(), step_roles)?;
    let mut map = Accepted::start(problem, target, image, system.roles(), options.threads)?;
    let mut energy_history = vec![map.energy];
    let (mut step_sizes, mut updates) = (Vec::new(), Vec::new());
    let (mut weights, mut rho) = (Vec::new(), Vec::new());
    let mut flow = Flow::default();
    let report = |context: &mut Context<'_>, done: usize, energy: f64| {
        context.report(&Progress {
            stage: "flow",
            done,
            total: Some(options.max_iterations),
            energy: Some(energy),
        });
    };
    report(context, 0, map.energy);
    let mut stop = Stop::IterationLimit;
    let (mut solve_seconds, mut step_seconds) = (0.0, 0.0);
    for iteration in 0..options.max_iterations {
        if context.is_cancelled() {
            stop = Stop::Cancelled;
            break;
        }
        let clock = Instant::now();
        weights_and_targets(objective, &map.faces, &mut weights, &mut rho);
        let pulling = pull.prescribe(&map.image, &map.normals, options.tolerance, system)?;
        system.solve(
            FlowInput {
                elements,
                target: &map.target,
                image: &map.image,
                normals: &map.normals,
                faces: &map.faces,
                weights: &weights,
                rho: &rho,
            },
            &mut flow,
        )?;
        solve_seconds += clock.elapsed().as_secs_f64();
        let clock = Instant::now();
        let largest = flow.vertex.iter().map(|v| v.norm()).fold(0.0, f64::max);
        map.target.prepare_step(&map.image)?;
        let accepted = search.search(system, &map, &flow, largest, pulling)?;
        step_seconds += clock.elapsed().as_secs_f64();
        let Some(found) = accepted else {
            stop = if largest < options.tolerance {
                Stop::Converged
            } else {
                Stop::Stalled
            };
            break;
        };
        let t = found.t;
        map.take(found, &mut search.trial);
        energy_history.push(map.energy);
        step_sizes.push(t);
        updates.push(t * largest);
        report(context, iteration + 1, map.energy);
        if t * largest < options.tolerance {
            stop = Stop::Converged;
            break;
        }
        if objective.has_barrier() && options.flat.is_flat(&energy_history) {
            stop = Stop::Flat;
            break;
        }
    }
    Ok(FlowRun {
        image: map.image,
        target: map.target,
        faces: map.faces,
        energy_history,
        step_sizes,
        updates,
        stop,
        solve_seconds,
        step_seconds,
        factorizations: system.work().0 - factorizations,
        cg_iterations: system.work().1 - cg_iterations,
    })
}

#[cfg(test)]
mod tests {
    use beltrami_fem::Frame;
    use beltrami_mesh::primitives::{Cells, grid};
    use beltrami_mesh::{Mesh, PolygonSoup};

    use super::*;

    #[test]
    fn the_smallest_positive_root_of_quadratics_and_lines() {
        let cases = [
            ((1.0, -3.0, 2.0), 0.5),
            ((1.0, 0.0, -1.0), 1.0),
            ((1.0, -2.0, 0.0), 0.5),
            ((1.0, 2.0, 1.0), f64::INFINITY),
            ((1.0, 0.0, 1.0), f64::INFINITY),
            ((1.0, 2.0, 0.0), f64::INFINITY),
            // Roots 1e-12 and 1e20: the naive formula loses the small one entirely.
            ((1e-12, -1.0, 1e-20), 1e-12),
        ];
        for ((c0, c1, c2), root) in cases {
            let got = smallest_positive_root(c0, c1, c2);
            assert!(
                got == root || (got - root).abs() <= 1e-12 * root,
                "{c0} + {c1} t + {c2} t^2: {got} instead of {root}"
            );
        }
    }

    /// Asserts that [`first_fold`] of `flow` from `image` is `t = 1/2` and that the flip
    /// measure agrees: no face flipped at `t = 0.49`, some at `0.51`.
    fn first_fold_at_one_half(
        elements: &Elements,
        image: &[Point3<f64>],
        normals: &[Vector3<f64>],
        flow: &[Vector3<f64>],
    ) {
        let mut faces = Vec::new();
        image_faces(elements, normals, image, &mut faces, 1);
        let fold = first_fold(elements, &faces, flow, image, normals, &mut Vec::new());
        assert!((fold - 0.5).abs() < 1e-12, "{fold}");
        for (t, flipped) in [(0.49, false), (0.51, true)] {
            let moved: Vec<Point3<f64>> = image.iter().zip(flow).map(|(p, v)| p + t * v).collect();
            image_faces(elements, normals, &moved, &mut faces, 1);
            assert_eq!(faces.iter().any(ImageFace::flipped), flipped, "t = {t}");
        }
    }

    /// An 8 x 8 grid of the unit square at its own place (normals `z`) whose vertex
    /// (4, 4) moves right by 2 cells per unit of `t` (the flow) and reaches its link's
    /// side `x = 5/8` at `t = 1/2`.
    struct DraggedVertex {
        elements: Elements,
        image: Vec<Point3<f64>>,
        normals: Vec<Vector3<f64>>,
        flow: Vec<Vector3<f64>>,
    }

    fn dragged_vertex() -> DraggedVertex {
        let n = 8;
        let mesh = Mesh::from_soup(&grid(n, n, Cells::Triangles)).unwrap();
        let elements = Elements::new(&mesh, Frame::Face).unwrap();
        let image: Vec<Point3<f64>> = mesh.positions().to_vec();
        let normals = vec![Vector3::z(); image.len()];
        let dragged = 4 + (n + 1) * 4;
        let mut flow = vec![Vector3::zeros(); image.len()];
        flow[dragged] = Vector3::new(2.0 / n as f64, 0.0, 0.0);
        DraggedVertex {
            elements,
            image,
            normals,
            flow,
        }
    }

    #[test]
    fn the_first_fold_is_where_a_dragged_vertex_crosses_its_link() {
        let DraggedVertex {
            elements,
            image,
            normals,
            flow,
        } = dragged_vertex();
        first_fold_at_one_half(&elements, &image, &normals, &flow);
        let mut faces = Vec::new();
        // The linearized rotation about the centre, V = J (p - c), scales every area by
        // 1 + t^2: nothing folds.
        let centre = Point3::new(0.5, 0.5, 0.0);
        let turn: Vec<Vector3<f64>> = image
            .iter()
            .map(|p| Vector3::new(centre.y - p.y, p.x - centre.x, 0.0))
            .collect();
        image_faces(&elements, &normals, &image, &mut faces, 1);
        assert_eq!(
            first_fold(&elements, &faces, &turn, &image, &normals, &mut Vec::new()),
            f64::INFINITY
        );
    }

    #[test]
    fn a_thin_face_tilted_to_its_reference_folds_where_it_crosses_it() {
        // The image of one triangle stands at 72 degrees to the target normal z; its apex
        // moves by (0, -0.2, 0) per unit of t, so the triangle seen from z,
        // (1, 0) x (0.5, 0.1 - 0.2 t), turns over at t = 1/2, while in its own plane the
        // same move only reaches the base at t = 5.
        let soup = PolygonSoup::from_triangles(
            vec![
                Point3::new(0.0, 0.0, 0.0),
                Point3::new(1.0, 0.0, 0.0),
                Point3::new(0.5, 0.5, 0.0),
            ],
            &[[0, 1, 2]],
        );
        let mesh = Mesh::from_soup(&soup).unwrap();
        let elements = Elements::new(&mesh, Frame::Face).unwrap();
        let image = vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(0.5, 0.1, 0.3),
        ];
        let normals = vec![Vector3::z(); 3];
        let flow = vec![
            Vector3::zeros(),
            Vector3::zeros(),
            Vector3::new(0.0, -0.2, 0.0),
        ];
        first_fold_at_one_half(&elements, &image, &normals, &flow);
    }

    /// A flow of the unit disk onto itself towards the constant coefficient
    /// `0.3 + 0.1 i` (`p = 2`): the rim slides along the circle except one vertex, which
    /// is held with the centre.
    struct PrescribedDisk {
        elements: Elements,
        image: Vec<Point3<f64>>,
        roles: Vec<Role>,
        objective: Objective,
    }

    fn prescribed_disk() -> PrescribedDisk {
        let mesh = Mesh::from_soup(&beltrami_mesh::primitives::disk(3)).unwrap();
        let elements = Elements::new(&mesh, Frame::Global).unwrap();
        let image = mesh.positions().to_vec();
        let on_rim = |p: &Point3<f64>| (p.coords.norm() - 1.0).abs() < 1e-9;
        let rim = image.iter().position(on_rim).unwrap();
        let centre = (0..image.len())
            .min_by(|&a, &b| image[a].coords.norm().total_cmp(&image[b].coords.norm()))
            .unwrap();
        let roles = (0..image.len())
            .map(|v| match v {
                _ if v == rim || v == centre => Role::Fixed,
                _ if on_rim(&image[v]) => Role::Curve(0),
                _ => Role::Free,
            })
            .collect();
        let sigma = vec![Complex64::new(0.3, 0.1); mesh.face_count()];
        let objective = Objective::new(
            elements.face_areas(),
            Some(sigma),
            2.0,
            crate::measure::Barrier::PLANAR,
        );
        PrescribedDisk {
            elements,
            image,
            roles,
            objective,
        }
    }

    /// The slope of `E` along the flow is `-2 Q` ([`FlowSystem::model_decrease`]): the
    /// step search compares the faces near a fold with the decrease `(2 t - t^2) Q` the
    /// Gauss-Newton model predicts, so `Q` must have `E`'s own scale.
    #[test]
    fn the_model_decrease_is_the_slope_of_the_error() {
        let PrescribedDisk {
            elements,
            mut image,
            roles,
            objective,
        } = prescribed_disk();
        let target = crate::target::UnitDisk;
        let mut normals = Vec::new();
        target
            .project_all(&roles, None, &mut image, &mut normals)
            .unwrap();
        let mut system =
            FlowSystem::new(&elements, &target, &image, roles, SolveOptions::default()).unwrap();
        let mut faces = Vec::new();
        image_faces(&elements, &normals, &image, &mut faces, 1);
        let (mut weights, mut rho, mut flow) = (Vec::new(), Vec::new(), Flow::default());
        weights_and_targets(&objective, &faces, &mut weights, &mut rho);
        system
            .solve(
                FlowInput {
                    elements: &elements,
                    target: &target,
                    image: &image,
                    normals: &normals,
                    faces: &faces,
                    weights: &weights,
                    rho: &rho,
                },
                &mut flow,
            )
            .unwrap();
        let q = system.model_decrease();
        assert!(q > 0.0, "{q}");
        let mut energy = |t: f64| {
            let moved: Vec<Point3<f64>> = image
                .iter()
                .zip(&flow.vertex)
                .map(|(p, v)| p + t * v)
                .collect();
            image_faces(&elements, &normals, &moved, &mut faces, 1);
            objective.evaluate(&faces, 1).0
        };
        let t = 1e-5;
        let slope = (energy(t) - energy(-t)) / (2.0 * t);
        assert!(
            (slope + 2.0 * q).abs() <= 1e-4 * 2.0 * q,
            "slope {slope:e} against -2 Q = {:e}",
            -2.0 * q
        );
    }

    /// The model decrease is the slope of the error also where an image face stands
    /// nearly edge-on over a curved target, its frame turned towards the target's
    /// tangent plane: there its `mu` depends on the target's normals at its corners,
    /// which turn as they move. Two faces on the unit sphere, one a thin triangle along
    /// the equator (its plane nearly through the centre, so about 80 degrees from the
    /// normals at its corners); the two vertices of the long edge held.
    #[test]
    fn the_model_decrease_is_the_slope_of_the_error_over_a_curved_target() {
        let soup = PolygonSoup::from_triangles(
            vec![
                Point3::new(0.0, 0.0, 0.0),
                Point3::new(1.0, 0.0, 0.0),
                Point3::new(0.5, 0.3, 0.0),
                Point3::new(0.5, -0.3, 0.0),
            ],
            &[[0, 1, 2], [0, 3, 1]],
        );
        let mesh = Mesh::from_soup(&soup).unwrap();
        let elements = Elements::new(&mesh, Frame::Global).unwrap();
        let on_sphere = |longitude: f64, latitude: f64| {
            let (c, s) = (latitude.cos(), latitude.sin());
            Point3::new(c * longitude.cos(), c * longitude.sin(), s)
        };
        let image = vec![
            on_sphere(-0.5, 0.0),
            on_sphere(0.5, 0.0),
            on_sphere(0.0, 0.005),
            on_sphere(0.0, -0.3),
        ];
        let roles = vec![Role::Fixed, Role::Fixed, Role::Free, Role::Free];
        let target = crate::target::UnitSphere;
        let energy = |t: f64, flow: &[Vector3<f64>]| {
            let mut moved: Vec<Point3<f64>> =
                image.iter().zip(flow).map(|(p, v)| p + t * v).collect();
            let mut normals = Vec::new();
            target
                .project_all(&roles, None, &mut moved, &mut normals)
                .unwrap();
            let mut faces = Vec::new();
            image_faces(&elements, &normals, &moved, &mut faces, 1);
            (faces, normals)
        };
        let objective = Objective::new(
            elements.face_areas(),
            None,
            2.0,
            crate::measure::Barrier {
                start: 1.0,
                area_floor: false,
            },
        );
        let (faces, normals) = energy(0.0, &vec![Vector3::zeros(); image.len()]);
        assert!(
            faces[0].facing() < 0.3 && !faces[0].flipped() && faces[1].facing() > 0.9,
            "{} {}",
            faces[0].facing(),
            faces[1].facing()
        );
        let mut system = FlowSystem::new(
            &elements,
            &target,
            &image,
            roles.clone(),
            SolveOptions::default(),
        )
        .unwrap();
        let (mut weights, mut rho, mut flow) = (Vec::new(), Vec::new(), Flow::default());
        weights_and_targets(&objective, &faces, &mut weights, &mut rho);
        system
            .solve(
                FlowInput {
                    elements: &elements,
                    target: &target,
                    image: &image,
                    normals: &normals,
                    faces: &faces,
                    weights: &weights,
                    rho: &rho,
                },
                &mut flow,
            )
            .unwrap();
        let q = system.model_decrease();
        assert!(q > 0.0, "{q}");
        let t = 1e-6;
        let slope = (objective.evaluate(&energy(t, &flow.vertex).0, 1).0
            - objective.evaluate(&energy(-t, &flow.vertex).0, 1).0)
            / (2.0 * t);
        assert!(
            (slope + 2.0 * q).abs() <= 1e-3 * 2.0 * q,
            "slope {slope:e} against -2 Q = {:e}",
            -2.0 * q
        );
    }

    /// The rise of the faces near a fold: small far from it, large as the dragged
    /// vertex nears its link (the near-fold barrier), none at all once a face turns.
    #[test]
    fn the_rise_near_a_fold_grows_to_the_fold() {
        let DraggedVertex {
            elements,
            image,
            normals,
            flow,
        } = dragged_vertex();
        let objective = Objective::new(
            elements.face_areas(),
            None,
            2.0,
            crate::measure::Barrier::PLANAR,
        );
        let mut faces = Vec::new();
        image_faces(&elements, &normals, &image, &mut faces, 1);
        let mut near = Vec::new();
        let fold = first_fold(&elements, &faces, &flow, &image, &normals, &mut near);
        assert!((fold - 0.5).abs() < 1e-12, "{fold}");
        // The faces around the dragged vertex, the nearest first.
        assert!(!near.is_empty() && near.len() <= 6, "{near:?}");
        assert!(near.iter().all(|&(root, _)| root < NEAR_FOLD_REACH * fold));
        assert!(near.windows(2).all(|w| w[0].0 <= w[1].0));
        let mut probe = Vec::new();
        let mut rise = |t: f64| {
            let map = ImageView {
                image: &image,
                normals: &normals,
                faces: &faces,
            };
            near_fold_rise(&elements, &objective, map, &near, &flow, t, &mut probe)
        };
        let (early, late) = (rise(0.05).unwrap(), rise(0.45).unwrap());
        assert!(early > 0.0 && late > 100.0 * early, "{early:e}, {late:e}");
        assert_eq!(rise(0.55), None);
        assert_eq!(probe, image, "the scratch is left as the image");
    }

    /// A system that served one run serves the next like a fresh one: from the same
    /// map the second run takes the same steps to the same image with the same work
    /// (its first solve factors its own matrix instead of starting conjugate gradients
    /// from the last run's factor, and its counts are its own).
    #[test]
    fn a_system_serves_a_second_run_like_a_fresh_one() {
        let PrescribedDisk {
            elements,
            image,
            roles,
            objective,
        } = prescribed_disk();
        let options = FlowOptions {
            tolerance: 1e-12,
            max_iterations: 6,
            solve: SolveOptions::default(),
            max_move: f64::INFINITY,
            min_step: 2f64.powi(-50),
            untangle_trials: false,
            threads: 1,
            flat: FlatRule::CURVED,
        };
        let target = crate::target::UnitDisk;
        let flow_from = |system: &mut FlowSystem| {
            let problem = FlowProblem {
                elements: &elements,
                objective: &objective,
                goals: &[],
            };
            run(
                problem,
                target,
                system,
                image.clone(),
                options,
                &mut Context::new(),
            )
            .unwrap()
        };
        let fresh =
            || FlowSystem::new(&elements, &target, &image, roles.clone(), options.solve).unwrap();
        let mut system = fresh();
        let first = flow_from(&mut system);
        let second = flow_from(&mut system);
        let alone = flow_from(&mut fresh());
        assert!(first.iterations() >= 3, "{:?}", first.step_sizes);
        assert!(first.cg_iterations > 0, "no step reused a factorization");
        for run in [&second, &alone] {
            let apart = run
                .image
                .iter()
                .zip(&first.image)
                .map(|(p, q)| (p - q).norm())
                .fold(0.0, f64::max);
            assert!(apart == 0.0, "the images differ by up to {apart:e}");
            assert_eq!(run.step_sizes, first.step_sizes);
            assert_eq!(
                (run.factorizations, run.cg_iterations),
                (first.factorizations, first.cg_iterations)
            );
        }
    }
}
