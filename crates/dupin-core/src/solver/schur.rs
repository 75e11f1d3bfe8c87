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

use super::SparseSystem;
use super::pattern::PatternMatrix;
use nalgebra::{Matrix4, Vector4};

/// Reusable state of the elimination.
#[derive(Default)]
pub(crate) struct BlockSchur {
    first: usize,
    size: usize,
    /// Per block: its Gram block `C` (padded to 4 x 4).
    c: Vec<Matrix4<f64>>,
    /// Per block: the rows of the coupling `B`, as (global variable < first, row of B).
    b: Vec<Vec<(u32, Vector4<f64>)>>,
    /// Per block: `(C + μD)⁻¹` of the last damped assembly.
    inv: Vec<Matrix4<f64>>,
    row_start: Vec<usize>,
    order: Vec<usize>,
    fill: Vec<usize>,
}

impl BlockSchur {
    /// Adds the upper triangle of `A = J_aᵀ J_a` to `pm` and records the blocks `B`, `C`.
    /// Returns the diagonal of the whole `JᵀJ` (all `n` variables), or `None` when a residual
    /// touches two blocks (then nothing useful was added to `pm`).
    pub(crate) fn assemble(
        &mut self,
        sys: &SparseSystem,
        n: usize,
        first: usize,
        size: usize,
        pm: &mut PatternMatrix,
    ) -> Option<Vec<f64>> {
        debug_assert!((1..=4).contains(&size) && first <= n && (n - first).is_multiple_of(size));
        self.first = first;
        self.size = size;
        let nb = (n - first) / size;
        self.c.clear();
        self.c.resize(nb, Matrix4::zeros());
        self.b.resize_with(nb, Vec::new);
        self.b.iter_mut().for_each(Vec::clear);
        let m = sys.residuals.len();
        // Group the entries by row (counting sort).
        self.row_start.clear();
        self.row_start.resize(m + 1, 0);
        for e in &sys.entries {
            self.row_start[e.row as usize + 1] += 1;
        }
        for i in 0..m {
            self.row_start[i + 1] += self.row_start[i];
        }
        self.order.clear();
        self.order.resize(sys.entries.len(), 0);
        self.fill.clear();
        self.fill.extend_from_slice(&self.row_start);
        for (k, e) in sys.entries.iter().enumerate() {
            let r = e.row as usize;
            self.order[self.fill[r]] = k;
            self.fill[r] += 1;
        }
        let mut diag = vec![0.0; n];
        let ents = &sys.entries;
        for r in 0..m {
            let row = &self.order[self.row_start[r]..self.row_start[r + 1]];
            let mut blk = usize::MAX;
            for &a in row {
                let c = ents[a].col as usize;
                if c >= first {
                    let bi = (c - first) / size;
                    if blk == usize::MAX {
                        blk = bi;
                    } else if blk != bi {
                        return None;
                    }
                }
            }
            for &a in row {
                let ea = ents[a];
                if (ea.col as usize) < first {
                    // The row of B for this variable (found once per entry, not per pair).
                    let slot = if blk == usize::MAX {
                        usize::MAX
                    } else {
                        let list = &mut self.b[blk];
                        match list.iter().position(|e| e.0 == ea.col) {
                            Some(i) => i,
                            None => {
                                list.push((ea.col, Vector4::zeros()));
                                list.len() - 1
                            }
                        }
                    };
                    for &b in row {
                        let eb = ents[b];
                        let v = ea.value * eb.value;
                        if (eb.col as usize) < first {
                            if ea.col <= eb.col {
                                pm.push(ea.col, eb.col, v);
                            }
                            if ea.col == eb.col {
                                diag[ea.col as usize] += v;
                            }
                        } else {
                            let k = (eb.col as usize - first) % size;
                            self.b[blk][slot].1[k] += v;
                        }
                    }
                } else {
                    let ka = (ea.col as usize - first) % size;
                    for &b in row {
                        let eb = ents[b];
                        if (eb.col as usize) >= first {
                            let kb = (eb.col as usize - first) % size;
                            self.c[blk][(ka, kb)] += ea.value * eb.value;
                            if ka == kb {
                                diag[ea.col as usize] += ea.value * eb.value;
                            }
                        }
                    }
                }
            }
        }
        Some(diag)
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
        self.inv.clear();
        for (blk, (c, list)) in self.c.iter().zip(&self.b).enumerate() {
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
            for (i, (ci, bi)) in list.iter().enumerate() {
                let y = inv * bi;
                for (cj, bj) in &list[i..] {
                    let s = y.dot(bj);
                    pm.push((*ci).min(*cj), (*ci).max(*cj), -s);
                }
            }
            self.inv.push(inv);
        }
        Ok(())
    }

    /// Right-hand side of the reduced system, `-g_a + B C⁻¹ g_c`.
    pub(crate) fn reduced_rhs(&self, g: &[f64]) -> Vec<f64> {
        let (first, size) = (self.first, self.size);
        let mut rhs: Vec<f64> = g[..first].iter().map(|v| -v).collect();
        for (blk, (inv, list)) in self.inv.iter().zip(&self.b).enumerate() {
            let mut gc = Vector4::zeros();
            for k in 0..size {
                gc[k] = g[first + blk * size + k];
            }
            let y = inv * gc;
            for (ci, bi) in list {
                rhs[*ci as usize] += bi.dot(&y);
            }
        }
        rhs
    }

    /// The full step from the reduced one: `h_c = C⁻¹ (-g_c - Bᵀ h_a)`.
    pub(crate) fn back_substitute(&self, mut ha: Vec<f64>, g: &[f64]) -> Vec<f64> {
        let (first, size) = (self.first, self.size);
        ha.resize(g.len(), 0.0);
        for (blk, (inv, list)) in self.inv.iter().zip(&self.b).enumerate() {
            let mut t = Vector4::zeros();
            for k in 0..size {
                t[k] = -g[first + blk * size + k];
            }
            for (ci, bi) in list {
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
