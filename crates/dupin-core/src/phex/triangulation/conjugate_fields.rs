//! Method 2 of the P-Hex paper (section 5.2, Fig. 16) with a user-chosen first direction field:
//! the pre-specified conjugation method along the flow lines of two conjugate direction fields
//! D_F and D_G, where D_F makes a fixed angle with the first principal direction and D_G is its
//! conjugate (computed with the Dupin indicatrix, section 4.2).
//!
//! The base curve L_0 is a flow line of D_F sampled uniformly; on every segment A_i A_i+1 the
//! flow line l_i of D_G through the midpoint M_i carries the ideal apex C_i (section 5.1, with the
//! lower bound b of section 5.3). The next base line L_1 is the D_F flow line through the lowest
//! of the C_i (relative to its ideal height), so every intersection C'_i = l_i x L_1 is at or above
//! its ideal height, i.e. above the line DE of Fig. 13, as section 5.2 requires. Flow lines are
//! traced in parameter space with RK4 at unit 3D speed (written by hand: the fields are only
//! defined up to sign, so each step is oriented against the previous one, which no ODE crate
//! does for us).

use super::layers::{
    LayerRule, Triangulation, TriangulationSpec, bounded_ratio, ideal_ratio, to_uv,
};
use crate::phex::PhexError;
use crate::surface::Surface;
use crate::{Vec2, Vec3};

/// The two conjugate direction fields of method 2 on a surface.
pub struct ConjugateFields<'a> {
    surface: &'a dyn Surface,
    angle: f64,
    dom: crate::surface::Domain,
}

impl<'a> ConjugateFields<'a> {
    /// D_F at `angle` (radians) from the first principal direction (from the u direction at
    /// umbilics, |k1 - k2| <= 1e-6 max |k|, where every direction is principal), D_G conjugate
    /// to it.
    pub fn new(surface: &'a dyn Surface, angle: f64) -> Self {
        ConjugateFields {
            surface,
            angle,
            dom: surface.domain(),
        }
    }

    /// Unit 3D directions (D_F, D_G) at the parameters `uv`, or `None` at a singular or planar
    /// point, or where D_F is (nearly) asymptotic so that D_G is (nearly) parallel to it (sine of
    /// their angle below 0.05).
    pub fn directions(&self, uv: Vec2) -> Option<(Vec3, Vec3)> {
        let (u, v) = self.dom.normalize(uv.x, uv.y);
        let c = self.surface.curvature(u, v).ok()?;
        let (sn, cs) = self.angle.sin_cos();
        // At (near-)umbilics the principal frame is rounding noise: use the u direction.
        let (e1, e2) = if (c.k1 - c.k2).abs() <= 1e-6 * c.k1.abs().max(c.k2.abs()) {
            let d = self.surface.derivatives(u, v);
            let e1 = d.pu.normalize();
            (e1, c.normal.cross(&e1))
        } else {
            (c.dir1, c.dir2)
        };
        let d1 = e1 * cs + e2 * sn;
        let d2 = c.conjugate_direction(&d1).ok()?;
        (d1.cross(&d2).norm() > 0.05).then_some((d1, d2))
    }

    /// The parameter-space velocity of unit 3D speed along field `which` (0: D_F, 1: D_G),
    /// oriented to make a non-negative product with `reference`.
    fn velocity(&self, uv: Vec2, which: usize, reference: Vec2) -> Option<Vec2> {
        let (d1, d2) = self.directions(uv)?;
        let t = if which == 0 { d1 } else { d2 };
        let (u, v) = self.dom.normalize(uv.x, uv.y);
        let d = self.surface.derivatives(u, v);
        let (e, f, g) = (d.pu.dot(&d.pu), d.pu.dot(&d.pv), d.pv.dot(&d.pv));
        let det = e * g - f * f;
        if !(det > 0.0) {
            return None;
        }
        let (a, b) = (d.pu.dot(&t), d.pv.dot(&t));
        let w = Vec2::new(g * a - f * b, e * b - f * a) / det;
        let w = if w.dot(&reference) < 0.0 { -w } else { w };
        w.iter().all(|x| x.is_finite()).then_some(w)
    }

