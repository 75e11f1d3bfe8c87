//! Input meshes and the PQ scenes of the outside contract (conical paper figures), plus the
//! benchmark meshes of the issue: a skew quad grid on z = xy and the centroid dual of a regular
//! torus triangulation.

use crate::math::Vec3;
use crate::mesh::PolyMesh;
use crate::surface::{Surface, Torus};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A quad grid of `n x n` quads over \[-1, 1\]², rotated by `rotation_deg` about the z axis
/// and lifted to the saddle z = xy. The grid lines are neither principal nor asymptotic
/// directions of the surface, so the quads are far from planar.
pub fn skew_quad_grid(n: usize, rotation_deg: f64) -> PolyMesh {
    let n = n.max(1);
    let (s, c) = rotation_deg.to_radians().sin_cos();
    let mut p = Vec::with_capacity((n + 1) * (n + 1));
    for j in 0..=n {
        for i in 0..=n {
            let a = -1.0 + 2.0 * i as f64 / n as f64;
            let b = -1.0 + 2.0 * j as f64 / n as f64;
            let (x, y) = (c * a - s * b, s * a + c * b);
            p.push(Vec3::new(x, y, x * y));
        }
    }
    let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    let faces: Vec<[u32; 4]> = (0..n)
        .flat_map(|j| (0..n).map(move |i| [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]))
        .collect();
    PolyMesh::new(p, faces).expect("grid indices are valid")
}

/// The `nu x nv` quad mesh of a torus's parameter lines (R = `major`, r = `minor`; its
/// principal curvature lines, so the quads are planar up to O(h^2)): vertex `i * nv + j` at
/// (u, v) = 2π (i / nu, j / nv), quads oriented along the outward normal.
pub fn torus_quad_mesh(nu: usize, nv: usize, major: f64, minor: f64) -> PolyMesh {
    let (nu, nv) = (nu.max(3), nv.max(3));
    let torus = Torus { major, minor };
    let (du, dv) = (
        std::f64::consts::TAU / nu as f64,
        std::f64::consts::TAU / nv as f64,
    );
    let p: Vec<Vec3> = (0..nu)
        .flat_map(|i| (0..nv).map(move |j| (i, j)))
        .map(|(i, j)| torus.position(i as f64 * du, j as f64 * dv))
        .collect();
    let faces: Vec<[u32; 4]> = (0..nu)
        .flat_map(|i| {
            (0..nv).map(move |j| {
                let (i1, j1) = ((i + 1) % nu, (j + 1) % nv);
                [i * nv + j, i1 * nv + j, i1 * nv + j1, i * nv + j1].map(|k| k as u32)
            })
        })
        .collect();
    PolyMesh::new(p, faces).expect("grid indices are valid")
}

/// The principal `n x n` quad mesh of the vase (its profile over (0, 6), angles (-0.9, 0.9))
/// with seeded noise of 2% of the grid spacing on every coordinate: a conical start far from
/// conical, the PQ benchmarks' harder case.
pub fn noisy_vase(n: usize) -> PolyMesh {
    let mut m = principal_quad_mesh(&SurfaceOfRevolution::vase(), (0.0, 6.0), (-0.9, 0.9), n, n);
    let h = 6.0 / n as f64;
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    for p in &mut m.positions {
        for k in 0..3 {
            p[k] += 0.02 * h * (rng.random::<f64>() * 2.0 - 1.0);
        }
    }
    m
}

/// The centroid dual of the regular triangulation of a torus (R = `major`, r = `minor`) with
/// `nu x nv` vertices (each parameter quad split along the same diagonal, all valences 6):
/// one vertex per triangle at its centroid, one hexagon per torus vertex. `nu * nv` hexagons,
/// oriented along the outward normal.
pub fn torus_centroid_dual(nu: usize, nv: usize, major: f64, minor: f64) -> PolyMesh {
    let (nu, nv) = (nu.max(3), nv.max(3));
    let torus = Torus { major, minor };
    let du = std::f64::consts::TAU / nu as f64;
    let dv = std::f64::consts::TAU / nv as f64;
    let vert = |i: usize, j: usize| torus.position((i % nu) as f64 * du, (j % nv) as f64 * dv);
    // Triangle (i, j, 0) = (i,j),(i+1,j),(i+1,j+1); (i, j, 1) = (i,j),(i+1,j+1),(i,j+1).
    let mut p = Vec::with_capacity(2 * nu * nv);
    for j in 0..nv {
        for i in 0..nu {
            p.push((vert(i, j) + vert(i + 1, j) + vert(i + 1, j + 1)) / 3.0);
            p.push((vert(i, j) + vert(i + 1, j + 1) + vert(i, j + 1)) / 3.0);
        }
    }
    let tri = |i: usize, j: usize, k: usize| (2 * ((j % nv) * nu + (i % nu)) + k) as u32;
    let mut faces = Vec::with_capacity(nu * nv);
    for j in 0..nv {
        for i in 0..nu {
            let (im, jm) = (i + nu - 1, j + nv - 1);
            faces.push([
                tri(i, j, 0),
                tri(i, j, 1),
                tri(im, j, 0),
                tri(im, jm, 1),
                tri(im, jm, 0),
                tri(i, jm, 1),
            ]);
        }
    }
    PolyMesh::new(p, faces).expect("dual indices are valid")
}

