//! The least-squares and constraint problems of the PQ perturbation (conical paper, Sec. 2.2,
//! eqs. (3), (5), (6), (7)): the unknowns (vertex positions and one plane per face of 4+
//! vertices), the penalty rows, the exact constraints, and the rows' two emitters (block
//! gradients for Gauss-Newton, triplets for SQP).

use super::options::{PqError, PqMode, PqOptions};
use crate::Vec3;
use crate::conical::discrete_terms::{angle_grad, quad_det_grad};
use crate::mesh::{MeshTopology, PolyMesh, least_squares_plane};
use crate::solver::{
    BlockLayout, BlockLeastSquares, BlockSystem, ConstrainedLeastSquares, SolverError, SparseSystem,
};
use std::f64::consts::PI;

/// Marks a vertex without unknowns (fixed) or a face without a plane.
pub(super) const NONE: u32 = u32::MAX;

/// Static data of the objective and constraints.
pub(super) struct Terms {
    pub(super) var_of: Vec<u32>,
    /// Per face: first of its 4 plane variables (unit normal n, offset d), or NONE.
    pub(super) plane_of: Vec<u32>,
    /// Per face: the initial centroid, origin of the face's plane offset.
    pub(super) centers: Vec<Vec3>,
    /// Index of the first plane variable (all vertex variables come before).
    pub(super) first_plane: usize,
    /// Whether the solver should eliminate the plane unknowns (all planar faces are quads).
    pub(super) eliminate_planes: bool,
    pub(super) num_vars: usize,
    /// The unknowns as blocks: one of 3 per vertex variable, then one of 4 per plane.
    pub(super) layout: BlockLayout,
    pub(super) convex: Vec<bool>,
    pub(super) conical_vertices: Vec<usize>,
    /// Fairness stencils: (start offsets, (vertex, coefficient)).
    pub(super) stencil_start: Vec<usize>,
    pub(super) stencil: Vec<(u32, f64)>,
    pub(super) normals0: Vec<Vec3>,
    pub(super) positions0: Vec<Vec3>,
    pub(super) scale: f64,
    /// [`PqOptions::keep_design`].
    pub(super) keep_design: bool,
    /// Per variable (with `keep_design`): 1 for positions and plane offsets, L² for the unit
    /// normals.
    pub(super) damping_weights: Vec<f64>,
}

/// The penalty and constraint rows of one iteration: the mesh, its unknowns and the current
/// fairness and closeness weights.
pub(super) struct Problem<'a> {
    pub(super) mesh: &'a PolyMesh,
    pub(super) topo: &'a MeshTopology,
    pub(super) terms: &'a Terms,
    pub(super) mode: PqMode,
    pub(super) determinant_terms: bool,
    pub(super) w_fair: f64,
    pub(super) w_close: f64,
}

/// Where a [`Problem`] writes its rows: per-block gradients for the Gauss-Newton solver, or
/// scalar triplets for the SQP refinement (one emission code for both).
trait Rows {
    /// Starts a row with the given value.
    fn row(&mut self, value: f64);
    /// Starts a row whose vertex gradients all point along coordinate `axis`.
    fn axis_row(&mut self, value: f64, axis: u8) {
        let _ = axis;
        self.row(value);
    }
    /// Sets the value of the current row.
    fn set_value(&mut self, value: f64);
    /// Adds `g` (3 components for a vertex, 4 for a plane) to the current row's gradient
    /// with respect to the block whose first variable is `var`.
    fn add(&mut self, var: u32, g: [f64; 4]);
}

struct BlockRows<'a> {
    sys: &'a mut BlockSystem,
    terms: &'a Terms,
}

impl Rows for BlockRows<'_> {
    #[inline(always)]
    fn row(&mut self, value: f64) {
        self.sys.push_row(value);
    }
    #[inline(always)]
    fn axis_row(&mut self, value: f64, axis: u8) {
        self.sys.push_axis_row(value, axis);
    }
    #[inline(always)]
    fn set_value(&mut self, value: f64) {
        if let Some(r) = self.sys.residuals.last_mut() {
            *r = value;
        }
    }
    #[inline(always)]
    fn add(&mut self, var: u32, g: [f64; 4]) {
        self.sys.add(self.terms.block_of_var(var), g);
    }
}