    /// One RK4 step of 3D length `h` along field `which`, oriented like `reference`.
    fn rk4(&self, p: Vec2, which: usize, reference: Vec2, h: f64) -> Option<(Vec2, Vec2)> {
        let k1 = self.velocity(p, which, reference)?;
        let k2 = self.velocity(p + k1 * (h / 2.0), which, k1)?;
        let k3 = self.velocity(p + k2 * (h / 2.0), which, k1)?;
        let k4 = self.velocity(p + k3 * h, which, k1)?;
        let q = p + (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0);
        Some((q, k4))
    }

    fn inside(&self, p: Vec2) -> bool {
        let ok = |x: f64, (lo, hi): (f64, f64), periodic: bool| {
            x.is_finite() && (periodic || (x >= lo - 1e-12 && x <= hi + 1e-12))
        };
        ok(p.x, self.dom.u, self.dom.periodic_u) && ok(p.y, self.dom.v, self.dom.periodic_v)
    }

    /// Flow line of field `which` from `p`, starting along `reference`, with steps of 3D length
    /// `h`, for at most `length`, stopping before leaving the domain or where `keep` fails.
    fn trace(
        &self,
        p: Vec2,
        which: usize,
        reference: Vec2,
        h: f64,
        length: f64,
        keep: &dyn Fn(Vec2) -> bool,
    ) -> Vec<Vec2> {
        let mut out = vec![p];
        let (mut cur, mut r) = (p, reference);
        let steps = (length / h).ceil() as usize;
        for _ in 0..steps.min(1_000_000) {
            match self.rk4(cur, which, r, h) {
                Some((q, dir)) if self.inside(q) && keep(q) => {
                    r = dir;
                    cur = q;
                    out.push(q);
                }
                _ => break,
            }
        }
        out
    }
}

/// A polyline with the bounding boxes of its chunks of [`CHUNK`] segments (crossing tests skip
/// whole chunks; a layer's flow line has thousands of segments).
struct Polyline {
    pts: Vec<Vec2>,
    boxes: Vec<(Vec2, Vec2)>,
}

const CHUNK: usize = 32;

impl Polyline {
    fn new(pts: Vec<Vec2>) -> Self {
        let boxes = (0..pts.len().saturating_sub(1))
            .step_by(CHUNK)
            .map(|k| {
                let w = &pts[k..(k + CHUNK + 1).min(pts.len())];
                let lo = w.iter().fold(w[0], |a, b| a.inf(b));
                let hi = w.iter().fold(w[0], |a, b| a.sup(b));
                (lo, hi)
            })
            .collect();
        Polyline { pts, boxes }
    }

    /// First crossing of the segment p q with the polyline: the fraction along p q.
    fn hits(&self, p: Vec2, q: Vec2) -> Option<f64> {
        let (lo, hi) = (p.inf(&q), p.sup(&q));
        let mut best: Option<f64> = None;
        for (c, (blo, bhi)) in self.boxes.iter().enumerate() {
            if bhi.x < lo.x || blo.x > hi.x || bhi.y < lo.y || blo.y > hi.y {
                continue;
            }
            let end = ((c + 1) * CHUNK + 1).min(self.pts.len());
            for w in self.pts[c * CHUNK..end].windows(2) {
                let (a, b) = (w[0], w[1]);
                let (r, s) = (q - p, b - a);
                let den = r.perp(&s);
                if den == 0.0 {
                    continue;
                }
                let t = (a - p).perp(&s) / den;
                let u = (a - p).perp(&r) / den;
                if (0.0..=1.0).contains(&t) && (0.0..=1.0).contains(&u) {
                    best = Some(best.map_or(t, |x: f64| x.min(t)));
                }
            }
        }
        best
    }
}

