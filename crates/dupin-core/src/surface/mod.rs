//! Parametric surfaces P(u, v) with analytic derivatives (P-Hex paper, section 3).
//!
//! The [`Surface`] trait asks implementors for the domain and the derivatives up to second order;
//! everything else (normal, fundamental forms, curvature, closest point) is provided from them.

mod bspline_patch;
mod closest_point;
mod curvature;
mod cylinder_cut;
mod library;
mod mesh_fit;
mod mesh_surface;
mod nurbs;
mod registry;
mod sampling;

pub use bspline_patch::{BSplinePatch, BSplinePatchError};
pub use closest_point::{ClosestPoint, ClosestPointError};
pub use curvature::{Curvature, CurvatureError, CurvatureTolerance, PointType, TangentFrame};
#[cfg(test)]
pub(crate) use library::graph_curvatures;
pub use library::{
    Catenoid, Cylinder, DupinCyclide, Ellipsoid, Enneper, FREEFORM, FreeformSurface,
    HyperbolicParaboloid, Hyperboloid, Sphere, SurfaceOfRevolution, Torus, TwistedSurface, Vase,
};
pub use mesh_fit::{MAX_FIT_TRIANGLES, MeshFit, MeshFitError, MeshFitOptions, fit_mesh_surface};
pub use mesh_surface::{MeshClosestPoint, MeshSurface, MeshSurfaceError, VertexCurvature};
pub use nurbs::{
    MAX_MOVE_IN_NET_SIZES, MAX_NURBS_CONTROL_POINTS, MAX_NURBS_DEGREE, MAX_NURBS_JSON_BYTES,
    NurbsDefinition, NurbsError, NurbsSurface,
};
pub use registry::{
    ParamSpec, RegistryError, SurfaceSpec, parse_assignment, surface_by_name, surface_catalog,
};
pub use sampling::sample_surface;

use crate::{Vec2, Vec3};

/// The parameter rectangle of a surface and which directions wrap around.
///
/// (P-Hex paper, section 3.)
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Domain {
    /// Range of u.
    pub u: (f64, f64),
    /// Range of v.
    pub v: (f64, f64),
    /// Whether u is periodic with period `u.1 - u.0`.
    pub periodic_u: bool,
    /// Whether v is periodic with period `v.1 - v.0`.
    pub periodic_v: bool,
}

impl Domain {
    /// u the angle about an axis, a full turn `[0, 2pi)` and periodic; v in `v`, not periodic:
    /// the meridian interval of a surface of revolution (sphere, cylinder, vase, catenoid,
    /// hyperboloid) or the latitude of the ellipsoid.
    pub fn full_turn_in_u(v: (f64, f64)) -> Domain {
        Domain {
            u: (0.0, std::f64::consts::TAU),
            v,
            periodic_u: true,
            periodic_v: false,
        }
    }

    /// u and v both a full turn `[0, 2pi)` and both periodic: the closed ring surfaces (torus,
    /// ring Dupin cyclide), parametrised by their two families of circles.
    pub fn full_turns() -> Domain {
        Domain {
            periodic_v: true,
            ..Domain::full_turn_in_u((0.0, std::f64::consts::TAU))
        }
    }

    /// Maps (u, v) into the domain: periodic directions wrap into `[lo, hi)`, the others are
    /// clamped to `[lo, hi]`. Non-finite input is returned unchanged.
    pub fn normalize(&self, u: f64, v: f64) -> (f64, f64) {
        fn one(x: f64, (lo, hi): (f64, f64), periodic: bool) -> f64 {
            if !x.is_finite() {
                x
            } else if periodic {
                lo + (x - lo).rem_euclid(hi - lo)
            } else {
                x.clamp(lo, hi)
            }
        }
        (
            one(u, self.u, self.periodic_u),
            one(v, self.v, self.periodic_v),
        )
    }

    /// Whether (u, v) lies in the domain (any value counts in a periodic direction).
    pub fn contains(&self, u: f64, v: f64) -> bool {
        let ok = |x: f64, (lo, hi): (f64, f64), periodic: bool| {
            x.is_finite() && (periodic || (lo <= x && x <= hi))
        };
        ok(u, self.u, self.periodic_u) && ok(v, self.v, self.periodic_v)
    }
}

