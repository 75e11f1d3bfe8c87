//! A triangle mesh of a smooth surface (a freeform roof exported from a CAD tool with no UVs)
//! made into a [`Surface`] that the P-Hex pipeline panels like a library surface: a mean-value
//! parametrisation onto the unit square, then a faired least-squares bicubic B-spline fit. A
//! mesh of cylinder topology is cut open along a seam first (`cylinder_cut.rs`), the seam put
//! on the sides u = 0 and u = 1, and fitted closed in u, so it has no seam
//! ([`NurbsSurface::closed_in_u`]).
//!
//! Why this route and not a triangulation walking the mesh itself: P-Hex needs second
//! derivatives everywhere (the Dupin indicatrix, P-Hex paper section 3) and closest points
//! with parameters (section 6's distance term); a piecewise-flat mesh has neither, and local
//! quadric fits per vertex (as `MeshSurface` does for curvature) do not give one smooth P(u, v).
//!
//! - Parametrisation: Floater's mean-value coordinates (Floater 2003, "Mean value coordinates")
//!   with the boundary on the unit square by arc length between four corners. The map is
//!   one-to-one for any triangulated disk and a convex boundary polygon (Floater's theorem), the
//!   weights are positive whatever the triangle shapes (cotangent weights are not), and the
//!   system is solved by faer's sparse LU (it is not symmetric).
//! - Fit: a clamped uniform bicubic B-spline net minimising the squared distances at the
//!   vertices plus a thin-plate term on the control net (second differences), the fairness that
//!   also fills control points no vertex reaches; faer's sparse Cholesky solves it.
//! - Reported: the distance from every input vertex to the fitted surface (closest points),
//!   largest and mean, so a user sees how far the panelled surface is from their design.

use super::Surface;
use super::cylinder_cut::cut_open_cylinder;
use super::nurbs::{NurbsDefinition, NurbsError, NurbsSurface, basis_values};
use crate::Vec2;
use crate::mesh::{MeshTopology, PolyMesh, TopologyError};
use faer::Side;
use faer::linalg::solvers::Solve;
use faer::sparse::{SparseColMat, Triplet};
use thiserror::Error;

/// The most triangles a fit takes (the page and a 2-core laptop handle it in seconds).
pub const MAX_FIT_TRIANGLES: usize = 2_000_000;

/// Options of [`fit_mesh_surface`] (builder style: `MeshFitOptions::default().with_fairness(..)`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshFitOptions {
    /// Control points along u and v; `None`: chosen from the vertex count (about one per eight
    /// vertices, at least 8 x 8 in all) and the aspect ratio of the boundary, 4 to 96 along each
    /// direction.
    pub control_points: Option<(usize, usize)>,
    /// Weight of the thin-plate term, relative to the data term per control point (>= 0).
    pub fairness: f64,
}

impl Default for MeshFitOptions {
    fn default() -> Self {
        MeshFitOptions {
            control_points: None,
            fairness: 1e-3,
        }
    }
}

impl MeshFitOptions {
    /// Sets the control net size.
    pub fn with_control_points(mut self, nu: usize, nv: usize) -> Self {
        self.control_points = Some((nu, nv));
        self
    }

    /// Sets the fairness weight.
    pub fn with_fairness(mut self, fairness: f64) -> Self {
        self.fairness = fairness;
        self
    }
}

