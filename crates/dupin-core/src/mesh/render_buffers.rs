//! Plain triangle buffers for renderers (lyon's idea: the core hands out buffers and never
//! knows who draws them).

use crate::Vec3;
use crate::mesh::PolyMesh;

/// An indexed triangle list with per-vertex normals, in `f32` as GPUs want them.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TriangleBuffers {
    /// x, y, z per vertex.
    pub positions: Vec<f32>,
    /// Unit normal per vertex.
    pub normals: Vec<f32>,
    /// Three vertex indices per triangle, counter-clockwise seen from the normal side.
    pub indices: Vec<u32>,
}

impl TriangleBuffers {
    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.positions.len() / 3
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }
}

/// Flat-shaded triangle buffers of a polygon mesh: each face is fanned from its first vertex
/// with its own vertices (so panels read as flat), the normal being the face's area vector.
/// `face_colors`, if given, holds one linear RGB triple per face; the result's second part is
/// then one RGB triple per output vertex (empty otherwise).
pub fn polymesh_buffers(
    mesh: &PolyMesh,
    face_colors: Option<&[[f32; 3]]>,
) -> (TriangleBuffers, Vec<f32>) {
    let mut out = TriangleBuffers::default();
    let mut colors = Vec::new();
    push_faces(mesh, 0, face_colors, Vec3::zeros(), &mut out, &mut colors);
    (out, colors)
}

