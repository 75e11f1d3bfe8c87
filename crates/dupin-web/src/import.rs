//! `Session.fromFile(name, bytes, config)`: a design opened in the page (file input or drop). A
//! NURBS surface (JSON) or a triangle mesh of a smooth surface becomes a surface the P-Hex
//! pipeline panels; a mesh of quads, hexagons or any polygons becomes panels that the PQ
//! perturbation makes planar (planar, conical or circular), keeping the design. The file never
//! leaves the page: the bytes come from the browser and stay in the worker.

use dupin_core::Stepper;
use dupin_core::conical::{MeshRule, PqMode, PqOptions, PqSceneStepper};
use dupin_core::fabrication::LengthUnit;
use dupin_core::mesh::PolyMesh;
use dupin_core::mesh::io::{ImportOptions, read_mesh};
use dupin_core::phex::{LayerRule, PhexConfig, PhexGoals, PhexPipeline, TriangulationMethod};
use dupin_core::surface::{MeshFitOptions, NurbsSurface, Surface, fit_mesh_surface};
use serde::{Deserialize, Serialize};
use std::sync::Arc;
use wasm_bindgen::prelude::*;

/// The options of `Session.fromFile`: `{ importAs, unit, size, method, init, bound, lambda, mu,
/// mode, fixBoundary, anchors, closeness, toleranceMm, controlPoints }`, all optional: the
/// surface settings are the free mode's.
#[derive(Deserialize, Default, Clone)]
#[serde(deny_unknown_fields, rename_all = "camelCase")]
struct ImportConfig {
    /// `surface` (P-Hex panels it) or `panels` (planarised); absent: guessed from the file.
    import_as: Option<String>,
    /// Length unit of the file's coordinates (`mm`, `cm`, `m`, `in`, `ft`); absent: the file's
    /// own (a NURBS JSON may state one), else metres.
    unit: Option<String>,
    /// Surface: target edge length of the base curve, in the file's unit.
    size: Option<f64>,
    /// Surface: `prescribed` (default: method 2 along the parameter lines) or `progressive`.
    method: Option<String>,
    /// Surface: hexagon initialisation, as in the free mode.
    init: Option<String>,
    /// Surface: parabolic lower bound b (section 5.3).
    bound: Option<f64>,
    /// Surface: initial fairness weight (section 7).
    lambda: Option<f64>,
    /// Surface: initial surface-distance weight (section 7).
    mu: Option<f64>,
    /// Panels: `planar` (default), `conical` or `circular`.
    mode: Option<String>,
    /// Panels: keep the boundary vertices where they are.
    fix_boundary: Option<bool>,
    /// Panels: vertices (0-based, in the file's order) that must not move.
    anchors: Option<Vec<usize>>,
    /// Panels: the closeness weight (how strongly the vertices stay near the design).
    closeness: Option<f64>,
    /// Panels: the largest distance of a panel corner from its plane, in millimetres.
    tolerance_mm: Option<f64>,
    /// NURBS surface: control-point moves, `[index, x, y, z]` each (index row-major,
    /// `i * nv + j`; coordinates in the file's unit), applied and followed in order (a point
    /// may move more than once: a drag is the positions the panelling followed).
    control_points: Option<Vec<[f64; 4]>>,
}

impl ImportConfig {
    /// Moves control point `index` to `p` in these options: one more move after those before
    /// (the panelling follows each in turn, [`following_run`]).
    fn move_control_point(&mut self, index: usize, p: [f64; 3]) {
        let entry = [index as f64, p[0], p[1], p[2]];
        self.control_points.get_or_insert_with(Vec::new).push(entry);
    }
}

/// The keys of [`ImportConfig`] as JS spells them, for the unknown-key check.
pub(crate) const IMPORT_CONFIG_KEYS: &[&str] = &[
    "importAs",
    "unit",
    "size",
    "method",
    "init",
    "bound",
    "lambda",
    "mu",
    "mode",
    "fixBoundary",
    "anchors",
    "closeness",
    "toleranceMm",
    "controlPoints",
];

/// The free mode's P-Hex run settings, shared by a library surface and an opened one: the
/// parabolic lower bound b (section 5.3), the initial fairness and surface-distance weights
/// (section 7) and the hexagon initialisation (`tangent-duality`, section 4.1, by default, or
/// `dupin-duality`, section 6). Absent values keep `config`'s.
pub(crate) fn apply_phex_settings(
    config: &mut PhexConfig,
    bound: Option<f64>,
    lambda: Option<f64>,
    mu: Option<f64>,
    init: Option<&str>,
) -> Result<(), String> {
    if let Some(b) = bound {
        config.rule = LayerRule::Ideal { bound: b };
    }
    if let Some(l) = lambda {
        config.lambda = l;
    }
    if let Some(m) = mu {
        config.mu = m;
    }
    if let Some(i) = init {
        config.initialisation = i.parse().map_err(|e| format!("{e}"))?;
    }
    Ok(())
}

/// The page's largest panel factorisation (1 GB: a browser tab must survive it).
const PAGE_MAX_FACTOR_BYTES: usize = 1 << 30;

