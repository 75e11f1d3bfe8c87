//! Per-face diagnostics of a P-Hex mesh and the contract's report (P-Hex paper, sections 4.2
//! and 7): planarity, validity (simple polygon), convexity and the shape deviation from the
//! affine regular (K > 0) or affine quasi-regular (K < 0) hexagon, plus the surface distance.

use crate::mesh::{PolyMesh, coordinate_precision_note, face_planarity, is_simple_polygon};

use crate::surface::Surface;

use crate::{Vec2, Vec3};
use std::collections::BTreeMap;

/// Diagnostics of one face.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FaceInfo {
    /// [`face_planarity`]: largest distance from the least-squares plane over mean edge.
    pub planarity: f64,
    /// Whether the face, projected to its plane, is a simple polygon (not self-intersecting).
    pub simple: bool,
    /// Whether the projected face is strictly convex.
    pub convex: bool,
    /// Gaussian curvature of the surface at the face's triangulation vertex.
    pub gaussian: f64,
    /// Hexagons only: relative deviation from the affine regular hexagon (K >= 0:
    /// max_i |h_(i+1) - h_i - h_(i+2)|) or the affine quasi-regular one (K < 0:
    /// min_k max of |h_(k+1) - (h_k + h_(k+2))/4| and the central-symmetry defects), over the
    /// largest |h_i| (vertices h_i relative to the centroid); `None` for other sizes.
    pub shape_deviation: Option<f64>,
}

/// The contract's P-Hex report plus per-face data.
#[derive(Debug, Clone, PartialEq)]
pub struct PhexReport {
    /// Number of vertices.
    pub vertices: usize,
    /// Number of faces.
    pub faces: usize,
    /// Polygon size -> count.
    pub face_sizes: BTreeMap<usize, usize>,
    /// Contract `max_planarity`.
    pub max_planarity: f64,
    /// Faces that are not simple polygons.
    pub invalid_faces: usize,
    /// Gauss-Newton iterations run.
    pub iterations: usize,
    /// Largest vertex distance to the surface.
    pub max_surface_distance: f64,
    /// Bounding-box diagonal of the mesh.
    pub bbox_diagonal: f64,
    /// Shortest edge over the mean edge (degeneracy check).
    pub min_edge_ratio: f64,
    /// Per-face diagnostics, in face order.
    pub per_face: Vec<FaceInfo>,
}

/// Face `i` of `mesh` projected onto its Newell-normal plane (2D points in face order), into
/// `out` (cleared first: callers that visit every face reuse one buffer).
fn project_face_into(mesh: &PolyMesh, i: usize, out: &mut Vec<Vec2>) {
    let f = mesh.face(i);
    let c = f.iter().map(|&v| mesh.positions[v as usize]).sum::<Vec3>() / f.len() as f64;
    // Corners relative to the centroid, over a power of two near their size: exact, so the
    // same bits at ordinary sizes, and no overflow or underflow in the cross products of a face
    // 1e150 or 1e-150 across (at 1e150 every face of a valid mesh read as self-intersecting).
    let size = f
        .iter()
        .map(|&v| (mesh.positions[v as usize] - c).amax())
        .fold(0.0, f64::max);
    let unit = if size.is_normal() {
        2f64.powi(size.log2().floor() as i32)
    } else {
        1.0
    };
    let at = |k: usize| (mesh.positions[f[k] as usize] - c) / unit;
    let mut n = Vec3::zeros();
    for k in 0..f.len() {
        n += at(k).cross(&at((k + 1) % f.len()));
    }
    let n = n.try_normalize(0.0).unwrap_or(Vec3::z());
    let (e1, e2) = crate::mesh::plane_basis(n);
    out.clear();
    out.extend((0..f.len()).map(|k| {
        let d = at(k);
        Vec2::new(d.dot(&e1), d.dot(&e2))
    }));
}

