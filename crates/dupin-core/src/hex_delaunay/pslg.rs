//! PSLG input (section 7): segments assigned to the hexagons they cross, the refinement rules
//! of section 7.2, centres of crossed hexagons moved onto the segments (section 7.3), and the
//! triangles added so that every segment is a union of output edges (section 7.4).
//!
//! Input: the distinct points and segments between them (non-crossing, checked by the stepper).
//! Output: extra splits during refinement ([`segment_pass`]), snapped centre positions for the
//! dual ([`snapped_centres`]) and, on the dual triangles, the segments inserted as edge chains
//! ([`insert_segments`]).
//!
//! Deviations from the paper, each for robustness:
//! - A hexagon crossed by a segment also holding an input point that is not an endpoint of that
//!   segment is split (the paper leaves this case open); input points lying exactly on a
//!   segment split it first ([`split_at_points`]), so this terminates.
//! - Hexagons crossed by two segments meeting at a common endpoint (acute corners) are not
//!   given the paper's doubled centre with its gap triangles (7.4); instead, after snapping,
//!   every segment is walked through the triangles and each triangle edge it still crosses is
//!   split at the crossing point (a Steiner vertex on the segment). This also covers the cases
//!   the paper's snapping leaves open (two snapped centres not adjacent in the dual, a snap
//!   that would invert a triangle: such a snap is undone), so every segment ends up a chain of
//!   edges whatever the configuration.
//! - Which triangles keep the angle bounds: exactly those that do not meet a segment (their
//!   corners are dual vertices the segments never moved, in a hierarchy that satisfies all point
//!   rules), a subset of "one hexagon away" in the paper's wording.

use super::dual::{Key, pack};
use super::error::HexDelaunayError;
use super::hierarchy::{Cell, Hierarchy};
use super::lattice::{Axial, DIRS, add, in_domain};
use super::simple_refinement::Refinement;
use crate::Vec2;
use robust::{Coord, orient2d};
use rustc_hash::{FxHashMap, FxHashSet};

/// Relative tolerance under which a vertex counts as lying on a segment (times the segment's
/// length), and under which a crossing point is merged into an edge's endpoint.
const ON_SEGMENT: f64 = 1e-9;

fn coord(p: Vec2) -> Coord<f64> {
    Coord { x: p.x, y: p.y }
}

/// Splits every segment at the input points lying on it, within `ON_SEGMENT` of its length
/// (points placed "on" a segment by floating-point arithmetic are rarely exactly on it), so
/// that refinement never has to separate a point from a segment through it: separating a
/// point 1e-16 away would need more levels than the depth cap. Returns segments as consecutive
/// point pairs along each original segment.
pub fn split_at_points(points: &[Vec2], segments: &[[u32; 2]]) -> Vec<[u32; 2]> {
    let mut out = Vec::with_capacity(segments.len());
    for &[a, b] in segments {
        let (pa, pb) = (points[a as usize], points[b as usize]);
        let d = pb - pa;
        let len = d.norm();
        let tol = ON_SEGMENT * len;
        let (lo, hi) = (
            pa.inf(&pb) - Vec2::new(tol, tol),
            pa.sup(&pb) + Vec2::new(tol, tol),
        );
        let mut on: Vec<(f64, u32)> = points
            .iter()
            .enumerate()
            .filter(|&(i, p)| {
                i as u32 != a
                    && i as u32 != b
                    && p.x >= lo.x
                    && p.x <= hi.x
                    && p.y >= lo.y
                    && p.y <= hi.y
                    && d.perp(&(*p - pa)).abs() <= tol * len
                    && (*p - pa).dot(&d) > 0.0
                    && (*p - pb).dot(&d) < 0.0
            })
            .map(|(i, p)| ((p - pa).dot(&d), i as u32))
            .collect();
        on.sort_by(|x, y| x.0.total_cmp(&y.0));
        let mut prev = a;
        for (_, i) in on {
            out.push([prev, i]);
            prev = i;
        }
        out.push([prev, b]);
    }
    out
}

/// Whether a segment of `segments` (index pairs into `points`) passes within `dist` of `c`.
/// A scan of all segments: O(segments) per query, only with a PSLG (section 7; a spatial index
/// would make it O(1), not needed for our inputs). The extended refinement's runs and the
/// coarsening's blossoms keep away from segments with it.
pub(crate) fn near_segment(points: &[Vec2], segments: &[[u32; 2]], c: Vec2, dist: f64) -> bool {
    segments.iter().any(|&[i, j]| {
        let (a, b) = (points[i as usize], points[j as usize]);
        let d = b - a;
        let t = ((c - a).dot(&d) / d.norm_squared()).clamp(0.0, 1.0);
        (a + d * t - c).norm() <= dist
    })
}

