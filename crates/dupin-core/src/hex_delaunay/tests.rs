//! Property tests of the hexagonal Delaunay triangulation over seeded random input families.

use super::*;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Largest circumradius/(2·inradius) of a triangle with all angles in [30°, 120°]: the
/// 30-30-120 triangle, 1 / (8 sin²15° sin 60°).
const SIMPLE_ASPECT: f64 = 2.154_700_538_379_252;

/// The input families the refinement is tested on: uniform and clustered points and the
/// degenerate sets (collinear, cocircular, lattice-aligned, duplicates, close pairs, one or two
/// points) where lattice rounding and the hierarchy's rules are most easily wrong.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Family {
    Uniform,
    Clustered,
    Collinear,
    Cocircular,
    LatticeAligned,
    Duplicates,
    ClosePairs,
    Single,
    Two,
}

pub(crate) const FAMILIES: [Family; 9] = [
    Family::Uniform,
    Family::Clustered,
    Family::Collinear,
    Family::Cocircular,
    Family::LatticeAligned,
    Family::Duplicates,
    Family::ClosePairs,
    Family::Single,
    Family::Two,
];

pub(crate) fn sample(family: Family, rng: &mut ChaCha8Rng) -> Vec<Vec2> {
    let offset = Vec2::new(
        rng.random_range(-100.0..100.0),
        rng.random_range(-100.0..100.0),
    );
    let scale = 10f64.powf(rng.random_range(-2.0..2.0));
    let u = |rng: &mut ChaCha8Rng| rng.random_range(-1.0..1.0f64);
    let n = rng.random_range(2..24usize);
    let pts: Vec<Vec2> = match family {
        Family::Uniform => (0..n)
            .map(|_| Vec2::new(u(rng), u(rng)) * scale + offset)
            .collect(),
        Family::Clustered => {
            let s = 10f64.powf(rng.random_range(-4.0..-1.0));
            let centres: Vec<Vec2> = (0..rng.random_range(1..4))
                .map(|_| Vec2::new(u(rng), u(rng)))
                .collect();
            (0..n)
                .map(|i| {
                    let c = centres[i % centres.len()];
                    (c + Vec2::new(u(rng), u(rng)) * s) * scale + offset
                })
                .collect()
        }
        Family::Collinear => {
            let t = rng.random_range(0.0..std::f64::consts::PI);
            let d = Vec2::new(t.cos(), t.sin());
            (0..n).map(|_| d * (u(rng) * scale) + offset).collect()
        }
        Family::Cocircular => (0..n)
            .map(|_| {
                let t = rng.random_range(0.0..std::f64::consts::TAU);
                Vec2::new(t.cos(), t.sin()) * scale + offset
            })
            .collect(),
        Family::LatticeAligned => {
            let h = 2f64.powi(rng.random_range(-6..4));
            (0..n)
                .map(|_| {
                    Vec2::new(
                        rng.random_range(-5..6) as f64 * h,
                        rng.random_range(-5..6) as f64 * h,
                    )
                })
                .collect()
        }
        Family::Duplicates => {
            let base: Vec<Vec2> = (0..n.div_ceil(3))
                .map(|_| Vec2::new(u(rng), u(rng)) * scale + offset)
                .collect();
            (0..n).map(|i| base[i % base.len()]).collect()
        }
        Family::ClosePairs => {
            let mut v = Vec::new();
            for _ in 0..rng.random_range(1..4) {
                let p = Vec2::new(u(rng), u(rng));
                let t = rng.random_range(0.0..std::f64::consts::TAU);
                v.push(p);
                v.push(p + Vec2::new(t.cos(), t.sin()) * 1e-9);
            }
            v
        }
        Family::Single => vec![Vec2::new(u(rng), u(rng)) * scale + offset],
        Family::Two => vec![
            Vec2::new(u(rng), u(rng)) * scale + offset,
            Vec2::new(u(rng), u(rng)) * scale + offset,
        ],
    };
    pts
}

fn d_min(points: &[Vec2]) -> f64 {
    let mut d = f64::INFINITY;
    for (i, p) in points.iter().enumerate() {
        for q in &points[i + 1..] {
            if p != q {
                d = d.min((p - q).norm());
            }
        }
    }
    d
}