/// Builds a method-2 triangulation along the flow lines of [`ConjugateFields`] with first-field
/// angle `angle` (radians), base edge length `size`, region and rule from `spec` (`samples` is
/// ignored: the base flow line is sampled every `size`; `start`, `end`, `along` give where the
/// base line starts, where layering stops and the along-parameter span of the base line).
///
/// Errors: [`PhexError::BadParameter`] for a non-finite angle or size,
/// [`PhexError::NoValidTriangulation`] when the first field is (nearly) asymptotic or the
/// fields are undefined at the start, or not even one layer fits, [`PhexError::BadSize`] when
/// the base line gives fewer than 6 or more than 4000 samples.
pub fn triangulate_along_fields(
    s: &dyn Surface,
    spec: &TriangulationSpec,
    angle: f64,
    size: f64,
) -> Result<Triangulation, PhexError> {
    check_parameters(spec, angle, size)?;
    let f = ConjugateFields::new(s, angle);
    let region = Region::new(s, &f, spec, size);
    let seed = to_uv(
        spec.swap,
        0.5 * (spec.along.0 + spec.along.1),
        0.5 * (spec.start + spec.end),
    );
    if f.directions(seed).is_none() {
        return Err(PhexError::NoValidTriangulation(format!(
            "the first field at {:.1} degrees is asymptotic (self-conjugate) or undefined at the \
             start of the region: choose another --field-angle",
            angle.to_degrees()
        )));
    }
    let base = region.base_line(seed)?;
    let mut t = Triangulation {
        uv: vec![],
        positions: vec![],
        normals: vec![],
        triangles: vec![],
        layers: vec![],
        closed_along: false,
        layer_steps: vec![],
    };
    let mut ids = vec![];
    for &p in &base {
        ids.push(region.push(&mut t, p)?);
    }
    t.layers.push(ids.clone());
    let base = Layer {
        first: 0,
        pts: base,
        ids,
    };
    // Layers from the base line toward `end`, then toward `start`.
    let mut down = vec![];
    for sign in [1.0, -1.0] {
        let across_ref = to_uv(spec.swap, 0.0, region.dir * sign);
        let mut layers = vec![Layer {
            first: 0,
            pts: base.pts.clone(),
            ids: base.ids.clone(),
        }];
        let mut prev_ratio: Option<f64> = None;
        for m in 1..spec.max_layers {
            let Some(next) = region.next_layer(&layers, m, across_ref, prev_ratio) else {
                break;
            };
            prev_ratio = Some(next.ratio);
            let mut new_ids = vec![];
            for &p in &next.pts {
                new_ids.push(region.push(&mut t, p)?);
            }
            let layer = Layer {
                first: next.first,
                pts: next.pts,
                ids: new_ids.clone(),
            };
            stitch(&mut t, &layers[m - 1], &layer, m);
            if sign > 0.0 {
                t.layers.push(new_ids);
                t.layer_steps.push(next.mean_step);
            } else {
                down.push((new_ids, next.mean_step));
            }
            layers.push(layer);
        }
    }
    // Layer order for the stepper: the lowest layer first, the base line in between.
    let up_layers = std::mem::take(&mut t.layers);
    let up_steps = std::mem::take(&mut t.layer_steps);
    for (ids, h) in down.into_iter().rev() {
        t.layers.push(ids);
        t.layer_steps.push(h);
    }
    t.layers.extend(up_layers);
    t.layer_steps.extend(up_steps);
    if t.layers.len() < 2 {
        return Err(PhexError::NoValidTriangulation(format!(
            "not even one layer fits along the field at {:.1} degrees: choose another \
             --field-angle, a smaller size or a larger region",
            angle.to_degrees()
        )));
    }
    Ok(t)
}

/// The finite angle, positive size and non-empty region [`triangulate_along_fields`] needs.
fn check_parameters(spec: &TriangulationSpec, angle: f64, size: f64) -> Result<(), PhexError> {
    if !angle.is_finite() {
        return Err(PhexError::BadParameter("field angle must be finite".into()));
    }
    if !(size.is_finite() && size > 0.0) {
        return Err(PhexError::BadSize(format!(
            "size {size} must be a positive length"
        )));
    }
    let (a0, a1) = spec.along;
    if !(a1 > a0) || !spec.start.is_finite() || !spec.end.is_finite() {
        return Err(PhexError::BadParameter("empty or non-finite region".into()));
    }
    Ok(())
}

