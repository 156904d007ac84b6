//! A closed genus-0 mesh onto the unit sphere, nearly conformally: a linear conformal
//! start (`sphere/conformal.rs`, the default), or Tutte's embedding of the mesh minus one face
//! (`start=tutte`; T. W. Wong and H. Zhao, "Computation of quasiconformal surface maps
//! using discrete Beltrami flow", SIAM J. Imaging Sci. 7, 2014, section 4.1: "remove a
//! triangle ..., apply Tutte embedding ..., then map onto a sphere by stereographic
//! projection, with the triangle put back to fill the hole"), then Moebius
//! normalization and the untangling of any flipped face (`sphere/untangle.rs`).
//!
//! # Stages
//!
//! The conformal start (`start=conformal`, stages `harmonic`, `projection`,
//! `corrections`; details in `sphere/conformal.rs`): the cotangent-harmonic map of the mesh with
//! the vertices of the face `r` chosen in stage 1 below held at a similar copy of `r`
//! (FLASH's first solve: P. T. Choi, K. C. Lam, L. M. Lui, SIAM J. Imaging Sci. 8, 2015),
//! its inverse stereographic projection (stage 3) and Moebius centering (stage 4), then
//! harmonic corrections alternating between the stereographic charts centred at the
//! puncture and at its antipode, each holding the other end of the sphere fixed (the
//! first is FLASH's far-hemisphere correction, the next ones a Schwarz alternation that
//! removes the seam it leaves). The linear solves reuse one factorization per chart.
//!
//! The Tutte start (`start=tutte`, stages `puncture`, `tutte`, `projection`):
//!
//! 1. **Puncture.** Remove one face `r`: the one with the largest `A_f q_f`, its area
//!    times its shape quality `q_f = 4 tan(pi / n) A_f / sum_k l_k^2` (`n` = 3 or 4
//!    sides of lengths `l_k`; `q = 1` for the equilateral triangle and the square, so the
//!    removed face is large and close to the regular polygon it is mapped onto). The rest
//!    is a disk whose single boundary loop is the outline of `r`; it keeps every vertex,
//!    so vertex ids do not change.
//! 2. **Tutte.** The disk goes into the plane with every interior vertex at a weighted
//!    mean of its neighbours ([`beltrami_fem::WeightedMeanSystem`]; mean-value weights by
//!    default, uniform on request) and the `n` boundary vertices on the corners of a
//!    regular `n`-gon (equilateral triangle or square) inscribed in the circle of radius
//!    `R`. The corners are placed counter-clockwise in loop order, the mirror of the
//!    usual clockwise placement of [`beltrami_fem::boundary`], so the faces run
//!    clockwise in the plane: seen from below, as the projection below needs. Tutte's
//!    theorem (Floater's for mean-value weights) makes this a bijection onto the polygon
//!    for triangles.
//! 3. **Projection.** The inverse stereographic projection from the north pole,
//!
//!    ```text
//!    s(x + i y) = (2x, 2y, |z|^2 - 1) / (|z|^2 + 1),
//!    ```
//!
//!    conformal, with `s(0)` the south pole and `s(infinity)` the north pole; the plane
//!    outside the polygon, i.e. the removed face, goes to a cap around the north pole.
//!    Near the south pole `s(z) ~ (2x, 2y, -1)`, where the outward normal is `-e_z`, so
//!    `s` maps the plane *seen from below* onto the sphere seen from outside: clockwise
//!    faces in the plane become outward-facing faces on the sphere. `R` gives the cap
//!    `|z| > R`, whose boundary circle passes through the removed face's vertices, the
//!    removed face's share `a = A_r / A` of the surface area: the cap has area
//!    `2 pi (1 - h)` with `h = (R^2 - 1) / (R^2 + 1)`, so `4 pi a = 4 pi / (R^2 + 1)` and
//!    `R = sqrt(1/a - 1)`.
//!
//! Then, for both starts:
//!
//! 4. **Normalization.** Moebius centering (A. Baden, K. Crane, M. Kazhdan, "Moebius
//!    registration", Computer Graphics Forum 37(5), SGP 2018): with source face areas
//!    `A_f` and `x_f` the centroid of face `f`'s image projected onto the sphere, the
//!    centre of mass `c = sum_f A_f x_f / sum_f A_f` of the pushed-forward area lies in
//!    the open unit ball. The conformal automorphism of the ball that moves `c` to the
//!    origin (L. V. Ahlfors, "Moebius transformations in several dimensions", 1981),
//!
//!    ```text
//!    phi_c(x) = ((1 - |c|^2)(x - c) - |x - c|^2 c) / (1 - 2 <x, c> + |c|^2 |x|^2),
//!    ```
//!
//!    is on the sphere `phi_c(x) = (1 - |c|^2)(x - c) / |x - c|^2 - c`, an
//!    orientation-preserving Moebius transformation of the sphere. Baden, Crane and
//!    Kazhdan iterate `x <- phi_c(x)` (vertex images projected back to unit length) with
//!    `c` recomputed each time. For small `b`, `phi_b(x) ~ x - 2b + 2 <x, b> x`, so the
//!    step `phi_b` moves the centre of mass to `c - 2 (I - M) b`, with the second moment
//!    `M = sum_f A_f x_f x_f^T / sum_f A_f`: the plain step `b = c` gives `(2M - I) c`
//!    (`-c/3` for a uniform spread, but slow where `M` is far from `I/3`), the Newton
//!    step `b = (2 (I - M))^{-1} c` gives 0 to first order. Each step takes the first of
//!    `b =` Newton (when inside the ball), `c`, `c/2`, `c/4`, ... that brings the centre of
//!    mass closer to the origin, until `|c| <= 1e-6` or after 100 steps. The area of the
//!    source is then spread around the sphere instead of crowding one side: the usual
//!    normalization of the Moebius freedom of spherical maps.
//!
//! 5. **Untangling.** Faces whose image faces inward (below) are re-solved in small
//!    patches with positive weights (`sphere/untangle.rs`); the report counts them and any left.
//!
//! # Flips
//!
//! The image of a face is the flat polygon through its vertex images. It faces outward
//! when its normal points away from the centre: a triangle `p0 p1 p2` is *inward* (a
//! flip) when `((p1 - p0) x (p2 - p0)) . m <= 0`, `m` the mean of its vertex images. A
//! quad's image is not planar; it is inward when any triangle of either diagonal split
//! (`012`, `023`, `013`, `123`) is. Those four triangles give the Jacobian of the
//! bilinear patch at its corners, and the Jacobian's component along the fixed direction
//! `m` is bilinear on the patch, so a quad that passes has a positive Jacobian at every
//! point, the Gauss points of the distortion measure included.
//!
//! A planar triangle's circumdisk goes to a spherical cap through the vertex images, and
//! the flat image faces outward exactly when that cap is the smaller of the two the
//! circle bounds. Tutte's map has no flips in the plane, but a very obtuse face has a
//! circumdisk far larger than itself, which the projection and the centering may blow up
//! beyond a hemisphere. The cotangent weights of the conformal start are negative across
//! edges opposite obtuse angles, so its harmonic solves may fold a face too (one in
//! 10^5 on the shared meshes). Stage 5 removes both kinds.
//!
//! The image always has the combinatorial orientation of the source: when the source's
//! faces face inward (negative signed volume), the image's faces still face outward, and
//! the report notes that the map reverses orientation in space.
//!
//! # Distortion
//!
//! The report's `mu` is measured intrinsically
//! ([`beltrami_fem::distortion::measure_surface`]) with [`ReferenceNormal::Radial`] (the
//! direction of the image point at each quadrature point) as the reference normal; its
//! flipped count is that of the inward faces above (together with any Gauss point the
//! measure finds flipped). The conformal start's `|mu|` is a discretization error: on a
//! round sphere moved by a rotation or a Moebius transformation mean `|mu|` falls by 4
//! per halving of the edges, on an ellipsoid by 2 (tests `sphere_conformal`). The Tutte
//! start is a bijective initialization but not conformal: its stretch is largest near
//! the removed face's corners (a full turn around them is squeezed into the polygon's
//! corner angle) and on long protrusions, which Tutte embeddings shrink geometrically.
//!
use std::f64::consts::{PI, TAU};

