//! A PQ scene stepped level by level (conical paper, Sec. 2 and 3: subdivision and PQ
//! perturbation alternating, Figs. 7, 9, 14, 16, 17), for a viewer that watches the hierarchy
//! grow: control mesh -> perturbed -> subdivided -> perturbed -> ...
//!
//! Input: a [`PqSceneSpec`] (a control mesh or strip with its rule, level count and
//! [`PqOptions`]; the named scenes are in [`crate::scenes`]). One [`Stepper::step`] is one perturbation iteration
//! ([`Stepper::step`] of [`PqPerturbation`]) or one subdivision (Catmull-Clark or Doo-Sabin for meshes, one
//! curve-rule round for strips). Output after every step: the current mesh, level, phase,
//! iteration count and the scene's measures; [`Stepper::finish`] gives the same
//! [`PqSceneResult`].

use super::circular::circular_residual;
use super::cones::conical_residual;
use super::developable_strip::{PqStrip, StripRule};
use super::perturbation::{PqAnalyses, PqError, PqMode, PqOptions, PqPerturbation, PqPhase};
use crate::Stepper;
use crate::mesh::{MeshTopology, PolyMesh, TopologyError, catmull_clark, doo_sabin, max_planarity};
use thiserror::Error;

/// Why a PQ scene could not be built.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum PqSceneError {
    /// No scene has this name.
    #[error("unknown PQ scene `{0}` (see --list-scenes)")]
    UnknownScene(String),
    /// A live edit that cannot be made (the message says why).
    #[error("{0}")]
    Edit(String),
    /// The perturbation rejected a mesh of the scene.
    #[error(transparent)]
    Pq(#[from] PqError),
    /// Subdivision met a non-manifold mesh.
    #[error(transparent)]
    Topology(#[from] TopologyError),
}

/// The final mesh of a PQ scene and its measures.
#[derive(Debug, Clone, PartialEq)]
pub struct PqSceneResult {
    /// The final mesh.
    pub mesh: PolyMesh,
    /// Subdivision levels applied.
    pub levels: usize,
    /// Perturbation iterations over all levels.
    pub iterations: usize,
    /// Whether every perturbation converged.
    pub converged: bool,
    /// The measures of the final mesh.
    pub measures: PqSceneMeasures,
}

/// What a PQ scene measures on a mesh: planarity always, and the residual of its mode or the
/// strip figures where they apply.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PqSceneMeasures {
    /// Contract `max_planarity`.
    pub max_planarity: f64,
    /// `conical_residual` (conical scenes).
    pub conical_residual: Option<f64>,
    /// `circular_residual` (circular scenes).
    pub circular_residual: Option<f64>,
    /// Largest determinant term (developable scenes).
    pub max_determinant: Option<f64>,
    /// Number of quads whose singular-curve point lies on the strip (developable scenes).
    pub singular_points_inside: Option<usize>,
}

/// What a PQ scene is made of: a control mesh refined by a surface subdivision rule, or a
/// control strip refined by a curve rule, with the perturbation options of every level.
#[derive(Debug, Clone)]
pub enum PqSceneSpec {
    /// Subdivide with Catmull-Clark and perturb, `levels` times, after perturbing `control`.
    Mesh {
        /// The control mesh (level 0).
        control: PolyMesh,
        /// Subdivision levels after the control mesh.
        levels: usize,
        /// The perturbation options of every level.
        options: PqOptions,
    },
    /// Developable subdivision of `strip` with `rule`, `rounds` times.
    Strip {
        /// The control strip (level 0).
        strip: PqStrip,
        /// The curve subdivision rule of its polylines.
        rule: StripRule,
        /// Subdivision rounds after the control strip.
        rounds: usize,
        /// The perturbation options of every level.
        options: PqOptions,
    },
}

/// Number of quads of `strip` whose singular-curve point lies on the strip (ruling parameter
/// in \[0, 1\]).
fn singular_points_inside(strip: &PqStrip) -> usize {
    strip
        .singular_curve()
        .iter()
        .filter(|p| matches!(p, Some((_, t)) if (0.0..=1.0).contains(t)))
        .count()
}

