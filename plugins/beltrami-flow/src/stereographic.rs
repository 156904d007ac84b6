//! The stereographic coordinate of the unit sphere from the north pole, and Beltrami
//! coefficients given in it.
//!
//! ```text
//! z = S(x) = (x_1 + i x_2) / (1 - x_3),    S^-1(z) = (2 Re z, 2 Im z, |z|^2 - 1) / (|z|^2 + 1),
//! ```
//!
//! so `S(0, 0, -1) = 0`, `S(1, 0, 0) = 1` and the north pole is `infinity`
//! (Wong-Zhao 2014, section 5.1).
//!
//! Orientation: seen from outside the sphere, `S` reverses orientation (at the south
//! pole the outward normal is `-e_3`, and `S` maps the frame `(e_1, -e_2)` of the
//! outside view to `(1, i)`, up to scale). Face frames of an outward-oriented sphere
//! mesh therefore relate to `z` anti-conformally: near a face, `z = a conj(zeta) + b` with
//! `zeta` the face coordinate and `a = dS(e_1)`. A map `w = f(z)` with coefficient
//! `mu_z`, read in the face frames of its source and image, has
//!
//! ```text
//! mu_face = conj(mu_z) a / conj(a)
//! ```
//!
//! (the conjugation from the two anti-conformal charts, the rotation from the source
//! chart; the image chart does not change `mu`).

use beltrami_fem::{BeltramiField, Frame};
use beltrami_mesh::{FaceId, Mesh, Point3, Vector3};
use num_complex::Complex64;
use thiserror::Error;

/// A face where the stereographic coordinate cannot be used.
#[derive(Debug, Clone, Copy, PartialEq, Error)]
pub enum StereographicError {
    /// The face's centroid projects to the north pole (`z = infinity`) or the origin.
    #[error(
        "face {face}: its centroid is at the north pole or the centre of the sphere, where the stereographic coordinate is undefined"
    )]
    Singular {
        /// The face (mesh index).
        face: FaceId,
    },
}

/// `S(p) = (p_1 + i p_2) / (1 - p_3)` for `p` on the unit sphere.
pub fn stereographic(p: &Point3<f64>) -> Complex64 {
    Complex64::new(p.x, p.y) / (1.0 - p.z)
}

/// `S^-1(z)`, a point of the unit sphere.
pub fn inverse_stereographic(z: Complex64) -> Point3<f64> {
    let r2 = z.norm_sqr();
    Point3::new(2.0 * z.re, 2.0 * z.im, r2 - 1.0) / (r2 + 1.0)
}

/// `dS_p(v)` for `p` on the unit sphere and `v` tangent at `p`.
fn differential(p: &Point3<f64>, v: &Vector3<f64>) -> Complex64 {
    let d = 1.0 - p.z;
    Complex64::new(v.x, v.y) / d + Complex64::new(p.x, p.y) * v.z / (d * d)
}

/// The field of a coefficient `mu(z)` given in the stereographic coordinate, evaluated at
/// each face's centroid (projected onto the sphere), in the face frame (module docs:
/// `mu_face = conj(mu(z)) a / conj(a)`). `mesh` is a sphere-like mesh around the origin,
/// outward-oriented.
pub fn field(
    mesh: &Mesh,
    mu: impl Fn(Complex64) -> Complex64,
) -> Result<BeltramiField, StereographicError> {
    let values = mesh
        .faces()
        .map(|f| {
            let c = mesh.face_centroid(f);
            let n = c.coords.norm();
            let on = Point3::from(c.coords / n);
            if n.is_nan() || n <= 0.0 || 1.0 - on.z <= 1e-12 {
                return Err(StereographicError::Singular { face: f });
            }
            let e1 = mesh.face_frame(f).e1;
            let tangent = e1 - on.coords * on.coords.dot(&e1);
            let a = differential(&on, &tangent);
            Ok(mu(stereographic(&on)).conj() * a / a.conj())
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(BeltramiField::new(Frame::Face, values))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn projection_round_trips_and_fixes_the_normalization_points() {
        for z in [
            Complex64::new(0.3, -2.0),
            Complex64::new(-0.01, 0.2),
            Complex64::new(5.0, 7.0),
        ] {
            let p = inverse_stereographic(z);
            assert!((p.coords.norm() - 1.0).abs() < 1e-15);
            assert!((stereographic(&p) - z).norm() < 1e-12 * (1.0 + z.norm()));
        }
        assert_eq!(
            stereographic(&Point3::new(0.0, 0.0, -1.0)),
            Complex64::new(0.0, 0.0)
        );
        assert_eq!(
            stereographic(&Point3::new(1.0, 0.0, 0.0)),
            Complex64::new(1.0, 0.0)
        );
    }

    #[test]
    fn differential_matches_finite_differences() {
        let p = inverse_stereographic(Complex64::new(0.4, -0.7));
        let [u, v] = beltrami_flow_engine::target::orthonormal_basis(&p.coords);
        for t in [u, v] {
            let h = 1e-6;
            let plus = Point3::from((p.coords + h * t).normalize());
            let minus = Point3::from((p.coords - h * t).normalize());
            let numeric = (stereographic(&plus) - stereographic(&minus)) / (2.0 * h);
            assert!((numeric - differential(&p, &t)).norm() < 1e-8);
        }
        // Anti-conformal for the outward orientation: dS(v) = -i dS(u) when u x v = n.
        assert!((differential(&p, &v) + Complex64::i() * differential(&p, &u)).norm() < 1e-12);
    }
}
