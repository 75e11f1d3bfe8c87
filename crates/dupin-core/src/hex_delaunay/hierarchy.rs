//! The hexagon hierarchy of section 3: split (subdivide) with join of semi-hexagons, the
//! balancing rule, and point location.
//!
//! State: for every level `k`, the set of split full hexagons, keyed by lattice coordinates (so the
//! refinement stays O(n log n): every query is O(1) expected, no list scans). The set is stored in
//! 16×16 tiles of lattice coordinates, one 256-bit set per tile in a hash map ([`TileSet`]):
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
//! `coarsening.rs`) is made of merges.

use super::error::HexDelaunayError;
use super::lattice::{
    Axial, DIRS, Frame, add, in_domain, is_even, normalize, on_boundary, parents_of_midpoint,
};
use crate::Vec2;
use rustc_hash::FxHashMap;
use std::cell::Cell as Memo;
use std::ops::ControlFlow;

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
    /// for the top of a blossom (`coarsening.rs`). Bit-parallel: per split tile, the hexagons
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

/// A set of hexagons `(level, centre)` stored like the split sets (16×16 tiles of bits per
/// level): a work queue of hexagons near a change (discs of neighbours, mostly overlapping) is
/// deduplicated in a few cached tiles instead of one hash entry per hexagon.
#[derive(Debug, Clone, Default)]
pub struct HexSet {
    levels: Vec<TileSet>,
    len: usize,
}

impl HexSet {
    /// Inserts `v` at `level`; returns whether it was new.
    pub fn insert(&mut self, level: u32, v: Axial) -> bool {
        if self.levels.len() <= level as usize {
            self.levels
                .resize_with(level as usize + 1, TileSet::default);
        }
        let new = self.levels[level as usize].insert(v);
        self.len += usize::from(new);
        new
    }

    /// Inserts every lattice point within hexagonal distance `r` of `c` at `level` (the
    /// neighbourhood of a change), a row of bits at a time.
    pub fn insert_disc(&mut self, level: u32, c: Axial, r: i64) {
        self.insert_stadium(level, c.0, (c.1, c.1), r);
    }

    /// Inserts the union of the discs of radius `r` around `(a, b)` for `b` in the range
    /// `bs` (inclusive): per row one interval, as the discs of neighbouring centres overlap.
    pub fn insert_stadium(&mut self, level: u32, a: i64, bs: (i64, i64), r: i64) {
        if self.levels.len() <= level as usize {
            self.levels
                .resize_with(level as usize + 1, TileSet::default);
        }
        let set = &mut self.levels[level as usize];
        // A column of tiles at a time, so that consecutive rows mostly hit the memoised tile.
        for tb in (bs.0 - r) >> TILE..=(bs.1 + r) >> TILE {
            let (lo, hi) = (tb << TILE, (tb << TILE) | TILE_MASK);
            for i in -r..=r {
                // The part of the row `a + i` inside this tile column.
                let b0 = (bs.0 + (-r).max(-i - r)).max(lo);
                let b1 = (bs.1 + r.min(-i + r)).min(hi);
                if b0 <= b1 {
                    self.len += set.insert_run(a + i, b0, b1);
                }
            }
        }
    }

    /// Calls `f` for every member of `level` in the union of the discs of radius `r` around
    /// `(a, b)`, `b` in the range `bs` (inclusive), a tile at a time (a few tile reads instead
    /// of one query per lattice point).
    pub fn for_each_in_stadium(
        &self,
        level: u32,
        a: i64,
        bs: (i64, i64),
        r: i64,
        f: impl FnMut(Axial),
    ) {
        if let Some(s) = self.levels.get(level as usize) {
            s.for_each_in_stadium(a, bs, r, f);
        }
    }

    /// Whether a member of `level` lies within hexagonal distance `r` of `c` (stops at the
    /// first).
    pub fn any_in_disc(&self, level: u32, c: Axial, r: i64) -> bool {
        self.levels
            .get(level as usize)
            .is_some_and(|s| s.any_in_disc(c, r))
    }