/// Surface subdivision rule between the levels of a mesh scene.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeshRule {
    /// Catmull-Clark (quads stay quads; the conical paper's Figs. 7 and 14).
    CatmullClark,
    /// Doo-Sabin (a quad mesh gains n-gons at the old vertices).
    DooSabin,
}

/// What the last step of a [`PqSceneStepper`] did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PqScenePhase {
    /// No step yet: the control mesh as given.
    Control,
    /// One perturbation iteration.
    Perturb,
    /// One subdivision (a new level).
    Subdivide,
    /// Finished: the last level is perturbed.
    Done,
}

impl PqScenePhase {
    /// `control`, `perturb`, `subdivide` or `done`.
    pub fn name(self) -> &'static str {
        match self {
            PqScenePhase::Control => "control",
            PqScenePhase::Perturb => "perturb",
            PqScenePhase::Subdivide => "subdivide",
            PqScenePhase::Done => "done",
        }
    }
}

/// The state after a step and its measures.
#[derive(Debug, Clone, PartialEq)]
pub struct PqSceneStepInfo {
    /// Subdivision level of the current mesh (0: control).
    pub level: usize,
    /// Total subdivision levels of the scene.
    pub levels: usize,
    /// What the last step did.
    pub phase: PqScenePhase,
    /// Phase of the running perturbation (penalty or SQP), `None` between perturbations.
    pub perturbation_phase: Option<PqPhase>,
    /// Perturbation iterations over all levels so far.
    pub iteration: usize,
    /// Faces of the current mesh.
    pub faces: usize,
    /// The measures of the current mesh.
    pub measures: PqSceneMeasures,
}

/// The refinement a stepper applies.
#[derive(Debug, Clone)]
pub(super) enum Target {
    Mesh(MeshRule),
    /// The current strip (the perturbation runs on its cut-open mesh).
    Strip {
        rule: StripRule,
        strip: PqStrip,
    },
}

/// A PQ scene that can be stepped and watched (see the module documentation).
pub struct PqSceneStepper {
    pub(super) target: Target,
    pub(super) options: PqOptions,
    pub(super) levels: usize,
    pub(super) level: usize,
    pub(super) phase: PqScenePhase,
    /// The running perturbation; `None` once it finished (the next step subdivides or the
    /// run is done).
    pub(super) perturbation: Option<PqPerturbation>,
    pub(super) mesh: PolyMesh,
    /// Iterations of the finished perturbations.
    pub(super) done_iterations: usize,
    /// Iterations of the running perturbation.
    pub(super) running_iterations: usize,
    pub(super) converged: bool,
    /// The mesh live edits start from ([`PqSceneStepper::commit`]), `None` before the first.
    pub(super) edit_base: Option<PolyMesh>,
    /// The stages of the running live edit.
    pub(super) edit_stages: Option<super::live_edit::EditStages>,
    /// Why the last live edit stopped short of its target.
    pub(super) edit_shortfall: Option<String>,
    /// The analyses of the last finished live edit's perturbation, for the next edit (the
    /// page's next pointer position: the same mesh and held vertices).
    pub(super) edit_analyses: Option<PqAnalyses>,
}

/// Why a finished PQ scene misses what it was asked (a perturbation level that did not reach
/// its tolerance), or `None` when every level converged.
pub fn pq_scene_shortfall(converged: bool, measures: &PqSceneMeasures) -> Option<String> {
    (!converged).then(|| {
        format!(
            "a perturbation level did not reach the tolerance (max_planarity {:.3e})",
            measures.max_planarity
        )
    })
}

impl PqSceneStepper {
    /// Whether every perturbation run so far reached its tolerance.
    pub fn converged(&self) -> bool {
        self.converged
    }

    /// The scene `spec` at its control mesh.
    pub fn from_spec(spec: PqSceneSpec) -> Result<Self, PqSceneError> {
        match spec {
            PqSceneSpec::Mesh {
                control,
                levels,
                options,
            } => Self::for_mesh(&control, MeshRule::CatmullClark, levels, options),
            PqSceneSpec::Strip {
                strip,
                rule,
                rounds,
                options,
            } => Self::for_strip(&strip, rule, rounds, options),
        }
    }

