//! Assembly of square sparse matrices from (row, col, value) lists whose pattern repeats, with
//! the symbolic analysis (triplet order and symbolic factorisation) cached across calls.

use super::SolverError;
use super::cholesky::{Ordering, SparseCholesky};
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};

/// Which factorisation a cached pattern feeds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Factor {
    /// Cholesky of a symmetric positive definite matrix whose upper triangle is given.
    CholeskyUpper,
    /// LU with partial pivoting of a general square matrix.
    Lu,
}

enum Symbolic {
    /// Supernodal Cholesky on the AMD-permuted matrix: the cached slots point into its
    /// permuted layout.
    Llt(Box<SparseCholesky>),
    Lu(SymbolicLu<u32>),
}

/// A square sparse matrix assembled repeatedly from the same index pattern.
///
/// Two assembly modes: while a pattern is being built ([`Self::begin`]) positions and values
/// are recorded; once the pattern is analysed ([`Self::begin_values_only`]) every pushed
/// value goes straight to its precomputed CSC slot (no intermediate list, no sorting). A
/// base point ([`Self::mark_base`]) lets the caller redo the tail of an assembly (e.g. the
/// damping terms of a retried step) without redoing the rest.
pub(crate) struct PatternMatrix {
    kind: Factor,
    n: usize,
    /// The pattern the cache was built for.
    pairs: Vec<(u32, u32)>,
    /// Cached analysis: the CSC pattern, the slot of every assembled entry in the factored
    /// layout (the CSC one for LU, the permuted one of the Cholesky), so assembly is a
    /// scatter-add without re-sorting or allocating, and the symbolic factorisation.
    cached: Option<(SymbolicSparseColMat<u32>, Vec<u32>, Symbolic)>,
    /// CSC values of the matrix being factored (filled directly in values-only mode).
    csc_values: Vec<f64>,
    /// CSC values at the base point, restored by [`Self::truncate_to_base`].
    csc_base: Vec<f64>,
    /// Whether `csc_base` holds the base point of the current assembly.
    base_valid: bool,
    /// Number of entries pushed before the base point.
    base_len: usize,
    /// Number of entries pushed in values-only mode (index into the cached slots).
    cursor: usize,
    /// Pairs of the matrix being assembled (build mode).
    new_pairs: Vec<(u32, u32)>,
    /// Values of the matrix being assembled, aligned with `new_pairs` (build mode).
    values: Vec<f64>,
    /// Values-only mode: entries follow the cached pattern and go straight to `csc_values`.
    same_pattern: bool,
    /// The cached slots follow the entry order of the last build-mode assembly (false while
    /// a new one has not been analysed, e.g. after a failed analysis).
    fresh: bool,
    /// The Cholesky values hold the factor of the last successful [`Self::solve`] (reused by
    /// [`Self::solve_factored`]).
    factored: bool,
}

impl PatternMatrix {
    pub(crate) fn new(kind: Factor) -> Self {
        PatternMatrix {
            kind,
            n: 0,
            pairs: Vec::new(),
            cached: None,
            csc_values: Vec::new(),
            csc_base: Vec::new(),
            base_valid: false,
            base_len: 0,
            cursor: 0,
            new_pairs: Vec::new(),
            values: Vec::new(),
            same_pattern: false,
            fresh: false,
            factored: false,
        }
    }

    /// Whether a pattern has been analysed for size `n` (so values-only assembly is possible).
    pub(crate) fn has_pattern(&self, n: usize) -> bool {
        self.cached.is_some() && self.n == n && self.fresh
    }

    /// Starts a values-only assembly: the caller pushes values with [`Self::push`] in the
    /// exact order of the cached pattern (see [`Self::has_pattern`]).
    pub(crate) fn begin_values_only(&mut self) {
        debug_assert!(self.cached.is_some());
        let nnz = self.cached.as_ref().map_or(0, |c| c.0.row_idx().len());
        self.csc_values.clear();
        self.csc_values.resize(nnz, 0.0);
        self.cursor = 0;
        self.base_valid = false;
        self.same_pattern = true;
        self.factored = false;
    }

