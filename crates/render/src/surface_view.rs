//! The 3D view: a surface seen by the orbit [`Camera`](crate::Camera) in orthographic
//! projection, z-buffered, with two-sided Lambert shading from smooth (area-weighted)
//! vertex normals and a light above-left of the camera. Wireframe, boundary edges
//! (thick, dark) and outlines of flipped faces (warning color) are drawn inside the
//! triangles, so hidden parts stay hidden.

use beltrami_mesh::{Mesh, Point3, Vector3};

use crate::colormap::BACKGROUND;
use crate::raster3d::{Raster, bands};
use crate::shading::{Coloring, Lines, TriangleShader, fan};
use crate::viewport::{Fit, Rect, bounds};
use crate::{Camera, Picture};

/// What the 3D view draws.
pub(crate) struct SurfaceView<'a> {
    pub mesh: &'a Mesh,
    /// One position per vertex.
    pub positions: &'a [Point3<f64>],
    pub coloring: Coloring<'a>,
    pub wire: bool,
    /// Flipped faces, outlined when given.
    pub flipped: Option<&'a [bool]>,
    pub camera: Camera,
}

/// Draws `view` into the panel `rect` at `samples` samples per pixel and axis; `unit` is
/// the width of a thin line in pixels.
pub(crate) fn draw(
    picture: &mut Picture,
    rect: Rect,
    samples: u32,
    unit: f32,
    view: &SurfaceView<'_>,
) {
    let mesh = view.mesh;
    let (w, h) = (
        rect.width as usize * samples as usize,
        rect.height as usize * samples as usize,
    );
    let basis = view.camera.basis();
    let projected: Vec<[f64; 3]> = view.positions.iter().map(|p| basis.project(p)).collect();
    let Some((lo, hi)) = bounds(
        mesh.faces()
            .flat_map(|f| mesh.face_vertices(f))
            .map(|v| [projected[v.idx()][0], projected[v.idx()][1]]),
    ) else {
        return;
    };
    let fit = Fit::new(lo, hi, w as f64, h as f64);
    let screen: Vec<[f64; 3]> = projected
        .iter()
        .map(|p| {
            let q = fit.apply(p[0], p[1]);
            [q[0], q[1], p[2]]
        })
        .collect();
    let normals = vertex_normals(mesh, view.positions);
    let light = {
        let l = 0.35 * basis.right + 0.45 * basis.up + 0.82 * basis.back;
        let l = l / l.norm();
        [l.x as f32, l.y as f32, l.z as f32]
    };
    let line = unit * samples as f32;
    let lines = Lines {
        wire: view.wire.then_some(line),
        // Only the half inside the surface shows: twice as wide.
        boundary: Some(4.0 * line),
        flipped: view.flipped.map(|flags| (3.0 * line, flags)),
    };
    // Band by band, so that memory follows the pixels, not the samples.
    for (top, rows) in bands(w, h, samples as usize) {
        let mut raster = Raster::band(w, top, rows, BACKGROUND);
        for f in mesh.faces() {
            for (corners, edges) in fan(mesh, f) {
                let vertices = corners.map(|c| mesh.origin(c).idx());
                let shader = TriangleShader::new(
                    mesh,
                    f,
                    corners,
                    edges,
                    &view.coloring,
                    &lines,
                    Some((vertices.map(|v| normals[v]), light)),
                );
                raster.triangle(vertices.map(|v| screen[v]), true, |fr| shader.shade(fr));
            }
        }
        picture.blit(
            rect.x,
            rect.y + (top / samples as usize) as u32,
            rect.width as usize,
            &raster.downsample(samples as usize),
        );
    }
}

/// Unit vertex normals: the sums of the incident fan triangles' vector areas.
fn vertex_normals(mesh: &Mesh, positions: &[Point3<f64>]) -> Vec<[f32; 3]> {
    let mut sum = vec![Vector3::<f64>::zeros(); positions.len()];
    for f in mesh.faces() {
        let (v, n) = mesh.face_vertex_array(f);
        let p = |k: usize| positions[v[k].idx()];
        let mut area = Vector3::zeros();
        for k in 1..n - 1 {
            area += (p(k) - p(0)).cross(&(p(k + 1) - p(0)));
        }
        for vertex in &v[..n] {
            sum[vertex.idx()] += area;
        }
    }
    sum.iter()
        .map(|s| {
            let len = s.norm();
            if len > 0.0 {
                [(s.x / len) as f32, (s.y / len) as f32, (s.z / len) as f32]
            } else {
                [0.0; 3]
            }
        })
        .collect()
}