/// What the page shows about an opened design: its name, how it is read, its unit and its
/// overall dimensions in metres; for a fitted mesh, the fit's largest distance in metres.
#[derive(Serialize, Clone, Debug)]
#[serde(rename_all = "camelCase")]
pub(crate) struct DesignInfo {
    name: String,
    import_as: &'static str,
    pub(crate) unit: &'static str,
    dimensions_m: [f64; 3],
    #[serde(skip_serializing_if = "Option::is_none")]
    fit_max_distance_m: Option<f64>,
    /// Seconds the file took to read (parse, and weld a mesh) in this worker.
    read_seconds: f64,
    /// Seconds the smooth fit of a triangle mesh took, for a fitted mesh.
    #[serde(skip_serializing_if = "Option::is_none")]
    fit_seconds: Option<f64>,
    /// A panel mesh's vertices as opened: the design the schedule's deviations are measured
    /// from (the planarisation keeps the vertex order).
    #[serde(skip)]
    pub(crate) positions: Option<Vec<dupin_core::Vec3>>,
    /// The anchored vertices of a panel mesh (drawn with the panels).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub(crate) anchors: Vec<usize>,
    /// A NURBS surface's control net, with its moved points where they were put.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(crate) control_net: Option<ControlNet>,
}

/// A NURBS surface's control net for the page: `nu` rows of `nv` points, `points` flat x, y, z
/// in the file's unit, point (i, j) at `i * nv + j`.
#[derive(Serialize, Clone, Debug, PartialEq)]
pub(crate) struct ControlNet {
    nu: usize,
    nv: usize,
    points: Vec<f64>,
}

impl DesignInfo {
    /// How far `mesh`'s vertices are from the opened panel design's, largest and mean, in
    /// millimetres; `None` for a surface or a mesh of another vertex count.
    pub(crate) fn deviation_mm(&self, mesh: &PolyMesh) -> Option<[f64; 2]> {
        let design = self.positions.as_ref()?;
        if design.len() != mesh.num_vertices() || design.is_empty() {
            return None;
        }
        let mm = self.unit.parse::<LengthUnit>().unwrap_or_default().to_mm();
        let (mut max, mut sum) = (0.0f64, 0.0);
        for (p, q) in mesh.positions.iter().zip(design) {
            let d = (p - q).norm() * mm;
            max = max.max(d);
            sum += d;
        }
        Some([max, sum / design.len() as f64])
    }
}

/// What an opened file runs: P-Hex on its surface, or the planarisation of its panels.
pub(crate) enum Imported {
    /// P-Hex on the design's surface and what the run is asked for.
    Phex(Box<PhexPipeline>, PhexGoals),
    /// The panels' perturbation, stepped like a PQ scene with no subdivision.
    Panels(Box<PqSceneStepper>),
}

/// Milliseconds on a monotonic-enough clock: the page's (`Date.now`, whole milliseconds) in
/// wasm, the system's natively. For the read and fit times the page shows.
fn now_ms() -> f64 {
    #[cfg(target_arch = "wasm32")]
    {
        js_sys::Date::now()
    }
    #[cfg(not(target_arch = "wasm32"))]
    {
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0.0, |d| d.as_secs_f64() * 1e3)
    }
}

/// The run and design information of an opened file, and for a NURBS surface what its
/// control points can be dragged with ([`NurbsSource`]). Errors name the file.
pub(crate) fn import_run(
    name: &str,
    bytes: &[u8],
    config: JsValue,
) -> Result<(Imported, DesignInfo, Option<NurbsSource>), JsError> {
    crate::js::refuse_unknown_keys(&config, "import config", IMPORT_CONFIG_KEYS)?;
    let cfg: ImportConfig = if config.is_undefined() || config.is_null() {
        ImportConfig::default()
    } else {
        serde_wasm_bindgen::from_value(config)
            .map_err(|e| JsError::new(&format!("bad import config: {e}")))?
    };
    let (run, info) = import_design_from(name, bytes, &cfg, None).map_err(|e| JsError::new(&e))?;
    let source = info.control_net.is_some().then(|| NurbsSource {
        name: name.to_string(),
        bytes: bytes.to_vec(),
        cfg,
    });
    Ok((run, info, source))
}

/// An opened NURBS surface as it was read: the file and its options, the control-point moves
/// among them. Moving a point reads the design again with one more move, so a drag ends on
/// exactly the run a reload of the same options gives (see [`following_run`]).
pub(crate) struct NurbsSource {
    name: String,
    bytes: Vec<u8>,
    cfg: ImportConfig,
}

/// The most control-point moves a design replays. Each move is followed from the run before it
/// to that run's end (a Gauss-Newton optimisation of the whole mesh: up to a second or two
/// for 10k panels in the page), so a reload costs that many optimisations; more are refused.
pub(crate) const MAX_CONTROL_POINT_MOVES: usize = 1000;