/// Why a mesh could not be fitted. Vertices and faces are numbered from 1, as in OBJ files.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum MeshFitError {
    /// A face is not a triangle.
    #[error(
        "face {} has {size} corners; a surface is fitted to a triangle mesh (panels are \
         planarised instead)", .face + 1
    )]
    NotTriangles {
        /// 0-based face index.
        face: usize,
        /// Its corner count.
        size: usize,
    },
    /// The mesh is not an oriented manifold.
    #[error("{0}")]
    Topology(#[from] TopologyError),
    /// The mesh is neither one disk-like piece nor one cylinder-like piece.
    #[error(
        "a surface is fitted to one piece with one boundary (a disk, like a roof) or two (a \
         cylinder, like a tube or a vault, cut open along a seam); this mesh has {loops} \
         boundary loops and Euler characteristic {euler} (a disk has 1 loop and 1, a cylinder \
         2 and 0)"
    )]
    NotADisk {
        /// Boundary loops found.
        loops: usize,
        /// V - E + F.
        euler: i64,
    },
    /// The boundary has fewer than the square's four corners.
    #[error(
        "the boundary has {count} vertices; a fit needs at least 4 (the corners of its square)"
    )]
    ShortBoundary {
        /// Boundary vertices.
        count: usize,
    },
    /// A vertex belongs to no triangle.
    #[error("vertex {} is in no triangle; remove it", .vertex + 1)]
    LooseVertex {
        /// 0-based vertex index.
        vertex: usize,
    },
    /// The mesh has more triangles than [`MAX_FIT_TRIANGLES`].
    #[error(
        "{triangles} triangles are more than the limit of {limit} for a surface fit; decimate \
         the mesh in the CAD tool", limit = MAX_FIT_TRIANGLES
    )]
    TooLarge {
        /// Triangles given.
        triangles: usize,
    },
    /// A bad option.
    #[error("{0}")]
    BadOption(String),
    /// A sparse solve failed (a degenerate mesh: triangles of zero area).
    #[error("the fit's linear system could not be solved ({0}); are there triangles of zero area?")]
    Solver(String),
    /// The fitted net is not a valid surface (non-finite coordinates).
    #[error("{0}")]
    Surface(#[from] NurbsError),
}

/// A fitted surface and how far it is from the mesh.
#[derive(Debug, Clone)]
pub struct MeshFit {
    /// The bicubic B-spline surface on [0, 1]².
    pub surface: NurbsSurface,
    /// The parameters of every mesh vertex (the mean-value map).
    pub uv: Vec<Vec2>,
    /// The four boundary vertices put at the corners (0, 0), (1, 0), (1, 1), (0, 1).
    pub corners: [usize; 4],
    /// The largest distance from a mesh vertex to the fitted surface, in the mesh's units.
    pub max_distance: f64,
    /// The mean of those distances.
    pub mean_distance: f64,
}

