//! Disks: both meshes onto the target's Tutte disk.
//!
//! The target's boundary loop goes onto the unit circle by arc length, clockwise in loop
//! order (`v_j -> exp(-2 pi i t_j)`, `t_j` the fraction of the loop length before `v_j`),
//! and its interior by Tutte's embedding with mean-value weights: a bijection onto the
//! inscribed polygon `D` ([`crate::param`]). The source's boundary vertex with arc-length
//! fraction `s_i` goes to the point of `D`'s boundary at fraction `s_i + delta`
//! (linear along the polygon's side between the two target vertices whose fractions
//! enclose it), and its interior by Tutte's embedding again: a bijection onto the same
//! polygon `D`. Locating the source's images in the target's embedding is then the
//! composition of a bijection with the inverse of one, and every source point lands
//! inside `D` (at distance 0 from the target's parameter mesh).
//!
//! `delta` is the boundary alignment without boundary landmarks: the one of 720 equally
//! spaced rotations that brings the source's boundary vertices closest, in the sum of
//! squared distances, to their images on the target's boundary after the rough spatial
//! match of [`SpatialMatch`]. With boundary landmarks (each target on the target's
//! boundary, in the same cyclic order on both loops) each lands on its target and the
//! vertices between two of them are spread by arc length over the stretch between their
//! targets. Interior landmarks are then matched in the disk by the landmark-matching
//! quasiconformal map of [`crate::landmark_match`] bent from the source's Tutte map, the
//! whole boundary held: every landmark lands exactly on its target.
//!
//! A source *ear* (a face with two boundary edges, `u -> m -> w` along the loop)
//! collapses onto a segment when no target boundary vertex lies strictly between the
//! images of `u` and `w`: all three vertices then land on one side of `D`, whatever
//! `m`'s image. Such ears are counted in the notes (they count as flipped); a target
//! boundary at least as fine as the source's avoids them.

use beltrami_core::FeatureMismatch;
use std::f64::consts::TAU;

use beltrami_fem::{BoundaryMap, Frame};
use beltrami_mesh::{BoundaryLoopId, Mesh, Point3, SurfacePoint, VertexId, parallel};
use num_complex::Complex64;

use crate::Routed;
use crate::compose;
use crate::error::{RegisterError, Side};
use crate::feature_match::{Channel, match_features};
use crate::landmark_match::match_landmarks;
use crate::landmarks::{Resolved, SpatialMatch, interpolate};
use crate::param::{arc_fractions, domain_mesh, planar_points, tutte};

/// Candidate rotations tried without a boundary landmark.
const ROTATIONS: usize = 720;

/// A landmark target this close (in coordinates) to a boundary edge counts as on it.
const ON_BOUNDARY: f64 = 1e-9;

/// The target's boundary: vertices in loop order, their fractions and their images.
struct Outline {
    vertices: Vec<VertexId>,
    fractions: Vec<f64>,
    images: Vec<Complex64>,
    positions: Vec<Point3<f64>>,
}

impl Outline {
    /// The target's boundary loop onto the unit circle by arc length, clockwise in loop
    /// order (module docs): the outline both Tutte maps share.
    fn of(target: &Mesh) -> Self {
        let target_loop: Vec<VertexId> = target.loop_vertices(BoundaryLoopId(0)).collect();
        let fractions = arc_fractions(target, &target_loop);
        let images: Vec<Complex64> = fractions
            .iter()
            .map(|&t| Complex64::from_polar(1.0, -TAU * t))
            .collect();
        Outline {
            positions: target_loop.iter().map(|&v| target.position(v)).collect(),
            vertices: target_loop,
            fractions,
            images,
        }
    }

