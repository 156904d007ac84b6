//! The two scalar fields of the solvers.

use num_complex::Complex64;
use std::fmt::Debug;
use std::ops::{Add, AddAssign, Mul, MulAssign, Neg, Sub, SubAssign};

mod sealed {
    pub trait Sealed {}
    impl Sealed for f64 {}
    impl Sealed for num_complex::Complex64 {}
}

/// The scalar of the solvers' matrices and vectors: `f64` or [`Complex64`] (Hermitian
/// systems). Sealed: the two are the only ones the solvers are tested for.
pub trait Scalar:
    faer::traits::ComplexField<Real = f64>
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
    /// `x` embedded in the scalar field (imaginary part 0).
    fn from_f64(x: f64) -> Self;

    /// Complex conjugate (identity for `f64`).
    fn conjugate(self) -> Self;

    /// `|x|^2`.
    fn norm_sqr(self) -> f64;

    /// True if no component is NaN or infinite.
    fn finite(self) -> bool;
}

impl Scalar for f64 {
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
    fn finite(self) -> bool {
        self.is_finite()
    }
}

impl Scalar for Complex64 {
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
    fn finite(self) -> bool {
        self.is_finite()
    }
}