    /// Removes `v` at `level`.
    pub fn remove(&mut self, level: u32, v: Axial) {
        if let Some(s) = self.levels.get_mut(level as usize)
            && s.remove(v)
        {
            self.len -= 1;
        }
    }

    /// Whether `v` at `level` is in the set.
    #[inline]
    pub fn contains(&self, level: u32, v: Axial) -> bool {
        self.levels
            .get(level as usize)
            .is_some_and(|s| s.contains(v))
    }

    /// The hexagons, level by level, tile by tile (deterministic order). The exact length is
    /// known, so collecting allocates once.
    pub fn iter(&self) -> impl ExactSizeIterator<Item = (u32, Axial)> + '_ {
        Counted {
            inner: self
                .levels
                .iter()
                .enumerate()
                .flat_map(|(k, s)| s.iter().map(move |v| (k as u32, v))),
            left: self.len,
        }
    }
}

/// An iterator with a known number of items left.
struct Counted<I> {
    inner: I,
    left: usize,
}

impl<I: Iterator> Iterator for Counted<I> {
    type Item = I::Item;

    #[inline]
    fn next(&mut self) -> Option<I::Item> {
        let x = self.inner.next()?;
        self.left -= 1;
        Some(x)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        (self.left, Some(self.left))
    }
}

impl<I: Iterator> ExactSizeIterator for Counted<I> {}

impl Extend<(u32, Axial)> for HexSet {
    fn extend<I: IntoIterator<Item = (u32, Axial)>>(&mut self, iter: I) {
        for (k, v) in iter {
            self.insert(k, v);
        }
    }
}

/// Side of a tile, as a shift: tiles of 16×16 lattice coordinates.
const TILE: u32 = 4;
const TILE_MASK: i64 = (1 << TILE) - 1;

/// A set of lattice points stored as 16×16 tiles, each a 256-bit set (4 words, half a cache
/// line). Written by hand because no crate offers a sparse 2D bitset over unbounded signed
/// coordinates; a hash set of points costs one scattered probe per query into a table that
/// outgrows the caches (1.4 million splits at 16k points in the extended mode), while
/// neighbouring queries here land in the same, already cached, tile.
#[derive(Debug, Clone)]
struct TileSet {
    /// Tile key → index into `words` and `keys`.
    index: FxHashMap<Axial, u32>,
    /// The tiles' bits, in order of creation.
    words: Vec<[u64; 4]>,
    /// The tiles' keys, in order of creation.
    keys: Vec<Axial>,
    /// The tile of the last query and its index (`NONE` if absent): the rules ask about a
    /// hexagon and its neighbours in a row, so most queries and inserts skip the hash probe.
    last: Memo<(Axial, u32)>,
}

/// No tile has this key (keys are coordinates shifted right by `TILE`).
const NO_TILE: Axial = (i64::MIN, i64::MIN);
/// Index of an absent tile.
const NONE: u32 = u32::MAX;

impl Default for TileSet {
    fn default() -> Self {
        TileSet {
            index: FxHashMap::default(),
            words: Vec::new(),
            keys: Vec::new(),
            last: Memo::new((NO_TILE, NONE)),
        }
    }
}

impl TileSet {
    /// Tile key and bit index (row-major within the tile) of `v`.
    #[inline]
    fn slot(v: Axial) -> (Axial, usize) {
        let bit = (((v.0 & TILE_MASK) << TILE) | (v.1 & TILE_MASK)) as usize;
        ((v.0 >> TILE, v.1 >> TILE), bit)
    }

    /// The split bits of the tile `(ta, tb)` with a rim of `R` (1 or 2) from its eight
    /// neighbours, `N = 16 + 2R` rows: `rows[a + R]` for `a` in -R..=15 + R holds row `a`,
    /// columns -R..=15 + R at bits 0..N.
    fn rows_with_rim<const R: usize, const N: usize>(&self, ta: i64, tb: i64) -> [u32; N] {
        debug_assert!((1..=2).contains(&R) && N == 16 + 2 * R);
        let mut rows = [0u32; N];
        for (da, r0, r1) in [(-1i64, 16 - R, 15usize), (0, 0, 15), (1, 0, R - 1)] {
            for db in -1i64..=1 {
                let i = self.tile((ta + da, tb + db));
                if i == NONE {
                    continue;
                }
                let w = &self.words[i as usize];
                for r in r0..=r1 {
                    let bits = ((w[r >> 2] >> ((r & 3) << TILE)) & 0xffff) as u32;
                    let part = match db {
                        -1 => bits >> (16 - R),
                        0 => bits << R,
                        _ => (bits & ((1 << R) - 1)) << (16 + R),
                    };
                    // Row r of the tile above or below is a rim row here.
                    rows[(da * 16 + (r + R) as i64) as usize] |= part;
                }
            }
        }
        rows
    }

