//! The Dupin center of a triangle in a tangent plane: the center of the unique Dupin conic
//! through its three vertices (P-Hex paper, section 4.1, Fig. 8 left).
//!
//! With Q the indicatrix form, the center o solves Q(a - o) = Q(b - o) = Q(c - o): two linear
//! equations 2 B(b - a, o - a) = Q(b - a), 2 B(c - a, o - a) = Q(c - a) (the circumcenter in the
//! "metric" Q). Closed-form 2 x 2 solve, no allocation.

use crate::phex::{DupinConic, DupinIndicatrix, IndicatrixError};
use crate::surface::{Curvature, PointType};
use crate::{Vec2, Vec3};
use thiserror::Error;

/// Why a Dupin center does not exist.
///
/// (P-Hex paper, section 4.1.)
#[derive(Debug, Clone, Copy, PartialEq, Error)]
pub enum DupinCenterError {
    /// A vertex or curvature is NaN or infinite.
    #[error("non-finite vertex or curvature")]
    NonFinite,
    /// K = 0 (parabolic or planar point): Dupin conics degenerate to line pairs or do not exist,
    /// so no unique circumscribing conic (section 5.3 handles this case separately).
    #[error("the point is {0:?}: no unique Dupin conic (K = 0)")]
    ZeroGaussianCurvature(PointType),
    /// Two vertices coincide or the three are collinear (relative area below 1e-12).
    #[error("degenerate triangle (coincident or collinear vertices)")]
    DegenerateTriangle,
}

impl From<IndicatrixError> for DupinCenterError {
    fn from(e: IndicatrixError) -> Self {
        match e {
            IndicatrixError::Planar => DupinCenterError::ZeroGaussianCurvature(PointType::Planar),
            _ => DupinCenterError::NonFinite,
        }
    }
}

/// The Dupin conic circumscribing triangle abc (P-Hex paper, section 4.1): its `center` is the
/// triangle's Dupin center, its `level` the common value Q(vertex - center).
///
/// Inputs are 2D points in the principal frame of `ind`. Errors: non-finite input, K = 0 (by the
/// indicatrix's point type), degenerate triangle. Never returns NaN.
#[inline]
pub fn dupin_conic_through(
    ind: &DupinIndicatrix,
    a: &Vec2,
    b: &Vec2,
    c: &Vec2,
) -> Result<DupinConic, DupinCenterError> {
    let t = ind.point_type();
    if t == PointType::Parabolic || t == PointType::Planar {
        return Err(DupinCenterError::ZeroGaussianCurvature(t));
    }
    if !(a
        .iter()
        .chain(b.iter())
        .chain(c.iter())
        .all(|x| x.is_finite()))
    {
        return Err(DupinCenterError::NonFinite);
    }
    let p = b - a;
    let q = c - a;
    let cross = p.x * q.y - p.y * q.x;
    if !(cross.abs() > 1e-12 * p.norm() * q.norm()) {
        return Err(DupinCenterError::DegenerateTriangle);
    }
    let (qp, qq) = (ind.quadratic(&p), ind.quadratic(&q));
    let x = Vec2::new(
        (qp * q.y - qq * p.y) / (2.0 * ind.k1() * cross),
        (p.x * qq - q.x * qp) / (2.0 * ind.k2() * cross),
    );
    let level = ind.quadratic(&x);
    if !(x.x.is_finite() && x.y.is_finite() && level.is_finite()) {
        return Err(DupinCenterError::NonFinite);
    }
    Ok(ind.conic(a + x, level))
}

/// The Dupin center of triangle abc (section 4.1): center of [`dupin_conic_through`].
#[inline]
pub fn dupin_center(
    ind: &DupinIndicatrix,
    a: &Vec2,
    b: &Vec2,
    c: &Vec2,
) -> Result<Vec2, DupinCenterError> {
    dupin_conic_through(ind, a, b, c).map(|c| c.center)
}

/// Dupin center of a 3D triangle with respect to the curvature at one point (section 6,
/// step 2): the vertices are projected orthogonally onto the tangent plane of `curv`, the
/// Dupin center is computed there and returned as a 3D point of that tangent plane.
#[inline]
pub fn dupin_center_3d(
    curv: &Curvature,
    a: &Vec3,
    b: &Vec3,
    c: &Vec3,
) -> Result<Vec3, DupinCenterError> {
    let f = curv.frame();
    let ind = curv.indicatrix()?;
    let o = dupin_center(&ind, &f.to_local(a), &f.to_local(b), &f.to_local(c))?;
    Ok(f.to_world(&o))
}

/// How [`approximate_dupin_center`] placed its point.
///
/// (P-Hex paper, section 6.)
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DupinCenterMethod {
    /// Average of the three per-vertex Dupin centers (section 6, steps 2 and 3).
    Averaged,
    /// Parabolic region detected: the centroid (section 6, step 1).
    Centroid,
}

