//! Elimination of local variable blocks from the sparse normal equations (Schur complement).
//!
//! Inputs: the residuals and Jacobian of a [`SparseSystem`] whose variables `first..n` form
//! consecutive blocks of `size` (1 to 4) unknowns such that every residual touches at most one
//! block (e.g. the plane (normal, offset) of one face in the PQ perturbation of the conical
//! paper, Sec. 2.2). Output: the reduced system on the variables `0..first`,
//! `(A - B C⁻¹ Bᵀ) h_a = -g_a + B C⁻¹ g_c`, assembled into a [`PatternMatrix`], and the back
//! substitution `h_c = C⁻¹ (-g_c - Bᵀ h_a)` (block Gaussian elimination, exact in exact
//! arithmetic). Here `A`, `B`, `C` are the blocks of the damped `JᵀJ + μD`.
//!
//! Written by hand: the elimination needs the block structure that only the problem knows and
//! the dense blocks are at most 4 x 4 (nalgebra); no sparse library offers it for a repeated
//! pattern. Each block `C` is block-diagonal, so its inverse costs O(1) per block, and the
//! couplings `B C⁻¹ Bᵀ` only touch variables already coupled by the block's residuals, so the
//! reduced matrix has no more fill than the vertex part of the full one while the sparse
//! Cholesky works on far fewer unknowns.
//!
//! The Jacobian pattern is analysed once ([`BlockSchur::plan`]: rows grouped, sorted by
//! column, block couplings listed) and reused while it repeats, so an assembly is one pass
//! over the products. Without blocks (`first == n`) the same code assembles the plain `JᵀJ`.

use super::SparseSystem;
use super::pattern::PatternMatrix;
use nalgebra::{Matrix4, Vector4};

const NONE: u32 = u32::MAX;

/// Reusable state of the elimination: the analysis of one Jacobian pattern (built once by
/// [`Self::plan`], reused while the pattern repeats) and the numeric blocks.
#[derive(Default)]
pub(crate) struct BlockSchur {
    first: usize,
    size: usize,
    /// Entries grouped by row: `order[row_start[r]..row_start[r + 1]]`, the first
    /// `row_global[r]` of them on variables `< first` sorted by column, then the block ones.
    row_start: Vec<u32>,
    row_global: Vec<u32>,
    order: Vec<u32>,
    /// Per row: the block its block entries belong to, or `NONE`.
    row_block: Vec<u32>,
    /// Per position of `order`: for a global entry of a block row the index of its row of
    /// `B`, for a block entry its component in the block.
    b_slot: Vec<u32>,
    /// Rows of `B` per block: `b_col[b_start[k]..b_start[k + 1]]` (sorted global variables)
    /// and their values `b_val` (padded to 4).
    b_start: Vec<u32>,
    b_col: Vec<u32>,
    b_val: Vec<Vector4<f64>>,
    /// Per block: its Gram block `C` (padded to 4 x 4).
    c: Vec<Matrix4<f64>>,
    /// Per block: `(C + μD)⁻¹` of the last damped assembly.
    inv: Vec<Matrix4<f64>>,
}

impl BlockSchur {
    /// Number of variables left after the elimination (`first`, or `n` without blocks).
    pub(crate) fn reduced_dim(&self) -> usize {
        self.first
    }

