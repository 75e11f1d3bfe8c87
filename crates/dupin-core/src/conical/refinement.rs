//! A PQ scene stepped level by level (conical paper, Sec. 2 and 3: subdivision and PQ
//! perturbation alternating, Figs. 7, 9, 14, 16, 17), for a viewer that watches the hierarchy
//! grow: control mesh -> perturbed -> subdivided -> perturbed -> ...
//!
//! Input: a scene name of [`crate::PQ_SCENES`] (or a control mesh / strip with its rule, level
//! count and [`PqOptions`]). One [`PqSceneStepper::step`] is one perturbation iteration
//! ([`PqPerturbation::step`]) or one subdivision (Catmull-Clark or Doo-Sabin for meshes, one
//! curve-rule round for strips). Output after every step: the current mesh, level, phase,
//! iteration count and the scene's measures; [`PqSceneStepper::finish`] gives the same
//! [`PqSceneResult`] as [`crate::pq_scene`].

use crate::circular::circular_residual;
use crate::conical::conical_residual;
use crate::developable_strip::{PqStrip, StripRule};
use crate::mesh::PolyMesh;
use crate::mesh_topology::MeshTopology;
use crate::planarity::max_planarity;
use crate::pq_perturbation::{PqMode, PqOptions, PqPerturbation, PqPhase};
use crate::pq_scenes::{
    PqSceneError, PqSceneResult, SceneSpec, scene_spec, singular_points_inside,
};
use crate::subdivision::{catmull_clark, doo_sabin};

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
    /// Contract `max_planarity` of the current mesh.
    pub max_planarity: f64,
    /// `conical_residual` (conical scenes).
    pub conical_residual: Option<f64>,
    /// `circular_residual` (circular scenes).
    pub circular_residual: Option<f64>,
    /// Largest determinant term (strip scenes).
    pub max_determinant: Option<f64>,
    /// Quads whose singular-curve point lies on the strip (strip scenes).
    pub singular_points_inside: Option<usize>,
}

/// The refinement a stepper applies.
#[derive(Debug, Clone)]
enum Target {
    Mesh(MeshRule),
    /// The current strip (the perturbation runs on its cut-open mesh).
    Strip {
        rule: StripRule,
        strip: PqStrip,
    },
}

/// A PQ scene that can be stepped and watched (see the module documentation).
pub struct PqSceneStepper {
    target: Target,
    options: PqOptions,
    levels: usize,
    level: usize,
    phase: PqScenePhase,
    /// The running perturbation; `None` once it finished (the next step subdivides or the
    /// run is done).
    perturbation: Option<PqPerturbation>,
    mesh: PolyMesh,
    /// Iterations of the finished perturbations.
    done_iterations: usize,
    /// Iterations of the running perturbation.
    running_iterations: usize,
    converged: bool,
}

impl PqSceneStepper {
    /// The named scene of [`crate::PQ_SCENES`], at its control mesh.
    pub fn new(name: &str) -> Result<Self, PqSceneError> {
        match scene_spec(name)? {
            SceneSpec::Mesh {
                control,
                levels,
                options,
            } => Self::for_mesh(&control, MeshRule::CatmullClark, levels, options),
            SceneSpec::Strip {
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
        })
    }

    /// Developable subdivision: perturb `strip` (with the determinant terms, glued across a
    /// closed or Möbius joint), then `rounds` times subdivide its polylines with `rule` and
    /// perturb, as [`crate::developable_subdivision`] does.
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

    /// Whether the run has finished.
    pub fn is_done(&self) -> bool {
        self.phase == PqScenePhase::Done
    }

    /// Perturbation iterations over all levels so far.
    pub fn iteration(&self) -> usize {
        self.done_iterations + self.running_iterations
    }

    /// One perturbation iteration or one subdivision (no-op once done); returns the state
    /// after it. A level whose mesh needs no perturbation (already within the tolerance)
    /// takes no step of its own.
    pub fn step(&mut self) -> Result<PqSceneStepInfo, PqSceneError> {
        self.settle();
        if self.phase == PqScenePhase::Done {
            return Ok(self.info());
        }
        if let Some(p) = self.perturbation.as_mut() {
            self.running_iterations = p.step().iteration;
            self.phase = PqScenePhase::Perturb;
            if !p.is_done() {
                let m = p.mesh().clone();
                self.show(m);
            }
            self.settle();
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
        Ok(self.info())
    }

    /// Ends a finished perturbation: its result becomes the current mesh, and after the last
    /// level the run is done.
    fn settle(&mut self) {
        if !self.perturbation.as_ref().is_some_and(|p| p.is_done()) {
            return;
        }
        let r = self
            .perturbation
            .take()
            .expect("a finished perturbation")
            .finish();
        self.done_iterations += r.iterations;
        self.running_iterations = 0;
        self.converged &= r.converged;
        self.show(r.mesh);
        if self.level == self.levels {
            self.phase = PqScenePhase::Done;
        }
    }

    /// Takes the positions of the perturbation's mesh (for strips, of the cut-open mesh).
    fn show(&mut self, perturbed: PolyMesh) {
        match &mut self.target {
            Target::Mesh(_) => self.mesh = perturbed,
            Target::Strip { strip, .. } => {
                *strip = strip.rebuild_from_cut(&perturbed.positions);
                self.mesh = strip.to_mesh();
            }
        }
    }

    /// The current state and its measures (computed on the current mesh).
    pub fn info(&self) -> PqSceneStepInfo {
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
            max_planarity: max_planarity(&self.mesh),
            conical_residual: conical,
            circular_residual: (self.options.mode == PqMode::Circular)
                .then(|| circular_residual(&self.mesh)),
            max_determinant: strip.map(|s| s.max_determinant()),
            singular_points_inside: strip.map(singular_points_inside),
        }
    }

