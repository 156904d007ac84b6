//! Point location on a target surface: the exact closest point of a mesh, found through
//! a kd-tree.
//!
//! # The index
//!
//! Every face is covered by *samples*, each a piece of the face bounded by a ball
//! `B(c, r)` and a slab `|n . (x - c)| <= t` (`n` the face's unit normal). A face whose
//! radius (largest distance from its vertex average to a vertex) is at most the target
//! radius `R0` is one sample: its vertex average, that radius, and the largest distance
//! of a corner from the plane through `c` as `t` (0 for a triangle). These bound the face
//! because a triangle is the convex hull of its corners and the bilinear patch of a quad
//! lies in the convex hull of its four corners. A larger face is split 1-to-4 (at edge
//! midpoints for a triangle, at parameter midpoints for a quad) until the pieces fit, at
//! most [`MAX_SPLIT_LEVEL`] times; each piece is again inside the hull of its corners.
//! `R0` is the 90th percentile of the face radii, so about nine faces in ten are one
//! sample and a few very large faces cannot blow up the search radius. Radii and
//! thicknesses are padded by a few ulps so that rounding cannot shrink them. The sample
//! centers go, in Morton order (see [`crate::morton`]), into a kiddo kd-tree; `R` is the
//! largest sample radius.
//!
//! # Why `locate` is exact
//!
//! Let `d*` be the distance from `p` to the mesh, attained at a point `x*` of face `f*`,
//! and `d >= d*` the distance to any face evaluated so far. Some sample of `f*` contains
//! `x*`, so its center has `|p - c| <= |p - x*| + |x* - c| <= d* + r <= d + R`: the
//! samples within `d + R` of `p` include one of `f*`. A sample can only hold a point
//! closer than `d` if its lower bound is below `d`: for `x` in the piece,
//! `|n . (p - x)| >= |n . (p - c)| - t` across the slab and, in the plane,
//! `|P (p - x)| >= |P (p - c)| - r` (`P` the projection along `n`); the two parts are
//! orthogonal, so `|p - x|^2` is at least the sum of their squares (clamped at 0).
//! `locate` therefore takes one face (a hint, the previous point's face in a batch, or the
//! face of the nearest sample center), asks the tree for all samples within its distance
//! plus `R`, and evaluates the exact closest point (see [`crate::closest_point`]) of every
//! face whose sample passes the lower bound. The result is the closest point of the
//! whole mesh; among faces at the same distance (a point on an edge or at a vertex) the
//! lowest face id wins, so the answer does not depend on the hint.
//!
//! The cost is one or two tree queries plus the faces near `p`: for points near the
//! surface (the flow's case) a handful of faces, more near a vertex, whose whole fan
//! passes the bound. For a point far from the surface the ball of radius `d + R` holds
//! every sample within `R` of the sphere of radius `d`, which grows with `d / R`; the
//! answer stays exact.

use beltrami_mesh::{FaceId, Mesh, SurfacePoint};
use kiddo::kd_tree::KdTree;
use kiddo::leaf_strategies::VecOfArenas;
use kiddo::stem_strategies::eytzinger::Eytzinger;
use kiddo::{QueryScratch, SquaredEuclidean};
use nalgebra::{Point3, Vector3};

use crate::closest_point::{ClosestPoint, closest_on_quad, closest_on_triangle};
use crate::error::{SpatialError, check_point};

/// Faces larger than the target sample radius are split 1-to-4 at most this many times
/// (at most `4^6 = 4096` samples per face).
pub const MAX_SPLIT_LEVEL: usize = 6;

/// Quantile of the face radii used as the target sample radius.
const TARGET_QUANTILE: f64 = 0.9;

/// Points per stretch at least of a batch shared between threads
/// ([`beltrami_mesh::parallel::chunk_ranges_of`]): a search takes about a microsecond and
/// a thread start tens of them, so a batch of a few thousand points (`g0_spot`'s 2,930
/// vertices, each round of the non-rigid ICP) is worth sharing.
const SEARCH_CHUNK: usize = 256;

/// Items per kd-tree leaf.
const BUCKET: usize = 16;

/// The kd-tree of sample centers: kiddo's immutable layout (Eytzinger stems, arena
/// leaves) with leaves of [`BUCKET`] items, items being sample indices.
pub(crate) type Tree = KdTree<f64, u32, Eytzinger, VecOfArenas<f64, u32, 3, BUCKET>, 3, BUCKET>;

