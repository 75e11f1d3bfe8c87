//! The damped normal equations `(JᵀJ + μD) h = -Jᵀr` of a [`BlockSystem`], assembled, reduced
//! and factored block by block.
//!
//! Inputs: a block system on a [`BlockLayout`] and an elimination threshold `elim`: the blocks
//! `elim..` are *local* (every residual row touches at most one of them, e.g. the plane of one
//! face in the PQ perturbation of the conical paper, Sec. 2.2). Output: the step `h`. The local
//! blocks are eliminated (Schur complement, block Gaussian elimination, exact in exact
//! arithmetic): the sparse Cholesky factors
//! `S = A + μD_a - Σ_e B_e (C_e + μD_e)⁻¹ B_eᵀ` on the kept blocks `0..elim` only, and
//! `h_e = (C_e + μD_e)⁻¹ (-g_e - B_eᵀ h_a)` follows per block. `A`, `B_e`, `C_e` are the
//! blocks of `JᵀJ`.
//!
//! Everything structural is done once per Jacobian pattern, at block level: which block pairs
//! `S` couples, the block CSC pattern and its scalar expansion, the fill-reducing ordering
//! (AMD on the block graph, each block's unknowns kept together) and faer's symbolic
//! factorisation, and for every row the slot each of its block products goes to. An assembly
//! is then one pass over the rows adding 4 x 4 outer products into those slots. A later pattern
//! whose block pairs all exist in the analysed one (the exact phase of the PQ perturbation,
//! a subset of the penalty phase) reuses the analysis when it fills at least 90% of it.
//!
//! Written by hand: no sparse library takes block-row Jacobians, eliminates problem-defined
//! local blocks and keeps the analysis for a repeated pattern; the dense 4 x 4 algebra is
//! nalgebra's, the sparse factorisation faer's ([`SparseCholesky`]).

use super::SolverError;
use super::block_system::{BlockLayout, BlockSystem, MAX_BLOCK};
use super::cholesky::{CholeskyAnalysis, SparseCholesky};
use super::nested_dissection::{Graph, amd_ordering, nested_dissection};
use super::pattern::csc_pattern;
use faer::sparse::SymbolicSparseColMat;
use nalgebra::{Matrix4, Vector4};

const NONE: u32 = u32::MAX;
/// Set on a row pair slot whose product is stored transposed (the later entry's block is the
/// smaller one, so it names the block row).
const TRANSPOSED: u32 = 1 << 31;

type Block = Matrix4<f64>;

/// Reduced systems of this many blocks or more are also ordered by nested dissection (on
/// smaller ones AMD's factor is as small, measured on the scenes).
const DISSECTION_FROM: usize = 4096;

/// `m += a bᵀ` on a nalgebra (column-major) 4 x 4 matrix, as plain array arithmetic.
#[inline(always)]
fn add_outer_matrix(m: &mut Block, a: &[f64; MAX_BLOCK], b: &[f64; MAX_BLOCK]) {
    let m = m.as_mut_slice();
    for l in 0..4 {
        for k in 0..4 {
            m[4 * l + k] += a[k] * b[l];
        }
    }
}

/// `acc += a bᵀ` on a row-major 4 x 4 block (plain arrays: the compiler vectorises this,
/// nalgebra's generic `ger` it does not).
#[inline(always)]
fn add_outer(acc: &mut [f64; 16], a: &[f64; MAX_BLOCK], b: &[f64; MAX_BLOCK]) {
    for k in 0..4 {
        for l in 0..4 {
            acc[4 * k + l] += a[k] * b[l];
        }
    }
}

/// The block pattern of the reduced matrix `S` and its scalar factorisation.
struct Structure {
    /// Kept blocks (`S` is `nk x nk` blocks).
    nk: usize,
    /// Block CSC of the upper triangle (block row <= block column, rows sorted).
    col_ptr: Vec<u32>,
    row_blk: Vec<u32>,
    /// Position of each kept unknown's diagonal entry.
    diag_pos: Vec<u32>,
    /// Every scalar entry as (index into the slots' flattened 4 x 4 blocks, position), in
    /// slot order: slot `s` owns `scatter[slot_start[s]..slot_start[s + 1]]`.
    scatter: Vec<(u32, u32)>,
    slot_start: Vec<u32>,
    chol: SparseCholesky,
}