/// The P-Hex run on a design whose control points moved (`config`, its surface `opened` with
/// `moves` applied). A new run on a reshaped surface would triangulate along parameter lines
/// the move bent away from conjugate and come out with self-intersecting hexagons near the
/// point (section 5.2; measured in `dupin_core::phex::pipeline::follow`), so the panelling
/// follows the moves instead, one at a time: the finished run before each move is followed to
/// it ([`PhexPipeline::follow_in_steps`]) and run to its end before the next one. The last
/// move's run is returned before its first step.
///
/// A drag is recorded as the pointer positions the panelling followed (a move each), so the
/// result depends only on the file, its options and the moves: a drag and a reload of the same
/// `controlPoints` give the same panels bit for bit, and the release costs one short move, not
/// the whole drag again. Where a run before a move gives no panels to follow (no hexagonal
/// mesh, invalid panels: [`PhexError::NotFollowed`](dupin_core::phex::PhexError)), the move
/// takes a new run on its surface.
///
/// `previous`: the run for every move but the last (the run shown during a drag), which is run
/// to its end if it has not ended and followed to the last move: the same run as following
/// every move from the design as opened (`None`), for one optimisation instead of one a move.
fn following_run(
    config: PhexConfig,
    opened: NurbsSurface,
    moves: &[[f64; 4]],
    previous: Option<&mut PhexPipeline>,
) -> Result<PhexPipeline, String> {
    if previous.is_some() {
        return follow_move(previous, config);
    }
    let mut surface = opened;
    let mut run = {
        let mut first = config.clone();
        first.nurbs = Some(Arc::new(surface.clone()));
        PhexPipeline::new(first).ok()
    };
    for &[index, x, y, z] in moves {
        surface
            .set_control_point(index as usize, dupin_core::Vec3::new(x, y, z))
            .map_err(|e| format!("controlPoints: {e}"))?;
        let mut next = config.clone();
        next.nurbs = Some(Arc::new(surface.clone()));
        run = Some(follow_move(run.as_mut(), next)?);
    }
    run.map_or_else(|| PhexPipeline::new(config).map_err(|e| format!("{e}")), Ok)
}

/// One move of [`following_run`]: `previous` (the run before the move) run to its end and
/// followed to `config`'s surface, or a new run there when it gives nothing to follow.
fn follow_move(
    previous: Option<&mut PhexPipeline>,
    config: PhexConfig,
) -> Result<PhexPipeline, String> {
    if let (Some(previous), Some(surface)) = (previous, config.nurbs.as_deref()) {
        // A step that fails leaves the run unfinished, and following refuses it below.
        let _ = previous.run_to_end();
        if let Ok(p) = previous.follow_in_steps(surface.clone()) {
            return Ok(p);
        }
    }
    PhexPipeline::new(config).map_err(|e| format!("{e}"))
}

impl NurbsSource {
    /// The run and design with control point `index` moved to `p` (file unit), one more move
    /// after those before; the source keeps the move only when it succeeds. The panelling
    /// follows from `previous`, the run for the moves before (the run shown), else from the
    /// design as opened through every move ([`following_run`]).
    pub(crate) fn move_control_point(
        &mut self,
        index: usize,
        p: [f64; 3],
        previous: Option<&mut PhexPipeline>,
    ) -> Result<(Imported, DesignInfo), String> {
        let mut cfg = self.cfg.clone();
        cfg.move_control_point(index, p);
        let out = import_design_from(&self.name, &self.bytes, &cfg, previous)?;
        self.cfg = cfg;
        Ok(out)
    }
}

/// [`import_design_from`] of a design as read (every move followed from the design as opened).
#[cfg(test)]
fn import_design(
    name: &str,
    bytes: &[u8],
    cfg: &ImportConfig,
) -> Result<(Imported, DesignInfo), String> {
    import_design_from(name, bytes, cfg, None)
}

