//! Valid triangulations for P-Hex meshes (P-Hex paper, section 5): progressive conjugation
//! (method 1, section 5.2), pre-specified conjugation along conjugate parameter lines (method 2,
//! section 5.2) and the parabolic-curve rules of section 5.3 (step re-use and the lower bound b
//! on |CM|/|AB| with the smooth transition r' = b + r^2/(4b) for r < 2b).
//!
//! Both methods work layer after layer: a layer is a polyline of surface points; the next layer
//! holds the apexes C of the ideal triangles (section 5.1) over its segments AB. Method 1 places
//! each apex freely (tangent-plane apex projected back onto the surface); method 2 keeps the
//! points on the second family of parameter lines (which must be conjugate to the first, e.g.
//! principal curvature lines) and only chooses the next base line so that the new points sit at
//! the ideal height, i.e. above the line DE of section 5.1.

use crate::phex::PhexError;
use crate::phex::ideal_apex_3d;
use crate::surface::Surface;
use crate::{Vec2, Vec3};

/// Above this |CM|/|AB| the ideal triangle is taken as degenerate (the base is nearly along a
/// parabolic direction) and the previous step is re-used (section 5.3).
pub const MAX_RATIO: f64 = 4.0;

/// The same limit where K > 0 (the ideal ratio there is sqrt(3)/2 sqrt(k_AB / k_conj), which
/// only grows large next to a parabolic curve).
pub const MAX_RATIO_ELLIPTIC: f64 = 1.5;

/// Position of a parabolic curve inside the layer that crosses it (see `centre_crossing`):
/// midway, as the step re-use of section 5.3 intends (the layer straddles the curve).
const CROSSING_FRACTION: f64 = 0.5;

/// A parabolic curve closer than this share of the step is not centred on (the layer would
/// be narrow; the parabolic-region rule of the dual mesh handles such a layer).
const MIN_CROSSING: f64 = 0.25;

/// Which triangulation method of section 5.2 to run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TriangulationMethod {
    /// Method 1: progressive conjugation from a base curve.
    Progressive,
    /// Method 2: pre-specified conjugation along the parameter lines (conjugate directions).
    Prescribed,
}

crate::names::named_choices!(TriangulationMethod, "method", {
    Progressive => "progressive",
    Prescribed => "prescribed",
});

/// The section 5.3 lower bound b of the scenes and of a configuration for a library surface.
pub const DEFAULT_BOUND: f64 = 0.3;

/// How the layer height |CM| is chosen for each layer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LayerRule {
    /// The ideal triangle of section 5.1, with the parabolic lower bound `b` of section 5.3
    /// (`b = 0` disables the bound, which gives the narrow layers of Fig. 19 left).
    Ideal {
        /// Lower bound b on |CM|/|AB| (section 5.3).
        bound: f64,
    },
    /// A fixed ratio |CM|/|AB| regardless of curvature (not a Dupin-ideal triangle; used to show
    /// the invalid triangulation of Fig. 11 left, and for developable surfaces where no ideal
    /// triangle exists).
    Fixed(f64),
}

/// Settings of a triangulation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TriangulationSpec {
    /// Method of section 5.2.
    pub method: TriangulationMethod,
    /// Layer height rule.
    pub rule: LayerRule,
    /// Number of base-curve samples (segments on a closed base curve).
    pub samples: usize,
    /// Swap the roles of u and v: base curve along v, layers advancing in u.
    pub swap: bool,
    /// Parameter (across the layers) of the base curve.
    pub start: f64,
    /// Parameter (across the layers) at which layering stops; for a periodic across-direction
    /// `start + period` closes the mesh.
    pub end: f64,
    /// Range of the base-curve parameter (along the layers).
    pub along: (f64, f64),
    /// Largest number of layers (guards against layers shrinking to nothing).
    pub max_layers: usize,
    /// Largest number of vertices (= P-Hex faces of the dual mesh): the run stops with
    /// [`PhexError::BadSize`] when the layers would make more, before the memory is spent.
    pub max_vertices: usize,
}

/// The default P-Hex face budget ([`TriangulationSpec::max_vertices`]): a mesh a 2-core,
/// 8 GB laptop optimises in well under a minute (192k faces took 95 s and 2.8 GB) and a
/// browser tab holds.
pub const MAX_PHEX_FACES: usize = 100_000;

