//! NURBS surfaces brought from a CAD tool: a documented JSON form (`docs/nurbs-json.md`), checked
//! into typed errors, and evaluated with exact derivatives to second order, so that the P-Hex
//! pipeline panels an imported design as it panels a library surface (P-Hex paper, section 3:
//! the Dupin indicatrix needs the second fundamental form).
//!
//! Evaluation follows The NURBS Book (Piegl and Tiller, 2nd ed.): the knot span by bisection
//! (A2.1), the basis functions and their derivatives (A2.3) and the rational derivatives of the
//! homogeneous surface (A4.4). It is written here rather than taken from `curvo` (which the tests
//! and benchmarks use as the reference): curvo returns each evaluation in nested `Vec`s (several
//! allocations per call, in the inner loop of the triangulation, the closest-point searches and
//! every Gauss-Newton step) and would bring geo, argmin and i_overlay into the page's wasm;
//! BENCHMARKS.md has the two side by side.

use super::{Domain, Surface, SurfaceDerivatives};
use crate::Vec3;
use crate::fabrication::{LengthUnit, UnknownUnit};
use crate::math::Num;
use crate::mesh::SolverFrame;
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// The largest degree in either direction (OpenNURBS's limit for surfaces is 11 as well).
pub const MAX_NURBS_DEGREE: usize = 11;

/// The most control points a surface may have (a 1000 x 1000 net; a roof from Rhino has hundreds).
pub const MAX_NURBS_CONTROL_POINTS: usize = 1_000_000;

/// The longest JSON text [`NurbsSurface::from_json`] reads (256 MiB): a larger file is refused
/// before it is parsed.
pub const MAX_NURBS_JSON_BYTES: usize = 256 << 20;

const P1: usize = MAX_NURBS_DEGREE + 1;

/// Why a NURBS surface was refused. Indices are 0-based, as in the JSON arrays.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum NurbsError {
    /// The text is not JSON of the documented shape.
    #[error("not a NURBS surface (docs/nurbs-json.md), line {line}, column {column}: {message}")]
    Json {
        /// 1-based line of the problem.
        line: usize,
        /// 1-based column of the problem.
        column: usize,
        /// serde_json's description.
        message: String,
    },
    /// The text is longer than [`MAX_NURBS_JSON_BYTES`].
    #[error(
        "the NURBS JSON has {bytes} bytes, more than the limit of {limit}; simplify the surface \
         in the CAD tool (fewer control points)"
    )]
    TooLong {
        /// Length of the text.
        bytes: usize,
        /// [`MAX_NURBS_JSON_BYTES`].
        limit: usize,
    },
    /// A degree is 0 or above [`MAX_NURBS_DEGREE`].
    #[error("degree_{direction} is {degree}; use a degree from 1 to {max}", max = MAX_NURBS_DEGREE)]
    Degree {
        /// `u` or `v`.
        direction: char,
        /// The degree given.
        degree: usize,
    },
    /// Fewer control points than degree + 1 along a direction.
    #[error(
        "{count} control points along {direction} are too few for degree {degree}; give at \
         least {}", .degree + 1
    )]
    TooFewPoints {
        /// `u` or `v`.
        direction: char,
        /// Control points along that direction.
        count: usize,
        /// Its degree.
        degree: usize,
    },
    /// More than [`MAX_NURBS_CONTROL_POINTS`] control points.
    #[error(
        "{nu} x {nv} control points are more than the limit of {max}; rebuild the surface \
         with fewer in the CAD tool", max = MAX_NURBS_CONTROL_POINTS
    )]
    TooLarge {
        /// Rows (along u).
        nu: usize,
        /// Points per row (along v).
        nv: usize,
    },
    /// The rows of `control_points` (or `weights`) differ in length.
    #[error("row {row} of {what} has {len} entries, row 0 has {expected}")]
    RaggedNet {
        /// `control_points` or `weights`.
        what: &'static str,
        /// The row.
        row: usize,
        /// Its length.
        len: usize,
        /// Row 0's length.
        expected: usize,
    },
    /// `weights` has another number of rows than `control_points`.
    #[error("weights has {rows} rows, control_points has {expected}")]
    WeightRows {
        /// Rows of weights.
        rows: usize,
        /// Rows of control points.
        expected: usize,
    },
    /// A knot vector has the wrong length.
    #[error(
        "knots_{direction} has {got} knots; {count} control points of degree {degree} need {} \
         (or {} in Rhino's convention, without the two end knots)",
        .count + .degree + 1, .count + .degree - 1
    )]
    KnotCount {
        /// `u` or `v`.
        direction: char,
        /// Knots given.
        got: usize,
        /// Control points along that direction.
        count: usize,
        /// Its degree.
        degree: usize,
    },
    /// A knot is NaN or infinite.
    #[error("knots_{direction}[{index}] is not finite")]
    KnotNotFinite {
        /// `u` or `v`.
        direction: char,
        /// Index in the vector as given.
        index: usize,
    },
    /// A knot is smaller than the one before it.
    #[error("knots_{direction}[{index}] = {} is smaller than the knot before it", Num(*.value))]
    KnotOrder {
        /// `u` or `v`.
        direction: char,
        /// Index in the vector as given.
        index: usize,
        /// The knot.
        value: f64,
    },
    /// An interior knot repeats more often than the degree: the surface would tear there.
    #[error(
        "knot {} of knots_{direction} repeats {multiplicity} times inside the domain, more \
         than the degree {degree}: the surface would be discontinuous there",
        Num(*.value)
    )]
    KnotMultiplicity {
        /// `u` or `v`.
        direction: char,
        /// The knot.
        value: f64,
        /// How often it repeats.
        multiplicity: usize,
        /// The degree.
        degree: usize,
    },
    /// The knots give an empty parameter interval.
    #[error("knots_{direction} give an empty domain: the knots at {degree} and {end} are equal")]
    EmptyDomain {
        /// `u` or `v`.
        direction: char,
        /// First index of the domain in the full vector (the degree).
        degree: usize,
        /// Last index of the domain in the full vector (the control point count).
        end: usize,
    },
    /// A control point has a NaN or infinite coordinate.
    #[error("control point ({i}, {j}) is not finite")]
    PointNotFinite {
        /// Row (along u).
        i: usize,
        /// Column (along v).
        j: usize,
    },
    /// A moved control point farther from the net than [`MAX_MOVE_IN_NET_SIZES`] times its size.
    #[error(
        "control point {index} would be {} from the net, more than 1e6 times its size ({})",
        Num(*.distance), Num(*.size)
    )]
    PointTooFar {
        /// The index given.
        index: usize,
        /// Distance of the new point from the net's bounding box.
        distance: f64,
        /// The net's bounding-box diagonal.
        size: f64,
    },
    /// A control point index past the net (a moved control point).
    #[error("control point {index} is not in the {nu} x {nv} net")]
    PointIndex {
        /// The index given (row-major: `i * nv + j`).
        index: usize,
        /// Rows (along u).
        nu: usize,
        /// Points per row (along v).
        nv: usize,
    },
    /// A weight is not positive and finite.
    #[error("weight ({i}, {j}) is {}; weights must be positive and finite", Num(*.w))]
    Weight {
        /// Row (along u).
        i: usize,
        /// Column (along v).
        j: usize,
        /// The weight.
        w: f64,
    },
    /// The `unit` is not one Dupin knows.
    #[error("{0}")]
    Unit(#[from] UnknownUnit),
    /// [`NurbsSurface::closed_in_u`] on a net that does not wrap around.
    #[error("the surface is not closed in u: {0}")]
    NotClosed(String),
}

