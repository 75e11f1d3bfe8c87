//! The stepper: the refinement one observable subdivision step at a time, for the page's 2D
//! view, plus the input checks and bounding-hexagon set-up shared with the one-shot function.

use super::dual::{DualBuilder, Key, pack, unpack};
use super::error::HexDelaunayError;
use super::extended::{
    ExtendedState, Relocation, after_coarsening, apply_fin_patches, coarsen, extended_pass,
    relocated_centres, take_relocated_centres,
};
use super::hierarchy::{Cell, Hierarchy};
use super::lattice::{Axial, DIRS, Frame, add, parents_of_midpoint};
use super::min_enclosing_circle::min_enclosing_circle;
use super::pslg::{
    insert_segments, segment_pass, snapped_centres, split_at_points, undo_inverting_snaps,
};
use super::simple_refinement::Refinement;
use super::{HexDelaunayMode, HexTriangulation, MAX_COORDINATE, MAX_LEVEL, MIN_EXTENT};
use crate::{Stepper, Vec2};
use robust::{Coord, orient2d};
use rustc_hash::{FxHashMap, FxHashSet};

/// A leaf cell of the current hexagon mesh, for drawing.
#[derive(Debug, Clone, PartialEq)]
pub struct HexCell {
    /// Corners, counter-clockwise (6 for a full hexagon, 4 for a semi-hexagon).
    pub corners: Vec<Vec2>,
    /// The paper's level: even for full hexagons, odd for semi-hexagons.
    pub paper_level: u32,
    /// Whether an input point lies in the cell.
    pub occupied: bool,
}

/// Hexagonal Delaunay triangulation run step by step: each [`Stepper::step`] performs one
/// refinement-rule subdivision (with the balancing splits it forces).
#[derive(Debug, Clone)]
pub struct HexDelaunayStepper {
    refinement: Refinement,
    input_map: Vec<u32>,
    by_bits: FxHashMap<(u64, u64), u32>,
    last: Vec<(u32, Axial)>,
    steps: usize,
    mode: HexDelaunayMode,
    /// Whether the last extended pass found nothing to split (extended mode); reset by
    /// splits and insertions.
    extended_clean: bool,
    extended: ExtendedState,
    /// Input segments as distinct-point index pairs.
    base_segments: Vec<[u32; 2]>,
    /// `base_segments` split at the points lying on them (what refinement and dual use).
    segments: Vec<[u32; 2]>,
    /// Whether the last segment pass found nothing to split; reset by any split.
    segments_clean: bool,
    /// Whether the local coarsening into blossoms (section 5.3, extended mode) runs.
    coarsening: bool,
    /// Whether it ran since the last insertion.
    coarsened: bool,
    /// The hexagons the last step merged (a coarsening step), in order.
    last_merged: Vec<(u32, Axial)>,
}

impl HexDelaunayStepper {
    /// Checks the input, builds the bounding hexagon and locates the points.
    pub fn new(
        points: &[Vec2],
        segments: &[[usize; 2]],
        mode: HexDelaunayMode,
    ) -> Result<Self, HexDelaunayError> {
        let (unique, input_map) = check_points(points)?;
        check_segments(points, segments)?;
        let circle = min_enclosing_circle(&unique).ok_or(HexDelaunayError::Empty)?;
        let rho = if unique.len() > 1 {
            if circle.radius < MIN_EXTENT {
                return Err(HexDelaunayError::TooSmall {
                    extent: circle.radius,
                    limit: MIN_EXTENT,
                });
            }
            circle.radius
        } else {
            circle.center.x.abs().max(circle.center.y.abs()).max(1.0)
        };
        // Ω has inradius 3R/4: 1.5 rho in the simple mode. The extended mode's rings and
        // fin rules need about three hexagons between a point and Ω's boundary, which with
        // 1.5 rho forces cells finer than the closest pair asks for (section 6.3's bound then
        // fails for sparse sets); inradius 3 rho leaves that room at the pair's own level.
        let root = match mode {
            HexDelaunayMode::Simple => 2.0 * rho,
            HexDelaunayMode::Extended => 4.0 * rho,
        };
        let base: Vec<[u32; 2]> = segments.iter().map(|s| s.map(|i| input_map[i])).collect();
        let mut s = Self::build(unique, input_map, circle.center, root, mode)?;
        s.segments = split_at_points(&s.refinement.points, &base);
        s.base_segments = base;
        Ok(s)
    }

