//! Beltrami coefficients of maps, per quadrature point and per face.
//!
//! At a quadrature point with tangent frame `(e1, e2)` the map has derivatives
//! `f_x = sum_k f_k d_x N_k`, `f_y = sum_k f_k d_y N_k` along the frame axes, and
//!
//! ```text
//! f_z = (f_x - i f_y) / 2,   f_zbar = (f_x + i f_y) / 2,   mu = f_zbar / f_z.
//! ```
//!
//! The Jacobian determinant of the map is `|f_z|^2 - |f_zbar|^2`: a point where it is
//! negative (`|mu| > 1`) is flipped.
//!
//! - Plane to plane ([`crate::Frame::Global`]) and surface to plane
//!   ([`crate::Frame::Face`]): the image values are complex numbers.
//! - Surface to surface in R^3 ([`surface_map`]), intrinsically (Wong-Zhao 2014,
//!   eq. 4.7-4.9): the image's tangent vectors `f_x`, `f_y` in R^3 are laid isometrically in
//!   the plane of the image's own tangent frame, oriented by a reference normal stated by
//!   a [`ReferenceNormal`]; `mu` is then the planar coefficient in the source frame. A
//!   different image frame rotates `f_z` and `f_zbar` alike and leaves `mu` unchanged.
//!
//! # Orientation of an image in R^3
//!
//! A map's image cannot be the reference for its own orientation (a folded region turns
//! its own normals over with it), so the normal that decides whether a point is flipped
//! is always stated from outside, by [`ReferenceNormal`]: `+z` for an image in the plane
//! z = 0, the radial direction for an image on a sphere about the origin, the source's
//! normal for an image close to the source, or one normal per face (a target surface's
//! normals at the image, `beltrami_spatial::SurfaceIndex::face_reference_normals`).
//!
//! [`image_derivatives`] is the one kernel every measure of a map into R^3 goes through.
//! With `m = f_x x f_y` (the image's vector area element) and `N` the reference normal:
//!
//! ```text
//! n   = m / |m|      if m . N > 0        (oriented as the reference: not flipped)
//! n   = -m / |m|     if m . N <= 0       (turned against it, or orthogonal: flipped)
//! e_1 = f_x / |f_x|,   e_2 = n x e_1     (the image frame, Wong-Zhao eq. 4.7)
//! F_x = |f_x|,         F_y = f_y . e_1 + i f_y . e_2     (eq. 4.8)
//! f_z = (F_x - i F_y) / 2,   f_zbar = (F_x + i F_y) / 2,   mu = f_zbar / f_z   (eq. 4.9)
//! ```
//!
//! The Jacobian `|f_z|^2 - |f_zbar|^2 = |f_x| (f_y . e_2) = m . n` is then `|m| > 0` on
//! the reference's side and `-|m| < 0` against it: a point is flipped exactly when
//! `m . N <= 0` (`|mu| > 1`). Where the image collapses (`m = 0`: a segment or a point),
//! `f_x` and `f_y` are laid on the real axis, `|mu| = 1` and the Jacobian is 0 (flipped).
//! For an image in the plane z = 0 with [`ReferenceNormal::Plane`] this is the planar
//! coefficient of [`planar_map`] with `f = x + i y`.

use beltrami_mesh::{FaceId, Point3, Vector3, VertexId};
use num_complex::Complex64;

use crate::{Elements, FemError, QuadraturePoint};

/// Largest `|mu|` reported where `f_z` vanishes but `f_zbar` does not (an
/// anti-conformal point), so that statistics stay finite.
pub const MU_CAP: f64 = 1e12;

/// The derivatives of a map at one quadrature point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointDerivatives {
    /// `f_z`.
    pub fz: Complex64,
    /// `f_zbar`.
    pub fzbar: Complex64,
}

impl PointDerivatives {
    /// From the derivatives `f_x`, `f_y` along the frame axes.
    #[inline]
    pub fn from_xy(fx: Complex64, fy: Complex64) -> Self {
        let i = Complex64::i();
        Self {
            fz: 0.5 * (fx - i * fy),
            fzbar: 0.5 * (fx + i * fy),
        }
    }

