//! The numeric supernodal Cholesky factorisation `A = L Lᵀ` that [`super::SparseCholesky`]
//! runs on wasm32, written into faer's supernodal layout: faer's symbolic analysis comes
//! before it and faer's solves after it.
//!
//! Input: faer's supernodal symbolic analysis of a pattern, the matrix's lower triangle in
//! that pattern's order (CSC) and the [`SupernodalPlan`] (which supernodes update which);
//! output: the factor's values, as faer's `factorize_supernodal_numeric_llt` writes them, or
//! the column whose pivot is not positive.
//!
//! Why by hand: natively faer sends every update of a supernode to its x86 gemm, with the
//! scatter into the supernode built in. On wasm32 an update takes faer's generic path: a
//! temporary matrix, a recursive split of the triangular block, nano-gemm's scalar kernel for
//! the small products, then the scatter. That made the numeric factorisation of a 10k-quad
//! face-space matrix about ten times slower in Node than natively, against under twice for
//! the rest of the solver. Here each update (by a descendant supernode, and by the
//! supernode's own earlier columns) is one register-blocked kernel: four rows by four columns
//! of accumulators, which LLVM compiles to two-lane f64 vectors with simd128. A large update
//! first copies its rows into blocks of four rows ([`pack`]) that [`block_products`] reads
//! front to back, where reading the factor in place strides a column (often a page) per
//! product term. The algorithm is faer's left-looking one.

use faer::sparse::linalg::cholesky::supernodal::SymbolicSupernodalCholesky;
use std::ops::Range;

/// Rows of one block of accumulators in [`products`].
const ROWS: usize = 4;
/// Columns (target columns) of one block of accumulators in [`products`].
const COLS: usize = 4;
// [`packed_products`] reads a block of columns as a block of packed rows.
const _: () = assert!(ROWS == COLS);
/// No local row (a row outside the supernode being factored).
const NONE: u32 = u32::MAX;

/// Which supernodes update which: the descendants of supernode `s` (those whose pattern has
/// a row among `s`'s columns) are `descendants[start[s]..start[s + 1]]`, in increasing order.
#[derive(Clone)]
pub(super) struct SupernodalPlan {
    start: Vec<u32>,
    descendants: Vec<u32>,
}

impl SupernodalPlan {
    /// The plan of a symbolic factorisation: O(entries of its row pattern).
    pub(super) fn new(symbolic: &SymbolicSupernodalCholesky<u32>) -> Self {
        let ns = symbolic.n_supernodes();
        let mut supernode_of = vec![0u32; symbolic.nrows()];
        for s in 0..ns {
            let (b, e) = (
                symbolic.supernode_begin()[s] as usize,
                symbolic.supernode_end()[s] as usize,
            );
            supernode_of[b..e].fill(s as u32);
        }
        let supernode_of = &supernode_of;
        // Each descendant's pattern is sorted, so the rows of one ancestor are consecutive.
        let ancestors = |d: usize| {
            let mut last = NONE;
            symbolic
                .supernode(d)
                .pattern()
                .iter()
                .filter_map(move |&r| {
                    let s = supernode_of[r as usize];
                    (s != last).then(|| {
                        last = s;
                        s
                    })
                })
        };
        let mut start = vec![0u32; ns + 1];
        for d in 0..ns {
            for s in ancestors(d) {
                start[s as usize + 1] += 1;
            }
        }
        for s in 0..ns {
            start[s + 1] += start[s];
        }
        let mut fill = start.clone();
        let mut descendants = vec![0u32; start[ns] as usize];
        for d in 0..ns {
            for s in ancestors(d) {
                descendants[fill[s as usize] as usize] = d as u32;
                fill[s as usize] += 1;
            }
        }
        SupernodalPlan { start, descendants }
    }
}