impl Structure {
    fn slots(&self) -> usize {
        self.row_blk.len()
    }

    /// The slot of block pair (i, j), i <= j, if the pattern has it.
    fn find(&self, i: u32, j: u32) -> Option<u32> {
        let (s, e) = (
            self.col_ptr[j as usize] as usize,
            self.col_ptr[j as usize + 1] as usize,
        );
        self.row_blk[s..e]
            .binary_search(&i)
            .ok()
            .map(|k| (s + k) as u32)
    }

    /// Analyses the upper block pairs `pairs` ((row, column), row <= column; the diagonal of
    /// every kept block included) and returns the structure and each pair's slot.
    fn analyse(
        layout: &BlockLayout,
        nk: usize,
        pairs: &[(u32, u32)],
        factor_limit: usize,
    ) -> Result<(Self, Vec<u32>), SolverError> {
        let (pattern, slots) = csc_pattern(nk, pairs)?;
        let col_ptr = pattern.col_ptr().to_vec();
        let row_blk = pattern.row_idx().to_vec();
        // Scalar upper pattern: column `offset(j) + l` lists, for every block row i of block
        // column j in order, the rows offset(i) + k (k <= l on the diagonal block).
        let n = layout.offset(nk);
        let mut scol = vec![0u32; n + 1];
        let mut srow: Vec<u32> = Vec::new();
        let mut entry_of = vec![NONE; row_blk.len() * 16];
        for j in 0..nk {
            let (oj, sj) = (layout.offset(j), layout.size(j));
            for l in 0..sj {
                for s in col_ptr[j] as usize..col_ptr[j + 1] as usize {
                    let i = row_blk[s] as usize;
                    let (oi, si) = (layout.offset(i), layout.size(i));
                    let rows = if i == j { l + 1 } else { si };
                    for k in 0..rows {
                        entry_of[s * 16 + k * 4 + l] = srow.len() as u32;
                        srow.push((oi + k) as u32);
                    }
                }
                scol[oj + l + 1] = srow.len() as u32;
            }
        }
        let upper = SymbolicSparseColMat::new_checked(n, n, scol, None, srow);
        let perm = fill_reducing_ordering(nk, &pattern)?;
        let mut fwd = Vec::with_capacity(n);
        for &b in &perm {
            let o = layout.offset(b as usize);
            fwd.extend((o..o + layout.size(b as usize)).map(|v| v as u32));
        }
        let chol = SparseCholesky::analyse_within(upper.as_ref(), &fwd, factor_limit)?;
        let positions = chol.positions();
        // Per block slot, the positions (row-major 4 x 4) of its scalar entries in the values
        // `chol` factors (`NONE` outside the blocks' sizes and below a diagonal block's
        // diagonal).
        let val_pos: Vec<u32> = entry_of
            .iter()
            .map(|&e| {
                if e == NONE {
                    NONE
                } else {
                    positions[e as usize]
                }
            })
            .collect();
        let mut scatter = Vec::new();
        let mut slot_start = vec![0u32];
        for (s, pos) in val_pos.chunks(16).enumerate() {
            for (w, &p) in pos.iter().enumerate() {
                if p != NONE {
                    scatter.push(((s * 16 + w) as u32, p));
                }
            }
            slot_start.push(scatter.len() as u32);
        }
        let mut diag_pos = vec![NONE; n];
        for j in 0..nk {
            let s = col_ptr[j + 1] as usize - 1; // the diagonal block ends its column
            let o = layout.offset(j);
            for k in 0..layout.size(j) {
                diag_pos[o + k] = val_pos[s * 16 + k * 4 + k];
            }
        }
        Ok((
            Structure {
                nk,
                col_ptr,
                row_blk,
                diag_pos,
                scatter,
                slot_start,
                chol,
            },
            slots,
        ))
    }
}

