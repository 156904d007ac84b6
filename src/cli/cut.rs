//! `beltrami cut`: cut a surface of genus g >= 1 (or with several boundary loops) into a
//! topological disk along a greedy shortest system of loops, and write the disk as OBJ.
//!
//! The cut mesh keeps the faces in their order; its first vertices are the mesh's own,
//! and the copies made along the cut follow them.

use std::path::PathBuf;

use anyhow::{Context, bail};
use beltrami_mesh::io::{self, Format, VertexAttributes};
use beltrami_mesh::{CutMesh, GeneratorKind, Mesh, cut_to_disk};
use clap::Args;
use serde_json::{Value, json};

use super::load::load_mesh;

#[derive(Debug, Args)]
pub struct CutArgs {
    /// Mesh file (.obj, .ply, .stl, .off, .gltf, .glb): one connected surface, not a closed genus-0 one.
    pub mesh: PathBuf,
    /// Where to write the cut mesh (.obj).
    #[arg(short, long, value_name = "OUT.obj")]
    pub output: PathBuf,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
    /// Repair what can be repaired safely (drop degenerate and duplicate faces, merge
    /// exactly coincident vertices) instead of failing; every repair is reported.
    #[arg(long)]
    pub repair: bool,
}

pub fn run(args: &CutArgs, quiet: bool) -> anyhow::Result<()> {
    if Format::from_path(&args.output) != Some(Format::Obj) {
        bail!(
            "{}: the cut mesh is written as OBJ: give an output name ending in .obj",
            args.output.display()
        );
    }
    super::outputs::check(&[("-o", Some(&args.output))])?;
    let loaded = load_mesh(&args.mesh, args.repair, quiet || args.json)?;
    let mesh = &loaded.mesh.mesh;
    let cut = cut_to_disk(mesh).with_context(|| format!("cannot cut {}", args.mesh.display()))?;
    io::obj::write(&args.output, &cut.mesh, &VertexAttributes::default())?;

    let report = Report::new(mesh, &cut);
    if args.json {
        println!("{}", report.json(args));
    } else {
        report.print(args);
    }
    Ok(())
}

/// What the command prints.
struct Report {
    genus: i64,
    boundary_loops: usize,
    /// Kind, length and edge count of every generator loop.
    generators: Vec<(GeneratorKind, f64, usize)>,
    cut_edges: usize,
    cut_length: f64,
    vertices: usize,
    faces: usize,
    boundary_edges: usize,
    boundary_length: f64,
    /// Lengths of the sides a, b, a^-1, b^-1 of a cut torus.
    torus_sides: Option<[f64; 4]>,
}

impl Report {
    fn new(mesh: &Mesh, cut: &CutMesh) -> Self {
        let component = cut.cut.components[0];
        Report {
            genus: component.genus,
            boundary_loops: component.boundary_loops,
            generators: cut
                .cut
                .generators
                .iter()
                .map(|g| (g.kind, g.length, g.halfedges.len()))
                .collect(),
            cut_edges: cut.cut.edges.len(),
            cut_length: cut.cut.length(mesh),
            vertices: cut.mesh.vertex_count(),
            faces: cut.mesh.face_count(),
            boundary_edges: cut.boundary.len(),
            boundary_length: cut.boundary_length(),
            torus_sides: cut
                .torus_sides
                .as_ref()
                .map(|s| s.sides().map(|r| cut.path_length(r))),
        }
    }

    fn json(&self, args: &CutArgs) -> Value {
        let generators: Vec<Value> = self
            .generators
            .iter()
            .map(|&(kind, length, edges)| {
                json!({
                    "kind": kind_name(kind),
                    "length": length,
                    "edges": edges,
                })
            })
            .collect();
        json!({
            "file": args.mesh.display().to_string(),
            "output": args.output.display().to_string(),
            "genus": self.genus,
            "boundary_loops": self.boundary_loops,
            "generators": generators,
            "cut_edges": self.cut_edges,
            "cut_length": self.cut_length,
            "vertices": self.vertices,
            "faces": self.faces,
            "boundary_edges": self.boundary_edges,
            "boundary_length": self.boundary_length,
            "torus_sides": self.torus_sides.map(|[a, b, ai, bi]| json!({
                "a": a, "b": b, "a_inv": ai, "b_inv": bi,
            })),
        })
    }

    fn print(&self, args: &CutArgs) {
        println!("{} -> {}", args.mesh.display(), args.output.display());
        let boundary = match self.boundary_loops {
            0 => "closed".to_string(),
            1 => "1 boundary loop".to_string(),
            n => format!("{n} boundary loops"),
        };
        println!("  genus           {} ({boundary})", self.genus);
        let lengths: Vec<String> = self
            .generators
            .iter()
            .map(|&(kind, length, _)| match kind {
                GeneratorKind::Handle => format!("{length:.6}"),
                GeneratorKind::Boundary(b) => format!("{length:.6} (boundary {b})"),
            })
            .collect();
        println!(
            "  generators      {}: {}",
            self.generators.len(),
            lengths.join(", ")
        );
        println!(
            "  cut graph       {} edges, length {:.6}",
            self.cut_edges, self.cut_length
        );
        println!(
            "  cut mesh        {} vertices, {} faces, a disk",
            self.vertices, self.faces
        );
        println!(
            "  boundary        {} edges, length {:.6}",
            self.boundary_edges, self.boundary_length
        );
        if let Some([a, b, ai, bi]) = self.torus_sides {
            println!("  torus sides     a {a:.6}, b {b:.6}, a^-1 {ai:.6}, b^-1 {bi:.6}");
        }
    }
}

fn kind_name(kind: GeneratorKind) -> String {
    match kind {
        GeneratorKind::Handle => "handle".to_string(),
        GeneratorKind::Boundary(b) => format!("boundary {}", b.0),
    }
}
