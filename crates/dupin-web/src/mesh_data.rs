//! Triangle buffers handed to JavaScript as typed arrays.

use crate::js::to_js;
use dupin_core::mesh::{
    PanelBuffers, PanelTail, PolyMesh, TriangleBuffers, face_planarity, planarity_color,
    polymesh_buffers, polymesh_edges, view_origin, write_obj,
};

use dupin_core::surface::{Torus, sample_surface};

use dupin_core::Vec3;
use serde::{Deserialize, Serialize};
use wasm_bindgen::prelude::*;

/// Where a shown mesh stands in its run (`Session.meshSince`): under one revision the mesh
/// only grows, so its first `faces` faces and `vertices` positions are those it had then.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct MeshKey {
    pub(crate) revision: u64,
    pub(crate) faces: usize,
    pub(crate) vertices: usize,
}

/// A triangle mesh as typed arrays: `positions` and `normals` (3 floats a vertex), `indices`
/// (3 a triangle).
#[wasm_bindgen]
pub struct MeshData {
    pub(crate) buffers: TriangleBuffers,
    /// Linear RGB per vertex (empty: the viewer's default colour).
    pub(crate) colors: Vec<f32>,
    /// Panel edges as segment endpoint pairs (empty: none drawn).
    pub(crate) edges: Vec<f32>,
    /// The polygon mesh behind the triangles, when there is one (OBJ export keeps its faces).
    pub(crate) panels: Option<PolyMesh>,
    /// The polygon mesh as handed over by a worker (`setPanels`): built into a [`PolyMesh`]
    /// only when asked for (presentation, OBJ), not on every frame's update.
    pub(crate) panel_arrays: Option<(Vec<f64>, Vec<u32>)>,
    /// The point every position here is relative to (`Session`'s view origin); the OBJ adds
    /// it back.
    pub(crate) view_origin: Vec3,
    /// Where a session's mesh stands in its run (`Session.meshSince`); `None` for a mesh that
    /// cannot be added to.
    pub(crate) key: Option<MeshKey>,
    /// For only what was added to a session's mesh: the key of the mesh it adds to.
    pub(crate) append_to: Option<MeshKey>,
}

impl MeshData {
    /// A smooth surface preview without colours or edges.
    pub(crate) fn smooth(buffers: TriangleBuffers) -> Self {
        MeshData {
            buffers,
            colors: Vec::new(),
            edges: Vec::new(),
            panels: None,
            panel_arrays: None,
            view_origin: Vec3::zeros(),
            key: None,
            append_to: None,
        }
    }

    /// Flat panels of `mesh`, coloured per face, with their edges.
    pub(crate) fn panels(mesh: PolyMesh, face_colors: &[[f32; 3]]) -> Self {
        let (buffers, colors) = polymesh_buffers(&mesh, Some(face_colors));
        MeshData {
            buffers,
            colors,
            edges: polymesh_edges(&mesh),
            panels: Some(mesh),
            panel_arrays: None,
            view_origin: Vec3::zeros(),
            key: None,
            append_to: None,
        }
    }

    /// Flat panels of `mesh` from its [`PanelBuffers`].
    pub(crate) fn from_panel_buffers(mesh: PolyMesh, panels: PanelBuffers) -> Self {
        MeshData {
            buffers: panels.buffers,
            colors: panels.colors,
            edges: panels.edges,
            panels: Some(mesh),
            panel_arrays: None,
            view_origin: Vec3::zeros(),
            key: None,
            append_to: None,
        }
    }

    /// What a session's mesh added since it stood at `since` (`Session.meshSince`): the render
    /// buffers' `tail`, the added panel positions (x y z each, relative to `view_origin`) and
    /// faces (`panelFaces`' layout); `key` is where the mesh stands now.
    pub(crate) fn tail(
        tail: PanelTail<'_>,
        panel_arrays: (Vec<f64>, Vec<u32>),
        view_origin: Vec3,
        since: MeshKey,
        key: MeshKey,
    ) -> Self {
        MeshData {
            buffers: TriangleBuffers {
                positions: tail.positions.to_vec(),
                normals: tail.normals.to_vec(),
                indices: tail.indices.to_vec(),
            },
            colors: tail.colors.to_vec(),
            edges: tail.edges.to_vec(),
            panels: None,
            panel_arrays: Some(panel_arrays),
            view_origin,
            key: Some(key),
            append_to: Some(since),
        }
    }

