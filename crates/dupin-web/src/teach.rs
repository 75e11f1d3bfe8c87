//! `DupinLesson`: the teaching inset's model (P-Hex paper, sections 3 to 5.1).
//!
//! Input: a library surface, its parameters and a parameter point (u, v). The lesson works in
//! the tangent plane at that point, in the principal frame (x along the k1 direction, y along
//! k2), where the Dupin indicatrix is k1 x^2 + k2 y^2 = +-1. It holds a triangle star centred at
//! the tangent point and hands the page plain drawing primitives: the indicatrix, the star, the
//! six triangles' Dupin conics and centres, the Dupin hexagon (section 4.1), the verdicts of
//! Propositions 4 and 5 (section 4.2) and the ideal-triangle construction (section 5.1). All
//! geometry is the core's; this file only arranges it for drawing.

use crate::js::err;
use crate::pick::StarPick;
use dupin_core::mesh::is_simple_polygon;
use dupin_core::phex::{
    DupinConic, DupinIndicatrix, TriangleStar, drag_lattice_star, drag_star_vertex,
    dupin_conic_through, ideal_triangle, project_star,
};
use dupin_core::surface::{Curvature, PointType, surface_by_name};
use dupin_core::{Vec2, Vec3};
use serde::Serialize;
use std::collections::BTreeMap;
use std::f64::consts::TAU;
use wasm_bindgen::prelude::*;

type P = [f64; 2];

fn p(v: Vec2) -> P {
    [v.x, v.y]
}

/// One drawn conic: polylines (one per branch), flat x y pairs.
type Curves = Vec<Vec<f64>>;

/// One proposition condition and whether it holds.
#[derive(Serialize, Debug, Clone)]
pub(crate) struct Condition {
    pub(crate) text: String,
    pub(crate) holds: bool,
}

/// A triangle of the star with its circumscribing Dupin conic (section 4.1).
#[derive(Serialize, Debug, Clone)]
pub(crate) struct TriangleConic {
    pub(crate) center: P,
    pub(crate) curves: Curves,
}

/// Everything the inset draws, in principal-frame coordinates.
#[derive(Serialize, Debug, Clone)]
#[serde(rename_all = "camelCase")]
pub(crate) struct LessonState {
    pub(crate) kind: &'static str,
    /// `lattice` (an editable star of congruent triangles) or `mesh` (a vertex's real star).
    pub(crate) star: &'static str,
    pub(crate) k1: f64,
    pub(crate) k2: f64,
    /// Half-width of the square the inset should show.
    pub(crate) extent: f64,
    /// The indicatrix |Q| = 1 (ellipse, two conjugate hyperbolas, or two parallel lines).
    pub(crate) indicatrix: Curves,
    /// Asymptotic directions (hyperbolic points only).
    pub(crate) asymptotes: Vec<P>,
    pub(crate) center: P,
    /// The six ring vertices around the centre (lattice: a, b, b - a, -a, -b, a - b).
    pub(crate) ring: Vec<P>,
    /// Dupin conics of the six triangles (empty when K = 0).
    pub(crate) triangle_conics: Vec<TriangleConic>,
    /// The Dupin hexagon (empty when K = 0).
    pub(crate) hexagon: Vec<P>,
    /// The conic through the hexagon (Proposition 3).
    pub(crate) hexagon_conic: Curves,
    /// `valid`, `invalid` or `undecided` (K = 0).
    pub(crate) verdict: &'static str,
    /// Why, citing the proposition.
    pub(crate) reason: String,
    /// The proposition's three equivalent conditions as evaluated.
    pub(crate) conditions: Vec<Condition>,
    /// The last dragged direction and its conjugate (section 3), when defined.
    pub(crate) dragged: Option<P>,
    pub(crate) conjugate: Option<P>,
}