/// `(simple, convex)` of the projected polygon `q`, as [`FaceInfo`] has them.
fn simple_and_convex(q: &[Vec2]) -> (bool, bool) {
    let n = q.len();
    let simple = is_simple_polygon(q).unwrap_or(false);
    let turn = |k: usize| (q[(k + 1) % n] - q[k]).perp(&(q[(k + 2) % n] - q[(k + 1) % n]));
    let convex = simple && ((0..n).all(|k| turn(k) > 0.0) || (0..n).all(|k| turn(k) < 0.0));
    (simple, convex)
}

/// `(self-intersecting, simple but not convex)` counts of the faces `faces` of `mesh`
/// ([`FaceInfo::simple`] and [`FaceInfo::convex`], without the planarity and shape figures: the
/// page counts them at every state of a run).
pub fn count_invalid_and_non_convex_faces(
    mesh: &PolyMesh,
    faces: std::ops::Range<usize>,
) -> (usize, usize) {
    let mut q = Vec::new();
    let (mut invalid, mut non_convex) = (0, 0);
    for i in faces {
        project_face_into(mesh, i, &mut q);
        let (simple, convex) = simple_and_convex(&q);
        invalid += usize::from(!simple);
        non_convex += usize::from(simple && !convex);
    }
    (invalid, non_convex)
}

/// Diagnostics of face `i` of `mesh`, with `gaussian` the curvature there.
pub fn face_info(mesh: &PolyMesh, i: usize, gaussian: f64) -> FaceInfo {
    let mut q = Vec::new();
    project_face_into(mesh, i, &mut q);
    let (simple, convex) = simple_and_convex(&q);
    let shape_deviation = (q.len() == 6).then(|| {
        let c = q.iter().sum::<Vec2>() / 6.0;
        let r: Vec<Vec2> = q.iter().map(|p| p - c).collect();
        let scale = r.iter().map(|v| v.norm()).fold(0.0, f64::max).max(1e-300);
        if gaussian >= 0.0 {
            (0..6)
                .map(|k| (r[(k + 1) % 6] - r[k] - r[(k + 2) % 6]).norm())
                .fold(0.0, f64::max)
                / scale
        } else {
            let sym = (0..3).map(|k| (r[k] + r[k + 3]).norm()).fold(0.0, f64::max);
            let best = (0..6)
                .map(|k| (r[(k + 1) % 6] - (r[k] + r[(k + 2) % 6]) / 4.0).norm())
                .fold(f64::INFINITY, f64::min);
            sym.max(best) / scale
        }
    });
    FaceInfo {
        planarity: face_planarity(mesh, i),
        simple,
        convex,
        gaussian,
        shape_deviation,
    }
}

/// Number of faces of `mesh` that are not simple polygons in their plane ([`FaceInfo::simple`]):
/// the report's `invalid_faces` (P-Hex paper, section 4.1: a valid hexagon does not
/// self-intersect), for any polygon mesh.
pub fn count_invalid_faces(mesh: &PolyMesh) -> usize {
    // `FaceInfo::simple` alone: the validity test run after every optimisation step, without
    // the planarity and shape figures of [`face_info`].
    let mut q = Vec::new();
    (0..mesh.num_faces())
        .filter(|&i| {
            project_face_into(mesh, i, &mut q);
            !is_simple_polygon(&q).unwrap_or(false)
        })
        .count()
}

