//! MOVED_CENTER_3 runs and their dual (section 5.4, "Centers of single / consecutive
//! MOVED_CENTER_3-hexagons", "Centers of MOVED_CENTER_4-hexagons").
//!
//! A run is `n` consecutive leaves around a common top neighbour `T` (a MOVED_CENTER_4), each
//! with three consecutive fins facing away from `T`; `n = 6` is a blossom. Input: the
//! original centres, the full hexagons across the fins, the relocated left/right neighbours.
//! Output: the new vertices and the triangles that replace the fans of the run's centres in
//! the plain dual (`dual.rs`).
//!
//! Positions (C original centres, Ĉ new ones, C_f the full hexagon across fin f):
//! - n = 1: C is dropped; fin vertices 3/5 C + 2/5 C_f0, 2/5 C + 3/5 C_f1 (middle),
//!   3/5 C + 2/5 C_f2; the top moves to 3/5 C_T + 2/5 C.
//! - n >= 2: Ĉ = 2/3 C + 1/3 C_T; middle fins 3/5 C + 2/5 C_f1; the fins two neighbours in
//!   the run share get one vertex 9/20 C_M + 11/20 C_f (C_M the mean of the two Ĉ); the
//!   run's end fins 25/52 Ĉ + 27/52 C_f. The top: n = 2: 5/4 C_T − 1/4 C_M, n = 3:
//!   7/6 C_T − 1/6 C_k1 (the middle one), n = 4: 4/3 C_T − 1/3 C_M (the middle two), n = 6:
//!   not moved. For n = 2 and 4, C_M is the mean of the *new* centres (as in the shared-fin
//!   formula); with the original centres no placement of the rest keeps α (checked by hand
//!   and by the local check in `refinement.rs`).
//!
//! Topology (the paper gives it only by its Fig. 9/10; ours is the Delaunay triangulation of
//! these vertices): each centre's fin vertex joins the joined hexagons beside its fin and the
//! hexagon across it; for n = 1 the three fin vertices form a triangle and the outer two join
//! the top; for n >= 2 each Ĉ joins its fin vertices, its run neighbours' Ĉ and the top.
//! A blossom is 60 triangles.

use crate::Vec2;
use crate::hex_delaunay::dual::Key;
use rustc_hash::FxHashMap;

/// A vertex of a patch: an existing dual vertex by key, or a new one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum VRef {
    /// The dual's vertex of this hexagon.
    Key(Key),
    /// The `i`-th new vertex of the patch.
    New(usize),
}

/// The replacement of one MOVED_CENTER_3 run's fans.
#[derive(Debug, Clone, Default)]
pub struct FinPatch {
    /// The run's centres (their fans are replaced; for n >= 2 their vertices move to Ĉ, for
    /// n = 1 the centre's vertex becomes the middle fin vertex).
    pub centres: Vec<Key>,
    /// Positions of existing vertices the patch sets (centres, the top).
    pub moved: Vec<(Key, Vec2)>,
    /// Positions of every other existing vertex the patch uses (emptied once they are in
    /// the relocation map).
    pub uses: Vec<(Key, Vec2)>,
    /// Positions of the new vertices.
    pub new: Vec<Vec2>,
    /// The triangles that replace the centres' fans, counter-clockwise.
    pub triangles: Vec<[VRef; 3]>,
    /// Triangles around the top that stay but move with it (checked, not emitted; emptied
    /// once checked).
    pub around_top: Vec<[Vec2; 3]>,
}

impl FinPatch {
    /// The top's new position (MOVED_CENTER_4; unchanged for a blossom).
    pub fn top_position(&self) -> Vec2 {
        self.moved
            .last()
            .expect("the top is the last moved vertex")
            .1
    }

    /// Position of a patch vertex.
    pub fn position(&self, v: VRef) -> Vec2 {
        match v {
            VRef::New(i) => self.new[i],
            VRef::Key(k) => self
                .moved
                .iter()
                .chain(&self.uses)
                .find(|e| e.0 == k)
                .map(|e| e.1)
                .expect("patch vertex with a position"),
        }
    }
}

