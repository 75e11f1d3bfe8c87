//! Residuals whose Jacobian comes in small dense blocks: every residual row lists, per
//! variable block it depends on (a vertex's 3 coordinates, a face plane's 4 parameters), the
//! gradient with respect to that block.
//!
//! Why blocks instead of scalar triplets: mesh problems couple variables a whole vertex or
//! plane at a time, so a row of a hexagon's angle sum is 6 gradients instead of 18 triplets,
//! and the normal matrix `JᵀJ` is 21 block products instead of 171 scalar ones. Its pattern
//! analysis, assembly and ordering then work on blocks ([`super::block_normal`]), 9-16x fewer
//! items than scalar entries. Scalar problems are the special case of blocks of size 1
//! ([`BlockSystem::fill_from_sparse`]).

use super::{SolverError, SparseSystem};

/// Largest block size (a face plane: unit normal and offset).
pub(crate) const MAX_BLOCK: usize = 4;

/// [`BlockSystem::row_axis`] of a row with general gradients.
pub(crate) const ANY_AXIS: u8 = u8::MAX;

/// Sizes and positions of the variable blocks: block `b` holds the variables
/// `offset(b)..offset(b) + size(b)` of the flat unknown vector.
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct BlockLayout {
    offset: Vec<u32>,
}

impl BlockLayout {
    /// Blocks of the given sizes (each 1 to [`MAX_BLOCK`]), consecutive in the unknown vector.
    pub(crate) fn new(sizes: impl IntoIterator<Item = usize>) -> Self {
        let mut offset = vec![0u32];
        for s in sizes {
            debug_assert!((1..=MAX_BLOCK).contains(&s));
            offset.push(offset.last().copied().unwrap_or(0) + s as u32);
        }
        BlockLayout { offset }
    }

    /// Number of blocks.
    pub(crate) fn num_blocks(&self) -> usize {
        self.offset.len() - 1
    }

    /// Number of scalar unknowns.
    pub(crate) fn num_variables(&self) -> usize {
        self.offset.last().copied().unwrap_or(0) as usize
    }

    /// First unknown of block `b`.
    #[inline]
    pub(crate) fn offset(&self, b: usize) -> usize {
        self.offset[b] as usize
    }

    /// Number of unknowns of block `b`.
    #[inline]
    pub(crate) fn size(&self, b: usize) -> usize {
        (self.offset[b + 1] - self.offset[b]) as usize
    }
}

/// The gradient of one residual with respect to one block (unused components 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct BlockEntry {
    /// Block index.
    pub block: u32,
    /// ∂r / ∂(block variables), padded with zeros.
    pub grad: [f64; MAX_BLOCK],
}

/// Residual values and their block Jacobian, as filled in by a problem row by row.
///
/// A row names each block at most once ([`BlockSystem::add`] merges repeats). Keeping the same
/// rows and blocks from one evaluation to the next lets the solver reuse its analysis.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct BlockSystem {
    /// Residual values r_i(x).
    pub residuals: Vec<f64>,
    /// Row `r` owns `entries[row_end[r - 1]..row_end[r]]` (`row_end[-1]` = 0).
    row_end: Vec<u32>,
    entries: Vec<BlockEntry>,
    /// Per row: `k` if every gradient of the row has only component `k` (a coordinate row of
    /// a Laplacian-type term), else [`ANY_AXIS`]; lets the assembly skip the zero products.
    row_axis: Vec<u8>,
    /// Number of entries of the current (last) row.
    current_len: usize,
}

impl BlockSystem {
    /// Removes all rows, keeping the allocations.
    pub(crate) fn clear(&mut self) {
        self.residuals.clear();
        self.row_end.clear();
        self.entries.clear();
        self.row_axis.clear();
        self.current_len = 0;
    }

    /// Starts a new residual row with the given value.
    #[inline]
    pub(crate) fn push_row(&mut self, value: f64) {
        self.push_axis_row(value, ANY_AXIS);
    }