use beltrami_core::{
    Accepts, Context, Element, Extras, Goal, GoalKind, Map, Metrics, OptionKind, OptionSpec,
    Output, Problem, Progress, Report, Settings, Solution, Solver, SolverError, SolverInfo,
    THREADS, Target, TargetKind, Topology, solve_renumbered, topology,
};
use beltrami_fem::ReferenceNormal;
use beltrami_fem::distortion::measure_surface;
use beltrami_fem::{BoundaryMap, EdgeWeights, WeightError, WeightedMeanSystem};
use beltrami_mesh::{FaceId, Mesh, Point3, Vector3, VertexId};
use nalgebra::Matrix3;
use num_complex::Complex64;

use crate::{Weights, edge_weights, solve_options};

mod conformal;
mod untangle;

use untangle::{Untangled, untangle};

/// A closed genus-0 mesh onto the unit sphere (module docs): the linear conformal start
/// (default) or the Tutte start, Moebius centering, untangling of flipped faces.
///
/// Reads: `target` (`Sphere` only), `goal` (`Conformal { p: 2 }` only) and the options
/// `start` (`conformal`, the default, or `tutte`), `corrections` and `overlap` (the
/// conformal start's chart corrections), `weights` (the Tutte start's: `mean-value`,
/// the default, or `uniform`), `max-steps` (centering) and `threads`. Takes no pins and
/// no curves. The report holds the timings of the stages (`harmonic`, `projection`,
/// `corrections` or `puncture`, `tutte`, `projection`; then `normalization`,
/// `untangle`, `distortion`), the number of normalization steps as its iterations, the
/// distance of the centre of mass from the origin after each step as its energy
/// history, and notes naming the removed face (input index), the corrections, and
/// counting flipped faces before and after the untangling.
#[derive(Debug, Clone, Copy, Default)]
pub struct Sphere;

