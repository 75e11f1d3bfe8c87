//! Live editing of a panel mesh: drag a vertex and the PQ perturbation (conical paper,
//! Sec. 2.2) keeps every face planar (conical, circular) around it, the dragged vertex held
//! where the pointer put it.
//!
//! Input: a [`PqSceneStepper`] on a panel mesh, a vertex and its new position. Output: the
//! stepper restarted on its *edit base* (the result committed before the drag) with that
//! vertex moved and held as an anchor beside the options' anchors, stepped as before, one
//! perturbation iteration a step, at the current level (no further subdivision).
//!
//! Every move of one drag starts from the same base, so the result after a drag is a
//! function of the base, the vertex and its last position alone, not of how many steps ran
//! between pointer events: replaying the committed edits rebuilds a mesh bit for bit (the
//! page's undo). A move is made in stages of at most [`STAGE`] of the mean edge at the vertex,
//! each perturbed to the tolerance from the last (continuation): from a planar base one held
//! vertex jumping an edge length or more leaves the penalty method in a poor local minimum
//! (conical-station: not converged from 0.8 edge lengths on, measured), while a quarter edge
//! converges in 4-8 iterations.

use super::perturbation::PqPerturbation;
use super::refinement::{PqSceneError, PqScenePhase, PqSceneStepper, Target};
use crate::mesh::{MeshTopology, PolyMesh};
use crate::{Stepper, Vec3};

/// Largest move of one stage of a live edit, in mean edge lengths at the vertex.
pub const STAGE: f64 = 0.25;

/// Most stages of one edit (a longer move takes longer stages).
const MAX_STAGES: usize = 64;

/// The positions a vertex is held at, stage by stage, on its way from `from` to `to`, the
/// last (`to` exactly) first.
fn stages(mesh: &PolyMesh, vertex: usize, from: Vec3, to: Vec3) -> Vec<Vec3> {
    let edge = MeshTopology::new(mesh)
        .ok()
        .map(|t| {
            let nb = t.neighbors(vertex);
            nb.iter()
                .map(|&u| (mesh.positions[u as usize] - from).norm())
                .sum::<f64>()
                / nb.len().max(1) as f64
        })
        .filter(|e| *e > 0.0 && e.is_finite());
    let k = match edge {
        Some(e) => ((to - from).norm() / (STAGE * e)).ceil() as usize,
        None => 1,
    }
    .clamp(1, MAX_STAGES);
    (1..=k)
        .rev()
        .map(|i| {
            if i == k {
                to
            } else {
                from + (to - from) * (i as f64 / k as f64)
            }
        })
        .collect()
}

impl PqSceneStepper {
    /// Runs the current perturbation to its end and makes its result the base of the next
    /// edits (call it when a drag starts).
    pub fn commit(&mut self) -> Result<(), PqSceneError> {
        self.run_to_end()?;
        self.edit_base = Some(self.mesh.clone());
        Ok(())
    }

    /// Why the last live edit stopped short of where its vertex was dragged (a stage that
    /// did not reach the tolerance), or `None`.
    pub fn edit_shortfall(&self) -> Option<&str> {
        self.edit_shortfall.as_deref()
    }

    /// The anchored vertices: the options' and every edited one.
    pub fn anchors(&self) -> &[usize] {
        &self.options.fixed_vertices
    }

