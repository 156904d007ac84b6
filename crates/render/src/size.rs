//! Image sizes: `WIDTHxHEIGHT` in pixels.

use std::fmt;
use std::str::FromStr;

use crate::RenderError;

/// The size of a picture in pixels, both sides in [`Size::MIN`]`..=`[`Size::MAX`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Size {
    width: u32,
    height: u32,
}

impl Size {
    /// The smallest width or height accepted.
    pub const MIN: u32 = 64;
    /// The largest width or height accepted.
    pub const MAX: u32 = 16384;

    /// A size, checked to lie in `MIN..=MAX` both ways.
    pub fn new(width: u32, height: u32) -> Result<Self, RenderError> {
        let text = format!("{width}x{height}");
        for (side, value) in [("width", width), ("height", height)] {
            if !(Self::MIN..=Self::MAX).contains(&value) {
                return Err(RenderError::Size {
                    text,
                    reason: format!(
                        "the {side} must lie between {} and {} pixels",
                        Self::MIN,
                        Self::MAX
                    ),
                });
            }
        }
        Ok(Self { width, height })
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }
}

impl Default for Size {
    /// 1600x1200.
    fn default() -> Self {
        Self {
            width: 1600,
            height: 1200,
        }
    }
}

impl FromStr for Size {
    type Err = RenderError;

    /// Parses `WIDTHxHEIGHT` (`x` or `X`), e.g. `1600x1200`.
    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let error = |reason: &str| RenderError::Size {
            text: text.to_string(),
            reason: reason.to_string(),
        };
        let (w, h) = text
            .trim()
            .split_once(['x', 'X'])
            .ok_or_else(|| error("expected WIDTHxHEIGHT, e.g. 1600x1200"))?;
        let parse = |s: &str, side: &str| {
            s.trim()
                .parse::<u32>()
                .map_err(|_| error(&format!("the {side} `{s}` is not a whole number of pixels")))
        };
        Size::new(parse(w, "width")?, parse(h, "height")?)
    }
}

impl fmt::Display for Size {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}x{}", self.width, self.height)
    }
}
