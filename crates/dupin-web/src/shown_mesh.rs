//! The figures and render buffers of the mesh the page shows, carried from one state of a run
//! to the next: kept for the faces the new state shares with the last one, computed for the
//! rest.
//!
//! A P-Hex run reveals its triangulation a layer at a time and the worker measures and draws
//! every layer, so computing every face at every state visited each face once per later layer
//! (the 10 203-panel roof: 111 states, 1.1 M face visits). Each state's mesh is the last one
//! plus faces there; after the dual step every face is new and everything is computed afresh.

use crate::mesh_data::MeshKey;
use dupin_core::Vec3;
use dupin_core::mesh::{
    PLANARITY_HIST_BINS, PanelBuffers, PanelTail, PolyMesh, face_planarity, planarity_color,
    planarity_histogram,
};
use dupin_core::phex::count_invalid_and_non_convex_faces;
use std::sync::atomic::{AtomicU64, Ordering};

/// Revisions are unique in the module, so a key of one session never matches another's.
static NEXT_REVISION: AtomicU64 = AtomicU64::new(1);

/// The current mesh with its per-face planarity, its face counts, its summary figures and its
/// planarity-coloured render buffers (built when first drawn).
#[derive(Debug, Default)]
pub(crate) struct ShownMesh {
    mesh: PolyMesh,
    planarity: Vec<f64>,
    /// Self-intersecting faces, and simple faces that are not convex.
    invalid: usize,
    non_convex: usize,
    figures: Figures,
    panels: PanelBuffers,
    /// Changes whenever a sync does more than add faces and vertices (a face gone or moved, a
    /// position changed), so that under one revision the shown mesh only grows.
    revision: u64,
}

/// Summary figures of the shown faces, summed in face order as they come (so a fresh pass
/// over the same faces gives them bit for bit), and the bounding box of every position.
#[derive(Debug, Default, Clone)]
struct Figures {
    planarity_sum: f64,
    /// NaN once any face's planarity is NaN.
    max_planarity: f64,
    histogram: Vec<u32>,
    edge_sum: f64,
    edges: usize,
    lo: [f64; 3],
    hi: [f64; 3],
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
        let positions_kept = self.mesh.positions.len() <= mesh.positions.len()
            && self
                .mesh
                .positions
                .iter()
                .zip(&mesh.positions)
                .all(|(a, b)| same_bits(a, b));
        // With every position as it was (none NaN), the faces' lists alone tell: the corner by
        // corner test costs a position lookup per corner.
        let faces_kept = if positions_kept {
            mesh.starts_with_faces_of(&self.mesh)
        } else {
            starts_with(&mesh, &self.mesh)
        };
        if !(faces_kept && positions_kept) || self.revision == 0 {
            self.revision = NEXT_REVISION.fetch_add(1, Ordering::Relaxed);
        }
        let kept = if faces_kept {
            self.mesh.num_faces()
        } else {
            self.planarity.clear();
            (self.invalid, self.non_convex) = (0, 0);
            self.panels = PanelBuffers::around(self.panels.origin());
            self.figures = Figures::default();
            0
        };
        // Afresh figures start from the first position too.
        let from_position = if faces_kept && positions_kept {
            self.mesh.positions.len()
        } else {
            0
        };
        self.figures.add(&mesh, kept, from_position);
        self.planarity
            .extend((kept..mesh.num_faces()).map(|i| face_planarity(&mesh, i)));
        self.figures.add_planarity(&self.planarity[kept..]);
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
    #[cfg(test)]
    pub(crate) fn planarity(&self) -> &[f64] {
        &self.planarity
    }

    /// `(self-intersecting, simple but not convex)` faces.
    pub(crate) fn shape_counts(&self) -> (usize, usize) {
        (self.invalid, self.non_convex)
    }

    /// The mean of [`ShownMesh::planarity`] (0 for no faces), as
    /// [`dupin_core::mesh::mean_planarity`] gives it.
    pub(crate) fn mean_planarity(&self) -> f64 {
        match self.planarity.len() {
            0 => 0.0,
            n => self.figures.planarity_sum / n as f64,
        }
    }

    /// The largest of [`ShownMesh::planarity`], NaN if any is NaN (0 for no faces).
    pub(crate) fn max_planarity(&self) -> f64 {
        self.figures.max_planarity
    }

    /// [`planarity_histogram`] of [`ShownMesh::planarity`].
    pub(crate) fn histogram(&self) -> Vec<u32> {
        self.figures.histogram.clone()
    }

    /// [`PolyMesh::mean_edge`] of the shown mesh.
    pub(crate) fn mean_edge(&self) -> f64 {
        match self.figures.edges {
            0 => 0.0,
            n => self.figures.edge_sum / n as f64,
        }
    }

    /// The extent of the bounding box of every position along x, y and z (zeros for none).
    pub(crate) fn extent(&self) -> [f64; 3] {
        let Figures { lo, hi, .. } = &self.figures;
        [0, 1, 2].map(|k| if hi[k] >= lo[k] { hi[k] - lo[k] } else { 0.0 })
    }

    /// Changes whenever the shown mesh does more than grow (see [`ShownMesh::sync`]).
    #[cfg(test)]
    pub(crate) fn revision(&self) -> u64 {
        self.revision
    }

