//! P1 and Q1 elements on surfaces in R^3: quadrature points, tangent frames, shape
//! functions and their gradients.
//!
//! # Reference elements
//!
//! A triangle `(p0, p1, p2)` is the image of the reference triangle `u, v >= 0,
//! u + v <= 1` under `X = N0 p0 + N1 p1 + N2 p2` with `N0 = 1 - u - v`, `N1 = u`,
//! `N2 = v` (P1), integrated with one point at the centroid (exact for the constant
//! gradients of P1). A quad `(p0, p1, p2, p3)` is the image of the unit square under the
//! bilinear map with `N0 = (1-u)(1-v)`, `N1 = u(1-v)`, `N2 = uv`, `N3 = (1-u)v` (Q1),
//! integrated with the 2x2 Gauss rule (exact for polynomials of degree 3 in each of
//! `u`, `v`). Non-planar quads are handled the Q1 way: the tangent vectors
//! `X_1 = dX/du`, `X_2 = dX/dv` vary over the element and each quadrature point has its
//! own tangent plane.
//!
//! # Frames
//!
//! Derivatives are taken in an orthonormal tangent frame `(e1, e2)` with normal
//! `n = e1 x e2`; a point of the tangent plane has the complex coordinate `x + i y` along
//! `(e1, e2)`.
//!
//! - [`Frame::Face`]: `n = X_1 x X_2 / |X_1 x X_2|` at the quadrature point and `e1` along
//!   the face's first edge `p1 - p0` projected onto the tangent plane, so that a triangle
//!   uses exactly its face frame ([`beltrami_mesh::FaceFrame`]) and the four points of a
//!   quad share the direction of its first edge.
//! - [`Frame::Global`]: for meshes in the plane z = 0, `e1 = x`, `e2 = y`, `n = z`: the
//!   global coordinate `z = x + i y`. A face listed clockwise in the plane then has a
//!   negative Jacobian determinant; its weight is the absolute value and its gradients
//!   stay correct.
//!
//! With the tangent Jacobian `J = [X_1 . e1, X_2 . e1; X_1 . e2, X_2 . e2]`, the gradient
//! of a shape function in the frame is `J^-T (dN/du, dN/dv)` and the quadrature weight is
//! the reference weight times `|det J|`.

use beltrami_mesh::{FaceId, Mesh, Point3, Vector2, Vector3, VertexId};
use std::ops::Range;

use crate::FemError;

/// Which tangent frame derivatives and Beltrami coefficients are expressed in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Frame {
    /// The plane's own coordinate `z = x + i y` (meshes in the plane z = 0 only).
    Global,
    /// The frame of each face: origin-free, real axis along the face's first edge.
    Face,
}

impl Frame {
    /// The name used in file headers and reports: `global` or `face`.
    pub fn name(self) -> &'static str {
        match self {
            Frame::Global => "global",
            Frame::Face => "face",
        }
    }
}

/// An orthonormal tangent frame at a quadrature point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TangentFrame {
    /// Real axis.
    pub e1: Vector3<f64>,
    /// Imaginary axis, `n x e1`.
    pub e2: Vector3<f64>,
    /// Unit normal.
    pub normal: Vector3<f64>,
}

impl TangentFrame {
    /// Coordinates of `v` along `(e1, e2)` (its tangential part).
    #[inline]
    pub fn local(&self, v: &Vector3<f64>) -> Vector2<f64> {
        Vector2::new(v.dot(&self.e1), v.dot(&self.e2))
    }
}

/// One quadrature point of one element.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QuadraturePoint {
    /// The face it belongs to.
    pub face: FaceId,
    /// Reference weight times `|det J|`: the weights of a face sum to its area (exact for
    /// triangles and planar convex quads).
    pub weight: f64,
    /// The tangent frame derivatives are expressed in.
    pub frame: TangentFrame,
    /// Shape function values at the point, one per face vertex (unused entries 0).
    pub shape: [f64; 4],
    /// Shape function gradients in the frame, one per face vertex (unused entries 0).
    pub grad: [Vector2<f64>; 4],
    /// Signed `det J`: negative when the element is clockwise in the frame.
    pub det: f64,
    /// The metric of the reference coordinates, `g_ij = X_i . X_j` with `X_1 = dX/du`,
    /// `X_2 = dX/dv` (the tangent vectors in R^3, before any projection to the frame);
    /// `sqrt(det g)` is the area element of the surface patch.
    pub metric: [[f64; 2]; 2],
}

