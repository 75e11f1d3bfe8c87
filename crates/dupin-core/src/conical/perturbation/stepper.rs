//! The stepped PQ perturbation (conical paper, Sec. 2.2): [`PqPerturbation`], one penalty or
//! exact-phase iteration per step, its metrics and result, and [`pq_perturb`], the stepper
//! run to its end.

use super::options::{PqError, PqMode, PqOptions, Refinement};
use super::planar_projection::PlanarProjection;
use super::problem::{Feasibility, NONE, Problem, Terms};
use crate::conical::circular_residual;
use crate::conical::conical_residual;
use crate::mesh::MeshTopology;
use crate::mesh::PolyMesh;
use crate::mesh::SolverFrame;
use crate::mesh::coordinate_precision_note;
use crate::mesh::max_planarity;
use crate::solver::{
    LevenbergMarquardt, LmAnalysis, LmOptions, LmStep, SolverError, Sqp, SqpOptions,
};
use crate::{Stepper, Vec3};
use std::convert::Infallible;

/// The phase a [`PqPerturbation`] is in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PqPhase {
    /// Penalty method: Gauss-Newton / Levenberg-Marquardt with weight halving.
    Penalty,
    /// SQP refinement on the KKT system.
    Sqp,
    /// Finished (converged or stopped).
    Done,
}

/// Metrics after one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PqStepInfo {
    /// Iterations done so far.
    pub iteration: usize,
    /// Phase after this step.
    pub phase: PqPhase,
    /// Contract `max_planarity` of the current mesh.
    pub max_planarity: f64,
    /// Conical or circular residual (0 in planar mode).
    pub mode_residual: f64,
}

/// Result of a perturbation.
#[derive(Debug, Clone, PartialEq)]
pub struct PqResult {
    /// The perturbed mesh (the best one reached when not converged).
    pub mesh: PolyMesh,
    /// Iterations used (penalty, Newton and chord steps; see [`PqResult::factorizations`]).
    pub iterations: usize,
    /// Whether the tolerance was reached.
    pub converged: bool,
    /// Why it stopped without converging.
    pub reason: Option<String>,
    /// Contract `max_planarity`.
    pub max_planarity: f64,
    /// `conical_residual` (conical mode only).
    pub conical_residual: Option<f64>,
    /// `circular_residual` (circular mode only).
    pub circular_residual: Option<f64>,
    /// Largest vertex displacement from the input.
    pub max_move: f64,
    /// Largest vertex displacement along the input's vertex normal (area-weighted): how far
    /// the design's surface moved.
    pub max_normal_move: f64,
    /// Largest vertex displacement across the input's vertex normal: how far a vertex slid
    /// along the design's surface.
    pub max_tangential_move: f64,
    /// Sparse factorisations used (one per tried Gauss-Newton step; the chord steps of the
    /// exact phase reuse the last one).
    pub factorizations: usize,
    /// The problem was refused before any numeric work: its sparse factor would need more
    /// memory than [`PqOptions::max_factor_bytes`] (`reason` names both sizes). The mesh is
    /// the input, untouched.
    pub refused: bool,
}

/// A PQ / conical / circular perturbation that can be stepped and watched (one step is one
/// penalty or SQP iteration, or in the exact phase a chord step reusing the last
/// factorisation). [`pq_perturb`] runs it to the end.
pub struct PqPerturbation {
    /// The current mesh in the user's coordinates (anchors keep their bits).
    mesh: PolyMesh,
    /// The same mesh in the solver's frame, where the problem is posed.
    work: PolyMesh,
    frame: SolverFrame,
    /// The input positions, for the displacement reported at the end.
    input: Vec<Vec3>,
    topo: MeshTopology,
    terms: Terms,
    options: PqOptions,
    x: Vec<f64>,
    w_fair: f64,
    w_close: f64,
    /// Penalty steps (and the [`Refinement::Sqp`] fall-back).
    lm: LevenbergMarquardt,
    /// Exact-phase steps ([`Refinement::GaussNewton`]): a solver of its own keeps the
    /// analysis of its sparsity pattern when a failed probe returns to the penalty phase.
    exact: LevenbergMarquardt,
    /// The next exact-phase step is the probe after the first penalty iteration.
    probe: bool,
    /// Whether that probe is made (the default exact phase and more than one penalty
    /// iteration allowed).
    probe_allowed: bool,
    sqp: Sqp,
    phase: PqPhase,
    iteration: usize,
    converged: bool,
    reason: Option<String>,
    last: (f64, f64),
    /// The next exact-phase step tries a chord step first (see [`CHORD_RATE`]).
    chord: bool,
    /// See [`PqResult::refused`].
    refused: bool,
    /// The iteration at which the run stops: [`PqOptions::max_iterations`] after its start,
    /// or after the start of its last [`PqPerturbation::restage`].
    iteration_cap: usize,
    /// The exact phase runs in face space ([`PlanarProjection`]: the least move onto planar
    /// quads, one unknown per quad) instead of [`Self::exact`]: a live edit of a quad mesh in
    /// planar mode ([`PqPerturbation::start_exact`]), or a run that keeps a design
    /// ([`LEAST_MOVE_CONTRACTION`]).
    face_space: bool,
    /// Its analysed pattern, made at its first step.
    projection: Option<PlanarProjection>,
    /// A face-space analysis taken over from another perturbation
    /// ([`PqPerturbation::adopt_analyses`]), used when it covers this mesh and its held
    /// vertices.
    spare_projection: Option<PlanarProjection>,
    /// The unknowns at the start while a run that keeps a design takes its first steps in
    /// face space ([`LEAST_MOVE_CONTRACTION`]); the penalty phase starts from them again if
    /// face space does not get there.
    least_move_start: Option<Vec<f64>>,
}

