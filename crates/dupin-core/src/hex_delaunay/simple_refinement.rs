//! Simple refinement (section 4.1): rules 1 to 5 driven by a work queue of affected points.
//!
//! Each point knows its leaf cell; a hash map lists the points of every occupied cell. A point
//! is (re)checked when it moved to a new cell or when a hexagon next to its cell was split; a
//! check applies the first rule that fires:
//!
//! 1. its cell holds several points → split the cell;
//! 2. its cell is a semi-hexagon → split the full hexagon on the semi-hexagon's long edge;
//! 3. a neighbouring full hexagon is occupied → split the cell;
//! 4. a neighbour is of lower level (a semi-hexagon covers the neighbour position) → split the
//!    full hexagon on that semi-hexagon's long edge;
//! 5. a neighbour is of higher level (split) → split the cell;
//!
//! 3b. (ours) another occupied hexagon of the same level lies two steps away, sharing a ring
//!    hexagon → split the cell. Without it two relocated centres can face each other across one
//!    ring edge with opposite angles up to 120° each, and the dual is not Delaunay (the paper
//!    claims Delaunay only for the extended refinement, through its 90° bound).
//!
//! Added for the bounded domain: a point in a boundary (virtual) hexagon splits it, since a
//! boundary centre must stay on Ω's boundary for the triangles to tile Ω. The balancing rule
//! runs inside every split. The queue empties when every occupied cell is a full hexagon holding
//! one point inside a ring of six unsplit, unoccupied full hexagons of its level — the paper's
//! final state. Each split costs O(1) expected hash operations plus the re-location of the
//! points it displaces (O(depth) each), so the whole refinement is O(T + n·depth²) for T output
//! triangles, n points.

use super::error::HexDelaunayError;
use super::hierarchy::{Cell, Hierarchy, Merge, MergeError};
use super::lattice::{Axial, DIRS, add};
use super::tile_set::HexSet;
use crate::Vec2;
use rustc_hash::FxHashMap;
use std::collections::VecDeque;

/// The refinement state: hierarchy, point cells and the work queue.
#[derive(Debug, Clone)]
pub struct Refinement {
    /// The hexagon hierarchy.
    pub hierarchy: Hierarchy,
    /// Distinct input points.
    pub points: Vec<Vec2>,
    /// Leaf cell of every point.
    pub cell_of: Vec<Cell>,
    occupants: FxHashMap<Cell, Vec<u32>>,
    /// The occupied full cells, tiled like the split sets: most occupancy queries (rings
    /// around occupied hexagons) find an empty cell here without probing `occupants`.
    occupied_full: HexSet,
    /// The occupied semi-hexagons (by the centre of their absent full hexagon), so that a split
    /// asks `occupants` only about its neighbours' semi-hexagons that hold points.
    occupied_semi: HexSet,
    /// The position of the last point located in each occupied full cell (what `point_in`
    /// answers, in one probe instead of three dependent reads through `occupants`).
    last_in: FxHashMap<(u32, Axial), Vec2>,
    queue: VecDeque<u32>,
    queued: Vec<bool>,
    scratch: Vec<(u32, Axial)>,
    /// Whether rule 3b applies (simple mode). The extended refinement replaces it by its ring
    /// conflict rules, which allow two OCCUPIED_1 hexagons two steps apart.
    pub rule_3b: bool,
}

enum Action {
    Split(u32, Axial),
    Present(u32, Axial),
}

impl Refinement {
    /// Locates every point in the (root-split) hierarchy and queues them all.
    pub fn new(hierarchy: Hierarchy, points: Vec<Vec2>) -> Self {
        let mut occupants: FxHashMap<Cell, Vec<u32>> = FxHashMap::default();
        let cell_of: Vec<Cell> = points.iter().map(|p| hierarchy.locate(*p)).collect();
        let mut occupied_full = HexSet::default();
        let mut occupied_semi = HexSet::default();
        let mut last_in = FxHashMap::default();
        for (i, c) in cell_of.iter().enumerate() {
            occupants.entry(*c).or_default().push(i as u32);
            match *c {
                Cell::Full(k, x) => {
                    occupied_full.insert(k, x);
                    last_in.insert((k, x), points[i]);
                }
                Cell::Semi(k, m) => {
                    occupied_semi.insert(k, m);
                }
            }
        }
        let n = points.len();
        Refinement {
            hierarchy,
            points,
            cell_of,
            occupants,
            occupied_full,
            occupied_semi,
            last_in,
            queue: (0..n as u32).collect(),
            queued: vec![true; n],
            scratch: Vec::new(),
            rule_3b: true,
        }
    }

