//! Dual mesh extraction (section 4.2).
//!
//! Every full hexagon's centre is joined to its full neighbours' centres, and across a
//! semi-hexagon to the centre of the semi-hexagon's opposite full hexagon; occupied centres are
//! then moved to their input point. On the lattice this dual is a recursive refinement of Ω's six
//! level-1 equilateral triangles: a level-`k` lattice triangle whose three corner hexagons are
//! split becomes its four level-`k+1` children; with exactly two split corners `a`, `b` it
//! becomes two 30-60-90 triangles meeting at the joined hexagon `a+b` (the paper's "half angle
//! at the centre of the un-subdivided hexagon"); otherwise it is a leaf. The balancing rule
//! guarantees nothing finer hides inside a leaf. Cost: O(1) expected per output triangle.
//!
//! Vertex numbering: corner ids are passed down the recursion, so only the midpoint of a
//! lattice edge (a joined hexagon) needs a look-up, and exactly the two triangles on either side
//! of that edge ask for it (conformity, from balancing); one on Ω's boundary is asked for once.
//! The map therefore forgets a midpoint at its second request and never stores boundary ones:
//! it holds only the front of the depth-first traversal, stays small and cache-resident, and
//! the extraction's time per triangle does not grow with the mesh.

use super::hierarchy::{Hierarchy, window_bit};
use super::lattice::{Axial, DIRS, add, normalize, on_boundary};
use super::tile_set::HexSet;
use crate::Vec2;
use rustc_hash::{FxHashMap, FxHashSet};
use std::collections::hash_map::Entry;

/// A normalised lattice position packed into 16 bytes: `(a + 2^50 | level << 56, b)`, the
/// coordinates' low bits kept low for the locality-preserving hash.
pub type Key = (i64, i64);

/// Packs a normalised `(level, v)` (level < 64, |a| < 2^50).
#[inline]
pub fn pack(level: u32, v: Axial) -> Key {
    let (l, v) = normalize(level, v);
    ((v.0 + (1 << 50)) | ((l as i64) << 56), v.1)
}

/// The `(level, v)` of a packed key.
#[inline]
pub fn unpack(key: Key) -> (u32, Axial) {
    (
        (key.0 >> 56) as u32,
        ((key.0 & ((1 << 56) - 1)) - (1 << 50), key.1),
    )
}

/// The dual triangles and vertex positions of a hexagon mesh.
pub struct DualBuilder<'h> {
    h: &'h Hierarchy,
    moved: &'h FxHashMap<Key, Vec2>,
    /// The keys of `moved`, tiled: most vertices are not moved, and a tile read (mostly of
    /// the tile just read) is cheaper than a probe into the large `moved`.
    is_moved: HexSet,
    /// Vertex index of the midpoints requested once so far.
    open: FxHashMap<Key, u32>,
    /// Vertex index of every relocated (occupied) centre.
    pub moved_vertex: FxHashMap<Key, u32>,
    /// Vertex positions: lattice positions, or the input point of an occupied hexagon.
    pub positions: Vec<Vec2>,
    /// Triangles, counter-clockwise.
    pub triangles: Vec<[u32; 3]>,
    /// Keys whose fans are not emitted (the MOVED_CENTER_3 run centres that `extended/fin_vertices.rs`
    /// re-triangulates), their vertices as a bit set, and how many triangles were left out.
    drop: &'h FxHashSet<Key>,
    dropped: Vec<u64>,
    /// Number of triangles left out because they touch a vertex of `drop`.
    pub removed: usize,
}

impl<'h> DualBuilder<'h> {
    /// Extracts the dual triangulation of the hierarchy's current hexagon mesh; `moved` gives
    /// the new positions of occupied centres. Storage is reserved exactly up front (one vertex
    /// per leaf full hexagon, at most two triangles per vertex), so nothing is reallocated.
    /// Triangles with a vertex whose key is in `drop` are left out (their fans are replaced;
    /// leaving them out here saves a pass over all triangles). `extra` vertices (and two
    /// triangles each) are reserved beyond the leaves, for what the caller appends.
    pub fn build(
        h: &'h Hierarchy,
        moved: &'h FxHashMap<Key, Vec2>,
        drop: &'h FxHashSet<Key>,
        extra: usize,
    ) -> Self {
        let leaves = h.leaf_count();
        let mut is_moved = HexSet::default();
        for &key in moved.keys() {
            let (level, v) = unpack(key);
            is_moved.insert(level, v);
        }
        let mut b = DualBuilder {
            h,
            moved,
            is_moved,
            open: FxHashMap::default(),
            // Every moved key is a vertex (sized once: growing would rehash a large map).
            moved_vertex: FxHashMap::with_capacity_and_hasher(moved.len(), Default::default()),
            positions: Vec::with_capacity(leaves + extra),
            triangles: Vec::with_capacity(2 * (leaves + extra)),
            drop,
            dropped: if drop.is_empty() {
                Vec::new()
            } else {
                vec![0; leaves.div_ceil(64)]
            },
            removed: 0,
        };
        let o = b.new_vertex(1, (0, 0));
        let corners: [u32; 6] = std::array::from_fn(|i| b.new_vertex(1, DIRS[i]));
        let split: [bool; 6] = std::array::from_fn(|i| h.is_split(1, DIRS[i]));
        let centre = h.is_split(1, (0, 0));
        for i in 0..6 {
            let j = (i + 1) % 6;
            b.emit(
                1,
                [(0, 0), DIRS[i], DIRS[j]],
                [o, corners[i], corners[j]],
                [centre, split[i], split[j]],
            );
        }
        debug_assert!(
            b.open.is_empty(),
            "a joined hexagon was requested only once"
        );
        b
    }