    /// Adds `mesh` as an extra layer in one colour, with its edges when `edges` is set (the
    /// renderer draws one triangle mesh and one line set, so layers are merged into them).
    pub(crate) fn add_layer(&mut self, mesh: &PolyMesh, color: [f32; 3], edges: bool) {
        let colors = vec![color; mesh.num_faces()];
        let (b, c) = polymesh_buffers(mesh, Some(&colors));
        let base = self.buffers.vertex_count() as u32;
        if self.colors.is_empty() {
            self.colors = vec![1.0; self.buffers.positions.len()];
        }
        self.buffers.positions.extend_from_slice(&b.positions);
        self.buffers.normals.extend_from_slice(&b.normals);
        self.buffers
            .indices
            .extend(b.indices.iter().map(|&i| i + base));
        self.colors.extend_from_slice(&c);
        if edges {
            self.edges.extend_from_slice(&polymesh_edges(mesh));
        }
    }

    /// Adds line segments (x y z of both endpoints per segment).
    pub(crate) fn add_lines(&mut self, segments: &[f32]) {
        self.edges.extend_from_slice(segments);
    }
}

#[wasm_bindgen]
impl MeshData {
    /// Rebuilds a mesh from the typed arrays of its getters (how a Web Worker hands render
    /// buffers to the page's thread). Throws when the lengths do not fit together or an index
    /// is out of range.
    #[wasm_bindgen(js_name = fromArrays)]
    pub fn from_arrays(
        positions: Vec<f32>,
        normals: Vec<f32>,
        indices: Vec<u32>,
        colors: Vec<f32>,
        edges: Vec<f32>,
    ) -> Result<MeshData, JsError> {
        let n = positions.len();
        if !n.is_multiple_of(3)
            || normals.len() != n
            || !indices.len().is_multiple_of(3)
            || !edges.len().is_multiple_of(6)
        {
            return Err(JsError::new(
                "mesh arrays: positions and normals need 3 floats a vertex, indices 3 a triangle, edges 6 a segment",
            ));
        }
        if !colors.is_empty() && colors.len() != n {
            return Err(JsError::new(
                "mesh arrays: colors need 3 floats a vertex (or none)",
            ));
        }
        if let Some(&i) = indices.iter().find(|&&i| i as usize >= n / 3) {
            return Err(JsError::new(&format!(
                "mesh arrays: index {i} out of range for {} vertices",
                n / 3
            )));
        }
        Ok(MeshData {
            buffers: TriangleBuffers {
                positions,
                normals,
                indices,
            },
            colors,
            edges,
            panels: None,
            panel_arrays: None,
            view_origin: Vec3::zeros(),
            key: None,
            append_to: None,
        })
    }

    /// The polygons behind the triangles as `panelPositions` (x y z a vertex, f64) and
    /// `panelFaces` (per face its corner count, then its corners); empty for a smooth surface.
    #[wasm_bindgen(getter, js_name = panelPositions)]
    pub fn panel_positions(&self) -> js_sys::Float64Array {
        match (&self.panels, &self.panel_arrays) {
            (Some(mesh), _) => js_sys::Float64Array::from(panel_position_array(mesh).as_slice()),
            (None, Some((positions, _))) => js_sys::Float64Array::from(positions.as_slice()),
            (None, None) => js_sys::Float64Array::new_with_length(0),
        }
    }

    /// The number of polygons behind the triangles (0 for a smooth surface or a worker's mesh
    /// before `setPanels`).
    #[wasm_bindgen(getter, js_name = panelCount)]
    pub fn panel_count(&self) -> usize {
        self.panels.as_ref().map_or(0, PolyMesh::num_faces)
    }

