//! The PQ scenes of the outside contract, after the conical paper's figures (Figs. 1, 7, 8, 9,
//! 14, 16, 17): each a control mesh or strip with its subdivision rule and perturbation options.

use crate::conical::{
    PqMode, PqOptions, PqSceneError, PqSceneResult, PqSceneSpec, PqSceneStepper, PqStrip,
    StripClosure, StripRule, principal_quad_mesh, trefoil_moebius,
};
use crate::mesh::PolyMesh;
use crate::surface::SurfaceOfRevolution;
use crate::{Stepper, Vec3};

/// Names of the PQ scenes of the outside contract, after the conical paper's figures.
pub const PQ_SCENES: &[&str] = &[
    "pq-catmull-clark",
    "conical-station",
    "developable-trefoil",
    "developable-strips",
    "circular-principal",
];

/// A roof of revolution (profile r = 2 + 0.4 cos(1.5 v), z = 1.2 sin v) for the station.
fn station_roof() -> SurfaceOfRevolution {
    SurfaceOfRevolution {
        profile: |v| {
            let (s, c) = (1.5 * v).sin_cos();
            [
                2.0 + 0.4 * c,
                -0.6 * s,
                -0.9 * c,
                1.2 * v.sin(),
                1.2 * v.cos(),
                -1.2 * v.sin(),
            ]
        },
        v_range: (-1.2, 1.2),
    }
}

/// The definition of the named PQ scene (see [`PQ_SCENES`]).
pub fn pq_scene_spec(name: &str) -> Result<PqSceneSpec, PqSceneError> {
    match name {
        "pq-catmull-clark" => {
            // Fig. 7: a coarse non-planar control mesh (dome with a twist), Catmull-Clark and
            // PQ perturbation alternating, two levels.
            let n = 4;
            let mut p = Vec::new();
            for j in 0..=n {
                for i in 0..=n {
                    let (x, y) = (i as f64 - 2.0, j as f64 - 2.0);
                    p.push(Vec3::new(
                        x,
                        y,
                        2.0 - 0.15 * (x * x + 0.5 * y * y) + 0.1 * x * y,
                    ));
                }
            }
            let control = PolyMesh::quad_grid(p, n, n).expect("valid grid");
            Ok(PqSceneSpec::Mesh {
                control,
                levels: 2,
                options: PqOptions::default(),
            })
        }
        "conical-station" => {
            // Figs. 1, 14: control mesh on principal lines of a roof of revolution, then
            // Catmull-Clark and conical perturbation alternating, two levels.
            let control = principal_quad_mesh(&station_roof(), (0.0, 2.4), (-1.2, 1.2), 6, 4);
            let options = PqOptions {
                mode: PqMode::Conical,
                ..PqOptions::default()
            };
            Ok(PqSceneSpec::Mesh {
                control,
                levels: 2,
                options,
            })
        }
        "circular-principal" => {
            // Fig. 17: a mesh from principal curves (here with a small seeded disturbance)
            // made circular.
            let mut m = principal_quad_mesh(
                &SurfaceOfRevolution::vase(),
                (0.0, 3.0),
                (-0.9, 0.9),
                16,
                12,
            );
            for (k, q) in m.positions.iter_mut().enumerate() {
                let s = (k as f64 * 12.9898).sin() * 43758.5453;
                let w = 0.004 * (s - s.floor() - 0.5);
                q.z += w;
            }
            let options = PqOptions {
                mode: PqMode::Circular,
                ..PqOptions::default()
            };
            Ok(PqSceneSpec::Mesh {
                control: m,
                levels: 0,
                options,
            })
        }
        "developable-trefoil" => {
            // Fig. 9: Möbius band along a trefoil knot, 42 control quads, 3 rounds of the
            // cubic Lane-Riesenfeld rule with PQ perturbation: 336 quads.
            Ok(PqSceneSpec::Strip {
                strip: trefoil_moebius(42, 0.35),
                rule: StripRule::LaneRiesenfeldCubic,
                rounds: 3,
                options: PqOptions::default(),
            })
        }
        "developable-strips" => {
            // Figs. 8, 16: an open control strip, 3 rounds of cubic Lane-Riesenfeld with PQ
            // perturbation.
            let n = 7;
            let a: Vec<Vec3> = (0..n)
                .map(|i| {
                    let t = i as f64;
                    Vec3::new(t, 0.6 * (0.8 * t).sin(), 0.0)
                })
                .collect();
            let b: Vec<Vec3> = (0..n)
                .map(|i| {
                    let t = i as f64;
                    Vec3::new(
                        t + 0.3 * (0.5 * t).cos(),
                        0.6 * (0.8 * t).sin() + 0.4,
                        2.0 + 0.3 * t,
                    )
                })
                .collect();
            Ok(PqSceneSpec::Strip {
                strip: PqStrip {
                    a,
                    b,
                    closure: StripClosure::Open,
                },
                rule: StripRule::LaneRiesenfeldCubic,
                rounds: 3,
                options: PqOptions::default(),
            })
        }
        other => Err(PqSceneError::UnknownScene(other.to_string())),
    }
}

/// The named PQ scene (see [`PQ_SCENES`]) at its control mesh, to be stepped.
pub fn pq_scene_stepper(name: &str) -> Result<PqSceneStepper, PqSceneError> {
    PqSceneStepper::from_spec(pq_scene_spec(name)?)
}

/// Builds the named PQ scene (see [`PQ_SCENES`]) in one go: its stepper run to the end.
pub fn pq_scene(name: &str) -> Result<PqSceneResult, PqSceneError> {
    pq_scene_stepper(name)?.finish()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_pq_scene_meets_the_contract_bounds() {
        for &name in PQ_SCENES {
            let r = pq_scene(name).unwrap();
            assert!(r.converged, "{name}");
            assert!(
                r.measures.max_planarity <= 1e-10,
                "{name}: {}",
                r.measures.max_planarity
            );
            if let Some(c) = r.measures.conical_residual {
                assert!(c <= 1e-10, "{name}: conical {c}");
            }
            if let Some(c) = r.measures.circular_residual {
                assert!(c <= 1e-10, "{name}: circular {c}");
            }
            if let Some(d) = r.measures.max_determinant {
                assert!(d <= 1e-10, "{name}: det {d}");
            }
        }
        assert!(matches!(
            pq_scene("nope"),
            Err(PqSceneError::UnknownScene(_))
        ));
    }
}
