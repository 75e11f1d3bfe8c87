//! The least move onto planar faces, solved in face space (conical paper, Sec. 2.2: "a PQ mesh
//! near the given one"): the exact phase of a live edit of a quad mesh, of a design kept near
//! planar ([`super::PqOptions::keep_design`]) from its first step, and of a P-Hex mesh that
//! starts near planar (`phex/planarity_optimisation.rs`).
//!
//! Input: the solver-frame positions of a polygon mesh, its free vertices (the anchors and
//! held vertices have no unknowns) and the unknowns' layout; output: one Gauss-Newton step on
//! the constraints `det(ê₀, ê₁, ê₂) = 0` per quad (unit vectors along three consecutive edges,
//! zero exactly when the quad is planar), `n - 3` of them per polygon of `n > 4` vertices (see
//! [`planarity_rows`]), of least Euclidean length:
//!
//! `Δx = -Jᵀ λ`, `(J Jᵀ) λ = c`,
//!
//! with `c` the determinants and `J` their gradients with respect to the free vertices. The
//! matrix `J Jᵀ` has one unknown per determinant (its multiplier `λ`), coupled to those
//! sharing a vertex with it. The exact phase of [`super::PqPerturbation`] solves the same
//! least-move problem on the vertex positions and one plane per face, its normal matrix one
//! 3 x 3 block per vertex after the planes are eliminated: on quads three times the unknowns
//! on the same graph, so its supernodal factor takes about 27 times the floating-point work of
//! this one (a 10 000-quad grid: 60 ms natively per factorisation on an AVX-512 machine; a
//! whole step here, evaluation and assembly included, takes about 15 ms). A live edit
//! moves a vertex of a planar mesh and a kept design is near planar, so every Newton step is
//! near the constraints, where the determinants are as good a measure of planarity as the
//! planes.
//!
//! Only planar mode: the conical and circular conditions are not determinants. The P-Hex
//! optimiser's vertex-space normal matrix (3 unknowns per vertex, two vertices per hexagon,
//! every pair of a hexagon's vertices coupled) factors about 6x slower than this one (3
//! unknowns per hexagon, coupled to its six neighbours): on the 10k-face NURBS roof one
//! factorisation took 0.24 s there and the whole least-move run, two steps, 0.23 s.

use super::problem::NONE as FIXED;
use crate::Vec3;
use crate::conical::discrete_terms::quad_det_grad;
use crate::mesh::PolyMesh;
use crate::solver::{
    CholeskyAnalysis, SolverError, SparseCholesky, amd_ordering, csc_pattern,
    fill_reducing_analysis,
};

/// Relative Levenberg damping of the face-space matrix: it keeps a determinant whose four
/// vertices are all held (a zero row) from making the matrix singular and is far below the
/// determinants' curvature, so the steps stay Newton steps.
const DAMPING: f64 = 1e-12;

/// Step halvings tried when a full step raises the residual.
const HALVINGS: usize = 4;

/// How much a chord step ([`PlanarProjection::chord_step`]) must lower the determinants'
/// squared sum to be kept: to a tenth (their norm to a third), else the step is made again
/// with a new factorisation. A chord step costs two triangular solves where a Newton step
/// costs a numeric factorisation as well, 5-10 times as much on the 10k-face roof.
const CHORD_GAIN: f64 = 0.1;

