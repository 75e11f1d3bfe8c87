//! Clicks on the 3D view: the view ray through a point of the canvas, the canvas position of a
//! 3D point (both with the viewer's orbit camera), and the triangle star of the picked vertex
//! as the teaching inset needs it (P-Hex paper, section 4.1).

use dupin_core::surface::Curvature;

use dupin_core::Stepper;
use dupin_core::phex::{PhexPhase, PhexPipeline};

use dupin_core::Vec3;

use dupin_core::mesh::{pick_vertex, vertex_ring};
use dupin_render::OrbitCamera;
use glam::{Vec3 as G3, Vec4};
use serde::{Deserialize, Serialize};

/// The ray through normalised device coordinates (`x`, `y` in [-1, 1], y up) of a viewport of
/// aspect `aspect`: a point on the near plane and a unit direction into the scene. `None` for
/// a singular camera or non-finite input.
// Used by the wasm-only `Viewer` (and the tests).
#[cfg_attr(not(target_arch = "wasm32"), allow(dead_code))]
pub(crate) fn view_ray(cam: &OrbitCamera, aspect: f32, x: f32, y: f32) -> Option<(G3, G3)> {
    let inv = cam.view_proj(aspect).inverse();
    let near = inv * Vec4::new(x, y, 0.0, 1.0);
    let far = inv * Vec4::new(x, y, 1.0, 1.0);
    if near.w == 0.0 || far.w == 0.0 {
        return None;
    }
    let (a, b) = (near.truncate() / near.w, far.truncate() / far.w);
    let d = (b - a).normalize_or_zero();
    (a.is_finite() && d != G3::ZERO).then_some((a, d))
}

/// Normalised device coordinates and depth (0 near .. 1 far) of `p`; `None` behind the eye.
// Used by the wasm-only `Viewer` (and the tests).
#[cfg_attr(not(target_arch = "wasm32"), allow(dead_code))]
pub(crate) fn project(cam: &OrbitCamera, aspect: f32, p: G3) -> Option<[f32; 3]> {
    let c = cam.view_proj(aspect) * p.extend(1.0);
    (c.w > 0.0).then(|| [c.x / c.w, c.y / c.w, c.z / c.w])
}

/// The vertices among `positions` in front of the eye whose projection by `view_proj` (a
/// 4 x 4 matrix, 16 numbers column-major, as `Viewer.viewProj` gives it) lies inside the
/// rectangle with corners (`rect[0]`, `rect[1]`) and (`rect[2]`, `rect[3]`) in normalised
/// device coordinates, in increasing order; a box selection, so hidden vertices count. Fails
/// for a matrix that is not 16 finite numbers or a corner that is not finite.
pub(crate) fn vertices_in_rect(
    positions: &[Vec3],
    view_proj: &[f64],
    rect: [f64; 4],
) -> Result<Vec<usize>, String> {
    if view_proj.len() != 16 || !view_proj.iter().all(|x| x.is_finite()) {
        return Err("the view needs 16 finite numbers (Viewer.viewProj)".into());
    }
    if !rect.iter().all(|x| x.is_finite()) {
        return Err("the selection rectangle needs finite corners".into());
    }
    // Row `r` of the column-major matrix times (p, 1).
    let row = |r: usize, p: &Vec3| {
        view_proj[r] * p.x + view_proj[4 + r] * p.y + view_proj[8 + r] * p.z + view_proj[12 + r]
    };
    let (x0, x1) = (rect[0].min(rect[2]), rect[0].max(rect[2]));
    let (y0, y1) = (rect[1].min(rect[3]), rect[1].max(rect[3]));
    Ok(positions
        .iter()
        .enumerate()
        .filter(|(_, p)| {
            let w = row(3, p);
            w > 0.0 && {
                let (x, y) = (row(0, p) / w, row(1, p) / w);
                (x0..=x1).contains(&x) && (y0..=y1).contains(&y)
            }
        })
        .map(|(i, _)| i)
        .collect())
}

