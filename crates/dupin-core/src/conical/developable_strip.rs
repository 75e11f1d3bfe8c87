//! Developable surfaces from PQ strips (conical paper, Sec. 3, Figs. 8, 9, 16): a strip of
//! planar quads between two polylines is a discrete developable; subdividing its two boundary
//! polylines (Chaikin or cubic Lane-Riesenfeld) and restoring planarity by PQ perturbation with
//! the determinant terms, alternately, converges to a smooth developable surface.
//!
//! Inputs: a [`PqStrip`] (two polylines with the same number of points, open, closed, or a
//! Möbius band), a [`StripRule`] and a number of rounds. Output: the refined PQ strip, its
//! determinant terms and its singular curve (the intersection points of consecutive rulings).

use crate::conical::discrete_terms::quad_det_grad;
use crate::conical::{PqError, PqOptions, PqPerturbation, PqResult};
use crate::mesh::PolyMesh;
use crate::mesh::{chaikin, lane_riesenfeld_cubic};
use crate::{Stepper, Vec3};

/// A strip of quads (a_i, a_{i+1}, b_{i+1}, b_i) between two polylines.
#[derive(Debug, Clone, PartialEq)]
pub struct PqStrip {
    /// First boundary polyline.
    pub a: Vec<Vec3>,
    /// Second boundary polyline (b_i is joined to a_i by a ruling).
    pub b: Vec<Vec3>,
    /// How the ends are joined.
    pub closure: StripClosure,
}

/// How the two ends of a strip are joined.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StripClosure {
    /// Open strip: n - 1 quads.
    Open,
    /// Closed cylinder: the last quad joins (a_{n-1}, a_0, b_0, b_{n-1}).
    Closed,
    /// Möbius band: the last quad joins (a_{n-1}, b_0, a_0, b_{n-1}), a half twist.
    Moebius,
}

/// Curve subdivision rule applied to the boundary polylines.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StripRule {
    /// Chaikin's corner cutting.
    Chaikin,
    /// The cubic Lane-Riesenfeld rule (cubic B-spline).
    LaneRiesenfeldCubic,
}

impl PqStrip {
    /// Number of quads.
    pub fn num_quads(&self) -> usize {
        match self.closure {
            StripClosure::Open => self.a.len().saturating_sub(1),
            _ => self.a.len(),
        }
    }

    /// The quad corner indices into `a ++ b` (a_i = i, b_i = n + i), with the Möbius twist.
    fn quads(&self) -> Vec<[u32; 4]> {
        let n = self.a.len() as u32;
        (0..self.num_quads() as u32)
            .map(|i| {
                let j = i + 1;
                if j < n {
                    [i, j, n + j, n + i]
                } else if self.closure == StripClosure::Closed {
                    [i, 0, n, n + i]
                } else {
                    [i, n, 0, n + i]
                }
            })
            .collect()
    }

    /// The strip as a polygon mesh (vertices a then b). A Möbius band is not orientable, so
    /// its last quad cannot be oriented like the others.
    pub fn to_mesh(&self) -> PolyMesh {
        let mut p = self.a.clone();
        p.extend_from_slice(&self.b);
        PolyMesh::new(p, self.quads()).unwrap_or_default()
    }

    /// The strip cut open at the end joint (the last quad uses copies of a_0 and b_0), so it
    /// is an orientable open strip, and the vertex pairs to glue back.
    fn cut_mesh(&self) -> (PolyMesh, Vec<(usize, usize)>) {
        let n = self.a.len();
        if self.closure == StripClosure::Open {
            return (self.to_mesh(), Vec::new());
        }
        let (end_a, end_b) = match self.closure {
            StripClosure::Closed => (self.a[0], self.b[0]),
            _ => (self.b[0], self.a[0]),
        };
        let mut a = self.a.clone();
        a.push(end_a);
        let mut b = self.b.clone();
        b.push(end_b);
        let m = n + 1;
        let mut p = a;
        p.extend_from_slice(&b);
        let faces: Vec<[u32; 4]> = (0..n as u32)
            .map(|i| [i, i + 1, m as u32 + i + 1, m as u32 + i])
            .collect();
        let glue = match self.closure {
            StripClosure::Closed => vec![(0, n), (m, m + n)],
            _ => vec![(m, n), (0, m + n)],
        };
        (PolyMesh::new(p, faces).unwrap_or_default(), glue)
    }

