//! # dupin-core
//!
//! The geometry core of Dupin: smooth surfaces, Dupin duality, P-Hex meshes, planar-quad and
//! conical meshes, and hexagonal Delaunay triangulation. Plain Rust: no wasm, DOM or GPU
//! dependency, so the same code runs natively, in the CLI and inside the browser.
//!
//! The modules are private; this page lists the public API (spade's style: a small, flat
//! surface chosen by `pub use`). See `ARCHITECTURE.md` for layering rules.

mod hex_delaunay;
mod math;
mod mesh;
mod obj;
mod planarity;
mod point_set;
mod render_buffers;
mod surface;

pub use hex_delaunay::{
    Circle, HexCell, HexDelaunayError, HexDelaunayMode, HexDelaunayStepper, HexTriangulation,
    MAX_COORDINATE, MAX_LEVEL, MIN_EXTENT, TriangulationQuality, hex_delaunay,
    min_enclosing_circle, triangulation_quality,
};
pub use math::{Vec2, Vec3};
pub use mesh::{MeshError, PolyMesh};
pub use obj::{ObjError, parse_obj, write_obj};
pub use planarity::{face_planarity, max_planarity};
pub use point_set::{PointSetError, parse_points, parse_segments};
pub use render_buffers::{TriangleBuffers, sample_surface};
pub use surface::{Domain, Surface, SurfaceDerivatives, Torus};
