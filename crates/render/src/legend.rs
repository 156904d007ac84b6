//! The legend line under the panels: faces, flipped faces (in the warning color when
//! there are any), mean and max `|mu|`.

use crate::colormap::{INK, Rgb, WARNING};
use crate::scene::FaceDistortion;
use crate::{Picture, text};

/// The legend items: text and color.
pub(crate) fn items(faces: usize, distortion: Option<&FaceDistortion>) -> Vec<(String, Rgb)> {
    let mut items = vec![(format!("faces {faces}"), INK)];
    if let Some(d) = distortion {
        let s = &d.stats;
        let flips = if s.flipped > 0 { WARNING } else { INK };
        items.push((format!("flipped {}", s.flipped), flips));
        items.push((format!("mean |\u{b5}| {}", number(s.mu_mean)), INK));
        items.push((format!("max |\u{b5}| {}", number(s.mu_max)), INK));
    }
    items
}

/// Draws `items` from `(x, y)` (top-left) on one line, text magnified `scale` times.
pub(crate) fn draw(picture: &mut Picture, x: i64, y: i64, items: &[(String, Rgb)], scale: u32) {
    let gap = 3 * text::GLYPH * i64::from(scale);
    let mut at = x;
    for (s, color) in items {
        at += picture.text(at, y, s, scale, *color) + gap;
    }
}

/// A value of `|mu|` with four significant digits or so.
pub(crate) fn number(v: f64) -> String {
    if !v.is_finite() {
        format!("{v}")
    } else if v.abs() >= 100.0 {
        format!("{v:.0}")
    } else if v.abs() >= 10.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.4}")
    }
}
