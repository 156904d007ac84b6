//! Boundary maps of disk meshes: where each boundary vertex goes when the boundary is
//! fixed (circle, unit square, convex polygon, the source's own plane positions, or
//! given values).
//!
//! # Orientation
//!
//! Boundary loops run with the surface on their right, so the outer boundary of a disk,
//! seen from the normal side, runs *clockwise* in loop order ([`beltrami_mesh::Mesh`]
//! conventions). A map keeps the faces counter-clockwise (no flips) only if the image of
//! the boundary is also traversed clockwise in loop order. Every map here therefore walks
//! its target curve clockwise: the circle by decreasing angle, a polygon given with
//! counter-clockwise corners `c_0, c_1, ..., c_{m-1}` in the order
//! `c_0, c_{m-1}, ..., c_1`.
//!
//! # Arc length
//!
//! With loop vertices `v_0 .. v_{n-1}` (rotated so that `v_0` is the start vertex) and
//! the cumulative edge length `s_k = sum_{l<k} |p_{l+1} - p_l|`, `L = s_n` (the closing
//! edge included), vertex `v_k` has the parameter `t_k = s_k / L` in `[0, 1)`.
//!
//! - [`circle`]: `v_k -> exp(-2 pi i t_k)`, so `v_0 -> 1`.
//! - [`polygon`]: the first corner goes to `v_0`; corner `j` (clockwise) to the vertex
//!   whose `t_k` is nearest to the fraction of the perimeter at which the corner sits
//!   (kept in order and distinct); the vertices between two corner vertices are spread
//!   along the side by their arc length between the two.
//! - [`square`]: the polygon `0, 1, 1 + i, i` (the unit square `[0, 1]^2`), or, with
//!   given corner vertices, those four vertices pinned to the four corners.
//!
//! Without a given start, the circle starts at the first vertex of the loop; the square
//! and polygons start at the *sharpest* boundary vertex (smallest sum of corner angles),
//! so that a mesh with corners (a grid, say) has its corners on corners of the target.
//!
//! # Collapsed faces
//!
//! A face whose vertices all land on one straight side of a polygon has zero area in the
//! image (a triangle "ear" at a boundary vertex with a single face, for instance). The
//! circle has no straight sides, so it never collapses a face; for polygons put corners
//! at such vertices (give the square's corners) or use the circle. [`collapsed_faces`]
//! lists them.
//!
//! [`keep`] and [`given`] read fixed boundary values from the source itself (a planar
//! mesh in z = 0) or from a per-vertex array.

use std::f64::consts::TAU;

use beltrami_mesh::{FaceId, Mesh, VertexId};
use num_complex::Complex64;
use thiserror::Error;

/// The images of the boundary vertices of one loop, in loop order.
#[derive(Debug, Clone, PartialEq)]
pub struct BoundaryMap {
    /// The loop's vertices, in loop order (clockwise around the outer boundary, seen from
    /// the normal side), starting at the start vertex.
    pub vertices: Vec<VertexId>,
    /// The image of each vertex of [`BoundaryMap::vertices`].
    pub positions: Vec<Complex64>,
}

