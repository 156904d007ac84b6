//! A small z-buffered triangle rasterizer: the fills of both views.
//!
//! Coordinates are in samples (a picture rendered at `s` samples per pixel and axis has
//! `s` times its pixel width), x to the right, y **down** (row order); a sample's center
//! is at `(i + 0.5, j + 0.5)`. Vertices are snapped to 1/256 of a sample and the edge
//! functions are evaluated exactly in integers, with a tie rule that gives every sample
//! on an edge shared by two triangles to exactly one of them: a closed mesh has no
//! cracks and no sample is drawn twice by neighbours.
//!
//! Triangles of either orientation are drawn (a flipped face of a map must show). For
//! every covered sample the caller's shader gets a [`Fragment`]: barycentric coordinates
//! and the distances to the three edges (for wireframes and outlines drawn inside the
//! triangles, so they are hidden by the depth test like the fills).

use crate::colormap::Rgb;

/// Subsample precision: vertices snap to `1 / SUB` of a sample.
const SUB: f64 = 256.0;

/// What the shader knows about a covered sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fragment {
    /// Barycentric coordinates of the sample, in the order the vertices were given.
    pub bary: [f32; 3],
    /// Distance in samples from the sample to the edge opposite each vertex.
    pub edge: [f32; 3],
}

/// The most samples of one band: 2^23 samples of 7 bytes (color and depth), 56 MiB.
/// A view larger than this is drawn band by band ([`bands`]), so that memory stays
/// proportional to the picture's pixels (4 bytes each in the [`crate::Picture`]) and
/// not to its samples.
const BAND_SAMPLES: usize = 1 << 23;

/// The bands `(top, rows)` of sample rows that cover a `width x height` view drawn at
/// `samples` samples per pixel and axis: each at most [`BAND_SAMPLES`] samples (but at
/// least one pixel row), `rows` a multiple of `samples` except perhaps the last.
pub(crate) fn bands(width: usize, height: usize, samples: usize) -> Vec<(usize, usize)> {
    let samples = samples.max(1);
    let rows = (BAND_SAMPLES / width.max(1) / samples * samples).max(samples);
    (0..height)
        .step_by(rows)
        .map(|top| (top, rows.min(height - top)))
        .collect()
}

/// A color and depth buffer: sample rows `top..top + height` of a view `width` samples
/// wide (all of it when `top` is 0 and `height` the view's height).
#[derive(Debug, Clone)]
pub struct Raster {
    width: usize,
    height: usize,
    top: usize,
    color: Vec<Rgb>,
    depth: Vec<f32>,
}

impl Raster {
    /// A `width x height` buffer filled with `background` at infinite depth.
    pub fn new(width: usize, height: usize, background: Rgb) -> Self {
        Self::band(width, 0, height, background)
    }

    /// The band of sample rows `top..top + rows` of a view `width` samples wide, filled
    /// with `background` at infinite depth. Triangles are given in the view's
    /// coordinates and clipped to the band.
    pub fn band(width: usize, top: usize, rows: usize, background: Rgb) -> Self {
        Self {
            width,
            height: rows,
            top,
            color: vec![background; width * rows],
            depth: vec![f32::INFINITY; width * rows],
        }
    }

    /// Width in samples.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in samples.
    pub fn height(&self) -> usize {
        self.height
    }

    /// The color of sample `(x, y)` (y down, in the band's own rows: 0 is row `top`).
    pub fn color(&self, x: usize, y: usize) -> Rgb {
        self.color[y * self.width + x]
    }