    /// The same run with at most `max_splits` split hexagons (default [`super::MAX_SPLITS`];
    /// each adds about six triangles); a step that would pass it fails with
    /// [`HexDelaunayError::TooManySplits`].
    pub fn with_max_splits(mut self, max_splits: usize) -> Self {
        self.refinement.hierarchy.max_splits = max_splits;
        self
    }

    /// Like [`new`](Self::new) but triangulating a given bounding hexagon Ω (centre `center`,
    /// inradius `inradius`, corners at 30° + 60° i) instead of the one derived from the points'
    /// enclosing circle, as the paper's "two close points in a unit hexagon" benchmark does.
    /// Every point must lie strictly inside Ω; the minimum-edge bound then holds only for points
    /// at least d_min/2 away from Ω's boundary.
    pub fn new_in_domain(
        points: &[Vec2],
        mode: HexDelaunayMode,
        center: Vec2,
        inradius: f64,
    ) -> Result<Self, HexDelaunayError> {
        let (unique, input_map) = check_points(points)?;
        let valid = (MIN_EXTENT..=MAX_COORDINATE).contains(&inradius)
            && center.x.is_finite()
            && center.y.is_finite();
        if !valid {
            return Err(HexDelaunayError::TooSmall {
                extent: inradius,
                limit: MIN_EXTENT,
            });
        }
        let mut s = Self::build(Vec::new(), Vec::new(), center, inradius / 0.75, mode)?;
        s.insert(&unique)?;
        s.input_map = input_map;
        Ok(s)
    }

    fn build(
        unique: Vec<Vec2>,
        input_map: Vec<u32>,
        center: Vec2,
        root_radius: f64,
        mode: HexDelaunayMode,
    ) -> Result<Self, HexDelaunayError> {
        let frame = Frame {
            origin: center,
            root_radius,
        };
        // Cells finer than 2^-42 of the coordinates' magnitude lose their shape in f64.
        let scale = center.x.abs().max(center.y.abs()) + root_radius;
        let by_precision = 42.0 - (scale / root_radius).log2();
        let max_level = (by_precision.floor().max(0.0) as u32).min(MAX_LEVEL);
        let hierarchy = Hierarchy::new(frame, max_level);
        let by_bits = unique
            .iter()
            .enumerate()
            .map(|(i, p)| (bits(p), i as u32))
            .collect();
        Ok(HexDelaunayStepper {
            refinement: {
                let mut r = Refinement::new(hierarchy, unique);
                r.rule_3b = mode == HexDelaunayMode::Simple;
                r
            },
            input_map,
            by_bits,
            last: Vec::new(),
            steps: 0,
            mode,
            extended_clean: false,
            extended: ExtendedState::default(),
            base_segments: Vec::new(),
            segments: Vec::new(),
            segments_clean: true,
            coarsening: true,
            coarsened: false,
            last_merged: Vec::new(),
        })
    }