    /// Number of entries assembled so far.
    pub(crate) fn len(&self) -> usize {
        if self.same_pattern {
            self.cursor
        } else {
            self.values.len()
        }
    }

    /// Marks the current point of the assembly as the base that [`Self::truncate_to_base`]
    /// returns to.
    pub(crate) fn mark_base(&mut self) {
        self.base_len = self.len();
        if self.same_pattern {
            self.csc_base.clone_from(&self.csc_values);
            self.base_valid = true;
        } else {
            self.base_valid = false;
        }
    }

    /// Drops everything assembled after the base point, so the tail of an assembly can be
    /// redone (e.g. for a new damping).
    pub(crate) fn truncate_to_base(&mut self) {
        if self.same_pattern {
            debug_assert!(self.base_valid);
            self.csc_values.copy_from_slice(&self.csc_base);
            self.cursor = self.base_len;
        } else {
            self.values.truncate(self.base_len);
            self.new_pairs.truncate(self.base_len);
        }
    }

    /// Adds the next entry in either mode: its position is recorded while the pattern is being
    /// built (after [`Self::begin`]); in values-only mode it must follow the cached order.
    #[inline]
    pub(crate) fn push(&mut self, row: u32, col: u32, value: f64) {
        if self.same_pattern {
            let slots = &self
                .cached
                .as_ref()
                .expect("values-only mode has a pattern")
                .1;
            if let Some(&slot) = slots.get(self.cursor) {
                self.csc_values[slot as usize] += value;
            }
            // Past the end: caught by `solve` as a pattern mismatch.
            self.cursor += 1;
        } else {
            self.new_pairs.push((row, col));
            self.values.push(value);
        }
    }