/// A layer on the staggered lattice: point g of an even layer sits at x = g, of an odd one at
/// x = g + 1/2; `first` is the lattice index of the layer's first point. Points leaving the
/// band are trimmed, so the layers fill the region even when the fields are tilted.
struct Layer {
    first: i64,
    pts: Vec<Vec2>,
    ids: Vec<u32>,
}

impl Layer {
    /// The point at lattice index `g`, if the layer has one.
    fn get(&self, g: i64) -> Option<Vec2> {
        let i = g - self.first;
        (i >= 0 && (i as usize) < self.pts.len()).then(|| self.pts[i as usize])
    }

    /// The vertex at lattice index `g`, if the layer has one.
    fn id(&self, g: i64) -> Option<u32> {
        let i = g - self.first;
        (i >= 0 && (i as usize) < self.ids.len()).then(|| self.ids[i as usize])
    }
}

/// The foot of a D_G flow line: lattice index, point, ideal height (`None` at a layer's end,
/// over layer m-2).
type Foot = (i64, Vec2, Option<f64>);

/// The points of a new layer before they become vertices.
struct NextLayer {
    /// Lattice index of the first point.
    first: i64,
    pts: Vec<Vec2>,
    /// Mean parameter step across from the feet to the new points.
    mean_step: f64,
    /// Mean layer ratio of the step (re-used across a parabolic stretch).
    ratio: f64,
}

/// What every layer of one triangulation shares: the surface, the fields, the band between
/// `start` and `end` and the tracing step.
struct Region<'a> {
    s: &'a dyn Surface,
    f: &'a ConjugateFields<'a>,
    spec: &'a TriangulationSpec,
    size: f64,
    /// +1 when the layers go toward increasing across-parameters from `start` to `end`.
    dir: f64,
    lo: f64,
    hi: f64,
    step: f64,
    along_ref: Vec2,
}

impl<'a> Region<'a> {
    fn new(
        s: &'a dyn Surface,
        f: &'a ConjugateFields<'a>,
        spec: &'a TriangulationSpec,
        size: f64,
    ) -> Self {
        Region {
            s,
            f,
            spec,
            size,
            dir: if spec.end >= spec.start { 1.0 } else { -1.0 },
            lo: spec.start.min(spec.end),
            hi: spec.start.max(spec.end),
            step: size / 8.0,
            along_ref: to_uv(spec.swap, 1.0, 0.0),
        }
    }

    fn across_of(&self, p: Vec2) -> f64 {
        if self.spec.swap { p.x } else { p.y }
    }

    fn along_of(&self, p: Vec2) -> f64 {
        if self.spec.swap { p.y } else { p.x }
    }

    fn in_band(&self, p: Vec2) -> bool {
        let a = if self.spec.swap { p.x } else { p.y };
        a >= self.lo - 1e-9 && a <= self.hi + 1e-9
    }

    fn pos(&self, p: Vec2) -> Vec3 {
        pos(self.s, &self.f.dom, p)
    }

    /// The base flow line through `seed`, the middle of the region, over the along span,
    /// inside the band, sampled every `size`.
    fn base_line(&self, seed: Vec2) -> Result<Vec<Vec2>, PhexError> {
        let (a0, a1) = self.spec.along;
        let (f, step, size) = (self.f, self.step, self.size);
        let fwd = f.trace(seed, 0, self.along_ref, step, 1e6 * size, &|p| {
            self.in_band(p) && self.along_of(p) <= a1 + 1e-9
        });
        let bwd = f.trace(seed, 0, -self.along_ref, step, 1e6 * size, &|p| {
            self.in_band(p) && self.along_of(p) >= a0 - 1e-9
        });
        let mut line: Vec<Vec2> = bwd.into_iter().rev().collect();
        line.extend(fwd.into_iter().skip(1));
        let base = resample(self.s, &f.dom, &line, size)?;
        let n = base.len() - 1;
        if !(6..=4000).contains(&n) {
            return Err(PhexError::BadSize(format!(
                "the base flow line gives {n} samples; use between 6 and 4000 (change --size or \
                 --field-angle: the base line leaves the region early)"
            )));
        }
        Ok(base)
    }

