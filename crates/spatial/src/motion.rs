//! Moving a surface point by a tangent displacement and landing on the surface.
//!
//! # The walk
//!
//! [`SurfaceIndex::move_point`] with [`MoveMethod::Walk`] follows the straight line of
//! the surface (a geodesic of the polyhedral metric) from the start point, in the
//! direction of the displacement `d`, for the length of `d`:
//!
//! 1. The normal part of `d` is dropped, with the interpolated vertex normal `n` of the
//!    start point (the normal of its [`TangentFrame`](crate::frame::TangentFrame)); the
//!    length of the tangential part `d_t` is the distance walked (a `d_t` within rounding
//!    of zero, `|d_t| <= 4 eps |d|`, leaves the point where it is). `d_t` is carried into
//!    the plane of the start face by the smallest rotation taking `n` to the face normal,
//!    which keeps its length and its angle to the axis of that rotation.
//! 2. Inside a triangle the path is straight: in barycentric coordinates the point moves
//!    as `l(t) = l + t delta`, with `delta` the barycentric change of the remaining
//!    displacement, and leaves through the edge whose coordinate first reaches 0.
//! 3. Across an interior edge the remaining displacement is *unfolded*: rotated about the
//!    edge from one face's plane into the other's, `w' = (w . e) e + (w . m) m'` with `e`
//!    the unit edge, `m = n x e` and `m' = n' x e`. On a developable surface this is the
//!    straight line of the unrolled surface; on a flat mesh it is plain vector addition.
//! 4. Through a vertex (the path meets it within `1e-12` in barycentric terms) the path
//!    continues as the *straightest* geodesic: with `theta` the sum of the corner angles
//!    at the vertex, the outgoing direction leaves at angle `theta / 2` from the incoming
//!    one, measured around the vertex (equal angles on both sides; straight on for a flat
//!    vertex). At a boundary vertex the path goes straight on (angle `pi`) if that stays
//!    in the vertex's fan, and otherwise it has reached the boundary.
//! 5. A start exactly at a vertex maps the tangent plane to the vertex's fan by scaling
//!    angles (measured from the first fan edge projected onto the tangent plane) by
//!    `theta / 2 pi` (by `theta / Phi` at a boundary vertex whose fan spans the angle
//!    `Phi` in the tangent plane; directions outside it have reached the boundary).
//!
//! Quads are walked as their two triangles `(p0, p1, p2)` and `(p0, p2, p3)` (the
//! diagonal is unfolded like an edge); the end point is mapped back to the bilinear
//! patch by Newton's method from the triangles' affine parameter ([`crate::closest_point`]),
//! exact for planar quads and on quad edges.
//!
//! # Boundaries
//!
//! When the path reaches a boundary edge (or leaves the surface at a boundary vertex),
//! [`BoundaryMode::Stop`] ends the move there, and [`BoundaryMode::Slide`] spends the
//! rest of the displacement moving along the boundary: its component along the boundary
//! edge that was hit (at a vertex, along the nearer boundary edge by angle) is walked as
//! arc length along the boundary polyline, across boundary vertices, so the point stays on
//! the boundary. With these two modes a point on the boundary with a displacement
//! pointing into the surface leaves the boundary; [`BoundaryMode::Keep`] slides like
//! `Slide` and also keeps points that start on the boundary on it, moving them by the
//! displacement's component along the boundary.
//!
//! # Projection
//!
//! [`MoveMethod::Project`] moves the point in space by `d_t` and takes the closest point
//! of the mesh ([`SurfaceIndex::locate_near`], exact, hinted with the start face): the
//! method of the Wong-Zhao paper. It is cheaper for long moves, but near thin parts or
//! sharp features the closest point can be on another sheet of the surface. The walk
//! falls back to it (reporting [`MoveOutcome::Projected`]) if it has not ended after
//! [`MoveOptions::max_steps`] triangle steps or meets a degenerate triangle.

use beltrami_mesh::surface_point::bilinear_weights;
use beltrami_mesh::{FaceId, HalfedgeId, Mesh, SurfacePoint, VertexId};
use nalgebra::{Point3, Vector3};

use crate::boundary::{OnBoundary, on_boundary};
use crate::closest_point::{closest_on_triangle, quad_edge_parameter, refine_on_quad};
use crate::error::{SpatialError, check_displacement};
use crate::frame::{any_orthogonal, interpolated_normal};
use crate::index::SurfaceIndex;

