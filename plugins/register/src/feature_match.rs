//! Scalar fields matched in a planar parameter domain: the intensity part of the
//! landmark- and intensity-based registration of Lam and Lui (K. C. Lam, L. M. Lui,
//! SIAM J. Imaging Sci. 7, 2014, section 5), with bijectivity kept through the Beltrami
//! coefficient.
//!
//! The source mesh has a bijective map `f` into the plane (its chart of the common
//! domain) and a field `I` per source vertex; the target's chart is a planar mesh with a
//! field `J` per vertex, linear on each triangle. The mismatch is
//! `E(f) = sum_i a_i (I_i - J(f(v_i)))^2 / sum_i a_i` (`a_i` a third of the area of the
//! source faces around `v_i`), both fields standardized first (mean 0, standard
//! deviation 1 over their vertices), so that they may come in different units.
//!
//! Each step moves every free vertex by the demons force of Thirion (Med. Image Anal.
//! 2, 1998), the step of Lam and Lui's intensity term:
//! `u_i = r_i g_i / (|g_i|^2 + alpha^2 r_i^2)` with `r_i = I_i - J(f(v_i))` and
//! `g_i = grad J` at `f(v_i)`, so `|u_i| <= 1 / (2 alpha)`: `alpha` is set so that no
//! vertex moves more than the median edge of the chart in a step of length 1. The force is
//! smoothed over vertex neighbours (a Gaussian-like regularization of the
//! displacement), the change of the Beltrami coefficient it makes smoothed and added to
//! the map's own (each face cut to `|nu| <= 0.8`), and the map rebuilt from it with the
//! held vertices in place ([`Reconstruction`]): a map with `|mu| < 1` everywhere, so
//! no fold. Where the discrete rebuild still folds a few faces, its own coefficient is
//! smoothed (first near the folds, then everywhere), cut and the map rebuilt again (up
//! to `MENDING` times). A step is kept when
//! it lowers `E` and flips nothing; otherwise the step length is halved. After a kept
//! step the length doubles, up to `MAX_LENGTH`: the force is a descent direction
//! whose size shrinks with the residuals, so late steps of length 1 make little way.
//!
//! The fields are matched coarse to fine: first both smoothed (`SCALES`, passes of
//! neighbour averaging, as many more on the target as it has more vertices per area),
//! then less, then as given, each scale starting from the last's map. The pass counts
//! follow the source's resolution ([`Passes`]). A scale ends when
//! a step lowers its mismatch by less than `STALL` of its first value, after
//! `MAX_STEPS` steps (`SHAPE_MAX_STEPS` when every channel is a coordinate), or when
//! the step length falls below `MIN_STEP`.
//!
//! Figures (docs/benchmarks.md): fsaverage5 pial onto white with 24 landmarks and the
//! sulcal depth on both, 2.75 mm -> 0.39 mm mean distance to the true correspondence.

use beltrami_fem::Frame;
use beltrami_mesh::Point3;
use beltrami_mesh::parallel;
use beltrami_mesh::{BoundingBox, FaceId, Mesh, SurfacePoint, VertexId};
use beltrami_spatial::SurfaceIndex;
use beltrami_spatial::closest_point::{ClosestPoint, closest_on_face};
use kiddo::SquaredEuclidean;
use kiddo::kd_tree::KdTree;
use kiddo::leaf_strategies::VecOfArenas;
use kiddo::stem_strategies::eytzinger::Eytzinger;
use num_complex::Complex64;
use std::sync::OnceLock;

use crate::error::{RegisterError, Side};
use crate::landmark_match::Reconstruction;
use crate::param::planar_points;

/// Steps per scale at most.
const MAX_STEPS: usize = 60;

/// Steps per scale at most when every channel is a coordinate (the shape match of
/// module `shape`): its goal is a template that is itself only near the true
/// correspondence, and late steps chase it past that. fsaverage5 pial onto white by
/// shape: 1.4785 mm from the truth with 60 steps, 1.4767 with 20, 1.4777 with 10, in
/// half the time; `g0_spot` onto its deformation 0.0142, 0.0143 and 0.0150.
const SHAPE_MAX_STEPS: usize = 20;

