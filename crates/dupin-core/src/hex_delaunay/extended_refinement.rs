//! Extended refinement (section 5): classification of the full hexagons by their fins and
//! occupancy (5.1), the extra refinement rules (5.2) and the centre relocations (5.4).
//!
//! Input: a [`Refinement`] whose simple rules (section 4.1) have run to the end (without rule
//! 3b). Output: further splits until no extended rule fires, then the relocated centres of the
//! dual mesh, keyed like the dual's vertices. Angles land in [α, 90°], α = 43.8979°.
//!
//! Types and formulas: MOVED_CENTER_1 (Ĉ = 5/6 C + 1/6 C_f0), MOVED_CENTER_2
//! (Ĉ = 3/5 C + 2/5 C_f01), OCCUPIED_1/2 (point inside / outside the half-sized hexagon),
//! MOVED_CENTER_IN_RING (shifted by half the vector from the occupied centre to the corner
//! nearest its point), FIXED_CENTER_IN_RING and FIXED_CENTER_REGULAR (not moved). Rules of 5.2:
//! SUBDIVIDE, MOVED_CENTER_x in the 1-ring of an OCCUPIED_1 or the 1-/2-ring of an OCCUPIED_2,
//! MOVED_CENTER_x whose fin-adjacent full hexagons are not fixed.
//!
//! Deviations (see docs/hexdelaunay.md): MOVED_CENTER_3 hexagons are subdivided like SUBDIVIDE
//! ones, so MOVED_CENTER_4, the consecutive-MOVED_CENTER_3 rule and blossoms (with split
//! counters, merge and break) never arise: more triangles, same bounds. Rules added:
//! (a) opposite-facing fin strips: a MOVED_CENTER hexagon is subdivided when an unsplit
//! same-level neighbour has fins none of which is at or next to its own fin directions (two
//! such centres move apart and leave a 35° triangle between them, a case Fig. 10 lacks);
//! (b) ring conflicts between occupied hexagons of one level, resolved by splitting or by a
//! local check of the triangles around the rings (see `classify`); (c) the 2-ring of an
//! occupied hexagon is made of unsplit full hexagons of its level; (d) on Ω's boundary a centre
//! may only slide along the boundary, Ω's corners and an OCCUPIED_2's moved ring stay off it.
//!
//! Each pass classifies every leaf full hexagon in O(1) expected hash look-ups, so a pass costs
//! O(T) for T current triangles; passes repeat until no rule fires.

use super::dual::{Key, pack};
use super::error::HexDelaunayError;
use super::hierarchy::{Cell, Hierarchy};
use super::lattice::{Axial, DIRS, add, in_domain, on_boundary, parents_of_midpoint};
use super::simple_refinement::Refinement;
use crate::math::Vec2;
use rustc_hash::{FxHashMap, FxHashSet};

const SQRT3: f64 = 1.732_050_807_568_877_2;

/// Calls `f(level, v)` for every leaf full hexagon.
fn for_each_leaf(h: &Hierarchy, mut f: impl FnMut(u32, Axial)) {
    if h.depth() == 0 {
        f(0, (0, 0));
        return;
    }
    for k in 0..h.depth() {
        for &x in h.split_at(k) {
            let c = (2 * x.0, 2 * x.1);
            if !h.is_split(k + 1, c) {
                f(k + 1, c);
            }
            for d in DIRS {
                let m = add(c, d);
                if !in_domain(k + 1, m) || !h.is_present(k + 1, m) || h.is_split(k + 1, m) {
                    continue;
                }
                let (a, _) = parents_of_midpoint(m);
                if a == x || !in_domain(k, a) {
                    f(k + 1, m);
                }
            }
        }
    }
}