/// Why a boundary map could not be built. Every variant names the vertex or the corner
/// concerned.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum BoundaryError {
    /// The mesh has no boundary loop.
    #[error("the mesh has no boundary")]
    NoBoundary,
    /// A vertex index beyond the mesh.
    #[error("vertex {vertex} does not exist: the mesh has {vertex_count} vertices")]
    VertexOutOfRange {
        /// The vertex named.
        vertex: VertexId,
        /// Number of vertices of the mesh.
        vertex_count: usize,
    },
    /// A start or corner vertex that is not on the boundary loop being mapped.
    #[error("vertex {vertex} is not on the boundary loop being mapped")]
    NotOnBoundary {
        /// The vertex named.
        vertex: VertexId,
    },
    /// A polygon with fewer than 3 corners.
    #[error("a polygon needs at least 3 corners, {corners} were given")]
    TooFewCorners {
        /// Number of corners given.
        corners: usize,
    },
    /// A polygon corner with a NaN or infinite coordinate.
    #[error("polygon corner {corner} is not finite")]
    NonFiniteCorner {
        /// Index of the corner.
        corner: usize,
    },
    /// A polygon whose corners run clockwise (negative signed area).
    #[error(
        "the polygon runs clockwise (it turns right at corner {corner}): list its corners counter-clockwise"
    )]
    NotCounterClockwise {
        /// The first corner where the polygon turns right.
        corner: usize,
    },
    /// A polygon that is not strictly convex: it turns right or goes straight at a
    /// corner, repeats a corner, or winds around more than once.
    #[error("the polygon is not strictly convex at corner {corner}")]
    NotConvex {
        /// The offending corner.
        corner: usize,
    },
    /// A boundary loop with fewer vertices than the polygon has corners.
    #[error(
        "the boundary has {vertices} vertices, fewer than the {corners} corners of the polygon"
    )]
    TooFewVertices {
        /// Vertices of the loop.
        vertices: usize,
        /// Corners of the polygon.
        corners: usize,
    },
    /// The same vertex given for two corners.
    #[error("vertex {vertex} is given for two corners")]
    RepeatedCorner {
        /// The vertex.
        vertex: VertexId,
    },
    /// Given corner vertices that do not follow the boundary counter-clockwise.
    #[error(
        "corner vertex {vertex} is out of order: corners must follow the boundary counter-clockwise (seen from the normal side)"
    )]
    CornerOrder {
        /// The first corner vertex found out of order.
        vertex: VertexId,
    },
    /// A start vertex different from the first of the given corners.
    #[error("the start vertex {start} differs from the first corner {corner}")]
    StartNotFirstCorner {
        /// The start vertex.
        start: VertexId,
        /// The first corner.
        corner: VertexId,
    },
    /// [`keep`] on a mesh that is not in the plane z = 0.
    #[error(
        "keeping the boundary needs a mesh in the plane z = 0, but vertex {vertex} has z = {z:e}"
    )]
    NotPlanar {
        /// The first vertex off the plane.
        vertex: VertexId,
        /// Its z coordinate.
        z: f64,
    },
    /// [`given`] with an array of the wrong length.
    #[error("the given boundary has {got} values but the mesh has {expected} vertices")]
    Length {
        /// Number of vertices.
        expected: usize,
        /// Number of values.
        got: usize,
    },
    /// [`given`] with a NaN or infinite value at a boundary vertex.
    #[error("the given position of boundary vertex {vertex} is not finite")]
    NonFiniteValue {
        /// The vertex.
        vertex: VertexId,
    },
}

/// Maps the longest boundary loop onto the unit circle by arc length, clockwise in loop
/// order: `v_k -> exp(-2 pi i t_k)` (module docs), with `start` (or the loop's first
/// vertex) at `1`.
pub fn circle(mesh: &Mesh, start: Option<VertexId>) -> Result<BoundaryMap, BoundaryError> {
    let vertices = rotated_loop(mesh, start)?;
    let t = arc_parameters(mesh, &vertices);
    let positions = t
        .iter()
        .map(|&t| {
            let (s, c) = (-TAU * t).sin_cos();
            Complex64::new(c, s)
        })
        .collect();
    Ok(BoundaryMap {
        vertices,
        positions,
    })
}

/// Maps the longest boundary loop onto the unit square `[0, 1]^2`.
///
/// With `corners` (boundary vertices listed counter-clockwise, seen from the normal
/// side) those vertices go to `0, 1, 1 + i, i`; otherwise the corners are the start
/// vertex (`start`, or the sharpest boundary vertex) and the vertices nearest to a
/// quarter, half and three quarters of the boundary length from it. Each side is
/// parameterized by arc length. `start`, when given with `corners`, must be `corners[0]`.
pub fn square(
    mesh: &Mesh,
    corners: Option<[VertexId; 4]>,
    start: Option<VertexId>,
) -> Result<BoundaryMap, BoundaryError> {
    let unit = [
        Complex64::new(0.0, 0.0),
        Complex64::new(1.0, 0.0),
        Complex64::new(1.0, 1.0),
        Complex64::new(0.0, 1.0),
    ];
    let Some(corners) = corners else {
        return polygon(mesh, &unit, start);
    };
    if let Some(start) = start
        && start != corners[0]
    {
        return Err(BoundaryError::StartNotFirstCorner {
            start,
            corner: corners[0],
        });
    }
    let vertices = rotated_loop(mesh, Some(corners[0]))?;
    let t = arc_parameters(mesh, &vertices);
    // Loop order is clockwise: after corners[0] come corners[3], corners[2], corners[1].
    let mut indices = vec![0];
    for &c in corners[1..].iter().rev() {
        let index = vertices
            .iter()
            .position(|&v| v == c)
            .ok_or(BoundaryError::NotOnBoundary { vertex: c })?;
        if index == 0 || indices.contains(&index) {
            return Err(BoundaryError::RepeatedCorner { vertex: c });
        }
        if index < indices[indices.len() - 1] {
            return Err(BoundaryError::CornerOrder { vertex: c });
        }
        indices.push(index);
    }
    let clockwise = clockwise_corners(&unit);
    let positions = place_on_sides(&t, &clockwise, &indices);
    Ok(BoundaryMap {
        vertices,
        positions,
    })
}