/// A barycentric coordinate at most this small puts the point on the opposite edge
/// (a path within it of a vertex passes through the vertex).
pub(crate) const VERTEX_TOLERANCE: f64 = 1e-12;

/// Barycentric rates below this fraction of the largest one count as zero (the path runs
/// parallel to that edge).
const PARALLEL_TOLERANCE: f64 = 1e-12;

/// How a point is moved.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MoveMethod {
    /// Walk along the surface, unfolding across edges (see the module docs).
    Walk,
    /// Move in space, then take the closest point of the mesh.
    Project,
}

/// What a move does at the boundary.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BoundaryMode {
    /// A walk ends where its path meets the boundary.
    Stop,
    /// A walk that meets the boundary spends the rest of the displacement's component
    /// along the boundary moving along it.
    Slide,
    /// As [`BoundaryMode::Slide`], and a point that starts on the boundary (on a boundary
    /// edge or at a boundary vertex) moves only along it, by the displacement's component
    /// along its boundary edge (at a vertex, the boundary edge the displacement points
    /// most along), with either method: boundary points stay on the boundary, as a
    /// boundary-to-boundary registration needs.
    Keep,
}

/// Options of [`SurfaceIndex::move_point`] and [`SurfaceIndex::move_all`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MoveOptions {
    /// Walk or project. Default: walk.
    pub method: MoveMethod,
    /// Behaviour at the boundary of the walk. Default: slide.
    pub boundary: BoundaryMode,
    /// Triangle steps after which a walk gives up and projects instead. Default: 10000.
    pub max_steps: usize,
}

impl Default for MoveOptions {
    fn default() -> Self {
        Self {
            method: MoveMethod::Walk,
            boundary: BoundaryMode::Slide,
            max_steps: 10_000,
        }
    }
}

/// How a move ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MoveOutcome {
    /// The whole displacement was walked inside the surface.
    Arrived,
    /// The path met the boundary and stopped there ([`BoundaryMode::Stop`]).
    StoppedAtBoundary,
    /// The path met the boundary and slid along it ([`BoundaryMode::Slide`]); the point
    /// is on the boundary.
    SlidAlongBoundary,
    /// The point was projected ([`MoveMethod::Project`], or the walk's fallback).
    Projected,
}

/// The result of a move.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Moved {
    /// Where the point landed.
    pub point: SurfacePoint,
    /// Its position, `point.position(mesh)`.
    pub position: Point3<f64>,
    /// How the move ended.
    pub outcome: MoveOutcome,
    /// Number of times the walk entered another face (0 for a projection).
    pub faces_crossed: usize,
}

/// Counts over a batch of moves ([`SurfaceIndex::move_all`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct MoveSummary {
    /// Moves that walked their whole displacement.
    pub arrived: usize,
    /// Moves stopped at the boundary.
    pub stopped_at_boundary: usize,
    /// Moves that slid along the boundary.
    pub slid_along_boundary: usize,
    /// Moves that were projected (by choice or as the walk's fallback).
    pub projected: usize,
    /// Faces entered, summed over all walks.
    pub faces_crossed: usize,
}

impl std::ops::Add for MoveSummary {
    type Output = Self;

    /// The counts of two batches together.
    fn add(self, other: Self) -> Self {
        Self {
            arrived: self.arrived + other.arrived,
            stopped_at_boundary: self.stopped_at_boundary + other.stopped_at_boundary,
            slid_along_boundary: self.slid_along_boundary + other.slid_along_boundary,
            projected: self.projected + other.projected,
            faces_crossed: self.faces_crossed + other.faces_crossed,
        }
    }
}

/// One triangle of the walk: a triangle face, or half of a quad split along `p0 p2`
/// (half 0 is `(p0, p1, p2)`, half 1 is `(p0, p2, p3)`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Tri {
    face: FaceId,
    half: u8,
}

/// Corners of a walk triangle: their slots in the face, vertices and positions, in
/// counter-clockwise order.
struct Corners {
    slots: [usize; 3],
    vertices: [VertexId; 3],
    positions: [Point3<f64>; 3],
}