struct TripletRows<'a> {
    sys: &'a mut SparseSystem,
    first_plane: usize,
}

impl Rows for TripletRows<'_> {
    fn row(&mut self, value: f64) {
        self.sys.push_residual(value);
    }
    fn set_value(&mut self, value: f64) {
        if let Some(r) = self.sys.residuals.last_mut() {
            *r = value;
        }
    }
    fn add(&mut self, var: u32, g: [f64; 4]) {
        let row = self.sys.residuals.len() as u32 - 1;
        let size = if (var as usize) < self.first_plane {
            3
        } else {
            4
        };
        for (k, &gk) in g.iter().enumerate().take(size) {
            self.sys.push_entry(row, var + k as u32, gk);
        }
    }
}

impl Terms {
    /// The block of the variables starting at `var` (vertex blocks of 3, then planes of 4).
    #[inline]
    fn block_of_var(&self, var: u32) -> u32 {
        let fp = self.first_plane as u32;
        if var < fp {
            var / 3
        } else {
            fp / 3 + (var - fp) / 4
        }
    }
}

impl Problem<'_> {
    #[inline]
    fn pos(&self, x: &[f64], v: u32) -> Vec3 {
        let b = self.terms.var_of[v as usize];
        if b == NONE {
            self.mesh.positions[v as usize]
        } else {
            let b = b as usize;
            Vec3::new(x[b], x[b + 1], x[b + 2])
        }
    }

    /// Adds the gradient `g` with respect to vertex `v` (nothing for a fixed vertex).
    #[inline(always)]
    fn emit<O: Rows>(&self, out: &mut O, v: u32, g: Vec3) {
        let b = self.terms.var_of[v as usize];
        if b != NONE {
            out.add(b, [g.x, g.y, g.z, 0.0]);
        }
    }

    /// Determinant terms of face `f`: every three consecutive unit edge vectors.
    fn dets<O: Rows>(&self, x: &[f64], f: usize, out: &mut O) {
        let face = self.mesh.face(f);
        let n = face.len();
        if n < 4 {
            return;
        }
        for k in 0..n {
            let idx = [k, (k + 1) % n, (k + 2) % n, (k + 3) % n];
            let (d, g) = quad_det_grad(idx.map(|i| self.pos(x, face[i])));
            out.row(d);
            for (j, &i) in idx.iter().enumerate() {
                self.emit(out, face[i], g[j]);
            }
        }
    }

    /// Face-plane terms of face `f`: `(n·(v - c) - d) / L` per vertex and `|n|² - 1`, with `c`
    /// the face's initial centroid (so the offset `d` stays near 0 and the derivatives in `n`
    /// are of the face's size rather than of its distance to the origin: far better
    /// conditioned normal equations).
    fn planes<O: Rows>(&self, x: &[f64], f: usize, out: &mut O) {
        let pb = self.terms.plane_of[f];
        if pb == NONE {
            return;
        }
        let b = pb as usize;
        let n = Vec3::new(x[b], x[b + 1], x[b + 2]);
        let d = x[b + 3];
        let inv = 1.0 / self.terms.scale;
        let c = self.terms.centers[f];
        for &v in self.mesh.face(f) {
            let p = self.pos(x, v) - c;
            out.row((n.dot(&p) - d) * inv);
            self.emit(out, v, n * inv);
            out.add(pb, [p.x * inv, p.y * inv, p.z * inv, -inv]);
        }
        out.row(n.norm_squared() - 1.0);
        out.add(pb, [2.0 * n.x, 2.0 * n.y, 2.0 * n.z, 0.0]);
    }

    /// Sum over corners `ks` of face `f` of the corner angles, minus `target`.
    fn angle_sum<O: Rows>(&self, x: &[f64], f: usize, ks: &[usize], target: f64, out: &mut O) {
        let face = self.mesh.face(f);
        let n = face.len();
        // The row's value is known after its gradients: start it at 0 and set it at the end.
        out.row(0.0);
        let mut sum = -target;
        for &k in ks {
            let (a, b) = ((k + n - 1) % n, (k + 1) % n);
            let (w, g) = angle_grad(
                self.pos(x, face[k]),
                self.pos(x, face[a]),
                self.pos(x, face[b]),
            );
            sum += w;
            self.emit(out, face[k], g[0]);
            self.emit(out, face[a], g[1]);
            self.emit(out, face[b], g[2]);
        }
        out.set_value(sum);
    }

    /// The angle balance `w1 - w2 + w3 - w4` of eq. (6) at every interior valence-4 vertex.
    fn conical<O: Rows>(&self, x: &[f64], out: &mut O) {
        for &v in &self.terms.conical_vertices {
            out.row(0.0);
            let mut sum = 0.0;
            for (k, &c) in self.topo.star(v).iter().enumerate() {
                let a = self.topo.source(self.topo.prev(c));
                let b = self.topo.target(c);
                let (w, g) = angle_grad(self.pos(x, v as u32), self.pos(x, a), self.pos(x, b));
                let s = if k % 2 == 0 { 1.0 } else { -1.0 };
                sum += s * w;
                self.emit(out, v as u32, g[0] * s);
                self.emit(out, a, g[1] * s);
                self.emit(out, b, g[2] * s);
            }
            out.set_value(sum);
        }
    }

    fn fairness_closeness<O: Rows>(&self, x: &[f64], out: &mut O) {
        let t = self.terms;
        if self.w_fair > 0.0 {
            let s = self.w_fair.sqrt() / t.scale;
            for i in 0..t.stencil_start.len() - 1 {
                let st = &t.stencil[t.stencil_start[i]..t.stencil_start[i + 1]];
                let mut val = Vec3::zeros();
                for &(v, c) in st {
                    val += c * self.pos(x, v);
                }
                if t.keep_design {
                    for &(v, c) in st {
                        val -= c * t.positions0[v as usize];
                    }
                }
                for k in 0..3 {
                    out.axis_row(s * val[k], k as u8);
                    for &(v, c) in st {
                        let mut g = Vec3::zeros();
                        g[k] = s * c;
                        self.emit(out, v, g);
                    }
                }
            }
        }
        if self.w_close > 0.0 {
            let s = self.w_close.sqrt() / t.scale;
            for v in 0..t.var_of.len() {
                if t.var_of[v] == NONE {
                    continue;
                }
                let n = t.normals0[v];
                let d = (self.pos(x, v as u32) - t.positions0[v]).dot(&n);
                out.row(s * d);
                self.emit(out, v as u32, s * n);
            }
        }
    }

    /// The penalty objective of eq. (5) (with the plane terms).
    fn penalty<O: Rows>(&self, x: &[f64], out: &mut O) {
        for f in 0..self.mesh.num_faces() {
            let n = self.mesh.face(f).len();
            if self.mode == PqMode::Circular && n == 4 {
                self.angle_sum(x, f, &[0, 2], PI, out);
                self.angle_sum(x, f, &[1, 3], PI, out);
            } else if self.terms.convex[f] && n > 3 {
                let ks: Vec<usize> = (0..n).collect();
                self.angle_sum(x, f, &ks, (n as f64 - 2.0) * PI, out);
            }
            if self.determinant_terms {
                self.dets(x, f, out);
            }
            self.planes(x, f, out);
        }
        if self.mode == PqMode::Conical {
            self.conical(x, out);
        }
        self.fairness_closeness(x, out);
    }

    /// The exact constraints: planes, and the circular or conical angle conditions.
    fn constraint_rows<O: Rows>(&self, x: &[f64], out: &mut O) {
        for f in 0..self.mesh.num_faces() {
            self.planes(x, f, out);
            if self.mode == PqMode::Circular && self.mesh.face(f).len() == 4 {
                self.angle_sum(x, f, &[0, 2], PI, out);
            }
        }
        if self.mode == PqMode::Conical {
            self.conical(x, out);
        }
    }

    /// A step's metric with [`PqOptions::keep_design`]: a plane normal's change weighs as the
    /// move of points at the mean edge's distance.
    fn damping_weights(&self) -> Option<&[f64]> {
        self.terms
            .keep_design
            .then_some(self.terms.damping_weights.as_slice())
    }

    /// The 4 plane unknowns of a face are seen by that face's plane residuals only: the
    /// solver eliminates them and factors a matrix on the vertex unknowns. Done for quad
    /// meshes only: eliminating the plane of an n-gon couples all its 3n vertex unknowns,
    /// which for hexagons costs more fill than the 4 unknowns save.
    fn local_from(&self) -> usize {
        if self.terms.eliminate_planes {
            self.terms.first_plane / 3
        } else {
            self.terms.layout.num_blocks()
        }
    }
}