/// Checks every guarantee of the simple refinement on one input; returns the triangle count.
pub(crate) fn check_simple(points: &[Vec2], what: &str) -> usize {
    let t = hex_delaunay(points, &[], HexDelaunayMode::Simple)
        .unwrap_or_else(|e| panic!("{what}: {e}"));
    check_triangulation(&t, points, what)
}

/// Checks every guarantee of the simple refinement on a result for `points`.
pub(crate) fn check_triangulation(t: &HexTriangulation, points: &[Vec2], what: &str) -> usize {
    check_with(t, points, what, HexDelaunayMode::Simple)
}

/// Largest circumradius/(2·inradius) with angles in [α, 90°] (section 6.2): the right
/// triangle with legs 1 and 3√3/5, 2ρ/φ ≈ 1.20787.
const EXTENDED_ASPECT: f64 = 1.207_87;

/// Shortest edge of the extended mode in terms of the closest pair d. Section 6.3 claims
/// d·√7/(12√3) ≈ 0.1273·d, assuming points are never split apart while six hexagons lie
/// between them; its own ring rules (an OCCUPIED_2's 2-ring fixed) split OCCUPIED_2 pairs three
/// steps apart, where d reaches (3√3 + 2) r. What holds here: every split at the deepest level
/// K is made for a pair with d <= (3√3 + 2) r_K (rule 1: 2 r_K, rule 3: (√3 + 2) r_K, ring
/// conflicts: two or three steps), so leaves have r >= d / (2 (3√3 + 2)), and every edge is at
/// least Fig. 8's √7/2 r: bound √7 d / (4 (3√3 + 2)) ≈ 0.0919·d (measured minimum over the
/// families: see docs/hexdelaunay.md). Section 6.3's own bound fails on
/// `shortest_edge_counterexample`'s three points (0.0989·d).
fn extended_min_edge(d: f64) -> f64 {
    d * 7f64.sqrt() / (4.0 * (3.0 * 3f64.sqrt() + 2.0))
}