/// The JSON form of a NURBS surface, as documented in `docs/nurbs-json.md`: degrees, knot
/// vectors (full, `count + degree + 1` knots, or Rhino's `count + degree - 1`), control points
/// as `control_points[i][j] = [x, y, z]` with `i` along u and `j` along v, optional weights of
/// the same shape (all 1 when absent: a non-rational B-spline) and an optional length unit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NurbsDefinition {
    /// Degree along u (1 to [`MAX_NURBS_DEGREE`]).
    pub degree_u: usize,
    /// Degree along v.
    pub degree_v: usize,
    /// Knot vector along u, non-decreasing.
    pub knots_u: Vec<f64>,
    /// Knot vector along v, non-decreasing.
    pub knots_v: Vec<f64>,
    /// Control points, `nu` rows of `nv` points (Euclidean, not multiplied by the weight).
    pub control_points: Vec<Vec<[f64; 3]>>,
    /// Weights, the shape of `control_points`; `None`: all 1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weights: Option<Vec<Vec<f64>>>,
    /// Length unit of the coordinates (`mm`, `cm`, `m`, `in`, `ft`); `None`: not stated.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unit: Option<String>,
}

/// Farthest a moved control point may lie from the net, in sizes (bounding-box diagonals) of
/// the net.
pub const MAX_MOVE_IN_NET_SIZES: f64 = 1e6;

/// A checked NURBS surface, evaluated with exact first and second derivatives.
///
/// Input: a [`NurbsDefinition`] (or its JSON); output: a [`Surface`] on the domain
/// `[U[p], U[nu]] x [V[q], V[nv]]`. Outside the domain the end spans' polynomials continue, so
/// searches that step slightly over the boundary see a smooth surface. A closed surface (a
/// cylinder or torus from a CAD tool) is panelled as an open patch with a seam.
///
/// (P-Hex paper, section 3; The NURBS Book, A2.1, A2.3, A4.4.)
#[derive(Debug, Clone, PartialEq)]
pub struct NurbsSurface {
    degree: [usize; 2],
    /// Full knot vectors (`count + degree + 1` knots).
    knots: [Vec<f64>; 2],
    count: [usize; 2],
    /// Control points as given (Euclidean), point (i, j) at `i * nv + j`.
    points: Vec<[f64; 3]>,
    /// Homogeneous control points `(w x, w y, w z, w)`, point (i, j) at `i * nv + j`.
    homogeneous: Vec<[f64; 4]>,
    unit: Option<LengthUnit>,
    /// Closed in u ([`NurbsSurface::closed_in_u`]): the domain is periodic in u.
    periodic_u: bool,
}

fn direction(d: usize) -> char {
    if d == 0 { 'u' } else { 'v' }
}