/// Fits a smooth surface to a triangulated disk or cylinder (see the module documentation).
///
/// Input: an oriented triangle mesh with one boundary loop, or two (a cylinder, cut open along
/// a seam first); output: the surface, the vertex parameters and the fit distances. Errors:
/// [`MeshFitError`].
pub fn fit_mesh_surface(
    mesh: &PolyMesh,
    options: &MeshFitOptions,
) -> Result<MeshFit, MeshFitError> {
    if mesh.num_faces() > MAX_FIT_TRIANGLES {
        return Err(MeshFitError::TooLarge {
            triangles: mesh.num_faces(),
        });
    }
    if !(options.fairness.is_finite() && options.fairness >= 0.0) {
        return Err(MeshFitError::BadOption(format!(
            "fairness {} must be a finite weight >= 0",
            options.fairness
        )));
    }
    for (face, f) in mesh.faces().enumerate() {
        if f.len() != 3 {
            return Err(MeshFitError::NotTriangles {
                face,
                size: f.len(),
            });
        }
    }
    let topo = MeshTopology::new(mesh)?;
    let mut used = vec![false; mesh.num_vertices()];
    for f in mesh.faces() {
        for &v in f {
            used[v as usize] = true;
        }
    }
    if let Some(vertex) = used.iter().position(|u| !u) {
        return Err(MeshFitError::LooseVertex { vertex });
    }
    let loops = boundary_loops(mesh, &topo);
    let euler = mesh.num_vertices() as i64 - topo.edges().len() as i64 + mesh.num_faces() as i64;
    let not_a_disk = MeshFitError::NotADisk {
        loops: loops.len(),
        euler,
    };
    // A cylinder is cut open along a seam into a disk whose corners are the seam's ends.
    let (cut, origin, seam_ends) = match (loops.len(), euler) {
        (1, 1) => (None, None, None),
        (2, 0) => {
            let c = cut_open_cylinder(mesh, &topo, &[loops[0].clone(), loops[1].clone()])
                .ok_or(not_a_disk)?;
            (Some(c.mesh), Some(c.origin), Some(c.ends))
        }
        _ => return Err(not_a_disk),
    };
    let disk = cut.as_ref().unwrap_or(mesh);
    let loops = match &cut {
        Some(d) => boundary_loops(d, &MeshTopology::new(d)?),
        None => loops,
    };
    if loops.len() != 1 {
        return Err(MeshFitError::NotADisk {
            loops: loops.len(),
            euler,
        });
    }
    if loops[0].len() < 4 {
        return Err(MeshFitError::ShortBoundary {
            count: loops[0].len(),
        });
    }
    let boundary = &loops[0];
    let corners = match (seam_ends, &origin) {
        (Some(ends), Some(origin)) => {
            let mut at = ends.map(|e| boundary.iter().position(|&v| v == e).unwrap_or(0));
            at.sort_unstable();
            // The seam must become the sides u = 0 and u = 1 (sides 1 and 3 of
            // `square_boundary`) for the surface to close in u, so side 0, from corner 0 to
            // corner 1, must be a loop's: a seam side has no vertex between its corners, or
            // vertices whose input vertex the boundary holds twice (once on each side).
            let mut times = vec![0u8; mesh.num_vertices()];
            for &v in boundary {
                let o = origin[v as usize] as usize;
                times[o] = times[o].saturating_add(1);
            }
            let next = (at[0] + 1) % boundary.len();
            let side_0_is_seam =
                next == at[1] || times[origin[boundary[next] as usize] as usize] > 1;
            if side_0_is_seam {
                at.rotate_left(1);
            }
            at
        }
        _ => square_corners(disk, boundary),
    };
    let boundary_uv = square_boundary(disk, boundary, &corners);
    let disk_uv = mean_value_map(disk, boundary, &boundary_uv)?;
    let (nu, nv) = match options.control_points {
        Some((nu, nv)) => {
            if !(4..=1000).contains(&nu) || !(4..=1000).contains(&nv) {
                return Err(MeshFitError::BadOption(format!(
                    "{nu} x {nv} control points; use 4 to 1000 along each direction"
                )));
            }
            (nu, nv)
        }
        None => net_size(disk, boundary, &corners),
    };
    // A cylinder's seam is the square's sides u = 0 and u = 1: fitted closed in u, the surface
    // goes all around with no seam, and P-Hex panels it as it panels a library tube.
    let closed_u = seam_ends.is_some();
    let nu = if closed_u { nu.max(8) } else { nu };
    let surface = least_squares_bspline(disk, &disk_uv, nu, nv, options.fairness, closed_u)?;
    // Distances of the input's vertices (a seam vertex at its first copy's parameters).
    let uv = disk_uv[..mesh.num_vertices()].to_vec();
    let (mut max_distance, mut sum) = (0.0f64, 0.0);
    for (p, t) in mesh.positions.iter().zip(&uv) {
        let d = surface
            .closest_point(p, Some(*t))
            .map_or_else(|_| (surface.position(t.x, t.y) - p).norm(), |c| c.distance);
        max_distance = max_distance.max(d);
        sum += d;
    }
    let input_vertex = |v: u32| origin.as_ref().map_or(v, |o| o[v as usize]) as usize;
    Ok(MeshFit {
        surface,
        uv,
        corners: corners.map(|k| input_vertex(boundary[k])),
        max_distance,
        mean_distance: sum / mesh.num_vertices() as f64,
    })
}

/// The boundary loops, each in the direction with the mesh on its left (counter-clockwise seen
/// along the normals).
pub(super) fn boundary_loops(mesh: &PolyMesh, topo: &MeshTopology) -> Vec<Vec<u32>> {
    let corners: usize = mesh.faces().map(<[u32]>::len).sum();
    let mut next_from = vec![u32::MAX; mesh.num_vertices()];
    for c in 0..corners as u32 {
        if topo.opposite(c).is_none() {
            next_from[topo.source(c) as usize] = topo.target(c);
        }
    }
    let mut seen = vec![false; mesh.num_vertices()];
    let mut loops = vec![];
    for start in 0..mesh.num_vertices() {
        if next_from[start] == u32::MAX || seen[start] {
            continue;
        }
        let mut lp = vec![];
        let mut v = start as u32;
        while !seen[v as usize] {
            seen[v as usize] = true;
            lp.push(v);
            v = next_from[v as usize];
        }
        loops.push(lp);
    }
    loops
}