const NAME: &str = "sphere";

/// The advice of the topology check, after "sphere maps closed genus-0 meshes; this
/// mesh has ...".
const NOT_A_SPHERE: &str = "use lscm/tutte for disks, or `beltrami cut` for higher genus";

/// The normalization stops once the centre of mass is this close to the origin.
const CENTER_TOLERANCE: f64 = 1e-6;

const OPTIONS: &[OptionSpec] = &[
    OptionSpec {
        name: "start",
        kind: OptionKind::Choice {
            default: "conformal",
            choices: &["conformal", "tutte"],
        },
        help: "conformal: cotangent-harmonic map of the punctured mesh, then harmonic corrections in the two stereographic charts (nearly conformal, FLASH-like); tutte: Tutte embedding of the punctured mesh (a bijection before the projection, far from conformal)",
    },
    OptionSpec {
        name: "corrections",
        kind: OptionKind::Int {
            default: 8,
            min: 0,
            max: 1000,
        },
        help: "start=conformal: harmonic chart corrections at most, alternating around the puncture and around its antipode (the first is FLASH's far-hemisphere correction)",
    },
    OptionSpec {
        name: "overlap",
        kind: OptionKind::Float {
            default: 0.5,
            min: 0.05,
            max: 0.95,
        },
        help: "start=conformal: each chart correction frees the vertices with height above -overlap (around the puncture) or below +overlap (around the antipode)",
    },
    crate::weights_option(
        "mean-value",
        &["mean-value", "uniform"],
        "start=tutte: edge weights of the Tutte embedding: mean-value (Floater) or uniform; cotangent weights are negative on obtuse triangles and may fold the map",
    ),
    OptionSpec {
        name: "max-steps",
        kind: OptionKind::Int {
            default: 100,
            min: 0,
            max: 100_000,
        },
        help: "Moebius centring steps at most",
    },
    THREADS,
];

const ACCEPTS: Accepts = Accepts {
    elements: &[Element::Triangle, Element::Quad],
    topologies: &[Topology::Sphere],
    targets: &[TargetKind::Sphere],
    goals: &[GoalKind::Conformal],
    constraints: &[],
};

/// The chart corrections stop once no vertex image moves farther than this.
const CORRECTION_TOLERANCE: f64 = 1e-9;

/// A normalization step halves its candidate this many times at most.
const MAX_HALVINGS: u32 = 20;

/// What [`Sphere`] is: its name, one line on what it computes, what it accepts and
/// its options.
const INFO: SolverInfo = SolverInfo {
    name: NAME,
    description: "closed genus-0 mesh onto the unit sphere, nearly conformally: cotangent-harmonic map of the punctured mesh, harmonic corrections alternating between the two stereographic charts, Moebius centering, flipped faces untangled (start=tutte: the Tutte embedding of the old initialization)",
    accepts: ACCEPTS,
    options: OPTIONS,
};

