//! Planarity optimisation of a polygon mesh near a surface (P-Hex paper, section 6):
//!
//! minimise  Σ_faces Σ_i vol(v_i, v_i+1, v_i+2, v_i+3)² + λ F_s + μ F_d
//!
//! where vol is the signed volume of the tetrahedron of four consecutive face vertices (scaled
//! by the face's initial mean edge cubed, so the term is scale free), generalised from hexagons
//! to any polygon of at least four vertices (every cyclic quadruple), boundary faces included;
//! F_s is the umbrella-Laplacian fairness Σ |v - mean(neighbours)|² and F_d the squared
//! distance to the surface in its tangent-plane (Gauss-Newton) form ((v - f)·n)² with foot point
//! f and unit normal n recomputed at every iteration. λ and μ shrink by 10 after every
//! iteration (the paper shrinks λ; shrinking μ too lets the planarity reach 1e-10 instead of
//! settling at a compromise with the distance term, whose size stays bounded because μ starts
//! from a moderate value and the geometry moves little).
//!
//! Solved by Gauss-Newton on the sparse normal equations through the shared
//! [`LevenbergMarquardt`] engine (faer sparse Cholesky). The stopping rule is the contract's
//! `max_planarity` (a tolerance), not a fixed iteration count.

use super::PhexError;
use crate::{
    LevenbergMarquardt, LmOptions, NonlinearLeastSquares, PolyMesh, SparseSystem, Surface, Vec2,
    Vec3, max_planarity,
};

/// Settings of the planarity optimisation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanarityOptions {
    /// Initial fairness weight λ (relative; shrinks by 10 each iteration).
    pub fairness: f64,
    /// Initial surface-distance weight μ (relative; shrinks by 10 each iteration).
    pub distance: f64,
    /// Stop once `max_planarity` is at most this.
    pub tolerance: f64,
    /// Largest number of Gauss-Newton iterations.
    pub max_iterations: usize,
}

impl Default for PlanarityOptions {
    fn default() -> Self {
        PlanarityOptions {
            fairness: 1e-6,
            distance: 1e-4,
            tolerance: 1e-10,
            max_iterations: 10,
        }
    }
}

/// The least-squares problem of one iteration (weights and foot points frozen).
struct Problem<'a> {
    mesh: &'a PolyMesh,
    face_scale: Vec<f64>,
    neighbours: &'a [Vec<u32>],
    feet: &'a [(Vec3, Vec3)],
    sqrt_lambda: f64,
    sqrt_mu: f64,
    edge: f64,
}

impl NonlinearLeastSquares for Problem<'_> {
    fn num_variables(&self) -> usize {
        3 * self.mesh.num_vertices()
    }

    fn evaluate(&self, x: &[f64], out: &mut SparseSystem) {
        let p = |i: u32| {
            Vec3::new(
                x[3 * i as usize],
                x[3 * i as usize + 1],
                x[3 * i as usize + 2],
            )
        };
        for (fi, f) in self.mesh.faces().enumerate() {
            let n = f.len();
            if n < 4 {
                continue;
            }
            let s = 1.0 / self.face_scale[fi].powi(3);
            let quads = if n == 4 { 1 } else { n };
            for i in 0..quads {
                let idx = [f[i], f[(i + 1) % n], f[(i + 2) % n], f[(i + 3) % n]];
                let [a, b, c, d] = idx.map(p);
                let (ab, ac, ad) = (b - a, c - a, d - a);
                let vol = ab.dot(&ac.cross(&ad));
                let gb = ac.cross(&ad);
                let gc = ad.cross(&ab);
                let gd = ab.cross(&ac);
                let ga = -(gb + gc + gd);
                let row = out.push_residual(vol * s);
                for (v, g) in idx.iter().zip([ga, gb, gc, gd]) {
                    for k in 0..3 {
                        out.push_entry(row, 3 * v + k as u32, g[k] * s);
                    }
                }
            }
        }
        for (v, nb) in self.neighbours.iter().enumerate() {
            let v = v as u32;
            // Fairness: v - mean(neighbours).
            if self.sqrt_lambda > 0.0 && !nb.is_empty() {
                let w = self.sqrt_lambda / self.edge;
                let inv = 1.0 / nb.len() as f64;
                let mean = nb.iter().map(|&j| p(j)).sum::<Vec3>() * inv;
                let r = p(v) - mean;
                for k in 0..3u32 {
                    let row = out.push_residual(w * r[k as usize]);
                    out.push_entry(row, 3 * v + k, w);
                    for &j in nb {
                        out.push_entry(row, 3 * j + k, -w * inv);
                    }
                }
            }
            // Distance to the surface, tangent-plane form.
            let (foot, nrm) = self.feet[v as usize];
            let w = self.sqrt_mu / self.edge;
            let row = out.push_residual(w * (p(v) - foot).dot(&nrm));
            for k in 0..3u32 {
                out.push_entry(row, 3 * v + k, w * nrm[k as usize]);
            }
        }
    }
}