/// One frame of the section 5.1 construction; the page draws frames 0..=k together.
#[derive(Serialize, Debug, Clone)]
pub(crate) struct IdealStep {
    pub(crate) caption: &'static str,
    /// Labelled points: (label, x, y).
    pub(crate) points: Vec<(&'static str, f64, f64)>,
    /// Segments x1 y1 x2 y2.
    pub(crate) segments: Vec<[f64; 4]>,
    pub(crate) curves: Curves,
}

/// A lesson at one surface point: the indicatrix and an editable triangle star.
#[wasm_bindgen]
pub struct DupinLesson {
    ind: DupinIndicatrix,
    /// Ring offsets a and b: the star's fundamental triangle is (0, a, b).
    a: Vec2,
    b: Vec2,
    /// Semi-axis scale of the indicatrix, for framing.
    extent: f64,
    dragged: Option<Vec2>,
    /// A mesh vertex's real star (ring offsets, counter-clockwise), when the lesson was built
    /// from one: six independent triangles instead of a lattice star.
    ring: Option<[Vec2; 6]>,
    /// Level of the drawn indicatrix Q = +-level (1 for the lattice lesson; a mesh star is
    /// small against the unit indicatrix, so it is drawn scaled to the star).
    level: f64,
}

impl DupinLesson {
    /// The lesson at (u, v) of `surface` with `params`; the star starts as the ideal triangle of
    /// section 5.1 on a base edge 20 degrees off the first principal direction.
    pub(crate) fn build(
        surface: &str,
        params: &[(&str, f64)],
        u: f64,
        v: f64,
    ) -> Result<Self, String> {
        if !(u.is_finite() && v.is_finite()) {
            return Err(format!("u and v must be finite numbers, got ({u}, {v})"));
        }
        let s = surface_by_name(surface, params).map_err(|e| e.to_string())?;
        let c = s.curvature(u, v).map_err(|e| e.to_string())?;
        Self::from_curvatures(c.k1, c.k2)
    }

    pub(crate) fn from_curvatures(k1: f64, k2: f64) -> Result<Self, String> {
        let ind = DupinIndicatrix::new(k1, k2).map_err(|e| e.to_string())?;
        if ind.point_type() == PointType::Planar {
            return Err(
                "planar point (k1 = k2 = 0): the Dupin indicatrix is undefined; pick another point"
                    .into(),
            );
        }
        let kmax = k1.abs().max(k2.abs());
        // Semi-axes beyond 8x the smaller one are clipped for framing (parabolic: the lines).
        let semi = |k: f64| (1.0 / k.abs().max(kmax / 64.0)).sqrt();
        let (sx, sy) = (semi(k1), semi(k2));
        let extent = 1.15 * sx.max(sy);
        let ang = 20f64.to_radians();
        let a = 0.7 * Vec2::new(sx * ang.cos(), sy * ang.sin());
        let b = match ideal_triangle(&ind, &Vec2::zeros(), &a) {
            Ok(t) => t.c,
            // K = 0 has no ideal triangle (section 5.3): any non-degenerate star will do.
            Err(_) => 0.6 * Vec2::new(-0.3 * sx, sy),
        };
        Ok(DupinLesson {
            ind,
            a,
            b,
            extent,
            dragged: None,
            ring: None,
            level: 1.0,
        })
    }

    /// The lesson at a mesh vertex: `curv` is the curvature at the vertex (its point is the
    /// star's centre), `ring` the six neighbours in counter-clockwise order. The neighbours are
    /// projected orthogonally onto the tangent plane in the principal frame (section 6, step 2:
    /// the projected triangle star, `dupin_core::phex::project_star`). Errors: non-finite
    /// neighbours, a projected triangle that is degenerate, planar or non-finite curvature.
    pub(crate) fn from_star(curv: &Curvature, ring: &[Vec3; 6]) -> Result<Self, String> {
        let r = project_star(curv, ring).map_err(|e| e.to_string())?;
        let mut l = Self::from_curvatures(curv.k1, curv.k2)?;
        let reach = r.iter().map(|q| q.norm()).fold(0.0, f64::max);
        // The indicatrix scaled to pass at the star's mean |Q| (its shape is what matters).
        let q = r.iter().map(|q| l.ind.quadratic(q).abs()).sum::<f64>() / 6.0;
        l.level = if q > 0.0 { q } else { reach * reach };
        l.extent = 1.6 * reach;
        l.a = r[0];
        l.b = r[1];
        l.ring = Some(r);
        Ok(l)
    }

    /// [`DupinLesson::from_star`] for a page pick that has a complete star.
    pub(crate) fn from_pick(pick: &StarPick) -> Result<Self, String> {
        if let Some(m) = &pick.message {
            return Err(m.clone());
        }
        let ring: [Vec3; 6] = pick
            .ring
            .iter()
            .map(|p| Vec3::new(p[0], p[1], p[2]))
            .collect::<Vec<_>>()
            .try_into()
            .map_err(|r: Vec<Vec3>| format!("a star needs 6 ring vertices, got {}", r.len()))?;
        Self::from_star(&pick.curvature(), &ring)
    }

    fn star(&self) -> Result<TriangleStar, String> {
        TriangleStar::new(Vec2::zeros(), self.a, self.b).map_err(|e| e.to_string())
    }

