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
//! `delta` is the boundary alignment: given by the first landmark whose source vertex is
//! on the boundary (its target must be on the target's boundary, and it lands there
//! exactly), otherwise the one of 720 equally spaced rotations that brings the source's
//! boundary vertices closest, in the sum of squared distances, to their images on the
//! target's boundary after the rough spatial match of [`SpatialMatch`].
//!
//! A source *ear* (a face with two boundary edges, `u -> m -> w` along the loop)
//! collapses onto a segment when no target boundary vertex lies strictly between the
//! images of `u` and `w`: all three vertices then land on one side of `D`, whatever
//! `m`'s image. Such ears are counted in the notes (they count as flipped); a target
//! boundary at least as fine as the source's avoids them.

use std::f64::consts::TAU;

use beltrami_fem::BoundaryMap;
use beltrami_mesh::{BoundaryLoopId, Mesh, Point3, SurfacePoint, VertexId, parallel};
use num_complex::Complex64;

use crate::compose;
use crate::error::{RegisterError, Side};
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

/// The source's images on the target and the landmarks honoured exactly (indices into
/// `marks`).
pub(crate) fn map(
    source: &Mesh,
    target: &Mesh,
    marks: &[Resolved],
    notes: &mut Vec<String>,
) -> Result<(Vec<SurfacePoint>, Vec<usize>), RegisterError> {
    let target_loop: Vec<VertexId> = target.loop_vertices(BoundaryLoopId(0)).collect();
    let fractions = arc_fractions(target, &target_loop);
    let images: Vec<Complex64> = fractions
        .iter()
        .map(|&t| Complex64::from_polar(1.0, -TAU * t))
        .collect();
    let outline = Outline {
        positions: target_loop.iter().map(|&v| target.position(v)).collect(),
        vertices: target_loop,
        fractions,
        images,
    };
    let target_boundary = BoundaryMap {
        vertices: outline.vertices.clone(),
        positions: outline.images.clone(),
    };

    let source_loop: Vec<VertexId> = source.loop_vertices(BoundaryLoopId(0)).collect();
    let mut loop_index = vec![usize::MAX; source.vertex_count()];
    for (i, v) in source_loop.iter().enumerate() {
        loop_index[v.idx()] = i;
    }
    let sigma = arc_fractions(source, &source_loop);

    // A landmark with one end on the boundary and the other inside is refused before
    // either Tutte map is computed.
    let pinned = boundary_landmark(source, target, &outline, marks, &loop_index)?;

    let delta = match pinned {
        Some((m, i, tau)) => {
            notes.push(format!(
                "disk: boundary rotated so that landmark {} (source vertex {}) lands on its target",
                marks[m].index,
                source.vertex_map().to_input(marks[m].source)
            ));
            tau - sigma[i]
        }
        None => {
            let delta = best_rotation(source, target, &source_loop, &sigma, &outline);
            notes.push(format!(
                "disk: no boundary landmark; boundary rotated by {delta:.4} turns, the best of {ROTATIONS} for a rough spatial match (centroids and sizes)"
            ));
            delta
        }
    };
    let tau: Vec<f64> = sigma.iter().map(|s| s + delta).collect();
    let collapsed = collapsed_ears(source, &source_loop, &tau, &outline);
    if collapsed > 0 {
        notes.push(format!(
            "disk: {collapsed} source ears (faces with two boundary edges) have all three vertices on one boundary edge of the target and collapse onto it (refine the target's boundary)"
        ));
    }
    let mut source_boundary = BoundaryMap {
        vertices: source_loop,
        positions: tau.iter().map(|&t| outline.image(t)).collect(),
    };
    let (target_param, source_param) = match pinned {
        // The two Tutte maps are independent: both at once, on two cores.
        None => {
            let (target_param, source_param) = parallel::join(
                || tutte(target, &target_boundary, Side::Target),
                || tutte(source, &source_boundary, Side::Source),
            );
            (target_param?, source_param?)
        }
        // The pinned landmark's source vertex goes where its target lies in the
        // target's map.
        Some((m, i, _)) => {
            let target_param = tutte(target, &target_boundary, Side::Target)?;
            source_boundary.positions[i] = interpolate(target, &target_param, &marks[m].target);
            let source_param = tutte(source, &source_boundary, Side::Source)?;
            (target_param, source_param)
        }
    };
    let domain = domain_mesh(target, planar_points(&target_param), Side::Target)?;
    let (points, gap) = compose::locate(&domain, &planar_points(&source_param))?;
    if gap > 1e-12 {
        notes.push(format!(
            "disk: the farthest source image was {gap:.3e} outside the target's disk and was moved onto it"
        ));
    }
    Ok((points, pinned.map(|p| vec![p.0]).unwrap_or_default()))
}

/// The first landmark whose source vertex is on the boundary, as `(index into marks,
/// position in the source's loop, fraction of its target along the target's loop)`;
/// an error names a landmark with one end on the boundary and the other inside.
fn boundary_landmark(
    source: &Mesh,
    target: &Mesh,
    outline: &Outline,
    marks: &[Resolved],
    loop_index: &[usize],
) -> Result<Option<(usize, usize, f64)>, RegisterError> {
    let mut pinned = None;
    for (m, mark) in marks.iter().enumerate() {
        let on_source = source.is_boundary_vertex(mark.source);
        let on_target = boundary_fraction(target, outline, mark)?;
        match (on_source, on_target) {
            (true, Some(tau)) => {
                if pinned.is_none() {
                    pinned = Some((m, loop_index[mark.source.idx()], tau));
                }
            }
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