impl Corners {
    fn of(mesh: &Mesh, tri: Tri) -> Self {
        let (v, n) = mesh.face_vertex_array(tri.face);
        let slots = if n == 4 && tri.half == 1 {
            [0, 2, 3]
        } else {
            [0, 1, 2]
        };
        let vertices = slots.map(|s| v[s]);
        Self {
            slots,
            vertices,
            positions: vertices.map(|v| mesh.position(v)),
        }
    }

    /// `(p1 - p0) x (p2 - p0)`.
    fn normal(&self) -> Vector3<f64> {
        let p = &self.positions;
        (p[1] - p[0]).cross(&(p[2] - p[0]))
    }

    /// Unit vectors from corner `c` along its two sides, in counter-clockwise order.
    fn sides(&self, c: usize) -> (Vector3<f64>, Vector3<f64>) {
        let p = &self.positions;
        (
            (p[(c + 1) % 3] - p[c]).normalize(),
            (p[(c + 2) % 3] - p[c]).normalize(),
        )
    }

    /// The interior angle at corner `c`.
    fn angle(&self, c: usize) -> f64 {
        let (a, b) = self.sides(c);
        a.cross(&b).norm().atan2(a.dot(&b))
    }
}

/// What lies across the side of a walk triangle opposite one of its corners.
enum Across {
    /// Another walk triangle.
    Tri(Tri),
    /// Nothing: the side is a boundary edge, given as the face halfedge along it.
    Boundary(HalfedgeId),
}

fn across(mesh: &Mesh, tri: Tri, corners: &Corners, k: usize) -> Across {
    let (a, b) = (corners.slots[(k + 1) % 3], corners.slots[(k + 2) % 3]);
    let degree = mesh.face_degree(tri.face);
    if (b + degree - a) % degree != 1 {
        // The diagonal of a quad.
        return Across::Tri(Tri {
            face: tri.face,
            half: 1 - tri.half,
        });
    }
    let h = HalfedgeId(mesh.face_halfedge(tri.face).0 + a as u32);
    let twin = mesh.twin(h);
    match mesh.face(twin) {
        None => Across::Boundary(h),
        Some(g) => {
            let j = twin.0 - mesh.face_halfedge(g).0;
            let half = u8::from(mesh.face_degree(g) == 4 && j >= 2);
            Across::Tri(Tri { face: g, half })
        }
    }
}

/// One walk triangle at a vertex: its corner there, the angle of that corner, and the
/// angle around the vertex where its wedge starts.
struct FanEntry {
    tri: Tri,
    corner: usize,
    start: f64,
    angle: f64,
}

/// The walk triangles around `v` counter-clockwise (for a boundary vertex from the
/// boundary edge at angle 0 to the one at the total angle), and the total angle.
fn fan(mesh: &Mesh, v: VertexId) -> (Vec<FanEntry>, f64) {
    let mut entries = Vec::new();
    let mut total = 0.0;
    for h in mesh.outgoing_halfedges(v) {
        let Some(f) = mesh.face(h) else { continue };
        let j = (h.0 - mesh.face_halfedge(f).0) as usize;
        let half = |half: u8, corner: usize| (Tri { face: f, half }, corner);
        let pieces: &[(Tri, usize)] = &match (mesh.face_degree(f), j) {
            (3, _) => vec![half(0, j)],
            (_, 0) => vec![half(0, 0), half(1, 0)],
            (_, 1) => vec![half(0, 1)],
            (_, 2) => vec![half(1, 1), half(0, 2)],
            _ => vec![half(1, 2)],
        };
        for &(tri, corner) in pieces {
            let angle = Corners::of(mesh, tri).angle(corner);
            entries.push(FanEntry {
                tri,
                corner,
                start: total,
                angle,
            });
            total += angle;
        }
    }
    (entries, total)
}

/// The smallest rotation taking the unit vector `from` to the unit vector `to`, applied
/// to `v`; the result is made orthogonal to `to` and given the length of `v`.
fn rotate_into_plane(v: &Vector3<f64>, from: &Vector3<f64>, to: &Vector3<f64>) -> Vector3<f64> {
    let c = from.dot(to);
    let k = from.cross(to);
    let rotated = if c > -1.0 + 1e-12 {
        c * v + k.cross(v) + (k.dot(v) / (1.0 + c)) * k
    } else {
        *v
    };
    let in_plane = rotated - rotated.dot(to) * to;
    let length = in_plane.norm();
    if length > 0.0 {
        in_plane * (v.norm() / length)
    } else {
        in_plane
    }
}