    /// Moves `vertex` of the edit base to `position`, holds it there from now on, and
    /// restarts the perturbation from that mesh (committing first when nothing was). Fails
    /// for a developable strip (edited through its polylines, not vertex by vertex), a vertex
    /// outside the mesh or a position that is not finite; the stepper is then unchanged.
    pub fn hold_vertex(&mut self, vertex: usize, position: Vec3) -> Result<(), PqSceneError> {
        if matches!(self.target, Target::Strip { .. }) {
            return Err(PqSceneError::Edit(
                "a developable strip is edited through its polylines, not vertex by vertex".into(),
            ));
        }
        if !position.iter().all(|c| c.is_finite()) {
            return Err(PqSceneError::Edit(format!(
                "the new position of vertex {vertex} is not finite"
            )));
        }
        if self.edit_base.is_none() {
            self.commit()?;
        }
        let base = self.edit_base.as_ref().expect("committed above");
        if vertex >= base.num_vertices() {
            return Err(PqSceneError::Edit(format!(
                "vertex {vertex} is not in the mesh ({} vertices)",
                base.num_vertices()
            )));
        }
        let mut path = stages(base, vertex, base.positions[vertex], position);
        let total = path.len();
        let first = path.pop().expect("at least one stage");
        let mut mesh = base.clone();
        mesh.positions[vertex] = first;
        let mut options = self.options.clone();
        if !options.fixed_vertices.contains(&vertex) {
            options.fixed_vertices.push(vertex);
            options.fixed_vertices.sort_unstable();
        }
        let perturbation = PqPerturbation::new(&mesh, options.clone())?;
        self.options = options;
        self.perturbation = Some(perturbation);
        self.mesh = mesh;
        self.edit_stages = Some((vertex, path, total));
        self.edit_shortfall = None;
        self.levels = self.level;
        self.phase = PqScenePhase::Perturb;
        self.running_iterations = 0;
        self.converged = true;
        Ok(())
    }

    /// Starts the next stage of the running live edit from the current mesh; false when
    /// there is none (the edit is finished).
    pub(super) fn next_edit_stage(&mut self) -> Result<bool, PqSceneError> {
        let Some((vertex, path, _)) = self.edit_stages.as_mut() else {
            return Ok(false);
        };
        let Some(next) = path.pop() else {
            self.edit_stages = None;
            return Ok(false);
        };
        let vertex = *vertex;
        let mut mesh = self.mesh.clone();
        mesh.positions[vertex] = next;
        self.perturbation = Some(PqPerturbation::new(&mesh, self.options.clone())?);
        self.mesh = mesh;
        Ok(true)
    }
}

#[cfg(test)]
mod tests {
    use crate::Stepper;
    use crate::mesh::max_planarity;
    use crate::scenes::pq_scene_stepper;

    /// The stages of a move: evenly spaced, the last exactly at the target, at most a
    /// [`super::STAGE`] of the mean edge apart.
    #[test]
    fn a_move_is_cut_into_quarter_edge_stages() {
        let grid: Vec<crate::Vec3> = (0..3)
            .flat_map(|y| (0..3).map(move |x| crate::Vec3::new(x as f64, y as f64, 0.0)))
            .collect();
        let mesh = crate::mesh::PolyMesh::quad_grid(grid, 2, 2).unwrap();
        let (from, to) = (mesh.positions[4], crate::Vec3::new(1.0, 1.0, 1.0));
        let path = super::stages(&mesh, 4, from, to);
        let z: Vec<f64> = path.iter().map(|p| p.z).collect();
        assert_eq!(z, vec![1.0, 0.75, 0.5, 0.25], "the last stage first");
        assert_eq!(path[0], to);
        // No move: one stage, at the target.
        assert_eq!(super::stages(&mesh, 4, from, from), vec![from]);
    }

