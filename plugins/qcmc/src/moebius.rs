//! Circles and the Moebius automorphisms of the unit disk.
//!
//! A circle domain is determined by its circles only up to the automorphisms of the unit
//! disk,
//!
//! ```text
//! phi(z) = e^{i theta} (z - a) / (1 - conj(a) z),    |a| < 1,
//! ```
//!
//! which map circles to circles and keep the unit circle (three real parameters: `a` and
//! `theta`). The solver fixes them by moving one inner circle to the centre and one
//! outer vertex to `1` ([`DiskAutomorphism::centering`]); the tests compare circle
//! domains up to them.
//!
//! The disk minus an eccentric disk `|z - d| < r` (`0 <= d`, `d + r < 1`) is the Moebius
//! image of the concentric annulus `rho < |w| < 1` with ([`concentric_radius`])
//!
//! ```text
//! a = [(1 + d^2 - r^2) - sqrt((1 + d^2 - r^2)^2 - 4 d^2)] / (2 d),
//! rho = |(d - r - a) / (1 - a (d - r))|,
//! ```
//!
//! `a` being the point inside the unit disk symmetric to `1/a` with respect to both
//! circles (`(a - d)(1/a - d) = r^2`): `phi_a` sends `a` to 0 and `1/a` to infinity,
//! so both image circles are symmetric about 0 and infinity, that is, concentric. The
//! conformal modulus of the domain is `log(1/rho) / (2 pi)`.

use num_complex::Complex64;

/// A circle of the plane: centre and radius.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlaneCircle {
    /// The centre.
    pub center: Complex64,
    /// The radius (positive).
    pub radius: f64,
}

impl PlaneCircle {
    /// The circle through three points, or `None` when they are (nearly) collinear.
    pub fn through(p: Complex64, q: Complex64, r: Complex64) -> Option<Self> {
        // The centre c solves |c - p| = |c - q| = |c - r|: two linear equations
        // 2 Re(conj(c) (q - p)) = |q|^2 - |p|^2 (and the same for r).
        let (u, v) = (q - p, r - p);
        let det = 2.0 * (u.re * v.im - u.im * v.re);
        if det.abs() <= 1e-300 {
            return None;
        }
        let (bu, bv) = (u.norm_sqr(), v.norm_sqr());
        let center =
            p + Complex64::new((bu * v.im - bv * u.im) / det, (u.re * bv - v.re * bu) / det);
        let radius = (center - p).norm();
        (radius.is_finite() && radius > 0.0).then_some(Self { center, radius })
    }

    /// The point of the circle nearest to `z` (Ho-Lui 2016, eq. 16); the circle's
    /// point `c + r` for `z = c`.
    pub fn project(&self, z: Complex64) -> Complex64 {
        let d = z - self.center;
        let n = d.norm();
        if n > 0.0 {
            self.center + d * (self.radius / n)
        } else {
            self.center + self.radius
        }
    }

    /// `| |z - c| - r | / r`: how far `z` is from the circle, relative to the radius.
    pub fn relative_distance(&self, z: Complex64) -> f64 {
        ((z - self.center).norm() - self.radius).abs() / self.radius
    }
}

/// A Moebius automorphism of the unit disk, `phi(z) = rotation (z - a) / (1 - conj(a) z)`
/// with `|rotation| = 1`, `|a| < 1` (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DiskAutomorphism {
    /// The point sent to 0.
    pub a: Complex64,
    /// The unit factor `e^{i theta}`.
    pub rotation: Complex64,
}

impl DiskAutomorphism {
    /// The identity.
    pub const IDENTITY: Self = Self {
        a: Complex64::new(0.0, 0.0),
        rotation: Complex64::new(1.0, 0.0),
    };

    /// `phi(z)`.
    pub fn apply(&self, z: Complex64) -> Complex64 {
        self.rotation * (z - self.a) / (1.0 - self.a.conj() * z)
    }