/// The fill-reducing ordering (`perm[new] = old`) of the `nk` nodes of `pattern` (upper
/// triangle, diagonal included; nodes are the kept blocks here, scalar unknowns in face
/// space): AMD, and from [`DISSECTION_FROM`] nodes on nested dissection too, keeping
/// whichever gives the smaller Cholesky factor of the pattern (for blocks, each block's
/// unknowns are then numbered together, so the scalar factor follows the block one).
pub(crate) fn fill_reducing_ordering(
    nk: usize,
    pattern: &SymbolicSparseColMat<u32>,
) -> Result<Vec<u32>, SolverError> {
    let perm = amd_ordering(pattern)?;
    if nk < DISSECTION_FROM {
        return Ok(perm);
    }
    let nd = nested_dissection(&node_graph(nk, pattern));
    let amd_len = CholeskyAnalysis::new(pattern.as_ref(), &perm)?.factor_len();
    let nd_len = CholeskyAnalysis::new(pattern.as_ref(), &nd)?.factor_len();
    Ok(if nd_len < amd_len { nd } else { perm })
}

/// [`fill_reducing_ordering`] of a scalar pattern, as the analysis of the ordering it keeps:
/// the winner's analysis is the one its factorisation needs, so it is not made twice.
pub(crate) fn fill_reducing_analysis(
    n: usize,
    pattern: &SymbolicSparseColMat<u32>,
) -> Result<CholeskyAnalysis, SolverError> {
    let amd = CholeskyAnalysis::new(pattern.as_ref(), &amd_ordering(pattern)?)?;
    if n < DISSECTION_FROM {
        return Ok(amd);
    }
    let nd = CholeskyAnalysis::new(
        pattern.as_ref(),
        &nested_dissection(&node_graph(n, pattern)),
    )?;
    Ok(if nd.factor_len() < amd.factor_len() {
        nd
    } else {
        amd
    })
}

/// The graph of the `nk` nodes of an upper-triangle pattern.
fn node_graph(nk: usize, pattern: &SymbolicSparseColMat<u32>) -> Graph {
    let (col_ptr, row_blk) = (pattern.col_ptr(), pattern.row_idx());
    Graph::from_upper_pairs(
        nk,
        (0..nk).flat_map(|j| {
            row_blk[col_ptr[j] as usize..col_ptr[j + 1] as usize]
                .iter()
                .map(move |&i| (i, j as u32))
        }),
    )
}

/// How the rows of one Jacobian pattern land in a [`Structure`].
struct RowMap {
    /// The pattern this map was made for.
    pattern: BlockSystem,
    elim: usize,
    /// Slot of every kept block's diagonal block.
    diag_slot: Vec<u32>,
    /// Per row, the slots of its kept entry pairs (i <= j in row order), flagged
    /// [`TRANSPOSED`] where entry j has the smaller block.
    pair_start: Vec<u32>,
    pair_slot: Vec<u32>,
    /// Per row, the position within the row of its local-block entry, or `NONE`.
    row_elim: Vec<u32>,
    /// Per entry of a row with a local block: the index of its coupling block `B`.
    b_index: Vec<u32>,
    /// Per local block: the kept blocks it couples (sorted), `e_cols[e_start[e]..]`, and the
    /// slots of their pairs (i <= j), `e_pair[e_pair_start[e]..]`.
    e_start: Vec<u32>,
    e_cols: Vec<u32>,
    e_pair_start: Vec<u32>,
    e_pair: Vec<u32>,
}

/// Reusable analysis and numeric storage of the block normal equations.
#[derive(Default)]
pub(crate) struct BlockNormal {
    structure: Option<Structure>,
    map: Option<RowMap>,
    /// Per slot: the kept part `A` of `JᵀJ` (row-major 4 x 4, padded).
    acc: Vec<[f64; 16]>,
    /// Per block: its part of the gradient `Jᵀr` (padded).
    gblk: Vec<[f64; MAX_BLOCK]>,
    /// Per local block: `C_e`, and `(C_e + μD_e)⁻¹` of the last factorisation.
    c: Vec<Block>,
    inv: Vec<Block>,
    /// Coupling blocks `B` (kept components x local components).
    b: Vec<Block>,
    /// Scalar values of `A` and of the damped reduced matrix.
    base: Vec<f64>,
    values: Vec<f64>,
    factored: bool,
    /// Number of symbolic analyses made (for tests and benchmarks).
    analyses: usize,
    /// The most memory the factor may take, in bytes (`None`: [`super::MAX_FACTOR_BYTES`]).
    factor_limit: Option<usize>,
}

impl BlockNormal {
    /// Whether the current analysis eliminates local blocks.
    #[cfg(test)]
    pub(crate) fn eliminates(&self) -> bool {
        self.map.as_ref().is_some_and(|m| m.e_start.len() > 1)
    }