/// A finished perturbation's analyses of its sparsity patterns (penalty and exact phase), for
/// the next stage of a live edit ([`PqPerturbation::take_analyses`]).
pub(crate) struct PqAnalyses {
    lm: Option<LmAnalysis>,
    exact: Option<LmAnalysis>,
    projection: Option<PlanarProjection>,
}

impl PqAnalyses {
    /// The face-space analysis alone, for another edit of the same mesh: it is used only for
    /// the very pattern it was made for, so a replayed edit repeats its run bit for bit
    /// whatever ran before it (the block solvers' analyses may also serve patterns they
    /// cover, whose factors then differ in rounding).
    pub(crate) fn face_space_only(self) -> Self {
        PqAnalyses {
            lm: None,
            exact: None,
            projection: self.projection,
        }
    }
}

/// Settings of the penalty and exact-phase Levenberg-Marquardt iterations.
fn lm_options(max_factor_bytes: usize) -> LmOptions {
    LmOptions {
        max_factor_bytes,
        decrease: 10.0,
        step_halvings: 2,
        ..LmOptions::default()
    }
}

/// Contraction of the constraint residual norm below which the exact phase takes chord
/// steps (reusing the last factorisation with a fresh residual) instead of Newton steps:
/// the rate of a chord step is about that of the Newton step it follows, and at this rate
/// two or three chord steps (an evaluation and two triangular solves each) cost less than
/// one factorisation and gain as much.
const CHORD_RATE: f64 = 0.05;

/// The exact phase may start after the first penalty iteration when its first step, at
/// near-Newton damping, lowers the squared constraint residual at least this much (residual
/// norm by about 3x). The paper uses the penalty method "to quickly derive an initial mesh
/// near a local minimum, and then employ SQP" (Sec. 2.2); the probe asks whether the mesh is
/// near enough. Measured first steps after one penalty iteration: torus dual 0.0054, conical
/// vase (5913 vertices) 0.0022 (kept: each saves three penalty factorisations); noisy vase
/// 0.77 and skew grid rejected at near-Newton damping (discarded: the exact phase from there
/// stalls or crawls and loses fairness, so the penalty phase goes on). Over the test suite the
/// kept ratios lie in 2.3e-10..0.094 and the discarded ones in 0.19..0.63 or are rejected.
/// A discarded probe costs one factorisation.
const PROBE_CONTRACTION: f64 = 0.1;

/// A run that keeps a design ([`PqOptions::keep_design`]) on a mesh of quads in planar mode
/// starts with a least-move step in face space ([`PlanarProjection`]) and goes on so when it
/// divides `max_planarity` by at least this much: the design is then near a planar one, and
/// its nearest is what keeping it asks for. Otherwise (and if a later step fails) the run
/// starts again from its input, penalty phase first. Measured on a 100 x 100 curved grid with
/// noise of 8% of an edge: planarity 1.1e-3 after the first step, converged in 4 steps, 75 ms
/// and a largest move of 2.4e-3 (the noise's amplitude 2e-3), where the paper's way takes
/// 0.96 s and moves vertices 0.1; 447 x 447 (200k quads): 2.5-2.7 s and 342 MB. From the skew
/// grid (`skew_quad_grid`, 30 degrees on z = xy) least-move steps converge too, but move the
/// design 0.32 where the penalty phase moves it 0.015 (447 x 447): each step's least move from
/// the last is not the least move from the design, so only a design that its first step
/// brings near planar keeps to them.
const LEAST_MOVE_CONTRACTION: f64 = 0.1;

/// Weights finite and >= 0, tolerance finite and > 0, at least one iteration.
fn check_options(o: &PqOptions) -> Result<(), PqError> {
    let check = |name: &'static str, value: f64, ok: bool, requirement: &'static str| {
        if ok {
            Ok(())
        } else {
            Err(PqError::InvalidOption {
                name,
                value,
                requirement,
            })
        }
    };
    check(
        "closeness",
        o.closeness,
        o.closeness.is_finite() && o.closeness >= 0.0,
        "must be finite and >= 0",
    )?;
    check(
        "fairness",
        o.fairness,
        o.fairness.is_finite() && o.fairness >= 0.0,
        "must be finite and >= 0",
    )?;
    check(
        "tolerance",
        o.tolerance,
        o.tolerance.is_finite() && o.tolerance > 0.0,
        "must be finite and > 0",
    )?;
    check(
        "max_factor_bytes",
        o.max_factor_bytes as f64,
        o.max_factor_bytes >= 1,
        "must be >= 1",
    )?;
    check(
        "max_iterations",
        o.max_iterations as f64,
        o.max_iterations >= 1,
        "must be >= 1",
    )?;
    Ok(())
}

