//! `beltrami render`: a picture of a mesh or of a map as PNG.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context as _, bail};
use beltrami_fem::ReferenceNormal;
use beltrami_render::{Camera, ColorBy, Layout, MuRange, Scene, Size, Style, View, check_png_path};
use clap::{Args, ValueEnum};

use super::distortion::{source_reference_note, target_normals};
use super::load::load_mesh;
use super::picture::load_map;

/// Views of `--view`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ViewArg {
    /// The parameter domain (texture coordinates), flat.
    Uv,
    /// The surface in 3D (MAPPED's positions for a map into R^3, else MESH), shaded.
    #[value(name = "3d")]
    ThreeD,
    /// Source and image side by side.
    Both,
}

/// Colorings of `--color`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ColorArg {
    /// |mu| per face (viridis, color bar).
    Mu,
    /// A checkerboard of the map's image, carried to the source.
    Checker,
    /// One neutral color.
    None,
}

#[derive(Debug, Args)]
pub struct RenderArgs {
    /// Mesh file (.obj, .ply, .stl, .off, .gltf, .glb); its texture coordinates (vt) are the map when
    /// there is no --map.
    pub mesh: PathBuf,
    /// The map: a mesh with MESH's faces whose texture coordinates (a map into the
    /// plane) or, without them, whose positions (a map into R^3) are the images of
    /// MESH's vertices (e.g. the output of `param` or `qc`).
    #[arg(long = "map", value_name = "MAPPED")]
    pub map: Option<PathBuf>,
    /// For a map into R^3: the surface the map lands on; flips are judged against its
    /// normals at the images, as in `beltrami distortion --target`. Without it the
    /// image's shape decides: +z for an image in the plane z = 0, the radial direction
    /// for one on a sphere about the origin, else MESH's normals.
    #[arg(long, value_name = "TARGET")]
    pub target: Option<PathBuf>,
    /// What to draw [default: both with a map, else 3d].
    #[arg(long, value_enum)]
    pub view: Option<ViewArg>,
    /// Face coloring [default: mu with a map, else none].
    #[arg(long, value_enum)]
    pub color: Option<ColorArg>,
    /// Draw every edge.
    #[arg(long)]
    pub wire: bool,
    /// Picture size in pixels, WIDTHxHEIGHT.
    #[arg(long, default_value = "1600x1200")]
    pub size: Size,
    /// 3D camera: azimuth about +y (from +z towards +x) and elevation, in degrees.
    #[arg(long, default_value = "0,0", allow_hyphen_values = true)]
    pub camera: Camera,
    /// |mu| range of the colormap, LO,HI.
    #[arg(long = "mu-range", default_value = "0,1")]
    pub mu_range: MuRange,
    /// Checkerboard squares across the longer side of the map's image.
    #[arg(long = "checker-cells", default_value_t = 16, value_parser = clap::value_parser!(u32).range(1..=10000))]
    pub checker_cells: u32,
    /// Repair what can be repaired safely in the input (see `beltrami info --repair`).
    #[arg(long)]
    pub repair: bool,
    /// Output picture (.png).
    #[arg(short, long)]
    pub output: PathBuf,
}

pub fn run(args: &RenderArgs, quiet: bool) -> anyhow::Result<()> {
    check_png_path(&args.output)?;
    super::outputs::check(&[("-o", Some(&args.output))])?;
    let start = Instant::now();
    let (loaded, image) = load_map(&args.mesh, args.map.as_deref(), args.repair, quiet)?;
    let has_map = image.is_some();
    let mesh = &loaded.mesh;
    let mut notes = Vec::new();
    let normals = match (&args.target, &image) {
        (None, _) => None,
        (Some(path), Some(Layout::Space(points))) => {
            let target = load_mesh(path, args.repair, quiet)?.mesh;
            let (normals, note) = target_normals(&target.mesh, mesh, points, path)?;
            notes.extend(note);
            Some(normals)
        }
        (Some(_), _) => {
            bail!("--target applies only to a map into R^3 (MAPPED with positions and no vt)")
        }
    };
    let reference = match (&normals, &image) {
        (Some(normals), _) => Some(ReferenceNormal::PerFace(normals)),
        (None, Some(Layout::Space(points))) => {
            let chosen = ReferenceNormal::for_image(points);
            notes.extend(source_reference_note(chosen, &args.mesh));
            Some(chosen)
        }
        (None, _) => None,
    };
    let scene = Scene::with_reference(mesh, image, reference)
        .with_context(|| format!("drawing {}", args.mesh.display()))?;
    if !quiet {
        for note in &notes {
            eprintln!("note: {note}");
        }
    }
    let view = match args.view {
        Some(ViewArg::Uv) => View::Uv,
        Some(ViewArg::ThreeD) => View::Surface,
        Some(ViewArg::Both) => View::Both,
        None if has_map => View::Both,
        None => View::Surface,
    };
    let color = match args.color {
        Some(ColorArg::Mu) => ColorBy::Mu,
        Some(ColorArg::Checker) => ColorBy::Checker,
        Some(ColorArg::None) => ColorBy::Plain,
        None if has_map => ColorBy::Mu,
        None => ColorBy::Plain,
    };
    let style = Style {
        size: args.size,
        view,
        color,
        wire: args.wire,
        camera: args.camera,
        mu_range: args.mu_range,
        checker_cells: args.checker_cells,
        ..Style::default()
    };
    let picture = beltrami_render::render(&scene, &style).map_err(|e| match &args.map {
        Some(_) => anyhow::anyhow!("{e}"),
        None => anyhow::anyhow!(
            "{e}\nhint: {} has no map on it: give --map MAPPED, or a mesh with vt",
            args.mesh.display()
        ),
    })?;
    picture.write_png(&args.output)?;
    if !quiet {
        let judged = match (scene.reference(), &args.target) {
            (None, _) => String::new(),
            (Some(_), Some(_)) => ", flips judged against TARGET's normals".to_string(),
            (Some(name), None) => format!(", flips judged against the {name} normal"),
        };
        println!(
            "{} -> {} ({}, {:.3} s{judged})",
            args.mesh.display(),
            args.output.display(),
            args.size,
            start.elapsed().as_secs_f64()
        );
    }
    Ok(())
}
