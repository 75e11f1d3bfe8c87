//! Nested dissection ordering of a sparse symmetric pattern (George 1973; the automatic,
//! level-structure variant of George & Liu 1978).
//!
//! Input: the adjacency of a graph (a symmetric pattern without its diagonal: here the block
//! graph of the reduced normal equations, one node per vertex of a panel mesh). Output: an
//! ordering `perm[new] = old` that numbers two halves first and the separator between them
//! last, recursively, and parts of at most [`LEAF`] nodes by AMD. On the meshes of this crate
//! (2D manifolds) the factor of the planarisation's penalty phase (fairness couples vertices
//! two edges apart) is 25% smaller than AMD's on a 50 000-quad grid, 10% on 200 000
//! (BENCHMARKS.md). The caller keeps whichever of the two orderings gives the smaller factor,
//! so this never makes a factor larger.
//!
//! Separators come from breadth-first level structures: from a pseudo-peripheral root, and
//! from the nodes a quarter, half and three quarters along its last level (on a grid with a
//! 9-point stencil the levels from a corner are L-shaped, those from the middle of a side
//! straight); the median level, trimmed to its nodes that touch the next level, is a vertex
//! separator, and the smallest balanced one of the candidate roots is kept.
//!
//! Written by hand: faer offers AMD and COLAMD only, METIS is C (and not for wasm32 here),
//! and no maintained pure-Rust nested dissection exists.

use super::SolverError;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::SymbolicSparseColMat;
use faer::sparse::linalg::amd;

/// Parts this small are ordered by AMD instead of being split further.
pub(crate) const LEAF: usize = 128;

const UNSEEN: u32 = u32::MAX;

/// A graph in compressed adjacency form (both directions of every edge, no self loops).
pub(crate) struct Graph {
    start: Vec<u32>,
    adj: Vec<u32>,
}

impl Graph {
    /// The graph of the upper-triangle pairs `(i, j)`, `i <= j < n` (diagonal pairs ignored).
    pub(crate) fn from_upper_pairs(
        n: usize,
        pairs: impl Iterator<Item = (u32, u32)> + Clone,
    ) -> Self {
        let mut start = vec![0u32; n + 1];
        for (i, j) in pairs.clone() {
            if i != j {
                start[i as usize + 1] += 1;
                start[j as usize + 1] += 1;
            }
        }
        for k in 0..n {
            start[k + 1] += start[k];
        }
        let mut fill = start.clone();
        let mut adj = vec![0u32; start[n] as usize];
        for (i, j) in pairs {
            if i != j {
                adj[fill[i as usize] as usize] = j;
                fill[i as usize] += 1;
                adj[fill[j as usize] as usize] = i;
                fill[j as usize] += 1;
            }
        }
        Graph { start, adj }
    }

    fn len(&self) -> usize {
        self.start.len() - 1
    }

    fn neighbours(&self, v: u32) -> &[u32] {
        &self.adj[self.start[v as usize] as usize..self.start[v as usize + 1] as usize]
    }
}

/// Breadth-first level structure inside one part (nodes whose `part` label is `label`).
struct Levels {
    /// Nodes in visiting order; level `l` is `order[level_start[l]..level_start[l + 1]]`.
    order: Vec<u32>,
    level_start: Vec<usize>,
}

/// Scratch shared by the whole dissection: part labels and BFS levels per node.
struct Scratch {
    part: Vec<u32>,
    level: Vec<u32>,
}

impl Scratch {
    /// The level structure from `root` within part `label`.
    fn levels(&mut self, g: &Graph, label: u32, root: u32) -> Levels {
        let mut order = vec![root];
        let mut level_start = vec![0, 1];
        self.level[root as usize] = 0;
        let mut head = 0;
        // `level` is only trusted for nodes reached in this search: mark them by writing it,
        // and reset what was written before returning.
        let mut depth = 0u32;
        while head < order.len() {
            let end = order.len();
            depth += 1;
            for k in head..end {
                let v = order[k];
                for &w in g.neighbours(v) {
                    if self.part[w as usize] == label && self.level[w as usize] == UNSEEN {
                        self.level[w as usize] = depth;
                        order.push(w);
                    }
                }
            }
            head = end;
            if order.len() > end {
                level_start.push(order.len());
            }
        }
        Levels { order, level_start }
    }