impl PqPerturbation {
    /// Checks the mesh and options and sets up the problem.
    pub fn new(mesh: &PolyMesh, options: PqOptions) -> Result<Self, PqError> {
        check_options(&options)?;
        let topo = MeshTopology::new(mesh)?;
        // Keeping a design, the problem is posed in a centred frame scaled by a power of two
        // to the unit box: a design at any distance from the origin and in any unit is solved
        // as the same design near the origin (its step metric is in lengths, so the size
        // does not matter either). The paper's settings stay in the user's coordinates:
        // their Levenberg metric weighs vertex moves (lengths) against unit normals and was
        // tuned on the library's scenes at their size; in the unit box the developable
        // trefoil ended with 30 singular points inside its strips instead of none.
        let frame = if options.keep_design {
            SolverFrame::unit_box(&mesh.positions)
        } else {
            SolverFrame::identity()
        };
        let mut work = mesh.clone();
        for p in &mut work.positions {
            *p = frame.to_solver(*p);
        }
        let (terms, x) = Terms::new(&work, &topo, &options)?;
        let o = &options;
        let scale_for_sqp = terms.scale;
        let factor_limit = o.max_factor_bytes;
        let probe_allowed = o.refinement == Refinement::GaussNewton && o.penalty_iterations > 1;
        let iteration_cap = o.max_iterations;
        let mut s = PqPerturbation {
            mesh: mesh.clone(),
            work,
            frame,
            input: mesh.positions.clone(),
            topo,
            terms,
            w_fair: o.fairness,
            w_close: o.closeness,
            options,
            x,
            lm: LevenbergMarquardt::new(lm_options(factor_limit)),
            exact: LevenbergMarquardt::new(lm_options(factor_limit)),
            probe: false,
            probe_allowed,
            sqp: Sqp::new(SqpOptions {
                absolute_damping: 1e-6 / (scale_for_sqp * scale_for_sqp),
                ..SqpOptions::default()
            }),
            phase: PqPhase::Penalty,
            iteration: 0,
            converged: false,
            reason: None,
            last: (f64::INFINITY, f64::INFINITY),
            chord: false,
            refused: false,
            iteration_cap,
            face_space: false,
            projection: None,
            spare_projection: None,
            least_move_start: None,
        };
        s.last = s.measures();
        if s.is_converged() {
            s.phase = PqPhase::Done;
            s.converged = true;
        } else if s.options.keep_design
            && s.options.mode == PqMode::Planar
            && s.options.refinement == Refinement::GaussNewton
            && PlanarProjection::applies(&s.work)
        {
            s.face_space = true;
            s.phase = PqPhase::Sqp;
            s.least_move_start = Some(s.x.clone());
        }
        Ok(s)
    }

    /// Takes the solvers' analyses of the sparsity patterns, for the perturbation of a live
    /// edit's next stage (the same mesh and anchors, other positions;
    /// [`PqPerturbation::adopt_analyses`]): its first steps factorise at once instead of
    /// analysing the patterns again (a fifth of a 10 000-quad drag's time, measured natively).
    /// A stage that follows the same stage gets the same analyses, so a replayed edit repeats
    /// the run bit for bit.
    pub(crate) fn take_analyses(&mut self) -> PqAnalyses {
        PqAnalyses {
            lm: Some(self.lm.take_analysis()),
            exact: Some(self.exact.take_analysis()),
            projection: self.projection.take().or(self.spare_projection.take()),
        }
    }

    /// Moves the held vertices `moved` (vertex, position in the user's coordinates) and
    /// continues from the current mesh in the exact phase, its first steps chord steps on the
    /// last factorisation: the next stage of a live edit (live_edit.rs), a quarter edge on
    /// from a converged stage, which the factor of that stage's Jacobian brings back to the
    /// constraints in a few triangular solves where a fresh perturbation (a penalty step, a
    /// probe, Newton steps) takes three to four factorisations. False, and nothing changed,
    /// unless this run converged in the exact phase with its factorisation still held; a
    /// stage that fails from here ends not converged like any run.
    pub(crate) fn restage(&mut self, moved: &[(usize, Vec3)]) -> bool {
        if !self.converged
            || self.options.refinement != Refinement::GaussNewton
            || moved.iter().any(|&(v, _)| self.terms.var_of[v] != NONE)
        {
            return false;
        }
        let mut work = self.work.clone();
        for &(v, p) in moved {
            work.positions[v] = self.frame.to_solver(p);
        }
        if !self.face_space && !self.restage_factor(&work) {
            return false;
        }
        self.work = work;
        for &(v, p) in moved {
            self.mesh.positions[v] = p;
        }
        self.phase = PqPhase::Sqp;
        self.probe = false;
        self.chord = true;
        self.converged = false;
        self.reason = None;
        self.iteration_cap = self.iteration + self.options.max_iterations;
        self.last = self.measures();
        if self.is_converged() {
            self.phase = PqPhase::Done;
            self.converged = true;
        }
        true
    }

    /// Keeps the exact phase's last factorisation for the next stage's mesh `work` (see
    /// [`LevenbergMarquardt::keep_factor_for`]).
    fn restage_factor(&mut self, work: &PolyMesh) -> bool {
        let problem = Problem {
            mesh: work,
            topo: &self.topo,
            terms: &self.terms,
            mode: self.options.mode,
            determinant_terms: self.options.determinant_terms,
            w_fair: self.w_fair,
            w_close: self.w_close,
        };
        self.exact.keep_factor_for(&Feasibility(&problem), &self.x)
    }

    /// Starts in the exact phase, its first step the probe of [`PROBE_CONTRACTION`] (a
    /// penalty step when the probe fails); true when it does (a run not started whose options
    /// allow the probe). For a mesh that is planar but where its held vertices moved, the
    /// first stage of a live edit: the penalty phase is there to bring a mesh from far, and
    /// from a planar mesh a quarter edge away its first step only costs a factorisation.
    ///
    /// A quad mesh in planar mode takes its exact phase in face space instead
    /// ([`PlanarProjection`]): every step a least-move Gauss-Newton step on the quads'
    /// determinants, from the first (no probe, no penalty step; a step that fails ends the run
    /// not converged).
    pub(crate) fn start_exact(&mut self) -> bool {
        if self.iteration != 0 || !self.probe_allowed {
            return false;
        }
        if self.face_space {
            // A run that keeps a design starts so already; no way back to the penalty phase.
            self.least_move_start = None;
            return true;
        }
        if self.phase != PqPhase::Penalty {
            return false;
        }
        if self.options.mode == PqMode::Planar && PlanarProjection::applies(&self.work) {
            self.face_space = true;
            self.phase = PqPhase::Sqp;
        } else {
            self.enter_refinement(true);
        }
        true
    }

