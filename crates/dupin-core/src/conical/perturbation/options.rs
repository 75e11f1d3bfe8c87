//! Settings and errors of the PQ perturbation (conical paper, Sec. 2.2 and 5): the mode, the
//! weights and caps, the exact-phase solver.

use crate::mesh::TopologyError;
use thiserror::Error;

/// Which property the perturbation enforces besides planar faces.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PqMode {
    /// Planar faces only (PQ mesh for quads; any polygon mesh).
    #[default]
    Planar,
    /// Planar faces and the angle balance at interior valence-4 vertices (conical mesh).
    Conical,
    /// Planar faces and opposite angles of every quad summing to π (circular mesh).
    Circular,
}

crate::names::named_choices!(PqMode, "mode", {
    Planar => "planar",
    Conical => "conical",
    Circular => "circular",
});

/// Settings of [`super::pq_perturb`] and [`super::PqPerturbation`].
///
/// Weights are dimensionless: fairness and closeness residuals are divided by the mean edge
/// length, so the defaults suit meshes of any scale.
#[derive(Debug, Clone, PartialEq)]
pub struct PqOptions {
    /// Property to enforce.
    pub mode: PqMode,
    /// Vertices that must not move (anchors), 0-based.
    pub fixed_vertices: Vec<usize>,
    /// Keep every boundary vertex fixed.
    pub fix_boundary: bool,
    /// Initial closeness weight w2 (≥ 0).
    pub closeness: f64,
    /// Initial fairness weight w1 (≥ 0).
    pub fairness: f64,
    /// Keep a user's design rather than make a fair mesh: the fairness term smooths the move
    /// from the input (second differences of `x - x0`) instead of the mesh itself (the
    /// paper's, which also pulls a boundary straight and a corner inwards), and a step's
    /// length is measured as the points' displacement: plane normals weigh `L²` (L the mean
    /// edge), so a step turns a face's plane rather than slide its vertices along it; the
    /// problem is posed in the unit box (`mesh::SolverFrame`), so the steps do not depend on
    /// the design's unit or its distance from the origin. Off
    /// for the library's scenes (meshes made to be fair, where the settings were tuned); on
    /// in `dupin planarize`. Measured on a 20 m planar quad grid with ±1 mm noise, 40 x 40:
    /// max_move 287 mm off, 1.25 mm on; 200 x 200: 201 mm off, 1.17 mm on. In planar mode on
    /// a mesh of quads the run starts with the least move onto planar quads, solved in face
    /// space (one unknown per quad), and keeps to it when its first step divides the
    /// planarity by 10 or more (the design is then near planar, and its nearest planar mesh is
    /// the one asked for: closeness and fairness do not enter); otherwise it starts again from
    /// the input, penalty phase first.
    pub keep_design: bool,
    /// Convergence: contract `max_planarity` and the mode's residual (radians) both at most
    /// this (> 0).
    pub tolerance: f64,
    /// The most memory a sparse factorisation may take, in bytes (≥ 1): a mesh whose factor
    /// would need more is refused before the factor is allocated ([`super::PqResult::refused`]).
    pub max_factor_bytes: usize,
    /// Iteration cap (penalty and SQP iterations together, ≥ 1).
    pub max_iterations: usize,
    /// Largest number of penalty iterations before switching to the exact phase. With
    /// [`Refinement::GaussNewton`] the exact phase is tried once after the first penalty
    /// iteration and kept when its first step, at near-Newton damping, divides the squared
    /// constraint residual by 10 or more; otherwise the penalty phase runs to this count.
    pub penalty_iterations: usize,
    /// Pairs of vertices that are the same point and move together (gluing a cut mesh, e.g. a
    /// Möbius band cut open along one rung, which cannot be oriented consistently).
    pub identify: Vec<(usize, usize)>,
    /// How the final, exact phase is solved.
    pub refinement: Refinement,
    /// Add the determinant terms `c_det` of unit edge vectors to the penalty (the paper's
    /// µ = 1, needed for thin quads of PQ strips, where face planes degenerate).
    pub determinant_terms: bool,
}

impl Default for PqOptions {
    fn default() -> Self {
        PqOptions {
            mode: PqMode::Planar,
            fixed_vertices: Vec::new(),
            fix_boundary: false,
            closeness: 0.01,
            fairness: 0.001,
            keep_design: false,
            tolerance: 1e-11,
            max_iterations: 100,
            max_factor_bytes: crate::solver::MAX_FACTOR_BYTES,
            penalty_iterations: 4,
            determinant_terms: false,
            identify: Vec::new(),
            refinement: Refinement::GaussNewton,
        }
    }
}

/// The solver of the exact phase that follows the penalty phase.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Refinement {
    /// SQP on the KKT system (eq. (3)) with sparse LU: fairness and closeness stay the
    /// objective (their weights keep halving) while the constraints become exact; Newton-SQP
    /// for the plane constraints (their Hessian is supplied). Takes about 20 steps on the
    /// benchmark meshes (the paper reports 20-50) and each step factors the indefinite KKT
    /// matrix, so it is 20-60x slower there than the default.
    Sqp,
    /// SQP in substance, the default: each step solves the quasi-definite KKT system
    /// `[μI Jᵀ; J -I] (h, y) = (0, -c)` of `min ½μ|h|²` subject to the linearised
    /// constraints `c + J h = 0`, by eliminating `y` (`(JᵀJ + μI) h = -Jᵀc`, the sparse
    /// Cholesky the penalty phase uses, with its plane unknowns eliminated per face). With
    /// μ = 1e-9 of the largest diagonal and J of full row rank (fewer constraints than
    /// unknowns on PQ meshes) this is the minimum-norm Newton-KKT step (tested against the
    /// dense KKT solution) and converges quadratically (tested). It differs from
    /// [`Refinement::Sqp`] only in the objective: the distance to the previous iterate
    /// instead of fairness and closeness, whose weights are already halved after every
    /// penalty iteration (1/16 after the default 4); so it ends at the nearest exact point
    /// rather than at the constrained optimum of the remaining weights.
    #[default]
    GaussNewton,
}

/// Why a perturbation could not start.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum PqError {
    /// The mesh is not an oriented manifold with boundary.
    #[error(transparent)]
    Topology(#[from] TopologyError),
    /// Conical mode on a mesh with no interior vertex of valence four.
    #[error("conical mode needs an interior vertex of valence 4; this mesh has none")]
    NoConicalVertex,
    /// Circular mode on a mesh without quads.
    #[error("circular mode needs quad faces; this mesh has none")]
    NoQuadFace,
    /// A fixed or identified vertex index does not exist.
    #[error("vertex {index} does not exist (the mesh has {vertices} vertices)")]
    FixedVertexOutOfRange {
        /// The bad index.
        index: usize,
        /// Number of vertices.
        vertices: usize,
    },
    /// A weight, tolerance or iteration count is out of range.
    #[error("invalid option {name} = {value}: {requirement}")]
    InvalidOption {
        /// Option name.
        name: &'static str,
        /// The given value.
        value: f64,
        /// What it must satisfy.
        requirement: &'static str,
    },
}