    /// Adds the vertex at the parameters `uv` (position and unit normal).
    fn push(&self, t: &mut Triangulation, uv: Vec2) -> Result<u32, PhexError> {
        if t.positions.len() >= self.spec.max_vertices {
            return Err(super::layers::over_budget(self.spec, t.layers.len()));
        }
        let (u, v) = self.f.dom.normalize(uv.x, uv.y);
        let d = self.s.derivatives(u, v);
        let nrm = d.pu.cross(&d.pv).try_normalize(1e-300).ok_or_else(|| {
            PhexError::NoValidTriangulation(format!(
                "the parametrisation is singular at ({u:.3}, {v:.3}); shrink the region"
            ))
        })?;
        if !d.p.iter().all(|c| c.is_finite()) {
            return Err(PhexError::NoValidTriangulation(
                "the surface is not finite in the region".into(),
            ));
        }
        t.uv.push(uv);
        t.positions.push(d.p);
        t.normals.push(nrm);
        Ok((t.uv.len() - 1) as u32)
    }

    /// Layer `m` over `layers[m - 1]` (section 5.2), toward `across_ref`: the D_G flow lines'
    /// feet, their ideal apexes, the D_F flow line through the lowest of them and the longest
    /// run of its crossings inside the band. `None` when no layer fits.
    fn next_layer(
        &self,
        layers: &[Layer],
        m: usize,
        across_ref: Vec2,
        prev_ratio: Option<f64>,
    ) -> Option<NextLayer> {
        let (feet, ratios) = self.feet(layers, m, prev_ratio);
        if ratios.is_empty() {
            return None;
        }
        let found = self.crossings(&layers[m - 1], &feet, across_ref)?;
        let (b0, b1) = self.longest_run(&found)?;
        let pts: Vec<Vec2> = found[b0..b1].iter().flatten().copied().collect();
        let first = feet[b0].0;
        let mean_step = pts
            .iter()
            .zip(&feet[b0..b1])
            .map(|(p, (_, q, _))| (self.across_of(*p) - self.across_of(*q)).abs())
            .sum::<f64>()
            / pts.len() as f64;
        Some(NextLayer {
            first,
            pts,
            mean_step,
            ratio: ratios.iter().sum::<f64>() / ratios.len() as f64,
        })
    }

    /// Feet (lattice index, point, ideal height) of the D_G flow lines of layer `m`: odd layers
    /// over the segments (g, g+1), even ones over (g-1, g) plus the ends over layer m-2; and
    /// the layer ratios used.
    fn feet(&self, layers: &[Layer], m: usize, prev_ratio: Option<f64>) -> (Vec<Foot>, Vec<f64>) {
        let cur = &layers[m - 1];
        let (c0, c1) = (cur.first, cur.first + cur.pts.len() as i64);
        let mut feet: Vec<Foot> = vec![];
        let mut ratios = vec![];
        let (g0, g1) = if m % 2 == 1 {
            (c0, c1 - 1)
        } else {
            (c0, c1 + 1)
        };
        for g in g0..g1 {
            let (ia, ib) = if m % 2 == 1 { (g, g + 1) } else { (g - 1, g) };
            match (cur.get(ia), cur.get(ib)) {
                (Some(a), Some(b)) => {
                    let ab = (self.pos(b) - self.pos(a)).norm();
                    let r = match self.spec.rule {
                        LayerRule::Fixed(r) => r,
                        LayerRule::Ideal { bound } => match ideal_ratio(self.s, a, b) {
                            Some(r) => bounded_ratio(r, bound),
                            // Section 5.3: re-use the previous step across a parabolic stretch.
                            None => prev_ratio.unwrap_or(0.75f64.sqrt()),
                        },
                    };
                    ratios.push(r);
                    feet.push((g, (a + b) / 2.0, Some(r * ab)));
                }
                _ => {
                    if let Some(p) = layers[m - 2].get(g) {
                        feet.push((g, p, None));
                    }
                }
            }
        }
        (feet, ratios)
    }