impl BlockLeastSquares for Problem<'_> {
    fn layout(&self) -> &BlockLayout {
        &self.terms.layout
    }
    fn local_from(&self) -> usize {
        Problem::local_from(self)
    }
    fn damping_weights(&self) -> Option<&[f64]> {
        Problem::damping_weights(self)
    }
    fn evaluate(&self, x: &[f64], out: &mut BlockSystem) -> Result<(), SolverError> {
        self.penalty(
            x,
            &mut BlockRows {
                sys: out,
                terms: self.terms,
            },
        );
        Ok(())
    }
}

impl ConstrainedLeastSquares for Problem<'_> {
    fn num_variables(&self) -> usize {
        self.terms.num_vars
    }
    fn objective(&self, x: &[f64], out: &mut SparseSystem) {
        self.fairness_closeness(
            x,
            &mut TripletRows {
                sys: out,
                first_plane: self.terms.first_plane,
            },
        );
    }
    fn constraints(&self, x: &[f64], out: &mut SparseSystem) {
        self.constraint_rows(
            x,
            &mut TripletRows {
                sys: out,
                first_plane: self.terms.first_plane,
            },
        );
    }
    /// The plane constraints `(n·v - d)/L` are bilinear: their Hessian couples v and n by
    /// `I/L`; `|n|² - 1` has Hessian `2I` on n. Angle constraints keep the Gauss-Newton part.
    fn constraint_hessian(&self, _x: &[f64], nu: &[f64], out: &mut Vec<(u32, u32, f64)>) {
        let inv = 1.0 / self.terms.scale;
        let mut row = 0usize;
        for f in 0..self.mesh.num_faces() {
            let face = self.mesh.face(f);
            let pb = self.terms.plane_of[f];
            if pb != NONE {
                for &v in face {
                    let vb = self.terms.var_of[v as usize];
                    if vb != NONE {
                        for k in 0..3 {
                            let w = nu[row] * inv;
                            out.push((vb + k, pb + k, w));
                            out.push((pb + k, vb + k, w));
                        }
                    }
                    row += 1;
                }
                for k in 0..3 {
                    out.push((pb + k, pb + k, 2.0 * nu[row]));
                }
                row += 1;
            }
            if self.mode == PqMode::Circular && face.len() == 4 {
                row += 1;
            }
        }
    }
}

