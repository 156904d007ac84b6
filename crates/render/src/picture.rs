//! The finished picture: an RGB image with y down (row 0 at the top), drawn on with
//! tiny-skia (antialiased lines and shapes) and the bitmap font, written as PNG
//! atomically.

use std::io::Write;
use std::path::Path;

use beltrami_mesh::io::write_atomically;
use tiny_skia::{Color, LineCap, LineJoin, Paint, PathBuilder, Pixmap, Rect, Stroke, Transform};

use crate::colormap::{BACKGROUND, Rgb};
use crate::{RenderError, Size, text};

/// An opaque RGB picture, `width x height` pixels, row 0 at the top.
#[derive(Debug, Clone)]
pub struct Picture {
    pixmap: Pixmap,
}

impl Picture {
    /// A picture of `size` filled with the white background.
    pub fn new(size: Size) -> Self {
        let mut pixmap = match Pixmap::new(size.width(), size.height()) {
            Some(p) => p,
            // A Size has both sides in 64..=16384, which Pixmap accepts.
            None => unreachable!("a checked Size makes a pixmap"),
        };
        let [r, g, b] = BACKGROUND;
        pixmap.fill(Color::from_rgba8(r, g, b, 255));
        Self { pixmap }
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.pixmap.width()
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.pixmap.height()
    }

    /// The color of pixel `(x, y)` (y down), or `None` outside the picture.
    pub fn pixel(&self, x: u32, y: u32) -> Option<Rgb> {
        let p = self.pixmap.pixel(x, y)?;
        Some([p.red(), p.green(), p.blue()])
    }

    /// The pixels as RGB bytes, row by row from the top.
    pub fn rgb(&self) -> Vec<u8> {
        self.pixmap
            .data()
            .chunks_exact(4)
            .flat_map(|p| [p[0], p[1], p[2]])
            .collect()
    }

    /// The picture encoded as an 8-bit RGB PNG (deterministic: the same picture gives
    /// the same bytes).
    pub fn encode_png(&self) -> Result<Vec<u8>, RenderError> {
        let mut bytes = Vec::new();
        self.encode_into(&mut bytes).map_err(RenderError::Encode)?;
        Ok(bytes)
    }

    fn encode_into(&self, out: impl Write) -> std::io::Result<()> {
        let mut encoder = png::Encoder::new(out, self.width(), self.height());
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_compression(png::Compression::High);
        let mut writer = encoder.write_header().map_err(std::io::Error::other)?;
        // Row by row, so that encoding adds one row of memory, not a copy of the picture.
        let mut stream = writer.stream_writer().map_err(std::io::Error::other)?;
        let mut row = Vec::with_capacity(3 * self.width() as usize);
        for line in self.pixmap.data().chunks_exact(4 * self.width() as usize) {
            row.clear();
            row.extend(line.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]));
            stream.write_all(&row)?;
        }
        stream.finish().map_err(std::io::Error::other)?;
        writer.finish().map_err(std::io::Error::other)
    }

    /// Writes the picture as PNG to `path` (which must end in `.png`): the file gets the
    /// complete picture or is left as it was.
    pub fn write_png(&self, path: &Path) -> Result<(), RenderError> {
        check_png_path(path)?;
        write_atomically(path, |w| self.encode_into(w))?;
        Ok(())
    }

    /// Copies `pixels` (`width x height`, row by row) with its top-left corner at
    /// `(x, y)`, clipped to the picture.
    pub(crate) fn blit(&mut self, x: u32, y: u32, width: usize, pixels: &[Rgb]) {
        let (w, h) = (self.width() as usize, self.height() as usize);
        let data = self.pixmap.data_mut();
        for (j, row) in pixels.chunks_exact(width.max(1)).enumerate() {
            let py = y as usize + j;
            if py >= h {
                break;
            }
            for (i, c) in row.iter().enumerate() {
                let px = x as usize + i;
                if px >= w {
                    break;
                }
                let k = 4 * (py * w + px);
                data[k..k + 4].copy_from_slice(&[c[0], c[1], c[2], 255]);
            }
        }
    }

    /// Sets one pixel (ignored outside the picture).
    pub(crate) fn put(&mut self, x: i64, y: i64, c: Rgb) {
        let (w, h) = (i64::from(self.width()), i64::from(self.height()));
        if (0..w).contains(&x) && (0..h).contains(&y) {
            let k = 4 * (y * w + x) as usize;
            self.pixmap.data_mut()[k..k + 4].copy_from_slice(&[c[0], c[1], c[2], 255]);
        }
    }

    /// Fills the axis-aligned rectangle `[x, x + w) x [y, y + h)` (pixels, y down).
    pub(crate) fn fill_rect(&mut self, x: f32, y: f32, w: f32, h: f32, c: Rgb) {
        if let Some(rect) = Rect::from_xywh(x, y, w, h) {
            self.pixmap
                .fill_rect(rect, &paint(c, 1.0), Transform::identity(), None);
        }
    }

    /// Strokes the polylines `lines` (each a list of points in pixels, y down) with
    /// round joins and caps, antialiased, `width` pixels wide, with opacity `alpha`.
    pub(crate) fn stroke(&mut self, lines: &[Vec<[f32; 2]>], width: f32, c: Rgb, alpha: f32) {
        let mut builder = PathBuilder::new();
        for line in lines {
            let mut points = line.iter();
            if let Some(p) = points.next() {
                builder.move_to(p[0], p[1]);
                for q in points {
                    builder.line_to(q[0], q[1]);
                }
            }
        }
        if let Some(path) = builder.finish() {
            let stroke = Stroke {
                width,
                line_cap: LineCap::Round,
                line_join: LineJoin::Round,
                ..Stroke::default()
            };
            self.pixmap.stroke_path(
                &path,
                &paint(c, alpha),
                &stroke,
                Transform::identity(),
                None,
            );
        }
    }

    /// Writes `s` with its top-left corner at `(x, y)` in the bitmap font magnified
    /// `scale` times; returns the width drawn.
    pub(crate) fn text(&mut self, x: i64, y: i64, s: &str, scale: u32, c: Rgb) -> i64 {
        text::draw(self, x, y, s, scale, c)
    }
}

/// Fails unless `path` ends in `.png` (any case).
pub fn check_png_path(path: &Path) -> Result<(), RenderError> {
    let png = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if png {
        Ok(())
    } else {
        Err(RenderError::NotPng {
            path: path.to_path_buf(),
        })
    }
}

fn paint(c: Rgb, alpha: f32) -> Paint<'static> {
    let mut paint = Paint::default();
    paint.set_color(Color::from_rgba8(
        c[0],
        c[1],
        c[2],
        (alpha.clamp(0.0, 1.0) * 255.0).round() as u8,
    ));
    paint.anti_alias = true;
    paint
}
