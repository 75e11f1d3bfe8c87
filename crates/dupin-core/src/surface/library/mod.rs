//! The named surfaces: one file per surface of the registry's catalogue (`surface_by_name`),
//! and the scene-only surfaces (the freeform surface of Fig. 22, twisted parametrisations,
//! surfaces of revolution given by a profile).

mod catenoid;
mod cylinder;
mod dupin_cyclide;
mod ellipsoid;
mod enneper;
mod freeform;
mod hyperbolic_paraboloid;
mod hyperboloid;
mod revolution;
mod sphere;
mod torus;
mod twisted;
mod vase;

pub use catenoid::Catenoid;
pub use cylinder::Cylinder;
pub use dupin_cyclide::DupinCyclide;
pub use ellipsoid::Ellipsoid;
pub use enneper::Enneper;
pub use freeform::{FREEFORM, FreeformSurface};
pub use hyperbolic_paraboloid::HyperbolicParaboloid;
#[cfg(test)]
pub(crate) use hyperbolic_paraboloid::graph_curvatures;
pub use hyperboloid::Hyperboloid;
pub use revolution::SurfaceOfRevolution;
pub use sphere::Sphere;
pub use torus::Torus;
pub use twisted::TwistedSurface;
pub use vase::Vase;
