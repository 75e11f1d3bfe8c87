//! Sequential quadratic programming for equality-constrained least squares (conical paper,
//! Sec. 2.2, eq. (3)): minimise `½|r(x)|²` subject to `c(x) = 0`.
//!
//! Each step solves the regularised KKT system
//!
//! ```text
//! [ JrᵀJr + μ s I    Jcᵀ ] [ h ]   [ -Jrᵀ r ]
//! [ Jc              -ε I ] [ ν ] = [ -c     ]
//! ```
//!
//! (Gauss-Newton Hessian of the objective, `ν` the multipliers; the constraints' curvature
//! `Σ ν_i ∇²c_i` is left out, so the constraints converge quadratically while optimality
//! converges linearly at a rate proportional to |ν|, small when the objective weights are small) with faer's sparse LU, then a
//! soft line search on the exact-penalty merit `½|r|² + ρ Σ|c_i|`. The small `-εI` block keeps
//! the system solvable when constraints are redundant or contradict fixed variables; the step
//! then satisfies them in the least-squares sense.

use super::pattern::{GramScratch, PatternMatrix, add_gram};
use super::{SolverError, SparseSystem};

/// A least-squares objective with equality constraints, both with sparse Jacobians.
pub trait ConstrainedLeastSquares {
    /// Number of unknowns.
    fn num_variables(&self) -> usize;
    /// Fills `out` (cleared by the caller) with the objective residuals r(x) and their Jacobian.
    fn objective(&self, x: &[f64], out: &mut SparseSystem);
    /// Fills `out` (cleared by the caller) with the constraint values c(x) and their Jacobian.
    fn constraints(&self, x: &[f64], out: &mut SparseSystem);
    /// Optionally adds `Σ ν_i ∇²c_i(x)` (the constraints' part of the Lagrangian Hessian) as
    /// (row, col, value) entries, both triangles. With it the step is a full Newton-SQP step
    /// and converges quadratically; without it (the default) the Hessian is Gauss-Newton.
    fn constraint_hessian(&self, _x: &[f64], _nu: &[f64], _out: &mut Vec<(u32, u32, f64)>) {}
}

/// Settings of [`Sqp`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SqpOptions {
    /// Proximal damping μ added to the Hessian, relative to its largest diagonal entry (and
    /// absolute when the objective is empty). Keeps the Hessian positive definite on variables
    /// the objective does not see.
    pub damping: f64,
    /// Absolute proximal damping added on top of the relative one (keeps steps short and the
    /// step independent of the objective's scale once the objective weights become tiny).
    pub absolute_damping: f64,
    /// Regularisation ε of the constraint block.
    pub regularization: f64,
    /// Largest number of step halvings in the line search.
    pub max_halvings: usize,
}

impl Default for SqpOptions {
    fn default() -> Self {
        SqpOptions {
            damping: 1e-8,
            absolute_damping: 0.0,
            regularization: 1e-14,
            max_halvings: 12,
        }
    }
}

/// What one [`Sqp::step`] did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SqpStep {
    /// Largest |c_i| before the step.
    pub violation_before: f64,
    /// Largest |c_i| after the step.
    pub violation_after: f64,
    /// ½|r|² after the step.
    pub objective_after: f64,
    /// Step length factor α of the line search (0 when no step was taken).
    pub alpha: f64,
    /// Norm of the accepted step α·h.
    pub step_norm: f64,
}

/// A stateful SQP iteration; the sparsity analysis of the KKT matrix is reused across steps.
pub struct Sqp {
    options: SqpOptions,
    kkt: PatternMatrix,
    obj: SparseSystem,
    cons: SparseSystem,
    trial_obj: SparseSystem,
    trial_cons: SparseSystem,
    scratch: GramScratch,
    /// Multipliers of the last step (used for the Lagrangian Hessian of the next one).
    nu: Vec<f64>,
    hess: Vec<(u32, u32, f64)>,
}

impl Sqp {
    /// A new iteration with the given settings.
    pub fn new(options: SqpOptions) -> Self {
        Sqp {
            options,
            kkt: PatternMatrix::new(),
            obj: SparseSystem::new(),
            cons: SparseSystem::new(),
            trial_obj: SparseSystem::new(),
            trial_cons: SparseSystem::new(),
            scratch: GramScratch::default(),
            nu: Vec::new(),
            hess: Vec::new(),
        }
    }