/// The exact constraints of the SQP phase as a least-squares problem (Gauss-Newton
/// refinement).
pub(super) struct Feasibility<'a, 'b>(pub(super) &'a Problem<'b>);

impl BlockLeastSquares for Feasibility<'_, '_> {
    fn layout(&self) -> &BlockLayout {
        &self.0.terms.layout
    }
    fn local_from(&self) -> usize {
        self.0.local_from()
    }
    fn damping_weights(&self) -> Option<&[f64]> {
        self.0.damping_weights()
    }
    fn evaluate(&self, x: &[f64], out: &mut BlockSystem) -> Result<(), SolverError> {
        self.0.constraint_rows(
            x,
            &mut BlockRows {
                sys: out,
                terms: self.0.terms,
            },
        );
        Ok(())
    }
}

/// A face plane's start: face, unit normal, offset from the face's centroid.
type PlaneStart = (usize, Vec3, f64);

impl Terms {
    /// The unknowns and static data of the problem on `mesh`, and the unknowns' start values
    /// (the input positions, each face's plane through its centroid).
    ///
    /// Errors, checked in this order: a fixed vertex out of range, a mesh without what the mode
    /// needs (interior valence-4 vertices, quads), an identified vertex out of range.
    pub(super) fn new(
        mesh: &PolyMesh,
        topo: &MeshTopology,
        o: &PqOptions,
    ) -> Result<(Terms, Vec<f64>), PqError> {
        let nv = mesh.num_vertices();
        for &i in &o.fixed_vertices {
            if i >= nv {
                return Err(PqError::FixedVertexOutOfRange {
                    index: i,
                    vertices: nv,
                });
            }
        }
        let conical_vertices = topo.interior_valence4();
        match o.mode {
            PqMode::Conical if conical_vertices.is_empty() => return Err(PqError::NoConicalVertex),
            PqMode::Circular if !mesh.faces().any(|f| f.len() == 4) => {
                return Err(PqError::NoQuadFace);
            }
            _ => {}
        }
        let (var_of, used, first_plane) = vertex_unknowns(mesh, topo, o)?;
        let (plane_of, centers, plane_init, num_vars) = face_planes(mesh, first_plane);
        let (normals0, convex) = start_normals_and_convexity(mesh);
        let (stencil_start, stencil) = fairness_stencils(topo, &used);
        let scale = mean_edge_length(mesh, topo);
        let x = start_values(mesh, &var_of, &plane_of, plane_init, num_vars);
        let mut damping_weights = vec![1.0; if o.keep_design { num_vars } else { 0 }];
        for &pb in plane_of.iter().filter(|_| o.keep_design) {
            if pb != NONE {
                for k in 0..3 {
                    damping_weights[pb as usize + k] = scale * scale;
                }
            }
        }
        let terms = Terms {
            damping_weights,
            plane_of,
            first_plane,
            centers,
            eliminate_planes: mesh.faces().all(|f| f.len() <= 4),
            layout: BlockLayout::new(
                std::iter::repeat_n(3, first_plane / 3)
                    .chain(std::iter::repeat_n(4, (num_vars - first_plane) / 4)),
            ),
            var_of,
            num_vars,
            convex,
            conical_vertices,
            stencil_start,
            stencil,
            normals0,
            positions0: mesh.positions.clone(),
            scale,
            keep_design: o.keep_design,
        };
        Ok((terms, x))
    }
}

