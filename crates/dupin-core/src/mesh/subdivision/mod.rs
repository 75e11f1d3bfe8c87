//! Subdivision rules used with PQ perturbation (conical paper, Sec. 3): Catmull-Clark and
//! Doo-Sabin for polygon meshes with boundary, Chaikin and cubic Lane-Riesenfeld for the
//! boundary polylines of PQ strips.

mod catmull_clark;
mod chaikin;
mod doo_sabin;
mod lane_riesenfeld;

pub use catmull_clark::catmull_clark;
pub use chaikin::chaikin;
pub use doo_sabin::doo_sabin;
pub use lane_riesenfeld::lane_riesenfeld_cubic;