/// The approximate Dupin center of a surface triangle used to initialise P-Hex meshes (P-Hex
/// paper, section 6 "Initialization via Dupin duality"):
/// 1. if the Gaussian curvatures at the three vertices differ in sign or one has |K| below
///    `parabolic_threshold` (the paper uses 1e-8), the centroid;
/// 2. otherwise, for each vertex, the Dupin center of the triangle projected onto that vertex's
///    tangent plane with that vertex's indicatrix;
/// 3. the average of the three.
///
/// `curv[i]` is the curvature at vertex i (its `point` is the vertex). Errors: non-finite input
/// or a degenerate projected triangle.
pub fn approximate_dupin_center(
    curv: [&Curvature; 3],
    parabolic_threshold: f64,
) -> Result<(Vec3, DupinCenterMethod), DupinCenterError> {
    let p = [curv[0].point, curv[1].point, curv[2].point];
    if !p.iter().all(|v| v.iter().all(|x| x.is_finite())) {
        return Err(DupinCenterError::NonFinite);
    }
    let k = [curv[0].gaussian, curv[1].gaussian, curv[2].gaussian];
    if !k.iter().all(|x| x.is_finite()) {
        return Err(DupinCenterError::NonFinite);
    }
    let same_sign =
        (k[0] > 0.0 && k[1] > 0.0 && k[2] > 0.0) || (k[0] < 0.0 && k[1] < 0.0 && k[2] < 0.0);
    if !same_sign || k.iter().any(|x| x.abs() < parabolic_threshold) {
        return Ok(((p[0] + p[1] + p[2]) / 3.0, DupinCenterMethod::Centroid));
    }
    let mut sum = Vec3::zeros();
    for (i, c) in curv.iter().enumerate() {
        sum += dupin_center_3d(c, &p[i], &p[(i + 1) % 3], &p[(i + 2) % 3])?;
    }
    Ok((sum / 3.0, DupinCenterMethod::Averaged))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn vertices_are_on_the_conic_and_it_is_unique() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        for _ in 0..10_000 {
            let mut k = || {
                let x: f64 = rng.random_range(0.1..4.0);
                if rng.random_bool(0.5) { x } else { -x }
            };
            let ind = DupinIndicatrix::new(k(), k()).unwrap();
            let mut p = || Vec2::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
            let (a, b, c) = (p(), p(), p());
            let Ok(conic) = dupin_conic_through(&ind, &a, &b, &c) else {
                continue;
            };
            let s = conic.level.abs().max(1e-300);
            let o = conic.center;
            let scale = 1.0 + o.norm_squared();
            for v in [a, b, c] {
                assert!(
                    (ind.quadratic(&(v - o)) - conic.level).abs() <= 1e-9 * scale * 4.0,
                    "{s}"
                );
            }
        }
    }

    #[test]
    fn section_6_approximation_tends_to_the_tangent_dual_point() {
        use crate::phex::tangent_dual_point;
        use crate::surface::{Surface, Torus};
        let t = Torus {
            major: 2.0,
            minor: 0.7,
        };
        let mut errs = Vec::new();
        for k in 0..4 {
            let h = 0.1 / 2f64.powi(k);
            let uv = [(0.5, 0.4), (0.5 + h, 0.4), (0.5 + 0.3 * h, 0.4 + h)];
            let c: Vec<Curvature> = uv
                .iter()
                .map(|&(u, v)| t.curvature(u, v).unwrap())
                .collect();
            let (o, how) = approximate_dupin_center([&c[0], &c[1], &c[2]], 1e-8).unwrap();
            assert_eq!(how, DupinCenterMethod::Averaged);
            let td = tangent_dual_point(
                [&c[0].point, &c[1].point, &c[2].point],
                [&c[0].normal, &c[1].normal, &c[2].normal],
            )
            .unwrap();
            errs.push((o - td.point).norm() / h);
        }
        // O(h^2) error, so error / h shrinks by about 2 per halving.
        for w in errs.windows(2) {
            assert!(w[1] < 0.7 * w[0], "{errs:?}");
        }
        // Mixed signs of K: the centroid.
        let c: Vec<Curvature> = [(0.5, 1.5), (0.5, 1.6), (0.6, 1.6)]
            .iter()
            .map(|&(u, v)| t.curvature(u, v).unwrap())
            .collect();
        let (o, how) = approximate_dupin_center([&c[0], &c[1], &c[2]], 1e-8).unwrap();
        assert_eq!(how, DupinCenterMethod::Centroid);
        assert!((o - (c[0].point + c[1].point + c[2].point) / 3.0).norm() < 1e-15);
    }

    #[test]
    fn circle_case_is_the_circumcenter() {
        let ind = DupinIndicatrix::new(2.0, 2.0).unwrap();
        let o = dupin_center(
            &ind,
            &Vec2::new(0.0, 0.0),
            &Vec2::new(2.0, 0.0),
            &Vec2::new(0.0, 2.0),
        )
        .unwrap();
        assert!((o - Vec2::new(1.0, 1.0)).norm() < 1e-15);
    }

    #[test]
    fn degenerate_input_is_a_typed_error() {
        let ind = DupinIndicatrix::new(1.0, 2.0).unwrap();
        let (a, b) = (Vec2::new(0.0, 0.0), Vec2::new(1.0, 0.0));
        assert_eq!(
            dupin_center(&ind, &a, &b, &b),
            Err(DupinCenterError::DegenerateTriangle)
        );
        assert_eq!(
            dupin_center(&ind, &a, &b, &Vec2::new(3.0, 0.0)),
            Err(DupinCenterError::DegenerateTriangle)
        );
        assert_eq!(
            dupin_center(&ind, &a, &b, &Vec2::new(f64::NAN, 1.0)),
            Err(DupinCenterError::NonFinite)
        );
        let c = Vec2::new(0.0, 1.0);
        assert_eq!(
            dupin_center(&DupinIndicatrix::new(1.0, 0.0).unwrap(), &a, &b, &c),
            Err(DupinCenterError::ZeroGaussianCurvature(
                PointType::Parabolic
            ))
        );
        assert_eq!(
            dupin_center(&DupinIndicatrix::new(0.0, 0.0).unwrap(), &a, &b, &c),
            Err(DupinCenterError::ZeroGaussianCurvature(PointType::Planar))
        );
        // Huge but finite coordinates must not overflow into NaN silently.
        let big = Vec2::new(1e300, 1e300);
        let r = dupin_center(&ind, &a, &big, &Vec2::new(-1e300, 1e300));
        assert!(r.is_err() || r.unwrap().iter().all(|x| x.is_finite()));
    }
}
