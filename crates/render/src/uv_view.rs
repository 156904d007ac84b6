//! The uv view: a map's parameter domain (or a planar mesh) drawn flat, x to the right
//! and y up, triangles filled with the coloring; boundary loops stroked thick and
//! flipped faces outlined in the warning color on top of everything, with a ring
//! around those too small to see.

use beltrami_mesh::{Mesh, Vector2};

use crate::Picture;
use crate::colormap::{BACKGROUND, INK, WARNING};
use crate::raster3d::{Raster, bands};
use crate::shading::{Coloring, Lines, TriangleShader, fan};
use crate::viewport::{Fit, Rect, bounds};

/// What the uv view draws.
pub(crate) struct UvView<'a> {
    pub mesh: &'a Mesh,
    /// One point per face corner (see [`crate::Layout::Plane`]).
    pub corners: &'a [Vector2<f64>],
    pub coloring: Coloring<'a>,
    pub wire: bool,
    /// Flipped faces, outlined when given.
    pub flipped: Option<&'a [bool]>,
}

/// Draws `view` into the panel `rect` at `samples` samples per pixel and axis; `unit` is
/// the width of a thin line in pixels.
pub(crate) fn draw(picture: &mut Picture, rect: Rect, samples: u32, unit: f32, view: &UvView<'_>) {
    let mesh = view.mesh;
    let s = f64::from(samples);
    let (w, h) = (
        rect.width as usize * samples as usize,
        rect.height as usize * samples as usize,
    );
    let corner_points = mesh
        .faces()
        .flat_map(|f| mesh.face_halfedges(f))
        .map(|h| [view.corners[h.idx()].x, view.corners[h.idx()].y]);
    let Some((lo, hi)) = bounds(corner_points) else {
        return;
    };
    let fit = Fit::new(lo, hi, w as f64, h as f64);
    let at = |h: beltrami_mesh::HalfedgeId| {
        let p = view.corners[h.idx()];
        let q = fit.apply(p.x, p.y);
        [q[0], q[1], 0.0]
    };
    let lines = Lines {
        wire: view.wire.then_some(unit * samples as f32),
        boundary: None,
        flipped: None,
    };
    let is_flipped = |f: beltrami_mesh::FaceId| view.flipped.is_some_and(|fl| fl[f.idx()]);
    // Band by band, so that memory follows the pixels, not the samples.
    for (top, rows) in bands(w, h, samples as usize) {
        let mut raster = Raster::band(w, top, rows, BACKGROUND);
        // Flipped faces last, so that they cover what they fold over.
        for pass in [false, true] {
            for f in mesh.faces().filter(|&f| is_flipped(f) == pass) {
                for (corners, edges) in fan(mesh, f) {
                    let shader =
                        TriangleShader::new(mesh, f, corners, edges, &view.coloring, &lines, None);
                    raster.triangle(corners.map(at), false, |fr| shader.shade(fr));
                }
            }
        }
        picture.blit(
            rect.x,
            rect.y + (top / samples as usize) as u32,
            rect.width as usize,
            &raster.downsample(samples as usize),
        );
    }

    // Overlays, in pixels.
    let to_pixel = |h: beltrami_mesh::HalfedgeId| {
        let q = at(h);
        [
            (q[0] / s) as f32 + rect.x as f32,
            (q[1] / s) as f32 + rect.y as f32,
        ]
    };
    let boundary: Vec<Vec<[f32; 2]>> = mesh
        .halfedges()
        .filter(|&b| mesh.is_boundary_halfedge(b))
        .map(|b| {
            // The face halfedge on the other side runs target(b) -> origin(b).
            let t = mesh.twin(b);
            vec![to_pixel(t), to_pixel(mesh.next(t))]
        })
        .collect();
    picture.stroke(&boundary, 2.0 * unit, INK, 1.0);
    if let Some(flags) = view.flipped {
        let mut outlines = Vec::new();
        let mut rings = Vec::new();
        for f in mesh.faces().filter(|f| flags[f.idx()]) {
            let mut line: Vec<[f32; 2]> = mesh.face_halfedges(f).map(to_pixel).collect();
            let (a, b) = bounds(line.iter().map(|p| [f64::from(p[0]), f64::from(p[1])]))
                .unwrap_or(([0.0; 2], [0.0; 2]));
            if (b[0] - a[0]).max(b[1] - a[1]) < f64::from(6.0 * unit) {
                rings.push([((a[0] + b[0]) / 2.0) as f32, ((a[1] + b[1]) / 2.0) as f32]);
            }
            line.push(line[0]);
            outlines.push(line);
        }
        picture.stroke(&outlines, 1.5 * unit, WARNING, 1.0);
        let ring_lines: Vec<Vec<[f32; 2]>> = rings
            .iter()
            .map(|c| {
                let r = 6.0 * unit;
                (0..=24)
                    .map(|k| {
                        let t = k as f32 * std::f32::consts::TAU / 24.0;
                        [c[0] + r * t.cos(), c[1] + r * t.sin()]
                    })
                    .collect()
            })
            .collect();
        picture.stroke(&ring_lines, 1.5 * unit, WARNING, 1.0);
    }
}
