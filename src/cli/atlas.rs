//! `beltrami atlas`: a texture atlas of any triangle mesh (see the `beltrami-atlas` crate
//! and docs/atlas.md).

use std::path::{Path, PathBuf};
use std::str::FromStr;
use std::time::Instant;

use anyhow::{Context as _, bail};
use beltrami_atlas::{Atlas, AtlasOptions, ChartCount, ConeCount};
use beltrami_mesh::io::{self, CornerUvs, Format};
use beltrami_mesh::{Mesh, Vector2};
use beltrami_render::{ColorBy, Layout, Scene, Style, View};
use clap::Args;
use serde_json::{Value, json};

use super::load::load_mesh;
use super::mapping::png_path;

/// `auto` (`None`) or a whole number of at least `least` (`what` names the count in the
/// error).
fn auto_or_count(text: &str, least: usize, what: &str) -> Result<Option<usize>, String> {
    if text == "auto" {
        return Ok(None);
    }
    match text.parse::<usize>() {
        Ok(n) if n >= least => Ok(Some(n)),
        _ => Err(format!(
            "`{text}` is neither `auto` nor a whole number of {what} (at least {least})"
        )),
    }
}

/// `--cones`: `auto` or a count per chart.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ConesArg(pub ConeCount);

impl FromStr for ConesArg {
    type Err = String;

    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let count = auto_or_count(text, 0, "cones per chart")?;
        Ok(Self(count.map_or(ConeCount::Auto, ConeCount::Exactly)))
    }
}

/// `--charts`: `auto` or the least number of charts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ChartsArg(pub ChartCount);

impl FromStr for ChartsArg {
    type Err = String;

    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let count = auto_or_count(text, 1, "charts")?;
        Ok(Self(count.map_or(ChartCount::Auto, ChartCount::AtLeast)))
    }
}

#[derive(Debug, Args)]
pub struct AtlasArgs {
    /// Mesh file (.obj, .ply, .stl, .off, .gltf, .glb): any manifold triangle mesh,
    /// closed or open, of any genus, in one piece or several.
    pub mesh: PathBuf,
    /// Output mesh with per-corner texture coordinates (.obj keeps the input's vertices
    /// in order and writes `f v/t`; .ply, .gltf and .glb split the vertices at seams).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Cone singularities per chart: `auto` places them until the stretch limit is met
    /// (at most 64 per chart), a number places that many.
    #[arg(long, value_name = "auto|N", default_value = "auto")]
    pub cones: ConesArg,
    /// Charts: `auto` makes as few as the stretch limit and the overlap test leave; a
    /// number N makes at least N, splitting the chart with the largest share of the
    /// squared stretch (area times its L2 stretch squared) until there are (a split
    /// whose half falls apart may give one more).
    #[arg(long, value_name = "auto|N", default_value = "auto")]
    pub charts: ChartsArg,
    /// The largest L2 texture stretch (Sander et al. 2001) of a chart, at least 1; a
    /// chart above it is split.
    #[arg(
        long = "max-stretch",
        value_name = "S",
        default_value_t = 1.1,
        allow_hyphen_values = true
    )]
    pub max_stretch: f64,
    /// The space between charts, as a fraction of the texture's side.
    #[arg(
        long,
        value_name = "P",
        default_value_t = 0.004,
        allow_hyphen_values = true
    )]
    pub padding: f64,
    /// Write the JSON report here.
    #[arg(long, value_name = "R.json")]
    pub report: Option<PathBuf>,
    /// Print the JSON report on stdout instead of the summary.
    #[arg(long)]
    pub json: bool,
    /// Also draw the atlas as PNG: a checkerboard of the texture on the surface, and the
    /// charts in the texture square.
    #[arg(long, value_parser = png_path)]
    pub png: Option<PathBuf>,
    /// Repair what can be repaired safely in the input (see `beltrami info --repair`).
    #[arg(long)]
    pub repair: bool,
}

