//! `Session.fromFile(name, bytes, config)`: a design opened in the page (file input or drop). A
//! NURBS surface (JSON) or a triangle mesh of a smooth surface becomes a surface the P-Hex
//! pipeline panels; a mesh of quads, hexagons or any polygons becomes panels that the PQ
//! perturbation makes planar (planar, conical or circular), keeping the design. The file never
//! leaves the page: the bytes come from the browser and stay in the worker.

use crate::js::err;
use crate::session::Run;
use dupin_core::conical::{MeshRule, PqMode, PqOptions, PqSceneStepper};
use dupin_core::fabrication::LengthUnit;
use dupin_core::mesh::PolyMesh;
use dupin_core::mesh::io::{ImportOptions, read_mesh};
use dupin_core::phex::{PhexConfig, PhexGoals, PhexPipeline, TriangulationMethod};
use dupin_core::surface::{MeshFitOptions, NurbsSurface, Surface, fit_mesh_surface};
use serde::{Deserialize, Serialize};
use wasm_bindgen::prelude::*;

/// The options of `Session.fromFile`: `{ importAs, unit, size, method, mode, fixBoundary }`, all
/// optional.
#[derive(Deserialize, Default)]
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
    /// Panels: `planar` (default), `conical` or `circular`.
    mode: Option<String>,
    /// Panels: keep the boundary vertices where they are.
    fix_boundary: Option<bool>,
}

/// The keys of [`ImportConfig`] as JS spells them, for the unknown-key check.
pub(crate) const IMPORT_CONFIG_KEYS: &[&str] =
    &["importAs", "unit", "size", "method", "mode", "fixBoundary"];

/// The page's largest panel factorisation (1 GB: a browser tab must survive it).
const PAGE_MAX_FACTOR_BYTES: usize = 1 << 30;

/// What the page shows about an opened design: its name, how it is read, its unit and its
/// overall dimensions in metres; for a fitted mesh, the fit's largest distance in metres.
#[derive(Serialize, Clone, Debug)]
#[serde(rename_all = "camelCase")]
pub(crate) struct DesignInfo {
    name: String,
    import_as: &'static str,
    unit: &'static str,
    dimensions_m: [f64; 3],
    #[serde(skip_serializing_if = "Option::is_none")]
    fit_max_distance_m: Option<f64>,
}

/// The run and design information of an opened file. Errors name the file.
pub(crate) fn import_run(
    name: &str,
    bytes: &[u8],
    config: JsValue,
) -> Result<(Run, DesignInfo), JsError> {
    crate::session::refuse_unknown_keys(&config, "import config", IMPORT_CONFIG_KEYS)?;
    let cfg: ImportConfig = if config.is_undefined() || config.is_null() {
        ImportConfig::default()
    } else {
        serde_wasm_bindgen::from_value(config)
            .map_err(|e| JsError::new(&format!("bad import config: {e}")))?
    };
    let named = |e: &dyn std::fmt::Display| JsError::new(&format!("{name}: {e}"));
    let wanted = match cfg.import_as.as_deref() {
        None => None,
        Some("surface") => Some(true),
        Some("panels") => Some(false),
        Some(other) => {
            return Err(JsError::new(&format!(
                "importAs `{other}`: use `surface` or `panels`"
            )));
        }
    };
    let mut unit: Option<LengthUnit> = match cfg.unit.as_deref() {
        Some(u) => Some(u.parse().map_err(err)?),
        None => None,
    };
    let is_json = name.to_ascii_lowercase().ends_with(".json")
        || bytes
            .iter()
            .find(|b| !b.is_ascii_whitespace())
            .is_some_and(|&b| b == b'{');
    let (surface, mesh, fit_distance) = if is_json {
        if wanted == Some(false) {
            return Err(named(
                &"a NURBS surface is panelled as a surface, not planarised",
            ));
        }
        let text = std::str::from_utf8(bytes).map_err(|e| named(&e))?;
        let s = NurbsSurface::from_json(text).map_err(|e| named(&e))?;
        unit = unit.or(s.unit());
        (Some(s), None, None)
    } else {
        let mesh = read_mesh(name, bytes, &ImportOptions::default())
            .map_err(|e| named(&e))?
            .mesh;
        let triangles = mesh.faces().all(|f| f.len() == 3);
        if wanted.unwrap_or(triangles) {
            let fit = fit_mesh_surface(&mesh, &MeshFitOptions::default()).map_err(|e| named(&e))?;
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
    let info = DesignInfo {
        name: name.to_string(),
        import_as: if surface.is_some() {
            "surface"
        } else {
            "panels"
        },
        unit: unit.name(),
        dimensions_m: extent.map(|e| e * unit.to_m()),
        fit_max_distance_m: fit_distance.map(|d| d * unit.to_m()),
    };
    let run = match (surface, mesh) {
        (Some(surface), _) => {
            let mut config = PhexConfig::for_nurbs(name, surface, cfg.size);
            if let Some(m) = &cfg.method {
                config.method = m.parse::<TriangulationMethod>().map_err(err)?;
            }
            let goals = PhexGoals::of(&config, true);
            Run::Phex(Box::new(PhexPipeline::new(config).map_err(err)?), goals)
        }
        (None, Some(mesh)) => panels_run(&mesh, &cfg)?,
        (None, None) => unreachable!("a file gives a surface or a mesh"),
    };
    Ok((run, info))
}

/// The planarisation of an opened panel mesh, stepped like a PQ scene with no subdivision: the
/// design kept (fairness on the move, `keep_design`), as `dupin planarize` does.
fn panels_run(mesh: &PolyMesh, cfg: &ImportConfig) -> Result<Run, JsError> {
    let mode: PqMode = cfg
        .mode
        .as_deref()
        .unwrap_or("planar")
        .parse()
        .map_err(err)?;
    let options = PqOptions {
        mode,
        keep_design: true,
        fix_boundary: cfg.fix_boundary.unwrap_or(false),
        max_factor_bytes: PAGE_MAX_FACTOR_BYTES,
        ..PqOptions::default()
    };
    let stepper =
        PqSceneStepper::for_mesh(mesh, MeshRule::CatmullClark, 0, options).map_err(err)?;
    Ok(Run::Pq {
        stepper: Box::new(stepper),
        started: false,
    })
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