/// Where a walk ended, before conversion to a surface point.
enum End {
    /// Inside (or on the boundary of) a walk triangle.
    InTri(Tri, [f64; 3], MoveOutcome),
    /// On face halfedge `h` at fraction `t` from its origin.
    OnHalfedge(HalfedgeId, f64, MoveOutcome),
}

/// A walk that could not finish (too many steps, degenerate triangle).
struct Stuck;

/// What follows a vertex: the walk goes on from a triangle, coordinates and
/// displacement, or it has ended.
enum Next {
    Continue(Tri, [f64; 3], Vector3<f64>),
    Stop(End),
}

/// The surface point at fraction `t` along face halfedge `h`.
fn point_on_halfedge(mesh: &Mesh, h: HalfedgeId, t: f64) -> SurfacePoint {
    let face = mesh
        .face(h)
        .expect("points on halfedges are on face halfedges");
    let j = (h.0 - mesh.face_halfedge(face).0) as usize;
    if mesh.face_degree(face) == 3 {
        let mut l = [0.0; 3];
        l[j] = 1.0 - t;
        l[(j + 1) % 3] = t;
        SurfacePoint::in_triangle(face, l)
    } else {
        let (u, v) = quad_edge_parameter(j, t);
        SurfacePoint::in_quad(face, u, v)
    }
}

/// The surface point of barycentric coordinates `l` in walk triangle `tri`.
fn to_surface_point(mesh: &Mesh, tri: Tri, l: [f64; 3]) -> SurfacePoint {
    if mesh.face_degree(tri.face) == 3 {
        return SurfacePoint::in_triangle(tri.face, l);
    }
    let (u, v) = if tri.half == 0 {
        (l[1] + l[2], l[2])
    } else {
        (l[1], l[1] + l[2])
    };
    let (vertices, _) = mesh.face_vertex_array(tri.face);
    let q = vertices.map(|v| mesh.position(v));
    let corners = Corners::of(mesh, tri);
    let x = Point3::from(
        l[0] * corners.positions[0].coords
            + l[1] * corners.positions[1].coords
            + l[2] * corners.positions[2].coords,
    );
    let (u, v) = refine_on_quad(&x, &q, u, v);
    SurfacePoint {
        face: tri.face,
        coords: bilinear_weights(u, v),
    }
}

/// The walk triangle and barycentric coordinates of a surface point (for a quad, the
/// closest point of its two triangles to the patch point).
fn from_surface_point(mesh: &Mesh, p: &SurfacePoint) -> (Tri, [f64; 3]) {
    let l = |c: [f64; 4]| [c[0], c[1], c[2]];
    if mesh.face_degree(p.face) == 3 {
        return (
            Tri {
                face: p.face,
                half: 0,
            },
            l(p.coords),
        );
    }
    let x = p.position(mesh);
    let halves = [0, 1].map(|half| {
        let tri = Tri { face: p.face, half };
        (
            tri,
            closest_on_triangle(&x, &Corners::of(mesh, tri).positions),
        )
    });
    let [(t0, c0), (t1, c1)] = halves;
    if c0.distance_squared <= c1.distance_squared {
        (t0, l(c0.coords))
    } else {
        (t1, l(c1.coords))
    }
}

/// Clamps coordinates to be non-negative and rescales them to sum to 1.
fn normalized(l: [f64; 3]) -> [f64; 3] {
    let l = l.map(|x| x.max(0.0));
    let sum = l[0] + l[1] + l[2];
    if sum > 0.0 {
        l.map(|x| x / sum)
    } else {
        [1.0, 0.0, 0.0]
    }
}

/// The state of one walk.
struct Walker<'a> {
    mesh: &'a Mesh,
    options: &'a MoveOptions,
    steps: usize,
    crossed: usize,
}

