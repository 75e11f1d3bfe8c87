//! # dupin-core
//!
//! The geometry core of Dupin: smooth surfaces, Dupin duality, P-Hex meshes, planar-quad and
//! conical meshes, and hexagonal Delaunay triangulation. Plain Rust: no wasm, DOM or GPU
//! dependency, so the same code runs natively, in the CLI and inside the browser.
//!
//! The modules are private; this page lists the public API (spade's style: a small, flat
//! surface chosen by `pub use`). See `ARCHITECTURE.md` for layering rules.

mod math;
mod mesh;
mod obj;
mod planarity;
mod render_buffers;
mod solver;
mod surface;

pub use math::{Vec2, Vec3};
pub use mesh::{MeshError, PolyMesh};
pub use obj::{ObjError, parse_obj, write_obj};
pub use planarity::{face_planarity, max_planarity};
pub use render_buffers::{TriangleBuffers, sample_surface};
pub use solver::{
    ConstrainedLeastSquares, JacobianEntry, LevenbergMarquardt, LmOptions, LmStep,
    NonlinearLeastSquares, SolverError, SparseSystem, Sqp, SqpOptions, SqpStep,
};
pub use surface::{Domain, Surface, SurfaceDerivatives, Torus};