/// The geometry of one run, lattice-free: `centres[i]` counter-clockwise around `top`,
/// `fine[i]` the five full hexagons across the fins of centre `i` (across fin 0, between fins
/// 0 and 1, across fin 1, between 1 and 2, across fin 2), `ends` the relocated left and right
/// neighbours (unused for a blossom), `keys` the keys of the same vertices.
pub struct Run {
    /// The top's centre and key.
    pub top: (Vec2, Key),
    /// Original centres and keys, counter-clockwise around the top.
    pub centres: Vec<(Vec2, Key)>,
    /// Per centre, the five fin-side full hexagons (fixed) and keys.
    pub fine: Vec<[(Vec2, Key); 5]>,
    /// Left and right neighbours (relocated) and keys; `None` for a blossom.
    pub ends: Option<[(Vec2, Key); 2]>,
    /// The top's other neighbours (relocated), from the right neighbour round to the left.
    pub others: Vec<Vec2>,
}

/// The MOVED_CENTER_4's new position for the run with original centres `c` (counter-clockwise;
/// six: a blossom, not moved).
pub fn top_new(t: Vec2, c: &[Vec2]) -> Vec2 {
    let hat = |i: usize| c[i] * (2.0 / 3.0) + t / 3.0;
    match c.len() {
        1 => t * 0.6 + c[0] * 0.4,
        2 => t * 1.25 - (hat(0) + hat(1)) * 0.125,
        3 => t * (7.0 / 6.0) - c[1] / 6.0,
        4 => t * (4.0 / 3.0) - (hat(1) + hat(2)) / 6.0,
        _ => t,
    }
}

/// Builds the patch of a run of `n` = 1, 2, 3, 4 or 6 (None for n = 5).
pub fn run_patch(run: &Run) -> Option<FinPatch> {
    let n = run.centres.len();
    let cyc = run.ends.is_none();
    let c: Vec<Vec2> = run.centres.iter().map(|x| x.0).collect();
    let t = run.top.0;
    let mut p = FinPatch {
        centres: run.centres.iter().map(|x| x.1).collect(),
        moved: Vec::new(),
        uses: Vec::new(),
        new: Vec::new(),
        triangles: Vec::new(),
        around_top: Vec::new(),
    };
    for f in &run.fine {
        for &(q, k) in f {
            p.uses.push((k, q));
        }
    }
    let fk = |i: usize, j: usize| VRef::Key(run.fine[i][j].1);
    let fp = |i: usize, j: usize| run.fine[i][j].0;
    let top = VRef::Key(run.top.1);
    let new = |p: &mut FinPatch, q: Vec2| {
        p.new.push(q);
        VRef::New(p.new.len() - 1)
    };
    let t_new;
    if n == 1 {
        let [(l, lk), (r, rk)] = run.ends?;
        p.uses.extend([(lk, l), (rk, r)]);
        let (l, r) = (VRef::Key(lk), VRef::Key(rk));
        let f1 = VRef::Key(run.centres[0].1);
        p.moved
            .push((run.centres[0].1, c[0] * 0.4 + fp(0, 2) * 0.6));
        let f0 = new(&mut p, c[0] * 0.6 + fp(0, 0) * 0.4);
        let f2 = new(&mut p, c[0] * 0.6 + fp(0, 4) * 0.4);
        t_new = top_new(t, &c);
        let [a0, m01, a1, m12, a2] = [0, 1, 2, 3, 4].map(|j| fk(0, j));
        p.triangles = vec![
            [f0, l, a0],
            [f0, a0, m01],
            [f0, m01, f1],
            [f1, m01, a1],
            [f1, a1, m12],
            [f1, m12, f2],
            [f2, m12, a2],
            [f2, a2, r],
            [f2, r, top],
            [f2, top, f0],
            [f0, f1, f2],
            [f0, top, l],
        ];
    } else {
        if n == 5 {
            return None;
        }
        let hat: Vec<Vec2> = c.iter().map(|&q| q * (2.0 / 3.0) + t / 3.0).collect();
        for (centre, &q) in run.centres.iter().zip(&hat) {
            p.moved.push((centre.1, q));
        }
        let h = |i: usize| VRef::Key(run.centres[i].1);
        let mid: Vec<VRef> = (0..n)
            .map(|i| new(&mut p, c[i] * 0.6 + fp(i, 2) * 0.4))
            .collect();
        let pairs = if cyc { n } else { n - 1 };
        let shared: Vec<VRef> = (0..pairs)
            .map(|i| {
                let cm = (hat[i] + hat[(i + 1) % n]) * 0.5;
                new(&mut p, cm * 0.45 + fp(i, 4) * 0.55)
            })
            .collect();
        let (e0, e1) = if cyc {
            (shared[n - 1], shared[n - 1])
        } else {
            (
                new(&mut p, hat[0] * (25.0 / 52.0) + fp(0, 0) * (27.0 / 52.0)),
                new(
                    &mut p,
                    hat[n - 1] * (25.0 / 52.0) + fp(n - 1, 4) * (27.0 / 52.0),
                ),
            )
        };
        let before = |i: usize| if i == 0 { e0 } else { shared[i - 1] };
        let after = |i: usize| if i == n - 1 && !cyc { e1 } else { shared[i] };
        t_new = top_new(t, &c);
        for (i, &f) in mid.iter().enumerate() {
            let (b, a) = (before(i), after(i));
            let [a0, m01, a1, m12, a2] = [0, 1, 2, 3, 4].map(|j| fk(i, j));
            p.triangles.extend([
                [b, m01, f],
                [f, m01, a1],
                [f, a1, m12],
                [f, m12, a],
                [h(i), b, f],
                [h(i), f, a],
                [b, a0, m01],
                [a, m12, a2],
            ]);
        }
        for i in 0..pairs {
            let j = (i + 1) % n;
            p.triangles
                .extend([[h(i), after(i), h(j)], [top, h(i), h(j)]]);
        }
        if let Some([(l, lk), (r, rk)]) = run.ends {
            p.uses.extend([(lk, l), (rk, r)]);
            let (l, r) = (VRef::Key(lk), VRef::Key(rk));
            p.triangles.extend([
                [l, fk(0, 0), e0],
                [l, e0, h(0)],
                [top, l, h(0)],
                [r, h(n - 1), e1],
                [r, e1, fk(n - 1, 4)],
                [top, h(n - 1), r],
            ]);
        }
    }
    p.moved.push((run.top.1, t_new));
    if let Some([(l, _), (r, _)]) = run.ends {
        let ring: Vec<Vec2> = std::iter::once(r)
            .chain(run.others.iter().copied())
            .chain(std::iter::once(l))
            .collect();
        for w in ring.windows(2) {
            p.around_top.push([t_new, w[0], w[1]]);
        }
    }
    Some(p)
}

