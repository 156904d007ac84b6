//! Anderson acceleration of a fixed-point iteration `x <- F(x)` (Anderson 1965; Walker
//! and Ni, SIAM J. Numer. Anal. 2011, type II with depth `m`).
//!
//! With `g_k = F(x_k) - x_k` the residual of iterate `k`, and the differences
//! `dG_j = g_{j+1} - g_j`, `dF_j = F(x_{j+1}) - F(x_j)` of the last `m` iterates, the next
//! iterate is
//!
//! `x_{k+1} = F(x_k) - sum_j gamma_j dF_j`, `gamma = argmin |g_k - sum_j gamma_j dG_j|`,
//!
//! the combination of the last images of `F` whose residual, extrapolated linearly, is
//! least. For a linear contraction this is GMRES on `x = F(x)`; for the rounds of an
//! iterative closest point method (each a closest-point query and a least-squares
//! solve, a fixed-point map that converges slowly where the surfaces slide along each
//! other) it takes the same steps in fewer rounds (Pavlov, Ovchinnikov, Derbyshev,
//! Tsetserukou and Oseledets, "AA-ICP", ICRA 2018; Zhang, Yao and Deng, "Fast and robust
//! iterative closest point", IEEE TPAMI 2021, for a non-rigid ICP).
//!
//! Safeguard: when a residual is longer than the one before (the linear model failed:
//! the closest points changed face), the history is dropped and the plain image
//! `F(x_k)` taken, so the iteration never does worse than a restart.

use beltrami_mesh::Vector3;
use nalgebra::{DMatrix, DVector};

/// One 3-vector per vertex: an iterate, its image or its residual.
type Field = Vec<Vector3<f64>>;

/// Relative Tikhonov term on the diagonal of the small least-squares problem: keeps it
/// solvable when two residual differences are nearly parallel.
const REGULARIZATION: f64 = 1e-10;

/// The state of an accelerated iteration on vectors of 3-vectors (module docs).
pub(crate) struct AndersonMixing {
    /// Differences kept at most (`m`; 0: the plain iteration).
    depth: usize,
    /// The last residual and image, once there is one.
    last: Option<(Field, Field)>,
    /// The length of the last residual.
    last_length: f64,
    /// `dG_j`, oldest first.
    residual_changes: Vec<Field>,
    /// `dF_j`, oldest first.
    image_changes: Vec<Field>,
}

impl AndersonMixing {
    /// A new iteration keeping `depth` differences (0: the plain iteration).
    pub(crate) fn new(depth: usize) -> Self {
        Self {
            depth,
            last: None,
            last_length: f64::INFINITY,
            residual_changes: Vec::new(),
            image_changes: Vec::new(),
        }
    }

    /// The next iterate from the iterate `x` and its image `image = F(x)`.
    pub(crate) fn next(
        &mut self,
        x: &[Vector3<f64>],
        image: Vec<Vector3<f64>>,
    ) -> Vec<Vector3<f64>> {
        if self.depth == 0 {
            return image;
        }
        let residual: Vec<Vector3<f64>> = image.iter().zip(x).map(|(f, x)| f - x).collect();
        let length = dot(&residual, &residual).sqrt();
        if length > self.last_length {
            self.last = None;
            self.residual_changes.clear();
            self.image_changes.clear();
        }
        self.last_length = length;
        if let Some((last_residual, last_image)) = self.last.take() {
            if self.residual_changes.len() == self.depth {
                self.residual_changes.remove(0);
                self.image_changes.remove(0);
            }
            self.residual_changes
                .push(difference(&residual, &last_residual));
            self.image_changes.push(difference(&image, &last_image));
        }
        let mixed = self.mixed(&residual, &image);
        self.last = Some((residual, image));
        mixed
    }

