//! # dupin-core
//!
//! The geometry core of Dupin: smooth surfaces, Dupin duality, P-Hex meshes, planar-quad and
//! conical meshes, and hexagonal Delaunay triangulation. Plain Rust: no wasm, DOM or GPU
//! dependency, so the same code runs natively, in the CLI and inside the browser.
//!
//! One public module per area, one folder per paper (see `ARCHITECTURE.md` for the module graph
//! and the layering rules); each paper folder's documentation opens with its section -> file
//! table.
//!
//! | module | what |
//! |---|---|
//! | [`mesh`] | [`mesh::PolyMesh`], topology, planarity, polygons, picking, render buffers, OBJ and point-set text, subdivision rules |
//! | [`surface`] | the [`surface::Surface`] trait, curvature, the surface library and registry, mesh surfaces, closest points |
//! | [`solver`] | sparse Gauss-Newton / Levenberg-Marquardt and SQP on faer |
//! | [`phex`] | P-Hex paper: Dupin duality, valid triangulations, dual hexagons, planarity optimisation |
//! | [`conical`] | conical paper: PQ perturbation, conical and circular meshes, offsets, support structures, developable strips |
//! | [`hex_delaunay`] | hexagonal Delaunay triangulation (Sußner, Greiner) |
//! | [`scenes`] | the named scenes of both papers' figures, benchmark meshes |
//! | [`fabrication`] | panel schedules: flattened, numbered panels on sheets |
//! | [`Stepper`] | the one shape of every stepped computation |
//! | [`UnknownName`] | a method, initialisation or mode name that none of its choices has |

// `!(x > t)` is used on purpose throughout: unlike `x <= t` it also rejects NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod conical;
pub mod fabrication;
pub mod hex_delaunay;
mod math;
pub mod mesh;
mod names;
pub mod phex;
pub mod scenes;
pub mod solver;
mod stepper;
pub mod surface;

pub use math::{Vec2, Vec3};
pub use names::UnknownName;
pub use stepper::Stepper;