    /// Adds a point (inside Ω) to an existing refinement and queues it; refinement resumes with
    /// the next [`step`](Self::step). Returns its index among the distinct points.
    pub fn add_point(&mut self, p: Vec2) -> u32 {
        let i = self.points.len() as u32;
        self.points.push(p);
        let c = self.hierarchy.locate(p);
        self.cell_of.push(c);
        self.occupants.entry(c).or_default().push(i);
        self.mark_occupied(c, i);
        self.queued.push(false);
        self.push(i);
        i
    }

    /// Whether the work queue is empty (refinement finished).
    pub fn is_done(&self) -> bool {
        self.queue.is_empty()
    }

    fn push(&mut self, i: u32) {
        if !self.queued[i as usize] {
            self.queued[i as usize] = true;
            self.queue.push_back(i);
        }
    }

    /// The points (distinct-point indices) in the leaf cell `c`.
    pub fn occupants_of(&self, c: &Cell) -> &[u32] {
        if let Cell::Full(k, x) = *c
            && !self.occupied_full.contains(k, x)
        {
            return &[];
        }
        self.occupants.get(c).map_or(&[], Vec::as_slice)
    }

    fn occupied(&self, c: &Cell) -> usize {
        if let Cell::Full(k, x) = *c
            && !self.occupied_full.contains(k, x)
        {
            return 0;
        }
        self.occupants.get(c).map_or(0, Vec::len)
    }

    /// The occupied full cells.
    pub fn occupied_full(&self) -> &HexSet {
        &self.occupied_full
    }

    /// The last point located in the full hexagon `x` at level `k`, if any (one hash look-up;
    /// once the simple rules are done every occupied cell holds exactly one point).
    #[inline]
    pub fn point_in(&self, k: u32, x: Axial) -> Option<Vec2> {
        if !self.occupied_full.contains(k, x) {
            return None;
        }
        self.last_in.get(&(k, x)).copied()
    }

    fn check(&self, i: u32) -> Option<Action> {
        let h = &self.hierarchy;
        match self.cell_of[i as usize] {
            Cell::Semi(k, m) => Some(Action::Present(k, m)),
            Cell::Full(k, x) => {
                if self.occupied(&Cell::Full(k, x)) >= 2 || h.on_boundary(k, x) {
                    return Some(Action::Split(k, x));
                }
                for d in DIRS {
                    let y = add(x, d);
                    if !h.is_present(k, y) {
                        return Some(Action::Present(k, y));
                    }
                }
                for d in DIRS {
                    let y = add(x, d);
                    if h.is_split(k, y) || self.occupied(&Cell::Full(k, y)) > 0 {
                        return Some(Action::Split(k, x));
                    }
                }
                // Rule 3b (ours): no other occupied hexagon of this level shares a ring
                // hexagon, else two relocated centres face each other across one ring edge and
                // the two opposite angles (up to 120° each) break the Delaunay property.
                for (j, d) in DIRS.iter().enumerate().filter(|_| self.rule_3b) {
                    let e = DIRS[(j + 1) % 6];
                    for z in [add(x, add(*d, *d)), add(x, add(*d, e))] {
                        if self.occupied(&Cell::Full(k, z)) > 0 && !h.is_split(k, z) {
                            return Some(Action::Split(k, x));
                        }
                    }
                }
                None
            }
        }
    }