    /// Moves ring vertex `index` (0..6: a, b, b - a, -a, -b, a - b) to `(x, y)`; the star stays
    /// a lattice star, so the opposite vertex moves symmetrically. Refuses degenerate stars.
    pub(crate) fn drag(&mut self, index: usize, x: f64, y: f64) -> Result<(), String> {
        let q = Vec2::new(x, y);
        if let Some(r) = self.ring {
            // A mesh star: only the dragged vertex moves.
            let r = drag_star_vertex(r, index, q).map_err(|e| e.to_string())?;
            self.ring = Some(r);
            (self.a, self.b) = (r[0], r[1]);
        } else {
            (self.a, self.b) =
                drag_lattice_star(self.a, self.b, index, q).map_err(|e| e.to_string())?;
        }
        self.dragged = Some(q);
        Ok(())
    }

    pub(crate) fn conjugate(&self, dx: f64, dy: f64) -> Result<Vec2, String> {
        self.ind
            .conjugate_direction(&Vec2::new(dx, dy))
            .map_err(|e| e.to_string())
    }

    /// The star after `drag`: its fundamental triangle's apex becomes the ideal apex again.
    pub(crate) fn make_ideal(&mut self) -> Result<(), String> {
        let t = ideal_triangle(&self.ind, &Vec2::zeros(), &self.a).map_err(|e| e.to_string())?;
        self.b = t.c;
        // A mesh star becomes the ideal lattice star on its first edge.
        self.ring = None;
        Ok(())
    }

    /// Polylines of a conic, clipped roughly to the inset (hyperbolas: both branches).
    fn conic_curves(&self, c: &DupinConic) -> Curves {
        let n = 96;
        match self.ind.point_type() {
            PointType::Elliptic => {
                let line: Vec<f64> = (0..=n)
                    .filter_map(|i| c.point_at(TAU * i as f64 / n as f64, 1))
                    .flat_map(|q| [q.x, q.y])
                    .collect();
                vec![line].into_iter().filter(|l| !l.is_empty()).collect()
            }
            PointType::Hyperbolic => {
                let scale = c.scale() / self.ind.k1().abs().max(self.ind.k2().abs()).sqrt();
                let reach = (4.0 * self.extent / scale.max(1e-300))
                    .max(1.0)
                    .acosh()
                    .min(6.0);
                [1i8, -1]
                    .iter()
                    .map(|&br| {
                        (0..=n)
                            .filter_map(|i| {
                                c.point_at(-reach + 2.0 * reach * i as f64 / n as f64, br)
                            })
                            .flat_map(|q| [q.x, q.y])
                            .collect::<Vec<f64>>()
                    })
                    .filter(|l| !l.is_empty())
                    .collect()
            }
            _ => Vec::new(),
        }
    }

