//! Gauss-Newton with Levenberg-Marquardt damping on sparse normal equations (conical paper,
//! Sec. 2.2: "an unconstrained least squares problem which can be solved effectively by the
//! Gauss-Newton method with L-M regularization").

use super::block_normal::BlockNormal;
use super::block_system::{BlockLayout, BlockSystem};
use super::{SolverError, SparseSystem};

/// A nonlinear least-squares problem `min ½ |r(x)|²` with a sparse Jacobian.
pub trait NonlinearLeastSquares {
    /// Number of unknowns.
    fn num_variables(&self) -> usize;
    /// Fills `out` (cleared by the caller) with r(x) and the Jacobian triplets at `x`.
    fn evaluate(&self, x: &[f64], out: &mut SparseSystem);
    /// Optional block structure `(first, size)`: the variables `first..n` form consecutive
    /// blocks of `size` (1 to 4) unknowns and every residual touches at most one block (e.g. a
    /// face plane that only the face's own residuals see). The solver then eliminates the
    /// blocks (Schur complement) and factors a matrix on the first `first` variables only;
    /// the step is the same. `None` (the default) solves the full normal equations.
    fn local_blocks(&self) -> Option<(usize, usize)> {
        None
    }
}

/// A least-squares problem whose Jacobian comes in blocks (the crate's mesh problems): the
/// unknowns are grouped by a [`BlockLayout`] and every residual row gives its gradient per
/// block ([`BlockSystem`]).
pub(crate) trait BlockLeastSquares {
    /// The variable blocks.
    fn layout(&self) -> &BlockLayout;
    /// The blocks from this index on are local (every row touches at most one of them) and
    /// are eliminated before the sparse factorisation; the default eliminates none.
    fn local_from(&self) -> usize {
        self.layout().num_blocks()
    }
    /// Fills `out` (cleared by the caller) with r(x) and its block Jacobian at `x`.
    fn evaluate(&self, x: &[f64], out: &mut BlockSystem) -> Result<(), SolverError>;
    /// Relative damping weight of every variable (all 1 by default): the metric in which a
    /// damped step is short. Variables of different units (lengths and unit normals) need
    /// weights that make their moves comparable.
    fn damping_weights(&self) -> Option<&[f64]> {
        None
    }
}

/// A scalar [`NonlinearLeastSquares`] seen as blocks of one unknown (with its
/// [`NonlinearLeastSquares::local_blocks`] as local blocks).
struct Scalar<'a, P: ?Sized> {
    problem: &'a P,
    layout: BlockLayout,
    local_from: usize,
    block_of: Vec<(u32, u8)>,
}

impl<'a, P: NonlinearLeastSquares + ?Sized> Scalar<'a, P> {
    fn new(problem: &'a P) -> Self {
        let n = problem.num_variables();
        let blocks = problem.local_blocks().filter(|&(first, size)| {
            (1..=4).contains(&size) && first > 0 && first < n && (n - first).is_multiple_of(size)
        });
        let (first, size) = blocks.unwrap_or((n, 1));
        let sizes =
            std::iter::repeat_n(1, first).chain(std::iter::repeat_n(size, (n - first) / size));
        let block_of = (0..n)
            .map(|v| {
                if v < first {
                    (v as u32, 0)
                } else {
                    (
                        (first + (v - first) / size) as u32,
                        ((v - first) % size) as u8,
                    )
                }
            })
            .collect();
        Scalar {
            problem,
            layout: BlockLayout::new(sizes),
            local_from: first,
            block_of,
        }
    }
}

