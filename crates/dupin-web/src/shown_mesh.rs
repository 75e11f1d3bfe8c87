//! The figures and render buffers of the mesh the page shows, carried from one state of a run
//! to the next: kept for the faces the new state shares with the last one, computed for the
//! rest.
//!
//! A P-Hex run reveals its triangulation a layer at a time and the worker measures and draws
//! every layer, so computing every face at every state visited each face once per later layer
//! (the 10 203-panel roof: 111 states, 1.1 M face visits). Each state's mesh is the last one
//! plus faces there; after the dual step every face is new and everything is computed afresh.

use dupin_core::mesh::{PanelBuffers, PolyMesh, face_planarity, planarity_color};
use dupin_core::phex::count_invalid_and_non_convex_faces;

/// The current mesh with its per-face planarity, its face counts and its planarity-coloured
/// render buffers (built when first drawn).
#[derive(Debug, Default)]
pub(crate) struct ShownMesh {
    mesh: PolyMesh,
    planarity: Vec<f64>,
    /// Self-intersecting faces, and simple faces that are not convex.
    invalid: usize,
    non_convex: usize,
    panels: PanelBuffers,
}

impl ShownMesh {
    /// Nothing shown yet; the render buffers will be relative to `origin`
    /// ([`dupin_core::mesh::view_origin`]).
    pub(crate) fn around(origin: dupin_core::Vec3) -> Self {
        ShownMesh {
            panels: PanelBuffers::around(origin),
            ..ShownMesh::default()
        }
    }

    /// Makes `mesh` the shown mesh. Its faces that the last shown mesh had first, with the same
    /// corners at the same positions, keep their figures; if any of the last mesh's faces is
    /// gone or moved, every figure is computed afresh.
    pub(crate) fn sync(&mut self, mesh: PolyMesh) {
        let kept = if starts_with(&mesh, &self.mesh) {
            self.mesh.num_faces()
        } else {
            self.planarity.clear();
            (self.invalid, self.non_convex) = (0, 0);
            self.panels = PanelBuffers::around(self.panels.origin());
            0
        };
        self.planarity
            .extend((kept..mesh.num_faces()).map(|i| face_planarity(&mesh, i)));
        let (invalid, non_convex) =
            count_invalid_and_non_convex_faces(&mesh, kept..mesh.num_faces());
        self.invalid += invalid;
        self.non_convex += non_convex;
        self.mesh = mesh;
    }

    /// The shown mesh.
    pub(crate) fn mesh(&self) -> &PolyMesh {
        &self.mesh
    }

    /// [`face_planarity`] of every face, in face order.
    pub(crate) fn planarity(&self) -> &[f64] {
        &self.planarity
    }

    /// `(self-intersecting, simple but not convex)` faces.
    pub(crate) fn shape_counts(&self) -> (usize, usize) {
        (self.invalid, self.non_convex)
    }

    /// The render buffers in planarity colours, brought up to the shown mesh.
    pub(crate) fn planarity_panels(&mut self) -> &PanelBuffers {
        if self.panels.faces() != self.mesh.num_faces() {
            let colors: Vec<[f32; 3]> =
                self.planarity.iter().map(|&p| planarity_color(p)).collect();
            self.panels.extend(&self.mesh, &colors);
        }
        &self.panels
    }
}

/// Whether `mesh`'s first faces are `earlier`'s, with the same corners at the same positions
/// (bit for bit, so a NaN never matches).
fn starts_with(mesh: &PolyMesh, earlier: &PolyMesh) -> bool {
    earlier.num_faces() <= mesh.num_faces()
        && (0..earlier.num_faces()).all(|i| {
            let f = earlier.face(i);
            f == mesh.face(i)
                && f.iter().all(|&v| {
                    let (a, b) = (
                        earlier.positions.get(v as usize),
                        mesh.positions.get(v as usize),
                    );
                    matches!((a, b), (Some(a), Some(b)) if a == b)
                })
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use dupin_core::Vec3;
    use dupin_core::mesh::{polymesh_buffers, polymesh_edges};

    /// A strip of `n` quads along x, the k-th lifted by `lift(k)` at its far corner.
    fn strip(n: usize, lift: impl Fn(usize) -> f64) -> PolyMesh {
        let positions = (0..=n)
            .flat_map(|i| {
                [
                    Vec3::new(i as f64, 0.0, 0.0),
                    Vec3::new(i as f64, 1.0, lift(i)),
                ]
            })
            .collect();
        let faces: Vec<[u32; 4]> = (0..n as u32)
            .map(|i| [2 * i, 2 * i + 2, 2 * i + 3, 2 * i + 1])
            .collect();
        PolyMesh::new(positions, faces).unwrap()
    }

    /// The first `n` faces of `mesh`.
    fn first(mesh: &PolyMesh, n: usize) -> PolyMesh {
        let faces: Vec<Vec<u32>> = (0..n).map(|i| mesh.face(i).to_vec()).collect();
        PolyMesh::new(mesh.positions.clone(), faces).unwrap()
    }

    /// What `ShownMesh` holds after any sequence of syncs is what a fresh computation of the
    /// last mesh gives: grown by faces (kept), then a vertex moved (all afresh), then shrunk.
    #[test]
    fn every_sync_gives_the_fresh_figures() {
        let full = strip(9, |i| 0.01 * (i % 3) as f64);
        let moved = strip(9, |i| if i == 4 { 0.3 } else { 0.01 * (i % 3) as f64 });
        let mut shown = ShownMesh::default();
        for mesh in [
            first(&full, 0),
            first(&full, 3),
            first(&full, 3),
            first(&full, 9),
            moved,
            first(&full, 5),
        ] {
            shown.sync(mesh.clone());
            let planarity: Vec<f64> = (0..mesh.num_faces())
                .map(|i| face_planarity(&mesh, i))
                .collect();
            assert_eq!(shown.planarity(), planarity.as_slice());
            assert_eq!(
                shown.shape_counts(),
                count_invalid_and_non_convex_faces(&mesh, 0..mesh.num_faces())
            );
            let colors: Vec<[f32; 3]> = planarity.iter().map(|&p| planarity_color(p)).collect();
            let (buffers, vertex_colors) = polymesh_buffers(&mesh, Some(&colors));
            let panels = shown.planarity_panels();
            assert_eq!(panels.buffers, buffers);
            assert_eq!(panels.colors, vertex_colors);
            let mut edges: Vec<Vec<u32>> = panels
                .edges
                .chunks(6)
                .map(|c| c.iter().map(|x| x.to_bits()).collect())
                .collect();
            let mut fresh: Vec<Vec<u32>> = polymesh_edges(&mesh)
                .chunks(6)
                .map(|c| c.iter().map(|x| x.to_bits()).collect())
                .collect();
            edges.sort();
            fresh.sort();
            assert_eq!(edges, fresh);
        }
    }

    /// A moved corner of a kept face is seen, and so is a NaN.
    #[test]
    fn a_moved_or_nan_corner_is_not_kept() {
        let a = strip(4, |_| 0.0);
        let b = strip(4, |i| if i == 2 { 1e-9 } else { 0.0 });
        assert!(starts_with(&a, &first(&a, 2)));
        assert!(!starts_with(&b, &a));
        assert!(!starts_with(&first(&a, 2), &a));
        let mut nan = a.clone();
        nan.positions[0].x = f64::NAN;
        assert!(!starts_with(&nan, &nan));
    }
}