    /// Where the D_G flow lines from `feet` cross the next D_F flow line: pass 1 through the
    /// median ideal apex; pass 2 through the one that came out lowest relative to its ideal
    /// height, so that all are at least ideal (above DE). `None` without an ideal apex.
    fn crossings(&self, cur: &Layer, feet: &[Foot], across_ref: Vec2) -> Option<Vec<Option<Vec2>>> {
        let (f, step) = (self.f, self.step);
        // Ideal apexes C_i along the D_G flow lines.
        let mut ideal = vec![];
        for (_, foot, h) in feet {
            if let Some(h) = h {
                let l = f.trace(*foot, 1, across_ref, h / 8.0, *h, &|_| true);
                ideal.push((l.len() == 9).then(|| l[8]));
            }
        }
        let mid = ideal
            .iter()
            .flatten()
            .nth(ideal.iter().flatten().count() / 2)?;
        let prev_len: f64 = cur
            .pts
            .windows(2)
            .map(|w| (self.pos(w[1]) - self.pos(w[0])).norm())
            .sum();
        let hmax = feet.iter().filter_map(|x| x.2).fold(0.0, f64::max);
        let mut sp = *mid;
        let mut found: Vec<Option<Vec2>> = vec![];
        for pass in 0..2 {
            let reach = 1.5 * prev_len + 4.0 * hmax;
            let fwd = f.trace(sp, 0, self.along_ref, step, reach, &|_| true);
            let bwd = f.trace(sp, 0, -self.along_ref, step, reach, &|_| true);
            let mut l1: Vec<Vec2> = bwd.into_iter().rev().collect();
            l1.extend(fwd.into_iter().skip(1));
            let l1 = Polyline::new(l1);
            found.clear();
            let mut rel = vec![];
            for (_, foot, h) in feet {
                let lim = 4.0 * h.unwrap_or(hmax).max(hmax);
                let x = hit(f, *foot, across_ref, step, lim, &l1);
                found.push(x.map(|x| x.0));
                if let Some(h) = h {
                    rel.push(x.map_or(f64::INFINITY, |x| x.1 / h));
                }
            }
            let (imin, &low) = rel
                .iter()
                .enumerate()
                .min_by(|a, b| a.1.total_cmp(b.1))
                .unwrap_or((0, &1.0));
            match ideal.get(imin) {
                Some(Some(p)) if pass == 0 && low < 0.999 => sp = *p,
                _ => break,
            }
        }
        Some(found)
    }

    /// The longest run of consecutive crossings inside the band and before `end`, as a range;
    /// `None` when it has fewer than 2 points.
    fn longest_run(&self, found: &[Option<Vec2>]) -> Option<(usize, usize)> {
        let ok = |p: &Option<Vec2>| p.is_some_and(|p| self.in_band(p));
        let (mut best, mut run_start) = ((0usize, 0usize), None);
        for i in 0..=found.len() {
            if i < found.len() && ok(&found[i]) {
                run_start.get_or_insert(i);
            } else if let Some(st) = run_start.take()
                && i - st > best.1 - best.0
            {
                best = (st, i);
            }
        }
        (best.1 - best.0 >= 2).then_some(best)
    }
}