#[cfg(test)]
thread_local! {
    /// Tests only: every step fails (to exercise what a live edit does when its fast way
    /// misses, which no move found by a search over the library's quad meshes does, and the
    /// P-Hex optimiser's hand-over to its weighted steps).
    pub(crate) static FAIL_STEPS: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// The face-space least-move projection of one polygon mesh with fixed free vertices (the
/// pattern of `J Jᵀ` and its analysed Cholesky factor, kept across steps and stages).
pub(crate) struct PlanarProjection {
    /// What the pattern was made for: the faces and the unknowns of their vertices.
    faces: Vec<u32>,
    var_of: Vec<u32>,
    /// The four vertices of every determinant (see [`planarity_rows`]).
    rows: Vec<[u32; 4]>,
    /// For every free vertex, its incident (row, corner) pairs, `incident[start[v]..start[v+1]]`.
    start: Vec<u32>,
    incident: Vec<(u32, u8)>,
    /// For every pair of corners at one free vertex (in the order [`Self::assemble`] walks
    /// them), where its product lands in the factor's values.
    slots: Vec<u32>,
    /// Where each determinant's diagonal entry lands.
    diagonal: Vec<u32>,
    cholesky: SparseCholesky,
    values: Vec<f64>,
    grads: Vec<[Vec3; 4]>,
    /// The gradients the last factorisation was made of (`J₀`).
    factor_grads: Vec<[Vec3; 4]>,
    residual: Vec<f64>,
    factorizations: usize,
}

impl PlanarProjection {
    /// Whether the PQ perturbation projects `mesh` so: every face a quad (its keep-design and
    /// live-edit figures were measured on quads).
    pub(super) fn applies(mesh: &PolyMesh) -> bool {
        mesh.num_faces() > 0 && mesh.faces().all(|f| f.len() == 4)
    }

    /// The pattern and its analysis for `mesh` whose vertex `v` has its unknowns at
    /// `var_of[v] .. + 3` (`u32::MAX` for none), ordered by AMD, and with `dissection` by
    /// whichever of AMD and nested dissection gives the smaller factor
    /// ([`fill_reducing_analysis`]: on quad grids the dissection's, on hexagons AMD's). Refused
    /// like the other solvers when the factor would take more than `max_factor_bytes`.
    pub(crate) fn new(
        mesh: &PolyMesh,
        var_of: &[u32],
        max_factor_bytes: usize,
        dissection: bool,
    ) -> Result<Self, SolverError> {
        let rows = planarity_rows(mesh);
        let nr = rows.len();
        let nv = mesh.num_vertices();
        let mut start = vec![0u32; nv + 1];
        for f in &rows {
            for &v in f {
                if var_of[v as usize] != FIXED {
                    start[v as usize + 1] += 1;
                }
            }
        }
        for v in 0..nv {
            start[v + 1] += start[v];
        }
        let mut fill = start.clone();
        let mut incident = vec![(0u32, 0u8); start[nv] as usize];
        for (q, f) in rows.iter().enumerate() {
            for (k, &v) in f.iter().enumerate() {
                if var_of[v as usize] != FIXED {
                    incident[fill[v as usize] as usize] = (q as u32, k as u8);
                    fill[v as usize] += 1;
                }
            }
        }
        // The upper triangle's entries: every determinant's diagonal, then the pairs at each
        // vertex.
        let mut pairs: Vec<(u32, u32)> = (0..nr as u32).map(|q| (q, q)).collect();
        for v in 0..nv {
            let at = &incident[start[v] as usize..start[v + 1] as usize];
            for (i, &(a, _)) in at.iter().enumerate() {
                for &(b, _) in &at[i..] {
                    pairs.push((a.min(b), a.max(b)));
                }
            }
        }
        let (pattern, csc_slot) = csc_pattern(nr, &pairs)?;
        let analysis = if dissection {
            fill_reducing_analysis(nr, &pattern)?
        } else {
            CholeskyAnalysis::new(pattern.as_ref(), &amd_ordering(&pattern)?)?
        };
        let cholesky = SparseCholesky::from_analysis(analysis, max_factor_bytes)?;
        let slot = |k: usize| cholesky.positions()[csc_slot[k] as usize];
        let diagonal = (0..nr).map(slot).collect();
        let slots = (nr..pairs.len()).map(slot).collect();
        let values = vec![0.0; cholesky.nnz()];
        Ok(PlanarProjection {
            faces: mesh.faces().flatten().copied().collect(),
            var_of: var_of.to_vec(),
            rows,
            start,
            incident,
            slots,
            diagonal,
            cholesky,
            values,
            grads: vec![[Vec3::zeros(); 4]; nr],
            factor_grads: vec![[Vec3::zeros(); 4]; nr],
            residual: vec![0.0; nr],
            factorizations: 0,
        })
    }

    /// A copy that solves with this one's last factorisation ([`Self::chord_step`]); the
    /// symbolic analysis is shared. Fails only when the copy's memory cannot be had.
    pub(crate) fn try_clone(&self) -> Result<Self, SolverError> {
        Ok(PlanarProjection {
            faces: self.faces.clone(),
            var_of: self.var_of.clone(),
            rows: self.rows.clone(),
            start: self.start.clone(),
            incident: self.incident.clone(),
            slots: self.slots.clone(),
            diagonal: self.diagonal.clone(),
            cholesky: self.cholesky.try_clone()?,
            values: self.values.clone(),
            grads: self.grads.clone(),
            factor_grads: self.factor_grads.clone(),
            residual: self.residual.clone(),
            factorizations: 0,
        })
    }

    /// Whether this projection was made for `mesh`'s faces with these unknowns.
    pub(crate) fn covers(&self, mesh: &PolyMesh, var_of: &[u32]) -> bool {
        self.var_of == var_of && mesh.faces().flatten().eq(self.faces.iter())
    }

    /// Sparse factorisations so far.
    pub(crate) fn factorizations(&self) -> usize {
        self.factorizations
    }

    /// The determinants and their gradients at the positions `p` (the solver's frame): the
    /// squared residual norm, or an error for a degenerate face (an edge of length zero).
    fn evaluate(&mut self, p: &[Vec3]) -> Result<f64, SolverError> {
        let mut cost = 0.0;
        for (q, f) in self.rows.iter().enumerate() {
            let (d, g) = quad_det_grad(std::array::from_fn(|k| p[f[k] as usize]));
            if !d.is_finite() || g.iter().any(|g| !g.iter().all(|c| c.is_finite())) {
                return Err(SolverError::NonFinite);
            }
            self.residual[q] = d;
            self.grads[q] = g;
            cost += d * d;
        }
        Ok(cost)
    }

    /// One least-move Gauss-Newton step of the free vertices of `x` (three unknowns per free
    /// vertex at `var_of`, as in [`super::PqPerturbation`]) towards planar faces, its length
    /// halved up to [`HALVINGS`] times until it lowers the determinants' squared sum; `work`
    /// holds the positions of `x` (the solver's frame) and follows it. Returns that sum before
    /// and after the step. Fails when no step lowers it (or the factorisation fails), `x`
    /// unchanged then.
    pub(crate) fn step(
        &mut self,
        work: &mut [Vec3],
        var_of: &[u32],
        x: &mut [f64],
    ) -> Result<(f64, f64), SolverError> {
        self.step_with(work, var_of, x, false)
    }

    /// A chord step: [`Self::step`] with the last factorisation and its gradients `J₀` (of the
    /// positions it was made at) in place of `J` (a simplified Newton step,
    /// `Δx = -J₀ᵀ (J₀ J₀ᵀ)⁻¹ c`, the least move onto `c + J₀ Δx = 0`, right to first order
    /// while `J` stays near `J₀`). `J₀ᵀ`, not `Jᵀ`, maps the multipliers back: `J Jᵀ` is
    /// nearly singular on P-Hex meshes (the damping holds it), and `Jᵀ` let the multipliers'
    /// large near-null part through (every chord on the roof raised the residual 20-1000
    /// fold). Kept when it lowers the determinants' squared sum to [`CHORD_GAIN`] of what it
    /// was; otherwise, or with no factorisation yet, the step is [`Self::step`]'s. Returns and
    /// fails as that does.
    ///
    /// Why: the exact phase of a followed P-Hex mesh ([`crate::phex::PhexPipeline::follow`])
    /// starts from the factorisation of the run before, at positions a move away, and its
    /// steps change `J` less and less; a factorisation is the bulk of a Newton step's time.
    pub(crate) fn chord_step(
        &mut self,
        work: &mut [Vec3],
        var_of: &[u32],
        x: &mut [f64],
    ) -> Result<(f64, f64), SolverError> {
        self.step_with(work, var_of, x, true)
    }

    /// [`Self::step`], or with `chord` [`Self::chord_step`].
    fn step_with(
        &mut self,
        work: &mut [Vec3],
        var_of: &[u32],
        x: &mut [f64],
        chord: bool,
    ) -> Result<(f64, f64), SolverError> {
        #[cfg(test)]
        if FAIL_STEPS.get() {
            return Err(SolverError::Factorization("failing on purpose".into()));
        }
        let before = self.evaluate(work)?;
        if before == 0.0 {
            return Ok((0.0, 0.0));
        }
        if chord && self.cholesky.is_factored() {
            if let Ok(done) = self.move_along(work, var_of, x, before, 0, CHORD_GAIN) {
                return Ok(done);
            }
            // `work` is back at the start; its determinants were last evaluated at the chord's.
            self.evaluate(work)?;
        }
        self.assemble();
        self.cholesky.factorize(&self.values)?;
        self.factorizations += 1;
        self.factor_grads.clone_from(&self.grads);
        self.move_along(work, var_of, x, before, HALVINGS, 1.0)
    }

    /// Moves the free vertices along the least-move direction of the last factorisation and
    /// the determinants last evaluated (at `work`), halving the step up to `halvings` times
    /// until the squared sum is below `gain * before`; `work` and `x` unchanged on failure.
    fn move_along(
        &mut self,
        work: &mut [Vec3],
        var_of: &[u32],
        x: &mut [f64],
        before: f64,
        halvings: usize,
        gain: f64,
    ) -> Result<(f64, f64), SolverError> {
        let mut lambda = self.residual.clone();
        self.cholesky.solve_in_place(&mut lambda)?;
        // Δv = -Σ λ_q ∇_v c_q (of the factorisation) over the determinants at v.
        let nv = work.len();
        let mut delta = vec![Vec3::zeros(); nv];
        for (v, d) in delta.iter_mut().enumerate() {
            for &(q, k) in &self.incident[self.start[v] as usize..self.start[v + 1] as usize] {
                *d -= self.factor_grads[q as usize][k as usize] * lambda[q as usize];
            }
        }
        let start: Vec<Vec3> = work.to_vec();
        let mut t = 1.0;
        for _ in 0..=halvings {
            for v in 0..nv {
                if var_of[v] != FIXED {
                    work[v] = start[v] + delta[v] * t;
                }
            }
            if let Ok(after) = self.evaluate(work)
                && after < gain * before
            {
                for v in 0..nv {
                    let b = var_of[v];
                    if b != FIXED {
                        let b = b as usize;
                        x[b..b + 3].copy_from_slice(work[v].as_slice());
                    }
                }
                return Ok((before, after));
            }
            t *= 0.5;
        }
        work.copy_from_slice(&start);
        Err(SolverError::Factorization(
            "no least-move step lowers the faces' non-planarity".into(),
        ))
    }

    /// Writes `J Jᵀ` (and the damping on its diagonal) into the factor's values.
    fn assemble(&mut self) {
        self.values.iter_mut().for_each(|v| *v = 0.0);
        let mut s = 0;
        for v in 0..self.start.len() - 1 {
            let at = &self.incident[self.start[v] as usize..self.start[v + 1] as usize];
            for (i, &(a, ka)) in at.iter().enumerate() {
                let ga = self.grads[a as usize][ka as usize];
                for &(b, kb) in &at[i..] {
                    self.values[self.slots[s] as usize] +=
                        ga.dot(&self.grads[b as usize][kb as usize]);
                    s += 1;
                }
            }
        }
        let mean = self
            .diagonal
            .iter()
            .map(|&d| self.values[d as usize])
            .sum::<f64>()
            / self.diagonal.len().max(1) as f64;
        let damping = DAMPING * mean.max(f64::MIN_POSITIVE);
        for &d in &self.diagonal {
            self.values[d as usize] += damping;
        }
    }
}

/// The determinants that make `mesh` planar: a quad's four vertices in order; for a polygon
/// of `n > 4` vertices, `n - 3` of them, every vertex not in the polygon's sharpest corner
/// `(a, a + 1, a + 2)` (largest sine between its unit edges) against that corner, so that each
/// determinant is a well-conditioned measure of that vertex's distance from the corner's plane.
fn planarity_rows(mesh: &PolyMesh) -> Vec<[u32; 4]> {
    let mut rows = Vec::new();
    for f in mesh.faces() {
        let n = f.len();
        if n == 4 {
            rows.push([f[0], f[1], f[2], f[3]]);
        } else if n > 4 {
            let p = |k: usize| mesh.positions[f[k % n] as usize];
            let sine = |a: usize| {
                let (e0, e1) = (p(a + 1) - p(a), p(a + 2) - p(a + 1));
                e0.cross(&e1).norm() / (e0.norm() * e1.norm())
            };
            let a = (0..n)
                .max_by(|&x, &y| sine(x).total_cmp(&sine(y)))
                .unwrap_or(0);
            for k in 3..n {
                rows.push([f[a], f[(a + 1) % n], f[(a + 2) % n], f[(a + k) % n]]);
            }
        }
    }
    rows
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::max_planarity;
    use nalgebra::{DMatrix, DVector};

    /// Three unknowns per vertex not in `fixed`, and their values.
    fn unknowns(mesh: &PolyMesh, fixed: &[usize]) -> (Vec<u32>, Vec<f64>) {
        let (mut var_of, mut x) = (Vec::new(), Vec::new());
        for (v, p) in mesh.positions.iter().enumerate() {
            if fixed.contains(&v) {
                var_of.push(FIXED);
            } else {
                var_of.push(x.len() as u32);
                x.extend(p.iter());
            }
        }
        (var_of, x)
    }

    /// A small P-Hex mesh (the tangent-duality start of `sphere-radial`: pentagons and
    /// hexagons, planar) with every coordinate moved by up to 5e-4 of the mean edge (seeded).
    fn noisy_hexagons(size: f64) -> PolyMesh {
        let mut cfg = crate::scenes::phex_scene("sphere-radial").unwrap().config;
        cfg.optimize = false;
        cfg.size = Some(size);
        let mut mesh = crate::phex::phex_run(cfg).unwrap().mesh;
        let e = mesh.mean_edge();
        let mut seed = 3u64;
        for p in &mut mesh.positions {
            for c in 0..3 {
                seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1);
                p[c] += 1e-3 * e * ((seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5);
            }
        }
        mesh
    }

    /// On polygons too, a step is the dense least move onto the linearised determinants,
    /// `n - 3` of them per face of `n` vertices, each a corner and a further vertex.
    #[test]
    fn a_polygon_step_is_the_least_move_onto_its_determinants() {
        let mesh = noisy_hexagons(0.5);
        let rows = planarity_rows(&mesh);
        let sizes = mesh.face_sizes();
        assert!(sizes.keys().any(|&n| n > 4), "{sizes:?}");
        let wanted: usize = mesh.faces().map(|f| f.len().saturating_sub(3)).sum();
        assert_eq!(rows.len(), wanted);
        for (r, f) in rows.iter().zip(
            mesh.faces()
                .flat_map(|f| std::iter::repeat_n(f, f.len().saturating_sub(3))),
        ) {
            assert!(r.iter().all(|v| f.contains(v)), "{r:?} not in {f:?}");
        }
        assert_step_is_the_dense_least_move(&mesh, &[0, 7]);
    }

    /// Steps from `mesh` with `fixed` held until every determinant of [`planarity_rows`] is
    /// below 1e-14, asserting quadratic convergence (residual r to at most 10 r² once below
    /// 1e-2), at most `max_steps` steps, planarity 1e-13 at the end and the fixed vertices'
    /// bits kept. Returns the moved positions, the projection and each step's
    /// `(before, after)`.
    fn converge_quadratically(
        mesh: &PolyMesh,
        fixed: &[usize],
        max_steps: usize,
    ) -> (Vec<Vec3>, PlanarProjection, Vec<(f64, f64)>) {
        let (var_of, mut x) = unknowns(mesh, fixed);
        let mut p = PlanarProjection::new(mesh, &var_of, usize::MAX, true).unwrap();
        let mut work = mesh.positions.clone();
        let rows = planarity_rows(mesh);
        let residual = |w: &[Vec3]| {
            rows.iter()
                .map(|r| quad_det_grad(r.map(|v| w[v as usize])).0.abs())
                .fold(0.0, f64::max)
        };
        let mut r = residual(&work);
        let mut steps = Vec::new();
        while r > 1e-14 {
            steps.push(p.step(&mut work, &var_of, &mut x).unwrap());
            let next = residual(&work);
            if r < 1e-2 {
                assert!(
                    next <= 10.0 * r * r + 1e-14,
                    "step {}: {r:e} to {next:e}",
                    steps.len()
                );
            }
            r = next;
            assert!(
                steps.len() <= max_steps,
                "residual {r:e} after {} steps",
                steps.len()
            );
        }
        let moved = PolyMesh::new(work.clone(), mesh.faces().map(|f| f.to_vec())).unwrap();
        assert!(
            max_planarity(&moved) <= 1e-13,
            "{:e}",
            max_planarity(&moved)
        );
        for &v in fixed {
            assert_eq!(work[v], mesh.positions[v]);
        }
        (work, p, steps)
    }

    /// From polygons 5e-4 edges from planar, the steps converge quadratically to planarity
    /// 1e-13, each lowering the determinants, moving the vertices about as far as the noise.
    #[test]
    fn steps_converge_quadratically_to_planar_polygons() {
        let mesh = noisy_hexagons(0.2);
        let (work, _, steps) = converge_quadratically(&mesh, &[], 4);
        assert!(
            steps.iter().all(|(before, after)| after < before),
            "{steps:?}"
        );
        let e = mesh.mean_edge();
        let moves = work
            .iter()
            .zip(&mesh.positions)
            .map(|(a, b)| (a - b).norm());
        let largest = moves.fold(0.0, f64::max);
        assert!(largest <= 1e-3 * e, "moved {:e} edges", largest / e);
    }

    /// Chord steps: with no factorisation a chord step is a Newton step; a copy of a projection
    /// factored at planar hexagons takes the same hexagons moved by noise back to planar 1e-13
    /// on that one factorisation, each chord lowering the determinants' squared sum at least
    /// tenfold. (Mapping the multipliers back through the new gradients passes here too; on the
    /// 10k roof it does not, which `a_drag_is_followed_by_least_moves` holds.)
    #[test]
    fn chord_steps_reuse_a_copied_factorisation() {
        let planar = {
            let mesh = noisy_hexagons(0.2);
            let (work, ..) = converge_quadratically(&mesh, &[], 4);
            PolyMesh::new(work, mesh.faces().map(|f| f.to_vec())).unwrap()
        };
        let (var_of, _) = unknowns(&planar, &[]);
        let mut fresh = PlanarProjection::new(&planar, &var_of, usize::MAX, true).unwrap();
        let mut moved = planar.clone();
        let e = planar.mean_edge();
        let mut seed = 11u64;
        for p in &mut moved.positions {
            for c in 0..3 {
                seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1);
                p[c] += 2e-3 * e * ((seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5);
            }
        }
        // No factorisation yet: the chord step is the Newton step, bit for bit.
        let (mut a, mut b) = (moved.positions.clone(), moved.positions.clone());
        let (mut xa, mut xb) = (unknowns(&moved, &[]).1, unknowns(&moved, &[]).1);
        let mut other = PlanarProjection::new(&planar, &var_of, usize::MAX, true).unwrap();
        fresh.chord_step(&mut a, &var_of, &mut xa).unwrap();
        other.step(&mut b, &var_of, &mut xb).unwrap();
        assert_eq!((a, xa), (b, xb));
        // Factored at the planar mesh (one Newton step there), then copied and moved on.
        let (mut at_planar, mut x) = (planar.positions.clone(), unknowns(&planar, &[]).1);
        other.step(&mut at_planar, &var_of, &mut x).unwrap();
        let mut copy = other.try_clone().unwrap();
        assert_eq!(copy.factorizations(), 0);
        let (mut work, mut x) = (moved.positions.clone(), unknowns(&moved, &[]).1);
        let mut chords = 0;
        loop {
            let (before, after) = copy.chord_step(&mut work, &var_of, &mut x).unwrap();
            if copy.factorizations() > 0 {
                break;
            }
            chords += 1;
            assert!(after < CHORD_GAIN * before, "{before:e} to {after:e}");
            let now = PolyMesh::new(work.clone(), planar.faces().map(|f| f.to_vec())).unwrap();
            if max_planarity(&now) <= 1e-13 {
                break;
            }
            assert!(
                chords < 20,
                "{chords} chords, planarity {:e}",
                max_planarity(&now)
            );
        }
        assert_eq!(copy.factorizations(), 0, "after {chords} chords");
        assert!(chords >= 2, "{chords}");
    }

    /// An `n x n` grid over a translational surface z = f(x) + g(y), whose grid quads are
    /// planar, with vertex `(i, j)` at index `j (n + 1) + i`.
    fn translational_grid(n: usize) -> PolyMesh {
        let positions = (0..=n)
            .flat_map(|j| (0..=n).map(move |i| (i as f64 / n as f64, j as f64 / n as f64)))
            .map(|(x, y)| Vec3::new(x, y, 0.3 * x * x - 0.2 * (3.0 * y).sin()))
            .collect();
        PolyMesh::quad_grid(positions, n, n).unwrap()
    }

    /// One step is the least move (Euclidean) of the free vertices onto the linearised
    /// constraints, `Δ = -Jᵀ (J Jᵀ)⁻¹ c`, as a dense solve computes it; the fixed vertices
    /// keep their bits.
    #[test]
    fn a_step_is_the_least_move_onto_the_linearised_constraints() {
        let n = 5;
        let mut mesh = translational_grid(n);
        let mut seed = 7u64;
        for p in &mut mesh.positions {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1);
            p.z += 1e-3 * ((seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5);
        }
        assert_step_is_the_dense_least_move(&mesh, &[0, n, n * (n + 1), (n + 1) * (n + 1) - 1]);
    }

    /// One step from `mesh` with `fixed` held is the dense least move `-Jᵀ (J Jᵀ)⁻¹ c` over the
    /// determinants of [`planarity_rows`], to 1e-9; the fixed vertices keep their bits.
    fn assert_step_is_the_dense_least_move(mesh: &PolyMesh, fixed: &[usize]) {
        let rows = planarity_rows(mesh);
        let (var_of, mut x) = unknowns(mesh, fixed);
        let x0 = x.clone();
        let mut j = DMatrix::<f64>::zeros(rows.len(), x.len());
        let mut c = DVector::zeros(rows.len());
        for (q, r) in rows.iter().enumerate() {
            let (d, g) = quad_det_grad(r.map(|v| mesh.positions[v as usize]));
            c[q] = d;
            for (k, &v) in r.iter().enumerate() {
                if var_of[v as usize] != FIXED {
                    for a in 0..3 {
                        j[(q, var_of[v as usize] as usize + a)] += g[k][a];
                    }
                }
            }
        }
        let jjt = &j * j.transpose();
        let dense = -(j.transpose() * jjt.lu().solve(&c).unwrap());
        let mut p = PlanarProjection::new(mesh, &var_of, usize::MAX, true).unwrap();
        let mut work = mesh.positions.clone();
        p.step(&mut work, &var_of, &mut x).unwrap();
        let step = DVector::from_iterator(x.len(), x.iter().zip(&x0).map(|(a, b)| a - b));
        assert!(
            (&step - &dense).norm() <= 1e-9 * dense.norm(),
            "{:e} against {:e}",
            (&step - &dense).norm(),
            dense.norm()
        );
        for &v in fixed {
            assert_eq!(work[v], mesh.positions[v]);
        }
    }

    /// From a planar quad mesh with one vertex held a third of an edge away, the steps
    /// converge quadratically to planarity 1e-13 in a few steps, one factorisation each, the
    /// held vertex and the boundary corners unmoved.
    #[test]
    fn steps_converge_quadratically_to_planar_quads() {
        let n = 12;
        let mut mesh = translational_grid(n);
        assert!(max_planarity(&mesh) < 1e-14);
        let held = 6 * (n + 1) + 5;
        mesh.positions[held].z += 0.3 / n as f64;
        let fixed = [held, 0, n, n * (n + 1), (n + 1) * (n + 1) - 1];
        let (_, p, steps) = converge_quadratically(&mesh, &fixed, 6);
        assert_eq!(p.factorizations(), steps.len());
    }
}