/// Position and first and second partial derivatives of P at one parameter point.
///
/// (P-Hex paper, section 3.)
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceDerivatives {
    /// P(u, v).
    pub p: Vec3,
    /// dP/du.
    pub pu: Vec3,
    /// dP/dv.
    pub pv: Vec3,
    /// d2P/du2.
    pub puu: Vec3,
    /// d2P/dudv.
    pub puv: Vec3,
    /// d2P/dv2.
    pub pvv: Vec3,
}

impl SurfaceDerivatives {
    /// Unit normal along Pu x Pv (zero where the parametrisation is singular).
    pub fn normal(&self) -> Vec3 {
        self.pu
            .cross(&self.pv)
            .try_normalize(0.0)
            .unwrap_or_else(Vec3::zeros)
    }
}

/// First and second fundamental forms at one point (P-Hex paper, section 3: the Dupin indicatrix
/// is built from them).
///
/// `I = [[e, f], [f, g]]` with `e = Pu.Pu`, `f = Pu.Pv`, `g = Pv.Pv`; `II = [[l, m], [m, n]]` with
/// `l = Puu.N`, `m = Puv.N`, `n = Pvv.N` for the unit normal `N` along `Pu x Pv`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FundamentalForms {
    /// Pu . Pu
    pub e: f64,
    /// Pu . Pv
    pub f: f64,
    /// Pv . Pv
    pub g: f64,
    /// Puu . N
    pub l: f64,
    /// Puv . N
    pub m: f64,
    /// Pvv . N
    pub n: f64,
    /// Unit normal along Pu x Pv (zero where the parametrisation is singular).
    pub normal: Vec3,
}

impl FundamentalForms {
    /// Computes both forms from derivatives.
    pub fn from_derivatives(d: &SurfaceDerivatives) -> Self {
        let normal = d.normal();
        FundamentalForms {
            e: d.pu.dot(&d.pu),
            f: d.pu.dot(&d.pv),
            g: d.pv.dot(&d.pv),
            l: d.puu.dot(&normal),
            m: d.puv.dot(&normal),
            n: d.pvv.dot(&normal),
            normal,
        }
    }

    /// det I = e g - f^2 (the squared area element).
    pub fn det_first(&self) -> f64 {
        self.e * self.g - self.f * self.f
    }
}

/// A smooth parametric surface. Implementors give analytic derivatives where they exist; all
/// differential geometry (normals, fundamental forms, curvature, closest point) is derived from
/// them by the provided methods (P-Hex paper, section 3).
pub trait Surface: Send + Sync {
    /// Parameter domain and periodicity.
    fn domain(&self) -> Domain;

    /// Position and derivatives up to second order at (u, v).
    fn derivatives(&self, u: f64, v: f64) -> SurfaceDerivatives;

    /// P(u, v).
    fn position(&self, u: f64, v: f64) -> Vec3 {
        self.derivatives(u, v).p
    }

    /// Unit normal along Pu x Pv (zero where the parametrisation is singular).
    fn normal(&self, u: f64, v: f64) -> Vec3 {
        self.derivatives(u, v).normal()
    }

    /// First and second fundamental forms at (u, v).
    fn fundamental_forms(&self, u: f64, v: f64) -> FundamentalForms {
        FundamentalForms::from_derivatives(&self.derivatives(u, v))
    }

    /// Principal curvatures and directions, Gaussian and mean curvature at (u, v), for the normal
    /// along Pu x Pv (see [`Curvature`]).
    fn curvature(&self, u: f64, v: f64) -> Result<Curvature, CurvatureError> {
        Curvature::from_derivatives(&self.derivatives(u, v))
    }

    /// The point of the surface closest to `p` (local search: Newton on the squared distance from
    /// `start`, or from the best point of a coarse grid over the domain when `start` is `None`).
    /// See [`closest_point`](ClosestPoint) for the guarantees.
    fn closest_point(
        &self,
        p: &Vec3,
        start: Option<Vec2>,
    ) -> Result<ClosestPoint, ClosestPointError> {
        closest_point::closest_point(self, p, start)
    }
}

