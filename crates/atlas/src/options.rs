//! What an atlas is asked to be.

use crate::AtlasError;
use crate::cones::ConeGoal;

/// The most cones placed on one chart when their number is chosen automatically.
pub const MAX_AUTO_CONES: usize = 64;

/// How many cones each chart gets.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ConeCount {
    /// As many as the stretch limit needs (at most [`MAX_AUTO_CONES`] per chart; a chart
    /// still too stretched is split).
    Auto,
    /// This many per chart (a closed genus-0 chart gets at least 2, a closed chart of
    /// genus 2 or more at least 1).
    Exactly(usize),
}

/// How many charts the atlas has.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ChartCount {
    /// As few as the stretch limit and the overlap test leave.
    Auto,
    /// At least this many: after the automatic charts, the chart of the largest share
    /// of the atlas's squared L2 stretch (its area times its own L2 stretch squared) is
    /// split in two until there are this many or more (one split may leave a half in
    /// pieces, so one more is possible).
    AtLeast(usize),
}

/// The options of [`crate::atlas`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AtlasOptions {
    /// How many cones each chart gets.
    pub cones: ConeCount,
    /// How many charts the atlas has.
    pub charts: ChartCount,
    /// The largest L2 stretch (Sander et al. 2001) a chart may have; a chart above it is
    /// split. At least 1.
    pub max_stretch: f64,
    /// The space kept between charts, as a fraction of the texture's side, in
    /// `[0, 0.25]`.
    pub padding: f64,
}

impl Default for AtlasOptions {
    fn default() -> Self {
        Self {
            cones: ConeCount::Auto,
            charts: ChartCount::Auto,
            max_stretch: 1.1,
            padding: 0.004,
        }
    }
}

impl AtlasOptions {
    /// Checks every option's range.
    pub fn validate(&self) -> Result<(), AtlasError> {
        if !(self.max_stretch >= 1.0 && self.max_stretch.is_finite()) {
            return Err(AtlasError::InvalidOption {
                option: "max-stretch",
                message: format!(
                    "{} is not a stretch: the L2 stretch is at least 1 (1 means no distortion); give a finite number such as 1.1",
                    self.max_stretch
                ),
            });
        }
        if !(0.0..=0.25).contains(&self.padding) {
            return Err(AtlasError::InvalidOption {
                option: "padding",
                message: format!(
                    "{} is outside [0, 0.25]: the padding is a fraction of the texture's side",
                    self.padding
                ),
            });
        }
        if let ChartCount::AtLeast(n) = self.charts
            && n == 0
        {
            return Err(AtlasError::InvalidOption {
                option: "charts",
                message: "0 charts: ask for `auto` or at least 1".into(),
            });
        }
        if let ConeCount::Exactly(n) = self.cones
            && n > 10_000
        {
            return Err(AtlasError::InvalidOption {
                option: "cones",
                message: format!("{n} cones per chart is more than 10000"),
            });
        }
        Ok(())
    }

    /// The cone placement goal of every chart.
    pub(crate) fn cone_goal(&self) -> ConeGoal {
        match self.cones {
            ConeCount::Auto => ConeGoal {
                stretch: self.max_stretch,
                max_cones: MAX_AUTO_CONES,
            },
            ConeCount::Exactly(n) => ConeGoal {
                stretch: 1.0,
                max_cones: n,
            },
        }
    }
}