    /// Number of symbolic analyses so far.
    pub(crate) fn analyses(&self) -> usize {
        self.analyses
    }

    /// Sets the most memory the factor may take, in bytes; an analysis beyond it fails with
    /// [`SolverError::TooLarge`] before the factor is allocated.
    pub(crate) fn set_factor_limit(&mut self, bytes: usize) {
        self.factor_limit = Some(bytes);
    }

    /// Makes sure the analysis fits the pattern of `sys` with local blocks `elim..` (ignored,
    /// i.e. nothing eliminated, when a row touches two of them or nothing would be kept).
    fn prepare(
        &mut self,
        sys: &BlockSystem,
        layout: &BlockLayout,
        elim: usize,
    ) -> Result<(), SolverError> {
        let nb = layout.num_blocks();
        let nk = kept_blocks(sys, nb, elim);
        if let Some(m) = &self.map
            && m.elim == nk
            && m.pattern.same_pattern(sys)
        {
            return Ok(());
        }
        self.map = None;
        let p = BlockPairs::of(sys, nb, nk);
        let slots = self.slots(layout, nk, &p.pairs)?;
        let diag_slot = slots[..nk].to_vec();
        let row_pairs = &slots[nk..p.first_e_pair];
        let pair_slot: Vec<u32> = row_pairs
            .iter()
            .zip(&p.transposed)
            .map(|(&s, &t)| if t { s | TRANSPOSED } else { s })
            .collect();
        let e_pair = slots[p.first_e_pair..].to_vec();
        let b_index = coupling_index(sys, nk, &p.row_elim, &p.e_start, &p.e_cols);
        self.reset_storage(nb - nk, p.e_cols.len());
        let mut pattern = BlockSystem::default();
        pattern.clone_from(sys);
        self.map = Some(RowMap {
            pattern,
            elim: nk,
            diag_slot,
            pair_start: p.pair_start,
            pair_slot,
            row_elim: p.row_elim,
            b_index,
            e_start: p.e_start,
            e_cols: p.e_cols,
            e_pair_start: p.e_pair_start,
            e_pair,
        });
        Ok(())
    }

    /// The slot of every pair in the analysed structure: the current one if it holds every
    /// pair and this pattern fills it (at least 90 % of its slots), else a new analysis.
    fn slots(
        &mut self,
        layout: &BlockLayout,
        nk: usize,
        pairs: &[(u32, u32)],
    ) -> Result<Vec<u32>, SolverError> {
        let reused = self.structure.as_ref().and_then(|s| {
            if s.nk != nk {
                return None;
            }
            let mut slots = Vec::with_capacity(pairs.len());
            let mut used = vec![false; s.slots()];
            for &(i, j) in pairs {
                let k = s.find(i, j)?;
                used[k as usize] = true;
                slots.push(k);
            }
            let filled = used.iter().filter(|&&u| u).count();
            (10 * filled >= 9 * s.slots()).then_some(slots)
        });
        Ok(match reused {
            Some(slots) => slots,
            None => {
                self.structure = None;
                let limit = self.factor_limit.unwrap_or(super::MAX_FACTOR_BYTES);
                let (s, slots) = Structure::analyse(layout, nk, pairs, limit)?;
                self.analyses += 1;
                self.structure = Some(s);
                slots
            }
        })
    }

    /// Zeroed numeric storage for the analysed structure, `ne` local blocks and `nb_blocks`
    /// coupling blocks; nothing factored.
    fn reset_storage(&mut self, ne: usize, nb_blocks: usize) {
        let st = self.structure.as_ref().expect("structure set by `slots`");
        self.acc.clear();
        self.acc.resize(st.slots(), [0.0; 16]);
        self.c.clear();
        self.c.resize(ne, Block::zeros());
        self.inv.clear();
        self.inv.resize(ne, Block::zeros());
        self.b.clear();
        self.b.resize(nb_blocks, Block::zeros());
        let nnz = st.chol.nnz();
        self.base.clear();
        self.base.resize(nnz, 0.0);
        self.values.clear();
        self.values.resize(nnz, 0.0);
        self.factored = false;
    }