/// The error of a triangulation that passes its vertex budget.
pub(super) fn over_budget(spec: &TriangulationSpec, layers: usize) -> PhexError {
    PhexError::BadSize(format!(
        "the triangulation passes the limit of {} vertices (P-Hex faces) at layer {layers}, \
         with more to come: use a larger size (or, where layers come out much thinner than the \
         size, another method or field angle), or raise the face limit (--max-faces)",
        spec.max_vertices
    ))
}

/// A triangulation on a surface, built layer by layer.
#[derive(Debug, Clone, PartialEq)]
pub struct Triangulation {
    /// Parameters (u, v) of every vertex.
    pub uv: Vec<Vec2>,
    /// Surface points.
    pub positions: Vec<Vec3>,
    /// Unit surface normals at the vertices.
    pub normals: Vec<Vec3>,
    /// Triangles (vertex indices, counter-clockwise seen from the normal).
    pub triangles: Vec<[u32; 3]>,
    /// Vertex indices of every layer, base curve first.
    pub layers: Vec<Vec<u32>>,
    /// Whether the layers are closed polylines.
    pub closed_along: bool,
    /// Across-parameter step of every layer (for diagnosing narrow layers, section 5.3).
    pub layer_steps: Vec<f64>,
}

/// The section 5.3 lower bound: r' = b + r^2/(4b) for r < 2b, r otherwise (C^1 at r = 2b).
pub fn bounded_ratio(r: f64, b: f64) -> f64 {
    if b > 0.0 && r < 2.0 * b {
        b + r * r / (4.0 * b)
    } else {
        r
    }
}

/// The parameter point at `along` the layer direction and `across` it: (along, across), or
/// (across, along) when the spec's `swap` makes v the layer direction.
pub(super) fn to_uv(swap: bool, along: f64, across: f64) -> Vec2 {
    if swap {
        Vec2::new(across, along)
    } else {
        Vec2::new(along, across)
    }
}

/// Ratio |CM|/|AB| of the ideal triangle on AB (surface points with parameters `a`, `b`), or
/// `None` where no ideal triangle exists (parabolic point, degenerate segment).
pub(super) fn ideal_ratio(s: &dyn Surface, a: Vec2, b: Vec2) -> Option<f64> {
    ideal_ratio_limited(s, a, b, MAX_RATIO_ELLIPTIC)
}

/// [`ideal_ratio`] with `elliptic_limit` in place of [`MAX_RATIO_ELLIPTIC`].
fn ideal_ratio_limited(s: &dyn Surface, a: Vec2, b: Vec2, elliptic_limit: f64) -> Option<f64> {
    let m = (a + b) / 2.0;
    let curv = s.curvature(m.x, m.y).ok()?;
    let (pa, pb) = (s.position(a.x, a.y), s.position(b.x, b.y));
    // Project A and B into the tangent plane at M.
    let n = curv.normal;
    let pm = curv.point;
    let pa = pa - n * (pa - pm).dot(&n);
    let pb = pb - n * (pb - pm).dot(&n);
    let c = ideal_apex_3d(&curv, &pa, &pb).ok()?;
    let ab = (pb - pa).norm();
    let r = (c - (pa + pb) / 2.0).norm() / ab;
    let limit = if curv.gaussian > 0.0 {
        elliptic_limit
    } else {
        MAX_RATIO
    };
    (r.is_finite() && r > 0.0 && r < limit).then_some(r)
}

/// Builds a triangulation of `s` per `spec` (section 5.2; section 5.3 at parabolic curves).
///
/// Output: every layer is a polyline of surface points; consecutive layers are joined by the
/// triangles (A_i, A_i+1, C_i) and (C_i, A_i+1, C_i+1).
///
/// Errors: [`PhexError::BadSize`] when the sample count is too small or too large,
/// [`PhexError::NoValidTriangulation`] when not even one layer fits or the parametrisation is
/// singular in the region.
pub fn triangulate(s: &dyn Surface, spec: &TriangulationSpec) -> Result<Triangulation, PhexError> {
    let mut b = Builder::new(s, spec)?;
    match spec.method {
        TriangulationMethod::Prescribed => b.prescribed()?,
        TriangulationMethod::Progressive => b.progressive()?,
    }
    if b.t.layers.len() < 2 {
        return Err(PhexError::NoValidTriangulation(
            "not even one layer of ideal triangles fits: make the size smaller or the region \
             larger"
                .into(),
        ));
    }
    Ok(b.t)
}