/// Passes of neighbour averaging of both fields, coarse to fine: each scale's match
/// starts from the last, so that features farther apart than the fine fields' reach are
/// brought together first.
const SCALES: [usize; 3] = [32, 8, 0];

/// Passes of edge-neighbour averaging applied to a step's change of coefficient: fewer
/// let the map follow finer features (fsaverage5 pial onto white by the sulcal depth:
/// 0.651 mm from the truth with 8 passes, 0.625 with 4, 0.620 with 2 at a quarter more
/// time); the force's own smoothing (`FORCE_SMOOTHING`) keeps the steps from folding.
const MU_SMOOTHING: usize = 4;

/// Passes of neighbour averaging applied to the force.
const FORCE_SMOOTHING: usize = 16;

/// The source's vertex count at which `SCALES` and `FORCE_SMOOTHING` were chosen
/// (fsaverage5: 10,242 vertices).
const CALIBRATED_VERTICES: f64 = 10_242.0;

/// The smoothing passes of a match whose source has a given vertex count.
///
/// `k` passes of neighbour averaging reach about `h sqrt(k)` (`h` the edge length, a
/// random walk's spread), so on a finer mesh of the same surface the same counts reach
/// less far: a quarter of the area per vertex halves the reach. Above
/// `CALIBRATED_VERTICES` the scales' counts grow with the vertex count, so that each
/// scale reaches as far over the surface, and the force's with its square root, so
/// that a finer mesh follows finer displacements. fsaverage5's pial surface onto its
/// white surface subdivided once (40,962 vertices) with 24 landmarks and the sulcal
/// depth: 0.550 mm mean distance to the true correspondence with the calibrated
/// counts; 0.335 with the force's grown by the square root alone, 0.282 with the
/// scales' grown as well (both grown with the vertex count: 0.334, the force's less
/// smoothed than the calibrated: 0.407); the sulcal depth alone 1.262 -> 0.755 mm, by
/// shape 1.220 -> 1.213 mm. Below it they stay: spot (2,930 vertices) onto its
/// deformation by shape lands 0.0138 from the truth with them, 0.037 with the counts
/// in proportion to its vertices, 0.0176 with the force's 8.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Passes {
    /// Of both fields at each scale, coarse to fine.
    scales: [usize; 3],
    /// Of a step's force.
    force: usize,
}

impl Passes {
    fn for_vertices(vertices: usize) -> Self {
        let finer = (vertices as f64 / CALIBRATED_VERTICES).max(1.0);
        Passes {
            scales: SCALES.map(|p| (p as f64 * finer).round() as usize),
            force: (FORCE_SMOOTHING as f64 * finer.sqrt()).round() as usize,
        }
    }
}

/// A step that lowers the mismatch by less than this fraction of the first value ends
/// the matching: on fsaverage5 pial onto white with the sulcal depth, steps below it
/// each gain about `1e-5` of the mismatch and no measurable distance to the truth
/// (docs/benchmarks.md).
const STALL: f64 = 3e-4;

/// Rebuilds of a step that folds a few faces, at most.
const MENDING: usize = 3;

/// The first mending smooths the coefficient only on the faces within this many edge
/// steps of a fold, keeping the step's change elsewhere; the later ones smooth it all.
/// `g0_spot` onto its deformation by shape: 44 mending rebuilds and 18 rejected steps
/// when every mending smooths it all, the feature match 0.26 s; with the first near the
/// folds 0.21 s (1 ring) or 0.19 s (2 rings), 0.0138 from the truth in every case.
/// The paths then part, by about as much as any change to a step moves them: inflated
/// onto white with 24 landmarks and the sulcal depth 0.626 mm -> 0.635 (1 ring), 0.637
/// (2), the twisted sphere of `tests/features.rs` 0.112 -> 0.115, 0.118; near the folds
/// in every mending the inflated surface went to 0.735 mm.
const MEND_RINGS: usize = 1;

/// The smallest step length tried.
const MIN_STEP: f64 = 0.125;

/// The largest step length: after a kept step the length doubles up to this (4 made
/// half of the cortex's trials fold or rise).
const MAX_LENGTH: f64 = 2.0;

/// One field to match: its values at the source's vertices and at the chart's.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Channel {
    /// Per vertex of the source.
    pub source: Vec<f64>,
    /// Per vertex of the target's chart.
    pub target: Vec<f64>,
    /// Standardized on each side at each scale (a scalar feature, in any unit), or
    /// taken as given (coordinates of both sides in one unit, module `shape`).
    pub standardize: bool,
}