    /// One subdivision step (see [`Stepper::step`]); whether it changed anything (`false` once
    /// refinement is finished). With segments,
    /// once the point rules (and extended passes) find nothing, one pass of the segment rules
    /// (section 7.2, see `pslg.rs`) is one step.
    ///
    /// Extended mode: once every rule is at its fixed point, one step is the local coarsening
    /// into blossoms (section 5.3, see `extended/coarsening.rs`; [`last_merges`](Self::last_merges)
    /// lists what it merged, [`last_splits`](Self::last_splits) is empty), after which the
    /// rules are checked again (a full extended pass, then the segment pass).
    fn subdivide(&mut self) -> Result<bool, HexDelaunayError> {
        self.last_merged.clear();
        self.last = self.refinement.step()?;
        if self.mode == HexDelaunayMode::Extended {
            if self.last.is_empty() {
                // Simple rules exhausted: one extended pass (section 5.2) is one step (none
                // while nothing changed since a pass, or the check after coarsening, found
                // nothing).
                if !self.extended_clean {
                    self.last =
                        extended_pass(&mut self.refinement, &mut self.extended, &self.segments)?;
                    self.extended_clean = self.last.is_empty();
                }
            } else {
                self.extended.record(&self.last);
                self.extended_clean = false;
            }
        }
        if self.last.is_empty() && !self.segments.is_empty() {
            // Point rules exhausted: one pass of the segment rules (section 7.2) is one step.
            self.last = segment_pass(&mut self.refinement, &self.segments)?;
            self.segments_clean = self.last.is_empty();
            if !self.segments_clean {
                self.extended_clean = false;
                self.extended.record(&self.last);
            }
        } else if !self.last.is_empty() {
            self.segments_clean = self.segments.is_empty();
        }
        if self.last.is_empty() && self.wants_coarsening() && self.everything_clean() {
            self.coarsened = true;
            let splits_before = self.refinement.hierarchy.split_count;
            let done = coarsen(&mut self.refinement, &self.segments);
            if !done.merged.is_empty() {
                // The rules are checked again around the blossoms (else by a full extended
                // pass), then by the segment pass.
                self.extended_clean = after_coarsening(
                    &self.refinement,
                    &mut self.extended,
                    &self.segments,
                    splits_before,
                    &done.merged,
                    &done.blossoms,
                );
                self.last_merged = done.merged;
                self.segments_clean = self.segments.is_empty();
                self.steps += 1;
                return Ok(true);
            }
        }
        if self.last.is_empty() {
            Ok(false)
        } else {
            self.steps += 1;
            Ok(true)
        }
    }

    /// Incremental insertion (the paper's abstract and section 9): adds further points to the
    /// current subdivision, which is refined further by the following steps or
    /// [`Stepper::run_to_end`] (in the extended mode the coarsening into blossoms runs again once
    /// the rules are at their fixed point; earlier blossoms are split where the new points'
    /// rules ask). The points must lie strictly inside [`domain`](Self::domain), which
    /// the first batch fixed. They are numbered after all earlier points in
    /// [`HexTriangulation::input_vertex`]. On error nothing is inserted.
    pub fn insert(&mut self, points: &[Vec2]) -> Result<(), HexDelaunayError> {
        let f = self.refinement.hierarchy.frame;
        // Ω's inradius is 3R/4; its edges' outward normals point at 0°, 60°, ...
        let inr = 0.75 * f.root_radius;
        for (index, p) in points.iter().enumerate() {
            if !p.x.is_finite() || !p.y.is_finite() {
                return Err(HexDelaunayError::NonFinite { index });
            }
            let q = p - f.origin;
            let inside = (0..6).all(|i| {
                let t = std::f64::consts::FRAC_PI_3 * i as f64;
                q.x * t.cos() + q.y * t.sin() < inr
            });
            if !inside {
                return Err(HexDelaunayError::OutsideDomain { index });
            }
        }
        for p in points {
            let p = p + Vec2::new(0.0, 0.0);
            let u = match self.by_bits.get(&bits(&p)) {
                Some(&u) => u,
                None => {
                    let u = self.refinement.add_point(p);
                    self.by_bits.insert(bits(&p), u);
                    u
                }
            };
            self.input_map.push(u);
        }
        self.extended_clean = false;
        self.extended.reset();
        self.coarsened = false;
        if !self.base_segments.is_empty() {
            self.segments = split_at_points(&self.refinement.points, &self.base_segments);
            self.segments_clean = false;
        }
        Ok(())
    }

    /// Forgets that the rules were checked and runs the remaining steps: a full extended pass
    /// must find nothing on a finished run (tests of the coarsening's local check).
    #[cfg(test)]
    pub(crate) fn recheck(&mut self) -> Result<bool, HexDelaunayError> {
        self.extended.reset();
        self.extended_clean = false;
        let mut changed = false;
        while self.subdivide()? {
            changed = true;
        }
        Ok(changed)
    }

    #[cfg(test)]
    pub(crate) fn refinement(&self) -> &Refinement {
        &self.refinement
    }

    /// Whether no rule fires (simple, extended and segment rules at their fixed point).
    fn everything_clean(&self) -> bool {
        self.refinement.is_done()
            && (self.mode == HexDelaunayMode::Simple || self.extended_clean)
            && self.segments_clean
    }