impl Walker<'_> {
    /// Walks from `(tri, l)` along `w` (in the triangle's plane).
    fn walk(&mut self, tri: Tri, l: [f64; 3], w: Vector3<f64>) -> Result<End, Stuck> {
        let mesh = self.mesh;
        let (mut tri, mut l, mut w) = (tri, l, w);
        loop {
            self.steps += 1;
            if self.steps > self.options.max_steps {
                return Err(Stuck);
            }
            let corners = Corners::of(mesh, tri);
            let p = &corners.positions;
            let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
            let n = e1.cross(&e2);
            let nn = n.norm_squared();
            // Zero or NaN: a degenerate triangle.
            if nn.is_nan() || nn <= 0.0 {
                return Err(Stuck);
            }
            let d1 = n.dot(&w.cross(&e2)) / nn;
            let d2 = n.dot(&e1.cross(&w)) / nn;
            let delta = [-d1 - d2, d1, d2];
            let scale = delta.iter().fold(0.0_f64, |m, d| m.max(d.abs()));
            let mut exit: Option<(f64, usize)> = None;
            for (i, &d) in delta.iter().enumerate() {
                if d < -PARALLEL_TOLERANCE * scale {
                    let t = l[i].max(0.0) / -d;
                    if exit.is_none_or(|(best, _)| t < best) {
                        exit = Some((t, i));
                    }
                }
            }
            let (t, k) = match exit {
                Some((t, k)) if t < 1.0 => (t, k),
                _ => {
                    let end = [0, 1, 2].map(|i| l[i] + delta[i]);
                    return Ok(End::InTri(tri, normalized(end), MoveOutcome::Arrived));
                }
            };
            let mut at = [0, 1, 2].map(|i| l[i] + t * delta[i]);
            at[k] = 0.0;
            let at = normalized(at);
            w *= 1.0 - t;
            let (i, j) = ((k + 1) % 3, (k + 2) % 3);
            if at[i] <= VERTEX_TOLERANCE || at[j] <= VERTEX_TOLERANCE {
                let c = if at[i] <= VERTEX_TOLERANCE { j } else { i };
                match self.through_vertex(tri, &corners, c, w)? {
                    Next::Continue(next, lv, wv) => (tri, l, w) = (next, lv, wv),
                    Next::Stop(end) => return Ok(end),
                }
                continue;
            }
            match across(mesh, tri, &corners, k) {
                Across::Boundary(h) => {
                    // Fraction along h (from corner i to corner j) is the coordinate of j.
                    return Ok(self.at_boundary_edge(h, at[j], &w));
                }
                Across::Tri(next) => {
                    let nc = Corners::of(mesh, next);
                    let edge = (p[j] - p[i]).normalize();
                    let (nu, nv) = (n.normalize(), nc.normal().normalize());
                    w = w.dot(&edge) * edge + w.dot(&nu.cross(&edge)) * nv.cross(&edge);
                    let mut nl = [0.0; 3];
                    for (s, v) in nc.vertices.iter().enumerate() {
                        if *v == corners.vertices[i] {
                            nl[s] = at[i];
                        } else if *v == corners.vertices[j] {
                            nl[s] = at[j];
                        }
                    }
                    if next.face != tri.face {
                        self.crossed += 1;
                    }
                    (tri, l) = (next, nl);
                }
            }
        }
    }

    /// The path reached the boundary edge of face halfedge `h` at fraction `t`, with `w`
    /// left to move.
    fn at_boundary_edge(&mut self, h: HalfedgeId, t: f64, w: &Vector3<f64>) -> End {
        let mesh = self.mesh;
        match self.options.boundary {
            BoundaryMode::Stop => End::OnHalfedge(h, t, MoveOutcome::StoppedAtBoundary),
            BoundaryMode::Slide | BoundaryMode::Keep => {
                let edge = mesh.halfedge_vector(h);
                let length = edge.norm();
                let along = if length > 0.0 {
                    w.dot(&edge) / length
                } else {
                    0.0
                };
                // Along the boundary halfedge (the twin, reversed) from fraction 1 - t.
                let (b, s) = slide(mesh, mesh.twin(h), 1.0 - t, -along);
                End::OnHalfedge(mesh.twin(b), 1.0 - s, MoveOutcome::SlidAlongBoundary)
            }
        }
    }

    /// The path reached corner `c` of `tri` with `w` left: the straightest continuation,
    /// or the end of the walk at the boundary.
    fn through_vertex(
        &mut self,
        tri: Tri,
        corners: &Corners,
        c: usize,
        w: Vector3<f64>,
    ) -> Result<Next, Stuck> {
        let mesh = self.mesh;
        let v = corners.vertices[c];
        let length = w.norm();
        let (entries, total) = fan(mesh, v);
        let Some(entry) = entries.iter().find(|e| e.tri == tri) else {
            return Err(Stuck);
        };
        if length == 0.0 {
            let mut l = [0.0; 3];
            l[c] = 1.0;
            return Ok(Next::Stop(End::InTri(tri, l, MoveOutcome::Arrived)));
        }
        // Angle of the reversed path direction inside this triangle's wedge.
        let back = -w / length;
        let (side, _) = corners.sides(c);
        let normal = corners.normal().normalize();
        let alpha = side
            .cross(&back)
            .dot(&normal)
            .atan2(side.dot(&back))
            .clamp(0.0, entry.angle);
        let incoming = entry.start + alpha;
        let outgoing = if mesh.is_boundary_vertex(v) {
            if incoming + std::f64::consts::PI <= total {
                incoming + std::f64::consts::PI
            } else if incoming - std::f64::consts::PI >= 0.0 {
                incoming - std::f64::consts::PI
            } else {
                let beyond_end = incoming + std::f64::consts::PI - total;
                let before_start = std::f64::consts::PI - incoming;
                return Ok(Next::Stop(self.leave_at_boundary_vertex(
                    v,
                    &entries,
                    beyond_end,
                    before_start,
                    length,
                )));
            }
        } else {
            (incoming + 0.5 * total) % total
        };
        Ok(self.direction_in_fan(&entries, outgoing, length))
    }

    /// The walk triangle, coordinates (at the vertex) and displacement of length `length`
    /// leaving the fan's vertex at angle `angle` around it.
    fn direction_in_fan(&self, entries: &[FanEntry], angle: f64, length: f64) -> Next {
        let entry = entries
            .iter()
            .find(|e| angle <= e.start + e.angle)
            .unwrap_or(&entries[entries.len() - 1]);
        let a = (angle - entry.start).clamp(0.0, entry.angle);
        let corners = Corners::of(self.mesh, entry.tri);
        let (side, _) = corners.sides(entry.corner);
        let normal = corners.normal().normalize();
        let direction = a.cos() * side + a.sin() * normal.cross(&side);
        let mut l = [0.0; 3];
        l[entry.corner] = 1.0;
        Next::Continue(entry.tri, l, length * direction)
    }

    /// The straight path leaves the surface at boundary vertex `v`: it is
    /// `beyond_end` past the boundary edge at the fan's total angle and `before_start`
    /// before the one at angle 0. Stop at `v`, or slide along the nearer edge by the
    /// projection of the remaining `length`.
    fn leave_at_boundary_vertex(
        &mut self,
        v: VertexId,
        entries: &[FanEntry],
        beyond_end: f64,
        before_start: f64,
        length: f64,
    ) -> End {
        let mesh = self.mesh;
        let first = &entries[0];
        let stop = |outcome| {
            let mut l = [0.0; 3];
            l[first.corner] = 1.0;
            End::InTri(first.tri, l, outcome)
        };
        if self.options.boundary == BoundaryMode::Stop {
            return stop(MoveOutcome::StoppedAtBoundary);
        }
        // The outgoing boundary halfedge of v runs along the fan's last side; the one
        // before it in its loop runs into v along the first side.
        let out = mesh.vertex_halfedge(v);
        let (b, s, excess, sign) = if beyond_end <= before_start {
            (out, 0.0, beyond_end, 1.0)
        } else {
            (mesh.prev(out), 1.0, before_start, -1.0)
        };
        let along = length * excess.cos();
        if along <= 0.0 {
            return stop(MoveOutcome::SlidAlongBoundary);
        }
        let (b, s) = slide(mesh, b, s, sign * along);
        End::OnHalfedge(mesh.twin(b), 1.0 - s, MoveOutcome::SlidAlongBoundary)
    }
}