    pub(crate) fn lesson_state(&self) -> LessonState {
        let ind = &self.ind;
        let kind = ind.point_type();
        let far = 4.0 * self.extent;
        let indicatrix = match kind {
            PointType::Elliptic => {
                self.conic_curves(&ind.conic(Vec2::zeros(), self.level * ind.k1().signum()))
            }
            PointType::Hyperbolic => {
                let mut c = self.conic_curves(&ind.conic(Vec2::zeros(), self.level));
                c.extend(self.conic_curves(&ind.conic(Vec2::zeros(), -self.level)));
                c
            }
            // k x^2 = 1 along the curved axis: two parallel lines (section 5.3).
            _ => {
                if ind.k1().abs() >= ind.k2().abs() {
                    let x = (self.level / ind.k1().abs()).sqrt();
                    vec![vec![x, -far, x, far], vec![-x, -far, -x, far]]
                } else {
                    let y = (self.level / ind.k2().abs()).sqrt();
                    vec![vec![-far, y, far, y], vec![-far, -y, far, -y]]
                }
            }
        };
        let asymptotes = ind
            .asymptotic_directions()
            .map(|d| d.iter().map(|v| p(*v)).collect())
            .unwrap_or_default();
        let mut st = LessonState {
            kind: kind.name(),
            star: if self.ring.is_some() {
                "mesh"
            } else {
                "lattice"
            },
            k1: ind.k1(),
            k2: ind.k2(),
            extent: self.extent,
            indicatrix,
            asymptotes,
            center: [0.0, 0.0],
            ring: Vec::new(),
            triangle_conics: Vec::new(),
            hexagon: Vec::new(),
            hexagon_conic: Vec::new(),
            verdict: "undecided",
            reason: String::new(),
            conditions: Vec::new(),
            dragged: self.dragged.map(p),
            conjugate: self
                .dragged
                .and_then(|d| ind.conjugate_direction(&d).ok())
                .map(p),
        };
        if let Some(ring) = self.ring {
            self.mesh_star_state(&mut st, &ring);
            return st;
        }
        let star = match self.star() {
            Ok(s) => s,
            Err(e) => {
                st.reason = e;
                return st;
            }
        };
        st.ring = star.ring().iter().map(|v| p(*v)).collect();
        for t in star.triangles() {
            if let Ok(c) = dupin_conic_through(ind, &t[0], &t[1], &t[2]) {
                st.triangle_conics.push(TriangleConic {
                    center: p(c.center),
                    curves: self.conic_curves(&c),
                });
            }
        }
        match star.dupin_hexagon(ind) {
            Ok(h) => {
                st.hexagon = h.vertices.iter().map(|v| p(*v)).collect();
                st.hexagon_conic = self.conic_curves(&h.conic);
            }
            Err(e) => {
                st.reason = format!(
                    "{e}. At a {} point the Dupin conics degenerate: no Dupin hexagon (section 5.3).",
                    kind.name()
                );
                return st;
            }
        }
        let valid = star.is_valid(ind).unwrap_or(false);
        st.verdict = if valid { "valid" } else { "invalid" };
        if kind == PointType::Elliptic {
            let inside = star.dupin_center_inside(ind).unwrap_or(false);
            let open = star
                .edges_not_enclosed_by_conjugate_pair(ind)
                .unwrap_or(false);
            st.conditions = vec![
                Condition {
                    text: "1) the Dupin hexagon is simple".into(),
                    holds: valid,
                },
                Condition {
                    text: "2) the Dupin center of the fundamental triangle is inside it".into(),
                    holds: inside,
                },
                Condition {
                    text: "3) no conjugate pair of directions encloses the three edge directions"
                        .into(),
                    holds: open,
                },
            ];
            st.reason = if valid {
                "K > 0: the Dupin center lies inside the fundamental triangle, so the Dupin hexagon is simple (Proposition 4, section 4.2).".into()
            } else {
                "K > 0: the Dupin center lies outside the fundamental triangle and a conjugate pair encloses its edge directions, so the Dupin hexagon self-intersects (Proposition 4, section 4.2).".into()
            };
        } else {
            let branches = star.vertices_on_different_branches(ind).unwrap_or(false);
            let ranges = star.edges_not_in_one_asymptotic_range(ind).unwrap_or(false);
            st.conditions = vec![
                Condition {
                    text: "1) the Dupin hexagon is simple".into(),
                    holds: valid,
                },
                Condition {
                    text: "2) the triangle's vertices lie on different branches of its Dupin hyperbola".into(),
                    holds: branches,
                },
                Condition {
                    text: "3) the edge directions are not all in one range between the asymptotes".into(),
                    holds: ranges,
                },
            ];
            st.reason = if valid {
                "K < 0: the fundamental triangle's vertices lie on both branches of its Dupin hyperbola, so the Dupin hexagon is simple (Proposition 5, section 4.2).".into()
            } else {
                "K < 0: all three vertices lie on one branch and all edge directions lie between the same asymptotes, so the Dupin hexagon self-intersects (Proposition 5, section 4.2).".into()
            };
        }
        st
    }