/// What one optimisation iteration did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanarityStep {
    /// Iteration number (1-based).
    pub iteration: usize,
    /// `max_planarity` after the iteration.
    pub max_planarity: f64,
    /// Objective before and after.
    pub cost_before: f64,
    /// Objective after the step.
    pub cost_after: f64,
}

/// Stateful Gauss-Newton planarity optimisation (one [`PlanarityOptimiser::step`] per
/// iteration, so a UI can watch it).
pub struct PlanarityOptimiser {
    options: PlanarityOptions,
    lm: LevenbergMarquardt,
    neighbours: Vec<Vec<u32>>,
    face_scale: Vec<f64>,
    edge: f64,
    uv: Vec<Option<Vec2>>,
    lambda: f64,
    mu: f64,
    iteration: usize,
    max_planarity: f64,
}

impl PlanarityOptimiser {
    /// Prepares the optimisation of `mesh` (neighbour lists, face scales).
    ///
    /// `start_uv` (optional, one per vertex) seeds the closest-point searches of F_d.
    pub fn new(
        mesh: &PolyMesh,
        start_uv: Option<&[Vec2]>,
        options: PlanarityOptions,
    ) -> Result<Self, PhexError> {
        if !(options.tolerance > 0.0) || !(options.fairness >= 0.0) || !(options.distance >= 0.0) {
            return Err(PhexError::BadParameter(
                "planarity tolerance must be > 0 and weights >= 0".into(),
            ));
        }
        let nv = mesh.num_vertices();
        let mut neighbours: Vec<Vec<u32>> = vec![vec![]; nv];
        for f in mesh.faces() {
            for i in 0..f.len() {
                let (a, b) = (f[i], f[(i + 1) % f.len()]);
                if !neighbours[a as usize].contains(&b) {
                    neighbours[a as usize].push(b);
                }
                if !neighbours[b as usize].contains(&a) {
                    neighbours[b as usize].push(a);
                }
            }
        }
        let face_scale: Vec<f64> = (0..mesh.num_faces())
            .map(|i| mesh.face_mean_edge(i).max(1e-300))
            .collect();
        let edge = face_scale.iter().sum::<f64>() / face_scale.len().max(1) as f64;
        Ok(PlanarityOptimiser {
            options,
            lm: LevenbergMarquardt::new(LmOptions {
                initial_damping: 1e-8,
                ..LmOptions::default()
            }),
            neighbours,
            face_scale,
            edge: edge.max(1e-300),
            uv: match start_uv {
                Some(s) if s.len() == nv => s.iter().map(|&p| Some(p)).collect(),
                _ => vec![None; nv],
            },
            lambda: options.fairness,
            mu: options.distance,
            iteration: 0,
            max_planarity: max_planarity(mesh),
        })
    }

    /// Iterations done so far.
    pub fn iteration(&self) -> usize {
        self.iteration
    }

    /// Current `max_planarity`.
    pub fn max_planarity(&self) -> f64 {
        self.max_planarity
    }

    /// Whether the tolerance is reached or the iteration budget is spent.
    pub fn done(&self) -> bool {
        self.max_planarity <= self.options.tolerance
            || self.iteration >= self.options.max_iterations
    }