impl Solver for Sphere {
    fn info(&self) -> &'static SolverInfo {
        &INFO
    }

    fn check_problem(&self, problem: &Problem<'_>, settings: &Settings) -> Result<(), SolverError> {
        weights(problem, settings).map(|_| ())
    }

    fn run(
        &self,
        problem: &Problem<'_>,
        settings: &Settings,
        context: &mut Context<'_>,
    ) -> Result<Solution, SolverError> {
        solve_renumbered(problem, |problem| sphere_map(problem, settings, context))
    }
}

/// The sphere map of `problem`, in the numbering of its mesh ([`Sphere`]).
fn sphere_map(
    problem: &Problem<'_>,
    settings: &Settings,
    context: &mut Context<'_>,
) -> Result<Solution, SolverError> {
    let mesh = problem.source;
    let kind = weights(problem, settings)?;
    let mut report = Report::new(NAME);
    let mut metrics = Metrics::default();

    let removed = removed_face(mesh);
    let (mut image, cotangent) = match start_of(settings) {
        Start::Conformal => {
            let (image, weights) = conformal_start(mesh, removed, settings, context, &mut report)?;
            (image, Some(weights))
        }
        Start::Tutte => (
            tutte_start(mesh, removed, kind, settings, context, &mut report)?,
            None,
        ),
    };

    normalize(
        mesh,
        &mut image,
        settings.int("max-steps"),
        context,
        &mut report,
        &mut metrics,
    )?;

    let untangled = context.stage("untangle", &mut report, || {
        if !mesh.faces().any(|f| is_inward(mesh, &image, f)) {
            return Ok(Untangled::default());
        }
        let weights = match cotangent {
            Some(weights) => weights,
            None => EdgeWeights::cotangent(mesh).map_err(weight_error)?,
        };
        Ok(untangle(
            mesh,
            &weights,
            &mut image,
            solve_options(settings),
        )?)
    })?;
    if untangled.flipped > 0 {
        report.notes.push(format!(
            "{} faces were flipped after the linear solves; {} patches around them (up to {} rings of edges) were re-solved with positive weights, leaving {} flipped",
            untangled.flipped, untangled.patches, untangled.rings, untangled.remaining
        ));
    }

    let (inward, distortion) = context.stage("distortion", &mut report, || {
        let inward = inward_faces(mesh, &image);
        Ok((
            inward,
            measure_surface(mesh, &image, ReferenceNormal::Radial)?,
        ))
    })?;
    let flipped = inward
        .iter()
        .zip(&distortion.flipped)
        .filter(|&(&a, &b)| a || b)
        .count();
    let mut stats = distortion.stats;
    stats.flipped = flipped;
    metrics.mu = Some(distortion.field);
    metrics.distortion = Some(stats);
    if flipped > 0 {
        report.notes.push(format!(
            "{flipped} of {} faces are flipped: their images face the centre of the sphere (very obtuse faces, whose circumcircles the projection blows up)",
            mesh.face_count()
        ));
    }
    if signed_volume(mesh) < 0.0 {
        report.notes.push(
            "the source's faces face inward (negative signed volume); the image faces face outward, so the map reverses orientation in space"
                .to_string(),
        );
    }
    Ok(Solution {
        output: Output::Map(Map::Spatial(image)),
        metrics,
        extras: Extras::default(),
        report,
    })
}

/// The start of the solver's `start` option.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Start {
    /// The linear conformal start (`sphere/conformal.rs`).
    Conformal,
    /// The Tutte embedding of the punctured mesh (module docs, stages 1 to 3).
    Tutte,
}

fn start_of(settings: &Settings) -> Start {
    match settings.choice("start") {
        "tutte" => Start::Tutte,
        _ => Start::Conformal,
    }
}

