//! The hexagonal mesh dual to a triangulation (P-Hex paper, section 6, initialisation; the
//! tangent duality of section 4.1, Fig. 6).
//!
//! Input: a [`Triangulation`] with unit normals at its vertices. Output: a polygon mesh with one
//! vertex per triangle and one face per interior triangulation vertex (the cycle of its
//! incident triangles): hexagons at valence-6 vertices, pentagons at valence 5, and so on.
//!
//! Each dual vertex is the point of the three tangent planes of its triangle closest to the
//! triangle's centroid: the intersection point when the planes are well conditioned (tangent
//! duality, section 4.1), the minimum-norm least-squares point otherwise (parallel rulings on
//! developable surfaces, near-parabolic triangles), computed with nalgebra's SVD. Every face of
//! the dual then lies in the tangent plane of its triangulation vertex whenever the three planes
//! of each of its triangles are consistent, so the initial mesh is already planar up to the
//! conditioning of those planes; the Gauss-Newton pass of `planarity_optimisation` removes the
//! rest.
//!
//! With the surface at hand (passed to [`dual_mesh`], as the pipeline does), a triangle in a
//! parabolic region (section 6, step (1): K of mixed sign at the vertices, or |K| < 1e-8) whose
//! tangent-plane point lies more than its longest edge from its centroid gets the centroid
//! instead, as in the Dupin duality: there the tangent duality is unstable (section 6). On the
//! vase next to a parabolic circle the normals turn across the layer by a small net amount, so
//! the planes are nearly parallel yet above the rank cut-off and their point is thrown far
//! along the meridian, which made a ring of hexagons self-intersect. Where the point stays near
//! the triangle (the torus's and cyclide's parabolic circles) it is kept, so those faces still
//! start planar. Faces around a replaced point start slightly non-planar; Gauss-Newton makes
//! them planar.

use super::PhexError;
use super::triangulation::Triangulation;
use crate::Vec3;
use crate::mesh::PolyMesh;
use nalgebra::Matrix3;

/// Cut-off of the smallest singular value of the tangent-plane system relative to the middle
/// one (below it the direction is treated as free and the centroid's component is kept).
const RANK_TOL: f64 = 3e-2;

/// The dual polygon mesh of a triangulation plus, for every face, its triangulation vertex.
#[derive(Debug, Clone, PartialEq)]
pub struct DualMesh {
    /// The polygon mesh (one vertex per triangle, one face per interior vertex).
    pub mesh: PolyMesh,
    /// For every face, the triangulation vertex it is dual to.
    pub face_vertex: Vec<u32>,
    /// For every dual vertex, surface parameters near it (a start for closest-point queries).
    pub vertex_uv: Vec<crate::Vec2>,
}

/// Tangent-plane dual point of one triangle (see the module docs).
pub fn tangent_plane_point(p: [Vec3; 3], n: [Vec3; 3]) -> Vec3 {
    let c = (p[0] + p[1] + p[2]) / 3.0;
    let a = Matrix3::from_rows(&[n[0].transpose(), n[1].transpose(), n[2].transpose()]);
    let rhs = Vec3::new(
        n[0].dot(&(p[0] - c)),
        n[1].dot(&(p[1] - c)),
        n[2].dot(&(p[2] - c)),
    );
    let svd = a.svd(true, true);
    let (Some(u), Some(vt)) = (svd.u, svd.v_t) else {
        return c;
    };
    let sv = svd.singular_values;
    // The normals of a small triangle are nearly parallel: the two smaller singular values are
    // both of order (edge x curvature). The smallest one is dropped only when it is small
    // against the middle one (normals varying in one direction only: parabolic points, rulings).
    let mut order = [0usize, 1, 2];
    order.sort_by(|&i, &j| sv[j].total_cmp(&sv[i]));
    let tol = RANK_TOL * sv[order[1]];
    let mut x = Vec3::zeros();
    for &i in &order {
        if sv[i] > tol && sv[i] > 1e-14 * sv[order[0]] {
            let coef = u.column(i).dot(&rhs) / sv[i];
            x += vt.row(i).transpose() * coef;
        }
    }
    if x.iter().all(|v| v.is_finite()) {
        c + x
    } else {
        c
    }
}