    /// One least-move step in face space (see [`Self::face_space`]) of the unknowns `x`,
    /// the pattern analysed at the first (or taken from the spare analysis when it covers
    /// this mesh and its held vertices).
    fn face_space_step(&mut self, x: &mut [f64]) -> Result<(), SolverError> {
        if self.projection.is_none() {
            let spare = self.spare_projection.take();
            self.projection = Some(match spare {
                Some(p) if p.covers(&self.work, &self.terms.var_of) => p,
                _ => PlanarProjection::new(
                    &self.work,
                    &self.terms.var_of,
                    self.options.max_factor_bytes,
                    true,
                )?,
            });
        }
        let projection = self.projection.as_mut().expect("made above");
        let mut work = self.work.positions.clone();
        let step = projection
            .step(&mut work, &self.terms.var_of, x)
            .map(|_| ());
        if step.is_ok() && self.iteration == 0 && self.least_move_start.is_some() {
            let mut after = self.work.clone();
            after.positions = work;
            if max_planarity(&after) > LEAST_MOVE_CONTRACTION * self.last.0 {
                return Err(SolverError::Factorization(
                    "the least move does not bring the design near planar".into(),
                ));
            }
        }
        step
    }

    /// Whether the run has reached the tolerance (so far).
    pub(crate) fn converged(&self) -> bool {
        self.converged
    }

    /// Symbolic analyses of sparsity patterns behind this perturbation's solvers, those of
    /// the perturbations it took its analyses from included.
    #[cfg(test)]
    pub(crate) fn analyses(&self) -> usize {
        self.lm.analyses() + self.exact.analyses()
    }

    /// Starts from another perturbation's analyses ([`PqPerturbation::take_analyses`]).
    pub(crate) fn adopt_analyses(&mut self, a: PqAnalyses) {
        if let Some(lm) = a.lm {
            self.lm.adopt_analysis(lm);
        }
        if let Some(exact) = a.exact {
            self.exact.adopt_analysis(exact);
        }
        self.spare_projection = a.projection;
    }

    fn mode_residual(&self) -> f64 {
        match self.options.mode {
            PqMode::Planar => 0.0,
            PqMode::Conical => conical_residual(&self.mesh, &self.topo),
            PqMode::Circular => circular_residual(&self.mesh),
        }
    }

    /// Contract `max_planarity` and the mode residual of the current mesh.
    fn measures(&self) -> (f64, f64) {
        (max_planarity(&self.mesh), self.mode_residual())
    }

    fn is_converged(&self) -> bool {
        self.last.0 <= self.options.tolerance && self.last.1 <= self.options.tolerance
    }

    fn sync_mesh(&mut self) {
        for v in 0..self.mesh.num_vertices() {
            let b = self.terms.var_of[v];
            if b != NONE {
                let b = b as usize;
                let q = Vec3::new(self.x[b], self.x[b + 1], self.x[b + 2]);
                self.work.positions[v] = q;
                self.mesh.positions[v] = self.frame.to_user(q);
            }
        }
    }

    /// The current mesh.
    pub fn mesh(&self) -> &PolyMesh {
        &self.mesh
    }

    /// The current phase.
    pub fn phase(&self) -> PqPhase {
        self.phase
    }

    fn iterate(&mut self) {
        let mut x = self.x.clone();
        let face_space =
            (self.phase == PqPhase::Sqp && self.face_space).then(|| self.face_space_step(&mut x));
        let problem = Problem {
            mesh: &self.work,
            topo: &self.topo,
            terms: &self.terms,
            mode: self.options.mode,
            determinant_terms: self.options.determinant_terms,
            w_fair: self.w_fair,
            w_close: self.w_close,
        };
        let outcome = match self.phase {
            PqPhase::Sqp if self.face_space => match face_space.expect("stepped above") {
                Err(_) if self.least_move_start.is_some() => {
                    // Not near a planar design: the paper's way from the input, this step its
                    // first penalty step.
                    self.face_space = false;
                    x = self.least_move_start.take().expect("checked above");
                    self.phase = PqPhase::Penalty;
                    let mut input = self.mesh.clone();
                    input.positions.clone_from(&self.input);
                    self.last = (max_planarity(&input), self.last.1);
                    self.lm.step_blocks(&problem, &mut x).map(|_| ())
                }
                step => step,
            },
            PqPhase::Penalty => self.lm.step_blocks(&problem, &mut x).map(|_| ()),
            _ if self.options.refinement == Refinement::GaussNewton => {
                let feasibility = Feasibility(&problem);
                let fast = |s: &LmStep| s.cost_after <= CHORD_RATE * CHORD_RATE * s.cost_before;
                if std::mem::take(&mut self.probe) {
                    match self.exact.try_step_blocks(&feasibility, &mut x) {
                        Ok(s) if s.cost_after <= PROBE_CONTRACTION * s.cost_before => {
                            self.chord = fast(&s);
                            Ok(())
                        }
                        // Not near enough: discard the probe, this step is a penalty step.
                        _ => {
                            x.copy_from_slice(&self.x);
                            self.exact.invalidate();
                            self.phase = PqPhase::Penalty;
                            self.lm.step_blocks(&problem, &mut x).map(|_| ())
                        }
                    }
                } else {
                    let chord = if self.chord {
                        self.exact.chord_step_blocks(&feasibility, &mut x)
                    } else {
                        Ok(None)
                    };
                    match chord {
                        Ok(Some(s)) if s.step_norm > 0.0 => {
                            self.chord = fast(&s);
                            Ok(())
                        }
                        // No chord step, or one that did not help: a Newton step.
                        _ => self.exact.step_blocks(&feasibility, &mut x).map(|s| {
                            self.chord = fast(&s);
                        }),
                    }
                }
            }
            _ => match self.sqp.step(&problem, &mut x) {
                Ok(_) => Ok(()),
                // Fall back to a damped penalty step when SQP finds no descent.
                Err(_) => self.lm.step_blocks(&problem, &mut x).map(|_| ()),
            },
        };
        self.iteration += 1;
        // The paper lets w1, w2 tend to zero; in the SQP phase too, so that its steps end at
        // the exact constraints instead of chasing the constrained optimum of fixed weights.
        if self.phase == PqPhase::Penalty || self.options.refinement == Refinement::Sqp {
            self.w_fair *= 0.5;
            self.w_close *= 0.5;
            self.lm.invalidate();
        }
        let before = self.last;
        match outcome {
            Ok(()) => {
                let old = std::mem::replace(&mut self.x, x);
                // The positions themselves, not `old` mapped again: the input's user
                // coordinates need not survive a round trip through the frame.
                let old_positions = (self.mesh.positions.clone(), self.work.positions.clone());
                self.sync_mesh();
                self.last = self.measures();
                // Keep the best mesh: reject a step that made both measures worse.
                if self.last.0.max(self.last.1) > 10.0 * before.0.max(before.1) {
                    self.x = old;
                    (self.mesh.positions, self.work.positions) = old_positions;
                    self.last = before;
                }
            }
            Err(e @ SolverError::TooLarge { .. }) => {
                // Known from the sparsity pattern before any numeric work: no other phase
                // would fit either.
                self.phase = PqPhase::Done;
                self.refused = true;
                self.reason = Some(e.to_string());
                return;
            }
            Err(e) => {
                if self.phase == PqPhase::Penalty {
                    self.enter_refinement(false);
                } else {
                    self.phase = PqPhase::Done;
                    self.reason = Some(format!("solver stalled: {e}{}", self.precision_note()));
                    return;
                }
            }
        }
        if self.is_converged() {
            self.phase = PqPhase::Done;
            self.converged = true;
        } else if self.iteration >= self.iteration_cap {
            self.phase = PqPhase::Done;
            self.reason = Some(format!(
                "iteration cap {} reached (max_planarity {:.3e}, mode residual {:.3e}){}",
                self.options.max_iterations,
                self.last.0,
                self.last.1,
                self.precision_note()
            ));
        } else if self.phase == PqPhase::Penalty {
            if self.iteration >= self.options.penalty_iterations
                || self.last.0.max(self.last.1) < 1e-4
            {
                self.enter_refinement(false);
            } else if self.iteration == 1 && self.probe_allowed {
                self.enter_refinement(true);
            }
        }
    }

