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

use super::PhexError;
use super::triangulation::{LayerRule, Triangulation, TriangulationSpec, bounded_ratio, ideal_ratio};
use crate::{Surface, Vec2, Vec3};

/// The two conjugate direction fields of method 2 on a surface.
pub struct ConjugateFields<'a> {
    surface: &'a dyn Surface,
    angle: f64,
    dom: crate::Domain,
}

impl<'a> ConjugateFields<'a> {
    /// D_F at `angle` (radians) from the first principal direction (from the u direction at
    /// umbilics, where every direction is principal), D_G conjugate to it.
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
        let d1 = c.dir1 * cs + c.dir2 * sn;
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

fn to_uv(swap: bool, along: f64, across: f64) -> Vec2 {
    if swap {
        Vec2::new(across, along)
    } else {
        Vec2::new(along, across)
    }
}

fn cross2(a: Vec2, b: Vec2) -> f64 {
    a.x * b.y - a.y * b.x
}

/// First crossing of the segment p q with the polyline `line`: (fraction along p q).
fn segment_hits(p: Vec2, q: Vec2, line: &[Vec2]) -> Option<f64> {
    let (lo, hi) = (p.inf(&q), p.sup(&q));
    let mut best: Option<f64> = None;
    for w in line.windows(2) {
        let (a, b) = (w[0], w[1]);
        if a.x.max(b.x) < lo.x || a.x.min(b.x) > hi.x || a.y.max(b.y) < lo.y || a.y.min(b.y) > hi.y
        {
            continue;
        }
        let (r, s) = (q - p, b - a);
        let den = cross2(r, s);
        if den == 0.0 {
            continue;
        }
        let t = cross2(a - p, s) / den;
        let u = cross2(a - p, r) / den;
        if (0.0..=1.0).contains(&t) && (0.0..=1.0).contains(&u) {
            best = Some(best.map_or(t, |x: f64| x.min(t)));
        }
    }
    best
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
    let f = ConjugateFields::new(s, angle);
    let dir = if spec.end >= spec.start { 1.0 } else { -1.0 };
    let across_of = |p: Vec2| if spec.swap { p.x } else { p.y };
    let along_of = |p: Vec2| if spec.swap { p.y } else { p.x };
    let (lo, hi) = (spec.start.min(spec.end), spec.start.max(spec.end));
    let in_band = move |p: Vec2| {
        let a = if spec.swap { p.x } else { p.y };
        a >= lo - 1e-9 && a <= hi + 1e-9
    };
    let seed = to_uv(spec.swap, a0, spec.start);
    if f.directions(seed).is_none() {
        return Err(PhexError::NoValidTriangulation(format!(
            "the first field at {:.1} degrees is asymptotic (self-conjugate) or undefined at the \
             start of the region: choose another --field-angle",
            angle.to_degrees()
        )));
    }
    let step = size / 8.0;
    let along_ref = to_uv(spec.swap, 1.0, 0.0);
    let across_ref = to_uv(spec.swap, 0.0, dir);
    // Base flow line: from (along start, start) over the along span, inside the band.
    let span = a1 - a0;
    let line = f.trace(seed, 0, along_ref, step, 1e6 * size, &|p| {
        in_band(p) && along_of(p) <= a0 + span + 1e-9
    });
    let base = resample(s, &f.dom, &line, size)?;
    let n = base.len() - 1;
    if !(6..=4000).contains(&n) {
        return Err(PhexError::BadSize(format!(
            "the base flow line gives {n} samples; use between 6 and 4000 (change --size or \
             --field-angle: the base line leaves the region early)"
        )));
    }
    let mut t = Triangulation {
        uv: vec![],
        positions: vec![],
        normals: vec![],
        triangles: vec![],
        layers: vec![],
        closed_along: false,
        layer_steps: vec![],
    };
    let push = |t: &mut Triangulation, uv: Vec2| -> Result<u32, PhexError> {
        let (u, v) = f.dom.normalize(uv.x, uv.y);
        let d = s.derivatives(u, v);
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
    };
    let mut layers_uv: Vec<Vec<Vec2>> = vec![base];
    let mut ids = vec![];
    for &p in &layers_uv[0] {
        ids.push(push(&mut t, p)?);
    }
    t.layers.push(ids);
    let mut prev_ratio: Option<f64> = None;
    for m in 1..spec.max_layers {
        let cur = &layers_uv[m - 1];
        let k = cur.len();
        // Feet of the D_G flow lines and, for the interior ones, the ideal heights.
        let mut feet: Vec<(Vec2, Option<f64>)> = vec![];
        let mut ratios = vec![];
        if m % 2 == 0 {
            feet.push((layers_uv[m - 2][0], None));
        }
        for i in 0..k - 1 {
            let (a, b) = (cur[i], cur[i + 1]);
            let ab = (pos(s, &f.dom, b) - pos(s, &f.dom, a)).norm();
            let r = match spec.rule {
                LayerRule::Fixed(r) => r,
                LayerRule::Ideal { bound } => match ideal_ratio(s, a, b) {
                    Some(r) => bounded_ratio(r, bound),
                    // Section 5.3: re-use the previous step across a parabolic stretch.
                    None => prev_ratio.unwrap_or(0.75f64.sqrt()),
                },
            };
            ratios.push(r);
            feet.push(((a + b) / 2.0, Some(r * ab)));
        }
        if m % 2 == 0 {
            feet.push((*layers_uv[m - 2].last().unwrap_or(&cur[k - 1]), None));
        }
        // Ideal apexes C_i along the D_G flow lines.
        let mut ideal = vec![];
        for (foot, h) in &feet {
            if let Some(h) = h {
                let l = f.trace(*foot, 1, across_ref, h / 8.0, *h, &|_| true);
                if l.len() == 9 {
                    ideal.push((*l.last().unwrap_or(foot), *h));
                }
            }
        }
        if ideal.len() < feet.iter().filter(|x| x.1.is_some()).count() {
            break;
        }
        let prev_len: f64 = cur
            .windows(2)
            .map(|w| (pos(s, &f.dom, w[1]) - pos(s, &f.dom, w[0])).norm())
            .sum();
        let hmax = feet.iter().filter_map(|x| x.1).fold(0.0, f64::max);
        // Pass 1 through the median ideal apex; pass 2 through the one that came out lowest.
        let mut seed_idx = ideal.len() / 2;
        let mut result = None;
        for _pass in 0..2 {
            let sp = ideal[seed_idx].0;
            let reach = 1.5 * prev_len + 4.0 * hmax;
            let fwd = f.trace(sp, 0, along_ref, step, reach, &|_| true);
            let bwd = f.trace(sp, 0, -along_ref, step, reach, &|_| true);
            let mut l1: Vec<Vec2> = bwd.into_iter().rev().collect();
            l1.extend(fwd.into_iter().skip(1));
            let mut pts = vec![];
            let mut heights = vec![];
            for (foot, h) in &feet {
                let lim = 4.0 * h.unwrap_or(hmax).max(hmax);
                match hit(&f, *foot, across_ref, step, lim, &l1) {
                    Some((p, len)) => {
                        pts.push(p);
                        heights.push(h.map(|h| len / h));
                    }
                    None => break,
                }
            }
            if pts.len() < feet.len() {
                result = None;
                break;
            }
            // Index (among the interior feet) of the lowest relative height.
            let rel: Vec<f64> = heights.iter().flatten().copied().collect();
            let (imin, &low) = rel
                .iter()
                .enumerate()
                .min_by(|a, b| a.1.total_cmp(b.1))
                .unwrap_or((0, &1.0));
            result = Some(pts);
            if low >= 0.999 || imin == seed_idx {
                break;
            }
            seed_idx = imin;
        }
        let Some(pts) = result else { break };
        if pts
            .iter()
            .any(|&p| !in_band(p) || (across_of(p) - spec.end) * dir > 1e-12)
        {
            break;
        }
        prev_ratio = Some(ratios.iter().sum::<f64>() / ratios.len().max(1) as f64);
        let mean_step = pts
            .iter()
            .zip(&feet)
            .map(|(p, (q, _))| (across_of(*p) - across_of(*q)).abs())
            .sum::<f64>()
            / pts.len() as f64;
        let prev_ids = t.layers[m - 1].clone();
        let mut new_ids = vec![];
        for &p in &pts {
            new_ids.push(push(&mut t, p)?);
        }
        let tri = |t: &mut Triangulation, a: u32, b: u32, c: u32| {
            // Orient along the surface normal (the fields' orientation is arbitrary).
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
        let (pk, nk) = (prev_ids.len(), new_ids.len());
        if m % 2 == 1 {
            // New point i over segment (i, i+1).
            for i in 0..pk - 1 {
                tri(&mut t, prev_ids[i], prev_ids[i + 1], new_ids[i]);
                if i + 1 < nk {
                    tri(&mut t, new_ids[i], prev_ids[i + 1], new_ids[i + 1]);
                }
            }
        } else {
            // New point i+1 over segment (i, i+1); the ends over the ends two layers down.
            for i in 0..pk {
                if i + 1 < pk {
                    tri(&mut t, prev_ids[i], prev_ids[i + 1], new_ids[i + 1]);
                }
                tri(&mut t, new_ids[i], prev_ids[i], new_ids[i + 1]);
            }
        }
        t.layers.push(new_ids);
        t.layer_steps.push(mean_step);
        layers_uv.push(pts);
    }
    if t.layers.len() < 2 {
        return Err(PhexError::NoValidTriangulation(format!(
            "not even one layer fits along the field at {:.1} degrees: choose another \
             --field-angle, a smaller size or a larger region",
            angle.to_degrees()
        )));
    }
    Ok(t)
}

fn pos(s: &dyn Surface, dom: &crate::Domain, p: Vec2) -> Vec3 {
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
    line: &[Vec2],
) -> Option<(Vec2, f64)> {
    let (mut cur, mut r, mut len) = (foot, reference, 0.0);
    while len < limit {
        let (q, dir) = f.rk4(cur, 1, r, h)?;
        if let Some(t) = segment_hits(cur, q, line) {
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
    dom: &crate::Domain,
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