/// Checks every guarantee of `mode` on a result for `points`; returns the triangle count.
pub(crate) fn check_with(
    t: &HexTriangulation,
    points: &[Vec2],
    what: &str,
    mode: HexDelaunayMode,
) -> usize {
    let q = triangulation_quality(&t.vertices, &t.triangles);
    assert_eq!(q.inverted, 0, "{what}: inverted triangles");
    assert_eq!(q.nonmanifold_edges, 0, "{what}: non-manifold edges");
    let (lo, hi, aspect) = match mode {
        HexDelaunayMode::Simple => (29.99, 120.01, SIMPLE_ASPECT),
        HexDelaunayMode::Extended => (43.89, 90.0001, EXTENDED_ASPECT),
    };
    // Per triangle, the angle tolerance also allows for the rounding of its corners to f64.
    for tri in &t.triangles {
        let p = tri.map(|i| t.vertices[i as usize]);
        let rel = rounding_tolerance(p);
        let (la, lb, lc) = (
            (p[1] - p[2]).norm(),
            (p[2] - p[0]).norm(),
            (p[0] - p[1]).norm(),
        );
        let area = 0.5 * (p[1] - p[0]).perp(&(p[2] - p[0])).abs();
        let ratio = la * lb * lc / (4.0 * area) / (2.0 * area / (0.5 * (la + lb + lc)));
        assert!(
            ratio <= aspect * (1.0 + 1e-6 + 16.0 * rel),
            "{what}: aspect ratio {ratio}"
        );
        assert_angles_in(p, (lo, hi), what);
    }
    assert!(
        q.min_angle_deg >= lo - 1e-3 && q.max_angle_deg <= hi + 1e-3,
        "{what}: angles {}..{}",
        q.min_angle_deg,
        q.max_angle_deg
    );
    assert_eq!(q.delaunay_violations, 0, "{what}: not Delaunay");
    // Tiling: the signed areas add up to Ω's area and the boundary edges lie on Ω's boundary.
    // Tolerance: 1e-9 relative, plus the rounding of boundary vertices to f64 (64 ulp of the
    // coordinates' magnitude along the perimeter), which dominates only for tiny offset domains.
    let area = t.domain_area();
    let perimeter: f64 = (0..6)
        .map(|i| (t.domain[i] - t.domain[(i + 1) % 6]).norm())
        .sum();
    let mag = t
        .domain
        .iter()
        .map(|p| p.x.abs().max(p.y.abs()))
        .fold(0.0, f64::max);
    assert!(
        (q.area - area).abs() <= 1e-9 * area + perimeter * 64.0 * f64::EPSILON * mag,
        "{what}: area {} vs {}",
        q.area,
        area
    );
    let mut boundary = 0.0;
    let mut directed = rustc_hash::FxHashSet::default();
    for tri in &t.triangles {
        for i in 0..3 {
            directed.insert((tri[i], tri[(i + 1) % 3]));
        }
    }
    for &(a, b) in &directed {
        if !directed.contains(&(b, a)) {
            let (p, r) = (t.vertices[a as usize], t.vertices[b as usize]);
            boundary += (p - r).norm();
            let on_edge = (0..6).any(|i| {
                let (c0, c1) = (t.domain[i], t.domain[(i + 1) % 6]);
                let e = c1 - c0;
                let dist = |x: Vec2| e.perp(&(x - c0)).abs() / e.norm();
                // Absolute rounding of coordinates of magnitude `mag` allowed on top.
                let mag = c0.x.abs().max(c0.y.abs());
                let tol = 1e-9 * e.norm() + 64.0 * f64::EPSILON * mag;
                dist(p) <= tol && dist(r) <= tol
            });
            assert!(on_edge, "{what}: boundary edge off Ω's boundary");
        }
    }
    assert!(
        (boundary - perimeter).abs() <= 1e-9 * perimeter,
        "{what}: boundary length {boundary} vs {perimeter}"
    );
    // Input points are vertices with their exact coordinates.
    assert_eq!(t.input_vertex.len(), points.len());
    for (i, p) in points.iter().enumerate() {
        let v = t.input_vertex[i] as usize;
        assert!(v < t.vertices.len(), "{what}: point {i} is not a vertex");
        assert_eq!(t.vertices[v], *p, "{what}: point {i} moved");
    }
    // Minimum edge in terms of the closest pair d. Section 6.3's d·√7/(12√3) is derived for the
    // extended refinement (OCCUPIED_1 rings). For the simple refinement: the first split at the
    // deepest level K comes from rule 1, 3 or 3b, so two points lie in hexagons at most two
    // steps apart there, d <= (2√3 + 2) r_K; an occupied leaf has r >= r_K / 2 and its point is
    // at least (√3/2) r from the ring centres, lattice edges are at least √3 r_K / 2. Hence
    // every edge is >= √3 d / (8 (√3 + 1)) ≈ 0.0793 d (measured minimum over the families:
    // 0.0908 d).
    let d = d_min(points);
    if d.is_finite() {
        let bound = match mode {
            HexDelaunayMode::Simple => d * 3f64.sqrt() / (8.0 * (3f64.sqrt() + 1.0)),
            HexDelaunayMode::Extended => extended_min_edge(d),
        };
        assert!(
            q.min_edge >= bound * (1.0 - 1e-9),
            "{what}: shortest edge {} below {}",
            q.min_edge,
            bound
        );
    }
    t.triangles.len()
}

fn run_families(per_family: usize) {
    for (fi, family) in FAMILIES.iter().enumerate() {
        let mut rng = ChaCha8Rng::seed_from_u64(1000 + fi as u64);
        for case in 0..per_family {
            let pts = sample(*family, &mut rng);
            check_simple(&pts, &format!("{family:?} case {case}"));
        }
    }
}

#[test]
fn simple_guarantees_over_seeded_families() {
    run_families(1000);
}

#[test]
#[ignore = "the full 10^4 inputs per family (minutes); run with --ignored (release-like core)"]
fn simple_guarantees_over_seeded_families_full() {
    run_families(10_000);
}

#[test]
fn larger_uniform_sets() {
    let mut rng = ChaCha8Rng::seed_from_u64(99);
    for n in [100, 500, 2000] {
        let pts: Vec<Vec2> = (0..n)
            .map(|_| Vec2::new(rng.random::<f64>(), rng.random::<f64>()))
            .collect();
        check_simple(&pts, &format!("uniform {n}"));
    }
}

