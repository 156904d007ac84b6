//! Orientation-preserving homeomorphisms of the torus `R^2 / Z^2` as seen on the unit
//! square: an integer matrix of determinant 1 about the square's centre, then a
//! translation.
//!
//! Square coordinates are `z = u + i v` with the loop `b` along `1` and `a` along `i`
//! (module `torus`). A matrix `L` of `SL(2, Z)` maps the lattice `Z^2` onto itself, so
//! `z -> L z + s (mod 1)` is a homeomorphism of the torus; it takes the loop `a` to the
//! lattice vector `L (0, 1)` and `b` to `L (1, 0)`, which fixes the homotopy class of a
//! map built through it. The identity pairs `a` with `a` and `b` with `b`; a quarter turn
//! pairs `a` with `b^-1` and `b` with `a`.

use num_complex::Complex64;

/// An integer matrix `[[m00, m01], [m10, m11]]` of determinant 1 acting on `(u, v)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct LatticeMap(pub [[i32; 2]; 2]);

impl LatticeMap {
    /// The identity: `a` with `a`, `b` with `b`.
    pub(crate) const IDENTITY: Self = Self([[1, 0], [0, 1]]);

    /// `n` counter-clockwise quarter turns (`z -> i^n z`).
    pub(crate) fn quarter_turns(n: u8) -> Self {
        match n % 4 {
            0 => Self::IDENTITY,
            1 => Self([[0, -1], [1, 0]]),
            2 => Self([[-1, 0], [0, -1]]),
            _ => Self([[0, 1], [-1, 0]]),
        }
    }

    /// `L z` for `z = u + i v`.
    pub(crate) fn apply(&self, z: Complex64) -> Complex64 {
        let [[a, b], [c, d]] = self.0.map(|row| row.map(f64::from));
        Complex64::new(a * z.re + b * z.im, c * z.re + d * z.im)
    }

    /// Every matrix of determinant 1 with entries in `-bound..=bound`.
    pub(crate) fn all_within(bound: i32) -> impl Iterator<Item = Self> {
        let range = move || -bound..=bound;
        range().flat_map(move |a| {
            range().flat_map(move |b| {
                range().flat_map(move |c| {
                    range()
                        .filter(move |&d| a * d - b * c == 1)
                        .map(move |d| Self([[a, b], [c, d]]))
                })
            })
        })
    }

    /// The pairing in words: which target loops (as `x a + y b`) the source's `a` and
    /// `b` go to.
    pub(crate) fn describe(&self) -> String {
        let [[m00, m01], [m10, m11]] = self.0;
        format!(
            "a -> {}, b -> {}",
            combination(m11, m01),
            combination(m10, m00)
        )
    }
}

/// `x a + y b` written as a user reads it ("a", "-b", "a + b", "2a - b").
fn combination(x: i32, y: i32) -> String {
    let term = |k: i32, name: &str| match k {
        1 => name.to_string(),
        -1 => format!("-{name}"),
        _ => format!("{k}{name}"),
    };
    match (x, y) {
        (0, 0) => "0".to_string(),
        (x, 0) => term(x, "a"),
        (0, y) => term(y, "b"),
        (x, y) if y > 0 => format!("{} + {}", term(x, "a"), term(y, "b")),
        (x, y) => format!("{} - {}", term(x, "a"), term(-y, "b")),
    }
}

/// `z -> L (z - c) + c + shift`, wrapped into `[0, 1)^2`, with `c = (1/2, 1/2)` the
/// centre of the square.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SquareMap {
    /// The linear part.
    pub linear: LatticeMap,
    /// The translation.
    pub shift: Complex64,
}

impl SquareMap {
    /// The linear part about the centre alone, no translation or wrap.
    pub(crate) fn turn(&self, x: Complex64) -> Complex64 {
        let center = Complex64::new(0.5, 0.5);
        center + self.linear.apply(x - center)
    }

    /// The image of a point of the square, wrapped into `[0, 1)^2`.
    pub(crate) fn apply(&self, x: Complex64) -> Complex64 {
        let y = self.turn(x) + self.shift;
        Complex64::new(y.re.rem_euclid(1.0), y.im.rem_euclid(1.0))
    }
}

/// The distance on the torus `R^2 / Z^2` between two points of the square.
pub(crate) fn periodic_distance(a: Complex64, b: Complex64) -> f64 {
    let d = a - b;
    Complex64::new(d.re - d.re.round(), d.im - d.im.round()).norm()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quarter_turns_multiply_by_i() {
        let z = Complex64::new(0.3, -0.7);
        for n in 0..4u8 {
            let turned = LatticeMap::quarter_turns(n).apply(z);
            assert!((turned - z * Complex64::i().powu(u32::from(n))).norm() < 1e-15);
        }
    }

    #[test]
    fn the_small_matrices_of_determinant_one_are_all_found_once() {
        let all: Vec<LatticeMap> = LatticeMap::all_within(1).collect();
        // Entries in {-1, 0, 1} with ad - bc = 1: counted by hand, 20.
        assert_eq!(all.len(), 20);
        for (k, m) in all.iter().enumerate() {
            let [[a, b], [c, d]] = m.0;
            assert_eq!(a * d - b * c, 1);
            assert!(!all[..k].contains(m));
        }
        for n in 0..4 {
            assert!(all.contains(&LatticeMap::quarter_turns(n)));
        }
    }

    #[test]
    fn a_lattice_map_is_a_bijection_of_the_torus() {
        // A shear maps the grid points of the square to grid points, each hit once.
        let map = SquareMap {
            linear: LatticeMap([[2, 1], [1, 1]]),
            shift: Complex64::new(0.25, 0.0),
        };
        let n = 8;
        let mut hit = vec![false; n * n];
        for i in 0..n {
            for j in 0..n {
                let z = map.apply(Complex64::new(i as f64, j as f64) / n as f64 + 0.5 / n as f64);
                let (p, q) = ((z.re * n as f64) as usize, (z.im * n as f64) as usize);
                assert!(!hit[p * n + q], "{z} hit twice");
                hit[p * n + q] = true;
            }
        }
    }

    #[test]
    fn the_pairing_is_written_as_loops() {
        assert_eq!(LatticeMap::IDENTITY.describe(), "a -> a, b -> b");
        assert_eq!(LatticeMap::quarter_turns(1).describe(), "a -> -b, b -> a");
        assert_eq!(
            LatticeMap([[1, 1], [0, 1]]).describe(),
            "a -> a + b, b -> b"
        );
        assert_eq!(
            LatticeMap([[2, -1], [1, 0]]).describe(),
            "a -> -b, b -> a + 2b"
        );
    }
}
