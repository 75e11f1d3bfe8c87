//! The hexagon hierarchy of section 3: split (subdivide) with join of semi-hexagons, the
//! balancing rule, and point location.
//!
//! State: for every level `k`, the set of split full hexagons, keyed by lattice coordinates (so the
//! refinement stays O(n log n): every query is O(1) expected, no list scans). The set is stored in
//! 16×16 tiles of lattice coordinates, one 256-bit set per tile in a hash map (`TileSet`, `tile_set.rs`):
//! the rules ask about a hexagon's neighbours, which mostly share its tile, so the map has
//! ~100x fewer entries than a set of hexagons and stays in cache, and a query is one probe.
//! Presence follows from it: a level-`k` lattice point in Ω is a full hexagon iff it is the
//! central child of a split level-`k-1` hexagon, or the join of the two semi-hexagons of two
//! adjacent split level-`k-1` hexagons (a parent outside Ω counts as split: the boundary
//! semi-hexagon is a virtual full hexagon, Fig. 1 right).
//!
//! Balancing (section 3.3, "adjacent levels differ by at most one") is equivalent to: every
//! split hexagon has its six lattice neighbours (inside Ω) present at its own level. Making a
//! neighbour present splits the full hexagon on the long edge of the semi-hexagon in the way
//! (the paper's "opposite neighbour"), recursively.
//!
//! Split counters, merge and break (section 3.2, the reverse operation). A full hexagon is
//! either the central child `2v` of a split hexagon `v` (the split "scales it down": its counter
//! is `v`'s plus one) or the join `2v + d` of two semi-hexagons (counter 0; a boundary
//! semi-hexagon is a virtual full hexagon, also counter 0). Since the split sets determine which
//! it is, the counter is a function of the position ([`Hierarchy::split_counter`]: the number of
//! levels since the position first became a lattice point). [`Hierarchy::merge`] is the inverse
//! of a split: it removes `v`'s split mark, so its central child is scaled up (counter minus
//! one) and its joined children are broken into semi-hexagons (allowed only at counter 0, which
//! every join has, and only for leaves). The local coarsening into blossoms (section 5.3,
//! `extended/coarsening.rs`) is made of merges.

use super::error::HexDelaunayError;
use super::lattice::{
    Axial, DIRS, Frame, add, in_domain, is_even, normalize, on_boundary, parents_of_midpoint,
};
use super::tile_set::{HexSet, TILE, TileSet};
use crate::Vec2;

/// A leaf cell of the hexagon mesh.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Cell {
    /// An unsplit full hexagon: level and centre.
    Full(u32, Axial),
    /// A semi-hexagon: half of the (absent) level-`k` hexagon at the given centre, the half that
    /// belongs to a split level-`k-1` hexagon whose neighbour across it is unsplit.
    Semi(u32, Axial),
}

/// Split sets per level plus the frame that places the lattice.
#[derive(Debug, Clone)]
pub struct Hierarchy {
    /// Placement of the lattice.
    pub frame: Frame,
    split: Vec<TileSet>,
    /// Number of split hexagons per level (so that merges can drop emptied deepest levels).
    per_level: Vec<usize>,
    /// Deepest level a hexagon may be split at.
    pub max_level: u32,
    /// Number of split hexagons.
    pub split_count: usize,
    /// The most split hexagons the refinement may make ([`super::MAX_SPLITS`] by default).
    pub max_splits: usize,
}

/// Why [`Hierarchy::merge`] refused (section 3.2: a merge must leave a balanced hierarchy).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum MergeError {
    /// The hexagon is not split.
    #[error("hexagon {1:?} at level {0} is not split")]
    NotSplit(u32, Axial),
    /// The root stays split (Ω is covered by the seven level-1 hexagons).
    #[error("the root hexagon cannot be merged")]
    Root,
    /// A hexagon of the next level within two steps of the central child is split: a child
    /// is not a leaf (a joined one could not be broken), or merging would leave a split
    /// hexagon next to a semi-hexagon (section 3.3's balancing).
    #[error("hexagon {1:?} at level {0} is split")]
    FinerNeighbour(u32, Axial),
}

