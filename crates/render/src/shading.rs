//! The color of a sample: the face coloring (`|mu|`, checkerboard or plain), Lambert
//! shading in the 3D view, and lines drawn inside the triangles (wireframe, boundary
//! edges, outlines of flipped faces) that the depth test hides like the fills.

use beltrami_mesh::{FaceId, HalfedgeId, Mesh, Point3, Vector2};

use crate::colormap::{CHECKER, INK, MuRange, PLAIN, Rgb, WARNING};
use crate::raster3d::Fragment;

/// The coloring of faces.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Coloring<'a> {
    /// One neutral color.
    Plain,
    /// `|mu|` per face through viridis over `range`.
    Mu { modulus: &'a [f64], range: MuRange },
    /// A checkerboard of the map's image, cut into squares (cubes, for an image in R^3)
    /// of side `cell` from `origin`.
    Checker {
        texture: Texture<'a>,
        origin: [f64; 3],
        cell: f64,
    },
}

/// The coordinates a checkerboard is drawn in.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Texture<'a> {
    /// Per corner in the plane.
    Corners(&'a [Vector2<f64>]),
    /// Per vertex in R^3.
    Vertices(&'a [Point3<f64>]),
}

impl Texture<'_> {
    /// The texture coordinate of corner `h`.
    fn at(&self, mesh: &Mesh, h: HalfedgeId) -> [f64; 3] {
        match self {
            Texture::Corners(c) => [c[h.idx()].x, c[h.idx()].y, 0.0],
            Texture::Vertices(p) => {
                let q = p[mesh.origin(h).idx()];
                [q.x, q.y, q.z]
            }
        }
    }
}

/// Line widths in samples (full widths) and which lines to draw.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Lines<'a> {
    /// Wireframe width, when drawn.
    pub wire: Option<f32>,
    /// Boundary edge width, when drawn here (the uv view strokes them on top instead).
    pub boundary: Option<f32>,
    /// Outline width of flipped faces, with the flags, when drawn here.
    pub flipped: Option<(f32, &'a [bool])>,
}

/// What a triangle of a face knows before its samples are shaded.
pub(crate) struct TriangleShader {
    base: Rgb,
    checker: Option<([[f64; 3]; 3], [f64; 3], f64)>,
    /// Per edge (opposite each vertex): line width and color, when one is drawn.
    lines: [Option<(f32, Rgb, f32)>; 3],
    /// Per-vertex normals for Lambert shading (3D view) and the light direction.
    light: Option<([[f32; 3]; 3], [f32; 3])>,
}

/// The fan triangles of face `f`: corner halfedges and, per triangle vertex, the mesh
/// halfedge of the opposite edge when that edge is a mesh edge (not a quad diagonal).
pub(crate) fn fan(
    mesh: &Mesh,
    f: FaceId,
) -> impl Iterator<Item = ([HalfedgeId; 3], [Option<HalfedgeId>; 3])> {
    let first = mesh.face_halfedge(f).0;
    let n = mesh.face_degree(f) as u32;
    let h = move |k: u32| HalfedgeId(first + k);
    (1..n - 1).map(move |k| {
        (
            [h(0), h(k), h(k + 1)],
            [
                Some(h(k)),
                (k + 1 == n - 1).then(|| h(n - 1)),
                (k == 1).then(|| h(0)),
            ],
        )
    })
}

impl TriangleShader {
    /// The shader of one fan triangle of face `f`.
    pub(crate) fn new<'a>(
        mesh: &Mesh,
        f: FaceId,
        corners: [HalfedgeId; 3],
        edges: [Option<HalfedgeId>; 3],
        coloring: &Coloring<'a>,
        lines: &Lines<'a>,
        light: Option<([[f32; 3]; 3], [f32; 3])>,
    ) -> Self {
        let (base, checker) = match coloring {
            Coloring::Plain => (PLAIN, None),
            Coloring::Mu { modulus, range } => (range.color(modulus[f.idx()]), None),
            Coloring::Checker {
                texture,
                origin,
                cell,
            } => (
                PLAIN,
                Some((corners.map(|h| texture.at(mesh, h)), *origin, *cell)),
            ),
        };
        let flipped = lines.flipped.filter(|(_, flags)| flags[f.idx()]);
        let edge_line = |e: Option<HalfedgeId>| {
            let e = e?;
            if let Some((w, _)) = flipped {
                return Some((w, WARNING, 1.0));
            }
            if let Some(w) = lines.boundary
                && mesh.is_boundary_halfedge(mesh.twin(e))
            {
                return Some((w, INK, 1.0));
            }
            lines.wire.map(|w| (w, INK, 0.6))
        };
        Self {
            base,
            checker,
            lines: edges.map(edge_line),
            light,
        }
    }

    /// The color of a sample.
    pub(crate) fn shade(&self, fragment: &Fragment) -> Rgb {
        let b = fragment.bary;
        let mut color = match &self.checker {
            None => self.base,
            Some((t, origin, cell)) => {
                let mut parity = 0i64;
                for k in 0..3 {
                    let x = f64::from(b[0]) * t[0][k]
                        + f64::from(b[1]) * t[1][k]
                        + f64::from(b[2]) * t[2][k];
                    parity += ((x - origin[k]) / cell).floor() as i64;
                }
                CHECKER[parity.rem_euclid(2) as usize]
            }
        };
        if let Some((normals, light)) = &self.light {
            let n: [f32; 3] = std::array::from_fn(|k| {
                b[0] * normals[0][k] + b[1] * normals[1][k] + b[2] * normals[2][k]
            });
            let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            let cos = if len > 0.0 {
                ((n[0] * light[0] + n[1] * light[1] + n[2] * light[2]) / len).abs()
            } else {
                1.0
            };
            let k = 0.3 + 0.7 * cos;
            color = color.map(|c| (f32::from(c) * k).round() as u8);
        }
        for (line, d) in self.lines.iter().zip(fragment.edge) {
            if let Some((width, ink, alpha)) = line {
                // Coverage of a line of `width` centered on the edge, antialiased over
                // one sample; only the half inside this triangle is drawn here.
                let coverage = (width * 0.5 + 0.5 - d).clamp(0.0, 1.0) * alpha;
                if coverage > 0.0 {
                    color = mix(color, *ink, coverage);
                }
            }
        }
        color
    }
}

/// `a` blended towards `b` by `t` in [0, 1].
pub(crate) fn mix(a: Rgb, b: Rgb, t: f32) -> Rgb {
    std::array::from_fn(|k| {
        (f32::from(a[k]) + (f32::from(b[k]) - f32::from(a[k])) * t).round() as u8
    })
}