    /// One Gauss-Newton iteration on `mesh` (positions updated in place) against `surface`.
    ///
    /// Errors: [`PhexError::Solver`] when the sparse solve fails or produces non-finite values.
    pub fn step(
        &mut self,
        mesh: &mut PolyMesh,
        surface: &dyn Surface,
    ) -> Result<PlanarityStep, PhexError> {
        let feet: Vec<(Vec3, Vec3)> = mesh
            .positions
            .iter()
            .enumerate()
            .map(|(i, p)| match surface.closest_point(p, self.uv[i]) {
                Ok(cp) => {
                    self.uv[i] = Some(cp.uv);
                    let n = surface.normal(cp.uv.x, cp.uv.y);
                    (cp.point, n)
                }
                Err(_) => (*p, Vec3::zeros()),
            })
            .collect();
        let problem = Problem {
            mesh,
            face_scale: self.face_scale.clone(),
            neighbours: &self.neighbours,
            feet: &feet,
            sqrt_lambda: self.lambda.sqrt(),
            sqrt_mu: self.mu.sqrt(),
            edge: self.edge,
        };
        let mut x: Vec<f64> = mesh
            .positions
            .iter()
            .flat_map(|p| [p.x, p.y, p.z])
            .collect();
        self.lm.invalidate();
        let res = self.lm.step(&problem, &mut x);
        self.iteration += 1;
        self.lambda /= 10.0;
        self.mu /= 10.0;
        let (cost_before, cost_after) = match res {
            Ok(s) => (s.cost_before, s.cost_after),
            Err(crate::SolverError::NoDescent { .. }) => (0.0, 0.0),
            Err(e) => return Err(PhexError::Solver(e)),
        };
        for (i, p) in mesh.positions.iter_mut().enumerate() {
            *p = Vec3::new(x[3 * i], x[3 * i + 1], x[3 * i + 2]);
        }
        self.max_planarity = max_planarity(mesh);
        if !self.max_planarity.is_finite() {
            return Err(PhexError::Solver(crate::SolverError::NonFinite));
        }
        Ok(PlanarityStep {
            iteration: self.iteration,
            max_planarity: self.max_planarity,
            cost_before,
            cost_after,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{phex_run, phex_scene};
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn perturbed_mesh_returns_to_planarity_within_ten_iterations() {
        for (name, seed) in [("sphere-radial", 1u64), ("hyperboloid-valid", 2)] {
            let scene = phex_scene(name).unwrap();
            let mut cfg = scene.config.clone();
            cfg.optimize = false;
            let r = phex_run(cfg).unwrap();
            let mut mesh = r.mesh.clone();
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let e = (0..mesh.num_faces())
                .map(|i| mesh.face_mean_edge(i))
                .sum::<f64>()
                / mesh.num_faces() as f64;
            for p in mesh.positions.iter_mut() {
                for k in 0..3 {
                    p[k] += rng.random_range(-1.0..1.0) * 0.002 * e;
                }
            }
            let before = max_planarity(&mesh);
            assert!(before > 1e-4);
            let surface = crate::surface_by_name(&scene.config.surface, &[]).unwrap();
            let min_edge = |m: &PolyMesh| {
                m.faces()
                    .flat_map(|f| (0..f.len()).map(move |k| (f[k], f[(k + 1) % f.len()])))
                    .map(|(a, b)| (m.positions[a as usize] - m.positions[b as usize]).norm())
                    .fold(f64::INFINITY, f64::min)
            };
            let min_before = min_edge(&mesh);
            let mut opt =
                PlanarityOptimiser::new(&mesh, None, PlanarityOptions::default()).unwrap();
            while !opt.done() {
                opt.step(&mut mesh, surface.as_ref()).unwrap();
            }
            assert!(
                opt.max_planarity() <= 1e-10,
                "{name}: {:e} after {}",
                opt.max_planarity(),
                opt.iteration()
            );
            assert!(opt.iteration() <= 10);
            // No edge collapses (the volume energy alone would allow it).
            assert!(min_edge(&mesh) > 0.5 * min_before, "{name}: edge collapse");
        }
    }

    #[test]
    fn bad_options_are_typed_errors() {
        let r = phex_run(phex_scene("sphere-radial").unwrap().config).unwrap();
        let o = PlanarityOptions {
            tolerance: f64::NAN,
            ..PlanarityOptions::default()
        };
        assert!(matches!(
            PlanarityOptimiser::new(&r.mesh, None, o),
            Err(PhexError::BadParameter(_))
        ));
    }
}