/// [`import_run`] after its options are read (plain Rust, tested natively); for a NURBS design
/// with moved control points, `previous` is the run for every move but the last, if the caller
/// has it ([`following_run`]).
fn import_design_from(
    name: &str,
    bytes: &[u8],
    cfg: &ImportConfig,
    previous: Option<&mut PhexPipeline>,
) -> Result<(Imported, DesignInfo), String> {
    let named = |e: &dyn std::fmt::Display| format!("{name}: {e}");
    let wanted = match cfg.import_as.as_deref() {
        None => None,
        Some("surface") => Some(true),
        Some("panels") => Some(false),
        Some(other) => {
            return Err(format!("importAs `{other}`: use `surface` or `panels`"));
        }
    };
    let mut unit: Option<LengthUnit> = match cfg.unit.as_deref() {
        Some(u) => Some(u.parse().map_err(|e| format!("{e}"))?),
        None => None,
    };
    // A NURBS surface is `.json`, or JSON text under a name no mesh format claims (a .3dm the
    // page converted, a file without extension); a `.gltf` is JSON too but a mesh.
    let ext = name.rsplit_once('.').map(|(_, e)| e.to_ascii_lowercase());
    let is_json = match ext.as_deref() {
        Some("json") => true,
        Some("obj" | "stl" | "gltf" | "glb") => false,
        _ => bytes
            .iter()
            .find(|b| !b.is_ascii_whitespace())
            .is_some_and(|&b| b == b'{'),
    };
    let t0 = now_ms();
    let read_ms: f64;
    // The NURBS surface as the file has it, when control points moved.
    let mut opened = None;
    let mut fit_ms = None;
    let (surface, mesh, fit_distance) = if is_json {
        if wanted == Some(false) {
            return Err(named(
                &"a NURBS surface is panelled as a surface, not planarised",
            ));
        }
        let text = std::str::from_utf8(bytes).map_err(|e| named(&e))?;
        let mut s = NurbsSurface::from_json(text).map_err(|e| named(&e))?;
        if cfg.control_points.as_ref().is_some_and(|m| !m.is_empty()) {
            opened = Some(s.clone());
        }
        let moves = cfg.control_points.as_ref().map_or(0, Vec::len);
        if moves > MAX_CONTROL_POINT_MOVES {
            return Err(named(&format_args!(
                "controlPoints: {moves} moves; a design replays at most \
                 {MAX_CONTROL_POINT_MOVES} (each is followed by an optimisation of the panels)"
            )));
        }
        for &[index, x, y, z] in cfg.control_points.iter().flatten() {
            if !(index >= 0.0 && index.fract() == 0.0 && index < u32::MAX as f64) {
                return Err(named(&format_args!(
                    "controlPoints: {index} is not a control point index"
                )));
            }
            s.set_control_point(index as usize, dupin_core::Vec3::new(x, y, z))
                .map_err(|e| named(&format_args!("controlPoints: {e}")))?;
        }
        unit = unit.or(s.unit());
        read_ms = now_ms() - t0;
        (Some(s), None, None)
    } else {
        if cfg.control_points.as_ref().is_some_and(|m| !m.is_empty()) {
            return Err(named(
                &"controlPoints are for a NURBS surface; a mesh has vertices",
            ));
        }
        let mesh = read_mesh(name, bytes, &ImportOptions::default())
            .map_err(|e| named(&e))?
            .mesh;
        read_ms = now_ms() - t0;
        let triangles = mesh.faces().all(|f| f.len() == 3);
        if wanted.unwrap_or(triangles) {
            let fit = fit_mesh_surface(&mesh, &MeshFitOptions::default()).map_err(|e| named(&e))?;
            fit_ms = Some(now_ms() - t0 - read_ms);
            (Some(fit.surface), Some(mesh), Some(fit.max_distance))
        } else {
            (None, Some(mesh), None)
        }
    };
    let unit = unit.unwrap_or_default();
    let extent = match (&mesh, &surface) {
        (Some(m), _) => bbox(&m.positions),
        (None, Some(s)) => {
            let d = s.domain();
            let samples: Vec<_> = (0..=32)
                .flat_map(|i| (0..=32).map(move |j| (i, j)))
                .map(|(i, j)| {
                    let u = d.u.0 + (d.u.1 - d.u.0) * i as f64 / 32.0;
                    let v = d.v.0 + (d.v.1 - d.v.0) * j as f64 / 32.0;
                    s.position(u, v)
                })
                .collect();
            bbox(&samples)
        }
        (None, None) => [0.0; 3],
    };
    // Only an opened NURBS surface has a net the user can drag; a fitted one's is ours.
    let control_net = surface.as_ref().filter(|_| is_json).map(|s| {
        let (nu, nv) = s.control_net_size();
        ControlNet {
            nu,
            nv,
            points: s.control_points().iter().flatten().copied().collect(),
        }
    });
    let info = DesignInfo {
        control_net,
        name: name.to_string(),
        import_as: if surface.is_some() {
            "surface"
        } else {
            "panels"
        },
        unit: unit.name(),
        dimensions_m: extent.map(|e| e * unit.to_m()),
        fit_max_distance_m: fit_distance.map(|d| d * unit.to_m()),
        read_seconds: read_ms * 1e-3,
        fit_seconds: fit_ms.map(|ms| ms * 1e-3),
        positions: match (&surface, &mesh) {
            (None, Some(m)) => Some(m.positions.clone()),
            _ => None,
        },
        anchors: match surface {
            None => cfg.anchors.clone().unwrap_or_default(),
            Some(_) => Vec::new(),
        },
    };
    let run = match (surface, mesh) {
        (Some(surface), _) => {
            // A fitted surface's u and v are ours: lay the layers across its parabolic curves.
            let mut config = if is_json {
                PhexConfig::for_nurbs(name, surface, cfg.size)
            } else {
                PhexConfig::for_fitted_mesh(name, surface, cfg.size)
            };
            if let Some(m) = &cfg.method {
                config.method = m
                    .parse::<TriangulationMethod>()
                    .map_err(|e| format!("{e}"))?;
            }
            apply_phex_settings(
                &mut config,
                cfg.bound,
                cfg.lambda,
                cfg.mu,
                cfg.init.as_deref(),
            )?;
            let goals = PhexGoals::of(&config, true);
            let pipeline = match opened {
                Some(opened) => {
                    let moves = cfg.control_points.as_deref().unwrap_or_default();
                    following_run(config, opened, moves, previous).map_err(|e| named(&e))?
                }
                None => PhexPipeline::new(config).map_err(|e| named(&e))?,
            };
            Imported::Phex(Box::new(pipeline), goals)
        }
        (None, Some(mesh)) => panels_run(&mesh, cfg, unit).map_err(|e| named(&e))?,
        (None, None) => unreachable!("a file gives a surface or a mesh"),
    };
    Ok((run, info))
}

/// The planarisation of an opened panel mesh, stepped like a PQ scene with no subdivision: the
/// design kept (fairness on the move, `keep_design`), as `dupin planarize` does.
fn panels_run(mesh: &PolyMesh, cfg: &ImportConfig, unit: LengthUnit) -> Result<Imported, String> {
    let mode: PqMode = cfg
        .mode
        .as_deref()
        .unwrap_or("planar")
        .parse()
        .map_err(|e| format!("{e}"))?;
    let mut options = PqOptions {
        mode,
        keep_design: true,
        fix_boundary: cfg.fix_boundary.unwrap_or(false),
        max_factor_bytes: PAGE_MAX_FACTOR_BYTES,
        ..PqOptions::default()
    };
    if let Some(anchors) = &cfg.anchors {
        if let Some(&bad) = anchors.iter().find(|&&a| a >= mesh.num_vertices()) {
            return Err(format!(
                "anchor {bad} is not a vertex (the mesh has {} vertices)",
                mesh.num_vertices()
            ));
        }
        options.fixed_vertices = anchors.clone();
    }
    if let Some(w) = cfg.closeness {
        if !(w.is_finite() && w >= 0.0) {
            return Err(format!("closeness must be a number >= 0, got {w}"));
        }
        options.closeness = w;
    }
    if let Some(t) = cfg.tolerance_mm {
        options.tolerance = relative_tolerance(mesh, t, unit)?;
    }
    let stepper = PqSceneStepper::for_mesh(mesh, MeshRule::CatmullClark, 0, options)
        .map_err(|e| format!("{e}"))?;
    Ok(Imported::Panels(Box::new(stepper)))
}