    /// Draws the triangle with vertices `(x, y, depth)` in samples. With `depth_test`
    /// a sample is drawn only where the triangle is nearer (smaller depth) than what is
    /// there; without it, later triangles cover earlier ones (painter's order). Vertices
    /// must be finite; triangles of zero area on the sample grid draw nothing.
    pub fn triangle(
        &mut self,
        v: [[f64; 3]; 3],
        depth_test: bool,
        mut shade: impl FnMut(&Fragment) -> Rgb,
    ) {
        let snap = |c: f64| (c * SUB).round() as i64;
        let mut p: [[i64; 2]; 3] = v.map(|q| [snap(q[0]), snap(q[1])]);
        let mut z = v.map(|q| q[2] as f32);
        // Orientation: make the doubled area positive, remembering the permutation.
        let area = edge_function(p[0], p[1], p[2]);
        if area == 0 {
            return;
        }
        let swapped = area < 0;
        if swapped {
            p.swap(1, 2);
            z.swap(1, 2);
        }
        let area = area.abs();
        // Bounding box in samples whose centers may be covered.
        let lo = |k: usize| p.iter().map(|q| q[k]).min().unwrap_or(0);
        let hi = |k: usize| p.iter().map(|q| q[k]).max().unwrap_or(0);
        let first = |c: i64| ((c as f64 / SUB - 0.5).ceil().max(0.0)) as i64;
        let last = |c: i64, n: usize| ((c as f64 / SUB - 0.5).floor() as i64).min(n as i64 - 1);
        let (x0, x1) = (first(lo(0)), last(hi(0), self.width));
        let (y0, y1) = (
            first(lo(1)).max(self.top as i64),
            last(hi(1), self.top + self.height),
        );
        if x0 > x1 || y0 > y1 {
            return;
        }
        // Edge k is opposite vertex k: from p[k+1] to p[k+2].
        let edges: [([i64; 2], [i64; 2]); 3] = [(p[1], p[2]), (p[2], p[0]), (p[0], p[1])];
        // Samples exactly on an edge belong to the triangle for which the edge runs
        // in one fixed half of directions (the neighbour has it reversed).
        let bias: [i64; 3] = edges.map(|(a, b)| {
            let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
            if dy > 0 || (dy == 0 && dx > 0) { 0 } else { -1 }
        });
        let length: [f32; 3] = edges.map(|(a, b)| {
            let (dx, dy) = ((b[0] - a[0]) as f64, (b[1] - a[1]) as f64);
            (dx.hypot(dy) / SUB) as f32
        });
        let half = (SUB / 2.0) as i64;
        let s = SUB as i64;
        let step_x: [i64; 3] = edges.map(|(a, b)| -(b[1] - a[1]) * s);
        let step_y: [i64; 3] = edges.map(|(a, b)| (b[0] - a[0]) * s);
        let start = [x0 * s + half, y0 * s + half];
        let mut row: [i64; 3] = std::array::from_fn(|k| {
            let (a, b) = edges[k];
            edge_function(a, b, start)
        });
        let inv_area = 1.0 / area as f64;
        // Distance to an edge = E / |edge|, in samples (E is in SUB^2 units).
        let to_distance: [f32; 3] =
            std::array::from_fn(|k| (1.0 / (SUB * SUB) / length[k].max(1e-12) as f64) as f32);
        for y in y0..=y1 {
            let mut e = row;
            let line = (y as usize - self.top) * self.width;
            for x in x0..=x1 {
                if e[0] + bias[0] >= 0 && e[1] + bias[1] >= 0 && e[2] + bias[2] >= 0 {
                    let b = e.map(|ek| (ek as f64 * inv_area) as f32);
                    let depth = b[0] * z[0] + b[1] * z[1] + b[2] * z[2];
                    let i = line + x as usize;
                    if !depth_test || depth < self.depth[i] {
                        let edge: [f32; 3] = std::array::from_fn(|k| e[k] as f32 * to_distance[k]);
                        let fragment = if swapped {
                            Fragment {
                                bary: [b[0], b[2], b[1]],
                                edge: [edge[0], edge[2], edge[1]],
                            }
                        } else {
                            Fragment { bary: b, edge }
                        };
                        self.depth[i] = depth;
                        self.color[i] = shade(&fragment);
                    }
                }
                for k in 0..3 {
                    e[k] += step_x[k];
                }
            }
            for k in 0..3 {
                row[k] += step_y[k];
            }
        }
    }

    /// Averages `factor x factor` blocks of samples into pixels, row by row: the
    /// `(width / factor) x (height / factor)` picture (of the band), antialiased.
    pub fn downsample(&self, factor: usize) -> Vec<Rgb> {
        let (w, h) = (self.width / factor, self.height / factor);
        let n = (factor * factor) as u32;
        let mut out = Vec::with_capacity(w * h);
        for y in 0..h {
            for x in 0..w {
                let mut sum = [0u32; 3];
                for j in 0..factor {
                    let row = (y * factor + j) * self.width + x * factor;
                    for c in &self.color[row..row + factor] {
                        for k in 0..3 {
                            sum[k] += u32::from(c[k]);
                        }
                    }
                }
                out.push(sum.map(|s| ((s + n / 2) / n) as u8));
            }
        }
        out
    }
}

/// Twice the signed area of `(a, b, c)`, positive when `c` lies to the right of
/// `a -> b` seen with y down (counter-clockwise on the screen with y down).
fn edge_function(a: [i64; 2], b: [i64; 2], c: [i64; 2]) -> i64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}