    /// `F(x_k) - sum_j gamma_j dF_j` with the least-squares `gamma` (module docs), or
    /// `image` itself when there is no difference yet or the problem is singular.
    fn mixed(&self, residual: &[Vector3<f64>], image: &[Vector3<f64>]) -> Vec<Vector3<f64>> {
        let m = self.residual_changes.len();
        let mut out = image.to_vec();
        if m == 0 {
            return out;
        }
        let gram = DMatrix::from_fn(m, m, |i, j| {
            let entry = dot(&self.residual_changes[i], &self.residual_changes[j]);
            if i == j {
                entry * (1.0 + REGULARIZATION)
            } else {
                entry
            }
        });
        let right = DVector::from_fn(m, |i, _| dot(&self.residual_changes[i], residual));
        let Some(gamma) = gram.cholesky().map(|c| c.solve(&right)) else {
            return out;
        };
        if gamma.iter().any(|g| !g.is_finite()) {
            return out;
        }
        for (change, g) in self.image_changes.iter().zip(gamma.iter()) {
            for (o, d) in out.iter_mut().zip(change) {
                *o -= d * *g;
            }
        }
        out
    }
}

/// `a - b`, entry by entry.
fn difference(a: &[Vector3<f64>], b: &[Vector3<f64>]) -> Vec<Vector3<f64>> {
    a.iter().zip(b).map(|(a, b)| a - b).collect()
}

/// `sum_i a_i . b_i`.
fn dot(a: &[Vector3<f64>], b: &[Vector3<f64>]) -> f64 {
    a.iter().zip(b).map(|(a, b)| a.dot(b)).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Matrix3;

    /// Iterations of `x <- M x + b` per vertex (two vertices) until the step is below
    /// `1e-10`, with `depth` differences kept, and the final iterate.
    fn iterate(depth: usize) -> (usize, Vec<Vector3<f64>>) {
        // A contraction with a slow direction (0.95), as in sliding closest points.
        let m = Matrix3::new(0.95, 0.02, 0.0, 0.0, 0.6, 0.1, 0.0, -0.1, 0.5);
        let b = [Vector3::new(1.0, -2.0, 0.5), Vector3::new(0.0, 3.0, 1.0)];
        let map = |x: &[Vector3<f64>]| -> Vec<Vector3<f64>> {
            x.iter().zip(&b).map(|(x, b)| m * x + b).collect()
        };
        let mut mixing = AndersonMixing::new(depth);
        let mut x = vec![Vector3::zeros(); 2];
        for k in 1..=10_000 {
            let next = mixing.next(&x, map(&x));
            let step = difference(&next, &x)
                .iter()
                .map(|d| d.norm())
                .fold(0.0, f64::max);
            x = next;
            if step < 1e-10 {
                return (k, x);
            }
        }
        (usize::MAX, x)
    }

    #[test]
    fn a_linear_contraction_reaches_its_fixed_point_in_fewer_steps() {
        let m = Matrix3::new(0.95, 0.02, 0.0, 0.0, 0.6, 0.1, 0.0, -0.1, 0.5);
        let b = [Vector3::new(1.0, -2.0, 0.5), Vector3::new(0.0, 3.0, 1.0)];
        let fixed: Vec<Vector3<f64>> = b
            .iter()
            .map(|b| (Matrix3::identity() - m).try_inverse().unwrap() * b)
            .collect();
        let (plain, x) = iterate(0);
        for (a, b) in x.iter().zip(&fixed) {
            assert!((a - b).norm() < 1e-7, "{a} against {b}");
        }
        // Three differences span the map's three directions: GMRES ends in a few steps.
        let (accelerated, x) = iterate(3);
        for (a, b) in x.iter().zip(&fixed) {
            assert!((a - b).norm() < 1e-9, "{a} against {b}");
        }
        assert!(plain > 400, "plain iteration took {plain} steps");
        assert!(
            accelerated <= 10,
            "accelerated iteration took {accelerated} steps"
        );
    }

    #[test]
    fn depth_zero_is_the_plain_iteration() {
        let mut mixing = AndersonMixing::new(0);
        let x = vec![Vector3::new(1.0, 2.0, 3.0)];
        let image = vec![Vector3::new(-1.0, 0.5, 4.0)];
        assert_eq!(mixing.next(&x, image.clone()), image);
        assert_eq!(mixing.next(&image, x.clone()), x);
    }
}