/// Whether the closed segment `a b` meets the closed hexagon of centre `c`, circumradius `r`
/// (corners at 0°, 60°, ...), inflated by a hair so that touching counts: separating axes.
fn hexagon_meets_segment(c: Vec2, r: f64, a: Vec2, b: Vec2) -> bool {
    let slack = 1e-9 * r;
    let (a, b) = (a - c, b - c);
    // The hexagon's three edge normals (30°, 90°, 150°), its extent along each is r√3/2.
    let h = 0.5 * 3f64.sqrt() * r + slack;
    for t in [30.0f64, 90.0, 150.0] {
        let n = Vec2::new(t.to_radians().cos(), t.to_radians().sin());
        let (x, y) = (a.dot(&n), b.dot(&n));
        if x.min(y) > h || x.max(y) < -h {
            return false;
        }
    }
    // The segment's normal: the hexagon's extent along it is at most r.
    let d = b - a;
    let len = d.norm();
    if len == 0.0 {
        return a.norm() <= r + slack;
    }
    let n = Vec2::new(-d.y, d.x) / len;
    let off = a.dot(&n);
    let ext = (0..6)
        .map(|i| {
            let t = std::f64::consts::FRAC_PI_3 * i as f64;
            (r * (t.cos() * n.x + t.sin() * n.y)).abs()
        })
        .fold(0.0, f64::max);
    off.abs() <= ext + slack
}

/// The leaf cells (full and semi-hexagons) that the segment `a b` meets, each with the segment
/// index: a descent from the root through the split hexagons it meets (a level-`k+1` leaf lies
/// inside the union of its parents' hexagons, so nothing is missed).
fn crossed_leaves(
    h: &Hierarchy,
    a: Vec2,
    b: Vec2,
    seg: u32,
    seen: &mut FxHashSet<(u32, Axial)>,
    out: &mut FxHashMap<Cell, Vec<u32>>,
) {
    let f = &h.frame;
    seen.clear();
    let mut stack = vec![(0u32, (0i64, 0i64))];
    while let Some((k, v)) = stack.pop() {
        let c = (2 * v.0, 2 * v.1);
        for child in std::iter::once(c).chain(DIRS.iter().map(|&d| add(c, d))) {
            let l = k + 1;
            if !in_domain(l, child) || !seen.insert((l, child)) {
                continue;
            }
            if !hexagon_meets_segment(f.position(l, child), f.radius(l), a, b) {
                continue;
            }
            let cell = if !h.is_present(l, child) {
                Cell::Semi(l, child)
            } else if h.is_split(l, child) {
                stack.push((l, child));
                continue;
            } else {
                Cell::Full(l, child)
            };
            let e = out.entry(cell).or_default();
            if e.last() != Some(&seg) {
                e.push(seg);
            }
        }
    }
}

/// All leaf cells met by the segments, with the segments meeting each.
fn crossed_cells(r: &Refinement, segments: &[[u32; 2]]) -> FxHashMap<Cell, Vec<u32>> {
    let mut out = FxHashMap::default();
    let mut seen = FxHashSet::default();
    for (i, &[a, b]) in segments.iter().enumerate() {
        let (pa, pb) = (r.points[a as usize], r.points[b as usize]);
        crossed_leaves(&r.hierarchy, pa, pb, i as u32, &mut seen, &mut out);
    }
    out
}

