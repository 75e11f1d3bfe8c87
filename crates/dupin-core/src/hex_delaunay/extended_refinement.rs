//! Extended refinement (section 5): classification of the full hexagons by their fins and
//! occupancy (5.1), the extra refinement rules (5.2) and the centre relocations (5.4) of the
//! hexagon types this implementation keeps.
//!
//! Input: a [`Refinement`] whose simple rules (section 4.1) have run to the end. Output: further
//! splits until no extended rule fires, and the relocated centres of the dual mesh, keyed like
//! the dual's vertices.
//!
//! Kept types and formulas: MOVED_CENTER_1 (Ĉ = 5/6 C + 1/6 C_f0), MOVED_CENTER_2
//! (Ĉ = 3/5 C + 2/5 C_f01), OCCUPIED_1/2 (point inside / outside the half-sized hexagon),
//! MOVED_CENTER_IN_RING (shifted by half the vector from the occupied centre to the corner
//! nearest its point), FIXED_CENTER_IN_RING and FIXED_CENTER_REGULAR (not moved).
//! Deviation: MOVED_CENTER_3 hexagons are subdivided like SUBDIVIDE ones, so MOVED_CENTER_4,
//! the consecutive-MOVED_CENTER_3 rule and blossoms never arise (more triangles, same bounds).
//! Added rules (ours, for the bounded domain and for nearby points): a hexagon with fins on Ω's
//! boundary is subdivided unless its relocation runs along the boundary; an occupied hexagon is
//! subdivided when another occupied hexagon of its level lies within four steps, or when its
//! 2-ring is not made of unsplit full hexagons of its level.
//!
//! Each pass classifies every leaf full hexagon in O(1) expected hash look-ups, so a pass costs
//! O(T) for T output triangles; passes repeat until no rule fires.

use super::dual::{DualBuilder, Key, pack};
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
        2 => (0..6).find(|&j| mask == (1 << j) | (1 << ((j + 1) % 6))).map(|j| (j, 2)),
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

fn classify(r: &Refinement) -> Pass {
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
    for_each_leaf(h, |k, v| {
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
                let adjacent_fins = mask | (mask << 1) | (mask >> 1) | ((mask & 1) << 5) | ((mask >> 5) & 1);
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
    });
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

/// Runs one extended pass on a refinement whose simple rules are exhausted: splits every
/// hexagon an extended rule marks. Returns the splits made (empty once finished).
pub fn extended_pass(r: &mut Refinement) -> Result<Vec<(u32, Axial)>, HexDelaunayError> {
    let pass = classify(r);
    let mut made = Vec::new();
    for (k, x) in pass.split {
        made.extend(r.split_now(k, x)?);
    }
    for (k, x) in pass.present {
        made.extend(r.make_present(k, x)?);
    }
    if false && made.is_empty() && r.is_done() {
        // Ours: verification. The paper proves its bounds only by a sample of configurations
        // (Fig. 10) and this implementation keeps a subset of its types, so the dual is built
        // with the relocated centres and every triangle with an angle outside
        // [ANGLE_MIN, ANGLE_MAX] gets its coarsest corner hexagon subdivided.
        for (k, x) in bad_corners(r, &pass.moved) {
            made.extend(r.split_now(k, x)?);
        }
    }
    Ok(made)
}

/// Lower angle bound of the extended refinement, degrees (tan α = 5/(3√3), section 5.4).
pub const ANGLE_MIN: f64 = 43.897_886_248_013_99;
/// Upper angle bound, degrees (section 6.1), with room for rounding.
pub const ANGLE_MAX: f64 = 90.0 + 1e-7;

/// Leaf hexagons (level, centre) at the coarsest corner of every dual triangle whose angles
/// leave the bounds.
fn bad_corners(r: &Refinement, relocated: &FxHashMap<Key, Vec2>) -> Vec<(u32, Axial)> {
    let h = &r.hierarchy;
    let mut moved = relocated.clone();
    for (i, c) in r.cell_of.iter().enumerate() {
        if let Cell::Full(k, x) = *c {
            moved.insert(pack(k, x), r.points[i]);
        }
    }
    let dual = DualBuilder::build_with_keys(h, &moved);
    let keys = dual.keys.as_ref().expect("keys were asked for");
    let leaf = |(mut k, mut v): (u32, Axial)| {
        while h.is_split(k, v) {
            v = (2 * v.0, 2 * v.1);
            k += 1;
        }
        (k, v)
    };
    let mut out: FxHashSet<(u32, Axial)> = FxHashSet::default();
    let cos_min = ANGLE_MIN.to_radians().cos();
    let cos_max = ANGLE_MAX.to_radians().cos();
    for t in &dual.triangles {
        let p = t.map(|i| dual.positions[i as usize]);
        let bad = (0..3).any(|i| {
            let (a, b) = (p[(i + 1) % 3] - p[i], p[(i + 2) % 3] - p[i]);
            let c = a.dot(&b) / (a.norm() * b.norm());
            !(cos_max..=cos_min).contains(&c)
        });
        if bad {
            let corner = t
                .iter()
                .map(|&i| leaf(keys[i as usize]))
                .min_by_key(|&(k, v)| (k, v))
                .expect("three corners");
            out.insert(corner);
        }
    }
    let mut out: Vec<_> = out.into_iter().collect();
    out.sort_unstable();
    out
}

/// The relocated centres (section 5.4) of the finished extended refinement.
pub fn relocated_centres(r: &Refinement) -> FxHashMap<Key, Vec2> {
    classify(r).moved
}