/// `out(g, i, Σ_k panel[k ld + i] · panel[k ld + cols[g]])` for every row `i` in `rows` and
/// every `g < cols.len() <= COLS`, `k < depth`: the products of a supernode's rows with some
/// of its own rows, which an update subtracts. `panel` is column-major with `ld` rows per
/// column.
#[cfg_attr(target_arch = "wasm32", target_feature(enable = "simd128"))]
fn products(
    panel: &[f64],
    ld: usize,
    depth: usize,
    cols: &[usize],
    rows: Range<usize>,
    mut out: impl FnMut(usize, usize, f64),
) {
    debug_assert!(!cols.is_empty() && cols.len() <= COLS);
    // Short groups repeat their first column: the same work per block, the extra sums unused.
    let c: [usize; COLS] = std::array::from_fn(|g| cols[if g < cols.len() { g } else { 0 }]);
    let panel = &panel[..depth * ld];
    let mut i = rows.start;
    while i + ROWS <= rows.end {
        let mut acc = [[0.0f64; ROWS]; COLS];
        for col in panel.chunks_exact(ld) {
            let a: &[f64; ROWS] = col[i..i + ROWS].try_into().expect("ROWS rows");
            for g in 0..COLS {
                let b = col[c[g]];
                for r in 0..ROWS {
                    acc[g][r] += a[r] * b;
                }
            }
        }
        for (g, acc) in acc.iter().enumerate().take(cols.len()) {
            for (r, &v) in acc.iter().enumerate() {
                out(g, i + r, v);
            }
        }
        i += ROWS;
    }
    for i in i..rows.end {
        let mut acc = [0.0f64; COLS];
        for col in panel.chunks_exact(ld) {
            for g in 0..COLS {
                acc[g] += col[i] * col[c[g]];
            }
        }
        for (g, &v) in acc.iter().enumerate().take(cols.len()) {
            out(g, i, v);
        }
    }
}

/// Copies rows `rows` of the first `depth` columns of `panel` (column-major, `ld` rows per
/// column) into `packed` as blocks of [`ROWS`] rows, each block `capacity` groups of ROWS
/// values (one group per column, zero-padded past the last row): the layout [`block_products`]
/// reads front to back. Only columns `first..depth` of the blocks from `first_block` on are
/// written; the rest is kept.
fn pack(
    panel: &[f64],
    ld: usize,
    (first, depth): (usize, usize),
    capacity: usize,
    (rows, first_block): (Range<usize>, usize),
    packed: &mut Vec<f64>,
) {
    let blocks = rows.len().div_ceil(ROWS);
    packed.resize(blocks * capacity * ROWS, 0.0);
    for k in first..depth {
        let col = &panel[k * ld..][..ld];
        let blocks = packed.chunks_exact_mut(capacity * ROWS).enumerate();
        for (b, block) in blocks.skip(first_block) {
            let group = &mut block[k * ROWS..][..ROWS];
            let from = rows.start + b * ROWS;
            for (r, v) in group.iter_mut().enumerate() {
                *v = if from + r < rows.end {
                    col[from + r]
                } else {
                    0.0
                };
            }
        }
    }
}

/// `acc[g][r] = Σ_k a[k ROWS + r] · b[k ROWS + g]`: the products of two packed blocks of
/// [`pack`] over their first `depth` columns. Both are read front to back, so a large
/// supernode streams through the cache instead of striding a page per column.
#[cfg_attr(target_arch = "wasm32", target_feature(enable = "simd128"))]
fn block_products(a: &[f64], b: &[f64], depth: usize) -> [[f64; ROWS]; COLS] {
    let mut acc = [[0.0f64; ROWS]; COLS];
    for (a, b) in a[..depth * ROWS]
        .chunks_exact(ROWS)
        .zip(b[..depth * ROWS].chunks_exact(COLS))
    {
        for g in 0..COLS {
            for r in 0..ROWS {
                acc[g][r] += a[r] * b[g];
            }
        }
    }
    acc
}

/// The products of [`products`] over a panel packed by [`pack`] (`capacity` groups per
/// block), by blocks: the columns are the packed rows from `cols_from` (a multiple of
/// ROWS), the rows those from `cols_from` to `len`; `out(i, acc)` takes the block of rows
/// from packed row `i` (`acc[g][r]` for row `i + r`, column `cols_from + g`; rows from `len`
/// on are padding).
fn packed_products(
    packed: &[f64],
    capacity: usize,
    depth: usize,
    cols_from: usize,
    len: usize,
    mut out: impl FnMut(usize, &[[f64; ROWS]; COLS]),
) {
    let block = |b: usize| &packed[b * capacity * ROWS..][..capacity * ROWS];
    let cols = block(cols_from / ROWS);
    for b in cols_from / ROWS..len.div_ceil(ROWS) {
        out(b * ROWS, &block_products(block(b), cols, depth));
    }
}