/// One pass of the segment rules (section 7.2 plus ours) over every leaf a segment meets:
/// - a met boundary hexagon is split (its centre must stay on Ω's boundary, so it cannot move
///   onto a segment);
/// - a met full hexagon whose segments do not all share one endpoint is split (the paper's
///   third rule, generalised to stars of segments at one point);
/// - a met full hexagon holding a point that is not an endpoint of each of its segments is
///   split (ours: the paper leaves a point next to a segment open).
///
/// The paper's first two rules (a met hexagon's neighbours all of its level) are left out:
/// making a met hexagon's neighbour present splits a coarser hexagon that the segment also
/// meets, whose new children need their neighbours present in turn, so the whole strip along
/// a connected PSLG becomes as fine as its finest spot (a point 1e-6 from a unit segment then
/// costs about 10^6 hexagons; measured: 139k triangles and 67 s for one such input). Without
/// them the strip is graded like the rest of the mesh, met semi-hexagons included; the
/// insertion in [`insert_segments`] does not need uniform strips, and the triangles this
/// affects meet the segments, so they are exempt from the bounds either way.
///
/// Returns the splits made, in order; empty when no rule fires.
pub fn segment_pass(
    r: &mut Refinement,
    segments: &[[u32; 2]],
) -> Result<Vec<(u32, Axial)>, HexDelaunayError> {
    let cells = crossed_cells(r, segments);
    let mut split = Vec::new();
    for (cell, segs) in &cells {
        let Cell::Full(k, x) = *cell else { continue };
        if r.hierarchy.on_boundary(k, x) {
            split.push((k, x));
            continue;
        }
        let [a, b] = segments[segs[0] as usize];
        let common = [a, b]
            .into_iter()
            .any(|p| segs.iter().all(|&s| segments[s as usize].contains(&p)));
        let stray = r
            .occupants_of(cell)
            .iter()
            .any(|&p| segs.iter().any(|&s| !segments[s as usize].contains(&p)));
        if !common || stray {
            split.push((k, x));
        }
    }
    // Deterministic order (the map's iteration order is not part of the result).
    split.sort_unstable();
    let mut made = Vec::new();
    for (k, x) in split {
        if !r.hierarchy.is_split(k, x) {
            made.extend(r.split_now(k, x)?);
        }
    }
    Ok(made)
}

/// Section 7.3: for every unoccupied leaf full hexagon met by exactly one segment, the
/// intersection of the segment with the hexagon's axis (line through the centre towards a
/// neighbour) forming the largest angle with it, if that intersection lies within the hexagon
/// (half-open along the axis, so two hexagons on one axis never share it). Keys are the dual's
/// vertex keys; values lie on the segment up to rounding.
pub fn snapped_centres(r: &Refinement, segments: &[[u32; 2]]) -> FxHashMap<Key, Vec2> {
    let h = &r.hierarchy;
    let f = &h.frame;
    let mut out = FxHashMap::default();
    for (cell, segs) in crossed_cells(r, segments) {
        let Cell::Full(k, x) = cell else { continue };
        if segs.len() != 1 || !r.occupants_of(&cell).is_empty() || h.on_boundary(k, x) {
            continue;
        }
        let [a, b] = segments[segs[0] as usize];
        let (s, t) = (r.points[a as usize], r.points[b as usize]);
        let d = t - s;
        let c = f.position(k, x);
        let rad = f.radius(k);
        // Unit axes towards the neighbours at 30°, 90°, 150°.
        let axis = (0..3)
            .map(|i| {
                let p = f.position(k, add(x, DIRS[i])) - c;
                p / p.norm()
            })
            .min_by(|u, v| u.dot(&d).abs().total_cmp(&v.dot(&d).abs()))
            .expect("three axes");
        // c + λ axis = s + τ d.
        let den = axis.perp(&d);
        if den == 0.0 {
            continue;
        }
        let w = s - c;
        let lambda = w.perp(&d) / den;
        let tau = w.perp(&axis) / den;
        let half = 0.5 * 3f64.sqrt() * rad;
        if lambda > -half && lambda <= half && (0.0..=1.0).contains(&tau) {
            out.insert(pack(k, x), s + d * tau);
        }
    }
    out
}

/// A triangle list with directed-edge adjacency, edited in place by the segment insertion.
struct Mesh<'a> {
    pos: &'a mut Vec<Vec2>,
    tris: &'a mut Vec<[u32; 3]>,
    /// Directed edge -> triangle holding it counter-clockwise.
    edge: FxHashMap<(u32, u32), u32>,
    /// One triangle per vertex.
    vt: Vec<u32>,
}

