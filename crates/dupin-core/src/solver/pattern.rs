//! Assembly of square sparse matrices from (row, col, value) lists whose pattern repeats, with
//! the symbolic analysis (triplet order and symbolic LU) cached across calls: the KKT
//! matrices of the SQP refinement. (The Gauss-Newton normal equations are assembled in blocks,
//! `block_normal.rs`, which uses [`csc_pattern`] on block pairs.)

use super::SolverError;
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};

/// A square sparse matrix assembled repeatedly from the same index pattern and solved by
/// sparse LU with partial pivoting.
pub(crate) struct PatternMatrix {
    n: usize,
    /// The (row, column) list the cached analysis was made for.
    pairs: Vec<(u32, u32)>,
    /// CSC pattern, CSC slot of every listed entry, symbolic LU.
    cached: Option<(SymbolicSparseColMat<u32>, Vec<u32>, SymbolicLu<u32>)>,
    csc_values: Vec<f64>,
    new_pairs: Vec<(u32, u32)>,
    values: Vec<f64>,
}

impl PatternMatrix {
    pub(crate) fn new() -> Self {
        PatternMatrix {
            n: 0,
            pairs: Vec::new(),
            cached: None,
            csc_values: Vec::new(),
            new_pairs: Vec::new(),
            values: Vec::new(),
        }
    }

    /// Starts a new `n x n` assembly.
    pub(crate) fn begin(&mut self, n: usize) {
        if n != self.n {
            self.cached = None;
            self.n = n;
        }
        self.new_pairs.clear();
        self.values.clear();
    }

    /// Adds `value` at (row, col); repeats are summed.
    #[inline]
    pub(crate) fn add(&mut self, row: u32, col: u32, value: f64) {
        self.new_pairs.push((row, col));
        self.values.push(value);
    }

    /// Solves `A x = rhs` in place for the assembled `A` (analysing its pattern only when it
    /// differs from the last one).
    pub(crate) fn solve(&mut self, rhs: &mut [f64]) -> Result<(), SolverError> {
        let n = self.n;
        let fe = |e: &dyn std::fmt::Debug| SolverError::Factorization(format!("{e:?}"));
        if self.cached.is_none() || self.pairs != self.new_pairs {
            let (sym, slots) = csc_pattern(n, &self.new_pairs)?;
            let lu = SymbolicLu::try_new(sym.as_ref()).map_err(|e| fe(&e))?;
            self.cached = Some((sym, slots, lu));
            std::mem::swap(&mut self.pairs, &mut self.new_pairs);
        }
        let (sym, slots, symbolic) = self.cached.as_ref().expect("cache built above");
        self.csc_values.clear();
        self.csc_values.resize(sym.row_idx().len(), 0.0);
        for (&slot, &v) in slots.iter().zip(&self.values) {
            self.csc_values[slot as usize] += v;
        }
        let mat = SparseColMatRef::<u32, f64>::new(sym.as_ref(), &self.csc_values);
        let f = Lu::try_new_with_symbolic(symbolic.clone(), mat.as_ref()).map_err(|e| fe(&e))?;
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

/// The CSC pattern (sorted rows per column) of a list of positions with repeats, and the CSC
/// position of every listed entry. Written by hand: faer's `try_new_from_indices` sorts all
/// entries, repeats included (several per product of the Gauss-Newton assembly, millions on
/// the large meshes); here bucketing by column and a per-row marker make it linear, and
/// only the distinct rows of a column are sorted.
pub(crate) fn csc_pattern(
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