/// The planarisation tolerance (contract planarity: a face's corner distance over its mean
/// edge) that keeps every corner within `mm` millimetres of its face's plane: `mm` over the
/// largest face's mean edge in mm, so the bound holds for every face. Never looser than 1e-3
/// (a millimetre on a metre is not planar) nor tighter than 1e-13 (rounding).
fn relative_tolerance(mesh: &PolyMesh, mm: f64, unit: LengthUnit) -> Result<f64, String> {
    if !(mm.is_finite() && mm > 0.0) {
        return Err(format!(
            "tolerance must be a positive length in mm, got {mm}"
        ));
    }
    let largest = mesh
        .faces()
        .map(|f| {
            let n = f.len();
            (0..n)
                .map(|i| {
                    (mesh.positions[f[(i + 1) % n] as usize] - mesh.positions[f[i] as usize]).norm()
                })
                .sum::<f64>()
                / n as f64
        })
        .fold(0.0f64, f64::max)
        * unit.to_mm();
    if largest <= 0.0 {
        return Err("the panels have no edge length to measure a tolerance on".into());
    }
    Ok((mm / largest).clamp(1e-13, 1e-3))
}

/// Extent of points along x, y and z.
fn bbox(points: &[dupin_core::Vec3]) -> [f64; 3] {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in points {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    [0, 1, 2].map(|k| if hi[k] >= lo[k] { hi[k] - lo[k] } else { 0.0 })
}

#[cfg(test)]
mod tests {
    use super::*;
    use dupin_core::Stepper;

    fn refused(name: &str, bytes: &[u8], cfg: &ImportConfig) -> String {
        match import_design(name, bytes, cfg) {
            Ok(_) => panic!("{name} was accepted"),
            Err(e) => e,
        }
    }

    fn run_to_end(run: &mut Imported) -> (f64, usize) {
        match run {
            Imported::Phex(p, _) => {
                while !p.is_done() {
                    p.step().unwrap();
                }
                let m = p.metrics();
                (m.max_planarity, m.invalid_faces)
            }
            Imported::Panels(stepper) => {
                while !stepper.is_done() {
                    stepper.step().unwrap();
                }
                (stepper.metrics().measures.max_planarity, 0)
            }
        }
    }

    fn grid_obj(n: usize, triangles: bool) -> String {
        let mut obj = String::new();
        for i in 0..=n {
            for j in 0..=n {
                let (x, y) = (i as f64, j as f64);
                let z = 0.05 * (x * x + y * y) + if (i * 7 + j * 3) % 5 == 0 { 1e-3 } else { 0.0 };
                obj += &format!("v {x} {y} {z}\n");
            }
        }
        let id = |i: usize, j: usize| i * (n + 1) + j + 1;
        for i in 0..n {
            for j in 0..n {
                let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                if triangles {
                    obj += &format!("f {a} {b} {c}\nf {a} {c} {d}\n");
                } else {
                    obj += &format!("f {a} {b} {c} {d}\n");
                }
            }
        }
        obj
    }

    #[test]
    fn a_tube_of_triangles_opens_as_a_surface_cut_open_along_a_seam() {
        let (nu, nv) = (24, 6);
        let mut obj = String::new();
        for j in 0..=nv {
            for i in 0..nu {
                let a = std::f64::consts::TAU * i as f64 / nu as f64;
                let r = 2.0 + 0.2 * (j as f64).cos();
                obj += &format!("v {} {} {}\n", r * a.cos(), r * a.sin(), 0.5 * j as f64);
            }
        }
        let id = |i: usize, j: usize| j * nu + i % nu + 1;
        for j in 0..nv {
            for i in 0..nu {
                let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                obj += &format!("f {a} {b} {c}\nf {a} {c} {d}\n");
            }
        }
        let (run, info) = import_design("tube.obj", obj.as_bytes(), &ImportConfig::default())
            .expect("a cylinder is fitted, not refused");
        assert_eq!(info.import_as, "surface");
        // 168 vertices only, so a coarse net: within 1% of the 6.2 m diagonal (6 cm).
        assert!(info.fit_max_distance_m.unwrap() < 0.07, "{info:?}");
        assert!(matches!(run, Imported::Phex(..)));
    }

    #[test]
    fn quads_are_panels_and_triangles_a_surface_unless_told() {
        let cfg = ImportConfig {
            unit: Some("ft".into()),
            ..ImportConfig::default()
        };
        let (mut run, info) =
            import_design("grid.obj", grid_obj(6, false).as_bytes(), &cfg).unwrap();
        assert_eq!((info.import_as, info.unit), ("panels", "ft"));
        // 6 ft across: 1.8288 m.
        assert!((info.dimensions_m[0] - 6.0 * 0.3048).abs() < 1e-12);
        let (planarity, _) = run_to_end(&mut run);
        assert!(planarity <= 1e-9, "{planarity}");
        // The bumps are 1 mm in feet (0.3048 mm): the design moves by about that, not more.
        let Imported::Panels(stepper) = &run else {
            panic!("a panels run")
        };
        let [max, mean] = info.deviation_mm(stepper.mesh()).unwrap();
        assert!(
            max > 0.01 && max < 2.0 * 0.3048 && mean <= max,
            "{max} {mean}"
        );

        let (run, info) = import_design(
            "dome.obj",
            grid_obj(12, true).as_bytes(),
            &ImportConfig::default(),
        )
        .unwrap();
        assert_eq!((info.import_as, info.unit), ("surface", "m"));
        assert!(info.fit_max_distance_m.unwrap() < 0.01, "{info:?}");
        // The fit is timed apart from the read.
        let (read, fit) = (info.read_seconds, info.fit_seconds.unwrap());
        assert!(
            read >= 0.0 && fit >= 0.0 && (read + fit).is_finite(),
            "{info:?}"
        );
        assert!(matches!(run, Imported::Phex(..)));

        let as_panels = ImportConfig {
            import_as: Some("panels".into()),
            ..ImportConfig::default()
        };
        let (run, _) = import_design("dome.obj", grid_obj(4, true).as_bytes(), &as_panels).unwrap();
        assert!(matches!(run, Imported::Panels(..)));
    }

    #[test]
    fn a_nurbs_design_states_its_unit_and_errors_name_the_file() {
        let json = r#"{"degree_u": 1, "degree_v": 1, "knots_u": [0, 0, 1, 1],
            "knots_v": [0, 0, 1, 1], "unit": "mm",
            "control_points": [[[0, 0, 0], [0, 2000, 0]], [[3000, 0, 0], [3000, 2000, 500]]]}"#;
        let (_, info) =
            import_design("roof.json", json.as_bytes(), &ImportConfig::default()).unwrap();
        assert_eq!((info.import_as, info.unit), ("surface", "mm"));
        assert!(info.read_seconds >= 0.0 && info.fit_seconds.is_none());
        assert!(
            (info.dimensions_m[0] - 3.0).abs() < 1e-12
                && (info.dimensions_m[2] - 0.5).abs() < 1e-12
        );
        let e = refused("roof.json", b"{ \"degree_u\": }", &ImportConfig::default());
        assert!(e.starts_with("roof.json: not a NURBS surface"), "{e}");
        let e = refused("x.obj", b"v 0 0 0\nf 1 2 3\n", &ImportConfig::default());
        assert!(e.starts_with("x.obj: "), "{e}");
        let as_what = ImportConfig {
            import_as: Some("roof".into()),
            ..ImportConfig::default()
        };
        assert!(refused("a.obj", b"", &as_what).contains("use `surface` or `panels`"));
    }

    /// A control point of the translational roof dragged up 0.3 m in four pointer positions,
    /// each followed from the run before it (the run shown): every position ends with planar,
    /// simple hexagons (a new run on the last surface has self-intersecting ones), the drag is
    /// four moves, and a reload of them replays the panels bit for bit, whether the run shown
    /// had ended before the next move or not.
    #[test]
    fn a_dragged_roof_point_is_followed_to_planar_simple_panels() {
        use dupin_core::phex::count_invalid_faces;
        let roof = NurbsSurface::try_from(dupin_core::scenes::benchmark_meshes::nurbs_roof())
            .unwrap()
            .to_json();
        let mut source = NurbsSource {
            name: "roof.json".into(),
            bytes: roof.as_bytes().to_vec(),
            cfg: ImportConfig::default(),
        };
        let index = 6 * 9 + 4;
        let [x, y, z] = NurbsSurface::from_json(&roof).unwrap().control_points()[index];
        let (mut shown, _) = import_design("roof.json", roof.as_bytes(), &source.cfg).unwrap();
        for (k, dz) in [0.05, 0.1, 0.2, 0.3].into_iter().enumerate() {
            let Imported::Phex(current, _) = &mut shown else {
                panic!("a P-Hex run");
            };
            // The page waits for the end; an API caller may move on at once.
            if k % 2 == 0 {
                current.run_to_end().unwrap();
                assert_eq!(count_invalid_faces(&current.mesh()), 0, "position {k}");
                assert!(dupin_core::mesh::max_planarity(&current.mesh()) <= 1e-9);
            }
            (shown, _) = source
                .move_control_point(index, [x, y, z + dz], Some(current))
                .unwrap();
            let Imported::Phex(next, _) = &shown else {
                panic!("a P-Hex run");
            };
            assert_eq!(
                next.metrics().phase,
                dupin_core::phex::PhexPhase::Optimisation
            );
        }
        let Imported::Phex(mut dragged, _) = shown else {
            panic!("a P-Hex run");
        };
        dragged.run_to_end().unwrap();
        let mesh = dragged.mesh();
        assert_eq!(count_invalid_faces(&mesh), 0);
        assert!(dupin_core::mesh::max_planarity(&mesh) <= 1e-9);
        let moves = source.cfg.control_points.clone().unwrap();
        assert_eq!(moves.len(), 4);
        assert_eq!(moves[3], [index as f64, x, y, z + 0.3]);
        let replay = ImportConfig {
            control_points: Some(moves),
            ..ImportConfig::default()
        };
        let (again, _) = import_design("roof.json", roof.as_bytes(), &replay).unwrap();
        let Imported::Phex(mut again, _) = again else {
            panic!("a P-Hex run");
        };
        again.run_to_end().unwrap();
        assert_eq!(again.mesh(), mesh);
        // A new run on the reshaped roof, as before following.
        let mut reshaped = NurbsSurface::from_json(&roof).unwrap();
        reshaped
            .set_control_point(index, dupin_core::Vec3::new(x, y, z + 0.3))
            .unwrap();
        let mut fresh = PhexPipeline::new(PhexConfig::for_nurbs("roof", reshaped, None)).unwrap();
        fresh.run_to_end().unwrap();
        assert!(count_invalid_faces(&fresh.mesh()) > 0);
    }

    /// Moved control points reshape an opened NURBS surface and show in its control net; a
    /// drag (`NurbsSource::move_control_point`, a move per position) gives the run that opening
    /// with the same `controlPoints` gives, bit for bit; bad moves, too many moves and moves on
    /// a mesh are refused, naming the file, and leave the source as it was.
    #[test]
    fn moved_control_points_reshape_an_opened_surface() {
        let json = r#"{"degree_u": 2, "degree_v": 2, "knots_u": [0, 0, 0, 1, 1, 1],
            "knots_v": [0, 0, 0, 1, 1, 1],
            "control_points": [[[0, 0, 0], [0, 2, 0.5], [0, 4, 0]],
                               [[2, 0, 0.5], [2, 2, 1.5], [2, 4, 0.5]],
                               [[4, 0, 0], [4, 2, 0.5], [4, 4, 0]]]}"#;
        let mut source = NurbsSource {
            name: "dome.json".into(),
            bytes: json.as_bytes().to_vec(),
            cfg: ImportConfig::default(),
        };
        let (_, first) =
            import_design("dome.json", json.as_bytes(), &ImportConfig::default()).unwrap();
        let net = first.control_net.clone().unwrap();
        assert_eq!((net.nu, net.nv, net.points.len()), (3, 3, 27));
        assert_eq!(&net.points[12..15], &[2.0, 2.0, 1.5]);
        // A drag of the middle point in three moves, then a corner, each from the run before.
        let mut run = None;
        let mut info = None;
        for (i, p) in [(4, 1.7), (4, 1.9), (4, 2.5), (0, -0.5)] {
            let previous = match &mut run {
                Some(Imported::Phex(p, _)) => Some(p.as_mut()),
                _ => None,
            };
            let point = if i == 4 { [2.0, 2.0, p] } else { [0.0, 0.0, p] };
            let (r, d) = source.move_control_point(i, point, previous).unwrap();
            (run, info) = (Some(r), Some(d));
        }
        let (run, info) = (run.unwrap(), info.unwrap());
        assert_eq!(source.cfg.control_points.as_ref().unwrap().len(), 4);
        let net = info.control_net.unwrap();
        assert_eq!(&net.points[12..15], &[2.0, 2.0, 2.5]);
        assert_eq!(&net.points[0..3], &[0.0, 0.0, -0.5]);
        assert!(info.dimensions_m[2] > first.dimensions_m[2]);
        let replay = ImportConfig {
            control_points: Some(vec![
                [4.0, 2.0, 2.0, 1.7],
                [4.0, 2.0, 2.0, 1.9],
                [4.0, 2.0, 2.0, 2.5],
                [0.0, 0.0, 0.0, -0.5],
            ]),
            ..ImportConfig::default()
        };
        let (again, _) = import_design("dome.json", json.as_bytes(), &replay).unwrap();
        let (Imported::Phex(mut a, _), Imported::Phex(mut b, _)) = (run, again) else {
            panic!("a NURBS design is a surface")
        };
        a.run_to_end().unwrap();
        b.run_to_end().unwrap();
        assert_eq!(a.mesh(), b.mesh(), "the dragged net replays bit for bit");

        let kept = source.cfg.control_points.clone();
        let e = source.move_control_point(9, [0.0; 3], None).err().unwrap();
        assert_eq!(
            e,
            "dome.json: controlPoints: control point 9 is not in the 3 x 3 net"
        );
        let e = source
            .move_control_point(1, [f64::NAN, 0.0, 0.0], None)
            .err()
            .unwrap();
        assert!(e.contains("not finite"), "{e}");
        assert_eq!(source.cfg.control_points, kept);
        let fractional = ImportConfig {
            control_points: Some(vec![[1.5, 0.0, 0.0, 0.0]]),
            ..ImportConfig::default()
        };
        let e = refused("dome.json", json.as_bytes(), &fractional);
        assert!(e.contains("1.5 is not a control point index"), "{e}");
        let too_many = ImportConfig {
            control_points: Some(vec![[4.0, 2.0, 2.0, 1.5]; MAX_CONTROL_POINT_MOVES + 1]),
            ..ImportConfig::default()
        };
        let e = refused("dome.json", json.as_bytes(), &too_many);
        assert!(
            e.contains("1001 moves; a design replays at most 1000"),
            "{e}"
        );
        let mut full = NurbsSource {
            name: "dome.json".into(),
            bytes: json.as_bytes().to_vec(),
            cfg: ImportConfig {
                control_points: Some(vec![[4.0, 2.0, 2.0, 1.5]; MAX_CONTROL_POINT_MOVES]),
                ..ImportConfig::default()
            },
        };
        let e = full
            .move_control_point(4, [2.0, 2.0, 1.6], None)
            .err()
            .unwrap();
        assert!(e.contains("a design replays at most 1000"), "{e}");
        assert_eq!(
            full.cfg.control_points.unwrap().len(),
            MAX_CONTROL_POINT_MOVES
        );
        let e = refused("x.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", &replay);
        assert!(
            e.starts_with("x.obj: controlPoints are for a NURBS surface"),
            "{e}"
        );
    }

    #[test]
    fn the_free_mode_settings_reach_an_opened_surface() {
        let json = r#"{"degree_u": 1, "degree_v": 1, "knots_u": [0, 0, 1, 1],
            "knots_v": [0, 0, 1, 1],
            "control_points": [[[0, 0, 0], [0, 2, 0]], [[3, 0, 0], [3, 2, 0.5]]]}"#;
        let cfg = ImportConfig {
            init: Some("dupin-duality".into()),
            bound: Some(0.2),
            lambda: Some(0.5),
            mu: Some(7.0),
            ..ImportConfig::default()
        };
        let (run, _) = import_design("roof.json", json.as_bytes(), &cfg).unwrap();
        let Imported::Phex(p, _) = run else {
            panic!("a NURBS design is a surface")
        };
        let c = p.config();
        assert_eq!(
            c.initialisation,
            dupin_core::phex::Initialisation::DupinDuality
        );
        assert_eq!(c.rule, LayerRule::Ideal { bound: 0.2 });
        assert_eq!((c.lambda, c.mu), (0.5, 7.0));
        let bad = ImportConfig {
            init: Some("spiral".into()),
            ..ImportConfig::default()
        };
        assert!(import_design("roof.json", json.as_bytes(), &bad).is_err());
    }

    #[test]
    fn a_gltf_is_a_mesh_and_json_under_another_name_a_nurbs_surface() {
        let gltf = r#"{"asset": {"version": "2.0"}}"#;
        let e = refused("roof.gltf", gltf.as_bytes(), &ImportConfig::default());
        assert!(!e.contains("NURBS"), "{e}");
        let json = r#"{"degree_u": 1, "degree_v": 1, "knots_u": [0, 0, 1, 1],
            "knots_v": [0, 0, 1, 1],
            "control_points": [[[0, 0, 0], [0, 2, 0]], [[3, 0, 0], [3, 2, 0.5]]]}"#;
        let (_, info) =
            import_design("roof.3dm", json.as_bytes(), &ImportConfig::default()).unwrap();
        assert_eq!(info.import_as, "surface");
    }

    /// The issue's acceptance: an opened 10 000-quad panel mesh with 20 anchors ends with the
    /// anchors exactly where the file put them and max planarity <= 1e-10.
    #[test]
    fn twenty_anchors_of_ten_thousand_quads_stay_exactly() {
        let text = grid_obj(100, false);
        let anchors: Vec<usize> = (0..20).map(|k| (k * 509) % (101 * 101)).collect();
        let cfg = ImportConfig {
            anchors: Some(anchors.clone()),
            ..ImportConfig::default()
        };
        let (mut run, info) = import_design("grid.obj", text.as_bytes(), &cfg).unwrap();
        assert_eq!(info.anchors, anchors);
        let design = info.positions.clone().unwrap();
        let (planarity, _) = run_to_end(&mut run);
        assert!(planarity <= 1e-10, "{planarity}");
        let Imported::Panels(stepper) = &run else {
            panic!("a panels run")
        };
        let mesh = stepper.mesh();
        assert_eq!(mesh.num_faces(), 10_000);
        for &a in &anchors {
            assert_eq!(mesh.positions[a], design[a], "anchor {a} moved");
        }
        // Not a test that cannot fail: the other vertices did move.
        assert!(info.deviation_mm(mesh).unwrap()[0] > 0.0);

        let bad = ImportConfig {
            anchors: Some(vec![101 * 101]),
            ..ImportConfig::default()
        };
        let e = refused("grid.obj", text.as_bytes(), &bad);
        assert!(e.contains("anchor 10201 is not a vertex"), "{e}");
    }

    /// A tolerance in millimetres bounds every corner's distance from its panel's plane, in the
    /// file's unit; a negative closeness is refused.
    #[test]
    fn a_tolerance_in_mm_bounds_every_corner_and_bad_weights_are_refused() {
        let text = grid_obj(6, false);
        for (unit, mm) in [("m", 0.5), ("cm", 0.05)] {
            let cfg = ImportConfig {
                unit: Some(unit.into()),
                tolerance_mm: Some(mm),
                closeness: Some(5.0),
                ..ImportConfig::default()
            };
            let (mut run, _) = import_design("grid.obj", text.as_bytes(), &cfg).unwrap();
            run_to_end(&mut run);
            let Imported::Panels(stepper) = &run else {
                panic!("a panels run")
            };
            let mesh = stepper.mesh();
            let to_mm = unit.parse::<LengthUnit>().unwrap().to_mm();
            let worst = dupin_core::mesh::face_planarities(mesh)
                .iter()
                .zip(mesh.faces())
                .map(|(p, f)| {
                    let n = f.len();
                    let edge = (0..n)
                        .map(|i| {
                            (mesh.positions[f[(i + 1) % n] as usize]
                                - mesh.positions[f[i] as usize])
                                .norm()
                        })
                        .sum::<f64>()
                        / n as f64;
                    p * edge * to_mm
                })
                .fold(0.0f64, f64::max);
            assert!(worst <= mm, "{unit}: {worst} mm");
        }
        for bad in [0.0, -1.0, f64::NAN] {
            let cfg = ImportConfig {
                tolerance_mm: Some(bad),
                ..ImportConfig::default()
            };
            assert!(refused("grid.obj", text.as_bytes(), &cfg).contains("tolerance"));
        }
        let cfg = ImportConfig {
            closeness: Some(-1.0),
            ..ImportConfig::default()
        };
        assert!(refused("grid.obj", text.as_bytes(), &cfg).contains("closeness"));
    }
}
