//! The color bar of `|mu|`: a vertical viridis ramp from the bottom (`lo`) to the top
//! (`hi`) of the range, five labelled ticks, the label `|µ|` above.

use crate::colormap::{INK, MuRange};
use crate::viewport::Rect;
use crate::{Picture, text};

/// The width in pixels the color bar needs at text magnification `scale`.
pub(crate) fn width(scale: u32) -> u32 {
    let k = scale as i64;
    (bar_width(scale) as i64 + 4 * k + text::width("0.000", scale) + 8 * k) as u32
}

fn bar_width(scale: u32) -> u32 {
    14 * scale
}

/// Draws the color bar of `range` in `rect`, text magnified `scale` times.
pub(crate) fn draw(picture: &mut Picture, rect: Rect, range: MuRange, scale: u32) {
    let k = i64::from(scale);
    let line = text::height(scale);
    let title_y = i64::from(rect.y);
    picture.text(i64::from(rect.x), title_y, "|\u{b5}|", scale, INK);
    let top = title_y + line + line;
    let bottom = i64::from(rect.y + rect.height) - line;
    if bottom <= top {
        return;
    }
    let bar = bar_width(scale);
    let x = rect.x as f32;
    let span = (bottom - top) as f64;
    for y in top..bottom {
        // Row y shows the value at its center, `hi` at the top.
        let t = 1.0 - ((y - top) as f64 + 0.5) / span;
        let color = crate::colormap::viridis_rgb(t);
        picture.fill_rect(x, y as f32, bar as f32, 1.0, color);
    }
    let frame = vec![
        [x, top as f32],
        [x + bar as f32, top as f32],
        [x + bar as f32, bottom as f32],
        [x, bottom as f32],
        [x, top as f32],
    ];
    picture.stroke(&[frame], 1.0, INK, 1.0);
    for i in 0..=4 {
        let t = f64::from(i) / 4.0;
        let y = bottom as f64 - t * span;
        let tick = vec![
            [x + bar as f32, y as f32],
            [x + bar as f32 + 3.0 * k as f32, y as f32],
        ];
        picture.stroke(&[tick], 1.0, INK, 1.0);
        let label = tick_label(range.lo + t * (range.hi - range.lo));
        picture.text(
            i64::from(rect.x) + i64::from(bar) + 5 * k,
            y as i64 - line / 2,
            &label,
            scale,
            INK,
        );
    }
}

/// A tick value with at most three decimals and no trailing zeros.
pub(crate) fn tick_label(value: f64) -> String {
    let s = format!("{value:.3}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s.is_empty() || s == "-" {
        "0".into()
    } else {
        s.into()
    }
}
