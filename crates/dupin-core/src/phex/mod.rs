//! P-Hex meshes (P-Hex paper, sections 5 to 7): a valid triangulation of a surface, its
//! tangent/Dupin dual hexagonal mesh, and Gauss-Newton planarity optimisation, as a one-shot
//! function ([`phex_run`]) and a stateful stepper ([`PhexPipeline`]).

mod conjugate_fields;
mod dupin_dual_hexagons;
mod loop_subdivision;
mod pipeline;
mod planarity_optimisation;
mod report;
mod scenes;
mod triangulation;

pub use conjugate_fields::{ConjugateFields, triangulate_along_fields};
pub use dupin_dual_hexagons::{
    DualMesh, Initialisation, PARABOLIC_THRESHOLD, dual_mesh, dual_mesh_options, dual_mesh_with,
    tangent_plane_point,
};
pub use loop_subdivision::{convex_loop_triangulation, loop_subdivide};
pub use pipeline::{PhexConfig, PhexMetrics, PhexPhase, PhexPipeline, PhexResult, phex_run};
pub use planarity_optimisation::{PlanarityOptimiser, PlanarityOptions, PlanarityStep};
pub use report::{FaceInfo, PhexReport, face_info, phex_report};
pub use scenes::{FREEFORM, FreeformSurface, PHEX_SCENES, PhexScene, TwistedSurface, phex_scene};
pub use triangulation::{
    LayerRule, Triangulation, TriangulationMethod, TriangulationSpec, bounded_ratio, triangulate,
};

use thiserror::Error;

/// Why a P-Hex run could not be done. Every message says what to change.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum PhexError {
    /// The scene name is not one of [`PHEX_SCENES`].
    #[error("unknown P-Hex scene '{name}'; known scenes: {known}")]
    UnknownScene {
        /// The name given.
        name: String,
        /// The known names, comma separated.
        known: String,
    },
    /// The surface name, a parameter or a parameter relation is invalid.
    #[error("{0}")]
    Surface(#[from] crate::RegistryError),
    /// A run parameter (method, iterations, weights) is out of range.
    #[error("bad parameter: {0}")]
    BadParameter(String),
    /// The requested size gives too few or too many elements for the surface.
    #[error("bad size: {0}")]
    BadSize(String),
    /// No valid triangulation exists in the chosen direction or region.
    #[error("no valid triangulation: {0}")]
    NoValidTriangulation(String),
    /// The sparse solver failed.
    #[error("planarity optimisation failed: {0}")]
    Solver(#[from] crate::SolverError),
}