    /// See [`MeshData::panel_positions`].
    #[wasm_bindgen(getter, js_name = panelFaces)]
    pub fn panel_faces(&self) -> js_sys::Uint32Array {
        match (&self.panels, &self.panel_arrays) {
            (Some(mesh), _) => js_sys::Uint32Array::from(panel_face_array(mesh).as_slice()),
            (None, Some((_, faces))) => js_sys::Uint32Array::from(faces.as_slice()),
            (None, None) => js_sys::Uint32Array::new_with_length(0),
        }
    }

    /// Where a session's mesh stands in its run, `{ revision, faces, vertices }`: give it to
    /// `Session.meshSince` for only what the run adds next. `undefined` for a mesh that cannot
    /// be added to (colours other than planarity, extra layers or anchors drawn, or not a
    /// session's).
    #[wasm_bindgen(getter)]
    pub fn key(&self) -> Result<JsValue, JsError> {
        self.key.map_or(Ok(JsValue::UNDEFINED), |k| to_js(&k))
    }

    /// For only what was added to a session's mesh (`Session.meshSince`): the `key` of the
    /// mesh it adds to; `undefined` for a whole mesh.
    #[wasm_bindgen(getter, js_name = appendTo)]
    pub fn append_to(&self) -> Result<JsValue, JsError> {
        self.append_to.map_or(Ok(JsValue::UNDEFINED), |k| to_js(&k))
    }

    /// Attaches the polygons of `panelPositions`/`panelFaces` (a worker's mesh rebuilt with
    /// `fromArrays`) and its `viewOrigin` (3 numbers; none: zero), so that presentation and
    /// OBJ keep the true panels. Checked when used; throws for an origin that is not 3 finite
    /// numbers.
    #[wasm_bindgen(js_name = setPanels)]
    pub fn set_panels(
        &mut self,
        positions: Vec<f64>,
        faces: Vec<u32>,
        origin: Option<Vec<f64>>,
    ) -> Result<(), JsError> {
        let origin = match origin.as_deref() {
            None => Vec3::zeros(),
            Some(&[x, y, z]) if [x, y, z].iter().all(|c| c.is_finite()) => Vec3::new(x, y, z),
            Some(_) => return Err(JsError::new("a view origin needs 3 finite numbers")),
        };
        self.panels = None;
        self.panel_arrays = (!faces.is_empty()).then_some((positions, faces));
        self.view_origin = origin;
        Ok(())
    }

    /// The point the positions are relative to (3 numbers): zero but for an opened design
    /// far from zero, whose view is centred near it so that `f32` resolves it.
    #[wasm_bindgen(getter, js_name = viewOrigin)]
    pub fn view_origin(&self) -> Vec<f64> {
        vec![self.view_origin.x, self.view_origin.y, self.view_origin.z]
    }

    /// Vertex positions, x y z per vertex.
    #[wasm_bindgen(getter)]
    pub fn positions(&self) -> js_sys::Float32Array {
        js_sys::Float32Array::from(self.buffers.positions.as_slice())
    }

    /// Unit vertex normals.
    #[wasm_bindgen(getter)]
    pub fn normals(&self) -> js_sys::Float32Array {
        js_sys::Float32Array::from(self.buffers.normals.as_slice())
    }

    /// Triangle vertex indices.
    #[wasm_bindgen(getter)]
    pub fn indices(&self) -> js_sys::Uint32Array {
        js_sys::Uint32Array::from(self.buffers.indices.as_slice())
    }

    /// Linear RGB per vertex (empty for the default colour).
    #[wasm_bindgen(getter)]
    pub fn colors(&self) -> js_sys::Float32Array {
        js_sys::Float32Array::from(self.colors.as_slice())
    }

    /// Panel edges: x y z of both endpoints per edge.
    #[wasm_bindgen(getter)]
    pub fn edges(&self) -> js_sys::Float32Array {
        js_sys::Float32Array::from(self.edges.as_slice())
    }