    fn new_vertex(&mut self, level: u32, v: Axial) -> u32 {
        let n = self.positions.len() as u32;
        let (l, w) = normalize(level, v);
        let moved = if self.is_moved.contains(l, w) {
            let key = pack(level, v);
            self.moved.get(&key).map(|&p| (key, p))
        } else {
            None
        };
        let p = match moved {
            Some((key, p)) => {
                self.moved_vertex.insert(key, n);
                if !self.dropped.is_empty() && self.drop.contains(&key) {
                    self.dropped[n as usize / 64] |= 1 << (n % 64);
                }
                p
            }
            None => self.h.frame.position(level, v),
        };
        self.positions.push(p);
        n
    }

    /// The vertex of the joined hexagon `v` at `level` (a lattice-edge midpoint).
    fn midpoint(&mut self, level: u32, v: Axial) -> u32 {
        if on_boundary(level, v) {
            return self.new_vertex(level, v);
        }
        let key = pack(level, v);
        // One hash per request: the first inserts the id the vertex is about to get, the
        // second removes it.
        let next = self.positions.len() as u32;
        match self.open.entry(key) {
            Entry::Occupied(e) => e.remove(),
            Entry::Vacant(e) => {
                e.insert(next);
                let i = self.new_vertex(level, v);
                debug_assert_eq!(i, next);
                i
            }
        }
    }

    /// Emits the lattice triangle `t` at level `k` (counter-clockwise) whose corner vertex
    /// indices `ids` and split states `split` are known: only new midpoints are looked up,
    /// about one hash look-up per output triangle, and the children's six corners' split
    /// states are one window read.
    fn emit(&mut self, k: u32, t: [Axial; 3], ids: [u32; 3], split: [bool; 3]) {
        let [a, b, c] = t;
        match split {
            [true, true, true] => {
                let (ab, bc, ca) = (add(a, b), add(b, c), add(c, a));
                let (iab, ibc, ica) = (
                    self.midpoint(k + 1, ab),
                    self.midpoint(k + 1, bc),
                    self.midpoint(k + 1, ca),
                );
                let (a2, b2, c2) = ((2 * a.0, 2 * a.1), (2 * b.0, 2 * b.1), (2 * c.0, 2 * c.1));
                // All six lie within two steps of `ab` (a, b, c are mutual neighbours).
                let w = self.h.split_window(k + 1, ab);
                let s = |v: Axial| w & window_bit((v.0 - ab.0, v.1 - ab.1)) != 0;
                let (sa, sb, sc, sab, sbc, sca) = (s(a2), s(b2), s(c2), s(ab), s(bc), s(ca));
                let [ia, ib, ic] = ids;
                self.emit(k + 1, [a2, ab, ca], [ia, iab, ica], [sa, sab, sca]);
                self.emit(k + 1, [ab, b2, bc], [iab, ib, ibc], [sab, sb, sbc]);
                self.emit(k + 1, [ca, bc, c2], [ica, ibc, ic], [sca, sbc, sc]);
                self.emit(k + 1, [ab, bc, ca], [iab, ibc, ica], [sab, sbc, sca]);
            }
            [true, true, false] => self.bisect(k, a, b, [ids[0], ids[1], ids[2]]),
            [false, true, true] => self.bisect(k, b, c, [ids[1], ids[2], ids[0]]),
            [true, false, true] => self.bisect(k, c, a, [ids[2], ids[0], ids[1]]),
            _ => self.push(ids),
        }
    }

    /// Appends a triangle unless it has a vertex in `drop`.
    #[inline]
    fn push(&mut self, t: [u32; 3]) {
        if !self.dropped.is_empty()
            && t.iter()
                .any(|&v| self.dropped[v as usize / 64] >> (v % 64) & 1 != 0)
        {
            self.removed += 1;
            return;
        }
        self.triangles.push(t);
    }

    /// Corners `a`, `b` split, the third not (counter-clockwise a, b, c; `ids` in that order):
    /// two right triangles meeting at the joined hexagon `a + b`.
    fn bisect(&mut self, k: u32, a: Axial, b: Axial, ids: [u32; 3]) {
        let m = self.midpoint(k + 1, add(a, b));
        let [va, vb, vc] = ids;
        self.push([va, m, vc]);
        self.push([m, vb, vc]);
    }
}
