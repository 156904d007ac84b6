//! Quaternionic Beltrami coefficients of maps from surfaces in R^3 (Gruber-Aulisa 2022).
//!
//! Vectors of R^3 are pure imaginary quaternions. For a map `f: M -> R^3` and the unit
//! normal `N` of the source surface (its Gauss map, which defines the complex structure
//! `J v = N x v` on the tangent plane), the conformal and anticonformal parts of `df`
//! with respect to `N` are (section 3)
//!
//! ```text
//! df^+ = (df - N *df) / 2,   df^- = (df + N *df) / 2,   *df(v) = df(J v),
//! ```
//!
//! with quaternion products. `f` is quasiconformal with coefficient `mu` when
//! `df^- = mu df^+` (Definition 3.3), where `mu = mu1 + mu2 N` is normal-valued; by
//! Lemma 5.2, evaluated on a tangent vector `v`,
//! `mu(v) = df^-(v) conj(df^+(v)) / |df^+(v)|^2`, whose scalar part is `mu1` and whose
//! vector part is `mu2 N`. Here `v = e1`, the real axis of the quadrature point's frame,
//! so `mu1 + i mu2` is directly comparable with the intrinsic `mu` in the same frame (they
//! agree when the image stays in the source's tangent planes).

use beltrami_mesh::{Point3, Vector3};
use nalgebra::Quaternion;
use num_complex::Complex64;

use crate::{Elements, FemError};

/// `(df^+(e1), df^-(e1))` from `df(e1) = dx`, `df(e2) = df(J e1) = dy` and the source
/// normal `normal` (unit).
pub fn conformal_parts(
    normal: &Vector3<f64>,
    dx: &Vector3<f64>,
    dy: &Vector3<f64>,
) -> (Quaternion<f64>, Quaternion<f64>) {
    let n = Quaternion::from_imag(*normal);
    let fx = Quaternion::from_imag(*dx);
    let n_star = n * Quaternion::from_imag(*dy);
    ((fx - n_star) * 0.5, (fx + n_star) * 0.5)
}

/// `mu1 + i mu2` of Lemma 5.2 from the parts of [`conformal_parts`]. Where `df^+`
/// vanishes the coefficient is undefined and `1` is returned (on the flip threshold).
pub fn mu_from_parts(
    normal: &Vector3<f64>,
    plus: &Quaternion<f64>,
    minus: &Quaternion<f64>,
) -> Complex64 {
    let norm2 = plus.norm_squared();
    if norm2 == 0.0 {
        return Complex64::new(1.0, 0.0);
    }
    let q = minus * plus.conjugate() / norm2;
    Complex64::new(q.scalar(), q.imag().dot(normal))
}

/// The quaternionic `mu` (with respect to the source normal) of a map `image` into R^3 at
/// every quadrature point of `elements` (use [`crate::Frame::Face`]).
pub fn quaternionic_mu(
    elements: &Elements,
    vertex_count: usize,
    image: &[Point3<f64>],
) -> Result<Vec<Complex64>, FemError> {
    let derivatives = crate::beltrami::spatial_derivatives(elements, vertex_count, image)?;
    Ok(elements
        .points()
        .iter()
        .zip(derivatives)
        .map(|(q, d)| {
            let (plus, minus) = conformal_parts(&q.frame.normal, &d.dx, &d.dy);
            mu_from_parts(&q.frame.normal, &plus, &minus)
        })
        .collect())
}