/// Reusable traversal storage of the kd-tree queries (one per batch, so that a query
/// does not set up its stack anew).
type Scratch = QueryScratch<Eytzinger, f64, 3>;

/// The closest point of the mesh to a query point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Located {
    /// The closest point as a surface point (face and coordinates).
    pub point: SurfacePoint,
    /// Its position: `point.position(mesh)`, bit for bit.
    pub position: Point3<f64>,
    /// Euclidean distance from the query point to `position`.
    pub distance: f64,
}

/// One kd-tree entry: a piece of a face, bounded by the ball of radius `radius` around
/// the entry's center `c` and by the slab `|normal . x - offset| <= thickness` (with
/// `offset = normal . c`; `normal` is the face's unit normal, or zero for a degenerate
/// face).
#[derive(Debug, Clone, Copy)]
struct Sample {
    face: FaceId,
    radius: f64,
    normal: [f64; 3],
    offset: f64,
    thickness: f64,
}

impl Sample {
    /// A lower bound on the distance from `p` to this piece, given `|p - c|^2`: a point
    /// `x` of the piece has `|n . (p - x)| >= |n . (p - c)| - thickness` across the slab
    /// and, in the plane, `|P(p - x)| >= |P(p - c)| - radius` (`P` the projection along
    /// `n`), and the two parts are orthogonal.
    #[inline]
    fn lower_bound(&self, p: &Point3<f64>, center_distance_squared: f64) -> f64 {
        let [a, b, c] = self.normal;
        let height = (a * p.x + b * p.y + c * p.z - self.offset).abs();
        let across = (height - self.thickness).max(0.0);
        let along =
            ((center_distance_squared - height * height).max(0.0).sqrt() - self.radius).max(0.0);
        (across * across + along * along).sqrt()
    }
}

/// A kd-tree index of a mesh for exact closest-point queries, with the mesh's vertex
/// normals for tangent frames and motion. See the module docs for the method and the
/// proof of exactness.
pub struct SurfaceIndex<'m> {
    mesh: &'m Mesh,
    tree: Tree,
    samples: Vec<Sample>,
    max_radius: f64,
    /// Position of the origin of every face halfedge, by halfedge id: the corners of
    /// each face, contiguous.
    corners: Vec<Point3<f64>>,
    vertex_normals: Vec<Vector3<f64>>,
    /// Threads of the batch queries ([`SurfaceIndex::with_threads`]).
    threads: usize,
}

impl std::fmt::Debug for SurfaceIndex<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SurfaceIndex")
            .field("faces", &self.mesh.face_count())
            .field("samples", &self.samples.len())
            .field("max_radius", &self.max_radius)
            .finish_non_exhaustive()
    }
}

/// Vertex average and largest corner distance of a set of corners, the latter padded
/// by a few ulps of the coordinates so that rounding of the corners cannot shrink the
/// ball below the piece it bounds.
fn ball(corners: &[Point3<f64>]) -> (Point3<f64>, f64) {
    let sum: Vector3<f64> = corners.iter().map(|c| c.coords).sum();
    let center = Point3::from(sum / corners.len() as f64);
    let radius = corners
        .iter()
        .map(|c| (c - center).norm())
        .fold(0.0, f64::max);
    let pad = 8.0 * f64::EPSILON * (center.coords.amax() + radius);
    (center, radius * (1.0 + 1e-12) + pad)
}

/// The sample of a piece of face `face` (the convex hull of `corners` contains it) with
/// the face's unit normal `normal`, and its center.
fn sample(face: FaceId, corners: &[Point3<f64>], normal: &Vector3<f64>) -> (Point3<f64>, Sample) {
    let (c, radius) = ball(corners);
    let offset = normal.dot(&c.coords);
    let thickness = corners
        .iter()
        .map(|x| normal.dot(&(x - c)).abs())
        .fold(0.0, f64::max);
    let pad = 8.0 * f64::EPSILON * (c.coords.amax() + radius);
    (
        c,
        Sample {
            face,
            radius,
            normal: [normal.x, normal.y, normal.z],
            offset,
            thickness: thickness * (1.0 + 1e-12) + pad,
        },
    )
}

