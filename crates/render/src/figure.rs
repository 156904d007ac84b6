//! A picture of a scene: one or two panels (uv view, 3D view), a color bar when faces
//! are colored by `|mu|`, panel titles above and a legend below.

use std::borrow::Cow;

use beltrami_mesh::{Mesh, Point3, Vector2};

use crate::colormap::INK;
use crate::scene::{Layout, Scene};
use crate::shading::{Coloring, Texture};
use crate::surface_view::{self, SurfaceView};
use crate::uv_view::{self, UvView};
use crate::viewport::Rect;
use crate::{Camera, MuRange, Picture, RenderError, Size, colorbar, legend, text};

/// Which view to draw.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum View {
    /// The parameter domain: the map's texture coordinates (or a planar mesh's own
    /// positions when there is no map), flat.
    Uv,
    /// The surface in 3D: the image of a map into R^3, else the mesh itself.
    Surface,
    /// Side by side: the source (the mesh, flat when it lies in the plane z = 0) on the
    /// left and the map's image on the right, with the same coloring.
    Both,
}

/// How faces are colored.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ColorBy {
    /// `|mu|` of the map per face, viridis over the style's [`MuRange`].
    Mu,
    /// A checkerboard drawn on the map's image (squares in the plane, cubes in R^3) and
    /// carried to the source: it stays square where the map is conformal.
    Checker,
    /// One neutral color.
    Plain,
}

/// Everything about a picture except its content.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Style {
    /// Picture size in pixels.
    pub size: Size,
    /// The view.
    pub view: View,
    /// The face coloring.
    pub color: ColorBy,
    /// Draw every edge (thin, translucent).
    pub wire: bool,
    /// Where the 3D view looks from.
    pub camera: Camera,
    /// The `|mu|` range of the colormap.
    pub mu_range: MuRange,
    /// Squares of the checkerboard across the longer side of the image's bounding box
    /// (0 counts as 1).
    pub checker_cells: u32,
    /// Samples per pixel along each axis for antialiasing, 1 to 4 (2 by default:
    /// 4 samples per pixel).
    pub samples: u32,
}

impl Default for Style {
    /// 1600x1200, both views, `|mu|` colors over `[0, 1]`, no wireframe, camera
    /// `(0, 0)`, 16 checker cells, 2x2 samples per pixel.
    fn default() -> Self {
        Self {
            size: Size::default(),
            view: View::Both,
            color: ColorBy::Mu,
            wire: false,
            camera: Camera::default(),
            mu_range: MuRange::default(),
            checker_cells: 16,
            samples: 2,
        }
    }
}

/// One panel's content.
enum Panel<'a> {
    Flat(Cow<'a, [Vector2<f64>]>),
    Surface(&'a [Point3<f64>]),
}

/// Draws `scene` in `style`.
///
/// Fails when the view or the coloring needs a map the scene does not have: the uv view
/// needs texture coordinates (or a mesh in the plane z = 0), `both`, `mu` and
/// `checker` need a map.
pub fn render(scene: &Scene<'_>, style: &Style) -> Result<Picture, RenderError> {
    let mesh = scene.mesh();
    let distortion = scene.distortion();
    let coloring = coloring(scene, style)?;
    let panels = panels(scene, style.view)?;

    let size = style.size;
    let mut picture = Picture::new(size);
    let short = size.width().min(size.height());
    let scale = (short / 500).max(1);
    let unit = (short as f32 / 800.0).max(1.0);
    let samples = style.samples.clamp(1, 4);
    let pad = 6 * scale;
    let line = text::height(scale) as u32;
    let strip = line + 2 * pad;
    let bar = if style.color == ColorBy::Mu {
        colorbar::width(scale) + pad
    } else {
        0
    };
    let area_width = size.width().saturating_sub(bar);
    let area_height = size.height().saturating_sub(2 * strip);
    let n = panels.len() as u32;
    let panel_width = area_width / n;
    let flipped = distortion.map(|d| d.flipped.as_slice());
    for (i, (panel, title)) in panels.iter().enumerate() {
        let rect = Rect {
            x: i as u32 * panel_width,
            y: strip,
            width: panel_width,
            height: area_height,
        };
        if rect.width == 0 || rect.height == 0 {
            continue;
        }
        match panel {
            Panel::Flat(corners) => uv_view::draw(
                &mut picture,
                rect,
                samples,
                unit,
                &UvView {
                    mesh,
                    corners,
                    coloring,
                    wire: style.wire,
                    flipped,
                },
            ),
            Panel::Surface(positions) => surface_view::draw(
                &mut picture,
                rect,
                samples,
                unit,
                &SurfaceView {
                    mesh,
                    positions,
                    coloring,
                    wire: style.wire,
                    flipped,
                    camera: style.camera,
                },
            ),
        }
        let x = i64::from(rect.x) + (i64::from(rect.width) - text::width(title, scale)) / 2;
        picture.text(x, i64::from(pad), title, scale, INK);
    }
    if style.color == ColorBy::Mu {
        let rect = Rect {
            x: area_width + pad,
            y: strip,
            width: colorbar::width(scale),
            height: area_height,
        };
        colorbar::draw(&mut picture, rect, style.mu_range, scale);
    }
    let items = legend::items(mesh.face_count(), distortion);
    legend::draw(
        &mut picture,
        i64::from(pad) * 2,
        i64::from(size.height() - strip + pad),
        &items,
        scale,
    );
    Ok(picture)
}

/// The panels of `view` for `scene`, left to right, with their titles; fails when the
/// view needs a map the scene does not have.
fn panels<'s>(
    scene: &'s Scene<'_>,
    view: View,
) -> Result<Vec<(Panel<'s>, &'static str)>, RenderError> {
    let mesh = scene.mesh();
    Ok(match view {
        View::Uv => match scene.image() {
            Some(Layout::Plane(c)) => {
                vec![(Panel::Flat(Cow::Borrowed(c)), "parameter domain (uv)")]
            }
            None if scene.planar_source() => {
                vec![(Panel::Flat(source_flat(mesh)?), "mesh (plane)")]
            }
            _ => {
                return Err(RenderError::Missing(
                    "the uv view needs texture coordinates (vt): give a map into the plane".into(),
                ));
            }
        },
        View::Surface => match scene.image() {
            Some(Layout::Space(p)) => vec![(Panel::Surface(p), "image (3D)")],
            _ => vec![(Panel::Surface(mesh.positions()), "surface (3D)")],
        },
        View::Both => {
            let Some(image) = scene.image() else {
                return Err(RenderError::Missing(
                    "the side-by-side view needs a map: texture coordinates (vt) or mapped positions"
                        .into(),
                ));
            };
            let source = if scene.planar_source() {
                (Panel::Flat(source_flat(mesh)?), "source (plane)")
            } else {
                (Panel::Surface(mesh.positions()), "source (3D)")
            };
            vec![source, image_panel(image)]
        }
    })
}