    /// Starts a row whose gradients will all have only component `axis` nonzero (the
    /// caller's promise; [`ANY_AXIS`] for none).
    #[inline]
    pub(crate) fn push_axis_row(&mut self, value: f64, axis: u8) {
        self.residuals.push(value);
        self.row_end.push(self.entries.len() as u32);
        self.row_axis.push(axis);
        self.current_len = 0;
    }

    /// See [`Self::push_axis_row`].
    #[inline]
    pub(crate) fn row_axis(&self, r: usize) -> u8 {
        self.row_axis[r]
    }

    /// Adds `grad` to the gradient of the current row with respect to `block`.
    #[inline(always)]
    pub(crate) fn add(&mut self, block: u32, grad: [f64; MAX_BLOCK]) {
        let start = self.row_end.last().map_or(0, |&e| e as usize) - self.current_len;
        if let Some(e) = self.entries[start..]
            .iter_mut()
            .rev()
            .find(|e| e.block == block)
        {
            for (a, b) in e.grad.iter_mut().zip(grad) {
                *a += b;
            }
        } else {
            self.entries.push(BlockEntry { block, grad });
            self.current_len += 1;
            *self.row_end.last_mut().expect("a row was started") += 1;
        }
    }

    #[inline]
    fn row_start(&self, r: usize) -> usize {
        if r == 0 {
            0
        } else {
            self.row_end[r - 1] as usize
        }
    }

    /// Number of residual rows.
    pub(crate) fn num_rows(&self) -> usize {
        self.residuals.len()
    }

    /// The block gradients of row `r`.
    #[inline]
    pub(crate) fn row(&self, r: usize) -> &[BlockEntry] {
        &self.entries[self.row_start(r)..self.row_end[r] as usize]
    }

    /// Half the squared norm of the residuals, ½ Σ r_i².
    pub(crate) fn cost(&self) -> f64 {
        0.5 * self.residuals.iter().map(|r| r * r).sum::<f64>()
    }

    /// Whether `other` has the same rows with the same blocks (the values may differ).
    pub(crate) fn same_pattern(&self, other: &BlockSystem) -> bool {
        self.row_end == other.row_end
            && self
                .entries
                .iter()
                .zip(&other.entries)
                .all(|(a, b)| a.block == b.block)
    }

    /// Checks that every value is finite and every block exists in `layout`.
    pub(crate) fn validate(&self, layout: &BlockLayout) -> Result<(), SolverError> {
        // v * 0 is 0 for finite v and NaN otherwise: one branch-free pass over the values.
        let mut zero = 0.0;
        for r in &self.residuals {
            zero += r * 0.0;
        }
        for e in &self.entries {
            zero += e.grad[0] * 0.0 + e.grad[1] * 0.0 + e.grad[2] * 0.0 + e.grad[3] * 0.0;
        }
        if zero != 0.0 {
            return Err(SolverError::NonFinite);
        }
        let nb = layout.num_blocks();
        if let Some(k) = self.entries.iter().position(|e| e.block as usize >= nb) {
            return Err(SolverError::OutOfRange {
                row: self.row_end.partition_point(|&end| end as usize <= k),
                col: self.entries[k].block as usize,
                rows: self.residuals.len(),
                cols: nb,
            });
        }
        Ok(())
    }

    /// `Jᵀ res`: this system's Jacobian applied to another residual vector of the same rows
    /// (`res = self.residuals` gives the gradient of [`Self::cost`]).
    pub(crate) fn gradient(&self, layout: &BlockLayout, res: &[f64]) -> Vec<f64> {
        let mut g = vec![0.0; layout.num_variables()];
        for (r, &rv) in res.iter().enumerate().take(self.num_rows()) {
            for e in self.row(r) {
                let o = layout.offset(e.block as usize);
                for k in 0..layout.size(e.block as usize) {
                    g[o + k] += e.grad[k] * rv;
                }
            }
        }
        g
    }

