//! Extended refinement (section 5): classification of the full hexagons by their fins and
//! occupancy (5.1), the extra refinement rules (5.2) and the centre relocations (5.4).
//!
//! Input: a [`Refinement`] whose simple rules (section 4.1) have run to the end (without rule
//! 3b). Output: further splits until no extended rule fires, then the relocated centres of the
//! dual mesh, keyed like the dual's vertices. Angles land in [α, 90°], α = 43.8979°.
//!
//! Types and formulas: MOVED_CENTER_1 (Ĉ = 5/6 C + 1/6 C_f0), MOVED_CENTER_2
//! (Ĉ = 3/5 C + 2/5 C_f01), MOVED_CENTER_3 and MOVED_CENTER_4 (runs around a common top, in
//! `fin_vertices.rs`), OCCUPIED_1/2 (point inside / outside the half-sized hexagon),
//! MOVED_CENTER_IN_RING (shifted by half the vector from the occupied centre to the corner
//! nearest its point), FIXED_CENTER_IN_RING and FIXED_CENTER_REGULAR (not moved). Rules of 5.2:
//! SUBDIVIDE, MOVED_CENTER_x in the 1-ring of an OCCUPIED_1 or the 1-/2-ring of an OCCUPIED_2,
//! MOVED_CENTER_x whose fin-adjacent full hexagons are not fixed.
//!
//! Deviations (see docs/hexdelaunay.md): the consecutive-MOVED_CENTER_3 and MOVED_CENTER_4
//! rules are replaced by a local check of every triangle a run of MOVED_CENTER_3 and its moved
//! top make (`Pass::analyse_run`); a run that fails it is split as SUBDIVIDE. No local
//! coarsening into blossoms (split counters, merge, break). Rules added:
//! (a) opposite-facing fin strips: a MOVED_CENTER hexagon is subdivided when an unsplit
//! same-level neighbour has fins none of which is at or next to its own fin directions (two
//! such centres move apart and leave a 35° triangle between them, a case Fig. 10 lacks);
//! (b) ring conflicts between occupied hexagons of one level (two OCCUPIED_2 two steps apart
//! share 1-ring hexagons, moved by the mean shift), resolved by splitting or by a
//! local check of the triangles around the rings (see `Pass::verify`); (c) the 2-ring of an
//! occupied hexagon is made of unsplit full hexagons of its level; (d) on Ω's boundary a centre
//! may only slide along the boundary, Ω's corners and an OCCUPIED_2's moved ring stay off it.
//!
//! Cost: the rules are pure functions of the hierarchy, evaluated per hexagon in O(1) expected
//! hash look-ups. After a wave of splits the next pass evaluates only the hexagons the splits
//! can affect (found from the splits, and the refinement's tiled set of occupied cells), so
//! the passes together cost O(S) for S splits; a full pass over all leaves, O(T) for T
//! triangles, starts and ends the run (a few in all: one more each time it finds something
//! the incremental passes left).

use super::fin_vertices::{FinPatch, Run, run_patch, top_new};
use crate::Vec2;
use crate::hex_delaunay::dual::{Key, pack};
use crate::hex_delaunay::error::HexDelaunayError;
use crate::hex_delaunay::hierarchy::{Cell, Hierarchy, window_bit};
use crate::hex_delaunay::lattice::{Axial, DIRS, add, hex_norm, in_domain, on_boundary};
use crate::hex_delaunay::pslg::near_segment;
use crate::hex_delaunay::simple_refinement::Refinement;
use crate::hex_delaunay::tile_set::HexSet;
use rustc_hash::{FxHashMap, FxHashSet};

const SQRT3: f64 = 1.732_050_807_568_877_2;

/// The shift of a 1-ring hexagon of several OCCUPIED_2 (ours: two OCCUPIED_2 two steps apart
/// are kept when the local check passes): the mean of their shifts, summed in a fixed order
/// (sorted) so that it does not depend on the order of the visits; one shift is itself.
fn mean_shift(shifts: &mut [Vec2]) -> Vec2 {
    if shifts.len() == 1 {
        return shifts[0];
    }
    shifts.sort_unstable_by(|a, b| (a.x, a.y).partial_cmp(&(b.x, b.y)).expect("finite shifts"));
    let sum = shifts.iter().fold(Vec2::zeros(), |s, v| s + v);
    sum / shifts.len() as f64
}

#[cfg(test)]
thread_local! {
    /// Test switch for the shortest-edge counterexample (docs/hexdelaunay.md): from this level
    /// on (0: never), waived ring conflicts whose local check fails are kept, not split.
    pub(in crate::hex_delaunay) static KEEP_FAILED_CHECKS_FROM: std::cell::Cell<u32> =
        const { std::cell::Cell::new(0) };
}

/// Whether a failed local check at `level` is kept (a test switch; never outside tests).
#[inline(always)]
fn keep_failed_check(#[allow(unused_variables)] level: u32) -> bool {
    #[cfg(test)]
    {
        KEEP_FAILED_CHECKS_FROM.with(|w| w.get() != 0 && level >= w.get())
    }
    #[cfg(not(test))]
    {
        false
    }
}

/// Calls `f(level, v)` once for every leaf full hexagon with a fin (an unsplit full hexagon
/// with a split neighbour of its level), found from the split hexagons: balancing makes every
/// neighbour of a split hexagon present, so the unsplit ones are these leaves. Each is reported
/// from its first split neighbour in `DIRS` order. Only these leaves can be marked or moved by
/// a fin (a leaf without fins moves only in a ring or as a run's top), and they are about a
/// tenth of all leaves on the uniform sets.
fn for_each_fin_leaf(h: &Hierarchy, mut f: impl FnMut(u32, Axial)) {
    // Level 0 is the root alone: no neighbours.
    for k in 1..h.depth() {
        for x in h.split_at(k) {
            let split = h.split_neighbours(k, x);
            if split == 0x3f {
                continue;
            }
            // The unsplit neighbours' fins lie within two steps of `x`: one window.
            let w = h.split_window(k, x);
            for (j, d) in DIRS.iter().enumerate() {
                let y = add(x, *d);
                if split & (1 << j) != 0 || !in_domain(k, y) {
                    continue;
                }
                // `x` is `y + DIRS[j + 3]`.
                if window_fins(w, *d).trailing_zeros() as usize == (j + 3) % 6 {
                    f(k, y);
                }
            }
        }
    }
}

