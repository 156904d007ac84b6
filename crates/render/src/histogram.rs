//! Histograms of `|mu|`, like the figures of the quasiconformal-map papers: bars over a
//! range of `|mu|` (`[0, 1]` by default) colored as in the pictures, the share of faces
//! (or of source area) per bar in percent, and a separate red bar for the values at or
//! beyond the top of the range (with the default range, the flipped and collapsed faces).

use beltrami_fem::distortion::DistortionStats;

use crate::colorbar::tick_label;
use crate::colormap::{INK, MuRange, WARNING};
use crate::legend::number;
use crate::scene::FaceDistortion;
use crate::{Picture, RenderError, Size, text};

/// What a bar measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Weighting {
    /// The share of faces.
    #[default]
    Faces,
    /// The share of the source surface's area.
    Area,
}

/// How a histogram is drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HistogramStyle {
    /// Picture size in pixels.
    pub size: Size,
    /// Bars over the range, 1 to [`HistogramStyle::MAX_BINS`].
    pub bins: usize,
    /// The range of `|mu|` the bars cover.
    pub range: MuRange,
    /// Faces or area.
    pub weighting: Weighting,
}

impl HistogramStyle {
    /// The most bars a histogram has.
    pub const MAX_BINS: usize = 1000;
}

impl Default for HistogramStyle {
    /// 1200x800, 50 bars over `[0, 1]`, share of faces.
    fn default() -> Self {
        Self {
            size: Size::new(1200, 800).unwrap_or_default(),
            bins: 50,
            range: MuRange::default(),
            weighting: Weighting::Faces,
        }
    }
}

/// The bars of a histogram, as fractions of the total weight.
#[derive(Debug, Clone, PartialEq)]
pub struct Bars {
    /// The range the bars cover, in equal widths.
    pub range: MuRange,
    /// Fraction in each bar: bar `k` holds `lo + k w <= |mu| < lo + (k + 1) w`.
    pub fractions: Vec<f64>,
    /// Fraction with `|mu| >= hi`.
    pub beyond: f64,
    /// Fraction with `|mu| < lo`.
    pub below: f64,
}

impl Bars {
    /// The bars of the values `modulus` (one per face) with `weights` (one per face, e.g.
    /// areas; `None` weighs every face 1). Zero total weight gives all-zero bars.
    pub fn new(
        modulus: &[f64],
        weights: Option<&[f64]>,
        bins: usize,
        range: MuRange,
    ) -> Result<Self, RenderError> {
        if bins == 0 || bins > HistogramStyle::MAX_BINS {
            return Err(RenderError::Bins {
                got: bins,
                max: HistogramStyle::MAX_BINS,
            });
        }
        if let Some(w) = weights {
            if w.len() != modulus.len() {
                return Err(RenderError::Length {
                    what: "weights",
                    expected: modulus.len(),
                    got: w.len(),
                });
            }
            if let Some(f) = w.iter().position(|x| !(x.is_finite() && *x >= 0.0)) {
                return Err(RenderError::NonFinite {
                    what: "the weight",
                    element: "face",
                    index: f,
                });
            }
        }
        if let Some(f) = modulus.iter().position(|m| !m.is_finite()) {
            return Err(RenderError::NonFinite {
                what: "|mu|",
                element: "face",
                index: f,
            });
        }
        let mut fractions = vec![0.0; bins];
        let (mut beyond, mut below, mut total) = (0.0, 0.0, 0.0);
        let width = (range.hi - range.lo) / bins as f64;
        for (f, &m) in modulus.iter().enumerate() {
            let w = weights.map_or(1.0, |w| w[f]);
            total += w;
            if m >= range.hi {
                beyond += w;
            } else if m < range.lo {
                below += w;
            } else {
                let k = ((m - range.lo) / width) as usize;
                fractions[k.min(bins - 1)] += w;
            }
        }
        if total > 0.0 {
            for x in &mut fractions {
                *x /= total;
            }
            beyond /= total;
            below /= total;
        }
        Ok(Self {
            range,
            fractions,
            beyond,
            below,
        })
    }
}

/// A step of about a fifth of `max` from 1, 2, 5 times a power of ten.
fn nice_step(max: f64) -> f64 {
    let raw = (max / 5.0).max(1e-12);
    let power = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * power)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * power)
}

