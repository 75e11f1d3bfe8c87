//! `HexDelaunayLab`: the 2D tab's model over the core's [`HexDelaunayStepper`] (Sußner &
//! Greiner, "Hexagonal Delaunay Triangulation", sections 3 to 5).
//!
//! Input: points (and segments) the user places, and a mode. Output for drawing: the current
//! hexagon cells after each subdivision step, the dual triangulation, and its angle statistics
//! (min, max, a histogram in 2-degree bins) to compare with the paper's bounds (simple mode
//! [30, 120] degrees, extended [43.9, 90]; with segments (section 7) the bounds hold only for
//! triangles that do not meet a segment). Whatever the core refuses (crossing segments, bad
//! points) comes back as the core's error message.

use crate::js::err;
use dupin_core::hex_delaunay::{
    HexDelaunayMode, HexDelaunayStepper, angle_histogram, triangulation_quality,
};

use dupin_core::{Stepper, Vec2};
use serde::Serialize;
use wasm_bindgen::prelude::*;

/// Histogram bin width, degrees.
pub(crate) const BIN_DEG: f64 = 2.0;

/// Cells of the current hexagon subdivision, flattened for drawing.
#[derive(Serialize, Debug, Clone, Default)]
#[serde(rename_all = "camelCase")]
pub(crate) struct Cells {
    /// Corner coordinates, x y pairs, cell after cell.
    pub(crate) corners: Vec<f64>,
    /// Corner count of each cell (6 hexagon, 4 semi-hexagon).
    pub(crate) sizes: Vec<u32>,
    /// Whether each cell holds an input point.
    pub(crate) occupied: Vec<bool>,
    /// The bounding hexagon Ω.
    pub(crate) domain: Vec<f64>,
}

/// The dual triangulation of the current cells and its angles.
#[derive(Serialize, Debug, Clone, Default)]
#[serde(rename_all = "camelCase")]
pub(crate) struct Dual {
    pub(crate) vertices: Vec<f64>,
    pub(crate) triangles: Vec<u32>,
    pub(crate) min_angle: f64,
    pub(crate) max_angle: f64,
    /// Counts of interior angles per `BIN_DEG` bin over [0, 180).
    pub(crate) histogram: Vec<u32>,
    pub(crate) bin_deg: f64,
    pub(crate) delaunay_violations: usize,
}

/// The 2D triangulator state: user points and segments, mode, and the running stepper.
#[wasm_bindgen]
pub struct HexDelaunayLab {
    mode: HexDelaunayMode,
    stepper: Option<HexDelaunayStepper>,
}

impl HexDelaunayLab {
    pub(crate) fn with_mode(mode: &str) -> Result<Self, String> {
        Ok(HexDelaunayLab {
            mode: mode
                .parse()
                .map_err(|e: dupin_core::UnknownName| e.to_string())?,
            stepper: None,
        })
    }

    /// Restarts the refinement on `xy` (x y pairs) and `segments` (index pairs).
    pub(crate) fn set_input(&mut self, xy: &[f64], segments: &[u32]) -> Result<(), String> {
        self.stepper = None;
        if !xy.len().is_multiple_of(2) || !segments.len().is_multiple_of(2) {
            return Err("points and segments come in pairs of numbers".into());
        }
        let points: Vec<Vec2> = xy.chunks_exact(2).map(|c| Vec2::new(c[0], c[1])).collect();
        let segs: Vec<[usize; 2]> = segments
            .chunks_exact(2)
            .map(|c| [c[0] as usize, c[1] as usize])
            .collect();
        let s = HexDelaunayStepper::new(&points, &segs, self.mode).map_err(|e| e.to_string())?;
        self.stepper = Some(s);
        Ok(())
    }

    pub(crate) fn cells_data(&self) -> Cells {
        let Some(s) = &self.stepper else {
            return Cells::default();
        };
        let mut out = Cells {
            domain: s.domain().iter().flat_map(|p| [p.x, p.y]).collect(),
            ..Cells::default()
        };
        for c in s.cells() {
            out.sizes.push(c.corners.len() as u32);
            out.occupied.push(c.occupied);
            out.corners
                .extend(c.corners.iter().flat_map(|p| [p.x, p.y]));
        }
        out
    }

    pub(crate) fn dual_data(&self) -> Dual {
        let Some(s) = &self.stepper else {
            return Dual::default();
        };
        let t = s.triangulation();
        let q = triangulation_quality(&t.vertices, &t.triangles);
        let histogram = angle_histogram(&t.vertices, &t.triangles, BIN_DEG);
        Dual {
            vertices: t.vertices.iter().flat_map(|p| [p.x, p.y]).collect(),
            triangles: t.triangles.iter().flatten().copied().collect(),
            min_angle: if t.triangles.is_empty() {
                0.0
            } else {
                q.min_angle_deg
            },
            max_angle: q.max_angle_deg,
            histogram,
            bin_deg: BIN_DEG,
            delaunay_violations: q.delaunay_violations,
        }
    }
}