/// The linear conformal start (`sphere/conformal.rs`): the punctured harmonic map (stage
/// "harmonic"), its projection and Moebius centering (stage "projection"), and the
/// chart corrections (stage "corrections").
fn conformal_start(
    mesh: &Mesh,
    removed: FaceId,
    settings: &Settings,
    context: &mut Context<'_>,
    report: &mut Report,
) -> Result<(Vec<Point3<f64>>, EdgeWeights), SolverError> {
    let share = mesh.face_area(removed) / mesh.total_area();
    report.notes.push(format!(
        "punctured face {} (input index, covering {share:.3e} of the area): its vertices are held at a similar copy of it in the first harmonic map",
        mesh.face_to_input(removed),
    ));
    let options = solve_options(settings);
    let (weights, order, planar) = context.stage("harmonic", report, || {
        let weights = EdgeWeights::cotangent(mesh).map_err(weight_error)?;
        let order = conformal::vertex_order(&weights)?;
        let planar = conformal::punctured_harmonic(mesh, &weights, removed, &order, options)?;
        Ok((weights, order, planar))
    })?;
    let mut image = context.stage("projection", report, || {
        let mut image: Vec<Point3<f64>> =
            planar.iter().map(|&z| inverse_stereographic(z)).collect();
        centre(mesh, &mut image, settings.int("max-steps"), |_, _| Ok(()))?;
        Ok(image)
    })?;
    let count = settings.int("corrections");
    let corrections = context.stage("corrections", report, || {
        let axis = radial_direction(mesh, &image, removed);
        conformal::correct(
            &weights,
            &mut image,
            axis,
            conformal::CorrectionSettings {
                overlap: settings.float("overlap"),
                count,
                tolerance: CORRECTION_TOLERANCE,
            },
            &order,
            options,
            |image| centre(mesh, image, settings.int("max-steps"), |_, _| Ok(())).map(|_| ()),
        )
    })?;
    if count > 0 {
        report.notes.push(format!(
            "{} chart corrections (alternating harmonic solves around the puncture and around its antipode, overlap |h| < {}); the last moved a vertex image by {:.2e} at most",
            corrections.done,
            settings.float("overlap"),
            corrections.last_move
        ));
    }
    Ok((image, weights))
}

/// The solver error of edge weights that cannot be computed.
fn weight_error(error: WeightError) -> SolverError {
    match error {
        WeightError::Fem(e) => SolverError::Fem(e),
        error @ WeightError::NonFinite { .. } => SolverError::Weights {
            solver: NAME,
            error,
        },
    }
}

/// The Tutte start (module docs, stages 1 to 3): puncture, Tutte embedding onto a
/// regular polygon, inverse stereographic projection.
fn tutte_start(
    mesh: &Mesh,
    removed: FaceId,
    kind: Weights,
    settings: &Settings,
    context: &mut Context<'_>,
    report: &mut Report,
) -> Result<Vec<Point3<f64>>, SolverError> {
    let punctured = context.stage("puncture", report, || puncture(mesh, removed))?;
    let share = mesh.face_area(removed) / mesh.total_area();
    let radius = cap_radius(share);
    report.notes.push(format!(
        "removed face {} (input index, a {}) covering {:.3e} of the area; its vertices go to a circle of radius {radius:.4} before the projection",
        mesh.face_to_input(removed),
        if mesh.face_degree(removed) == 3 {
            "triangle"
        } else {
            "quad"
        },
        share
    ));

    let (planar, negative) = context.stage("tutte", report, || {
        let weights = edge_weights(&punctured, kind).map_err(weight_error)?;
        let boundary = hole_boundary(&punctured, radius);
        let system = WeightedMeanSystem::new(&weights, &boundary)?;
        let negative = weights.negative_count(system.interior().iter().copied());
        Ok((system.solve(solve_options(settings))?, negative))
    })?;
    if negative > 0 {
        report.notes.push(format!(
            "{negative} mean-value weights of interior vertices are negative (reflex quad corners); the bijectivity theorem needs positive weights"
        ));
    }

    context.stage("projection", report, || {
        Ok(planar.iter().map(|&z| inverse_stereographic(z)).collect())
    })
}

