//! The P-Hex scenes of the contract, after the P-Hex paper's figures (Figs. 1, 11, 15, 18, 19,
//! 20, 22 and section 3), as triangulation settings on library surfaces.

use super::PhexError;
use super::pipeline::PhexConfig;
use super::triangulation::{LayerRule, TriangulationMethod};
use crate::{Domain, Surface, SurfaceDerivatives};
use std::f64::consts::{PI, TAU};

/// Every P-Hex scene name (what `dupin phex --list-scenes` prints).
pub const PHEX_SCENES: &[&str] = &[
    "cyclide-architecture",
    "sphere-radial",
    "sphere-diverging",
    "sphere-spiral",
    "hyperboloid-invalid",
    "hyperboloid-valid",
    "cyclide-progressive",
    "cyclide-prescribed",
    "vase-bottom-up",
    "vase-longitudinal",
    "torus-no-bound",
    "torus-bound",
    "minimal-surface",
    "freeform-parabolic",
    "cylinder-developable",
];

/// A scene: the configuration of a pipeline run plus whether it is expected to satisfy the
/// acceptance thresholds (the paper's failure examples are not).
#[derive(Debug, Clone, PartialEq)]
pub struct PhexScene {
    /// Scene name.
    pub name: &'static str,
    /// The run configuration.
    pub config: PhexConfig,
    /// False for the scenes that show the paper's failures (`hyperboloid-invalid`,
    /// `torus-no-bound`).
    pub expect_valid: bool,
}

/// The section 5.3 lower bound b used by the scenes.
pub const DEFAULT_BOUND: f64 = 0.3;

fn cfg(
    surface: &str,
    params: &[(&str, f64)],
    method: TriangulationMethod,
    rule: LayerRule,
    swap: bool,
    across: (f64, f64),
    along: Option<(f64, f64)>,
    size: f64,
) -> PhexConfig {
    PhexConfig {
        surface: surface.to_string(),
        params: params.iter().map(|(k, v)| (k.to_string(), *v)).collect(),
        twist: 0.0,
        method,
        rule,
        swap,
        across: Some(across),
        along,
        size: Some(size),
        iterations: 10,
        optimize: true,
    }
}

/// Builds the named scene.
///
/// Errors: [`PhexError::UnknownScene`] with the list of names.
pub fn phex_scene(name: &str) -> Result<PhexScene, PhexError> {
    use LayerRule::*;
    use TriangulationMethod::*;
    let ideal = Ideal {
        bound: DEFAULT_BOUND,
    };
    let (config, expect_valid) = match name {
        "cyclide-architecture" => (
            cfg("dupin-cyclide", &[], Prescribed, ideal, false, (-1.2, 1.2), None, 0.12),
            true,
        ),
        "sphere-radial" => (
            cfg("sphere", &[], Progressive, ideal, false, (0.0, 1.2), None, 0.1),
            true,
        ),
        "sphere-diverging" => (
            cfg("sphere", &[], Progressive, ideal, false, (1.1, -0.9), None, 0.08),
            true,
        ),
        "sphere-spiral" => {
            let mut c = cfg("sphere", &[], Prescribed, ideal, false, (-1.1, 1.1), None, 0.1);
            c.twist = 1.0;
            (c, true)
        }
        "hyperboloid-invalid" => (
            cfg("hyperboloid", &[], Prescribed, Fixed(0.12), false, (-1.0, 1.0), None, 0.15),
            false,
        ),
        "hyperboloid-valid" => (
            cfg("hyperboloid", &[], Prescribed, ideal, false, (-1.0, 1.0), None, 0.15),
            true,
        ),
        "cyclide-progressive" => (
            cfg("dupin-cyclide", &[], Progressive, ideal, false, (-1.0, 1.0), None, 0.12),
            true,
        ),
        "cyclide-prescribed" => (
            cfg("dupin-cyclide", &[], Prescribed, ideal, false, (0.0, TAU), None, 0.12),
            true,
        ),
        "vase-bottom-up" => (
            cfg("vase", &[], Prescribed, ideal, false, (0.0, 3.0), None, 0.12),
            true,
        ),
        "vase-longitudinal" => (
            cfg("vase", &[], Prescribed, ideal, true, (0.0, TAU), Some((0.0, 3.0)), 0.12),
            true,
        ),
        "torus-no-bound" => (
            cfg("torus", &[], Prescribed, Ideal { bound: 0.0 }, false, (0.0, PI), None, 0.15),
            false,
        ),
        "torus-bound" => (
            cfg("torus", &[], Prescribed, ideal, false, (0.0, TAU), None, 0.15),
            true,
        ),
        "minimal-surface" => (
            cfg("enneper", &[], Prescribed, ideal, false, (-1.0, 1.0), Some((-1.0, 1.0)), 0.08),
            true,
        ),
        "freeform-parabolic" => (
            cfg("bspline", &[], Prescribed, ideal, false, (0.0, 5.0), Some((0.0, 5.0)), 0.15),
            true,
        ),
        "cylinder-developable" => (
            cfg("cylinder", &[], Prescribed, Fixed(0.866), false, (0.0, 2.0), None, 0.12),
            true,
        ),
        _ => {
            return Err(PhexError::UnknownScene {
                name: name.to_string(),
                known: PHEX_SCENES.join(", "),
            });
        }
    };
    let name = PHEX_SCENES.iter().find(|n| **n == name).copied().unwrap_or("");
    Ok(PhexScene {
        name,
        config,
        expect_valid,
    })
}