impl<P: NonlinearLeastSquares + ?Sized> BlockLeastSquares for Scalar<'_, P> {
    fn layout(&self) -> &BlockLayout {
        &self.layout
    }
    fn local_from(&self) -> usize {
        self.local_from
    }
    fn evaluate(&self, x: &[f64], out: &mut BlockSystem) -> Result<(), SolverError> {
        // A fresh triplet list per evaluation: `Scalar` lives for one step, so a kept buffer
        // would save a few allocations at the price of interior mutability.
        let mut triplets = SparseSystem::default();
        self.problem.evaluate(x, &mut triplets);
        out.fill_from_sparse(&triplets, &self.block_of)
    }
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
    /// Step halvings tried on a rejected step before the damping is raised (each costs one
    /// evaluation instead of a factorisation).
    pub step_halvings: usize,
    /// When the full step raises the cost, first try a second-order correction: one chord
    /// step from the trial point with the same factorisation (`h₂ = -(J₀ᵀJ₀ + μD)⁻¹ J₀ᵀ
    /// r(x + h)`, an evaluation and two triangular solves), accepted if `x + h + h₂` lowers
    /// the cost. The Maratos-effect remedy of SQP (Nocedal and Wright, Numerical
    /// Optimization, Sec. 15.6): on curved constraints the Newton step is right to first
    /// order and wrong to second, which halving throws away and the correction repairs.
    pub second_order_correction: bool,
    /// Factor by which the damping shrinks after an accepted step with a good model (gain
    /// ratio ρ > 0.75; less, by Nielsen's rule, for 0.5 < ρ ≤ 0.75; > 1).
    pub decrease: f64,
    /// The most memory the sparse factor may take, in bytes: a step whose analysis needs more
    /// fails with [`SolverError::TooLarge`] before the factor is allocated.
    pub max_factor_bytes: usize,
}

