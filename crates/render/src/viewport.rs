//! Panels of a picture and the similarity that fits a drawing into one.

/// A rectangle of the picture in pixels (y down).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Rect {
    pub x: u32,
    pub y: u32,
    pub width: u32,
    pub height: u32,
}

/// Maps drawing coordinates (x right, y up) into a panel's samples (y down), keeping
/// the aspect ratio and centering, with a margin of 4% of the panel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Fit {
    scale: f64,
    center: [f64; 2],
    offset: [f64; 2],
}

impl Fit {
    /// The fit of the box `lo..hi` into a panel of `width x height` samples.
    pub(crate) fn new(lo: [f64; 2], hi: [f64; 2], width: f64, height: f64) -> Self {
        let span = [hi[0] - lo[0], hi[1] - lo[1]];
        let room = [width * 0.92, height * 0.92];
        let scale = [room[0] / span[0], room[1] / span[1]]
            .into_iter()
            .filter(|s| s.is_finite() && *s > 0.0)
            .fold(f64::INFINITY, f64::min);
        Self {
            scale: if scale.is_finite() { scale } else { 1.0 },
            center: [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0],
            offset: [width / 2.0, height / 2.0],
        }
    }

    /// Where a drawing point goes, in samples (y down).
    pub(crate) fn apply(&self, x: f64, y: f64) -> [f64; 2] {
        [
            self.offset[0] + (x - self.center[0]) * self.scale,
            self.offset[1] - (y - self.center[1]) * self.scale,
        ]
    }
}

/// The bounding box of points in the plane (`None` for no points).
pub(crate) fn bounds(points: impl Iterator<Item = [f64; 2]>) -> Option<([f64; 2], [f64; 2])> {
    points.fold(None, |acc, p| {
        let (lo, hi) = acc.unwrap_or((p, p));
        Some((
            [lo[0].min(p[0]), lo[1].min(p[1])],
            [hi[0].max(p[0]), hi[1].max(p[1])],
        ))
    })
}