/// Gauss points of the 2-point rule on [0, 1]: 1/2 -+ 1/(2 sqrt 3).
const GAUSS_2: [f64; 2] = [0.211_324_865_405_187_1, 0.788_675_134_594_812_9];

/// Shape functions and their `(d/du, d/dv)` derivatives at reference point `(u, v)`.
fn reference_shape(n: usize, u: f64, v: f64) -> ([f64; 4], [[f64; 2]; 4]) {
    if n == 3 {
        (
            [1.0 - u - v, u, v, 0.0],
            [[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0], [0.0, 0.0]],
        )
    } else {
        (
            [(1.0 - u) * (1.0 - v), u * (1.0 - v), u * v, (1.0 - u) * v],
            [
                [-(1.0 - v), -(1.0 - u)],
                [1.0 - v, -u],
                [v, u],
                [-v, 1.0 - u],
            ],
        )
    }
}

/// Reference points `(u, v)` and weights of the element rule.
fn reference_rule(n: usize) -> &'static [(f64, f64, f64)] {
    const TRI: [(f64, f64, f64); 1] = [(1.0 / 3.0, 1.0 / 3.0, 0.5)];
    const QUAD: [(f64, f64, f64); 4] = [
        (GAUSS_2[0], GAUSS_2[0], 0.25),
        (GAUSS_2[1], GAUSS_2[0], 0.25),
        (GAUSS_2[1], GAUSS_2[1], 0.25),
        (GAUSS_2[0], GAUSS_2[1], 0.25),
    ];
    if n == 3 { &TRI } else { &QUAD }
}

/// The reference polygon of face `f` with corners `p` (`n` of them) and corner angles
/// `beta`, placed in the face's plane ([`Elements::with_reference_angles`]).
fn reference_polygon(
    f: FaceId,
    p: &[Point3<f64>; 4],
    n: usize,
    beta: &[f64],
) -> Result<[Point3<f64>; 4], FemError> {
    use std::f64::consts::PI;
    let sum: f64 = beta.iter().sum();
    let (what, full) = if n == 3 {
        ("triangle", PI)
    } else {
        ("convex quad", 2.0 * PI)
    };
    let invalid = FemError::ReferenceAngles { face: f, what, sum };
    if (sum - full).abs() > 1e-6 || beta.iter().any(|b| !(*b > 0.0 && *b < PI)) {
        return Err(invalid);
    }
    let (x1, x2) = if n == 3 {
        (p[1] - p[0], p[2] - p[0])
    } else {
        (
            (p[1] - p[0] + (p[2] - p[3])) * 0.5,
            (p[3] - p[0] + (p[2] - p[1])) * 0.5,
        )
    };
    let normal = x1.cross(&x2).normalize();
    let first = p[1] - p[0];
    let e1 = (first - first.dot(&normal) * normal).normalize();
    let e2 = normal.cross(&e1);
    // The polygon in the plane, first side along the x axis, counter-clockwise.
    let mut local = [Vector2::zeros(); 4];
    if n == 3 {
        let (s1, s2) = (beta[1].sin(), beta[2].sin());
        local[1] = Vector2::new(s2, 0.0);
        local[2] = Vector2::new(beta[0].cos(), beta[0].sin()) * s1;
    } else {
        let directions: [Vector2<f64>; 4] = std::array::from_fn(|k| {
            let turn: f64 = beta[1..=k].iter().map(|b| PI - b).sum();
            Vector2::new(turn.cos(), turn.sin())
        });
        let t: [f64; 4] = std::array::from_fn(|k| (p[(k + 1) % 4] - p[k]).norm());
        let closure: Vector2<f64> = (0..4).map(|k| directions[k] * t[k]).sum();
        let mut gram = nalgebra::Matrix2::zeros();
        for d in &directions {
            gram += d * d.transpose();
        }
        let lambda = gram.try_inverse().ok_or(invalid.clone())? * closure;
        let lengths: [f64; 4] = std::array::from_fn(|k| t[k] - directions[k].dot(&lambda));
        let mean = lengths.iter().sum::<f64>() / 4.0;
        if lengths.iter().any(|l| l.is_nan() || *l <= 0.01 * mean) {
            return Err(invalid);
        }
        for k in 1..4 {
            local[k] = local[k - 1] + directions[k - 1] * lengths[k - 1];
        }
    }
    let shoelace = |q: &[Vector2<f64>]| {
        (0..q.len())
            .map(|k| q[k].perp(&q[(k + 1) % q.len()]))
            .sum::<f64>()
            * 0.5
    };
    let area = if n == 3 {
        0.5 * (p[1] - p[0]).cross(&(p[2] - p[0])).norm()
    } else {
        let centre = (p[0].coords + p[1].coords + p[2].coords + p[3].coords) * 0.25;
        (0..4)
            .map(|k| {
                0.5 * (p[k].coords - centre)
                    .cross(&(p[(k + 1) % 4].coords - centre))
                    .dot(&normal)
            })
            .sum::<f64>()
    };
    let scale = (area.abs() / shoelace(&local[..n])).sqrt();
    if !scale.is_finite() {
        return Err(FemError::DegenerateElement { face: f, det: area });
    }
    Ok(std::array::from_fn(|k| {
        let q = local[k.min(n - 1)] * scale;
        p[0] + e1 * q.x + e2 * q.y
    }))
}