    fn clear_levels(&mut self, lv: &Levels) {
        for &v in &lv.order {
            self.level[v as usize] = UNSEEN;
        }
    }
}

/// The separator of a level structure: the median level's nodes touching the next level.
/// `None` when the structure is too shallow to split. Returns (separator, size of the
/// smaller side).
fn median_separator(g: &Graph, s: &Scratch, lv: &Levels) -> Option<(Vec<u32>, usize)> {
    let depth = lv.level_start.len() - 1;
    if depth < 3 {
        return None;
    }
    let n = lv.order.len();
    // The first level at or past the middle, kept off the first and last levels.
    let mut m = (1..depth - 1)
        .find(|&l| lv.level_start[l + 1] >= n / 2)
        .unwrap_or(depth - 2);
    m = m.max(1);
    let next = m as u32 + 1;
    let sep: Vec<u32> = lv.order[lv.level_start[m]..lv.level_start[m + 1]]
        .iter()
        .copied()
        .filter(|&v| g.neighbours(v).iter().any(|&w| s.level[w as usize] == next))
        .collect();
    let after = n - lv.level_start[m + 1];
    let before = n - after - sep.len();
    Some((sep, before.min(after)))
}

/// Orders a connected or disconnected part of at most [`LEAF`] nodes (or one that does not
/// split) by AMD on its induced subgraph, appending to `out`.
fn order_leaf(g: &Graph, s: &mut Scratch, nodes: &[u32], out: &mut Vec<u32>) {
    if nodes.len() <= 2 {
        out.extend_from_slice(nodes);
        return;
    }
    // Local numbering through `level` (free between searches).
    for (k, &v) in nodes.iter().enumerate() {
        s.level[v as usize] = k as u32;
    }
    let label = s.part[nodes[0] as usize];
    let mut col_ptr = vec![0u32];
    let mut rows = Vec::new();
    for &v in nodes {
        let c = s.level[v as usize];
        let first = rows.len();
        rows.extend(
            g.neighbours(v)
                .iter()
                .filter(|&&w| s.part[w as usize] == label && s.level[w as usize] < c)
                .map(|&w| s.level[w as usize]),
        );
        rows.push(c);
        rows[first..].sort_unstable();
        col_ptr.push(rows.len() as u32);
    }
    for &v in nodes {
        s.level[v as usize] = UNSEEN;
    }
    let n = nodes.len();
    let pattern = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, rows);
    match amd_ordering(&pattern) {
        Ok(perm) => out.extend(perm.iter().map(|&k| nodes[k as usize])),
        Err(_) => out.extend_from_slice(nodes),
    }
}

/// faer's AMD ordering (`perm[new] = old`) of a square pattern (upper triangle or both).
pub(crate) fn amd_ordering(pattern: &SymbolicSparseColMat<u32>) -> Result<Vec<u32>, SolverError> {
    let fe = |e: &dyn std::fmt::Debug| SolverError::Factorization(format!("{e:?}"));
    let n = pattern.ncols();
    let mut perm = vec![0u32; n];
    let mut perm_inv = vec![0u32; n];
    let mut mem = MemBuffer::try_new(amd::order_maybe_unsorted_scratch::<u32>(
        n,
        pattern.row_idx().len(),
    ))
    .map_err(|e| fe(&e))?;
    amd::order_maybe_unsorted(
        &mut perm,
        &mut perm_inv,
        pattern.as_ref(),
        amd::Control::default(),
        MemStack::new(&mut mem),
    )
    .map_err(|e| fe(&e))?;
    Ok(perm)
}