/// The first variable of every vertex (3 each; [`NONE`] for fixed and unused vertices,
/// identified vertices share one), which vertices faces use, and the number of vertex
/// variables.
fn vertex_unknowns(
    mesh: &PolyMesh,
    topo: &MeshTopology,
    o: &PqOptions,
) -> Result<(Vec<u32>, Vec<bool>, usize), PqError> {
    let nv = mesh.num_vertices();
    let mut fixed = vec![false; nv];
    for &i in &o.fixed_vertices {
        fixed[i] = true;
    }
    let mut used = vec![false; nv];
    for f in mesh.faces() {
        for &v in f {
            used[v as usize] = true;
        }
    }
    let mut var_of = vec![NONE; nv];
    let mut num_vars = 0usize;
    for v in 0..nv {
        if used[v] && !fixed[v] && !(o.fix_boundary && topo.is_boundary(v)) {
            var_of[v] = num_vars as u32;
            num_vars += 3;
        }
    }
    for &(i, j) in &o.identify {
        if i >= nv || j >= nv {
            return Err(PqError::FixedVertexOutOfRange {
                index: i.max(j),
                vertices: nv,
            });
        }
        if var_of[i] != NONE && var_of[j] != NONE {
            var_of[j] = var_of[i];
        } else {
            var_of[i] = NONE;
            var_of[j] = NONE;
        }
    }
    Ok((var_of, used, num_vars))
}

/// One plane (4 variables from `first_plane` on) per face of 4+ vertices: the first variable
/// per face ([`NONE`] for triangles), the face centroids, the planes' starts, and the total
/// number of variables.
fn face_planes(
    mesh: &PolyMesh,
    first_plane: usize,
) -> (Vec<u32>, Vec<Vec3>, Vec<PlaneStart>, usize) {
    let p = &mesh.positions;
    let mut num_vars = first_plane;
    let mut centers = vec![Vec3::zeros(); mesh.num_faces()];
    let mut plane_of = vec![NONE; mesh.num_faces()];
    let mut plane_init = Vec::new();
    for (f, face) in mesh.faces().enumerate() {
        if face.len() >= 4 {
            plane_of[f] = num_vars as u32;
            num_vars += 4;
            let pts: Vec<Vec3> = face.iter().map(|&v| p[v as usize]).collect();
            // The Newell normal through the centroid: as good a start as the least-squares
            // plane for the near-planar faces met here, without an eigen-solve per face.
            let c = pts.iter().sum::<Vec3>() / pts.len() as f64;
            centers[f] = c;
            let (n, d) = match newell(&pts).try_normalize(1e-300) {
                Some(n) => (n, 0.0),
                None => {
                    // Degenerate (zero-area) face: the least-squares plane, oriented along
                    // the Newell normal.
                    let (centroid, n) = least_squares_plane(pts.iter().copied());
                    let n = if n.dot(&newell(&pts)) < 0.0 { -n } else { n };
                    (n, n.dot(&centroid) - n.dot(&c))
                }
            };
            plane_init.push((f, n, d));
        }
    }
    (plane_of, centers, plane_init, num_vars)
}

