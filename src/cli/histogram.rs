//! `beltrami histogram`: the histogram of |mu| of a map as PNG.

use std::path::PathBuf;

use anyhow::{Context as _, bail};
use beltrami_render::histogram::{HistogramStyle, Weighting, render_histogram};
use beltrami_render::{MuRange, Scene, Size, check_png_path};
use clap::Args;

use super::picture::load_map;

#[derive(Debug, Args)]
pub struct HistogramArgs {
    /// Mesh file (.obj, .ply, .stl, .off, .gltf, .glb); its texture coordinates (vt) are the map when no
    /// MAPPED is given.
    pub mesh: PathBuf,
    /// The map: a mesh with MESH's faces whose texture coordinates or, without them,
    /// positions are the images of MESH's vertices.
    pub mapped: Option<PathBuf>,
    /// Weigh faces by their source area instead of counting them.
    #[arg(long)]
    pub area: bool,
    /// Number of bars over the |mu| range.
    #[arg(long, default_value_t = 50, value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub bins: u32,
    /// |mu| range of the bars, LO,HI (values at or above HI get their own bar).
    #[arg(long = "mu-range", default_value = "0,1")]
    pub mu_range: MuRange,
    /// Picture size in pixels, WIDTHxHEIGHT.
    #[arg(long, default_value = "1200x800")]
    pub size: Size,
    /// Repair what can be repaired safely in the input (see `beltrami info --repair`).
    #[arg(long)]
    pub repair: bool,
    /// Output picture (.png).
    #[arg(short, long)]
    pub output: PathBuf,
}

pub fn run(args: &HistogramArgs, quiet: bool) -> anyhow::Result<()> {
    check_png_path(&args.output)?;
    super::outputs::check(&[("-o", Some(&args.output))])?;
    let (loaded, image) = load_map(&args.mesh, args.mapped.as_deref(), args.repair, quiet)?;
    if image.is_none() {
        bail!(
            "{} has no texture coordinates (vt): give the map as MAPPED",
            args.mesh.display()
        );
    }
    let scene = Scene::new(&loaded.mesh, image)
        .with_context(|| format!("measuring the map of {}", args.mesh.display()))?;
    let Some(distortion) = scene.distortion() else {
        bail!("no map to measure");
    };
    let style = HistogramStyle {
        size: args.size,
        bins: args.bins as usize,
        range: args.mu_range,
        weighting: if args.area {
            Weighting::Area
        } else {
            Weighting::Faces
        },
    };
    render_histogram(distortion, &style)?.write_png(&args.output)?;
    if !quiet {
        let s = &distortion.stats;
        println!(
            "{} -> {}: {} faces, {} flipped, |mu| mean {:.4e} max {:.4e}",
            args.mesh.display(),
            args.output.display(),
            s.faces,
            s.flipped,
            s.mu_mean,
            s.mu_max
        );
    }
    Ok(())
}