/// Bit `j` set when the neighbour in direction `DIRS[j]` is split (a fin lies between).
fn fin_mask(h: &Hierarchy, k: u32, v: Axial) -> u8 {
    h.split_neighbours(k, v)
}

/// For one or two consecutive fins, the index of the first fin direction and the count.
fn consecutive(mask: u8) -> Option<(usize, usize)> {
    match mask.count_ones() {
        1 => Some((mask.trailing_zeros() as usize, 1)),
        2 => (0..6)
            .find(|&j| mask == (1 << j) | (1 << ((j + 1) % 6)))
            .map(|j| (j, 2)),
        _ => None,
    }
}

/// For exactly three consecutive fins, the index of the first fin direction.
fn three_consecutive(mask: u8) -> Option<usize> {
    if mask.count_ones() != 3 {
        return None;
    }
    (0..6).find(|&j| mask == (1 << j) | (1 << ((j + 1) % 6)) | (1 << ((j + 2) % 6)))
}

/// Lattice points at hexagonal distance exactly `r` from `v`.
pub(super) fn ring(v: Axial, r: i64) -> impl Iterator<Item = Axial> {
    (0..6).flat_map(move |j| {
        let d = DIRS[j];
        let e = DIRS[(j + 2) % 6];
        (0..r).map(move |t| (v.0 + r * d.0 + t * e.0, v.1 + r * d.1 + t * e.1))
    })
}

/// The window bits of a hexagon and its six neighbours.
const WINDOW_DISC1: u32 = window_bit((0, 0))
    | window_bit(DIRS[0])
    | window_bit(DIRS[1])
    | window_bit(DIRS[2])
    | window_bit(DIRS[3])
    | window_bit(DIRS[4])
    | window_bit(DIRS[5]);

/// Outward normals of the half-sized hexagon's edges (at 30° + 60° i).
const EDGE_NORMALS: [(f64, f64); 6] = [
    (0.866_025_403_784_438_6, 0.5),
    (0.0, 1.0),
    (-0.866_025_403_784_438_6, 0.5),
    (-0.866_025_403_784_438_6, -0.5),
    (0.0, -1.0),
    (0.866_025_403_784_438_6, -0.5),
];

/// Whether `p` lies in the half-sized hexagon of the hexagon with centre `c`, circumradius `r`.
pub(super) fn in_half_hexagon(p: Vec2, c: Vec2, r: f64) -> bool {
    let q = p - c;
    EDGE_NORMALS
        .iter()
        .all(|&(nx, ny)| q.x * nx + q.y * ny <= 0.25 * SQRT3 * r)
}

/// The neighbours of the leaf `t` at level `k` that have three consecutive fins facing away
/// from `t`, i.e. whose top neighbour (section 5.1) is `t`, as a bit mask over `DIRS`. Such a
/// `t` is no FIXED_CENTER (it is a MOVED_CENTER_4).
pub(super) fn tops_mask(h: &Hierarchy, k: u32, t: Axial) -> u8 {
    tops_in_window(h, k, t, h.split_window(k, t))
}

/// [`tops_mask`] from the split window `w` around `t`: the middle fin of `y = t + d_i` is
/// `t + 2 d_i`, and `y`'s fins all lie in the window.
fn tops_in_window(h: &Hierarchy, k: u32, t: Axial, w: u32) -> u8 {
    let mut m = 0;
    for (i, d) in DIRS.iter().enumerate() {
        if w & window_bit(add(*d, *d)) == 0 {
            continue;
        }
        let y = add(t, *d);
        if !h.is_present(k, y) || w & window_bit(*d) != 0 {
            continue;
        }
        // Fins j..j+2 with the middle one j+1 = i, i.e. j = i - 1.
        if three_consecutive(window_fins(w, *d)) == Some((i + 5) % 6) {
            m |= 1 << i;
        }
    }
    m
}

/// The fin mask of `v + d` (`d` zero or a neighbour direction) from the split window `w`
/// around `v`.
fn window_fins(w: u32, d: Axial) -> u8 {
    DIRS.iter().enumerate().fold(0u8, |m, (j, e)| {
        m | (u8::from(w & window_bit(add(d, *e)) != 0) << j)
    })
}

/// The first position and length of the single run of set bits of a top's mask (cyclic),
/// `(0, 6)` for a blossom; None for several runs or five.
fn run_shape(mask: u8) -> Option<(usize, usize)> {
    if mask == 0x3f {
        return Some((0, 6));
    }
    let s = (0..6).find(|&i| mask & (1 << i) != 0 && mask & (1 << ((i + 5) % 6)) == 0)?;
    let n = (0..6)
        .take_while(|&i| mask & (1 << ((s + i) % 6)) != 0)
        .count();
    (n == mask.count_ones() as usize && n != 5).then_some((s, n))
}

/// Where the top `t` at level `k` goes if its run is accepted (None if it cannot be).
fn top_formula(h: &Hierarchy, k: u32, t: Axial) -> Option<Vec2> {
    let (s, n) = run_shape(tops_mask(h, k, t))?;
    let f = &h.frame;
    let c: Vec<Vec2> = (0..n)
        .map(|i| f.position(k, add(t, DIRS[(s + i) % 6])))
        .collect();
    Some(top_new(f.position(k, t), &c))
}

/// A top's verdict on its MOVED_CENTER_3 run.
#[derive(Debug, Clone, Copy, PartialEq)]
enum RunVerdict {
    /// Relocated: the patch's index in `Pass::patches`.
    Accepted(usize),
    /// Its MOVED_CENTER_3 hexagons are split (as SUBDIVIDE).
    Rejected,
    /// A hexagon it depends on is split this pass: decided on the next one.
    Pending,
}

/// Whether the triangle `p` is counter-clockwise with angles in [α, 90°] (local tolerances as
/// in `Pass::verify`) and edges at least `min_edge`.
fn acute_enough(p: &[Vec2; 3], min_edge: f64) -> bool {
    let cos_lo = (ANGLE_MIN - 1e-9).to_radians().cos();
    (0..3).all(|j| {
        let (u, w) = (p[(j + 1) % 3] - p[j], p[(j + 2) % 3] - p[j]);
        let c = u.dot(&w) / (u.norm() * w.norm());
        u.perp(&w) > 0.0 && c >= -1e-12 && c <= cos_lo && u.norm() >= min_edge
    })
}