struct Builder<'a> {
    s: &'a dyn Surface,
    spec: &'a TriangulationSpec,
    dom: crate::surface::Domain,
    t: Triangulation,
    closed: bool,
    periodic_across: bool,
    ds: f64,
    dir: f64,
}

impl<'a> Builder<'a> {
    fn new(s: &'a dyn Surface, spec: &'a TriangulationSpec) -> Result<Self, PhexError> {
        let dom = s.domain();
        let (periodic_along, periodic_across) = if spec.swap {
            (dom.periodic_v, dom.periodic_u)
        } else {
            (dom.periodic_u, dom.periodic_v)
        };
        if spec.samples < 6 || spec.samples > 4000 {
            return Err(PhexError::BadSize(format!(
                "{} base samples; use between 6 and 4000 (change --size)",
                spec.samples
            )));
        }
        let (a0, a1) = spec.along;
        if !(a1 > a0) || !spec.start.is_finite() || !spec.end.is_finite() {
            return Err(PhexError::BadParameter("empty or non-finite region".into()));
        }
        let closed = periodic_along && ((a1 - a0) - period_along(&dom, spec.swap)).abs() < 1e-9;
        Ok(Builder {
            s,
            spec,
            dom,
            t: Triangulation {
                uv: vec![],
                positions: vec![],
                normals: vec![],
                triangles: vec![],
                layers: vec![],
                closed_along: closed,
                layer_steps: vec![],
            },
            closed,
            periodic_across,
            ds: (a1 - a0) / spec.samples as f64,
            dir: if spec.end >= spec.start { 1.0 } else { -1.0 },
        })
    }

    fn push(&mut self, uv: Vec2) -> Result<u32, PhexError> {
        if self.t.positions.len() >= self.spec.max_vertices {
            return Err(over_budget(self.spec, self.t.layers.len()));
        }
        let (u, v) = self.dom.normalize(uv.x, uv.y);
        let d = self.s.derivatives(u, v);
        if !d.p.iter().all(|c| c.is_finite()) {
            return Err(PhexError::NoValidTriangulation(
                "the surface is not finite in the region".into(),
            ));
        }
        let nrm = d.pu.cross(&d.pv).try_normalize(1e-300).ok_or_else(|| {
            PhexError::NoValidTriangulation(format!(
                "the parametrisation is singular at ({u:.3}, {v:.3}); shrink the region"
            ))
        })?;
        self.t.uv.push(uv);
        self.t.positions.push(d.p);
        self.t.normals.push(nrm);
        Ok((self.t.uv.len() - 1) as u32)
    }

    fn tri(&mut self, a: u32, b: u32, c: u32) {
        // Counter-clockwise in (along, across) with across increasing; flip to keep the
        // orientation of Pu x Pv.
        if self.spec.swap != (self.dir < 0.0) {
            self.t.triangles.push([a, c, b]);
        } else {
            self.t.triangles.push([a, b, c]);
        }
    }

    fn along_at(&self, j: usize, i: usize) -> f64 {
        let off = if !j.is_multiple_of(2) { 0.5 } else { 0.0 };
        self.spec.along.0 + (i as f64 + off) * self.ds
    }

    fn layer_len(&self, j: usize) -> usize {
        let n = self.spec.samples;
        if self.closed {
            n
        } else if j.is_multiple_of(2) {
            n + 1
        } else {
            n
        }
    }