    /// Assembles `JᵀJ` of `sys` (kept part, local blocks and couplings) and returns the
    /// gradient `Jᵀr` and the diagonal of `JᵀJ`, both over all unknowns.
    pub(crate) fn assemble(
        &mut self,
        sys: &BlockSystem,
        layout: &BlockLayout,
        elim: usize,
    ) -> Result<(Vec<f64>, Vec<f64>), SolverError> {
        self.prepare(sys, layout, elim)?;
        let (map, st) = (
            self.map.as_ref().expect("prepared"),
            self.structure.as_ref().expect("prepared"),
        );
        let nk = map.elim;
        let n = layout.num_variables();
        let mut g = vec![0.0; n];
        let mut diag = vec![0.0; n];
        self.acc.fill([0.0; 16]);
        self.gblk.clear();
        self.gblk.resize(layout.num_blocks(), [0.0; MAX_BLOCK]);
        self.c.fill(Block::zeros());
        self.b.fill(Block::zeros());
        let mut entry = 0usize;
        for r in 0..sys.num_rows() {
            let row = sys.row(r);
            let res = sys.residuals[r];
            let slots = &map.pair_slot[map.pair_start[r] as usize..map.pair_start[r + 1] as usize];
            let axis = sys.row_axis(r) as usize;
            let mut p = 0;
            for (i, a) in row.iter().enumerate() {
                for (gk, ak) in self.gblk[a.block as usize].iter_mut().zip(a.grad) {
                    *gk += ak * res;
                }
                if a.block as usize >= nk {
                    continue;
                }
                for b in &row[i..] {
                    if b.block as usize >= nk {
                        continue;
                    }
                    let s = slots[p];
                    p += 1;
                    if axis < MAX_BLOCK {
                        // Only component (axis, axis) of the product is nonzero.
                        self.acc[(s & !TRANSPOSED) as usize][5 * axis] +=
                            a.grad[axis] * b.grad[axis];
                    } else if s & TRANSPOSED != 0 {
                        add_outer(&mut self.acc[(s & !TRANSPOSED) as usize], &b.grad, &a.grad);
                    } else {
                        add_outer(&mut self.acc[s as usize], &a.grad, &b.grad);
                    }
                }
            }
            let local = map.row_elim[r];
            if local != NONE {
                let le = &row[local as usize];
                add_outer_matrix(&mut self.c[le.block as usize - nk], &le.grad, &le.grad);
                for (i, a) in row.iter().enumerate() {
                    let bi = map.b_index[entry + i];
                    if bi != NONE {
                        add_outer_matrix(&mut self.b[bi as usize], &a.grad, &le.grad);
                    }
                }
            }
            entry += row.len();
        }
        for (b, gb) in self.gblk.iter().enumerate() {
            let o = layout.offset(b);
            g[o..o + layout.size(b)].copy_from_slice(&gb[..layout.size(b)]);
        }
        for (b, &s) in map.diag_slot.iter().enumerate() {
            let o = layout.offset(b);
            for k in 0..layout.size(b) {
                diag[o + k] = self.acc[s as usize][5 * k];
            }
        }
        for (e, c) in self.c.iter().enumerate() {
            let o = layout.offset(nk + e);
            for k in 0..layout.size(nk + e) {
                diag[o + k] = c[(k, k)];
            }
        }
        let acc = self.acc.as_flattened();
        for &(from, to) in &st.scatter {
            self.base[to as usize] = acc[from as usize];
        }
        self.factored = false;
        Ok((g, diag))
    }