    /// Whether the coarsening into blossoms is still to run (extended mode).
    fn wants_coarsening(&self) -> bool {
        self.mode == HexDelaunayMode::Extended && self.coarsening && !self.coarsened
    }

    /// Turns the local coarsening into blossoms (section 5.3, extended mode; on by default)
    /// on or off, e.g. to compare triangle counts. Takes effect at the next fixed point.
    pub fn set_coarsening(&mut self, on: bool) {
        self.coarsening = on;
    }

    /// The hexagons merged by the last step (centre and circumradius of each merged hexagon,
    /// seven per blossom: its top, then the top's neighbours); empty unless the last step was
    /// the coarsening into blossoms (section 5.3).
    pub fn last_merges(&self) -> Vec<(Vec2, f64)> {
        self.discs(&self.last_merged)
    }

    /// Centre and circumradius of each hexagon `(level, lattice coordinates)`.
    fn discs(&self, cells: &[(u32, Axial)]) -> Vec<(Vec2, f64)> {
        let f = &self.refinement.hierarchy.frame;
        cells
            .iter()
            .map(|&(k, v)| (f.position(k, v), f.radius(k)))
            .collect()
    }

    /// Number of steps taken through [`Stepper::step`].
    pub fn steps(&self) -> usize {
        self.steps
    }

    /// Number of split hexagons so far (root included).
    pub fn split_count(&self) -> usize {
        self.refinement.hierarchy.split_count
    }

    /// The hexagons split by the last step (centre and circumradius), balancing splits first.
    pub fn last_splits(&self) -> Vec<(Vec2, f64)> {
        self.discs(&self.last)
    }

    /// Corners of the bounding hexagon Ω, counter-clockwise.
    pub fn domain(&self) -> [Vec2; 6] {
        self.refinement.hierarchy.frame.domain_corners()
    }

    /// The current leaf cells (full and semi-hexagons). Boundary cells, whose centres lie on
    /// Ω's edges, are returned whole, as the paper's virtual full hexagons (half of each lies
    /// outside Ω).
    pub fn cells(&self) -> Vec<HexCell> {
        let h = &self.refinement.hierarchy;
        let f = &h.frame;
        let occupied: rustc_hash::FxHashSet<Cell> =
            self.refinement.cell_of.iter().copied().collect();
        let mut out = Vec::new();
        for k in 0..h.depth() {
            for x in h.split_at(k) {
                let c = (2 * x.0, 2 * x.1);
                if !h.is_split(k + 1, c) {
                    out.push(HexCell {
                        corners: f.hexagon(k + 1, c).to_vec(),
                        paper_level: 2 * (k + 1),
                        occupied: occupied.contains(&Cell::Full(k + 1, c)),
                    });
                }
                for (j, d) in DIRS.iter().enumerate() {
                    let m = add(c, *d);
                    if !super::lattice::in_domain(k + 1, m) {
                        continue;
                    }
                    if h.is_present(k + 1, m) {
                        let (a, _) = parents_of_midpoint(m);
                        let first = a == x || !super::lattice::in_domain(k, a);
                        if first && !h.is_split(k + 1, m) {
                            out.push(HexCell {
                                corners: f.hexagon(k + 1, m).to_vec(),
                                paper_level: 2 * (k + 1),
                                occupied: occupied.contains(&Cell::Full(k + 1, m)),
                            });
                        }
                    } else {
                        // The half towards x: corners j+2..=j+5 (corner i at 60i degrees,
                        // direction d_j at 30 + 60j degrees points away from x).
                        let hex = f.hexagon(k + 1, m);
                        let corners = (2..6).map(|i| hex[(j + i) % 6]).collect();
                        out.push(HexCell {
                            corners,
                            paper_level: 2 * k + 1,
                            occupied: occupied.contains(&Cell::Semi(k + 1, m)),
                        });
                    }
                }
            }
        }
        out
    }