    /// Method 2: points on the parameter lines, next base line at the ideal height.
    fn prescribed(&mut self) -> Result<(), PhexError> {
        let spec = self.spec;
        let period = period_across(&self.dom, spec.swap);
        let closing = self.periodic_across && ((spec.end - spec.start).abs() - period).abs() < 1e-9;
        let planned = if closing {
            Some(plan_closed_steps(self.s, spec, self.ds, period)?)
        } else {
            None
        };
        let mut across = spec.start;
        let mut layer = vec![];
        for i in 0..self.layer_len(0) {
            layer.push(self.push(to_uv(spec.swap, self.along_at(0, i), across))?);
        }
        self.t.layers.push(layer);
        let mut prev_step = None;
        for j in 0..spec.max_layers {
            let step = match &planned {
                Some(p) if j < p.len() => p[j],
                Some(_) => break,
                None => {
                    let along: Vec<f64> = (0..self.layer_len(j))
                        .map(|i| self.along_at(j, i))
                        .collect();
                    let (s, ds) = (self.s, self.ds);
                    match layer_step(s, spec, &along, across, ds, prev_step, MAX_RATIO_ELLIPTIC) {
                        Some(h) if matches!(spec.rule, LayerRule::Ideal { .. }) => {
                            // Section 5.3 re-uses the step only where the layers approach a
                            // parabolic curve; moving away from one (a base curve next to it),
                            // the large ideal ratio is kept: a re-used, flatter step makes the
                            // elliptic hexagons of the next layer self-intersect.
                            let h = if parabolic_ahead(s, spec, &along, across, 2.5 * h).is_none() {
                                layer_step(s, spec, &along, across, ds, prev_step, MAX_RATIO)
                                    .unwrap_or(h)
                            } else {
                                h
                            };
                            centre_crossing(s, spec, &along, across, h)
                        }
                        Some(h) => h,
                        None => break,
                    }
                }
            };
            let next = across + self.dir * step;
            if planned.is_none() && (next - spec.end) * self.dir > 1e-12 {
                break;
            }
            prev_step = Some(step);
            let closing_now = planned.as_ref().is_some_and(|p| j + 1 == p.len());
            let new_layer = if closing_now {
                self.t.layers[0].clone()
            } else {
                let mut l = vec![];
                for i in 0..self.layer_len(j + 1) {
                    l.push(self.push(to_uv(spec.swap, self.along_at(j + 1, i), next))?);
                }
                l
            };
            let prev = self.t.layers[j].clone();
            let (k, m) = (prev.len(), new_layer.len());
            if self.closed {
                for i in 0..k {
                    if j.is_multiple_of(2) {
                        // New point i sits over the segment (i, i+1).
                        self.tri(prev[i], prev[(i + 1) % k], new_layer[i]);
                        self.tri(new_layer[i], prev[(i + 1) % k], new_layer[(i + 1) % m]);
                    } else {
                        // New point i+1 sits over the segment (i, i+1).
                        self.tri(prev[i], prev[(i + 1) % k], new_layer[(i + 1) % m]);
                        self.tri(new_layer[i], prev[i], new_layer[(i + 1) % m]);
                    }
                }
            } else if j.is_multiple_of(2) {
                for i in 0..k - 1 {
                    self.tri(prev[i], prev[i + 1], new_layer[i]);
                    if i + 1 < m {
                        self.tri(new_layer[i], prev[i + 1], new_layer[i + 1]);
                    }
                }
            } else {
                for i in 0..k {
                    if i + 1 < k {
                        self.tri(prev[i], prev[i + 1], new_layer[i + 1]);
                    }
                    self.tri(new_layer[i], prev[i], new_layer[i + 1]);
                }
            }
            self.t.layers.push(new_layer);
            self.t.layer_steps.push(step);
            across = next;
            if closing_now {
                break;
            }
        }
        Ok(())
    }