/// The dual of a finished extended run takes the relocations of the last full pass; a second
/// call computes them anew and must agree (a stale cache would differ).
#[test]
fn extended_cached_relocation_matches_a_new_full_pass() {
    let mut rng = ChaCha8Rng::seed_from_u64(17);
    for family in FAMILIES {
        let pts = sample(family, &mut rng);
        let mut s = HexDelaunayStepper::new(&pts, &[], HexDelaunayMode::Extended).unwrap();
        s.run_to_end().unwrap();
        let cached = s.triangulation();
        assert_eq!(cached, s.triangulation(), "{family:?}");
    }
}

/// The angle error (radians) the rounding of a triangle's corners to f64 can cause: 4 ulp of
/// the coordinates' magnitude over its shortest edge (only matters for points 1e-9 apart at unit
/// offset, where an exact right angle of the lattice reads 90.0001 degrees after rounding).
pub(super) fn rounding_tolerance(p: [Vec2; 3]) -> f64 {
    let mag = p
        .iter()
        .map(|v| v.x.abs().max(v.y.abs()))
        .fold(0.0, f64::max);
    let short = (0..3)
        .map(|i| (p[i] - p[(i + 1) % 3]).norm())
        .fold(f64::INFINITY, f64::min);
    4.0 * f64::EPSILON * mag / short
}

/// Asserts that every angle of triangle `p` is in [`lo`, `hi`] degrees, up to
/// [`rounding_tolerance`].
pub(super) fn assert_angles_in(p: [Vec2; 3], (lo, hi): (f64, f64), what: &str) {
    let tol = rounding_tolerance(p).to_degrees();
    for i in 0..3 {
        let a = (p[(i + 1) % 3] - p[i])
            .angle(&(p[(i + 2) % 3] - p[i]))
            .to_degrees();
        assert!(
            a >= lo - tol && a <= hi + tol,
            "{what}: angle {a} outside [{lo}, {hi}] (rounding tolerance {tol})"
        );
    }
}

/// Simple for even cases, extended for odd ones: the two modes over one sample sequence.
pub(super) fn alternate_mode(case: usize) -> HexDelaunayMode {
    if case.is_multiple_of(2) {
        HexDelaunayMode::Simple
    } else {
        HexDelaunayMode::Extended
    }
}

#[test]
fn stepper_matches_one_shot_and_cells_tile() {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    for case in 0..60 {
        let pts = sample(FAMILIES[case % 9], &mut rng);
        let mode = alternate_mode(case);
        let one = hex_delaunay(&pts, &[], mode).unwrap();
        let mut s = HexDelaunayStepper::new(&pts, &[], mode).unwrap();
        let mut steps = 0;
        while s.step().unwrap().changed {
            steps += 1;
            // A step splits, or is the coarsening into blossoms (extended mode).
            assert!(!s.last_splits().is_empty() || !s.last_merges().is_empty());
            assert!(steps < 100_000, "stepper does not terminate");
        }
        assert!(s.is_done());
        assert_eq!(s.triangulation(), one);
        // The leaf cells cover the root hexagon: full hexagons and semi-hexagons with the right
        // areas add up to the root's area (boundary cells drawn whole).
        let cells = s.cells();
        assert!(cells.iter().filter(|c| c.occupied).count() >= 1);
        for c in &cells {
            assert!(c.corners.len() == 6 || c.corners.len() == 4, "{c:?}");
            assert_eq!(c.corners.len() == 6, c.paper_level % 2 == 0);
        }
    }
}