    /// Analyses the Jacobian pattern of `sys` for blocks of `size` (1 to 4) from `first` on
    /// (`first == n`: no blocks, plain `JᵀJ`). Returns false, leaving no usable plan, when a
    /// residual touches two blocks.
    pub(crate) fn plan(&mut self, sys: &SparseSystem, n: usize, first: usize, size: usize) -> bool {
        debug_assert!((1..=4).contains(&size) && first <= n && (n - first).is_multiple_of(size));
        self.first = first;
        self.size = size;
        let nb = (n - first) / size;
        let m = sys.residuals.len();
        let ents = &sys.entries;
        // Group the entries by row (counting sort), then order each row: global variables by
        // column (so every pair (i, j >= i) is in the upper triangle), then block variables.
        self.row_start.clear();
        self.row_start.resize(m + 1, 0);
        for e in ents {
            self.row_start[e.row as usize + 1] += 1;
        }
        for i in 0..m {
            self.row_start[i + 1] += self.row_start[i];
        }
        self.order.clear();
        self.order.resize(ents.len(), 0);
        let mut fill = self.row_start.clone();
        for (k, e) in ents.iter().enumerate() {
            let r = e.row as usize;
            self.order[fill[r] as usize] = k as u32;
            fill[r] += 1;
        }
        self.row_global.clear();
        self.row_block.clear();
        let mut pairs: Vec<(u32, u32)> = Vec::new();
        for r in 0..m {
            let (s, e) = (self.row_start[r] as usize, self.row_start[r + 1] as usize);
            let row = &mut self.order[s..e];
            row.sort_unstable_by_key(|&k| {
                let c = ents[k as usize].col;
                ((c as usize) >= first, c)
            });
            let ng = row
                .iter()
                .take_while(|&&k| (ents[k as usize].col as usize) < first)
                .count();
            let mut blk = NONE;
            for &k in &row[ng..] {
                let b = ((ents[k as usize].col as usize - first) / size) as u32;
                if blk == NONE {
                    blk = b;
                } else if blk != b {
                    self.first = n;
                    return false;
                }
            }
            if blk != NONE {
                pairs.extend(row[..ng].iter().map(|&k| (blk, ents[k as usize].col)));
            }
            self.row_global.push(ng as u32);
            self.row_block.push(blk);
        }
        pairs.sort_unstable();
        pairs.dedup();
        self.b_start.clear();
        self.b_start.resize(nb + 1, 0);
        for &(b, _) in &pairs {
            self.b_start[b as usize + 1] += 1;
        }
        for k in 0..nb {
            self.b_start[k + 1] += self.b_start[k];
        }
        self.b_col.clear();
        self.b_col.extend(pairs.iter().map(|p| p.1));
        self.b_slot.clear();
        self.b_slot.resize(self.order.len(), NONE);
        for r in 0..m {
            let blk = self.row_block[r];
            if blk == NONE {
                continue;
            }
            let s = self.row_start[r] as usize;
            let (bs, be) = (
                self.b_start[blk as usize] as usize,
                self.b_start[blk as usize + 1] as usize,
            );
            let (ng, e) = (
                s + self.row_global[r] as usize,
                self.row_start[r + 1] as usize,
            );
            for p in s..ng {
                let col = ents[self.order[p] as usize].col;
                let at = self.b_col[bs..be]
                    .binary_search(&col)
                    .expect("every coupling is listed");
                self.b_slot[p] = (bs + at) as u32;
            }
            for p in ng..e {
                self.b_slot[p] =
                    ((ents[self.order[p] as usize].col as usize - first) % size) as u32;
            }
        }
        self.b_val.clear();
        self.b_val.resize(self.b_col.len(), Vector4::zeros());
        self.c.clear();
        self.c.resize(nb, Matrix4::zeros());
        self.inv.clear();
        self.inv.resize(nb, Matrix4::zeros());
        true
    }

    /// Adds the upper triangle of `A = J_aᵀ J_a` to `pm` and records the blocks `B`, `C`, for
    /// the pattern analysed by [`Self::plan`] (the pushes follow the same order every time).
    /// Fills `g` with the gradient `Jᵀr` and `diag` with the diagonal of `JᵀJ` (all `n`
    /// variables).
    pub(crate) fn assemble(
        &mut self,
        sys: &SparseSystem,
        pm: &mut PatternMatrix,
        g: &mut [f64],
        diag: &mut [f64],
    ) {
        let (first, size) = (self.first, self.size);
        g.fill(0.0);
        diag.fill(0.0);
        self.c.fill(Matrix4::zeros());
        self.b_val.fill(Vector4::zeros());
        let ents = &sys.entries;
        let mut sink = pm.sink();
        for (r, &res) in sys.residuals.iter().enumerate() {
            let (s, e) = (self.row_start[r] as usize, self.row_start[r + 1] as usize);
            let ng = self.row_global[r] as usize;
            let (glob, local) = self.order[s..e].split_at(ng);
            let local_k = &self.b_slot[s + ng..e];
            let blk = self.row_block[r];
            for (i, &a) in glob.iter().enumerate() {
                let ea = ents[a as usize];
                let (ca, va) = (ea.col, ea.value);
                g[ca as usize] += va * res;
                diag[ca as usize] += va * va;
                sink.push(ca, ca, va * va);
                for &b in &glob[i + 1..] {
                    let eb = ents[b as usize];
                    let v = va * eb.value;
                    if eb.col == ca {
                        // A repeated column: both ordered pairs land on the diagonal.
                        diag[ca as usize] += 2.0 * v;
                        sink.push(ca, ca, 2.0 * v);
                    } else {
                        sink.push(ca, eb.col, v);
                    }
                }
                if blk != NONE {
                    let bv = &mut self.b_val[self.b_slot[s + i] as usize];
                    for (&b, &k) in local.iter().zip(local_k) {
                        bv[k as usize] += va * ents[b as usize].value;
                    }
                }
            }
            if blk != NONE {
                let c = &mut self.c[blk as usize];
                for (&a, &ka) in local.iter().zip(local_k) {
                    let ea = ents[a as usize];
                    g[ea.col as usize] += ea.value * res;
                    for (&b, &kb) in local.iter().zip(local_k) {
                        c[(ka as usize, kb as usize)] += ea.value * ents[b as usize].value;
                    }
                }
            }
        }
        for (blk, c) in self.c.iter().enumerate() {
            for k in 0..size {
                diag[first + blk * size + k] = c[(k, k)];
            }
        }
    }