    /// A mesh vertex's star: six independent triangles (centre, r_i, r_i+1). Its Dupin hexagon
    /// joins their Dupin centers; it is valid when that hexagon is simple (the definition,
    /// section 4.1). Propositions 4 and 5 are about lattice stars, so they are evaluated per
    /// triangle, each as the fundamental triangle of its own lattice star.
    fn mesh_star_state(&self, st: &mut LessonState, ring: &[Vec2; 6]) {
        let ind = &self.ind;
        st.ring = ring.iter().map(|v| p(*v)).collect();
        let o = Vec2::zeros();
        let mut centers = Vec::new();
        for i in 0..6 {
            let (a, b) = (ring[i], ring[(i + 1) % 6]);
            match dupin_conic_through(ind, &o, &a, &b) {
                Ok(c) => {
                    centers.push(c.center);
                    st.triangle_conics.push(TriangleConic {
                        center: p(c.center),
                        curves: self.conic_curves(&c),
                    });
                }
                Err(e) => {
                    st.reason = format!(
                        "{e}. At a {} point the Dupin conics degenerate: no Dupin hexagon (section 5.3).",
                        ind.point_type().name()
                    );
                    return;
                }
            }
        }
        st.hexagon = centers.iter().map(|v| p(*v)).collect();
        let simple = is_simple_polygon(&centers).unwrap_or(false);
        st.verdict = if simple { "valid" } else { "invalid" };
        let elliptic = ind.point_type() == PointType::Elliptic;
        st.conditions.push(Condition {
            text: "the Dupin hexagon of this star is simple (validity, section 4.1)".into(),
            holds: simple,
        });
        let mut lattice_valid = 0;
        for i in 0..6 {
            let Ok(t) = TriangleStar::new(o, ring[i], ring[(i + 1) % 6]) else {
                continue;
            };
            let (holds, what) = if elliptic {
                (
                    t.dupin_center_inside(ind).unwrap_or(false),
                    "its Dupin center lies inside it (Prop. 4)",
                )
            } else {
                (
                    t.vertices_on_different_branches(ind).unwrap_or(false),
                    "its vertices lie on both branches of its Dupin hyperbola (Prop. 5)",
                )
            };
            lattice_valid += usize::from(holds);
            st.conditions.push(Condition {
                text: format!("triangle {}: {what}", i + 1),
                holds,
            });
        }
        st.reason = format!(
            "The projected star of a mesh vertex: six different triangles, so its validity is the definition: the Dupin hexagon joining their Dupin centers is {} (section 4.1). {lattice_valid} of 6 triangles would give a valid lattice star by Proposition {} (section 4.2).",
            if simple {
                "simple"
            } else {
                "self-intersecting"
            },
            if elliptic { 4 } else { 5 }
        );
    }

    /// The section 5.1 construction on the base A = centre, B = ring vertex a.
    pub(crate) fn ideal_steps(&self) -> Result<Vec<IdealStep>, String> {
        let (a, b) = (Vec2::zeros(), self.a);
        let t = ideal_triangle(&self.ind, &a, &b).map_err(|e| e.to_string())?;
        let seg = |u: Vec2, v: Vec2| [u.x, u.y, v.x, v.y];
        let ell = t.m + t.direction * (1.5 * t.step);
        let ell0 = t.m - t.direction * (0.5 * t.step);
        let base_conic = self.ind.conic(t.m, self.ind.quadratic(&((b - a) * 0.5)));
        let o = t.ideal_dupin_center(&self.ind);
        let elliptic = self.ind.point_type() == PointType::Elliptic;
        Ok(vec![
            IdealStep {
                caption: "Section 5.1: start from the base edge AB of a new triangle.",
                points: vec![("A", a.x, a.y), ("B", b.x, b.y)],
                segments: vec![seg(a, b)],
                curves: Vec::new(),
            },
            IdealStep {
                caption: "M is the midpoint of AB.",
                points: vec![("M", t.m.x, t.m.y)],
                segments: Vec::new(),
                curves: Vec::new(),
            },
            IdealStep {
                caption: "The line l through M conjugate to AB (section 5.1): the apex C lies on it.",
                points: Vec::new(),
                segments: vec![seg(ell0, ell)],
                curves: Vec::new(),
            },
            IdealStep {
                caption: if elliptic {
                    "K > 0: the Dupin ellipse with diameter AB; the parallelogram ABED with AD, BE parallel to l has DE tangent to it."
                } else {
                    "K < 0: the Dupin hyperbola centred at M through A and B; D and E make MD and ME its asymptotes (ABED a parallelogram)."
                },
                points: vec![("D", t.d.x, t.d.y), ("E", t.e.x, t.e.y)],
                segments: vec![seg(a, t.d), seg(t.d, t.e), seg(t.e, b)],
                curves: self.conic_curves(&base_conic),
            },
            IdealStep {
                caption: if elliptic {
                    "C on l with |CM| = sqrt(3) |AD|: the Dupin center O of ABC is its centroid (an ideal triangle). Any C beyond DE gives a valid star (Prop. 4)."
                } else {
                    "C on l with |CM| = sqrt(3) |AD|: the Dupin center O is (A + B + 4C)/6 (an ideal triangle). Any C beyond DE gives a valid star (Prop. 5)."
                },
                points: vec![("C", t.c.x, t.c.y), ("O", o.x, o.y)],
                segments: vec![seg(b, t.c), seg(t.c, a)],
                curves: Vec::new(),
            },
        ])
    }
}

#[wasm_bindgen]
impl DupinLesson {
    /// `new DupinLesson(surface, params, u, v)`: the lesson at (u, v) of a library surface;
    /// `params` is an object of the surface's parameters (missing keys take their defaults).
    /// Throws for unknown surfaces, bad parameters, singular or planar points.
    #[wasm_bindgen(constructor)]
    pub fn new(surface: JsValue, params: JsValue, u: f64, v: f64) -> Result<DupinLesson, JsError> {
        let surface = crate::js::string_arg(&surface, "the surface name")?;
        let (u, v) = (
            crate::js::number_arg(u, "u")?,
            crate::js::number_arg(v, "v")?,
        );
        let params: BTreeMap<String, f64> = if params.is_undefined() || params.is_null() {
            BTreeMap::new()
        } else {
            serde_wasm_bindgen::from_value(params)
                .map_err(|e| err(format!("surface parameters must be numbers: {e}")))?
        };
        let list: Vec<(&str, f64)> = params.iter().map(|(k, v)| (k.as_str(), *v)).collect();
        DupinLesson::build(&surface, &list, u, v).map_err(err)
    }

