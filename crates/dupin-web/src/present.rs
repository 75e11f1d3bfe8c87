//! Presentation mode: the current panel mesh as glass with metal frames (beams along edges,
//! nodes at vertices), optionally with its offset layer (conical-meshes paper, section on
//! offsets: `dupin_core::conical::offset_mesh`) joined by support beams, drawn by
//! `dupin_render::PresentationRenderer` (sun shadow map, hemisphere light) with a damped orbit.

// Scene building is used by the wasm-only `Presenter` (and the native tests).
#![cfg_attr(not(target_arch = "wasm32"), allow(dead_code))]

use crate::mesh_data::MeshData;
use dupin_core::Vec3;
use dupin_core::conical::offset_mesh;
use dupin_core::mesh::{PolyMesh, TriangleBuffers, polymesh_buffers};
use dupin_core::scenes::benchmark_meshes::torus_quad_mesh;
use wasm_bindgen::prelude::*;

/// Glass and frame buffers of a presentation scene, with counts for the page.
pub(crate) struct Scene {
    pub(crate) glass: TriangleBuffers,
    pub(crate) frames: dupin_render::FrameInstances,
    pub(crate) panels: usize,
    pub(crate) beams: usize,
    /// Why the offset layer is missing, when it was asked for and the core refused it.
    pub(crate) offset_error: Option<String>,
}

/// The largest vertex move of a drawn offset layer, in face distances.
const MAX_OFFSET_MOVE: f64 = 10.0;

/// Builds the scene for `mesh`; with `offset`, adds the face-offset layer at a quarter of the
/// mean edge length and a support beam from each vertex to its offset.
pub(crate) fn build_scene(mesh: &PolyMesh, offset: bool) -> Scene {
    let edges = dupin_core::mesh::polymesh_edges(mesh);
    let (mut sum, mut n) = (0.0f64, 0usize);
    for s in edges.chunks_exact(6) {
        let d = ((s[3] - s[0]).powi(2) + (s[4] - s[1]).powi(2) + (s[5] - s[2]).powi(2)).sqrt();
        if d.is_finite() {
            sum += d as f64;
            n += 1;
        }
    }
    let mean = if n > 0 { sum / n as f64 } else { 1.0 };
    let (beam, node) = ((0.06 * mean) as f32, (0.11 * mean) as f32);
    let (mut glass, _) = polymesh_buffers(mesh, None);
    let mut frame_edges = edges;
    let mut offset_error = None;
    let mut panels = mesh.num_faces();
    if offset {
        let distance = 0.25 * mean;
        let checked = offset_mesh(mesh, distance)
            .map_err(|e| e.to_string())
            .and_then(|off| offset_admitted(mesh, &off, distance).map(|()| off));
        match checked {
            Ok(off) => {
                let (g, _) = polymesh_buffers(&off, None);
                append(&mut glass, &g);
                frame_edges.extend(dupin_core::mesh::polymesh_edges(&off));
                // Support beams: vertex i of the mesh to vertex i of its offset.
                for i in 0..mesh.num_vertices().min(off.num_vertices()) {
                    let (a, b): (Vec3, Vec3) = (mesh.positions[i], off.positions[i]);
                    frame_edges.extend([a.x, a.y, a.z, b.x, b.y, b.z].map(|x| x as f32));
                }
                panels += off.num_faces();
            }
            Err(e) => offset_error = Some(format!("no offset layer: {e}")),
        }
    }
    let beams = frame_edges.len() / 6;
    Scene {
        glass,
        frames: dupin_render::frame_instances(&frame_edges, beam, node),
        panels,
        beams,
        offset_error,
    }
}

/// Whether the offset `off` of `mesh` at face distance `distance` is one to draw: faces that
/// are nearly coplanar around a vertex meet far away, an offset that exists but is no frame
/// anyone builds; the reason says so instead of drawing it.
fn offset_admitted(mesh: &PolyMesh, off: &PolyMesh, distance: f64) -> Result<(), String> {
    let (worst, v) = (0..mesh.num_vertices().min(off.num_vertices()))
        .map(|i| ((off.positions[i] - mesh.positions[i]).norm(), i))
        .fold((0.0f64, 0), |a, b| if b.0 > a.0 { b } else { a });
    if worst > MAX_OFFSET_MOVE * distance.abs() {
        return Err(format!(
            "at face distance {distance:.3} vertex {v} would move {worst:.3} ({:.0}x): its faces \
             are nearly coplanar; conical meshes have offsets within about the distance \
             (conical paper, section 4), e.g. conical-station",
            worst / distance.abs()
        ));
    }
    Ok(())
}

