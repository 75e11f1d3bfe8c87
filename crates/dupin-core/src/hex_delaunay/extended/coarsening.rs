//! Local coarsening into blossoms (section 5.3: "as fine as necessary but as coarse as
//! possible").
//!
//! Input: a finished extended refinement (every rule of sections 4.1 and 5.2 at its fixed
//! point). Output: the hexagons merged (section 3.2), seven per blossom, after which the
//! extended passes run again to their fixed point (the stepper shows the coarsening as its own
//! step).
//!
//! A blossom is six MOVED_CENTER_3 hexagons around a common top `t` (level `k`). It is formed
//! from a region of uniform level `k + 1`: when `t`, its six neighbours and its 2-ring are
//! split at level `k`, the disc of radius 3 around `2t` at level `k + 1` is 37 full hexagons;
//! merging `t` and its six neighbours (each merge scales the central child up and breaks its
//! joins, section 3.2) replaces them by 7 hexagons whose 18 outer semi-hexagons are the fins of
//! the six neighbours, three each, facing away from `t`. In the dual the disc of radius 4
//! around `2t` is 60 triangles instead of 96. The paper's condition: all hexagons in the
//! 4-ring of the blossom's centre are FIXED_CENTER_REGULAR. Ours, which that means on the
//! lattice plus the conditions of our run check (`refinement.rs`, `analyse_run`):
//!
//! - the disc of radius 5 around `2t` at level `k + 1` has no split hexagon (the 4-ring has no
//!   fins) and lies off Ω's boundary;
//! - no occupied hexagon of level `k + 1` within 5 steps of `2t`, nor an OCCUPIED_2 at 6 (no
//!   4-ring hexagon in a 1-ring or an OCCUPIED_2's 2-ring), none of level `k` within 3 steps of
//!   `t` (the run check's "no occupied hexagon within two steps of a run hexagon");
//! - no 4-ring hexagon is the top of a MOVED_CENTER_3 (it is then MOVED_CENTER_4);
//! - no segment within three radii of `t` or of a petal (section 7.2, as for runs).
//!
//! Then every triangle outside the disc of radius 4 is the same triangle as before, with the
//! same corners (the 4-ring stays fixed, nothing else changes class), and the blossom's own 60
//! triangles are the paper's configuration, which the run check verifies (angles in [α, 90°],
//! edges at least √7/2 of the fin level's radius), so the guarantees are unchanged; the final
//! extended passes confirm the fixed point (a blossom they reject would be split again).
//!
//! Cost: candidates come from a bit-parallel scan of the split tiles of each level (the
//! 2-ring split, the next level unsplit within 5 steps of `2t`: `Hierarchy::
//! for_each_blossom_top`), each then checked with a few tile reads, so the pass is O(S) for S
//! split hexagons, with no search per candidate. Candidates are taken in order and checked on
//! the current hierarchy, so two blossoms never overlap (their 5-discs are disjoint).

use super::refinement::{in_half_hexagon, ring, tops_mask};
use crate::hex_delaunay::hierarchy::WINDOW_DISC2;
use crate::hex_delaunay::lattice::{Axial, DIRS, add, hex_norm};
use crate::hex_delaunay::pslg::near_segment;
use crate::hex_delaunay::simple_refinement::Refinement;

/// What one coarsening pass did.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Coarsening {
    /// The blossoms formed: level and top `t` (the blossom's centre is `2t` one level finer).
    pub blossoms: Vec<(u32, Axial)>,
    /// The hexagons merged (seven per blossom: the top, then its neighbours in `DIRS` order).
    pub merged: Vec<(u32, Axial)>,
}