/// What a merge did (section 3.2): the central child `2v` at `level + 1` was scaled up into
/// `v` at `level`, and the joined children in `broken` (at `level + 1`) were broken into two
/// semi-hexagons each (the other half stays with the split neighbour, or outside Ω).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Merge {
    /// Level of the merged hexagon.
    pub level: u32,
    /// The merged hexagon.
    pub v: Axial,
    /// The joins broken, at `level + 1`, in `DIRS` order.
    pub broken: Vec<Axial>,
}

impl Hierarchy {
    /// A hierarchy whose root hexagon is split (so Ω is covered by the seven level-1 hexagons).
    pub fn new(frame: Frame, max_level: u32) -> Self {
        let mut root = TileSet::default();
        root.insert((0, 0));
        Hierarchy {
            frame,
            split: vec![root],
            per_level: vec![1],
            max_level,
            split_count: 1,
            max_splits: super::MAX_SPLITS,
        }
    }

    /// Section 3.2's split counter of the full hexagon `v` at `level` (None if it is not
    /// present): 0 for a hexagon created by a join (or a boundary virtual hexagon, or the
    /// root), plus one for every split that scaled it down since. Inputs: any lattice point.
    /// Output: `level - l` for the coarsest level `l` where the same position is a lattice
    /// point, since only a split's central child keeps its parent's position.
    pub fn split_counter(&self, level: u32, v: Axial) -> Option<u32> {
        if !self.is_present(level, v) {
            return None;
        }
        Some(level - normalize(level, v).0)
    }

    /// Whether the full hexagon `m` at `level` may be broken into its two semi-hexagons
    /// (section 3.2): it is a leaf whose split counter is 0 (a join, not a central child).
    pub fn can_break(&self, level: u32, m: Axial) -> bool {
        level >= 1 && self.split_counter(level, m) == Some(0) && !self.is_split(level, m)
    }

    /// Whether `v` at `level` can be merged ([`merge`](Self::merge) without changing anything).
    pub fn can_merge(&self, level: u32, v: Axial) -> Result<(), MergeError> {
        if level == 0 {
            return Err(MergeError::Root);
        }
        if !self.is_split(level, v) {
            return Err(MergeError::NotSplit(level, v));
        }
        // The children (disc of radius 1 around 2v) must be leaves, and their neighbours
        // (radius 2) unsplit: a split one would need its neighbours present (balancing).
        let c = (2 * v.0, 2 * v.1);
        let w = self.split_window(level + 1, c);
        if w & WINDOW_DISC2 != 0 {
            let d = DISC2
                .iter()
                .find(|&&d| w & window_bit(d) != 0)
                .expect("a set bit of the disc");
            return Err(MergeError::FinerNeighbour(level + 1, add(c, *d)));
        }
        Ok(())
    }

    /// The reverse of a split (section 3.2): the central child of `v` at `level` is scaled up
    /// (its split counter drops by one) and the joins among `v`'s children are broken (each at
    /// counter 0, a leaf: [`can_break`](Self::can_break)). Refused, changing nothing, unless
    /// [`can_merge`](Self::can_merge); the hierarchy stays balanced. Points in the children
    /// are the caller's to re-locate (`Refinement::merge_now`). O(1) expected.
    pub fn merge(&mut self, level: u32, v: Axial) -> Result<Merge, MergeError> {
        self.can_merge(level, v)?;
        let c = (2 * v.0, 2 * v.1);
        let broken: Vec<Axial> = DIRS
            .iter()
            .map(|d| add(c, *d))
            .filter(|&m| in_domain(level + 1, m) && self.is_present(level + 1, m))
            .collect();
        debug_assert!(broken.iter().all(|&m| self.can_break(level + 1, m)));
        self.split[level as usize].remove(v);
        self.per_level[level as usize] -= 1;
        self.split_count -= 1;
        // The deepest levels that lost their last split hexagon go (`depth` stays exact).
        while self.per_level.last() == Some(&0) {
            self.per_level.pop();
            self.split.pop();
        }
        Ok(Merge { level, v, broken })
    }