    /// The lesson at a picked mesh vertex: `pick` is what `Session.pickVertex` returned (the
    /// surface point, its principal frame and the six ring neighbours). Throws with the pick's
    /// message for a vertex without a complete star, and for planar points or flat triangles.
    #[wasm_bindgen(js_name = fromStar)]
    pub fn from_star_js(pick: JsValue) -> Result<DupinLesson, JsError> {
        let pick: StarPick = serde_wasm_bindgen::from_value(pick)
            .map_err(|e| err(format!("not a vertex pick: {e}")))?;
        DupinLesson::from_pick(&pick).map_err(err)
    }

    /// A lesson with given principal curvatures (k1, k2), for experiments and tests.
    #[wasm_bindgen(js_name = fromCurvatures)]
    pub fn from_curvatures_js(k1: f64, k2: f64) -> Result<DupinLesson, JsError> {
        DupinLesson::from_curvatures(k1, k2).map_err(err)
    }

    /// Drawing primitives and verdict (see the page's teach.js for the fields).
    pub fn state(&self) -> Result<JsValue, JsError> {
        serde_wasm_bindgen::to_value(&self.lesson_state()).map_err(err)
    }

    /// Drags ring vertex `index` (0..5) to (x, y) in the principal frame; returns the new state.
    #[wasm_bindgen(js_name = dragVertex)]
    pub fn drag_vertex(&mut self, index: usize, x: f64, y: f64) -> Result<JsValue, JsError> {
        self.drag(index, x, y).map_err(err)?;
        self.state_js()
    }

    /// The unit direction conjugate to (dx, dy) with respect to the indicatrix (section 3).
    #[wasm_bindgen(js_name = conjugateOf)]
    pub fn conjugate_of(&self, dx: f64, dy: f64) -> Result<Vec<f64>, JsError> {
        let e = self.conjugate(dx, dy).map_err(err)?;
        Ok(vec![e.x, e.y])
    }

    /// The section 5.1 construction on the star's first edge, as frames to draw cumulatively.
    #[wasm_bindgen(js_name = idealTriangleSteps)]
    pub fn ideal_triangle_steps(&self) -> Result<JsValue, JsError> {
        serde_wasm_bindgen::to_value(&self.ideal_steps().map_err(err)?).map_err(err)
    }

    /// Puts the star's apex back at the ideal position; returns the new state.
    #[wasm_bindgen(js_name = makeIdeal)]
    pub fn make_ideal_js(&mut self) -> Result<JsValue, JsError> {
        self.make_ideal().map_err(err)?;
        self.state_js()
    }

    fn state_js(&self) -> Result<JsValue, JsError> {
        serde_wasm_bindgen::to_value(&self.lesson_state()).map_err(err)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn verdict(l: &DupinLesson) -> &'static str {
        l.lesson_state().verdict
    }

    #[test]
    fn ideal_default_star_is_valid_on_both_signs() {
        for (k1, k2) in [(2.0, 0.5), (-1.0, -3.0), (1.5, -0.7), (0.4, -2.0)] {
            let l = DupinLesson::from_curvatures(k1, k2).unwrap();
            let s = l.lesson_state();
            assert_eq!(s.verdict, "valid", "k = ({k1}, {k2}): {}", s.reason);
            assert_eq!(s.ring.len(), 6);
            assert_eq!(s.hexagon.len(), 6);
            assert_eq!(s.triangle_conics.len(), 6);
            assert!(s.conditions.iter().all(|c| c.holds));
        }
    }