    /// For the coarser tile `(ta, tb)` (this set one level finer): bit `b` of entry `a` set
    /// when a child of the coarse hexagon `(16 ta + a, 16 tb + b)` (its central child `2v` or
    /// a join `2v + d`) is in this set. The children of row `a` lie in rows `2a - 1..=2a + 1`,
    /// columns `2b - 1..=2b + 1`, within the 4×4 tiles around `(2 ta, 2 tb)`.
    fn children_split(&self, ta: i64, tb: i64) -> [u16; 16] {
        // tiles[i][j]: the tile (2 ta - 1 + i, 2 tb - 1 + j).
        let tiles: [[u32; 4]; 4] = std::array::from_fn(|i| {
            std::array::from_fn(|j| self.tile((2 * ta - 1 + i as i64, 2 * tb - 1 + j as i64)))
        });
        // Bit k of the result: column 32 tb - 1 + k of the fine row `r` (relative to 32 ta).
        let wide = |r: i64| -> u64 {
            let ti = ((r + 16) >> TILE) as usize; // tile row 2 ta - 1 + ti
            let row = (r & TILE_MASK) as usize;
            let mut out = 0u64;
            for (j, &i) in tiles[ti].iter().enumerate() {
                if i == NONE {
                    continue;
                }
                let w = &self.words[i as usize];
                let bits = (w[row >> 2] >> ((row & 3) << TILE)) & 0xffff;
                // Tile column 2 tb - 1 + j starts at column 16 j - 16 of 32 tb, bit 16 j - 15.
                out |= if j == 0 {
                    bits >> 15
                } else {
                    bits << (16 * j - 15)
                };
            }
            out
        };
        std::array::from_fn(|a| {
            let r = 2 * a as i64;
            let (mid, up, down) = (wide(r), wide(r + 1), wide(r - 1));
            // At bit 2b: columns 2b - 1, 2b, 2b + 1 of row 2a; 2b - 1, 2b of row 2a + 1;
            // 2b, 2b + 1 of row 2a - 1.
            let m = mid | (mid >> 1) | (mid >> 2) | up | (up >> 1) | (down >> 1) | (down >> 2);
            let lo = compress_even((m & 0xffff) as u32);
            let hi = compress_even(((m >> 16) & 0xffff) as u32);
            (lo | (hi << 8)) as u16
        })
    }

    /// Index of the tile `key` (`NONE` if absent), remembered for the next query.
    #[inline(always)]
    fn tile(&self, key: Axial) -> u32 {
        let (k, i) = self.last.get();
        if k == key {
            return i;
        }
        let i = self.index.get(&key).copied().unwrap_or(NONE);
        self.last.set((key, i));
        i
    }

    #[inline(always)]
    fn contains(&self, v: Axial) -> bool {
        let (key, bit) = Self::slot(v);
        let i = self.tile(key);
        i != NONE && (self.words[i as usize][bit >> 6] >> (bit & 63)) & 1 != 0
    }