    /// The side `j` (from vertex `j` to `j + 1`) holding fraction `tau` in `[0, 1)` and
    /// the linear parameter along it.
    fn side(&self, tau: f64) -> (usize, f64) {
        let n = self.fractions.len();
        let j = self
            .fractions
            .partition_point(|&t| t <= tau)
            .saturating_sub(1);
        let end = if j + 1 < n {
            self.fractions[j + 1]
        } else {
            1.0
        };
        let span = end - self.fractions[j];
        let lambda = if span > 0.0 {
            ((tau - self.fractions[j]) / span).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (j, lambda)
    }

    fn image(&self, tau: f64) -> Complex64 {
        let (j, lambda) = self.side(tau.rem_euclid(1.0));
        let next = (j + 1) % self.images.len();
        self.images[j] + (self.images[next] - self.images[j]) * lambda
    }

    fn position(&self, tau: f64) -> Point3<f64> {
        let (j, lambda) = self.side(tau.rem_euclid(1.0));
        let next = (j + 1) % self.positions.len();
        self.positions[j] + (self.positions[next] - self.positions[j]) * lambda
    }
}

/// The source's boundary loop: its vertices in loop order, each vertex's position in it
/// (`usize::MAX` off the loop) and their arc-length fractions.
struct SourceLoop {
    /// The loop's vertices in loop order.
    vertices: Vec<VertexId>,
    /// Every source vertex's position in `vertices`, `usize::MAX` off the loop.
    index: Vec<usize>,
    /// The arc-length fraction before each vertex of `vertices`.
    sigma: Vec<f64>,
}

impl SourceLoop {
    /// The first boundary loop of `source`.
    fn of(source: &Mesh) -> Self {
        let vertices: Vec<VertexId> = source.loop_vertices(BoundaryLoopId(0)).collect();
        let mut index = vec![usize::MAX; source.vertex_count()];
        for (i, v) in vertices.iter().enumerate() {
            index[v.idx()] = i;
        }
        let sigma = arc_fractions(source, &vertices);
        Self {
            vertices,
            index,
            sigma,
        }
    }
}

/// The source's images on the target, the landmarks honoured exactly (indices into
/// `marks`) and the target's disk (its Tutte map, per target vertex).
pub(crate) fn map(
    source: &Mesh,
    target: &Mesh,
    marks: &[Resolved],
    notes: &mut Vec<String>,
) -> Result<Routed<Vec<Complex64>>, RegisterError> {
    let outline = Outline::of(target);
    let target_boundary = BoundaryMap {
        vertices: outline.vertices.clone(),
        positions: outline.images.clone(),
    };
    let source_loop = SourceLoop::of(source);

    // A landmark with one end on the boundary and the other inside, or boundary
    // landmarks in another cyclic order on the two loops, are refused before either
    // Tutte map is computed.
    let pinned = boundary_landmarks(source, target, &outline, marks, &source_loop.index)?;

    let tau = boundary_fractions(
        source,
        target,
        &source_loop,
        &outline,
        marks,
        &pinned,
        notes,
    );
    let source_loop = source_loop.vertices;
    let collapsed = collapsed_ears(source, &source_loop, &tau, &outline);
    if collapsed > 0 {
        notes.push(format!(
            "disk: {collapsed} source ears (faces with two boundary edges) have all three vertices on one boundary edge of the target and collapse onto it (refine the target's boundary)"
        ));
    }
    let source_boundary = BoundaryMap {
        vertices: source_loop.clone(),
        positions: tau.iter().map(|&t| outline.image(t)).collect(),
    };
    // The two Tutte maps are independent: both at once, on two cores.
    let (target_param, source_param) = parallel::join(
        || tutte(target, &target_boundary, Side::Target),
        || tutte(source, &source_boundary, Side::Source),
    );
    let target_param = target_param?;
    let mut source_param = source_param?;
    // Each landmark's source vertex goes where its target lies in the target's map: on
    // the boundary at once, inside through the matching in the disk.
    for &(m, _, _) in &pinned {
        source_param[marks[m].source.idx()] = interpolate(target, &target_param, &marks[m].target);
    }
    let source_param = match_interior_landmarks(
        source,
        target,
        &target_param,
        &source_loop,
        marks,
        source_param,
        notes,
    )?;
    let domain = domain_mesh(target, planar_points(&target_param), Side::Target)?;
    let (points, gap) = compose::locate(&domain, &planar_points(&source_param))?;
    if gap > 1e-12 {
        notes.push(format!(
            "disk: the farthest source image was {gap:.3e} outside the target's disk and was moved onto it"
        ));
    }
    Ok(Routed {
        points,
        honoured: (0..marks.len()).collect(),
        domain: target_param,
    })
}

/// The fraction of the target's boundary every source boundary vertex goes to (module
/// docs): the best rotation without boundary landmarks, else by arc length between the
/// `pinned` ones; the choice is noted.
fn boundary_fractions(
    source: &Mesh,
    target: &Mesh,
    source_loop: &SourceLoop,
    outline: &Outline,
    marks: &[Resolved],
    pinned: &[(usize, usize, f64)],
    notes: &mut Vec<String>,
) -> Vec<f64> {
    let sigma = &source_loop.sigma;
    if pinned.is_empty() {
        let delta = best_rotation(source, target, &source_loop.vertices, sigma, outline);
        notes.push(format!(
            "disk: no boundary landmark; boundary rotated by {delta:.4} turns, the best of {ROTATIONS} for a rough spatial match (centroids and sizes)"
        ));
        sigma.iter().map(|s| s + delta).collect()
    } else {
        notes.push(format!(
            "disk: boundary laid so that landmarks {} land on their targets, by arc length between them",
            pinned
                .iter()
                .map(|p| marks[p.0].index.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ));
        between_landmarks(sigma, pinned)
    }
}

/// The source's Tutte map `source_param` bent so that the interior landmarks land on
/// their targets in the target's disk `target_param` (module docs), the whole boundary
/// held; unchanged without interior landmarks.
///
/// # Errors
/// [`RegisterError::LandmarkFolds`] when the matching leaves flipped faces; the errors
/// of [`match_landmarks`].
fn match_interior_landmarks(
    source: &Mesh,
    target: &Mesh,
    target_param: &[Complex64],
    source_loop: &[VertexId],
    marks: &[Resolved],
    source_param: Vec<Complex64>,
    notes: &mut Vec<String>,
) -> Result<Vec<Complex64>, RegisterError> {
    let interior: Vec<usize> = (0..marks.len())
        .filter(|&m| !source.is_boundary_vertex(marks[m].source))
        .collect();
    if interior.is_empty() {
        return Ok(source_param);
    }
    let fixed: Vec<(VertexId, Complex64)> = source_loop
        .iter()
        .map(|&v| (v, source_param[v.idx()]))
        .chain(interior.iter().map(|&m| {
            (
                marks[m].source,
                interpolate(target, target_param, &marks[m].target),
            )
        }))
        .collect();
    let matched = match_landmarks(
        source,
        Frame::Face,
        &source_param,
        &fixed,
        &[],
        Side::Source,
    )?;
    let matched = matched.without_folds("disk")?;
    notes.push(format!(
        "disk: {} interior landmarks matched in the disk ({} smoothing steps)",
        interior.len(),
        matched.steps
    ));
    Ok(matched.map)
}

/// The registration `points` (a bijection of the disks, the landmarks exact) bent in the
/// target's disk `target_param` so that `features` match (module `feature_match`), its
/// boundary and landmarks held.
pub(crate) fn match_features_after(
    source: &Mesh,
    target: &Mesh,
    target_param: &[Complex64],
    points: &[SurfacePoint],
    marks: &[Resolved],
    channels: &[Channel],
    notes: &mut Vec<String>,
) -> Result<(Vec<SurfacePoint>, FeatureMismatch), RegisterError> {
    let chart: Vec<Complex64> = points
        .iter()
        .map(|p| interpolate(target, target_param, p))
        .collect();
    let fixed: Vec<(VertexId, Complex64)> = source
        .vertices()
        .filter(|&v| source.is_boundary_vertex(v))
        .chain(marks.iter().map(|m| m.source))
        .map(|v| (v, chart[v.idx()]))
        .collect();
    let domain = domain_mesh(target, planar_points(target_param), Side::Target)?;
    let matched = match_features(source, &chart, &fixed, channels, &domain, Side::Source)?;
    notes.push(format!(
        "disk: features matched in the target's disk with the boundary and the landmarks held: mismatch {:.4} -> {:.4} (mean squared difference of the fields) in {} steps",
        matched.before, matched.after, matched.steps
    ));
    let (located, _) = compose::locate(&domain, &planar_points(&matched.map))?;
    let mismatch = FeatureMismatch {
        before: matched.before,
        after: matched.after,
        steps: matched.steps,
    };
    Ok((located, mismatch))
}

/// The boundary fractions of the source's loop vertices (arc-length fractions `sigma`)
/// laid between the boundary landmarks `pinned` (`(mark, position in the loop, target
/// fraction)`): each landmark at its target's fraction, the vertices between two
/// landmarks spread by arc length over the target's stretch between them. Unwrapped:
/// increasing along the loop.
fn between_landmarks(sigma: &[f64], pinned: &[(usize, usize, f64)]) -> Vec<f64> {
    let mut order: Vec<(usize, f64)> = pinned.iter().map(|&(_, i, t)| (i, t)).collect();
    order.sort_by_key(|&(i, _)| i);
    let n = order.len();
    let mut tau = vec![0.0; sigma.len()];
    for k in 0..n {
        let (i0, t0) = order[k];
        let (i1, t1) = order[(k + 1) % n];
        let source_span = if n == 1 {
            1.0
        } else {
            (sigma[i1] - sigma[i0]).rem_euclid(1.0)
        };
        let target_span = if n == 1 {
            1.0
        } else {
            (t1 - t0).rem_euclid(1.0)
        };
        let mut i = i0;
        loop {
            let along = (sigma[i] - sigma[i0]).rem_euclid(1.0);
            tau[i] = t0 + target_span * along / source_span;
            i = (i + 1) % sigma.len();
            if i == i1 {
                break;
            }
        }
    }
    for i in 1..tau.len() {
        while tau[i] < tau[i - 1] {
            tau[i] += 1.0;
        }
    }
    tau
}

/// The landmarks whose source vertex is on the boundary, as `(index into marks,
/// position in the source's loop, fraction of its target along the target's loop)`;
/// an error names a landmark with one end on the boundary and the other inside, and a
/// landmark that breaks the cyclic order of the boundary landmarks (an
/// orientation-preserving map keeps the order of points along the boundary).
fn boundary_landmarks(
    source: &Mesh,
    target: &Mesh,
    outline: &Outline,
    marks: &[Resolved],
    loop_index: &[usize],
) -> Result<Vec<(usize, usize, f64)>, RegisterError> {
    let mut pinned = Vec::new();
    for (m, mark) in marks.iter().enumerate() {
        let on_source = source.is_boundary_vertex(mark.source);
        let on_target = boundary_fraction(target, outline, mark)?;
        match (on_source, on_target) {
            (true, Some(tau)) => pinned.push((m, loop_index[mark.source.idx()], tau)),
            (false, None) => {}
            (true, None) => {
                return Err(RegisterError::Landmark {
                    index: mark.index,
                    vertex: mark.source,
                    reason: "the source vertex is on the boundary but its target is not: a disk map takes the boundary onto the boundary".to_string(),
                });
            }
            (false, Some(_)) => {
                return Err(RegisterError::Landmark {
                    index: mark.index,
                    vertex: mark.source,
                    reason: "the source vertex is inside the disk but its target is on the boundary: a disk map takes the boundary onto the boundary".to_string(),
                });
            }
        }
    }
    // Along the source's loop the targets' fractions must turn once around the
    // target's loop: their steps (mod 1) add up to one turn exactly when the cyclic
    // orders agree.
    let mut order = pinned.clone();
    order.sort_by_key(|p| p.1);
    let n = order.len();
    if n >= 3 {
        let mut turned = 0.0;
        for k in 0..n {
            let step = (order[(k + 1) % n].2 - order[k].2).rem_euclid(1.0);
            turned += step;
            if turned > 1.0 + 1e-9 || step == 0.0 {
                let mark = &marks[order[(k + 1) % n].0];
                return Err(RegisterError::Landmark {
                    index: mark.index,
                    vertex: mark.source,
                    reason: "its target breaks the order of the boundary landmarks: along the two boundary loops they come in different cyclic orders (or two share a target), and an orientation-preserving map keeps the order along the boundary".to_string(),
                });
            }
        }
    }
    Ok(pinned)
}

/// The boundary fraction of a landmark's target when it lies on the target's boundary:
/// a boundary vertex's own fraction, or on a boundary edge the fractions of its ends
/// mixed by the point's coordinates.
fn boundary_fraction(
    target: &Mesh,
    outline: &Outline,
    mark: &Resolved,
) -> Result<Option<f64>, RegisterError> {
    let position_in_loop = |v: VertexId| outline.vertices.iter().position(|&w| w == v);
    if let Some(v) = mark.vertex {
        return Ok(position_in_loop(v).map(|j| outline.fractions[j]));
    }
    let point = &mark.target;
    let (vertices, degree) = target.face_vertex_array(point.face);
    for (k, h) in target.face_halfedges(point.face).enumerate() {
        if !target.is_boundary_halfedge(target.twin(h)) {
            continue;
        }
        let next = (k + 1) % degree;
        let (cu, cw) = (point.coords[k], point.coords[next]);
        if cu + cw < 1.0 - ON_BOUNDARY {
            continue;
        }
        // The boundary halfedge runs from target(h) = vertex j to origin(h) = vertex j + 1.
        let (Some(j), Some(_)) = (
            position_in_loop(vertices[next]),
            position_in_loop(vertices[k]),
        ) else {
            continue;
        };
        let start = outline.fractions[j];
        let end = outline.fractions.get(j + 1).copied().unwrap_or(1.0);
        return Ok(Some(start + (end - start) * cu / (cu + cw)));
    }
    Ok(None)
}

/// The rotation (in turns) of the source's boundary fractions that minimizes the sum of
/// squared distances between the source's boundary vertices, moved by the spatial match,
/// and the target boundary points they would go to.
fn best_rotation(
    source: &Mesh,
    target: &Mesh,
    source_loop: &[VertexId],
    sigma: &[f64],
    outline: &Outline,
) -> f64 {
    let spatial = SpatialMatch::new(source, target);
    let moved: Vec<Point3<f64>> = source_loop
        .iter()
        .map(|&v| spatial.to_target(&source.position(v)))
        .collect();
    let cost = |delta: f64| -> f64 {
        moved
            .iter()
            .zip(sigma)
            .map(|(p, s)| (p - outline.position(s + delta)).norm_squared())
            .sum()
    };
    (0..ROTATIONS)
        .map(|k| k as f64 / ROTATIONS as f64)
        .map(|d| (d, cost(d)))
        .fold(
            (0.0, f64::INFINITY),
            |best, c| if c.1 < best.1 { c } else { best },
        )
        .0
}

/// The number of source ears (boundary vertices `m` with a single face, between `u` and
/// `w` along the loop) with no target boundary vertex strictly between the images of `u`
/// and `w`: their three vertices land on one side of the target polygon, which no choice
/// of `m`'s image avoids. `tau` are the unwrapped boundary fractions, increasing along
/// the loop.
fn collapsed_ears(
    source: &Mesh,
    source_loop: &[VertexId],
    tau: &[f64],
    outline: &Outline,
) -> usize {
    let n = source_loop.len();
    source_loop
        .iter()
        .enumerate()
        .filter(|&(i, &m)| {
            if source.vertex_degree(m) != 2 {
                return false;
            }
            let (prev, next) = ((i + n - 1) % n, (i + 1) % n);
            let lo = tau[prev] - if prev > i { 1.0 } else { 0.0 };
            let hi = tau[next] + if next < i { 1.0 } else { 0.0 };
            !outline
                .fractions
                .iter()
                .map(|&t| t + (lo - t).floor() + 1.0)
                .any(|x| x > lo && x < hi)
        })
        .count()
}