#[test]
fn bad_input_is_refused() {
    assert_eq!(
        hex_delaunay(&[], &[], HexDelaunayMode::Simple),
        Err(HexDelaunayError::Empty)
    );
    let nan = [Vec2::new(0.0, 0.0), Vec2::new(f64::NAN, 1.0)];
    assert_eq!(
        hex_delaunay(&nan, &[], HexDelaunayMode::Simple),
        Err(HexDelaunayError::NonFinite { index: 1 })
    );
    let inf = [Vec2::new(f64::INFINITY, 1.0)];
    assert!(matches!(
        hex_delaunay(&inf, &[], HexDelaunayMode::Simple),
        Err(HexDelaunayError::NonFinite { index: 0 })
    ));
    let big = [Vec2::new(1e200, 0.0), Vec2::new(0.0, 0.0)];
    assert!(matches!(
        hex_delaunay(&big, &[], HexDelaunayMode::Simple),
        Err(HexDelaunayError::TooLarge { index: 0, .. })
    ));
    let tiny = [Vec2::new(0.0, 0.0), Vec2::new(1e-200, 0.0)];
    assert!(matches!(
        hex_delaunay(&tiny, &[], HexDelaunayMode::Simple),
        Err(HexDelaunayError::TooSmall { .. })
    ));
    // Two points far closer than double precision can separate at their offset: depth cap.
    let close = [Vec2::new(1e6, 0.0), Vec2::new(1e6 + 1e-9, 0.0)];
    assert_eq!(
        hex_delaunay(&close, &[], HexDelaunayMode::Simple),
        Err(HexDelaunayError::DepthLimit { max_level: 0 })
    );
    // The cap reached in the middle of refinement.
    let close = [
        Vec2::new(0.0, 0.0),
        Vec2::new(10.0, 0.0),
        Vec2::new(1e-12, 0.0),
    ];
    assert_eq!(
        hex_delaunay(&close, &[], HexDelaunayMode::Simple),
        Err(HexDelaunayError::DepthLimit { max_level: 41 })
    );
    let pts = [
        Vec2::new(0.0, 0.0),
        Vec2::new(1.0, 1.0),
        Vec2::new(0.0, 1.0),
        Vec2::new(1.0, 0.0),
    ];
    assert_eq!(
        hex_delaunay(&pts, &[[0, 7]], HexDelaunayMode::Simple),
        Err(HexDelaunayError::SegmentIndex {
            segment: 0,
            index: 7,
            points: 4
        })
    );
    assert_eq!(
        hex_delaunay(&pts, &[[0, 1], [2, 3]], HexDelaunayMode::Simple),
        Err(HexDelaunayError::SegmentsCross {
            first: 0,
            second: 1
        })
    );
    assert_eq!(
        hex_delaunay(&pts, &[[0, 0]], HexDelaunayMode::Simple),
        Err(HexDelaunayError::DegenerateSegment { segment: 0 })
    );
    // Valid segments are triangulated (section 7, see pslg.rs).
    let t = hex_delaunay(&pts, &[[0, 2]], HexDelaunayMode::Extended).unwrap();
    assert!(!t.segment_edges.is_empty());
    // Bad input is refused the same way in the extended mode.
    assert_eq!(
        hex_delaunay(&nan, &[], HexDelaunayMode::Extended),
        Err(HexDelaunayError::NonFinite { index: 1 })
    );
    assert!(matches!(
        hex_delaunay(&close, &[], HexDelaunayMode::Extended),
        Err(HexDelaunayError::DepthLimit { .. })
    ));
}

#[test]
fn incremental_insertion_keeps_the_guarantees() {
    let mut rng = ChaCha8Rng::seed_from_u64(77);
    for case in 0..300 {
        let mode = if case % 3 == 2 {
            HexDelaunayMode::Extended
        } else {
            HexDelaunayMode::Simple
        };
        let first = sample(FAMILIES[case % 5], &mut rng);
        // Further points inside the hull of the first batch (hence inside Ω), some duplicates,
        // none closer than 1e-6 of the batch's extent to another (or the depth cap is hit).
        let extent = first
            .iter()
            .map(|p| (p - first[0]).norm())
            .fold(0.0, f64::max);
        let mut more: Vec<Vec2> = Vec::new();
        let candidates: Vec<Vec2> = (0..rng.random_range(1..10))
            .map(|_| {
                let (i, j) = (
                    rng.random_range(0..first.len()),
                    rng.random_range(0..first.len()),
                );
                if rng.random_range(0..4) == 0 {
                    first[i]
                } else {
                    let t = rng.random::<f64>();
                    first[i] * t + first[j] * (1.0 - t)
                }
            })
            .collect();
        for c in candidates {
            let near = |p: &Vec2| *p != c && (p - c).norm() < 1e-6 * extent;
            if !first.iter().chain(&more).any(near) {
                more.push(c);
            }
        }
        let mut s = HexDelaunayStepper::new(&first, &[], mode).unwrap();
        s.run_to_end().unwrap();
        let before = s.triangulation();
        s.insert(&more).unwrap();
        s.run_to_end().unwrap();
        let after = s.triangulation();
        assert_eq!(after.domain, before.domain);
        assert!(after.triangles.len() >= before.triangles.len());
        let all: Vec<Vec2> = first.iter().chain(&more).copied().collect();
        check_with(&after, &all, &format!("incremental case {case}"), mode);
    }
    // Outside Ω: refused, nothing inserted.
    let pts = [Vec2::new(0.0, 0.0), Vec2::new(1.0, 0.0)];
    let mut s = HexDelaunayStepper::new(&pts, &[], HexDelaunayMode::Simple).unwrap();
    s.run_to_end().unwrap();
    let n = s.triangulation().input_vertex.len();
    assert_eq!(
        s.insert(&[Vec2::new(0.5, 0.1), Vec2::new(0.5, 10.0)]),
        Err(HexDelaunayError::OutsideDomain { index: 1 })
    );
    assert_eq!(
        s.insert(&[Vec2::new(0.5, f64::NAN)]),
        Err(HexDelaunayError::NonFinite { index: 0 })
    );
    assert_eq!(s.triangulation().input_vertex.len(), n);
}