#[wasm_bindgen]
impl HexDelaunayLab {
    /// `new HexDelaunayLab(mode)`, mode `simple` or `extended`.
    #[wasm_bindgen(constructor)]
    pub fn new(mode: JsValue) -> Result<HexDelaunayLab, JsError> {
        let mode = crate::js::string_arg(&mode, "the mode")?;
        HexDelaunayLab::with_mode(&mode).map_err(err)
    }

    /// Replaces the input and restarts at the bounding hexagon: `xy` holds x y pairs, `segments`
    /// point-index pairs. Throws the core's message (bad points, crossing segments...).
    #[wasm_bindgen(js_name = setInput)]
    pub fn set_input_js(&mut self, xy: Vec<f64>, segments: Vec<u32>) -> Result<(), JsError> {
        self.set_input(&xy, &segments).map_err(err)
    }

    /// One subdivision step; false once refinement is finished (or there is no input).
    pub fn step(&mut self) -> Result<bool, JsError> {
        match &mut self.stepper {
            Some(s) => s.step().map(|m| m.changed).map_err(err),
            None => Ok(false),
        }
    }

    /// Whether refinement is finished.
    pub fn done(&self) -> bool {
        self.stepper.as_ref().is_none_or(|s| s.is_done())
    }

    /// Subdivision steps taken.
    pub fn steps(&self) -> usize {
        self.stepper.as_ref().map_or(0, |s| s.steps())
    }

    /// `{ corners, sizes, occupied, domain }` of the current hexagon cells.
    pub fn cells(&self) -> Result<JsValue, JsError> {
        serde_wasm_bindgen::to_value(&self.cells_data()).map_err(err)
    }

    /// `{ vertices, triangles, minAngle, maxAngle, histogram, binDeg, delaunayViolations }` of
    /// the dual triangulation of the current cells.
    pub fn dual(&self) -> Result<JsValue, JsError> {
        serde_wasm_bindgen::to_value(&self.dual_data()).map_err(err)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Section 4: once the simple refinement finishes, every angle is in [30, 120] degrees and
    /// the histogram counts every angle once.
    #[test]
    fn simple_mode_steps_to_the_paper_bounds() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let xy: Vec<f64> = (0..40).map(|_| rng.random_range(-1.0..1.0)).collect();
        let mut lab = HexDelaunayLab::with_mode("simple").unwrap();
        lab.set_input(&xy, &[]).unwrap();
        let mut steps = 0;
        let first = lab.cells_data().sizes.len();
        while !lab.stepper.as_ref().unwrap().is_done() {
            lab.stepper.as_mut().unwrap().step().unwrap();
            steps += 1;
            assert!(steps < 100_000);
        }
        assert!(steps > 1 && lab.cells_data().sizes.len() > first);
        let d = lab.dual_data();
        assert!(
            d.min_angle >= 30.0 - 1e-9 && d.max_angle <= 120.0 + 1e-9,
            "{d:?}"
        );
        let n: u32 = d.histogram.iter().sum();
        assert_eq!(n as usize, d.triangles.len());
        assert_eq!(d.delaunay_violations, 0);
        // Every input point is a vertex of the triangulation.
        for p in xy.chunks_exact(2) {
            assert!(d.vertices.chunks_exact(2).any(|v| v == p));
        }
    }

    #[test]
    fn refusals_carry_the_core_message() {
        let mut lab = HexDelaunayLab::with_mode("simple").unwrap();
        // Segments are triangulated (section 7); crossing ones are refused with the reason.
        lab.set_input(&[0.0, 0.0, 1.0, 0.0, 0.0, 1.0], &[0, 1])
            .unwrap();
        while lab.stepper.as_mut().unwrap().step().unwrap().changed {}
        assert!(
            !lab.stepper
                .as_ref()
                .unwrap()
                .triangulation()
                .segment_edges
                .is_empty()
        );
        let e = lab.set_input(&[0.0, 0.0, 1.0, 1.0, 0.0, 1.0, 1.0, 0.0], &[0, 1, 2, 3]);
        assert!(e.unwrap_err().contains("cross"));
        assert!(lab.set_input(&[0.0, f64::NAN], &[]).is_err());
        assert!(lab.set_input(&[0.0], &[]).is_err());
        assert!(lab.set_input(&[], &[]).is_err());
        assert!(HexDelaunayLab::with_mode("fancy").is_err());
        let mut ext = HexDelaunayLab::with_mode("extended").unwrap();
        ext.set_input(&[0.0, 0.0, 1.0, 0.2], &[]).unwrap();
        while ext.stepper.as_mut().unwrap().step().unwrap().changed {}
        let d = ext.dual_data();
        assert!(d.min_angle >= 43.89 && d.max_angle <= 90.0001, "{d:?}");
    }
}