/// Maps the longest boundary loop onto the boundary of a strictly convex polygon with
/// `corners` listed counter-clockwise: the first corner at `start` (or the sharpest
/// boundary vertex), the others at the boundary vertices nearest to their proportional
/// arc length, each side by arc length (module docs).
///
/// Errors: fewer than 3 corners, a non-finite corner, a clockwise or non-convex polygon
/// (naming the corner), a boundary with fewer vertices than corners, a start vertex off
/// the boundary.
pub fn polygon(
    mesh: &Mesh,
    corners: &[Complex64],
    start: Option<VertexId>,
) -> Result<BoundaryMap, BoundaryError> {
    check_convex(corners)?;
    let start = match start {
        Some(v) => Some(v),
        None => Some(sharpest_vertex(mesh, &longest_loop(mesh)?)),
    };
    let vertices = rotated_loop(mesh, start)?;
    let (n, m) = (vertices.len(), corners.len());
    if n < m {
        return Err(BoundaryError::TooFewVertices {
            vertices: n,
            corners: m,
        });
    }
    let t = arc_parameters(mesh, &vertices);
    let clockwise = clockwise_corners(corners);
    // Fraction of the perimeter at which each clockwise corner sits.
    let sides: Vec<f64> = (0..m)
        .map(|j| (clockwise[(j + 1) % m] - clockwise[j]).norm())
        .collect();
    let perimeter: f64 = sides.iter().sum();
    let mut indices = vec![0];
    let mut walked = 0.0;
    for j in 1..m {
        walked += sides[j - 1];
        let fraction = walked / perimeter;
        // The nearest parameter, kept after the previous corner and leaving one vertex
        // for each corner still to place, so that corners get distinct vertices.
        let above = t.partition_point(|&tk| tk < fraction);
        let nearest = if above == 0 {
            0
        } else if above >= n || fraction - t[above - 1] <= t[above] - fraction {
            above - 1
        } else {
            above
        };
        let low = indices[j - 1] + 1;
        let high = n - (m - j);
        indices.push(nearest.clamp(low, high));
    }
    let positions = place_on_sides(&t, &clockwise, &indices);
    Ok(BoundaryMap {
        vertices,
        positions,
    })
}

/// The source's own boundary positions `x + i y`, for a mesh in the plane z = 0 (to
/// `1e-12` times its bounding-box diagonal).
pub fn keep(mesh: &Mesh) -> Result<BoundaryMap, BoundaryError> {
    let tol = 1e-12 * mesh.bounding_box().diagonal();
    if let Some(vertex) = mesh.vertices().find(|&v| mesh.position(v).z.abs() > tol) {
        return Err(BoundaryError::NotPlanar {
            vertex,
            z: mesh.position(vertex).z,
        });
    }
    let vertices = rotated_loop(mesh, None)?;
    let positions = vertices
        .iter()
        .map(|&v| {
            let p = mesh.position(v);
            Complex64::new(p.x, p.y)
        })
        .collect();
    Ok(BoundaryMap {
        vertices,
        positions,
    })
}

/// The boundary values of a given planar map (`values[v]` the image of vertex `v`; only
/// the boundary vertices are read).
pub fn given(mesh: &Mesh, values: &[Complex64]) -> Result<BoundaryMap, BoundaryError> {
    if values.len() != mesh.vertex_count() {
        return Err(BoundaryError::Length {
            expected: mesh.vertex_count(),
            got: values.len(),
        });
    }
    let vertices = rotated_loop(mesh, None)?;
    let positions = vertices
        .iter()
        .map(|&v| {
            let z = values[v.idx()];
            if z.is_finite() {
                Ok(z)
            } else {
                Err(BoundaryError::NonFiniteValue { vertex: v })
            }
        })
        .collect::<Result<_, _>>()?;
    Ok(BoundaryMap {
        vertices,
        positions,
    })
}