    /// Method 1: every apex placed freely at the ideal position and projected onto the surface.
    fn progressive(&mut self) -> Result<(), PhexError> {
        let spec = self.spec;
        let (a0, a1) = spec.along;
        let s = self.s;
        let mut cur: Vec<Vec2> = (0..self.layer_len(0))
            .map(|i| to_uv(spec.swap, self.along_at(0, i), spec.start))
            .collect();
        let mut layer = vec![];
        for p in cur.clone() {
            layer.push(self.push(p)?);
        }
        self.t.layers.push(layer);
        let shift = if spec.swap {
            Vec2::new(0.0, a1 - a0)
        } else {
            Vec2::new(a1 - a0, 0.0)
        };
        let mut prev_ratio: Option<f64> = None;
        for _ in 0..spec.max_layers {
            let k = cur.len();
            let segs = if self.closed { k } else { k - 1 };
            if segs < 2 {
                break;
            }
            let mut next = Vec::with_capacity(segs);
            let mut ratios = vec![];
            for i in 0..segs {
                let ua = cur[i];
                let ub = if self.closed && i + 1 == k {
                    cur[0] + shift
                } else {
                    cur[i + 1]
                };
                let (pa, pb) = (s.position(ua.x, ua.y), s.position(ub.x, ub.y));
                let m = (ua + ub) / 2.0;
                let d = s.derivatives(m.x, m.y);
                let nrm = d.pu.cross(&d.pv).try_normalize(1e-300).unwrap_or(Vec3::z());
                let ab = pb - pa;
                let r = match spec.rule {
                    LayerRule::Fixed(r) => r,
                    LayerRule::Ideal { bound } => match ideal_ratio(s, ua, ub) {
                        Some(r) if r < MAX_RATIO => bounded_ratio(r, bound),
                        // Section 5.3: re-use the previous step across the parabolic curve.
                        _ => prev_ratio.unwrap_or(0.866),
                    },
                };
                ratios.push(r);
                let across_dir = if spec.swap { d.pu } else { d.pv };
                let mut side = nrm.cross(&ab).normalize();
                if side.dot(&across_dir) * self.dir < 0.0 {
                    side = -side;
                }
                if let LayerRule::Ideal { .. } = spec.rule
                    && let Ok(curv) = s.curvature(m.x, m.y)
                    && let Ok(ind) = curv.indicatrix()
                {
                    let f = curv.frame();
                    if let Ok(c) = ind.conjugate_direction(&f.vector_to_local(&ab)) {
                        let mut cw = f.vector_to_world(&c).normalize();
                        if cw.dot(&side) < 0.0 {
                            cw = -cw;
                        }
                        if cw.dot(&side) > 0.2 {
                            side = cw / cw.dot(&side);
                        }
                    }
                }
                let c3 = (pa + pb) / 2.0 + side * (r * ab.norm());
                let h = r * ab.norm() / across_dir.norm().max(1e-300);
                let guess = if spec.swap {
                    Vec2::new(m.x + self.dir * h, m.y)
                } else {
                    Vec2::new(m.x, m.y + self.dir * h)
                };
                let cp = s.closest_point(&c3, Some(guess)).map_err(|e| {
                    PhexError::NoValidTriangulation(format!("apex projection failed: {e}"))
                })?;
                let mut uv = cp.uv;
                if self.dom.periodic_u {
                    let p = self.dom.u.1 - self.dom.u.0;
                    uv.x += p * ((guess.x - uv.x) / p).round();
                }
                if self.dom.periodic_v {
                    let p = self.dom.v.1 - self.dom.v.0;
                    uv.y += p * ((guess.y - uv.y) / p).round();
                }
                next.push(uv);
            }
            let across_of = |p: &Vec2| if spec.swap { p.x } else { p.y };
            if next
                .iter()
                .any(|p| (across_of(p) - spec.end) * self.dir > 1e-12)
            {
                break;
            }
            // A front pressed against a side of the domain: apexes beyond it are clamped onto
            // one boundary point, so two neighbours coincide and the next layer would have no
            // direction. The layers stop there, as at the end of the across range.
            let collapsed = next.windows(2).any(|w| {
                let (a, b) = (s.position(w[0].x, w[0].y), s.position(w[1].x, w[1].y));
                let d = (b - a).norm();
                d == 0.0 || d.is_nan()
            });
            if collapsed {
                break;
            }
            prev_ratio = Some(ratios.iter().sum::<f64>() / ratios.len() as f64);
            let step = next
                .iter()
                .zip(&cur)
                .map(|(a, b)| (across_of(a) - across_of(b)).abs())
                .sum::<f64>()
                / next.len() as f64;
            let prev = self.t.layers.last().unwrap().clone();
            let mut layer = vec![];
            for p in next.clone() {
                layer.push(self.push(p)?);
            }
            let m = layer.len();
            for i in 0..segs {
                self.tri(prev[i], prev[(i + 1) % k], layer[i]);
                if self.closed {
                    self.tri(layer[i], prev[(i + 1) % k], layer[(i + 1) % m]);
                } else if i + 1 < m {
                    self.tri(layer[i], prev[i + 1], layer[i + 1]);
                }
            }
            self.t.layers.push(layer);
            self.t.layer_steps.push(step);
            cur = next;
        }
        Ok(())
    }
}

fn period_along(dom: &crate::surface::Domain, swap: bool) -> f64 {
    if swap {
        dom.v.1 - dom.v.0
    } else {
        dom.u.1 - dom.u.0
    }
}

fn period_across(dom: &crate::surface::Domain, swap: bool) -> f64 {
    if swap {
        dom.u.1 - dom.u.0
    } else {
        dom.v.1 - dom.v.0
    }
}