/// The capability check, returning the weights to use.
fn weights(problem: &Problem<'_>, settings: &Settings) -> Result<Weights, SolverError> {
    let unsupported = |message: String| Err(SolverError::unsupported(NAME, message));
    topology::require_sphere(NAME, problem.source, NOT_A_SPHERE)?;
    match &problem.target {
        Target::Sphere => {}
        Target::Plane(_) | Target::Disk | Target::Annulus { .. } | Target::CircleDomain => {
            return unsupported(
                "sphere maps onto the unit sphere; for planar targets cut the mesh into a disk (or remove a face) and use tutte, harmonic or lscm"
                    .to_string(),
            );
        }
        Target::Mesh(_) | Target::Surface => {
            return unsupported(
                "sphere maps onto the unit sphere; for maps onto a surface use beltrami-flow or lsqc"
                    .to_string(),
            );
        }
    }
    match &problem.goal {
        Goal::Conformal { p } if *p == 2.0 => {}
        Goal::Conformal { p } => {
            return unsupported(format!(
                "sphere computes a fixed initial map and minimizes no norm of mu, so it cannot aim at p = {p}; start beltrami-flow from its map"
            ));
        }
        Goal::Prescribed(_) => {
            return unsupported(
                "sphere computes a fixed initial map and cannot follow a prescribed Beltrami coefficient; start beltrami-flow from its map"
                    .to_string(),
            );
        }
        Goal::Features(_) => {
            return unsupported(
                "sphere computes a fixed initial map and matches no features; features are matched by register"
                    .to_string(),
            );
        }
        Goal::Extremal => {
            return unsupported(
                "sphere computes a fixed initial map, not an extremal (Teichmueller) map; use teichmuller"
                    .to_string(),
            );
        }
    }
    let constraints = &problem.constraints;
    if let Some(pin) = constraints.pins().next() {
        return unsupported(format!(
            "sphere places every vertex itself and takes no pins (given: {}, the first on vertex {}); pin landmarks in beltrami-flow, starting from this map",
            constraints.pins().count(),
            pin.vertex
        ));
    }
    let curves = constraints.curves().count();
    if curves > 0 {
        return unsupported(format!(
            "sphere cannot make vertices follow curves (given: {curves}); use beltrami-flow"
        ));
    }
    Ok(crate::weights_of(settings))
}

/// The face to remove: the largest area times shape quality `q_f` (module docs). The
/// mesh is closed, so it has faces; ties go to the first face.
fn removed_face(mesh: &Mesh) -> FaceId {
    let score = |f: FaceId| {
        let area = mesh.face_area(f);
        let squares: f64 = mesh
            .face_halfedges(f)
            .map(|h| mesh.halfedge_vector(h).norm_squared())
            .sum();
        let n = mesh.face_degree(f) as f64;
        let quality = 4.0 * (PI / n).tan() * area / squares;
        let score = area * quality;
        if score.is_finite() { score } else { 0.0 }
    };
    mesh.faces()
        .map(|f| (f, score(f)))
        .fold((FaceId(0), f64::NEG_INFINITY), |best, (f, s)| {
            if s > best.1 { (f, s) } else { best }
        })
        .0
}

/// The mesh without face `removed`, with the same vertex ids.
fn puncture(mesh: &Mesh, removed: FaceId) -> Result<Mesh, SolverError> {
    let punctured = mesh.punctured(removed)?;
    let map = punctured.vertex_map();
    if let Some(v) = mesh
        .vertices()
        .find(|&v| map.from_input(v.idx()) != Some(v))
    {
        return Err(SolverError::invalid(
            NAME,
            format!(
                "removing face {} (input index) left vertex {} (input index) without faces",
                mesh.face_to_input(removed),
                mesh.vertex_map().to_input(v)
            ),
        ));
    }
    if !punctured.is_disk() {
        return Err(SolverError::invalid(
            NAME,
            format!(
                "removing face {} (input index) left {} instead of a disk",
                mesh.face_to_input(removed),
                topology::describe(&punctured)
            ),
        ));
    }
    Ok(punctured)
}

/// `R = sqrt(1/a - 1)` for the removed face's area share `a` (module docs); 1 if `a` is
/// not in `(0, 1)`.
fn cap_radius(share: f64) -> f64 {
    let radius = (1.0 / share - 1.0).sqrt();
    if radius.is_finite() && radius > 0.0 {
        radius
    } else {
        1.0
    }
}

