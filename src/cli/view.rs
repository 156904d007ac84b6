//! `beltrami view`: a self-contained HTML page of a mesh or of a map, to turn in a
//! browser or send to a colleague.

use std::io::Write as _;
use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context as _, bail};
use beltrami_mesh::io::write_atomically;
use beltrami_render::{MuRange, Scene, html_page};
use clap::Args;

use super::picture::load_map;

#[derive(Debug, Args)]
pub struct ViewArgs {
    /// Mesh file (.obj, .ply, .stl, .off, .gltf, .glb); its texture coordinates (vt) are
    /// the map when there is no --map.
    pub mesh: PathBuf,
    /// The map: a mesh with MESH's faces whose texture coordinates (a map into the
    /// plane) or, without them, whose positions (a map into R^3) are the images of
    /// MESH's vertices (e.g. the output of `param`, `qc` or `register`).
    #[arg(long = "map", value_name = "MAPPED")]
    pub map: Option<PathBuf>,
    /// |mu| range of the colormap, LO,HI.
    #[arg(long = "mu-range", default_value = "0,1")]
    pub mu_range: MuRange,
    /// The page's title [default: the file names].
    #[arg(long)]
    pub title: Option<String>,
    /// Repair what can be repaired safely in the input (see `beltrami info --repair`).
    #[arg(long)]
    pub repair: bool,
    /// Output page (.html).
    #[arg(short, long)]
    pub output: PathBuf,
}

pub fn run(args: &ViewArgs, quiet: bool) -> anyhow::Result<()> {
    let extension = args.output.extension().and_then(|e| e.to_str());
    if !extension.is_some_and(|e| e.eq_ignore_ascii_case("html") || e.eq_ignore_ascii_case("htm")) {
        bail!(
            "{}: the page is HTML: give an output name ending in .html",
            args.output.display()
        );
    }
    super::outputs::check(&[("-o", Some(&args.output))])?;
    let start = Instant::now();
    let (loaded, image) = load_map(&args.mesh, args.map.as_deref(), args.repair, quiet)?;
    let scene = Scene::new(&loaded.mesh, image)
        .with_context(|| format!("drawing {}", args.mesh.display()))?;
    let title = args.title.clone().unwrap_or_else(|| match &args.map {
        Some(map) => format!("{} on {}", map.display(), args.mesh.display()),
        None => args.mesh.display().to_string(),
    });
    let page = html_page(&scene, &title, args.mu_range);
    write_atomically(&args.output, |w| w.write_all(page.as_bytes()))?;
    if !quiet {
        println!(
            "{} -> {} ({} KB, {:.3} s)",
            args.mesh.display(),
            args.output.display(),
            page.len() / 1024,
            start.elapsed().as_secs_f64()
        );
    }
    Ok(())
}