/// Where the parts of a histogram go, in pixels: the plot area `[left, right] x [top,
/// bottom]` (y down), the beyond bar right of it, and the text scale.
struct HistogramLayout {
    /// Text magnification: one per 400 pixels of the shorter side.
    scale: u32,
    /// `scale` as a pixel multiplier.
    k: i64,
    /// Height of a text line.
    line: i64,
    /// Width of the axis strokes: one per 600 pixels of the shorter side, at least 1.
    unit: f32,
    left: i64,
    top: i64,
    bottom: i64,
    right: i64,
    /// Width of the beyond bar.
    beyond_width: i64,
    plot_w: f64,
    plot_h: f64,
}

impl HistogramLayout {
    /// The layout of a picture of `size`: room for the y labels on the left, the x labels
    /// and axis title below, the title above and the beyond bar on the right. `None` when
    /// no plot area is left.
    fn new(size: Size) -> Option<Self> {
        let short = size.width().min(size.height());
        let scale = (short / 400).max(1);
        let k = i64::from(scale);
        let line = text::height(scale);
        let unit = (short as f32 / 600.0).max(1.0);
        let left = text::width("100.0%", scale) + 6 * k;
        let top = 3 * line;
        let bottom = i64::from(size.height()) - 5 * line;
        let beyond_width = (i64::from(size.width()) / 14).max(4 * line);
        let right = i64::from(size.width()) - beyond_width - 4 * line;
        if right <= left || bottom <= top {
            return None;
        }
        let (plot_w, plot_h) = ((right - left) as f64, (bottom - top) as f64);
        Some(Self {
            scale,
            k,
            line,
            unit,
            left,
            top,
            bottom,
            right,
            beyond_width,
            plot_w,
            plot_h,
        })
    }
}

/// The vertical scale of the bars: fractions `0..=top_value` over the plot's height,
/// with a grid line every `step`.
struct ValueAxis {
    step: f64,
    top_value: f64,
}

impl ValueAxis {
    /// A nice step for the highest bar (the beyond bar included) and the first multiple
    /// of it at or above the highest bar (at least one step).
    fn new(bars: &Bars) -> Self {
        let peak = bars
            .fractions
            .iter()
            .copied()
            .chain([bars.beyond])
            .fold(0.0, f64::max);
        let step = nice_step(if peak > 0.0 { peak } else { 1.0 });
        let top_value = (peak / step).ceil().max(1.0) * step;
        Self { step, top_value }
    }

    /// The picture row of fraction `v`: `bottom - v / top_value * plot_h`.
    fn y_of(&self, layout: &HistogramLayout, v: f64) -> f64 {
        layout.bottom as f64 - v / self.top_value * layout.plot_h
    }
}

/// Draws the histogram of `distortion`'s `|mu|` in `style`.
pub fn render_histogram(
    distortion: &FaceDistortion,
    style: &HistogramStyle,
) -> Result<Picture, RenderError> {
    let weights = match style.weighting {
        Weighting::Faces => None,
        Weighting::Area => Some(distortion.areas.as_slice()),
    };
    let bars = Bars::new(&distortion.modulus, weights, style.bins, style.range)?;
    let size = style.size;
    let mut picture = Picture::new(size);
    let Some(layout) = HistogramLayout::new(size) else {
        return Ok(picture);
    };

    let what = match style.weighting {
        Weighting::Faces => "faces",
        Weighting::Area => "area",
    };
    let title = format!("|\u{b5}| histogram ({} bins, share of {what})", style.bins);
    picture.text(layout.left, layout.line, &title, layout.scale, INK);

    let axis = ValueAxis::new(&bars);
    draw_grid(&mut picture, &layout, &axis);
    draw_bars(&mut picture, &layout, &axis, &bars);
    draw_axes(&mut picture, &layout, &bars);
    draw_legend(&mut picture, &layout, size, &distortion.stats, &bars);
    Ok(picture)
}

/// Draws the horizontal grid lines and their labels (percent), from 0 up to the top
/// value.
fn draw_grid(picture: &mut Picture, layout: &HistogramLayout, axis: &ValueAxis) {
    let HistogramLayout {
        scale,
        k,
        line,
        left,
        right,
        ..
    } = *layout;
    let mut v = 0.0;
    while v <= axis.top_value * (1.0 + 1e-9) {
        let y = axis.y_of(layout, v) as f32;
        picture.stroke(
            &[vec![[left as f32, y], [right as f32, y]]],
            1.0,
            [220, 220, 220],
            1.0,
        );
        let label = format!("{}%", tick_label(100.0 * v));
        let w = text::width(&label, scale);
        picture.text(left - w - 4 * k, y as i64 - line / 2, &label, scale, INK);
        v += axis.step;
    }
}