/// Factors the matrix whose lower triangle is `(col_ptr, row_idx, values)` (CSC, in the
/// analysed order) into `l` (faer's supernodal layout of `symbolic`, `len_val` entries).
/// `local` is scratch of `nrows` entries, all [`NONE`] on entry and on return. Returns the
/// column of the first pivot that is not positive (or not finite).
pub(super) fn factorize(
    symbolic: &SymbolicSupernodalCholesky<u32>,
    plan: &SupernodalPlan,
    (col_ptr, row_idx, values): (&[u32], &[u32], &[f64]),
    l: &mut [f64],
    local: &mut [u32],
) -> Result<(), usize> {
    let val_ptr = symbolic.col_ptr_for_val();
    let mut row_map = Vec::new();
    let (mut packed, mut own) = (Vec::new(), Vec::new());
    for s in 0..symbolic.n_supernodes() {
        let (s_start, s_end) = (
            symbolic.supernode_begin()[s] as usize,
            symbolic.supernode_end()[s] as usize,
        );
        let s_pattern = symbolic.supernode(s).pattern();
        let nc = s_end - s_start;
        let nr = nc + s_pattern.len();
        for (i, &r) in s_pattern.iter().enumerate() {
            local[r as usize] = (nc + i) as u32;
        }
        let (head, tail) = l.split_at_mut(val_ptr[s] as usize);
        let ls = &mut tail[..val_ptr[s + 1] as usize - val_ptr[s] as usize];
        // Zeroed here rather than all at once: the block is then in cache for its updates.
        ls.fill(0.0);

        for j in s_start..s_end {
            let at = col_ptr[j] as usize..col_ptr[j + 1] as usize;
            for (&i, &v) in row_idx[at.clone()].iter().zip(&values[at]) {
                let i = i as usize;
                if i < j {
                    continue;
                }
                let row = if i < s_end {
                    i - s_start
                } else {
                    local[i] as usize
                };
                ls[(j - s_start) * nr + row] += v;
            }
        }

        for &d in &plan.descendants[plan.start[s] as usize..plan.start[s + 1] as usize] {
            let d = d as usize;
            let d_pattern = symbolic.supernode(d).pattern();
            let d_nc = (symbolic.supernode_end()[d] - symbolic.supernode_begin()[d]) as usize;
            let d_nr = d_nc + d_pattern.len();
            let ld = &head[val_ptr[d] as usize..val_ptr[d + 1] as usize];
            let first = d_pattern.partition_point(|&r| (r as usize) < s_start);
            let mid = d_pattern[first..].partition_point(|&r| (r as usize) < s_end);
            // Where each of `d`'s rows from `first` on lands in `ls`.
            row_map.clear();
            row_map.extend(d_pattern[first..].iter().enumerate().map(|(k, &r)| {
                if k < mid {
                    r as usize - s_start
                } else {
                    local[r as usize] as usize
                }
            }));
            let base = d_nc + first;
            if mid > COLS {
                pack(ld, d_nr, (0, d_nc), d_nc, (base..d_nr, 0), &mut packed);
                for g0 in (0..mid).step_by(COLS) {
                    let n = COLS.min(mid - g0);
                    let cols = &row_map[g0..g0 + n];
                    packed_products(&packed, d_nc, d_nc, g0, d_nr - base, |i, acc| {
                        for (r, &row) in row_map[i..].iter().take(ROWS).enumerate() {
                            for (&col, acc) in cols.iter().zip(acc) {
                                if row >= col {
                                    ls[col * nr + row] -= acc[r];
                                }
                            }
                        }
                    });
                }
                continue;
            }
            for g0 in (0..mid).step_by(COLS) {
                let n = COLS.min(mid - g0);
                let cols: [usize; COLS] = std::array::from_fn(|g| base + g0 + g);
                products(ld, d_nr, d_nc, &cols[..n], base + g0..d_nr, |g, i, v| {
                    let (col, row) = (row_map[g0 + g], row_map[i - base]);
                    if row >= col {
                        ls[col * nr + row] -= v;
                    }
                });
            }
        }

        for j0 in (0..nc).step_by(COLS) {
            let n = COLS.min(nc - j0);
            let cols: [usize; COLS] = std::array::from_fn(|g| j0 + g);
            let cols = &cols[..n];
            let (done, rest) = ls.split_at_mut(j0 * nr);
            if j0 > 0 {
                // The columns finished last, packed from their diagonal down: the rows
                // above are not read again.
                let last = (j0 - COLS, j0);
                pack(done, nr, last, nc, (0..nr, (j0 - COLS) / ROWS), &mut own);
                packed_products(&own, nc, j0, j0, nr, |i, acc| {
                    for (g, acc) in acc.iter().enumerate().take(n) {
                        let col = &mut rest[g * nr..][..nr];
                        for (r, &v) in acc.iter().enumerate().take(nr - i) {
                            if i + r >= j0 + g {
                                col[i + r] -= v;
                            }
                        }
                    }
                });
            }
            for (g, &j) in cols.iter().enumerate() {
                let (left, right) = rest.split_at_mut(g * nr);
                let col = &mut right[..nr];
                for k in 0..g {
                    let prev = &left[k * nr..(k + 1) * nr];
                    let b = prev[j];
                    for (c, &p) in col[j..].iter_mut().zip(&prev[j..]) {
                        *c -= p * b;
                    }
                }
                let pivot = col[j];
                if !(pivot > 0.0 && pivot.is_finite()) {
                    for &r in s_pattern {
                        local[r as usize] = NONE;
                    }
                    return Err(s_start + j);
                }
                let root = pivot.sqrt();
                col[j] = root;
                let inv = 1.0 / root;
                col[j + 1..].iter_mut().for_each(|c| *c *= inv);
            }
        }
        for &r in s_pattern {
            local[r as usize] = NONE;
        }
    }
    Ok(())
}

