//! The named scenes of the outside contract, after the papers' figures, and the benchmark
//! meshes. Scenes are data for the algorithms (settings on library surfaces, control meshes and
//! their rules), kept out of the algorithm folders.
//!
//! | paper | scenes | file |
//! |---|---|---|
//! | P-Hex (Figs. 1, 11, 15, 18-22, sec. 3) | `cyclide-architecture`, `sphere-radial`, ... | `phex.rs` |
//! | conical (Figs. 1, 7-9, 14, 16, 17) | `pq-catmull-clark`, `conical-station`, ... | `pq.rs` |
//! | both, for people | one sentence per scene with its figure | `descriptions.rs` |
//! | conical (benchmarks), import | skew grid on z = xy, torus quads, triangulation and centroid dual, noisy vase; a NURBS roof | `benchmark_meshes.rs` |

pub mod benchmark_meshes;
mod descriptions;
mod phex;
mod pq;

pub use descriptions::scene_description;
#[cfg(test)]
pub(crate) use phex::acceptance_for_tests;
pub use phex::{PHEX_SCENES, PhexScene, phex_scene};
pub use pq::{PQ_SCENES, pq_scene, pq_scene_spec, pq_scene_stepper};