    /// Proposition 4: moving the apex b along the conjugate line through the midpoint of the
    /// base flips validity exactly where the Dupin center leaves the triangle (line DE of 5.1).
    #[test]
    fn validity_flips_when_the_apex_crosses_de() {
        for (k1, k2) in [(2.0, 0.5), (1.5, -0.7)] {
            let mut l = DupinLesson::from_curvatures(k1, k2).unwrap();
            let t = ideal_triangle(&l.ind, &Vec2::zeros(), &l.a).unwrap();
            let dist_de = t.step / 3f64.sqrt(); // |MD| along l
            let at = |s: f64| t.m + t.direction * s;
            // Beyond DE: valid; below DE (still above AB): invalid (section 5.1).
            let beyond = at(dist_de * 1.2);
            l.drag(1, beyond.x, beyond.y).unwrap();
            assert_eq!(verdict(&l), "valid", "k = ({k1}, {k2}) beyond DE");
            let below = at(dist_de * 0.8);
            l.drag(1, below.x, below.y).unwrap();
            let s = l.lesson_state();
            assert_eq!(s.verdict, "invalid", "k = ({k1}, {k2}) below DE");
            assert!(s.conditions.iter().all(|c| !c.holds), "{:?}", s.conditions);
            l.make_ideal().unwrap();
            assert_eq!(verdict(&l), "valid");
        }
    }

    #[test]
    fn drag_keeps_a_lattice_star_and_refuses_degenerate_ones() {
        let mut l = DupinLesson::from_curvatures(1.0, 2.0).unwrap();
        l.drag(3, -0.2, -0.1).unwrap();
        assert_eq!(l.a, Vec2::new(0.2, 0.1));
        let r = l.lesson_state().ring;
        assert_eq!(r[0], [0.2, 0.1]);
        assert_eq!(r[3], [-0.2, -0.1]);
        let before = (l.a, l.b);
        assert!(l.drag(1, 0.4, 0.2).is_err(), "b parallel to a");
        assert!(l.drag(0, f64::NAN, 0.0).is_err());
        assert!(l.drag(6, 0.1, 0.1).is_err());
        assert_eq!((l.a, l.b), before, "a refused drag changes nothing");
    }

    #[test]
    fn conjugate_and_errors() {
        let l = DupinLesson::from_curvatures(2.0, -0.5).unwrap();
        let d = Vec2::new(0.3, 0.8);
        let e = l.conjugate(d.x, d.y).unwrap();
        assert!(l.ind.bilinear(&d, &e).abs() < 1e-12);
        assert!(l.conjugate(0.0, 0.0).is_err());
        assert!(DupinLesson::from_curvatures(0.0, 0.0).is_err());
        assert!(DupinLesson::build("sphere", &[], f64::NAN, 0.0).is_err());
        assert!(DupinLesson::build("no-such-surface", &[], 0.0, 0.0).is_err());
        // A parabolic point: parallel lines, no verdict, a reason citing section 5.3.
        let par = DupinLesson::build("cylinder", &[], 0.3, 0.2).unwrap();
        let s = par.lesson_state();
        assert_eq!(s.kind, "parabolic");
        assert_eq!(s.indicatrix.len(), 2);
        assert_eq!(s.verdict, "undecided");
        assert!(s.reason.contains("5.3"), "{}", s.reason);
        assert!(par.ideal_steps().is_err());
    }

    #[test]
    fn ideal_steps_place_c_at_the_ideal_dupin_center() {
        for (k1, k2) in [(2.0, 0.5), (1.5, -0.7)] {
            let l = DupinLesson::from_curvatures(k1, k2).unwrap();
            let steps = l.ideal_steps().unwrap();
            assert_eq!(steps.len(), 5);
            let (_, cx, cy) = steps[4].points[0];
            let (_, ox, oy) = steps[4].points[1];
            let c = dupin_conic_through(&l.ind, &Vec2::zeros(), &l.a, &Vec2::new(cx, cy)).unwrap();
            assert!((c.center - Vec2::new(ox, oy)).norm() < 1e-9);
        }
    }

    #[test]
    fn torus_outer_and_inner_points_have_both_signs() {
        let out = DupinLesson::build("torus", &[], 0.0, 0.0).unwrap();
        assert_eq!(out.lesson_state().kind, "elliptic");
        let inner = DupinLesson::build("torus", &[], 0.0, PI).unwrap();
        assert_eq!(inner.lesson_state().kind, "hyperbolic");
        assert_eq!(inner.lesson_state().asymptotes.len(), 2);
    }
}

#[cfg(test)]
mod mesh_star_tests {
    use super::*;
    use dupin_core::surface::{Surface, Torus};
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// A lattice star (a, b) lifted onto the osculating paraboloid z = Q(x)/2 at a torus point.
    fn lifted(c: &Curvature, ind: &DupinIndicatrix, a: Vec2, b: Vec2) -> [Vec3; 6] {
        let f = c.frame();
        [a, b, b - a, -a, -b, a - b].map(|q| f.to_world(&q) + c.normal * (0.5 * ind.quadratic(&q)))
    }

