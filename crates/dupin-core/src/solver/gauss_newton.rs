//! Gauss-Newton with Levenberg-Marquardt damping on sparse normal equations (conical paper,
//! Sec. 2.2: "an unconstrained least squares problem which can be solved effectively by the
//! Gauss-Newton method with L-M regularization").

use super::pattern::{Factor, GramScratch, PatternMatrix, add_gram};
use super::{SolverError, SparseSystem};

/// A nonlinear least-squares problem `min ½ |r(x)|²` with a sparse Jacobian.
pub trait NonlinearLeastSquares {
    /// Number of unknowns.
    fn num_variables(&self) -> usize;
    /// Fills `out` (cleared by the caller) with r(x) and the Jacobian triplets at `x`.
    fn evaluate(&self, x: &[f64], out: &mut SparseSystem);
}

/// Settings of [`LevenbergMarquardt`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LmOptions {
    /// Initial damping μ, relative to the largest diagonal entry of JᵀJ.
    pub initial_damping: f64,
    /// Damping below which μ is not decreased further (relative).
    pub min_damping: f64,
    /// Number of damping increases tried before a step is declared failed.
    pub max_retries: usize,
    /// Scale the damping per variable by the diagonal of JᵀJ (Marquardt) instead of one
    /// uniform value (Levenberg); better when variables have different units.
    pub marquardt_scaling: bool,
    /// Factor by which the damping shrinks after an accepted step (> 1).
    pub decrease: f64,
}

impl Default for LmOptions {
    fn default() -> Self {
        LmOptions {
            initial_damping: 1e-4,
            min_damping: 1e-15,
            max_retries: 12,
            decrease: 3.0,
            marquardt_scaling: false,
        }
    }
}

/// What one [`LevenbergMarquardt::step`] did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LmStep {
    /// ½|r|² before the step.
    pub cost_before: f64,
    /// ½|r|² after the step (equal to `cost_before` when nothing was accepted).
    pub cost_after: f64,
    /// Euclidean norm of the accepted step (0 when none was).
    pub step_norm: f64,
    /// Relative damping used for the accepted step.
    pub damping: f64,
}

/// A stateful Levenberg-Marquardt iteration: call [`LevenbergMarquardt::step`] repeatedly; the
/// problem may change its weights between steps (the PQ penalty schedule does).
pub struct LevenbergMarquardt {
    options: LmOptions,
    damping: f64,
    normal: PatternMatrix,
    sys: SparseSystem,
    trial_sys: SparseSystem,
    /// The accepted point whose evaluation is in `trial_sys`, while still valid.
    cached_x: Option<Vec<f64>>,
    scratch: GramScratch,
}

impl LevenbergMarquardt {
    /// A new iteration with the given settings.
    pub fn new(options: LmOptions) -> Self {
        LevenbergMarquardt {
            options,
            damping: options.initial_damping,
            normal: PatternMatrix::new(Factor::CholeskyUpper),
            sys: SparseSystem::new(),
            trial_sys: SparseSystem::new(),
            cached_x: None,
            scratch: GramScratch::default(),
        }
    }

    /// Tells the iteration that the problem changed (e.g. its weights), so the evaluation kept
    /// from the last accepted step must not be reused.
    pub fn invalidate(&mut self) {
        self.cached_x = None;
    }

    /// Sets the relative damping μ.
    pub fn set_damping(&mut self, mu: f64) {
        self.damping = mu;
    }

    /// The current relative damping μ.
    pub fn damping(&self) -> f64 {
        self.damping
    }

    /// Solves the damped normal equations `(JᵀJ + μ·s·I) h = -Jᵀr` for the system `sys`, where
    /// `s` is the largest diagonal entry of JᵀJ (so `mu` is relative). Returns `h`.
    fn damped_step(&mut self, n: usize, mu: f64) -> Result<Vec<f64>, SolverError> {
        self.normal.begin(n);
        let diag = add_gram(&self.sys, n, &mut self.normal, true, &mut self.scratch);
        let sys = &self.sys;
        let scale = diag.iter().fold(0.0f64, |a, &b| a.max(b)).max(1e-300);
        #[allow(clippy::needless_range_loop)]
        for i in 0..n {
            let d = if self.options.marquardt_scaling {
                diag[i] + 1e-9 * scale
            } else {
                scale
            };
            self.normal.add(i as u32, i as u32, mu * d);
        }
        let mut rhs = sys.gradient(n);
        rhs.iter_mut().for_each(|g| *g = -*g);
        self.normal.solve(&mut rhs)?;
        Ok(rhs)
    }