impl Channel {
    /// Both sides after `passes` of neighbour averaging (`target_passes` on the target),
    /// standardized when the channel asks for it.
    fn at_scale(
        &self,
        neighbours: &[Vec<usize>],
        domain_neighbours: &[Vec<usize>],
        passes: usize,
        target_passes: usize,
    ) -> (Vec<f64>, Vec<f64>) {
        let source = smoothed(neighbours, None, self.source.clone(), passes);
        let target = smoothed(domain_neighbours, None, self.target.clone(), target_passes);
        if self.standardize {
            (standardized(&source), standardized(&target))
        } else {
            (source, target)
        }
    }
}

/// The demons force of every vertex (module docs), summed over the channels:
/// `u_i = sum_c r_ci g_ci / (sum_c |g_ci|^2 + alpha^2 sum_c r_ci^2)` with
/// `r_ci = I_c(v_i) - J_c(f(v_i))` and `g_ci = grad J_c` at `f(v_i)` (`probe`), zero on
/// held vertices and where the fields are flat and agree.
fn demons_force(
    source_fields: &[Vec<f64>],
    probe: &Probe,
    held: &[bool],
    alpha: f64,
) -> Vec<Complex64> {
    let zero = Complex64::new(0.0, 0.0);
    (0..held.len())
        .map(|i| {
            if held[i] {
                return zero;
            }
            let mut pull = zero;
            let (mut slope, mut residual) = (0.0, 0.0);
            for (c, field) in source_fields.iter().enumerate() {
                let r = field[i] - probe.values[c][i];
                let g = probe.gradients[c][i];
                pull += g * r;
                slope += g.norm_sqr();
                residual += r * r;
            }
            let denominator = slope + alpha * alpha * residual;
            if denominator > 0.0 {
                pull / denominator
            } else {
                zero
            }
        })
        .collect()
}

/// A map that matches the fields and how far it got.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct FeatureMatch {
    /// The image of every source vertex in the chart; held vertices at their values.
    pub map: Vec<Complex64>,
    /// Steps kept.
    pub steps: usize,
    /// The mismatch `E` (module docs) of the given map and of the returned one.
    pub before: f64,
    pub after: f64,
}