/// What section 5.1 (and our ring rules) make of an occupied hexagon.
#[derive(Debug, Clone, Copy)]
enum Occupied {
    /// Split (ring conflict, boundary ring or a finer 2-ring hexagon).
    Split,
    /// Its 2-ring has coarser cells, made present this pass (they are marked already).
    Rough,
    /// OCCUPIED_1 or OCCUPIED_2 with its rings: `shift` moves its 1-ring (zero for an
    /// OCCUPIED_1); `verify` is the largest distance to a point whose ring conflict was waived
    /// (0 if none), whose triangles around the 1-ring must be checked.
    Rings {
        occ2: bool,
        shift: Vec2,
        verify: f64,
    },
}

/// How a leaf full hexagon's centre ends up (section 5.4), or that a rule splits it.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Leaf {
    Split,
    Fixed,
    Moved(Vec2),
    /// A MOVED_CENTER_3 of an accepted run: its fan is replaced (`fin_vertices.rs`).
    Fins,
}

/// The ring roles of a pass's analysed occupied hexagons.
#[derive(Default)]
struct Rings {
    /// The hexagons in the 1-ring of an occupied hexagon or the 2-ring of an OCCUPIED_2 (and
    /// the occupied ones), tiled: most queries are for hexagons in no ring.
    member: HexSet,
    /// The shift of each hexagon in the moved 1-ring of an OCCUPIED_2 (the mean shift where
    /// two OCCUPIED_2 two steps apart share 1-ring hexagons).
    moved: FxHashMap<(u32, Axial), Vec2>,
}

/// Hexagons as (level, centre).
type Hexes = Vec<(u32, Axial)>;

/// The hexagons a pass marks for splitting and those it makes present, sorted.
type Marks = (Hexes, Hexes);

/// One classification pass: the rules as pure functions of the current hierarchy, evaluated
/// only where asked, with the occupied hexagons' verdicts memoised for the pass. A rule fires
/// the same way whichever subset of hexagons a pass visits, so an incremental pass marks only
/// what a full pass would mark too.
struct Pass<'a> {
    r: &'a Refinement,
    /// The PSLG's segments (point index pairs); runs stay away from them (section 7.2).
    segments: &'a [[u32; 2]],
    occupied: FxHashMap<(u32, Axial), Occupied>,
    /// Once the pass's occupied hexagons are analysed: the ring hexagons, with the shift of a
    /// moved 1-ring (so a leaf asks one tile instead of its 18 neighbours).
    rings: Option<Rings>,
    split: FxHashSet<(u32, Axial)>,
    present: FxHashSet<(u32, Axial)>,
    /// The verdicts on MOVED_CENTER_3 runs, by top, and the accepted runs' patches.
    runs: FxHashMap<(u32, Axial), RunVerdict>,
    /// Leaf classes once the rings are frozen: a run's analysis asks for its top's other
    /// neighbours, which the pass visits as leaves too.
    leaves: FxHashMap<(u32, Axial), Leaf>,
    patches: Vec<FinPatch>,
}

impl<'a> Pass<'a> {
    fn new(r: &'a Refinement, segments: &'a [[u32; 2]]) -> Self {
        Pass {
            r,
            segments,
            occupied: FxHashMap::default(),
            rings: None,
            split: FxHashSet::default(),
            present: FxHashSet::default(),
            runs: FxHashMap::default(),
            leaves: FxHashMap::default(),
            patches: Vec::new(),
        }
    }

    /// The verdict on the occupied hexagon `x` at level `k` (None if unoccupied); marks its
    /// splits and presences the first time it is asked.
    fn occupied(&mut self, k: u32, x: Axial) -> Option<Occupied> {
        if let Some(&o) = self.occupied.get(&(k, x)) {
            return Some(o);
        }
        let p = self.r.point_in(k, x)?;
        let o = self.analyse(k, x, p);
        self.occupied.insert((k, x), o);
        Some(o)
    }

    fn analyse(&mut self, k: u32, x: Axial, p: Vec2) -> Occupied {
        let h = &self.r.hierarchy;
        let f = &h.frame;
        let c = f.position(k, x);
        let rad = f.radius(k);
        let occ2 = !in_half_hexagon(p, c, rad);
        // Ring conflicts between occupied hexagons of one level (section 5.1's rings must not
        // overlap with different roles). Two steps apart (a shared 1-ring hexagon: moved by
        // the mean of both shifts if both are OCCUPIED_2, else a fixed ring hexagon of one is
        // moved by the other), or three steps apart with both OCCUPIED_2 (a moved 1-ring
        // hexagon lies in the other's fixed 2-ring): ours, kept when the triangles around the
        // 1-ring still meet the bounds (checked in `verify`), else split. Splitting every such
        // pair would put the points in cells too small for section 6.3's edge bound (two
        // OCCUPIED_2 two steps apart were split unconditionally before: 3% more triangles on
        // the 100-point set). Four steps apart the rings only share fixed 2-ring hexagons (the
        // paper's Fig. 7).
        let mut verify: f64 = 0.0;
        // The occupied hexagons two or three steps away, from one read of the occupied tiles
        // (the verdict does not depend on their order).
        let mut near = [(0i64, (0i64, 0i64)); 37];
        let mut count = 0;
        self.r
            .occupied_full()
            .for_each_in_stadium(k, x.0, (x.1, x.1), 3, |z| {
                let dist = hex_norm((z.0 - x.0, z.1 - x.1));
                if dist >= 2 {
                    near[count] = (dist, z);
                    count += 1;
                }
            });
        for &(dist, z) in &near[..count] {
            let q = self
                .r
                .point_in(k, z)
                .expect("an occupied full cell has a point");
            let other = !in_half_hexagon(q, f.position(k, z), rad);
            match (dist, occ2, other) {
                (2, _, _) | (3, true, true) => {
                    verify = verify.max((p - q).norm());
                }
                _ => {}
            }
        }
        // Ours: an OCCUPIED_2's moved 1-ring must not touch Ω's boundary (tiling).
        if occ2 && ring(x, 1).any(|z| on_boundary(k, z)) {
            self.split.insert((k, x));
            return Occupied::Split;
        }
        // Ours: the 2-ring must be unsplit full hexagons of this level (rules 4 and 5 one ring
        // further out): a finer one splits the occupied hexagon, a coarser one is made present.
        let mut rough = None;
        let win = h.split_window(k, x);
        for (z, d) in ring(x, 2).zip(ring((0, 0), 2)) {
            if !in_domain(k, z) {
                continue;
            }
            // A split hexagon is present.
            if win & window_bit(d) != 0 {
                self.split.insert((k, x));
                rough = Some(Occupied::Split);
            } else if !h.is_present(k, z) {
                self.present.insert((k, z));
                rough.get_or_insert(Occupied::Rough);
            }
        }
        if let Some(o) = rough {
            return o;
        }
        let shift = if occ2 {
            // Corner nearest to p: corners at 60° i.
            let q = p - c;
            let a = q.y.atan2(q.x);
            let i = (a / std::f64::consts::FRAC_PI_3).round() as i64;
            let t = std::f64::consts::FRAC_PI_3 * i as f64;
            Vec2::new(t.cos(), t.sin()) * (0.5 * rad)
        } else {
            Vec2::zeros()
        };
        Occupied::Rings {
            occ2,
            shift,
            verify,
        }
    }