    /// When the user's coordinates cannot hold the tolerance (a design far from the origin
    /// for its size), a note saying so and what to do; otherwise nothing.
    fn precision_note(&self) -> String {
        coordinate_precision_note(&self.mesh, self.options.tolerance)
    }

    /// Switches to the exact phase; `probe`: its first step is the trial of
    /// [`PROBE_CONTRACTION`].
    fn enter_refinement(&mut self, probe: bool) {
        self.phase = PqPhase::Sqp;
        self.probe = probe;
        self.lm.invalidate();
        self.exact.invalidate();
        // Near-Gauss-Newton steps on the constraints: quadratic convergence once close. If the
        // first one is rejected (far from feasible), retry at the penalty phase's damping.
        let last = self.lm.damping();
        // The exact phase's constraints are curved (angles, |n| = 1): a Newton step that
        // overshoots is repaired by a second-order correction rather than halved.
        self.exact.set_second_order_correction(true);
        if probe {
            self.exact.set_damping(1e-9);
        } else {
            // The penalty solver takes the `Refinement::Sqp` fall-back steps from here on
            // (after a probe it may still take penalty steps, which keep their settings).
            self.lm.set_second_order_correction(true);
            self.exact.set_damping_with_fallback(1e-9, last);
        }
    }

    /// Sparse factorisations so far (penalty and exact phase).
    pub(crate) fn factorizations(&self) -> usize {
        self.lm.factorizations()
            + self.exact.factorizations()
            + self
                .projection
                .as_ref()
                .map_or(0, PlanarProjection::factorizations)
    }
}

/// One step is one penalty or exact-phase iteration (a chord step in the exact phase); a step
/// cannot fail (a solver failure ends the run with [`PqResult::reason`]).
impl Stepper for PqPerturbation {
    type Metrics = PqStepInfo;
    type Output = PqResult;
    type Error = Infallible;

    fn step(&mut self) -> Result<PqStepInfo, Infallible> {
        if self.phase != PqPhase::Done {
            self.iterate();
        }
        Ok(self.metrics())
    }

    fn is_done(&self) -> bool {
        self.phase == PqPhase::Done
    }

    /// The iterations left under the cap.
    fn steps_left_at_most(&self) -> Option<usize> {
        Some(if self.is_done() {
            0
        } else {
            self.iteration_cap.saturating_sub(self.iteration)
        })
    }

    fn metrics(&self) -> PqStepInfo {
        PqStepInfo {
            iteration: self.iteration,
            phase: self.phase,
            max_planarity: self.last.0,
            mode_residual: self.last.1,
        }
    }

    /// Runs to the end and returns the result (the best mesh reached when not converged).
    fn finish(mut self) -> Result<PqResult, Infallible> {
        self.run_to_end()?;
        let (mut max_move, mut max_normal_move, mut max_tangential_move) = (0.0f64, 0.0f64, 0.0f64);
        for ((now, was), n) in self
            .mesh
            .positions
            .iter()
            .zip(&self.input)
            .zip(&self.terms.normals0)
        {
            let d = now - was;
            let along = d.dot(n);
            max_move = max_move.max(d.norm());
            max_normal_move = max_normal_move.max(along.abs());
            max_tangential_move = max_tangential_move.max((d - n * along).norm());
        }
        let factorizations = self.factorizations();
        Ok(PqResult {
            conical_residual: (self.options.mode == PqMode::Conical).then_some(self.last.1),
            circular_residual: (self.options.mode == PqMode::Circular).then_some(self.last.1),
            max_planarity: self.last.0,
            iterations: self.iteration,
            converged: self.converged,
            reason: self.reason,
            max_move,
            max_normal_move,
            max_tangential_move,
            factorizations,
            refused: self.refused,
            mesh: self.mesh,
        })
    }
}

