//! Which way to lay the layers on a surface with parabolic curves (P-Hex paper, section 5.3 and
//! section 7, Fig. 22): the paper lays its layers across a parabolic curve, the curve running along them,
//! and advises a conjugate network that "includes the parabolic curve so that the triangulation
//! is not disrupted when crossing" it. A surface fitted to a triangle mesh gets its u and v from
//! an arbitrary corner of the mesh, so either of its parameter directions may be the one along
//! the parabolic curves; counting where the Gaussian curvature changes sign along each tells
//! them apart.

use crate::surface::Surface;

/// Sign changes of the Gaussian curvature K along the parameter lines of a surface, sampled on
/// an n x n grid of its domain: how often a u line (v fixed) and a v line (u fixed) cross a
/// parabolic curve.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ParabolicCrossings {
    /// Sign changes along the u lines, summed over the sampled lines.
    pub along_u: usize,
    /// Sign changes along the v lines, summed over the sampled lines.
    pub along_v: usize,
}

impl ParabolicCrossings {
    /// Counts the sign changes on `samples` x `samples` cell centres of `surface`'s domain.
    /// Samples with |K| at most 1e-6 of the largest |K| (flat to rounding) and samples without
    /// a curvature (singular points) are skipped: a change is counted between the two nearest
    /// samples of opposite sign.
    pub fn of(surface: &dyn Surface, samples: usize) -> Self {
        let dom = surface.domain();
        let n = samples.max(2);
        let at = |i: usize, r: (f64, f64)| r.0 + (i as f64 + 0.5) / n as f64 * (r.1 - r.0);
        let k: Vec<f64> = (0..n * n)
            .map(|ij| {
                let (i, j) = (ij / n, ij % n);
                surface
                    .curvature(at(i, dom.u), at(j, dom.v))
                    .map_or(f64::NAN, |c| c.gaussian)
            })
            .collect();
        let largest = k
            .iter()
            .filter(|x| x.is_finite())
            .fold(0.0, |a: f64, b| a.max(b.abs()));
        let sign = |x: f64| -> i8 {
            if !(x.abs() > 1e-6 * largest) {
                0
            } else if x > 0.0 {
                1
            } else {
                -1
            }
        };
        let changes = |line: &mut dyn Iterator<Item = f64>| {
            let mut last = 0;
            let mut count = 0;
            for s in line.map(sign).filter(|&s| s != 0) {
                count += usize::from(last != 0 && s != last);
                last = s;
            }
            count
        };
        ParabolicCrossings {
            along_u: (0..n)
                .map(|j| changes(&mut (0..n).map(|i| k[i * n + j])))
                .sum(),
            along_v: (0..n)
                .map(|i| changes(&mut (0..n).map(|j| k[i * n + j])))
                .sum(),
        }
    }

    /// Whether the layers should advance in u with the base curve along v (the triangulation's
    /// `swap`): when the u lines cross parabolic curves clearly more often than the v lines
    /// (over twice as often, and by more than two), so the v lines run along them. Otherwise
    /// (no parabolic curve, or one crossing both alike, as a bump's circle does) the default.
    pub fn layers_along_v(&self) -> bool {
        self.along_u > 2 * self.along_v + 2
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenes::benchmark_meshes::nurbs_roof;
    use crate::surface::NurbsSurface;

    /// The roof's parabolic line x = 0 crosses every u line (u runs along x) and no v line; a
    /// sphere has none; swapping u and v swaps the counts.
    #[test]
    fn the_roof_s_parabolic_line_crosses_its_u_lines() {
        let roof = NurbsSurface::try_from(nurbs_roof()).unwrap();
        let c = ParabolicCrossings::of(&roof, 24);
        assert_eq!(
            c,
            ParabolicCrossings {
                along_u: 24,
                along_v: 0
            }
        );
        assert!(c.layers_along_v());
        let mut def = nurbs_roof();
        def.control_points = (0..def.control_points[0].len())
            .map(|j| def.control_points.iter().map(|row| row[j]).collect())
            .collect();
        std::mem::swap(&mut def.knots_u, &mut def.knots_v);
        std::mem::swap(&mut def.degree_u, &mut def.degree_v);
        let swapped = NurbsSurface::try_from(def).unwrap();
        let c = ParabolicCrossings::of(&swapped, 24);
        assert_eq!(
            c,
            ParabolicCrossings {
                along_u: 0,
                along_v: 24
            }
        );
        assert!(!c.layers_along_v());
        let sphere = crate::surface::surface_by_name("sphere", &[]).unwrap();
        let c = ParabolicCrossings::of(sphere.as_ref(), 24);
        assert_eq!(
            c,
            ParabolicCrossings {
                along_u: 0,
                along_v: 0
            }
        );
        assert!(!c.layers_along_v());
    }
}