/// Draws the bars colored by the `|mu|` at their centers, then the beyond bar and its
/// label in the warning color.
fn draw_bars(picture: &mut Picture, layout: &HistogramLayout, axis: &ValueAxis, bars: &Bars) {
    let HistogramLayout {
        scale,
        line,
        left,
        bottom,
        right,
        beyond_width,
        plot_w,
        ..
    } = *layout;
    let n = bars.fractions.len();
    let bar_w = plot_w / n as f64;
    for (i, &f) in bars.fractions.iter().enumerate() {
        if f <= 0.0 {
            continue;
        }
        let center = bars.range.lo + (i as f64 + 0.5) * (bars.range.hi - bars.range.lo) / n as f64;
        let x0 = left as f64 + i as f64 * bar_w;
        let y = axis.y_of(layout, f);
        let gap = if bar_w > 4.0 { 1.0 } else { 0.0 };
        picture.fill_rect(
            x0 as f32,
            y as f32,
            (bar_w - gap).max(1.0) as f32,
            (bottom as f64 - y) as f32,
            bars.range.color(center),
        );
    }
    let bx = right + 2 * line;
    if bars.beyond > 0.0 {
        let y = axis.y_of(layout, bars.beyond);
        picture.fill_rect(
            bx as f32,
            y as f32,
            beyond_width as f32,
            (bottom as f64 - y) as f32,
            WARNING,
        );
    }
    let beyond_label = format!(">={}", tick_label(bars.range.hi));
    picture.text(
        bx + (beyond_width - text::width(&beyond_label, scale)) / 2,
        bottom + line / 2,
        &beyond_label,
        scale,
        WARNING,
    );
}

/// Draws the axes, six x ticks with their `|mu|` labels, and the x axis title.
fn draw_axes(picture: &mut Picture, layout: &HistogramLayout, bars: &Bars) {
    let HistogramLayout {
        scale,
        k,
        line,
        unit,
        left,
        top,
        bottom,
        right,
        plot_w,
        ..
    } = *layout;
    let axes = vec![
        [left as f32, top as f32],
        [left as f32, bottom as f32],
        [right as f32, bottom as f32],
    ];
    picture.stroke(&[axes], unit, INK, 1.0);
    for i in 0..=5 {
        let t = f64::from(i) / 5.0;
        let x = left as f64 + t * plot_w;
        picture.stroke(
            &[vec![
                [x as f32, bottom as f32],
                [x as f32, (bottom + 3 * k) as f32],
            ]],
            unit,
            INK,
            1.0,
        );
        let label = tick_label(bars.range.lo + t * (bars.range.hi - bars.range.lo));
        let w = text::width(&label, scale);
        picture.text(x as i64 - w / 2, bottom + line / 2, &label, scale, INK);
    }
    let axis_title = "|\u{b5}|";
    picture.text(
        left + (right - left - text::width(axis_title, scale)) / 2,
        bottom + 2 * line,
        axis_title,
        scale,
        INK,
    );
}

/// Draws the legend along the bottom edge: face and flipped counts (the latter in the
/// warning color when nonzero), the mean, max and area-weighted L2 of `|mu|`, and the
/// share below the range when there is one.
fn draw_legend(
    picture: &mut Picture,
    layout: &HistogramLayout,
    size: Size,
    s: &DistortionStats,
    bars: &Bars,
) {
    let HistogramLayout {
        scale,
        k,
        line,
        left,
        ..
    } = *layout;
    let mut items = vec![
        format!("faces {}", s.faces),
        format!("flipped {}", s.flipped),
        format!("mean {}", number(s.mu_mean)),
        format!("max {}", number(s.mu_max)),
        format!("L2 (area) {}", number(s.mu_l2)),
    ];
    if bars.below > 0.0 {
        items.push(format!(
            "{}% below {}",
            tick_label(100.0 * bars.below),
            tick_label(bars.range.lo)
        ));
    }
    let mut x = left;
    let y = i64::from(size.height()) - line - line / 2;
    for (i, item) in items.iter().enumerate() {
        let color = if i == 1 && s.flipped > 0 {
            WARNING
        } else {
            INK
        };
        x += picture.text(x, y, item, scale, color) + 2 * text::GLYPH * k;
    }
}