/// The point a design's `f32` render buffers are best taken relative to: zero for a design
/// near the origin (within 256 times its size, where `f32`'s 24 bits still resolve 1/65 536 of
/// the design), else the centre of its bounding box rounded to a multiple of a power of two
/// near its size. A design at state-plane coordinates (1e6..1e7 m) drawn in absolute `f32`
/// would snap to a half-metre grid; relative to this origin it is drawn as finely as one near
/// zero. Non-finite points are skipped; no finite point gives zero.
pub fn view_origin(points: &[Vec3]) -> Vec3 {
    let mut lo = Vec3::repeat(f64::INFINITY);
    let mut hi = Vec3::repeat(f64::NEG_INFINITY);
    for p in points.iter().filter(|p| p.iter().all(|c| c.is_finite())) {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    if lo.x > hi.x {
        return Vec3::zeros();
    }
    // Halves first: the sum of two coordinates near f64::MAX would overflow.
    let center = lo * 0.5 + hi * 0.5;
    let size = (hi * 0.5 - lo * 0.5).max() * 2.0;
    if center.amax() <= 256.0 * size {
        return Vec3::zeros();
    }
    // A round origin (the same for a design moved by less than its rounding step) and an
    // exact one: the quotient's rounding and the product by a power of two lose nothing that
    // matters at this size.
    let step = if size.is_normal() {
        2f64.powi(size.log2().ceil().clamp(-1000.0, 1000.0) as i32)
    } else {
        1.0
    };
    center.map(|c| (c / step).round() * step)
}

/// Appends faces `from..` of `mesh`, taken relative to `origin`, to `out` and (with
/// `face_colors`, one triple per face from `from` on) their colours to `colors`, as
/// [`polymesh_buffers`] lays them out.
fn push_faces(
    mesh: &PolyMesh,
    from: usize,
    face_colors: Option<&[[f32; 3]]>,
    origin: Vec3,
    out: &mut TriangleBuffers,
    colors: &mut Vec<f32>,
) {
    // The page rebuilds these at every state of a run, so nothing is allocated per face.
    let faces = from..mesh.num_faces();
    let corners: usize = faces.clone().map(|i| mesh.face(i).len()).sum();
    let triangles: usize = faces
        .clone()
        .map(|i| mesh.face(i).len().saturating_sub(2))
        .sum();
    out.positions.reserve(3 * corners);
    out.normals.reserve(3 * corners);
    out.indices.reserve(3 * triangles);
    if face_colors.is_some() {
        colors.reserve(3 * corners);
    }
    for fi in faces {
        let f = mesh.face(fi);
        // Relative to the origin before anything else: the cross products below would lose
        // every digit of a small face far from zero.
        let at = |k: usize| mesh.positions[f[k] as usize] - origin;
        // Newell's normal: robust for non-planar and non-convex polygons.
        let mut n = Vec3::zeros();
        for k in 0..f.len() {
            n += at(k).cross(&at((k + 1) % f.len()));
        }
        let n = n.try_normalize(0.0).unwrap_or_else(Vec3::z);
        let base = out.vertex_count() as u32;
        let color = face_colors.and_then(|c| c.get(fi - from));
        for k in 0..f.len() {
            let q = at(k);
            out.positions.extend([q.x as f32, q.y as f32, q.z as f32]);
            out.normals.extend([n.x as f32, n.y as f32, n.z as f32]);
            if let Some(c) = color {
                colors.extend(c);
            }
        }
        for k in 1..f.len() as u32 - 1 {
            out.indices.extend([base, base + k, base + k + 1]);
        }
    }
}

/// Every edge of a polygon mesh once, as pairs of `[x, y, z]` endpoints (6 floats an edge), for
/// drawing panel frames. Edges come in the order of their (lower, higher) vertex pairs, from
/// the lower vertex.
pub fn polymesh_edges(mesh: &PolyMesh) -> Vec<f32> {
    let mut out = Vec::new();
    push_edge_segments(mesh, &edge_keys(mesh, 0), Vec3::zeros(), &mut out);
    out
}

/// The edges of faces `from..` of `mesh` as (lower, higher) vertex pairs in a `u64`, sorted,
/// each once. Sorting finds each edge once at a fraction of hashing's cost.
fn edge_keys(mesh: &PolyMesh, from: usize) -> Vec<u64> {
    let mut keys: Vec<u64> = (from..mesh.num_faces())
        .flat_map(|i| {
            let f = mesh.face(i);
            (0..f.len()).map(move |k| {
                let (a, b) = (f[k], f[(k + 1) % f.len()]);
                (u64::from(a.min(b)) << 32) | u64::from(a.max(b))
            })
        })
        .collect();
    keys.sort_unstable();
    keys.dedup();
    keys
}

/// Appends the segments of the edges `keys` ([`edge_keys`]) to `out`, from the lower vertex,
/// relative to `origin`.
fn push_edge_segments(mesh: &PolyMesh, keys: &[u64], origin: Vec3, out: &mut Vec<f32>) {
    out.reserve(6 * keys.len());
    for &key in keys {
        for v in [key >> 32, key & u64::from(u32::MAX)] {
            let q = mesh.positions[v as usize] - origin;
            out.extend([q.x as f32, q.y as f32, q.z as f32]);
        }
    }
}

/// [`polymesh_buffers`] and [`polymesh_edges`] of a mesh that grows by faces, kept from one
/// state to the next: a P-Hex run reveals its triangulation a layer at a time and the page draws
/// every layer, so rebuilding at every state visited each face once per later layer (1.1 M face
/// visits for the 10 203-panel roof's 111 states). [`PanelBuffers::extend`] adds only the new
/// faces, and [`PanelBuffers::since`] hands out only what they added, for a viewer that keeps
/// the rest. The buffers are relative to an origin ([`PanelBuffers::around`], [`view_origin`]).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PanelBuffers {
    /// The faces' triangles, as [`polymesh_buffers`] lays them out.
    pub buffers: TriangleBuffers,
    /// One RGB triple per vertex of `buffers`.
    pub colors: Vec<f32>,
    /// Every edge once (6 floats an edge), in the order the faces brought them.
    pub edges: Vec<f32>,
    /// Every edge so far as [`edge_keys`] has them, sorted.
    edge_keys: Vec<u64>,
    /// How many faces are in.
    faces: usize,
    /// The point every position is taken relative to.
    origin: Vec3,
    /// Where the buffers ended after each `extend`, in the order of the calls.
    marks: Vec<PanelMark>,
}