    /// The destination of the next entries, for tight assembly loops: the same as calling
    /// [`Self::push`] for each, without looking up the mode every time.
    pub(crate) fn sink(&mut self) -> Sink<'_> {
        if self.same_pattern {
            Sink::Direct {
                slots: &self
                    .cached
                    .as_ref()
                    .expect("values-only mode has a pattern")
                    .1,
                csc: &mut self.csc_values,
                cursor: &mut self.cursor,
            }
        } else {
            Sink::Build {
                pairs: &mut self.new_pairs,
                values: &mut self.values,
            }
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
        self.base_valid = false;
        self.base_len = 0;
        self.same_pattern = false;
        self.fresh = false;
        self.factored = false;
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
        self.factored = false;
        if self.same_pattern {
            // Values-only assembly: the values are in place if exactly the cached entries came.
            let expected = self.cached.as_ref().map_or(usize::MAX, |c| c.1.len());
            if self.cursor != expected {
                return Err(SolverError::Factorization(
                    "values-only assembly without a matching pattern".into(),
                ));
            }
        }
        let mut reuse =
            self.same_pattern || (self.cached.is_some() && self.pairs == self.new_pairs);
        // A Cholesky pattern contained in the cached one (e.g. the constraints-only phase after
        // the penalty phase) reuses its symbolic factorisation: the missing entries are zeros.
        if !reuse
            && !self.same_pattern
            && self.kind == Factor::CholeskyUpper
            && let Some((sym, slots, Symbolic::Llt(chol))) = self.cached.as_mut()
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
                let positions = chol.positions();
                new_slots
                    .iter_mut()
                    .for_each(|k| *k = positions[*k as usize]);
                *slots = new_slots;
                std::mem::swap(&mut self.pairs, &mut self.new_pairs);
                self.new_pairs.clear();
                reuse = true;
            }
        }
        if !reuse {
            let (sym, mut slots) = csc_pattern(n, &self.new_pairs)?;
            let symbolic = match self.kind {
                Factor::CholeskyUpper => {
                    let chol = SparseCholesky::analyse(sym.as_ref(), Ordering::Amd)?;
                    let positions = chol.positions();
                    slots.iter_mut().for_each(|k| *k = positions[*k as usize]);
                    Symbolic::Llt(Box::new(chol))
                }
                Factor::Lu => Symbolic::Lu(SymbolicLu::try_new(sym.as_ref()).map_err(|e| fe(&e))?),
            };
            self.cached = Some((sym, slots, symbolic));
            std::mem::swap(&mut self.pairs, &mut self.new_pairs);
            self.new_pairs.clear();
        }
        self.fresh = true;
        let (sym, slots, symbolic) = self.cached.as_mut().expect("cache built above");
        if !self.same_pattern {
            // Scatter the recorded values (the part before the base point kept aside), then go
            // on in values-only mode: further tails (e.g. damping retries) need no comparison.
            self.csc_values.clear();
            self.csc_values.resize(sym.row_idx().len(), 0.0);
            let base = self.base_len.min(self.values.len());
            for (&slot, &v) in slots.iter().zip(&self.values[..base]) {
                self.csc_values[slot as usize] += v;
            }
            self.csc_base.clone_from(&self.csc_values);
            self.base_valid = true;
            for (&slot, &v) in slots[base..].iter().zip(&self.values[base..]) {
                self.csc_values[slot as usize] += v;
            }
            self.cursor = self.values.len();
            self.same_pattern = true;
        }
        match symbolic {
            Symbolic::Llt(chol) => {
                chol.factorize(&self.csc_values)?;
                self.factored = true;
                chol.solve_in_place(rhs)
            }
            Symbolic::Lu(s) => {
                let mat = SparseColMatRef::<u32, f64>::new(sym.as_ref(), &self.csc_values);
                let f = Lu::try_new_with_symbolic(s.clone(), mat.as_ref()).map_err(|e| fe(&e))?;
                f.solve_in_place(faer::MatMut::from_column_major_slice_mut(rhs, n, 1));
                if rhs.iter().all(|v| v.is_finite()) {
                    Ok(())
                } else {
                    Err(SolverError::Factorization(
                        "the solve produced non-finite values (singular matrix)".into(),
                    ))
                }
            }
        }
    }
}

impl PatternMatrix {
    /// Solves `A x = rhs` in place with the Cholesky factor of the last successful
    /// [`Self::solve`], without a new factorisation (chord steps). Fails when there is no such
    /// factor (an LU matrix, a failed factorisation, or a new assembly begun since).
    pub(crate) fn solve_factored(&mut self, rhs: &mut [f64]) -> Result<(), SolverError> {
        match self.cached.as_mut() {
            Some((_, _, Symbolic::Llt(chol))) if self.factored => chol.solve_in_place(rhs),
            _ => Err(SolverError::Factorization(
                "no factorisation to reuse".into(),
            )),
        }
    }
}

