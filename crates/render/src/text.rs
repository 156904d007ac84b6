//! Text in the public-domain 8x8 bitmap font of the `font8x8` crate, magnified by a whole
//! factor: crisp at any size, no font file, no shaping. Covers ASCII and Latin-1
//! (including `µ`, U+00B5); other characters draw as `?`.

use font8x8::legacy::{BASIC_LEGACY, LATIN_LEGACY};

use crate::Picture;
use crate::colormap::Rgb;

/// Glyph cell size in font pixels.
pub const GLYPH: i64 = 8;

/// The width in pixels of `s` at magnification `scale`.
pub fn width(s: &str, scale: u32) -> i64 {
    s.chars().count() as i64 * GLYPH * i64::from(scale)
}

/// The height in pixels of a line at magnification `scale`.
pub fn height(scale: u32) -> i64 {
    GLYPH * i64::from(scale)
}

fn glyph(c: char) -> [u8; 8] {
    let code = c as usize;
    match code {
        0x20..=0x7e => BASIC_LEGACY[code],
        0xa0..=0xff => LATIN_LEGACY[code - 0xa0],
        _ => BASIC_LEGACY['?' as usize],
    }
}

/// Draws `s` with its top-left corner at `(x, y)`; returns the width drawn.
pub(crate) fn draw(picture: &mut Picture, x: i64, y: i64, s: &str, scale: u32, c: Rgb) -> i64 {
    let k = i64::from(scale.max(1));
    for (n, ch) in s.chars().enumerate() {
        let left = x + n as i64 * GLYPH * k;
        for (row, bits) in glyph(ch).iter().enumerate() {
            for col in 0..8 {
                if bits & (1 << col) != 0 {
                    for dy in 0..k {
                        for dx in 0..k {
                            picture.put(left + col * k + dx, y + row as i64 * k + dy, c);
                        }
                    }
                }
            }
        }
    }
    width(s, scale.max(1))
}