    /// Factors the reduced matrix of the last assembly with damping `μ d` (`d` over all
    /// unknowns). Fails when a damped local block or the reduced matrix is not positive
    /// definite.
    pub(crate) fn factor(
        &mut self,
        layout: &BlockLayout,
        mu: f64,
        d: &[f64],
    ) -> Result<(), SolverError> {
        self.factored = false;
        let (map, st) = match (self.map.as_ref(), self.structure.as_mut()) {
            (Some(m), Some(s)) => (m, s),
            _ => {
                return Err(SolverError::Factorization(
                    "no assembled system to factor".into(),
                ));
            }
        };
        let nk = map.elim;
        self.values.copy_from_slice(&self.base);
        for (&at, &dv) in st.diag_pos.iter().zip(d) {
            self.values[at as usize] += mu * dv;
        }
        let mut y: Vec<Block> = Vec::new();
        for (e, c) in self.c.iter().enumerate() {
            let (o, size) = (layout.offset(nk + e), layout.size(nk + e));
            let mut ct = *c;
            for k in 0..4 {
                if k < size {
                    ct[(k, k)] += mu * d[o + k];
                } else {
                    ct[(k, k)] = 1.0;
                }
            }
            let inv = ct
                .cholesky()
                .ok_or_else(|| {
                    SolverError::Factorization(format!("local block {e} is not positive definite"))
                })?
                .inverse();
            let (s, t) = (map.e_start[e] as usize, map.e_start[e + 1] as usize);
            let bs = &self.b[s..t];
            y.clear();
            y.extend(bs.iter().map(|b| b * inv));
            let mut q = map.e_pair_start[e] as usize;
            for (i, yi) in y.iter().enumerate() {
                for bj in &bs[i..] {
                    let slot = map.e_pair[q] as usize;
                    q += 1;
                    // (Y_i B_jᵀ)ᵀ in nalgebra's column-major order is Y_i B_jᵀ row-major.
                    let prod = bj * yi.transpose();
                    let prod = prod.as_slice();
                    let range = st.slot_start[slot] as usize..st.slot_start[slot + 1] as usize;
                    for &(q, at) in &st.scatter[range] {
                        self.values[at as usize] -= prod[q as usize & 15];
                    }
                }
            }
            self.inv[e] = inv;
        }
        st.chol.factorize(&self.values)?;
        self.factored = true;
        Ok(())
    }

    /// Solves `(JᵀJ + μD) h = -g` with the last factorisation (any `g` over all unknowns;
    /// [`Self::factor`] must have succeeded since the last assembly).
    pub(crate) fn solve(
        &mut self,
        layout: &BlockLayout,
        g: &[f64],
    ) -> Result<Vec<f64>, SolverError> {
        let (map, st) = match (self.map.as_ref(), self.structure.as_mut()) {
            (Some(m), Some(s)) if self.factored => (m, s),
            _ => {
                return Err(SolverError::Factorization(
                    "no factorisation to solve with".into(),
                ));
            }
        };
        let nk = map.elim;
        let local = |e: usize, v: &[f64]| {
            let (o, size) = (layout.offset(nk + e), layout.size(nk + e));
            let mut w = Vector4::zeros();
            for k in 0..size {
                w[k] = v[o + k];
            }
            w
        };
        let nkv = layout.offset(nk);
        let mut h: Vec<f64> = g[..nkv].iter().map(|v| -v).collect();
        for (e, inv) in self.inv.iter().enumerate() {
            let y = inv * local(e, g);
            for bi in map.e_start[e] as usize..map.e_start[e + 1] as usize {
                let a = map.e_cols[bi] as usize;
                let by = self.b[bi] * y;
                let o = layout.offset(a);
                for k in 0..layout.size(a) {
                    h[o + k] += by[k];
                }
            }
        }
        st.chol.solve_in_place(&mut h)?;
        h.resize(g.len(), 0.0);
        for (e, inv) in self.inv.iter().enumerate() {
            let mut t = -local(e, g);
            for bi in map.e_start[e] as usize..map.e_start[e + 1] as usize {
                let a = map.e_cols[bi] as usize;
                let o = layout.offset(a);
                let mut ha = Vector4::zeros();
                for k in 0..layout.size(a) {
                    ha[k] = h[o + k];
                }
                t -= self.b[bi].transpose() * ha;
            }
            let he = inv * t;
            let o = layout.offset(nk + e);
            for k in 0..layout.size(nk + e) {
                h[o + k] = he[k];
            }
        }
        if h.iter().all(|v| v.is_finite()) {
            Ok(h)
        } else {
            Err(SolverError::Factorization(
                "the solve produced non-finite values (singular matrix)".into(),
            ))
        }
    }
}

/// The number of kept blocks for local blocks `elim..`: `nb` (nothing eliminated) when
/// `elim` is 0 or when a row touches two local blocks.
fn kept_blocks(sys: &BlockSystem, nb: usize, elim: usize) -> usize {
    let mut elim = elim.min(nb);
    if elim == 0 {
        elim = nb;
    }
    if elim < nb {
        let two = (0..sys.num_rows()).any(|r| {
            sys.row(r)
                .iter()
                .filter(|e| e.block as usize >= elim)
                .count()
                > 1
        });
        if two {
            elim = nb;
        }
    }
    elim
}