/// The paper's data sets (Table 1), seeded: two points 0.02 apart, 100 random points on a line,
/// 100 / 1k / 2k random points in the plane. (The IMR letters are a PSLG, not supported yet.)
pub(crate) fn paper_data_sets() -> Vec<(&'static str, Vec<Vec2>, usize)> {
    let mut rng = ChaCha8Rng::seed_from_u64(2008);
    let mut plane = |n: usize| -> Vec<Vec2> {
        (0..n)
            .map(|_| Vec2::new(rng.random::<f64>(), rng.random::<f64>()))
            .collect()
    };
    let p100 = plane(100);
    let p1k = plane(1000);
    let p2k = plane(2000);
    let mut rng = ChaCha8Rng::seed_from_u64(2009);
    let line: Vec<Vec2> = (0..100)
        .map(|_| {
            let t = rng.random::<f64>();
            Vec2::new(t, 0.3 * t)
        })
        .collect();
    vec![
        (
            "2 close pts",
            vec![Vec2::new(0.0, 0.0), Vec2::new(0.02, 0.0)],
            684,
        ),
        ("100 pts on line", line, 18667),
        ("100 pts on plane", p100, 12748),
        ("1k pts on plane", p1k, 127729),
        ("2k pts on plane", p2k, 268138),
    ]
}

/// Triangle count of one of the paper's data sets in `mode`, every guarantee checked.
pub(crate) fn paper_count(name: &str, pts: &[Vec2], mode: HexDelaunayMode) -> usize {
    let t = if name == "2 close pts" {
        // The paper's set-up: a hexagon of unit (circum)radius around the pair.
        let mut s =
            HexDelaunayStepper::new_in_domain(pts, mode, Vec2::new(0.01, 0.0), 3f64.sqrt() / 2.0)
                .unwrap();
        s.run_to_end().unwrap();
        s.triangulation()
    } else {
        hex_delaunay(pts, &[], mode).unwrap()
    };
    check_with(&t, pts, name, mode)
}

#[test]
fn paper_data_sets_take_fewer_triangles_than_table_1() {
    for (name, pts, paper) in paper_data_sets() {
        let simple = paper_count(name, &pts, HexDelaunayMode::Simple);
        if pts.len() > 100 {
            // 1k / 2k in the extended mode: the ignored test below (too slow for debug runs).
            println!("{name}: simple {simple} triangles (paper: {paper})");
            assert!(simple < paper, "{name}: {simple} triangles, paper {paper}");
            continue;
        }
        let extended = paper_count(name, &pts, HexDelaunayMode::Extended);
        println!("{name}: simple {simple}, extended {extended} triangles (paper: {paper})");
        assert!(simple < paper, "{name}: {simple} triangles, paper {paper}");
        // The extended mode still splits MOVED_CENTER_3 runs that fail its local check and
        // forms few blossoms (see extended/refinement.rs, extended/coarsening.rs), so it is not below
        // the paper's counts everywhere; its counts are reported in BENCHMARKS.md, its
        // guarantees checked above.
    }
}