    /// Rebuilds a strip of the same closure from the positions of its cut mesh.
    pub(crate) fn rebuild_from_cut(&self, positions: &[Vec3]) -> PqStrip {
        let n = self.a.len();
        let m = if self.closure == StripClosure::Open {
            n
        } else {
            n + 1
        };
        PqStrip {
            a: positions[..n].to_vec(),
            b: positions[m..m + n].to_vec(),
            closure: self.closure,
        }
    }

    /// One round of the curve rule on both boundary polylines (a Möbius band's boundary is one
    /// closed curve a_0..a_{n-1} b_0..b_{n-1}, subdivided as such).
    pub fn subdivide(&self, rule: StripRule) -> PqStrip {
        let apply = |pts: &[Vec3], closed: bool| match rule {
            StripRule::Chaikin => chaikin(pts, closed),
            StripRule::LaneRiesenfeldCubic => lane_riesenfeld_cubic(pts, closed),
        };
        match self.closure {
            StripClosure::Open => PqStrip {
                a: apply(&self.a, false),
                b: apply(&self.b, false),
                closure: self.closure,
            },
            StripClosure::Closed => PqStrip {
                a: apply(&self.a, true),
                b: apply(&self.b, true),
                closure: self.closure,
            },
            StripClosure::Moebius => {
                let mut c = self.a.clone();
                c.extend_from_slice(&self.b);
                let c = apply(&c, true);
                let h = c.len() / 2;
                PqStrip {
                    a: c[..h].to_vec(),
                    b: c[h..].to_vec(),
                    closure: self.closure,
                }
            }
        }
    }

    /// The four determinant terms `c_det` of every quad (conical paper, Sec. 2.2), largest
    /// absolute value.
    pub fn max_determinant(&self) -> f64 {
        let m = self.to_mesh();
        let mut worst: f64 = 0.0;
        for f in m.faces() {
            let p: Vec<Vec3> = f.iter().map(|&v| m.positions[v as usize]).collect();
            for k in 0..4 {
                let q = [p[k], p[(k + 1) % 4], p[(k + 2) % 4], p[(k + 3) % 4]];
                worst = worst.max(quad_det_grad(q).0.abs());
            }
        }
        worst
    }

    /// The singular curve (curve of regression) of the discrete developable: for every quad,
    /// the intersection of its two rulings a_i b_i and a_{i+1} b_{i+1} (coplanar in a PQ
    /// strip), with the ruling parameter t of the point (0 at a_i, 1 at b_i). `None` for
    /// parallel rulings (cylindrical quads). A t inside \[0, 1\] means the singular curve
    /// enters the strip.
    pub fn singular_curve(&self) -> Vec<Option<(Vec3, f64)>> {
        let m = self.to_mesh();
        m.faces()
            .map(|f| {
                let p: Vec<Vec3> = f.iter().map(|&v| m.positions[v as usize]).collect();
                // Rulings: p0 -> p3 (a_i -> b_i) and p1 -> p2.
                let (o1, d1) = (p[0], p[3] - p[0]);
                let (o2, d2) = (p[1], p[2] - p[1]);
                let w = o1 - o2;
                let (aa, ab, bb) = (d1.dot(&d1), d1.dot(&d2), d2.dot(&d2));
                let den = aa * bb - ab * ab;
                if den.abs() <= 1e-14 * aa * bb {
                    return None;
                }
                let s = (ab * d2.dot(&w) - bb * d1.dot(&w)) / den;
                let t = (aa * d2.dot(&w) - ab * d1.dot(&w)) / den;
                Some((0.5 * ((o1 + s * d1) + (o2 + t * d2)), s))
            })
            .collect()
    }

    /// PQ perturbation of the strip with the determinant terms on (µ = 1), glued across the
    /// end joint for closed and Möbius strips.
    pub fn perturb(&self, options: PqOptions) -> Result<(PqStrip, PqResult), PqError> {
        let Ok(r) = self.perturbation(&options)?.finish();
        Ok((self.rebuild_from_cut(&r.mesh.positions), r))
    }