    /// The shift of `v` at level `k` if it lies in the moved 1-ring of an OCCUPIED_2 (the
    /// mean shift if it lies in several, see [`mean_shift`]).
    fn ring1_moved(&mut self, k: u32, v: Axial) -> Option<Vec2> {
        if let Some(rings) = &self.rings {
            if !rings.member.contains(k, v) {
                return None;
            }
            return rings.moved.get(&(k, v)).copied();
        }
        let mut shifts = [Vec2::zeros(); 6];
        let mut n = 0;
        for z in ring(v, 1) {
            // Most neighbours hold no point: the tiled set says so without a probe.
            if !self.r.occupied_full().contains(k, z) {
                continue;
            }
            if let Some(Occupied::Rings {
                occ2: true, shift, ..
            }) = self.occupied(k, z)
            {
                shifts[n] = shift;
                n += 1;
            }
        }
        (n > 0).then(|| mean_shift(&mut shifts[..n]))
    }

    /// Whether `v` at level `k` is occupied or in the 1-ring of an occupied hexagon or the
    /// 2-ring of an OCCUPIED_2.
    fn in_some_ring(&mut self, k: u32, v: Axial) -> bool {
        if self.r.point_in(k, v).is_some() {
            return true;
        }
        if let Some(rings) = &self.rings {
            return rings.member.contains(k, v);
        }
        for dist in 1..=2 {
            for z in ring(v, dist) {
                if let Some(Occupied::Rings { occ2, .. }) = self.occupied(k, z)
                    && (dist == 1 || occ2)
                {
                    return true;
                }
            }
        }
        false
    }

    /// FIXED_CENTER_x: no fins, not occupied, not moved in a ring.
    fn fixed(&mut self, k: u32, v: Axial) -> bool {
        let h = &self.r.hierarchy;
        if !h.is_present(k, v) {
            return false;
        }
        // Itself and its neighbours unsplit (no fins), then the rest in the same order.
        let w = h.split_window(k, v);
        w & WINDOW_DISC1 == 0
            && self.r.point_in(k, v).is_none()
            && self.ring1_moved(k, v).is_none()
            && tops_in_window(h, k, v, w) == 0
    }

    /// Whether an occupied full hexagon of level `k` lies within `r` steps of `y` (one read
    /// of the occupied tiles).
    fn occupied_within(&self, k: u32, y: Axial, r: i64) -> bool {
        let mut any = false;
        self.r
            .occupied_full()
            .for_each_in_stadium(k, y.0, (y.1, y.1), r, |_| any = true);
        any
    }

    /// The verdict on the MOVED_CENTER_3 run around the top `t` at level `k` (memoised).
    fn run(&mut self, k: u32, t: Axial) -> RunVerdict {
        if let Some(&v) = self.runs.get(&(k, t)) {
            return v;
        }
        let v = self.analyse_run(k, t);
        self.runs.insert((k, t), v);
        v
    }

    /// Section 5.4 for the MOVED_CENTER_3 hexagons around the top `t` (see `fin_vertices.rs`
    /// for the positions and triangles). The paper's conditions are checked (fin-side hexagons
    /// fixed, one consecutive run per top, no ring, no boundary), with ours: no occupied
    /// hexagon within three steps of the top, no other top or three-fin hexagon next to it.
    /// Because the paper shows the bounds only by figures, every triangle of the patch and
    /// around the moved top (with the neighbours' own relocations) must also have its angles
    /// in [α, 90°] and its edges at least Fig. 8's √7/2·r of the fin level (so section 6.3's
    /// argument is unchanged); else the run's hexagons are split, as SUBDIVIDE ones.
    fn analyse_run(&mut self, k: u32, t: Axial) -> RunVerdict {
        use RunVerdict::*;
        let h = &self.r.hierarchy;
        let f = &h.frame;
        let mask = tops_mask(h, k, t);
        if mask == 0
            || !h.is_present(k, t)
            || h.is_split(k, t)
            || fin_mask(h, k, t) != 0
            || on_boundary(k, t)
            || DIRS.iter().any(|&d| !h.is_present(k, add(t, d)))
            || self.in_some_ring(k, t)
            || near_segment(
                &self.r.points,
                self.segments,
                f.position(k, t),
                3.0 * f.radius(k),
            )
        {
            return Rejected;
        }
        // Several runs (the paper's MOVED_CENTER_4 rule) or five are split.
        let Some((start, n)) = run_shape(mask) else {
            return Rejected;
        };
        let dir = |e: usize| DIRS[e % 6];
        let mut centres = Vec::with_capacity(n);
        let mut fine = Vec::with_capacity(n);
        for i in 0..n {
            let e = start + i;
            let y = add(t, dir(e));
            // No occupied hexagon within two steps: the rings' checks (`verify`) read the
            // dual there as the plain one. No segment within three radii (the paper's 7.2: no
            // MOVED_CENTER hexagon at or next to a met one; measured: a run's fin vertices
            // next to a segment broke its insertion on the IMR letters).
            if on_boundary(k, y)
                || self.occupied_within(k, y, 2)
                || near_segment(
                    &self.r.points,
                    self.segments,
                    f.position(k, y),
                    3.0 * f.radius(k),
                )
            {
                return Rejected;
            }
            let c2 = (2 * y.0, 2 * y.1);
            let zs = [
                add(c2, add(dir(e + 5), dir(e + 5))),
                add(c2, add(dir(e + 5), dir(e))),
                add(c2, add(dir(e), dir(e))),
                add(c2, add(dir(e), dir(e + 1))),
                add(c2, add(dir(e + 1), dir(e + 1))),
            ];
            if !zs.iter().all(|&z| self.fixed(k + 1, z)) {
                return Rejected;
            }
            centres.push((f.position(k, y), pack(k, y)));
            fine.push(zs.map(|z| (f.position(k + 1, z), pack(k + 1, z))));
        }
        // The other neighbours of the top, from the right end round to the left end.
        let mut ring = Vec::new();
        if n < 6 {
            for i in n..6 {
                let x = add(t, dir(start + i));
                let h = &self.r.hierarchy;
                let xm = fin_mask(h, k, x);
                if three_consecutive(xm).is_some() {
                    return Rejected;
                }
                let p = if xm == 0 && tops_mask(h, k, x) != 0 && !self.in_some_ring(k, x) {
                    // Another top: at the fixed point its run is accepted too (else its
                    // hexagons are split), so it is taken where its run puts it.
                    match top_formula(h, k, x) {
                        Some(p) => p,
                        None => return Pending,
                    }
                } else {
                    match self.frozen_leaf(k, x) {
                        Leaf::Moved(p) => p,
                        Leaf::Fixed => f.position(k, x),
                        Leaf::Split => return Pending,
                        Leaf::Fins => return Rejected,
                    }
                };
                ring.push((p, pack(k, x)));
            }
        }
        let ends = (n < 6).then(|| [ring[ring.len() - 1], ring[0]]);
        let others = if n < 6 {
            ring[1..ring.len() - 1].iter().map(|x| x.0).collect()
        } else {
            Vec::new()
        };
        let run = Run {
            top: (f.position(k, t), pack(k, t)),
            centres,
            fine,
            ends,
            others,
        };
        let Some(patch) = run_patch(&run) else {
            return Rejected;
        };
        let min_edge = 0.5 * 7f64.sqrt() * f.radius(k + 1) * (1.0 - 1e-9);
        let ok = patch
            .triangles
            .iter()
            .map(|tri| tri.map(|v| patch.position(v)))
            .chain(patch.around_top.iter().copied())
            .all(|p| acute_enough(&p, min_edge));
        if !ok {
            return Rejected;
        }
        // The moved top's triangles were only checked: not kept (memory at the dual's peak).
        let mut patch = patch;
        patch.around_top = Vec::new();
        self.patches.push(patch);
        Accepted(self.patches.len() - 1)
    }