    /// Bit `j` set when `v + DIRS[j]` is in the set.
    #[inline(always)]
    fn neighbours(&self, v: Axial) -> u8 {
        let (row, col) = (v.0 & TILE_MASK, v.1 & TILE_MASK);
        if row == 0 || col == 0 || row == TILE_MASK || col == TILE_MASK {
            let mut m = 0u8;
            for (j, d) in DIRS.iter().enumerate() {
                m |= u8::from(self.contains(add(v, *d))) << j;
            }
            return m;
        }
        let i = self.tile((v.0 >> TILE, v.1 >> TILE));
        if i == NONE {
            return 0;
        }
        let w = &self.words[i as usize];
        let bit = |a: i64, b: i64| -> u8 {
            let i = (((row + a) << TILE) | (col + b)) as usize;
            ((w[i >> 6] >> (i & 63)) & 1) as u8
        };
        // DIRS: (1, 0), (0, 1), (-1, 1), (-1, 0), (0, -1), (1, -1).
        bit(1, 0)
            | bit(0, 1) << 1
            | bit(-1, 1) << 2
            | bit(-1, 0) << 3
            | bit(0, -1) << 4
            | bit(1, -1) << 5
    }

    /// The 5×5 window of bits around `v` (see [`Hierarchy::split_window`]): five rows of five
    /// bits, from one tile column or, where the window crosses a tile edge in `b`, two (each
    /// column's rows cross at most one tile edge in `a`, so the memo keeps probes rare).
    #[inline]
    fn window(&self, v: Axial) -> u32 {
        let (row, col) = (v.0 & TILE_MASK, v.1 & TILE_MASK);
        if (2..=TILE_MASK - 2).contains(&row) && (2..=TILE_MASK - 2).contains(&col) {
            // Inside one tile (the common case): one look-up.
            let i = self.tile((v.0 >> TILE, v.1 >> TILE));
            if i == NONE {
                return 0;
            }
            let w = &self.words[i as usize];
            let mut win = 0u32;
            for dr in 0..5 {
                let r = (row - 2 + dr) as usize;
                let bits = ((w[r >> 2] >> ((r & 3) << TILE)) & 0xffff) as u32;
                win |= ((bits >> (col - 2)) & 31) << (5 * dr);
            }
            return win;
        }
        let b0 = v.1 - 2;
        let col = (b0 & TILE_MASK) as u32;
        let mut win = 0u32;
        for part in 0..=i64::from(col > 11) {
            let tb = (b0 >> TILE) + part;
            for dr in 0..5 {
                let a = v.0 - 2 + dr;
                let i = self.tile((a >> TILE, tb));
                if i == NONE {
                    continue;
                }
                let row = (a & TILE_MASK) as usize;
                let bits =
                    ((self.words[i as usize][row >> 2] >> ((row & 3) << TILE)) & 0xffff) as u32;
                // The first tile holds columns col.., the second the rest from 0.
                let five = if part == 0 {
                    bits >> col
                } else {
                    bits << (16 - col)
                } & 31;
                win |= five << (5 * dr);
            }
        }
        win
    }

    /// The index of tile `key`, created empty if absent.
    #[inline(always)]
    fn tile_or_insert(&mut self, key: Axial) -> u32 {
        let mut i = self.tile(key);
        if i == NONE {
            i = self.words.len() as u32;
            self.index.insert(key, i);
            self.words.push([0; 4]);
            self.keys.push(key);
            self.last.set((key, i));
        }
        i
    }

    /// Inserts `v`; returns whether it was new.
    #[inline(always)]
    fn insert(&mut self, v: Axial) -> bool {
        let (key, bit) = Self::slot(v);
        let i = self.tile_or_insert(key);
        let w = &mut self.words[i as usize][bit >> 6];
        let m = 1u64 << (bit & 63);
        let new = *w & m == 0;
        *w |= m;
        new
    }

    /// Inserts `(a, b)` for `b0 <= b <= b1`, all in one tile; returns how many were new.
    fn insert_run(&mut self, a: i64, b0: i64, b1: i64) -> usize {
        let (key, bit) = Self::slot((a, b0));
        let i = self.tile_or_insert(key);
        let len = (b1 - b0 + 1) as u32;
        let m = ((1u64 << len) - 1) << (bit & 63);
        let w = &mut self.words[i as usize][bit >> 6];
        let new = (m & !*w).count_ones() as usize;
        *w |= m;
        new
    }