    /// Perturb `control`, then `levels` times subdivide with `rule` and perturb.
    pub fn for_mesh(
        control: &PolyMesh,
        rule: MeshRule,
        levels: usize,
        options: PqOptions,
    ) -> Result<Self, PqSceneError> {
        let perturbation = PqPerturbation::new(control, options.clone())?;
        Ok(PqSceneStepper {
            target: Target::Mesh(rule),
            options,
            levels,
            level: 0,
            phase: PqScenePhase::Control,
            perturbation: Some(perturbation),
            mesh: control.clone(),
            done_iterations: 0,
            running_iterations: 0,
            converged: true,
            edit_base: None,
            edit_stages: None,
            edit_shortfall: None,
            edit_analyses: None,
        })
    }

    /// Developable subdivision: perturb `strip` (with the determinant terms, glued across a
    /// closed or Möbius joint), then `rounds` times subdivide its polylines with `rule` and
    /// perturb, as [`super::developable_subdivision`] does.
    pub fn for_strip(
        strip: &PqStrip,
        rule: StripRule,
        rounds: usize,
        options: PqOptions,
    ) -> Result<Self, PqSceneError> {
        let perturbation = strip.perturbation(&options)?;
        Ok(PqSceneStepper {
            target: Target::Strip {
                rule,
                strip: strip.clone(),
            },
            options,
            levels: rounds,
            level: 0,
            phase: PqScenePhase::Control,
            perturbation: Some(perturbation),
            mesh: strip.to_mesh(),
            done_iterations: 0,
            running_iterations: 0,
            converged: true,
            edit_base: None,
            edit_stages: None,
            edit_shortfall: None,
            edit_analyses: None,
        })
    }

    /// The current mesh (for strips the strip itself, the Möbius joint closed).
    pub fn mesh(&self) -> &PolyMesh {
        &self.mesh
    }

    /// The current strip (strip scenes).
    pub fn strip(&self) -> Option<&PqStrip> {
        match &self.target {
            Target::Strip { strip, .. } => Some(strip),
            Target::Mesh(_) => None,
        }
    }

    /// The perturbation mode of every level.
    pub fn mode(&self) -> PqMode {
        self.options.mode
    }

    /// Current subdivision level (0: control).
    pub fn level(&self) -> usize {
        self.level
    }

    /// What the last step did.
    pub fn phase(&self) -> PqScenePhase {
        self.phase
    }

    /// Perturbation iterations over all levels so far.
    pub fn iteration(&self) -> usize {
        self.done_iterations + self.running_iterations
    }

    /// Ends a finished perturbation: its result becomes the current mesh, and after the last
    /// level the run is done.
    fn settle(&mut self) -> Result<(), PqSceneError> {
        if !self.perturbation.as_ref().is_some_and(|p| p.is_done()) {
            return Ok(());
        }
        if self.continue_edit() || self.restart_edit_slowly()? {
            return Ok(());
        }
        let mut finished = self.perturbation.take().expect("a finished perturbation");
        let analyses = finished.take_analyses();
        let Ok(r) = finished.finish();
        self.done_iterations += r.iterations;
        self.running_iterations = 0;
        self.converged &= r.converged;
        self.show(r.mesh);
        // A live edit moves its vertices in stages (live_edit.rs): the next one starts here,
        // unless this one missed the tolerance (the edit then ends short of its target, as a
        // run that did not converge).
        if !r.converged
            && let Some(stages) = self.edit_stages.take()
        {
            self.edit_shortfall = Some(stages.shortfall());
        }
        if self.next_edit_stage()? {
            // The next stage solves the same pattern: it starts from this one's analyses.
            if let Some(p) = self.perturbation.as_mut() {
                p.adopt_analyses(analyses);
            }
            return Ok(());
        }
        if self.edit_base.is_some() {
            self.edit_analyses = Some(analyses.face_space_only());
        }
        if self.level == self.levels {
            self.phase = PqScenePhase::Done;
        }
        Ok(())
    }

