//! The scalar fields of the solvers.

use num_complex::Complex64;
use std::fmt::Debug;
use std::ops::{Add, AddAssign, Mul, MulAssign, Neg, Sub, SubAssign};

mod sealed {
    pub trait Sealed {}
    impl Sealed for f32 {}
    impl Sealed for f64 {}
    impl Sealed for num_complex::Complex64 {}
}

/// The scalar of the solvers' matrices and vectors: `f64`, [`Complex64`] (Hermitian
/// systems), or `f32` (a factorization of half the memory whose solves are refined in
/// `f64`: [`MixedSpdSolver`](crate::MixedSpdSolver)). Sealed: these are the ones the
/// solvers are tested for.
pub trait Scalar:
    faer::traits::ComplexField
    + Copy
    + Debug
    + PartialEq
    + Send
    + Sync
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign
    + sealed::Sealed
    + 'static
{
    /// The default singularity tolerance of a factorization in this scalar, per
    /// unknown ([`SolveOptions::singularity_tolerance`](crate::SolveOptions)): rounding
    /// leaves a singular matrix with a relative pivot of about `0.13 n eps`. `f64`:
    /// `8 eps`, 60 times above. `f32`: `eps = 1.2e-7`, 8 times above: with `8 eps` the
    /// tolerance of the non-rigid ICP's normal equations on fsaverage5 (41K unknowns)
    /// would be 0.039, above a pivot of 0.017 of that well-posed system.
    const TOLERANCE_PER_UNKNOWN: f64;

    /// `x` embedded in the scalar field (imaginary part 0).
    fn from_f64(x: f64) -> Self;

    /// Complex conjugate (identity for `f64`).
    fn conjugate(self) -> Self;

    /// `|x|^2`.
    fn norm_sqr(self) -> f64;

    /// The real part.
    fn real(self) -> f64;

    /// True if no component is NaN or infinite.
    fn finite(self) -> bool;
}

impl Scalar for f32 {
    const TOLERANCE_PER_UNKNOWN: f64 = f32::EPSILON as f64;

    /// Rounded to the nearest `f32`.
    #[inline]
    fn from_f64(x: f64) -> Self {
        x as f32
    }

    #[inline]
    fn conjugate(self) -> Self {
        self
    }

    #[inline]
    fn norm_sqr(self) -> f64 {
        f64::from(self) * f64::from(self)
    }

    #[inline]
    fn real(self) -> f64 {
        f64::from(self)
    }

    #[inline]
    fn finite(self) -> bool {
        self.is_finite()
    }
}

impl Scalar for f64 {
    const TOLERANCE_PER_UNKNOWN: f64 = 8.0 * f64::EPSILON;

    #[inline]
    fn from_f64(x: f64) -> Self {
        x
    }

    #[inline]
    fn conjugate(self) -> Self {
        self
    }

    #[inline]
    fn norm_sqr(self) -> f64 {
        self * self
    }

    #[inline]
    fn real(self) -> f64 {
        self
    }

    #[inline]
    fn finite(self) -> bool {
        self.is_finite()
    }
}

impl Scalar for Complex64 {
    const TOLERANCE_PER_UNKNOWN: f64 = 8.0 * f64::EPSILON;

    #[inline]
    fn from_f64(x: f64) -> Self {
        Complex64::new(x, 0.0)
    }

    #[inline]
    fn conjugate(self) -> Self {
        self.conj()
    }

    #[inline]
    fn norm_sqr(self) -> f64 {
        Complex64::norm_sqr(&self)
    }

    #[inline]
    fn real(self) -> f64 {
        self.re
    }

    #[inline]
    fn finite(self) -> bool {
        self.is_finite()
    }
}