/// The vertices of the longest boundary loop (by length; the first of equal ones).
fn longest_loop(mesh: &Mesh) -> Result<Vec<VertexId>, BoundaryError> {
    mesh.boundary_loop_list()
        .into_iter()
        .reduce(|best, l| if l.length > best.length { l } else { best })
        .map(|l| l.vertices)
        .ok_or(BoundaryError::NoBoundary)
}

/// The longest loop in loop order, rotated to begin at `start` (if given).
fn rotated_loop(mesh: &Mesh, start: Option<VertexId>) -> Result<Vec<VertexId>, BoundaryError> {
    let mut vertices = longest_loop(mesh)?;
    if let Some(start) = start {
        if start.idx() >= mesh.vertex_count() {
            return Err(BoundaryError::VertexOutOfRange {
                vertex: start,
                vertex_count: mesh.vertex_count(),
            });
        }
        let k = vertices
            .iter()
            .position(|&v| v == start)
            .ok_or(BoundaryError::NotOnBoundary { vertex: start })?;
        vertices.rotate_left(k);
    }
    Ok(vertices)
}

/// The boundary vertex of `vertices` with the smallest sum of incident corner angles
/// (the first of equal ones): the sharpest corner of the boundary.
fn sharpest_vertex(mesh: &Mesh, vertices: &[VertexId]) -> VertexId {
    let angle_sum = |v: VertexId| -> f64 {
        mesh.outgoing_halfedges(v)
            .filter(|&h| mesh.face(h).is_some())
            .map(|h| mesh.corner_angle(h))
            .sum()
    };
    let mut best = (vertices[0], angle_sum(vertices[0]));
    for &v in &vertices[1..] {
        let a = angle_sum(v);
        if a < best.1 {
            best = (v, a);
        }
    }
    best.0
}

/// The arc-length parameters `t_k = s_k / L` of a closed loop (module docs). A loop of
/// zero length (coincident vertices) falls back to `t_k = k / n`, which keeps the
/// parameters increasing.
fn arc_parameters(mesh: &Mesh, vertices: &[VertexId]) -> Vec<f64> {
    let n = vertices.len();
    let mut s = Vec::with_capacity(n);
    let mut total = 0.0;
    for k in 0..n {
        s.push(total);
        total += (mesh.position(vertices[(k + 1) % n]) - mesh.position(vertices[k])).norm();
    }
    if total > 0.0 && total.is_finite() {
        s.iter().map(|sk| sk / total).collect()
    } else {
        (0..n).map(|k| k as f64 / n as f64).collect()
    }
}

/// Counter-clockwise corners `c_0, c_1, .., c_{m-1}` in clockwise order
/// `c_0, c_{m-1}, .., c_1`.
fn clockwise_corners(corners: &[Complex64]) -> Vec<Complex64> {
    std::iter::once(corners[0])
        .chain(corners[1..].iter().rev().copied())
        .collect()
}

/// Positions of the loop vertices with parameters `t` when clockwise corner `j` sits at
/// loop index `indices[j]` (`indices[0] = 0`, increasing): each vertex between two corner
/// vertices goes along the side between the two corners in proportion to its arc
/// length from the first. A side whose ends have equal parameters (zero length) is
/// spread by vertex count instead.
fn place_on_sides(t: &[f64], clockwise: &[Complex64], indices: &[usize]) -> Vec<Complex64> {
    let (n, m) = (t.len(), clockwise.len());
    let mut positions = vec![Complex64::new(0.0, 0.0); n];
    for j in 0..m {
        let (a, b) = (clockwise[j], clockwise[(j + 1) % m]);
        let first = indices[j];
        let (last, t_last) = if j + 1 < m {
            (indices[j + 1], t[indices[j + 1]])
        } else {
            (n, 1.0)
        };
        let span = t_last - t[first];
        for (k, position) in positions.iter_mut().enumerate().take(last).skip(first) {
            let s = if span > 0.0 {
                (t[k] - t[first]) / span
            } else {
                (k - first) as f64 / (last - first) as f64
            };
            *position = a + (b - a) * s;
        }
    }
    positions
}

/// `a.re b.im - a.im b.re`.
fn cross(a: Complex64, b: Complex64) -> f64 {
    a.re * b.im - a.im * b.re
}