/// The block pairs of S, in the order the row map reads their slots back: the kept
/// diagonals, every row's kept pairs, every local block's couplings; with the rows' and the
/// local blocks' indices into them.
struct BlockPairs {
    pairs: Vec<(u32, u32)>,
    /// Per row, the start of its kept pairs in `transposed` (and after the diagonals, in
    /// `pairs`).
    pair_start: Vec<u32>,
    /// Per row kept pair, whether its second entry has the smaller block.
    transposed: Vec<bool>,
    /// Per row, the position of its local-block entry, or `NONE`.
    row_elim: Vec<u32>,
    /// Per local block, the kept blocks it couples (sorted): `e_cols[e_start[e]..]`.
    e_start: Vec<u32>,
    e_cols: Vec<u32>,
    /// Per local block, the start of its coupling pairs after `first_e_pair`.
    e_pair_start: Vec<u32>,
    first_e_pair: usize,
}

impl BlockPairs {
    fn of(sys: &BlockSystem, nb: usize, nk: usize) -> Self {
        let mut pairs: Vec<(u32, u32)> = (0..nk as u32).map(|b| (b, b)).collect();
        let mut pair_start = Vec::with_capacity(sys.num_rows() + 1);
        let mut row_elim = Vec::with_capacity(sys.num_rows());
        let mut transposed = Vec::new();
        let mut couplings: Vec<(u32, u32)> = Vec::new();
        pair_start.push(0u32);
        for r in 0..sys.num_rows() {
            let row = sys.row(r);
            let mut local = NONE;
            for (i, a) in row.iter().enumerate() {
                if a.block as usize >= nk {
                    local = i as u32;
                    continue;
                }
                for b in &row[i..] {
                    if b.block as usize >= nk {
                        continue;
                    }
                    transposed.push(b.block < a.block);
                    pairs.push((a.block.min(b.block), a.block.max(b.block)));
                }
            }
            if local != NONE {
                let e = row[local as usize].block - nk as u32;
                for a in row.iter().filter(|a| (a.block as usize) < nk) {
                    couplings.push((e, a.block));
                }
            }
            row_elim.push(local);
            pair_start.push(transposed.len() as u32);
        }
        let ne = nb - nk;
        couplings.sort_unstable();
        couplings.dedup();
        let mut e_start = vec![0u32; ne + 1];
        for &(e, _) in &couplings {
            e_start[e as usize + 1] += 1;
        }
        for e in 0..ne {
            e_start[e + 1] += e_start[e];
        }
        let e_cols: Vec<u32> = couplings.iter().map(|p| p.1).collect();
        let mut e_pair_start = vec![0u32];
        let first_e_pair = pairs.len();
        for e in 0..ne {
            let cols = &e_cols[e_start[e] as usize..e_start[e + 1] as usize];
            for (i, &ci) in cols.iter().enumerate() {
                for &cj in &cols[i..] {
                    pairs.push((ci, cj));
                }
            }
            e_pair_start.push((pairs.len() - first_e_pair) as u32);
        }
        BlockPairs {
            pairs,
            pair_start,
            transposed,
            row_elim,
            e_start,
            e_cols,
            e_pair_start,
            first_e_pair,
        }
    }
}