/// Checks one knot vector and returns it in the full convention.
fn full_knots(
    d: usize,
    knots: &[f64],
    count: usize,
    degree: usize,
) -> Result<Vec<f64>, NurbsError> {
    let direction = direction(d);
    let full_len = count + degree + 1;
    let full: Vec<f64> = if knots.len() == full_len {
        knots.to_vec()
    } else if knots.len() + 2 == full_len && !knots.is_empty() {
        // Rhino and OpenNURBS leave out the first and the last knot: they never reach the domain.
        let mut v = Vec::with_capacity(full_len);
        v.push(knots[0]);
        v.extend_from_slice(knots);
        v.push(knots[knots.len() - 1]);
        v
    } else {
        return Err(NurbsError::KnotCount {
            direction,
            got: knots.len(),
            count,
            degree,
        });
    };
    for (index, &k) in knots.iter().enumerate() {
        if !k.is_finite() {
            return Err(NurbsError::KnotNotFinite { direction, index });
        }
        if index > 0 && k < knots[index - 1] {
            return Err(NurbsError::KnotOrder {
                direction,
                index,
                value: k,
            });
        }
    }
    let (lo, hi) = (full[degree], full[count]);
    if lo >= hi {
        return Err(NurbsError::EmptyDomain {
            direction,
            degree,
            end: count,
        });
    }
    let mut i = degree + 1;
    while i < count {
        let value = full[i];
        let multiplicity = full[i..count].iter().take_while(|&&k| k == value).count();
        if value > lo && multiplicity > degree {
            return Err(NurbsError::KnotMultiplicity {
                direction,
                value,
                multiplicity,
                degree,
            });
        }
        i += multiplicity;
    }
    Ok(full)
}

impl TryFrom<NurbsDefinition> for NurbsSurface {
    type Error = NurbsError;

    fn try_from(def: NurbsDefinition) -> Result<Self, NurbsError> {
        let degree = [def.degree_u, def.degree_v];
        for (d, &p) in degree.iter().enumerate() {
            if !(1..=MAX_NURBS_DEGREE).contains(&p) {
                return Err(NurbsError::Degree {
                    direction: direction(d),
                    degree: p,
                });
            }
        }
        let nu = def.control_points.len();
        let nv = def.control_points.first().map_or(0, Vec::len);
        if nu.saturating_mul(nv) > MAX_NURBS_CONTROL_POINTS {
            return Err(NurbsError::TooLarge { nu, nv });
        }
        for (row, r) in def.control_points.iter().enumerate() {
            if r.len() != nv {
                return Err(NurbsError::RaggedNet {
                    what: "control_points",
                    row,
                    len: r.len(),
                    expected: nv,
                });
            }
        }
        let count = [nu, nv];
        for d in 0..2 {
            if count[d] <= degree[d] {
                return Err(NurbsError::TooFewPoints {
                    direction: direction(d),
                    count: count[d],
                    degree: degree[d],
                });
            }
        }
        if let Some(w) = &def.weights {
            if w.len() != nu {
                return Err(NurbsError::WeightRows {
                    rows: w.len(),
                    expected: nu,
                });
            }
            for (row, r) in w.iter().enumerate() {
                if r.len() != nv {
                    return Err(NurbsError::RaggedNet {
                        what: "weights",
                        row,
                        len: r.len(),
                        expected: nv,
                    });
                }
            }
        }
        let knots = [
            full_knots(0, &def.knots_u, nu, degree[0])?,
            full_knots(1, &def.knots_v, nv, degree[1])?,
        ];
        let mut homogeneous = Vec::with_capacity(nu * nv);
        let mut points = Vec::with_capacity(nu * nv);
        for (i, row) in def.control_points.iter().enumerate() {
            for (j, p) in row.iter().enumerate() {
                if !p.iter().all(|c| c.is_finite()) {
                    return Err(NurbsError::PointNotFinite { i, j });
                }
                let w = def.weights.as_ref().map_or(1.0, |w| w[i][j]);
                if !(w.is_finite() && w > 0.0) {
                    return Err(NurbsError::Weight { i, j, w });
                }
                let h = [w * p[0], w * p[1], w * p[2], w];
                if !h.iter().all(|c| c.is_finite()) {
                    return Err(NurbsError::PointNotFinite { i, j });
                }
                homogeneous.push(h);
                points.push(*p);
            }
        }
        let unit = def.unit.as_deref().map(str::parse).transpose()?;
        let surface = NurbsSurface {
            degree,
            knots,
            count,
            points,
            homogeneous,
            unit,
            periodic_u: false,
        };
        // A net that wraps around in u is a closed surface (a Rhino periodic surface, a tube):
        // panelled all around, with no seam. One that wraps in v only is the same surface with
        // u and v exchanged, and is read so, to be panelled all around too.
        Ok(surface
            .clone()
            .closed_in_u()
            .or_else(|_| surface.transposed().closed_in_u())
            .unwrap_or(surface))
    }
}

impl NurbsSurface {
    /// This surface as closed in u, its domain periodic in u (a tube or a vault all around):
    /// a periodic B-spline in u written out, i.e. u knots uniformly spaced (no end
    /// multiplicity; the first and the last knot, which never reach the domain, may be
    /// anything, as Rhino leaves them out) and the last `degree_u` rows of control points and
    /// weights repeating the first ones, so the surface joins itself across u = lo ~ hi with
    /// continuous derivatives up to order `degree_u - 1` (second order for bicubics). Reading
    /// a definition (`NurbsSurface::try_from`) does this whenever the net so wraps. Errors
    /// ([`NurbsError::NotClosed`]) name what does not wrap.
    pub fn closed_in_u(mut self) -> Result<Self, NurbsError> {
        let p = self.degree[0];
        let [nu, nv] = self.count;
        let k = &self.knots[0][1..self.knots[0].len() - 1];
        let step = (k[k.len() - 1] - k[0]) / (k.len() - 1) as f64;
        if let Some(i) = (1..k.len()).find(|&i| ((k[i] - k[i - 1]) - step).abs() > 1e-9 * step) {
            return Err(NurbsError::NotClosed(format!(
                "u knots {i} and {} are not one uniform step apart",
                i + 1
            )));
        }
        if nu < 2 * p {
            return Err(NurbsError::NotClosed(format!(
                "{nu} rows of control points are too few to repeat {p}"
            )));
        }
        for r in 0..p {
            for j in 0..nv {
                let (a, b) = (r * nv + j, (nu - p + r) * nv + j);
                if self.homogeneous[a] != self.homogeneous[b] {
                    return Err(NurbsError::NotClosed(format!(
                        "control point ({}, {j}) does not repeat ({r}, {j})",
                        nu - p + r
                    )));
                }
            }
        }
        self.periodic_u = true;
        Ok(self)
    }