/// How the dual vertices are placed (section 6 initialisation).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Initialisation {
    /// Tangent duality (section 4.1): the point of the three tangent planes nearest the
    /// centroid; the centroid where that point is unstable in a parabolic region (section 6,
    /// step (1), see the module docs). Faces start planar wherever the planes are well
    /// conditioned.
    #[default]
    TangentDuality,
    /// Approximate Dupin duality (section 6, steps 1 to 4: per-vertex Dupin centers averaged,
    /// the centroid in parabolic regions, see [`crate::phex::approximate_dupin_center`]). Faces start
    /// non-planar; the Gauss-Newton optimisation makes them planar.
    DupinDuality,
}

crate::names::named_choices!(Initialisation, "init", {
    TangentDuality => "tangent-duality",
    DupinDuality => "dupin-duality",
});

/// In a parabolic region, a tangent-plane point farther than this many longest triangle edges
/// from the centroid counts as unstable and is replaced by the centroid (0.5 and 1 both keep
/// every scene's Gauss-Newton iteration count; without a limit the torus and cyclide scenes,
/// whose points stay near their triangles, lose their planar start).
const UNSTABLE_DISTANCE: f64 = 1.0;

/// Parabolic threshold on |K| of the parabolic-region rule (the paper's 1e-8).
pub const PARABOLIC_THRESHOLD: f64 = 1e-8;

/// Section 6, step (1), parabolic region detection: the Gaussian curvatures `k` at a
/// triangle's vertices are not all of one sign, or one of them is within
/// [`PARABOLIC_THRESHOLD`] of zero.
fn in_parabolic_region(k: [f64; 3]) -> bool {
    let same_sign = k.iter().all(|&x| x > 0.0) || k.iter().all(|&x| x < 0.0);
    !same_sign || k.iter().any(|x| x.abs() < PARABOLIC_THRESHOLD)
}

/// How [`dual_mesh`] builds the dual (section 6), lyon-style:
/// `DualMeshOptions::default().with_initialisation(..).with_boundary_faces(..)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct DualMeshOptions {
    /// How the dual vertices are placed (section 6 initialisation).
    pub initialisation: Initialisation,
    /// Also make faces at boundary triangulation vertices (section 6: the optimisation is
    /// "generalised to boundary faces"): a boundary vertex `v` whose incident triangles form
    /// one fan `t_1 .. t_k` with `k >= 2` gives the face `[m(v, w_in), t_1, .., t_k,
    /// m(v, w_out)]`, where `w_in`, `w_out` are its two boundary neighbours and `m(v, w)` is a
    /// new dual vertex per boundary edge: the point of the tangent planes of `v` and `w`
    /// nearest the edge midpoint (shared by the faces of `v` and `w`; always placed by tangent
    /// duality). Every boundary face therefore also starts in the tangent plane of its vertex.
    /// Fans with one triangle (corners) give no face. Interior vertices give the same faces
    /// either way.
    pub boundary_faces: bool,
}

impl DualMeshOptions {
    /// Tangent duality, interior faces only.
    pub const DEFAULT: Self = DualMeshOptions {
        initialisation: Initialisation::TangentDuality,
        boundary_faces: false,
    };

    /// These options with `initialisation`.
    pub fn with_initialisation(mut self, initialisation: Initialisation) -> Self {
        self.initialisation = initialisation;
        self
    }

    /// These options with boundary faces on or off.
    pub fn with_boundary_faces(mut self, on: bool) -> Self {
        self.boundary_faces = on;
        self
    }
}