    /// The automorphism that makes the circle `circle` (inside the unit disk) concentric
    /// with the unit circle (module docs) and sends `fixed` (on the unit circle) to `1`.
    pub fn centering(circle: &PlaneCircle, fixed: Complex64) -> Self {
        let d = circle.center.norm();
        let a = if d > 0.0 {
            circle.center / d * symmetric_point(d, circle.radius)
        } else {
            Complex64::new(0.0, 0.0)
        };
        let moved = Self {
            a,
            rotation: Complex64::new(1.0, 0.0),
        }
        .apply(fixed);
        Self {
            a,
            rotation: moved.conj() / moved.norm(),
        }
    }

    /// The image of `circle` (a circle not through the pole `1 / conj(a)`): the circle
    /// through the images of three of its points.
    pub fn circle(&self, circle: &PlaneCircle) -> Option<PlaneCircle> {
        let at = |t: f64| self.apply(circle.center + circle.radius * Complex64::cis(t));
        PlaneCircle::through(
            at(0.0),
            at(2.0 * std::f64::consts::PI / 3.0),
            at(4.0 * std::f64::consts::PI / 3.0),
        )
    }
}

/// The real point `0 <= a < 1` symmetric (with `1/a`) to the unit circle and to the
/// circle of centre `d >= 0` and radius `r` (module docs).
fn symmetric_point(d: f64, r: f64) -> f64 {
    if d <= 0.0 {
        return 0.0;
    }
    let s = 1.0 + d * d - r * r;
    (s - (s * s - 4.0 * d * d).max(0.0).sqrt()) / (2.0 * d)
}

/// The inner radius `rho` of the concentric annulus `rho < |w| < 1` conformally
/// equivalent to the unit disk minus the closed disk of centre `d` (real, `d >= 0`) and
/// radius `r`, `d + r < 1` (module docs).
pub fn concentric_radius(d: f64, r: f64) -> f64 {
    let a = symmetric_point(d, r);
    let x = d - r;
    ((x - a) / (1.0 - a * x)).abs()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centering_makes_an_eccentric_circle_concentric_and_keeps_the_unit_circle() {
        let circle = PlaneCircle {
            center: Complex64::new(0.3, -0.2),
            radius: 0.25,
        };
        let fixed = Complex64::cis(2.0);
        let phi = DiskAutomorphism::centering(&circle, fixed);
        assert!((phi.apply(fixed) - 1.0).norm() < 1e-14);
        let image = phi.circle(&circle).unwrap();
        assert!(image.center.norm() < 1e-13, "{image:?}");
        let rho = concentric_radius(circle.center.norm(), circle.radius);
        assert!((image.radius - rho).abs() < 1e-13, "{} {rho}", image.radius);
        for t in 0..7 {
            let z = Complex64::cis(t as f64);
            assert!((phi.apply(z).norm() - 1.0).abs() < 1e-14);
            let w = circle.center + circle.radius * Complex64::cis(t as f64);
            assert!(image.relative_distance(phi.apply(w)) < 1e-13);
        }
    }

    #[test]
    fn concentric_radius_is_the_identity_for_concentric_circles() {
        assert!((concentric_radius(0.0, 0.4) - 0.4).abs() < 1e-15);
        // The modulus log(1/rho) / 2 pi shrinks (rho grows) as the hole moves towards
        // the boundary: the two circles come closer.
        assert!(concentric_radius(0.1, 0.4) > 0.4);
        assert!(concentric_radius(0.5, 0.4) > concentric_radius(0.1, 0.4));
    }

    #[test]
    fn circle_through_three_points() {
        let c = PlaneCircle::through(
            Complex64::new(1.0, 0.0),
            Complex64::new(0.0, 1.0),
            Complex64::new(-1.0, 0.0),
        )
        .unwrap();
        assert!(c.center.norm() < 1e-15 && (c.radius - 1.0).abs() < 1e-15);
        assert!(
            PlaneCircle::through(
                Complex64::new(0.0, 0.0),
                Complex64::new(1.0, 1.0),
                Complex64::new(2.0, 2.0)
            )
            .is_none()
        );
    }
}