    /// Deepest level that has a split hexagon.
    pub fn depth(&self) -> u32 {
        self.split.len() as u32
    }

    /// Whether the hexagon `v` at `level` is split.
    #[inline]
    pub fn is_split(&self, level: u32, v: Axial) -> bool {
        self.split
            .get(level as usize)
            .is_some_and(|s| s.contains(v))
    }

    /// Bit `j` set when the neighbour `v + DIRS[j]` at `level` is split (the fins of a leaf).
    /// One tile read for the 14×14 inner points of a tile, else six queries.
    #[inline]
    pub fn split_neighbours(&self, level: u32, v: Axial) -> u8 {
        match self.split.get(level as usize) {
            Some(s) => s.neighbours(v),
            None => 0,
        }
    }

    /// The split states of the 5×5 lattice points around `v` at `level` (the disc of radius
    /// 2 among them) as a bit mask: bit [`window_bit`]`(d)` is set when `v + d` is split. A few
    /// tile rows instead of up to 19 queries.
    #[inline]
    pub fn split_window(&self, level: u32, v: Axial) -> u32 {
        match self.split.get(level as usize) {
            Some(s) => s.window(v),
            None => 0,
        }
    }

    /// Whether the lattice point `v` at `level` is a full hexagon (leaf or split).
    #[inline]
    pub fn is_present(&self, level: u32, v: Axial) -> bool {
        if level == 0 {
            return v == (0, 0);
        }
        if !in_domain(level, v) {
            return false;
        }
        // One look-up of the parents' level (this is the most frequent query).
        let parents = self.split.get(level as usize - 1);
        let split = |e: Axial| parents.is_some_and(|s| s.contains(e));
        if is_even(v) {
            return split((v.0 >> 1, v.1 >> 1));
        }
        let (a, b) = parents_of_midpoint(v);
        // The domain test only for a parent that is not split (most parents are inside).
        (split(a) || !in_domain(level - 1, a)) && (split(b) || !in_domain(level - 1, b))
    }

    /// Whether `v` (in Ω) and its neighbours in Ω at `level >= 1` are all present, read from
    /// one window of the parents' split states: the parents of these points lie within two
    /// steps of `v / 2` (rounded down).
    fn disc1_present(&self, level: u32, v: Axial) -> bool {
        let u = (v.0 >> 1, v.1 >> 1);
        let w = self.split_window(level - 1, u);
        let split = |e: Axial| {
            let d = (e.0 - u.0, e.1 - u.1);
            debug_assert!(d.0.abs() <= 2 && d.1.abs() <= 2, "{d:?} outside the window");
            w & window_bit(d) != 0
        };
        std::iter::once((0, 0)).chain(DIRS).all(|d| {
            let z = add(v, d);
            if !in_domain(level, z) {
                return d != (0, 0);
            }
            if is_even(z) {
                return split((z.0 >> 1, z.1 >> 1));
            }
            let (a, b) = parents_of_midpoint(z);
            (split(a) || !in_domain(level - 1, a)) && (split(b) || !in_domain(level - 1, b))
        })
    }

    /// Makes `v` at `level` a full hexagon, splitting what lies on it. New splits are appended
    /// to `out` in the order they happen.
    pub fn ensure_present(
        &mut self,
        level: u32,
        v: Axial,
        out: &mut Vec<(u32, Axial)>,
    ) -> Result<(), HexDelaunayError> {
        if level == 0 {
            return Ok(());
        }
        if is_even(v) {
            return self.ensure_split(level - 1, (v.0 >> 1, v.1 >> 1), out);
        }
        let (a, b) = parents_of_midpoint(v);
        for e in [a, b] {
            if in_domain(level - 1, e) {
                self.ensure_split(level - 1, e, out)?;
            }
        }
        Ok(())
    }