/// The lengths of [`PanelBuffers`]' vectors after an `extend` that left `faces` faces in.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct PanelMark {
    faces: usize,
    positions: usize,
    indices: usize,
    edges: usize,
}

/// What the faces from a face count on added to [`PanelBuffers`] ([`PanelBuffers::since`]):
/// appended to each vector as it stood then, it gives the vector as it stands. `indices` are
/// into the whole buffers (the vertices before the tail count too).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PanelTail<'a> {
    /// See [`TriangleBuffers::positions`].
    pub positions: &'a [f32],
    /// See [`TriangleBuffers::normals`].
    pub normals: &'a [f32],
    /// See [`TriangleBuffers::indices`].
    pub indices: &'a [u32],
    /// See [`PanelBuffers::colors`].
    pub colors: &'a [f32],
    /// See [`PanelBuffers::edges`].
    pub edges: &'a [f32],
}

impl PanelBuffers {
    /// Empty buffers whose positions will be taken relative to `origin` (see [`view_origin`]);
    /// `default()` is relative to zero.
    pub fn around(origin: Vec3) -> Self {
        PanelBuffers {
            origin,
            ..PanelBuffers::default()
        }
    }

    /// The point the positions are relative to.
    pub fn origin(&self) -> Vec3 {
        self.origin
    }

    /// How many faces are in: the first `faces()` of the meshes given to `extend`.
    pub fn faces(&self) -> usize {
        self.faces
    }

    /// Adds faces `self.faces()..` of `mesh`, face `self.faces() + k` coloured
    /// `new_face_colors[k]` (one triple per new face). `mesh`'s first `self.faces()` faces must
    /// be the ones already in, at the same positions (the caller checks: the buffers cannot).
    pub fn extend(&mut self, mesh: &PolyMesh, new_face_colors: &[[f32; 3]]) {
        let from = self.faces.min(mesh.num_faces());
        push_faces(
            mesh,
            from,
            Some(new_face_colors),
            self.origin,
            &mut self.buffers,
            &mut self.colors,
        );
        let mut fresh = edge_keys(mesh, from);
        fresh.retain(|k| self.edge_keys.binary_search(k).is_err());
        push_edge_segments(mesh, &fresh, self.origin, &mut self.edges);
        if !fresh.is_empty() {
            self.edge_keys.extend(fresh);
            // Two sorted runs: the sort merges them in linear time.
            self.edge_keys.sort();
        }
        self.faces = mesh.num_faces();
        self.marks.push(PanelMark {
            faces: self.faces,
            positions: self.buffers.positions.len(),
            indices: self.buffers.indices.len(),
            edges: self.edges.len(),
        });
    }

