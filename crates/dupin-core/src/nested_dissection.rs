//! Geometric nested dissection: a fill-reducing elimination order for the sparse Cholesky
//! factorisation of matrices whose graph is a surface mesh (George, "Nested dissection of a
//! regular finite element mesh", 1973; the geometric variant of Miller, Teng, Thurston and
//! Vavasis splits by a plane through the median point).
//!
//! Input: one point per graph node and the symmetric adjacency in CSR form. Output: the
//! permutation `order[new] = old`. Each set is split by the plane through the median of its
//! points orthogonal to their principal axis; the nodes of the smaller side that touch the other
//! side form the separator, which is eliminated after both halves. Small sets (the leaves) are
//! ordered by approximate minimum degree.
//!
//! Why by hand: faer (the sparse Cholesky used here) only offers AMD, which on surface meshes
//! leaves about twice the fill of nested dissection, and no graph-partitioning crate (METIS
//! bindings are C) compiles to wasm32 without a C toolchain; the coordinates make a geometric
//! split enough for meshes.

use crate::Vec3;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::SymbolicSparseColMatRef;
use faer::sparse::linalg::amd;
use nalgebra::{Matrix3, SymmetricEigen};

/// Sets at most this large are ordered by minimum degree instead of being split.
const LEAF: usize = 96;

/// Elimination order (`order[new] = old`) of the graph with node positions `points` and
/// symmetric adjacency `adj[xadj[v]..xadj[v + 1]]` (self loops allowed, ignored).
///
/// `xadj` must have `points.len() + 1` non-decreasing entries and `adj` indices below
/// `points.len()` (the callers build both from a mesh, so a violation is a bug and panics).
pub(crate) fn nested_dissection(points: &[Vec3], xadj: &[usize], adj: &[u32]) -> Vec<u32> {
    let n = points.len();
    assert_eq!(xadj.len(), n + 1, "one adjacency range per node");
    let mut nd = Dissection {
        points,
        xadj,
        adj,
        mark: vec![0; n],
        stamp: 0,
        local: vec![u32::MAX; n],
        order: Vec::with_capacity(n),
    };
    // Explicit stack of pending sets: a set is pushed as "split" work, and its separator as
    // "emit" work underneath its halves, so it is emitted after both.
    let mut stack = vec![Work::Split((0..n as u32).collect())];
    while let Some(w) = stack.pop() {
        match w {
            Work::Emit(s) => nd.order.extend_from_slice(&s),
            Work::Split(s) if s.len() <= LEAF => nd.leaf(&s),
            Work::Split(s) => {
                let (left, right, sep) = nd.split(s);
                stack.push(Work::Emit(sep));
                stack.push(Work::Split(right));
                stack.push(Work::Split(left));
            }
        }
    }
    debug_assert_eq!(nd.order.len(), n);
    nd.order
}

enum Work {
    Split(Vec<u32>),
    Emit(Vec<u32>),
}

struct Dissection<'a> {
    points: &'a [Vec3],
    xadj: &'a [usize],
    adj: &'a [u32],
    /// Side labels of the set being split: `stamp` left, `stamp + 1` right.
    mark: Vec<u32>,
    stamp: u32,
    /// Local index of a node in the leaf being ordered (`u32::MAX` outside).
    local: Vec<u32>,
    order: Vec<u32>,
}

impl Dissection<'_> {
    fn neighbours(&self, v: u32) -> &[u32] {
        &self.adj[self.xadj[v as usize]..self.xadj[v as usize + 1]]
    }

    /// Splits `set` at the median along the principal axis; returns (left, right, separator).
    fn split(&mut self, mut set: Vec<u32>) -> (Vec<u32>, Vec<u32>, Vec<u32>) {
        let inv = 1.0 / set.len() as f64;
        let mean = set.iter().map(|&v| self.points[v as usize]).sum::<Vec3>() * inv;
        let mut cov = Matrix3::zeros();
        for &v in &set {
            let d = self.points[v as usize] - mean;
            cov += d * d.transpose();
        }
        let eig = SymmetricEigen::new(cov);
        let axis = eig.eigenvectors.column(eig.eigenvalues.imax()).into_owned();
        let key = |v: u32| self.points[v as usize].dot(&axis);
        let mid = set.len() / 2;
        set.select_nth_unstable_by(mid, |&a, &b| key(a).total_cmp(&key(b)));
        let right = set.split_off(mid);
        let left = set;
        if self.stamp >= u32::MAX - 2 {
            self.mark.iter_mut().for_each(|m| *m = 0);
            self.stamp = 0;
        }
        self.stamp += 2;
        let (sl, sr) = (self.stamp, self.stamp + 1);
        for &v in &left {
            self.mark[v as usize] = sl;
        }
        for &v in &right {
            self.mark[v as usize] = sr;
        }
        // Boundary of each side towards the other; the smaller one is the separator.
        let touches = |v: u32, other: u32| {
            self.neighbours(v)
                .iter()
                .any(|&u| self.mark[u as usize] == other)
        };
        let bl: Vec<bool> = left.iter().map(|&v| touches(v, sr)).collect();
        let br: Vec<bool> = right.iter().map(|&v| touches(v, sl)).collect();
        let cut = |side: Vec<u32>, flags: &[bool]| {
            let (mut keep, mut sep) = (Vec::new(), Vec::new());
            for (v, &f) in side.into_iter().zip(flags) {
                if f { &mut sep } else { &mut keep }.push(v);
            }
            (keep, sep)
        };
        if bl.iter().filter(|&&f| f).count() <= br.iter().filter(|&&f| f).count() {
            let (keep, sep) = cut(left, &bl);
            (keep, right, sep)
        } else {
            let (keep, sep) = cut(right, &br);
            (left, keep, sep)
        }
    }

    /// Orders a small set by approximate minimum degree on its induced subgraph.
    fn leaf(&mut self, set: &[u32]) {
        for (i, &v) in set.iter().enumerate() {
            self.local[v as usize] = i as u32;
        }
        let m = set.len();
        let mut col_ptr = Vec::with_capacity(m + 1);
        let mut rows = Vec::new();
        col_ptr.push(0u32);
        let mut col = Vec::new();
        for &v in set {
            col.clear();
            col.extend(
                self.neighbours(v)
                    .iter()
                    .map(|&u| self.local[u as usize])
                    .filter(|&l| l != u32::MAX),
            );
            col.sort_unstable();
            col.dedup();
            rows.extend_from_slice(&col);
            col_ptr.push(rows.len() as u32);
        }
        let mut perm = vec![0u32; m];
        let mut perm_inv = vec![0u32; m];
        let ok = SymbolicSparseColMatRef::new_checked(m, m, &col_ptr, None, &rows);
        let mut mem = MemBuffer::new(amd::order_maybe_unsorted_scratch::<u32>(m, rows.len()));
        let done = amd::order_maybe_unsorted(
            &mut perm,
            &mut perm_inv,
            ok,
            amd::Control::default(),
            MemStack::new(&mut mem),
        );
        match done {
            Ok(_) => self.order.extend(perm.iter().map(|&p| set[p as usize])),
            Err(_) => self.order.extend_from_slice(set),
        }
        for &v in set {
            self.local[v as usize] = u32::MAX;
        }
    }
}
