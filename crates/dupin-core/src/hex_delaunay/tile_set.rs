//! Sets of lattice points stored as 16×16 tiles of bits (section 3's split sets and the
//! extended passes' work queues): [`TileSet`] per level, [`HexSet`] over all levels. The
//! hexagon rules ask about a hexagon's neighbours, which mostly share its tile, so the map has
//! ~100x fewer entries than a set of hexagons and stays in cache, and a query is one probe.

use super::lattice::{Axial, DIRS, add};
use rustc_hash::FxHashMap;
use std::cell::Cell as Memo;
use std::ops::ControlFlow;

/// A set of hexagons `(level, centre)` stored like the split sets (16×16 tiles of bits per
/// level): a work queue of hexagons near a change (discs of neighbours, mostly overlapping) is
/// deduplicated in a few cached tiles instead of one hash entry per hexagon.
#[derive(Debug, Clone, Default)]
pub struct HexSet {
    pub(super) levels: Vec<TileSet>,
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
pub(super) const TILE: u32 = 4;
pub(super) const TILE_MASK: i64 = (1 << TILE) - 1;

/// A set of lattice points stored as 16×16 tiles, each a 256-bit set (4 words, half a cache
/// line). Written by hand because no crate offers a sparse 2D bitset over unbounded signed
/// coordinates; a hash set of points costs one scattered probe per query into a table that
/// outgrows the caches (1.4 million splits at 16k points in the extended mode), while
/// neighbouring queries here land in the same, already cached, tile.
#[derive(Debug, Clone)]
pub(super) struct TileSet {
    /// Tile key → index into `words` and `keys`.
    index: FxHashMap<Axial, u32>,
    /// The tiles' bits, in order of creation.
    pub(super) words: Vec<[u64; 4]>,
    /// The tiles' keys, in order of creation.
    pub(super) keys: Vec<Axial>,
    /// The tile of the last query and its index (`NONE` if absent): the rules ask about a
    /// hexagon and its neighbours in a row, so most queries and inserts skip the hash probe.
    last: Memo<(Axial, u32)>,
}

/// No tile has this key (keys are coordinates shifted right by `TILE`).
const NO_TILE: Axial = (i64::MIN, i64::MIN);
/// Index of an absent tile.
pub(super) const NONE: u32 = u32::MAX;

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
    pub(super) fn slot(v: Axial) -> (Axial, usize) {
        let bit = (((v.0 & TILE_MASK) << TILE) | (v.1 & TILE_MASK)) as usize;
        ((v.0 >> TILE, v.1 >> TILE), bit)
    }

    /// The split bits of the tile `(ta, tb)` with a rim of `R` (1 or 2) from its eight
    /// neighbours, `N = 16 + 2R` rows: `rows[a + R]` for `a` in -R..=15 + R holds row `a`,
    /// columns -R..=15 + R at bits 0..N.
    pub(super) fn rows_with_rim<const R: usize, const N: usize>(
        &self,
        ta: i64,
        tb: i64,
    ) -> [u32; N] {
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
    pub(super) fn children_split(&self, ta: i64, tb: i64) -> [u16; 16] {
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
    pub(super) fn tile(&self, key: Axial) -> u32 {
        let (k, i) = self.last.get();
        if k == key {
            return i;
        }
        let i = self.index.get(&key).copied().unwrap_or(NONE);
        self.last.set((key, i));
        i
    }

    #[inline(always)]
    pub(super) fn contains(&self, v: Axial) -> bool {
        let (key, bit) = Self::slot(v);
        let i = self.tile(key);
        i != NONE && (self.words[i as usize][bit >> 6] >> (bit & 63)) & 1 != 0
    }

    /// Bit `j` set when `v + DIRS[j]` is in the set.
    #[inline(always)]
    pub(super) fn neighbours(&self, v: Axial) -> u8 {
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
    pub(super) fn window(&self, v: Axial) -> u32 {
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
    pub(super) fn tile_or_insert(&mut self, key: Axial) -> u32 {
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
    pub(super) fn insert(&mut self, v: Axial) -> bool {
        let (key, bit) = Self::slot(v);
        let i = self.tile_or_insert(key);
        let w = &mut self.words[i as usize][bit >> 6];
        let m = 1u64 << (bit & 63);
        let new = *w & m == 0;
        *w |= m;
        new
    }

    /// Inserts `(a, b)` for `b0 <= b <= b1`, all in one tile; returns how many were new.
    pub(super) fn insert_run(&mut self, a: i64, b0: i64, b1: i64) -> usize {
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
    pub(super) fn stadium_rows(
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
    pub(super) fn for_each_in_stadium(
        &self,
        a: i64,
        bs: (i64, i64),
        r: i64,
        mut f: impl FnMut(Axial),
    ) {
        let _ = self.stadium_rows(a, bs, r, |row_a, base_b, mut m| {
            while m != 0 {
                f((row_a, base_b | i64::from(m.trailing_zeros())));
                m &= m - 1;
            }
            ControlFlow::Continue(())
        });
    }

    /// Whether a member lies within hexagonal distance `r` of `c`, stopping at the first.
    pub(super) fn any_in_disc(&self, c: Axial, r: i64) -> bool {
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
    pub(super) fn remove(&mut self, v: Axial) -> bool {
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
    pub(super) fn iter(&self) -> TileIter<'_> {
        TileIter {
            set: self,
            tile: 0,
            word: 0,
            bits: self.words.first().map_or(0, |w| w[0]),
        }
    }
}

/// Iterator over a [`TileSet`]: the set bits of each word in turn.
pub(super) struct TileIter<'a> {
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

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;
    use rustc_hash::FxHashSet;

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