    /// `mu = f_zbar / f_z`. Where `f_z = 0`: if `f_zbar = 0` too (a collapsed point) `mu`
    /// is undefined and reported as `1`, on the flip threshold; otherwise it is
    /// `MU_CAP f_zbar / |f_zbar|`.
    #[inline]
    pub fn mu(&self) -> Complex64 {
        let n = self.fz.norm_sqr();
        if n > 0.0 {
            self.fzbar * self.fz.conj() / n
        } else if self.fzbar.norm_sqr() > 0.0 {
            self.fzbar / self.fzbar.norm() * MU_CAP
        } else {
            Complex64::new(1.0, 0.0)
        }
    }

    /// Jacobian determinant `|f_z|^2 - |f_zbar|^2` (negative: flipped).
    #[inline]
    pub fn jacobian(&self) -> f64 {
        self.fz.norm_sqr() - self.fzbar.norm_sqr()
    }
}

/// [`FemError::Length`] unless `got == expected`.
pub(crate) fn check_len(what: &'static str, expected: usize, got: usize) -> Result<(), FemError> {
    if expected == got {
        Ok(())
    } else {
        Err(FemError::Length {
            what,
            expected,
            got,
        })
    }
}

/// Derivatives of a map into the plane (complex vertex values, indexed by vertex id) at
/// every quadrature point of `elements`.
pub fn planar_map(
    elements: &Elements,
    vertex_count: usize,
    map: &[Complex64],
) -> Result<Vec<PointDerivatives>, FemError> {
    check_planar_map(vertex_count, map)?;
    Ok(elements
        .points()
        .iter()
        .map(|q| planar_derivatives(q, elements.nodes(q.face), map))
        .collect())
}

/// Checks a map into the plane: one finite value per vertex ([`FemError::Length`],
/// [`FemError::NonFinite`] naming the first bad vertex).
pub(crate) fn check_planar_map(vertex_count: usize, map: &[Complex64]) -> Result<(), FemError> {
    check_len("map", vertex_count, map.len())?;
    match map
        .iter()
        .position(|z| !(z.re.is_finite() && z.im.is_finite()))
    {
        Some(index) => Err(FemError::NonFinite { what: "map", index }),
        None => Ok(()),
    }
}

/// The derivatives at quadrature point `q` of the planar map `map` on the face with
/// vertices `nodes`: `f_x = sum_k map[v_k] d_x N_k`, likewise `f_y`.
pub(crate) fn planar_derivatives(
    q: &QuadraturePoint,
    nodes: &[VertexId],
    map: &[Complex64],
) -> PointDerivatives {
    let (mut fx, mut fy) = (Complex64::default(), Complex64::default());
    for (k, v) in nodes.iter().enumerate() {
        fx += map[v.idx()] * q.grad[k].x;
        fy += map[v.idx()] * q.grad[k].y;
    }
    PointDerivatives::from_xy(fx, fy)
}

/// The derivatives of a map into R^3 along the frame axes at one quadrature point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpatialDerivatives {
    /// `df(e1) = sum_k f_k d_x N_k`.
    pub dx: Vector3<f64>,
    /// `df(e2) = sum_k f_k d_y N_k`.
    pub dy: Vector3<f64>,
}

/// The derivatives of a map `image` into R^3 (one point per vertex) at every quadrature
/// point of `elements`.
pub fn spatial_derivatives(
    elements: &Elements,
    vertex_count: usize,
    image: &[Point3<f64>],
) -> Result<Vec<SpatialDerivatives>, FemError> {
    check_len("image", vertex_count, image.len())?;
    if let Some(index) = image.iter().position(|p| !p.iter().all(|x| x.is_finite())) {
        return Err(FemError::NonFinite {
            what: "image",
            index,
        });
    }
    Ok(elements
        .points()
        .iter()
        .map(|q| {
            let (mut dx, mut dy) = (Vector3::zeros(), Vector3::zeros());
            for (k, v) in elements.nodes(q.face).iter().enumerate() {
                dx += image[v.idx()].coords * q.grad[k].x;
                dy += image[v.idx()].coords * q.grad[k].y;
            }
            SpatialDerivatives { dx, dy }
        })
        .collect())
}