/// Builds the dual polygon mesh of `t` (section 6 initialisation) with `options`.
///
/// `surface` gives the curvature at the triangulation vertices: the Dupin duality needs it, and
/// with it the tangent duality applies the parabolic-region rule (see the module docs).
/// Without it (`None`, no curvature at hand) the tangent duality places every vertex at its
/// tangent-plane point.
///
/// Errors: [`PhexError::NoValidTriangulation`] when no face can be formed;
/// [`PhexError::BadParameter`] for the Dupin duality without a surface.
pub fn dual_mesh(
    t: &Triangulation,
    surface: Option<&dyn crate::surface::Surface>,
    options: &DualMeshOptions,
) -> Result<DualMesh, PhexError> {
    let Some(surface) = surface else {
        return match options.initialisation {
            Initialisation::TangentDuality => {
                dual_from_points_impl(t, tangent_points(t), options.boundary_faces)
            }
            Initialisation::DupinDuality => Err(PhexError::BadParameter(
                "the Dupin duality needs the surface's curvature; pass the surface".into(),
            )),
        };
    };
    let positions = match options.initialisation {
        Initialisation::TangentDuality => {
            let k: Vec<Option<f64>> =
                t.uv.iter()
                    .map(|uv| surface.curvature(uv.x, uv.y).ok().map(|c| c.gaussian))
                    .collect();
            let mut points = tangent_points(t);
            for (point, tr) in points.iter_mut().zip(&t.triangles) {
                let parabolic = match tr.map(|i| k[i as usize]) {
                    [Some(a), Some(b), Some(c)] => in_parabolic_region([a, b, c]),
                    _ => true,
                };
                if parabolic {
                    let p = tr.map(|i| t.positions[i as usize]);
                    let c = (p[0] + p[1] + p[2]) / 3.0;
                    let longest = (0..3)
                        .map(|j| (p[j] - p[(j + 1) % 3]).norm())
                        .fold(0.0, f64::max);
                    if !((*point - c).norm() <= UNSTABLE_DISTANCE * longest) {
                        *point = c;
                    }
                }
            }
            points
        }
        Initialisation::DupinDuality => {
            let curv: Vec<Option<crate::surface::Curvature>> =
                t.uv.iter()
                    .zip(&t.positions)
                    .map(|(uv, p)| {
                        surface.curvature(uv.x, uv.y).ok().map(|mut c| {
                            // The vertex itself (the parameters may be unwrapped).
                            c.point = *p;
                            c
                        })
                    })
                    .collect();
            t.triangles
                .iter()
                .map(|tr| {
                    let centroid = tr.iter().map(|&i| t.positions[i as usize]).sum::<Vec3>() / 3.0;
                    match tr.map(|i| curv[i as usize].as_ref()) {
                        [Some(a), Some(b), Some(c)] => {
                            crate::phex::approximate_dupin_center([a, b, c], PARABOLIC_THRESHOLD)
                                .map_or(centroid, |r| r.0)
                        }
                        _ => centroid,
                    }
                })
                .collect()
        }
    };
    dual_from_points_impl(t, positions, options.boundary_faces)
}

fn tangent_points(t: &Triangulation) -> Vec<Vec3> {
    t.triangles
        .iter()
        .map(|tr| {
            let p = tr.map(|i| t.positions[i as usize]);
            let n = tr.map(|i| t.normals[i as usize]);
            tangent_plane_point(p, n)
        })
        .collect()
}

/// The point of the tangent planes at `a` (normal `na`) and `b` (normal `nb`) nearest their
/// midpoint (the midpoint projected onto the mean plane when the planes are nearly parallel).
fn edge_point(a: Vec3, na: Vec3, b: Vec3, nb: Vec3) -> Vec3 {
    let m = 0.5 * (a + b);
    let (ra, rb) = (na.dot(&(a - m)), nb.dot(&(b - m)));
    let c = na.dot(&nb);
    let det = 1.0 - c * c;
    if det > 1e-8 {
        // x = m + α na + β nb with [1 c; c 1] (α, β) = (ra, rb).
        let alpha = (ra - c * rb) / det;
        let beta = (rb - c * ra) / det;
        m + na * alpha + nb * beta
    } else {
        let n = (na + nb).normalize();
        let x = m + n * (0.5 * (ra + rb));
        if x.iter().all(|v| v.is_finite()) {
            x
        } else {
            m
        }
    }
}

/// Whether `pts`, projected onto the plane through `origin` with unit normal `n`, form a simple
/// polygon.
fn starts_simple(pts: &[Vec3], origin: Vec3, n: Vec3) -> bool {
    let (e1, e2) = crate::mesh::plane_basis(n);
    let q: Vec<crate::Vec2> = pts
        .iter()
        .map(|p| crate::Vec2::new((p - origin).dot(&e1), (p - origin).dot(&e2)))
        .collect();
    crate::mesh::is_simple_polygon(&q).unwrap_or(false)
}