    /// [`leaf`](Self::leaf), memoised while the rings are frozen (with exact ring roles, in
    /// `verify`, the class may differ, so it is computed anew there).
    fn frozen_leaf(&mut self, k: u32, v: Axial) -> Leaf {
        if self.rings.is_none() {
            return self.leaf(k, v);
        }
        if let Some(&l) = self.leaves.get(&(k, v)) {
            return l;
        }
        let l = self.leaf(k, v);
        self.leaves.insert((k, v), l);
        l
    }

    /// Classifies the leaf full hexagon `v` at level `k` (5.1, 5.2, 5.4).
    fn leaf(&mut self, k: u32, v: Axial) -> Leaf {
        let h = &self.r.hierarchy;
        let f = &h.frame;
        let mask = fin_mask(h, k, v);
        if mask == 0 {
            return match self.ring1_moved(k, v) {
                Some(s) => Leaf::Moved(f.position(k, v) + s),
                // MOVED_CENTER_4 (5.4): moved with its run of MOVED_CENTER_3.
                None if tops_mask(h, k, v) != 0 => match self.run(k, v) {
                    RunVerdict::Accepted(i) => Leaf::Moved(self.patches[i].top_position()),
                    _ => Leaf::Fixed,
                },
                None => Leaf::Fixed,
            };
        }
        let Some((j, n)) = consecutive(mask) else {
            if let Some(j) = three_consecutive(mask)
                && !self.in_some_ring(k, v)
            {
                // MOVED_CENTER_3: relocated with its run around its top neighbour.
                return match self.run(k, add(v, DIRS[(j + 4) % 6])) {
                    RunVerdict::Accepted(_) => Leaf::Fins,
                    RunVerdict::Rejected => Leaf::Split,
                    RunVerdict::Pending => Leaf::Fixed,
                };
            }
            return Leaf::Split; // SUBDIVIDE, or MOVED_CENTER_3 in a ring.
        };
        // A boundary centre may only slide along Ω's edge: one fin, towards a boundary
        // neighbour. Ω's corners stay put (the triangles must tile Ω).
        let corner = v.0 == 0 || v.1 == 0 || v.0 + v.1 == 0;
        if on_boundary(k, v) && (corner || !(n == 1 && on_boundary(k, add(v, DIRS[j])))) {
            return Leaf::Split;
        }
        // The checks below are independent; the cheapest run first.
        if self.in_some_ring(k, v) {
            return Leaf::Split;
        }
        let c2 = (2 * v.0, 2 * v.1);
        let a = add(c2, add(DIRS[j], DIRS[j])); // centre of the fin's far full hexagon
        let (target, w) = if n == 1 {
            if !self.fixed(k + 1, a) {
                return Leaf::Split;
            }
            (f.position(k + 1, a), 1.0 / 6.0)
        } else {
            let j1 = (j + 1) % 6;
            let b = add(c2, add(DIRS[j1], DIRS[j1]));
            let ab = add(c2, add(DIRS[j], DIRS[j1]));
            if !self.fixed(k + 1, a) || !self.fixed(k + 1, b) || !self.fixed(k + 1, ab) {
                return Leaf::Split;
            }
            (f.position(k + 1, ab), 0.4)
        };
        // Ours: opposite-facing fin strips. The neighbours' fins come from one read of the
        // split states around v.
        let adjacent_fins =
            mask | (mask << 1) | (mask >> 1) | ((mask & 1) << 5) | ((mask >> 5) & 1);
        let win = h.split_window(k, v);
        for (i, d) in DIRS.iter().enumerate() {
            let y = add(v, *d);
            if mask & (1 << i) != 0 || !h.is_present(k, y) {
                continue;
            }
            // The fins of y (its neighbours lie in the window; v itself is unsplit).
            let my = window_fins(win, *d);
            if my != 0 && my & adjacent_fins == 0 {
                return Leaf::Split;
            }
        }
        let c = f.position(k, v);
        Leaf::Moved(c + (target - c) * w)
    }

    /// Visits the leaf `v` at level `k` (one with fins: no rule splits the others): marks it
    /// when a rule splits it.
    fn visit(&mut self, k: u32, v: Axial) -> Leaf {
        let l = self.frozen_leaf(k, v);
        if l == Leaf::Split {
            self.split.insert((k, v));
        }
        l
    }