/// One-shot PQ / conical / circular perturbation of `mesh` (see the module documentation):
/// [`PqPerturbation`] run to its end.
pub fn pq_perturb(mesh: &PolyMesh, options: PqOptions) -> Result<PqResult, PqError> {
    let Ok(result) = PqPerturbation::new(mesh, options)?.finish();
    Ok(result)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::representable_planarity;
    use crate::scenes::benchmark_meshes::{noisy_vase, skew_quad_grid, torus_centroid_dual};
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;
    fn run(mesh: &PolyMesh, options: PqOptions) -> PqResult {
        let r = pq_perturb(mesh, options).unwrap();
        eprintln!(
            "iterations {} converged {} planarity {:.3e} move {:.3e} {:?}",
            r.iterations, r.converged, r.max_planarity, r.max_move, r.reason
        );
        r
    }

    /// A design 1e7 from the origin with edges of about 0.1 cannot be planar to 1e-10 in f64:
    /// the run ends not converged, and its reason says why and what to do; the same mesh at the
    /// origin converges.
    #[test]
    fn far_from_the_origin_the_reason_names_the_coordinate_precision() {
        let near = skew_quad_grid(6, 20.0);
        let mut far = near.clone();
        for p in &mut far.positions {
            *p += Vec3::new(1e7, -1e7, 1e7);
        }
        let options = PqOptions {
            max_iterations: 20,
            ..PqOptions::default()
        };
        assert!(run(&near, options.clone()).converged);
        let r = run(&far, options);
        assert!(!r.converged);
        let reason = r.reason.unwrap();
        assert!(
            reason.contains("precision") && reason.contains("near the origin"),
            "{reason}"
        );
        assert!(representable_planarity(&far) > 1e-10);
        assert!(representable_planarity(&near) < 1e-14);
    }

    /// The exact phase is a Newton-KKT (SQP) iteration on the constraints (see
    /// [`Refinement::GaussNewton`]): once the constraint residual is small its Newton steps
    /// converge quadratically, r_{k+1} <= r_k^1.5 at every step below 5e-3 (measured: skew
    /// grid 10x10 1.8e-2, 6.3e-4, 7.1e-6; torus dual 2.9e-2, 3.8e-3, 8.8e-6), and once they
    /// contract by [`CHORD_RATE`] the chord steps that follow (no factorisation) keep
    /// contracting at about that rate (torus dual 8.8e-6, 4.0e-8, 2.0e-10, 9.7e-13: 3 chord
    /// steps instead of a third factorisation).
    #[test]
    fn exact_phase_converges_quadratically() {
        for (name, m) in [
            ("skew 10x10", skew_quad_grid(10, 30.0)),
            ("torus dual", torus_centroid_dual(48, 24, 3.0, 1.0)),
        ] {
            let mut s = PqPerturbation::new(&m, PqOptions::default()).unwrap();
            let (mut newton, mut chord) = (Vec::new(), Vec::new());
            let mut prev = f64::INFINITY;
            while !s.is_done() {
                let factored = s.factorizations();
                let exact = s.phase() != PqPhase::Penalty;
                let i = s.step().unwrap();
                let r = i.max_planarity.max(i.mode_residual);
                if exact {
                    if s.factorizations() > factored {
                        newton.push((prev, r));
                    } else {
                        chord.push((prev, r));
                    }
                }
                prev = r;
            }
            let result = s.finish().unwrap();
            assert!(result.converged, "{name}");
            assert!(
                result.factorizations < result.iterations,
                "{name}: no chord step"
            );
            let fast: Vec<_> = newton.iter().filter(|&&(a, _)| a < 5e-3).collect();
            assert!(!fast.is_empty(), "{name}: {newton:?}");
            for &&(a, b) in &fast {
                assert!(b <= a.powf(1.5), "{name}: {a:e} -> {b:e} not superlinear");
            }
            assert!(!chord.is_empty(), "{name}");
            for &(a, b) in &chord {
                assert!(b <= 0.1 * a, "{name}: chord step {a:e} -> {b:e}");
            }
        }
    }

    /// The probe after the first penalty iteration (`PROBE_CONTRACTION`): kept on the torus
    /// dual (one penalty factorisation instead of four, the exact phase converges from
    /// there), discarded on the skew grid and the noisy conical vase, where the run is then
    /// exactly one without a probe (same penalty settings, same mesh at the end of the
    /// penalty phase and at the end, bit for bit) at the price of one factorisation.
    #[test]
    fn probe_starts_the_exact_phase_only_when_near() {
        let conical = PqOptions {
            mode: PqMode::Conical,
            ..PqOptions::default()
        };
        for (name, m, options, kept) in [
            (
                "torus dual",
                torus_centroid_dual(48, 24, 3.0, 1.0),
                PqOptions::default(),
                true,
            ),
            (
                "skew 30x30",
                skew_quad_grid(30, 30.0),
                PqOptions::default(),
                false,
            ),
            ("noisy vase", noisy_vase(30), conical, false),
        ] {
            let run = |probe: bool| {
                let mut s = PqPerturbation::new(&m, options.clone()).unwrap();
                assert!(s.probe_allowed);
                s.probe_allowed = probe;
                // The mesh when the penalty phase ends.
                let mut after_penalty = None;
                while !s.is_done() {
                    let penalty = s.phase() != PqPhase::Sqp || s.probe;
                    s.step().unwrap();
                    // Penalty steps keep the penalty settings, probe or not.
                    if s.phase() == PqPhase::Penalty {
                        assert_eq!(
                            s.lm.options(),
                            lm_options(options.max_factor_bytes),
                            "{name}"
                        );
                    }
                    if penalty && s.phase() == PqPhase::Sqp && !s.probe {
                        after_penalty = Some(s.mesh().clone());
                    }
                }
                let penalty = s.lm.factorizations();
                (penalty, after_penalty, s.finish().unwrap())
            };
            let (penalty, probed_penalty, probed) = run(true);
            let (penalty_without, without_penalty, without) = run(false);
            assert!(probed.converged && without.converged, "{name}");
            assert_eq!(penalty_without, 4, "{name}");
            if kept {
                assert_eq!(penalty, 1, "{name}");
                assert!(probed.factorizations + 2 < without.factorizations, "{name}");
            } else {
                assert_eq!(penalty, 4, "{name}");
                assert!(probed_penalty.is_some(), "{name}");
                assert_eq!(probed_penalty, without_penalty, "{name}");
                assert_eq!(probed.factorizations, without.factorizations + 1, "{name}");
                assert_eq!(probed.mesh, without.mesh, "{name}");
            }
        }
    }

    /// Keeping the design, the solver works in a centred frame scaled by a power of two to
    /// the unit box (`SolverFrame::unit_box`): a design scaled by a power of two takes exactly
    /// the same steps to the same shape bit for bit, and at any size from 1e-6 to 1e6 and at
    /// state-plane offsets (1e7) it takes the same steps and ends planar to the tolerance in
    /// the user's coordinates, with moves in proportion to its size. (The paper's settings, in the user's
    /// coordinates, take different steps at different sizes: a z = xy grid stalled at some
    /// sizes and took 17-31 iterations at others.)
    #[test]
    fn planarisation_is_free_of_scale_and_offset() {
        let base = skew_quad_grid(20, 30.0);
        let options = PqOptions {
            keep_design: true,
            ..PqOptions::default()
        };
        let reference = run(&base, options.clone());
        assert!(reference.converged);
        let scaled = |scale: f64, offset: f64| {
            let mut m = base.clone();
            for p in &mut m.positions {
                *p = *p * scale + Vec3::repeat(offset);
            }
            (m.clone(), run(&m, options.clone()))
        };
        for scale in [
            0.5f64.powi(20),
            0.5f64.powi(7),
            2f64.powi(10),
            2f64.powi(20),
        ] {
            let (_, r) = scaled(scale, 0.0);
            assert_eq!(r.iterations, reference.iterations, "scale {scale:e}");
            assert_eq!(r.factorizations, reference.factorizations);
            for (p, q) in r.mesh.positions.iter().zip(&reference.mesh.positions) {
                assert_eq!(p / scale, *q, "scale {scale:e}");
            }
        }
        for (scale, offset) in [
            (1e-6, 0.0),
            (1e-3, 0.0),
            (3.7, 0.0),
            (1e3, 0.0),
            (1e6, 0.0),
            (1e4, 1e7),
            (1e6, -1e7),
        ] {
            let (m, r) = scaled(scale, offset);
            let at = format!("scale {scale:e}, offset {offset:e}");
            assert!(r.converged, "{at}: {:?}", r.reason);
            assert!(max_planarity(&r.mesh) <= 1e-11, "{at}");
            // The step metric is in lengths: the same steps, not only at powers of two.
            assert_eq!(r.iterations, reference.iterations, "{at}");
            let relative_move = r.max_move / scale / reference.max_move;
            assert!((relative_move - 1.0).abs() < 1e-6, "{at}: {relative_move}");
            let moved = m
                .positions
                .iter()
                .zip(&r.mesh.positions)
                .map(|(a, b)| (a - b).norm())
                .fold(0.0, f64::max);
            assert_eq!(moved, r.max_move, "{at}");
        }
    }

    /// A 20 m x 20 m planar 40 x 40 quad grid with up to 1 mm of noise (seeded): the plane
    /// z = 0 is a planar mesh within 1 mm of it. Keeping the design moves no vertex by more
    /// than twice that (measured 1.25 mm); the paper's fair-mesh settings pull the corners
    /// in by 287 mm.
    #[test]
    fn keeping_the_design_moves_a_noisy_planar_grid_by_its_noise_only() {
        let n = 40;
        let mut p = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                let h = ((i as f64 * 12.9898 + j as f64 * 78.233).sin() * 43758.5453).fract();
                p.push(Vec3::new(
                    20.0 * i as f64 / n as f64,
                    20.0 * j as f64 / n as f64,
                    1e-3 * h,
                ));
            }
        }
        let m = PolyMesh::quad_grid(p, n, n).unwrap();
        let kept = run(
            &m,
            PqOptions {
                keep_design: true,
                ..PqOptions::default()
            },
        );
        assert!(kept.converged, "{:?}", kept.reason);
        assert!(kept.max_move <= 2e-3, "{}", kept.max_move);
        // The noise is along the normal; the vertices barely slide.
        assert!(kept.max_normal_move <= kept.max_move);
        assert!(
            kept.max_tangential_move <= 0.1 * kept.max_normal_move,
            "{kept:?}"
        );
        let slide = |r: &PqResult| {
            m.positions
                .iter()
                .zip(&r.mesh.positions)
                .map(|(a, b)| ((b - a).x.powi(2) + (b - a).y.powi(2)).sqrt())
                .fold(0.0, f64::max)
        };
        assert!((slide(&kept) - kept.max_tangential_move).abs() <= 1e-2 * kept.max_normal_move);
        let fair = run(&m, PqOptions::default());
        assert!(fair.max_move > 0.1, "{}", fair.max_move);
    }

    /// A factor beyond `max_factor_bytes` is refused from the sparsity pattern, before any
    /// numeric work: the mesh comes back untouched and the reason names both sizes.
    #[test]
    fn beyond_the_factor_limit_the_run_is_refused_untouched() {
        let m = skew_quad_grid(20, 30.0);
        let r = run(
            &m,
            PqOptions {
                max_factor_bytes: 1000,
                ..PqOptions::default()
            },
        );
        assert!(r.refused && !r.converged);
        assert_eq!(r.mesh, m);
        assert_eq!(r.factorizations, 0);
        let reason = r.reason.unwrap();
        assert!(
            reason.contains("needs") && reason.contains("limit"),
            "{reason}"
        );
        assert!(!run(&m, PqOptions::default()).refused);
    }

    /// Anchors keep the user's bits although the solver moves everything into its frame.
    #[test]
    fn anchors_keep_their_bits_far_from_the_origin() {
        let mut m = skew_quad_grid(12, 30.0);
        for p in &mut m.positions {
            *p = *p * 1234.5 + Vec3::new(3.1e5, 1.7e6, 0.3);
        }
        let fixed = vec![0, 7, 40, 100];
        let r = run(
            &m,
            PqOptions {
                fixed_vertices: fixed.clone(),
                keep_design: true,
                ..PqOptions::default()
            },
        );
        assert!(r.converged, "{:?}", r.reason);
        for v in fixed {
            assert_eq!(r.mesh.positions[v], m.positions[v]);
        }
    }

    #[test]
    fn skew_grid_becomes_planar() {
        let m = skew_quad_grid(30, 30.0);
        assert!(max_planarity(&m) > 1e-3);
        let r = run(&m, PqOptions::default());
        assert!(r.converged);
        assert!(max_planarity(&r.mesh) <= 1e-10);
    }

    #[test]
    fn torus_dual_hexagons_become_planar() {
        let m = torus_centroid_dual(48, 24, 3.0, 1.0);
        assert_eq!(m.num_faces(), 1152);
        assert!(max_planarity(&m) > 1e-3);
        let r = run(&m, PqOptions::default());
        assert!(r.converged);
        assert!(max_planarity(&r.mesh) <= 1e-10);
    }

    /// An `n x n` quad grid of 0.05 edges on a translational surface (whose grid quads are
    /// planar), its heights with seeded noise of `amplitude` (in units of the edge).
    fn noisy_curved_grid(n: usize, amplitude: f64) -> PolyMesh {
        let mut rng = ChaCha8Rng::seed_from_u64(30);
        let positions = (0..=n)
            .flat_map(|j| (0..=n).map(move |i| (i as f64 * 0.05, j as f64 * 0.05)))
            .map(|(x, y)| Vec3::new(x, y, 0.3 * ((x - 0.75).powi(2) - (y - 0.75).powi(2))))
            .collect::<Vec<_>>()
            .into_iter()
            .map(|p| p + Vec3::new(0.0, 0.0, 0.05 * amplitude * (rng.random::<f64>() - 0.5)))
            .collect();
        PolyMesh::quad_grid(positions, n, n).unwrap()
    }

    /// Keeping a design near planar (noise of 4% of an edge on a curved grid), the run is the
    /// least move in face space from its first step: converged in a few cheap steps, every
    /// vertex moved less than twice the noise's amplitude (measured: 1.12x), where the paper's
    /// way (penalty phase first) moves them further.
    #[test]
    fn a_design_near_planar_is_kept_by_the_least_move() {
        let mesh = noisy_curved_grid(30, 0.04);
        let keep = PqOptions {
            keep_design: true,
            ..PqOptions::default()
        };
        let mut s = PqPerturbation::new(&mesh, keep.clone()).unwrap();
        assert!(s.face_space);
        while !s.is_done() {
            s.step().unwrap();
            assert_ne!(s.phase(), PqPhase::Penalty);
        }
        let r = s.finish().unwrap();
        assert!(r.converged, "{:?}", r.reason);
        assert!(r.max_planarity <= keep.tolerance);
        assert!(r.iterations <= 6, "{} iterations", r.iterations);
        // The grid under the noise is planar (a translational surface's isolines): the
        // design is within `amplitude` of a planar mesh, and is kept within 2x that.
        let amplitude = 0.04 * 0.05 / 2.0;
        assert!(r.max_move <= 2.0 * amplitude, "max_move {:e}", r.max_move);
        let paper = run(&mesh, PqOptions::default());
        assert!(paper.max_move > 2.0 * r.max_move, "{:e}", paper.max_move);
    }

    /// Keeping a design far from planar (the skew grid: its first least-move step does not
    /// divide the planarity by 10), the run starts again from the input in the penalty
    /// phase, and ends as that way does; anchors keep their bits either way.
    #[test]
    fn a_design_far_from_planar_takes_the_penalty_phase() {
        let mesh = skew_quad_grid(10, 30.0);
        let options = PqOptions {
            keep_design: true,
            fixed_vertices: vec![0, 10],
            ..PqOptions::default()
        };
        let mut s = PqPerturbation::new(&mesh, options.clone()).unwrap();
        assert!(s.face_space);
        s.step().unwrap();
        assert!(!s.face_space, "the least move took the skew grid");
        let r = s.finish().unwrap();
        assert!(r.converged, "{:?}", r.reason);
        let mut paper = PqPerturbation::new(&mesh, options).unwrap();
        paper.face_space = false;
        paper.least_move_start = None;
        paper.phase = PqPhase::Penalty;
        let paper = paper.finish().unwrap();
        assert_eq!(r.mesh.positions, paper.mesh.positions);
        for v in [0, 10] {
            assert_eq!(r.mesh.positions[v], mesh.positions[v]);
        }
    }
}