/// An orbit camera as six numbers: target x, y, z, distance, yaw, pitch (the URL hash's and a
/// shared presentation's camera).
#[cfg_attr(not(target_arch = "wasm32"), allow(dead_code))]
pub(crate) fn camera_numbers(c: &OrbitCamera) -> Vec<f32> {
    vec![
        c.target.x, c.target.y, c.target.z, c.distance, c.yaw, c.pitch,
    ]
}

/// The orbit camera of [`camera_numbers`]' six numbers (target, distance, yaw, pitch).
// Used by the wasm-only `Viewer` and `Presenter` (and the tests).
#[cfg_attr(not(target_arch = "wasm32"), allow(dead_code))]
pub(crate) fn camera_from(v: &[f32]) -> Result<OrbitCamera, String> {
    if v.len() != 6 || !v.iter().all(|x| x.is_finite()) || v[3] <= 0.0 {
        return Err(
            "camera needs 6 finite numbers: target x, y, z, distance > 0, yaw, pitch".into(),
        );
    }
    let mut cam = OrbitCamera::framing(G3::ZERO, 1.0);
    cam.target = G3::new(v[0], v[1], v[2]);
    cam.distance = v[3];
    cam.yaw = v[4];
    cam.pitch = v[5].clamp(-1.55, 1.55);
    Ok(cam)
}

/// A picked triangulation vertex with what the inset needs: its surface point and principal
/// frame, and (for an interior valence-6 vertex) its six neighbours in counter-clockwise order.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
#[serde(rename_all = "camelCase")]
pub(crate) struct StarPick {
    /// Triangulation vertex index.
    pub(crate) vertex: usize,
    /// Its surface parameters.
    pub(crate) uv: [f64; 2],
    /// The surface point (the vertex) and the unit normal.
    pub(crate) point: [f64; 3],
    pub(crate) normal: [f64; 3],
    /// Principal curvatures (k1 >= k2) and unit principal directions.
    pub(crate) k1: f64,
    pub(crate) k2: f64,
    pub(crate) dir1: [f64; 3],
    pub(crate) dir2: [f64; 3],
    /// The six ring neighbours (vertex indices), counter-clockwise seen from the normal; empty
    /// when the star is incomplete.
    pub(crate) neighbours: Vec<u32>,
    /// Their positions.
    pub(crate) ring: Vec<[f64; 3]>,
    /// Why there is no star (boundary vertex, valence other than 6, singular point).
    pub(crate) message: Option<String>,
    /// The run's surface and its parameters (so the teaching inset can show the same surface
    /// at the same (u, v)); empty when not known.
    #[serde(default)]
    pub(crate) surface: String,
    #[serde(default)]
    pub(crate) params: std::collections::BTreeMap<String, f64>,
}

impl StarPick {
    /// The curvature record of the picked point.
    pub(crate) fn curvature(&self) -> Curvature {
        let v = |a: [f64; 3]| Vec3::new(a[0], a[1], a[2]);
        Curvature {
            point: v(self.point),
            normal: v(self.normal),
            k1: self.k1,
            k2: self.k2,
            dir1: v(self.dir1),
            dir2: v(self.dir2),
            gaussian: self.k1 * self.k2,
            mean: 0.5 * (self.k1 + self.k2),
        }
    }
}

/// The triangles of `p`'s triangulation on screen: the layers shown so far (while layering,
/// `faces` counts them; the hexagon phase starts with every layer shown), then all.
pub(crate) fn shown_triangles(p: &PhexPipeline) -> &[[u32; 3]] {
    let tri = &p.triangulation().triangles;
    let m = p.metrics();
    match m.phase {
        PhexPhase::Triangulation | PhexPhase::Hexagons => &tri[..m.faces.min(tri.len())],
        _ => tri,
    }
}

/// The triangulation vertex under the ray `origin + t dir` with its star, or `None` when the
/// ray misses the triangles on screen.
pub(crate) fn pick_star(p: &PhexPipeline, origin: Vec3, dir: Vec3) -> Option<StarPick> {
    let tri = p.triangulation();
    let shown = shown_triangles(p);
    let hit = pick_vertex(&tri.positions, shown, origin, dir)?;
    Some(star_of(p, shown, hit.vertex))
}