/// The boundary loop of the punctured mesh (the removed face's outline, `n` vertices) on
/// the corners `R exp(2 pi i k / n)` of a regular polygon, counter-clockwise in loop
/// order (module docs).
fn hole_boundary(punctured: &Mesh, radius: f64) -> BoundaryMap {
    let vertices: Vec<VertexId> = punctured
        .boundary_loops()
        .flat_map(|b| punctured.loop_vertices(b))
        .collect();
    let n = vertices.len() as f64;
    let positions = (0..vertices.len())
        .map(|k| Complex64::from_polar(radius, TAU * k as f64 / n))
        .collect();
    BoundaryMap {
        vertices,
        positions,
    }
}

/// `s(z) = (2x, 2y, |z|^2 - 1) / (|z|^2 + 1)`, the inverse stereographic projection from
/// the north pole.
fn inverse_stereographic(z: Complex64) -> Point3<f64> {
    let r2 = z.norm_sqr();
    let d = r2 + 1.0;
    Point3::new(2.0 * z.re / d, 2.0 * z.im / d, (r2 - 1.0) / d)
}

/// The mean of the images of `f`'s vertices.
fn image_mean(mesh: &Mesh, image: &[Point3<f64>], f: FaceId) -> Vector3<f64> {
    let (vertices, n) = mesh.face_vertex_array(f);
    vertices[..n]
        .iter()
        .map(|v| image[v.idx()].coords)
        .sum::<Vector3<f64>>()
        / n as f64
}

/// The unit radial direction at the image of `f` (zero if the image's mean is the
/// origin).
fn radial_direction(mesh: &Mesh, image: &[Point3<f64>], f: FaceId) -> Vector3<f64> {
    let m = image_mean(mesh, image, f);
    let norm = m.norm();
    if norm > 0.0 { m / norm } else { m }
}

/// The centre of mass `c = sum_f A_f x_f / sum_f A_f` of the source area carried to the
/// sphere and the second moment `M = sum_f A_f x_f x_f^T / sum_f A_f`, `x_f` the radial
/// direction at the image of face `f`.
fn moments(mesh: &Mesh, areas: &[f64], image: &[Point3<f64>]) -> (Vector3<f64>, Matrix3<f64>) {
    let total: f64 = areas.iter().sum();
    let (mut c, mut m) = (Vector3::zeros(), Matrix3::zeros());
    for (f, &a) in mesh.faces().zip(areas) {
        let x = radial_direction(mesh, image, f);
        c += a * x;
        m += a * x * x.transpose();
    }
    (c / total, m / total)
}

/// `phi_b` (module docs) on the unit sphere, the result projected back to unit length.
fn moebius(b: Vector3<f64>, source: &[Point3<f64>], target: &mut Vec<Point3<f64>>) {
    let shrink = 1.0 - b.norm_squared();
    target.clear();
    target.extend(source.iter().map(|p| {
        let d = p.coords - b;
        let q = shrink / d.norm_squared() * d - b;
        Point3::from(q / q.norm())
    }));
}

/// Moebius centering (module docs): applies `phi_b` to every image point until the
/// centre of mass `c` is within [`CENTER_TOLERANCE`] of the origin or after
/// [`max_steps`] steps, recording each step in the report; the "normalization" timing.
///
/// Each step tries, in order, the Newton step of the linearization,
/// `b = (2 (I - M))^{-1} c` (when it is inside the ball), then `b = c` (Baden, Crane and
/// Kazhdan's iteration) and `c/2, c/4, ...`, and takes the first that moves the centre of
/// mass closer to the origin; the Newton step converges in a few steps where the
/// linearization holds, the others keep the far steps safe.
fn normalize(
    mesh: &Mesh,
    image: &mut Vec<Point3<f64>>,
    max_steps: usize,
    context: &mut Context<'_>,
    report: &mut Report,
    metrics: &mut Metrics,
) -> Result<(), SolverError> {
    context.check_cancelled()?;
    let start = std::time::Instant::now();
    let centering = centre(mesh, image, max_steps, |steps, distance| {
        context.check_cancelled()?;
        metrics.energy_history.push(distance);
        context.report(&Progress {
            stage: "normalization",
            done: steps,
            total: Some(max_steps),
            energy: Some(distance),
        });
        Ok(())
    })?;
    let Centering {
        steps,
        initial,
        last,
    } = centering;
    metrics.iterations = steps;
    report
        .timings
        .push(("normalization".to_string(), start.elapsed().as_secs_f64()));
    if last <= CENTER_TOLERANCE {
        report.notes.push(format!(
            "Moebius centering moved the centre of mass of the area from {initial:.3e} to {last:.1e} from the origin in {steps} steps"
        ));
    } else {
        report.notes.push(format!(
            "Moebius centering stopped after {steps} steps with the centre of mass of the area {last:.3e} from the origin (started at {initial:.3e})"
        ));
    }
    Ok(())
}