    /// The same surface with u and v exchanged: control point (i, j) becomes (j, i), the
    /// degrees and knot vectors trade places, and the domain is not periodic.
    fn transposed(&self) -> Self {
        let [nu, nv] = self.count;
        // New point (a, b) is stored at a nu + b and was old point (b, a).
        let old = |k: usize| (k % nu) * nv + k / nu;
        NurbsSurface {
            degree: [self.degree[1], self.degree[0]],
            knots: [self.knots[1].clone(), self.knots[0].clone()],
            count: [nv, nu],
            points: (0..nu * nv).map(|k| self.points[old(k)]).collect(),
            homogeneous: (0..nu * nv).map(|k| self.homogeneous[old(k)]).collect(),
            unit: self.unit,
            periodic_u: false,
        }
    }

    /// Whether the domain is periodic in u ([`NurbsSurface::closed_in_u`]).
    pub fn is_closed_in_u(&self) -> bool {
        self.periodic_u
    }

    /// Reads the JSON form (`docs/nurbs-json.md`). Errors name the line and column of malformed
    /// JSON, or the array entry that breaks a rule.
    pub fn from_json(text: &str) -> Result<Self, NurbsError> {
        if text.len() > MAX_NURBS_JSON_BYTES {
            return Err(NurbsError::TooLong {
                bytes: text.len(),
                limit: MAX_NURBS_JSON_BYTES,
            });
        }
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let def: NurbsDefinition = serde_json::from_str(text).map_err(|e| NurbsError::Json {
            line: e.line(),
            column: e.column(),
            message: crate::mesh::io::quoted(&e.to_string()),
        })?;
        Self::try_from(def)
    }

    /// The JSON form, with full knot vectors and explicit weights; [`NurbsSurface::from_json`]
    /// reads it back to the same surface, bit for bit.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(&self.definition())
            .expect("a definition of finite numbers serialises")
    }

    /// The surface as a [`NurbsDefinition`] (full knots, Euclidean points, explicit weights).
    pub fn definition(&self) -> NurbsDefinition {
        let [nu, nv] = self.count;
        let rows = |i: usize| i * nv..(i + 1) * nv;
        NurbsDefinition {
            degree_u: self.degree[0],
            degree_v: self.degree[1],
            knots_u: self.knots[0].clone(),
            knots_v: self.knots[1].clone(),
            control_points: (0..nu).map(|i| self.points[rows(i)].to_vec()).collect(),
            weights: Some(
                (0..nu)
                    .map(|i| self.homogeneous[rows(i)].iter().map(|h| h[3]).collect())
                    .collect(),
            ),
            unit: self.unit.map(|u| u.name().to_string()),
        }
    }

    /// Degrees along u and v.
    pub fn degrees(&self) -> (usize, usize) {
        (self.degree[0], self.degree[1])
    }

    /// Control points along u and v.
    pub fn control_net_size(&self) -> (usize, usize) {
        (self.count[0], self.count[1])
    }

    /// The length unit the file states, if any.
    pub fn unit(&self) -> Option<LengthUnit> {
        self.unit
    }

    /// The control points (Euclidean), point (i, j) at `i * nv + j`.
    pub fn control_points(&self) -> &[[f64; 3]] {
        &self.points
    }

    /// Moves control point `index` (row-major, `i * nv + j`) to `p`, keeping its weight (at
    /// most [`MAX_MOVE_IN_NET_SIZES`] net sizes from the net, where evaluation stays exact): the
    /// surface changes over the `(p + 1) x (q + 1)` spans the point supports and nowhere else
    /// (The NURBS Book, P3.6). On a surface closed in u a point of the first or the last
    /// `degree_u` rows moves with its copy, so the surface stays closed. Fails, leaving the
    /// surface as it was, for an index past the net or a point that is not finite (also once
    /// weighted).
    pub fn set_control_point(&mut self, index: usize, p: Vec3) -> Result<(), NurbsError> {
        let [nu, nv] = self.count;
        if index >= nu * nv {
            return Err(NurbsError::PointIndex { index, nu, nv });
        }
        let (lo, hi) = self.control_bounds();
        let size = (hi - lo).norm();
        let distance = (p - p.sup(&lo).inf(&hi)).norm();
        if !(distance <= MAX_MOVE_IN_NET_SIZES * size) && p.iter().all(|c| c.is_finite()) {
            return Err(NurbsError::PointTooFar {
                index,
                distance,
                size,
            });
        }
        let w = self.homogeneous[index][3];
        let h = [w * p.x, w * p.y, w * p.z, w];
        if !h.iter().all(|c| c.is_finite()) {
            return Err(NurbsError::PointNotFinite {
                i: index / nv,
                j: index % nv,
            });
        }
        // On a surface closed in u the first `degree_u` rows are the last ones: a point there
        // moves with its copy, and the surface stays closed.
        let (i, j, p_u) = (index / nv, index % nv, self.degree[0]);
        let copy = match i {
            _ if !self.periodic_u => None,
            i if i < p_u => Some(i + nu - p_u),
            i if i >= nu - p_u => Some(i + p_u - nu),
            _ => None,
        };
        for k in std::iter::once(index).chain(copy.map(|c| c * nv + j)) {
            self.points[k] = [p.x, p.y, p.z];
            self.homogeneous[k] = h;
        }
        Ok(())
    }

    /// This surface with every control point mapped into `frame`, weights and knots kept: the
    /// same surface in the solver's coordinates (a NURBS surface follows an affine map of its
    /// control points, The NURBS Book, Sec. 4.4), exactly but for rounding, with the same
    /// parameters.
    pub fn in_frame(&self, frame: &SolverFrame) -> NurbsSurface {
        let points: Vec<[f64; 3]> = self
            .points
            .iter()
            .map(|&p| frame.to_solver(Vec3::from(p)).into())
            .collect();
        let homogeneous = points
            .iter()
            .zip(&self.homogeneous)
            .map(|(p, h)| [h[3] * p[0], h[3] * p[1], h[3] * p[2], h[3]])
            .collect();
        NurbsSurface {
            points,
            homogeneous,
            ..self.clone()
        }
    }

    /// Axis-aligned bounds of the control points (the surface lies in their convex hull).
    pub fn control_bounds(&self) -> (Vec3, Vec3) {
        let mut lo = Vec3::repeat(f64::INFINITY);
        let mut hi = Vec3::repeat(f64::NEG_INFINITY);
        for p in &self.points {
            let p = Vec3::from(*p);
            lo = lo.inf(&p);
            hi = hi.sup(&p);
        }
        (lo, hi)
    }
}