    /// The dual triangulation of the current hexagon mesh, occupied centres moved to their
    /// points. Input points are exact vertices only once refinement is finished; segments are
    /// edge chains only then too. Should the segment insertion break down numerically (see
    /// [`HexDelaunayError::SegmentInsertion`]), the triangulation is returned without the
    /// segments and [`HexTriangulation::segment_edges`] is empty; [`crate::hex_delaunay::hex_delaunay`]
    /// reports that error instead.
    pub fn triangulation(&self) -> HexTriangulation {
        match self.try_triangulation() {
            Ok(t) => t,
            Err(_) => self.dual(false, self.relocation()).0,
        }
    }

    /// [`triangulation`](Self::triangulation), failing if a segment cannot be inserted.
    pub fn try_triangulation(&self) -> Result<HexTriangulation, HexDelaunayError> {
        self.triangulation_with(self.relocation())
    }

    /// [`try_triangulation`](Self::try_triangulation), taking the extended mode's cached
    /// relocations out of the stepper instead of copying them, so that they are not held twice
    /// while the dual is built (the one-shot [`super::hex_delaunay`]'s peak memory).
    pub(super) fn take_triangulation(&mut self) -> Result<HexTriangulation, HexDelaunayError> {
        let relocation = match self.mode {
            HexDelaunayMode::Extended if self.is_done() => {
                take_relocated_centres(&self.refinement, &mut self.extended, &self.segments)
            }
            _ => Relocation::default(),
        };
        self.triangulation_with(relocation)
    }

    /// The relocations (section 5.4) the dual uses: none until the extended refinement is done.
    fn relocation(&self) -> Relocation {
        match self.mode {
            HexDelaunayMode::Extended if self.is_done() => {
                relocated_centres(&self.refinement, &self.extended, &self.segments)
            }
            _ => Relocation::default(),
        }
    }

    /// The triangulation with the given relocations, segments inserted once refinement is done.
    fn triangulation_with(
        &self,
        relocation: Relocation,
    ) -> Result<HexTriangulation, HexDelaunayError> {
        let with_segments = self.is_done() && !self.segments.is_empty();
        let (mut t, segs, orig) = self.dual(with_segments, relocation);
        if with_segments {
            undo_inverting_snaps(&mut t.vertices, &t.triangles, &orig);
            let mut fixed = vec![false; t.vertices.len()];
            for &v in &t.input_vertex {
                fixed[v as usize] = true;
            }
            t.segment_edges = insert_segments(&mut t.vertices, &mut t.triangles, &segs, fixed)?;
        }
        Ok(t)
    }

    /// The dual, with the segments' hexagons snapped onto them if `snap`; also returns the
    /// segments as vertex pairs and the unsnapped positions of the snapped vertices.
    fn dual(
        &self,
        snap: bool,
        relocation: Relocation,
    ) -> (HexTriangulation, Vec<[u32; 2]>, FxHashMap<u32, Vec2>) {
        let h = &self.refinement.hierarchy;
        let Relocation {
            mut moved, patches, ..
        } = relocation;
        let centres: FxHashSet<Key> = patches.iter().flat_map(|p| p.centres.clone()).collect();
        // Section 7.3: unoccupied hexagons met by one segment move onto it; their previous
        // positions are kept so that a snap inverting a triangle can be undone.
        let mut snapped: Vec<(Key, Vec2)> = Vec::new();
        if snap {
            for (key, p) in snapped_centres(&self.refinement, &self.segments) {
                if centres.contains(&key) {
                    continue; // replaced by fin vertices; the segment walk splits what it crosses
                }
                let before = moved
                    .insert(key, p)
                    .unwrap_or_else(|| lattice_position(h, key));
                snapped.push((key, before));
            }
        }
        let mut point_key = Vec::with_capacity(self.refinement.points.len());
        for (i, c) in self.refinement.cell_of.iter().enumerate() {
            let key = match *c {
                Cell::Full(k, x) => Some(pack(k, x)),
                Cell::Semi(..) => None,
            };
            if let Some(key) = key {
                moved.insert(key, self.refinement.points[i]);
            }
            point_key.push(key);
        }
        // The patches' new vertices are appended: reserved up front, not reallocated.
        let extra = patches.iter().map(|p| p.new.len()).sum();
        let mut dual = DualBuilder::build(h, &moved, &centres, extra);
        debug_assert_eq!(dual.positions.len(), h.leaf_count());
        apply_fin_patches(
            &mut dual.positions,
            &mut dual.triangles,
            &dual.moved_vertex,
            &patches,
            dual.removed,
        );
        let unique_vertex: Vec<u32> = point_key
            .iter()
            .map(|k| {
                k.and_then(|k| dual.moved_vertex.get(&k).copied())
                    .unwrap_or(u32::MAX)
            })
            .collect();
        let orig = snapped
            .into_iter()
            .filter_map(|(key, before)| dual.moved_vertex.get(&key).map(|&v| (v, before)))
            .collect();
        let segs = self
            .segments
            .iter()
            .map(|s| s.map(|u| unique_vertex[u as usize]))
            .collect();
        let t = HexTriangulation {
            vertices: dual.positions,
            triangles: dual.triangles,
            input_vertex: self
                .input_map
                .iter()
                .map(|&u| unique_vertex[u as usize])
                .collect(),
            domain: h.frame.domain_corners(),
            depth: h.depth(),
            segment_edges: Vec::new(),
        };
        (t, segs, orig)
    }
}