/// A surface re-parametrised as P(u + twist v, v): its v-lines become spirals (used for the
/// spiral sphere pattern of Fig. 20).
pub struct TwistedSurface {
    /// The original surface.
    pub inner: Box<dyn Surface>,
    /// Shear factor.
    pub twist: f64,
}

impl Surface for TwistedSurface {
    fn domain(&self) -> Domain {
        self.inner.domain()
    }

    fn derivatives(&self, u: f64, v: f64) -> SurfaceDerivatives {
        let t = self.twist;
        let d = self.inner.derivatives(u + t * v, v);
        SurfaceDerivatives {
            p: d.p,
            pu: d.pu,
            pv: d.pu * t + d.pv,
            puu: d.puu,
            puv: d.puu * t + d.puv,
            pvv: d.puu * (t * t) + d.puv * (2.0 * t) + d.pvv,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::phex_run;

    fn run(name: &str) -> crate::PhexResult {
        let scene = phex_scene(name).unwrap();
        phex_run(scene.config).unwrap_or_else(|e| panic!("{name}: {e}"))
    }

    #[test]
    fn print_all_scenes() {
        for name in PHEX_SCENES {
            let scene = phex_scene(name).unwrap();
            match phex_run(scene.config) {
                Ok(r) => {
                    let rep = &r.report;
                    let k_pos_nonconvex = rep
                        .per_face
                        .iter()
                        .filter(|f| f.gaussian > 1e-3 && !f.convex)
                        .count();
                    let k_neg_convex = rep
                        .per_face
                        .iter()
                        .filter(|f| f.gaussian < -1e-3 && f.convex)
                        .count();
                    eprintln!(
                        "{name}: faces {} sizes {:?} planarity {:.2e} invalid {} iters {} dist/diag {:.2e} minedge {:.2e} K+nonconvex {} K-convex {} layers {}",
                        rep.faces,
                        rep.face_sizes,
                        rep.max_planarity,
                        rep.invalid_faces,
                        rep.iterations,
                        rep.max_surface_distance / rep.bbox_diagonal,
                        rep.min_edge_ratio,
                        k_pos_nonconvex,
                        k_neg_convex,
                        r.triangulation.layers.len()
                    );
                }
                Err(e) => eprintln!("{name}: ERROR {e}"),
            }
        }
        let _ = run;
    }
}