impl Mesh<'_> {
    fn set(&mut self, t: u32, tri: [u32; 3]) {
        let old = self.tris[t as usize];
        for i in 0..3 {
            let e = (old[i], old[(i + 1) % 3]);
            if self.edge.get(&e) == Some(&t) {
                self.edge.remove(&e);
            }
        }
        self.tris[t as usize] = tri;
        for i in 0..3 {
            self.edge.insert((tri[i], tri[(i + 1) % 3]), t);
            self.vt[tri[i] as usize] = t;
        }
    }

    fn push(&mut self, tri: [u32; 3]) {
        let t = self.tris.len() as u32;
        self.tris.push([tri[0], tri[0], tri[0]]);
        self.set(t, tri);
    }

    /// The triangles around interior vertex `c`, each rotated to start at `c`; `None` if the
    /// fan is open (a boundary vertex).
    fn fan(&self, c: u32) -> Option<Vec<[u32; 3]>> {
        let start = self.vt[c as usize];
        let mut t = start;
        let mut out = Vec::new();
        loop {
            let tri = self.tris[t as usize];
            let i = tri.iter().position(|&v| v == c)?;
            let rot = [tri[i], tri[(i + 1) % 3], tri[(i + 2) % 3]];
            out.push(rot);
            // Next counter-clockwise: across edge (c, rot[2]).
            t = *self.edge.get(&(c, rot[2]))?;
            if t == start || out.len() > self.tris.len() {
                return Some(out);
            }
        }
    }

    /// Where a segment crosses an edge within a quarter of its length from the end `v`, moves
    /// `v` onto the segment (orthogonal projection) instead of adding a Steiner vertex, as 7.3
    /// moves centres: fewer slivers. Only for vertices that are not input points or on a segment
    /// already (`fixed`), not on Ω's boundary, whose projection lies ahead on the segment, and
    /// when no triangle around `v` inverts; returns `v` if moved.
    fn pull_onto(
        &mut self,
        v: u32,
        fraction: f64,
        (s, d, here): (Vec2, Vec2, f64),
        fixed: &[bool],
    ) -> Option<u32> {
        if fraction > 0.25 || fixed[v as usize] {
            return None;
        }
        let fan = self.fan(v)?;
        let old = self.pos[v as usize];
        let tau = (old - s).dot(&d) / d.norm_squared();
        if !(tau > here && tau < 1.0) {
            return None;
        }
        self.pos[v as usize] = s + d * tau;
        let ok = fan.iter().all(|t| {
            let p = t.map(|i| coord(self.pos[i as usize]));
            orient2d(p[0], p[1], p[2]) > 0.0
        });
        if ok {
            Some(v)
        } else {
            self.pos[v as usize] = old;
            None
        }
    }

    /// Splits edge (a, b) (and its twin) at the new vertex `q`.
    fn split_edge(&mut self, a: u32, b: u32, q: u32) -> Option<()> {
        let t1 = *self.edge.get(&(a, b))?;
        let t2 = *self.edge.get(&(b, a))?;
        let c = opposite(self.tris[t1 as usize], a, b);
        let d = opposite(self.tris[t2 as usize], b, a);
        self.vt.push(t1);
        self.set(t1, [a, q, c]);
        self.push([q, b, c]);
        self.set(t2, [b, q, d]);
        self.push([q, a, d]);
        Some(())
    }
}

fn opposite(t: [u32; 3], a: u32, b: u32) -> u32 {
    t.into_iter()
        .find(|&v| v != a && v != b)
        .expect("a triangle has a third vertex")
}