    /// Number of vertices.
    #[wasm_bindgen(getter, js_name = vertexCount)]
    pub fn vertex_count(&self) -> usize {
        self.buffers.vertex_count()
    }

    /// Number of triangles.
    #[wasm_bindgen(getter, js_name = triangleCount)]
    pub fn triangle_count(&self) -> usize {
        self.buffers.triangle_count()
    }

    /// The mesh as OBJ text (the outside contract's format; panels keep their true size and
    /// place: the view origin is added back).
    #[wasm_bindgen(js_name = toObj)]
    pub fn to_obj(&self) -> Result<String, JsError> {
        let mut mesh = self.to_polymesh()?;
        if self.view_origin != Vec3::zeros() {
            mesh.positions
                .iter_mut()
                .for_each(|p| *p += self.view_origin);
        }
        Ok(write_obj(&mesh))
    }
}

impl MeshData {
    /// The mesh as polygons: the panels where the data carries them, else its triangles.
    pub(crate) fn to_polymesh(&self) -> Result<PolyMesh, JsError> {
        if let Some(mesh) = &self.panels {
            return Ok(mesh.clone());
        }
        if let Some((positions, faces)) = &self.panel_arrays {
            return panels_from_arrays(positions, faces).map_err(|e| JsError::new(&e));
        }
        let positions = self
            .buffers
            .positions
            .chunks_exact(3)
            .map(|p| Vec3::new(p[0] as f64, p[1] as f64, p[2] as f64))
            .collect();
        PolyMesh::new(positions, self.buffers.indices.chunks_exact(3)).map_err(crate::js::err)
    }
}

/// `mesh`'s `panelPositions` array (see [`MeshData::panel_faces`]).
fn panel_position_array(mesh: &PolyMesh) -> Vec<f64> {
    panel_positions_from(mesh, 0, Vec3::zeros())
}

/// The `panelPositions` of `mesh`'s vertices `from..`, relative to `origin`.
pub(crate) fn panel_positions_from(mesh: &PolyMesh, from: usize, origin: Vec3) -> Vec<f64> {
    mesh.positions[from..]
        .iter()
        .flat_map(|p| {
            let q = p - origin;
            [q.x, q.y, q.z]
        })
        .collect()
}

/// `mesh`'s `panelFaces` array (see [`MeshData::panel_faces`]).
fn panel_face_array(mesh: &PolyMesh) -> Vec<u32> {
    panel_faces_from(mesh, 0)
}

/// The `panelFaces` of `mesh`'s faces `from..`.
pub(crate) fn panel_faces_from(mesh: &PolyMesh, from: usize) -> Vec<u32> {
    (from..mesh.num_faces())
        .flat_map(|i| {
            let f = mesh.face(i);
            std::iter::once(f.len() as u32).chain(f.iter().copied())
        })
        .collect()
}

/// A polygon mesh from `panelPositions`/`panelFaces` arrays (see [`MeshData::panel_faces`]).
fn panels_from_arrays(positions: &[f64], faces: &[u32]) -> Result<PolyMesh, String> {
    let bad = || {
        "panel arrays: positions need 3 numbers a vertex, faces a count then that many corners"
            .to_string()
    };
    if !positions.len().is_multiple_of(3) {
        return Err(bad());
    }
    let points: Vec<Vec3> = positions
        .chunks_exact(3)
        .map(|p| Vec3::new(p[0], p[1], p[2]))
        .collect();
    let mut polygons: Vec<&[u32]> = Vec::new();
    let mut rest = faces;
    while let Some((&n, tail)) = rest.split_first() {
        let n = n as usize;
        if n < 3 || n > tail.len() {
            return Err(bad());
        }
        polygons.push(&tail[..n]);
        rest = &tail[n..];
    }
    PolyMesh::new(points, polygons).map_err(|e| e.to_string())
}

