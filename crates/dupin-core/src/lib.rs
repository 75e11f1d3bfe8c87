//! # dupin-core
//!
//! The geometry core of Dupin: smooth surfaces, Dupin duality, P-Hex meshes, planar-quad and
//! conical meshes, and hexagonal Delaunay triangulation. Plain Rust: no wasm, DOM or GPU
//! dependency, so the same code runs natively, in the CLI and inside the browser.
//!
//! The modules are private; this page lists the public API (spade's style: a small, flat
//! surface chosen by `pub use`). See `ARCHITECTURE.md` for layering rules.

mod circular;
mod conical;
mod developable_strip;
mod discrete_terms;
mod math;
mod mesh;
mod mesh_topology;
mod obj;
mod offset;
mod planarity;
mod pq_perturbation;
mod pq_scenes;
mod principal_quad_mesh;
mod render_buffers;
mod solver;
mod subdivision;
mod support_structure;
mod surface;

pub use circular::{circular_residual, quad_circularity};
pub use conical::{
    VertexType, angle_balance, cone_axes, conical_residual, face_normals, focal_points,
    spherical_image, vertex_type,
};
pub use developable_strip::{
    PqStrip, StripClosure, StripRule, developable_subdivision, trefoil_moebius,
};
pub use math::{Vec2, Vec3};
pub use mesh::{MeshError, PolyMesh};
pub use mesh_topology::{MeshTopology, TopologyError};
pub use obj::{ObjError, parse_obj, write_obj};
pub use offset::{OffsetError, offset_mesh};
pub use planarity::{face_planarity, max_planarity};
pub use pq_perturbation::{
    PqError, PqMode, PqOptions, PqPerturbation, PqPhase, PqResult, PqStepInfo, Refinement,
    pq_perturb,
};
pub use pq_scenes::{
    PQ_SCENES, PqSceneError, PqSceneResult, pq_scene, skew_quad_grid, torus_centroid_dual,
};
pub use principal_quad_mesh::{SurfaceOfRevolution, principal_quad_mesh};
pub use render_buffers::{TriangleBuffers, sample_surface};
pub use solver::{
    ConstrainedLeastSquares, JacobianEntry, LevenbergMarquardt, LmOptions, LmStep,
    NonlinearLeastSquares, SolverError, SparseSystem, Sqp, SqpOptions, SqpStep,
};
pub use subdivision::{catmull_clark, chaikin, doo_sabin, lane_riesenfeld_cubic};
pub use support_structure::support_structure;
pub use surface::{Domain, Surface, SurfaceDerivatives, Torus};