    /// Calls `f(row, tile column base, mask)` for every tile row meeting the union of the
    /// discs of radius `r` around `(a, b)`, `b` in `bs`: the members of that row's interval,
    /// as bits of the tile's row of 16; stops when `f` breaks.
    fn stadium_rows(
        &self,
        a: i64,
        bs: (i64, i64),
        r: i64,
        mut f: impl FnMut(i64, i64, u64) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let (a0, a1, b0, b1) = (a - r, a + r, bs.0 - r, bs.1 + r);
        for ta in a0 >> TILE..=a1 >> TILE {
            for tb in b0 >> TILE..=b1 >> TILE {
                let i = self.tile((ta, tb));
                if i == NONE {
                    continue;
                }
                let w = &self.words[i as usize];
                let (base_a, base_b) = (ta << TILE, tb << TILE);
                for row_a in a0.max(base_a)..=a1.min(base_a | TILE_MASK) {
                    // The row's interval: b - bs in [max(-r, -i - r), min(r, -i + r)].
                    let i = row_a - a;
                    let lo = (bs.0 + (-r).max(-i - r)).max(base_b);
                    let hi = (bs.1 + r.min(-i + r)).min(base_b | TILE_MASK);
                    if lo > hi {
                        continue;
                    }
                    let row = (row_a & TILE_MASK) as usize;
                    let bits = (w[row >> 2] >> ((row & 3) << TILE)) & 0xffff;
                    f(
                        row_a,
                        base_b,
                        bits & (((1u64 << (hi - lo + 1)) - 1) << (lo & TILE_MASK)),
                    )?;
                }
            }
        }
        ControlFlow::Continue(())
    }

    /// Calls `f` for every member of the union of the discs of radius `r` around `(a, b)`,
    /// `b` in `bs` (see [`stadium_rows`](Self::stadium_rows)).
    fn for_each_in_stadium(&self, a: i64, bs: (i64, i64), r: i64, mut f: impl FnMut(Axial)) {
        let _ = self.stadium_rows(a, bs, r, |row_a, base_b, mut m| {
            while m != 0 {
                f((row_a, base_b | i64::from(m.trailing_zeros())));
                m &= m - 1;
            }
            ControlFlow::Continue(())
        });
    }

    /// Whether a member lies within hexagonal distance `r` of `c`, stopping at the first.
    fn any_in_disc(&self, c: Axial, r: i64) -> bool {
        self.stadium_rows(c.0, (c.1, c.1), r, |_, _, m| {
            if m != 0 {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        })
        .is_break()
    }

    /// Removes `v` (an emptied tile stays, as an all-zero entry); returns whether it was in.
    fn remove(&mut self, v: Axial) -> bool {
        let (key, bit) = Self::slot(v);
        let i = self.tile(key);
        if i == NONE {
            return false;
        }
        let w = &mut self.words[i as usize][bit >> 6];
        let m = 1u64 << (bit & 63);
        let was = *w & m != 0;
        *w &= !m;
        was
    }

    /// The points, tile by tile (in order of creation), row-major within a tile.
    fn iter(&self) -> TileIter<'_> {
        TileIter {
            set: self,
            tile: 0,
            word: 0,
            bits: self.words.first().map_or(0, |w| w[0]),
        }
    }
}

/// Iterator over a [`TileSet`]: the set bits of each word in turn.
struct TileIter<'a> {
    set: &'a TileSet,
    tile: usize,
    word: usize,
    bits: u64,
}

impl Iterator for TileIter<'_> {
    type Item = Axial;

    #[inline]
    fn next(&mut self) -> Option<Axial> {
        while self.bits == 0 {
            self.word += 1;
            if self.word == 4 {
                self.word = 0;
                self.tile += 1;
            }
            self.bits = *self.set.words.get(self.tile)?.get(self.word)?;
        }
        let bit = (self.word << 6) | self.bits.trailing_zeros() as usize;
        self.bits &= self.bits - 1;
        let (ta, tb) = self.set.keys[self.tile];
        let (row, col) = ((bit >> TILE) as i64, (bit as i64) & TILE_MASK);
        Some(((ta << TILE) | row, (tb << TILE) | col))
    }
}

