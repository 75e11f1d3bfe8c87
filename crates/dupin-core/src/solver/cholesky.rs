//! Sparse Cholesky factorisation of symmetric positive definite matrices whose pattern
//! repeats, shared by the solvers (the Gauss-Newton normal equations of
//! [`super::block_normal`] and the P-Hex planarity optimisation): the symbolic analysis for a
//! given fill-reducing
//! ordering once, then any number of numeric factorisations and solves (faer's supernodal
//! Cholesky).
//!
//! Input: the upper triangle pattern of `A` (CSC, sorted rows) and a fill-reducing ordering
//! (`fwd[new] = old`, chosen by the caller: AMD on a block or vertex graph). The
//! matrix is stored already permuted, `P A Pᵀ` as its lower triangle (faer's supernodal
//! layout), and the values are written straight into that layout through
//! [`SparseCholesky::positions`]; so faer's analysis runs with the identity ordering and
//! its per-factorisation copy of `A` into the permuted order (`permute_self_adjoint`, 2-4%
//! of a PQ run) is not needed. The result is the same factorisation.

use super::SolverError;
use super::supernodal_llt::{self, SupernodalPlan};
use faer::Side;
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
    factorize_symbolic_cholesky,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat, SymbolicSparseColMatRef};
use faer::{Conj, Par};
use std::sync::Arc;

/// A symbolic Cholesky analysis of one pattern with its numeric storage and workspace.
pub(crate) struct SparseCholesky {
    /// `fwd[new] = old`, `inv[old] = new`.
    fwd: Vec<u32>,
    inv: Vec<u32>,
    /// Pattern of `P A Pᵀ`, lower triangle.
    lower: SymbolicSparseColMat<u32>,
    /// For every entry of the input upper pattern (in its CSC order), its position in `lower`.
    positions: Vec<u32>,
    /// Shared by copies ([`Self::try_clone`]): never changed after the analysis.
    symbolic: Arc<SymbolicCholesky<u32>>,
    /// Values of the factor L.
    factor: Vec<f64>,
    scratch: MemBuffer,
    /// What `scratch` was sized for.
    scratch_req: StackReq,
    /// Permuted right-hand side.
    work: Vec<f64>,
    /// `factor` holds the factorisation of the last successful [`Self::factorize`].
    factored: bool,
    /// The hand-written numeric factorisation's plan and scratch (made on its first use).
    by_hand: Option<(SupernodalPlan, Vec<u32>)>,
    /// The last factorisation was the hand-written one, so its solves are too.
    solve_by_hand: bool,
}

/// Whether the numeric factorisation is [`super::supernodal_llt`]'s rather than faer's: on
/// wasm32, where faer's supernodal updates take its generic matrix product (see there).
const BY_HAND: bool = cfg!(target_arch = "wasm32");

/// Turns per-bucket counts (in `v[1..]`) into bucket starts.
fn prefix_sum(v: &mut [u32]) {
    for i in 1..v.len() {
        v[i] += v[i - 1];
    }
}

fn fe(e: &dyn std::fmt::Debug) -> SolverError {
    SolverError::Factorization(format!("{e:?}"))
}

impl SparseCholesky {
    /// Analyses the upper-triangle pattern `upper` (square, sorted rows, diagonal included)
    /// for the given ordering. Fails on a malformed ordering or when faer runs out of memory.
    pub(crate) fn analyse(
        upper: SymbolicSparseColMatRef<'_, u32>,
        fwd: &[u32],
    ) -> Result<Self, SolverError> {
        Self::analyse_within(upper, fwd, super::MAX_FACTOR_BYTES)
    }

    /// [`Self::analyse`] with a memory limit for the factor, in bytes.
    pub(crate) fn analyse_within(
        upper: SymbolicSparseColMatRef<'_, u32>,
        fwd: &[u32],
        limit: usize,
    ) -> Result<Self, SolverError> {
        Self::from_analysis(CholeskyAnalysis::new(upper, fwd)?, limit)
    }

