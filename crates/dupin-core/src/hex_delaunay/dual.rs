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

use super::hierarchy::Hierarchy;
use super::lattice::{Axial, DIRS, add, normalize};
use super::spatial_hash::LatticeMap;
use crate::math::Vec2;
use rustc_hash::FxHashMap;

/// A normalised lattice position packed into 16 bytes: `(a + 2^50 | level << 56, b)`, the
/// coordinates' low bits kept low for the locality-preserving hash.
pub type Key = (i64, i64);

/// Packs a normalised `(level, v)` (level < 64, |a| < 2^50).
#[inline]
pub fn pack(level: u32, v: Axial) -> Key {
    let (l, v) = normalize(level, v);
    ((v.0 + (1 << 50)) | ((l as i64) << 56), v.1)
}

/// The dual triangles and vertex positions of a hexagon mesh.
pub struct DualBuilder<'h> {
    h: &'h Hierarchy,
    moved: &'h FxHashMap<Key, Vec2>,
    /// Vertex index of each lattice key.
    pub index: LatticeMap<Key, u32>,
    /// Vertex positions: lattice positions, or the input point of an occupied hexagon.
    pub positions: Vec<Vec2>,
    /// Triangles, counter-clockwise.
    pub triangles: Vec<[u32; 3]>,
}

impl<'h> DualBuilder<'h> {
    /// Extracts the dual triangulation of the hierarchy's current hexagon mesh; `moved` gives
    /// the new positions of occupied centres. Storage is reserved exactly up front (one vertex
    /// per leaf full hexagon, at most two triangles per vertex), so nothing is reallocated.
    pub fn build(h: &'h Hierarchy, moved: &'h FxHashMap<Key, Vec2>) -> Self {
        let leaves = h.leaf_count();
        let mut index = LatticeMap::default();
        index.reserve(leaves);
        let mut b = DualBuilder {
            h,
            moved,
            index,
            positions: Vec::with_capacity(leaves),
            triangles: Vec::with_capacity(2 * leaves),
        };
        let o = b.vertex(1, (0, 0));
        let corners: [u32; 6] = std::array::from_fn(|i| b.vertex(1, DIRS[i]));
        for i in 0..6 {
            let j = (i + 1) % 6;
            b.emit(1, [(0, 0), DIRS[i], DIRS[j]], [o, corners[i], corners[j]]);
        }
        b
    }

    fn vertex(&mut self, level: u32, v: Axial) -> u32 {
        let key = pack(level, v);
        let n = self.positions.len() as u32;
        let (h, moved, positions) = (self.h, self.moved, &mut self.positions);
        *self.index.entry(key).or_insert_with(|| {
            positions.push(
                moved
                    .get(&key)
                    .copied()
                    .unwrap_or_else(|| h.frame.position(level, v)),
            );
            n
        })
    }

    /// Emits the lattice triangle `t` at level `k` (counter-clockwise) whose corner vertex
    /// indices `ids` are known: only new midpoints are looked up, about one hash look-up per
    /// output triangle.
    fn emit(&mut self, k: u32, t: [Axial; 3], ids: [u32; 3]) {
        let [a, b, c] = t;
        let split = [
            self.h.is_split(k, a),
            self.h.is_split(k, b),
            self.h.is_split(k, c),
        ];
        match split {
            [true, true, true] => {
                let (ab, bc, ca) = (add(a, b), add(b, c), add(c, a));
                let (iab, ibc, ica) = (
                    self.vertex(k + 1, ab),
                    self.vertex(k + 1, bc),
                    self.vertex(k + 1, ca),
                );
                let (a2, b2, c2) = ((2 * a.0, 2 * a.1), (2 * b.0, 2 * b.1), (2 * c.0, 2 * c.1));
                let [ia, ib, ic] = ids;
                self.emit(k + 1, [a2, ab, ca], [ia, iab, ica]);
                self.emit(k + 1, [ab, b2, bc], [iab, ib, ibc]);
                self.emit(k + 1, [ca, bc, c2], [ica, ibc, ic]);
                self.emit(k + 1, [ab, bc, ca], [iab, ibc, ica]);
            }
            [true, true, false] => self.bisect(k, a, b, [ids[0], ids[1], ids[2]]),
            [false, true, true] => self.bisect(k, b, c, [ids[1], ids[2], ids[0]]),
            [true, false, true] => self.bisect(k, c, a, [ids[2], ids[0], ids[1]]),
            _ => self.triangles.push(ids),
        }
    }

    /// Corners `a`, `b` split, the third not (counter-clockwise a, b, c; `ids` in that order):
    /// two right triangles meeting at the joined hexagon `a + b`.
    fn bisect(&mut self, k: u32, a: Axial, b: Axial, ids: [u32; 3]) {
        let m = self.vertex(k + 1, add(a, b));
        let [va, vb, vc] = ids;
        self.triangles.push([va, m, vc]);
        self.triangles.push([m, vb, vc]);
    }
}