/// Derivatives of a surface of revolution P = (rho(v) cos u, rho(v) sin u, z(v)) from the profile
/// and its first two derivatives `rho = (rho, rho', rho'')`, `z = (z, z', z'')`.
pub(crate) fn revolution_derivatives(
    u: f64,
    rho: (f64, f64, f64),
    z: (f64, f64, f64),
) -> SurfaceDerivatives {
    let (su, cu) = u.sin_cos();
    let (r, r1, r2) = rho;
    SurfaceDerivatives {
        p: Vec3::new(r * cu, r * su, z.0),
        pu: Vec3::new(-r * su, r * cu, 0.0),
        pv: Vec3::new(r1 * cu, r1 * su, z.1),
        puu: Vec3::new(-r * cu, -r * su, 0.0),
        puv: Vec3::new(-r1 * su, r1 * cu, 0.0),
        pvv: Vec3::new(r2 * cu, r2 * su, z.2),
    }
}

#[cfg(test)]
pub(crate) mod test_support {
    //! Shared checks for the surface library.
    use super::*;

    /// Analytic derivatives against central differences at the given points.
    pub fn check_derivatives<S: Surface + ?Sized>(s: &S, pts: &[(f64, f64)], tol: f64) {
        let h = 1e-5;
        for &(u, v) in pts {
            let d = s.derivatives(u, v);
            let scale = 1.0 + d.p.norm();
            let fu = (s.position(u + h, v) - s.position(u - h, v)) / (2.0 * h);
            let fv = (s.position(u, v + h) - s.position(u, v - h)) / (2.0 * h);
            assert!((fu - d.pu).norm() < tol * scale, "pu at {u},{v}");
            assert!((fv - d.pv).norm() < tol * scale, "pv at {u},{v}");
            let duu = (s.derivatives(u + h, v).pu - s.derivatives(u - h, v).pu) / (2.0 * h);
            let duv = (s.derivatives(u, v + h).pu - s.derivatives(u, v - h).pu) / (2.0 * h);
            let dvu = (s.derivatives(u + h, v).pv - s.derivatives(u - h, v).pv) / (2.0 * h);
            let dvv = (s.derivatives(u, v + h).pv - s.derivatives(u, v - h).pv) / (2.0 * h);
            assert!((duu - d.puu).norm() < tol * scale, "puu at {u},{v}");
            assert!((duv - d.puv).norm() < tol * scale, "puv at {u},{v}");
            assert!((dvu - d.puv).norm() < tol * scale, "pvu at {u},{v}");
            assert!((dvv - d.pvv).norm() < tol * scale, "pvv at {u},{v}");
        }
    }

    /// Relative agreement of two curvature values, scaled by the larger curvature magnitude.
    pub fn assert_close(got: f64, want: f64, scale: f64, tol: f64, what: &str) {
        assert!(
            (got - want).abs() <= tol * scale.max(1e-300),
            "{what}: got {got}, want {want} (scale {scale})"
        );
    }

    /// Checks k1, k2, K, H of `s` at (u, v) against closed forms (k1 >= k2), to `tol` relative to
    /// max(|k1|, |k2|).
    pub fn check_curvature<S: Surface + ?Sized>(s: &S, u: f64, v: f64, k1: f64, k2: f64, tol: f64) {
        let c = s.curvature(u, v).expect("regular point");
        let scale = k1.abs().max(k2.abs());
        assert_close(c.k1, k1, scale, tol, &format!("k1 at ({u}, {v})"));
        assert_close(c.k2, k2, scale, tol, &format!("k2 at ({u}, {v})"));
        assert_close(c.gaussian, k1 * k2, scale * scale, tol, "gaussian");
        assert_close(c.mean, 0.5 * (k1 + k2), scale, tol, "mean");
    }

    /// Principal curvatures (k1 >= k2) of a surface of revolution P = (rho cos u, rho sin u, z)
    /// with profile derivatives, for the normal along Pu x Pv: the classical closed forms
    /// k_parallel = -z' / (rho s), k_meridian = (rho'' z' - rho' z'') / s^3, s = |(rho', z')|.
    pub fn revolution_curvatures(rho: f64, d1: (f64, f64), d2: (f64, f64)) -> (f64, f64) {
        let s = (d1.0 * d1.0 + d1.1 * d1.1).sqrt();
        let kp = -d1.1 / (rho * s);
        let km = (d2.0 * d1.1 - d1.0 * d2.1) / (s * s * s);
        (kp.max(km), kp.min(km))
    }
}
