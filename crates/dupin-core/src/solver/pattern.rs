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
use faer::sparse::{Pair, SparseColMatRef, SymbolicSparseColMat};
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
    /// Cached analysis: the CSC pattern, the CSC slot of every assembled entry (so assembly
    /// is a scatter-add without re-sorting or allocating) and the symbolic factorisation.
    cached: Option<(SymbolicSparseColMat<u32>, Vec<u32>, Symbolic)>,
    /// CSC values of the matrix being factored.
    csc_values: Vec<f64>,
    /// Pairs of the matrix being assembled.
    pub new_pairs: Vec<(u32, u32)>,
    /// Values of the matrix being assembled, aligned with `new_pairs`.
    pub values: Vec<f64>,
    /// The caller promised the same pattern as the cached one (values only were pushed).
    same_pattern: bool,
}

impl PatternMatrix {
    pub(crate) fn new(kind: Factor) -> Self {
        PatternMatrix {
            kind,
            n: 0,
            pairs: Vec::new(),
            cached: None,
            csc_values: Vec::new(),
            new_pairs: Vec::new(),
            values: Vec::new(),
            same_pattern: false,
        }
    }

    /// Whether a pattern has been analysed for size `n` (so values-only assembly is possible).
    pub(crate) fn has_pattern(&self, n: usize) -> bool {
        self.cached.is_some() && self.n == n
    }

    /// Starts a values-only assembly: the caller pushes values with [`Self::add_value`] in the
    /// exact order of the cached pattern.
    pub(crate) fn begin_values_only(&mut self) {
        self.values.clear();
        self.same_pattern = true;
    }

    /// Adds the next value of a values-only assembly.
    #[inline]
    pub(crate) fn add_value(&mut self, value: f64) {
        self.values.push(value);
    }

    /// Number of values assembled so far.
    pub(crate) fn len(&self) -> usize {
        self.values.len()
    }

    /// Drops the values (and, while the pattern is being built, the positions) after the
    /// first `len`, so the tail of an assembly can be redone (e.g. for a new damping).
    pub(crate) fn truncate(&mut self, len: usize) {
        self.values.truncate(len);
        if !self.same_pattern {
            self.new_pairs.truncate(len);
        }
    }

    /// Adds the next entry in either mode: its position is recorded only while the pattern
    /// is being built (after [`Self::begin`]); in values-only mode it must follow the cached
    /// order.
    #[inline]
    pub(crate) fn push(&mut self, row: u32, col: u32, value: f64) {
        if !self.same_pattern {
            self.new_pairs.push((row, col));
        }
        self.values.push(value);
    }

    /// Starts a new assembly of an `n x n` matrix.
    pub(crate) fn begin(&mut self, n: usize) {
        if n != self.n {
            self.cached = None;
            self.n = n;
        }
        self.new_pairs.clear();
        self.values.clear();
        self.same_pattern = false;
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
        let mut reuse = self.cached.is_some()
            && if self.same_pattern {
                self.values.len() == self.pairs.len()
            } else {
                self.pairs == self.new_pairs
            };
        // A Cholesky pattern contained in the cached one (e.g. the constraints-only phase after
        // the penalty phase) reuses its symbolic factorisation: the missing entries are zeros.
        if !reuse
            && !self.same_pattern
            && self.kind == Factor::CholeskyUpper
            && let Some((sym, slots, _)) = self.cached.as_mut()
        {
            let (col_ptr, row_idx) = (sym.col_ptr(), sym.row_idx());
            let mut new_slots = Vec::with_capacity(self.new_pairs.len());
            for &(r, c) in &self.new_pairs {
                if c as usize >= n {
                    break;
                }
                let range = col_ptr[c as usize] as usize..col_ptr[c as usize + 1] as usize;
                match row_idx[range.clone()].binary_search(&r) {
                    Ok(at) => new_slots.push((range.start + at) as u32),
                    Err(_) => break,
                }
            }
            // Only when the new pattern fills most of the cached one: a much sparser matrix
            // (e.g. without the fairness couplings) is cheaper to factor with its own analysis.
            let filled = if new_slots.len() == self.new_pairs.len() {
                let mut seen = vec![false; row_idx.len()];
                new_slots.iter().for_each(|&k| seen[k as usize] = true);
                seen.iter().filter(|&&b| b).count()
            } else {
                0
            };
            if 10 * filled >= 9 * row_idx.len() {
                *slots = new_slots;
                std::mem::swap(&mut self.pairs, &mut self.new_pairs);
                self.new_pairs.clear();
                reuse = true;
            }
        }
        if !reuse {
            if self.same_pattern {
                return Err(SolverError::Factorization(
                    "values-only assembly without a matching pattern".into(),
                ));
            }
            let idx: Vec<Pair<u32, u32>> = self
                .new_pairs
                .iter()
                .map(|&(r, c)| Pair::new(r, c))
                .collect();
            let (sym, _) =
                SymbolicSparseColMat::try_new_from_indices(n, n, &idx).map_err(|e| fe(&e))?;
            // The CSC position of every entry (rows are sorted within each column).
            let (col_ptr, row_idx) = (sym.col_ptr(), sym.row_idx());
            let slots = self
                .new_pairs
                .iter()
                .map(|&(r, c)| {
                    let range = col_ptr[c as usize] as usize..col_ptr[c as usize + 1] as usize;
                    let at = row_idx[range.clone()]
                        .binary_search(&r)
                        .expect("every entry is in the pattern built from the entries");
                    (range.start + at) as u32
                })
                .collect();
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
            self.cached = Some((sym, slots, symbolic));
            std::mem::swap(&mut self.pairs, &mut self.new_pairs);
            self.new_pairs.clear();
        }
        // The values now follow the cached pattern: further solves with changed values (e.g.
        // damping retries) reuse it without comparing.
        self.same_pattern = true;
        let (sym, slots, symbolic) = self.cached.as_mut().expect("cache built above");
        self.csc_values.clear();
        self.csc_values.resize(sym.row_idx().len(), 0.0);
        for (&slot, &v) in slots.iter().zip(&self.values) {
            self.csc_values[slot as usize] += v;
        }
        let mat = SparseColMatRef::<u32, f64>::new(sym.as_ref(), &self.csc_values);
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
    values_only: bool,
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
                    if values_only {
                        pm.add_value(ea.value * eb.value);
                    } else {
                        pm.add(ea.col, eb.col, ea.value * eb.value);
                    }
                }
                if ea.col == eb.col {
                    diag[ea.col as usize] += ea.value * eb.value;
                }
            }
        }
    }
    diag
}