/// The source's chart map `initial` (bijective, one value per vertex of `mesh`) bent so
/// that every channel's source values match its values on the planar mesh `domain`
/// (the target's chart) with the vertices of `fixed` held (module docs).
///
/// # Errors
/// The errors of [`Reconstruction`]; [`RegisterError::Spatial`] when the chart cannot be
/// searched.
pub(crate) fn match_features(
    mesh: &Mesh,
    initial: &[Complex64],
    fixed: &[(VertexId, Complex64)],
    channels: &[Channel],
    domain: &Mesh,
    side: Side,
) -> Result<FeatureMatch, RegisterError> {
    let weights = mesh.vertex_areas();
    let mut held = vec![false; mesh.vertex_count()];
    for &(v, _) in fixed {
        if let Some(h) = held.get_mut(v.idx()) {
            *h = true;
        }
    }
    let neighbours = vertex_neighbours(mesh);
    let domain_neighbours = vertex_neighbours(domain);
    // Smoothing passes on the target that give the same scale as on the source: the
    // reach of `k` passes grows as `h sqrt(k)`, with `h^2` about the area per vertex.
    let ratio = domain.vertex_count() as f64 / mesh.vertex_count().max(1) as f64;
    let alpha = 0.5 / median_edge(mesh, initial).max(f64::MIN_POSITIVE);
    let (mut reconstruction, _) =
        Reconstruction::new(mesh, Frame::Face, initial, fixed, &[], side)?;
    let index = OnceLock::new();
    let vertices = VertexTree::new(domain);
    let (exact_source, exact_target): (Vec<_>, Vec<_>) = channels
        .iter()
        .map(|c| c.at_scale(&neighbours, &domain_neighbours, 0, 0))
        .unzip();
    let exact_target = TargetField::new(&index, &vertices, domain, &exact_target);
    let start = exact_target.probe(initial, None)?;
    let before = mismatch(&exact_source, &start.values, &weights);

    let max_steps = if channels.iter().any(|c| c.standardize) {
        MAX_STEPS
    } else {
        SHAPE_MAX_STEPS
    };
    let mut map = initial.to_vec();
    let mut current_mu = reconstruction.measure(&map)?.0;
    let mut steps = 0;
    let smoothing = Passes::for_vertices(mesh.vertex_count());
    for passes in smoothing.scales {
        let target_passes = (passes as f64 * ratio).round() as usize;
        let (source_fields, target_fields): (Vec<_>, Vec<_>) = channels
            .iter()
            .map(|c| c.at_scale(&neighbours, &domain_neighbours, passes, target_passes))
            .unzip();
        let target_field = TargetField::new(&index, &vertices, domain, &target_fields);
        let mut probe = target_field.probe(&map, Some(&start))?;
        let mut energy = mismatch(&source_fields, &probe.values, &weights);
        let first = energy;
        let mut length = 1.0;
        let mut level_steps = 0;
        while level_steps < max_steps && length >= MIN_STEP {
            let force = demons_force(&source_fields, &probe, &held, alpha);
            let force = smoothed(&neighbours, Some(&held), force, smoothing.force);
            let moved: Vec<Complex64> = map
                .iter()
                .zip(&force)
                .map(|(z, u)| z + u * length)
                .collect();
            let (mu, _) = reconstruction.measure(&moved)?;
            let nu = reconstruction.regularized_step(&current_mu, &mu, MU_SMOOTHING);
            let mut rebuilt = reconstruction.solve(&nu)?;
            // The fields at the rebuilt map are probed on this core while the other
            // measures it: most steps fold nothing and keep both.
            let (trial, measured) = parallel::join(
                || target_field.probe(&rebuilt, Some(&probe)),
                || reconstruction.measure_folds(&rebuilt),
            );
            let (mut rebuilt_mu, folded) = measured?;
            let mut flipped = folded.iter().filter(|&&f| f).count();
            let mut trial = trial?;
            // Where the discrete rebuild still folds a few faces, its own coefficient is
            // smoothed and cut and the map rebuilt again: first near the folds only, then
            // everywhere (the landmark matching's mending).
            if flipped > 0 {
                for attempt in 0..MENDING {
                    let nu = if attempt == 0 {
                        reconstruction.regularized_near(rebuilt_mu, &folded, MEND_RINGS, 2)
                    } else {
                        reconstruction.regularized(rebuilt_mu, 2)
                    };
                    rebuilt = reconstruction.solve(&nu)?;
                    (rebuilt_mu, flipped) = reconstruction.measure(&rebuilt)?;
                    if flipped == 0 {
                        break;
                    }
                }
                trial = target_field.probe(&rebuilt, Some(&probe))?;
            }
            let trial_energy = mismatch(&source_fields, &trial.values, &weights);
            if flipped > 0 || trial_energy >= energy {
                length *= 0.5;
                continue;
            }
            let decrease = energy - trial_energy;
            current_mu = rebuilt_mu;
            map = rebuilt;
            probe = trial;
            energy = trial_energy;
            level_steps += 1;
            length = (2.0 * length).min(MAX_LENGTH);
            if decrease < STALL * first {
                break;
            }
        }
        steps += level_steps;
    }
    let after = mismatch(
        &exact_source,
        &exact_target.probe(&map, Some(&start))?.values,
        &weights,
    );
    Ok(FeatureMatch {
        map,
        steps,
        before,
        after,
    })
}

/// The neighbours of every vertex, by index.
fn vertex_neighbours(mesh: &Mesh) -> Vec<Vec<usize>> {
    mesh.vertices()
        .map(|v| mesh.vertex_neighbors(v).map(|w| w.idx()).collect())
        .collect()
}

/// `values` after `passes` of averaging each vertex with its neighbours, the vertices
/// marked in `held` (when given) kept as they are.
fn smoothed<T>(
    neighbours: &[Vec<usize>],
    held: Option<&[bool]>,
    mut values: Vec<T>,
    passes: usize,
) -> Vec<T>
where
    T: Copy + std::iter::Sum + std::ops::Add<Output = T> + std::ops::Div<f64, Output = T>,
{
    for _ in 0..passes {
        values = (0..values.len())
            .map(|i| {
                if held.is_some_and(|h| h[i]) {
                    return values[i];
                }
                let sum: T = neighbours[i].iter().map(|&j| values[j]).sum();
                (values[i] + sum) / (1 + neighbours[i].len()) as f64
            })
            .collect();
    }
    values
}