/// A2.1: the span index `i` in `[p, n]` with `U[i] <= t < U[i + 1]` (the last span for
/// `t >= U[n + 1]`, the first for `t < U[p]`).
fn find_span(knots: &[f64], count: usize, p: usize, t: f64) -> usize {
    let inside = &knots[p + 1..count];
    p + inside.partition_point(|&k| k <= t)
}

/// The knot span of `t` and the cubic basis functions non-zero there, `N[span - 3 + r]`
/// (r = 0..=3): what a least-squares fit sums per data point.
pub(super) fn basis_values(knots: &[f64], count: usize, p: usize, t: f64) -> (usize, [f64; 4]) {
    debug_assert_eq!(p, 3);
    let span = find_span(knots, count, p, t);
    (span, basis_derivatives::<4>(knots, span, p, t)[0])
}

/// A2.3: the non-zero basis functions `N[i - p + r]` (r = 0..=p) at `t` and their first and
/// second derivatives, `ders[k][r]`, for `p < N` (arrays of N: the cubic path's are a ninth of
/// the general one's, which callgrind showed zeroing took 6% of a P-Hex run).
fn basis_derivatives<const N: usize>(
    knots: &[f64],
    span: usize,
    p: usize,
    t: f64,
) -> [[f64; N]; 3] {
    let mut ndu = [[0.0; N]; N];
    let mut left = [0.0; N];
    let mut right = [0.0; N];
    ndu[0][0] = 1.0;
    for j in 1..=p {
        left[j] = t - knots[span + 1 - j];
        right[j] = knots[span + j] - t;
        let mut saved = 0.0;
        for r in 0..j {
            ndu[j][r] = right[r + 1] + left[j - r];
            let temp = ndu[r][j - 1] / ndu[j][r];
            ndu[r][j] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        ndu[j][j] = saved;
    }
    let mut ders = [[0.0; N]; 3];
    for j in 0..=p {
        ders[0][j] = ndu[j][p];
    }
    let nd = p.min(2);
    let mut a = [[0.0; N]; 2];
    for r in 0..=p {
        let (mut s1, mut s2) = (0, 1);
        a[0][0] = 1.0;
        for k in 1..=nd {
            let mut d = 0.0;
            let rk = r as isize - k as isize;
            let pk = p - k;
            if r >= k {
                a[s2][0] = a[s1][0] / ndu[pk + 1][rk as usize];
                d = a[s2][0] * ndu[rk as usize][pk];
            }
            let j1 = if rk >= -1 { 1 } else { (-rk) as usize };
            let j2 = if r as isize - 1 <= pk as isize {
                k - 1
            } else {
                p - r
            };
            for j in j1..=j2 {
                let idx = (rk + j as isize) as usize;
                a[s2][j] = (a[s1][j] - a[s1][j - 1]) / ndu[pk + 1][idx];
                d += a[s2][j] * ndu[idx][pk];
            }
            if r <= pk {
                a[s2][k] = -a[s1][k - 1] / ndu[pk + 1][r];
                d += a[s2][k] * ndu[r][pk];
            }
            ders[k][r] = d;
            std::mem::swap(&mut s1, &mut s2);
        }
    }
    let mut factor = p as f64;
    for (k, row) in ders.iter_mut().enumerate().take(nd + 1).skip(1) {
        for x in row.iter_mut().take(p + 1) {
            *x *= factor;
        }
        factor *= (p - k) as f64;
    }
    ders
}

impl Surface for NurbsSurface {
    fn domain(&self) -> Domain {
        let [p, q] = self.degree;
        let [nu, nv] = self.count;
        Domain {
            u: (self.knots[0][p], self.knots[0][nu]),
            v: (self.knots[1][q], self.knots[1][nv]),
            periodic_u: self.periodic_u,
            periodic_v: false,
        }
    }

    fn derivatives(&self, u: f64, v: f64) -> SurfaceDerivatives {
        if self.degree[0].max(self.degree[1]) <= 3 {
            self.derivatives_up_to::<4>(u, v)
        } else {
            self.derivatives_up_to::<P1>(u, v)
        }
    }
}

impl NurbsSurface {
    /// A4.4 for derivatives up to second order: the homogeneous derivatives `A(k, l)` and
    /// `w(k, l)`, then `S(k, l) = (A(k, l) - sum of binomial(k, i) binomial(l, j) w(i, j)
    /// S(k - i, l - j) over (i, j) != (0, 0)) / w`; both degrees below `N`.
    // r and s index the basis rows of all three orders and the net at once.
    #[allow(clippy::needless_range_loop)]
    fn derivatives_up_to<const N: usize>(&self, u: f64, v: f64) -> SurfaceDerivatives {
        let [p, q] = self.degree;
        let [nu, nv] = self.count;
        let su = find_span(&self.knots[0], nu, p, u);
        let sv = find_span(&self.knots[1], nv, q, v);
        let bu = basis_derivatives::<N>(&self.knots[0], su, p, u);
        let bv = basis_derivatives::<N>(&self.knots[1], sv, q, v);
        // h[k][l]: the homogeneous derivative d^(k+l)/du^k dv^l, k + l <= 2.
        let mut h = [[[0.0f64; 4]; 3]; 3];
        for r in 0..=p {
            let row = (su - p + r) * nv + (sv - q);
            let mut t = [[0.0f64; 4]; 3];
            for s in 0..=q {
                let c = &self.homogeneous[row + s];
                for (l, tl) in t.iter_mut().enumerate() {
                    let b = bv[l][s];
                    for x in 0..4 {
                        tl[x] += b * c[x];
                    }
                }
            }
            for (k, hk) in h.iter_mut().enumerate() {
                let b = bu[k][r];
                for (l, hkl) in hk.iter_mut().enumerate().take(3 - k) {
                    for x in 0..4 {
                        hkl[x] += b * t[l][x];
                    }
                }
            }
        }
        let a = |k: usize, l: usize| Vec3::new(h[k][l][0], h[k][l][1], h[k][l][2]);
        let w = |k: usize, l: usize| h[k][l][3];
        let w0 = w(0, 0);
        let s00 = a(0, 0) / w0;
        let s10 = (a(1, 0) - s00 * w(1, 0)) / w0;
        let s01 = (a(0, 1) - s00 * w(0, 1)) / w0;
        let s20 = (a(2, 0) - s10 * (2.0 * w(1, 0)) - s00 * w(2, 0)) / w0;
        let s11 = (a(1, 1) - s10 * w(0, 1) - s01 * w(1, 0) - s00 * w(1, 1)) / w0;
        let s02 = (a(0, 2) - s01 * (2.0 * w(0, 1)) - s00 * w(0, 2)) / w0;
        SurfaceDerivatives {
            p: s00,
            pu: s10,
            pv: s01,
            puu: s20,
            puv: s11,
            pvv: s02,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A cubic tube written out closed in u (8 rows around, 3 repeated) is a smooth closed
    /// surface: value, first and second derivatives agree across u = 0 ~ 1 and its domain is
    /// periodic; a clamped net, uneven knots or a row that does not repeat are refused.
    #[test]
    fn a_net_written_out_closed_in_u_closes_smoothly() {
        let m = 8;
        let ring = |i: usize| {
            let a = std::f64::consts::TAU * (i % m) as f64 / m as f64;
            (0..4)
                .map(|j| {
                    [
                        2.0 * a.cos(),
                        2.0 * a.sin(),
                        j as f64 + 0.3 * (2.0 * a).sin(),
                    ]
                })
                .collect::<Vec<_>>()
        };
        let def = NurbsDefinition {
            degree_u: 3,
            degree_v: 3,
            knots_u: (0..m + 7).map(|k| (k as f64 - 3.0) / m as f64).collect(),
            knots_v: vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0],
            control_points: (0..m + 3).map(ring).collect(),
            weights: None,
            unit: None,
        };
        let tube = NurbsSurface::try_from(def.clone())
            .unwrap()
            .closed_in_u()
            .unwrap();
        assert!(tube.is_closed_in_u() && tube.domain().periodic_u);
        assert_eq!(tube.domain().u, (0.0, 1.0));
        for v in [0.0, 0.4, 1.0] {
            let (a, b) = (tube.derivatives(0.0, v), tube.derivatives(1.0, v));
            for (x, y) in [(a.p, b.p), (a.pu, b.pu), (a.puu, b.puu), (a.puv, b.puv)] {
                assert!((x - y).norm() < 1e-12 * (1.0 + x.norm()), "{x:?} {y:?}");
            }
        }
        let refused = |d: NurbsDefinition| {
            let e = NurbsSurface::try_from(d)
                .unwrap()
                .closed_in_u()
                .unwrap_err();
            assert!(matches!(e, NurbsError::NotClosed(_)), "{e}");
            e.to_string()
        };
        let mut uneven = def.clone();
        uneven.knots_u[5] += 0.01;
        assert!(refused(uneven).contains("uniform step"));
        let mut torn = def.clone();
        torn.control_points[m + 1][2][2] += 1e-3;
        assert!(refused(torn).contains("does not repeat"));
        let clamped = NurbsDefinition {
            knots_u: vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0],
            control_points: (0..4).map(ring).collect(),
            ..def
        };
        assert!(refused(clamped).contains("uniform step"));
    }

    /// A bilinear-by-biquadratic net (degree 1 along u, 2 along v) as JSON, with `edit` applied
    /// to the definition first.
    fn json_with(edit: impl FnOnce(&mut serde_json::Value)) -> String {
        let mut v = serde_json::json!({
            "degree_u": 1,
            "degree_v": 2,
            "knots_u": [0, 0, 1, 1],
            "knots_v": [0, 0, 0, 1, 1, 1],
            "control_points": [
                [[0, 0, 0], [0, 1, 1], [0, 2, 0]],
                [[1, 0, 0], [1, 1, 1], [1, 2, 0]]
            ],
            "unit": "mm"
        });
        edit(&mut v);
        v.to_string()
    }

    fn error(edit: impl FnOnce(&mut serde_json::Value)) -> NurbsError {
        NurbsSurface::from_json(&json_with(edit)).unwrap_err()
    }

    #[test]
    fn a_small_net_reads_with_its_unit_and_domain() {
        let s = NurbsSurface::from_json(&json_with(|_| {})).unwrap();
        assert_eq!(s.unit(), Some(LengthUnit::Millimetre));
        assert_eq!(s.degrees(), (1, 2));
        assert_eq!(s.control_net_size(), (2, 3));
        let d = s.domain();
        assert_eq!((d.u, d.v), ((0.0, 1.0), (0.0, 1.0)));
        // The middle of a quadratic Bezier arch of control height 1 is at height 1/2.
        let m = s.derivatives(0.5, 0.5);
        assert_eq!(m.p, Vec3::new(0.5, 1.0, 0.5));
        assert_eq!(m.pvv, Vec3::new(0.0, 0.0, -4.0));
        assert_eq!(m.puu, Vec3::zeros());
        let (lo, hi) = s.control_bounds();
        assert_eq!((lo, hi), (Vec3::zeros(), Vec3::new(1.0, 2.0, 1.0)));
    }

    /// Moving a control point changes the surface where the point acts, keeps its weight, and
    /// reads back through the JSON form; a bad move is refused and changes nothing.
    #[test]
    fn a_moved_control_point_reshapes_the_surface_locally() {
        let text = json_with(|v| {
            v["weights"] = serde_json::json!([[1, 0.5, 2], [1.5, 1, 0.7]]);
        });
        let mut s = NurbsSurface::from_json(&text).unwrap();
        let before = s.clone();
        // Point (1, 1): the arch's top on the u = 1 side, weight 1.
        s.set_control_point(4, Vec3::new(1.0, 1.0, 3.0)).unwrap();
        assert_eq!(s.control_points()[4], [1.0, 1.0, 3.0]);
        let (a, b) = (before.position(1.0, 0.5), s.position(1.0, 0.5));
        assert!(b.z > a.z + 0.5, "{a} -> {b}");
        // At u = 0 (bilinear in u) the other row alone acts: the surface is unchanged there.
        assert_eq!(before.position(0.0, 0.5), s.position(0.0, 0.5));
        assert_eq!(NurbsSurface::from_json(&s.to_json()).unwrap(), s);
        let moved = s.clone();
        let e = s.set_control_point(6, Vec3::zeros()).unwrap_err();
        assert_eq!(e.to_string(), "control point 6 is not in the 2 x 3 net");
        let e = s
            .set_control_point(2, Vec3::new(f64::INFINITY, 0.0, 0.0))
            .unwrap_err();
        assert_eq!(e.to_string(), "control point (0, 2) is not finite");
        // Past a million net sizes.
        let e = s
            .set_control_point(2, Vec3::new(1e308, 0.0, 0.0))
            .unwrap_err();
        assert!(
            e.to_string().contains("more than 1e6 times its size"),
            "{e}"
        );
        assert_eq!(s, moved);
    }

    /// In a frame the surface is the same one mapped: positions map with the frame, unit
    /// normals are kept and curvatures scale with the frame's unit, at the same parameters.
    #[test]
    fn a_surface_in_a_frame_is_the_same_surface_mapped() {
        let text = json_with(|v| {
            v["weights"] = serde_json::json!([[1, 0.5, 2], [1.5, 1, 0.7]]);
        });
        let mut def = NurbsSurface::from_json(&text).unwrap().definition();
        let far = |p: [f64; 3]| (Vec3::from(p) * 1000.0 + Vec3::new(3e6, 5e6, 0.0)).into();
        for row in &mut def.control_points {
            row.iter_mut().for_each(|p| *p = far(*p));
        }
        let user = NurbsSurface::try_from(def).unwrap();
        let points: Vec<Vec3> = user.control_points().iter().map(|&p| p.into()).collect();
        let frame = SolverFrame::unit_box(&points);
        let solver = user.in_frame(&frame);
        for (u, v) in [(0.0, 0.0), (0.3, 0.7), (1.0, 0.5)] {
            let (a, b) = (user.position(u, v), frame.to_user(solver.position(u, v)));
            assert!((a - b).norm() <= 1e-9 * 1e3, "{a} vs {b}");
            let (ca, cb) = (
                user.curvature(u, v).unwrap(),
                solver.curvature(u, v).unwrap(),
            );
            assert!((ca.normal - cb.normal).norm() < 1e-9);
            let unit = frame.scale();
            assert!(
                (ca.gaussian * unit * unit - cb.gaussian).abs()
                    <= 1e-9 * cb.gaussian.abs().max(1.0)
            );
        }
        assert_eq!(solver.domain(), user.domain());
    }

    #[test]
    fn derivatives_match_finite_differences() {
        let text = json_with(|v| {
            v["weights"] = serde_json::json!([[1, 0.5, 2], [1.5, 1, 0.7]]);
        });
        let s = NurbsSurface::from_json(&text).unwrap();
        let h = 1e-5;
        for (u, v) in [(0.3, 0.2), (0.7, 0.9), (0.5, 0.5)] {
            let d = s.derivatives(u, v);
            let du = |f: &dyn Fn(f64, f64) -> Vec3| (f(u + h, v) - f(u - h, v)) / (2.0 * h);
            let dv = |f: &dyn Fn(f64, f64) -> Vec3| (f(u, v + h) - f(u, v - h)) / (2.0 * h);
            let pu = |a, b| s.derivatives(a, b).pu;
            let pv = |a, b| s.derivatives(a, b).pv;
            let p = |a, b| s.derivatives(a, b).p;
            for (got, want) in [
                (d.pu, du(&p)),
                (d.pv, dv(&p)),
                (d.puu, du(&pu)),
                (d.puv, dv(&pu)),
                (d.pvv, dv(&pv)),
            ] {
                assert!(
                    (got - want).norm() < 1e-6 * (1.0 + want.norm()),
                    "{got:?} {want:?}"
                );
            }
        }
    }

    #[test]
    fn every_rule_has_its_error() {
        let msg = |e: NurbsError| e.to_string();
        assert!(matches!(
            NurbsSurface::from_json("{\"degree_u\": 1,\n \"degree_v\": }").unwrap_err(),
            NurbsError::Json { line: 2, .. }
        ));
        assert!(
            msg(error(|v| v["degree_u"] = 0.into()))
                .contains("degree_u is 0; use a degree from 1 to 11")
        );
        assert!(matches!(
            error(|v| v["degree_v"] = 3.into()),
            NurbsError::TooFewPoints {
                direction: 'v',
                count: 3,
                degree: 3
            }
        ));
        assert!(matches!(
            error(|v| v["control_points"][1] = serde_json::json!([[1, 0, 0]])),
            NurbsError::RaggedNet {
                what: "control_points",
                row: 1,
                len: 1,
                expected: 3
            }
        ));
        assert_eq!(
            msg(error(|v| v["knots_v"] = serde_json::json!([0, 1, 1]))),
            "knots_v has 3 knots; 3 control points of degree 2 need 6 (or 4 in Rhino's \
             convention, without the two end knots)"
        );
        assert!(matches!(
            error(|v| v["knots_u"] = serde_json::json!([0, 1, 0.5, 1])),
            NurbsError::KnotOrder {
                direction: 'u',
                index: 2,
                ..
            }
        ));
        assert!(matches!(
            error(|v| v["knots_u"] = serde_json::json!([1, 1, 1, 1])),
            NurbsError::EmptyDomain { direction: 'u', .. }
        ));
        assert!(matches!(
            error(|v| v["weights"] = serde_json::json!([[1, 1, 1], [1, 0, 1]])),
            NurbsError::Weight { i: 1, j: 1, .. }
        ));
        assert!(matches!(
            error(|v| v["weights"] = serde_json::json!([[1, 1, 1]])),
            NurbsError::WeightRows {
                rows: 1,
                expected: 2
            }
        ));
        assert!(msg(error(|v| v["unit"] = "furlong".into())).contains("unknown length unit"));
        // An unknown field is a typo, not something to ignore.
        assert!(matches!(
            error(|v| v["degre_u"] = 1.into()),
            NurbsError::Json { .. }
        ));
        // Finite in the file but not once weighted.
        assert!(matches!(
            error(|v| {
                v["control_points"][0][0] = serde_json::json!([1e308, 0, 0]);
                v["weights"] = serde_json::json!([[10, 1, 1], [1, 1, 1]]);
            }),
            NurbsError::PointNotFinite { i: 0, j: 0 }
        ));
        // Five equal interior knots on a degree-2 direction tear the surface.
        let torn = error(|v| {
            v["control_points"] = serde_json::json!([
                [
                    [0, 0, 0],
                    [0, 1, 0],
                    [0, 2, 0],
                    [0, 3, 0],
                    [0, 4, 0],
                    [0, 5, 0]
                ],
                [
                    [1, 0, 0],
                    [1, 1, 0],
                    [1, 2, 0],
                    [1, 3, 0],
                    [1, 4, 0],
                    [1, 5, 0]
                ]
            ]);
            v["knots_v"] = serde_json::json!([0, 0, 0, 0.5, 0.5, 0.5, 1, 1, 1]);
        });
        assert!(matches!(
            torn,
            NurbsError::KnotMultiplicity {
                direction: 'v',
                multiplicity: 3,
                degree: 2,
                ..
            }
        ));
        let big = "x".repeat(MAX_NURBS_JSON_BYTES + 1);
        assert!(matches!(
            NurbsSurface::from_json(&big),
            Err(NurbsError::TooLong { .. })
        ));
    }
}