/// Inserts the segments (pairs of vertex indices) into the triangulation so that each becomes a
/// chain of edges: walks from one end to the other through the triangles, following an edge
/// where the next vertex lies on the segment (within `ON_SEGMENT`·length), else moving a
/// nearby vertex of the crossed edge onto the segment (see `Mesh::pull_onto`; never a vertex
/// marked in `fixed`, the input points), else splitting the crossed edge at its crossing point
/// (the new vertex lies on the segment up to rounding). Returns the chain edges of all segments.
pub fn insert_segments(
    positions: &mut Vec<Vec2>,
    triangles: &mut Vec<[u32; 3]>,
    segments: &[[u32; 2]],
    mut fixed: Vec<bool>,
) -> Result<Vec<[u32; 2]>, HexDelaunayError> {
    let mut m = Mesh {
        vt: vec![u32::MAX; positions.len()],
        edge: FxHashMap::default(),
        pos: positions,
        tris: triangles,
    };
    m.edge.reserve(3 * m.tris.len());
    for t in 0..m.tris.len() as u32 {
        let tri = m.tris[t as usize];
        for i in 0..3 {
            m.edge.insert((tri[i], tri[(i + 1) % 3]), t);
            m.vt[tri[i] as usize] = t;
        }
    }
    let mut chain: Vec<[u32; 2]> = Vec::new();
    for (segment, &[sv, tv]) in segments.iter().enumerate() {
        let fail = HexDelaunayError::SegmentInsertion { segment };
        let (s, t) = (m.pos[sv as usize], m.pos[tv as usize]);
        let d = t - s;
        let len2 = d.norm_squared();
        let tol = ON_SEGMENT * len2.sqrt();
        let along = |p: Vec2| (p - s).dot(&d) / len2;
        let off = |p: Vec2| d.perp(&(p - s)).abs() / len2.sqrt();
        let mut c = sv;
        let mut steps = 0usize;
        while c != tv {
            steps += 1;
            if steps > m.tris.len() + 8 {
                return Err(fail);
            }
            let fan = m.fan(c).ok_or(fail.clone())?;
            let here = along(m.pos[c as usize]);
            // A neighbour on the segment, ahead: follow its edge.
            let ahead = fan
                .iter()
                .map(|tri| tri[1])
                .filter(|&a| {
                    let p = m.pos[a as usize];
                    a == tv || (off(p) <= tol && along(p) > here && along(p) < 1.0)
                })
                .min_by(|&a, &b| along(m.pos[a as usize]).total_cmp(&along(m.pos[b as usize])));
            let next = match ahead {
                Some(a) => a,
                None => {
                    // The triangle whose corner at c contains the direction to t.
                    let pc = coord(m.pos[c as usize]);
                    let tri = fan
                        .iter()
                        .find(|tri| {
                            orient2d(pc, coord(m.pos[tri[1] as usize]), coord(t)) >= 0.0
                                && orient2d(pc, coord(m.pos[tri[2] as usize]), coord(t)) < 0.0
                        })
                        .ok_or(fail.clone())?;
                    let (a, b) = (tri[1], tri[2]);
                    let (pa, pb) = (m.pos[a as usize], m.pos[b as usize]);
                    let oa = orient2d(coord(s), coord(t), coord(pa));
                    let ob = orient2d(coord(s), coord(t), coord(pb));
                    if oa * ob > 0.0 || oa == ob {
                        return Err(fail);
                    }
                    // Crossing parameters along a b (λ) and along the segment (τ).
                    let lambda = oa / (oa - ob);
                    let e = pb - pa;
                    let lab = e.norm();
                    if lambda * lab <= tol {
                        a
                    } else if (1.0 - lambda) * lab <= tol {
                        b
                    } else if let Some(v) = m.pull_onto(
                        if lambda < 0.5 { a } else { b },
                        lambda.min(1.0 - lambda),
                        (s, d, here),
                        &fixed,
                    ) {
                        v
                    } else {
                        let den = d.perp(&e);
                        let tau = (pa - s).perp(&e) / den;
                        if !(tau.is_finite() && tau > here && tau < 1.0) {
                            return Err(fail);
                        }
                        let q = m.pos.len() as u32;
                        m.pos.push(s + d * tau);
                        fixed.push(true);
                        m.split_edge(a, b, q).ok_or(fail.clone())?;
                        // A chain edge split by the crossing (only under rounding) stays a chain.
                        if let Some(i) = chain.iter().position(|e| *e == [a, b] || *e == [b, a]) {
                            chain[i] = [a, q];
                            chain.push([q, b]);
                        }
                        q
                    }
                }
            };
            chain.push([c, next]);
            fixed[next as usize] = true;
            c = next;
        }
    }
    Ok(chain)
}