    /// What the faces from `faces` on added, when the buffers held exactly `faces` faces after
    /// some `extend` (or `faces` is 0); `None` otherwise.
    pub fn since(&self, faces: usize) -> Option<PanelTail<'_>> {
        let mark = if faces == 0 {
            PanelMark::default()
        } else {
            // Face counts only grow from one extend to the next.
            let k = self.marks.partition_point(|m| m.faces < faces);
            *self.marks.get(k).filter(|m| m.faces == faces)?
        };
        Some(PanelTail {
            positions: &self.buffers.positions[mark.positions..],
            normals: &self.buffers.normals[mark.positions..],
            indices: &self.buffers.indices[mark.indices..],
            colors: &self.colors[mark.positions..],
            edges: &self.edges[mark.edges..],
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polymesh_buffers_fan_faces_and_list_edges_once() {
        let p = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(2.0, 0.5, 0.0),
        ];
        let m = crate::mesh::PolyMesh::new(p, [vec![0u32, 1, 2, 3], vec![1, 4, 2]]).unwrap();
        let (b, c) = polymesh_buffers(&m, Some(&[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]));
        assert_eq!(b.vertex_count(), 7);
        assert_eq!(b.triangle_count(), 3);
        assert_eq!(c.len(), 21);
        assert_eq!(&c[12..15], &[0.0, 1.0, 0.0]);
        assert!(b.normals.chunks(3).all(|n| n == [0.0, 0.0, 1.0]));
        // 4 + 3 edges, the shared edge 1-2 once, each from its lower vertex.
        let edges = polymesh_edges(&m);
        let pairs: Vec<[usize; 2]> = edges
            .chunks(6)
            .map(|e| {
                let find = |q: &[f32]| {
                    (0..5)
                        .find(|&v| {
                            let p = m.positions[v];
                            [p.x as f32, p.y as f32, p.z as f32] == q
                        })
                        .unwrap()
                };
                [find(&e[..3]), find(&e[3..])]
            })
            .collect();
        assert_eq!(pairs, [[0, 1], [0, 3], [1, 2], [1, 4], [2, 3], [2, 4]]);
    }

    /// A 6 x 5 grid of quads, each split into two triangles with the odd ones reversed, so
    /// shared edges come both ways.
    fn triangles() -> PolyMesh {
        let positions = (0..6)
            .flat_map(|j| (0..7).map(move |i| Vec3::new(i as f64, j as f64, (i * j) as f64 * 0.1)))
            .collect();
        let faces: Vec<[u32; 3]> = (0..5u32)
            .flat_map(|j| {
                (0..6u32).flat_map(move |i| {
                    let v = |a: u32, b: u32| b * 7 + a;
                    [
                        [v(i, j), v(i + 1, j), v(i + 1, j + 1)],
                        [v(i, j), v(i + 1, j + 1), v(i, j + 1)],
                    ]
                })
            })
            .collect();
        PolyMesh::new(positions, faces).unwrap()
    }

    /// The first `n` faces of `mesh`.
    fn first(mesh: &PolyMesh, n: usize) -> PolyMesh {
        PolyMesh::new(
            mesh.positions.clone(),
            (0..n).map(|i| mesh.face(i).to_vec()).collect::<Vec<_>>(),
        )
        .unwrap()
    }

    /// Grown a layer at a time, the buffers are the one-shot ones bit for bit and the edges
    /// the same set, each once; in one go, the edges too are the one-shot ones.
    #[test]
    fn panel_buffers_grown_by_layers_are_the_one_shot_ones() {
        let mesh = triangles();
        let colors: Vec<[f32; 3]> = (0..mesh.num_faces())
            .map(|i| [i as f32 / 60.0, 0.5, 1.0 - i as f32 / 60.0])
            .collect();
        let (buffers, vertex_colors) = polymesh_buffers(&mesh, Some(&colors));
        let mut grown = PanelBuffers::default();
        for n in [0, 7, 12, 12, 31, 60] {
            grown.extend(&first(&mesh, n), &colors[grown.faces()..n]);
            assert_eq!(grown.faces(), n);
        }
        assert_eq!(grown.buffers, buffers);
        assert_eq!(grown.colors, vertex_colors);
        let segments = |e: &[f32]| {
            let mut s: Vec<Vec<u32>> = e
                .chunks(6)
                .map(|c| c.iter().map(|x| x.to_bits()).collect())
                .collect();
            s.sort();
            s
        };
        let one_shot = polymesh_edges(&mesh);
        assert_eq!(one_shot.len(), 6 * (6 * 6 + 7 * 5 + 30));
        assert_eq!(segments(&grown.edges), segments(&one_shot));
        let mut once = PanelBuffers::default();
        once.extend(&mesh, &colors);
        assert_eq!(once.edges, one_shot);
        assert_eq!(once.buffers, buffers);
    }

    /// The tail since any face count an `extend` left, appended to the buffers as they were
    /// then, gives the buffers as they are; a count no `extend` left has no tail.
    #[test]
    fn a_tail_appended_to_earlier_buffers_gives_the_current_ones() {
        let mesh = triangles();
        let colors: Vec<[f32; 3]> = (0..mesh.num_faces())
            .map(|i| [i as f32 / 60.0, 0.25, 0.5])
            .collect();
        let mut grown = PanelBuffers::default();
        let mut earlier = vec![grown.clone()];
        for n in [7, 12, 12, 31, 60] {
            grown.extend(&first(&mesh, n), &colors[grown.faces()..n]);
            earlier.push(grown.clone());
        }
        for then in &earlier {
            let tail = grown.since(then.faces()).unwrap();
            let cat = |a: &[f32], b: &[f32]| [a, b].concat();
            assert_eq!(
                cat(&then.buffers.positions, tail.positions),
                grown.buffers.positions
            );
            assert_eq!(
                cat(&then.buffers.normals, tail.normals),
                grown.buffers.normals
            );
            assert_eq!(
                [then.buffers.indices.as_slice(), tail.indices].concat(),
                grown.buffers.indices
            );
            assert_eq!(cat(&then.colors, tail.colors), grown.colors);
            assert_eq!(cat(&then.edges, tail.edges), grown.edges);
        }
        assert!(grown.since(60).unwrap().indices.is_empty());
        for n in [1, 6, 8, 30, 59, 61] {
            assert_eq!(grown.since(n), None, "{n}");
        }
    }

    /// A design at state-plane coordinates is drawn relative to its view origin exactly as
    /// the same design near zero: positions, normals (whose cross products would cancel in
    /// absolute coordinates) and edges, bit for bit.
    #[test]
    fn a_far_design_is_drawn_as_finely_as_one_near_zero() {
        let near = triangles();
        let shift = Vec3::new(3.0 * 2f64.powi(22), 5.0 * 2f64.powi(22), 0.0);
        let mut far = near.clone();
        far.positions.iter_mut().for_each(|p| *p += shift);
        assert_eq!(view_origin(&near.positions), Vec3::zeros());
        assert_eq!(view_origin(&far.positions), shift);
        let colors = vec![[0.5f32; 3]; near.num_faces()];
        let mut relative = PanelBuffers::around(view_origin(&far.positions));
        relative.extend(&far, &colors);
        let mut at_zero = PanelBuffers::default();
        at_zero.extend(&near, &colors);
        assert_eq!(relative.buffers, at_zero.buffers);
        assert_eq!(relative.edges, at_zero.edges);
        assert_eq!(relative.origin(), shift);
    }

    /// The view origin is zero near zero, round and within one and a half sizes of every point
    /// far from it, unmoved by a move smaller than its rounding step, and ignores non-finite
    /// points.
    #[test]
    fn the_view_origin_is_near_the_design_and_round() {
        let v = Vec3::new;
        assert_eq!(view_origin(&[]), Vec3::zeros());
        assert_eq!(view_origin(&[v(f64::NAN, 0.0, 0.0)]), Vec3::zeros());
        // 256 sizes away is still near.
        assert_eq!(
            view_origin(&[v(255.0, 0.0, 0.0), v(257.0, 0.0, 0.0)]),
            Vec3::zeros()
        );
        let roof = [
            v(3_000_123.4, 5_000_456.7, 96.0),
            v(3_000_143.9, 5_000_470.2, 104.5),
        ];
        let o = view_origin(&roof);
        assert_ne!(o, Vec3::zeros());
        assert!(o.iter().all(|c| (c / 32.0).fract() == 0.0), "{o}");
        assert!(roof.iter().all(|p| (p - o).amax() <= 1.5 * 20.5), "{o}");
        let nudged = roof.map(|p| p + v(0.01, -0.01, 0.0));
        assert_eq!(view_origin(&nudged), o);
        let with_nan = [
            roof[0],
            v(f64::NAN, 1.0, 1.0),
            roof[1],
            v(f64::INFINITY, 0.0, 0.0),
        ];
        assert_eq!(view_origin(&with_nan), o);
        // One point far away: itself, to within half a unit.
        let one = view_origin(&[v(4e6 + 0.3, -2e6, 7.0)]);
        assert_eq!(one, v(4e6, -2e6, 7.0));
        // Extreme coordinates stay finite.
        let huge = view_origin(&[Vec3::repeat(f64::MAX), Vec3::repeat(f64::MAX * 0.5)]);
        assert!(huge.iter().all(|c| c.is_finite()));
    }
}