    /// Our waived ring conflicts: every triangle around the 1-ring of the occupied hexagon `x`
    /// (all lattice triangles of its level, by the 2-ring rule) must keep its angles in
    /// [α, 90°] and its edges at least section 6.3's d·√7/(12√3) for the pair's distance d,
    /// else `x` is split.
    fn verify(&mut self, k: u32, x: Axial, dist: f64) {
        if self.split.contains(&(k, x)) {
            return;
        }
        // Exact relocations: the ring roles asked one by one, not from a partial ring map.
        let rings = self.rings.take();
        // The disc's positions in a 5×5 array by offset from `x`.
        let slot = |v: Axial| ((v.0 - x.0 + 2) * 5 + v.1 - x.1 + 2) as usize;
        let mut pos = [Vec2::zeros(); 25];
        for z in disc(x, 2) {
            let p = match self.r.point_in(k, z) {
                Some(p) => p,
                None => match self.leaf(k, z) {
                    Leaf::Moved(p) => p,
                    _ => self.r.hierarchy.frame.position(k, z),
                },
            };
            pos[slot(z)] = p;
        }
        self.rings = rings;
        let cos_lo = (ANGLE_MIN - 1e-9).to_radians().cos();
        let min_edge = dist * 7f64.sqrt() / (12.0 * SQRT3) * (1.0 + 1e-9);
        let ok = ring(x, 1).all(|y| {
            (0..6).all(|i| {
                let p = [y, add(y, DIRS[i]), add(y, DIRS[(i + 1) % 6])].map(|v| pos[slot(v)]);
                (0..3).all(|j| {
                    let (u, w) = (p[(j + 1) % 3] - p[j], p[(j + 2) % 3] - p[j]);
                    let c = u.dot(&w) / (u.norm() * w.norm());
                    u.perp(&w) > 0.0 && c >= -1e-12 && c <= cos_lo && u.norm() >= min_edge
                })
            })
        });
        if !ok && !keep_failed_check(k) {
            self.split.insert((k, x));
        }
    }

    /// Runs the occupied hexagon's own rules (marks, and the check of a waived conflict).
    fn visit_occupied(&mut self, k: u32, x: Axial) {
        if let Some(Occupied::Rings { verify, .. }) = self.occupied(k, x)
            && verify > 0.0
        {
            self.verify(k, x, verify);
        }
    }

    /// From now on, ring roles come from the occupied hexagons analysed so far (all of them in
    /// a full pass; in an incremental pass those near the changes, so a role may be missed:
    /// that only keeps a leaf from being marked, which a later pass catches).
    fn freeze_rings(&mut self) {
        let mut rings = Rings::default();
        let mut shared = Vec::new();
        let mut seen = FxHashSet::default();
        for (&(k, x), o) in &self.occupied {
            if let Occupied::Rings { occ2, shift, .. } = *o {
                // `x` itself is occupied: in a ring for `in_some_ring` anyway, and in no moved
                // 1-ring (occupied hexagons are never adjacent).
                rings.member.insert_disc(k, x, if occ2 { 2 } else { 1 });
                if occ2 {
                    for z in ring(x, 1) {
                        if let Some(&first) = rings.moved.get(&(k, z)) {
                            if seen.insert((k, z)) {
                                shared.push(((k, z), first));
                            }
                            shared.push(((k, z), shift));
                        } else {
                            rings.moved.insert((k, z), shift);
                        }
                    }
                }
            }
        }
        // 1-ring hexagons of several OCCUPIED_2 (a conflict kept under the local check): the
        // mean of their shifts, whatever the order the occupied hexagons were visited in.
        shared.sort_by_key(|e| e.0);
        for group in shared.chunk_by_mut(|a, b| a.0 == b.0) {
            let key = group[0].0;
            let mut shifts: Vec<Vec2> = group.iter().map(|e| e.1).collect();
            rings.moved.insert(key, mean_shift(&mut shifts));
        }
        self.rings = Some(rings);
    }

    /// The marks, sorted (deterministic order of the splits).
    fn marks(self) -> Marks {
        (sorted_hexes(self.split), sorted_hexes(self.present))
    }
}

/// A full pass: every occupied hexagon and every leaf with fins (no rule marks a leaf without
/// fins). Returns the marks and the relocations (meaningful when nothing is marked).
fn full_pass(r: &Refinement, segments: &[[u32; 2]]) -> (Marks, Relocation) {
    let mut pass = Pass::new(r, segments);
    // Every occupied hexagon is analysed: one map of known size instead of repeated growth.
    pass.occupied.reserve(r.points.len());
    for c in &r.cell_of {
        if let Cell::Full(k, x) = *c {
            pass.visit_occupied(k, x);
        }
    }
    pass.freeze_rings();
    let mut fin_moved = Vec::new();
    for_each_fin_leaf(&r.hierarchy, |k, v| {
        if let Leaf::Moved(p) = pass.visit(k, v) {
            fin_moved.push((pack(k, v), p));
        }
    });
    // The accepted runs, in the order of their tops (deterministic vertex numbering).
    let mut accepted: Vec<((u32, Axial), usize)> = pass
        .runs
        .iter()
        .filter_map(|(&t, v)| match v {
            RunVerdict::Accepted(i) => Some((t, *i)),
            _ => None,
        })
        .collect();
    accepted.sort_unstable();
    let ring_moved = &pass.rings.as_ref().expect("frozen rings").moved;
    // Sized once (with room for the points the dual adds): growing a map of this size
    // rehashes it into fresh memory several times.
    let n = fin_moved.len()
        + ring_moved.len()
        + accepted
            .iter()
            .map(|&(_, i)| pass.patches[i].moved.len() + pass.patches[i].uses.len())
            .sum::<usize>()
        + r.points.len();
    let mut moved: FxHashMap<Key, Vec2> =
        FxHashMap::with_capacity_and_hasher(n, Default::default());
    moved.extend(fin_moved);
    // The leaves without fins that move: the moved 1-rings of the OCCUPIED_2 (with nothing
    // marked these are leaves without fins: a ring leaf with fins is split) and the runs' tops
    // (set from the patches below).
    let f = &r.hierarchy.frame;
    for (&(k, z), s) in ring_moved {
        moved.insert(pack(k, z), f.position(k, z) + s);
    }
    let mut relocation = Relocation {
        moved,
        patches: Vec::new(),
        tops: Vec::new(),
    };
    relocation.add_patches(
        accepted
            .into_iter()
            .map(|(t, i)| (t, std::mem::take(&mut pass.patches[i])))
            .collect(),
    );
    (pass.marks(), relocation)
}