    /// Adds `-B (C + μD_c)⁻¹ Bᵀ` (upper triangle) to `pm`, keeping the block inverses for
    /// [`Self::reduced_rhs`] and [`Self::back_substitute`]. `d` is the damping scale of all
    /// `n` variables. Fails when a damped block is not positive definite.
    pub(crate) fn add_complement(
        &mut self,
        pm: &mut PatternMatrix,
        mu: f64,
        d: &[f64],
    ) -> Result<(), super::SolverError> {
        let (first, size) = (self.first, self.size);
        let mut y: Vec<Vector4<f64>> = Vec::new();
        let mut sink = pm.sink();
        for (blk, c) in self.c.iter().enumerate() {
            let mut ct = *c;
            for k in 0..4 {
                if k < size {
                    ct[(k, k)] += mu * d[first + blk * size + k];
                } else {
                    ct[(k, k)] = 1.0;
                }
            }
            let inv = ct
                .cholesky()
                .ok_or_else(|| {
                    super::SolverError::Factorization(format!(
                        "local block {blk} is not positive definite"
                    ))
                })?
                .inverse();
            let (bs, be) = (self.b_start[blk] as usize, self.b_start[blk + 1] as usize);
            let (cols, rows) = (&self.b_col[bs..be], &self.b_val[bs..be]);
            y.clear();
            y.extend(rows.iter().map(|b| inv * b));
            // Columns are sorted, so (ci, cj) with j >= i is in the upper triangle.
            for (i, (&ci, yi)) in cols.iter().zip(&y).enumerate() {
                for (&cj, bj) in cols[i..].iter().zip(&rows[i..]) {
                    sink.push(ci, cj, -yi.dot(bj));
                }
            }
            self.inv[blk] = inv;
        }
        Ok(())
    }

    /// Right-hand side of the reduced system, `-g_a + B C⁻¹ g_c`.
    pub(crate) fn reduced_rhs(&self, g: &[f64]) -> Vec<f64> {
        let (first, size) = (self.first, self.size);
        let mut rhs: Vec<f64> = g[..first].iter().map(|v| -v).collect();
        for (blk, inv) in self.inv.iter().enumerate() {
            let mut gc = Vector4::zeros();
            for k in 0..size {
                gc[k] = g[first + blk * size + k];
            }
            let y = inv * gc;
            let (bs, be) = (self.b_start[blk] as usize, self.b_start[blk + 1] as usize);
            for (ci, bi) in self.b_col[bs..be].iter().zip(&self.b_val[bs..be]) {
                rhs[*ci as usize] += bi.dot(&y);
            }
        }
        rhs
    }

    /// The full step from the reduced one: `h_c = C⁻¹ (-g_c - Bᵀ h_a)`.
    pub(crate) fn back_substitute(&self, mut ha: Vec<f64>, g: &[f64]) -> Vec<f64> {
        let (first, size) = (self.first, self.size);
        ha.resize(g.len(), 0.0);
        for (blk, inv) in self.inv.iter().enumerate() {
            let mut t = Vector4::zeros();
            for k in 0..size {
                t[k] = -g[first + blk * size + k];
            }
            let (bs, be) = (self.b_start[blk] as usize, self.b_start[blk + 1] as usize);
            for (ci, bi) in self.b_col[bs..be].iter().zip(&self.b_val[bs..be]) {
                t -= bi * ha[*ci as usize];
            }
            let hc = inv * t;
            for k in 0..size {
                ha[first + blk * size + k] = hc[k];
            }
        }
        ha
    }
}