    /// Processes the queue until at least one hexagon is split (one observable subdivision step,
    /// including the balancing splits it forces) or the queue is empty. Returns the splits made,
    /// in order; empty means refinement is finished.
    pub fn step(&mut self) -> Result<Vec<(u32, Axial)>, HexDelaunayError> {
        while let Some(i) = self.queue.pop_front() {
            self.queued[i as usize] = false;
            let Some(action) = self.check(i) else {
                continue;
            };
            let mut out = std::mem::take(&mut self.scratch);
            out.clear();
            match action {
                Action::Split(k, x) => self.hierarchy.ensure_split(k, x, &mut out)?,
                Action::Present(k, y) => self.hierarchy.ensure_present(k, y, &mut out)?,
            }
            for &(k, x) in &out {
                self.after_split(k, x);
            }
            self.push(i);
            let made = out.clone();
            self.scratch = out;
            if !made.is_empty() {
                return Ok(made);
            }
        }
        Ok(Vec::new())
    }

    /// Splits the full hexagon `x` at level `k` now (with its balancing splits), re-locating
    /// the displaced points and queueing the affected ones. Returns the splits made.
    pub fn split_now(&mut self, k: u32, x: Axial) -> Result<Vec<(u32, Axial)>, HexDelaunayError> {
        let mut out = Vec::new();
        self.hierarchy.ensure_split(k, x, &mut out)?;
        for &(k, x) in &out {
            self.after_split(k, x);
        }
        Ok(out)
    }

    /// Makes `x` at level `k` a full hexagon now (splitting the coarser hexagon on it, with
    /// balancing), re-locating displaced points. Returns the splits made.
    pub fn make_present(
        &mut self,
        k: u32,
        x: Axial,
    ) -> Result<Vec<(u32, Axial)>, HexDelaunayError> {
        let mut out = Vec::new();
        self.hierarchy.ensure_present(k, x, &mut out)?;
        for &(k, x) in &out {
            self.after_split(k, x);
        }
        Ok(out)
    }

    /// Merges the split hexagon `v` at level `k` now (section 3.2's reverse operation, see
    /// [`Hierarchy::merge`]): the points in its children move to the merged hexagon (or, from
    /// a broken join, to the neighbour's semi-hexagon), and the points whose rules may fire
    /// again (in and next to the changed cells) are queued. Refused, changing nothing, when
    /// the merge would unbalance the hierarchy.
    pub fn merge_now(&mut self, k: u32, v: Axial) -> Result<Merge, MergeError> {
        let m = self.hierarchy.merge(k, v)?;
        let c = (2 * v.0, 2 * v.1);
        let mut moved = Vec::new();
        for d in std::iter::once((0, 0)).chain(DIRS) {
            let x = add(c, d);
            if self.occupied_full.contains(k + 1, x) {
                self.occupied_full.remove(k + 1, x);
                self.last_in.remove(&(k + 1, x));
                moved.extend(
                    self.occupants
                        .remove(&Cell::Full(k + 1, x))
                        .unwrap_or_default(),
                );
            }
            if d != (0, 0) && self.occupied_semi.contains(k + 1, x) {
                self.occupied_semi.remove(k + 1, x);
                moved.extend(
                    self.occupants
                        .remove(&Cell::Semi(k + 1, x))
                        .unwrap_or_default(),
                );
            }
        }
        for i in moved {
            let cell = self.hierarchy.locate(self.points[i as usize]);
            self.relocate(i, cell);
        }
        // Points next to the merged cells see absent or coarser neighbours now.
        let mut near = Vec::new();
        self.occupied_full
            .for_each_in_stadium(k + 1, c.0, (c.1, c.1), 2, |x| {
                near.push(Cell::Full(k + 1, x))
            });
        self.occupied_full
            .for_each_in_stadium(k, v.0, (v.1, v.1), 1, |x| near.push(Cell::Full(k, x)));
        for cell in near {
            if let Some(pts) = self.occupants.get(&cell) {
                for i in pts.clone() {
                    self.push(i);
                }
            }
        }
        Ok(m)
    }

    /// Runs the refinement to the end.
    pub fn run(&mut self) -> Result<(), HexDelaunayError> {
        while !self.step()?.is_empty() {}
        Ok(())
    }