/// The input's area-weighted vertex normals (closeness term) and which faces are convex
/// (angle-sum term).
fn start_normals_and_convexity(mesh: &PolyMesh) -> (Vec<Vec3>, Vec<bool>) {
    let p = &mesh.positions;
    let mut normals0 = vec![Vec3::zeros(); mesh.num_vertices()];
    let mut convex = Vec::with_capacity(mesh.num_faces());
    for f in mesh.faces() {
        let pts: Vec<Vec3> = f.iter().map(|&v| p[v as usize]).collect();
        let nrm = newell(&pts);
        for &v in f {
            normals0[v as usize] += nrm;
        }
        convex.push(is_convex(&pts));
    }
    for n in &mut normals0 {
        *n = n.try_normalize(0.0).unwrap_or_else(Vec3::zeros);
    }
    (normals0, convex)
}

/// The fairness stencils (start offsets, (vertex, coefficient)): second differences through
/// opposite neighbours at even valence and along the boundary, the umbrella Laplacian at odd
/// valence.
fn fairness_stencils(topo: &MeshTopology, used: &[bool]) -> (Vec<usize>, Vec<(u32, f64)>) {
    let mut stencil_start = vec![0];
    let mut stencil = Vec::new();
    #[allow(clippy::needless_range_loop)]
    for v in 0..used.len() {
        if !used[v] {
            continue;
        }
        let nb = topo.neighbors(v);
        let k = nb.len();
        if topo.is_boundary(v) {
            if k >= 2 {
                stencil.extend([(nb[0], 1.0), (nb[k - 1], 1.0), (v as u32, -2.0)]);
                stencil_start.push(stencil.len());
            }
        } else if k.is_multiple_of(2) {
            for i in 0..k / 2 {
                stencil.extend([(nb[i], 1.0), (nb[i + k / 2], 1.0), (v as u32, -2.0)]);
                stencil_start.push(stencil.len());
            }
        } else if k > 0 {
            stencil.extend(nb.iter().map(|&u| (u, 1.0 / k as f64)));
            stencil.push((v as u32, -1.0));
            stencil_start.push(stencil.len());
        }
    }
    (stencil_start, stencil)
}

/// Mean edge length L of the input (1 without edges): the length unit of the residuals.
fn mean_edge_length(mesh: &PolyMesh, topo: &MeshTopology) -> f64 {
    let p = &mesh.positions;
    let edges = topo.edges();
    if edges.is_empty() {
        1.0
    } else {
        edges
            .iter()
            .map(|&(a, b)| (p[a as usize] - p[b as usize]).norm())
            .sum::<f64>()
            / edges.len() as f64
    }
}

/// The unknowns at the start: the input positions and the face planes' starts.
fn start_values(
    mesh: &PolyMesh,
    var_of: &[u32],
    plane_of: &[u32],
    plane_init: Vec<PlaneStart>,
    num_vars: usize,
) -> Vec<f64> {
    let p = &mesh.positions;
    let mut x = vec![0.0; num_vars];
    for v in 0..mesh.num_vertices() {
        if var_of[v] != NONE {
            let b = var_of[v] as usize;
            x[b..b + 3].copy_from_slice(p[v].as_slice());
        }
    }
    for (f, n, d) in plane_init {
        let b = plane_of[f] as usize;
        x[b..b + 3].copy_from_slice(n.as_slice());
        x[b + 3] = d;
    }
    x
}

/// Newell normal (area-weighted) of a polygon.
fn newell(pts: &[Vec3]) -> Vec3 {
    let n = pts.len();
    let mut s = Vec3::zeros();
    for k in 0..n {
        s += pts[k].cross(&pts[(k + 1) % n]);
    }
    s * 0.5
}

fn is_convex(pts: &[Vec3]) -> bool {
    let nrm = newell(pts);
    let n = pts.len();
    (0..n).all(|k| {
        let a = pts[(k + 1) % n] - pts[k];
        let b = pts[(k + 2) % n] - pts[(k + 1) % n];
        a.cross(&b).dot(&nrm) > 0.0
    })
}