/// The refinement's state after a step ([`HexDelaunayStepper`]'s [`Stepper::Metrics`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HexDelaunayMetrics {
    /// Whether the last step changed the subdivision (split hexagons, or merged them into
    /// blossoms); `false` once refinement is finished.
    pub changed: bool,
    /// Steps taken that changed the subdivision.
    pub steps: usize,
    /// Split hexagons so far (root included).
    pub split_count: usize,
}

impl Stepper for HexDelaunayStepper {
    type Metrics = HexDelaunayMetrics;
    type Output = HexTriangulation;
    type Error = HexDelaunayError;

    /// One subdivision step (with the balancing splits it forces); a no-op with
    /// [`HexDelaunayMetrics::changed`] `false` once refinement is finished. With segments,
    /// once the point rules (and extended passes) find nothing, one pass of the segment rules
    /// (section 7.2, see `pslg.rs`) is one step.
    ///
    /// Extended mode: once every rule is at its fixed point, one step is the local coarsening
    /// into blossoms (section 5.3, see `coarsening.rs`; [`last_merges`](HexDelaunayStepper::last_merges)
    /// lists what it merged, [`last_splits`](HexDelaunayStepper::last_splits) is empty), after which the
    /// rules are checked again (a full extended pass, then the segment pass).
    fn step(&mut self) -> Result<HexDelaunayMetrics, HexDelaunayError> {
        self.subdivide()?;
        Ok(self.metrics())
    }

    /// Whether refinement is finished.
    fn is_done(&self) -> bool {
        self.everything_clean() && !(self.wants_coarsening())
    }

    fn metrics(&self) -> HexDelaunayMetrics {
        HexDelaunayMetrics {
            changed: !self.last.is_empty() || !self.last_merged.is_empty(),
            steps: self.steps,
            split_count: self.split_count(),
        }
    }

    /// Runs all remaining steps (the simple mode without segments by the refinement's own
    /// loop, which ends in the same subdivision).
    fn run_to_end(&mut self) -> Result<(), HexDelaunayError> {
        if self.mode == HexDelaunayMode::Simple && self.segments.is_empty() {
            return self.refinement.run();
        }
        while self.subdivide()? {}
        Ok(())
    }

    /// Runs to the end and returns the triangulation, taking the extended state's cached
    /// relocations instead of copying them.
    fn finish(mut self) -> Result<HexTriangulation, HexDelaunayError> {
        self.run_to_end()?;
        self.take_triangulation()
    }
}

/// The lattice position of a packed dual key.
fn lattice_position(h: &Hierarchy, key: Key) -> Vec2 {
    let (level, v) = unpack(key);
    h.frame.position(level, v)
}

fn bits(p: &Vec2) -> (u64, u64) {
    ((p.x + 0.0).to_bits(), (p.y + 0.0).to_bits())
}