/// Across-parameter step of the next layer for method 2: the median over the layer of the ideal
/// |CM| converted to parameter length; parabolic stretches re-use the previous step (5.3).
fn layer_step(
    s: &dyn Surface,
    spec: &TriangulationSpec,
    along: &[f64],
    across: f64,
    ds: f64,
    prev: Option<f64>,
    elliptic_limit: f64,
) -> Option<f64> {
    let mut hs = vec![];
    let stride = (along.len() / 16).max(1);
    for i in (0..along.len()).step_by(stride) {
        let a = to_uv(spec.swap, along[i], across);
        let b = to_uv(spec.swap, along[i] + ds, across);
        let (pa, pb) = (s.position(a.x, a.y), s.position(b.x, b.y));
        let ab = (pb - pa).norm();
        let r = match spec.rule {
            LayerRule::Fixed(r) => Some(r),
            LayerRule::Ideal { bound } => match ideal_ratio_limited(s, a, b, elliptic_limit) {
                Some(r) if r < MAX_RATIO => Some(bounded_ratio(r, bound)),
                _ => None,
            },
        };
        let m = (a + b) / 2.0;
        let d = s.derivatives(m.x, m.y);
        let across_len = if spec.swap { d.pu.norm() } else { d.pv.norm() };
        if let Some(r) = r
            && across_len > 1e-300
        {
            hs.push(r * ab / across_len);
        }
    }
    if hs.is_empty() {
        // Section 5.3: re-use the previous step across a parabolic stretch; on a base curve
        // that is itself parabolic, start with the equilateral height sqrt(3)/2 |AB|.
        return prev.or_else(|| {
            let a = to_uv(spec.swap, along[0], across);
            let b = to_uv(spec.swap, along[0] + ds, across);
            let m = (a + b) / 2.0;
            let d = s.derivatives(m.x, m.y);
            let across_len = if spec.swap { d.pu.norm() } else { d.pv.norm() };
            let ab = (s.position(b.x, b.y) - s.position(a.x, a.y)).norm();
            let h = 0.75f64.sqrt() * ab / across_len;
            (h.is_finite() && h > 0.0).then_some(h)
        });
    }
    hs.sort_by(|a, b| a.total_cmp(b));
    let h = hs[hs.len() / 2];
    (h.is_finite() && h > 0.0).then_some(h)
}

