//! P-Hex meshes (P-Hex paper): Dupin duality on a smooth surface (sections 3 to 5.1), a valid
//! triangulation along conjugate directions (section 5), its tangent/Dupin dual hexagonal mesh
//! (section 6) and Gauss-Newton planarity optimisation (sections 6, 7), as a one-shot function
//! ([`phex_run`]) and a stateful stepper ([`PhexPipeline`]).
//!
//! | section | concept | file |
//! |---|---|---|
//! | 3 to 5.1 | indicatrix, Dupin center, tangent duality, triangle stars, ideal triangle | `duality/` |
//! | 5.2, 5.3 | triangulation methods 1 and 2, parabolic rules, Loop subdivision | `triangulation/` |
//! | 6 | the hexagonal mesh dual to a triangulation (tangent or Dupin duality) | `dual_hexagons.rs` |
//! | 6, 7 | Gauss-Newton planarity optimisation with fairness and surface distance | `planarity_optimisation.rs` |
//! | 5 to 7 | the stepped pipeline and its one-shot run | `pipeline.rs` |
//! | 8 | the report: planarity, validity, shape deviation per face | `report.rs` |

mod dual_hexagons;
mod duality;
mod pipeline;
mod planarity_optimisation;
mod report;
mod triangulation;

pub use dual_hexagons::{
    DualMesh, DualMeshOptions, Initialisation, PARABOLIC_THRESHOLD, dual_mesh, tangent_plane_point,
};
pub use duality::{
    DupinCenterError, DupinCenterMethod, DupinConic, DupinHexagon, DupinIndicatrix, IdealTriangle,
    IdealTriangleError, IndicatrixError, StarEditError, TangentDualPoint, TangentDualityError,
    TriangleStar, TriangleStarError, approximate_dupin_center, drag_lattice_star, drag_star_vertex,
    dupin_center, dupin_center_3d, dupin_conic_through, ideal_apex_3d, ideal_triangle,
    is_affine_quasi_regular_hexagon, is_affine_regular_hexagon, project_star, tangent_dual_point,
};
pub use pipeline::{
    MAX_FOLLOW_STEPS, PhexConfig, PhexMetrics, PhexPhase, PhexPipeline, PhexResult, phex_run,
};
pub use planarity_optimisation::{PlanarityOptimiser, PlanarityOptions, PlanarityStep};
pub use report::{
    FaceInfo, PhexGoals, PhexReport, count_invalid_and_non_convex_faces, count_invalid_faces,
    face_info, phex_report,
};
pub use triangulation::{
    ConjugateFields, DEFAULT_BOUND, LayerRule, MAX_PHEX_FACES, MAX_RATIO, MAX_RATIO_ELLIPTIC,
    ParabolicCrossings, Triangulation, TriangulationMethod, TriangulationSpec, bounded_ratio,
    convex_loop_triangulation, loop_subdivide, triangulate, triangulate_along_fields,
};

use thiserror::Error;

/// Why a P-Hex run could not be done. Every message says what to change.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum PhexError {
    /// The scene name is not one of [`crate::scenes::PHEX_SCENES`].
    #[error("unknown P-Hex scene '{name}'; known scenes: {known}")]
    UnknownScene {
        /// The name given.
        name: String,
        /// The known names, comma separated.
        known: String,
    },
    /// The surface name, a parameter or a parameter relation is invalid.
    #[error("{0}")]
    Surface(#[from] crate::surface::RegistryError),
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
    Solver(#[from] crate::solver::SolverError),
    /// A reshaped design cannot be followed from this run: the run, or a step on the way, has
    /// self-intersecting or non-planar faces, which following would only carry along.
    #[error("not followed: {0}")]
    NotFollowed(String),
}
