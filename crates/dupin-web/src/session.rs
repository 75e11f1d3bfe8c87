//! `Session`: the contract's step-by-step JS API over the core's P-Hex pipeline and PQ scenes.

use crate::mesh_data::MeshData;
use dupin_core::{
    PHEX_SCENES, PQ_SCENES, PhexConfig, PhexPipeline, PolyMesh, TriangulationMethod, face_info,
    face_planarity, max_planarity, phex_scene, pq_scene, write_obj,
};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use wasm_bindgen::prelude::*;

/// `new Session(config)`: `{ scene }` or `{ surface, params, method, size }`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SessionConfig {
    scene: Option<String>,
    surface: Option<String>,
    #[serde(default)]
    params: BTreeMap<String, f64>,
    method: Option<String>,
    size: Option<f64>,
}

/// What `step()` and `metrics()` return.
#[derive(Serialize, Clone, Copy)]
#[serde(rename_all = "camelCase")]
struct Metrics {
    phase: &'static str,
    layer: usize,
    iteration: usize,
    faces: usize,
    vertices: usize,
    max_planarity: f64,
    invalid_faces: usize,
}

enum Run {
    Phex(Box<PhexPipeline>),
    /// PQ scenes are computed in one step (subdivision and perturbation levels run together).
    Pq {
        name: String,
        mesh: Option<PolyMesh>,
        iterations: usize,
    },
}

/// A running computation the page steps through.
#[wasm_bindgen]
pub struct Session {
    run: Run,
}

/// Every scene a `Session` accepts: the P-Hex scenes, then the PQ scenes.
#[wasm_bindgen(js_name = sceneNames)]
pub fn scene_names() -> Vec<String> {
    PHEX_SCENES
        .iter()
        .chain(PQ_SCENES)
        .map(|s| s.to_string())
        .collect()
}

#[wasm_bindgen]
impl Session {
    /// Starts a session. Throws an `Error` naming what to change for a bad configuration.
    #[wasm_bindgen(constructor)]
    pub fn new(config: JsValue) -> Result<Session, JsError> {
        let cfg: SessionConfig = serde_wasm_bindgen::from_value(config)
            .map_err(|e| JsError::new(&format!("bad session config: {e}")))?;
        let run = match (&cfg.scene, &cfg.surface) {
            (Some(scene), None) if PQ_SCENES.contains(&scene.as_str()) => Run::Pq {
                name: scene.clone(),
                mesh: None,
                iterations: 0,
            },
            (Some(scene), None) => {
                let scene = phex_scene(scene).map_err(|e| JsError::new(&e.to_string()))?;
                Run::Phex(Box::new(
                    PhexPipeline::new(scene.config).map_err(|e| JsError::new(&e.to_string()))?,
                ))
            }
            (None, Some(surface)) => {
                let method = match cfg.method.as_deref().unwrap_or("progressive") {
                    "progressive" => TriangulationMethod::Progressive,
                    "prescribed" => TriangulationMethod::Prescribed,
                    other => {
                        return Err(JsError::new(&format!(
                            "method must be `progressive` or `prescribed`, not `{other}`"
                        )));
                    }
                };
                let params: Vec<(String, f64)> = cfg.params.into_iter().collect();
                let config = PhexConfig::for_surface(surface, &params, method, cfg.size);
                Run::Phex(Box::new(
                    PhexPipeline::new(config).map_err(|e| JsError::new(&e.to_string()))?,
                ))
            }
            _ => {
                return Err(JsError::new(
                    "give either `scene` or `surface` (with `params`, `method`, `size`)",
                ));
            }
        };
        Ok(Session { run })
    }

    /// Advances one observable step (a triangulation layer, the dual mesh, one Gauss-Newton
    /// iteration; a whole PQ scene) and returns the metrics.
    pub fn step(&mut self) -> Result<JsValue, JsError> {
        match &mut self.run {
            Run::Phex(p) => {
                if !p.done() {
                    p.step().map_err(|e| JsError::new(&e.to_string()))?;
                }
            }
            Run::Pq {
                name,
                mesh,
                iterations,
            } => {
                if mesh.is_none() {
                    let r = pq_scene(name).map_err(|e| JsError::new(&e.to_string()))?;
                    *iterations = r.iterations;
                    *mesh = Some(r.mesh);
                }
            }
        }
        self.metrics()
    }

    /// True once the run has finished.
    pub fn done(&self) -> bool {
        match &self.run {
            Run::Phex(p) => p.done(),
            Run::Pq { mesh, .. } => mesh.is_some(),
        }
    }

    /// `{ phase, layer, iteration, faces, vertices, maxPlanarity, invalidFaces }`.
    pub fn metrics(&self) -> Result<JsValue, JsError> {
        serde_wasm_bindgen::to_value(&self.metrics_struct())
            .map_err(|e| JsError::new(&e.to_string()))
    }

    /// The current mesh as OBJ text (faces at their true size).
    #[wasm_bindgen(js_name = exportObj)]
    pub fn export_obj(&self) -> String {
        self.current_mesh()
            .map(|m| write_obj(&m))
            .unwrap_or_default()
    }

    /// The current mesh for the viewer: flat panels coloured by planarity error (blue planar,
    /// through white, to red at 1e-2 and above, on a log scale) and their edges.
    pub fn mesh(&self) -> MeshData {
        let m = self.current_mesh().unwrap_or_default();
        let colors: Vec<[f32; 3]> = (0..m.num_faces())
            .map(|i| planarity_color(face_planarity(&m, i)))
            .collect();
        MeshData::panels(m, &colors)
    }
}

impl Session {
    fn current_mesh(&self) -> Option<PolyMesh> {
        match &self.run {
            Run::Phex(p) => Some(p.mesh()),
            Run::Pq { mesh, .. } => mesh.clone(),
        }
    }

    fn metrics_struct(&self) -> Metrics {
        match &self.run {
            Run::Phex(p) => {
                let m = p.metrics();
                Metrics {
                    phase: m.phase.name(),
                    layer: m.layer,
                    iteration: m.iteration,
                    faces: m.faces,
                    vertices: m.vertices,
                    max_planarity: m.max_planarity,
                    invalid_faces: m.invalid_faces,
                }
            }
            Run::Pq {
                mesh, iterations, ..
            } => Metrics {
                phase: if mesh.is_some() { "done" } else { "ready" },
                layer: 0,
                iteration: *iterations,
                faces: mesh.as_ref().map_or(0, |m| m.num_faces()),
                vertices: mesh.as_ref().map_or(0, |m| m.num_vertices()),
                max_planarity: mesh.as_ref().map_or(0.0, max_planarity),
                // Self-intersecting panels, tested in each face's least-squares plane.
                invalid_faces: mesh.as_ref().map_or(0, |m| {
                    (0..m.num_faces())
                        .filter(|&i| !face_info(m, i, 0.0).simple)
                        .count()
                }),
            },
        }
    }
}

/// Blue (planar to 1e-12) -> white (1e-7) -> red (1e-2 and worse), log scale; linear RGB.
fn planarity_color(p: f64) -> [f32; 3] {
    let t = ((p.max(1e-12).log10() + 12.0) / 10.0).clamp(0.0, 1.0) as f32;
    let (blue, white, red) = ([0.20, 0.45, 0.85], [0.92, 0.92, 0.92], [0.85, 0.20, 0.15]);
    let mix = |a: [f32; 3], b: [f32; 3], s: f32| [0, 1, 2].map(|k| a[k] + (b[k] - a[k]) * s);
    if t < 0.5 {
        mix(blue, white, t * 2.0)
    } else {
        mix(white, red, t * 2.0 - 1.0)
    }
}