    /// Splits the full hexagon `v` at `level`, first making it and its neighbours present
    /// (balancing rule). New splits are appended to `out` in order; `v` comes last.
    pub fn ensure_split(
        &mut self,
        level: u32,
        v: Axial,
        out: &mut Vec<(u32, Axial)>,
    ) -> Result<(), HexDelaunayError> {
        if self.is_split(level, v) {
            return Ok(());
        }
        if level >= self.max_level {
            return Err(HexDelaunayError::DepthLimit {
                max_level: self.max_level,
            });
        }
        if self.split_count >= self.max_splits {
            return Err(HexDelaunayError::TooManySplits {
                limit: self.max_splits,
            });
        }
        // Usually `v` and its neighbours are present already: one window read says so.
        if level == 0 || !self.disc1_present(level, v) {
            self.ensure_present(level, v, out)?;
            for d in DIRS {
                let y = add(v, d);
                if in_domain(level, y) {
                    self.ensure_present(level, y, out)?;
                }
            }
        }
        if self.split.len() <= level as usize {
            self.split.resize_with(level as usize + 1, TileSet::default);
            self.per_level.resize(level as usize + 1, 0);
        }
        self.split[level as usize].insert(v);
        self.per_level[level as usize] += 1;
        self.split_count += 1;
        out.push((level, v));
        Ok(())
    }

    /// The leaf cell containing `p` (which must lie in Ω). Descends from the root choosing, at
    /// each level, the nearest of the seven children of the current split hexagon, so a point on
    /// a shared edge is still assigned consistently to one cell (section 6.3's "first tested").
    pub fn locate(&self, p: Vec2) -> Cell {
        self.locate_from(p, 0, (0, 0))
    }

    /// [`locate`](Self::locate) starting below the split hexagon `a` at `level`, which must
    /// contain `p`.
    pub fn locate_from(&self, p: Vec2, mut level: u32, mut a: Axial) -> Cell {
        loop {
            let next = level + 1;
            let mut best = (a.0 * 2, a.1 * 2);
            let mut best_d = (self.frame.position(next, best) - p).norm_squared();
            for d in DIRS {
                let c = add(best_center(a), d);
                if !in_domain(next, c) {
                    continue;
                }
                let dist = (self.frame.position(next, c) - p).norm_squared();
                if dist < best_d {
                    best_d = dist;
                    best = c;
                }
            }
            if !self.is_present(next, best) {
                return Cell::Semi(next, best);
            }
            if self.is_split(next, best) {
                level = next;
                a = best;
            } else {
                return Cell::Full(next, best);
            }
        }
    }

    /// Whether `v` at `level` is a boundary (virtual) hexagon.
    #[inline]
    pub fn on_boundary(&self, level: u32, v: Axial) -> bool {
        on_boundary(level, v)
    }

    /// Number of leaf full hexagons (the dual mesh's vertices): every split hexagon's central
    /// child continues its position, so this counts the root plus, per split hexagon, its joined
    /// children (each counted from the parent that `parents_of_midpoint` names first, or from
    /// the inner parent for a boundary join).
    pub fn leaf_count(&self) -> usize {
        let mut n = 1;
        for (k, set) in self.split.iter().enumerate() {
            let k = k as u32;
            for x in set.iter() {
                let split = set.neighbours(x);
                for (j, d) in DIRS.iter().enumerate() {
                    let y = add(x, *d);
                    let boundary_join = !in_domain(k, y) && in_domain(k + 1, add(x, y));
                    if boundary_join || (split & (1 << j) != 0 && x < y) {
                        n += 1;
                    }
                }
            }
        }
        n
    }