    /// The rows of a scalar triplet system on `layout`, whose blocks cover the variables in
    /// order (`block_of[variable] = (block, component)`). Repeated (row, column) entries are
    /// summed. Fails on an entry outside the system.
    pub(crate) fn fill_from_sparse(
        &mut self,
        sys: &SparseSystem,
        block_of: &[(u32, u8)],
    ) -> Result<(), SolverError> {
        sys.validate(block_of.len())?;
        self.clear();
        let m = sys.residuals.len();
        let mut start = vec![0u32; m + 1];
        for e in &sys.entries {
            start[e.row as usize + 1] += 1;
        }
        for i in 0..m {
            start[i + 1] += start[i];
        }
        let mut order = vec![0u32; sys.entries.len()];
        let mut fill = start.clone();
        for (k, e) in sys.entries.iter().enumerate() {
            order[fill[e.row as usize] as usize] = k as u32;
            fill[e.row as usize] += 1;
        }
        // Position of each block in the current row, to merge its entries in O(1).
        let mut seen: Vec<(u32, u32)> = vec![(u32::MAX, 0); block_of.len()];
        for r in 0..m {
            self.push_row(sys.residuals[r]);
            let row_start = self.entries.len() as u32;
            for &k in &order[start[r] as usize..start[r + 1] as usize] {
                let e = sys.entries[k as usize];
                let (b, comp) = block_of[e.col as usize];
                let (mark, at) = seen[b as usize];
                if mark == r as u32 {
                    self.entries[(row_start + at) as usize].grad[comp as usize] += e.value;
                } else {
                    let mut grad = [0.0; MAX_BLOCK];
                    grad[comp as usize] = e.value;
                    seen[b as usize] = (r as u32, self.entries.len() as u32 - row_start);
                    self.entries.push(BlockEntry { block: b, grad });
                    self.current_len += 1;
                    *self.row_end.last_mut().expect("row pushed") += 1;
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_merge_repeated_blocks_and_convert_from_triplets() {
        let layout = BlockLayout::new([1, 3, 4]);
        assert_eq!((layout.num_blocks(), layout.num_variables()), (3, 8));
        assert_eq!((layout.offset(2), layout.size(2)), (4, 4));
        let mut s = BlockSystem::default();
        s.push_row(2.0);
        s.add(1, [1.0, 0.0, 0.0, 0.0]);
        s.add(2, [0.0, 0.0, 0.0, 1.0]);
        s.add(1, [0.0, 2.0, 0.0, 0.0]);
        s.push_row(-1.0);
        assert_eq!(s.row(0).len(), 2);
        assert_eq!(s.row(0)[0].grad, [1.0, 2.0, 0.0, 0.0]);
        assert!(s.row(1).is_empty());
        assert_eq!(s.cost(), 2.5);
        let g = s.gradient(&layout, &s.residuals);
        assert_eq!(g, vec![0.0, 2.0, 4.0, 0.0, 0.0, 0.0, 0.0, 2.0]);
        // The same rows as triplets, with a repeated entry.
        let mut t = SparseSystem::new();
        let r0 = t.push_residual(2.0);
        t.push_entry(r0, 1, 0.5);
        t.push_entry(r0, 7, 1.0);
        t.push_entry(r0, 2, 2.0);
        t.push_entry(r0, 1, 0.5);
        t.push_residual(-1.0);
        let block_of: Vec<(u32, u8)> = (0..8)
            .map(|v| match v {
                0 => (0, 0),
                1..=3 => (1, (v - 1) as u8),
                _ => (2, (v - 4) as u8),
            })
            .collect();
        let mut c = BlockSystem::default();
        c.fill_from_sparse(&t, &block_of).unwrap();
        assert!(c.same_pattern(&s));
        assert_eq!(c, s);
        assert!(c.validate(&layout).is_ok());
        t.push_entry(r0, 8, 1.0);
        assert!(c.fill_from_sparse(&t, &block_of).is_err());
    }
}