/// Distance (in the across parameter, >= 0) from `across` to the parabolic curve ahead, when
/// K changes sign within `reach` on every sampled along-position of the layer (a parabolic
/// curve running along the layers, as the vase's circle); `None` otherwise.
fn parabolic_ahead(
    s: &dyn Surface,
    spec: &TriangulationSpec,
    along: &[f64],
    across: f64,
    reach: f64,
) -> Option<f64> {
    let dir = if spec.end >= spec.start { 1.0 } else { -1.0 };
    let k = |a: f64, x: f64| {
        let p = to_uv(spec.swap, a, x);
        s.curvature(p.x, p.y).ok().map(|c| c.gaussian)
    };
    let stride = (along.len() / 8).max(1);
    let mut ds = vec![];
    for &a in along.iter().step_by(stride) {
        let k0 = k(a, across)?;
        // Scan in 16 steps for a sign change, then bisect it.
        let n = 16;
        let mut lo = 0.0;
        let mut hit = None;
        for i in 1..=n {
            let t = reach * i as f64 / n as f64;
            if k(a, across + dir * t)? * k0 <= 0.0 {
                hit = Some((lo, t));
                break;
            }
            lo = t;
        }
        let (mut lo, mut hi) = hit?;
        for _ in 0..40 {
            let mid = 0.5 * (lo + hi);
            if k(a, across + dir * mid)? * k0 > 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        ds.push(0.5 * (lo + hi));
    }
    ds.sort_by(|a, b| a.total_cmp(b));
    let (d0, d1) = (*ds.first()?, *ds.last()?);
    (d1 - d0 < 0.05 * reach).then_some(0.5 * (d0 + d1))
}

/// Section 5.3, crossing a parabolic curve that runs along the layers: the step `h` is
/// adjusted so that the parabolic curve lies midway in one layer, so that the vertex layers on
/// both sides keep a distance from it. Off-centre, the three tangent planes of a crossing
/// triangle are nearly but not exactly parallel and their dual point flies off along the
/// meridian (an invalid ring of hexagons on the vase; see docs/phex.md).
fn centre_crossing(
    s: &dyn Surface,
    spec: &TriangulationSpec,
    along: &[f64],
    across: f64,
    h: f64,
) -> f64 {
    let f = CROSSING_FRACTION;
    match parabolic_ahead(s, spec, along, across, 2.5 * h) {
        // Already (nearly) on the curve: a centred layer would be too narrow.
        Some(d) if d < MIN_CROSSING * h => h,
        // This layer crosses the curve (at most twice the step wide).
        Some(d) if d <= f * 2.0 * h => d / f,
        // Approach in whole steps no smaller than h (flatter triangles than ideal make the
        // elliptic hexagons self-intersect) so that the crossing layer starts f h before it.
        Some(d) => {
            let rest = d - f * h;
            (rest / (rest / h).floor().max(1.0)).max(h)
        }
        None => h,
    }
}

/// Steps of a closed across-direction (method 2): the ideal steps around the period, scaled so
/// that an even number of layers closes exactly.
fn plan_closed_steps(
    s: &dyn Surface,
    spec: &TriangulationSpec,
    ds: f64,
    period: f64,
) -> Result<Vec<f64>, PhexError> {
    let (a0, _) = spec.along;
    let along: Vec<f64> = (0..spec.samples).map(|i| a0 + ds * i as f64).collect();
    let mut steps = vec![];
    let mut x = spec.start;
    let mut prev = None;
    while x < spec.start + period {
        if steps.len() >= spec.max_layers {
            return Err(PhexError::NoValidTriangulation(format!(
                "more than {} layers needed to close the surface (layers become narrow near \
                 parabolic curves): set a lower bound b > 0 or a larger size",
                spec.max_layers
            )));
        }
        let h = layer_step(s, spec, &along, x, ds, prev, MAX_RATIO_ELLIPTIC).ok_or_else(|| {
            PhexError::NoValidTriangulation("no ideal triangle on the base curve".into())
        })?;
        prev = Some(h);
        steps.push(h);
        x += h;
    }
    let mut count = steps.len();
    if count % 2 == 1 {
        count += 1;
    }
    count = count.max(4);
    // Resample the step function at `count` layers and scale to the period.
    let total: f64 = steps.iter().sum();
    let mut out = Vec::with_capacity(count);
    for j in 0..count {
        let src = (j as f64 + 0.5) / count as f64 * steps.len() as f64;
        out.push(steps[(src as usize).min(steps.len() - 1)]);
    }
    let sum: f64 = out.iter().sum();
    let _ = total;
    out.iter_mut().for_each(|h| *h *= period / sum);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::phex::{PhexConfig, phex_run};
    use crate::surface::surface_by_name;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn parabolic_bound_is_at_least_b_smooth_and_identity_above_2b() {
        let b = 0.3;
        for i in 0..200 {
            let r = i as f64 * 0.005;
            let rp = bounded_ratio(r, b);
            assert!(rp >= b && rp >= r - 1e-15, "r {r} -> {rp}");
            if r >= 2.0 * b {
                assert_eq!(rp, r);
            }
        }
        // Continuous with continuous slope at r = 2b.
        let e = 1e-7;
        let (lo, hi) = (bounded_ratio(2.0 * b - e, b), bounded_ratio(2.0 * b + e, b));
        assert!((hi - lo).abs() < 3e-7);
        let slope_lo = (bounded_ratio(2.0 * b - e, b) - bounded_ratio(2.0 * b - 2.0 * e, b)) / e;
        assert!((slope_lo - 1.0).abs() < 1e-5);
        assert_eq!(bounded_ratio(0.1, 0.0), 0.1);
    }

    #[test]
    fn bad_sizes_are_typed_errors() {
        let s = surface_by_name("torus", &[]).unwrap();
        let mut spec = TriangulationSpec {
            method: TriangulationMethod::Prescribed,
            rule: LayerRule::Ideal { bound: 0.3 },
            samples: 3,
            swap: false,
            start: 0.0,
            end: 1.0,
            along: (0.0, std::f64::consts::TAU),
            max_layers: 100,
            max_vertices: MAX_PHEX_FACES,
        };
        assert!(matches!(
            triangulate(s.as_ref(), &spec),
            Err(PhexError::BadSize(_))
        ));
        spec.samples = 40;
        spec.along = (1.0, 1.0);
        assert!(matches!(
            triangulate(s.as_ref(), &spec),
            Err(PhexError::BadParameter(_))
        ));
        for size in [-1.0, 0.0, f64::NAN, 1e-9, 100.0] {
            let c =
                PhexConfig::for_surface("torus", &[], TriangulationMethod::Prescribed, Some(size));
            assert!(phex_run(c).is_err(), "size {size}");
        }
        let c = PhexConfig::for_surface("no-such", &[], TriangulationMethod::Prescribed, None);
        assert!(matches!(phex_run(c), Err(PhexError::Surface(_))));
    }

    #[test]
    fn prescribed_layers_stay_on_conjugate_parameter_lines_at_the_ideal_height() {
        // Method 2 on a surface of revolution: every layer is a parameter line and the layer
        // height matches the ideal ratio of section 5.1 to within the per-layer median.
        let s = surface_by_name("sphere", &[]).unwrap();
        let spec = TriangulationSpec {
            method: TriangulationMethod::Prescribed,
            rule: LayerRule::Ideal { bound: 0.0 },
            samples: 60,
            swap: false,
            start: -0.5,
            end: 0.5,
            along: (0.0, std::f64::consts::TAU),
            max_layers: 100,
            max_vertices: MAX_PHEX_FACES,
        };
        let t = triangulate(s.as_ref(), &spec).unwrap();
        for l in &t.layers {
            let v0 = t.uv[l[0] as usize].y;
            assert!(l.iter().all(|&i| (t.uv[i as usize].y - v0).abs() < 1e-12));
        }
        // On the unit sphere the ideal triangle is equilateral: |CM| = sqrt(3)/2 |AB|.
        let tri = t.triangles[0].map(|i| t.positions[i as usize]);
        let e: Vec<f64> = (0..3).map(|k| (tri[k] - tri[(k + 1) % 3]).norm()).collect();
        let mean = e.iter().sum::<f64>() / 3.0;
        assert!(e.iter().all(|x| (x - mean).abs() < 0.05 * mean), "{e:?}");
    }

    #[test]
    fn layer_crossing_a_parabolic_circle_along_the_layers_is_centred_on_it() {
        // Section 5.3 on the vase (method 2, bottom up): the middle parabolic circle v = 1.5
        // runs along the layers and lies midway in the one layer that crosses it.
        for (radius, amplitude) in [(1.0, 0.2), (1.0, 0.3), (1.0, 0.35), (0.8, 0.3), (1.3, 0.5)] {
            let mut c = crate::scenes::phex_scene("vase-bottom-up").unwrap().config;
            c.params = vec![("radius".into(), radius), ("amplitude".into(), amplitude)];
            let p = crate::phex::PhexPipeline::new(c).unwrap();
            let t = p.triangulation();
            let v: Vec<f64> = t.layers.iter().map(|l| t.uv[l[0] as usize].y).collect();
            let j = v
                .windows(2)
                .position(|w| w[0] < 1.5 && w[1] > 1.5)
                .expect("a layer crosses the circle");
            let mid = 0.5 * (v[j] + v[j + 1]);
            assert!(
                (mid - 1.5).abs() < 1e-9 * (v[j + 1] - v[j]),
                "radius {radius} amplitude {amplitude}: layer {} to {}",
                v[j],
                v[j + 1]
            );
        }
    }

    /// Property test: seeded random parameters of each surface family; the whole pipeline meets
    /// the acceptance thresholds.
    #[test]
    fn random_surface_parameters_meet_acceptance() {
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        for _ in 0..3 {
            let big_r = rng.random_range(1.5..3.0);
            let r = rng.random_range(0.3..0.6) * big_r;
            let a = rng.random_range(0.7..1.5);
            let c = rng.random_range(0.7..1.5);
            let radius = rng.random_range(0.5..2.0);
            type Case = (&'static str, Vec<(String, f64)>, Option<(f64, f64)>);
            let cases: Vec<Case> = vec![
                ("torus", vec![("R".into(), big_r), ("r".into(), r)], None),
                (
                    "hyperboloid",
                    vec![("a".into(), a), ("c".into(), c), ("vmax".into(), 1.0)],
                    None,
                ),
                ("sphere", vec![("radius".into(), radius)], Some((0.0, 1.1))),
            ];
            for (name, params, across) in cases {
                let mut cfg =
                    PhexConfig::for_surface(name, &params, TriangulationMethod::Prescribed, None);
                if across.is_some() {
                    cfg.across = across;
                }
                let res = phex_run(cfg).unwrap_or_else(|e| panic!("{name} {params:?}: {e}"));
                let bad = crate::scenes::acceptance_for_tests(&res.report);
                assert!(bad.is_empty(), "{name} {params:?}: {bad:?}");
            }
        }
    }
}