fn append(a: &mut TriangleBuffers, b: &TriangleBuffers) {
    let base = a.vertex_count() as u32;
    a.positions.extend(&b.positions);
    a.normals.extend(&b.normals);
    a.indices.extend(b.indices.iter().map(|i| i + base));
}

/// A torus of about `panels` quad panels (R = 2, r = 0.7), for the presentation benchmark.
pub(crate) fn torus_panels(panels: u32) -> Result<PolyMesh, String> {
    if !(16..=200_000).contains(&panels) {
        return Err(format!("panel count must be in 16..=200000, got {panels}"));
    }
    let nu = ((panels as f64 * 2.5).sqrt().round() as usize).max(4);
    let nv = (panels as usize).div_ceil(nu).max(4);
    Ok(torus_quad_mesh(nu, nv, 2.0, 0.7))
}

/// A torus panel mesh of about `panels` quads, for trying presentation mode at scale.
#[wasm_bindgen(js_name = torusPanels)]
pub fn torus_panels_js(panels: u32) -> Result<MeshData, JsError> {
    let m = torus_panels(panels).map_err(crate::js::err)?;
    let colors = vec![[0.9f32, 0.9, 0.9]; m.num_faces()];
    Ok(MeshData::panels(m, &colors))
}

#[cfg(target_arch = "wasm32")]
pub use canvas::Presenter;

#[cfg(target_arch = "wasm32")]
mod canvas {
    use super::*;
    use crate::viewer::Canvas;
    use dupin_render::{OrbitCamera, PresentationRenderer};

    /// Presentation view on its own canvas (WebGPU, or WebGL2), with a damped orbit.
    #[wasm_bindgen]
    pub struct Presenter {
        canvas: Canvas<PresentationRenderer>,
        /// Angular velocity (yaw, pitch), radians per second, decaying with `DAMPING`.
        velocity: (f32, f32),
    }

    /// Velocity half-life of the orbit after a drag, seconds.
    const HALF_LIFE: f32 = 0.25;

    #[wasm_bindgen]
    impl Presenter {
        /// Creates the presentation view on `canvas` (`force_webgl2`: skip WebGPU).
        pub async fn create(
            canvas: web_sys::HtmlCanvasElement,
            force_webgl2: bool,
        ) -> Result<Presenter, JsError> {
            let canvas = Canvas::open(
                canvas,
                force_webgl2,
                "dupin presentation",
                PresentationRenderer::new,
            )
            .await?;
            Ok(Presenter {
                canvas,
                velocity: (0.0, 0.0),
            })
        }

        /// `"WebGPU"` or `"WebGL2"`.
        #[wasm_bindgen(getter)]
        pub fn backend(&self) -> String {
            self.canvas.backend.to_string()
        }

        /// Shows `mesh` as glass and frames (with `offset`, also its offset layer); returns
        /// `{ panels, beams, offsetError }` and frames the camera on it.
        #[wasm_bindgen(js_name = setMesh)]
        pub fn set_mesh(&mut self, mesh: &MeshData, offset: bool) -> Result<JsValue, JsError> {
            let poly = mesh.to_polymesh()?;
            let scene = build_scene(&poly, offset);
            let canvas = &mut self.canvas;
            canvas
                .renderer
                .set_scene(
                    &canvas.device,
                    &canvas.queue,
                    &scene.glass,
                    None,
                    &scene.frames,
                )
                .map_err(crate::js::err)?;
            let (c, r) = canvas.renderer.bounds();
            canvas.camera = OrbitCamera::framing(c, r);
            let info = js_sys::Object::new();
            let set = |k: &str, v: JsValue| js_sys::Reflect::set(&info, &k.into(), &v);
            let _ = set("panels", (scene.panels as f64).into());
            let _ = set("beams", (scene.beams as f64).into());
            let _ = set(
                "offsetError",
                scene.offset_error.map_or(JsValue::NULL, |e| e.into()),
            );
            Ok(info.into())
        }

        /// A drag of (`dx`, `dy`) radians: turns the view and leaves it coasting, damped.
        pub fn orbit(&mut self, dx: f32, dy: f32, dt_ms: f32) {
            if !(dx.is_finite() && dy.is_finite()) {
                return;
            }
            self.canvas.camera.orbit(dx, dy);
            let dt = (dt_ms / 1000.0).max(1.0 / 240.0);
            self.velocity = (dx / dt, dy / dt);
        }