    /// One damped Gauss-Newton step on `x` (updated in place when a step reduces the cost).
    ///
    /// The damping is decreased after a successful step and increased until the cost decreases
    /// otherwise; after `max_retries` increases [`SolverError::NoDescent`] is returned and `x`
    /// is left unchanged.
    pub fn step<P: NonlinearLeastSquares + ?Sized>(
        &mut self,
        problem: &P,
        x: &mut [f64],
    ) -> Result<LmStep, SolverError> {
        let n = problem.num_variables();
        if self.cached_x.as_deref() == Some(&*x) {
            std::mem::swap(&mut self.sys, &mut self.trial_sys);
        } else {
            self.sys.clear();
            problem.evaluate(x, &mut self.sys);
            self.sys.validate(n)?;
        }
        self.cached_x = None;
        let cost_before = self.sys.cost();
        if cost_before == 0.0 {
            return Ok(LmStep {
                cost_before,
                cost_after: 0.0,
                step_norm: 0.0,
                damping: self.damping,
            });
        }
        let mut trial = vec![0.0; n];
        for _ in 0..=self.options.max_retries {
            let h = match self.damped_step(n, self.damping) {
                Ok(h) => h,
                Err(_) => {
                    self.damping = (self.damping * 10.0).max(1e-12);
                    continue;
                }
            };
            for i in 0..n {
                trial[i] = x[i] + h[i];
            }
            self.trial_sys.clear();
            problem.evaluate(&trial, &mut self.trial_sys);
            let cost_after = if self.trial_sys.validate(n).is_ok() {
                self.trial_sys.cost()
            } else {
                f64::INFINITY
            };
            if cost_after < cost_before {
                x.copy_from_slice(&trial);
                self.cached_x = Some(trial);
                let used = self.damping;
                self.damping = (self.damping / self.options.decrease).max(self.options.min_damping);
                return Ok(LmStep {
                    cost_before,
                    cost_after,
                    step_norm: h.iter().map(|v| v * v).sum::<f64>().sqrt(),
                    damping: used,
                });
            }
            self.damping = (self.damping * 4.0).max(1e-12);
        }
        Err(SolverError::NoDescent {
            damping: self.damping,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Rosenbrock in residual form: r = (10 (y - x²), 1 - x); minimum 0 at (1, 1).
    struct Rosenbrock;
    impl NonlinearLeastSquares for Rosenbrock {
        fn num_variables(&self) -> usize {
            2
        }
        fn evaluate(&self, x: &[f64], out: &mut SparseSystem) {
            let r0 = out.push_residual(10.0 * (x[1] - x[0] * x[0]));
            out.push_entry(r0, 0, -20.0 * x[0]);
            out.push_entry(r0, 1, 10.0);
            let r1 = out.push_residual(1.0 - x[0]);
            out.push_entry(r1, 0, -1.0);
        }
    }

    #[test]
    fn rosenbrock_converges_to_the_minimum() {
        let mut lm = LevenbergMarquardt::new(LmOptions::default());
        let mut x = vec![-1.2, 1.0];
        for _ in 0..100 {
            match lm.step(&Rosenbrock, &mut x) {
                Ok(s) if s.cost_after < 1e-30 => break,
                Ok(_) => {}
                Err(e) => panic!("{e}"),
            }
        }
        assert!(
            (x[0] - 1.0).abs() < 1e-10 && (x[1] - 1.0).abs() < 1e-10,
            "{x:?}"
        );
    }

    /// A sparse overdetermined linear system A x = b: Gauss-Newton solves it in one step to the
    /// least-squares solution, which we check against the normal equations computed densely.
    struct Linear {
        a: Vec<(u32, u32, f64)>,
        b: Vec<f64>,
        n: usize,
    }
    impl NonlinearLeastSquares for Linear {
        fn num_variables(&self) -> usize {
            self.n
        }
        fn evaluate(&self, x: &[f64], out: &mut SparseSystem) {
            let mut r: Vec<f64> = self.b.iter().map(|b| -b).collect();
            for &(i, j, v) in &self.a {
                r[i as usize] += v * x[j as usize];
            }
            for v in r {
                out.push_residual(v);
            }
            for &(i, j, v) in &self.a {
                out.push_entry(i, j, v);
            }
        }
    }

    #[test]
    fn linear_least_squares_matches_dense_solution() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let (m, n) = (40, 12);
        let mut a = Vec::new();
        for i in 0..m {
            for j in 0..n {
                if j == i % n || rng.random::<f64>() < 0.3 {
                    a.push((i as u32, j as u32, rng.random::<f64>() * 2.0 - 1.0));
                }
            }
        }
        let b: Vec<f64> = (0..m).map(|_| rng.random::<f64>()).collect();
        let p = Linear {
            a: a.clone(),
            b: b.clone(),
            n,
        };
        let mut lm = LevenbergMarquardt::new(LmOptions {
            initial_damping: 0.0,
            min_damping: 0.0,
            ..LmOptions::default()
        });
        let mut x = vec![0.0; n];
        lm.step(&p, &mut x).unwrap();
        let mut dense = nalgebra::DMatrix::<f64>::zeros(m, n);
        for &(i, j, v) in &a {
            dense[(i as usize, j as usize)] += v;
        }
        let bv = nalgebra::DVector::from_vec(b);
        let want = (dense.transpose() * &dense)
            .cholesky()
            .unwrap()
            .solve(&(dense.transpose() * bv));
        for j in 0..n {
            assert!(
                (x[j] - want[j]).abs() < 1e-10,
                "{j}: {} vs {}",
                x[j],
                want[j]
            );
        }
    }

    #[test]
    fn non_finite_residuals_are_reported() {
        struct Bad;
        impl NonlinearLeastSquares for Bad {
            fn num_variables(&self) -> usize {
                1
            }
            fn evaluate(&self, _x: &[f64], out: &mut SparseSystem) {
                let r = out.push_residual(f64::NAN);
                out.push_entry(r, 0, 1.0);
            }
        }
        let mut lm = LevenbergMarquardt::new(LmOptions::default());
        assert_eq!(lm.step(&Bad, &mut [0.0]), Err(SolverError::NonFinite));
    }
}
