//! Planar-quad, conical and circular meshes, developable strips, offsets and support structures
//! (Liu, Pottmann, Wallner, Yang, Wang: "Geometric modeling with conical meshes and developable
//! surfaces", 2006).
//!
//! | section | concept | file |
//! |---|---|---|
//! | 2 | PQ perturbation: modes, options and errors | `perturbation/options.rs` |
//! | 2 | PQ perturbation: unknowns, penalty rows (eq. (5)), exact constraints (eqs. (3), (6), (7)) | `perturbation/problem.rs` |
//! | 2 | PQ perturbation: the stepper (penalty phase, then SQP) and its one-shot run | `perturbation/stepper.rs` |
//! | 2 | discrete angle and determinant terms with their gradients | `discrete_terms.rs` |
//! | 3 | subdivision and perturbation alternating, level by level | `refinement.rs` |
//! | 3.2 | conical vertices: angle balance, cone axes, spherical image | `cones.rs` |
//! | 3.3, 5 | circular quads | `circular.rs` |
//! | 5 | quad meshes along principal curvature lines | `principal_quads.rs` |
//! | 4 | face offsets of a conical mesh | `offset.rs` |
//! | 4 | support structures: one planar quad per edge | `support.rs` |
//! | 6 | developable strips: PQ strips, curve subdivision, singular curves | `developable_strip.rs` |

mod circular;
mod cones;
mod developable_strip;
mod discrete_terms;
mod live_edit;
mod offset;
mod perturbation;
mod principal_quads;
mod refinement;
mod support;

// The least move onto planar faces, shared with the P-Hex optimiser's near-planar starts.
#[cfg(test)]
pub(crate) use perturbation::FAIL_STEPS;
pub(crate) use perturbation::PlanarProjection;

pub use circular::{circular_residual, quad_circularity};
pub use cones::{
    VertexType, angle_balance, cone_axes, conical_residual, face_normals, focal_points,
    spherical_image, vertex_type,
};
pub use developable_strip::{
    PqStrip, StripClosure, StripRule, developable_subdivision, trefoil_moebius,
};
pub use offset::{DEFAULT_OFFSET_DISTANCE, MAX_OFFSET_TO_SIZE, OffsetError, offset_mesh};
pub use perturbation::{
    PqError, PqMode, PqOptions, PqPerturbation, PqPhase, PqResult, PqStepInfo, Refinement,
    pq_perturb,
};
pub use principal_quads::principal_quad_mesh;
pub use refinement::{
    MeshRule, PqSceneError, PqSceneMeasures, PqScenePhase, PqSceneResult, PqSceneSpec,
    PqSceneStepInfo, PqSceneStepper, pq_scene_shortfall,
};
pub use support::support_structure;
