//! `beltrami bench load`: parse time of each mesh format against halfedge build time.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::Context;
use beltrami_mesh::io::{self, VertexAttributes};
use beltrami_mesh::primitives::{Cells, grid};
use beltrami_mesh::{BuildOptions, Mesh};
use clap::Args;
use serde_json::json;

#[derive(Debug, Args)]
pub struct LoadArgs {
    /// Sizes of the generated triangle grids, in triangles (comma-separated).
    #[arg(long, value_delimiter = ',', default_value = "100000,400000,1000000")]
    pub triangles: Vec<usize>,
    /// Formats the generated grids are written in and read back from (comma-separated:
    /// obj, ply, stl, off, glb, gltf).
    #[arg(long = "format", value_delimiter = ',', default_value = "obj")]
    pub formats: Vec<String>,
    /// Also time these mesh files.
    #[arg(long = "mesh")]
    pub meshes: Vec<PathBuf>,
    /// Repetitions per case; the table shows the fastest.
    #[arg(long, default_value_t = 3)]
    pub repeat: usize,
    /// Print one JSON object per case instead of the table.
    #[arg(long)]
    pub json: bool,
}

pub fn run(args: &LoadArgs) -> anyhow::Result<()> {
    let dir = tempfile::tempdir().context("cannot create a temporary folder")?;
    let mut cases: Vec<(String, PathBuf)> = Vec::new();
    for &t in &args.triangles {
        let n = ((t as f64 / 2.0).sqrt().round() as usize).max(1);
        let soup = grid(n, n, Cells::Triangles);
        let mesh = Mesh::from_soup(&soup)?;
        for format in &args.formats {
            let path = dir.path().join(format!("grid_{n}x{n}.{format}"));
            if io::Format::from_path(&path).is_none() {
                anyhow::bail!(
                    "--format {format}: not a mesh format (obj, ply, stl, off, glb, gltf)"
                );
            }
            io::write(&path, &mesh, &VertexAttributes::default())?;
            cases.push((format!("grid {n}x{n} .{format}"), path));
        }
    }
    for m in &args.meshes {
        cases.push((m.display().to_string(), m.clone()));
    }
    if !args.json {
        println!("| mesh | vertices | faces | file MB | parse s | build s | build / parse |");
        println!("|---|---|---|---|---|---|---|");
    }
    for (name, path) in &cases {
        let mut best_parse = Duration::MAX;
        let mut best_build = Duration::MAX;
        let mut counts = (0, 0);
        for _ in 0..args.repeat.max(1) {
            let start = Instant::now();
            let raw = io::read_raw(path)?;
            best_parse = best_parse.min(start.elapsed());
            let start = Instant::now();
            let (mesh, _) = Mesh::build(&raw.soup, &BuildOptions::default())?;
            best_build = best_build.min(start.elapsed());
            counts = (mesh.vertex_count(), mesh.face_count());
        }
        let mb = std::fs::metadata(path)?.len() as f64 / 1e6;
        let (p, b) = (best_parse.as_secs_f64(), best_build.as_secs_f64());
        if args.json {
            println!(
                "{}",
                json!({"mesh": name, "vertices": counts.0, "faces": counts.1, "file_mb": mb,
                       "parse_s": p, "build_s": b})
            );
        } else {
            println!(
                "| {name} | {} | {} | {mb:.1} | {p:.3} | {b:.3} | {:.2} |",
                counts.0,
                counts.1,
                b / p
            );
        }
    }
    Ok(())
}