#[test]
#[ignore = "the 1k / 2k sets in the extended mode (BENCHMARKS.md, Table 1); run with --release"]
fn paper_data_sets_extended_large() {
    for (name, pts, paper) in paper_data_sets() {
        if pts.len() > 100 {
            let extended = paper_count(name, &pts, HexDelaunayMode::Extended);
            println!("{name}: extended {extended} triangles (paper: {paper})");
        }
    }
}

/// Checks every guarantee of the extended refinement on one input; returns the triangle count.
pub(crate) fn check_extended(points: &[Vec2], what: &str) -> usize {
    let t = hex_delaunay(points, &[], HexDelaunayMode::Extended)
        .unwrap_or_else(|e| panic!("{what}: {e}"));
    check_with(&t, points, what, HexDelaunayMode::Extended)
}

fn run_families_extended(per_family: usize, seed: u64) {
    for (fi, family) in FAMILIES.iter().enumerate() {
        let mut rng = ChaCha8Rng::seed_from_u64(seed + fi as u64);
        for case in 0..per_family {
            let pts = sample(*family, &mut rng);
            check_extended(
                &pts,
                &format!("extended {family:?} case {case} (seed {seed})"),
            );
        }
    }
}

#[test]
fn extended_guarantees_over_seeded_families() {
    run_families_extended(60, 3000);
}

#[test]
#[ignore = "the full 10^4 inputs per family (minutes); run with --ignored --release"]
fn extended_guarantees_over_seeded_families_full() {
    run_families_extended(10_000, 4000);
}