/// `values` with their mean subtracted, divided by their standard deviation (left
/// centred when it is 0).
fn standardized(values: &[f64]) -> Vec<f64> {
    let n = values.len().max(1) as f64;
    let mean = values.iter().sum::<f64>() / n;
    let deviation = (values.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n).sqrt();
    let scale = if deviation > 0.0 {
        1.0 / deviation
    } else {
        1.0
    };
    values.iter().map(|x| (x - mean) * scale).collect()
}

/// The median length of the edges of `mesh` under the planar map `map`.
fn median_edge(mesh: &Mesh, map: &[Complex64]) -> f64 {
    let mut lengths: Vec<f64> = mesh
        .edges()
        .map(|e| {
            let [a, b] = mesh.edge_vertices(e);
            (map[a.idx()] - map[b.idx()]).norm()
        })
        .collect();
    if lengths.is_empty() {
        return 0.0;
    }
    let middle = lengths.len() / 2;
    *lengths.select_nth_unstable_by(middle, f64::total_cmp).1
}

/// The area-weighted mean squared difference of the channels' fields, summed over
/// the channels.
fn mismatch(source: &[Vec<f64>], at_images: &[Vec<f64>], weights: &[f64]) -> f64 {
    let total: f64 = weights.iter().sum();
    source
        .iter()
        .zip(at_images)
        .map(|(field, at)| {
            field
                .iter()
                .zip(at)
                .zip(weights)
                .map(|((a, b), w)| w * (a - b).powi(2))
                .sum::<f64>()
        })
        .sum::<f64>()
        / total.max(f64::MIN_POSITIVE)
}

/// Points the walks miss at most that are found by trying every face of the chart;
/// more are found through the chart's index, built the first time. The index of a
/// stereographic chart splits its large faces near the pole into up to 4,096 pieces:
/// building it takes as long as the exhaustive search of a few hundred points
/// (`g0_spot`: 24-58 ms, fsaverage5: 98-137 ms, for 5 to 107 points missed in a first
/// probe and none after).
const EXHAUSTIVE_POINTS: usize = 128;

/// The target's fields on its chart: values at the vertices, linear on each triangle.
struct TargetField<'d> {
    /// The chart's index, once a probe needed it.
    index: &'d OnceLock<SurfaceIndex<'d>>,
    /// The chart's vertices, for the first probe's starting faces.
    vertices: &'d VertexTree,
    domain: &'d Mesh,
    /// Per channel, per vertex.
    values: Vec<Vec<f64>>,
    /// Per channel, the gradient of the linear interpolant on each face, as
    /// `d/dx + i d/dy`.
    gradients: Vec<Vec<Complex64>>,
}

/// The target's fields and their gradients at the images of the source's vertices (per
/// channel, per vertex), and where the images are.
struct Probe {
    values: Vec<Vec<f64>>,
    gradients: Vec<Vec<Complex64>>,
    /// The images probed.
    images: Vec<Complex64>,
    /// Their points on the chart.
    points: Vec<SurfacePoint>,
}

impl<'d> TargetField<'d> {
    fn new(
        index: &'d OnceLock<SurfaceIndex<'d>>,
        vertices: &'d VertexTree,
        domain: &'d Mesh,
        channels: &[Vec<f64>],
    ) -> Self {
        let gradients = channels
            .iter()
            .map(|values| face_gradients(domain, values))
            .collect();
        Self {
            index,
            vertices,
            domain,
            values: channels.to_vec(),
            gradients,
        }
    }

