//! The coordinates a solver works in: the user's, centred and scaled, so that its accuracy
//! and its behaviour do not depend on where the design sits or which unit it is drawn in.
//!
//! A design in millimetres at state-plane offsets (1e7) and the same design in metres near the
//! origin must be solved alike. Solvers therefore see `q = (p - c) / s`, with `c` the centre
//! of the bounding box and `s` a length unit, and hand back `p = c + s q`. With
//! [`SolverFrame::unit_box`] the unit is a power of two, so the scaling is exact and a design
//! scaled by a power of two is solved bit for bit alike. Fixed vertices are never mapped back:
//! they keep the user's bits.

use crate::Vec3;

/// A centred and scaled frame for a set of points (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolverFrame {
    center: Vec3,
    /// The length unit, finite and positive.
    scale: f64,
}

impl SolverFrame {
    /// The frame centred on the bounding box of `points` whose length unit is `unit` (e.g. a
    /// multiple of the mean edge length, so the unknowns are of size one). The identity for
    /// no points or a unit that is not finite and positive.
    pub fn new(points: &[Vec3], unit: f64) -> Self {
        let mut lo = Vec3::repeat(f64::INFINITY);
        let mut hi = Vec3::repeat(f64::NEG_INFINITY);
        for p in points {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        if points.is_empty() || !(unit.is_finite() && unit > 0.0) {
            return SolverFrame::identity();
        }
        // Halves first: the sum of two coordinates near f64::MAX would overflow.
        let center = lo * 0.5 + hi * 0.5;
        SolverFrame {
            center,
            scale: unit,
        }
    }

    /// The frame centred on the bounding box of `points` whose unit is the power of two
    /// nearest half its longest side: the box maps into about `[-1, 1]^3`, and a design
    /// scaled by a power of two maps to the same bits.
    pub fn unit_box(points: &[Vec3]) -> Self {
        let mut lo = Vec3::repeat(f64::INFINITY);
        let mut hi = Vec3::repeat(f64::NEG_INFINITY);
        for p in points {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        let half = (hi * 0.5 - lo * 0.5).max();
        let unit = 2f64.powi(half.log2().round().clamp(-1000.0, 1000.0) as i32);
        Self::new(points, if unit.is_normal() { unit } else { half })
    }

    /// The user's coordinates unchanged.
    pub fn identity() -> Self {
        SolverFrame {
            center: Vec3::zeros(),
            scale: 1.0,
        }
    }

    /// The frame's length unit in the user's units.
    pub fn scale(&self) -> f64 {
        self.scale
    }

    /// A user's point in the solver's coordinates.
    pub fn to_solver(&self, p: Vec3) -> Vec3 {
        (p - self.center) / self.scale
    }

    /// A solver's point in the user's coordinates.
    pub fn to_user(&self, q: Vec3) -> Vec3 {
        q * self.scale + self.center
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_frame_is_centred_and_scaled() {
        let pts = [
            Vec3::new(1e7, 2e7, -5.0),
            Vec3::new(1e7 + 40.0, 2e7 + 20.0, 5.0),
        ];
        let f = SolverFrame::new(&pts, 4.0);
        assert_eq!(f.scale(), 4.0);
        assert_eq!(f.to_solver(pts[0]), Vec3::new(-5.0, -2.5, -1.25));
        assert_eq!(f.to_user(f.to_solver(pts[1])), pts[1]);
        // A unit that is not a length leaves the coordinates alone.
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert_eq!(SolverFrame::new(&pts, bad), SolverFrame::identity());
        }
        // Extreme coordinates do not overflow.
        let huge = [Vec3::repeat(f64::MAX), Vec3::repeat(-f64::MAX)];
        let f = SolverFrame::new(&huge, 1e300);
        assert!(f.to_solver(huge[0]).iter().all(|c| c.is_finite()));
    }

    #[test]
    fn a_design_scaled_by_a_power_of_two_looks_the_same_to_the_solver() {
        let pts = [Vec3::new(0.3, -1.7, 2.2), Vec3::new(-0.9, 0.4, 1.1)];
        let f = SolverFrame::unit_box(&pts);
        assert_eq!(f.scale(), 1.0);
        let big: Vec<Vec3> = pts.iter().map(|p| p * 1024.0).collect();
        let g = SolverFrame::unit_box(&big);
        assert_eq!(g.scale(), 1024.0);
        for (p, b) in pts.iter().zip(&big) {
            assert_eq!(f.to_solver(*p), g.to_solver(*b));
        }
    }
}
