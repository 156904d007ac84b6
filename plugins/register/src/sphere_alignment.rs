//! The Moebius transformation of the unit sphere that best carries points onto partners:
//! the alignment of two sphere maps by geometry when no landmark fixes it.
//!
//! Every orientation-preserving Moebius transformation of the sphere is a rotation after
//! a *boost* `phi_a(x) = (1 - |a|^2) (x - a) / |x - a|^2 - a` (the boundary values of the
//! conformal automorphism of the unit ball taking `a` to `0`; L. V. Ahlfors, *Moebius
//! transformations in several dimensions*, 1981, ch. II), `a` in the open ball: `phi_a`
//! spreads the points near `a / |a|` and gathers those opposite. The fit minimizes
//! `E(a) = min_R sum_i |R phi_a(s_i) - t_i|^2`, `R` by Kabsch for each `a`
//! ([`best_rotation`]), `a` by a compass search from `0` (each coordinate moved by a
//! step, the step halved when no move lowers `E`): three unknowns, a smooth `E`, and
//! the rotation fit of the same pairs as its value at `a = 0`.

use beltrami_mesh::Vector3;
use nalgebra::Matrix3;

use crate::landmarks::best_rotation;

/// The largest `|a|` tried: a boost with `|a|` near 1 gathers the sphere into a point.
const MAX_BOOST: f64 = 0.95;

/// The first step of the compass search and the step at which it ends.
const FIRST_STEP: f64 = 0.25;
const LAST_STEP: f64 = 1e-6;

/// Trials of the compass search at most.
const MAX_TRIALS: usize = 2000;

/// A Moebius transformation of the unit sphere, `x -> R phi_a(x)` (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SphereMoebius {
    /// The boost's point in the open unit ball.
    pub a: Vector3<f64>,
    /// The rotation after the boost.
    pub rotation: Matrix3<f64>,
}

impl SphereMoebius {
    /// The rotation `rotation` alone (`a = 0`).
    pub(crate) fn rotation(rotation: Matrix3<f64>) -> Self {
        Self {
            a: Vector3::zeros(),
            rotation,
        }
    }

    /// The image of a unit vector.
    pub(crate) fn apply(&self, x: &Vector3<f64>) -> Vector3<f64> {
        self.rotation * boost(&self.a, x)
    }
}

/// `phi_a(x)` for a unit vector `x` (module docs); the identity at `a = 0`.
fn boost(a: &Vector3<f64>, x: &Vector3<f64>) -> Vector3<f64> {
    let d = x - a;
    let d2 = d.norm_squared();
    if d2 == 0.0 {
        // x = a cannot happen for |a| < 1 and |x| = 1; kept total for rounding.
        return *x;
    }
    d * ((1.0 - a.norm_squared()) / d2) - a
}

/// The residual `min_R sum |R phi_a(s) - t|^2` and its rotation.
fn fit_rotation(a: &Vector3<f64>, pairs: &[(Vector3<f64>, Vector3<f64>)]) -> (f64, Matrix3<f64>) {
    let boosted: Vec<(Vector3<f64>, Vector3<f64>)> =
        pairs.iter().map(|(s, t)| (boost(a, s), *t)).collect();
    let rotation = best_rotation(&boosted);
    let residual = boosted
        .iter()
        .map(|(s, t)| (rotation * s - t).norm_squared())
        .sum();
    (residual, rotation)
}

/// The Moebius transformation minimizing `sum |M s_i - t_i|^2` over the pairs of unit
/// vectors `(s_i, t_i)` (module docs), and its residual.
pub(crate) fn fitted_moebius(pairs: &[(Vector3<f64>, Vector3<f64>)]) -> (SphereMoebius, f64) {
    let mut a = Vector3::zeros();
    let (mut residual, mut rotation) = fit_rotation(&a, pairs);
    let mut step = FIRST_STEP;
    let mut trials = 0;
    while step >= LAST_STEP && trials < MAX_TRIALS {
        let mut improved = false;
        for axis in 0..3 {
            for sign in [1.0, -1.0] {
                let mut trial = a;
                trial[axis] += sign * step;
                if trial.norm() > MAX_BOOST {
                    continue;
                }
                trials += 1;
                let (r, rot) = fit_rotation(&trial, pairs);
                if r < residual {
                    (a, residual, rotation) = (trial, r, rot);
                    improved = true;
                }
            }
        }
        if !improved {
            step *= 0.5;
        }
    }
    (SphereMoebius { a, rotation }, residual)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Rotation3;

    fn sphere_points(n: usize) -> Vec<Vector3<f64>> {
        // A Fibonacci lattice: evenly spread unit vectors.
        let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
        (0..n)
            .map(|i| {
                let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
                let r = (1.0 - z * z).sqrt();
                let phi = golden * i as f64;
                Vector3::new(r * phi.cos(), r * phi.sin(), z)
            })
            .collect()
    }

    #[test]
    fn a_boost_keeps_the_sphere_and_its_inverse_undoes_it() {
        let a = Vector3::new(0.3, -0.2, 0.5);
        for x in sphere_points(50) {
            let y = boost(&a, &x);
            assert!((y.norm() - 1.0).abs() < 1e-12);
            // phi_a^-1 = phi_-a for the ball's automorphisms of this form.
            assert!((boost(&(-a), &y) - x).norm() < 1e-12);
        }
    }

    #[test]
    fn the_fit_recovers_a_boost_and_a_rotation() {
        let truth = SphereMoebius {
            a: Vector3::new(0.35, -0.1, 0.25),
            rotation: Rotation3::from_euler_angles(0.4, -0.7, 1.9).into_inner(),
        };
        let pairs: Vec<_> = sphere_points(400)
            .into_iter()
            .map(|s| (s, truth.apply(&s)))
            .collect();
        let (fitted, residual) = fitted_moebius(&pairs);
        assert!(residual < 1e-6, "residual {residual}");
        for (s, t) in &pairs {
            assert!((fitted.apply(s) - t).norm() < 1e-3);
        }
        // A rotation alone leaves a residual the boost removes.
        let (rotation_only, _) = fit_rotation(&Vector3::zeros(), &pairs);
        assert!(rotation_only > 1.0, "rotation alone: {rotation_only}");
    }
}