/// Moves a point along its boundary loop by arc length: from fraction `s` of boundary
/// halfedge `b`, `distance` forward (positive, along the loop's direction) or backward.
/// Returns the boundary halfedge and fraction where it ends.
fn slide(mesh: &Mesh, b: HalfedgeId, s: f64, distance: f64) -> (HalfedgeId, f64) {
    let (mut b, mut s, mut left) = (b, s, distance);
    let mut edges_passed = 0usize;
    loop {
        if edges_passed == 64 {
            // A long slide: first drop whole turns around the loop.
            let mut perimeter = 0.0;
            let mut h = b;
            loop {
                perimeter += mesh.halfedge_vector(h).norm();
                h = mesh.next(h);
                if h == b {
                    break;
                }
            }
            if perimeter > 0.0 {
                left %= perimeter;
            } else {
                return (b, s);
            }
        }
        edges_passed += 1;
        let length = mesh.halfedge_vector(b).norm();
        if left > 0.0 {
            let room = (1.0 - s) * length;
            if left <= room {
                return (b, s + left / length);
            }
            left -= room;
            (b, s) = (mesh.next(b), 0.0);
        } else if left < 0.0 {
            let room = s * length;
            if -left <= room {
                return (b, s + left / length);
            }
            left += room;
            (b, s) = (mesh.prev(b), 1.0);
        } else {
            return (b, s);
        }
    }
}