/// The triangles between layer `m - 1` (`cur`) and layer `m`, oriented along the surface
/// normal (the fields' orientation is arbitrary).
fn stitch(t: &mut Triangulation, cur: &Layer, layer: &Layer, m: usize) {
    let tri = |t: &mut Triangulation, a: Option<u32>, b: Option<u32>, c: Option<u32>| {
        let (Some(a), Some(b), Some(c)) = (a, b, c) else {
            return;
        };
        let (pa, pb, pc) = (
            t.positions[a as usize],
            t.positions[b as usize],
            t.positions[c as usize],
        );
        if (pb - pa).cross(&(pc - pa)).dot(&t.normals[a as usize]) >= 0.0 {
            t.triangles.push([a, b, c]);
        } else {
            t.triangles.push([a, c, b]);
        }
    };
    let lo = cur.first.min(layer.first) - 1;
    let hi = (cur.first + cur.ids.len() as i64).max(layer.first + layer.ids.len() as i64) + 1;
    for g in lo..hi {
        if m % 2 == 1 {
            // New point g (x = g + 1/2) over the segment (g, g+1).
            tri(t, cur.id(g), cur.id(g + 1), layer.id(g));
            tri(t, layer.id(g), cur.id(g + 1), layer.id(g + 1));
        } else {
            // New point g (x = g) over the segment (g-1, g) of the odd layer.
            tri(t, cur.id(g - 1), cur.id(g), layer.id(g));
            tri(t, layer.id(g), cur.id(g), layer.id(g + 1));
        }
    }
}

fn pos(s: &dyn Surface, dom: &crate::surface::Domain, p: Vec2) -> Vec3 {
    let (u, v) = dom.normalize(p.x, p.y);
    s.position(u, v)
}

/// Where the D_G flow line from `foot` first crosses `line`, and the 3D length to it.
fn hit(
    f: &ConjugateFields,
    foot: Vec2,
    reference: Vec2,
    h: f64,
    limit: f64,
    line: &Polyline,
) -> Option<(Vec2, f64)> {
    let (mut cur, mut r, mut len) = (foot, reference, 0.0);
    while len < limit {
        let (q, dir) = f.rk4(cur, 1, r, h)?;
        if let Some(t) = line.hits(cur, q) {
            return Some((cur + (q - cur) * t, len + t * h));
        }
        cur = q;
        r = dir;
        len += h;
    }
    None
}

