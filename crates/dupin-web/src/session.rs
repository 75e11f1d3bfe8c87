//! `Session`: the contract's step-by-step JS API over the core's P-Hex pipeline and PQ scenes.

use crate::import::Imported;
use crate::js::{err, refuse_unknown_keys, to_js};
use crate::mesh_data::{MeshData, MeshKey, panel_faces_from, panel_positions_from};
use crate::shown_mesh::ShownMesh;
use dupin_core::conical::{
    PqMode, PqSceneMeasures, PqSceneStepInfo, PqSceneStepper, offset_mesh, pq_scene_shortfall,
    support_structure,
};
use dupin_core::fabrication::{
    DxfOptions, GlbLayer, LengthUnit, SheetOptions, panel_csv, panel_dxf, panel_schedule,
    panel_schedule_svg, panels_glb, support_csv,
};
use dupin_core::mesh::view_origin;
use dupin_core::mesh::{
    ColorMode, NOT_HEX, PLANARITY_HIST_HI, PLANARITY_HIST_LO, PLANARITY_LEGEND_LOG10, PolyMesh,
    REGULARITY_LEGEND, convexity_color, max_planarity, planarity_color, regularity_color,
    write_obj,
};
use dupin_core::phex::{
    Initialisation, LayerRule, PhexConfig, PhexGoals, PhexPipeline, TriangulationMethod, face_info,
};
use dupin_core::scenes::{PHEX_SCENES, PQ_SCENES, phex_scene, pq_scene_stepper};
use dupin_core::surface::surface_catalog;
use dupin_core::{Stepper, Vec3};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use wasm_bindgen::prelude::*;

/// `new Session(config)`: `{ scene }` or `{ surface, params, method, size, bound, lambda, mu,
/// init }`.
#[derive(Deserialize, Serialize, Clone, Default)]
#[serde(deny_unknown_fields)]
struct SessionConfig {
    /// The opened file's name (`Session.fromFile` only; not a key of `new Session`).
    #[serde(skip_deserializing, skip_serializing_if = "Option::is_none")]
    imported: Option<String>,
    scene: Option<String>,
    surface: Option<String>,
    #[serde(default)]
    params: BTreeMap<String, f64>,
    method: Option<String>,
    size: Option<f64>,
    /// Parabolic lower bound b (section 5.3).
    bound: Option<f64>,
    /// Initial fairness weight (section 7).
    lambda: Option<f64>,
    /// Initial surface-distance weight (section 7).
    mu: Option<f64>,
    /// Hexagon initialisation: `tangent-duality` (default, section 4.1) or `dupin-duality`
    /// (section 6; starts non-planar, so the optimisation runs).
    init: Option<String>,
}

/// The free mode's triangulation methods (section 5.2) as (name, label for people, value),
/// the default first.
pub(crate) const METHODS: [(&str, &str, TriangulationMethod); 2] = [
    (
        "progressive",
        "progressive",
        TriangulationMethod::Progressive,
    ),
    ("prescribed", "prescribed", TriangulationMethod::Prescribed),
];

/// The free mode's hexagon initialisations (sections 4.1 and 6) as (name, label for people,
/// value), the default first.
pub(crate) const INITIALISATIONS: [(&str, &str, Initialisation); 2] = [
    (
        "tangent-duality",
        "tangent duality",
        Initialisation::TangentDuality,
    ),
    (
        "dupin-duality",
        "Dupin duality",
        Initialisation::DupinDuality,
    ),
];

/// The fields of [`SessionConfig`], for [`refuse_unknown_keys`].
const SESSION_CONFIG_KEYS: &[&str] = &[
    "scene", "surface", "params", "method", "size", "bound", "lambda", "mu", "init",
];

/// What `step()` and `metrics()` return.
#[derive(Serialize, Clone)]
#[serde(rename_all = "camelCase")]
struct Metrics {
    /// The stepper's phase; a finished run that misses what it was asked ends in `warning`
    /// (with `reason`), never `done`.
    phase: &'static str,
    /// Why the finished run is a `warning`.
    #[serde(skip_serializing_if = "Option::is_none")]
    reason: Option<String>,
    layer: usize,
    iteration: usize,
    faces: usize,
    vertices: usize,
    max_planarity: f64,
    mean_planarity: f64,
    invalid_faces: usize,
    /// Face counts per bin of log10(planarity), see `histLog10`.
    histogram: Vec<u32>,
    /// `[lo, hi]` of the histogram's log10 axis.
    hist_log10: [f64; 2],
    /// PQ scenes: subdivision level of the mesh on show (0: control) and the scene's count.
    #[serde(skip_serializing_if = "Option::is_none")]
    level: Option<usize>,
    #[serde(skip_serializing_if = "Option::is_none")]
    levels: Option<usize>,
    /// Conical scenes: `conical_residual` (radians).
    #[serde(skip_serializing_if = "Option::is_none")]
    conical_residual: Option<f64>,
    /// Circular scenes: `circular_residual`.
    #[serde(skip_serializing_if = "Option::is_none")]
    circular_residual: Option<f64>,
    /// Strip scenes: largest determinant term.
    #[serde(skip_serializing_if = "Option::is_none")]
    max_determinant: Option<f64>,
    /// Strip scenes: quads whose singular-curve point lies on the strip.
    #[serde(skip_serializing_if = "Option::is_none")]
    singular_points_inside: Option<usize>,
    /// An opened design: what it is and how large.
    #[serde(skip_serializing_if = "Option::is_none")]
    design: Option<crate::import::DesignInfo>,
    /// An opened panel design: how far the vertices are from where the file put them, largest
    /// and mean, in millimetres.
    #[serde(skip_serializing_if = "Option::is_none")]
    deviation_mm: Option<[f64; 2]>,
    /// Simple faces that are not convex (a P-Hex hexagon where K < 0 is, by section 4.2).
    non_convex_faces: usize,
    /// An opened design: the current mesh's mean edge in metres (its planarity in mm follows
    /// from it, not from the page's panel edge).
    #[serde(skip_serializing_if = "Option::is_none")]
    mean_edge_m: Option<f64>,
    /// At most this many steps are left (iterative phases count their cap): the page's progress
    /// bar. See `Stepper::steps_left_at_most`.
    #[serde(skip_serializing_if = "Option::is_none")]
    steps_left_at_most: Option<usize>,
    /// The current mesh's bounding box extent along x, y, z and its mean edge, in the run's
    /// own units (a scene's, or the opened design's): the page shows the dimensions in metres
    /// at its panel edge (or, for a design, its unit).
    extent: [f64; 3],
    mean_edge: f64,
    /// The point the view's coordinates are relative to (`MeshData.viewOrigin`): zero for a
    /// scene and for a design near zero, near the design for an opened one far from zero.
    /// Picks, drags, box selections and `mesh()` speak the view's coordinates; the metrics,
    /// the design's control net and every export the file's.
    view_origin: [f64; 3],
}

/// The extra layers `Session.mesh` can draw with the panels: `{ offset, support, distance }`
/// (all optional; no layers by default).
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct LayerConfig {
    /// The offset mesh at face distance `distance`.
    #[serde(default)]
    offset: bool,
    /// The support structure: one planar quad per edge between the mesh and its offset.
    #[serde(default)]
    support: bool,
    /// Face distance of the offset, in scene units (positive along the face normals);
    /// [`DEFAULT_OFFSET`] when not given.
    distance: Option<f64>,
}

/// Offset distance when the layers do not give one: the core's default for the page.
pub(crate) const DEFAULT_OFFSET: f64 = dupin_core::conical::DEFAULT_OFFSET_DISTANCE;

/// Offset and support beams of a mesh (conical paper, Sec. 4) and their measures.
#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct LayerInfo {
    distance: f64,
    offset_faces: usize,
    /// Contract `max_planarity` of the offset faces.
    offset_planarity: f64,
    beams: usize,
    /// Contract `max_planarity` of the support quads (planar for a conical mesh).
    beam_planarity: f64,
}

enum Run {
    /// A P-Hex run and what it is asked for (a finished run that misses it is a `warning`).
    Phex(Box<PhexPipeline>, PhexGoals),
    /// A PQ scene, one perturbation iteration or one subdivision a step; the first step shows
    /// the control mesh.
    Pq {
        stepper: Box<PqSceneStepper>,
        started: bool,
    },
}