/// Whether a blossom can be formed around `t` at level `k` (see the module docs), for a
/// candidate `t` of [`Hierarchy::for_each_blossom_top`](crate::hex_delaunay::hierarchy::Hierarchy).
fn blossom_fits(r: &Refinement, segments: &[[u32; 2]], k: u32, t: Axial) -> bool {
    let h = &r.hierarchy;
    // `t` comes from `for_each_blossom_top`; merges since (earlier blossoms of this level)
    // only unsplit hexagons of level `k`, so the next level stays unsplit around `2t`, and
    // the 2-ring is read again (all its children present then).
    if k == 0 || h.split_window(k, t) & WINDOW_DISC2 != WINDOW_DISC2 {
        return false;
    }
    debug_assert!(!h.any_split_within(k + 1, (2 * t.0, 2 * t.1), 5));
    let fine = k + 1;
    let c = (2 * t.0, 2 * t.1);
    // Level-(k+1) boundary points have hexagonal norm 2^k: the 5-disc strictly inside.
    if hex_norm(c) + 5 >= 1i64 << k {
        return false;
    }
    let f = &h.frame;
    let occ = r.occupied_full();
    if occ.any_in_disc(k, t, 3) || occ.any_in_disc(fine, c, 5) {
        return false;
    }
    // At distance 6 only an OCCUPIED_2 reaches the 4-ring (with its 2-ring).
    let rad = f.radius(fine);
    let mut occupied_near = false;
    occ.for_each_in_stadium(fine, c.0, (c.1, c.1), 6, |z| {
        occupied_near |= r
            .point_in(fine, z)
            .is_some_and(|p| !in_half_hexagon(p, f.position(fine, z), rad));
    });
    if occupied_near || ring(c, 4).any(|z| tops_mask(h, fine, z) != 0) {
        return false;
    }
    if !segments.is_empty() {
        let reach = 3.0 * f.radius(k);
        let centres = std::iter::once(t).chain(DIRS.iter().map(|&d| add(t, d)));
        for y in centres {
            if near_segment(&r.points, segments, f.position(k, y), reach) {
                return false;
            }
        }
    }
    true
}

/// One coarsening pass (section 5.3) over a finished extended refinement: forms every blossom
/// the conditions allow, finest level first, and returns what it merged. The caller runs the
/// extended passes again (a full one first).
#[inline(never)] // called once per run; kept out of the stepper for profiles
pub fn coarsen(r: &mut Refinement, segments: &[[u32; 2]]) -> Coarsening {
    let mut out = Coarsening::default();
    let depth = r.hierarchy.depth();
    for k in (1..depth).rev() {
        // Candidates in the tiles' order (deterministic), each checked on the current state.
        let h = &r.hierarchy;
        // From the tiles: the 2-ring split, the next level unsplit within 5 steps of `2t`
        // (bit-parallel, a few shifts per tile row).
        let mut candidates = Vec::new();
        h.for_each_blossom_top(k, |t| candidates.push(t));
        for t in candidates {
            if !blossom_fits(r, segments, k, t) {
                continue;
            }
            for y in std::iter::once(t).chain(DIRS.iter().map(|&d| add(t, d))) {
                r.merge_now(k, y)
                    .expect("a blossom's hexagons have unsplit children");
                out.merged.push((k, y));
            }
            out.blossoms.push((k, t));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use crate::Stepper;
    use crate::Vec2;
    use crate::hex_delaunay::tests::{check_with, paper_data_sets};
    use crate::hex_delaunay::{HexDelaunayMode, HexDelaunayStepper};

    /// The stepper shows the coarsening as its own step; each blossom saves 36 triangles
    /// (96 → 60) against the same run without coarsening, and every guarantee holds after it.
    #[test]
    fn blossoms_replace_96_triangles_by_60() {
        for (name, pts, _) in paper_data_sets().into_iter().take(3) {
            let count = |coarsen: bool| {
                let mut s = if name == "2 close pts" {
                    let c = Vec2::new(0.01, 0.0);
                    HexDelaunayStepper::new_in_domain(
                        &pts,
                        HexDelaunayMode::Extended,
                        c,
                        3f64.sqrt() / 2.0,
                    )
                } else {
                    HexDelaunayStepper::new(&pts, &[], HexDelaunayMode::Extended)
                }
                .unwrap();
                s.set_coarsening(coarsen);
                let mut merged = Vec::new();
                while s.step().unwrap().changed {
                    if !s.last_merges().is_empty() {
                        assert!(merged.is_empty(), "{name}: one coarsening step");
                        assert!(s.last_splits().is_empty(), "{name}");
                        merged = s.last_merges();
                    }
                }
                assert!(s.is_done());
                let t = s.triangulation();
                // The relocations patched after the coarsening equal a new full pass's, which
                // marks nothing.
                let mut again = s.clone();
                assert!(
                    !again.recheck().unwrap(),
                    "{name}: a rule fires after coarsening"
                );
                assert_eq!(again.triangulation(), t, "{name}");
                (
                    check_with(&t, &pts, name, HexDelaunayMode::Extended),
                    merged.len(),
                )
            };
            let (plain, none) = count(false);
            let (coarse, merged) = count(true);
            assert_eq!(none, 0);
            assert_eq!(merged % 7, 0, "{name}");
            println!(
                "{name}: {plain} -> {coarse} triangles, {} blossoms",
                merged / 7
            );
            assert_eq!(plain - coarse, 36 * merged / 7, "{name}");
        }
    }
}