/// Arc length along the boundary loop at each of its vertices from vertex 0, and the perimeter.
fn boundary_arc(mesh: &PolyMesh, boundary: &[u32]) -> (Vec<f64>, f64) {
    let m = boundary.len();
    let p = |k: usize| mesh.positions[boundary[k % m] as usize];
    let mut arc = vec![0.0; m + 1];
    for k in 0..m {
        arc[k + 1] = arc[k] + (p(k + 1) - p(k)).norm();
    }
    let total = arc[m];
    arc.pop();
    (arc, total)
}

/// Picks the four boundary vertices that become the square's corners: corner 0 is the sharpest
/// turn of the loop; corners 1 to 3 the sharpest turns within an eighth of the perimeter of the
/// quarter points after it (a roof exported from a four-sided patch has its corners there; a
/// round boundary gets its quarters). Returns them as positions in `boundary`, in loop order.
fn square_corners(mesh: &PolyMesh, boundary: &[u32]) -> [usize; 4] {
    let m = boundary.len();
    let p = |k: usize| mesh.positions[boundary[k % m] as usize];
    let turn: Vec<f64> = (0..m)
        .map(|k| {
            let a = p(k) - p(k + m - 1);
            let b = p(k + 1) - p(k);
            a.angle(&b)
        })
        .collect();
    let (arc, total) = boundary_arc(mesh, boundary);
    let c0 = (0..m)
        .max_by(|&a, &b| turn[a].total_cmp(&turn[b]).then(b.cmp(&a)))
        .unwrap_or(0);
    let along = |k: usize| (arc[k] - arc[c0]).rem_euclid(total);
    let mut corners = [c0, 0, 0, 0];
    for (q, corner) in corners.iter_mut().enumerate().skip(1) {
        let target = q as f64 * total / 4.0;
        *corner = (0..m)
            .filter(|&k| {
                let a = along(k);
                (a - target).abs() <= total / 8.0
            })
            .max_by(|&a, &b| turn[a].total_cmp(&turn[b]).then(b.cmp(&a)))
            .unwrap_or_else(|| {
                (0..m)
                    .min_by(|&a, &b| {
                        (along(a) - target)
                            .abs()
                            .total_cmp(&(along(b) - target).abs())
                    })
                    .unwrap_or(0)
            });
    }
    // Keep the corners in loop order and distinct (a boundary of few vertices).
    for q in 1..4 {
        if along(corners[q]) <= along(corners[q - 1]) {
            corners[q] = (corners[q - 1] + 1) % m;
        }
    }
    corners
}

/// Places the boundary on the unit square by arc length, `corners` (positions in `boundary`, in
/// loop order) at (0, 0), (1, 0), (1, 1), (0, 1). Returns the boundary vertices' parameters.
fn square_boundary(mesh: &PolyMesh, boundary: &[u32], corners: &[usize; 4]) -> Vec<Vec2> {
    let m = boundary.len();
    let (arc, total) = boundary_arc(mesh, boundary);
    let along = |k: usize| (arc[k] - arc[corners[0]]).rem_euclid(total);
    let square = [
        Vec2::new(0.0, 0.0),
        Vec2::new(1.0, 0.0),
        Vec2::new(1.0, 1.0),
        Vec2::new(0.0, 1.0),
    ];
    let mut uv = vec![Vec2::zeros(); m];
    for side in 0..4 {
        let (a, b) = (corners[side], corners[(side + 1) % 4]);
        let len = (along(b) - along(a)).rem_euclid(total);
        let len = if len == 0.0 { total } else { len };
        let (s0, s1) = (square[side], square[(side + 1) % 4]);
        let mut k = a;
        loop {
            let t = ((along(k) - along(a)).rem_euclid(total) / len).clamp(0.0, 1.0);
            uv[k] = s0 + (s1 - s0) * t;
            k = (k + 1) % m;
            if k == b {
                break;
            }
        }
    }
    uv
}