/// Builds the report of `mesh` on `surface`. `face_gaussian[i]` is the Gaussian curvature at
/// face i's triangulation vertex; `start_uv` seeds the closest-point searches.
pub fn phex_report(
    mesh: &PolyMesh,
    surface: &dyn Surface,
    face_gaussian: &[f64],
    start_uv: &[Vec2],
    iterations: usize,
) -> PhexReport {
    let per_face: Vec<FaceInfo> = (0..mesh.num_faces())
        .map(|i| face_info(mesh, i, face_gaussian.get(i).copied().unwrap_or(0.0)))
        .collect();
    let max_surface_distance = mesh
        .positions
        .iter()
        .enumerate()
        .map(|(i, p)| {
            surface
                .closest_point(p, start_uv.get(i).copied())
                .map(|c| c.distance)
                .unwrap_or(f64::INFINITY)
        })
        .fold(0.0, f64::max);
    let mut edges = vec![];
    for f in mesh.faces() {
        for k in 0..f.len() {
            let (a, b) = (f[k], f[(k + 1) % f.len()]);
            edges.push((mesh.positions[a as usize] - mesh.positions[b as usize]).norm());
        }
    }
    let mean = edges.iter().sum::<f64>() / edges.len().max(1) as f64;
    let min = edges.iter().copied().fold(f64::INFINITY, f64::min);
    PhexReport {
        vertices: mesh.num_vertices(),
        faces: mesh.num_faces(),
        face_sizes: mesh.face_sizes(),
        max_planarity: per_face.iter().map(|f| f.planarity).fold(0.0, f64::max),
        invalid_faces: per_face.iter().filter(|f| !f.simple).count(),
        iterations,
        max_surface_distance,
        bbox_diagonal: mesh.bbox_diagonal(),
        min_edge_ratio: if mean > 0.0 { min / mean } else { 0.0 },
        per_face,
    }
}

/// What a P-Hex run is asked for, so that a finished run that misses it says so (CLI exit 3, the
/// page's `warning` phase) instead of passing as done.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhexGoals {
    /// Faces planar to this `max_planarity` (the optimiser's tolerance); `None` when the
    /// planarity optimisation was switched off.
    pub planarity: Option<f64>,
    /// No self-intersecting face (off only for scenes made to show invalid faces).
    pub valid: bool,
}

impl PhexGoals {
    /// The goals of a run of `config`; `valid` as above.
    pub fn of(config: &super::PhexConfig, valid: bool) -> Self {
        PhexGoals {
            planarity: config
                .optimize
                .then(|| config.planarity_options().tolerance),
            valid,
        }
    }

    /// What a finished run with these figures misses, each miss in a sentence (joined by `; `);
    /// `None` when it meets every goal. A NaN planarity is a miss. `mesh` is the run's result:
    /// a planarity miss on a design too far from the origin for its size names the
    /// coordinates' precision as the cause ([`coordinate_precision_note`]).
    pub fn shortfall(
        &self,
        mesh: &PolyMesh,
        max_planarity: f64,
        iterations: usize,
        invalid_faces: usize,
    ) -> Option<String> {
        let mut missed = Vec::new();
        if let Some(tolerance) = self.planarity
            && !(max_planarity <= tolerance)
        {
            missed.push(format!(
                "max_planarity {max_planarity:.3e} is above the tolerance {tolerance:.0e} after \
                 {iterations} iterations{}",
                coordinate_precision_note(mesh, tolerance)
            ));
        }
        if self.valid && invalid_faces > 0 {
            missed.push(format!(
                "{invalid_faces} of {} faces are self-intersecting (invalid); try a larger \
                 size or another method",
                mesh.num_faces()
            ));
        }
        (!missed.is_empty()).then(|| missed.join("; "))
    }
}

#[cfg(test)]
mod shape_tests {
    use super::*;

