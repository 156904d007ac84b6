//! `beltrami bench render`: the cost of a picture on generated grids of up to ~1M
//! triangles, one thread.
//!
//! The grid is the unit square, mapped by a smooth non-conformal map into the plane
//! (`uv` view) and lifted onto a wavy height field (`3d` view), so both rasterizers see
//! a full-size mesh with |mu| colors or a checkerboard. It times the scene (measuring
//! |mu| and flips through the fem crate), each picture and the PNG encoding.

use super::fastest;
use beltrami_mesh::primitives::{Cells, grid};
use beltrami_mesh::{Mesh, Point3, Vector2};
use beltrami_render::{ColorBy, Layout, Scene, Size, Style, View, render};
use clap::Args;

#[derive(Debug, Args)]
pub struct RenderArgs {
    /// Sizes of the generated triangle grids, in triangles.
    #[arg(long, value_delimiter = ',', default_value = "100000,1000000")]
    pub triangles: Vec<usize>,
    /// Picture size.
    #[arg(long, default_value = "1600x1200")]
    pub size: Size,
    /// Runs per figure; the fastest is printed.
    #[arg(long, default_value_t = 3)]
    pub repeat: usize,
}

pub fn run(args: &RenderArgs) -> anyhow::Result<()> {
    println!(
        "| mesh | faces | vertices | view | coloring | scene s | picture s | PNG encode s | PNG KB |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for &triangles in &args.triangles {
        let n = ((triangles as f64 / 2.0).sqrt().round() as usize).max(1);
        let mesh = Mesh::from_soup(&grid(n, n, Cells::Triangles))?;
        let uv: Vec<Vector2<f64>> = mesh
            .positions()
            .iter()
            .map(|p| Vector2::new(p.x + 0.3 * p.y * p.y, p.y + 0.1 * (3.0 * p.x).sin()))
            .collect();
        let wavy: Vec<Point3<f64>> = mesh
            .positions()
            .iter()
            .map(|p| Point3::new(p.x, 0.15 * (6.0 * p.x).sin() * (4.0 * p.y).cos(), -p.y))
            .collect();
        let wavy_mesh = {
            let mut soup = grid(n, n, Cells::Triangles);
            soup.positions = wavy;
            Mesh::from_soup(&soup)?
        };
        let cases: [(&str, &Mesh, View, ColorBy); 4] = [
            ("square", &mesh, View::Uv, ColorBy::Mu),
            ("square", &mesh, View::Both, ColorBy::Checker),
            ("wavy", &wavy_mesh, View::Surface, ColorBy::Mu),
            ("wavy", &wavy_mesh, View::Both, ColorBy::Checker),
        ];
        for (name, m, view, color) in cases {
            let (scene_s, scene) = fastest(args.repeat, || {
                Ok(Scene::new(m, Some(Layout::plane_from_vertices(m, &uv)?))?)
            })?;
            let style = Style {
                size: args.size,
                view,
                color,
                camera: beltrami_render::Camera::new(20.0, 30.0)?,
                ..Style::default()
            };
            let (picture_s, picture) = fastest(args.repeat, || Ok(render(&scene, &style)?))?;
            let (encode_s, bytes) = fastest(args.repeat, || Ok(picture.encode_png()?))?;
            println!(
                "| {name} {n}x{n} | {} | {} | {} | {} | {scene_s:.3} | {picture_s:.3} | {encode_s:.3} | {} |",
                mesh.face_count(),
                mesh.vertex_count(),
                match view {
                    View::Uv => "uv",
                    View::Surface => "3d",
                    View::Both => "both",
                },
                match color {
                    ColorBy::Mu => "mu",
                    ColorBy::Checker => "checker",
                    ColorBy::Plain => "none",
                },
                bytes.len() / 1024
            );
        }
    }
    Ok(())
}