impl Default for LmOptions {
    fn default() -> Self {
        LmOptions {
            initial_damping: 1e-4,
            min_damping: 1e-15,
            max_retries: 12,
            decrease: 3.0,
            step_halvings: 0,
            second_order_correction: false,
            marquardt_scaling: false,
            max_factor_bytes: super::MAX_FACTOR_BYTES,
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

/// An iteration's analysis of its sparsity pattern, moved to another iteration
/// ([`LevenbergMarquardt::take_analysis`]).
pub(crate) struct LmAnalysis(BlockNormal);

/// A stateful Levenberg-Marquardt iteration: call [`LevenbergMarquardt::step`] repeatedly; the
/// problem may change its weights between steps (the PQ penalty schedule does).
pub struct LevenbergMarquardt {
    options: LmOptions,
    damping: f64,
    normal: BlockNormal,
    sys: BlockSystem,
    trial_sys: BlockSystem,
    /// Number of factorisations so far.
    factorizations: usize,
    /// The accepted point whose evaluation is in `trial_sys`, while still valid.
    cached_x: Option<Vec<f64>>,
    /// Damping the first rejected try jumps to (0: plain growth), see
    /// [`Self::set_damping_with_fallback`].
    fallback: f64,
    /// Whether the last step was accepted with the factorisation still held, `sys` keeping
    /// the Jacobian it was made from: a [`Self::chord_step`] may reuse it.
    chord_ready: bool,
    /// The damping of that factorisation.
    chord_damping: f64,
    /// Evaluation at a chord step's trial point.
    chord_sys: BlockSystem,
}

impl LevenbergMarquardt {
    /// A new iteration with the given settings.
    pub fn new(options: LmOptions) -> Self {
        let mut normal = BlockNormal::default();
        normal.set_factor_limit(options.max_factor_bytes);
        LevenbergMarquardt {
            options,
            damping: options.initial_damping,
            normal,
            sys: BlockSystem::default(),
            trial_sys: BlockSystem::default(),
            cached_x: None,
            factorizations: 0,
            fallback: 0.0,
            chord_ready: false,
            chord_damping: 0.0,
            chord_sys: BlockSystem::default(),
        }
    }

    /// Takes this iteration's analysis of the sparsity pattern (and its storage) for an
    /// iteration about to solve a problem of the same pattern ([`Self::adopt_analysis`]); this
    /// one keeps its counters and analyses again if it steps once more.
    pub(crate) fn take_analysis(&mut self) -> LmAnalysis {
        let mut fresh = BlockNormal::default();
        fresh.set_factor_limit(self.options.max_factor_bytes);
        self.chord_ready = false;
        LmAnalysis(std::mem::replace(&mut self.normal, fresh))
    }

    /// Starts from `normal`, another iteration's analysis ([`Self::take_analysis`]): the first
    /// step factorises at once when the pattern is the analysed one. The pattern is checked
    /// at that step as always; one the analysis does not cover is analysed anew.
    pub(crate) fn adopt_analysis(&mut self, LmAnalysis(mut normal): LmAnalysis) {
        normal.set_factor_limit(self.options.max_factor_bytes);
        self.normal = normal;
        self.chord_ready = false;
    }

    /// Tells the iteration that the problem changed (e.g. its weights), so the evaluation kept
    /// from the last accepted step must not be reused.
    pub fn invalidate(&mut self) {
        self.cached_x = None;
        self.chord_ready = false;
    }

    /// Number of sparse factorisations done so far (one per tried step).
    pub fn factorizations(&self) -> usize {
        self.factorizations
    }

    /// Number of symbolic analyses of a sparsity pattern done so far.
    pub fn analyses(&self) -> usize {
        self.normal.analyses()
    }

    /// Sets the relative damping μ.
    pub fn set_damping(&mut self, mu: f64) {
        self.damping = mu;
        self.fallback = 0.0;
    }

    /// Sets the relative damping μ to try first and the damping to jump to if that try is
    /// rejected (instead of growing by doubling factors, one factorisation each): e.g. a
    /// near-Newton first try in a new phase, falling back to the damping the previous phase
    /// ended with.
    pub fn set_damping_with_fallback(&mut self, mu: f64, fallback: f64) {
        self.damping = mu;
        self.fallback = fallback;
    }

    /// Turns the second-order correction ([`LmOptions::second_order_correction`]) on or off.
    pub fn set_second_order_correction(&mut self, on: bool) {
        self.options.second_order_correction = on;
    }

    /// The settings in force (with any changes made since [`Self::new`]).
    #[cfg(test)]
    pub(crate) fn options(&self) -> LmOptions {
        self.options
    }

    /// The current relative damping μ.
    pub fn damping(&self) -> f64 {
        self.damping
    }

    /// Assembles the normal equations of `self.sys` and returns the gradient Jᵀr and the
    /// per-variable damping scale `D`. The analysis of the Jacobian pattern is done once per
    /// pattern ([`BlockNormal`]); a repeated pattern costs one pass over the rows.
    fn assemble<P: BlockLeastSquares + ?Sized>(
        &mut self,
        problem: &P,
    ) -> Result<(Vec<f64>, Vec<f64>), SolverError> {
        let (g, mut diag) =
            self.normal
                .assemble(&self.sys, problem.layout(), problem.local_from())?;
        let scale = diag.iter().fold(0.0f64, |a, &b| a.max(b)).max(1e-300);
        for v in &mut diag {
            *v = if self.options.marquardt_scaling {
                *v + 1e-9 * scale
            } else {
                scale
            };
        }
        if let Some(w) = problem.damping_weights() {
            for (v, w) in diag.iter_mut().zip(w) {
                *v *= w;
            }
        }
        Ok((g, diag))
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
        self.step_blocks(&Scalar::new(problem), x)
    }

    /// [`Self::step`] for a block problem.
    pub(crate) fn step_blocks<P: BlockLeastSquares + ?Sized>(
        &mut self,
        problem: &P,
        x: &mut [f64],
    ) -> Result<LmStep, SolverError> {
        let layout = problem.layout();
        let n = layout.num_variables();
        self.chord_ready = false;
        if self.cached_x.as_deref() == Some(&*x) {
            std::mem::swap(&mut self.sys, &mut self.trial_sys);
        } else {
            self.sys.clear();
            problem.evaluate(x, &mut self.sys)?;
            self.sys.validate(layout)?;
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
        let (g, d) = self.assemble(problem)?;
        let mut trial = vec![0.0; n];
        let mut grow = 2.0;
        for _ in 0..=self.options.max_retries {
            self.factorizations += 1;
            let h = match self
                .normal
                .factor(layout, self.damping, &d)
                .and_then(|()| self.normal.solve(layout, &g))
            {
                Ok(h) => h,
                Err(_) => {
                    self.damping = (self.damping * 10.0).max(1e-12);
                    continue;
                }
            };
            // Try the full step, then (cheaper than a new factorisation) a few shortened ones.
            let mut h = h;
            let mut cost_after = f64::INFINITY;
            let mut shortened = false;
            for k in 0..=self.options.step_halvings {
                if k > 0 {
                    h.iter_mut().for_each(|v| *v *= 0.5);
                    shortened = true;
                }
                for i in 0..n {
                    trial[i] = x[i] + h[i];
                }
                self.trial_sys.clear();
                let ok = problem.evaluate(&trial, &mut self.trial_sys).is_ok()
                    && self.trial_sys.validate(layout).is_ok();
                cost_after = if ok {
                    self.trial_sys.cost()
                } else {
                    f64::INFINITY
                };
                if cost_after < cost_before {
                    break;
                }
                if k == 0
                    && ok
                    && self.options.second_order_correction
                    && self.trial_sys.same_pattern(&self.sys)
                {
                    let g2 = self.sys.gradient(layout, &self.trial_sys.residuals);
                    if let Ok(h2) = self.normal.solve(layout, &g2) {
                        let corrected: Vec<f64> =
                            trial.iter().zip(&h2).map(|(a, b)| a + b).collect();
                        self.chord_sys.clear();
                        let ok2 = problem.evaluate(&corrected, &mut self.chord_sys).is_ok()
                            && self.chord_sys.validate(layout).is_ok();
                        if ok2 && self.chord_sys.cost() < cost_before {
                            cost_after = self.chord_sys.cost();
                            std::mem::swap(&mut self.trial_sys, &mut self.chord_sys);
                            trial = corrected;
                            h.iter_mut().zip(&h2).for_each(|(a, b)| *a += b);
                            break;
                        }
                    }
                }
            }
            if cost_after < cost_before && shortened {
                x.copy_from_slice(&trial);
                self.cached_x = Some(trial);
                let used = self.damping;
                self.chord_ready = true;
                self.chord_damping = used;
                self.damping = (self.damping * 2.0).max(1e-12);
                return Ok(LmStep {
                    cost_before,
                    cost_after,
                    step_norm: h.iter().map(|v| v * v).sum::<f64>().sqrt(),
                    damping: used,
                });
            }
            if cost_after < cost_before {
                // Gain ratio against the model decrease ½ hᵀ(μ D h - g).
                let predicted: f64 = 0.5
                    * (0..n)
                        .map(|i| h[i] * (self.damping * d[i] * h[i] - g[i]))
                        .sum::<f64>();
                let rho = if predicted > 0.0 {
                    (cost_before - cost_after) / predicted
                } else {
                    1.0
                };
                x.copy_from_slice(&trial);
                self.cached_x = Some(trial);
                let used = self.damping;
                self.chord_ready = true;
                self.chord_damping = used;
                // Nielsen's update (1999), floored at 1/decrease: shrink fully only when the
                // model is nearly exact, barely on a fair one (ρ ≈ 0.7), grow on a poor one.
                // A fixed shrink on every ρ > 0.5 made the next try fail (a wasted
                // factorisation) about every second step on strongly curved constraints.
                // Good model (ρ > 0.75): the full shrink, so Newton steps (and their
                // quadratic convergence) are reached without delay.
                let factor = if rho > 0.75 {
                    1.0 / self.options.decrease
                } else {
                    (1.0 - (2.0 * rho - 1.0).powi(3)).clamp(1.0 / self.options.decrease, 2.0)
                };
                self.damping = (self.damping * factor).max(self.options.min_damping);
                return Ok(LmStep {
                    cost_before,
                    cost_after,
                    step_norm: h.iter().map(|v| v * v).sum::<f64>().sqrt(),
                    damping: used,
                });
            }
            self.damping = (self.damping * grow).max(1e-12).max(self.fallback);
            self.fallback = 0.0;
            grow *= 2.0;
        }
        Err(SolverError::NoDescent {
            damping: self.damping,
        })
    }

    /// [`Self::step`] at the current damping only: one factorisation (with its step halvings
    /// and second-order correction), no damping increases; [`SolverError::NoDescent`] when
    /// that step does not lower the cost (`x` unchanged). A trial of whether a problem is in
    /// reach of near-Newton steps, at the price of one factorisation.
    pub(crate) fn try_step_blocks<P: BlockLeastSquares + ?Sized>(
        &mut self,
        problem: &P,
        x: &mut [f64],
    ) -> Result<LmStep, SolverError> {
        let retries = std::mem::replace(&mut self.options.max_retries, 0);
        let step = self.step_blocks(problem, x);
        self.options.max_retries = retries;
        step
    }

    /// A chord (simplified Newton) step from `x`, the point the last accepted
    /// [`Self::step`] or chord step reached: `(J₀ᵀJ₀ + μD) h = -J₀ᵀ r(x)` with the Jacobian
    /// `J₀` and the factorisation of the last factored step and a fresh residual, so it costs
    /// one evaluation and two triangular solves instead of an assembly and a factorisation.
    /// The gradient must use `J₀` too: with `J(x)ᵀr` its part outside the row space of `J₀`
    /// would be amplified by `1/μ` on an underdetermined system. Converges linearly, at a
    /// rate proportional to the distance from the factored point, so it pays off in the
    /// quadratic phase of Newton's method (Kelley, Iterative Methods for Linear and Nonlinear
    /// Equations, 1995, Sec. 5.4).
    ///
    /// Returns `None` when no factorisation can be reused (nothing accepted since the last
    /// factorisation, [`Self::invalidate`] called, a different Jacobian pattern); then `x` is
    /// unchanged and [`Self::step`] is the way on. A step that does not lower the cost is
    /// not taken (`cost_after == cost_before`, `step_norm == 0`).
    pub fn chord_step<P: NonlinearLeastSquares + ?Sized>(
        &mut self,
        problem: &P,
        x: &mut [f64],
    ) -> Result<Option<LmStep>, SolverError> {
        self.chord_step_blocks(&Scalar::new(problem), x)
    }

    /// Keeps the last factorisation for chord steps on a changed problem of the same layout
    /// and Jacobian pattern (e.g. a held vertex moved): evaluates `problem` at `x`, the point
    /// the last accepted step reached, as the residual the next
    /// [`Self::chord_step_blocks`] starts from. False (and no chord step ready) when there
    /// is no factorisation to keep, `x` is not that point, or the evaluation fails or
    /// changes the pattern.
    pub(crate) fn keep_factor_for<P: BlockLeastSquares + ?Sized>(
        &mut self,
        problem: &P,
        x: &[f64],
    ) -> bool {
        if !self.chord_ready || self.cached_x.as_deref() != Some(x) {
            self.chord_ready = false;
            return false;
        }
        self.trial_sys.clear();
        let ok = problem.evaluate(x, &mut self.trial_sys).is_ok()
            && self.trial_sys.validate(problem.layout()).is_ok()
            && self.sys.same_pattern(&self.trial_sys);
        if !ok {
            self.chord_ready = false;
            self.cached_x = None;
        }
        ok
    }

    /// [`Self::chord_step`] for a block problem.
    pub(crate) fn chord_step_blocks<P: BlockLeastSquares + ?Sized>(
        &mut self,
        problem: &P,
        x: &mut [f64],
    ) -> Result<Option<LmStep>, SolverError> {
        let layout = problem.layout();
        if !self.chord_ready || self.cached_x.as_deref() != Some(&*x) {
            return Ok(None);
        }
        // `sys`: the evaluation the factor was made from; `trial_sys`: the one at `x`.
        if !self.sys.same_pattern(&self.trial_sys) {
            return Ok(None);
        }
        let cost_before = self.trial_sys.cost();
        let unchanged = LmStep {
            cost_before,
            cost_after: cost_before,
            step_norm: 0.0,
            damping: self.chord_damping,
        };
        if cost_before == 0.0 {
            return Ok(Some(unchanged));
        }
        let g = self.sys.gradient(layout, &self.trial_sys.residuals);
        let Ok(h) = self.normal.solve(layout, &g) else {
            self.chord_ready = false;
            return Ok(None);
        };
        let trial: Vec<f64> = x.iter().zip(&h).map(|(a, b)| a + b).collect();
        self.chord_sys.clear();
        let ok = problem.evaluate(&trial, &mut self.chord_sys).is_ok()
            && self.chord_sys.validate(layout).is_ok();
        let cost_after = if ok {
            self.chord_sys.cost()
        } else {
            f64::INFINITY
        };
        if cost_after >= cost_before {
            return Ok(Some(unchanged));
        }
        x.copy_from_slice(&trial);
        self.cached_x = Some(trial);
        std::mem::swap(&mut self.trial_sys, &mut self.chord_sys);
        Ok(Some(LmStep {
            cost_before,
            cost_after,
            step_norm: h.iter().map(|v| v * v).sum::<f64>().sqrt(),
            damping: self.chord_damping,
        }))
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

    /// On an underdetermined system (fewer residuals than unknowns, the constraints of the
    /// PQ exact phase) a step at near-zero damping is the SQP / Newton-KKT step of
    /// `min ½|h|²` subject to the linearised constraints `c + J h = 0`: the KKT system
    /// `[I Jᵀ; J 0] (h, λ) = (0, -c)`, solved densely here for comparison.
    #[test]
    fn underdetermined_step_is_the_kkt_min_norm_step() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let (m, n) = (12, 40);
        let mut a = Vec::new();
        for i in 0..m {
            for j in 0..n {
                if j % m == i || rng.random::<f64>() < 0.2 {
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
        let mut lm = LevenbergMarquardt::new(LmOptions::default());
        lm.set_damping(1e-9);
        let x0: Vec<f64> = (0..n).map(|_| rng.random::<f64>()).collect();
        let mut x = x0.clone();
        lm.step(&p, &mut x).unwrap();
        let mut j = nalgebra::DMatrix::<f64>::zeros(m, n);
        for &(i, k, v) in &a {
            j[(i as usize, k as usize)] += v;
        }
        let c = &j * nalgebra::DVector::from_column_slice(&x0) - nalgebra::DVector::from_vec(b);
        let mut kkt = nalgebra::DMatrix::<f64>::identity(n + m, n + m);
        kkt.view_mut((n, n), (m, m)).fill(0.0);
        kkt.view_mut((n, 0), (m, n)).copy_from(&j);
        kkt.view_mut((0, n), (n, m)).copy_from(&j.transpose());
        let mut rhs = nalgebra::DVector::<f64>::zeros(n + m);
        rhs.rows_mut(n, m).copy_from(&(-&c));
        let sol = kkt.lu().solve(&rhs).unwrap();
        let h_kkt = sol.rows(0, n);
        let h: Vec<f64> = x.iter().zip(&x0).map(|(a, b)| a - b).collect();
        let err = (0..n).map(|i| (h[i] - h_kkt[i]).abs()).fold(0.0, f64::max);
        // The damping (1e-9 of the largest diagonal) perturbs the step by ~1e-7 relative; a
        // different solution of the underdetermined system would differ by O(1).
        assert!(err <= 1e-5 * h_kkt.amax(), "step differs from KKT by {err}");
        // And the linear constraints are met after this one step.
        let c1 = &j
            * (nalgebra::DVector::from_column_slice(&x)
                - nalgebra::DVector::from_column_slice(&x0))
            + &c;
        assert!(c1.amax() <= 1e-5 * c.amax(), "{}", c1.amax());
    }

    /// An underdetermined nonlinear system `r_i = (A x)_i + x_i² x_{i+1} - b_i`.
    struct Bent {
        a: nalgebra::DMatrix<f64>,
        b: Vec<f64>,
    }
    impl Bent {
        fn jacobian(&self, x: &[f64]) -> nalgebra::DMatrix<f64> {
            let mut j = self.a.clone();
            for i in 0..self.a.nrows() {
                j[(i, i)] += 2.0 * x[i] * x[i + 1];
                j[(i, i + 1)] += x[i] * x[i];
            }
            j
        }
        fn residual(&self, x: &[f64]) -> nalgebra::DVector<f64> {
            let ax = &self.a * nalgebra::DVector::from_column_slice(x);
            nalgebra::DVector::from_fn(self.a.nrows(), |i, _| {
                ax[i] + x[i] * x[i] * x[i + 1] - self.b[i]
            })
        }
    }
    impl NonlinearLeastSquares for Bent {
        fn num_variables(&self) -> usize {
            self.a.ncols()
        }
        fn evaluate(&self, x: &[f64], out: &mut SparseSystem) {
            let (r, j) = (self.residual(x), self.jacobian(x));
            for i in 0..j.nrows() {
                let row = out.push_residual(r[i]);
                for k in 0..j.ncols() {
                    out.push_entry(row, k as u32, j[(i, k)]);
                }
            }
        }
    }

    /// A chord step after a near-Newton step is the minimum-norm simplified Newton step
    /// `-J₀ᵀ(J₀J₀ᵀ)⁻¹ r(x₁)` with the Jacobian of the factored point (no new factorisation),
    /// and it shrinks the residual; without an accepted factored step there is none.
    #[test]
    fn chord_step_reuses_the_factorisation_with_the_old_jacobian() {
        let mut rng = ChaCha8Rng::seed_from_u64(17);
        let (m, n) = (6, 10);
        let a = nalgebra::DMatrix::from_fn(m, n, |_, _| rng.random::<f64>() * 2.0 - 1.0);
        let b: Vec<f64> = (0..m).map(|_| rng.random::<f64>()).collect();
        let p = Bent { a, b };
        let mut lm = LevenbergMarquardt::new(LmOptions::default());
        let mut x: Vec<f64> = (0..n).map(|_| rng.random::<f64>() * 0.2).collect();
        assert_eq!(lm.chord_step(&p, &mut x), Ok(None));
        lm.set_damping(1e-9);
        let x0 = x.clone();
        lm.step(&p, &mut x).unwrap();
        assert_eq!(lm.factorizations(), 1);
        let x1 = x.clone();
        let s = lm.chord_step(&p, &mut x).unwrap().expect("a chord step");
        assert_eq!(lm.factorizations(), 1, "a chord step must not factor");
        let j0 = p.jacobian(&x0);
        let r1 = p.residual(&x1);
        let want = -j0.transpose() * (&j0 * j0.transpose()).lu().solve(&r1).unwrap();
        let h = nalgebra::DVector::from_fn(n, |i, _| x[i] - x1[i]);
        assert!((&h - &want).amax() <= 1e-6 * want.amax(), "{h} vs {want}");
        // With the Jacobian of x₁ instead, the step is a different one.
        let j1 = p.jacobian(&x1);
        let newton = -j1.transpose() * (&j1 * j1.transpose()).lu().solve(&r1).unwrap();
        assert!((&newton - &want).amax() > 1e-3 * want.amax());
        assert!(s.cost_after < 0.1 * s.cost_before, "{s:?}");
        assert!((p.residual(&x).norm_squared() * 0.5 - s.cost_after).abs() <= 1e-15);
        lm.invalidate();
        assert_eq!(lm.chord_step(&p, &mut x), Ok(None));
    }

    /// A linear problem whose last variables form blocks of 3 seen by one residual group each.
    struct Blocked {
        inner: Linear,
        blocks: Option<(usize, usize)>,
    }
    impl NonlinearLeastSquares for Blocked {
        fn num_variables(&self) -> usize {
            self.inner.n
        }
        fn evaluate(&self, x: &[f64], out: &mut SparseSystem) {
            self.inner.evaluate(x, out);
        }
        fn local_blocks(&self) -> Option<(usize, usize)> {
            self.blocks
        }
    }

    /// Eliminating the local blocks (Schur complement) gives the same damped step as the full
    /// normal equations, to rounding, and one fewer-unknown factorisation per try.
    #[test]
    fn block_elimination_gives_the_same_steps() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let (global, size, nb) = (10usize, 3usize, 6usize);
        let n = global + size * nb;
        let mut a = Vec::new();
        let mut m = 0u32;
        for blk in 0..nb {
            for _ in 0..5 {
                for j in 0..global {
                    if rng.random::<f64>() < 0.4 {
                        a.push((m, j as u32, rng.random::<f64>() * 2.0 - 1.0));
                    }
                }
                for k in 0..size {
                    a.push((
                        m,
                        (global + blk * size + k) as u32,
                        rng.random::<f64>() - 0.5,
                    ));
                }
                m += 1;
            }
        }
        for j in 0..global {
            a.push((m, j as u32, 1.0));
            m += 1;
        }
        let b: Vec<f64> = (0..m).map(|_| rng.random::<f64>()).collect();
        let make = |blocks| Blocked {
            inner: Linear {
                a: a.clone(),
                b: b.clone(),
                n,
            },
            blocks,
        };
        let options = LmOptions {
            initial_damping: 1e-3,
            ..LmOptions::default()
        };
        let (full, blocked) = (make(None), make(Some((global, size))));
        let (mut lm_full, mut lm_blocked) = (
            LevenbergMarquardt::new(options),
            LevenbergMarquardt::new(options),
        );
        let (mut x_full, mut x_blocked) = (vec![0.5; n], vec![0.5; n]);
        for _ in 0..3 {
            let s_full = lm_full.step(&full, &mut x_full).unwrap();
            let s_blocked = lm_blocked.step(&blocked, &mut x_blocked).unwrap();
            assert!(lm_blocked.normal.eliminates() && !lm_full.normal.eliminates());
            assert!((s_full.cost_after - s_blocked.cost_after).abs() <= 1e-12);
            for j in 0..n {
                assert!(
                    (x_full[j] - x_blocked[j]).abs() < 1e-10,
                    "{j}: {} vs {}",
                    x_full[j],
                    x_blocked[j]
                );
            }
        }
        // A residual that touches two blocks: the solver falls back to the full system.
        let mut two = make(Some((global, size)));
        two.inner.a.push((0, (global + size) as u32, 1.0));
        let mut lm = LevenbergMarquardt::new(options);
        let mut x = vec![0.5; n];
        lm.step(&two, &mut x).unwrap();
        assert!(!lm.normal.eliminates());
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