/// The samples of one face, appended to `centers` and `samples`.
fn push_face_samples(
    mesh: &Mesh,
    f: FaceId,
    target: f64,
    centers: &mut Vec<Point3<f64>>,
    samples: &mut Vec<Sample>,
) {
    let (v, n) = mesh.face_vertex_array(f);
    let p = |k: usize| mesh.position(v[k]);
    let area = mesh.face_vector_area(f);
    let normal = if area.norm() > 0.0 {
        area.normalize()
    } else {
        Vector3::zeros()
    };
    let mut push = |corners: &[Point3<f64>]| {
        let (c, s) = sample(f, corners, &normal);
        centers.push(c);
        samples.push(s);
    };
    if n == 3 {
        split_triangle([p(0), p(1), p(2)], target, 0, &mut push);
    } else {
        let q = [p(0), p(1), p(2), p(3)];
        split_quad(&q, (0.0, 1.0, 0.0, 1.0), target, 0, &mut push);
    }
}

fn split_triangle(
    t: [Point3<f64>; 3],
    target: f64,
    level: usize,
    push: &mut impl FnMut(&[Point3<f64>]),
) {
    if level == MAX_SPLIT_LEVEL || ball(&t).1 <= target {
        push(&t);
        return;
    }
    let mid = |a: &Point3<f64>, b: &Point3<f64>| Point3::from((a.coords + b.coords) * 0.5);
    let (ab, bc, ca) = (mid(&t[0], &t[1]), mid(&t[1], &t[2]), mid(&t[2], &t[0]));
    for piece in [[t[0], ab, ca], [ab, t[1], bc], [ca, bc, t[2]], [ab, bc, ca]] {
        split_triangle(piece, target, level + 1, push);
    }
}

fn split_quad(
    q: &[Point3<f64>; 4],
    (u0, u1, v0, v1): (f64, f64, f64, f64),
    target: f64,
    level: usize,
    push: &mut impl FnMut(&[Point3<f64>]),
) {
    let x = |u: f64, v: f64| {
        crate::closest_point::weighted_sum(q, &beltrami_mesh::surface_point::bilinear_weights(u, v))
    };
    let corners = [x(u0, v0), x(u1, v0), x(u1, v1), x(u0, v1)];
    if level == MAX_SPLIT_LEVEL || ball(&corners).1 <= target {
        push(&corners);
        return;
    }
    let (um, vm) = (0.5 * (u0 + u1), 0.5 * (v0 + v1));
    for rect in [
        (u0, um, v0, vm),
        (um, u1, v0, vm),
        (um, u1, vm, v1),
        (u0, um, vm, v1),
    ] {
        split_quad(q, rect, target, level + 1, push);
    }
}

impl<'m> SurfaceIndex<'m> {
    /// Builds the index of `mesh`: face samples, their kd-tree, and the angle-weighted
    /// vertex normals. Fails only if the mesh needs more than `u32::MAX` samples.
    pub fn new(mesh: &'m Mesh) -> Result<Self, SpatialError> {
        let mut radii: Vec<f64> = mesh
            .faces()
            .map(|f| {
                let (v, n) = mesh.face_vertex_array(f);
                let corners: Vec<Point3<f64>> = v[..n].iter().map(|&v| mesh.position(v)).collect();
                ball(&corners).1
            })
            .collect();
        let k = ((radii.len() - 1) as f64 * TARGET_QUANTILE).round() as usize;
        let (_, &mut target, _) = radii.select_nth_unstable_by(k, f64::total_cmp);

        let mut centers = Vec::with_capacity(mesh.face_count() + mesh.face_count() / 4);
        let mut samples = Vec::with_capacity(centers.capacity());
        for f in mesh.faces() {
            push_face_samples(mesh, f, target, &mut centers, &mut samples);
        }
        if u32::try_from(samples.len()).is_err() {
            return Err(SpatialError::TooLarge {
                samples: samples.len(),
            });
        }
        let max_radius = samples.iter().map(|s| s.radius).fold(0.0, f64::max);
        // Morton order, so that the samples of one kd-tree leaf are close in memory.
        let order = crate::morton::order(&centers);
        let samples: Vec<Sample> = order.iter().map(|&i| samples[i as usize]).collect();
        let centers: Vec<[f64; 3]> = order
            .iter()
            .map(|&i| centers[i as usize].coords.into())
            .collect();
        let tree = Tree::new_from_slice(&centers).map_err(|_| SpatialError::TooLarge {
            samples: samples.len(),
        })?;
        Ok(Self {
            mesh,
            tree,
            samples,
            max_radius,
            corners: mesh
                .faces()
                .flat_map(|f| mesh.face_vertices(f).map(|v| mesh.position(v)))
                .collect(),
            vertex_normals: mesh.vertex_normals(),
            threads: 1,
        })
    }