pub fn run(args: &AtlasArgs, quiet: bool) -> anyhow::Result<()> {
    match Format::from_path(&args.output) {
        Some(Format::Obj | Format::Ply | Format::Gltf | Format::Glb) => {}
        _ => bail!(
            "{}: an atlas is written as .obj, .ply, .gltf or .glb (the formats that hold texture coordinates with seams)",
            args.output.display()
        ),
    }
    super::outputs::check(&[
        ("-o", Some(&args.output)),
        ("--png", args.png.as_deref()),
        ("--report", args.report.as_deref()),
    ])?;
    let options = AtlasOptions {
        cones: args.cones.0,
        charts: args.charts.0,
        max_stretch: args.max_stretch,
        padding: args.padding,
    };
    options.validate()?;
    let loaded = load_mesh(&args.mesh, args.repair, quiet || args.json)?;
    let mesh = &loaded.mesh.mesh;
    let start = Instant::now();
    let atlas = beltrami_atlas::atlas(mesh, &options)
        .with_context(|| format!("cannot make an atlas of {}", args.mesh.display()))?;
    let seconds = start.elapsed().as_secs_f64();
    let (uvs, corners) = corner_uvs(mesh, &atlas);
    io::write_seamed(
        &args.output,
        mesh,
        &CornerUvs {
            uvs: &uvs,
            corners: &corners,
        },
        &loaded.mesh.obj_groups,
    )?;
    if let Some(path) = &args.png {
        write_png(path, mesh, &uvs, &corners)?;
    }
    let report = report_json(args, mesh, &atlas, &options, seconds);
    if let Some(path) = &args.report {
        let text = serde_json::to_string_pretty(&report)?;
        io::write_atomically(path, |w| std::io::Write::write_all(w, text.as_bytes()))
            .with_context(|| format!("cannot write the report {}", path.display()))?;
    }
    if args.json {
        println!("{report}");
    } else if !quiet {
        print_summary(args, &report);
    }
    Ok(())
}

/// The atlas's UVs and, per face halfedge, the index of its corner's UV.
fn corner_uvs(mesh: &Mesh, atlas: &Atlas) -> (Vec<Vector2<f64>>, Vec<u32>) {
    let uvs = atlas
        .uv
        .uvs
        .iter()
        .map(|p| Vector2::new(p[0], p[1]))
        .collect();
    let mut corners = vec![0u32; mesh.halfedge_count()];
    for f in mesh.faces() {
        for (k, h) in mesh.face_halfedges(f).enumerate() {
            corners[h.idx()] = atlas.uv.corners[f.idx()][k];
        }
    }
    (uvs, corners)
}

/// `--png`: the surface with a checkerboard of the texture beside the texture square.
fn write_png(
    path: &Path,
    mesh: &Mesh,
    uvs: &[Vector2<f64>],
    corners: &[u32],
) -> anyhow::Result<()> {
    let per_corner: Vec<Vector2<f64>> = (0..beltrami_render::corner_count(mesh))
        .map(|h| uvs[corners[h] as usize])
        .collect();
    let scene = Scene::new(mesh, Some(Layout::plane(mesh, per_corner)?))?;
    let style = Style {
        view: View::Both,
        color: ColorBy::Checker,
        checker_cells: 32,
        ..Style::default()
    };
    beltrami_render::render(&scene, &style)?
        .write_png(path)
        .with_context(|| format!("cannot write the picture {}", path.display()))
}

fn report_json(
    args: &AtlasArgs,
    mesh: &Mesh,
    atlas: &Atlas,
    options: &AtlasOptions,
    seconds: f64,
) -> Value {
    let mut report = serde_json::Map::new();
    report.insert("mesh".into(), json!(args.mesh.display().to_string()));
    report.insert("output".into(), json!(args.output.display().to_string()));
    report.extend(beltrami::report::atlas(mesh, atlas, options, seconds));
    Value::Object(report)
}

fn print_summary(args: &AtlasArgs, report: &Value) {
    let number = |path: &[&str]| {
        path.iter()
            .fold(report, |v, k| &v[*k])
            .as_f64()
            .unwrap_or(f64::NAN)
    };
    println!(
        "{} -> {} ({:.3} s)",
        args.mesh.display(),
        args.output.display(),
        number(&["seconds"])
    );
    println!(
        "  charts          {}  cones {}",
        report["charts"], report["cones"]
    );
    println!(
        "  stretch         L2 {:.4}  Linf {:.3}  area distortion {:.4}",
        number(&["stretch", "l2"]),
        number(&["stretch", "linf"]),
        number(&["stretch", "area_distortion"])
    );
    println!(
        "  seams           {} edges, {:.2}% of the edge length",
        report["seams"]["edges"],
        100.0 * number(&["seams", "length_share"])
    );
    println!(
        "  |mu|            mean {:.4}  max {:.4}",
        number(&["mu", "mean"]),
        number(&["mu", "max"])
    );
    println!("  flipped faces   {}", report["flipped_faces"]);
}
