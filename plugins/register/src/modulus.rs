//! The conformal modulus of a closed genus-1 mesh, and the Teichmueller bound between two.
//!
//! A torus `T` is conformally the flat torus `C / (Z A + Z B)` whose lattice is spanned by
//! the periods `A = integral_a omega`, `B = integral_b omega` of its holomorphic 1-form
//! `omega` (unique up to a complex factor) along the two loops of its cut square
//! ([`crate::torus`]). Its modulus in that marking is `tau = A / B`; with the square's
//! conventions (`a` along `i`, `b` along `1`, the square oriented with the surface) `tau`
//! lies in the upper half-plane.
//!
//! Discretely (P1 or Q1 forms, the Hodge decomposition of Gu-Yau 2003, "Global conformal
//! surface parameterization", SGP): the square parameter `u + i v` of the cut torus
//! gives two closed 1-forms `du`, `dv` (the two copies of a seam vertex differ by a
//! lattice vector, so the forms agree across the seams) with periods `integral_a dv = 1`,
//! `integral_b dv = 0`, `integral_a du = 0`, `integral_b du = 1`. Their harmonic parts
//! `theta_a = dv + df_v`, `theta_b = du + df_u` minimize the Dirichlet energy
//! `integral |dv + df|^2` over functions `f` on the vertices: `K f = -b` with `K` the
//! stiffness matrix (the cotangent Laplacian on triangles) and `b` the stiffness applied
//! to the local parameter values face by face. The Hodge star of a harmonic form is
//! harmonic, `*theta_a = alpha theta_a + beta theta_b`, and with the Gram entries
//! `G_xy = integral theta_x . theta_y` and the wedge `W = integral theta_a ^ theta_b`
//! (Riemann's bilinear relation gives `W = -1` in these conventions):
//!
//! ```text
//! beta = G_aa / W,   alpha = -G_ab / W,   omega = theta_a + i *theta_a,
//! A = 1 + i alpha,   B = i beta.
//! ```
//!
//! The error of the modulus is second order in the mesh size on smooth surfaces (test
//! `the_modulus_of_a_torus_of_revolution_converges_at_second_order`).
//!
//! The Teichmueller bound: a quasiconformal map between two tori that takes the first's
//! marking to the second's is homotopic to the affine map of the lattices, whose
//! Beltrami coefficient is constant with `|mu| = |tau - tau'| / |tau - conj(tau')|`, and
//! which is extremal (Teichmueller 1939): every map in that homotopy class has
//! `sup |mu|` at least this.

use beltrami_fem::operators::stiffness_matrix;
use beltrami_fem::{Elements, Frame};
use beltrami_mesh::{CutMesh, Mesh};
use beltrami_sparse::{SolveOptions, solve_spd};
use faer::Mat;
use num_complex::Complex64;

use crate::error::{RegisterError, Side};
use crate::square_map::LatticeMap;

/// The periods of a torus's holomorphic 1-form along the loops `a` and `b` of its cut
/// square (module docs), normalized so that `theta_a`, the real part, has period 1 on
/// `a` and 0 on `b`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TorusPeriods {
    /// `integral_a omega`.
    pub a: Complex64,
    /// `integral_b omega`.
    pub b: Complex64,
}

impl TorusPeriods {
    /// The conformal modulus in this marking, `tau = A / B` (upper half-plane for a
    /// consistently oriented mesh).
    pub fn tau(&self) -> Complex64 {
        self.a / self.b
    }

    /// The period along the loop whose square translation is `x + i y` (`x` times `b`
    /// and `y` times `a`): periods are additive on homology.
    fn along(&self, translation: Complex64) -> Complex64 {
        self.b * translation.re + self.a * translation.im
    }

    /// The modulus in the marking that a map with the square part `linear` pairs with
    /// the source's loops: the target's periods along the images `L (0, 1)` of `a` and
    /// `L (1, 0)` of `b` (module `square_map`).
    pub(crate) fn tau_in(&self, linear: &LatticeMap) -> Complex64 {
        self.along(linear.apply(Complex64::i()))
            / self.along(linear.apply(Complex64::new(1.0, 0.0)))
    }
}

