//! `pageSchema()`: the names, defaults and bounds the page shows, read from the core so the
//! page never types them again.

use crate::import::MAX_CONTROL_POINT_MOVES;
use crate::js::to_js;
use crate::session::{DEFAULT_OFFSET, INITIALISATIONS, METHODS};
use dupin_core::hex_delaunay::HexDelaunayMode;
use dupin_core::mesh::ColorMode;
use dupin_core::surface::surface_catalog;
use serde::Serialize;
use wasm_bindgen::prelude::*;

/// A named choice: its name (what the API takes) and its label for people.
#[derive(Serialize, Debug, PartialEq)]
pub(crate) struct Choice {
    name: &'static str,
    label: &'static str,
}

fn choices<T>(table: &[(&'static str, &'static str, T)]) -> Vec<Choice> {
    table
        .iter()
        .map(|&(name, label, _)| Choice { name, label })
        .collect()
}

/// A parameter of the torus preview: its key and default.
#[derive(Serialize, Debug, PartialEq)]
pub(crate) struct TorusParam {
    key: &'static str,
    default: f64,
}

/// A 2D triangulator mode and the angle bounds (degrees) it guarantees.
#[derive(Serialize, Debug, PartialEq)]
#[serde(rename_all = "camelCase")]
pub(crate) struct HexdMode {
    name: &'static str,
    angle_bounds: [f64; 2],
}

/// What [`page_schema`] returns.
#[derive(Serialize, Debug, PartialEq)]
#[serde(rename_all = "camelCase")]
pub(crate) struct PageSchema {
    /// Colour modes of the panels, the default first.
    color_modes: Vec<&'static str>,
    /// Free-mode triangulation methods, the default first.
    methods: Vec<Choice>,
    /// Free-mode hexagon initialisations, the default first.
    initialisations: Vec<Choice>,
    /// Face distance of the offset layer when none is given.
    offset_distance: f64,
    /// The torus preview's parameters (the library torus's), in order.
    torus: Vec<TorusParam>,
    /// The 2D triangulator's modes, the default first.
    hex_delaunay_modes: Vec<HexdMode>,
    /// The most control-point moves an opened NURBS design replays (`controlPoints`).
    max_control_point_moves: usize,
}

pub(crate) fn schema() -> PageSchema {
    let torus = surface_catalog()
        .iter()
        .find(|s| s.name == "torus")
        .map(|s| {
            s.params
                .iter()
                .map(|p| TorusParam {
                    key: p.key,
                    default: p.default,
                })
                .collect()
        })
        .unwrap_or_default();
    PageSchema {
        color_modes: ColorMode::ALL.iter().map(|m| m.name()).collect(),
        methods: choices(&METHODS),
        initialisations: choices(&INITIALISATIONS),
        offset_distance: DEFAULT_OFFSET,
        torus,
        hex_delaunay_modes: HexDelaunayMode::ALL
            .iter()
            .map(|m| HexdMode {
                name: m.name(),
                angle_bounds: m.angle_bounds_deg(),
            })
            .collect(),
        max_control_point_moves: MAX_CONTROL_POINT_MOVES,
    }
}

/// The page's names, defaults and bounds: `{ colorModes, methods: [{ name, label }],
/// initialisations: [{ name, label }], offsetDistance, torus: [{ key, default }],
/// hexDelaunayModes: [{ name, angleBounds: [min, max] }], maxControlPointMoves }` (lists start
/// with the default).
#[wasm_bindgen(js_name = pageSchema)]
pub fn page_schema() -> Result<JsValue, JsError> {
    to_js(&schema())
}

#[cfg(test)]
mod tests {
    use super::*;
    use dupin_core::conical::DEFAULT_OFFSET_DISTANCE;
    use dupin_core::phex::{Initialisation, TriangulationMethod};

    /// Every value of the schema is the core's: the page reads nothing it could get wrong.
    #[test]
    fn schema_values_are_the_core_constants() {
        let s = schema();
        assert_eq!(s.color_modes, ["planarity", "convexity", "regularity"]);
        for (name, mode) in s.color_modes.iter().zip(ColorMode::ALL) {
            assert_eq!(ColorMode::parse(name), Ok(mode));
        }
        assert_eq!(s.offset_distance, DEFAULT_OFFSET_DISTANCE);
        assert_eq!(s.offset_distance, 0.15);
        assert_eq!(s.max_control_point_moves, 1000);
        let names = |c: &[Choice]| c.iter().map(|c| c.name).collect::<Vec<_>>();
        assert_eq!(names(&s.methods), ["progressive", "prescribed"]);
        assert_eq!(METHODS[0].2, TriangulationMethod::Progressive);
        // The page's names are the core's, which parse them.
        assert!(METHODS.iter().all(|&(name, _, m)| name == m.name()));
        assert!(INITIALISATIONS.iter().all(|&(name, _, i)| name == i.name()));
        assert_eq!(
            names(&s.initialisations),
            ["tangent-duality", "dupin-duality"]
        );
        assert_eq!(INITIALISATIONS[0].2, Initialisation::TangentDuality);
        // The default initialisation and method are the core's.
        assert_eq!(INITIALISATIONS[0].2, Initialisation::default());
        assert_eq!(
            s.torus,
            [
                TorusParam {
                    key: "R",
                    default: 2.0
                },
                TorusParam {
                    key: "r",
                    default: 0.7
                }
            ]
        );
        assert_eq!(s.hex_delaunay_modes.len(), HexDelaunayMode::ALL.len());
        for (m, core) in s.hex_delaunay_modes.iter().zip(HexDelaunayMode::ALL) {
            assert_eq!(
                (m.name, m.angle_bounds),
                (core.name(), core.angle_bounds_deg())
            );
        }
        assert_eq!(s.hex_delaunay_modes[0].name, "simple");
        assert_eq!(s.hex_delaunay_modes[0].angle_bounds, [30.0, 120.0]);
        assert_eq!(s.hex_delaunay_modes[1].name, "extended");
        assert_eq!(s.hex_delaunay_modes[1].angle_bounds, [43.9, 90.0]);
    }
}