/// A running computation the page steps through.
#[wasm_bindgen]
pub struct Session {
    run: Run,
    config: SessionConfig,
    /// The current mesh's per-face figures and render buffers, for the metrics and `mesh()`
    /// (a worker step asks for both), carried over the faces a state shares with the last.
    shown: ShownMesh,
    /// `shown` is the run's current mesh: nothing changed the run since it was synced (every
    /// change of `run` clears this, so a state's metrics and mesh sync once between them).
    shown_is_current: bool,
    /// Extra layers drawn with the panels (`setLayers`).
    layers: LayerConfig,
    /// The opened design (`Session.fromFile`), shown with the metrics.
    design: Option<crate::import::DesignInfo>,
    /// An opened NURBS surface, whose control points `moveControlPoint` drags.
    nurbs: Option<crate::import::NurbsSource>,
    /// The point every position the view sees is relative to ([`view_origin`]): the render
    /// buffers, picks, drags and selections. Fixed when the session opens, so a reshaped or
    /// replayed design keeps its camera; exports and the metrics stay in the user's
    /// coordinates.
    view_origin: Vec3,
}

/// The run of an opened design.
fn imported_run(imported: Imported) -> Run {
    match imported {
        Imported::Phex(p, goals) => Run::Phex(p, goals),
        Imported::Panels(stepper) => Run::Pq {
            stepper,
            started: false,
        },
    }
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

/// One sentence for people about scene `name` and the paper figure it follows; `undefined` for
/// a name that is not a scene.
#[wasm_bindgen(js_name = sceneDescription)]
pub fn scene_description(name: &str) -> Option<String> {
    dupin_core::scenes::scene_description(name).map(str::to_string)
}

#[derive(Serialize)]
struct ParamOut {
    key: &'static str,
    default: f64,
    min: f64,
    max: f64,
    integer: bool,
    doc: &'static str,
}

#[derive(Serialize)]
struct SurfaceOut {
    name: &'static str,
    parametrisation: &'static str,
    params: Vec<ParamOut>,
}

/// The core's surface library for the free mode: `[{ name, parametrisation, params: [{ key,
/// default, min, max, integer, doc }] }]` (ranges are the registry's, inclusive).
#[wasm_bindgen(js_name = surfaceCatalog)]
pub fn surface_catalog_js() -> Result<JsValue, JsError> {
    let list: Vec<SurfaceOut> = surface_catalog()
        .iter()
        .map(|s| SurfaceOut {
            name: s.name,
            parametrisation: s.parametrisation,
            params: s
                .params
                .iter()
                .map(|p| ParamOut {
                    key: p.key,
                    default: p.default,
                    min: p.min,
                    max: p.max,
                    integer: p.integer,
                    doc: p.doc,
                })
                .collect(),
        })
        .collect();
    to_js(&list)
}

/// The free mode's defaults: `{ bound, lambda, mu }` as the core uses them.
#[wasm_bindgen(js_name = freeDefaults)]
pub fn free_defaults() -> Result<JsValue, JsError> {
    let c = PhexConfig::for_surface("torus", &[], TriangulationMethod::Progressive, None);
    let bound = match c.rule {
        LayerRule::Ideal { bound } => bound,
        _ => 0.3,
    };
    #[derive(Serialize)]
    struct D {
        bound: f64,
        lambda: f64,
        mu: f64,
    }
    to_js(&D {
        bound,
        lambda: c.lambda,
        mu: c.mu,
    })
}

/// Colour stops of a colour mode for the page's legend: `[{ label, color: [r, g, b] }]` (linear
/// RGB in 0..1, the same colours the panels get).
#[wasm_bindgen(js_name = colorLegend)]
pub fn color_legend(mode: JsValue) -> Result<JsValue, JsError> {
    let mode = crate::js::string_arg(&mode, "the colour mode")?;
    #[derive(Serialize)]
    struct Stop {
        label: String,
        color: [f32; 3],
    }
    let stops: Vec<Stop> = match ColorMode::parse(&mode).map_err(err)? {
        ColorMode::Planarity => PLANARITY_LEGEND_LOG10
            .iter()
            .map(|&e| Stop {
                label: format!("1e{e}"),
                color: planarity_color(10f64.powf(e)),
            })
            .collect(),
        ColorMode::Convexity => vec![
            Stop {
                label: "convex".into(),
                color: convexity_color(true, true),
            },
            Stop {
                label: "non-convex".into(),
                color: convexity_color(true, false),
            },
            Stop {
                label: "self-intersecting".into(),
                color: convexity_color(false, false),
            },
        ],
        ColorMode::Regularity => {
            let mut v: Vec<Stop> = REGULARITY_LEGEND
                .iter()
                .map(|&d| Stop {
                    label: format!("{d:.1}"),
                    color: regularity_color(d),
                })
                .collect();
            v.push(Stop {
                label: "not a hexagon".into(),
                color: NOT_HEX,
            });
            v
        }
    };
    to_js(&stops)
}

#[wasm_bindgen]
impl Session {
    /// Starts a session. Throws an `Error` naming what to change for a bad configuration.
    #[wasm_bindgen(constructor)]
    pub fn new(config: JsValue) -> Result<Session, JsError> {
        refuse_unknown_keys(&config, "session config", SESSION_CONFIG_KEYS)?;
        let cfg: SessionConfig = serde_wasm_bindgen::from_value(config)
            .map_err(|e| JsError::new(&format!("bad session config: {e}")))?;
        let run = match (&cfg.scene, &cfg.surface) {
            (Some(scene), None) if PQ_SCENES.contains(&scene.as_str()) => Run::Pq {
                stepper: Box::new(pq_scene_stepper(scene).map_err(err)?),
                started: false,
            },
            (Some(scene), None) => {
                let scene = phex_scene(scene).map_err(err)?;
                let goals = PhexGoals::of(&scene.config, scene.expect_valid);
                Run::Phex(
                    Box::new(PhexPipeline::new(scene.config).map_err(err)?),
                    goals,
                )
            }
            (None, Some(surface)) => {
                let method: TriangulationMethod = cfg
                    .method
                    .as_deref()
                    .unwrap_or("progressive")
                    .parse()
                    .map_err(err)?;
                let params: Vec<(String, f64)> =
                    cfg.params.iter().map(|(k, v)| (k.clone(), *v)).collect();
                let mut config = PhexConfig::for_surface(surface, &params, method, cfg.size);
                crate::import::apply_phex_settings(
                    &mut config,
                    cfg.bound,
                    cfg.lambda,
                    cfg.mu,
                    cfg.init.as_deref(),
                )
                .map_err(|e| JsError::new(&e))?;
                let goals = PhexGoals::of(&config, true);
                Run::Phex(Box::new(PhexPipeline::new(config).map_err(err)?), goals)
            }
            _ => {
                return Err(JsError::new(
                    "give either `scene` or `surface` (with `params`, `method`, `size`)",
                ));
            }
        };
        Ok(Session {
            run,
            config: cfg,
            shown: ShownMesh::default(),
            shown_is_current: false,
            layers: LayerConfig::default(),
            design: None,
            nurbs: None,
            view_origin: Vec3::zeros(),
        })
    }

    /// Opens a design file: `name` (its extension tells the format), its `bytes` and
    /// `{ importAs, unit, size, method, init, bound, lambda, mu, mode, fixBoundary }` (all
    /// optional; the surface settings are the free mode's). A NURBS surface as
    /// JSON (docs/nurbs-json.md) or a triangle mesh (fitted by a smooth surface) is panelled by
    /// P-Hex; a panel mesh (OBJ, STL, glTF/GLB) is planarised keeping the design. The metrics
    /// then carry `design: { name, importAs, unit, dimensionsM, fitMaxDistanceM }`. Throws an
    /// `Error` naming the file and what is wrong with it.
    #[wasm_bindgen(js_name = fromFile)]
    pub fn from_file(name: &str, bytes: &[u8], config: JsValue) -> Result<Session, JsError> {
        let (imported, design, nurbs) = crate::import::import_run(name, bytes, config)?;
        let run = imported_run(imported);
        // A P-Hex run's frame holds its surface's box (the first states show one layer); a
        // panel mesh is all there from the start.
        let origin = match &run {
            Run::Phex(p, _) => {
                let f = p.frame();
                view_origin(&[f.to_user(Vec3::repeat(-1.0)), f.to_user(Vec3::repeat(1.0))])
            }
            Run::Pq { stepper, .. } => view_origin(&stepper.mesh().positions),
        };
        Ok(Session {
            run,
            nurbs,
            config: SessionConfig {
                imported: Some(name.to_string()),
                ..SessionConfig::default()
            },
            shown: ShownMesh::around(origin),
            shown_is_current: false,
            layers: LayerConfig::default(),
            design: Some(design),
            view_origin: origin,
        })
    }

    /// Moves control point `index` (row-major, `i * nv + j` of the `controlNet` in
    /// `metrics().design`) of an opened NURBS surface to `(x, y, z)` (the file's unit), one
    /// move after those before: the run shown is run to its end (if it has not ended) and its
    /// P-Hex panelling follows the reshaped surface (`import::following_run`). The move joins
    /// `controlPoints`, and a page opened with them replays every move in turn to the same
    /// panels, bit for bit. A drag moves the point to each pointer position once the run for
    /// the one before has ended. Throws for a run that is not an opened NURBS surface, an index
    /// past the net, a point that is not finite or more moves than a design replays (1 000),
    /// leaving the run as it was.
    #[wasm_bindgen(js_name = moveControlPoint)]
    pub fn move_control_point(
        &mut self,
        // A number, checked here: an index parameter would take -1 as 2^32 - 1 and "x" as 0.
        index: f64,
        x: f64,
        y: f64,
        z: f64,
    ) -> Result<(), JsError> {
        if !(index >= 0.0 && index.fract() == 0.0 && index < u32::MAX as f64) {
            return Err(JsError::new(&format!(
                "{index} is not a control point index"
            )));
        }
        let index = index as usize;
        let Some(source) = self.nurbs.as_mut() else {
            return Err(JsError::new(
                "control points are for an opened NURBS surface (open a .json or .3dm surface)",
            ));
        };
        let previous = match &mut self.run {
            Run::Phex(current, _) => Some(current.as_mut()),
            Run::Pq { .. } => None,
        };
        let (imported, design) = source
            .move_control_point(index, [x, y, z], previous)
            .map_err(|e| JsError::new(&e))?;
        self.run = imported_run(imported);
        self.shown_is_current = false;
        self.design = Some(design);
        Ok(())
    }

    /// [`Session::move_control_point`], by the name earlier pages used for a drag's pointer
    /// positions (a drag's positions are moves like any other).
    #[wasm_bindgen(js_name = dragControlPoint)]
    pub fn drag_control_point(
        &mut self,
        index: f64,
        x: f64,
        y: f64,
        z: f64,
    ) -> Result<(), JsError> {
        self.move_control_point(index, x, y, z)
    }
}

#[wasm_bindgen]
impl Session {
    /// Advances one observable step (a triangulation layer, the dual mesh, one Gauss-Newton
    /// iteration; for PQ scenes the control mesh, one perturbation iteration or one
    /// subdivision) and returns the metrics.
    pub fn step(&mut self) -> Result<JsValue, JsError> {
        self.advance()?;
        self.metrics()
    }

    /// [`Session::step`] without building the metrics (the worker times the solver and the
    /// metrics separately, then calls `metrics()`).
    pub fn advance(&mut self) -> Result<(), JsError> {
        self.shown_is_current = false;
        match &mut self.run {
            Run::Phex(p, _) => {
                if !p.is_done() {
                    p.step().map_err(err)?;
                }
            }
            Run::Pq { stepper, started } => {
                if !*started {
                    *started = true;
                } else {
                    stepper.step().map_err(err)?;
                }
            }
        }
        Ok(())
    }

    /// True once the run has finished.
    pub fn done(&self) -> bool {
        match &self.run {
            Run::Phex(p, _) => p.is_done(),
            Run::Pq { stepper, started } => *started && stepper.is_done(),
        }
    }

    /// `{ phase, layer, iteration, faces, vertices, maxPlanarity, meanPlanarity, invalidFaces,
    /// histogram, histLog10 }`.
    pub fn metrics(&mut self) -> Result<JsValue, JsError> {
        to_js(&self.metrics_struct())
    }

    /// The current mesh as OBJ text (faces at their true size).
    #[wasm_bindgen(js_name = exportObj)]
    pub fn export_obj(&self) -> String {
        self.current_mesh()
            .map(|m| write_obj(&m))
            .unwrap_or_default()
    }

    /// The current mesh and its report as JSON text: `{ config, metrics, report, mesh: {
    /// vertices: [[x, y, z]], faces: [[i, ...]] } }` (0-based faces). The P-Hex report has the
    /// contract's fields plus `per_face` (planarity, simple, convex, gaussian, shape_deviation).
    #[wasm_bindgen(js_name = exportJson)]
    pub fn export_json(&mut self) -> Result<String, JsError> {
        let mesh = self.current_mesh().unwrap_or_default();
        let metrics = self.metrics_struct();
        let report = match &self.run {
            Run::Phex(p, _) => p.report().map(|r| {
                serde_json::json!({
                    "vertices": r.vertices,
                    "faces": r.faces,
                    "face_sizes": r.face_sizes,
                    "max_planarity": r.max_planarity,
                    "invalid_faces": r.invalid_faces,
                    "iterations": r.iterations,
                    "max_surface_distance": r.max_surface_distance,
                    "bbox_diagonal": r.bbox_diagonal,
                    "per_face": r.per_face.iter().map(|f| serde_json::json!({
                        "planarity": f.planarity,
                        "simple": f.simple,
                        "convex": f.convex,
                        "gaussian": f.gaussian,
                        "shape_deviation": f.shape_deviation,
                    })).collect::<Vec<_>>(),
                })
            }),
            Run::Pq { .. } => None,
        };
        let report = report.unwrap_or_else(|| {
            let mut sizes = BTreeMap::new();
            for i in 0..mesh.num_faces() {
                *sizes.entry(mesh.face(i).len()).or_insert(0usize) += 1;
            }
            serde_json::json!({
                "vertices": mesh.num_vertices(),
                "faces": mesh.num_faces(),
                "face_sizes": sizes,
                "max_planarity": metrics.max_planarity,
                "invalid_faces": metrics.invalid_faces,
                "iterations": metrics.iteration,
            })
        });
        let doc = serde_json::json!({
            "config": self.config,
            "metrics": metrics,
            "report": report,
            "mesh": {
                "vertices": mesh.positions.iter().map(|p| [p.x, p.y, p.z]).collect::<Vec<_>>(),
                "faces": (0..mesh.num_faces()).map(|i| mesh.face(i).to_vec()).collect::<Vec<_>>(),
            },
        });
        serde_json::to_string(&doc).map_err(err)
    }

    /// The SVG panel schedule of the current mesh: every panel flattened into its plane,
    /// numbered by face index, edge lengths in mm for panels scaled so the mean edge is
    /// `panel_edge_m` metres, packed on square sheets (see `dupin_core::fabrication::panel_schedule`).
    #[wasm_bindgen(js_name = exportSvg)]
    pub fn export_svg(&self, panel_edge_m: f64) -> Result<String, JsError> {
        if !(panel_edge_m.is_finite() && panel_edge_m > 0.0) {
            return Err(JsError::new(&format!(
                "panel edge must be a positive length in metres, got {panel_edge_m}"
            )));
        }
        let mesh = self.current_mesh().unwrap_or_default();
        let sched = panel_schedule(
            &mesh,
            &SheetOptions {
                sheet: None,
                gap: None,
            },
        )
        .map_err(err)?;
        let mean_edge = mesh.mean_edge();
        let scale = if mean_edge > 0.0 {
            panel_edge_m * 1000.0 / mean_edge
        } else {
            1.0
        };
        Ok(panel_schedule_svg(&sched, scale))
    }

    /// The current panels in real units for fabrication files: an opened design in its own
    /// unit; a scene scaled so its mean edge is `panel_edge_m` metres (the page's panel edge).
    fn fabrication_mesh(&self, panel_edge_m: f64) -> Result<(PolyMesh, LengthUnit), JsError> {
        let (mut layers, unit) = self.fabrication_layers(panel_edge_m, false)?;
        Ok((layers.swap_remove(0).1, unit))
    }

    /// [`Session::fabrication_mesh`] with, when `with_layers`, the offset and support layers
    /// on show (conical runs), named `panels`, `offset` and `beams` and scaled as the panels.
    fn fabrication_layers(
        &self,
        panel_edge_m: f64,
        with_layers: bool,
    ) -> Result<FabricationLayers, JsError> {
        let mesh = self.current_mesh().unwrap_or_default();
        let (scale, unit) = match &self.design {
            Some(d) => (1.0, d.unit.parse().unwrap_or_default()),
            None => {
                if !(panel_edge_m.is_finite() && panel_edge_m > 0.0) {
                    return Err(JsError::new(&format!(
                        "panel edge must be a positive length in metres, got {panel_edge_m}"
                    )));
                }
                let mean_edge = mesh.mean_edge();
                let scale = if mean_edge > 0.0 {
                    panel_edge_m / mean_edge
                } else {
                    1.0
                };
                (scale, LengthUnit::Metre)
            }
        };
        let extra = match with_layers {
            true => self.layer_meshes(&mesh)?,
            false => None,
        };
        let mut layers = vec![("panels", mesh)];
        if let Some((offset, beams, _)) = extra {
            layers.extend(offset.map(|m| ("offset", m)));
            layers.extend(beams.map(|m| ("beams", m)));
        }
        if scale != 1.0 {
            for (_, m) in &mut layers {
                for p in &mut m.positions {
                    *p *= scale;
                }
            }
        }
        Ok((layers, unit))
    }

    /// The cutting file (DXF, `$INSUNITS` millimetres): every panel flattened into its plane
    /// as a closed polyline on layer `PANELS`, its number on `LABELS`, edge lengths on
    /// `DIMENSIONS`, packed without overlap on 2500 x 1250 mm sheets. Real sizes: an opened
    /// design's own unit, a scene scaled to a mean edge of `panel_edge_m` metres.
    #[wasm_bindgen(js_name = exportDxf)]
    pub fn export_dxf(&self, panel_edge_m: f64) -> Result<String, JsError> {
        let (mesh, unit) = self.fabrication_mesh(panel_edge_m)?;
        panel_dxf(&mesh, &DxfOptions::default().with_unit(unit)).map_err(err)
    }

    /// The panel schedule as CSV: number, corners, area (m²), perimeter, planarity (mm), the
    /// deviation from an opened panel design (mm), edge lengths. A conical run adds its support
    /// structure at the offset distance set for its layers: node axes and beams (see
    /// `support_csv`). Units as [`Session::export_dxf`].
    #[wasm_bindgen(js_name = exportCsv)]
    pub fn export_csv(&self, panel_edge_m: f64) -> Result<String, JsError> {
        let (mesh, unit) = self.fabrication_mesh(panel_edge_m)?;
        let design = self
            .design
            .as_ref()
            .and_then(|d| d.positions.as_deref())
            .filter(|p| p.len() == mesh.num_vertices());
        let mut csv = panel_csv(&mesh, unit, design);
        if self.offset_reason().is_none() {
            // The distance is in the run's units: scale it as the panels were.
            let raw = self.current_mesh().unwrap_or_default().mean_edge();
            let scale = if raw > 0.0 {
                mesh.mean_edge() / raw
            } else {
                1.0
            };
            let d = self.layers.distance.unwrap_or(DEFAULT_OFFSET) * scale;
            let offset = offset_mesh(&mesh, d).map_err(err)?;
            csv += &support_csv(&mesh, &offset, unit).map_err(err)?;
        }
        Ok(csv)
    }

    /// The panels as binary glTF 2.0, written in metres (readable by three.js, model-viewer and
    /// Rhino). Units as [`Session::export_dxf`].
    #[wasm_bindgen(js_name = exportGlb)]
    pub fn export_glb(&self, panel_edge_m: f64) -> Result<Vec<u8>, JsError> {
        let (layers, unit) = self.fabrication_layers(panel_edge_m, true)?;
        let layers: Vec<GlbLayer> = layers
            .iter()
            .map(|(name, mesh)| GlbLayer { name, mesh })
            .collect();
        Ok(panels_glb(&layers, unit))
    }

    /// The panels for a .3dm (written in the page by rhino3dm): `{ unit, layers: [{ name,
    /// positions, faces }] }` with `positions` flat `[x, y, z, ...]` in `unit`, `faces` 0-based
    /// corner lists, and the layers `panels`, then `offset` and `beams` when they are on show.
    /// Units as [`Session::export_dxf`].
    #[wasm_bindgen(js_name = exportPanels)]
    pub fn export_panels(&self, panel_edge_m: f64) -> Result<JsValue, JsError> {
        #[derive(Serialize)]
        struct Layer {
            name: &'static str,
            positions: Vec<f64>,
            faces: Vec<Vec<u32>>,
        }
        #[derive(Serialize)]
        struct Panels {
            unit: &'static str,
            layers: Vec<Layer>,
        }
        let (layers, unit) = self.fabrication_layers(panel_edge_m, true)?;
        let panels = Panels {
            unit: unit.name(),
            layers: layers
                .into_iter()
                .map(|(name, m)| Layer {
                    name,
                    positions: m.positions.iter().flat_map(|p| [p.x, p.y, p.z]).collect(),
                    faces: m.faces().map(<[u32]>::to_vec).collect(),
                })
                .collect(),
        };
        to_js(&panels)
    }

    /// The P-Hex triangulation vertex under a click: `origin` and `direction` (3 numbers each)
    /// are the view ray (`Viewer.pickRay`; positions in and out are the view's, see the
    /// metrics' `viewOrigin`). Returns `null` when the ray misses the triangles on
    /// screen, else `{ vertex, uv, point, normal, k1, k2, dir1, dir2, neighbours, ring,
    /// message }`: the surface point, its principal frame and the six ring neighbours (indices
    /// and positions, counter-clockwise), or `message` saying why there is no complete star.
    /// Throws for a PQ scene (no triangulation) or a malformed ray.
    #[wasm_bindgen(js_name = pickVertex)]
    pub fn pick_vertex(&self, origin: Vec<f64>, direction: Vec<f64>) -> Result<JsValue, JsError> {
        let Run::Phex(p, _) = &self.run else {
            return Err(JsError::new(
                "vertex picking needs a P-Hex run: PQ scenes have no triangulation",
            ));
        };
        if origin.len() != 3 || direction.len() != 3 {
            return Err(JsError::new("a ray needs 3 origin and 3 direction numbers"));
        }
        let v = |a: &[f64]| dupin_core::Vec3::new(a[0], a[1], a[2]);
        let o = self.view_origin;
        match crate::pick::pick_star(p, v(&origin) + o, v(&direction)) {
            Some(mut pick) => {
                let to_view = |q: &mut [f64; 3]| *q = (Vec3::from(*q) - o).into();
                to_view(&mut pick.point);
                pick.ring.iter_mut().for_each(to_view);
                to_js(&pick)
            }
            None => Ok(JsValue::NULL),
        }
    }

    /// The panel-mesh vertex under a click, for anchoring: `origin` and `direction` (3 numbers
    /// each) are the view ray (`Viewer.pickRay`, in the view's coordinates as `point` is). Returns `null` on a miss, else `{ vertex,
    /// point }` (the corner of the panel hit first that is nearest the hit point, 0-based in
    /// the file's order). Throws for a P-Hex run (its vertices are the solver's, not the
    /// design's) or a malformed ray.
    #[wasm_bindgen(js_name = pickPanelVertex)]
    pub fn pick_panel_vertex(
        &self,
        origin: Vec<f64>,
        direction: Vec<f64>,
    ) -> Result<JsValue, JsError> {
        let Run::Pq { .. } = &self.run else {
            return Err(JsError::new(
                "anchors are for a panel mesh: a P-Hex surface has no design vertices to hold",
            ));
        };
        if origin.len() != 3 || direction.len() != 3 {
            return Err(JsError::new("a ray needs 3 origin and 3 direction numbers"));
        }
        let m = self.current_mesh().unwrap_or_default();
        // Each panel as a fan of triangles from its first corner: a pick needs only the
        // panel's surface, not a good triangulation.
        let triangles: Vec<[u32; 3]> = m
            .faces()
            .flat_map(|f| (1..f.len().saturating_sub(1)).map(move |i| [f[0], f[i], f[i + 1]]))
            .collect();
        let v = |a: &[f64]| dupin_core::Vec3::new(a[0], a[1], a[2]);
        let o = self.view_origin;
        let Some(pick) =
            dupin_core::mesh::pick_vertex(&m.positions, &triangles, v(&origin) + o, v(&direction))
        else {
            return Ok(JsValue::NULL);
        };
        #[derive(Serialize)]
        struct PanelPick {
            vertex: usize,
            point: [f64; 3],
        }
        let p = m.positions[pick.vertex] - o;
        to_js(&PanelPick {
            vertex: pick.vertex,
            point: [p.x, p.y, p.z],
        })
    }

    /// Drags `vertex` of a panel mesh (a PQ scene or an opened panel mesh) to `(x, y, z)` (the
    /// view's coordinates, see the metrics' `viewOrigin`): the vertex is held there (an anchor
    /// from now on) and the perturbation restarts, one iteration a step, from the mesh
    /// committed when the drag began (`start`: a new drag, which first finishes the running
    /// perturbation and commits its result). So every move of a drag starts from the same mesh
    /// and replaying the committed drags rebuilds a mesh bit for bit. Throws for a P-Hex run, a developable strip, a vertex outside the mesh or
    /// a position that is not finite, leaving the run as it was.
    #[wasm_bindgen(js_name = dragVertex)]
    pub fn drag_vertex(
        &mut self,
        vertex: usize,
        x: f64,
        y: f64,
        z: f64,
        start: bool,
    ) -> Result<(), JsError> {
        self.drag_vertices(vertex, x, y, z, Vec::new(), start)
    }

    /// [`Session::drag_vertex`] with a box-selected `group` dragged along: `vertex` goes to
    /// `(x, y, z)` and every vertex of `group` moves by the same translation from the
    /// committed mesh; all of them are held from now on. Throws as `dragVertex` does, and
    /// for a group vertex outside the mesh.
    #[wasm_bindgen(js_name = dragVertices)]
    pub fn drag_vertices(
        &mut self,
        vertex: usize,
        x: f64,
        y: f64,
        z: f64,
        group: Vec<u32>,
        start: bool,
    ) -> Result<(), JsError> {
        self.shown_is_current = false;
        let Run::Pq { stepper, started } = &mut self.run else {
            return Err(JsError::new(
                "dragging is for a panel mesh: a P-Hex run follows its surface, not its vertices",
            ));
        };
        if start {
            stepper.commit().map_err(err)?;
        }
        let group: Vec<usize> = group.into_iter().map(|v| v as usize).collect();
        let target = Vec3::new(x, y, z) + self.view_origin;
        stepper.hold_group(vertex, target, &group).map_err(err)?;
        *started = true;
        Ok(())
    }

    /// The panel-mesh vertices inside a rectangle of the view, for a box selection:
    /// `view_proj` is the viewer's 16 numbers (`Viewer.viewProj`, column-major), the rectangle
    /// is given by two corners in normalised device coordinates (x, y in [-1, 1], y up).
    /// Every vertex in front of the eye whose projection lies inside counts, hidden or not (a
    /// window selection). Returns `{ vertices, points }`: the vertex numbers in increasing
    /// order and their positions in the view's coordinates, 3 numbers each. Throws for a P-Hex
    /// run, a matrix that is not 16 finite numbers or a corner that is not finite.
    #[wasm_bindgen(js_name = verticesInRect)]
    pub fn vertices_in_rect(
        &self,
        view_proj: Vec<f64>,
        x0: f64,
        y0: f64,
        x1: f64,
        y1: f64,
    ) -> Result<JsValue, JsError> {
        let Run::Pq { .. } = &self.run else {
            return Err(JsError::new(
                "box selection is for a panel mesh: a P-Hex surface has no design vertices to drag",
            ));
        };
        let m = self.current_mesh().unwrap_or_default();
        let o = self.view_origin;
        let seen: Vec<Vec3> = m.positions.iter().map(|p| p - o).collect();
        let vertices = crate::pick::vertices_in_rect(&seen, &view_proj, [x0, y0, x1, y1])
            .map_err(|e| JsError::new(&e))?;
        #[derive(Serialize)]
        struct Selection {
            vertices: Vec<usize>,
            points: Vec<f64>,
        }
        let points = vertices
            .iter()
            .flat_map(|&v| {
                let p = seen[v];
                [p.x, p.y, p.z]
            })
            .collect();
        to_js(&Selection { vertices, points })
    }

    /// The current mesh for the viewer: flat panels coloured by `mode` (`planarity`: blue
    /// planar, through white, to red at 1e-2 and above, log scale; `convexity`; `regularity`:
    /// the P-Hex paper's section 4.2 deviation from the affine (quasi-)regular hexagon) and
    /// their edges.
    pub fn mesh(&mut self, mode: JsValue) -> Result<MeshData, JsError> {
        // No mode (undefined or null): planarity colours.
        let mode = if mode.is_undefined() || mode.is_null() {
            None
        } else {
            Some(crate::js::string_arg(&mode, "the colour mode")?)
        };
        self.mesh_in(mode.as_deref())
    }

    /// [`Session::mesh`], or only what the run added since an earlier mesh: `since` is the
    /// `key` of a mesh this session gave (`undefined` or `null`: none). When the shown mesh is
    /// that one with faces and vertices added (a P-Hex run revealing its triangulation), in
    /// planarity colours with no layers or anchors drawn, the result carries only what was
    /// added: its `appendTo` is `since`, its arrays are to be appended to that mesh's
    /// (`indices` count that mesh's vertices too), `panelPositions` holds the added vertices
    /// and `panelFaces` the added faces. Otherwise it is the whole mesh, as `mesh` gives it.
    /// Either way its `key` is where the mesh stands now. Throws for a `since` that is not a
    /// mesh's `key`.
    #[wasm_bindgen(js_name = meshSince)]
    pub fn mesh_since(&mut self, mode: JsValue, since: JsValue) -> Result<MeshData, JsError> {
        let since = if since.is_undefined() || since.is_null() {
            None
        } else {
            refuse_unknown_keys(&since, "mesh key", &["revision", "faces", "vertices"])?;
            Some(
                serde_wasm_bindgen::from_value(since)
                    .map_err(|e| JsError::new(&format!("bad mesh key: {e}")))?,
            )
        };
        let planarity = mode.is_undefined()
            || mode.is_null()
            || mode.as_string().map(|m| ColorMode::parse(&m)) == Some(Ok(ColorMode::Planarity));
        if let Some(since) = since
            && planarity
            && let Some(tail) = self.tail_since(since)
        {
            return Ok(tail);
        }
        self.mesh(mode)
    }

    /// Sets the extra layers `mesh()` draws: `{ offset, support, distance }` (see
    /// `offsetUnavailable`); `null` or `{}` for none. Throws for a distance that is not a
    /// finite non-zero number, or layers this run has no offset for.
    #[wasm_bindgen(js_name = setLayers)]
    pub fn set_layers(&mut self, layers: JsValue) -> Result<(), JsError> {
        let l: LayerConfig = if layers.is_null() || layers.is_undefined() {
            LayerConfig::default()
        } else {
            refuse_unknown_keys(&layers, "layers", &["offset", "support", "distance"])?;
            serde_wasm_bindgen::from_value(layers)
                .map_err(|e| JsError::new(&format!("bad layers: {e}")))?
        };
        parse_layers(l, self.offset_reason()).map(|l| self.layers = l)
    }

    /// Why this run has no offset layer (a sentence for the page), or `undefined` when it has
    /// one: offsets at a constant face distance with planar support beams exist for conical
    /// meshes (conical paper, Sec. 4), i.e. the conical PQ scenes.
    #[wasm_bindgen(js_name = offsetUnavailable)]
    pub fn offset_unavailable(&self) -> Option<String> {
        self.offset_reason().map(str::to_string)
    }

    /// The layers on show and their measures: `{ distance, offsetFaces, offsetPlanarity,
    /// beams, beamPlanarity }` (contract planarity of the offset faces and of the support
    /// quads), or `null` when no layer is on.
    #[wasm_bindgen(js_name = layerInfo)]
    pub fn layer_info(&self) -> Result<JsValue, JsError> {
        if !(self.layers.offset || self.layers.support) || self.offset_reason().is_some() {
            return Ok(JsValue::NULL);
        }
        let m = self.current_mesh().unwrap_or_default();
        let distance = self.layers.distance.unwrap_or(DEFAULT_OFFSET);
        let (beams, offset) = support_structure(&m, distance).map_err(err)?;
        to_js(&LayerInfo {
            distance,
            offset_faces: offset.num_faces(),
            offset_planarity: max_planarity(&offset),
            beams: beams.num_faces(),
            beam_planarity: max_planarity(&beams),
        })
    }
}

/// Checks layer settings: the distance (when given) must be finite and non-zero, and layers
/// can only be switched on where `unavailable` is `None`.
fn parse_layers(l: LayerConfig, unavailable: Option<&str>) -> Result<LayerConfig, JsError> {
    if let Some(d) = l.distance
        && !(d.is_finite() && d != 0.0)
    {
        return Err(JsError::new(&format!(
            "offset distance must be a finite number other than 0, got {d}"
        )));
    }
    if (l.offset || l.support)
        && let Some(reason) = unavailable
    {
        return Err(JsError::new(reason));
    }
    Ok(l)
}

const OFFSET_COLOR: [f32; 3] = [0.80, 0.62, 0.30];
const BEAM_COLOR: [f32; 3] = [0.55, 0.56, 0.60];

/// Three crossed segments (a third of the mean edge each way) at every anchored vertex, drawn
/// with the panel edges.
fn anchor_crosses(mesh: &PolyMesh, anchors: &[usize]) -> Vec<f32> {
    let r = mesh.mean_edge() / 3.0;
    anchors
        .iter()
        .filter_map(|&a| mesh.positions.get(a))
        .flat_map(|p| {
            (0..3).flat_map(move |k| {
                let mut d = dupin_core::Vec3::zeros();
                d[k] = r;
                let (a, b) = (p - d, p + d);
                [a.x, a.y, a.z, b.x, b.y, b.z].map(|x| x as f32)
            })
        })
        .collect()
}

/// An offset layer, a support-structure layer and the beams' segments between each vertex and
/// its offset (the quads' other edges are the panels' and the offset's).
type Layers = (Option<PolyMesh>, Option<PolyMesh>, Vec<f32>);

/// Named meshes in one length unit: the panels and the layers on show, for fabrication files.
type FabricationLayers = (Vec<(&'static str, PolyMesh)>, LengthUnit);

impl Session {
    /// [`Session::mesh`] for Rust callers: `None` is planarity colours.
    pub fn mesh_in(&mut self, mode: Option<&str>) -> Result<MeshData, JsError> {
        let mode = ColorMode::parse(mode.unwrap_or("")).map_err(err)?;
        self.sync_shown();
        // Everything drawn is relative to the view origin (the planarity buffers are built so).
        let mut m = self.shown.mesh().clone();
        if self.view_origin != Vec3::zeros() {
            m.positions.iter_mut().for_each(|p| *p -= self.view_origin);
        }
        let coloured = |colors: Vec<[f32; 3]>| MeshData::panels(m.clone(), &colors);
        let mut data = match mode {
            // Planarity colours are kept from state to state (see `ShownMesh`).
            ColorMode::Planarity => {
                MeshData::from_panel_buffers(m.clone(), self.shown.planarity_panels().clone())
            }
            ColorMode::Convexity => coloured(
                (0..m.num_faces())
                    .map(|i| {
                        let f = face_info(&m, i, 0.0);
                        convexity_color(f.simple, f.convex)
                    })
                    .collect(),
            ),
            ColorMode::Regularity => {
                // The regularity measure depends on the sign of K at the face: the P-Hex report
                // has it per face; other meshes are compared with the affine-regular hexagon.
                let report = match &self.run {
                    Run::Phex(p, _) => p.report(),
                    Run::Pq { .. } => None,
                };
                coloured(
                    (0..m.num_faces())
                        .map(|i| {
                            let d = match &report {
                                Some(r) => r.per_face.get(i).and_then(|f| f.shape_deviation),
                                None => face_info(&m, i, 1.0).shape_deviation,
                            };
                            d.map_or(NOT_HEX, regularity_color)
                        })
                        .collect(),
                )
            }
        };
        // The held vertices of a panel mesh: the opened design's anchors and every dragged one.
        if let Run::Pq { stepper, .. } = &self.run
            && !stepper.anchors().is_empty()
        {
            data.add_lines(&anchor_crosses(&m, stepper.anchors()));
        }
        if let Some((offset, beams, segments)) = self.layer_meshes(&m)? {
            if let Some(offset) = offset {
                data.add_layer(&offset, OFFSET_COLOR, true);
            }
            if let Some(beams) = beams {
                data.add_layer(&beams, BEAM_COLOR, false);
                data.add_lines(&segments);
            }
        }
        data.view_origin = self.view_origin;
        if mode == ColorMode::Planarity && !self.draws_extras() {
            data.key = Some(self.shown.key());
        }
        Ok(data)
    }

    /// What [`Session::mesh_since`] hands out when only faces and vertices were added since
    /// `since` and nothing but the planarity-coloured panels is drawn; `None` otherwise.
    fn tail_since(&mut self, since: MeshKey) -> Option<MeshData> {
        if self.draws_extras() {
            return None;
        }
        self.sync_shown();
        let key = self.shown.key();
        let origin = self.view_origin;
        let (tail, mesh) = self.shown.planarity_tail(since)?;
        // As `mesh_in` takes them: relative to the view origin.
        let positions = panel_positions_from(mesh, since.vertices, origin);
        let faces = panel_faces_from(mesh, since.faces);
        Some(MeshData::tail(tail, (positions, faces), origin, since, key))
    }

    /// Whether `mesh_in` draws more than the panels: a panel mesh's anchors, or offset and
    /// support layers.
    fn draws_extras(&self) -> bool {
        let anchors = matches!(&self.run, Run::Pq { stepper, .. } if !stepper.anchors().is_empty());
        let layers = (self.layers.offset || self.layers.support) && self.offset_reason().is_none();
        anchors || layers
    }

    /// Brings [`Session::shown`] up to the current mesh.
    fn sync_shown(&mut self) {
        if self.shown_is_current {
            return;
        }
        let mesh = self.current_mesh().unwrap_or_default();
        self.shown.sync(mesh);
        self.shown_is_current = true;
    }

    /// Why this run has no offset layer (see `offsetUnavailable`).
    fn offset_reason(&self) -> Option<&'static str> {
        match &self.run {
            Run::Pq { stepper, .. } if stepper.mode() == PqMode::Conical => None,
            _ => Some(
                "offset and support beams need a conical mesh (conical paper, Sec. 4): pick conical-station",
            ),
        }
    }

    /// The offset and support layers of `mesh` that are switched on (None: none).
    fn layer_meshes(&self, mesh: &PolyMesh) -> Result<Option<Layers>, JsError> {
        let l = &self.layers;
        if !(l.offset || l.support) || self.offset_reason().is_some() {
            return Ok(None);
        }
        let d = l.distance.unwrap_or(DEFAULT_OFFSET);
        let (beams, offset) = support_structure(mesh, d).map_err(err)?;
        let n = mesh.num_vertices();
        let mut used = vec![false; n];
        for f in mesh.faces() {
            for &v in f {
                used[v as usize] = true;
            }
        }
        let segments: Vec<f32> = (0..n)
            .filter(|&v| used[v])
            .flat_map(|v| {
                let (a, b) = (mesh.positions[v], offset.positions[v]);
                [a.x, a.y, a.z, b.x, b.y, b.z].map(|x| x as f32)
            })
            .collect();
        Ok(Some((
            l.offset.then_some(offset),
            l.support.then_some(beams),
            segments,
        )))
    }

    fn current_mesh(&self) -> Option<PolyMesh> {
        match &self.run {
            Run::Phex(p, _) => Some(p.mesh()),
            Run::Pq { stepper, .. } => Some(stepper.mesh().clone()),
        }
    }

    fn metrics_struct(&mut self) -> Metrics {
        self.sync_shown();
        let mesh = self.shown.mesh();
        let mean_planarity = self.shown.mean_planarity();
        let histogram = self.shown.histogram();
        let hist_log10 = [PLANARITY_HIST_LO, PLANARITY_HIST_HI];
        let (self_intersecting, non_convex_faces) = self.shown.shape_counts();
        let mean_edge = self.shown.mean_edge();
        let mean_edge_m = self
            .design
            .as_ref()
            .map(|d| mean_edge * d.unit.parse::<LengthUnit>().unwrap_or_default().to_m());
        let extent = self.shown.extent();
        match &self.run {
            Run::Phex(p, goals) => {
                let m = p.metrics();
                // Measured on the mesh shown, in the user's coordinates: an imported design
                // is solved in its own frame (`PhexPipeline::frame`), and far from the origin
                // the user's coordinates hold less than the solver's.
                // A NaN face makes the whole NaN (a miss), as the optimiser's figure did.
                let max_planarity = self.shown.max_planarity();
                let reason = p
                    .is_done()
                    .then(|| goals.shortfall(mesh, max_planarity, m.iteration, m.invalid_faces))
                    .flatten();
                Metrics {
                    phase: if reason.is_some() {
                        "warning"
                    } else {
                        m.phase.name()
                    },
                    reason,
                    layer: m.layer,
                    iteration: m.iteration,
                    faces: m.faces,
                    vertices: m.vertices,
                    max_planarity,
                    mean_planarity,
                    invalid_faces: m.invalid_faces,
                    histogram,
                    hist_log10,
                    level: None,
                    levels: None,
                    conical_residual: None,
                    circular_residual: None,
                    max_determinant: None,
                    singular_points_inside: None,
                    design: self.design.clone(),
                    deviation_mm: None,
                    non_convex_faces,
                    mean_edge_m,
                    steps_left_at_most: p.steps_left_at_most(),
                    extent,
                    mean_edge,
                    view_origin: self.view_origin.into(),
                }
            }
            Run::Pq { stepper, started } => {
                let PqSceneStepInfo {
                    level,
                    levels,
                    phase,
                    iteration,
                    measures:
                        PqSceneMeasures {
                            max_planarity,
                            conical_residual,
                            circular_residual,
                            max_determinant,
                            singular_points_inside,
                        },
                    ..
                } = stepper.metrics();
                let reason = stepper
                    .is_done()
                    .then(|| {
                        stepper.edit_shortfall().map(String::from).or_else(|| {
                            pq_scene_shortfall(stepper.converged(), &stepper.metrics().measures)
                        })
                    })
                    .flatten();
                Metrics {
                    // Before the first step nothing is shown yet.
                    phase: match (*started, &reason) {
                        (false, _) => "ready",
                        (true, Some(_)) => "warning",
                        (true, None) => phase.name(),
                    },
                    reason,
                    layer: level,
                    iteration,
                    faces: mesh.num_faces(),
                    vertices: mesh.num_vertices(),
                    max_planarity,
                    mean_planarity,
                    // Self-intersecting panels, tested in each face's plane.
                    invalid_faces: self_intersecting,
                    histogram,
                    hist_log10,
                    level: Some(level),
                    levels: Some(levels),
                    conical_residual,
                    circular_residual,
                    max_determinant,
                    singular_points_inside,
                    design: self.design.clone(),
                    deviation_mm: self.design.as_ref().and_then(|d| d.deviation_mm(mesh)),
                    non_convex_faces,
                    mean_edge_m,
                    // The first step only shows the control mesh.
                    steps_left_at_most: stepper
                        .steps_left_at_most()
                        .map(|n| n + usize::from(!*started)),
                    extent,
                    mean_edge,
                    view_origin: self.view_origin.into(),
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use dupin_core::mesh::{face_planarity, planarity_histogram};

    /// Not a test: where a worker step of the page's 10k-face benchmark configuration goes,
    /// natively (thread CPU time per Gauss-Newton iteration, CG iterations and Cholesky
    /// factorisations), against the page's metrics and render buffers for the same mesh.
    /// `cargo test -p dupin-web --lib profile_10k -- --ignored --nocapture`.
    #[test]
    #[ignore]
    fn profile_10k_worker_step() {
        use dupin_core::phex::{
            Initialisation, PhexConfig, PhexPipeline, PlanarityOptimiser, TriangulationMethod,
        };
        let cpu = || {
            let s = std::fs::read_to_string("/proc/thread-self/schedstat").unwrap_or_default();
            s.split_whitespace()
                .next()
                .and_then(|t| t.parse::<f64>().ok())
                .unwrap_or(0.0)
                * 1e-9
        };
        let mut cfg =
            PhexConfig::for_surface("torus", &[], TriangulationMethod::Prescribed, Some(0.155));
        cfg.initialisation = Initialisation::DupinDuality;
        let p = PhexPipeline::new(cfg.clone()).unwrap();
        let mut d = p.initial_dual_mesh().unwrap();
        let mut opt =
            PlanarityOptimiser::new(&d.mesh, Some(&d.vertex_uv), cfg.planarity_options()).unwrap();
        println!("faces {}", d.mesh.num_faces());
        while !opt.is_done() {
            let (t, cg, f) = (cpu(), opt.cg_iterations(), opt.factorizations());
            let st = opt.step(&mut d.mesh, p.surface()).unwrap();
            println!(
                "iteration {}: {:.3} s CPU, CG {}, factorisations {}, nnz(L) {}, max planarity {:.2e}, cost {:.3e} -> {:.3e}, rejections {}, forcing {:.2e}",
                st.iteration,
                cpu() - t,
                opt.cg_iterations() - cg,
                opt.factorizations() - f,
                opt.factor_len(),
                st.max_planarity,
                st.cost_before,
                st.cost_after,
                opt.planarity_rejections(),
                opt.forcing()
            );
        }
        let t = cpu();
        let per_face: Vec<f64> = (0..d.mesh.num_faces())
            .map(|i| face_planarity(&d.mesh, i))
            .collect();
        let t_metrics = cpu() - t;
        let t = cpu();
        let colors: Vec<[f32; 3]> = per_face.iter().map(|&q| planarity_color(q)).collect();
        let m = MeshData::panels(d.mesh.clone(), &colors);
        println!(
            "metrics (per-face planarity) {:.1} ms, render buffers {:.1} ms ({} triangles)",
            t_metrics * 1e3,
            (cpu() - t) * 1e3,
            m.buffers.triangle_count()
        );
    }

    /// A free-mode torus session of `cfg`, as `new Session({ surface: "torus", ... })` makes it.
    fn torus_session(cfg: PhexConfig) -> Session {
        let goals = PhexGoals::of(&cfg, true);
        Session {
            run: Run::Phex(Box::new(PhexPipeline::new(cfg).unwrap()), goals),
            config: serde_json::from_str(r#"{"surface": "torus"}"#).unwrap(),
            shown: ShownMesh::default(),
            shown_is_current: false,
            layers: LayerConfig::default(),
            design: None,
            nurbs: None,
            view_origin: Vec3::zeros(),
        }
    }

    /// A finished run that misses what it was asked ends in `warning` with the reason, never
    /// `done`: the free-mode torus at panel size 0.2 ends with self-intersecting faces.
    #[test]
    fn metrics_carry_the_extent_and_mean_edge_of_the_mesh_on_show() {
        let cfg = PhexConfig::for_surface("torus", &[], TriangulationMethod::Prescribed, Some(0.6));
        let mut session = torus_session(cfg);
        while !session.done() {
            session.advance().unwrap();
        }
        let m = session.metrics_struct();
        let mesh = session.current_mesh().unwrap();
        // The library torus (R = 2, r = 0.7 by default) spans 2 (R + r) across and 2 r high.
        assert!((m.extent[0] - 5.4).abs() < 0.1 && (m.extent[1] - 5.4).abs() < 0.1);
        assert!((m.extent[2] - 1.4).abs() < 0.05, "height {}", m.extent[2]);
        assert_eq!(m.mean_edge, mesh.mean_edge());
        assert_eq!(ShownMesh::default().extent(), [0.0; 3]);
    }

    #[test]
    fn a_missed_result_ends_in_warning_not_done() {
        let cfg =
            PhexConfig::for_surface("torus", &[], TriangulationMethod::Progressive, Some(0.2));
        let mut session = torus_session(cfg);
        while !session.done() {
            assert_ne!(session.metrics_struct().phase, "warning");
            session.advance().unwrap();
        }
        let m = session.metrics_struct();
        assert!(m.invalid_faces > 0, "the case no longer has invalid faces");
        assert_eq!(m.phase, "warning");
        assert!(m.reason.unwrap().contains("faces are self-intersecting"));
    }

    /// Each state's tail (`meshSince` with the last state's key), appended to the arrays held
    /// so far, gives that state's whole mesh bit for bit: triangles, colours, edges and
    /// panels. The triangulation's layers come as tails, and a state whose mesh moved (the
    /// optimisation) or another colour mode comes whole.
    #[test]
    fn tails_appended_state_by_state_give_the_whole_meshes() {
        let cfg = PhexConfig::for_surface("torus", &[], TriangulationMethod::Prescribed, Some(0.6));
        let mut s = torus_session(cfg);
        type Arrays = (
            Vec<f32>,
            Vec<f32>,
            Vec<u32>,
            Vec<f32>,
            Vec<f32>,
            Vec<f64>,
            Vec<u32>,
        );
        let arrays = |m: &MeshData| -> Arrays {
            let (positions, faces) = match (&m.panels, &m.panel_arrays) {
                (Some(p), _) => (
                    p.positions.iter().flat_map(|q| [q.x, q.y, q.z]).collect(),
                    p.faces()
                        .flat_map(|f| std::iter::once(f.len() as u32).chain(f.iter().copied()))
                        .collect(),
                ),
                (None, Some(a)) => a.clone(),
                (None, None) => unreachable!(),
            };
            let b = &m.buffers;
            let (p, n, i) = (b.positions.clone(), b.normals.clone(), b.indices.clone());
            (p, n, i, m.colors.clone(), m.edges.clone(), positions, faces)
        };
        let (mut held, mut key): (Option<Arrays>, Option<MeshKey>) = (None, None);
        let (mut tails, mut wholes) = (0, 0);
        while !s.done() {
            s.advance().unwrap();
            let whole = s.mesh_in(None).unwrap();
            let part = match key.and_then(|k| s.tail_since(k)) {
                Some(part) => part,
                None => s.mesh_in(None).unwrap(),
            };
            assert_eq!(part.key, whole.key);
            let now = match (part.append_to, held.take()) {
                (Some(since), Some(mut h)) => {
                    assert_eq!(Some(since), key);
                    let t = arrays(&part);
                    h.0.extend(t.0);
                    h.1.extend(t.1);
                    h.2.extend(t.2);
                    h.3.extend(t.3);
                    h.4.extend(t.4);
                    h.5.extend(t.5);
                    h.6.extend(t.6);
                    tails += 1;
                    h
                }
                (None, _) => {
                    wholes += 1;
                    arrays(&part)
                }
                (Some(_), None) => unreachable!(),
            };
            assert_eq!(now, arrays(&whole));
            held = Some(now);
            key = part.key;
        }
        assert!(tails >= 10 && wholes >= 2, "{tails} tails, {wholes} whole");
        // Other colours cannot be added to, nor added to what they drew.
        assert_eq!(s.mesh_in(Some("convexity")).unwrap().key, None);
        assert!(s.tail_since(key.unwrap()).is_some());
        let stale = MeshKey {
            revision: key.unwrap().revision + 1,
            ..key.unwrap()
        };
        assert!(s.tail_since(stale).is_none());
    }

    /// The per-face figures kept from state to state follow every step: the metrics' mean and
    /// histogram and the planarity colours always match a fresh computation on the current
    /// mesh.
    #[test]
    fn cached_face_planarity_follows_every_step() {
        let mut cfg =
            PhexConfig::for_surface("torus", &[], TriangulationMethod::Prescribed, Some(0.6));
        cfg.initialisation = dupin_core::phex::Initialisation::DupinDuality;
        let mut session = torus_session(cfg);
        let mut optimised = 0;
        while !session.done() {
            session.advance().unwrap();
            let mesh = session.current_mesh().unwrap();
            let fresh: Vec<f64> = (0..mesh.num_faces())
                .map(|i| face_planarity(&mesh, i))
                .collect();
            let m = session.metrics_struct();
            let mean = if fresh.is_empty() {
                0.0
            } else {
                fresh.iter().sum::<f64>() / fresh.len() as f64
            };
            assert_eq!(m.mean_planarity, mean);
            assert_eq!(m.histogram, planarity_histogram(&fresh));
            assert_eq!(session.shown.planarity(), fresh.as_slice());
            optimised += usize::from(m.phase == "optimisation" || m.phase == "done");
        }
        assert!(optimised >= 2, "the run optimised");
    }

    fn pq_session(scene: &str) -> Session {
        Session {
            run: Run::Pq {
                stepper: Box::new(pq_scene_stepper(scene).unwrap()),
                started: false,
            },
            config: serde_json::from_str(&format!(r#"{{"scene": "{scene}"}}"#)).unwrap(),
            shown: ShownMesh::default(),
            shown_is_current: false,
            layers: LayerConfig::default(),
            design: None,
            nurbs: None,
            view_origin: Vec3::zeros(),
        }
    }

    /// A drag on the finished `conical-station`: the run restarts from the committed mesh,
    /// the dragged vertex is held where it was put and drawn as an anchor, and the run ends
    /// planar again.
    #[test]
    fn a_drag_restarts_the_run_with_the_vertex_held() {
        let mut s = pq_session("conical-station");
        while !s.done() {
            s.advance().unwrap();
        }
        let before = s.current_mesh().unwrap();
        let v = 40;
        let p = before.positions[v] + dupin_core::Vec3::new(0.0, 0.0, 0.05);
        s.drag_vertex(v, p.x, p.y, p.z, true).unwrap();
        assert!(!s.done(), "the drag restarts the run");
        let t0 = std::time::Instant::now();
        let mut steps = 0;
        while !s.done() {
            s.advance().unwrap();
            steps += 1;
        }
        eprintln!(
            "{} faces: replanarised in {steps} steps, {:?}",
            before.num_faces(),
            t0.elapsed()
        );
        let after = s.current_mesh().unwrap();
        assert_eq!(after.positions[v], p);
        let m = s.metrics_struct();
        assert_eq!(m.phase, "done");
        assert!(m.max_planarity <= 1e-9, "{}", m.max_planarity);
        let crosses = anchor_crosses(&after, &[v]);
        assert!(!crosses.is_empty());
    }

    /// A group drag: the dragged vertex lands where it was put, its box-selected group moves
    /// by the same translation, every one of them is held, the run ends planar.
    #[test]
    fn a_group_drag_moves_the_selection_together() {
        let mut s = pq_session("conical-station");
        while !s.done() {
            s.advance().unwrap();
        }
        let before = s.current_mesh().unwrap();
        let (v, group) = (40usize, vec![41u32, 39, 40]);
        let p = before.positions[v] + dupin_core::Vec3::new(0.0, 0.0, 0.05);
        let delta = p - before.positions[v];
        s.drag_vertices(v, p.x, p.y, p.z, group.clone(), true)
            .unwrap();
        while !s.done() {
            s.advance().unwrap();
        }
        let after = s.current_mesh().unwrap();
        assert_eq!(after.positions[v], p);
        for &w in &group[..2] {
            let w = w as usize;
            assert_eq!(after.positions[w], before.positions[w] + delta);
        }
        let m = s.metrics_struct();
        assert_eq!(m.phase, "done");
        assert!(m.max_planarity <= 1e-9, "{}", m.max_planarity);
        let Run::Pq { stepper, .. } = &s.run else {
            unreachable!()
        };
        assert!([39, 40, 41].iter().all(|a| stepper.anchors().contains(a)));
    }

    /// A PQ scene steps level by level: the control mesh first, then one perturbation
    /// iteration or one subdivision a step, every step changing the metrics, ending at the
    /// one-shot scene with the contract bounds.
    #[test]
    fn pq_session_steps_level_by_level() {
        let mut s = pq_session("conical-station");
        assert_eq!(s.metrics_struct().phase, "ready");
        s.advance().unwrap();
        let first = s.metrics_struct();
        assert_eq!(
            (first.phase, first.level, first.faces),
            ("control", Some(0), 24)
        );
        let key = |m: &Metrics| (m.phase, m.level, m.iteration, m.faces, m.max_planarity);
        let mut prev = key(&first);
        let mut levels_seen = vec![0];
        let mut steps = 1;
        while !s.done() {
            s.advance().unwrap();
            steps += 1;
            let m = s.metrics_struct();
            assert_ne!(key(&m), prev, "step {steps} left the metrics unchanged");
            assert_eq!(m.max_planarity, max_planarity(&s.current_mesh().unwrap()));
            if levels_seen.last() != m.level.as_ref() {
                levels_seen.push(m.level.unwrap());
            }
            prev = key(&m);
        }
        assert_eq!(levels_seen, vec![0, 1, 2]);
        let m = s.metrics_struct();
        assert_eq!(m.phase, "done");
        assert!(m.max_planarity <= 1e-10 && m.conical_residual.unwrap() <= 1e-10);
        let one_shot = dupin_core::scenes::pq_scene("conical-station").unwrap();
        assert_eq!(s.current_mesh().unwrap(), one_shot.mesh);
        assert_eq!(m.iteration, one_shot.iterations);
    }

    /// Offset and support layers of the finished conical station: the offset has the mesh's
    /// faces and is planar, there is one beam per edge and the beams are planar (conical
    /// paper, Sec. 4); the drawn mesh gains both layers and a segment per vertex.
    #[test]
    fn conical_layers_are_planar_and_drawn() {
        let mut s = pq_session("conical-station");
        while !s.done() {
            s.advance().unwrap();
        }
        let plain = s.mesh_in(None).unwrap();
        let mesh = s.current_mesh().unwrap();
        assert!(s.offset_reason().is_none());
        assert!(pq_session("developable-strips").offset_reason().is_some());
        s.layers = LayerConfig {
            offset: true,
            support: true,
            distance: Some(0.2),
        };
        let (offset, beams, segments) = s.layer_meshes(&mesh).unwrap().unwrap();
        let (offset, beams) = (offset.unwrap(), beams.unwrap());
        let edges = dupin_core::mesh::MeshTopology::new(&mesh)
            .unwrap()
            .edges()
            .len();
        assert_eq!(offset.num_faces(), mesh.num_faces());
        assert_eq!(beams.num_faces(), edges);
        assert!(max_planarity(&offset) <= 1e-9, "{}", max_planarity(&offset));
        assert!(max_planarity(&beams) <= 1e-9, "{}", max_planarity(&beams));
        assert_eq!(segments.len(), 6 * mesh.num_vertices());
        let layered = s.mesh_in(None).unwrap();
        let tris = |m: &MeshData| m.buffers.triangle_count();
        let offset_tris = dupin_core::mesh::polymesh_buffers(&offset, None)
            .0
            .triangle_count();
        let beam_tris = dupin_core::mesh::polymesh_buffers(&beams, None)
            .0
            .triangle_count();
        assert_eq!(tris(&layered), tris(&plain) + offset_tris + beam_tris);
        assert_eq!(layered.colors.len(), layered.buffers.positions.len());
        assert!(layered.edges.len() > plain.edges.len() + segments.len());
        // Only the support layer: no offset panels.
        s.layers.offset = false;
        assert_eq!(tris(&s.mesh_in(None).unwrap()), tris(&plain) + beam_tris);
    }
}