/// The nested dissection ordering of `g`: `perm[new] = old`.
pub(crate) fn nested_dissection(g: &Graph) -> Vec<u32> {
    let n = g.len();
    let mut s = Scratch {
        part: vec![0; n],
        level: vec![UNSEEN; n],
    };
    // Each part is ordered into its own range of the result: halves first, separator last.
    let mut perm = vec![0u32; n];
    let mut next_label = 1u32;
    // (nodes, label, first position)
    let mut stack: Vec<(Vec<u32>, u32, usize)> = vec![((0..n as u32).collect(), 0, 0)];
    let mut leaf = Vec::new();
    while let Some((nodes, label, at)) = stack.pop() {
        if nodes.len() <= LEAF {
            leaf.clear();
            order_leaf(g, &mut s, &nodes, &mut leaf);
            perm[at..at + leaf.len()].copy_from_slice(&leaf);
            continue;
        }
        // One component at a time: a search that misses nodes splits off what it reached.
        let root = pseudo_peripheral(g, &mut s, label, nodes[0]);
        let lv = s.levels(g, label, root);
        if lv.order.len() < nodes.len() {
            let reached = lv.order.clone();
            s.clear_levels(&lv);
            let rest: Vec<u32> = {
                for &v in &reached {
                    s.part[v as usize] = next_label;
                }
                nodes
                    .iter()
                    .copied()
                    .filter(|&v| s.part[v as usize] == label)
                    .collect()
            };
            let len = reached.len();
            stack.push((reached, next_label, at));
            stack.push((rest, label, at + len));
            next_label += 1;
            continue;
        }
        // Candidate roots: the pseudo-peripheral one and three along its last level.
        let last = &lv.order[*lv.level_start.iter().rev().nth(1).expect("a level")..];
        let candidates = [
            last[last.len() / 4],
            last[last.len() / 2],
            last[3 * last.len() / 4],
        ];
        let mut best = median_separator(g, &s, &lv).map(|(sep, small)| (sep, small, root));
        s.clear_levels(&lv);
        for &r in &candidates {
            let lv = s.levels(g, label, r);
            if let Some((sep, small)) = median_separator(g, &s, &lv) {
                // Balanced (the smaller side at least a quarter of the part) and smaller.
                let balanced = 4 * small >= nodes.len();
                let better = match &best {
                    None => true,
                    Some((b, bsmall, _)) => {
                        let b_balanced = 4 * bsmall >= nodes.len();
                        (balanced && !b_balanced) || (balanced == b_balanced && sep.len() < b.len())
                    }
                };
                if better {
                    best = Some((sep, small, r));
                }
            }
            s.clear_levels(&lv);
        }
        let Some((sep, _, r)) = best else {
            // No level structure splits it (nearly a clique): AMD on it whole.
            leaf.clear();
            order_leaf(g, &mut s, &nodes, &mut leaf);
            perm[at..at + leaf.len()].copy_from_slice(&leaf);
            continue;
        };
        // Label the separator, then the side before it (reached from `r` without crossing
        // it); the rest is the side after.
        let sep_label = next_label;
        let before_label = next_label + 1;
        let after_label = next_label + 2;
        next_label += 3;
        for &v in &sep {
            s.part[v as usize] = sep_label;
        }
        let before = {
            let lv = s.levels(g, label, r);
            let reached = lv.order.clone();
            s.clear_levels(&lv);
            reached
        };
        for &v in &before {
            s.part[v as usize] = before_label;
        }
        let after: Vec<u32> = nodes
            .iter()
            .copied()
            .filter(|&v| s.part[v as usize] == label)
            .collect();
        for &v in &after {
            s.part[v as usize] = after_label;
        }
        let end = at + nodes.len();
        perm[end - sep.len()..end].copy_from_slice(&sep);
        let (nb, na) = (before.len(), after.len());
        stack.push((before, before_label, at));
        stack.push((after, after_label, at + nb));
        debug_assert_eq!(nb + na + sep.len(), nodes.len());
    }
    perm
}