/// Solves `L Lᵀ x = b` in place (`x` holds `b` on entry) with a factor written by
/// [`factorize`]: forward through the supernodes, then back. The same reason as for the
/// factorisation: faer's solve makes one generic matrix product per supernode on wasm32.
pub(super) fn solve_in_place(symbolic: &SymbolicSupernodalCholesky<u32>, l: &[f64], x: &mut [f64]) {
    let val_ptr = symbolic.col_ptr_for_val();
    let block = |s: usize| {
        let s_start = symbolic.supernode_begin()[s] as usize;
        let nc = symbolic.supernode_end()[s] as usize - s_start;
        let pattern = symbolic.supernode(s).pattern();
        let ls = &l[val_ptr[s] as usize..val_ptr[s + 1] as usize];
        (s_start, nc, nc + pattern.len(), pattern, ls)
    };
    for s in 0..symbolic.n_supernodes() {
        let (s_start, nc, nr, pattern, ls) = block(s);
        for j in 0..nc {
            let col = &ls[j * nr..(j + 1) * nr];
            let xj = x[s_start + j] / col[j];
            x[s_start + j] = xj;
            for (i, &v) in col[j + 1..nc].iter().enumerate() {
                x[s_start + j + 1 + i] -= v * xj;
            }
            for (&r, &v) in pattern.iter().zip(&col[nc..]) {
                x[r as usize] -= v * xj;
            }
        }
    }
    for s in (0..symbolic.n_supernodes()).rev() {
        let (s_start, nc, nr, pattern, ls) = block(s);
        for j in (0..nc).rev() {
            let col = &ls[j * nr..(j + 1) * nr];
            let mut xj = x[s_start + j];
            for (&r, &v) in pattern.iter().zip(&col[nc..]) {
                xj -= v * x[r as usize];
            }
            for (i, &v) in col[j + 1..nc].iter().enumerate() {
                xj -= v * x[s_start + j + 1 + i];
            }
            x[s_start + j] = xj / col[j];
        }
    }
}