/// Moves back every snapped vertex of a triangle that the snapping inverted or flattened
/// (`orig` holds their unsnapped positions), until no triangle is inverted. Unsnapped, the
/// dual is valid, so this ends.
pub fn undo_inverting_snaps(
    positions: &mut [Vec2],
    triangles: &[[u32; 3]],
    orig: &FxHashMap<u32, Vec2>,
) {
    let mut undone: FxHashSet<u32> = FxHashSet::default();
    let affected: Vec<usize> = triangles
        .iter()
        .enumerate()
        .filter(|(_, t)| t.iter().any(|v| orig.contains_key(v)))
        .map(|(i, _)| i)
        .collect();
    loop {
        let mut changed = false;
        for &i in &affected {
            let t = triangles[i];
            let p = t.map(|v| coord(positions[v as usize]));
            if orient2d(p[0], p[1], p[2]) > 0.0 {
                continue;
            }
            for v in t {
                if let Some(&o) = orig.get(&v)
                    && undone.insert(v)
                {
                    positions[v as usize] = o;
                    changed = true;
                }
            }
        }
        if !changed {
            return;
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::super::{HexDelaunayMode, HexTriangulation, hex_delaunay, triangulation_quality};
    use super::*;
    use crate::Stepper;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Whether the closed segment `s t` meets the closed triangle `p` (exact predicates).
    fn meets(p: [Vec2; 3], s: Vec2, t: Vec2) -> bool {
        let o = |a: Vec2, b: Vec2, c: Vec2| orient2d(coord(a), coord(b), coord(c));
        let inside = |q: Vec2| (0..3).all(|i| o(p[i], p[(i + 1) % 3], q) >= 0.0);
        if inside(s) || inside(t) {
            return true;
        }
        (0..3).any(|i| {
            let (a, b) = (p[i], p[(i + 1) % 3]);
            let (o1, o2) = (o(s, t, a), o(s, t, b));
            let (o3, o4) = (o(a, b, s), o(a, b, t));
            o1 * o2 <= 0.0 && o3 * o4 <= 0.0 && !(o1 == 0.0 && o2 == 0.0 && o3 == 0.0)
        })
    }

    /// Checks a PSLG result; returns (triangles, exempt triangles).
    pub(crate) fn check_pslg(
        t: &HexTriangulation,
        points: &[Vec2],
        segments: &[[usize; 2]],
        mode: HexDelaunayMode,
        what: &str,
    ) -> (usize, usize) {
        let v = &t.vertices;
        // Tiling: no inverted triangle, each directed edge once, areas sum to Ω's area, the
        // boundary edges' total length is Ω's perimeter.
        let q = triangulation_quality(v, &t.triangles);
        assert_eq!(q.inverted, 0, "{what}: inverted triangles");
        assert_eq!(q.nonmanifold_edges, 0, "{what}: non-manifold edges");
        let area = t.domain_area();
        assert!(
            (q.area - area).abs() <= 1e-9 * area,
            "{what}: area {} vs {area}",
            q.area
        );
        let mut directed = FxHashSet::default();
        for tri in &t.triangles {
            for i in 0..3 {
                directed.insert((tri[i], tri[(i + 1) % 3]));
            }
        }
        let perimeter: f64 = (0..6)
            .map(|i| (t.domain[i] - t.domain[(i + 1) % 6]).norm())
            .sum();
        let boundary: f64 = directed
            .iter()
            .filter(|(a, b)| !directed.contains(&(*b, *a)))
            .map(|&(a, b)| (v[a as usize] - v[b as usize]).norm())
            .sum();
        assert!(
            (boundary - perimeter).abs() <= 1e-9 * perimeter,
            "{what}: boundary {boundary} vs {perimeter}"
        );
        // Input points are vertices with exact coordinates.
        for (i, p) in points.iter().enumerate() {
            assert_eq!(v[t.input_vertex[i] as usize], *p, "{what}: point {i}");
        }
        // Every segment is a chain of mesh edges from one endpoint to the other through
        // vertices on it (up to rounding: 2e-9 of its length).
        let mut adj: FxHashMap<u32, Vec<u32>> = FxHashMap::default();
        for &(a, b) in &directed {
            adj.entry(a).or_default().push(b);
        }
        let mut on_segment = FxHashSet::default();
        for (i, seg) in segments.iter().enumerate() {
            let (sv, tv) = (t.input_vertex[seg[0]], t.input_vertex[seg[1]]);
            let (s, e) = (v[sv as usize], v[tv as usize]);
            let d = e - s;
            let len2 = d.norm_squared();
            let along = |p: Vec2| (p - s).dot(&d) / len2;
            let off = |p: Vec2| d.perp(&(p - s)).abs() / len2.sqrt();
            let mut c = sv;
            on_segment.insert(c);
            while c != tv {
                let next = adj[&c]
                    .iter()
                    .copied()
                    .filter(|&w| {
                        let p = v[w as usize];
                        w == tv
                            || (off(p) <= 2e-9 * len2.sqrt()
                                && along(p) > along(v[c as usize])
                                && along(p) < 1.0)
                    })
                    .min_by(|&a, &b| along(v[a as usize]).total_cmp(&along(v[b as usize])));
                let Some(next) = next else {
                    panic!("{what}: segment {i} is not a chain of edges");
                };
                c = next;
                on_segment.insert(c);
            }
        }
        for e in &t.segment_edges {
            assert!(directed.contains(&(e[0], e[1])) || directed.contains(&(e[1], e[0])));
            assert!(
                on_segment.contains(&e[0]) && on_segment.contains(&e[1]),
                "{what}"
            );
        }
        // Exempt: triangles with a vertex on a segment. All others meet no segment and keep
        // the mode's angle bounds and the Delaunay property.
        let (lo, hi) = match mode {
            HexDelaunayMode::Simple => (29.99, 120.01),
            HexDelaunayMode::Extended => (43.89, 90.0001),
        };
        let keep: Vec<[u32; 3]> = t
            .triangles
            .iter()
            .copied()
            .filter(|tri| !tri.iter().any(|x| on_segment.contains(x)))
            .collect();
        for tri in &keep {
            let p = tri.map(|i| v[i as usize]);
            for seg in segments {
                let (s, e) = (points[seg[0]], points[seg[1]]);
                assert!(
                    !meets(p, s, e),
                    "{what}: a non-exempt triangle meets a segment"
                );
            }
            let away = format!("{what} (away from the segments)");
            super::super::tests::assert_angles_in(p, (lo, hi), &away);
        }
        let qk = triangulation_quality(v, &keep);
        assert_eq!(
            qk.delaunay_violations, 0,
            "{what}: not Delaunay away from segments"
        );
        (t.triangles.len(), t.triangles.len() - keep.len())
    }

    fn u(rng: &mut ChaCha8Rng) -> f64 {
        rng.random_range(-1.0..1.0)
    }

    /// One seeded PSLG of family `case % 5`: a random star-shaped polygon (with points inside),
    /// random chords kept when they cross none before, a lattice segment with points exactly on
    /// it, two segments at an acute angle with a point near one of them, a polygon with a hole.
    pub(crate) fn sample_pslg(case: usize, rng: &mut ChaCha8Rng) -> (Vec<Vec2>, Vec<[usize; 2]>) {
        let offset = Vec2::new(rng.random_range(-50.0..50.0), rng.random_range(-50.0..50.0));
        let scale = 10f64.powf(rng.random_range(-2.0..2.0));
        let mut pts: Vec<Vec2> = Vec::new();
        let mut segs = Vec::new();
        let polygon = |pts: &mut Vec<Vec2>,
                       segs: &mut Vec<[usize; 2]>,
                       r0: f64,
                       rng: &mut ChaCha8Rng| {
            // Angular gaps below 3π/4 keep the polygon simple whatever the radii.
            let n = rng.random_range(4..10usize);
            let ang: Vec<f64> = (0..n)
                .map(|i| std::f64::consts::TAU * (i as f64 + rng.random_range(0.0..0.5)) / n as f64)
                .collect();
            let base = pts.len();
            for a in ang {
                let r = r0 * rng.random_range(0.3..1.0);
                pts.push(Vec2::new(a.cos(), a.sin()) * r);
            }
            for i in 0..n {
                segs.push([base + i, base + (i + 1) % n]);
            }
        };
        match case % 5 {
            0 => {
                polygon(&mut pts, &mut segs, 1.0, rng);
                for _ in 0..rng.random_range(0..6) {
                    pts.push(Vec2::new(u(rng), u(rng)) * 0.3);
                }
            }
            1 => {
                for _ in 0..rng.random_range(1..8) {
                    let (a, b) = (Vec2::new(u(rng), u(rng)), Vec2::new(u(rng), u(rng)));
                    let i = pts.len();
                    pts.push(a);
                    pts.push(b);
                    segs.push([i, i + 1]);
                    if super::super::stepper::check_segments(&pts, &segs).is_err() {
                        segs.pop();
                    }
                }
            }
            2 => {
                let h = 2f64.powi(rng.random_range(-4..2));
                let (dx, dy) = (
                    rng.random_range(1..4) as f64,
                    rng.random_range(-3..4) as f64,
                );
                let n = rng.random_range(2..7);
                for i in 0..=n {
                    pts.push(Vec2::new(dx * i as f64, dy * i as f64) * h);
                }
                segs.push([0, n]);
                for _ in 0..rng.random_range(0..4) {
                    pts.push(Vec2::new(u(rng), u(rng)) * (n as f64 * h * 3.0));
                }
            }
            3 => {
                let t = rng.random_range(0.02..0.6f64);
                let r = rng.random_range(0.2..1.0);
                pts.push(Vec2::new(0.0, 0.0));
                pts.push(Vec2::new(1.0, 0.0));
                pts.push(Vec2::new(t.cos(), t.sin()) * r);
                segs.push([0, 1]);
                segs.push([0, 2]);
                let gap = 10f64.powf(rng.random_range(-6.0..-1.0));
                pts.push(Vec2::new(rng.random_range(0.1..0.9), -gap));
            }
            _ => {
                polygon(&mut pts, &mut segs, 1.0, rng);
                let n = pts.len();
                // Star-shaped about the origin, so the shrunk copy lies inside.
                let hole: Vec<Vec2> = pts.iter().map(|p| p * 0.2).collect();
                for (i, p) in hole.into_iter().enumerate() {
                    pts.push(p);
                    segs.push([n + i, n + (i + 1) % n]);
                }
            }
        }
        let pts = pts.into_iter().map(|p| p * scale + offset).collect();
        (pts, segs)
    }

    fn run_cases(mode: HexDelaunayMode, seed: u64, cases: usize) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut exempt = 0;
        for case in 0..cases {
            let (pts, segs) = sample_pslg(case, &mut rng);
            let what = format!("{mode:?} case {case} ({} segments)", segs.len());
            let t = hex_delaunay(&pts, &segs, mode).unwrap_or_else(|e| panic!("{what}: {e}"));
            exempt += check_pslg(&t, &pts, &segs, mode, &what).1;
        }
        assert!(exempt > 0, "segments leave some triangles exempt");
    }

    #[test]
    fn simple_segments_are_edges_and_bounds_hold_away_from_them() {
        run_cases(HexDelaunayMode::Simple, 71, 600);
    }

    #[test]
    fn extended_segments_are_edges_and_bounds_hold_away_from_them() {
        run_cases(HexDelaunayMode::Extended, 72, 250);
    }

    /// The same checks on 10^4 inputs per mode (2000 per family):
    /// `cargo test --release -p dupin-core pslg_full -- --ignored`.
    #[test]
    #[ignore]
    fn pslg_full() {
        run_cases(HexDelaunayMode::Simple, 171, 10_000);
        run_cases(HexDelaunayMode::Extended, 172, 10_000);
    }

    /// Stepping gives the one-shot result; the segment pass is a step, `is_done` waits for it,
    /// and an inserted point on a segment splits it.
    #[test]
    fn stepper_with_segments_matches_one_shot_and_inserts() {
        use crate::hex_delaunay::HexDelaunayStepper;
        let mut rng = ChaCha8Rng::seed_from_u64(73);
        for case in 0..40 {
            let mode = super::super::tests::alternate_mode(case);
            let (pts, segs) = sample_pslg(case, &mut rng);
            let mut s = HexDelaunayStepper::new(&pts, &segs, mode).unwrap();
            assert!(
                s.triangulation().segment_edges.is_empty(),
                "no segments before the end"
            );
            while s.step().unwrap().changed {}
            assert!(s.is_done());
            assert_eq!(s.triangulation(), hex_delaunay(&pts, &segs, mode).unwrap());
            // A point inserted on a segment (a fraction no family puts a point at): the
            // segment is split there.
            let [i, j] = segs[0];
            let mid = pts[i] + (pts[j] - pts[i]) * 0.0137;
            s.insert(&[mid]).unwrap();
            s.run_to_end().unwrap();
            let t = s.try_triangulation().unwrap();
            let mut all = pts.clone();
            all.push(mid);
            check_pslg(
                &t,
                &all,
                &segs,
                mode,
                &format!("{mode:?} case {case} + point on a segment"),
            );
            let m = t.input_vertex[pts.len()];
            assert!(t.segment_edges.iter().any(|e| e.contains(&m)));
        }
    }

    #[test]
    fn points_on_a_segment_split_it() {
        let pts = [
            Vec2::new(0.0, 0.0),
            Vec2::new(4.0, 2.0),
            Vec2::new(1.0, 0.5),
            Vec2::new(3.0, 1.5),
            Vec2::new(2.0, 1.5),
        ];
        let s = split_at_points(&pts, &[[0, 1]]);
        assert_eq!(s, vec![[0, 2], [2, 3], [3, 1]]);
        for mode in [HexDelaunayMode::Simple, HexDelaunayMode::Extended] {
            let t = hex_delaunay(&pts, &[[0, 1]], mode).unwrap();
            check_pslg(&t, &pts, &[[0, 1]], mode, "points on a segment");
        }
    }

    /// The paper's data set 4, the letters IMR as a PSLG (fixture under tests/data).
    pub(crate) fn imr() -> (Vec<Vec2>, Vec<[usize; 2]>) {
        let pts =
            crate::mesh::parse_points(include_str!("../../tests/data/imr_points.txt")).unwrap();
        let segs =
            crate::mesh::parse_segments(include_str!("../../tests/data/imr_segments.txt")).unwrap();
        (pts, segs)
    }

    #[test]
    fn imr_letters_as_pslg() {
        let (pts, segs) = imr();
        assert_eq!((pts.len(), segs.len()), (75, 75));
        for mode in [HexDelaunayMode::Simple, HexDelaunayMode::Extended] {
            let t = hex_delaunay(&pts, &segs, mode).unwrap();
            let (n, exempt) = check_pslg(&t, &pts, &segs, mode, "IMR");
            assert!(exempt < n);
            let alone = hex_delaunay(&pts, &[], mode).unwrap().triangles.len();
            eprintln!(
                "IMR {mode:?}: {n} triangles ({alone} for the points alone), {exempt} meet a \
                 segment, {} segment edges",
                t.segment_edges.len()
            );
        }
    }
}