/// Per entry of a row with a local block: the index of its coupling block `B` (`NONE` for
/// the local entry and for rows without one).
fn coupling_index(
    sys: &BlockSystem,
    nk: usize,
    row_elim: &[u32],
    e_start: &[u32],
    e_cols: &[u32],
) -> Vec<u32> {
    let mut b_index = Vec::new();
    for (r, &local) in row_elim.iter().enumerate() {
        let row = sys.row(r);
        if local == NONE {
            b_index.extend(std::iter::repeat_n(NONE, row.len()));
            continue;
        }
        let e = (row[local as usize].block as usize) - nk;
        let (s, t) = (e_start[e] as usize, e_start[e + 1] as usize);
        for a in row {
            b_index.push(if (a.block as usize) < nk {
                let k = e_cols[s..t]
                    .binary_search(&a.block)
                    .expect("every coupling is listed");
                (s + k) as u32
            } else {
                NONE
            });
        }
    }
    b_index
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// A random block system: vertex-like blocks of 3 and 1, then local blocks of 4; every
    /// row touches 1-4 random kept blocks and, for some rows, one local block.
    fn random_system(rng: &mut ChaCha8Rng, rows: usize) -> (BlockLayout, BlockSystem, usize) {
        let kept: Vec<usize> = (0..12).map(|b| if b % 5 == 4 { 1 } else { 3 }).collect();
        let nk = kept.len();
        let layout = BlockLayout::new(kept.iter().copied().chain(std::iter::repeat_n(4, 6)));
        let mut sys = BlockSystem::default();
        for r in 0..rows {
            sys.push_row(rng.random::<f64>() - 0.5);
            for _ in 0..1 + r % 4 {
                let b = rng.random_range(0..nk);
                let mut g = [0.0; MAX_BLOCK];
                for v in g.iter_mut().take(layout.size(b)) {
                    *v = rng.random::<f64>() - 0.5;
                }
                sys.add(b as u32, g);
            }
            if r % 3 == 0 {
                let e = nk + (r / 3) % 6;
                let g = [0.0; MAX_BLOCK].map(|_: f64| rng.random::<f64>() - 0.5);
                sys.add(e as u32, g);
            }
        }
        (layout, sys, nk)
    }

    /// The dense step `(JᵀJ + μ diag(d)) h = -Jᵀr` of a block system.
    fn dense_step(layout: &BlockLayout, sys: &BlockSystem, mu: f64, d: &[f64]) -> Vec<f64> {
        let n = layout.num_variables();
        let mut j = nalgebra::DMatrix::<f64>::zeros(sys.num_rows(), n);
        for r in 0..sys.num_rows() {
            for e in sys.row(r) {
                let o = layout.offset(e.block as usize);
                for k in 0..layout.size(e.block as usize) {
                    j[(r, o + k)] += e.grad[k];
                }
            }
        }
        let res = nalgebra::DVector::from_column_slice(&sys.residuals);
        let mut a = j.transpose() * &j;
        for i in 0..n {
            a[(i, i)] += mu * d[i];
        }
        let h = a.cholesky().unwrap().solve(&(-(j.transpose() * res)));
        h.iter().copied().collect()
    }

    /// With and without eliminating the local blocks, and after switching to a sub-pattern
    /// that reuses the analysis, the block normal equations give the dense step.
    #[test]
    fn block_steps_match_the_dense_normal_equations() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let (layout, sys, nk) = random_system(&mut rng, 80);
        let n = layout.num_variables();
        let d: Vec<f64> = (0..n).map(|_| 1.0 + rng.random::<f64>()).collect();
        for elim in [nk, layout.num_blocks()] {
            let mut normal = BlockNormal::default();
            let (g, _) = normal.assemble(&sys, &layout, elim).unwrap();
            assert_eq!(normal.eliminates(), elim < layout.num_blocks());
            for mu in [1e-3, 0.5] {
                normal.factor(&layout, mu, &d).unwrap();
                let h = normal.solve(&layout, &g).unwrap();
                let want = dense_step(&layout, &sys, mu, &d);
                for i in 0..n {
                    assert!((h[i] - want[i]).abs() < 1e-9 * (1.0 + want[i].abs()), "{i}");
                }
            }
            // Every 17th row dropped: a sub-pattern filling > 90% of the analysed one, whose
            // analysis is reused, with the same answer as a dense solve.
            let mut sub = BlockSystem::default();
            for r in (0..sys.num_rows()).filter(|r| r % 17 != 0) {
                sub.push_row(sys.residuals[r]);
                for e in sys.row(r) {
                    sub.add(e.block, e.grad);
                }
            }
            let analyses = normal.analyses();
            let (g2, _) = normal.assemble(&sub, &layout, elim).unwrap();
            assert_eq!(normal.analyses(), analyses, "the analysis is reused");
            normal.factor(&layout, 1e-2, &d).unwrap();
            let h2 = normal.solve(&layout, &g2).unwrap();
            let want2 = dense_step(&layout, &sub, 1e-2, &d);
            for i in 0..n {
                assert!(
                    (h2[i] - want2[i]).abs() < 1e-9 * (1.0 + want2[i].abs()),
                    "sub {i}"
                );
            }
        }
    }
}