    /// Dragging a vertex of `conical-station` (its 3 steps of one drag, then a second drag):
    /// every face planar to 1e-9 again, the dragged vertex exactly where it was put, the
    /// result independent of how many steps ran between moves, and replaying the committed
    /// edits rebuilds it bit for bit.
    #[test]
    fn a_dragged_vertex_is_held_and_the_mesh_replanarised() {
        let mut s = pq_scene_stepper("conical-station").unwrap();
        s.commit().unwrap();
        let base = s.mesh().clone();
        let v = base.num_vertices() / 2;
        let target = base.positions[v] + crate::Vec3::new(0.02, -0.01, 0.03);
        // Three pointer moves, a few steps after each, the last move at `target`.
        for (k, f) in [0.3, 0.7, 1.0].iter().enumerate() {
            s.hold_vertex(v, base.positions[v] + (target - base.positions[v]) * *f)
                .unwrap();
            for _ in 0..k {
                s.step().unwrap();
            }
        }
        s.run_to_end().unwrap();
        let dragged = s.mesh().clone();
        assert_eq!(dragged.positions[v], target, "the dragged vertex is held");
        assert!(
            max_planarity(&dragged) <= 1e-9,
            "{}",
            max_planarity(&dragged)
        );
        assert!(s.converged());
        assert!(s.anchors().contains(&v));

        // The same edit with no intermediate moves gives the same mesh, bit for bit.
        let mut replay = pq_scene_stepper("conical-station").unwrap();
        replay.hold_vertex(v, target).unwrap();
        replay.run_to_end().unwrap();
        assert_eq!(replay.mesh(), &dragged);

        // A second drag starts from the first one's result; the first vertex stays put.
        let w = v / 3;
        s.commit().unwrap();
        let second = s.mesh().positions[w] + crate::Vec3::new(0.0, 0.0, -0.02);
        s.hold_vertex(w, second).unwrap();
        s.run_to_end().unwrap();
        assert_eq!(s.mesh().positions[w], second);
        assert_eq!(s.mesh().positions[v], target);
        assert!(max_planarity(s.mesh()) <= 1e-9);
    }

    /// Moves of one and two edge lengths, which a single restart does not converge from
    /// (measured: not converged from 0.8 edge lengths on), converge in stages, the progress
    /// bound never exceeded.
    #[test]
    fn long_moves_converge_in_stages() {
        let mut s = pq_scene_stepper("conical-station").unwrap();
        s.commit().unwrap();
        let base = s.mesh().clone();
        for (v, edges) in [(166, 1.2), (100, 2.0)] {
            let target = base.positions[v] + crate::Vec3::new(0.0, 0.0, 0.18 * edges);
            let mut t = pq_scene_stepper("conical-station").unwrap();
            t.hold_vertex(v, target).unwrap();
            let bound = t.steps_left_at_most().unwrap();
            let mut steps = 0;
            while !t.is_done() {
                t.step().unwrap();
                steps += 1;
            }
            assert!(steps <= bound, "{steps} steps, bound {bound}");
            assert!(t.converged(), "vertex {v}, {edges} edges");
            assert_eq!(t.mesh().positions[v], target);
            assert!(max_planarity(t.mesh()) <= 1e-9);
        }
    }

    /// A drag the perturbation cannot follow (a vertex pulled ten edge lengths out of the
    /// surface) ends not converged, and says which of its stages stopped it.
    #[test]
    fn a_drag_too_far_says_so() {
        let mut s = pq_scene_stepper("conical-station").unwrap();
        s.commit().unwrap();
        let p = s.mesh().positions[166] + crate::Vec3::new(0.0, 0.0, 1.8);
        s.hold_vertex(166, p).unwrap();
        s.run_to_end().unwrap();
        assert!(!s.converged());
        let why = s.edit_shortfall().expect("a reason");
        assert!(
            why.contains("vertex 166") && why.contains("stage 10 of 40"),
            "{why}"
        );
        assert_ne!(s.mesh().positions[166], p);
        // The next drag starts afresh.
        s.hold_vertex(166, s.mesh().positions[166]).unwrap();
        assert!(s.edit_shortfall().is_none());
    }

    /// Edits that cannot be made are refused and leave the stepper as it was.
    #[test]
    fn bad_edits_are_refused() {
        let mut s = pq_scene_stepper("conical-station").unwrap();
        s.commit().unwrap();
        let before = s.mesh().clone();
        let n = before.num_vertices();
        let e = s.hold_vertex(n, crate::Vec3::zeros()).unwrap_err();
        assert!(e.to_string().contains("is not in the mesh"), "{e}");
        let e = s
            .hold_vertex(0, crate::Vec3::new(f64::NAN, 0.0, 0.0))
            .unwrap_err();
        assert!(e.to_string().contains("not finite"), "{e}");
        assert_eq!(s.mesh(), &before);
        assert!(s.is_done());
        let mut strip = pq_scene_stepper("developable-trefoil").unwrap();
        let e = strip.hold_vertex(0, crate::Vec3::zeros()).unwrap_err();
        assert!(e.to_string().contains("polylines"), "{e}");
    }
}