    /// Where the shown mesh stands: its revision and its face and vertex counts.
    pub(crate) fn key(&self) -> MeshKey {
        MeshKey {
            revision: self.revision,
            faces: self.mesh.num_faces(),
            vertices: self.mesh.positions.len(),
        }
    }

    /// What the shown mesh added to the planarity-coloured render buffers since it stood at
    /// `since` ([`PanelBuffers::since`]), with the mesh (its faces from `since.faces` and
    /// positions from `since.vertices` are the added ones); `None` unless the mesh has only
    /// grown since then.
    pub(crate) fn planarity_tail(&mut self, since: MeshKey) -> Option<(PanelTail<'_>, &PolyMesh)> {
        let now = self.key();
        if since.revision != now.revision
            || since.faces > now.faces
            || since.vertices > now.vertices
        {
            return None;
        }
        self.planarity_panels();
        Some((self.panels.since(since.faces)?, &self.mesh))
    }

    /// The render buffers in planarity colours, brought up to the shown mesh.
    pub(crate) fn planarity_panels(&mut self) -> &PanelBuffers {
        if self.panels.faces() != self.mesh.num_faces() {
            let colors: Vec<[f32; 3]> = self.planarity[self.panels.faces()..]
                .iter()
                .map(|&p| planarity_color(p))
                .collect();
            self.panels.extend(&self.mesh, &colors);
        }
        &self.panels
    }
}

impl Figures {
    /// Adds the edges of faces `faces..` and positions `positions..` of `mesh`.
    fn add(&mut self, mesh: &PolyMesh, faces: usize, positions: usize) {
        if self.histogram.is_empty() {
            self.histogram = vec![0; PLANARITY_HIST_BINS];
        }
        if positions == 0 {
            (self.lo, self.hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        }
        for p in &mesh.positions[positions..] {
            for (k, c) in [p.x, p.y, p.z].into_iter().enumerate() {
                self.lo[k] = self.lo[k].min(c);
                self.hi[k] = self.hi[k].max(c);
            }
        }
        (self.edge_sum, self.edges) = mesh.sum_edge_lengths(faces, (self.edge_sum, self.edges));
    }

    /// Adds the planarity of the next faces.
    fn add_planarity(&mut self, planarity: &[f64]) {
        for &p in planarity {
            self.planarity_sum += p;
            self.max_planarity = if self.max_planarity.is_nan() || p.is_nan() {
                f64::NAN
            } else {
                self.max_planarity.max(p)
            };
        }
        for (h, n) in self
            .histogram
            .iter_mut()
            .zip(planarity_histogram(planarity))
        {
            *h += n;
        }
    }
}

/// Whether two points are the same bit for bit (so a NaN never is).
fn same_bits(a: &Vec3, b: &Vec3) -> bool {
    a == b
        && a.iter()
            .zip(b.iter())
            .all(|(x, y)| x.to_bits() == y.to_bits())
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
    /// last mesh gives: grown by faces (kept), then a vertex moved (all afresh), then shrunk,
    /// then a vertex no face uses moved (faces kept). The revision stays exactly while the mesh
    /// only grows.
    #[test]
    fn every_sync_gives_the_fresh_figures() {
        let full = strip(9, |i| 0.01 * (i % 3) as f64);
        let moved = strip(9, |i| if i == 4 { 0.3 } else { 0.01 * (i % 3) as f64 });
        let mut unused_moved = first(&full, 5);
        unused_moved.positions[19].z = 7.0;
        let mut shown = ShownMesh::default();
        let mut last: Option<(PolyMesh, u64)> = None;
        for mesh in [
            first(&full, 0),
            first(&full, 3),
            first(&full, 3),
            first(&full, 9),
            moved,
            first(&full, 5),
            unused_moved,
        ] {
            shown.sync(mesh.clone());
            let planarity: Vec<f64> = (0..mesh.num_faces())
                .map(|i| face_planarity(&mesh, i))
                .collect();
            assert_eq!(shown.planarity(), planarity.as_slice());
            let bits = |x: f64| x.to_bits();
            assert_eq!(
                bits(shown.mean_planarity()),
                bits(dupin_core::mesh::mean_planarity(&planarity))
            );
            let max = planarity.iter().fold(0.0f64, |a, &b| a.max(b));
            assert_eq!(bits(shown.max_planarity()), bits(max));
            assert_eq!(shown.histogram(), planarity_histogram(&planarity));
            assert_eq!(bits(shown.mean_edge()), bits(mesh.mean_edge()));
            let mut lo = [f64::INFINITY; 3];
            let mut hi = [f64::NEG_INFINITY; 3];
            for p in &mesh.positions {
                for k in 0..3 {
                    (lo[k], hi[k]) = (lo[k].min(p[k]), hi[k].max(p[k]));
                }
            }
            assert_eq!(shown.extent(), [0, 1, 2].map(|k| hi[k] - lo[k]));
            if let Some((before, revision)) = &last {
                let grew = starts_with(&mesh, before) && mesh.positions == before.positions;
                assert_eq!(shown.revision() == *revision, grew);
            }
            last = Some((mesh.clone(), shown.revision()));
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