    /// Calls `f(level, v)` for every member `v` of `set` that is unsplit with a split neighbour
    /// of its level (a leaf with fins if it is present), in `set`'s order. Per tile of `set`,
    /// the fins of all 256 points come from the split tile and the edges of its eight
    /// neighbours, a few shifts per row, instead of two queries per member.
    pub fn for_each_with_fins(&self, set: &HexSet, mut f: impl FnMut(u32, Axial)) {
        for (k, cand) in set.levels.iter().enumerate() {
            let Some(split) = self.split.get(k) else {
                break;
            };
            for (t, words) in cand.words.iter().enumerate() {
                if *words == [0; 4] {
                    continue;
                }
                let (ta, tb) = cand.keys[t];
                let rows = split.rows_with_rim::<1, 18>(ta, tb);
                for a in 0..16usize {
                    let (up, me, down) = (rows[a + 2], rows[a + 1], rows[a]);
                    // Neighbours (1, 0), (1, -1), (0, 1), (0, -1), (-1, 1), (-1, 0).
                    let fins = up | (up << 1) | (me >> 1) | (me << 1) | (down >> 1) | down;
                    let c = ((words[a >> 2] >> ((a & 3) << TILE)) & 0xffff) as u32;
                    let mut hits = (fins >> 1) & !(me >> 1) & c & 0xffff;
                    while hits != 0 {
                        let col = i64::from(hits.trailing_zeros());
                        hits &= hits - 1;
                        f(k as u32, ((ta << TILE) | a as i64, (tb << TILE) | col));
                    }
                }
            }
        }
    }

    /// Whether a hexagon of `level` within hexagonal distance `r` of `c` is split (a few tile
    /// reads).
    pub fn any_split_within(&self, level: u32, c: Axial, r: i64) -> bool {
        self.split
            .get(level as usize)
            .is_some_and(|s| s.any_in_disc(c, r))
    }

    /// Calls `f(t)` for every `t` of `level` whose disc of radius 2 consists of split
    /// hexagons none of whose seven children is split: the disc of radius 5 around `2t` one
    /// level finer is unsplit (those are exactly the 19 hexagons' children). The candidates
    /// for the top of a blossom (`extended/coarsening.rs`). Bit-parallel: per split tile, the hexagons
    /// whose children are all leaves come from the rows of the 4×4 finer tiles around its
    /// children, then the disc condition is two erosions by the six neighbours (tile rows with
    /// a rim of two). Tile by tile (deterministic order).
    pub fn for_each_blossom_top(&self, level: u32, mut f: impl FnMut(Axial)) {
        let Some(split) = self.split.get(level as usize) else {
            return;
        };
        let fine = self.split.get(level as usize + 1);
        // L: the split hexagons whose children are all unsplit.
        let mut leafy = TileSet::default();
        for (t, words) in split.words.iter().enumerate() {
            if *words == [0; 4] {
                continue;
            }
            let (ta, tb) = split.keys[t];
            let children = match fine {
                Some(fine) => fine.children_split(ta, tb),
                None => [0; 16],
            };
            let i = leafy.tile_or_insert((ta, tb));
            for (a, &c) in children.iter().enumerate() {
                let bits = (words[a >> 2] >> ((a & 3) << TILE)) & 0xffff;
                leafy.words[i as usize][a >> 2] |= (bits & !u64::from(c)) << ((a & 3) << TILE);
            }
        }
        for (t, words) in leafy.words.iter().enumerate() {
            if *words == [0; 4] {
                continue;
            }
            let (ta, tb) = leafy.keys[t];
            // rows[a + 2], a in -2..=17: row a, columns -2..=17 at bits 0..=19.
            let rows = leafy.rows_with_rim::<2, 20>(ta, tb);
            let erode = |up: u32, me: u32, down: u32| {
                // Neighbours (1, 0), (1, -1), (0, 1), (0, -1), (-1, 1), (-1, 0) as in
                // `for_each_with_fins`.
                up & (up << 1) & (me >> 1) & (me << 1) & (down >> 1) & down & me
            };
            // e1[a + 1], a in -1..=16: the members with all six neighbours in L, at the bits
            // of `rows` (columns -1..=16 meaningful).
            let e1: [u32; 18] = std::array::from_fn(|i| erode(rows[i + 2], rows[i + 1], rows[i]));
            for a in 0..16usize {
                let all = erode(e1[a + 2], e1[a + 1], e1[a]);
                let mut hits = (all >> 2) & 0xffff;
                while hits != 0 {
                    let col = i64::from(hits.trailing_zeros());
                    hits &= hits - 1;
                    f(((ta << TILE) | a as i64, (tb << TILE) | col));
                }
            }
        }
    }

