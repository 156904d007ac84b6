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
//!   the plane of the image's own tangent frame, oriented by a reference normal (the target
//!   surface's normal where known, else the source normal); `mu` is then the planar
//!   coefficient in the source frame. A different image frame rotates `f_z` and `f_zbar`
//!   alike and leaves `mu` unchanged.

use beltrami_mesh::{FaceId, Point3, Vector3};
use num_complex::Complex64;

use crate::{Elements, FemError};

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

fn check_len(what: &'static str, expected: usize, got: usize) -> Result<(), FemError> {
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
    check_len("map", vertex_count, map.len())?;
    if let Some(index) = map
        .iter()
        .position(|z| !(z.re.is_finite() && z.im.is_finite()))
    {
        return Err(FemError::NonFinite { what: "map", index });
    }
    Ok(elements
        .points()
        .iter()
        .map(|q| {
            let (mut fx, mut fy) = (Complex64::default(), Complex64::default());
            for (k, v) in elements.nodes(q.face).iter().enumerate() {
                fx += map[v.idx()] * q.grad[k].x;
                fy += map[v.idx()] * q.grad[k].y;
            }
            PointDerivatives::from_xy(fx, fy)
        })
        .collect())
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

/// Derivatives of a surface-to-surface map `image` (one point of R^3 per vertex) at every
/// quadrature point, intrinsically (Wong-Zhao eq. 4.7-4.9; see the module docs).
///
/// `reference_normals` gives, per face, the normal the image's orientation is judged
/// against (e.g. the target surface's normal at the image); `None` uses the source
/// normal at each point. Use a source frame of [`crate::Frame::Face`] for surfaces.
pub fn surface_map(
    elements: &Elements,
    vertex_count: usize,
    image: &[Point3<f64>],
    reference_normals: Option<&[Vector3<f64>]>,
) -> Result<Vec<PointDerivatives>, FemError> {
    if let Some(n) = reference_normals {
        check_len("reference normals", elements.face_count(), n.len())?;
    }
    let d = spatial_derivatives(elements, vertex_count, image)?;
    Ok(elements
        .points()
        .iter()
        .zip(d)
        .map(|(q, SpatialDerivatives { dx, dy })| {
            let reference = reference_normals.map_or(q.frame.normal, |n| n[q.face.idx()]);
            let m = dx.cross(&dy);
            let normal = if m.dot(&reference) >= 0.0 { m } else { -m };
            let len = dx.norm();
            if normal.norm() == 0.0 {
                // The image has no area here (a segment or a point): lay it on the real
                // axis; |mu| = 1 and the Jacobian is zero.
                let fy = if len > 0.0 {
                    dy.dot(&dx) / len
                } else {
                    dy.norm()
                };
                return PointDerivatives::from_xy(
                    Complex64::new(len, 0.0),
                    Complex64::new(fy, 0.0),
                );
            }
            let e1 = dx / len;
            let e2 = normal.normalize().cross(&e1);
            PointDerivatives::from_xy(
                Complex64::new(len, 0.0),
                Complex64::new(dy.dot(&e1), dy.dot(&e2)),
            )
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