/// The quadrature points of face `f` with corners `p` (`n` of them; unused entries
/// repeat the last) in `frame`, given one by one to `emit` (reference_rule's order).
/// Fails with [`FemError::DegenerateElement`] where `det J` vanishes relative to the
/// squared size of the face.
fn face_points(
    f: FaceId,
    p: &[Point3<f64>; 4],
    n: usize,
    frame: Frame,
    mut emit: impl FnMut(QuadraturePoint),
) -> Result<(), FemError> {
    let first_edge = p[1] - p[0];
    let size2 = first_edge.norm_squared().max((p[2] - p[0]).norm_squared());
    for &(u, w, ref_weight) in reference_rule(n) {
        let (shape, dref) = reference_shape(n, u, w);
        let (mut x1, mut x2) = (Vector3::zeros(), Vector3::zeros());
        for k in 0..n {
            x1 += dref[k][0] * p[k].coords;
            x2 += dref[k][1] * p[k].coords;
        }
        let tangent = match frame {
            Frame::Global => TangentFrame {
                e1: Vector3::x(),
                e2: Vector3::y(),
                normal: Vector3::z(),
            },
            Frame::Face => {
                let normal = x1.cross(&x2).normalize();
                let e1 = (first_edge - first_edge.dot(&normal) * normal).normalize();
                TangentFrame {
                    e1,
                    e2: normal.cross(&e1),
                    normal,
                }
            }
        };
        let (a, b) = (tangent.local(&x1), tangent.local(&x2));
        let det = a.x * b.y - b.x * a.y;
        if is_degenerate(det, size2) {
            return Err(FemError::DegenerateElement { face: f, det });
        }
        let mut grad = [Vector2::zeros(); 4];
        for k in 0..n {
            let (du, dv) = (dref[k][0], dref[k][1]);
            grad[k] = Vector2::new(b.y * du - a.y * dv, -b.x * du + a.x * dv) / det;
        }
        let g12 = x1.dot(&x2);
        emit(QuadraturePoint {
            face: f,
            weight: ref_weight * det.abs(),
            frame: tangent,
            shape,
            grad,
            det,
            metric: [[x1.norm_squared(), g12], [g12, x2.norm_squared()]],
        });
    }
    Ok(())
}

/// Visits the quadrature points of the faces `faces` (indices) of `mesh` in `frame`, face
/// by face, without keeping them: `visit(f, vertices, points)` with the face's vertices
/// and its points (1 for a triangle, 4 for a quad), as [`Elements::new`] computes them.
/// For one pass over a large mesh (a distortion measure), where the stored points would
/// cost a few hundred bytes per face; ranges of faces can be visited on several threads.
///
/// Errors as [`Elements::new`] (the first degenerate face of the range);
/// [`FemError::Length`] for a range beyond the faces.
pub fn for_each_face_points(
    mesh: &Mesh,
    frame: Frame,
    faces: Range<usize>,
    visit: impl FnMut(FaceId, &[VertexId], &[QuadraturePoint]),
) -> Result<(), FemError> {
    if faces.end > mesh.face_count() {
        return Err(FemError::Length {
            what: "the range of faces",
            expected: mesh.face_count(),
            got: faces.end,
        });
    }
    if frame == Frame::Global {
        check_planar(mesh)?;
    }
    visit_face_points(mesh, frame, faces, visit)
}

