//! Colors of `|mu|`: the viridis colormap (perceptually uniform, readable in grey and by
//! most color-blind readers) over a range of `|mu|`, and the fixed colors of the
//! pictures.

use std::fmt;
use std::str::FromStr;

use crate::RenderError;

/// An sRGB color, 8 bits per channel.
pub type Rgb = [u8; 3];

/// Viridis sampled at 0, 1/8, .., 1 (sRGB in [0, 1]), interpolated linearly between.
const VIRIDIS: [[f32; 3]; 9] = [
    [0.267, 0.005, 0.329],
    [0.279, 0.175, 0.483],
    [0.230, 0.322, 0.546],
    [0.173, 0.449, 0.558],
    [0.128, 0.567, 0.551],
    [0.151, 0.682, 0.499],
    [0.369, 0.789, 0.383],
    [0.678, 0.864, 0.190],
    [0.993, 0.906, 0.144],
];

/// The viridis color of `t` clamped to [0, 1] (NaN maps to 1), as sRGB in [0, 1]: dark
/// purple at 0, teal at 1/2, yellow at 1.
pub fn viridis(t: f64) -> [f32; 3] {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        1.0
    };
    let x = t * (VIRIDIS.len() - 1) as f64;
    let k = (x.floor() as usize).min(VIRIDIS.len() - 2);
    let s = (x - k as f64) as f32;
    let (a, b) = (VIRIDIS[k], VIRIDIS[k + 1]);
    [
        a[0] + s * (b[0] - a[0]),
        a[1] + s * (b[1] - a[1]),
        a[2] + s * (b[2] - a[2]),
    ]
}

/// The viridis color of `t` (see [`viridis`]) in 8 bits per channel.
pub fn viridis_rgb(t: f64) -> Rgb {
    viridis(t).map(|c| (c * 255.0).round() as u8)
}

/// The range of `|mu|` the colormap spans: `lo` gets the first color, `hi` and above the
/// last. The default is `[0, 1]`, the whole range of an orientation-preserving map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MuRange {
    /// `|mu|` at the bottom of the color bar.
    pub lo: f64,
    /// `|mu|` at the top of the color bar.
    pub hi: f64,
}

impl MuRange {
    /// A range, checked: finite, `0 <= lo < hi`.
    pub fn new(lo: f64, hi: f64) -> Result<Self, RenderError> {
        if !(lo.is_finite() && hi.is_finite() && 0.0 <= lo && lo < hi) {
            return Err(RenderError::MuRange {
                text: format!("{lo},{hi}"),
                reason: "expected finite LO,HI with 0 <= LO < HI".into(),
            });
        }
        Ok(Self { lo, hi })
    }

    /// Where `modulus` falls in the range, clamped to [0, 1].
    pub fn normalize(&self, modulus: f64) -> f64 {
        ((modulus - self.lo) / (self.hi - self.lo)).clamp(0.0, 1.0)
    }

    /// The color of `modulus`.
    pub fn color(&self, modulus: f64) -> Rgb {
        if modulus.is_finite() {
            viridis_rgb(self.normalize(modulus))
        } else {
            viridis_rgb(1.0)
        }
    }
}

impl Default for MuRange {
    /// `[0, 1]`.
    fn default() -> Self {
        Self { lo: 0.0, hi: 1.0 }
    }
}

impl FromStr for MuRange {
    type Err = RenderError;

    /// Parses `LO,HI`, e.g. `0,0.5`.
    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let error = |reason: &str| RenderError::MuRange {
            text: text.to_string(),
            reason: reason.to_string(),
        };
        let (lo, hi) = text
            .split_once(',')
            .ok_or_else(|| error("expected LO,HI, e.g. 0,0.5"))?;
        let parse = |s: &str| {
            s.trim()
                .parse::<f64>()
                .map_err(|_| error(&format!("`{s}` is not a number")))
        };
        let (lo, hi) = (parse(lo)?, parse(hi)?);
        MuRange::new(lo, hi).map_err(|_| error("expected finite LO,HI with 0 <= LO < HI"))
    }
}

impl fmt::Display for MuRange {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{},{}", self.lo, self.hi)
    }
}

/// The background of every picture: white.
pub const BACKGROUND: Rgb = [255, 255, 255];
/// Text, axes and boundary loops: near black.
pub const INK: Rgb = [30, 30, 30];
/// Flipped faces (outline, histogram bar of `|mu| >= 1`): a red that viridis never uses.
pub const WARNING: Rgb = [228, 26, 28];
/// Faces without a coloring.
pub const PLAIN: Rgb = [205, 205, 210];
/// The two colors of a checkerboard.
pub const CHECKER: [Rgb; 2] = [[240, 240, 240], [235, 120, 45]];
