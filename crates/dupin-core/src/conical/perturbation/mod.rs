//! PQ perturbation (conical paper, Sec. 2.2 and 5): move the vertices of any polygon mesh as
//! little as possible so that every face becomes planar, and optionally every interior
//! valence-4 vertex conical (eq. (6)) or every quad circular (eq. (7)).
//!
//! Inputs: a [`PolyMesh`] (any face sizes), [`PqOptions`]. Output: [`PqResult`] with the
//! perturbed mesh, or a [`PqError`] for input the method cannot work on.
//!
//! The method follows the paper:
//! 1. **Penalty phase** (eq. (5)): Gauss-Newton with Levenberg-Marquardt damping on
//!    `w1 f_fair + w2 f_close + f_plane + f_angle (+ f_det)` where
//!    - `f_angle` is the angle-sum condition of eq. (1) generalised to n-gons,
//!      `Σ φ_k - (n - 2) π`, used for faces that are convex at the start (for non-convex planar
//!      polygons the angle sum is not `(n - 2)π`, so the term would fight planarity). It keeps
//!      faces convex, as in the paper;
//!    - `f_plane` makes the faces planar: every face of 4+ vertices carries a plane (unit
//!      normal n, offset d) as extra unknowns with residuals `(n·v - d)/L` per vertex and
//!      `|n|² - 1`. The angle sum deviates from `(n - 2)π` only to second order in the
//!      non-planarity, so it cannot drive planarity to 1e-10 quickly; the plane terms are
//!      first order, bilinear and well conditioned (this is the one departure from the paper);
//!    - `f_det` (option [`PqOptions::determinant_terms`], for PQ strips, the paper's µ = 1):
//!      `det(ê_k, ê_{k+1}, ê_{k+2})` of unit vectors along every three consecutive edges; for a
//!      quad exactly the paper's four `c_det` terms;
//!    - `f_fair` is the row/column bending energy `(v_{i+1} - 2 v_i + v_{i-1})²` through
//!      opposite neighbours of even-valence vertices and along the boundary (the umbrella
//!      Laplacian at odd valence);
//!    - `f_close` is the tangent-plane (Gauss-Newton) approximation `((v - y)·n)²` of the
//!      squared distance to the reference surface, here the input mesh with footpoint y the
//!      input vertex and n its area-weighted normal.
//!
//!    `w1` and `w2` start at the user's weights and are halved after every iteration. The
//!    phase lasts [`PqOptions::penalty_iterations`] iterations, or one when a trial step of
//!    the exact phase from there is a near-Newton step (the paper's "initial mesh near a
//!    local minimum, and then employ SQP"; tried once, discarded otherwise).
//! 2. **Exact phase**, see [`Refinement`]: the constraints are the plane terms, the angle
//!    balance of eq. (6) (conical) and `φ1 + φ3 - π` per quad (circular; with planarity this
//!    implies eq. (7)). Either SQP on the KKT system of eq. (3) with fairness and closeness
//!    as objective, or (default) the Newton-KKT step of the constraints with the step length
//!    as objective, solved through the quasi-definite form by sparse Cholesky. The angle sum
//!    of eq. (1) is left out here: its gradient vanishes on planar faces, which would make
//!    the KKT system singular.
//!
//! Keeping a design ([`PqOptions::keep_design`]) on a mesh of quads in planar mode, the run
//! starts with phase 2 in face space instead: Newton steps of least Euclidean length onto the
//! quads' planarity determinants, one unknown per quad (`planar_projection.rs`), kept when the
//! first one divides the planarity by 10 or more (otherwise phase 1 from the input). Its
//! matrix has a third of the unknowns of the vertex-and-plane system on the same graph,
//! which is what makes 200 000 quads fit in 0.35 GB and 3 s, and a live drag of 10 000 quads
//! in the page keep up with the pointer.
//!
//! Every face gets planar to the contract's `max_planarity` <= tolerance, including the
//! hexagons of P-Hex meshes and mixed meshes; triangles are planar already.

//!
//! | section | concept | file |
//! |---|---|---|
//! | 2.2, 5 | mode, weights, caps, exact-phase solver, errors | `options.rs` |
//! | 2.2 (eqs. (3), (5)), 3.2 (eq. (6)), 5 (eq. (7)) | unknowns, penalty rows, exact constraints | `problem.rs` |
//! | 2.2 | a live edit's exact phase on quad meshes (and P-Hex's near-planar starts): the least move onto planar faces in face space | `planar_projection.rs` |
//! | 2.2 | the stepper (penalty phase, then exact phase), its metrics and result, the one-shot run | `stepper.rs` |

mod options;
mod planar_projection;
mod problem;
#[cfg(test)]
pub(crate) use planar_projection::FAIL_STEPS;
pub(crate) use planar_projection::PlanarProjection;
mod stepper;

pub use options::{PqError, PqMode, PqOptions, Refinement};
pub(crate) use stepper::PqAnalyses;
pub use stepper::{PqPerturbation, PqPhase, PqResult, PqStepInfo, pq_perturb};