/// Floater's mean-value map: every interior vertex the weighted mean of its neighbours, weights
/// `(tan(a/2) + tan(b/2)) / |x_j - x_i|` with a, b the angles at i beside edge ij.
fn mean_value_map(
    mesh: &PolyMesh,
    boundary: &[u32],
    boundary_uv: &[Vec2],
) -> Result<Vec<Vec2>, MeshFitError> {
    let n = mesh.num_vertices();
    const BOUNDARY: u32 = u32::MAX;
    let mut fixed = vec![None; n];
    for (k, &v) in boundary.iter().enumerate() {
        fixed[v as usize] = Some(boundary_uv[k]);
    }
    // Interior vertices numbered 0..ni.
    let mut index = vec![BOUNDARY; n];
    let mut ni = 0u32;
    for v in 0..n {
        if fixed[v].is_none() {
            index[v] = ni;
            ni += 1;
        }
    }
    let ni = ni as usize;
    let mut triplets = Vec::with_capacity(7 * ni);
    let mut rhs = faer::Mat::<f64>::zeros(ni, 2);
    for f in mesh.faces() {
        for k in 0..3 {
            let (i, j, l) = (
                f[k] as usize,
                f[(k + 1) % 3] as usize,
                f[(k + 2) % 3] as usize,
            );
            let row = index[i];
            if row == BOUNDARY {
                continue;
            }
            let x = mesh.positions[i];
            let (ej, el) = (mesh.positions[j] - x, mesh.positions[l] - x);
            let (lj, ll) = (ej.norm(), el.norm());
            // tan(theta / 2) = (1 - cos) / sin = (|a||b| - a.b) / |a x b|.
            let half_tan = (lj * ll - ej.dot(&el)) / ej.cross(&el).norm();
            for (other, len) in [(j, lj), (l, ll)] {
                let w = half_tan / len;
                if !w.is_finite() {
                    return Err(MeshFitError::Solver(format!(
                        "the triangle at vertex {} has zero area",
                        i + 1
                    )));
                }
                triplets.push(Triplet::new(row, row, w));
                match fixed[other] {
                    Some(t) => {
                        rhs[(row as usize, 0)] += w * t.x;
                        rhs[(row as usize, 1)] += w * t.y;
                    }
                    None => triplets.push(Triplet::new(row, index[other], -w)),
                }
            }
        }
    }
    // Each row divided by its diagonal (the vertex's total weight): the row becomes "the vertex
    // minus a convex combination of its neighbours", diagonally dominant with a unit diagonal, so
    // the LU's partial pivoting keeps the diagonal. Unscaled, a sliver triangle (an angle near
    // 180 degrees, weight ~1e16) made it pivot on a neighbour's small entry and put a vertex at
    // u = 18, far outside the square Floater's theorem promises.
    let mut diagonal = vec![0.0; ni];
    for t in &triplets {
        if t.row == t.col {
            diagonal[t.row as usize] += t.val;
        }
    }
    for t in &mut triplets {
        t.val /= diagonal[t.row as usize];
    }
    for (r, d) in diagonal.iter().enumerate() {
        rhs[(r, 0)] /= d;
        rhs[(r, 1)] /= d;
    }
    let mut uv: Vec<Vec2> = fixed
        .iter()
        .map(|f| f.unwrap_or_else(Vec2::zeros))
        .collect();
    if ni > 0 {
        let a = SparseColMat::<u32, f64>::try_new_from_triplets(ni, ni, &triplets)
            .map_err(|e| MeshFitError::Solver(format!("{e:?}")))?;
        let lu = a
            .sp_lu()
            .map_err(|e| MeshFitError::Solver(format!("{e:?}")))?;
        let x = lu.solve(&rhs);
        for v in 0..n {
            if index[v] != BOUNDARY {
                let r = index[v] as usize;
                uv[v] = Vec2::new(x[(r, 0)], x[(r, 1)]);
            }
        }
    }
    if uv.iter().any(|t| !(t.x.is_finite() && t.y.is_finite())) {
        return Err(MeshFitError::Solver("the parameters are not finite".into()));
    }
    Ok(uv)
}