    /// The fields and their gradients at the images `map`. An image where it was in
    /// `near` (the last probe, when given) keeps its point; another is found by a walk
    /// from its last face, or, in the first probe, from a face of the chart's vertex
    /// nearest to it; those the walk misses, at their closest points of the chart, by
    /// trying every face when they are few ([`EXHAUSTIVE_POINTS`]), else through the
    /// index. The index is exact but slow on a stereographic chart, whose faces near the
    /// pole are huge (every search ball holds much of the chart: 1.5 s of the 7 s of a
    /// cortex's registration with a field), and a held vertex outside the chart would be
    /// searched every step.
    fn probe(&self, map: &[Complex64], near: Option<&Probe>) -> Result<Probe, RegisterError> {
        let walked: Vec<Option<SurfacePoint>> = match near {
            Some(near) => map
                .iter()
                .zip(near.images.iter().zip(&near.points))
                .map(|(&z, (&before, point))| {
                    if z == before {
                        Some(*point)
                    } else {
                        walk(self.domain, z, point.face)
                    }
                })
                .collect(),
            None => map
                .iter()
                .map(|&z| {
                    let start = self.vertices.face_near(self.domain, z)?;
                    walk(self.domain, z, start)
                })
                .collect(),
        };
        let lost: Vec<usize> = (0..map.len()).filter(|&i| walked[i].is_none()).collect();
        let at = planar_points(&lost.iter().map(|&i| map[i]).collect::<Vec<_>>());
        let exhaustive = (lost.len() <= EXHAUSTIVE_POINTS)
            .then(|| closest_of_every_face(self.domain, &at))
            .flatten();
        let found = match exhaustive {
            Some(found) => found,
            None => {
                let index = match self.index.get() {
                    Some(index) => index,
                    None => {
                        let built = SurfaceIndex::new(self.domain)?;
                        self.index.get_or_init(|| built)
                    }
                };
                index
                    .locate_all(&at)?
                    .into_iter()
                    .map(|l| l.point)
                    .collect()
            }
        };
        let mut points = walked;
        for (&i, point) in lost.iter().zip(found) {
            points[i] = Some(point);
        }
        let points: Vec<SurfacePoint> = points.into_iter().flatten().collect();
        let channels = self.values.len();
        let mut probe = Probe {
            values: vec![Vec::with_capacity(map.len()); channels],
            gradients: vec![Vec::with_capacity(map.len()); channels],
            images: map.to_vec(),
            points: Vec::new(),
        };
        for point in &points {
            let (vs, degree) = self.domain.face_vertex_array(point.face);
            for c in 0..channels {
                probe.values[c].push(
                    (0..degree)
                        .map(|k| point.coords[k] * self.values[c][vs[k].idx()])
                        .sum(),
                );
                probe.gradients[c].push(self.gradients[c][point.face.idx()]);
            }
        }
        probe.points = points;
        Ok(probe)
    }
}

/// The closest points of `mesh` to `points` found by trying every face, among faces at
/// the same distance the lowest face id (the rule of [`SurfaceIndex`]); `None` for a mesh
/// without faces. A face whose bounding box lies farther than the best face so far is
/// passed over (its points lie farther still): the same answer as evaluating every face,
/// at a few comparisons for most of them.
fn closest_of_every_face(mesh: &Mesh, points: &[Point3<f64>]) -> Option<Vec<SurfacePoint>> {
    let positions = mesh.positions();
    // A face has corners, so each box is `Some`; one per face keeps the zip aligned.
    let boxes: Vec<Option<BoundingBox>> = mesh
        .faces()
        .map(|f| BoundingBox::around(mesh.face_vertices(f).map(|v| &positions[v.idx()])))
        .collect();
    points
        .iter()
        .map(|p| {
            let mut best: Option<(FaceId, ClosestPoint)> = None;
            for (f, bounds) in mesh.faces().zip(&boxes) {
                // Padded so that rounding cannot pass over a face at the same distance,
                // which the tie rule may prefer.
                let beyond = |(_, b): &(FaceId, ClosestPoint)| {
                    bounds.is_some_and(|bounds| {
                        bounds.distance_squared(p) > b.distance_squared * (1.0 + 1e-9)
                    })
                };
                if best.as_ref().is_some_and(beyond) {
                    continue;
                }
                let c = closest_on_face(mesh, f, p);
                if best
                    .as_ref()
                    .is_none_or(|(_, b)| c.distance_squared < b.distance_squared)
                {
                    best = Some((f, c));
                }
            }
            best.map(|(face, c)| SurfacePoint {
                face,
                coords: c.coords,
            })
        })
        .collect()
}