    /// Takes the positions of the perturbation's mesh (for strips, of the cut-open mesh).
    pub(super) fn show(&mut self, perturbed: PolyMesh) {
        match &mut self.target {
            Target::Mesh(_) => self.mesh = perturbed,
            Target::Strip { strip, .. } => {
                *strip = strip.rebuild_from_cut(&perturbed.positions);
                self.mesh = strip.to_mesh();
            }
        }
    }
}

/// One step is one perturbation iteration or one subdivision.
impl PqSceneStepper {
    /// One perturbation iteration or one subdivision, unmeasured; `show` copies a running
    /// perturbation's mesh out for display.
    fn advance(&mut self, show: bool) -> Result<(), PqSceneError> {
        self.settle()?;
        if self.phase == PqScenePhase::Done {
            return Ok(());
        }
        if let Some(p) = self.perturbation.as_mut() {
            let Ok(i) = p.step();
            self.running_iterations = i.iteration;
            self.phase = PqScenePhase::Perturb;
            if show && !p.is_done() {
                let m = p.mesh().clone();
                self.show(m);
            }
            self.settle()?;
        } else {
            self.level += 1;
            self.phase = PqScenePhase::Subdivide;
            match &mut self.target {
                Target::Mesh(rule) => {
                    self.mesh = match rule {
                        MeshRule::CatmullClark => catmull_clark(&self.mesh)?,
                        MeshRule::DooSabin => doo_sabin(&self.mesh)?,
                    };
                    self.perturbation =
                        Some(PqPerturbation::new(&self.mesh, self.options.clone())?);
                }
                Target::Strip { rule, strip } => {
                    *strip = strip.subdivide(*rule);
                    self.mesh = strip.to_mesh();
                    self.perturbation = Some(strip.perturbation(&self.options)?);
                }
            }
        }
        Ok(())
    }
}

impl Stepper for PqSceneStepper {
    type Metrics = PqSceneStepInfo;
    type Output = PqSceneResult;
    type Error = PqSceneError;

    /// One perturbation iteration or one subdivision (no-op once done); returns the state
    /// after it. A level whose mesh needs no perturbation (already within the tolerance)
    /// takes no step of its own.
    fn step(&mut self) -> Result<PqSceneStepInfo, PqSceneError> {
        self.advance(true)?;
        Ok(self.metrics())
    }

    /// The steps without their measures and without copying each iteration's mesh out of the
    /// perturbation: the same final state, at the cost of the one-shot parts.
    fn run_to_end(&mut self) -> Result<(), PqSceneError> {
        while !self.is_done() {
            self.advance(false)?;
        }
        Ok(())
    }

    /// Whether the run has finished.
    fn is_done(&self) -> bool {
        self.phase == PqScenePhase::Done
    }

    /// The running perturbation's iterations under its cap, then those of a live edit's
    /// stages still to come, then per level still to come a
    /// subdivision and a perturbation's cap.
    fn steps_left_at_most(&self) -> Option<usize> {
        if self.is_done() {
            return Some(0);
        }
        let running = self
            .perturbation
            .as_ref()
            .and_then(|p| p.steps_left_at_most())
            .unwrap_or(0);
        let stages = self
            .edit_stages
            .as_ref()
            .map_or(0, |s| s.steps_at_most(self.options.max_iterations));
        Some(running + stages + (self.levels - self.level) * (1 + self.options.max_iterations))
    }

    /// The current state and its measures (computed on the current mesh).
    fn metrics(&self) -> PqSceneStepInfo {
        let conical = (self.options.mode == PqMode::Conical).then(|| {
            MeshTopology::new(&self.mesh)
                .map_or(f64::INFINITY, |t| conical_residual(&self.mesh, &t))
        });
        let strip = self.strip();
        PqSceneStepInfo {
            level: self.level,
            levels: self.levels,
            phase: self.phase,
            perturbation_phase: self.perturbation.as_ref().map(|p| p.phase()),
            iteration: self.iteration(),
            faces: self.mesh.num_faces(),
            measures: PqSceneMeasures {
                max_planarity: max_planarity(&self.mesh),
                conical_residual: conical,
                circular_residual: (self.options.mode == PqMode::Circular)
                    .then(|| circular_residual(&self.mesh)),
                max_determinant: strip.map(|s| s.max_determinant()),
                singular_points_inside: strip.map(singular_points_inside),
            },
        }
    }