/// Where the normal that decides the orientation of a map's image in R^3 comes from
/// (module docs, "Orientation of an image in R^3"). The image's own normals are never
/// the reference: a fold turns them over with it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ReferenceNormal<'a> {
    /// The image lies in the plane z = 0: the reference is `+z`, the orientation of the
    /// planar frame (a map given as positions `(x, y, 0)` is measured as the planar map
    /// `x + i y`).
    Plane,
    /// The image lies on a sphere about the origin: the reference at a quadrature point
    /// is the direction of its image point `sum_k N_k f_k` (outward), as the sphere
    /// initialization uses.
    Radial,
    /// The source's own normal at the quadrature point (the normal of its tangent
    /// frame): for images close to the source, such as maps of a surface into itself.
    Source,
    /// One normal per face (by face id), e.g. a target surface's normals at the image
    /// (`beltrami_spatial::SurfaceIndex::face_reference_normals`). Need not be unit.
    PerFace(&'a [Vector3<f64>]),
}

impl ReferenceNormal<'_> {
    /// The name in reports: `plane`, `radial`, `source` or `per-face`.
    pub fn name(&self) -> &'static str {
        match self {
            ReferenceNormal::Plane => "plane",
            ReferenceNormal::Radial => "radial",
            ReferenceNormal::Source => "source",
            ReferenceNormal::PerFace(_) => "per-face",
        }
    }

    /// The reference normal at quadrature point `q`, whose image is `image_point` (not
    /// normalized; only its direction matters). [`ReferenceNormal::PerFace`] must hold a
    /// normal for `q.face` ([`surface_map`] checks the length).
    pub fn at(&self, q: &QuadraturePoint, image_point: &Point3<f64>) -> Vector3<f64> {
        match self {
            ReferenceNormal::Plane => Vector3::z(),
            ReferenceNormal::Radial => image_point.coords,
            ReferenceNormal::Source => q.frame.normal,
            ReferenceNormal::PerFace(normals) => normals[q.face.idx()],
        }
    }

    /// The reference for a map's `image` (one point per vertex) when no target surface
    /// is known: [`ReferenceNormal::Plane`] when every image point lies in the plane
    /// z = 0 (`|z| <= 1e-12` times the diagonal of the image's bounding box, as
    /// [`crate::element::is_planar`]), else [`ReferenceNormal::Radial`] when every point
    /// lies on one sphere about the origin (`| |p| - r | <= 1e-6 r`, `r > 0` the mean of
    /// `|p|`), else [`ReferenceNormal::Source`] (right only for images close to the
    /// source: give a target surface's normals with [`ReferenceNormal::PerFace`]
    /// otherwise).
    pub fn for_image(image: &[Point3<f64>]) -> ReferenceNormal<'static> {
        let (lo, hi) = image.iter().fold(
            (
                Vector3::repeat(f64::INFINITY),
                Vector3::repeat(f64::NEG_INFINITY),
            ),
            |(lo, hi), p| (lo.inf(&p.coords), hi.sup(&p.coords)),
        );
        let diagonal = if image.is_empty() {
            0.0
        } else {
            (hi - lo).norm()
        };
        if image.iter().all(|p| p.z.abs() <= 1e-12 * diagonal) {
            return ReferenceNormal::Plane;
        }
        let radius = image.iter().map(|p| p.coords.norm()).sum::<f64>() / image.len().max(1) as f64;
        if radius > 0.0
            && image
                .iter()
                .all(|p| (p.coords.norm() - radius).abs() <= 1e-6 * radius)
        {
            return ReferenceNormal::Radial;
        }
        ReferenceNormal::Source
    }
}

/// The unit normal of the plane spanned by `u` and `v`, turned to the side of
/// `reference`: `m / |m|` with `m = u x v` when `m . reference > 0`, else `-m / |m|`
/// (the orientation rule of the module docs); `None` when `m = 0`.
#[inline]
pub fn oriented_normal(
    u: &Vector3<f64>,
    v: &Vector3<f64>,
    reference: &Vector3<f64>,
) -> Option<Vector3<f64>> {
    let m = u.cross(v);
    if m.norm_squared() > 0.0 {
        let m = m.normalize();
        Some(if m.dot(reference) > 0.0 { m } else { -m })
    } else {
        None
    }
}