    /// Runs to the end and returns the scene's result.
    pub fn finish(mut self) -> Result<PqSceneResult, PqSceneError> {
        while !self.is_done() {
            self.step()?;
        }
        let i = self.info();
        Ok(PqSceneResult {
            mesh: self.mesh,
            levels: self.levels,
            iterations: self.done_iterations,
            converged: self.converged,
            max_planarity: i.max_planarity,
            conical_residual: i.conical_residual,
            circular_residual: i.circular_residual,
            max_determinant: i.max_determinant,
            singular_points_inside: i.singular_points_inside,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pq_scenes::{PQ_SCENES, pq_scene};

    /// Every PQ scene stepped to the end gives exactly the one-shot `pq_scene` result, and the
    /// steps are the promised ones: the control mesh first, every step changes the state,
    /// each level is one subdivision followed by perturbation iterations, and the levels
    /// count up to the scene's.
    #[test]
    fn stepper_ends_at_the_one_shot_result() {
        for &name in PQ_SCENES {
            let mut s = PqSceneStepper::new(name).unwrap();
            assert_eq!(s.phase(), PqScenePhase::Control);
            assert_eq!((s.level(), s.iteration()), (0, 0));
            let mut prev = s.info();
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
            let one_shot = pq_scene(name).unwrap();
            assert_eq!(stepped, one_shot, "{name}");
        }
    }

    /// The measures of a step are those of the mesh on show: after a subdivision the mesh is
    /// far from conical again (Catmull-Clark of the symmetric control keeps its quads planar,
    /// not its vertex cones), and the last perturbation restores the contract bounds.
    #[test]
    fn measures_follow_the_levels() {
        let mut s = PqSceneStepper::new("conical-station").unwrap();
        // The control mesh follows principal lines of a surface of revolution: already PQ
        // and conical, so the first step subdivides.
        let control = s.info();
        assert_eq!(control.faces, 24);
        assert!(control.max_planarity <= 1e-10);
        let mut after_subdivision = Vec::new();
        while !s.is_done() {
            let i = s.step().unwrap();
            assert_eq!(i.max_planarity, max_planarity(s.mesh()));
            if i.phase == PqScenePhase::Subdivide {
                after_subdivision.push(i.max_planarity.max(i.conical_residual.unwrap()));
            }
        }
        assert_eq!(after_subdivision.len(), 2);
        assert!(
            after_subdivision.iter().all(|&p| p > 1e-6),
            "{after_subdivision:?}"
        );
        let last = s.info();
        assert_eq!(last.faces, 24 * 16);
        assert!(last.max_planarity <= 1e-10);
        assert!(last.conical_residual.unwrap() <= 1e-10);
        assert!(last.circular_residual.is_none() && last.max_determinant.is_none());
        // Done is final: more steps change nothing.
        assert_eq!(s.step().unwrap(), last);
    }

    /// Doo-Sabin levels: a 3x3 quad grid gains the faces of the old vertices and edges, and
    /// the perturbation makes every level planar.
    #[test]
    fn doo_sabin_levels_are_planar() {
        let control = crate::pq_scenes::skew_quad_grid(3, 20.0);
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
            r.converged && r.max_planarity <= 1e-10,
            "{}",
            r.max_planarity
        );
    }

    /// Bad options are refused before any step, with the perturbation's error.
    #[test]
    fn bad_options_are_refused() {
        let options = PqOptions {
            closeness: f64::NAN,
            ..PqOptions::default()
        };
        let control = crate::pq_scenes::skew_quad_grid(2, 0.0);
        assert!(matches!(
            PqSceneStepper::for_mesh(&control, MeshRule::CatmullClark, 1, options),
            Err(PqSceneError::Pq(_))
        ));
        assert!(matches!(
            PqSceneStepper::new("nope"),
            Err(PqSceneError::UnknownScene(_))
        ));
    }
}
