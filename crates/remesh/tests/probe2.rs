use beltrami_core::{Context, Solver};
use beltrami_init::{Lscm, Tutte};
use beltrami_mesh::{BuildOptions, io};
use beltrami_remesh::{RemeshOptions, remesh};
use beltrami_spatial::SurfaceIndex;

#[test]
fn probe2() {
    for name in ["disk_human_face", "g0_spot"] {
        let path = format!("/work/shared/meshes/{name}.obj");
        let mesh = io::read(std::path::Path::new(&path), &BuildOptions::default())
            .unwrap()
            .mesh;
        let l = 0.01 * mesh.bounding_box().diagonal();
        let solvers: [&dyn Solver; 2] = [&Lscm, &Tutte];
        let r = remesh(
            &mesh,
            &solvers,
            &RemeshOptions::with_edge_length(l),
            &mut Context::new(),
        )
        .unwrap();
        let out = &r.remeshed.mesh;
        let idx = SurfaceIndex::new(out).unwrap();
        let mut worst: Vec<(f64, u32, bool)> = mesh
            .vertices()
            .map(|v| {
                (
                    idx.locate(&mesh.position(v)).unwrap().distance / l,
                    v.0,
                    mesh.is_boundary_vertex(v),
                )
            })
            .collect();
        worst.sort_by(|a, b| b.0.total_cmp(&a.0));
        eprintln!("{name} input->output worst (in L): {:?}", &worst[..8]);
        let idx2 = SurfaceIndex::new(&mesh).unwrap();
        let mut w2: Vec<(f64, u32)> = out
            .faces()
            .map(|f| {
                (
                    idx2.locate(&out.face_centroid(f)).unwrap().distance / l,
                    f.0,
                )
            })
            .collect();
        w2.sort_by(|a, b| b.0.total_cmp(&a.0));
        eprintln!("{name} output->input worst (in L): {:?}", &w2[..5]);
    }
}
