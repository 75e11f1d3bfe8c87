//! Helpers shared by the core's integration tests.

use dupin_core::mesh::{MeshTopology, PolyMesh};

/// The boundary vertices of `mesh` more than `margin` above its lowest and below its highest
/// point (in z): for a tube or vault standing on z, the vertices of a seam, none when the
/// panels close around and the only boundary is at the two ends.
pub fn boundary_vertices_between_ends(mesh: &PolyMesh, margin: f64) -> Vec<usize> {
    let topo = MeshTopology::new(mesh).unwrap();
    let (lo, hi) = mesh
        .positions
        .iter()
        .fold((f64::MAX, f64::MIN), |(lo, hi), p| {
            (lo.min(p.z), hi.max(p.z))
        });
    (0..mesh.num_vertices())
        .filter(|&v| {
            topo.is_boundary(v) && (lo + margin..hi - margin).contains(&mesh.positions[v].z)
        })
        .collect()
}