    fn relocate(&mut self, i: u32, c: Cell) {
        self.cell_of[i as usize] = c;
        self.occupants.entry(c).or_default().push(i);
        self.mark_occupied(c, i);
        self.push(i);
    }

    /// Records that the point `i` was located in the cell `c` (the tiled filters in front of
    /// `occupants`, and the last point of a full cell).
    fn mark_occupied(&mut self, c: Cell, i: u32) {
        match c {
            Cell::Full(k, x) => {
                self.occupied_full.insert(k, x);
                self.last_in.insert((k, x), self.points[i as usize]);
            }
            Cell::Semi(k, m) => {
                self.occupied_semi.insert(k, m);
            }
        }
    }

    /// Re-locates the points displaced by splitting `x` at level `k` and queues the points whose
    /// rules may now fire.
    fn after_split(&mut self, k: u32, x: Axial) {
        // Most split hexagons hold no point: the tiled filter answers without a probe.
        let moved = if self.occupied_full.contains(k, x) {
            self.occupied_full.remove(k, x);
            self.last_in.remove(&(k, x));
            self.occupants.remove(&Cell::Full(k, x)).unwrap_or_default()
        } else {
            Vec::new()
        };
        for i in moved {
            let c = self.hierarchy.locate_from(self.points[i as usize], k, x);
            self.relocate(i, c);
        }
        for d in DIRS {
            // Semi-hexagons of split neighbours towards x are now joined into full hexagons.
            let m = add(x, add(x, d));
            if !self.occupied_semi.contains(k + 1, m) {
                continue;
            }
            self.occupied_semi.remove(k + 1, m);
            if let Some(v) = self.occupants.remove(&Cell::Semi(k + 1, m)) {
                for i in v {
                    self.relocate(i, Cell::Full(k + 1, m));
                }
            }
        }
        for d in DIRS {
            let y = add(x, d);
            if !self.occupied_full.contains(k, y) {
                continue;
            }
            if let Some(v) = self.occupants.get(&Cell::Full(k, y)) {
                let v = v.clone();
                for i in v {
                    self.push(i);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::lattice::{in_domain, on_boundary};
    use super::super::tests::{FAMILIES, sample};
    use super::*;
    use crate::Stepper;
    use crate::hex_delaunay::HexDelaunayStepper;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    /// Section 4.1's final state and section 3.3's balancing rule, checked on the hierarchy.
    #[test]
    fn final_state_rings_and_balance() {
        let mut rng = ChaCha8Rng::seed_from_u64(31);
        for case in 0..900 {
            let pts = sample(FAMILIES[case % FAMILIES.len()], &mut rng);
            let mut s =
                HexDelaunayStepper::new(&pts, &[], crate::hex_delaunay::HexDelaunayMode::Simple)
                    .unwrap();
            s.run_to_end().unwrap();
            let r = s.refinement();
            let h = &r.hierarchy;
            // Balancing: every split hexagon has its six neighbours (inside Ω) present, i.e.
            // adjacent cells differ by at most one paper level.
            for k in 0..h.depth() {
                for x in h.split_at(k) {
                    assert!(h.is_present(k, x), "case {case}: split but absent");
                    for d in DIRS {
                        let y = add(x, d);
                        if in_domain(k, y) {
                            assert!(h.is_present(k, y), "case {case}: unbalanced at {k} {x:?}");
                        }
                    }
                }
            }
            // Every occupied cell is an interior full hexagon with one point, inside a ring of
            // six present, unsplit, unoccupied full hexagons of its level.
            for c in &r.cell_of {
                let Cell::Full(k, x) = *c else {
                    panic!("case {case}: a point ends in a semi-hexagon");
                };
                assert_eq!(r.occupied(c), 1, "case {case}");
                assert!(!on_boundary(k, x), "case {case}");
                for d in DIRS {
                    let y = add(x, d);
                    assert!(h.is_present(k, y) && !h.is_split(k, y), "case {case}");
                    assert_eq!(r.occupied(&Cell::Full(k, y)), 0, "case {case}");
                }
            }
        }
    }
}