/// The gradient of the linear interpolant of `values` (per vertex) on each face of the
/// planar mesh `domain`, as `d/dx + i d/dy` (0 on a face of zero area).
fn face_gradients(domain: &Mesh, values: &[f64]) -> Vec<Complex64> {
    domain
        .faces()
        .map(|f| {
            let (vs, _) = domain.face_vertex_array(f);
            let p = |k: usize| domain.position(vs[k]);
            let (a, b, c) = (p(0), p(1), p(2));
            let (e1, e2) = (b - a, c - a);
            let (d1, d2) = (
                values[vs[1].idx()] - values[vs[0].idx()],
                values[vs[2].idx()] - values[vs[0].idx()],
            );
            // [e1; e2] g = [d1; d2] by Cramer's rule.
            let det = e1.x * e2.y - e1.y * e2.x;
            if det == 0.0 {
                return Complex64::new(0.0, 0.0);
            }
            Complex64::new((d1 * e2.y - d2 * e1.y) / det, (e1.x * d2 - e2.x * d1) / det)
        })
        .collect()
}

/// Points per kd-tree leaf.
const BUCKET: usize = 16;

/// The vertices of a planar chart in a kd-tree: a face near any point of the chart in
/// logarithmic time, whatever the sizes of its faces.
struct VertexTree {
    tree: Option<KdTree<f64, u32, Eytzinger, VecOfArenas<f64, u32, 2, BUCKET>, 2, BUCKET>>,
}

impl VertexTree {
    /// The tree of the vertices of `domain` (in the plane `z = 0`).
    fn new(domain: &Mesh) -> Self {
        let points: Vec<[f64; 2]> = domain.positions().iter().map(|p| [p.x, p.y]).collect();
        Self {
            tree: KdTree::new_from_slice(&points).ok(),
        }
    }

    /// A face of the vertex of `domain` nearest to `z`.
    fn face_near(&self, domain: &Mesh, z: Complex64) -> Option<FaceId> {
        let nearest = self
            .tree
            .as_ref()?
            .query(&[z.re, z.im])
            .nearest_one::<SquaredEuclidean<f64>>()
            .execute();
        domain.vertex_faces(VertexId(nearest.item)).next()
    }
}

/// Faces a walk crosses at most before the index takes over.
const MAX_WALK: usize = 64;

