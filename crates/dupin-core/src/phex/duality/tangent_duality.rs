//! Tangent duality: the meeting point of three tangent planes (P-Hex paper, section 4.1,
//! Fig. 6), with a condition estimate that tells when the construction breaks down (nearly
//! parallel planes: vertices too close or curvature too small).

use crate::Vec3;
use nalgebra::Matrix3;
use thiserror::Error;

/// Why three planes have no (reliable) meeting point.
///
/// (P-Hex paper, section 4.1.)
#[derive(Debug, Clone, Copy, PartialEq, Error)]
pub enum TangentDualityError {
    /// A point or normal is NaN or infinite.
    #[error("non-finite plane")]
    NonFinite,
    /// A normal is the zero vector.
    #[error("zero plane normal")]
    ZeroNormal,
    /// The normals are linearly dependent to working precision (reciprocal condition number
    /// below 1e-14): two planes are parallel or the three share a line direction.
    #[error("the three planes are (nearly) parallel: reciprocal condition {rcond:e}")]
    Parallel {
        /// Reciprocal condition number of the normal matrix.
        rcond: f64,
    },
}

/// Meeting point of three planes and how well determined it is.
///
/// (P-Hex paper, section 4.1.)
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TangentDualPoint {
    /// The common point.
    pub point: Vec3,
    /// Reciprocal 1-norm condition number of the matrix of unit normals, in (0, 1]: 1 for three
    /// orthogonal planes, about |det| for nearly parallel ones. The computed point's error is
    /// about machine epsilon / rcond times the triangle's size (the system is solved relative to
    /// the first point); small curvature or a small triangle makes rcond O(h^2 K)-small
    /// (section 4.1's breakdown).
    pub rcond: f64,
}

/// Intersection of the planes through `points[i]` with normals `normals[i]` (the tangent planes
/// of S at a triangle's vertices; section 4.1). Normals need not be unit. Errors on non-finite
/// input, zero normals, or numerically parallel planes.
#[inline]
pub fn tangent_dual_point(
    points: [&Vec3; 3],
    normals: [&Vec3; 3],
) -> Result<TangentDualPoint, TangentDualityError> {
    let mut m = Matrix3::zeros();
    let mut rhs = Vec3::zeros();
    for i in 0..3 {
        let (p, n) = (points[i], normals[i]);
        if !(p.iter().chain(n.iter()).all(|x| x.is_finite())) {
            return Err(TangentDualityError::NonFinite);
        }
        let len = n.norm();
        if len == 0.0 {
            return Err(TangentDualityError::ZeroNormal);
        }
        let u = n / len;
        m.set_row(i, &u.transpose());
        // Relative to the first point: the error then scales with the triangle, not with the
        // distance of the planes from the origin.
        rhs[i] = u.dot(&(p - points[0]));
    }
    let Some(inv) = m.try_inverse() else {
        return Err(TangentDualityError::Parallel { rcond: 0.0 });
    };
    let norm1 = |a: &Matrix3<f64>| {
        (0..3)
            .map(|j| a.column(j).abs().sum())
            .fold(0.0_f64, f64::max)
    };
    let rcond = 1.0 / (norm1(&m) * norm1(&inv));
    if !(rcond >= 1e-14) {
        return Err(TangentDualityError::Parallel {
            rcond: if rcond.is_finite() { rcond } else { 0.0 },
        });
    }
    let point = points[0] + inv * rhs;
    if !point.iter().all(|x| x.is_finite()) {
        return Err(TangentDualityError::Parallel { rcond });
    }
    Ok(TangentDualPoint { point, rcond })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::{Sphere, Surface};

    #[test]
    fn meets_on_all_three_planes() {
        let s = Sphere { radius: 2.0 };
        let uv = [(0.1, 0.2), (0.3, 0.1), (0.2, 0.4)];
        let p: Vec<Vec3> = uv.iter().map(|&(u, v)| s.position(u, v)).collect();
        let n: Vec<Vec3> = uv.iter().map(|&(u, v)| s.normal(u, v)).collect();
        let r = tangent_dual_point([&p[0], &p[1], &p[2]], [&n[0], &n[1], &n[2]]).unwrap();
        for i in 0..3 {
            assert!((r.point - p[i]).dot(&n[i]).abs() < 1e-12);
        }
        assert!(r.rcond > 0.0 && r.rcond < 0.1);
    }

    #[test]
    fn condition_drops_with_triangle_size_and_parallel_planes_error() {
        let s = Sphere { radius: 1.0 };
        let mut prev = 1.0;
        for k in 0..5 {
            let h = 0.2 / 4f64.powi(k);
            let uv = [(0.0, 0.0), (h, 0.0), (0.0, h)];
            let p: Vec<Vec3> = uv.iter().map(|&(u, v)| s.position(u, v)).collect();
            let n: Vec<Vec3> = uv.iter().map(|&(u, v)| s.normal(u, v)).collect();
            let r = tangent_dual_point([&p[0], &p[1], &p[2]], [&n[0], &n[1], &n[2]]).unwrap();
            assert!(r.rcond < prev);
            prev = r.rcond;
        }
        let z = Vec3::z();
        let o = Vec3::zeros();
        assert!(matches!(
            tangent_dual_point([&o, &Vec3::x(), &Vec3::y()], [&z, &z, &Vec3::x()]),
            Err(TangentDualityError::Parallel { .. })
        ));
        assert_eq!(
            tangent_dual_point([&o, &o, &o], [&z, &Vec3::zeros(), &Vec3::x()]),
            Err(TangentDualityError::ZeroNormal)
        );
        assert_eq!(
            tangent_dual_point(
                [&o, &o, &Vec3::new(f64::NAN, 0.0, 0.0)],
                [&z, &Vec3::y(), &Vec3::x()]
            ),
            Err(TangentDualityError::NonFinite)
        );
    }
}