    /// The factorisation of an analysis: refused when its factor needs more than `limit`
    /// bytes, before the factor is allocated.
    pub(crate) fn from_analysis(a: CholeskyAnalysis, limit: usize) -> Result<Self, SolverError> {
        let CholeskyAnalysis {
            fwd,
            inv,
            lower,
            positions,
            symbolic,
        } = a;
        let n = fwd.len();
        // The factor's size is known from the pattern: refuse before allocating it (an
        // allocation failure aborts the process, and in a browser kills the worker).
        let needed = symbolic
            .len_val()
            .saturating_mul(std::mem::size_of::<f64>());
        if needed > limit {
            return Err(SolverError::TooLarge { needed, limit });
        }
        // Zeroed by the allocator (calloc: pages zeroed on first touch), not by a memset.
        let factor = vec![0.0; symbolic.len_val()];
        let req = symbolic
            .factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default())
            .or(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq));
        Ok(SparseCholesky {
            fwd,
            inv,
            lower,
            positions,
            factor,
            scratch: MemBuffer::try_new(req).map_err(|e| fe(&e))?,
            scratch_req: req,
            symbolic: Arc::new(symbolic),
            work: vec![0.0; n],
            factored: false,
            by_hand: None,
            solve_by_hand: false,
        })
    }

    /// A copy with the same analysis (shared) and the same factor values, so it solves with the
    /// last factorisation as this one does. faer's symbolic factorisation is not `Clone`, and
    /// the scratch buffer is allocated afresh (so this can fail on memory, as the analysis can).
    pub(crate) fn try_clone(&self) -> Result<Self, SolverError> {
        Ok(SparseCholesky {
            fwd: self.fwd.clone(),
            inv: self.inv.clone(),
            lower: self.lower.clone(),
            positions: self.positions.clone(),
            symbolic: Arc::clone(&self.symbolic),
            factor: self.factor.clone(),
            scratch: MemBuffer::try_new(self.scratch_req).map_err(|e| fe(&e))?,
            scratch_req: self.scratch_req,
            work: self.work.clone(),
            factored: self.factored,
            by_hand: self.by_hand.clone(),
            solve_by_hand: self.solve_by_hand,
        })
    }

    /// Whether a factorisation is there to solve with.
    pub(crate) fn is_factored(&self) -> bool {
        self.factored
    }

    /// Number of stored matrix entries (of the upper triangle, = of the permuted lower one).
    pub(crate) fn nnz(&self) -> usize {
        self.positions.len()
    }

    /// Stored entries of the factor L (supernodal blocks included).
    pub(crate) fn factor_len(&self) -> usize {
        self.factor.len()
    }

    /// Where entry `k` of the input upper pattern (CSC order) lives in the values passed to
    /// [`Self::factorize`].
    pub(crate) fn positions(&self) -> &[u32] {
        &self.positions
    }

    /// Factors the matrix whose values are given in the permuted layout (see
    /// [`Self::positions`]). Fails when it is not numerically positive definite.
    pub(crate) fn factorize(&mut self, values: &[f64]) -> Result<(), SolverError> {
        self.factorize_by(values, BY_HAND)
    }

    /// [`Self::factorize`] by faer's numeric factorisation or, `by_hand`, by
    /// [`super::supernodal_llt`] (where faer's analysis is supernodal).
    fn factorize_by(&mut self, values: &[f64], by_hand: bool) -> Result<(), SolverError> {
        self.factored = false;
        self.solve_by_hand = false;
        if values.len() != self.positions.len() {
            return Err(SolverError::Factorization(
                "values do not match the analysed pattern".into(),
            ));
        }
        if by_hand && let SymbolicCholeskyRaw::Supernodal(symbolic) = self.symbolic.raw() {
            let (plan, local) = self.by_hand.get_or_insert_with(|| {
                (
                    SupernodalPlan::new(symbolic),
                    vec![u32::MAX; symbolic.nrows()],
                )
            });
            let lower = (self.lower.col_ptr(), self.lower.row_idx(), values);
            self.solve_by_hand = true;
            supernodal_llt::factorize(symbolic, plan, lower, &mut self.factor, local).map_err(
                |index| {
                    fe(&faer::linalg::cholesky::llt::factor::LltError::NonPositivePivot { index })
                },
            )?;
            self.factored = true;
            return Ok(());
        }
        let mat = SparseColMatRef::<u32, f64>::new(self.lower.as_ref(), values);
        self.symbolic
            .factorize_numeric_llt(
                &mut self.factor,
                mat,
                Side::Lower,
                LltRegularization::default(),
                Par::Seq,
                MemStack::new(&mut self.scratch),
                Default::default(),
            )
            .map_err(|e| fe(&e))?;
        self.factored = true;
        Ok(())
    }

    /// Solves `A x = rhs` in place with the last factorisation (any number of times). Fails
    /// when there is none or the solution is not finite.
    pub(crate) fn solve_in_place(&mut self, rhs: &mut [f64]) -> Result<(), SolverError> {
        let n = self.fwd.len();
        if !self.factored || rhs.len() != n {
            return Err(SolverError::Factorization(
                "no factorisation to solve with".into(),
            ));
        }
        for (w, &old) in self.work.iter_mut().zip(&self.fwd) {
            *w = rhs[old as usize];
        }
        match self.symbolic.raw() {
            SymbolicCholeskyRaw::Supernodal(symbolic) if self.solve_by_hand => {
                supernodal_llt::solve_in_place(symbolic, &self.factor, &mut self.work);
            }
            _ => {
                let llt = faer::sparse::linalg::cholesky::LltRef::new(&self.symbolic, &self.factor);
                llt.solve_in_place_with_conj(
                    Conj::No,
                    faer::MatMut::from_column_major_slice_mut(&mut self.work, n, 1),
                    Par::Seq,
                    MemStack::new(&mut self.scratch),
                );
            }
        }
        for (r, &new) in rhs.iter_mut().zip(&self.inv) {
            *r = self.work[new as usize];
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

/// The symbolic side of a [`SparseCholesky`]: the permuted pattern and faer's symbolic
/// factorisation for one ordering, without the factor's storage, so that orderings can be
/// compared by the size of their factor before one is allocated.
pub(crate) struct CholeskyAnalysis {
    fwd: Vec<u32>,
    inv: Vec<u32>,
    lower: SymbolicSparseColMat<u32>,
    positions: Vec<u32>,
    symbolic: SymbolicCholesky<u32>,
}

impl CholeskyAnalysis {
    /// Entries of the factor L this ordering leads to (supernodal blocks included).
    pub(crate) fn factor_len(&self) -> usize {
        self.symbolic.len_val()
    }

    /// Analyses the upper-triangle pattern `upper` (square, sorted rows, diagonal included)
    /// for the ordering `fwd` (`fwd[new] = old`). Fails on a malformed ordering or when faer
    /// runs out of memory.
    pub(crate) fn new(
        upper: SymbolicSparseColMatRef<'_, u32>,
        fwd: &[u32],
    ) -> Result<Self, SolverError> {
        let n = upper.ncols();
        let fwd = fwd.to_vec();
        if fwd.len() != n {
            return Err(SolverError::Factorization(
                "the ordering has the wrong length".into(),
            ));
        }
        let mut inv = vec![u32::MAX; n];
        for (new, &old) in fwd.iter().enumerate() {
            if old as usize >= n || inv[old as usize] != u32::MAX {
                return Err(SolverError::Factorization(
                    "the ordering is not a permutation".into(),
                ));
            }
            inv[old as usize] = new as u32;
        }
        // The permuted entries (row >= col in the lower triangle): bucketed by row, then by
        // column walking the rows in order, so every column comes out sorted (two counting
        // sorts, no comparison sort).
        let (col_ptr, row_idx) = (upper.col_ptr(), upper.row_idx());
        let nnz = row_idx.len();
        let entry = |k: usize, c: usize| {
            let (i, j) = (inv[row_idx[k] as usize], inv[c]);
            (i.max(j), i.min(j))
        };
        let mut row_ptr = vec![0u32; n + 1];
        for c in 0..n {
            for k in col_ptr[c] as usize..col_ptr[c + 1] as usize {
                row_ptr[entry(k, c).0 as usize + 1] += 1;
            }
        }
        prefix_sum(&mut row_ptr);
        let mut by_row = vec![(0u32, 0u32); nnz];
        let mut fill = row_ptr.clone();
        for c in 0..n {
            for k in col_ptr[c] as usize..col_ptr[c + 1] as usize {
                let (row, col) = entry(k, c);
                by_row[fill[row as usize] as usize] = (col, k as u32);
                fill[row as usize] += 1;
            }
        }
        let mut lower_ptr = vec![0u32; n + 1];
        by_row
            .iter()
            .for_each(|&(col, _)| lower_ptr[col as usize + 1] += 1);
        prefix_sum(&mut lower_ptr);
        let mut fill = lower_ptr.clone();
        let mut lower_row = vec![0u32; nnz];
        let mut positions = vec![0u32; nnz];
        for row in 0..n {
            for &(col, k) in &by_row[row_ptr[row] as usize..row_ptr[row + 1] as usize] {
                let at = fill[col as usize] as usize;
                lower_row[at] = row as u32;
                positions[k as usize] = at as u32;
                fill[col as usize] += 1;
            }
        }
        // faer's analysis takes the upper triangle: the transpose of `lower`, whose columns
        // are the rows counted in `row_ptr`.
        let upper_ptr = row_ptr;
        let mut fill = upper_ptr.clone();
        let mut upper_row = vec![0u32; nnz];
        // Columns of `lower` in increasing order, so each column of the transpose is sorted.
        for c in 0..n {
            for &row in &lower_row[lower_ptr[c] as usize..lower_ptr[c + 1] as usize] {
                upper_row[fill[row as usize] as usize] = c as u32;
                fill[row as usize] += 1;
            }
        }
        let lower = SymbolicSparseColMat::new_checked(n, n, lower_ptr, None, lower_row);
        let permuted_upper = SymbolicSparseColMat::new_checked(n, n, upper_ptr, None, upper_row);
        let symbolic = factorize_symbolic_cholesky(
            permuted_upper.as_ref(),
            Side::Upper,
            SymmetricOrdering::Identity,
            CholeskySymbolicParams {
                // faer's automatic choice picks the simplicial kernel for mesh matrices,
                // several times slower here.
                supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
                ..Default::default()
            },
        )
        .map_err(|e| fe(&e))?;
        Ok(CholeskyAnalysis {
            fwd,
            inv,
            lower,
            positions,
            symbolic,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// A random sparse SPD matrix, factored through the permuted layout with AMD and with a
    /// custom (reversed) ordering, solves `A x = b` as the dense Cholesky does.
    #[test]
    fn permuted_factorisation_solves_like_dense() {
        let mut rng = ChaCha8Rng::seed_from_u64(23);
        let n = 40;
        let mut dense = nalgebra::DMatrix::<f64>::zeros(n, n);
        for i in 0..n {
            for j in i + 1..n {
                if rng.random::<f64>() < 0.1 {
                    let v = rng.random::<f64>() - 0.5;
                    dense[(i, j)] = v;
                    dense[(j, i)] = v;
                }
            }
            dense[(i, i)] = 4.0 + rng.random::<f64>();
        }
        let mut col_ptr = vec![0u32];
        let mut row_idx = Vec::new();
        let mut upper_values = Vec::new();
        for c in 0..n {
            for r in 0..=c {
                if dense[(r, c)] != 0.0 {
                    row_idx.push(r as u32);
                    upper_values.push(dense[(r, c)]);
                }
            }
            col_ptr.push(row_idx.len() as u32);
        }
        let upper = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
        let b: Vec<f64> = (0..n).map(|_| rng.random::<f64>()).collect();
        let want = dense
            .clone()
            .cholesky()
            .unwrap()
            .solve(&nalgebra::DVector::from_column_slice(&b));
        let reversed: Vec<u32> = (0..n as u32).rev().collect();
        let identity: Vec<u32> = (0..n as u32).collect();
        for ordering in [&identity, &reversed] {
            let mut chol = SparseCholesky::analyse(upper.as_ref(), ordering).unwrap();
            let mut values = vec![0.0; chol.nnz()];
            for (k, &v) in upper_values.iter().enumerate() {
                values[chol.positions()[k] as usize] = v;
            }
            let mut x = b.clone();
            assert!(chol.solve_in_place(&mut x).is_err(), "not factored yet");
            chol.factorize(&values).unwrap();
            for _ in 0..2 {
                let mut x = b.clone();
                chol.solve_in_place(&mut x).unwrap();
                for i in 0..n {
                    assert!(
                        (x[i] - want[i]).abs() < 1e-12,
                        "{i}: {} vs {}",
                        x[i],
                        want[i]
                    );
                }
            }
        }
        assert!(SparseCholesky::analyse(upper.as_ref(), &[0, 0]).is_err());
    }

    /// A factor larger than the limit is refused from its pattern, before any numeric work,
    /// with both sizes in the message.
    #[test]
    fn factors_beyond_the_memory_limit_are_refused() {
        // A dense 30 x 30 pattern: its factor holds at least 465 entries, 3720 bytes.
        let n = 30u32;
        let col_ptr: Vec<u32> = (0..=n).map(|c| c * (c + 1) / 2).collect();
        let row_idx: Vec<u32> = (0..n).flat_map(|c| 0..=c).collect();
        let upper =
            SymbolicSparseColMat::new_checked(n as usize, n as usize, col_ptr, None, row_idx);
        let fwd: Vec<u32> = (0..n).collect();
        assert!(SparseCholesky::analyse_within(upper.as_ref(), &fwd, 100_000).is_ok());
        match SparseCholesky::analyse_within(upper.as_ref(), &fwd, 1000) {
            Err(e @ SolverError::TooLarge { needed, limit }) => {
                assert!(needed >= 3720 && limit == 1000, "{needed}");
                assert!(e.to_string().contains("GB, more than the limit"), "{e}");
            }
            other => panic!("expected TooLarge, got {:?}", other.map(|_| ())),
        }
    }

    /// The hand-written numeric factorisation (wasm32's) writes faer's factor, entry for
    /// entry to rounding, and its solve finds faer's solution, on random sparse SPD matrices
    /// of 1 to 4 900 unknowns (supernodes from one column to dense blocks of hundreds, short
    /// and full groups of its kernel) under AMD, nested dissection and the identity ordering;
    /// and it refuses an indefinite matrix.
    #[test]
    fn the_hand_written_factorisation_writes_faer_s_factor() {
        use crate::solver::block_normal::fill_reducing_ordering;
        use crate::solver::{amd_ordering, csc_pattern};
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        // (unknowns, random couplings per unknown, grid side: a 5-point grid stencil when > 0)
        for (n, per, side) in [
            (1, 0, 0),
            (2, 1, 0),
            (7, 3, 0),
            (60, 2, 0),
            (300, 4, 0),
            (200, 200, 0),
            (900, 0, 30),
            (4900, 0, 70),
        ] {
            let mut pairs: Vec<(u32, u32)> = (0..n as u32).map(|i| (i, i)).collect();
            for i in 0..n as u32 {
                for _ in 0..per {
                    let j = rng.random_range(0..n as u32);
                    pairs.push((i.min(j), i.max(j)));
                }
                if side > 0 {
                    let (x, y) = (i % side, i / side);
                    if x + 1 < side {
                        pairs.push((i, i + 1));
                    }
                    if y + 1 < side {
                        pairs.push((i, i + side));
                    }
                }
            }
            pairs.sort_unstable();
            pairs.dedup();
            let (pattern, slot) = csc_pattern(n, &pairs).unwrap();
            // Diagonally dominant: positive definite.
            let mut upper = vec![0.0; pairs.len()];
            let mut row_sum = vec![0.0f64; n];
            for (k, &(r, c)) in pairs.iter().enumerate() {
                if r != c {
                    let v = rng.random::<f64>() - 0.5;
                    upper[k] = v;
                    row_sum[r as usize] += v.abs();
                    row_sum[c as usize] += v.abs();
                }
            }
            for (k, &(r, c)) in pairs.iter().enumerate() {
                if r == c {
                    upper[k] = row_sum[r as usize] + 0.1 + rng.random::<f64>();
                }
            }
            let identity: Vec<u32> = (0..n as u32).collect();
            for order in [
                identity,
                amd_ordering(&pattern).unwrap(),
                fill_reducing_ordering(n, &pattern).unwrap(),
            ] {
                let mut chol = SparseCholesky::analyse(pattern.as_ref(), &order).unwrap();
                let mut values = vec![0.0; chol.nnz()];
                for (k, &v) in upper.iter().enumerate() {
                    values[chol.positions()[slot[k] as usize] as usize] = v;
                }
                let b: Vec<f64> = (0..n).map(|_| rng.random::<f64>() - 0.5).collect();
                chol.factorize_by(&values, false).unwrap();
                let faer = chol.factor.clone();
                let mut faer_x = b.clone();
                chol.solve_in_place(&mut faer_x).unwrap();
                chol.factorize_by(&values, true).unwrap();
                assert!(chol.solve_by_hand || n < 2);
                let mut x = b.clone();
                chol.solve_in_place(&mut x).unwrap();
                let x_scale = faer_x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                for (a, b) in x.iter().zip(&faer_x) {
                    assert!((a - b).abs() <= 1e-12 * x_scale, "{n}: {a} vs {b}");
                }
                assert!(chol.by_hand.is_some() || n < 2, "{n}: not supernodal");
                let scale = faer.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                // Every entry of L: the diagonal blocks' upper triangles are not L (faer's
                // dense factorisation leaves values there; nothing reads them).
                let SymbolicCholeskyRaw::Supernodal(sym) = chol.symbolic.raw() else {
                    unreachable!()
                };
                for s in 0..sym.n_supernodes() {
                    let nc = (sym.supernode_end()[s] - sym.supernode_begin()[s]) as usize;
                    let nr = nc + sym.supernode(s).pattern().len();
                    let at = sym.col_ptr_for_val()[s] as usize;
                    for (j, i) in (0..nc).flat_map(|j| (j..nr).map(move |i| (j, i))) {
                        let (a, b) = (chol.factor[at + j * nr + i], faer[at + j * nr + i]);
                        assert!((a - b).abs() <= 1e-12 * scale, "{n}, {s}: {a} vs {b}");
                    }
                }
                // The same with one diagonal entry negative: refused, not factored.
                let mut bad = values.clone();
                let last = chol.positions()[slot[pairs.len() - 1] as usize] as usize;
                bad[last] = -1.0;
                assert!(chol.factorize_by(&bad, true).is_err(), "{n}");
                assert!(chol.solve_in_place(&mut vec![0.0; n]).is_err());
            }
        }
    }
}