    /// The projected star of a lifted lattice star is that lattice star, and its verdict (the
    /// definition: the Dupin hexagon is simple) agrees with Propositions 4 and 5 evaluated on
    /// every one of its six triangles, on seeded random stars at elliptic and hyperbolic points.
    #[test]
    fn mesh_star_of_a_lattice_star_follows_propositions_4_and_5() {
        let torus = Torus {
            major: 2.0,
            minor: 0.7,
        };
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let mut seen = std::collections::BTreeSet::new();
        for (u, v) in [(0.3, 0.2), (1.0, 3.0)] {
            let c = torus.curvature(u, v).unwrap();
            let ind = c.indicatrix().unwrap();
            for _ in 0..300 {
                let mut r = || Vec2::new(rng.random_range(-0.2..0.2), rng.random_range(-0.2..0.2));
                let (a, b) = (r(), r());
                let Ok(star) = TriangleStar::new(Vec2::zeros(), a, b) else {
                    continue;
                };
                let Ok(valid) = star.is_valid(&ind) else {
                    continue;
                };
                let l = DupinLesson::from_star(&c, &lifted(&c, &ind, a, b)).unwrap();
                let s = l.lesson_state();
                assert_eq!(s.star, "mesh");
                for (got, want) in s.ring.iter().zip(star.ring()) {
                    assert!((Vec2::new(got[0], got[1]) - want).norm() < 1e-12);
                }
                let verdict = if valid { "valid" } else { "invalid" };
                assert_eq!(s.verdict, verdict, "a = {a:?}, b = {b:?}");
                assert_eq!(s.conditions.len(), 7);
                assert!(
                    s.conditions.iter().all(|k| k.holds == valid),
                    "{:?}",
                    s.conditions
                );
                seen.insert((s.kind, s.verdict));
            }
        }
        assert_eq!(seen.len(), 4, "both verdicts at both point types: {seen:?}");
    }

    #[test]
    fn mesh_star_drag_moves_one_vertex_and_errors_are_messages() {
        let torus = Torus {
            major: 2.0,
            minor: 0.7,
        };
        let c = torus.curvature(0.3, 0.2).unwrap();
        let ind = c.indicatrix().unwrap();
        let ring = lifted(&c, &ind, Vec2::new(0.1, 0.02), Vec2::new(0.03, 0.1));
        let mut l = DupinLesson::from_star(&c, &ring).unwrap();
        let before = l.lesson_state().ring;
        l.drag(2, -0.09, 0.11).unwrap();
        let after = l.lesson_state().ring;
        for i in 0..6 {
            assert_eq!(before[i] == after[i], i != 2, "vertex {i}");
        }
        assert_eq!(after[2], [-0.09, 0.11]);
        // Onto the line through the centre and a neighbour: triangle 1 (or 2) is flat.
        assert!(l.drag(2, 2.0 * after[1][0], 2.0 * after[1][1]).is_err());
        assert_eq!(
            l.lesson_state().ring,
            after,
            "a refused drag changes nothing"
        );
        // A collapsed ring vertex is refused at construction.
        let mut flat = ring;
        flat[3] = c.point;
        assert!(DupinLesson::from_star(&c, &flat).is_err());
        // A pick without a star carries its message through.
        let pick = StarPick {
            vertex: 3,
            uv: [0.3, 0.2],
            point: [c.point.x, c.point.y, c.point.z],
            normal: [c.normal.x, c.normal.y, c.normal.z],
            k1: c.k1,
            k2: c.k2,
            dir1: [c.dir1.x, c.dir1.y, c.dir1.z],
            dir2: [c.dir2.x, c.dir2.y, c.dir2.z],
            neighbours: Vec::new(),
            ring: Vec::new(),
            message: Some("vertex 3 is on the boundary".into()),
            surface: "torus".into(),
            params: Default::default(),
        };
        assert_eq!(
            DupinLesson::from_pick(&pick).err().as_deref(),
            Some("vertex 3 is on the boundary")
        );
        // make_ideal turns a mesh star into the ideal lattice star: valid.
        l.make_ideal().unwrap();
        let s = l.lesson_state();
        assert_eq!((s.star, s.verdict), ("lattice", "valid"));
    }
}