    /// Runs to the end and returns the scene's result.
    fn finish(mut self) -> Result<PqSceneResult, PqSceneError> {
        self.run_to_end()?;
        let measures = self.metrics().measures;
        Ok(PqSceneResult {
            mesh: self.mesh,
            levels: self.levels,
            iterations: self.done_iterations,
            converged: self.converged,
            measures,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::conical::{developable_subdivision, pq_perturb};
    use crate::scenes::{PQ_SCENES, benchmark_meshes::skew_quad_grid, pq_scene_spec};

    /// The scene built from the one-shot parts (`pq_perturb`, `catmull_clark`,
    /// `developable_subdivision`), independently of the stepper.
    fn one_shot(name: &str) -> PqSceneResult {
        match pq_scene_spec(name).unwrap() {
            PqSceneSpec::Mesh {
                control,
                levels,
                options,
            } => subdivide_and_perturb(&control, levels, &options).unwrap(),
            PqSceneSpec::Strip {
                strip,
                rule,
                rounds,
                options,
            } => {
                let (levels, it, ok) =
                    developable_subdivision(&strip, rule, rounds, &options).unwrap();
                strip_result(levels, it, ok)
            }
        }
    }

    /// Subdivide with `rule` and perturb with `options`, `levels` times, after perturbing the
    /// control mesh itself.
    fn subdivide_and_perturb(
        control: &PolyMesh,
        levels: usize,
        options: &PqOptions,
    ) -> Result<PqSceneResult, PqSceneError> {
        let mut r = pq_perturb(control, options.clone())?;
        let mut iterations = r.iterations;
        let mut converged = r.converged;
        for _ in 0..levels {
            let fine = catmull_clark(&r.mesh)?;
            r = pq_perturb(&fine, options.clone())?;
            iterations += r.iterations;
            converged &= r.converged;
        }
        let topo = MeshTopology::new(&r.mesh)?;
        Ok(PqSceneResult {
            measures: PqSceneMeasures {
                max_planarity: max_planarity(&r.mesh),
                conical_residual: (options.mode == PqMode::Conical)
                    .then(|| conical_residual(&r.mesh, &topo)),
                circular_residual: (options.mode == PqMode::Circular)
                    .then(|| circular_residual(&r.mesh)),
                max_determinant: None,
                singular_points_inside: None,
            },
            mesh: r.mesh,
            levels,
            iterations,
            converged,
        })
    }

    fn strip_result(levels: Vec<PqStrip>, iterations: usize, converged: bool) -> PqSceneResult {
        let last = levels.last().expect("at least the control level");
        let mesh = last.to_mesh();
        let inside = singular_points_inside(last);
        PqSceneResult {
            measures: PqSceneMeasures {
                max_planarity: max_planarity(&mesh),
                conical_residual: None,
                circular_residual: None,
                max_determinant: Some(last.max_determinant()),
                singular_points_inside: Some(inside),
            },
            mesh,
            levels: levels.len() - 1,
            iterations,
            converged,
        }
    }

    /// Every PQ scene stepped to the end gives exactly the one-shot `pq_scene` result, and the
    /// steps are the promised ones: the control mesh first, every step changes the state,
    /// each level is one subdivision followed by perturbation iterations, and the levels
    /// count up to the scene's.
    #[test]
    fn stepper_ends_at_the_one_shot_result() {
        for &name in PQ_SCENES {
            let mut s = PqSceneStepper::from_spec(pq_scene_spec(name).unwrap()).unwrap();
            assert_eq!(s.phase(), PqScenePhase::Control);
            assert_eq!((s.level(), s.iteration()), (0, 0));
            let mut prev = s.metrics();
            let mut subdivisions = 0;
            let mut steps = 0;
            while !s.is_done() {
                let i = s.step().unwrap();
                steps += 1;
                match i.phase {
                    PqScenePhase::Subdivide => {
                        subdivisions += 1;
                        assert_eq!(i.level, prev.level + 1, "{name}");
                        assert!(i.faces > prev.faces, "{name}: a level adds faces");
                        assert_eq!(i.iteration, prev.iteration, "{name}");
                    }
                    PqScenePhase::Perturb | PqScenePhase::Done => {
                        assert_eq!(i.level, prev.level, "{name}");
                        assert_eq!(i.iteration, prev.iteration + 1, "{name}");
                        if s.is_done() {
                            assert_eq!(i.perturbation_phase, None, "{name}");
                        }
                    }
                    PqScenePhase::Control => panic!("{name}: back at the control mesh"),
                }
                prev = i;
            }
            assert_eq!(subdivisions, prev.levels, "{name}");
            // Every step is one iteration or one subdivision.
            assert_eq!(steps, prev.iteration + prev.levels, "{name}");
            let stepped = s.finish().unwrap();
            let one_shot = one_shot(name);
            assert_eq!(stepped, one_shot, "{name}");
        }
    }

    /// The measures of a step are those of the mesh on show: after a subdivision the mesh is
    /// far from conical again (Catmull-Clark of the symmetric control keeps its quads planar,
    /// not its vertex cones), and the last perturbation restores the contract bounds.
    #[test]
    fn measures_follow_the_levels() {
        let mut s = PqSceneStepper::from_spec(pq_scene_spec("conical-station").unwrap()).unwrap();
        // The control mesh follows principal lines of a surface of revolution: already PQ
        // and conical, so the first step subdivides.
        let control = s.metrics();
        assert_eq!(control.faces, 24);
        assert!(control.measures.max_planarity <= 1e-10);
        let mut after_subdivision = Vec::new();
        while !s.is_done() {
            let i = s.step().unwrap();
            assert_eq!(i.measures.max_planarity, max_planarity(s.mesh()));
            if i.phase == PqScenePhase::Subdivide {
                after_subdivision.push(
                    i.measures
                        .max_planarity
                        .max(i.measures.conical_residual.unwrap()),
                );
            }
        }
        assert_eq!(after_subdivision.len(), 2);
        assert!(
            after_subdivision.iter().all(|&p| p > 1e-6),
            "{after_subdivision:?}"
        );
        let last = s.metrics();
        assert_eq!(last.faces, 24 * 16);
        assert!(last.measures.max_planarity <= 1e-10);
        assert!(last.measures.conical_residual.unwrap() <= 1e-10);
        assert!(
            last.measures.circular_residual.is_none() && last.measures.max_determinant.is_none()
        );
        // Done is final: more steps change nothing.
        assert_eq!(s.step().unwrap(), last);
    }

    /// Doo-Sabin levels: a 3x3 quad grid gains the faces of the old vertices and edges, and
    /// the perturbation makes every level planar.
    #[test]
    fn doo_sabin_levels_are_planar() {
        let control = skew_quad_grid(3, 20.0);
        let mut s = PqSceneStepper::for_mesh(&control, MeshRule::DooSabin, 1, PqOptions::default())
            .unwrap();
        let mut faces = Vec::new();
        while !s.is_done() {
            let i = s.step().unwrap();
            if i.phase == PqScenePhase::Subdivide {
                faces.push(i.faces);
            }
        }
        // Doo-Sabin: a face per old face, edge and vertex (boundary ones included).
        assert_eq!(faces, vec![9 + 24 + 16]);
        let r = s.finish().unwrap();
        assert!(
            r.converged && r.measures.max_planarity <= 1e-10,
            "{}",
            r.measures.max_planarity
        );
    }

    /// Bad options are refused before any step, with the perturbation's error.
    #[test]
    fn bad_options_are_refused() {
        let options = PqOptions {
            closeness: f64::NAN,
            ..PqOptions::default()
        };
        let control = skew_quad_grid(2, 0.0);
        assert!(matches!(
            PqSceneStepper::for_mesh(&control, MeshRule::CatmullClark, 1, options),
            Err(PqSceneError::Pq(_))
        ));
        assert!(matches!(
            pq_scene_spec("nope"),
            Err(PqSceneError::UnknownScene(_))
        ));
    }
}