/// The smallest `sup |mu|` of a quasiconformal map between tori of moduli `source` and
/// `target` in matched markings: `|tau - tau'| / |tau - conj(tau')|` (module docs). Both
/// in the upper half-plane.
pub fn teichmueller_bound(source: Complex64, target: Complex64) -> f64 {
    (source - target).norm() / (source - target.conj()).norm()
}

/// The periods of `mesh` from its cut square: `cut` (from `cut_to_disk(mesh)`) and the
/// square parameter `param` of every cut vertex (module docs).
pub(crate) fn periods(
    mesh: &Mesh,
    cut: &CutMesh,
    param: &[Complex64],
    side: Side,
) -> Result<TorusPeriods, RegisterError> {
    let elements_error = |error| RegisterError::Elements { side, error };
    let elements = Elements::new(mesh, Frame::Face).map_err(elements_error)?;
    // The parameter at every corner of every face, in the order of the face's nodes
    // (seam vertices have several copies; each face sees one).
    let mut local = vec![[Complex64::new(0.0, 0.0); 4]; mesh.face_count()];
    for cut_face in cut.mesh.faces() {
        let face = cut.original_face(cut_face);
        let nodes = elements.nodes(face);
        for v in cut.mesh.face_vertices(cut_face) {
            let original = cut.original_vertex(v);
            if let Some(k) = nodes.iter().position(|&n| n == original) {
                local[face.idx()][k] = param[v.idx()];
            }
        }
    }
    let n = mesh.vertex_count();
    let mut stiffness = stiffness_matrix(mesh, &elements).map_err(elements_error)?;
    // `f` is determined up to a constant: K + K_00 e_0 e_0^T fixes f_0 = 0 and leaves
    // the other equations exact, since the right-hand side sums to zero.
    let diagonal = stiffness
        .row_idx_of_col_raw(0)
        .iter()
        .position(|&i| i == 0)
        .ok_or(RegisterError::NoSquare { side })?;
    let start = stiffness.col_ptr()[0];
    let pin = stiffness.val()[start + diagonal];
    stiffness.val_mut()[start + diagonal] += pin;
    // Column 0: du (theta_b), column 1: dv (theta_a).
    let mut rhs = Mat::<f64>::zeros(n, 2);
    for q in elements.points() {
        let nodes = elements.nodes(q.face);
        let corners = &local[q.face.idx()];
        let grad_u = gradient(&q.grad[..nodes.len()], corners.iter().map(|z| z.re));
        let grad_v = gradient(&q.grad[..nodes.len()], corners.iter().map(|z| z.im));
        for (k, &node) in nodes.iter().enumerate() {
            rhs[(node.idx(), 0)] -= q.weight * q.grad[k].dot(&grad_u);
            rhs[(node.idx(), 1)] -= q.weight * q.grad[k].dot(&grad_v);
        }
    }
    let f = solve_spd(stiffness.as_ref(), rhs.as_ref(), SolveOptions::default())
        .map_err(|error| RegisterError::Solve { side, error })?;
    let (mut g_aa, mut g_ab, mut wedge) = (0.0, 0.0, 0.0);
    for q in elements.points() {
        let nodes = elements.nodes(q.face);
        let corners = &local[q.face.idx()];
        let grads = &q.grad[..nodes.len()];
        let theta_b = gradient(
            grads,
            nodes
                .iter()
                .zip(corners)
                .map(|(v, z)| z.re + f[(v.idx(), 0)]),
        );
        let theta_a = gradient(
            grads,
            nodes
                .iter()
                .zip(corners)
                .map(|(v, z)| z.im + f[(v.idx(), 1)]),
        );
        g_aa += q.weight * theta_a.norm_squared();
        g_ab += q.weight * theta_a.dot(&theta_b);
        wedge += q.weight * (theta_a.x * theta_b.y - theta_a.y * theta_b.x) * q.det.signum();
    }
    let alpha = -g_ab / wedge;
    let beta = g_aa / wedge;
    Ok(TorusPeriods {
        a: Complex64::new(1.0, alpha),
        b: Complex64::new(0.0, beta),
    })
}