/// How a Moebius centering went: steps taken, and the distance of the centre of mass
/// from the origin before and after.
#[derive(Debug, Clone, Copy)]
struct Centering {
    steps: usize,
    initial: f64,
    last: f64,
}

/// The centering iteration of [`normalize`] (module docs), calling `on_step(steps,
/// distance)` after each step; the image ends at unit length to the last bit.
fn centre(
    mesh: &Mesh,
    image: &mut Vec<Point3<f64>>,
    max_steps: usize,
    mut on_step: impl FnMut(usize, f64) -> Result<(), SolverError>,
) -> Result<Centering, SolverError> {
    let areas: Vec<f64> = mesh.faces().map(|f| mesh.face_area(f)).collect();
    let (mut c, mut m) = moments(mesh, &areas, image);
    let initial = c.norm();
    let mut trial = Vec::with_capacity(image.len());
    let mut steps = 0;
    // An average of unit vectors lies in the closed ball; on its boundary (all mass at
    // one point) no Moebius transformation can spread it.
    while c.norm() > CENTER_TOLERANCE && c.norm() < 1.0 && steps < max_steps {
        let newton = (2.0 * (Matrix3::identity() - m))
            .try_inverse()
            .map(|inverse| inverse * c)
            .filter(|b| b.norm() < 1.0);
        let halvings = (0..MAX_HALVINGS).map(|k| c / f64::from(1u32 << k));
        let mut improved = None;
        for b in newton.into_iter().chain(halvings) {
            moebius(b, image, &mut trial);
            let (c_trial, m_trial) = moments(mesh, &areas, &trial);
            if c_trial.norm() < c.norm() {
                improved = Some((c_trial, m_trial));
                break;
            }
        }
        let Some((c_new, m_new)) = improved else {
            break;
        };
        std::mem::swap(image, &mut trial);
        (c, m) = (c_new, m_new);
        steps += 1;
        on_step(steps, c.norm())?;
    }
    // Unit length to the last bit, also where no step was taken.
    for p in image.iter_mut() {
        *p = Point3::from(p.coords / p.coords.norm());
    }
    Ok(Centering {
        steps,
        initial,
        last: c.norm(),
    })
}

/// Per face: true if its image faces the centre (module docs: a triangle whose normal
/// points inward, a quad with such a triangle in either diagonal split).
fn inward_faces(mesh: &Mesh, image: &[Point3<f64>]) -> Vec<bool> {
    mesh.faces().map(|f| is_inward(mesh, image, f)).collect()
}

/// True if the image of `f` faces the centre (module docs).
fn is_inward(mesh: &Mesh, image: &[Point3<f64>], f: FaceId) -> bool {
    const TRIANGLES: [[usize; 3]; 1] = [[0, 1, 2]];
    const QUAD_SPLITS: [[usize; 3]; 4] = [[0, 1, 2], [0, 2, 3], [0, 1, 3], [1, 2, 3]];
    let (vertices, n) = mesh.face_vertex_array(f);
    let p = |k: usize| image[vertices[k].idx()];
    let m = image_mean(mesh, image, f);
    let triangles: &[[usize; 3]] = if n == 3 { &TRIANGLES } else { &QUAD_SPLITS };
    triangles.iter().any(|&[a, b, c]| {
        let normal = (p(b) - p(a)).cross(&(p(c) - p(a)));
        normal.dot(&m) <= 0.0
    })
}

/// The signed volume `sum_f (1/6) p0 . (p1 x p2)` enclosed by the source (quads split
/// along `v0 v2`); positive when the faces face outward.
fn signed_volume(mesh: &Mesh) -> f64 {
    mesh.faces()
        .map(|f| {
            let (vertices, n) = mesh.face_vertex_array(f);
            let p = |k: usize| mesh.position(vertices[k]).coords;
            (1..n - 1)
                .map(|k| p(0).dot(&p(k).cross(&p(k + 1))))
                .sum::<f64>()
                / 6.0
        })
        .sum()
}