/// The derivatives at one point of a map into R^3 whose derivatives along the source
/// frame axes are `dx = df(e1)` and `dy = df(e2)`, in the image frame oriented by
/// `reference` (Wong-Zhao 2014 eq. 4.7-4.9; the formulas are in the module docs): the
/// Jacobian is positive where `(dx x dy) . reference > 0`, negative (flipped, `|mu| > 1`)
/// where it is `<= 0`, and 0 with `|mu| = 1` where the image collapses (`dx x dy = 0`).
pub fn image_derivatives(
    dx: &Vector3<f64>,
    dy: &Vector3<f64>,
    reference: &Vector3<f64>,
) -> PointDerivatives {
    let len = dx.norm();
    let Some(normal) = oriented_normal(dx, dy, reference) else {
        // The image has no area here (a segment or a point): lay it on the real axis;
        // |mu| = 1 and the Jacobian is zero.
        let fy = if len > 0.0 {
            dy.dot(dx) / len
        } else {
            dy.norm()
        };
        return PointDerivatives::from_xy(Complex64::new(len, 0.0), Complex64::new(fy, 0.0));
    };
    let e1 = dx / len;
    let e2 = normal.cross(&e1);
    PointDerivatives::from_xy(
        Complex64::new(len, 0.0),
        Complex64::new(dy.dot(&e1), dy.dot(&e2)),
    )
}

/// Derivatives of a surface-to-surface map `image` (one point of R^3 per vertex) at every
/// quadrature point, intrinsically ([`image_derivatives`] with the reference normal of
/// `reference` at each point; Wong-Zhao eq. 4.7-4.9, see the module docs). Use a source
/// frame of [`crate::Frame::Face`] for surfaces.
///
/// Fails with [`FemError::Length`] for a wrong number of image points or of
/// [`ReferenceNormal::PerFace`] normals, and with [`FemError::NonFinite`] for a
/// non-finite image point or normal.
pub fn surface_map(
    elements: &Elements,
    vertex_count: usize,
    image: &[Point3<f64>],
    reference: ReferenceNormal<'_>,
) -> Result<Vec<PointDerivatives>, FemError> {
    if let ReferenceNormal::PerFace(normals) = reference {
        check_len("reference normals", elements.face_count(), normals.len())?;
        if let Some(index) = normals
            .iter()
            .position(|n| !n.iter().all(|x| x.is_finite()))
        {
            return Err(FemError::NonFinite {
                what: "reference normal",
                index,
            });
        }
    }
    let d = spatial_derivatives(elements, vertex_count, image)?;
    Ok(elements
        .points()
        .iter()
        .zip(d)
        .map(|(q, SpatialDerivatives { dx, dy })| {
            let point = if matches!(reference, ReferenceNormal::Radial) {
                elements
                    .nodes(q.face)
                    .iter()
                    .zip(&q.shape)
                    .fold(Point3::origin(), |p, (v, &n)| p + image[v.idx()].coords * n)
            } else {
                Point3::origin()
            };
            image_derivatives(&dx, &dy, &reference.at(q, &point))
        })
        .collect())
}

/// `mu` at every quadrature point.
pub fn point_mu(derivatives: &[PointDerivatives]) -> Vec<Complex64> {
    derivatives.iter().map(PointDerivatives::mu).collect()
}

/// One `mu` per face: the value at its single point (P1), or the weighted mean over its
/// four points (Q1; they share the face's frame direction, so the values are comparable).
pub fn face_mu(elements: &Elements, point_mu: &[Complex64]) -> Vec<Complex64> {
    (0..elements.face_count())
        .map(|f| {
            let f = FaceId(f as u32);
            let range = elements.face_points_range(f);
            let points = &elements.points()[range.clone()];
            if points.len() == 1 {
                return point_mu[range.start];
            }
            let total: f64 = points.iter().map(|q| q.weight).sum();
            points
                .iter()
                .zip(&point_mu[range])
                .map(|(q, &m)| m * q.weight)
                .sum::<Complex64>()
                / total
        })
        .collect()
}

/// Faces with a flipped or collapsed quadrature point (Jacobian `<= 0`).
pub fn flipped_faces(elements: &Elements, derivatives: &[PointDerivatives]) -> Vec<bool> {
    let mut flipped = vec![false; elements.face_count()];
    for (q, d) in elements.points().iter().zip(derivatives) {
        if d.jacobian() <= 0.0 {
            flipped[q.face.idx()] = true;
        }
    }
    flipped
}

/// Converts `mu` between frames: if the new frame's real axis is the old one rotated by
/// `theta` (counter-clockwise about the normal), `mu_new = mu_old e^{-2 i theta}`
/// (Gruber-Aulisa 2022, Lemma 3.4: `mu(a v) = conj(a)^2 / |a|^2 mu(v)`).
pub fn rotate_frame(mu: Complex64, theta: f64) -> Complex64 {
    mu * Complex64::from_polar(1.0, -2.0 * theta)
}