/// The relocations of section 5.4 for the dual of a finished extended refinement.
#[derive(Debug, Clone, Default)]
pub struct Relocation {
    /// New positions of moved centres (and the positions of the hexagons around a
    /// MOVED_CENTER_3, so that the dual builder reports their vertices).
    pub moved: FxHashMap<Key, Vec2>,
    /// The MOVED_CENTER_3 hexagons, whose centre vertex the fins' vertices replace.
    pub patches: Vec<FinPatch>,
    /// The top of each patch's run, sorted (the patches' order, which numbers the vertices).
    pub tops: Vec<(u32, Axial)>,
}

impl Relocation {
    /// Adds accepted runs' patches (their vertices' positions, and the patches at their tops'
    /// places in the order): one merge of two sorted lists, O(patches), not an insertion each.
    /// The dual builder reports the vertex of every key in `moved`; a patch's `uses` are
    /// dropped once there, so they are not kept twice through the dual's peak.
    fn add_patches(&mut self, mut new: Vec<((u32, Axial), FinPatch)>) {
        new.sort_by_key(|e| e.0);
        for (_, p) in &mut new {
            for &(key, q) in &p.moved {
                self.moved.insert(key, q);
            }
            for &(key, q) in &p.uses {
                self.moved.entry(key).or_insert(q);
            }
            p.uses = Vec::new();
        }
        let n = self.tops.len() + new.len();
        let mut tops = Vec::with_capacity(n);
        let mut patches = Vec::with_capacity(n);
        let mut old = std::mem::take(&mut self.tops)
            .into_iter()
            .zip(std::mem::take(&mut self.patches))
            .peekable();
        for (top, p) in new {
            while let Some(e) = old.next_if(|e| e.0 < top) {
                tops.push(e.0);
                patches.push(e.1);
            }
            tops.push(top);
            patches.push(p);
        }
        for (top, p) in old {
            tops.push(top);
            patches.push(p);
        }
        self.tops = tops;
        self.patches = patches;
    }
}

/// What an incremental pass visits after the splits `changes`.
///
/// Leaves: only a leaf with fins can be marked, so a split of `(k, x)` matters to the leaves
/// of level `k` within two steps (their fins, or a neighbour's fins for the opposite-strip
/// rule), the new leaves of level `k + 1` and those near them (three steps from `2x`: their
/// neighbours' presence and the rings of points that moved in; with two, the final full pass
/// still found splits), and the leaves of level `k - 1` whose fin-side hexagons include `x` or
/// its neighbours (two steps from `x / 2`).
///
/// Occupied hexagons: their rules read the occupancy within three steps, the 2-ring and, for
/// a waived ring conflict, the relocations of the 2-ring (fins one step further, fin-side
/// hexagons one level finer); the leaves read their rings. Those within eight steps at levels
/// `k` and `k + 1` (from `2x`) and six at level `k - 1` are re-run and give the ring roles.
fn affected(r: &Refinement, changes: &[(u32, Axial)]) -> (HexSet, HexSet) {
    let mut leaves = HexSet::default();
    let mut occupied = HexSet::default();
    let occ = r.occupied_full();
    // Changes in one lattice row with consecutive `b` are taken together: the union of their
    // discs is one interval per row (a "stadium"), so overlapping discs cost one insert.
    let mut sorted = sorted_hexes(changes.iter().copied());
    sorted.dedup();
    let mut i = 0;
    while i < sorted.len() {
        let (k, (a, lo)) = sorted[i];
        let mut hi = lo;
        i += 1;
        while i < sorted.len() && sorted[i] == (k, (a, hi + 1)) {
            hi += 1;
            i += 1;
        }
        leaves.insert_stadium(k, a, (lo, hi), 2);
        leaves.insert_stadium(k + 1, 2 * a, (2 * lo, 2 * hi), 3);
        if k >= 1 {
            let half = (lo.div_euclid(2), hi.div_euclid(2));
            leaves.insert_stadium(k - 1, a.div_euclid(2), half, 2);
            occ.for_each_in_stadium(k - 1, a.div_euclid(2), half, 6, |o| {
                occupied.insert(k - 1, o);
            });
        }
        occ.for_each_in_stadium(k, a, (lo, hi), 8, |o| {
            occupied.insert(k, o);
        });
        occ.for_each_in_stadium(k + 1, 2 * a, (2 * lo, 2 * hi), 8, |o| {
            occupied.insert(k + 1, o);
        });
    }
    // The order of the visits does not matter (the rules read the state, not the marks).
    (leaves, occupied)
}

/// An incremental pass over the given leaves and occupied hexagons.
fn region_pass(r: &Refinement, segments: &[[u32; 2]], leaves: &HexSet, occupied: &HexSet) -> Marks {
    let h = &r.hierarchy;
    let mut pass = Pass::new(r, segments);
    for (k, x) in occupied.iter() {
        pass.visit_occupied(k, x);
    }
    pass.freeze_rings();
    // Only a leaf with fins can be marked; the fins are the cheapest test.
    h.for_each_with_fins(leaves, |k, v| {
        if h.is_present(k, v) {
            pass.visit(k, v);
        }
    });
    pass.marks()
}

/// After the coarsening into blossoms (`coarsening.rs`) merged `merged`, forming blossoms
/// around `tops`, right after a full pass that found nothing: verifies in an incremental pass
/// over what the merges can affect (the same neighbourhoods as for splits: the rules read the
/// split states there) that no rule fires and every blossom's run is accepted, and adds the
/// blossoms' patches to that full pass's relocations, which stay valid elsewhere (the blossoms'
/// 4-rings were FIXED_CENTER_REGULAR and stay fixed, nothing else changes class). Returns
/// whether that held; if not (or without cached relocations), the next pass is a full one.
/// Saves the second full pass over all leaves (O(T)): the check is O(blossoms).
#[inline(never)] // called once per run; kept out of the stepper for profiles
pub fn after_coarsening(
    r: &Refinement,
    state: &mut ExtendedState,
    segments: &[[u32; 2]],
    splits_before: usize,
    merged: &[(u32, Axial)],
    tops: &[(u32, Axial)],
) -> bool {
    state.changes = None;
    let cached = state.relocation.take();
    let Some((splits, points, mut relocation)) = cached else {
        return false;
    };
    if splits != splits_before || points != r.points.len() {
        return false;
    }
    let (leaves, occupied) = affected(r, merged);
    let h = &r.hierarchy;
    let mut pass = Pass::new(r, segments);
    for (k, x) in occupied.iter() {
        pass.visit_occupied(k, x);
    }
    pass.freeze_rings();
    h.for_each_with_fins(&leaves, |k, v| {
        if h.is_present(k, v) {
            pass.visit(k, v);
        }
    });
    let mut accepted = Vec::with_capacity(tops.len());
    for &(k, t) in tops {
        match pass.run(k, t) {
            RunVerdict::Accepted(i) => accepted.push(((k, t), i)),
            _ => return false,
        }
    }
    if !pass.split.is_empty() || !pass.present.is_empty() {
        return false;
    }
    relocation.add_patches(
        accepted
            .into_iter()
            .map(|(top, i)| (top, std::mem::take(&mut pass.patches[i])))
            .collect(),
    );
    state.relocation = Some((h.split_count, r.points.len(), relocation));
    true
}