/// Control points along u and v from the vertex count and the boundary's aspect ratio.
fn net_size(mesh: &PolyMesh, boundary: &[u32], corners: &[usize; 4]) -> (usize, usize) {
    let m = boundary.len();
    let side = |s: usize| {
        let (a, b) = (corners[s], corners[(s + 1) % 4]);
        let mut len = 0.0;
        let mut k = a;
        while k != b {
            let (p, q) = (boundary[k] as usize, boundary[(k + 1) % m] as usize);
            len += (mesh.positions[q] - mesh.positions[p]).norm();
            k = (k + 1) % m;
        }
        len
    };
    let (lu, lv) = (side(0) + side(2), side(1) + side(3));
    let total = (mesh.num_vertices() as f64 / 8.0).max(64.0);
    let ratio = (lu / lv).clamp(0.05, 20.0);
    let nu = (total * ratio).sqrt().round() as usize;
    let nv = (total / ratio).sqrt().round() as usize;
    (nu.clamp(4, 96), nv.clamp(4, 96))
}

/// Clamped uniform cubic knots on [0, 1] for `n` control points.
fn uniform_knots(n: usize) -> Vec<f64> {
    let spans = n - 3;
    let mut k = vec![0.0; 4];
    k.extend((1..spans).map(|i| i as f64 / spans as f64));
    k.extend([1.0; 4]);
    k
}

/// The u knots of a cubic B-spline closed in u with `n` distinct control rows written out as
/// `n + 3` rows: uniformly spaced with no end multiplicity, the domain [0, 1] between knots 3
/// and `n + 3`.
fn closed_knots(n: usize) -> Vec<f64> {
    (0..n + 7).map(|k| (k as f64 - 3.0) / n as f64).collect()
}

