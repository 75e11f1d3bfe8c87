//! Assembly of square sparse matrices from (row, col, value) lists whose pattern repeats, with
//! the symbolic analysis (triplet order and symbolic factorisation) cached across calls.

use super::SolverError;
use faer::Side;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, SymbolicCholesky, SymmetricOrdering, factorize_symbolic_cholesky,
};
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::sparse::{Argsort, Pair, SparseColMat, SymbolicSparseColMat};
use faer::{Conj, Par};

/// Which factorisation a cached pattern feeds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Factor {
    /// Cholesky of a symmetric positive definite matrix whose upper triangle is given.
    CholeskyUpper,
    /// LU with partial pivoting of a general square matrix.
    Lu,
}

enum Symbolic {
    /// Supernodal Cholesky (forced: faer's automatic choice picks the simplicial kernel for
    /// our mesh matrices, several times slower here) with its value and scratch buffers.
    Llt {
        symbolic: Box<SymbolicCholesky<u32>>,
        values: Vec<f64>,
        scratch: MemBuffer,
    },
    Lu(SymbolicLu<u32>),
}

/// A square sparse matrix assembled repeatedly from the same index pattern.
pub(crate) struct PatternMatrix {
    kind: Factor,
    n: usize,
    /// The pattern the cache was built for.
    pairs: Vec<(u32, u32)>,
    cached: Option<(SymbolicSparseColMat<u32>, Argsort<u32>, Symbolic)>,
    /// Pairs of the matrix being assembled.
    pub new_pairs: Vec<(u32, u32)>,
    /// Values of the matrix being assembled, aligned with `new_pairs`.
    pub values: Vec<f64>,
}

impl PatternMatrix {
    pub(crate) fn new(kind: Factor) -> Self {
        PatternMatrix {
            kind,
            n: 0,
            pairs: Vec::new(),
            cached: None,
            new_pairs: Vec::new(),
            values: Vec::new(),
        }
    }

    /// Starts a new assembly of an `n x n` matrix.
    pub(crate) fn begin(&mut self, n: usize) {
        if n != self.n {
            self.cached = None;
            self.n = n;
        }
        self.new_pairs.clear();
        self.values.clear();
    }

    /// Adds `value` at (row, col); repeated positions are summed.
    #[inline]
    pub(crate) fn add(&mut self, row: u32, col: u32, value: f64) {
        self.new_pairs.push((row, col));
        self.values.push(value);
    }

    /// Factors the assembled matrix and solves `A x = rhs` in place.
    pub(crate) fn solve(&mut self, rhs: &mut [f64]) -> Result<(), SolverError> {
        let n = self.n;
        let fe = |e: &dyn std::fmt::Debug| SolverError::Factorization(format!("{e:?}"));
        if self.cached.is_none() || self.pairs != self.new_pairs {
            let idx: Vec<Pair<u32, u32>> = self
                .new_pairs
                .iter()
                .map(|&(r, c)| Pair::new(r, c))
                .collect();
            let (sym, argsort) =
                SymbolicSparseColMat::try_new_from_indices(n, n, &idx).map_err(|e| fe(&e))?;
            let symbolic = match self.kind {
                Factor::CholeskyUpper => {
                    let symbolic = factorize_symbolic_cholesky(
                        sym.as_ref(),
                        Side::Upper,
                        SymmetricOrdering::Amd,
                        CholeskySymbolicParams {
                            supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
                            ..Default::default()
                        },
                    )
                    .map_err(|e| fe(&e))?;
                    let req = symbolic
                        .factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default())
                        .or(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq));
                    Symbolic::Llt {
                        values: vec![0.0; symbolic.len_val()],
                        scratch: MemBuffer::try_new(req).map_err(|e| fe(&e))?,
                        symbolic: Box::new(symbolic),
                    }
                }
                Factor::Lu => Symbolic::Lu(SymbolicLu::try_new(sym.as_ref()).map_err(|e| fe(&e))?),
            };
            self.cached = Some((sym, argsort, symbolic));
            std::mem::swap(&mut self.pairs, &mut self.new_pairs);
            self.new_pairs.clear();
            self.new_pairs.extend_from_slice(&self.pairs);
        }
        let (sym, argsort, symbolic) = self.cached.as_mut().expect("cache built above");
        let mat = SparseColMat::<u32, f64>::new_from_argsort(sym.clone(), argsort, &self.values)
            .map_err(|e| fe(&e))?;
        let rhs_mat = faer::MatMut::from_column_major_slice_mut(rhs, n, 1);
        match symbolic {
            Symbolic::Llt {
                symbolic,
                values,
                scratch,
            } => {
                let f = symbolic
                    .factorize_numeric_llt(
                        values,
                        mat.as_ref(),
                        Side::Upper,
                        LltRegularization::default(),
                        Par::Seq,
                        MemStack::new(scratch),
                        Default::default(),
                    )
                    .map_err(|e| fe(&e))?;
                f.solve_in_place_with_conj(Conj::No, rhs_mat, Par::Seq, MemStack::new(scratch));
            }
            Symbolic::Lu(s) => {
                let f = Lu::try_new_with_symbolic(s.clone(), mat.as_ref()).map_err(|e| fe(&e))?;
                f.solve_in_place(rhs_mat);
            }
        }
        if rhs.iter().all(|v| v.is_finite()) {
            Ok(())
        } else {
            Err(SolverError::Factorization(
                "the solve produced non-finite values (singular matrix)".into(),
            ))
        }
    }
}

/// Reusable buffers of [`add_gram`].
#[derive(Default)]
pub(crate) struct GramScratch {
    row_start: Vec<usize>,
    order: Vec<usize>,
}

/// Adds JᵀJ of `sys` (n columns) to `pm`: only the upper triangle when `upper_only`, else both
/// triangles. Returns the diagonal of JᵀJ.
pub(crate) fn add_gram(
    sys: &super::SparseSystem,
    n: usize,
    pm: &mut PatternMatrix,
    upper_only: bool,
    scratch: &mut GramScratch,
) -> Vec<f64> {
    let m = sys.residuals.len();
    // Group the entries by row (counting sort).
    let row_start = &mut scratch.row_start;
    row_start.clear();
    row_start.resize(m + 1, 0);
    for e in &sys.entries {
        row_start[e.row as usize + 1] += 1;
    }
    for i in 0..m {
        row_start[i + 1] += row_start[i];
    }
    let order = &mut scratch.order;
    order.clear();
    order.resize(sys.entries.len(), 0);
    let mut fill = row_start.clone();
    for (k, e) in sys.entries.iter().enumerate() {
        let r = e.row as usize;
        order[fill[r]] = k;
        fill[r] += 1;
    }
    let mut diag = vec![0.0; n];
    for r in 0..m {
        let row = &order[row_start[r]..row_start[r + 1]];
        for &a in row {
            let ea = sys.entries[a];
            for &b in row {
                let eb = sys.entries[b];
                if !upper_only || ea.col <= eb.col {
                    pm.add(ea.col, eb.col, ea.value * eb.value);
                }
                if ea.col == eb.col {
                    diag[ea.col as usize] += ea.value * eb.value;
                }
            }
        }
    }
    diag
}