/// [`for_each_face_points`] with the range and, for [`Frame::Global`], the planarity
/// already checked by the caller (once for all its ranges).
pub(crate) fn visit_face_points(
    mesh: &Mesh,
    frame: Frame,
    faces: Range<usize>,
    mut visit: impl FnMut(FaceId, &[VertexId], &[QuadraturePoint]),
) -> Result<(), FemError> {
    let mut points = Vec::with_capacity(4);
    for f in faces.map(FaceId::from_usize) {
        let (v, n) = mesh.face_vertex_array(f);
        let p = std::array::from_fn(|k| mesh.position(v[k.min(n - 1)]));
        points.clear();
        face_points(f, &p, n, frame, |q| points.push(q))?;
        visit(f, &v[..n], &points);
    }
    Ok(())
}

/// Whether a Jacobian determinant `det` (twice the area of a triangle) vanishes relative
/// to `size2`, the squared size of its face (the larger of its first two sides): the
/// test of [`Elements::new`] and of the faces of the conformal energy.
pub(crate) fn is_degenerate(det: f64, size2: f64) -> bool {
    !det.is_finite() || det.abs() <= 1e-14 * size2
}

/// Checks that every vertex has z = 0 up to `1e-12` times the bounding-box diagonal.
pub fn check_planar(mesh: &Mesh) -> Result<(), FemError> {
    let tol = 1e-12 * mesh.bounding_box().diagonal();
    match mesh.vertices().find(|&v| mesh.position(v).z.abs() > tol) {
        Some(vertex) => Err(FemError::NotPlanar {
            vertex,
            z: mesh.position(vertex).z,
        }),
        None => Ok(()),
    }
}

/// True if the mesh lies in the plane z = 0 (the condition of [`Frame::Global`]).
pub fn is_planar(mesh: &Mesh) -> bool {
    check_planar(mesh).is_ok()
}

/// The quadrature points of every face of a mesh, in face order.
#[derive(Debug, Clone)]
pub struct Elements {
    points: Vec<QuadraturePoint>,
    /// Points of face `f` are `offsets[f]..offsets[f + 1]`.
    offsets: Vec<u32>,
    /// Vertices of each face (unused entries repeat the first).
    nodes: Vec<[VertexId; 4]>,
    degree: Vec<u8>,
    /// Sides `p_(k+1) - p_k` of each face in the frame of its first point.
    sides: Vec<[Vector2<f64>; 4]>,
    frame: Frame,
}

impl Elements {
    /// Computes quadrature points, frames, shape values and gradients for every face.
    ///
    /// Fails with [`FemError::NotPlanar`] for [`Frame::Global`] on a mesh off the plane
    /// z = 0, and with [`FemError::DegenerateElement`] where `det J` vanishes (relative to
    /// the squared element size).
    pub fn new(mesh: &Mesh, frame: Frame) -> Result<Self, FemError> {
        if frame == Frame::Global {
            check_planar(mesh)?;
        }
        Self::build(mesh, frame, |_, p, _| Ok(*p))
    }

    /// Elements whose shapes are reference polygons with given corner angles, placed in
    /// the planes of the faces (Gruber-Aulisa 2022, section 6.2): derivatives and
    /// weights measure a map from the reference metric `g_ref`, normals and frames are
    /// the surface's ([`Frame::Face`]: `e1` along the first edge). `angles` holds the
    /// corner angle of every face corner at the halfedge leaving its vertex inside the
    /// face (the layout of `Constraint::ReferenceAngles`).
    ///
    /// A triangle with angles `b0, b1, b2` has the sides `sin b2 : sin b0 : sin b1`
    /// (law of sines) and the face's area. A quad's sides turn by `pi - b_k`; their
    /// lengths are the face's own edge lengths `t` moved least in the Euclidean norm to
    /// close the polygon, `l = t - D^T (D D^T)^-1 D t` with `D` the 2 x 4 matrix of unit
    /// side directions, scaled to the face's area; its plane is the bilinear tangent
    /// plane at the centre.
    ///
    /// Errors: [`FemError::Length`] when `angles` has not one entry per halfedge,
    /// [`FemError::ReferenceAngles`] when a face's angles do not sum to `pi` (`2 pi`)
    /// within `1e-6` or a quad side comes out shorter than a hundredth of the mean.
    pub fn with_reference_angles(mesh: &Mesh, angles: &[f64]) -> Result<Self, FemError> {
        if angles.len() != mesh.halfedge_count() {
            return Err(FemError::Length {
                what: "reference angles",
                expected: mesh.halfedge_count(),
                got: angles.len(),
            });
        }
        Self::build(mesh, Frame::Face, |f, p, n| {
            let beta: Vec<f64> = mesh.face_halfedges(f).map(|h| angles[h.idx()]).collect();
            reference_polygon(f, p, n, &beta)
        })
    }