/// The even bits 0, 2, .., 14 of `x` as bits 0..=7.
#[inline]
fn compress_even(x: u32) -> u32 {
    let x = x & 0x5555;
    let x = (x | (x >> 1)) & 0x3333;
    let x = (x | (x >> 2)) & 0x0f0f;
    (x | (x >> 4)) & 0x00ff
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
    use rustc_hash::FxHashSet;

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

    /// The levelled set keeps levels apart and lists each member once.
    #[test]
    fn hex_set_keeps_levels_apart() {
        let mut rng = ChaCha8Rng::seed_from_u64(6);
        let mut t = HexSet::default();
        let mut s: FxHashSet<(u32, Axial)> = FxHashSet::default();
        for _ in 0..3000 {
            let h = (
                rng.random_range(0u32..4),
                (rng.random_range(-20i64..20), rng.random_range(-20i64..20)),
            );
            assert_eq!(t.insert(h.0, h.1), s.insert(h));
            if rng.random_range(0..4) == 0 {
                // Remove a random member or non-member.
                let g = (rng.random_range(0u32..4), (rng.random_range(-20i64..20), 0));
                t.remove(g.0, g.1);
                s.remove(&g);
            }
        }
        for k in 0..5 {
            for a in -22..22 {
                for b in -22..22 {
                    assert_eq!(t.contains(k, (a, b)), s.contains(&(k, (a, b))));
                }
            }
        }
        // Discs, as the extended passes insert them, across tile borders.
        for _ in 0..300 {
            let (k, c, r) = (
                rng.random_range(0u32..4),
                (rng.random_range(-40i64..40), rng.random_range(-40i64..40)),
                rng.random_range(0i64..4),
            );
            t.insert_disc(k, c, r);
            for a in -r..=r {
                for b in -r..=r {
                    if (a + b).abs() <= r {
                        s.insert((k, (c.0 + a, c.1 + b)));
                    }
                }
            }
        }
        for k in 0..5 {
            for a in -45..45 {
                for b in -45..45 {
                    assert_eq!(t.contains(k, (a, b)), s.contains(&(k, (a, b))));
                }
            }
        }
        // Stadium queries find exactly the members within the distance of a centre, and
        // stadium inserts insert exactly those points.
        for _ in 0..300 {
            let (k, a, b, len, r) = (
                rng.random_range(0u32..4),
                rng.random_range(-45i64..45),
                rng.random_range(-45i64..45),
                rng.random_range(0i64..6),
                rng.random_range(0i64..10),
            );
            let near = |v: Axial| {
                (b..=b + len).any(|bc| {
                    let d = (v.0 - a, v.1 - bc);
                    d.0.abs().max(d.1.abs()).max((d.0 + d.1).abs()) <= r
                })
            };
            let mut got = Vec::new();
            t.for_each_in_stadium(k, a, (b, b + len), r, |v| got.push(v));
            got.sort_unstable();
            let mut want: Vec<Axial> = s
                .iter()
                .filter(|h| h.0 == k && near(h.1))
                .map(|h| h.1)
                .collect();
            want.sort_unstable();
            assert_eq!(got, want, "{k} {a} {b} {len} {r}");
            if len == 0 {
                let any = t
                    .levels
                    .get(k as usize)
                    .is_some_and(|s| s.any_in_disc((a, b), r));
                assert_eq!(any, !want.is_empty(), "{k} {a} {b} {r}");
            }
            let mut u = HexSet::default();
            u.insert_stadium(k, a, (b, b + len), r);
            let mut got: Vec<Axial> = u.iter().map(|h| h.1).collect();
            got.sort_unstable();
            let mut want: Vec<Axial> = (a - r..=a + r)
                .flat_map(|x| (b - r..=b + len + r).map(move |y| (x, y)))
                .filter(|&v| near(v))
                .collect();
            want.sort_unstable();
            assert_eq!(got, want, "{a} {b} {len} {r}");
            assert_eq!(u.iter().len(), want.len());
        }
        assert_eq!(t.iter().len(), s.len());
        let mut got: Vec<_> = t.iter().collect();
        assert_eq!(got.len(), s.len());
        got.sort_unstable();
        let mut want: Vec<_> = s.into_iter().collect();
        want.sort_unstable();
        assert_eq!(got, want);
    }
}