/// Applies the patches to a plain dual built without the triangles at the run centres
/// (`DualBuilder::build` leaves out the fans of the keys it is given; `removed` of them): sets
/// the moved positions, appends the new vertices and the patches' triangles. `vertex_of`
/// gives the vertex of every key a patch names.
pub fn apply_fin_patches(
    positions: &mut Vec<Vec2>,
    triangles: &mut Vec<[u32; 3]>,
    vertex_of: &FxHashMap<Key, u32>,
    patches: &[FinPatch],
    removed: usize,
) {
    if patches.is_empty() {
        return;
    }
    let mut added = 0;
    for p in patches {
        for &(k, q) in &p.moved {
            positions[vertex_of[&k] as usize] = q;
        }
        let base = positions.len() as u32;
        positions.extend_from_slice(&p.new);
        let id = |v: VRef| match v {
            VRef::Key(k) => vertex_of[&k],
            VRef::New(i) => base + i as u32,
        };
        for t in &p.triangles {
            triangles.push(t.map(id));
        }
        added += p.triangles.len();
    }
    // Euler: each new vertex adds two triangles.
    debug_assert_eq!(
        added,
        removed + 2 * patches.iter().map(|p| p.new.len()).sum::<usize>(),
        "the patches replace whole fans"
    );
}

#[cfg(test)]
mod tests {
    use super::super::refinement::ANGLE_MIN;
    use super::*;

    const S3: f64 = 1.732_050_807_568_877_2;

    fn dir(deg: f64) -> Vec2 {
        let a = deg.to_radians();
        Vec2::new(a.cos(), a.sin())
    }