/// The state between extended passes: the splits since the last pass (`None`: the next pass
/// is a full one). After splits a pass classifies only the hexagons near them (a work queue
/// of affected hexagons, one pass per wave of splits). A run ends only after a full pass finds
/// nothing, so the result is a fixed point of the full rules, at O(changes) cost per
/// incremental pass.
#[derive(Debug, Default, Clone)]
pub struct ExtendedState {
    changes: Option<Vec<(u32, Axial)>>,
    /// The relocations of the last full pass that found nothing, with the split count and
    /// number of points it saw: the dual takes them ([`take_relocated_centres`], by `&mut`)
    /// or copies them ([`relocated_centres`]) instead of running a further full pass.
    relocation: Option<(usize, usize, Relocation)>,
}

impl ExtendedState {
    /// Forces a full pass next (after insertions).
    pub fn reset(&mut self) {
        self.changes = None;
        self.relocation = None;
    }

    /// Records splits made outside the extended passes (simple rules, balancing).
    pub fn record(&mut self, made: &[(u32, Axial)]) {
        if !made.is_empty() {
            self.relocation = None;
        }
        if let Some(c) = &mut self.changes {
            c.extend_from_slice(made);
        }
    }

    /// The cached relocations if they are those of `r` as it is now (same splits and points).
    fn cached(&self, r: &Refinement) -> Option<&Relocation> {
        match &self.relocation {
            Some((splits, points, relocation))
                if *splits == r.hierarchy.split_count && *points == r.points.len() =>
            {
                Some(relocation)
            }
            _ => None,
        }
    }
}

/// The hexagons in the order of `(level, a, b)`, sorted as one 128-bit key each (the order
/// of the tuples; cheaper to compare). Coordinates are below 2^59 in magnitude (levels are
/// capped at 48).
fn sorted_hexes(hexes: impl IntoIterator<Item = (u32, Axial)>) -> Hexes {
    const OFF: i64 = 1 << 59;
    let mut keys: Vec<u128> = hexes
        .into_iter()
        .map(|(k, (a, b))| {
            debug_assert!(a.abs() < OFF && b.abs() < OFF && k < 256);
            (u128::from(k) << 120) | (((a + OFF) as u128) << 60) | (b + OFF) as u128
        })
        .collect();
    keys.sort_unstable();
    let mask = (1u128 << 60) - 1;
    keys.into_iter()
        .map(|x| {
            let a = ((x >> 60) & mask) as i64 - OFF;
            let b = (x & mask) as i64 - OFF;
            ((x >> 120) as u32, (a, b))
        })
        .collect()
}

/// Lattice points within hexagonal distance `r` of `v`.
fn disc(v: Axial, r: i64) -> impl Iterator<Item = Axial> {
    (-r..=r).flat_map(move |a| ((-r).max(-a - r)..=r.min(-a + r)).map(move |b| (v.0 + a, v.1 + b)))
}

/// One extended step on a refinement whose simple rules are exhausted: classifies (near the
/// last changes, or everywhere) and splits every hexagon an extended rule marks. Returns the
/// splits made; empty once a full pass finds nothing.
pub fn extended_pass(
    r: &mut Refinement,
    state: &mut ExtendedState,
    segments: &[[u32; 2]],
) -> Result<Vec<(u32, Axial)>, HexDelaunayError> {
    state.relocation = None;
    loop {
        let full = state.changes.is_none();
        let (split, present) = match state.changes.take() {
            Some(changes) => {
                let (leaves, occupied) = affected(r, &changes);
                region_pass(r, segments, &leaves, &occupied)
            }
            None => {
                let (marks, relocation) = full_pass(r, segments);
                if marks.0.is_empty() && marks.1.is_empty() {
                    // The fixed point: these are the dual's relocations.
                    let seen = (r.hierarchy.split_count, r.points.len());
                    state.relocation = Some((seen.0, seen.1, relocation));
                }
                marks
            }
        };
        let mut made = Vec::new();
        for (k, x) in split {
            made.extend(r.split_now(k, x)?);
        }
        for (k, x) in present {
            made.extend(r.make_present(k, x)?);
        }
        if !made.is_empty() {
            state.changes = Some(made.clone());
            return Ok(made);
        }
        if full {
            return Ok(made);
        }
    }
}

/// Lower angle bound of the extended refinement, degrees (tan α = 5/(3√3), section 5.4).
pub const ANGLE_MIN: f64 = 43.897_886_248_013_99;

/// The relocations (section 5.4) of the finished extended refinement: a copy of those of the
/// last full pass if nothing changed since (same splits and points), else a new full pass.
pub fn relocated_centres(
    r: &Refinement,
    state: &ExtendedState,
    segments: &[[u32; 2]],
) -> Relocation {
    match state.cached(r) {
        Some(relocation) => relocation.clone(),
        None => full_pass(r, segments).1,
    }
}

/// [`relocated_centres`], taking the cached relocations out of `state` instead of copying
/// them (so that they are not held twice while the dual is built: peak memory); a second
/// call makes a new full pass.
pub fn take_relocated_centres(
    r: &Refinement,
    state: &mut ExtendedState,
    segments: &[[u32; 2]],
) -> Relocation {
    match state.relocation.take() {
        Some((splits, points, relocation))
            if splits == r.hierarchy.split_count && points == r.points.len() =>
        {
            relocation
        }
        _ => full_pass(r, segments).1,
    }
}