/// The CSC pattern (sorted rows per column) of a list of positions with repeats, and the CSC
/// position of every listed entry. Written by hand: faer's `try_new_from_indices` sorts all
/// entries, repeats included (several per product of the Gauss-Newton assembly, millions on
/// the large meshes); here bucketing by column and a per-row marker make it linear, and
/// only the distinct rows of a column are sorted.
fn csc_pattern(
    n: usize,
    pairs: &[(u32, u32)],
) -> Result<(SymbolicSparseColMat<u32>, Vec<u32>), SolverError> {
    if pairs
        .iter()
        .any(|&(r, c)| r as usize >= n || c as usize >= n)
        || pairs.len() >= u32::MAX as usize
    {
        return Err(SolverError::Factorization(
            "matrix entry outside the matrix".into(),
        ));
    }
    // Bucket the entries by column (counting sort).
    let mut start = vec![0u32; n + 1];
    for &(_, c) in pairs {
        start[c as usize + 1] += 1;
    }
    for c in 0..n {
        start[c + 1] += start[c];
    }
    let mut by_col = vec![0u32; pairs.len()];
    let mut fill = start.clone();
    for (k, &(_, c)) in pairs.iter().enumerate() {
        by_col[fill[c as usize] as usize] = k as u32;
        fill[c as usize] += 1;
    }
    // Distinct rows per column, sorted; `pos[r]` is the CSC position of row r in the column
    // being scanned, valid while `mark[r]` is that column.
    let mut mark = vec![u32::MAX; n];
    let mut pos = vec![0u32; n];
    let mut col_ptr = Vec::with_capacity(n + 1);
    let mut row_idx: Vec<u32> = Vec::new();
    let mut slots = vec![0u32; pairs.len()];
    col_ptr.push(0u32);
    for c in 0..n {
        let ks = &by_col[start[c] as usize..start[c + 1] as usize];
        let begin = row_idx.len();
        for &k in ks {
            let r = pairs[k as usize].0 as usize;
            if mark[r] != c as u32 {
                mark[r] = c as u32;
                row_idx.push(r as u32);
            }
        }
        row_idx[begin..].sort_unstable();
        for (at, &r) in row_idx[begin..].iter().enumerate() {
            pos[r as usize] = (begin + at) as u32;
        }
        for &k in ks {
            slots[k as usize] = pos[pairs[k as usize].0 as usize];
        }
        col_ptr.push(row_idx.len() as u32);
    }
    Ok((
        SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx),
        slots,
    ))
}

/// Where the entries of an assembly go, from [`PatternMatrix::sink`].
pub(crate) enum Sink<'a> {
    /// Pattern being built: positions and values are recorded.
    Build {
        pairs: &'a mut Vec<(u32, u32)>,
        values: &'a mut Vec<f64>,
    },
    /// Values-only: each value is added at its cached CSC slot.
    Direct {
        slots: &'a [u32],
        csc: &'a mut [f64],
        cursor: &'a mut usize,
    },
}

impl Sink<'_> {
    /// Adds the next entry (see [`PatternMatrix::push`]).
    #[inline(always)]
    pub(crate) fn push(&mut self, row: u32, col: u32, value: f64) {
        match self {
            Sink::Build { pairs, values } => {
                pairs.push((row, col));
                values.push(value);
            }
            Sink::Direct { slots, csc, cursor } => {
                // Past the end of the pattern: caught by `solve` as a mismatch.
                if let Some(&slot) = slots.get(**cursor)
                    && let Some(c) = csc.get_mut(slot as usize)
                {
                    *c += value;
                }
                **cursor += 1;
            }
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

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Every listed position maps to the CSC slot of its own (row, column), each column's rows
    /// are strictly increasing, and no position is missing or invented.
    #[test]
    fn csc_pattern_maps_every_entry_to_its_position() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let n = 30;
        let pairs: Vec<(u32, u32)> = (0..2000)
            .map(|_| (rng.random_range(0..n) as u32, rng.random_range(0..n) as u32))
            .collect();
        let (sym, slots) = csc_pattern(n, &pairs).unwrap();
        let (col_ptr, row_idx) = (sym.col_ptr(), sym.row_idx());
        for (&(r, c), &slot) in pairs.iter().zip(&slots) {
            let range = col_ptr[c as usize] as usize..col_ptr[c as usize + 1] as usize;
            assert!(range.contains(&(slot as usize)));
            assert_eq!(row_idx[slot as usize], r);
        }
        let mut distinct: Vec<(u32, u32)> = pairs.clone();
        distinct.sort_unstable_by_key(|&(r, c)| (c, r));
        distinct.dedup();
        assert_eq!(distinct.len(), row_idx.len());
        for c in 0..n {
            let rows = &row_idx[col_ptr[c] as usize..col_ptr[c + 1] as usize];
            assert!(rows.windows(2).all(|w| w[0] < w[1]));
        }
        assert!(csc_pattern(n, &[(0, n as u32)]).is_err());
    }
}