/// Checks that `corners` form a strictly convex polygon listed counter-clockwise: every
/// corner turns left (cross product of the incoming and outgoing sides above
/// `1e-12` times the squared longest side) and the turning angles add up to one turn.
fn check_convex(corners: &[Complex64]) -> Result<(), BoundaryError> {
    let m = corners.len();
    if m < 3 {
        return Err(BoundaryError::TooFewCorners { corners: m });
    }
    if let Some(corner) = corners.iter().position(|c| !c.is_finite()) {
        return Err(BoundaryError::NonFiniteCorner { corner });
    }
    let side = |k: usize| corners[(k + 1) % m] - corners[k];
    let scale = (0..m).map(|k| side(k).norm_sqr()).fold(0.0, f64::max);
    let turn = |k: usize| cross(side((k + m - 1) % m), side(k));
    let area: f64 = (0..m)
        .map(|k| cross(corners[k], corners[(k + 1) % m]))
        .sum();
    if area < 0.0
        && let Some(corner) = (0..m).find(|&k| turn(k) < 0.0)
    {
        return Err(BoundaryError::NotCounterClockwise { corner });
    }
    let mut turned = 0.0;
    for k in 0..m {
        if turn(k) <= 1e-12 * scale {
            return Err(BoundaryError::NotConvex { corner: k });
        }
        let (a, b) = (side((k + m - 1) % m), side(k));
        turned += cross(a, b).atan2(a.re * b.re + a.im * b.im);
        // A star polygon turns left at every corner but winds around more than once.
        if turned > TAU * (1.0 + 1e-9) {
            return Err(BoundaryError::NotConvex { corner: k });
        }
    }
    Ok(())
}

/// Faces whose vertices all lie on the boundary loop between two consecutive corners of
/// `map` taken as straight sides: they collapse in the image. Corners are the vertices
/// where the image turns (a circle turns at every vertex, so it has none).
pub fn collapsed_faces(mesh: &Mesh, map: &BoundaryMap) -> Vec<FaceId> {
    let n = map.vertices.len();
    let mut slot = vec![usize::MAX; mesh.vertex_count()];
    for (k, v) in map.vertices.iter().enumerate() {
        slot[v.idx()] = k;
    }
    // A vertex is straight when it lies on the segment between its neighbours' images.
    let straight = |k: usize| {
        let (a, b, c) = (
            map.positions[(k + n - 1) % n],
            map.positions[k],
            map.positions[(k + 1) % n],
        );
        let scale = (c - a).norm_sqr();
        cross(b - a, c - a).abs() <= 1e-12 * scale
    };
    mesh.faces()
        .filter(|&f| {
            let (vertices, len) = mesh.face_vertex_array(f);
            let mut slots = [0; 4];
            for (s, v) in slots.iter_mut().zip(&vertices[..len]) {
                *s = slot[v.idx()];
            }
            let slots = &slots[..len];
            if slots.contains(&usize::MAX) {
                return false;
            }
            // Starting at one of its vertices, the face spans a stretch of the loop; it
            // collapses if every loop vertex strictly inside that stretch is straight.
            slots.iter().any(|&first| {
                let span = slots
                    .iter()
                    .map(|&s| (s + n - first) % n)
                    .fold(0, usize::max);
                (1..span).all(|d| straight((first + d) % n))
            })
        })
        .collect()
}

/// Two boundary vertices far apart: the boundary vertex farthest from the first vertex
/// of the longest loop, and the boundary vertex farthest from that one (the two-sweep
/// approximation of the boundary's diameter): the default pins of lscm and lsqc. A mesh
/// without boundary gives vertex 0 twice.
pub fn far_boundary_pair(mesh: &Mesh) -> (VertexId, VertexId) {
    let vertices = mesh
        .boundary_loop_list()
        .into_iter()
        .reduce(|best, l| if l.length > best.length { l } else { best })
        .map(|l| l.vertices)
        .unwrap_or_default();
    let farthest = |from: VertexId| {
        let p = mesh.position(from);
        vertices
            .iter()
            .copied()
            .max_by(|&u, &v| {
                let du = (mesh.position(u) - p).norm_squared();
                let dv = (mesh.position(v) - p).norm_squared();
                du.total_cmp(&dv)
            })
            .unwrap_or(from)
    };
    let first = vertices.first().copied().unwrap_or(VertexId(0));
    let a = farthest(first);
    (a, farthest(a))
}