    /// Iterates over the split hexagons of `level`, tile by tile (deterministic order).
    pub fn split_at(&self, level: u32) -> impl Iterator<Item = Axial> + '_ {
        self.split
            .get(level as usize)
            .into_iter()
            .flat_map(TileSet::iter)
    }
}

/// The offsets of the disc of radius 2 (19 lattice points).
const DISC2: [Axial; 19] = [
    (0, 0),
    (1, 0),
    (0, 1),
    (-1, 1),
    (-1, 0),
    (0, -1),
    (1, -1),
    (2, 0),
    (2, -1),
    (2, -2),
    (1, 1),
    (1, -2),
    (0, 2),
    (0, -2),
    (-1, 2),
    (-1, -1),
    (-2, 2),
    (-2, 1),
    (-2, 0),
];

/// The window bits of the disc of radius 2.
pub const WINDOW_DISC2: u32 = {
    let mut m = 0;
    let mut i = 0;
    while i < DISC2.len() {
        m |= window_bit(DISC2[i]);
        i += 1;
    }
    m
};

/// The bit of the offset `d` (both coordinates in -2..=2) in [`Hierarchy::split_window`].
#[inline]
pub const fn window_bit(d: Axial) -> u32 {
    1 << (5 * (d.0 + 2) + d.1 + 2)
}