/// The least-squares bicubic net with thin-plate fairness (`nu` x `nv` unknown control points;
/// `closed_u`: rows wrap around, `nu` >= 8, and the net is written out closed in u). The normal
/// matrix couples control points at most 3 apart in each direction, so it is kept as a 7 x 7
/// stencil per control point while the data is summed, then handed to faer as its lower
/// triangle.
fn least_squares_bspline(
    mesh: &PolyMesh,
    uv: &[Vec2],
    nu: usize,
    nv: usize,
    fairness: f64,
    closed_u: bool,
) -> Result<NurbsSurface, MeshFitError> {
    let (rows_u, ku) = if closed_u {
        (nu + 3, closed_knots(nu))
    } else {
        (nu, uniform_knots(nu))
    };
    let kv = uniform_knots(nv);
    let n = nu * nv;
    let mut stencil = vec![[0.0f64; 49]; n];
    let mut rhs = faer::Mat::<f64>::zeros(n, 3);
    let at = |di: isize, dj: isize| ((di + 3) * 7 + dj + 3) as usize;
    // The unknown row of written-out row `i`, and the offset from row `i` to row `i2` (both
    // unknown rows; around a closed net the short way, which is unique for nu >= 7).
    let row_of = |i: usize| if closed_u { i % nu } else { i };
    let offset = |i: usize, i2: usize| -> isize {
        let d = i2 as isize - i as isize;
        if closed_u {
            let d = d.rem_euclid(nu as isize);
            if d > nu as isize / 2 {
                d - nu as isize
            } else {
                d
            }
        } else {
            d
        }
    };
    for (p, t) in mesh.positions.iter().zip(uv) {
        let (su, bu) = basis_values(&ku, rows_u, 3, t.x);
        let (sv, bv) = basis_values(&kv, nv, 3, t.y);
        for r in 0..4 {
            for s in 0..4 {
                let (i, j) = (row_of(su - 3 + r), sv - 3 + s);
                let w = bu[r] * bv[s];
                let row = i * nv + j;
                for c in 0..3 {
                    rhs[(row, c)] += w * p[c];
                }
                for (r2, b) in bu.iter().enumerate() {
                    let di = offset(i, row_of(su - 3 + r2));
                    for (s2, c) in bv.iter().enumerate() {
                        stencil[row][at(di, s2 as isize - s as isize)] += w * b * c;
                    }
                }
            }
        }
    }
    // Thin plate on the net: (d2/du2)^2 + 2 (d2/dudv)^2 + (d2/dv2)^2 as differences, weighted
    // by the data per control point so the balance does not depend on the sampling density.
    let lambda = fairness * mesh.num_vertices() as f64 / n as f64;
    let mut add = |cells: &[((usize, usize), f64)], weight: f64| {
        for &((i, j), a) in cells {
            for &((i2, j2), b) in cells {
                let (i, i2) = (row_of(i), row_of(i2));
                let (di, dj) = (offset(i, i2), j2 as isize - j as isize);
                stencil[i * nv + j][at(di, dj)] += weight * a * b;
            }
        }
    };
    // Around a closed net the differences wrap (rows nu and nu + 1 are rows 0 and 1).
    let last = if closed_u { nu + 1 } else { 0 };
    for i in 0..nu {
        for j in 0..nv {
            if i + 2 < nu + last {
                add(
                    &[((i, j), 1.0), ((i + 1, j), -2.0), ((i + 2, j), 1.0)],
                    lambda,
                );
            }
            if j + 2 < nv {
                add(
                    &[((i, j), 1.0), ((i, j + 1), -2.0), ((i, j + 2), 1.0)],
                    lambda,
                );
            }
            if i + 1 < nu + last.min(1) && j + 1 < nv {
                let cells = [
                    ((i, j), 1.0),
                    ((i + 1, j), -1.0),
                    ((i, j + 1), -1.0),
                    ((i + 1, j + 1), 1.0),
                ];
                add(&cells, 2.0 * lambda);
            }
        }
    }
    let mut triplets = Vec::with_capacity(25 * n);
    for i in 0..nu {
        for j in 0..nv {
            let col = i * nv + j;
            for di in -3isize..=3 {
                for dj in -3isize..=3 {
                    let (mut i2, j2) = (i as isize + di, j as isize + dj);
                    if closed_u {
                        i2 = i2.rem_euclid(nu as isize);
                    }
                    if i2 < 0 || j2 < 0 || i2 >= nu as isize || j2 >= nv as isize {
                        continue;
                    }
                    let row = i2 as usize * nv + j2 as usize;
                    let v = stencil[col][at(di, dj)];
                    if row >= col && v != 0.0 {
                        triplets.push(Triplet::new(row as u32, col as u32, v));
                    }
                }
            }
        }
    }
    // A control point no vertex reaches and no fairness term holds (fairness 0 and a hole in
    // the data) makes the matrix singular: the solve then fails with that message.
    let a = SparseColMat::<u32, f64>::try_new_from_triplets(n, n, &triplets)
        .map_err(|e| MeshFitError::Solver(format!("{e:?}")))?;
    let llt = a.sp_cholesky(Side::Lower).map_err(|e| {
        MeshFitError::Solver(format!(
            "{e:?}: some control points have no data; raise the fairness or use fewer control points"
        ))
    })?;
    let x = llt.solve(&rhs);
    let control_points = (0..rows_u)
        .map(|i| {
            (0..nv)
                .map(|j| {
                    let r = row_of(i) * nv + j;
                    [x[(r, 0)], x[(r, 1)], x[(r, 2)]]
                })
                .collect()
        })
        .collect();
    let surface = NurbsSurface::try_from(NurbsDefinition {
        degree_u: 3,
        degree_v: 3,
        knots_u: ku,
        knots_v: kv,
        control_points,
        weights: None,
        unit: None,
    })?;
    Ok(if closed_u {
        surface.closed_in_u()?
    } else {
        surface
    })
}