        /// Advances the coasting orbit by `dt_ms`; true while it still moves (redraw needed).
        pub fn tick(&mut self, dt_ms: f32) -> bool {
            let dt = (dt_ms / 1000.0).clamp(0.0, 0.1);
            let (vx, vy) = self.velocity;
            if vx.hypot(vy) < 1e-3 {
                self.velocity = (0.0, 0.0);
                return false;
            }
            self.canvas.camera.orbit(vx * dt, vy * dt);
            let decay = 0.5f32.powf(dt / HALF_LIFE);
            self.velocity = (vx * decay, vy * decay);
            true
        }

        /// Stops any coasting.
        pub fn stop(&mut self) {
            self.velocity = (0.0, 0.0);
        }

        /// Moves the camera closer (`factor` < 1) or farther.
        pub fn zoom(&mut self, factor: f32) {
            self.canvas.camera.zoom(factor);
        }

        /// The camera as `[target x, y, z, distance, yaw, pitch]`, as `Viewer.camera` gives it.
        pub fn camera(&self) -> Vec<f32> {
            crate::pick::camera_numbers(&self.canvas.camera)
        }

        /// Sets the camera from six numbers as [`Presenter::camera`] gives them (a shared
        /// presentation opens on the view it was shared from). Throws for a wrong length,
        /// non-finite values or a distance that is not positive.
        #[wasm_bindgen(js_name = setCamera)]
        pub fn set_camera(&mut self, v: Vec<f32>) -> Result<(), JsError> {
            self.canvas.camera = crate::pick::camera_from(&v).map_err(crate::js::err)?;
            self.velocity = (0.0, 0.0);
            Ok(())
        }

        /// Adapts to a new canvas size in device pixels.
        pub fn resize(&mut self, width: u32, height: u32) {
            self.canvas.resize(width, height);
        }

        /// Lets wgpu deliver finished work (snapshots on WebGL2); call every frame.
        pub fn poll(&self) {
            self.canvas.poll();
        }

        /// Draws one frame.
        pub fn render(&mut self) -> Result<(), JsError> {
            self.canvas.render()
        }

        /// Renders at `scale` x the canvas size (2 for the 2x PNG); resolves to an `ImageData`.
        pub fn snapshot(&mut self, scale: f32) -> Result<js_sys::Promise, JsError> {
            self.canvas.snapshot(scale)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scene_counts_and_offset_layer() {
        let m = torus_panels(400).unwrap();
        assert!((400..=440).contains(&m.num_faces()));
        let s = build_scene(&m, false);
        assert_eq!(s.panels, m.num_faces());
        // A closed quad torus: 2 edges per face.
        assert_eq!(s.beams, 2 * m.num_faces());
        assert_eq!(s.glass.triangle_count(), 2 * m.num_faces());
        // 4 sides per beam and 6 per node, 2 triangles a side.
        assert_eq!(s.frames.beam_count(), s.beams);
        assert_eq!(s.frames.node_count(), m.num_vertices());
        assert_eq!(
            s.frames.triangle_count(),
            2 * (4 * s.beams + 6 * m.num_vertices())
        );
        let o = build_scene(&m, true);
        match &o.offset_error {
            None => {
                assert_eq!(o.panels, 2 * m.num_faces());
                assert_eq!(o.beams, 2 * s.beams + m.num_vertices());
            }
            Some(e) => assert!(e.starts_with("no offset layer"), "{e}"),
        }
        assert!(torus_panels(3).is_err());
    }

    /// Frames follow panel edges and counts are panels: a hexagon mesh is framed along its
    /// hexagons' edges (3 per face on a closed hexagon mesh), never across them.
    #[test]
    fn hexagons_are_framed_along_their_edges() {
        let m = dupin_core::scenes::benchmark_meshes::torus_centroid_dual(24, 12, 2.0, 0.7);
        assert!(m.faces().all(|f| f.len() == 6));
        let s = build_scene(&m, false);
        assert_eq!(s.panels, m.num_faces());
        assert_eq!(s.beams, 3 * m.num_faces());
        assert_eq!(s.glass.triangle_count(), 4 * m.num_faces());
    }

    #[test]
    fn an_offset_moving_a_vertex_far_is_refused_with_its_reason() {
        let m = torus_panels(100).unwrap();
        let mut off = m.clone();
        assert!(offset_admitted(&m, &off, 0.1).is_ok());
        off.positions[7].z += 1.05;
        let e = offset_admitted(&m, &off, 0.1).unwrap_err();
        assert!(
            e.contains("vertex 7 would move") && e.contains("conical-station"),
            "{e}"
        );
        off.positions[7].z -= 0.1;
        assert!(offset_admitted(&m, &off, 0.1).is_ok());
    }
}
