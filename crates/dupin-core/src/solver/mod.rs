//! A small sparse nonlinear least-squares engine shared by every optimisation of the core
//! (PQ / conical / circular perturbation here, P-Hex planarity optimisation later).
//!
//! A problem hands over its residuals and the sparse Jacobian as triplets in a
//! [`SparseSystem`] (the crate's own mesh problems as per-block gradients in a `BlockSystem`,
//! a vertex or face plane at a time). Two step types are offered:
//!
//! - [`LevenbergMarquardt`]: Gauss-Newton on the normal equations `(JᵀJ + μI) h = -Jᵀr` with
//!   Levenberg-Marquardt damping `μ` adapted after every accepted or rejected step (conical
//!   paper, Sec. 2.2, penalty method, eq. (5)). The normal matrix is assembled in blocks,
//!   local blocks (face planes) are eliminated, and the rest is factored by faer's sparse
//!   Cholesky (`block_normal.rs`).
//! - [`Sqp`]: sequential quadratic programming for `min ½|r(x)|²` subject to `c(x) = 0`, one
//!   Newton step on the KKT system of eq. (3) of the conical paper, factored by faer's sparse LU,
//!   with a soft line search on an exact-penalty merit function.
//!
//! Both cache the sparsity analysis (symbolic factorisation and the triplet order) and reuse it
//! as long as the problem emits the same (row, column) pattern, so iterating on a fixed mesh
//! costs one numeric factorisation per step.

mod block_normal;
mod block_system;
mod cholesky;
mod gauss_newton;
mod nested_dissection;
mod pattern;
mod sqp;
mod supernodal_llt;

pub(crate) use block_normal::fill_reducing_analysis;
pub(crate) use block_system::{BlockLayout, BlockSystem};
pub(crate) use cholesky::{CholeskyAnalysis, SparseCholesky};
pub(crate) use gauss_newton::{BlockLeastSquares, LmAnalysis};
pub use gauss_newton::{LevenbergMarquardt, LmOptions, LmStep, NonlinearLeastSquares};
pub(crate) use nested_dissection::amd_ordering;
pub(crate) use pattern::csc_pattern;
pub use sqp::{ConstrainedLeastSquares, Sqp, SqpOptions, SqpStep};

use thiserror::Error;

/// The most memory a sparse Cholesky factor may take: what a 2-core, 8 GB laptop and a
/// browser tab (whose wasm memory stops at 4 GB) survive beside the rest of the computation.
pub const MAX_FACTOR_BYTES: usize = 2_000_000_000;

/// Why a solver step failed.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SolverError {
    /// A residual or Jacobian entry was NaN or infinite.
    #[error("the problem produced a non-finite residual or derivative")]
    NonFinite,
    /// A Jacobian entry names a variable or residual outside the declared sizes.
    #[error("Jacobian entry ({row}, {col}) is outside the {rows} x {cols} system")]
    OutOfRange {
        /// Residual index of the entry.
        row: usize,
        /// Variable index of the entry.
        col: usize,
        /// Number of residuals.
        rows: usize,
        /// Number of variables.
        cols: usize,
    },
    /// The sparse factorisation failed (matrix numerically singular or not positive definite
    /// even after damping).
    #[error("sparse factorisation failed: {0}")]
    Factorization(String),
    /// The factorisation would need more memory than the limit (estimated from the sparsity
    /// pattern before any numeric work).
    #[error(
        "the sparse factorisation needs {:.2} GB, more than the limit of {:.2} GB; use a coarser \
         mesh or split it into parts",
        *.needed as f64 / 1e9,
        *.limit as f64 / 1e9
    )]
    TooLarge {
        /// Bytes the factor would take.
        needed: usize,
        /// The limit in bytes ([`MAX_FACTOR_BYTES`]).
        limit: usize,
    },
    /// No step reduced the objective, even with the largest damping tried.
    #[error("no descent step found (damping {damping:e})")]
    NoDescent {
        /// The damping at which the search stopped.
        damping: f64,
    },
}

/// One entry of a sparse Jacobian: ∂ residual\[row\] / ∂ x\[col\].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JacobianEntry {
    /// Residual index.
    pub row: u32,
    /// Variable index.
    pub col: u32,
    /// The derivative.
    pub value: f64,
}

/// Residual values and their sparse Jacobian, as filled in by a problem.
///
/// Entries may come in any order and repeat a (row, col) pair (repeats are summed). Keeping the
/// same pattern from one evaluation to the next lets the solvers reuse their sparsity analysis.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SparseSystem {
    /// Residual values r_i(x).
    pub residuals: Vec<f64>,
    /// Jacobian entries.
    pub entries: Vec<JacobianEntry>,
}

impl SparseSystem {
    /// An empty system.
    pub fn new() -> Self {
        Self::default()
    }

    /// Removes all residuals and entries, keeping the allocations.
    pub fn clear(&mut self) {
        self.residuals.clear();
        self.entries.clear();
    }

    /// Appends a residual and returns its row index.
    pub fn push_residual(&mut self, value: f64) -> u32 {
        self.residuals.push(value);
        (self.residuals.len() - 1) as u32
    }

    /// Appends a Jacobian entry.
    pub fn push_entry(&mut self, row: u32, col: u32, value: f64) {
        self.entries.push(JacobianEntry { row, col, value });
    }

    /// Half the squared norm of the residuals, ½ Σ r_i².
    pub fn cost(&self) -> f64 {
        0.5 * self.residuals.iter().map(|r| r * r).sum::<f64>()
    }

    /// Largest absolute residual (0 when empty).
    pub fn max_abs(&self) -> f64 {
        self.residuals.iter().fold(0.0, |m, r| m.max(r.abs()))
    }

    /// Checks that everything is finite and inside `num_variables` columns.
    pub fn validate(&self, num_variables: usize) -> Result<(), SolverError> {
        if !self.residuals.iter().all(|r| r.is_finite()) {
            return Err(SolverError::NonFinite);
        }
        for e in &self.entries {
            if !e.value.is_finite() {
                return Err(SolverError::NonFinite);
            }
            if e.col as usize >= num_variables || e.row as usize >= self.residuals.len() {
                return Err(SolverError::OutOfRange {
                    row: e.row as usize,
                    col: e.col as usize,
                    rows: self.residuals.len(),
                    cols: num_variables,
                });
            }
        }
        Ok(())
    }

    /// Jᵀ r, the gradient of [`SparseSystem::cost`].
    pub fn gradient(&self, num_variables: usize) -> Vec<f64> {
        let mut g = vec![0.0; num_variables];
        for e in &self.entries {
            g[e.col as usize] += e.value * self.residuals[e.row as usize];
        }
        g
    }
}