#[test]
#[ignore = "exploration: counts failures per family (HEXD_PER, HEXD_SEED), fails if any"]
fn explore_extended() {
    let per: usize = std::env::var("HEXD_PER")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(200);
    let seed: u64 = std::env::var("HEXD_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(4000);
    std::panic::set_hook(Box::new(|_| {}));
    let mut total = 0;
    for (fi, family) in FAMILIES.iter().enumerate() {
        let mut rng = ChaCha8Rng::seed_from_u64(seed + fi as u64);
        let mut fails = 0;
        for case in 0..per {
            let pts = sample(*family, &mut rng);
            let what = format!("{family:?} case {case}");
            let r = std::panic::catch_unwind(|| check_extended(&pts, &what));
            if let Err(e) = r {
                fails += 1;
                if fails <= 3 {
                    let msg = e
                        .downcast_ref::<String>()
                        .cloned()
                        .unwrap_or_else(|| "?".into());
                    println!("FAIL {msg}");
                }
            }
        }
        println!("{family:?}: {fails}/{per} failed");
        total += fails;
    }
    assert_eq!(total, 0, "inputs breaking a guarantee");
}

#[test]
#[ignore = "exploration: shortest edge over closest pair, per family"]
fn explore_edge_ratio() {
    for (fi, family) in FAMILIES.iter().enumerate() {
        let mut rng = ChaCha8Rng::seed_from_u64(4000 + fi as u64);
        let mut worst = f64::INFINITY;
        for _ in 0..200 {
            let pts = sample(*family, &mut rng);
            let d = d_min(&pts);
            if !d.is_finite() {
                continue;
            }
            let t = hex_delaunay(&pts, &[], HexDelaunayMode::Extended).unwrap();
            let q = triangulation_quality(&t.vertices, &t.triangles);
            worst = worst.min(q.min_edge / d);
        }
        println!(
            "{family:?}: min edge / d = {worst:.4} (bound {:.4})",
            extended_min_edge(1.0)
        );
        assert!(worst >= extended_min_edge(1.0), "{family:?}");
    }
}

/// Section 6.3's bound d·√7/(12√3) cannot hold with the paper's construction: three points
/// (the worst of a seeded search over 2-4 random points, `explore_edge_ratio_small_inputs`;
/// docs/hexdelaunay.md, "Shortest edge"). Points 1 and 2 (d = d_min = 0.0675) are OCCUPIED_2
/// hexagons three steps apart at level 7 (d = 6.69 r_7, more than the 3√3 r_7 that section
/// 6.3's six hexagons allow), where the half-corner shifts of their 1-rings (section 5.4) with
/// their 2-rings fixed leave a triangle with a 42.5° angle: the pair must be split (the
/// paper's only remedy), and level 8 brings Fig. 8's edge √7/2·r_8 = 0.0989·d. Kept instead
/// of split, the angle bound fails (at level 6 already, 37.5°, if that pair is kept too).
#[test]
fn shortest_edge_counterexample() {
    use super::extended::KEEP_FAILED_CHECKS_FROM;
    let pts = [
        Vec2::new(-0.02704048987050455, 0.2759392856805694),
        Vec2::new(-0.08342531198940248, 0.8513278090847259),
        Vec2::new(-0.09000659602737593, 0.9184876432813776),
    ];
    let d = d_min(&pts);
    assert_eq!(d, (pts[1] - pts[2]).norm());
    let paper = 7f64.sqrt() / (12.0 * 3f64.sqrt());
    let run = |keep_from: u32| {
        KEEP_FAILED_CHECKS_FROM.with(|w| w.set(keep_from));
        let t = hex_delaunay(&pts, &[], HexDelaunayMode::Extended).unwrap();
        KEEP_FAILED_CHECKS_FROM.with(|w| w.set(0));
        let q = triangulation_quality(&t.vertices, &t.triangles);
        (t, q)
    };
    let s = HexDelaunayStepper::new(&pts, &[], HexDelaunayMode::Extended).unwrap();
    let radius = |k: u32| s.refinement().hierarchy.frame.radius(k);
    // As built: every guarantee checked here holds, section 6.3's does not.
    let (t, q) = run(0);
    check_with(&t, &pts, "counterexample", HexDelaunayMode::Extended);
    assert_eq!(
        t.depth, 8,
        "level-7 hexagons are split: leaves down to level 8"
    );
    println!(
        "min edge {:.6} = {:.4} r_8 = {:.4} d (paper {paper:.4} d); d = {:.3} r_7",
        q.min_edge,
        q.min_edge / radius(8),
        q.min_edge / d,
        d / radius(7)
    );
    assert!(
        (q.min_edge / radius(8) - 7f64.sqrt() / 2.0).abs() < 1e-9,
        "Fig. 8's edge"
    );
    assert!(q.min_edge < paper * d);
    assert!(d > 3.0 * 3f64.sqrt() * radius(7));
    // The level-7 pair kept (paper's shifts, no split): an angle below α.
    let (t7, q7) = run(7);
    println!(
        "level-7 pair kept: depth {}, angles {:.4}..{:.4}, min edge {:.4} d",
        t7.depth,
        q7.min_angle_deg,
        q7.max_angle_deg,
        q7.min_edge / d
    );
    assert!(t7.depth == 7 && q7.min_angle_deg < 43.0 && q7.min_edge >= paper * d);
    // Kept from level 6 on: worse.
    let (t6, q6) = run(6);
    println!(
        "level-6 pair kept: depth {}, angles {:.4}..{:.4}",
        t6.depth, q6.min_angle_deg, q6.max_angle_deg
    );
    assert!(t6.depth == 6 && q6.min_angle_deg < 38.0);
}

#[test]
#[ignore = "exploration: the smallest ratios shortest edge / closest pair over 2-4 random points"]
fn explore_edge_ratio_small_inputs() {
    let mut rng = ChaCha8Rng::seed_from_u64(99);
    let per: usize = std::env::var("HEXD_PER")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(20_000);
    for n in 2..=4usize {
        let mut worst = (f64::INFINITY, Vec::new());
        for case in 0..per {
            let pts: Vec<Vec2> = if case % 2 == 0 {
                (0..n)
                    .map(|_| Vec2::new(rng.random_range(0.0..1.0), rng.random_range(0.0..1.0)))
                    .collect()
            } else {
                let t = rng.random_range(0.0..std::f64::consts::PI);
                let d = Vec2::new(t.cos(), t.sin());
                (0..n).map(|_| d * rng.random_range(0.0..1.0)).collect()
            };
            let d = d_min(&pts);
            let t = hex_delaunay(&pts, &[], HexDelaunayMode::Extended).unwrap();
            let q = triangulation_quality(&t.vertices, &t.triangles);
            if q.min_edge / d < worst.0 {
                worst = (q.min_edge / d, pts.clone());
            }
        }
        println!("{n} points: min edge / d = {:.4} at {:?}", worst.0, worst.1);
    }
}