/// `sum_k values_k grad_k`: the gradient of the interpolant with node values `values`.
fn gradient(
    grads: &[nalgebra::Vector2<f64>],
    values: impl Iterator<Item = f64>,
) -> nalgebra::Vector2<f64> {
    grads.iter().zip(values).map(|(g, x)| g * x).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::torus::square;
    use beltrami_mesh::primitives::{Cells, torus};

    fn modulus(mesh: &Mesh) -> Complex64 {
        let square = square(mesh, Side::Source, &mut Vec::new()).unwrap();
        periods(mesh, &square.cut, &square.param, Side::Source)
            .unwrap()
            .tau()
    }

    /// `tau` moved into the fundamental domain `|Re| <= 1/2, |tau| >= 1` of the modular
    /// group: the same conformal class whatever the loops.
    fn reduced(mut tau: Complex64) -> Complex64 {
        for _ in 0..100 {
            tau.re -= tau.re.round();
            if tau.norm_sqr() >= 1.0 - 1e-12 {
                break;
            }
            tau = -tau.inv();
        }
        tau
    }

    #[test]
    fn the_modulus_of_a_flat_square_torus_is_i() {
        // A torus of revolution with R = sqrt(2) r is conformally the square torus
        // (the ratio sqrt(R^2 - r^2) / r of the next test is 1).
        let mesh = Mesh::from_soup(&torus(96, 96, 2f64.sqrt(), 1.0, Cells::Triangles)).unwrap();
        let tau = reduced(modulus(&mesh));
        assert!((tau - Complex64::i()).norm() < 2e-3, "tau = {tau}");
    }

    #[test]
    fn the_modulus_of_a_torus_of_revolution_converges_at_second_order() {
        // Conformal coordinates of the torus (R + r cos s) around the axis: t with
        // dt = r ds / (R + r cos s) over the tube, period 2 pi r / sqrt(R^2 - r^2);
        // around the axis 2 pi: the lattice is rectangular with ratio
        // sqrt(R^2 - r^2) / r.
        let (major, minor): (f64, f64) = (3.0, 1.0);
        let exact = (major * major - minor * minor).sqrt() / minor;
        let mut errors = Vec::new();
        for k in [1, 2, 4] {
            let mesh =
                Mesh::from_soup(&torus(36 * k, 12 * k, major, minor, Cells::Triangles)).unwrap();
            let tau = reduced(modulus(&mesh));
            assert!(tau.im > 0.0, "tau = {tau}");
            errors.push((tau - Complex64::new(0.0, exact)).norm());
        }
        assert!(errors[2] < 5e-3, "errors {errors:?}");
        for w in errors.windows(2) {
            let rate = (w[0] / w[1]).log2();
            assert!(rate > 1.8, "errors {errors:?}");
        }
    }

    #[test]
    fn the_bound_of_two_tori_of_revolution_is_the_ratio_of_their_moduli() {
        // Rectangular lattices i m and i m': the affine map stretches by K = m / m', and
        // k = (K - 1) / (K + 1).
        let (m, m2) = (2.0f64, 1.5f64);
        let k = teichmueller_bound(Complex64::new(0.0, m), Complex64::new(0.0, m2));
        let big_k = m / m2;
        assert!((k - (big_k - 1.0) / (big_k + 1.0)).abs() < 1e-15);
        assert_eq!(
            teichmueller_bound(Complex64::new(0.3, 1.1), Complex64::new(0.3, 1.1)),
            0.0
        );
    }

    #[test]
    fn the_lattice_maps_act_on_tau_as_the_modular_group() {
        // [[p, q], [r, t]] takes a to q b + t a and b to p b + r a, so the modulus in
        // that marking is (t tau + q) / (r tau + p).
        let periods = TorusPeriods {
            a: Complex64::new(1.0, 0.4),
            b: Complex64::new(0.0, -0.7),
        };
        let tau = periods.tau();
        for linear in LatticeMap::all_within(2) {
            let [[p, q], [r, t]] = linear.0.map(|row| row.map(f64::from));
            let expected = (tau * t + q) / (tau * r + p);
            assert!((periods.tau_in(&linear) - expected).norm() < 1e-14);
            assert!(periods.tau_in(&linear).im > 0.0);
        }
        assert!((periods.tau_in(&LatticeMap::quarter_turns(1)) + tau.inv()).norm() < 1e-15);
    }
}