/// Samples the torus ((R + r cos v) cos u, (R + r cos v) sin u, r sin v) on a `nu` x `nv` grid.
///
/// Throws when R or r is not a positive finite number, or the grid is outside 3..=2048.
#[wasm_bindgen(js_name = torusMesh)]
pub fn torus_mesh(major: f64, minor: f64, nu: u32, nv: u32) -> Result<MeshData, JsError> {
    for (name, value) in [("R", major), ("r", minor)] {
        if !(value.is_finite() && value > 0.0) {
            return Err(JsError::new(&format!(
                "torus {name} must be a positive number, got {value}"
            )));
        }
    }
    for (name, value) in [("nu", nu), ("nv", nv)] {
        if !(3..=2048).contains(&value) {
            return Err(JsError::new(&format!(
                "torus grid {name} must be between 3 and 2048, got {value}"
            )));
        }
    }
    let buffers = sample_surface(&Torus { major, minor }, nu as usize, nv as usize);
    Ok(MeshData::smooth(buffers))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A worker's panels survive the trip through typed arrays polygon for polygon, and bad
    /// arrays are refused.
    #[test]
    fn panels_travel_as_arrays() {
        let m = dupin_core::scenes::benchmark_meshes::torus_centroid_dual(12, 6, 2.0, 0.7);
        let colors = vec![[1.0f32; 3]; m.num_faces()];
        let data = MeshData::panels(m.clone(), &colors);
        let panels = data.panels.as_ref().unwrap();
        let (p, f) = (panel_position_array(panels), panel_face_array(panels));
        let mut rebuilt = MeshData::smooth(data.buffers.clone());
        assert!(rebuilt.set_panels(p.clone(), f.clone(), None).is_ok());
        let back = rebuilt.to_polymesh().unwrap();
        assert_eq!(back, m);
        // Panels relative to a view origin come back there in the OBJ.
        let origin = vec![1024.0, -2048.0, 0.5];
        assert!(
            rebuilt
                .set_panels(p.clone(), f.clone(), Some(origin.clone()))
                .is_ok()
        );
        assert_eq!(rebuilt.view_origin(), origin);
        let mut moved = m.clone();
        moved
            .positions
            .iter_mut()
            .for_each(|q| *q += Vec3::new(1024.0, -2048.0, 0.5));
        assert_eq!(rebuilt.to_obj().ok(), Some(write_obj(&moved)));
        for bad in [vec![7, 0, 1, 2], vec![2, 0, 1], vec![3, 0, 1]] {
            assert!(panels_from_arrays(&p, &bad).is_err(), "{bad:?}");
        }
        assert!(panels_from_arrays(&p[1..], &f).is_err());
    }
}

/// Largest design text `designMesh` parses (bytes) and largest face count it shows.
const DESIGN_TEXT_LIMIT: usize = 256 << 20;
const DESIGN_FACE_LIMIT: usize = 2_000_000;

/// The polygon mesh of a design file: `{ vertices: [[x, y, z]], faces: [[i, ...]] }` (0-based),
/// bare or under `mesh` as Dupin's JSON export writes it (`Session.exportJson`).
#[derive(serde::Deserialize)]
struct DesignJson {
    mesh: Option<PanelsJson>,
    #[serde(flatten)]
    bare: Option<PanelsJson>,
}

#[derive(serde::Deserialize)]
struct PanelsJson {
    vertices: Vec<[f64; 3]>,
    faces: Vec<Vec<u32>>,
}

/// The panels of a design file (`{ vertices: [[x, y, z]], faces: [[i, ...]] }`, 0-based, bare or
/// under `mesh` as the JSON export writes it) for a `Viewer`, flat and coloured by
/// planarity as the page colours a run, with their edges: what the `<dupin-viewer>` element
/// shows.
///
/// Throws, naming what to fix, for text over 256 MB, JSON without `vertices` and `faces`,
/// over 2 000 000 faces, and faces naming missing vertices or with fewer than three.
#[wasm_bindgen(js_name = designMesh)]
pub fn design_mesh(json: &str) -> Result<MeshData, JsError> {
    let mesh = design_panels(json).map_err(|e| JsError::new(&e))?;
    Ok(design_view(mesh))
}