use crate::circular::circular_residual;
use crate::conical::conical_residual;
use crate::developable_strip::{
    PqStrip, StripClosure, StripRule, developable_subdivision, trefoil_moebius,
};
use crate::mesh_topology::{MeshTopology, TopologyError};
use crate::planarity::max_planarity;
use crate::pq_perturbation::{PqError, PqMode, PqOptions, pq_perturb};
use crate::principal_quad_mesh::{SurfaceOfRevolution, principal_quad_mesh};
use crate::subdivision::catmull_clark;
use thiserror::Error;

/// Names of the PQ scenes of the outside contract, after the conical paper's figures.
pub const PQ_SCENES: &[&str] = &[
    "pq-catmull-clark",
    "conical-station",
    "developable-trefoil",
    "developable-strips",
    "circular-principal",
];

/// Why a PQ scene could not be built.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum PqSceneError {
    /// No scene has this name.
    #[error("unknown PQ scene `{0}` (see --list-scenes)")]
    UnknownScene(String),
    /// The perturbation rejected a mesh of the scene.
    #[error(transparent)]
    Pq(#[from] PqError),
    /// Subdivision met a non-manifold mesh.
    #[error(transparent)]
    Topology(#[from] TopologyError),
}

/// The final mesh of a PQ scene and its measures.
#[derive(Debug, Clone, PartialEq)]
pub struct PqSceneResult {
    /// The final mesh.
    pub mesh: PolyMesh,
    /// Subdivision levels applied.
    pub levels: usize,
    /// Perturbation iterations over all levels.
    pub iterations: usize,
    /// Whether every perturbation converged.
    pub converged: bool,
    /// Contract `max_planarity`.
    pub max_planarity: f64,
    /// `conical_residual` (conical scenes).
    pub conical_residual: Option<f64>,
    /// `circular_residual` (circular scenes).
    pub circular_residual: Option<f64>,
    /// Largest determinant term (developable scenes).
    pub max_determinant: Option<f64>,
    /// Number of quads whose singular-curve point lies on the strip (developable scenes).
    pub singular_points_inside: Option<usize>,
}

/// Subdivide with `rule` and perturb with `options`, `levels` times, after perturbing the
/// control mesh itself.
fn subdivide_and_perturb(
    control: &PolyMesh,
    levels: usize,
    options: &PqOptions,
) -> Result<PqSceneResult, PqSceneError> {
    let mut r = pq_perturb(control, options.clone())?;
    let mut iterations = r.iterations;
    let mut converged = r.converged;
    for _ in 0..levels {
        let fine = catmull_clark(&r.mesh)?;
        r = pq_perturb(&fine, options.clone())?;
        iterations += r.iterations;
        converged &= r.converged;
    }
    let topo = MeshTopology::new(&r.mesh)?;
    Ok(PqSceneResult {
        max_planarity: max_planarity(&r.mesh),
        conical_residual: (options.mode == PqMode::Conical)
            .then(|| conical_residual(&r.mesh, &topo)),
        circular_residual: (options.mode == PqMode::Circular).then(|| circular_residual(&r.mesh)),
        mesh: r.mesh,
        levels,
        iterations,
        converged,
        max_determinant: None,
        singular_points_inside: None,
    })
}

fn strip_result(levels: Vec<PqStrip>, iterations: usize, converged: bool) -> PqSceneResult {
    let last = levels.last().expect("at least the control level");
    let mesh = last.to_mesh();
    let inside = singular_points_inside(last);
    PqSceneResult {
        max_planarity: max_planarity(&mesh),
        conical_residual: None,
        circular_residual: None,
        max_determinant: Some(last.max_determinant()),
        singular_points_inside: Some(inside),
        mesh,
        levels: levels.len() - 1,
        iterations,
        converged,
    }
}

/// Number of quads of `strip` whose singular-curve point lies on the strip (ruling parameter
/// in \[0, 1\]).
pub(crate) fn singular_points_inside(strip: &PqStrip) -> usize {
    strip
        .singular_curve()
        .iter()
        .filter(|p| matches!(p, Some((_, t)) if (0.0..=1.0).contains(t)))
        .count()
}

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

/// What a PQ scene is made of: a control mesh refined by a surface subdivision rule, or a
/// control strip refined by a curve rule, with the perturbation options of every level.
#[derive(Debug, Clone)]
pub(crate) enum SceneSpec {
    /// Subdivide with Catmull-Clark and perturb, `levels` times, after perturbing `control`.
    Mesh {
        control: PolyMesh,
        levels: usize,
        options: PqOptions,
    },
    /// Developable subdivision of `strip` with `rule`, `rounds` times.
    Strip {
        strip: PqStrip,
        rule: StripRule,
        rounds: usize,
        options: PqOptions,
    },
}

/// The definition of the named PQ scene (see [`PQ_SCENES`]).
pub(crate) fn scene_spec(name: &str) -> Result<SceneSpec, PqSceneError> {
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
            let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
            let faces: Vec<[u32; 4]> = (0..n)
                .flat_map(|j| {
                    (0..n).map(move |i| [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)])
                })
                .collect();
            let control = PolyMesh::new(p, faces).expect("valid grid");
            Ok(SceneSpec::Mesh {
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
            Ok(SceneSpec::Mesh {
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
            Ok(SceneSpec::Mesh {
                control: m,
                levels: 0,
                options,
            })
        }
        "developable-trefoil" => {
            // Fig. 9: Möbius band along a trefoil knot, 42 control quads, 3 rounds of the
            // cubic Lane-Riesenfeld rule with PQ perturbation: 336 quads.
            Ok(SceneSpec::Strip {
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
            Ok(SceneSpec::Strip {
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

/// Builds the named PQ scene (see [`PQ_SCENES`]) in one go. [`crate::PqSceneStepper`] runs the
/// same scene one observable step at a time and ends at the same result.
pub fn pq_scene(name: &str) -> Result<PqSceneResult, PqSceneError> {
    match scene_spec(name)? {
        SceneSpec::Mesh {
            control,
            levels,
            options,
        } => subdivide_and_perturb(&control, levels, &options),
        SceneSpec::Strip {
            strip,
            rule,
            rounds,
            options,
        } => {
            let (levels, it, ok) = developable_subdivision(&strip, rule, rounds, &options)?;
            Ok(strip_result(levels, it, ok))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn torus_quad_mesh_is_closed_and_faces_outward() {
        let m = torus_quad_mesh(12, 8, 2.0, 0.7);
        assert_eq!((m.num_vertices(), m.num_faces()), (96, 96));
        let topo = MeshTopology::new(&m).unwrap();
        assert!((0..m.num_vertices()).all(|v| !topo.is_boundary(v)));
        for f in 0..m.num_faces() {
            let v: Vec<Vec3> = m.face(f).iter().map(|&i| m.positions[i as usize]).collect();
            let n = (v[2] - v[0]).cross(&(v[3] - v[1]));
            let c = (v[0] + v[1] + v[2] + v[3]) / 4.0;
            let axis = Vec3::new(c.x, c.y, 0.0).normalize() * 2.0;
            assert!(n.dot(&(c - axis)) > 0.0, "face {f} points inward");
        }
    }

    #[test]
    fn every_pq_scene_meets_the_contract_bounds() {
        for &name in PQ_SCENES {
            let r = pq_scene(name).unwrap();
            assert!(r.converged, "{name}");
            assert!(r.max_planarity <= 1e-10, "{name}: {}", r.max_planarity);
            if let Some(c) = r.conical_residual {
                assert!(c <= 1e-10, "{name}: conical {c}");
            }
            if let Some(c) = r.circular_residual {
                assert!(c <= 1e-10, "{name}: circular {c}");
            }
            if let Some(d) = r.max_determinant {
                assert!(d <= 1e-10, "{name}: det {d}");
            }
        }
        assert!(matches!(
            pq_scene("nope"),
            Err(PqSceneError::UnknownScene(_))
        ));
    }
}