/// A node of (nearly) largest eccentricity in the component of `start` within part `label`:
/// repeated searches from a node of the last level of smallest degree until the depth stops
/// growing.
fn pseudo_peripheral(g: &Graph, s: &mut Scratch, label: u32, start: u32) -> u32 {
    let mut root = start;
    let mut depth = 0;
    for _ in 0..8 {
        let lv = s.levels(g, label, root);
        let d = lv.level_start.len();
        let last = &lv.order[lv.level_start[d - 2]..];
        let candidate = *last
            .iter()
            .min_by_key(|&&v| g.neighbours(v).len())
            .expect("a nonempty level");
        s.clear_levels(&lv);
        if d <= depth {
            break;
        }
        depth = d;
        root = candidate;
    }
    root
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The 9-point stencil graph of a k x k grid (the block graph of a planarised quad grid).
    fn grid(k: u32) -> Graph {
        let id = |x: u32, y: u32| y * k + x;
        let mut pairs = Vec::new();
        for y in 0..k {
            for x in 0..k {
                for (dx, dy) in [(1, 0), (0, 1), (1, 1)] {
                    if x + dx < k && y + dy < k {
                        pairs.push((id(x, y), id(x + dx, y + dy)));
                    }
                }
                if x > 0 && y + 1 < k {
                    pairs.push((
                        id(x - 1, y + 1).min(id(x, y)),
                        id(x - 1, y + 1).max(id(x, y)),
                    ));
                }
            }
        }
        Graph::from_upper_pairs((k * k) as usize, pairs.into_iter())
    }

    /// The ordering is a permutation, every separator separates (the last-numbered part's
    /// removal disconnects the rest), on a grid and on a disconnected graph.
    #[test]
    fn orders_every_node_once_and_the_top_separator_separates() {
        let g = grid(60);
        let perm = nested_dissection(&g);
        let mut seen = vec![false; g.len()];
        for &v in &perm {
            assert!(!seen[v as usize], "{v} twice");
            seen[v as usize] = true;
        }
        assert!(seen.iter().all(|&s| s));
        // The top separator of a 60 x 60 grid is at most a bit longer than a side.
        let pos: Vec<usize> = {
            let mut p = vec![0; g.len()];
            for (k, &v) in perm.iter().enumerate() {
                p[v as usize] = k;
            }
            p
        };
        // The top separator is numbered last: the shortest tail whose removal disconnects.
        let sep_len = (1..=g.len())
            .find(|&t| {
                // The first `len - t` nodes split into at least two components.
                let keep = |v: u32| pos[v as usize] < g.len() - t;
                components(&g, keep) >= 2
            })
            .expect("a separator");
        assert!(sep_len <= 70, "top separator of {sep_len} nodes");

        let two = Graph::from_upper_pairs(6, [(0, 1), (1, 2), (3, 4), (4, 5)].into_iter());
        let mut p = nested_dissection(&two);
        p.sort_unstable();
        assert_eq!(p, vec![0, 1, 2, 3, 4, 5]);
    }

    /// On the planarisation's penalty pattern of a quad grid (9-point stencil and the
    /// fairness's second differences two vertices apart), nested dissection's factor is
    /// smaller than AMD's.
    #[test]
    fn dissection_beats_amd_on_a_fairness_grid() {
        let k = 90u32;
        let id = |x: u32, y: u32| y * k + x;
        let mut pairs = Vec::new();
        for y in 0..k {
            for x in 0..k {
                for (dx, dy) in [(1i32, 0i32), (0, 1), (1, 1), (-1, 1), (2, 0), (0, 2)] {
                    let (u, v) = (x as i32 + dx, y as i32 + dy);
                    if u >= 0 && (u as u32) < k && (v as u32) < k {
                        let (a, b) = (id(x, y), id(u as u32, v as u32));
                        pairs.push((a.min(b), a.max(b)));
                    }
                }
                pairs.push((id(x, y), id(x, y)));
            }
        }
        let n = (k * k) as usize;
        let (pattern, _) = crate::solver::pattern::csc_pattern(n, &pairs).unwrap();
        let g = Graph::from_upper_pairs(n, pairs.iter().copied());
        let nd = nested_dissection(&g);
        let identity: Vec<u32> = (0..n as u32).collect();
        let perm = amd_ordering(&pattern).unwrap();
        let len = |p: &[u32]| {
            crate::solver::cholesky::CholeskyAnalysis::new(pattern.as_ref(), p)
                .unwrap()
                .factor_len()
        };
        let (nd_len, amd_len, natural) = (len(&nd), len(&perm), len(&identity));
        assert!(
            nd_len < amd_len,
            "nested dissection {nd_len}, AMD {amd_len}"
        );
        assert!(amd_len < natural, "AMD {amd_len}, natural {natural}");
    }

    fn components(g: &Graph, keep: impl Fn(u32) -> bool) -> usize {
        let n = g.len();
        let mut seen = vec![false; n];
        let mut count = 0;
        for s in 0..n as u32 {
            if seen[s as usize] || !keep(s) {
                continue;
            }
            count += 1;
            let mut stack = vec![s];
            seen[s as usize] = true;
            while let Some(v) = stack.pop() {
                for &w in g.neighbours(v) {
                    if !seen[w as usize] && keep(w) {
                        seen[w as usize] = true;
                        stack.push(w);
                    }
                }
            }
        }
        count
    }
}