/// Bit `j` set when the neighbour in direction `DIRS[j]` is split (a fin lies between).
fn fin_mask(h: &Hierarchy, k: u32, v: Axial) -> u8 {
    let mut m = 0u8;
    for (j, d) in DIRS.iter().enumerate() {
        if h.is_split(k, add(v, *d)) {
            m |= 1 << j;
        }
    }
    m
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

/// Lattice points at hexagonal distance exactly `r` from `v`.
fn ring(v: Axial, r: i64) -> impl Iterator<Item = Axial> {
    (0..6).flat_map(move |j| {
        let d = DIRS[j];
        let e = DIRS[(j + 2) % 6];
        (0..r).map(move |t| (v.0 + r * d.0 + t * e.0, v.1 + r * d.1 + t * e.1))
    })
}

/// Whether `p` lies in the half-sized hexagon of the hexagon with centre `c`, circumradius `r`.
fn in_half_hexagon(p: Vec2, c: Vec2, r: f64) -> bool {
    let q = p - c;
    (0..6).all(|i| {
        let t = std::f64::consts::FRAC_PI_6 + std::f64::consts::FRAC_PI_3 * i as f64;
        q.x * t.cos() + q.y * t.sin() <= 0.25 * SQRT3 * r
    })
}

/// The result of one classification pass.
struct Pass {
    split: Vec<(u32, Axial)>,
    present: Vec<(u32, Axial)>,
    moved: FxHashMap<Key, Vec2>,
}

/// Classifies the leaves (all of them, or those in `region`) and the occupied hexagons.
fn classify(r: &Refinement, region: Option<&FxHashSet<(u32, Axial)>>) -> Pass {
    let h = &r.hierarchy;
    let f = &h.frame;
    let mut occupied: FxHashMap<(u32, Axial), Vec2> = FxHashMap::default();
    for (i, c) in r.cell_of.iter().enumerate() {
        if let Cell::Full(k, x) = *c {
            occupied.insert((k, x), r.points[i]);
        }
    }
    let mut split: FxHashSet<(u32, Axial)> = FxHashSet::default();
    let mut present: FxHashSet<(u32, Axial)> = FxHashSet::default();
    // Ring memberships: 1-ring of an OCCUPIED_1 / OCCUPIED_2 (with its shift), 2-ring of an
    // OCCUPIED_2.
    let mut ring1_fixed: FxHashSet<(u32, Axial)> = FxHashSet::default();
    let mut ring1_moved: FxHashMap<(u32, Axial), Vec2> = FxHashMap::default();
    let mut ring2: FxHashSet<(u32, Axial)> = FxHashSet::default();
    let mut verify: Vec<(u32, Axial, f64)> = Vec::new();
    for (&(k, x), &p) in &occupied {
        let c = f.position(k, x);
        let rad = f.radius(k);
        let occ2 = !in_half_hexagon(p, c, rad);
        // Ring conflicts between occupied hexagons of one level (section 5.1's rings must not
        // overlap with different roles). Two OCCUPIED_2 two steps apart would move a shared
        // ring hexagon twice: split. Two steps apart with one OCCUPIED_2 (a fixed ring hexagon
        // of the other is moved), or three steps apart with both OCCUPIED_2 (a moved 1-ring
        // hexagon lies in the other's fixed 2-ring): ours, kept when the triangles around the
        // 1-ring still meet the bounds (checked below), else split. Splitting every such pair
        // would put the points in cells too small for section 6.3's edge bound. Four steps
        // apart the rings only share fixed 2-ring hexagons (the paper's Fig. 7).
        let mut must_split = false;
        for dist in 2..=3 {
            for z in ring(x, dist) {
                if let Some(&q) = occupied.get(&(k, z)) {
                    let other = !in_half_hexagon(q, f.position(k, z), rad);
                    match (dist, occ2, other) {
                        (2, true, true) => must_split = true,
                        (2, true, false) | (2, false, true) | (3, true, true) => {
                            verify.push((k, x, (p - q).norm()));
                        }
                        _ => {}
                    }
                }
            }
        }
        if must_split {
            split.insert((k, x));
            continue;
        }
        // Ours: an OCCUPIED_2's moved 1-ring must not touch Ω's boundary (tiling).
        if occ2 && ring(x, 1).any(|z| on_boundary(k, z)) {
            split.insert((k, x));
            continue;
        }
        // Ours: the 2-ring must be unsplit full hexagons of this level (rules 4 and 5 one ring
        // further out): a finer one splits the occupied hexagon, a coarser one is made present.
        let mut rough = false;
        for z in ring(x, 2) {
            if !in_domain(k, z) {
                continue;
            }
            if !h.is_present(k, z) {
                present.insert((k, z));
                rough = true;
            } else if h.is_split(k, z) {
                split.insert((k, x));
                rough = true;
            }
        }
        if rough {
            continue;
        }
        if occ2 {
            // Corner nearest to p: corners at 60° i.
            let q = p - c;
            let a = q.y.atan2(q.x);
            let i = (a / std::f64::consts::FRAC_PI_3).round() as i64;
            let t = std::f64::consts::FRAC_PI_3 * i as f64;
            let shift = Vec2::new(t.cos(), t.sin()) * (0.5 * rad);
            for z in ring(x, 1) {
                ring1_moved.insert((k, z), shift);
            }
            for z in ring(x, 2) {
                ring2.insert((k, z));
            }
        } else {
            for z in ring(x, 1) {
                ring1_fixed.insert((k, z));
            }
        }
    }
    // Fixed means: no fins, not occupied, not moved in a ring.
    let fixed = |k: u32, v: Axial| -> bool {
        h.is_present(k, v)
            && !h.is_split(k, v)
            && fin_mask(h, k, v) == 0
            && !occupied.contains_key(&(k, v))
            && !ring1_moved.contains_key(&(k, v))
    };
    let mut moved: FxHashMap<Key, Vec2> = FxHashMap::default();
    let mut visit = |k: u32, v: Axial| {
        let mask = fin_mask(h, k, v);
        if mask == 0 {
            if let Some(s) = ring1_moved.get(&(k, v)) {
                moved.insert(pack(k, v), f.position(k, v) + s);
            }
            return;
        }
        let Some((j, n)) = consecutive(mask) else {
            split.insert((k, v)); // SUBDIVIDE (and, here, MOVED_CENTER_3).
            return;
        };
        if ring1_fixed.contains(&(k, v))
            || ring1_moved.contains_key(&(k, v))
            || ring2.contains(&(k, v))
            || occupied.contains_key(&(k, v))
        {
            split.insert((k, v));
            return;
        }
        for d in DIRS {
            let y = add(v, d);
            if h.is_present(k, y) && !h.is_split(k, y) {
                let my = fin_mask(h, k, y);
                let adjacent_fins =
                    mask | (mask << 1) | (mask >> 1) | ((mask & 1) << 5) | ((mask >> 5) & 1);
                if my != 0 && my & adjacent_fins == 0 {
                    split.insert((k, v));
                    return;
                }
            }
        }
        let c2 = (2 * v.0, 2 * v.1);
        let a = add(c2, add(DIRS[j], DIRS[j])); // centre of the fin's far full hexagon
        let (target, w) = if n == 1 {
            if !fixed(k + 1, a) {
                split.insert((k, v));
                return;
            }
            (f.position(k + 1, a), 1.0 / 6.0)
        } else {
            let j1 = (j + 1) % 6;
            let b = add(c2, add(DIRS[j1], DIRS[j1]));
            let ab = add(c2, add(DIRS[j], DIRS[j1]));
            if !fixed(k + 1, a) || !fixed(k + 1, b) || !fixed(k + 1, ab) {
                split.insert((k, v));
                return;
            }
            (f.position(k + 1, ab), 0.4)
        };
        let c = f.position(k, v);
        // A boundary centre may only slide along Ω's edge: one fin, towards a boundary
        // neighbour.
        // Ω's corners stay put (the triangles must tile Ω).
        let corner = v.0 == 0 || v.1 == 0 || v.0 + v.1 == 0;
        if on_boundary(k, v) && (corner || !(n == 1 && on_boundary(k, add(v, DIRS[j])))) {
            split.insert((k, v));
            return;
        }
        moved.insert(pack(k, v), c + (target - c) * w);
    };
    match region {
        None => for_each_leaf(h, &mut visit),
        Some(set) => {
            // The fans checked below need the relocations of the occupied hexagons' 2-rings.
            let extra = verify
                .iter()
                .flat_map(|&(k, x, _)| disc(x, 2).map(move |z| (k, z)));
            let mut seen: FxHashSet<(u32, Axial)> = FxHashSet::default();
            for (k, v) in set.iter().copied().chain(extra) {
                if h.is_present(k, v) && !h.is_split(k, v) && seen.insert((k, v)) {
                    visit(k, v);
                }
            }
        }
    }
    // The waived ring conflicts: every triangle around the 1-ring of such an occupied hexagon
    // (all lattice triangles of its level, by the 2-ring rule) must keep its angles in
    // [α, 90°] and its edges at least section 6.3's d·√7/(12√3) for the pair's distance d.
    let at = |k: u32, v: Axial| -> Vec2 {
        if let Some(&p) = occupied.get(&(k, v)) {
            p
        } else {
            moved
                .get(&pack(k, v))
                .copied()
                .unwrap_or_else(|| f.position(k, v))
        }
    };
    let cos_lo = (ANGLE_MIN - 1e-9).to_radians().cos();
    for &(k, x, dist) in &verify {
        if split.contains(&(k, x)) {
            continue;
        }
        // Section 6.3's bound for the pair.
        let min_edge = dist * 7f64.sqrt() / (12.0 * SQRT3) * (1.0 + 1e-9);
        let ok = ring(x, 1).all(|y| {
            (0..6).all(|i| {
                let p = [y, add(y, DIRS[i]), add(y, DIRS[(i + 1) % 6])].map(|v| at(k, v));
                (0..3).all(|j| {
                    let (u, w) = (p[(j + 1) % 3] - p[j], p[(j + 2) % 3] - p[j]);
                    let c = u.dot(&w) / (u.norm() * w.norm());
                    u.perp(&w) > 0.0 && c >= -1e-12 && c <= cos_lo && u.norm() >= min_edge
                })
            })
        });
        if !ok {
            split.insert((k, x));
        }
    }
    let mut split: Vec<_> = split.into_iter().collect();
    split.sort_unstable();
    let mut present: Vec<_> = present.into_iter().collect();
    present.sort_unstable();
    Pass {
        split,
        present,
        moved,
    }
}

/// Which leaves the next extended pass must classify: after splits, only those near them
/// (the work-queue design of the simple refinement, one pass per wave of splits); otherwise
/// all of them. A run ends only after a full pass finds nothing, so the result is the same
/// fixed point a sequence of full passes reaches, at O(changes) cost per incremental pass.
#[derive(Debug, Clone, Default)]
pub struct ExtendedState {
    changes: Option<Vec<(u32, Axial)>>,
}

impl ExtendedState {
    /// Forces a full pass next (after insertions).
    pub fn reset(&mut self) {
        self.changes = None;
    }

    /// Records splits made outside the extended passes (simple rules, balancing).
    pub fn record(&mut self, made: &[(u32, Axial)]) {
        if let Some(c) = &mut self.changes {
            c.extend_from_slice(made);
        }
    }
}

/// Lattice points within hexagonal distance `r` of `v`.
fn disc(v: Axial, r: i64) -> impl Iterator<Item = Axial> {
    (-r..=r).flat_map(move |a| ((-r).max(-a - r)..=r.min(-a + r)).map(move |b| (v.0 + a, v.1 + b)))
}

/// Leaves whose classification a split of `(k, x)` may change: its level within two steps
/// (fins, neighbours' fins, rings), the coarser level within three, the finer within four
/// (new leaves and the fin-adjacent hexagons of 5.2's fourth rule).
fn candidates(changes: &[(u32, Axial)]) -> FxHashSet<(u32, Axial)> {
    let mut out = FxHashSet::default();
    for &(k, x) in changes {
        out.extend(disc(x, 2).map(|z| (k, z)));
        if k >= 1 {
            out.extend(disc((x.0.div_euclid(2), x.1.div_euclid(2)), 3).map(|z| (k - 1, z)));
        }
        out.extend(disc((2 * x.0, 2 * x.1), 4).map(|z| (k + 1, z)));
    }
    out
}

/// One extended step on a refinement whose simple rules are exhausted: classifies (near the
/// last changes, or everywhere) and splits every hexagon an extended rule marks. Returns the
/// splits made; empty once a full pass finds nothing.
pub fn extended_pass(
    r: &mut Refinement,
    state: &mut ExtendedState,
) -> Result<Vec<(u32, Axial)>, HexDelaunayError> {
    loop {
        let region = state.changes.take().map(|c| candidates(&c));
        let full = region.is_none();
        let pass = classify(r, region.as_ref());
        let mut made = Vec::new();
        for (k, x) in pass.split {
            made.extend(r.split_now(k, x)?);
        }
        for (k, x) in pass.present {
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

/// The relocated centres (section 5.4) of the finished extended refinement.
pub fn relocated_centres(r: &Refinement) -> FxHashMap<Key, Vec2> {
    classify(r, None).moved
}