#[inline]
fn best_center(a: Axial) -> Axial {
    (a.0 * 2, a.1 * 2)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;
    use rustc_hash::{FxHashMap, FxHashSet};

    /// The tiled set answers like a hash set of points, across tile borders and negative
    /// coordinates, and iterates over exactly its points.
    #[test]
    fn tile_set_matches_a_hash_set() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let mut t = TileSet::default();
        let mut s: FxHashSet<Axial> = FxHashSet::default();
        for _ in 0..4000 {
            let v = (rng.random_range(-40i64..40), rng.random_range(-40i64..40));
            assert_eq!(t.insert(v), s.insert(v), "{v:?}");
        }
        for a in -45..45 {
            for b in -45..45 {
                assert_eq!(t.contains((a, b)), s.contains(&(a, b)), "{a} {b}");
                let m = DIRS.iter().enumerate().fold(0u8, |m, (j, d)| {
                    m | u8::from(s.contains(&add((a, b), *d))) << j
                });
                assert_eq!(t.neighbours((a, b)), m, "{a} {b}");
            }
        }
        let mut h = Hierarchy::new(
            Frame {
                origin: Vec2::zeros(),
                root_radius: 1.0,
            },
            8,
        );
        h.split = vec![t.clone()];
        for a in -45..45 {
            for b in -45..45 {
                let w = h.split_window(0, (a, b));
                for da in -2..=2 {
                    for db in -2..=2 {
                        let want = s.contains(&(a + da, b + db));
                        assert_eq!(w & window_bit((da, db)) != 0, want, "{a} {b} {da} {db}");
                    }
                }
            }
        }
        // The bulk fin test finds the members with fins that are not in the set themselves.
        let mut cand = HexSet::default();
        for _ in 0..3000 {
            cand.insert(
                0,
                (rng.random_range(-45i64..45), rng.random_range(-45i64..45)),
            );
        }
        let mut bulk = Vec::new();
        h.for_each_with_fins(&cand, |k, v| bulk.push((k, v)));
        let naive: Vec<(u32, Axial)> = cand
            .iter()
            .filter(|&(_, v)| !t.contains(v) && t.neighbours(v) != 0)
            .collect();
        assert_eq!(bulk, naive);
        let mut got: Vec<Axial> = t.iter().collect();
        let n = got.len();
        got.sort_unstable();
        got.dedup();
        assert_eq!(n, got.len(), "a point iterated twice");
        let mut want: Vec<Axial> = s.into_iter().collect();
        want.sort_unstable();
        assert_eq!(got, want);
    }

    fn test_hierarchy(max_level: u32) -> Hierarchy {
        Hierarchy::new(
            Frame {
                origin: Vec2::zeros(),
                root_radius: 1.0,
            },
            max_level,
        )
    }

    /// The split hexagons, sorted (two hierarchies are the same iff these are).
    fn splits(h: &Hierarchy) -> Vec<(u32, Axial)> {
        let mut v: Vec<(u32, Axial)> = (0..h.depth())
            .flat_map(|k| h.split_at(k).map(move |x| (k, x)))
            .collect();
        v.sort_unstable();
        v
    }

    /// Every present full hexagon with its split counter (levels up to `depth`).
    fn counters(h: &Hierarchy) -> FxHashMap<(u32, Axial), u32> {
        let mut m = FxHashMap::default();
        for k in 0..=h.depth() {
            let n = 1i64 << k;
            for a in -n..=n {
                for b in -n..=n {
                    if let Some(c) = h.split_counter(k, (a, b)) {
                        m.insert((k, (a, b)), c);
                    }
                }
            }
        }
        m
    }

    /// Fig. 1: the root's central child has counter 1 after one split, 2 after two; joins
    /// (including the boundary's virtual full hexagons) have 0; a merge gives back the
    /// counters before the split.
    #[test]
    fn split_counters_as_in_fig_1() {
        let mut h = test_hierarchy(8);
        assert_eq!(h.split_counter(0, (0, 0)), Some(0));
        assert_eq!(h.split_counter(1, (0, 0)), Some(1));
        for d in DIRS {
            // Level-1 boundary hexagons: joins with the virtual outside.
            assert_eq!(h.split_counter(1, d), Some(0));
            assert!(h.can_break(1, d));
        }
        let mut out = Vec::new();
        h.ensure_split(1, (0, 0), &mut out).unwrap();
        assert_eq!(out, vec![(1, (0, 0))], "no balancing split needed");
        assert_eq!(h.split_counter(2, (0, 0)), Some(2));
        // The centre's semi-hexagons towards its unsplit neighbours: no full hexagon.
        assert_eq!(h.split_counter(2, DIRS[0]), None);
        let before = counters(&h);
        h.ensure_split(1, DIRS[0], &mut out).unwrap();
        // Split of a counter-0 hexagon: its child has 1; the join with the centre has 0.
        assert_eq!(h.split_counter(2, (2, 0)), Some(1));
        assert_eq!(h.split_counter(2, DIRS[0]), Some(0));
        assert!(h.can_break(2, DIRS[0]));
        assert!(!h.can_break(2, (2, 0)), "a central child is no join");
        let m = h.merge(1, DIRS[0]).unwrap();
        // Only the join with the centre: the children's other neighbours inside Ω are halves
        // of unsplit level-1 hexagons (semi-hexagons), the rest lies outside Ω.
        assert_eq!(m.broken, vec![DIRS[0]]);
        assert_eq!(counters(&h), before);
        assert_eq!(h.merge(0, (0, 0)), Err(MergeError::Root));
        assert_eq!(h.merge(1, DIRS[1]), Err(MergeError::NotSplit(1, DIRS[1])));
    }

    /// Split then merge gives back the same hierarchy (also after the balancing splits a split
    /// forces, merged in reverse order), and merges that would unbalance it are refused.
    #[test]
    fn split_then_merge_returns_the_same_hierarchy() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        for _ in 0..200 {
            let mut h = test_hierarchy(7);
            let mut out = Vec::new();
            for _ in 0..rng.random_range(0..30) {
                let k = rng.random_range(1u32..5);
                let n = 1i64 << (k - 1);
                let v = (rng.random_range(-n..=n), rng.random_range(-n..=n));
                if in_domain(k, v) && h.is_present(k, v) {
                    h.ensure_split(k, v, &mut out).unwrap();
                }
            }
            let before = splits(&h);
            let count = h.split_count;
            let depth = h.depth();
            let k = rng.random_range(1u32..6);
            let n = 1i64 << (k - 1);
            let v = (rng.random_range(-n..=n), rng.random_range(-n..=n));
            if !in_domain(k, v) || h.is_split(k, v) {
                continue;
            }
            out.clear();
            h.ensure_split(k, v, &mut out).unwrap();
            for &(l, x) in out.iter().rev() {
                h.merge(l, x).unwrap();
            }
            assert_eq!(splits(&h), before);
            assert_eq!((h.split_count, h.depth()), (count, depth));
            // A merge under a split child or next to a split hexagon of the next level is
            // refused and changes nothing.
            for (l, x) in before {
                if l == 0 {
                    continue;
                }
                let c = (2 * x.0, 2 * x.1);
                let finer = DISC2.iter().any(|d| h.is_split(l + 1, add(c, *d)));
                let snapshot = splits(&h);
                match h.can_merge(l, x) {
                    Ok(()) => assert!(!finer),
                    Err(e) => {
                        assert!(finer);
                        assert_eq!(h.merge(l, x), Err(e));
                        assert_eq!(splits(&h), snapshot);
                    }
                }
            }
        }
    }

    /// The split counter as the paper keeps it (section 3.2), tracked operation by operation
    /// in a model (a split gives the central child its parent's counter plus one and every new
    /// join 0; a merge checks the child's counter, scales it back and breaks the joins, each at
    /// counter 0), equals `split_counter` after random splits and merges; joins and breaks
    /// round-trip.
    #[test]
    fn split_counters_follow_splits_merges_joins_and_breaks() {
        let mut rng = ChaCha8Rng::seed_from_u64(8);
        for _ in 0..40 {
            let mut h = test_hierarchy(6);
            let mut model = counters(&h);
            for _ in 0..120 {
                let k = rng.random_range(1u32..5);
                let n = 1i64 << (k - 1);
                let v = (rng.random_range(-n..=n), rng.random_range(-n..=n));
                if !in_domain(k, v) {
                    continue;
                }
                if h.is_split(k, v) {
                    let Ok(m) = h.merge(k, v) else {
                        continue;
                    };
                    let c = (2 * v.0, 2 * v.1);
                    let child = model.remove(&(k + 1, c)).expect("central child present");
                    assert_eq!(child, model[&(k, v)] + 1);
                    for x in &m.broken {
                        assert_eq!(model.remove(&(k + 1, *x)), Some(0), "break at counter 0");
                    }
                } else if h.is_present(k, v) {
                    let mut out = Vec::new();
                    h.ensure_split(k, v, &mut out).unwrap();
                    for (l, x) in out {
                        let c = (2 * x.0, 2 * x.1);
                        model.insert((l + 1, c), model[&(l, x)] + 1);
                        for d in DIRS {
                            let m = add(c, d);
                            if in_domain(l + 1, m) && h.is_present(l + 1, m) {
                                // Joined now (or already, from an earlier split).
                                model.entry((l + 1, m)).or_insert(0);
                            }
                        }
                    }
                }
                assert_eq!(counters(&h), model);
            }
        }
    }

    /// The bulk scan for blossom tops finds exactly the hexagons whose disc of radius 2 is
    /// split with unsplit children (queries: the 19 splits and the children's 5-disc).
    #[test]
    fn blossom_tops_match_the_queries() {
        let mut rng = ChaCha8Rng::seed_from_u64(10);
        for (density, child) in [(0.95, 0.02), (0.99, 0.005), (1.0, 0.002)] {
            let mut coarse = TileSet::default();
            let mut fine = TileSet::default();
            for a in -40i64..40 {
                for b in -40i64..40 {
                    if rng.random_bool(density) {
                        coarse.insert((a, b));
                    }
                    if rng.random_bool(child) {
                        fine.insert((2 * a + rng.random_range(0..2), 2 * b));
                    }
                }
            }
            let mut h = test_hierarchy(8);
            h.split = vec![coarse.clone(), fine.clone()];
            let mut got = Vec::new();
            h.for_each_blossom_top(0, |v| got.push(v));
            got.sort_unstable();
            let mut want: Vec<Axial> = coarse
                .iter()
                .filter(|&t| {
                    DISC2.iter().all(|d| coarse.contains(add(t, *d)))
                        && !h.any_split_within(1, (2 * t.0, 2 * t.1), 5)
                })
                .collect();
            want.sort_unstable();
            assert!(!want.is_empty(), "{density}");
            assert_eq!(got, want, "{density}");
        }
    }
}