/// The star of triangulation vertex `v` among `triangles`.
pub(crate) fn star_of(p: &PhexPipeline, triangles: &[[u32; 3]], v: usize) -> StarPick {
    let tri = p.triangulation();
    let a3 = |x: Vec3| [x.x, x.y, x.z];
    let uv = tri.uv[v];
    let mut out = StarPick {
        vertex: v,
        uv: [uv.x, uv.y],
        point: a3(tri.positions[v]),
        normal: a3(tri.normals[v]),
        k1: 0.0,
        k2: 0.0,
        dir1: [0.0; 3],
        dir2: [0.0; 3],
        neighbours: Vec::new(),
        ring: Vec::new(),
        message: None,
        surface: p.config().surface.clone(),
        params: p.config().params.iter().cloned().collect(),
    };
    match p.surface().curvature(uv.x, uv.y) {
        Ok(c) => {
            out.k1 = c.k1;
            out.k2 = c.k2;
            out.dir1 = a3(c.dir1);
            out.dir2 = a3(c.dir2);
            out.normal = a3(c.normal);
        }
        Err(e) => {
            out.message = Some(format!("vertex {v}: no curvature there ({e})"));
            return out;
        }
    }
    match vertex_ring(tri.positions.len(), triangles, v) {
        Ok(ring) => {
            out.neighbours = ring.to_vec();
            out.ring = ring
                .iter()
                .map(|&i| a3(tri.positions[i as usize]))
                .collect();
        }
        Err(e) => out.message = Some(format!("{e}; click an interior vertex")),
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A box selection takes the vertices whose projection lies in the rectangle (either
    /// corner order), none behind the eye, and refuses a malformed view or rectangle; the
    /// camera's own matrix agrees with `project`.
    #[test]
    fn a_box_selects_the_vertices_projected_inside_it() {
        let cam = OrbitCamera::framing(G3::ZERO, 2.0);
        let vp = cam.view_proj(1.5);
        let view: Vec<f64> = vp.to_cols_array().iter().map(|&x| f64::from(x)).collect();
        let grid: Vec<Vec3> = (-3..=3)
            .flat_map(|i| (-3..=3).map(move |j| Vec3::new(i as f64 * 0.3, j as f64 * 0.3, 0.1)))
            .collect();
        let ndc: Vec<[f32; 3]> = grid
            .iter()
            .map(|p| project(&cam, 1.5, G3::new(p.x as f32, p.y as f32, p.z as f32)).unwrap())
            .collect();
        let rect = [-0.3, 0.4, 0.5, -0.2];
        let inside: Vec<usize> = (0..grid.len())
            .filter(|&i| {
                let [x, y, _] = ndc[i];
                (-0.3..=0.5).contains(&f64::from(x)) && (-0.2..=0.4).contains(&f64::from(y))
            })
            .collect();
        assert!(!inside.is_empty() && inside.len() < grid.len());
        assert_eq!(vertices_in_rect(&grid, &view, rect).unwrap(), inside);
        let everything = vertices_in_rect(&grid, &view, [-1.0, -1.0, 1.0, 1.0]).unwrap();
        assert_eq!(
            everything.len(),
            grid.len(),
            "the framed grid is all in view"
        );
        // Behind the eye: mirrored through the eye, the grid projects inside yet is not taken.
        let eye = cam.eye();
        let behind: Vec<Vec3> = grid
            .iter()
            .map(|p| {
                let e = Vec3::new(eye.x as f64, eye.y as f64, eye.z as f64);
                e + (e - p)
            })
            .collect();
        assert!(
            vertices_in_rect(&behind, &view, [-1.0, -1.0, 1.0, 1.0])
                .unwrap()
                .is_empty()
        );
        assert!(vertices_in_rect(&grid, &view[..15], rect).is_err());
        assert!(vertices_in_rect(&grid, &view, [0.0, f64::NAN, 1.0, 1.0]).is_err());
    }
    use dupin_core::phex::{PhexConfig, TriangulationMethod};

    #[test]
    fn the_ray_through_a_projected_point_passes_through_it() {
        let cam = camera_from(&[0.3, -0.2, 0.1, 4.0, -0.9, 0.55]).unwrap();
        for p in [G3::new(0.5, 0.2, -0.3), G3::new(-1.0, 0.4, 0.8), G3::ZERO] {
            let [x, y, z] = project(&cam, 1.5, p).unwrap();
            assert!((0.0..1.0).contains(&z));
            let (o, d) = view_ray(&cam, 1.5, x, y).unwrap();
            let off = (p - o) - d * (p - o).dot(d);
            assert!(off.length() < 1e-4 * (p - o).length(), "{off:?}");
            assert!((p - o).dot(d) > 0.0);
        }
        assert!(camera_from(&[0.0; 5]).is_err());
        assert!(camera_from(&[0.0, 0.0, 0.0, -1.0, 0.0, 0.0]).is_err());
    }

    #[test]
    fn camera_numbers_round_trip() {
        let v = [0.3, -0.2, 0.1, 4.0, -0.9, 0.55];
        assert_eq!(camera_numbers(&camera_from(&v).unwrap()), v);
    }

    /// Clicking the projection of an interior vertex picks that vertex, with its six
    /// neighbours in counter-clockwise order around the normal; a boundary vertex gets the
    /// inline message instead of a star.
    #[test]
    fn a_click_on_a_projected_vertex_picks_it_and_its_star() {
        let cfg = PhexConfig::for_surface("torus", &[], TriangulationMethod::Prescribed, Some(0.5));
        let mut p = PhexPipeline::new(cfg).unwrap();
        while !p.is_done() {
            p.step().unwrap();
        }
        let tri = p.triangulation().clone();
        let cam = camera_from(&[0.0, 0.0, 0.0, 7.0, -0.9, 0.55]).unwrap();
        let eye = cam.eye();
        // The vertex nearest the eye is in front of everything else.
        let v = (0..tri.positions.len())
            .min_by(|&i, &j| {
                let d = |k: usize| {
                    let q = tri.positions[k];
                    (G3::new(q.x as f32, q.y as f32, q.z as f32) - eye).length()
                };
                d(i).total_cmp(&d(j))
            })
            .unwrap();
        let q = tri.positions[v];
        let [x, y, _] = project(&cam, 1.5, G3::new(q.x as f32, q.y as f32, q.z as f32)).unwrap();
        let (o, d) = view_ray(&cam, 1.5, x, y).unwrap();
        let g = |a: G3| Vec3::new(a.x as f64, a.y as f64, a.z as f64);
        let pick = pick_star(&p, g(o), g(d)).unwrap();
        assert_eq!(pick.vertex, v);
        assert_eq!(pick.message, None);
        assert_eq!(pick.neighbours.len(), 6);
        let n = Vec3::from(pick.normal);
        for k in 0..6 {
            let a = tri.positions[pick.neighbours[k] as usize] - q;
            let b = tri.positions[pick.neighbours[(k + 1) % 6] as usize] - q;
            assert!(a.cross(&b).dot(&n) > 0.0, "not counter-clockwise at {k}");
            assert!(
                tri.triangles.iter().any(|t| t.contains(&(v as u32))
                    && t.contains(&pick.neighbours[k])
                    && t.contains(&pick.neighbours[(k + 1) % 6])),
                "ring edge {k} is not a triangle of the triangulation"
            );
        }
        // A ray away from the torus misses.
        assert!(pick_star(&p, g(eye), g(-d)).is_none());
    }

    #[test]
    fn boundary_vertices_get_a_message() {
        let cfg = PhexConfig::for_surface("torus", &[], TriangulationMethod::Prescribed, Some(0.5));
        let mut p = PhexPipeline::new(cfg).unwrap();
        p.step().unwrap();
        p.step().unwrap();
        let tri = p.triangulation();
        // A base-curve vertex after two layers: the fan cannot close.
        let v = tri.layers[0][0] as usize;
        let s = star_of(&p, shown_triangles(&p), v);
        let msg = s.message.expect("boundary message");
        assert!(msg.contains("boundary"), "{msg}");
        assert!(s.neighbours.is_empty());
        // Once every layer is in, the same vertex has its full star.
        while p.metrics().phase == PhexPhase::Triangulation {
            p.step().unwrap();
        }
        let s = star_of(&p, shown_triangles(&p), v);
        assert_eq!((s.message, s.neighbours.len()), (None, 6));
    }
}