/// The mesh, lying in the plane z = 0, as a planar layout of its vertices' `(x, y)`.
fn source_flat(mesh: &Mesh) -> Result<Cow<'static, [Vector2<f64>]>, RenderError> {
    let xy: Vec<Vector2<f64>> = mesh
        .positions()
        .iter()
        .map(|p| Vector2::new(p.x, p.y))
        .collect();
    match Layout::plane_from_vertices(mesh, &xy)? {
        Layout::Plane(c) => Ok(Cow::Owned(c)),
        Layout::Space(_) => unreachable!("plane_from_vertices makes a planar layout"),
    }
}

/// The panel of a map's image and its title.
fn image_panel(layout: &Layout) -> (Panel<'_>, &'static str) {
    match layout {
        Layout::Plane(c) => (Panel::Flat(Cow::Borrowed(c.as_slice())), "image (uv)"),
        Layout::Space(p) => (Panel::Surface(p.as_slice()), "image (3D)"),
    }
}

/// The face coloring of `style` for `scene`.
fn coloring<'a>(scene: &'a Scene<'_>, style: &Style) -> Result<Coloring<'a>, RenderError> {
    let needs_map = |what: &str| {
        RenderError::Missing(format!(
            "coloring by {what} needs a map: texture coordinates (vt) or mapped positions"
        ))
    };
    Ok(match style.color {
        ColorBy::Plain => Coloring::Plain,
        ColorBy::Mu => Coloring::Mu {
            modulus: &scene.distortion().ok_or_else(|| needs_map("|mu|"))?.modulus,
            range: style.mu_range,
        },
        ColorBy::Checker => {
            let image = scene.image().ok_or_else(|| needs_map("a checkerboard"))?;
            let mesh = scene.mesh();
            let (texture, points): (Texture<'a>, Vec<[f64; 3]>) = match image {
                Layout::Plane(c) => (
                    Texture::Corners(c),
                    mesh.faces()
                        .flat_map(|f| mesh.face_halfedges(f))
                        .map(|h| [c[h.idx()].x, c[h.idx()].y, 0.0])
                        .collect(),
                ),
                Layout::Space(p) => (
                    Texture::Vertices(p),
                    p.iter().map(|q| [q.x, q.y, q.z]).collect(),
                ),
            };
            let mut lo = [f64::INFINITY; 3];
            let mut hi = [f64::NEG_INFINITY; 3];
            for p in &points {
                for k in 0..3 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
            let extent = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max);
            let cell = if extent > 0.0 {
                extent / f64::from(style.checker_cells.max(1))
            } else {
                1.0
            };
            Coloring::Checker {
                texture,
                origin: lo,
                cell,
            }
        }
    })
}