/// Checks coordinates and removes exact duplicates. Returns the distinct points and, for each
/// input point, the index of its distinct point.
fn check_points(points: &[Vec2]) -> Result<(Vec<Vec2>, Vec<u32>), HexDelaunayError> {
    if points.is_empty() {
        return Err(HexDelaunayError::Empty);
    }
    for (index, p) in points.iter().enumerate() {
        if !p.x.is_finite() || !p.y.is_finite() {
            return Err(HexDelaunayError::NonFinite { index });
        }
        let m = p.x.abs().max(p.y.abs());
        if m > MAX_COORDINATE {
            return Err(HexDelaunayError::TooLarge {
                index,
                value: m,
                limit: MAX_COORDINATE,
            });
        }
    }
    // Distinct points in Morton (Z-curve) order, so that refinement works through space
    // coherently.
    let (mut lo, mut hi) = (points[0], points[0]);
    for p in points {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    let span = (hi - lo).max().max(f64::MIN_POSITIVE);
    let morton = |p: &Vec2| {
        let q = |t: f64| ((t / span) * 1048575.0).clamp(0.0, 1048575.0) as u64;
        let (mut x, mut y, mut m) = (q(p.x - lo.x), q(p.y - lo.y), 0u64);
        for bit in 0..20 {
            m |= ((x & 1) << (2 * bit)) | ((y & 1) << (2 * bit + 1));
            x >>= 1;
            y >>= 1;
        }
        m
    };
    let mut order: Vec<u32> = (0..points.len() as u32).collect();
    let key = |i: u32| {
        let p = points[i as usize];
        // +0.0 and -0.0 are the same point.
        (morton(&p), (p.x + 0.0).to_bits(), (p.y + 0.0).to_bits())
    };
    let dedup_key = |i: u32| {
        let p = points[i as usize];
        ((p.x + 0.0).to_bits(), (p.y + 0.0).to_bits())
    };
    order.sort_by_cached_key(|&i| key(i));
    let mut map = vec![0u32; points.len()];
    let mut unique = Vec::new();
    let mut prev = None;
    for i in order {
        let k = dedup_key(i);
        if prev != Some(k) {
            unique.push(points[i as usize] + Vec2::new(0.0, 0.0));
            prev = Some(k);
        }
        map[i as usize] = unique.len() as u32 - 1;
    }
    Ok((unique, map))
}

/// Checks segment indices, lengths and crossings (exact orientation predicates).
pub(super) fn check_segments(
    points: &[Vec2],
    segments: &[[usize; 2]],
) -> Result<(), HexDelaunayError> {
    for (segment, s) in segments.iter().enumerate() {
        for &index in s {
            if index >= points.len() {
                return Err(HexDelaunayError::SegmentIndex {
                    segment,
                    index,
                    points: points.len(),
                });
            }
        }
        if points[s[0]] == points[s[1]] {
            return Err(HexDelaunayError::DegenerateSegment { segment });
        }
    }
    let c = |i: usize| Coord {
        x: points[i].x,
        y: points[i].y,
    };
    for i in 0..segments.len() {
        for j in i + 1..segments.len() {
            let [a, b] = segments[i];
            let [p, q] = segments[j];
            let same = |u: usize, v: usize| points[u] == points[v];
            if (same(a, p) && same(b, q)) || (same(a, q) && same(b, p)) {
                return Err(HexDelaunayError::DuplicateSegment {
                    first: i,
                    second: j,
                });
            }
            let shared = [a, b]
                .iter()
                .any(|&u| [p, q].iter().any(|&v| points[u] == points[v]));
            let o1 = orient2d(c(a), c(b), c(p));
            let o2 = orient2d(c(a), c(b), c(q));
            let o3 = orient2d(c(p), c(q), c(a));
            let o4 = orient2d(c(p), c(q), c(b));
            let crosses = if o1 == 0.0 && o2 == 0.0 {
                // Collinear: they may meet only at a shared endpoint.
                let d = points[b] - points[a];
                let t = |v: usize| (points[v] - points[a]).dot(&d) / d.norm_squared();
                let (lo, hi) = (t(p).min(t(q)).max(0.0), t(p).max(t(q)).min(1.0));
                hi > lo || (hi == lo && !shared)
            } else if shared {
                false
            } else {
                o1 * o2 <= 0.0 && o3 * o4 <= 0.0
            };
            if crosses {
                return Err(HexDelaunayError::SegmentsCross {
                    first: i,
                    second: j,
                });
            }
        }
    }
    Ok(())
}