impl SurfaceIndex<'_> {
    /// Moves `point` by the tangent displacement `displacement` (its part along the
    /// normal at `point` is dropped) and lands on the surface: see the module docs for
    /// the walk, the boundary modes and the projection. Fails if `point` does not belong
    /// to the mesh or the displacement is not finite.
    pub fn move_point(
        &self,
        point: &SurfacePoint,
        displacement: &Vector3<f64>,
        options: &MoveOptions,
    ) -> Result<Moved, SpatialError> {
        let mesh = self.mesh();
        point.validate(mesh)?;
        check_displacement(displacement)?;
        let normal = interpolated_normal(mesh, self.vertex_normals(), point);
        let tangent = displacement - displacement.dot(&normal) * normal;
        // A tangential part at the rounding level of removing the normal part is none.
        if tangent.norm() <= 4.0 * f64::EPSILON * displacement.norm() {
            return Ok(Moved {
                point: *point,
                position: point.position(mesh),
                outcome: MoveOutcome::Arrived,
                faces_crossed: 0,
            });
        }
        if options.boundary == BoundaryMode::Keep
            && let Some(on) = on_boundary(mesh, point)
        {
            return Ok(self.along_boundary(on, &tangent));
        }
        if options.method == MoveMethod::Project {
            return self.project(point, &tangent);
        }
        let mut walker = Walker {
            mesh,
            options,
            steps: 0,
            crossed: 0,
        };
        let (tri, l) = from_surface_point(mesh, point);
        let corners = Corners::of(mesh, tri);
        let end = match l.iter().position(|&x| x >= 1.0 - VERTEX_TOLERANCE) {
            Some(c) => {
                let v = corners.vertices[c];
                match self.leave_vertex(&mut walker, v, &normal, &tangent) {
                    Next::Continue(tri, l, w) => walker.walk(tri, l, w),
                    Next::Stop(end) => Ok(end),
                }
            }
            None => {
                let face_normal = corners.normal().normalize();
                let w = rotate_into_plane(&tangent, &normal, &face_normal);
                walker.walk(tri, l, w)
            }
        };
        let Ok(end) = end else {
            return self.project(point, &tangent);
        };
        let (point, outcome) = match end {
            End::InTri(tri, l, outcome) => (to_surface_point(mesh, tri, l), outcome),
            End::OnHalfedge(h, t, outcome) => (point_on_halfedge(mesh, h, t), outcome),
        };
        Ok(Moved {
            point,
            position: point.position(mesh),
            outcome,
            faces_crossed: walker.crossed,
        })
    }

    /// A walk starting at vertex `v` along the tangent vector `tangent` (normal `normal`):
    /// the tangent plane's angles scaled onto the vertex's fan.
    fn leave_vertex(
        &self,
        walker: &mut Walker<'_>,
        v: VertexId,
        normal: &Vector3<f64>,
        tangent: &Vector3<f64>,
    ) -> Next {
        let mesh = self.mesh();
        let (entries, total) = fan(mesh, v);
        let length = tangent.norm();
        let project = |x: Vector3<f64>| {
            let t = x - x.dot(normal) * normal;
            let n = t.norm();
            if n > 0.0 {
                t / n
            } else {
                any_orthogonal(normal)
            }
        };
        let first = &entries[0];
        let reference = project(Corners::of(mesh, first.tri).sides(first.corner).0);
        let angle_of = |x: &Vector3<f64>| {
            let a = reference.cross(x).dot(normal).atan2(reference.dot(x));
            if a < 0.0 {
                a + std::f64::consts::TAU
            } else {
                a
            }
        };
        let heading = angle_of(&(tangent / length));
        let angle = if mesh.is_boundary_vertex(v) {
            let last = &entries[entries.len() - 1];
            let span = angle_of(&project(Corners::of(mesh, last.tri).sides(last.corner).1));
            let span = if span > 0.0 {
                span
            } else {
                std::f64::consts::TAU
            };
            if heading > span {
                return Next::Stop(walker.leave_at_boundary_vertex(
                    v,
                    &entries,
                    heading - span,
                    std::f64::consts::TAU - heading,
                    length,
                ));
            }
            heading * total / span
        } else {
            heading * total / std::f64::consts::TAU
        };
        walker.direction_in_fan(&entries, angle, length)
    }

    /// Moves a boundary point along the boundary by the component of `tangent` along its
    /// edge ([`BoundaryMode::Keep`]).
    fn along_boundary(&self, on: OnBoundary, tangent: &Vector3<f64>) -> Moved {
        let mesh = self.mesh();
        let unit = |h: HalfedgeId| {
            let e = mesh.halfedge_vector(h);
            let length = e.norm();
            if length > 0.0 { e / length } else { e }
        };
        // The boundary halfedge, fraction along it, and signed distance to slide.
        let (b, s, distance) = match on {
            OnBoundary::Edge(h, t) => (mesh.twin(h), 1.0 - t, -tangent.dot(&unit(h))),
            OnBoundary::Vertex(v) => {
                let out = mesh.vertex_halfedge(v);
                let into = mesh.prev(out);
                let (forward, backward) = (tangent.dot(&unit(out)), -tangent.dot(&unit(into)));
                if forward >= backward {
                    (out, 0.0, forward.max(0.0))
                } else {
                    (into, 1.0, -backward.max(0.0))
                }
            }
        };
        let (b, s) = slide(mesh, b, s, distance);
        let point = point_on_halfedge(mesh, mesh.twin(b), 1.0 - s);
        Moved {
            point,
            position: point.position(mesh),
            outcome: MoveOutcome::SlidAlongBoundary,
            faces_crossed: 0,
        }
    }

    /// Moves `point` in space by `tangent` and takes the closest point of the mesh.
    fn project(&self, point: &SurfacePoint, tangent: &Vector3<f64>) -> Result<Moved, SpatialError> {
        let target = point.position(self.mesh()) + tangent;
        let located = self.locate_near(&target, point.face)?;
        Ok(Moved {
            point: located.point,
            position: located.position,
            outcome: MoveOutcome::Projected,
            faces_crossed: 0,
        })
    }

    /// Moves every point by its displacement ([`SurfaceIndex::move_point`]), in place:
    /// the per-step update of a flow. All points and displacements are checked first, so
    /// on error (naming the first bad item) no point has moved.
    pub fn move_all(
        &self,
        points: &mut [SurfacePoint],
        displacements: &[Vector3<f64>],
        options: &MoveOptions,
    ) -> Result<MoveSummary, SpatialError> {
        if displacements.len() != points.len() {
            return Err(SpatialError::LengthMismatch {
                what: "displacements",
                expected: points.len(),
                found: displacements.len(),
            });
        }
        for (i, (p, d)) in points.iter().zip(displacements).enumerate() {
            p.validate(self.mesh())
                .map_err(|e| SpatialError::from(e).in_batch(i))?;
            check_displacement(d).map_err(|e| e.in_batch(i))?;
        }
        let parts =
            beltrami_mesh::parallel::map_chunks_mut(points, self.threads(), |offset, chunk| {
                let mut summary = MoveSummary::default();
                for (i, p) in chunk.iter_mut().enumerate() {
                    let d = &displacements[offset + i];
                    let moved = self
                        .move_point(p, d, options)
                        .map_err(|e| e.in_batch(offset + i))?;
                    *p = moved.point;
                    summary.faces_crossed += moved.faces_crossed;
                    match moved.outcome {
                        MoveOutcome::Arrived => summary.arrived += 1,
                        MoveOutcome::StoppedAtBoundary => summary.stopped_at_boundary += 1,
                        MoveOutcome::SlidAlongBoundary => summary.slid_along_boundary += 1,
                        MoveOutcome::Projected => summary.projected += 1,
                    }
                }
                Ok::<_, SpatialError>(summary)
            });
        // The first failure in point order, as a sequential loop would report it.
        parts
            .into_iter()
            .try_fold(MoveSummary::default(), |total, part| Ok(total + part?))
    }
}