/// The point `z` of the planar triangle mesh `domain`, found by walking from face
/// `start` across the edge opposite the most negative barycentric coordinate; `None`
/// when the walk leaves the mesh or does not end.
fn walk(domain: &Mesh, z: Complex64, start: FaceId) -> Option<SurfacePoint> {
    let mut face = start;
    for _ in 0..MAX_WALK {
        let (vs, degree) = domain.face_vertex_array(face);
        if degree != 3 {
            return None;
        }
        let p = [0, 1, 2].map(|k| {
            let q = domain.position(vs[k]);
            Complex64::new(q.x, q.y)
        });
        let cross = |a: Complex64, b: Complex64| (a.conj() * b).im;
        let area = cross(p[1] - p[0], p[2] - p[0]);
        if area == 0.0 {
            return None;
        }
        let l = [
            cross(p[1] - z, p[2] - z) / area,
            cross(p[2] - z, p[0] - z) / area,
            cross(p[0] - z, p[1] - z) / area,
        ];
        let k = (0..3).min_by(|&a, &b| l[a].total_cmp(&l[b]))?;
        if l[k] >= -1e-12 {
            let clamped = l.map(|x| x.max(0.0));
            let sum: f64 = clamped.iter().sum();
            return Some(SurfacePoint::in_triangle(face, clamped.map(|x| x / sum)));
        }
        // The edge opposite corner k runs from corner k + 1 to corner k + 2.
        let from = vs[(k + 1) % 3];
        let h = domain
            .face_halfedges(face)
            .find(|&h| domain.origin(h) == from)?;
        face = domain.face(domain.twin(h))?;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use beltrami_mesh::primitives::{Cells, grid};

    #[test]
    fn every_face_tried_gives_the_index_closest_point() {
        // Points inside the square, outside it and on its edges: the exhaustive search
        // of the probes' few lost points finds what the chart's index finds.
        let square = Mesh::from_soup(&grid(9, 7, Cells::Triangles)).unwrap();
        let index = SurfaceIndex::new(&square).unwrap();
        for k in 0..200 {
            let t = k as f64;
            let p = Point3::new(1.6 * (0.37 * t).sin(), 1.6 * (0.53 * t).cos(), 0.0);
            let exhaustive = closest_of_every_face(&square, &[p]).unwrap()[0];
            let located = index.locate(&p).unwrap();
            assert_eq!(exhaustive.face, located.point.face, "{p}");
            assert_eq!(exhaustive.coords, located.point.coords, "{p}");
        }
    }

    #[test]
    fn the_coarse_scale_reaches_as_far_on_a_finer_mesh() {
        // A unit impulse at the centre of the unit square, smoothed by the coarsest
        // scale's passes on two meshes of it with four times the vertices one of the
        // other (both above the calibrated count): the spread (the root of the second
        // moment of the normalized result) is the same on the square at either
        // resolution; with the calibrated counts on both it would halve.
        let spread = |cells: usize| {
            let square = Mesh::from_soup(&grid(cells, cells, Cells::Triangles)).unwrap();
            let centre = cells / 2 * (cells + 2);
            let mut impulse = vec![0.0; square.vertex_count()];
            impulse[centre] = 1.0;
            let passes = Passes::for_vertices(square.vertex_count()).scales[0];
            let smooth = smoothed(&vertex_neighbours(&square), None, impulse, passes);
            let c = square.positions()[centre];
            let mass: f64 = smooth.iter().sum();
            let moment: f64 = smooth
                .iter()
                .zip(square.positions())
                .map(|(w, p)| w * ((p.x - c.x).powi(2) + (p.y - c.y).powi(2)))
                .sum();
            (moment / mass).sqrt()
        };
        let (coarse, fine) = (spread(110), spread(220));
        assert!(
            (fine / coarse - 1.0).abs() < 0.05,
            "spread {coarse} at 111^2 vertices, {fine} at 221^2"
        );
    }

    #[test]
    fn a_shifted_bump_is_moved_onto_its_target() {
        // The source is the unit square with a bump centred at (0.45, 0.5); the
        // target's chart is the same square with the bump at (0.55, 0.5). With the
        // boundary held, the matching moves the bump's centre towards (0.55, 0.5) and
        // lowers the mismatch by most of it, with no fold.
        let square = Mesh::from_soup(&grid(24, 24, Cells::Triangles)).unwrap();
        let bump = |x: f64, y: f64, cx: f64| (-((x - cx).powi(2) + (y - 0.5).powi(2)) / 0.02).exp();
        let identity: Vec<Complex64> = square
            .positions()
            .iter()
            .map(|p| Complex64::new(p.x, p.y))
            .collect();
        let source: Vec<f64> = square
            .positions()
            .iter()
            .map(|p| bump(p.x, p.y, 0.45))
            .collect();
        let target: Vec<f64> = square
            .positions()
            .iter()
            .map(|p| bump(p.x, p.y, 0.55))
            .collect();
        let fixed: Vec<(VertexId, Complex64)> = square
            .vertices()
            .filter(|&v| square.is_boundary_vertex(v))
            .map(|v| (v, identity[v.idx()]))
            .collect();
        let channel = Channel {
            source,
            target,
            standardize: true,
        };
        let matched = match_features(
            &square,
            &identity,
            &fixed,
            &[channel],
            &square,
            Side::Source,
        )
        .unwrap();
        assert!(matched.steps > 0);
        assert!(
            matched.after < 0.2 * matched.before,
            "{} -> {}",
            matched.before,
            matched.after
        );
        let centre = square
            .vertices()
            .min_by(|&a, &b| {
                let d = |v: VertexId| {
                    let p = square.position(v);
                    (p.x - 0.45).powi(2) + (p.y - 0.5).powi(2)
                };
                d(a).total_cmp(&d(b))
            })
            .unwrap();
        let image = matched.map[centre.idx()];
        assert!(
            (image - Complex64::new(0.55, 0.5)).norm() < 0.03,
            "the bump's centre went to {image}"
        );
        let (reconstruction, _) =
            Reconstruction::new(&square, Frame::Face, &identity, &fixed, &[], Side::Source)
                .unwrap();
        assert_eq!(reconstruction.measure(&matched.map).unwrap().1, 0);
    }
}