/// Points of the polyline `line` every `size` of 3D length (the last one at its end).
fn resample(
    s: &dyn Surface,
    dom: &crate::surface::Domain,
    line: &[Vec2],
    size: f64,
) -> Result<Vec<Vec2>, PhexError> {
    let pts: Vec<Vec3> = line.iter().map(|&p| pos(s, dom, p)).collect();
    let mut cum = vec![0.0];
    for w in pts.windows(2) {
        cum.push(cum.last().copied().unwrap_or(0.0) + (w[1] - w[0]).norm());
    }
    let total = cum.last().copied().unwrap_or(0.0);
    let n = (total / size).round();
    if !(n >= 1.0 && total.is_finite()) {
        return Err(PhexError::NoValidTriangulation(
            "the base flow line leaves the region at once: choose another --field-angle or \
             region"
                .into(),
        ));
    }
    let n = n as usize;
    let mut out = Vec::with_capacity(n + 1);
    let mut j = 0;
    for i in 0..=n {
        let target = total * i as f64 / n as f64;
        while j + 2 < cum.len() && cum[j + 1] < target {
            j += 1;
        }
        let seg = (cum[j + 1] - cum[j]).max(1e-300);
        let w = ((target - cum[j]) / seg).clamp(0.0, 1.0);
        out.push(line[j] + (line[j + 1] - line[j]) * w);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::phex::{PhexConfig, TriangulationMethod, phex_run};
    use crate::surface::surface_by_name;

    /// (surface, params, across range, angle in degrees, size) of the field-angle cases.
    type Case = (&'static str, Vec<(String, f64)>, (f64, f64), f64, f64);

    fn cases() -> Vec<Case> {
        vec![
            ("torus", vec![], (-1.0, 1.0), 15.0, 0.1),
            ("hyperboloid", vec![], (-0.8, 0.8), -20.0, 0.1),
        ]
    }

    fn config(c: &Case) -> PhexConfig {
        let mut cfg =
            PhexConfig::for_surface(c.0, &c.1, TriangulationMethod::Prescribed, Some(c.4));
        cfg.across = Some(c.2);
        cfg.field_angle = Some(c.3.to_radians());
        cfg
    }

    /// Section 5.2: the layer edges A_i A_i+1 follow D_F (at the chosen angle from the first
    /// principal direction) and the segments M_i C'_i follow the conjugate field D_G, i.e. the
    /// second fundamental form II(A_i A_i+1, M_i C'_i) vanishes up to discretisation error.
    #[test]
    fn triangulation_edges_follow_the_chosen_field_and_its_conjugate() {
        for c in cases() {
            let s = surface_by_name(c.0, &[]).unwrap();
            let r = phex_run(config(&c)).unwrap();
            let t = &r.triangulation;
            assert!(t.layers.len() >= 6, "{}: {} layers", c.0, t.layers.len());
            let (mut worst_conj, mut worst_angle, mut n) = (0.0f64, 0.0f64, 0);
            let mut layer_of = vec![usize::MAX; t.positions.len()];
            for (j, l) in t.layers.iter().enumerate() {
                for &v in l {
                    layer_of[v as usize] = j;
                }
            }
            // Triangles A_i A_i+1 C'_i: two vertices on one layer, the apex built after them.
            for tr in &t.triangles {
                let mut tr = tr.map(|v| v as usize);
                tr.sort();
                let [a, b, cp] = tr;
                if layer_of[a] != layer_of[b] || layer_of[cp] == layer_of[a] {
                    continue;
                }
                {
                    let mid = (t.uv[a] + t.uv[b]) / 2.0;
                    let dom = s.domain();
                    let (u, v) = dom.normalize(mid.x, mid.y);
                    let curv = s.curvature(u, v).unwrap();
                    let fr = curv.frame();
                    let ab = fr.vector_to_local(&(t.positions[b] - t.positions[a]));
                    let mc = fr.vector_to_local(&(t.positions[cp] - s.position(u, v)));
                    let ind = curv.indicatrix().unwrap();
                    let kmax = curv.k1.abs().max(curv.k2.abs());
                    let rel = ind.bilinear(&ab, &mc).abs() / (kmax * ab.norm() * mc.norm());
                    worst_conj = worst_conj.max(rel);
                    // Angle of A_i A_i+1 against the first principal direction, modulo pi.
                    let ang = ab.y.atan2(ab.x);
                    let want = c.3.to_radians();
                    let d = (ang - want).rem_euclid(std::f64::consts::PI);
                    worst_angle = worst_angle.max(d.min(std::f64::consts::PI - d));
                    n += 1;
                }
            }
            eprintln!(
                "{}: {n} triangles, worst relative II {worst_conj:.2e}, worst angle error {:.2} deg",
                c.0,
                worst_angle.to_degrees()
            );
            assert!(n > 100);
            assert!(worst_conj < 0.02, "{}: II {worst_conj:e}", c.0);
            assert!(worst_angle.to_degrees() < 3.0, "{}: angle", c.0);
        }
    }

    #[test]
    fn field_angle_runs_meet_the_acceptance_thresholds() {
        for c in cases() {
            let r = phex_run(config(&c)).unwrap_or_else(|e| panic!("{}: {e}", c.0));
            let bad = crate::scenes::acceptance_for_tests(&r.report);
            eprintln!("{}: {} faces, {bad:?}", c.0, r.report.faces);
            assert!(r.report.faces > 500, "{}", c.0);
            assert!(bad.is_empty(), "{}: {bad:?}", c.0);
        }
    }

    #[test]
    fn an_asymptotic_first_field_is_a_typed_error() {
        // On the hyperboloid (a = c = 1) the asymptotic directions are at 45 degrees from the
        // principal ones: D_F there is self-conjugate and no triangulation exists.
        let mut c = cases()[1].clone();
        c.3 = 45.0;
        match phex_run(config(&c)) {
            Err(PhexError::NoValidTriangulation(m)) => assert!(m.contains("field-angle"), "{m}"),
            other => panic!("{:?}", other.map(|r| r.report.faces)),
        }
        let mut cfg = config(&cases()[0]);
        cfg.field_angle = Some(f64::NAN);
        assert!(matches!(phex_run(cfg), Err(PhexError::BadParameter(_))));
        let mut cfg = config(&cases()[0]);
        cfg.method = TriangulationMethod::Progressive;
        assert!(matches!(phex_run(cfg), Err(PhexError::BadParameter(_))));
    }
}