fn dual_from_points_impl(
    t: &Triangulation,
    mut positions: Vec<Vec3>,
    boundary: bool,
) -> Result<DualMesh, PhexError> {
    let nv = t.positions.len();
    let mut vertex_uv: Vec<crate::Vec2> =
        t.triangles.iter().map(|tr| t.uv[tr[0] as usize]).collect();
    let mut edge_points: std::collections::HashMap<(u32, u32), u32> = Default::default();
    // Star of every vertex: for a CCW triangle (a, b, c), vertex a sees the edge b -> c.
    let mut star: Vec<Vec<(u32, u32, u32)>> = vec![vec![]; nv];
    for (ti, tr) in t.triangles.iter().enumerate() {
        for k in 0..3 {
            star[tr[k] as usize].push((tr[(k + 1) % 3], tr[(k + 2) % 3], ti as u32));
        }
    }
    let mut faces: Vec<Vec<u32>> = vec![];
    let mut face_vertex = vec![];
    for (v, st) in star.iter().enumerate() {
        if boundary && st.len() >= 2 {
            // An open fan: starts at the triangle whose `b` is no other triangle's `c`.
            if let Some(&first) = st.iter().find(|e| st.iter().all(|f| f.1 != e.0)) {
                let mut fan = vec![first];
                let mut cur = first;
                while let Some(&e) = st.iter().find(|e| e.0 == cur.1) {
                    if fan.len() > st.len() {
                        break;
                    }
                    fan.push(e);
                    cur = e;
                }
                if fan.len() == st.len() {
                    let edge = |w: u32| {
                        let (a, b) = (w as usize, v);
                        edge_point(t.positions[a], t.normals[a], t.positions[b], t.normals[b])
                    };
                    // Keep only boundary faces that start as simple polygons in the tangent
                    // plane of their vertex (on K < 0 a half star can fold over near corners).
                    let mut pts = vec![edge(first.0)];
                    pts.extend(fan.iter().map(|e| positions[e.2 as usize]));
                    pts.push(edge(cur.1));
                    if !starts_simple(&pts, t.positions[v], t.normals[v]) {
                        continue;
                    }
                    let mut point = |w: u32| {
                        let key = (w.min(v as u32), w.max(v as u32));
                        *edge_points.entry(key).or_insert_with(|| {
                            let (a, b) = (key.0 as usize, key.1 as usize);
                            positions.push(edge_point(
                                t.positions[a],
                                t.normals[a],
                                t.positions[b],
                                t.normals[b],
                            ));
                            vertex_uv.push(t.uv[v]);
                            (positions.len() - 1) as u32
                        })
                    };
                    let mut face = vec![point(first.0)];
                    face.extend(fan.iter().map(|e| e.2));
                    face.push(point(cur.1));
                    faces.push(face);
                    face_vertex.push(v as u32);
                    continue;
                }
            }
        }
        if st.len() < 3 {
            continue;
        }
        // Follow b -> c links; interior iff it closes after visiting every triangle.
        let mut face = Vec::with_capacity(st.len());
        let mut cur = st[0];
        let mut ok = true;
        for _ in 0..st.len() {
            face.push(cur.2);
            match st.iter().find(|e| e.0 == cur.1) {
                Some(&e) => cur = e,
                None => {
                    ok = false;
                    break;
                }
            }
        }
        if ok && cur == st[0] && face.len() == st.len() {
            faces.push(face);
            face_vertex.push(v as u32);
        }
    }
    if faces.is_empty() {
        return Err(PhexError::NoValidTriangulation(
            "the triangulation has no interior vertex: make the size smaller".into(),
        ));
    }
    let mesh = PolyMesh::new(positions, &faces)
        .map_err(|e| PhexError::NoValidTriangulation(format!("dual mesh: {e}")))?;
    Ok(DualMesh {
        mesh,
        face_vertex,
        vertex_uv,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn unit(rng: &mut ChaCha8Rng) -> Vec3 {
        Vec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        )
        .normalize()
    }

    #[test]
    fn well_conditioned_point_is_on_all_three_tangent_planes() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        for _ in 0..200 {
            let p = [unit(&mut rng), unit(&mut rng), unit(&mut rng)];
            let n = [unit(&mut rng), unit(&mut rng), unit(&mut rng)];
            if n[0].dot(&n[1].cross(&n[2])).abs() < 0.2 {
                continue;
            }
            let x = tangent_plane_point(p, n);
            for k in 0..3 {
                assert!((x - p[k]).dot(&n[k]).abs() < 1e-9, "plane {k}");
            }
        }
    }

    #[test]
    fn parabolic_region_is_mixed_signs_or_a_vanishing_curvature() {
        assert!(!in_parabolic_region([1.0, 2.0, 0.5]));
        assert!(!in_parabolic_region([-1.0, -2.0, -0.5]));
        assert!(in_parabolic_region([1.0, -2.0, 0.5]));
        assert!(in_parabolic_region([-1.0, 2.0, -0.5]));
        assert!(in_parabolic_region([1.0, 2.0, 0.5 * PARABOLIC_THRESHOLD]));
        assert!(in_parabolic_region([-1.0, -2.0, 0.0]));
    }

    #[test]
    fn unstable_parabolic_points_become_centroids_and_the_rest_stay_tangent_dual() {
        // Section 6, step (1), on the vase over its whole domain: the base curve lies on the
        // bottom parabolic circle, the first layer is not centred on it and its tangent-plane
        // points fly off (52 invalid faces in the initial mesh). The unstable points of
        // parabolic triangles become centroids, every other triangle keeps its tangent-plane
        // point, and the initial mesh is valid.
        let params = [("radius", 1.0), ("amplitude", 0.35)];
        let mut cfg = crate::phex::PhexConfig::for_surface(
            "vase",
            &[],
            crate::phex::TriangulationMethod::Prescribed,
            Some(0.12),
        );
        cfg.optimize = false;
        let r = crate::phex::phex_run(cfg).unwrap();
        assert_eq!(r.report.invalid_faces, 0);
        let t = &r.triangulation;
        let s = crate::surface::surface_by_name("vase", &params).unwrap();
        let d = dual_mesh(t, Some(s.as_ref()), &DualMeshOptions::default()).unwrap();
        let plain = dual_mesh(t, None, &DualMeshOptions::default()).unwrap();
        let mut replaced = 0;
        for (i, tr) in t.triangles.iter().enumerate() {
            let k = tr.map(|v| {
                let uv = t.uv[v as usize];
                s.curvature(uv.x, uv.y).unwrap().gaussian
            });
            let p = tr.map(|v| t.positions[v as usize]);
            let c = (p[0] + p[1] + p[2]) / 3.0;
            let longest = (0..3)
                .map(|j| (p[j] - p[(j + 1) % 3]).norm())
                .fold(0.0, f64::max);
            let tangent = plain.mesh.positions[i];
            if in_parabolic_region(k) && (tangent - c).norm() > longest {
                replaced += 1;
                assert!((d.mesh.positions[i] - c).norm() < 1e-12);
            } else {
                assert_eq!(d.mesh.positions[i], tangent);
            }
        }
        assert!(replaced > 0);
    }

    #[test]
    fn stable_parabolic_points_are_kept_on_the_torus() {
        // The torus's parabolic circles: the tangent-plane points stay near their triangles,
        // so the rule keeps the exact tangent duality and the faces start planar.
        let mut cfg = crate::scenes::phex_scene("torus-bound").unwrap().config;
        cfg.optimize = false;
        let r = crate::phex::phex_run(cfg).unwrap();
        let t = &r.triangulation;
        let s = crate::surface::surface_by_name("torus", &[]).unwrap();
        let parabolic = t
            .triangles
            .iter()
            .filter(|tr| {
                in_parabolic_region(tr.map(|v| {
                    let uv = t.uv[v as usize];
                    s.curvature(uv.x, uv.y).unwrap().gaussian
                }))
            })
            .count();
        assert!(parabolic > 100, "{parabolic} parabolic triangles");
        let d = dual_mesh(t, Some(s.as_ref()), &DualMeshOptions::default()).unwrap();
        assert_eq!(
            d.mesh,
            dual_mesh(t, None, &DualMeshOptions::default())
                .unwrap()
                .mesh
        );
        assert!(
            r.report.max_planarity < 1e-12,
            "{:e}",
            r.report.max_planarity
        );
    }

    #[test]
    fn rulings_give_the_point_of_the_common_line_nearest_the_centroid() {
        // Three tangent planes of a cylinder all contain the z axis direction: the point is on
        // all planes (consistent rank-2 system) at the centroid's height.
        let ang = [0.0f64, 0.3, 0.15];
        let p = ang.map(|a| Vec3::new(a.cos(), a.sin(), a));
        let n = ang.map(|a| Vec3::new(a.cos(), a.sin(), 0.0));
        // Make the system consistent: two points on one ruling share a normal.
        let p = [p[0], Vec3::new(p[0].x, p[0].y, 0.5), p[1]];
        let n = [n[0], n[0], n[1]];
        let x = tangent_plane_point(p, n);
        for k in 0..3 {
            assert!((x - p[k]).dot(&n[k]).abs() < 1e-12);
        }
        let cz = (p[0].z + p[1].z + p[2].z) / 3.0;
        assert!((x.z - cz).abs() < 1e-12);
    }

    #[test]
    fn every_dual_face_lies_in_the_tangent_plane_of_its_vertex() {
        let r = crate::phex::phex_run(crate::scenes::phex_scene("torus-bound").unwrap().config)
            .unwrap();
        let t = &r.triangulation;
        let d = dual_mesh(t, None, &DualMeshOptions::default()).unwrap();
        for (f, &v) in d.face_vertex.iter().enumerate() {
            let (p, n) = (t.positions[v as usize], t.normals[v as usize]);
            let e = d.mesh.face_mean_edge(f);
            for &i in d.mesh.face(f) {
                assert!((d.mesh.positions[i as usize] - p).dot(&n).abs() < 1e-9 * e);
            }
        }
    }

    #[test]
    fn boundary_faces_close_the_dual_and_become_planar() {
        use crate::mesh::max_planarity;
        use crate::phex::{PlanarityOptimiser, PlanarityOptions};
        use std::collections::HashSet;
        for (scene, seed) in [("sphere-radial", 3u64), ("hyperboloid-valid", 4)] {
            let sc = crate::scenes::phex_scene(scene).unwrap();
            let mut cfg = sc.config.clone();
            cfg.optimize = false;
            let r = crate::phex::phex_run(cfg).unwrap();
            let t = &r.triangulation;
            let inner = dual_mesh(t, None, &DualMeshOptions::default()).unwrap();
            let d = dual_mesh(
                t,
                None,
                &DualMeshOptions::default().with_boundary_faces(true),
            )
            .unwrap();
            let interior: HashSet<u32> = inner.face_vertex.iter().copied().collect();
            let boundary: Vec<usize> = (0..d.mesh.num_faces())
                .filter(|&f| !interior.contains(&d.face_vertex[f]))
                .collect();
            assert!(!boundary.is_empty(), "{scene}: no boundary face");
            assert_eq!(d.mesh.num_faces(), inner.mesh.num_faces() + boundary.len());
            // Oriented 2-manifold with boundary: each directed edge once, each edge in <= 2 faces.
            let mut directed = HashSet::new();
            for f in d.mesh.faces() {
                assert!(f.len() >= 4, "{scene}: face of {} vertices", f.len());
                for k in 0..f.len() {
                    assert!(directed.insert((f[k], f[(k + 1) % f.len()])), "{scene}");
                }
            }
            // Boundary faces start in the tangent plane of their vertex (sphere: exactly).
            if scene == "sphere-radial" {
                for &f in &boundary {
                    let v = d.face_vertex[f] as usize;
                    let (p, n) = (t.positions[v], t.normals[v]);
                    let e = d.mesh.face_mean_edge(f);
                    for &i in d.mesh.face(f) {
                        let off = (d.mesh.positions[i as usize] - p).dot(&n).abs();
                        assert!(off < 1e-9 * e, "{scene}: {off:e}");
                    }
                }
            }
            // The Gauss-Newton optimisation makes every face, boundary faces included, planar
            // from a perturbed start.
            let mut mesh = d.mesh.clone();
            let e = (0..mesh.num_faces())
                .map(|i| mesh.face_mean_edge(i))
                .sum::<f64>()
                / mesh.num_faces() as f64;
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            for p in mesh.positions.iter_mut() {
                for k in 0..3 {
                    p[k] += rng.random_range(-1.0..1.0) * 1e-3 * e;
                }
            }
            assert!(max_planarity(&mesh) > 1e-5);
            let surface = crate::surface::surface_by_name(&sc.config.surface, &[]).unwrap();
            let mut opt =
                PlanarityOptimiser::new(&mesh, Some(&d.vertex_uv), PlanarityOptions::default())
                    .unwrap();
            while !opt.is_done() {
                opt.step(&mut mesh, surface.as_ref()).unwrap();
            }
            assert!(
                opt.max_planarity() <= 1e-10,
                "{scene}: {:e}",
                opt.max_planarity()
            );
            assert!(opt.iteration() <= 10);
        }
    }
}