    /// The stateful perturbation [`PqStrip::perturb`] runs, on the cut-open mesh: step it and
    /// read the strip back with [`PqStrip::rebuild_from_cut`].
    pub(crate) fn perturbation(&self, options: &PqOptions) -> Result<PqPerturbation, PqError> {
        let (mesh, glue) = self.cut_mesh();
        // Thin quads: the unit-edge determinants exceed the planarity measure by the aspect
        // ratio, so aim the planarity a little lower.
        let options = PqOptions {
            determinant_terms: true,
            identify: glue,
            tolerance: options.tolerance * 1e-2,
            ..options.clone()
        };
        PqPerturbation::new(&mesh, options)
    }
}

/// Developable subdivision: `rounds` times, subdivide the boundary polylines with `rule`, then
/// restore planarity by PQ perturbation. The input strip is made PQ first. Returns the strips
/// of every level (input level first) and the total number of perturbation iterations.
pub fn developable_subdivision(
    strip: &PqStrip,
    rule: StripRule,
    rounds: usize,
    options: &PqOptions,
) -> Result<(Vec<PqStrip>, usize, bool), PqError> {
    let (mut s, r) = strip.perturb(options.clone())?;
    let mut iterations = r.iterations;
    let mut converged = r.converged;
    let mut levels = vec![s.clone()];
    for _ in 0..rounds {
        let (next, r) = s.subdivide(rule).perturb(options.clone())?;
        iterations += r.iterations;
        converged &= r.converged;
        s = next;
        levels.push(s.clone());
    }
    Ok((levels, iterations, converged))
}

/// The trefoil Möbius band of Fig. 9: a strip of `n` rulings along the trefoil knot
/// (sin t + 2 sin 2t, cos t - 2 cos 2t, -sin 3t), ruling direction turning half a turn about
/// the curve's normal-binormal frame, half-width `width`.
pub fn trefoil_moebius(n: usize, width: f64) -> PqStrip {
    let n = n.max(3);
    let curve = |t: f64| {
        Vec3::new(
            t.sin() + 2.0 * (2.0 * t).sin(),
            t.cos() - 2.0 * (2.0 * t).cos(),
            -(3.0 * t).sin(),
        )
    };
    let mut a = Vec::with_capacity(n);
    let mut b = Vec::with_capacity(n);
    for i in 0..n {
        let t = std::f64::consts::TAU * i as f64 / n as f64;
        let h = 1e-4;
        let d1 = (curve(t + h) - curve(t - h)) / (2.0 * h);
        let d2 = (curve(t + h) - 2.0 * curve(t) + curve(t - h)) / (h * h);
        let tan = d1.normalize();
        let nor = (d2 - tan * tan.dot(&d2)).normalize();
        let bin = tan.cross(&nor);
        let dir = (0.5 * t).cos() * nor + (0.5 * t).sin() * bin;
        a.push(curve(t) - width * dir);
        b.push(curve(t) + width * dir);
    }
    PqStrip {
        a,
        b,
        closure: StripClosure::Moebius,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::max_planarity;

    #[test]
    fn moebius_closure_is_consistent() {
        let s = trefoil_moebius(12, 0.3);
        // Rung 0 of the next period is (b_0, a_0): the ruling at t = 2π is the reverse one.
        let m = s.to_mesh();
        assert_eq!(m.num_faces(), 12);
        assert_eq!(m.face(11), &[11, 12, 0, 23]);
        let sub = s.subdivide(StripRule::Chaikin);
        assert_eq!(sub.a.len(), 24);
    }

    #[test]
    fn trefoil_band_reproduced_as_developable() {
        // 42 control quads, 3 rounds of cubic Lane-Riesenfeld: 336 quads as in Fig. 9.
        let s = trefoil_moebius(42, 0.35);
        let (levels, _, converged) =
            developable_subdivision(&s, StripRule::LaneRiesenfeldCubic, 3, &PqOptions::default())
                .unwrap();
        assert!(converged);
        let last = levels.last().unwrap();
        assert_eq!(last.num_quads(), 336);
        assert!(max_planarity(&last.to_mesh()) <= 1e-10);
        assert!(
            last.max_determinant() <= 1e-10,
            "{}",
            last.max_determinant()
        );
    }
}