    /// The counts the page shows at every state are `face_info`'s, face for face: a convex
    /// quad, a dart (simple, not convex), a bow tie (self-intersecting), a triangle and a
    /// collinear triangle (not simple).
    #[test]
    fn the_counts_are_face_info_s() {
        let p = |x: f64, y: f64, z: f64| Vec3::new(x, y, z);
        let positions = vec![
            p(0.0, 0.0, 0.0),
            p(1.0, 0.0, 0.0),
            p(1.0, 1.0, 0.0),
            p(0.0, 1.0, 0.0),
            p(0.3, 0.3, 0.0),
            p(2.0, 0.0, 0.0),
            p(3.0, 0.0, 0.0),
        ];
        let faces = [
            vec![0u32, 1, 2, 3],
            vec![0, 1, 4, 3],
            vec![0, 2, 1, 3],
            vec![1, 5, 2],
            vec![1, 5, 6],
        ];
        let mesh = PolyMesh::new(positions, faces).unwrap();
        let infos: Vec<FaceInfo> = (0..5).map(|i| face_info(&mesh, i, 0.0)).collect();
        let shape: Vec<(bool, bool)> = infos.iter().map(|f| (f.simple, f.convex)).collect();
        assert_eq!(
            shape,
            [
                (true, true),
                (true, false),
                (false, false),
                (true, true),
                (false, false)
            ]
        );
        assert_eq!(count_invalid_and_non_convex_faces(&mesh, 0..5), (2, 1));
        assert_eq!(count_invalid_and_non_convex_faces(&mesh, 2..4), (1, 0));
        assert_eq!(count_invalid_faces(&mesh), 2);
        // The same at any size: the cross products neither overflow nor underflow.
        for scale in [1e150, 1e-150, 2f64.powi(500), 2f64.powi(-500)] {
            let mut m = mesh.clone();
            m.positions.iter_mut().for_each(|p| *p *= scale);
            assert_eq!(
                count_invalid_and_non_convex_faces(&m, 0..5),
                (2, 1),
                "{scale:e}"
            );
        }
    }
}

#[cfg(test)]
mod goal_tests {
    use super::PhexGoals;
    use crate::Vec3;
    use crate::mesh::PolyMesh;

    /// A planar 10 x 10 grid of unit quads (100 faces) with its corner at `origin`.
    fn grid(origin: Vec3) -> PolyMesh {
        let positions = (0..11)
            .flat_map(|j| (0..11).map(move |i| origin + Vec3::new(i as f64, j as f64, 0.0)))
            .collect();
        PolyMesh::quad_grid(positions, 10, 10).unwrap()
    }

    #[test]
    fn shortfall_names_each_missed_goal_and_nan_misses() {
        let goals = PhexGoals {
            planarity: Some(1e-10),
            valid: true,
        };
        let mesh = grid(Vec3::zeros());
        assert_eq!(goals.shortfall(&mesh, 1e-12, 4, 0), None);
        let both = goals.shortfall(&mesh, 1e-6, 10, 3).unwrap();
        assert!(both.contains("1.000e-6 is above the tolerance 1e-10 after 10 iterations"));
        assert!(both.contains("3 of 100 faces are self-intersecting"));
        assert!(!both.contains("precision"), "{both}");
        assert!(goals.shortfall(&mesh, f64::NAN, 1, 0).is_some());
        let lax = PhexGoals {
            planarity: None,
            valid: false,
        };
        assert_eq!(lax.shortfall(&mesh, f64::NAN, 0, 50), None);
    }

    /// At state-plane offsets unit panels cannot be planar to 1e-10 in f64 (coordinates 2e-9
    /// apart at 1e7): the miss names the coordinates' precision and what to do.
    #[test]
    fn far_from_the_origin_a_planarity_miss_names_the_coordinate_precision() {
        let goals = PhexGoals {
            planarity: Some(1e-10),
            valid: true,
        };
        let far = grid(Vec3::new(3e6, 5e6, 0.0));
        let why = goals.shortfall(&far, 9.2e-9, 10, 0).unwrap();
        assert!(
            why.contains("precision")
                && why.contains("about 1.1e-9")
                && why.contains("near the origin"),
            "{why}"
        );
        // The same miss near the origin is the solver's, not the coordinates'.
        let near = grid(Vec3::zeros());
        let why = goals.shortfall(&near, 9.2e-9, 10, 0).unwrap();
        assert!(!why.contains("precision"), "{why}");
    }
}