    /// One SQP step on `x` (updated in place when the line search accepts a step).
    pub fn step<P: ConstrainedLeastSquares + ?Sized>(
        &mut self,
        problem: &P,
        x: &mut [f64],
    ) -> Result<SqpStep, SolverError> {
        let n = problem.num_variables();
        self.obj.clear();
        self.cons.clear();
        problem.objective(x, &mut self.obj);
        problem.constraints(x, &mut self.cons);
        self.obj.validate(n)?;
        self.cons.validate(n)?;
        let p = self.cons.residuals.len();
        let size = n + p;
        self.kkt.begin(size);
        let diag = add_gram(&self.obj, n, &mut self.kkt, false, &mut self.scratch);
        let scale = diag.iter().fold(0.0f64, |a, &b| a.max(b));
        let mu = if scale > 0.0 {
            self.options.damping * scale + self.options.absolute_damping
        } else {
            self.options.damping.max(1e-12) + self.options.absolute_damping
        };
        for i in 0..n {
            self.kkt.add(i as u32, i as u32, mu);
        }
        if self.nu.len() == p {
            self.hess.clear();
            problem.constraint_hessian(x, &self.nu, &mut self.hess);
            for &(r, c, v) in &self.hess {
                if (r as usize) < n && (c as usize) < n && v.is_finite() {
                    self.kkt.add(r, c, v);
                }
            }
        }
        for e in &self.cons.entries {
            let r = n as u32 + e.row;
            self.kkt.add(r, e.col, e.value);
            self.kkt.add(e.col, r, e.value);
        }
        let jscale = self
            .cons
            .entries
            .iter()
            .fold(0.0f64, |a, e| a.max(e.value.abs()));
        // Relative to the scale of the Schur complement Jc H⁻¹ Jcᵀ.
        let eps = self.options.regularization * (jscale * jscale) / (scale + mu);
        for i in 0..p {
            self.kkt.add((n + i) as u32, (n + i) as u32, -eps);
        }
        let mut rhs = self.obj.gradient(n);
        rhs.iter_mut().for_each(|g| *g = -*g);
        rhs.extend(self.cons.residuals.iter().map(|c| -c));
        self.kkt.solve(&mut rhs)?;
        let (h, nu) = rhs.split_at(n);
        let rho = 2.0 * nu.iter().fold(0.0f64, |a, v| a.max(v.abs())) + 1e-12;
        let merit = |o: &SparseSystem, c: &SparseSystem| {
            o.cost() + rho * c.residuals.iter().map(|v| v.abs()).sum::<f64>()
        };
        let merit0 = merit(&self.obj, &self.cons);
        let violation_before = self.cons.max_abs();
        let mut alpha = 1.0;
        let mut trial = vec![0.0; n];
        for _ in 0..=self.options.max_halvings {
            for i in 0..n {
                trial[i] = x[i] + alpha * h[i];
            }
            self.trial_obj.clear();
            self.trial_cons.clear();
            problem.objective(&trial, &mut self.trial_obj);
            problem.constraints(&trial, &mut self.trial_cons);
            let ok = self.trial_obj.validate(n).is_ok() && self.trial_cons.validate(n).is_ok();
            if ok {
                let m1 = merit(&self.trial_obj, &self.trial_cons);
                let v1 = self.trial_cons.max_abs();
                // Accept on merit decrease, or (at full step) on a clear drop of the violation
                // when the merit only stalls at rounding level.
                if m1 < merit0 || (alpha == 1.0 && v1 < 0.5 * violation_before) {
                    x.copy_from_slice(&trial);
                    self.nu.clear();
                    self.nu.extend_from_slice(nu);
                    return Ok(SqpStep {
                        violation_before,
                        violation_after: v1,
                        objective_after: self.trial_obj.cost(),
                        alpha,
                        step_norm: alpha * h.iter().map(|v| v * v).sum::<f64>().sqrt(),
                    });
                }
            }
            alpha *= 0.5;
        }
        self.nu.clear();
        Err(SolverError::NoDescent { damping: mu })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Closest point to a = (0.88, 0.44, 0.22) (|a| ≈ 1.02) on the unit sphere: r = x - a, c = |x|² - 1.
    struct SphereProjection;
    impl ConstrainedLeastSquares for SphereProjection {
        fn num_variables(&self) -> usize {
            3
        }
        fn objective(&self, x: &[f64], out: &mut SparseSystem) {
            for (k, a) in [0.88, 0.44, 0.22].iter().enumerate() {
                let r = out.push_residual(x[k] - a);
                out.push_entry(r, k as u32, 1.0);
            }
        }
        fn constraints(&self, x: &[f64], out: &mut SparseSystem) {
            let r = out.push_residual(x.iter().map(|v| v * v).sum::<f64>() - 1.0);
            for (k, xk) in x.iter().enumerate() {
                out.push_entry(r, k as u32, 2.0 * xk);
            }
        }
    }

    #[test]
    fn projects_onto_the_sphere_exactly() {
        let mut sqp = Sqp::new(SqpOptions::default());
        let mut x = vec![0.3, 0.9, -0.2];
        for _ in 0..40 {
            match sqp.step(&SphereProjection, &mut x) {
                Ok(s) if s.violation_after < 1e-15 && s.step_norm < 1e-14 => break,
                Ok(_) => {}
                Err(e) => panic!("{e}"),
            }
        }
        let a = nalgebra::Vector3::new(0.88, 0.44, 0.22);
        let want = a.normalize();
        for k in 0..3 {
            assert!((x[k] - want[k]).abs() < 1e-9, "{x:?} vs {want:?}");
        }
        let norm2: f64 = x.iter().map(|v| v * v).sum();
        assert!((norm2 - 1.0).abs() < 1e-14);
    }

    /// The same projection with the constraint Hessian 2νI supplied: Newton-SQP converges in
    /// a handful of steps even from a point far from the sphere.
    struct SphereProjectionNewton;
    impl ConstrainedLeastSquares for SphereProjectionNewton {
        fn num_variables(&self) -> usize {
            3
        }
        fn objective(&self, x: &[f64], out: &mut SparseSystem) {
            for (k, a) in [2.0, 1.0, 0.5].iter().enumerate() {
                let r = out.push_residual(x[k] - a);
                out.push_entry(r, k as u32, 1.0);
            }
        }
        fn constraints(&self, x: &[f64], out: &mut SparseSystem) {
            SphereProjection.constraints(x, out)
        }
        fn constraint_hessian(&self, _x: &[f64], nu: &[f64], out: &mut Vec<(u32, u32, f64)>) {
            for k in 0..3 {
                out.push((k, k, 2.0 * nu[0]));
            }
        }
    }

    #[test]
    fn newton_sqp_with_constraint_hessian_converges_fast() {
        let mut sqp = Sqp::new(SqpOptions::default());
        let mut x = vec![0.3, 0.9, -0.2];
        let mut steps = 0;
        for _ in 0..30 {
            steps += 1;
            // Once converged, no step can lower the merit any more: that ends the loop.
            match sqp.step(&SphereProjectionNewton, &mut x) {
                Ok(s) if s.violation_after < 1e-15 && s.step_norm < 1e-13 => break,
                Ok(_) => {}
                Err(_) => break,
            }
        }
        let want = nalgebra::Vector3::new(2.0, 1.0, 0.5).normalize();
        for k in 0..3 {
            assert!((x[k] - want[k]).abs() < 1e-12, "{x:?} vs {want:?}");
        }
        assert!(steps <= 12, "{steps} steps");
    }

    /// Redundant constraints (the same line twice) and a variable the objective ignores: the
    /// regularised KKT system must still give the exact feasible minimiser.
    struct Redundant;
    impl ConstrainedLeastSquares for Redundant {
        fn num_variables(&self) -> usize {
            3
        }
        fn objective(&self, x: &[f64], out: &mut SparseSystem) {
            let r = out.push_residual(x[0] - 1.0);
            out.push_entry(r, 0, 1.0);
            let r = out.push_residual(x[1] - 1.0);
            out.push_entry(r, 1, 1.0);
        }
        fn constraints(&self, x: &[f64], out: &mut SparseSystem) {
            for _ in 0..2 {
                let r = out.push_residual(x[0] + x[1]);
                out.push_entry(r, 0, 1.0);
                out.push_entry(r, 1, 1.0);
            }
        }
    }

    #[test]
    fn redundant_constraints_are_handled() {
        let mut sqp = Sqp::new(SqpOptions::default());
        let mut x = vec![0.5, 0.7, 3.0];
        for _ in 0..5 {
            if sqp.step(&Redundant, &mut x).is_err() {
                break;
            }
        }
        assert!((x[0] + x[1]).abs() < 1e-12, "{x:?}");
        assert!(x[0].abs() < 1e-6 && x[1].abs() < 1e-6, "{x:?}");
        assert!((x[2] - 3.0).abs() < 1e-6, "untouched variable moved: {x:?}");
    }
}