    /// The configuration of Fig. 9/10 with unit circumradius: `n` MOVED_CENTER_3 around the
    /// top at the origin, the ends MOVED_CENTER_1 (moved 1/6 towards their fin), the rest of
    /// the top's neighbours fixed.
    fn config(n: usize) -> Run {
        let mut key = 0i64;
        let mut next = |p: Vec2| {
            key += 1;
            (p, (key, 0))
        };
        let nb: Vec<Vec2> = (0..6).map(|i| dir(30.0 + 60.0 * i as f64) * S3).collect();
        let mut centres = Vec::new();
        let mut fine = Vec::new();
        for (i, &c) in nb.iter().enumerate().take(n) {
            let th = 30.0 + 60.0 * i as f64;
            centres.push(next(c));
            fine.push([
                next(c + dir(th - 60.0) * S3),
                next(c + dir(th - 30.0) * 1.5),
                next(c + dir(th) * S3),
                next(c + dir(th + 30.0) * 1.5),
                next(c + dir(th + 60.0) * S3),
            ]);
        }
        // Fine hexagons shared by neighbours in the run are one vertex.
        for i in 1..n {
            fine[i][0] = fine[i - 1][4];
        }
        if n == 6 {
            fine[0][0] = fine[5][4];
        }
        let ends = (n < 6).then(|| {
            let l = nb[5] + (fine[0][0].0 - nb[5]) / 6.0;
            let r = nb[n] + (fine[n - 1][4].0 - nb[n]) / 6.0;
            [next(l), next(r)]
        });
        let others = if n < 6 {
            ((n + 1)..5).map(|i| nb[i]).collect()
        } else {
            Vec::new()
        };
        Run {
            top: next(Vec2::zeros()),
            centres,
            fine,
            ends,
            others,
        }
    }

    fn angles(p: &[Vec2; 3]) -> [f64; 3] {
        std::array::from_fn(|j| {
            (p[(j + 1) % 3] - p[j])
                .angle(&(p[(j + 2) % 3] - p[j]))
                .to_degrees()
        })
    }

    fn min_max(p: &FinPatch) -> (f64, f64, usize) {
        let tris: Vec<[Vec2; 3]> = p
            .triangles
            .iter()
            .map(|t| t.map(|v| p.position(v)))
            .chain(p.around_top.iter().copied())
            .collect();
        let mut lo = f64::INFINITY;
        let mut hi: f64 = 0.0;
        for t in &tris {
            assert!(
                (t[1] - t[0]).perp(&(t[2] - t[0])) > 0.0,
                "counter-clockwise"
            );
            for a in angles(t) {
                lo = lo.min(a);
                hi = hi.max(a);
            }
        }
        (lo, hi, p.triangles.len())
    }

    /// Section 5.4 / 6.1: with the relocation formulas every triangle of a single MOVED_CENTER_3,
    /// of runs of 2, 3, 4 and of a blossom has its angles in [α, 90°]; a blossom is 60
    /// triangles (section 5.3), a single MOVED_CENTER_3 12, a run of n 10n + 4.
    #[test]
    fn runs_keep_the_angle_bounds() {
        for n in [1, 2, 3, 4, 6] {
            let p = run_patch(&config(n)).expect("a patch");
            let (lo, hi, count) = min_max(&p);
            assert!(
                lo >= ANGLE_MIN - 1e-9 && hi <= 90.0 + 1e-9,
                "n = {n}: angles {lo}..{hi}"
            );
            let expected = match n {
                1 => 12,
                6 => 60,
                _ => 10 * n + 4,
            };
            assert_eq!(count, expected, "n = {n}");
        }
        assert!(
            run_patch(&{
                let mut r = config(4);
                r.centres.push(r.centres[0]);
                r.fine.push(r.fine[0]);
                r
            })
            .is_none()
        );
    }

    /// Our reading of the n = 2 MOVED_CENTER_4 formula: with C_M the mean of the original
    /// centres the top's triangles fall below α; with the new centres they do not.
    #[test]
    fn the_two_run_top_needs_the_new_centres() {
        let run = config(2);
        let mut p = run_patch(&run).unwrap();
        let c: Vec<Vec2> = run.centres.iter().map(|x| x.0).collect();
        let t = run.top.0;
        let literal = t * 1.25 - (c[0] + c[1]) * 0.125;
        let top_key = run.top.1;
        for m in p.moved.iter_mut().filter(|m| m.0 == top_key) {
            m.1 = literal;
        }
        for tri in &mut p.around_top {
            tri[0] = literal;
        }
        let (lo, _, _) = min_max(&p);
        assert!(lo < ANGLE_MIN - 1.0, "literal C_M gives {lo}");
    }
}