    /// The index with its batch queries ([`SurfaceIndex::locate_all`],
    /// [`SurfaceIndex::locate_all_near`], [`SurfaceIndex::move_all`]) spread over
    /// `threads` threads (0: one per core; 1, the default: the calling thread only).
    /// Each point's result is the same for any number of threads: the searches are exact
    /// and the walks independent.
    pub fn with_threads(mut self, threads: usize) -> Self {
        self.threads = if threads == 0 {
            beltrami_mesh::parallel::available_threads()
        } else {
            threads
        };
        self
    }

    /// Threads of the batch queries.
    pub fn threads(&self) -> usize {
        self.threads
    }

    /// The indexed mesh.
    pub fn mesh(&self) -> &'m Mesh {
        self.mesh
    }

    /// Angle-weighted unit vertex normals of the mesh, by vertex id.
    pub fn vertex_normals(&self) -> &[Vector3<f64>] {
        &self.vertex_normals
    }

    /// Number of kd-tree samples (at least one per face).
    pub fn sample_count(&self) -> usize {
        self.samples.len()
    }

    /// The largest sample radius `R`: a face with a point within distance `d` of a query
    /// has a sample center within `d + R`.
    pub fn max_sample_radius(&self) -> f64 {
        self.max_radius
    }

    /// The exact closest point of the mesh to `p`. Fails on a non-finite `p`.
    pub fn locate(&self, p: &Point3<f64>) -> Result<Located, SpatialError> {
        check_point(p)?;
        Ok(self.search(p, None, &mut Scratch::new()))
    }

    /// Every face with a point within `radius` of `p`, in increasing id order, each once;
    /// a few farther faces may be listed too. A face within `radius` has a sample whose
    /// center is within `radius + R` and whose lower bound (module docs) is at most
    /// `radius`, so the same tree query and bound as [`SurfaceIndex::locate`] find it.
    /// Fails on a non-finite `p` or a radius that is negative or not finite.
    pub fn faces_within(&self, p: &Point3<f64>, radius: f64) -> Result<Vec<FaceId>, SpatialError> {
        check_point(p)?;
        if !(radius.is_finite() && radius >= 0.0) {
            return Err(SpatialError::InvalidRadius { radius });
        }
        let reach = (radius + self.max_radius) * (1.0 + 1e-12);
        let pad = 16.0 * f64::EPSILON * p.coords.amax();
        let mut faces = Vec::new();
        self.tree
            .query(&[p.x, p.y, p.z])
            .within::<SquaredEuclidean<f64>>(reach * reach)
            .unsorted()
            .visit(|item| {
                let sample = &self.samples[item.item as usize];
                if sample.lower_bound(p, item.distance) <= radius * (1.0 + 1e-12) + pad {
                    faces.push(sample.face);
                }
            });
        faces.sort_unstable();
        faces.dedup();
        Ok(faces)
    }

    /// The exact closest point of the mesh to `p`, with the search started from face
    /// `hint` (typically the face the point was on before it moved) instead of the face
    /// of the nearest sample: one kd-tree query instead of two, with a small radius when
    /// the hint is good. The answer does not depend on the hint.
    pub fn locate_near(&self, p: &Point3<f64>, hint: FaceId) -> Result<Located, SpatialError> {
        check_point(p)?;
        self.check_hint(hint)?;
        Ok(self.search(p, Some(hint), &mut Scratch::new()))
    }

    /// [`SurfaceIndex::locate`] for every point; results in the order of `points`. The
    /// points are processed in Morton order, each search starting from the previous
    /// point's face when that point is within the largest sample radius (see
    /// [`crate::morton`]). An error names the first bad point's index
    /// ([`SpatialError::InBatch`]).
    pub fn locate_all(&self, points: &[Point3<f64>]) -> Result<Vec<Located>, SpatialError> {
        for (i, p) in points.iter().enumerate() {
            check_point(p).map_err(|e| e.in_batch(i))?;
        }
        Ok(self.batch(points, |_, previous| previous))
    }

    /// [`SurfaceIndex::locate_near`] for every point with its own hint (`hints[i]` for
    /// `points[i]`): the per-step re-location of a flow. Results in the order of
    /// `points`; the points are processed in Morton order.
    pub fn locate_all_near(
        &self,
        points: &[Point3<f64>],
        hints: &[FaceId],
    ) -> Result<Vec<Located>, SpatialError> {
        if hints.len() != points.len() {
            return Err(SpatialError::LengthMismatch {
                what: "hints",
                expected: points.len(),
                found: hints.len(),
            });
        }
        for (i, (p, &h)) in points.iter().zip(hints).enumerate() {
            check_point(p).map_err(|e| e.in_batch(i))?;
            self.check_hint(h).map_err(|e| e.in_batch(i))?;
        }
        Ok(self.batch(points, |i, _| Some(hints[i])))
    }

    fn check_hint(&self, hint: FaceId) -> Result<(), SpatialError> {
        if hint.idx() < self.mesh.face_count() {
            Ok(())
        } else {
            Err(SpatialError::HintOutOfRange {
                face: hint,
                face_count: self.mesh.face_count(),
            })
        }
    }

    /// Searches for every (checked) point in Morton order, starting from
    /// `start(i, previous)` where `previous` is the face found for the previous point
    /// if that point is within the largest sample radius of point `i`.
    fn batch(
        &self,
        points: &[Point3<f64>],
        start: impl Fn(usize, Option<FaceId>) -> Option<FaceId> + Sync,
    ) -> Vec<Located> {
        let order = crate::morton::order(points);
        // Each thread takes a stretch of the Morton order, its points near each other.
        let stretches = beltrami_mesh::parallel::map_ranges_of(
            order.len(),
            self.threads,
            SEARCH_CHUNK,
            |range| {
                let mut scratch = Scratch::new();
                let mut previous: Option<(usize, FaceId)> = None;
                order[range]
                    .iter()
                    .map(|&i| {
                        let i = i as usize;
                        let p = &points[i];
                        let near = previous
                            .filter(|&(j, _)| (points[j] - p).norm() <= self.max_radius)
                            .map(|(_, face)| face);
                        let located = self.search(p, start(i, near), &mut scratch);
                        previous = Some((i, located.point.face));
                        located
                    })
                    .collect::<Vec<_>>()
            },
        );
        let unset = Located {
            point: SurfacePoint {
                face: FaceId(0),
                coords: [0.0; 4],
            },
            position: Point3::origin(),
            distance: f64::INFINITY,
        };
        let mut out = vec![unset; points.len()];
        for (&i, located) in order.iter().zip(stretches.into_iter().flatten()) {
            out[i as usize] = located;
        }
        out
    }

    /// [`crate::closest_point::closest_on_face`] from the index's contiguous corners.
    #[inline]
    fn closest_on(&self, f: FaceId, p: &Point3<f64>) -> ClosestPoint {
        let h = self.mesh.face_halfedge(f).idx();
        let c = &self.corners;
        if self.mesh.face_degree(f) == 3 {
            closest_on_triangle(p, &[c[h], c[h + 1], c[h + 2]])
        } else {
            closest_on_quad(p, &[c[h], c[h + 1], c[h + 2], c[h + 3]])
        }
    }

    /// The exact search, from face `start` or else from the face of the nearest sample
    /// center: all samples within `|p - best| + R`, pruned by their lower bounds, ties to
    /// the lowest face id.
    fn search(&self, p: &Point3<f64>, start: Option<FaceId>, scratch: &mut Scratch) -> Located {
        let face = start.unwrap_or_else(|| {
            let nearest = self
                .tree
                .query(&[p.x, p.y, p.z])
                .nearest_one::<SquaredEuclidean<f64>>()
                .with_scratch(scratch)
                .execute();
            self.samples[nearest.item as usize].face
        });
        let best = self.closest_on(face, p);
        let (mut face, mut best) = (face, best);
        let mut best_distance = best.distance();
        // Padded so that rounding of the squared distances cannot drop a sample on the
        // sphere.
        let radius = (best_distance + self.max_radius) * (1.0 + 1e-12);
        // Rounding of the bound is of the order of the coordinates' ulps.
        let pad = 16.0 * f64::EPSILON * p.coords.amax();
        self.tree
            .query(&[p.x, p.y, p.z])
            .within::<SquaredEuclidean<f64>>(radius * radius)
            .unsorted()
            .with_scratch(scratch)
            .visit(|item| {
                let sample = &self.samples[item.item as usize];
                if sample.face == face
                    || sample.lower_bound(p, item.distance) > best_distance * (1.0 + 1e-12) + pad
                {
                    return;
                }
                let c = self.closest_on(sample.face, p);
                let closer = c.distance_squared < best.distance_squared;
                let tie = c.distance_squared == best.distance_squared && sample.face < face;
                if closer || tie {
                    best = c;
                    face = sample.face;
                    best_distance = c.distance();
                }
            });
        Located {
            point: SurfacePoint {
                face,
                coords: best.coords,
            },
            position: best.position,
            distance: best.distance(),
        }
    }
}