    /// The elements of `mesh` with the corners of face `f` at `corners(f, positions,
    /// degree)` (unused entries repeat the last corner).
    fn build(
        mesh: &Mesh,
        frame: Frame,
        corners: impl Fn(FaceId, &[Point3<f64>; 4], usize) -> Result<[Point3<f64>; 4], FemError>,
    ) -> Result<Self, FemError> {
        // One point per triangle, four per quad (`reference_rule`).
        let mut points = Vec::with_capacity(mesh.triangle_count() + 4 * mesh.quad_count());
        let mut offsets = Vec::with_capacity(mesh.face_count() + 1);
        let mut nodes = Vec::with_capacity(mesh.face_count());
        let mut degree = Vec::with_capacity(mesh.face_count());
        let mut sides = Vec::with_capacity(mesh.face_count());
        offsets.push(0);
        for f in mesh.faces() {
            let (v, n) = mesh.face_vertex_array(f);
            let p = corners(
                f,
                &std::array::from_fn(|k| mesh.position(v[k.min(n - 1)])),
                n,
            )?;
            face_points(f, &p, n, frame, |q| points.push(q))?;
            let first = points[points.len() - reference_rule(n).len()].frame;
            sides.push(std::array::from_fn(|k| {
                if k < n {
                    first.local(&(p[(k + 1) % n] - p[k]))
                } else {
                    Vector2::zeros()
                }
            }));
            offsets.push(points.len() as u32);
            nodes.push(std::array::from_fn(|k| v[if k < n { k } else { 0 }]));
            degree.push(n as u8);
        }
        Ok(Self {
            points,
            offsets,
            nodes,
            degree,
            sides,
            frame,
        })
    }

    /// The frame the derivatives are expressed in.
    pub fn frame(&self) -> Frame {
        self.frame
    }

    /// All quadrature points, face by face.
    pub fn points(&self) -> &[QuadraturePoint] {
        &self.points
    }

    /// Number of quadrature points.
    pub fn point_count(&self) -> usize {
        self.points.len()
    }

    /// Number of faces.
    pub fn face_count(&self) -> usize {
        self.nodes.len()
    }

    /// Index range of the quadrature points of face `f` in [`Elements::points`].
    pub fn face_points_range(&self, f: FaceId) -> std::ops::Range<usize> {
        self.offsets[f.idx()] as usize..self.offsets[f.idx() + 1] as usize
    }

    /// Per face, its area as the quadrature sees it: the sum of its points' weights
    /// (exact for triangles; the bilinear area for quads).
    pub fn face_areas(&self) -> Vec<f64> {
        (0..self.face_count())
            .map(|f| {
                self.face_points(FaceId(f as u32))
                    .iter()
                    .map(|q| q.weight)
                    .sum()
            })
            .collect()
    }

    /// The quadrature points of face `f` (1 for a triangle, 4 for a quad).
    pub fn face_points(&self, f: FaceId) -> &[QuadraturePoint] {
        &self.points[self.face_points_range(f)]
    }

    /// The sides of face `f` in the frame of its first quadrature point: side `k` runs
    /// from node `k` to node `k + 1` (the face's halfedge `k`); for reference elements,
    /// the reference polygon's sides.
    pub fn sides(&self, f: FaceId) -> &[Vector2<f64>] {
        &self.sides[f.idx()][..self.degree[f.idx()] as usize]
    }

    /// The vertices of face `f` (its nodes) in order.
    pub fn nodes(&self, f: FaceId) -> &[VertexId] {
        &self.nodes[f.idx()][..self.degree[f.idx()] as usize]
    }
}