/// A design's panels coloured by planarity (measured where the design is) and drawn relative
/// to their view origin, so a design at state-plane coordinates is drawn as finely as one at
/// zero.
fn design_view(mut mesh: PolyMesh) -> MeshData {
    let colors: Vec<[f32; 3]> = (0..mesh.num_faces())
        .map(|i| planarity_color(face_planarity(&mesh, i)))
        .collect();
    let origin = view_origin(&mesh.positions);
    mesh.positions.iter_mut().for_each(|p| *p -= origin);
    let mut data = MeshData::panels(mesh, &colors);
    data.view_origin = origin;
    data
}

/// The polygon mesh of a design file, or what is wrong with it (see [`design_mesh`]).
fn design_panels(json: &str) -> Result<PolyMesh, String> {
    if json.len() > DESIGN_TEXT_LIMIT {
        return Err(format!(
            "the design is {} MB of text; a viewer reads at most 256 MB",
            json.len() >> 20
        ));
    }
    let design: DesignJson = serde_json::from_str(json).map_err(|e| {
        format!(
            "not a Dupin design: {e} (expected {{\"mesh\": {{\"vertices\": [[x, y, z], ...], \"faces\": [[0, 1, 2], ...]}}}}, as the JSON export writes it)"
        )
    })?;
    let panels = design.mesh.or(design.bare).ok_or(
        "not a Dupin design: no `mesh` with `vertices` and `faces` (as the JSON export writes it)",
    )?;
    if panels.faces.len() > DESIGN_FACE_LIMIT {
        return Err(format!(
            "the design has {} faces; a viewer shows at most 2000000",
            panels.faces.len()
        ));
    }
    let points = panels.vertices.iter().map(|p| Vec3::new(p[0], p[1], p[2]));
    PolyMesh::new(points.collect(), panels.faces).map_err(|e| format!("the design's mesh: {e}"))
}

#[cfg(test)]
mod design_tests {
    use super::*;

    /// A design far from zero is shown as the same design at zero, with its colours, and its
    /// OBJ is where the file put it.
    #[test]
    fn a_far_design_is_viewed_as_one_at_zero() {
        let json = |dx: f64| {
            format!(
                r#"{{"vertices": [[{a},-0.5,0],[{b},-0.5,0],[{b},0.5,0.25],[{a},0.5,-0.25]], "faces": [[0,1,2,3]]}}"#,
                a = dx - 0.5,
                b = dx + 0.5
            )
        };
        let near = design_view(design_panels(&json(0.0)).unwrap());
        let far_mesh = design_panels(&json(4_194_304.0)).unwrap();
        let far = design_view(far_mesh.clone());
        assert_eq!(far.view_origin, Vec3::new(4_194_304.0, 0.0, 0.0));
        assert_eq!(far.buffers, near.buffers);
        assert_eq!(far.colors, near.colors);
        assert_eq!(far.to_obj().ok(), Some(write_obj(&far_mesh)));
    }

    #[test]
    fn a_design_is_read_bare_or_as_the_json_export_writes_it() {
        let bare = r#"{"vertices": [[0,0,0],[1,0,0],[1,1,0],[0,1,0]], "faces": [[0,1,2,3]]}"#;
        let export = format!(r#"{{"config": {{}}, "metrics": {{}}, "mesh": {bare}}}"#);
        for text in [bare, export.as_str()] {
            let m = design_panels(text).unwrap();
            assert_eq!((m.num_vertices(), m.num_faces()), (4, 1));
        }
    }

    #[test]
    fn a_bad_design_says_what_is_wrong() {
        let cases = [
            ("{", "not a Dupin design"),
            (r#"{"config": {}}"#, "no `mesh`"),
            (
                r#"{"vertices": [[0,0,0]], "faces": [[0,1,2]]}"#,
                "the design's mesh",
            ),
            (
                r#"{"vertices": [[0,0,"x"]], "faces": []}"#,
                "not a Dupin design",
            ),
        ];
        for (text, want) in cases {
            let e = design_panels(text).unwrap_err();
            assert!(e.contains(want), "{text}: {e}");
        }
    }
}
