//! Following a reshaped design: the planarity optimisation of section 7 warm-started from the
//! P-Hex mesh of the design before the change.
//!
//! Method 2 triangulates along the design's parameter lines, which must be conjugate (section
//! 5.2). A designer who drags one control point of a translational roof bends those lines away
//! from conjugate near the point, and a new run on the reshaped surface comes out with
//! self-intersecting hexagons there: on the 20 x 15 m roof of `scenes::benchmark_meshes` at size
//! 0.3, moving control point (6, 4) up by 0.1 m gave 31 of 5 487 faces, by 0.3 m 60. The hexagons
//! of the design before the change are planar and simple; moved with the surface and optimised
//! again against the reshaped one, they stay simple: the same moves gave 0 invalid faces and
//! max planarity 8e-12 and 4e-11 after 4 and 8 iterations (the tests below hold this).
//!
//! Input: a pipeline with its hexagonal mesh (after its hexagon step) and the reshaped NURBS
//! surface (the same knots, degrees and net size: only control points moved). Output: a
//! pipeline on the reshaped surface in its optimisation phase, whose steps are Gauss-Newton
//! iterations, as [`Stepper::step`] documents.

use super::{PhexPipeline, build_surface};
use crate::Stepper;
use crate::Vec3;
use crate::mesh::SolverFrame;
use crate::phex::PhexError;
use crate::phex::pipeline::{PhexMetrics, PhexPhase};
use crate::phex::planarity_optimisation::{PlanarityOptimiser, PlanarityOptions};
use crate::surface::{NurbsSurface, Surface};
use std::sync::Arc;

/// [`PlanarityOptions::near_planar_start`] of a followed mesh: its faces were planar and simple
/// before the move. The roof's 10 203 hexagons (size 0.22) moved with control point (6, 4) up
/// 0.1 m start 1.4e-2 from planar; at 1e-2 they took the weighted steps.
const FOLLOW_NEAR_PLANAR: f64 = 1e-1;

/// [`PlanarityOptions::least_move_progress`] for a followed run: moved planar hexagons converge
/// by least moves even where the first ones divide their largest planarity by 1.5 only (see
/// there); a least move that gains less than a tenth hands over to the weighted steps.
const FOLLOW_LEAST_MOVE_PROGRESS: f64 = 0.9;

/// How planar a run (and each step on the way) must have ended for
/// [`PhexPipeline::follow_in_steps`] to follow from it. Looser than the optimiser's tolerance:
/// the roof's middle steps end at up to 2.5e-10, and the next step starts from them anyway; the
/// last step's result is judged by the run's own goals.
const FOLLOW_START_PLANARITY: f64 = 1e-6;

/// Most steps [`PhexPipeline::follow_in_steps`] splits a change into: each optimises the whole
/// mesh to its end, so this bounds a move's cost to that many optimisations; a larger move
/// ends where its last step gets to, and the report says how far that is.
pub const MAX_FOLLOW_STEPS: usize = 8;

impl PhexPipeline {
    /// This pipeline's P-Hex mesh on the reshaped NURBS `surface` (section 7, warm-started; see
    /// the module docs): every hexagon vertex moves by the change of the surface at its foot
    /// point's parameters, the triangulation is evaluated on the new surface at the same
    /// parameters, and the returned pipeline's steps optimise planarity against the new surface
    /// (its configuration's iteration cap and weights). The solver frame stays this pipeline's,
    /// so the mesh carries over unchanged in the solver's coordinates.
    ///
    /// Errors: [`PhexError::BadParameter`] when this pipeline is not on an imported NURBS
    /// surface, has no hexagonal mesh yet, or `surface` has other knots, degrees or net size;
    /// [`PhexError::Solver`] when the moved mesh is not finite.
    pub fn follow(&self, surface: NurbsSurface) -> Result<PhexPipeline, PhexError> {
        let (_, dual) = self.reshapable_to(&surface)?;
        let mut config = self.config.clone();
        config.nurbs = Some(Arc::new(surface));
        let solver = build_surface(&config, &self.frame)?;
        let dom = solver.domain();
        let feet = self.foot_parameters(dual);
        let mut dual = dual.clone();
        for (p, uv) in dual.mesh.positions.iter_mut().zip(&feet) {
            let (u, v) = dom.normalize(uv.x, uv.y);
            *p += solver.position(u, v) - self.surface.position(u, v);
        }
        dual.vertex_uv = feet.clone();
        let mut tri = self.tri.clone();
        for ((uv, p), n) in tri.uv.iter().zip(&mut tri.positions).zip(&mut tri.normals) {
            let (u, v) = dom.normalize(uv.x, uv.y);
            let d = solver.derivatives(u, v);
            *p = d.p;
            // A singular point keeps the normal it had (the triangulation is only drawn).
            if let Some(m) = d.pu.cross(&d.pv).try_normalize(1e-300) {
                *n = m;
            }
        }
        let user = match self.frame == SolverFrame::identity() {
            true => None,
            false => {
                let mut user_tri = tri.clone();
                for p in &mut user_tri.positions {
                    *p = self.frame.to_user(*p);
                }
                Some((build_surface(&config, &SolverFrame::identity())?, user_tri))
            }
        };
        // Planar, simple hexagons moved a little: least-move steps first (10 203 faces, control
        // point (6, 4) up 0.1 m: 0.39 s of optimisation natively against 2.1 s for the
        // weighted steps; they give way to those where they do not keep every face simple).
        let options = PlanarityOptions {
            near_planar_start: FOLLOW_NEAR_PLANAR,
            least_move_progress: FOLLOW_LEAST_MOVE_PROGRESS,
            ..config.planarity_options()
        };
        let mut opt = PlanarityOptimiser::new(&dual.mesh, Some(&feet), options)?;
        if let Some(before) = &self.optimiser {
            opt.continue_least_moves_from(before, &dual.mesh);
        }
        let phase = if config.optimize && !opt.is_done() {
            PhexPhase::Optimisation
        } else {
            PhexPhase::Done
        };
        let metrics = PhexMetrics {
            phase,
            layer: tri.layers.len(),
            iteration: 0,
            faces: dual.mesh.num_faces(),
            vertices: dual.mesh.num_vertices(),
            max_planarity: opt.max_planarity(),
            invalid_faces: opt.invalid_faces(),
        };
        Ok(PhexPipeline {
            surface: solver,
            frame: self.frame,
            user,
            config,
            shown: tri.layers.len(),
            tri,
            layer_triangles: self.layer_triangles.clone(),
            dual: Some(dual),
            optimiser: Some(opt),
            phase,
            metrics,
        })
    }

    /// [`PhexPipeline::follow`] in steps small enough to follow: the control points move in
    /// `k` equal steps, `k` the largest control-point move over the mean hexagon edge, rounded
    /// up (1 to [`MAX_FOLLOW_STEPS`]); every step but the last is optimised to its end. The
    /// last one is returned before its first step. The steps depend only on this pipeline and
    /// `surface`, so a design reshaped in one move and one reshaped by a drag that ends at the
    /// same net follow to the same mesh from the same start.
    ///
    /// Measured on the roof of the module docs at size 0.3, control point (6, 4) up by 1 m: in
    /// one step the optimisation ended at max planarity 7e-2 with 10 invalid faces; in four
    /// equal steps each ended at or below 2.5e-10 with none, as the steps chosen here do
    /// (`a_large_move_is_followed_in_steps_the_same_from_any_start_path`).
    ///
    /// Following keeps valid panels valid; it cannot mend invalid ones. So this run must have
    /// ended with every face simple and planar to 1e-6, and so must every step on the way;
    /// otherwise [`PhexError::NotFollowed`] comes back at once, and a new run on `surface`
    /// serves as well. (A 3 x 3 dome whose run ends with 158 self-intersecting faces of 2 499
    /// spent 2-3 s a step at the iteration cap, 8 steps a move, and ended no better.)
    ///
    /// Errors: those of [`PhexPipeline::follow`] and of the optimisation steps;
    /// [`PhexError::NotFollowed`] as above.
    pub fn follow_in_steps(&self, surface: NurbsSurface) -> Result<PhexPipeline, PhexError> {
        let (old, dual) = self.reshapable_to(&surface)?;
        self.followable("the run")?;
        let (from, to) = (old.control_points(), surface.control_points());
        let largest = from
            .iter()
            .zip(to)
            .map(|(a, b)| (Vec3::from(*a) - Vec3::from(*b)).norm())
            .fold(0.0, f64::max);
        let edge = self.to_user(dual.mesh.clone()).mean_edge();
        let k = (largest / edge).ceil();
        let k = if k.is_finite() {
            k.clamp(1.0, MAX_FOLLOW_STEPS as f64) as usize
        } else {
            1
        };
        let mut current: Option<PhexPipeline> = None;
        for step in 1..k {
            let t = step as f64 / k as f64;
            let mut s = old.clone();
            for (i, (a, b)) in from.iter().zip(to).enumerate() {
                if a != b {
                    let (a, b) = (Vec3::from(*a), Vec3::from(*b));
                    s.set_control_point(i, a + (b - a) * t)
                        .map_err(|e| PhexError::BadParameter(format!("{e}")))?;
                }
            }
            let mut next = current.as_ref().unwrap_or(self).follow(s)?;
            next.run_to_end()?;
            next.followable(&format!("step {step} of {k}"))?;
            current = Some(next);
        }
        current.as_ref().unwrap_or(self).follow(surface)
    }

    /// This run's NURBS surface and hexagonal mesh when `surface` is a reshape of the surface
    /// (the same degrees, domain and net size); [`PhexPipeline::follow`]'s errors otherwise.
    fn reshapable_to(
        &self,
        surface: &NurbsSurface,
    ) -> Result<(&NurbsSurface, &super::DualMesh), PhexError> {
        let Some(old) = self.config.nurbs.as_deref() else {
            return Err(PhexError::BadParameter(
                "only a run on an imported NURBS surface follows a reshaped surface".into(),
            ));
        };
        let Some(dual) = &self.dual else {
            return Err(PhexError::BadParameter(
                "the run has no hexagonal mesh to follow the surface with yet".into(),
            ));
        };
        if old.degrees() != surface.degrees()
            || old.control_net_size() != surface.control_net_size()
            || old.domain() != surface.domain()
        {
            return Err(PhexError::BadParameter(
                "a reshaped surface must keep the knots, degrees and net size: only control \
                 points move"
                    .into(),
            ));
        }
        Ok((old, dual))
    }

    /// Ok when this run has ended with every face simple and planar to
    /// [`FOLLOW_START_PLANARITY`]; [`PhexError::NotFollowed`] naming `what` and its shortfall
    /// otherwise.
    fn followable(&self, what: &str) -> Result<(), PhexError> {
        let m = self.metrics();
        let tolerance = FOLLOW_START_PLANARITY;
        let shortfall = if m.phase != PhexPhase::Done {
            Some("has not ended".to_string())
        } else if m.invalid_faces > 0 {
            Some(format!("has {} self-intersecting faces", m.invalid_faces))
        } else if !(m.max_planarity <= tolerance) {
            Some(format!(
                "ended at max planarity {:.1e}, beyond {tolerance:.0e}",
                m.max_planarity
            ))
        } else {
            None
        };
        match shortfall {
            Some(s) => Err(PhexError::NotFollowed(format!("{what} {s}"))),
            None => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::max_planarity;
    use crate::phex::{PhexConfig, count_invalid_faces};
    use crate::scenes::benchmark_meshes::nurbs_roof;
    use crate::surface::NurbsDefinition;

    fn translational_roof_nurbs() -> NurbsSurface {
        NurbsSurface::try_from(nurbs_roof()).unwrap()
    }

    /// The benchmark roof with control point (i, j) raised by `dz`.
    fn raised(i: usize, j: usize, dz: f64) -> NurbsSurface {
        let mut s = translational_roof_nurbs();
        let nv = s.control_net_size().1;
        let p = Vec3::from(s.control_points()[i * nv + j]) + Vec3::new(0.0, 0.0, dz);
        s.set_control_point(i * nv + j, p).unwrap();
        s
    }

    fn finished(surface: NurbsSurface, size: f64) -> PhexPipeline {
        let mut p = PhexPipeline::new(PhexConfig::for_nurbs("roof", surface, Some(size))).unwrap();
        p.run_to_end().unwrap();
        p
    }

    #[test]
    fn a_raised_control_point_is_followed_with_planar_simple_hexagons() {
        let start = finished(translational_roof_nurbs(), 0.8);
        assert_eq!(count_invalid_faces(&start.mesh()), 0);
        for dz in [0.1, 0.3, -0.3] {
            // A new run on the reshaped roof has self-intersecting hexagons near the point ...
            let fresh = finished(raised(6, 4, dz), 0.8);
            assert!(count_invalid_faces(&fresh.mesh()) > 0, "dz {dz}");
            // ... the followed mesh has none, and its faces are planar.
            let mut followed = start.follow_in_steps(raised(6, 4, dz)).unwrap();
            assert_eq!(followed.metrics().phase, PhexPhase::Optimisation);
            followed.run_to_end().unwrap();
            let mesh = followed.mesh();
            assert_eq!(mesh.num_faces(), start.mesh().num_faces());
            assert_eq!(count_invalid_faces(&mesh), 0, "dz {dz}");
            assert!(
                max_planarity(&mesh) <= 1e-9,
                "dz {dz}: {}",
                max_planarity(&mesh)
            );
            // Bending planar hexagons over the new bump costs distance to the design (measured:
            // 0.031 and 0.080 m at +0.1 and +0.3 m, the start 0.031 m): reported, and bounded.
            let (near, before) = (
                followed.report().unwrap().max_surface_distance,
                start.report().unwrap().max_surface_distance,
            );
            assert!(near <= 3.0 * before, "dz {dz}: {near} vs {before}");
            let at = |s: &dyn Surface| s.position(5.0, 3.0);
            assert_eq!(at(followed.surface()), at(&raised(6, 4, dz)));
        }
    }

    /// A drag, each position followed from the finished run before it: the moved hexagons,
    /// planar before, converge by least moves alone. Measured on the 10k roof (size 0.22):
    /// straight up, the second position's first least move divided the planarity by 2.6 only;
    /// on the page's oblique path below, 9.9 then 1.5 and 1.8. Each time quadratic convergence
    /// followed (to 1e-14 in five least moves), where the weighted steps the optimiser handed
    /// over to at a 1/4 or 1/2 bar took 4-6 times as long and ended as far from the surface
    /// (0.0265 against 0.0262 m at +0.176 m).
    #[test]
    fn a_drag_is_followed_by_least_moves() {
        let mut run = finished(translational_roof_nurbs(), 0.22);
        let before = run.report().unwrap().max_surface_distance;
        let check = |next: &mut PhexPipeline, what: &str| {
            next.run_to_end().unwrap();
            let mesh = next.mesh();
            assert_eq!(count_invalid_faces(&mesh), 0, "{what}");
            assert!(
                max_planarity(&mesh) <= 1e-10,
                "{what}: {}",
                max_planarity(&mesh)
            );
            let opt = next.optimiser().unwrap();
            assert!(
                opt.least_moves_only(),
                "{what}: {} iterations",
                opt.iteration()
            );
            next.report().unwrap().max_surface_distance
        };
        for dz in [0.088, 0.176, 0.264] {
            let mut next = run.follow_in_steps(raised(6, 4, dz)).unwrap();
            // Bending planar hexagons over the bump costs distance to the design (measured:
            // 0.014, 0.026, 0.038 m), reported and bounded.
            let near = check(&mut next, &format!("up {dz}"));
            assert!(near <= before + 0.2 * dz, "dz {dz}: {near} vs {before}");
            run = next;
        }
        // The page's quick drag of control point (6, 4) 8 px up in the default view: a first
        // position, then the release 0.34 m on, which follows in three equal steps.
        let moved = |d: [f64; 3]| {
            let mut s = translational_roof_nurbs();
            let i = 6 * s.control_net_size().1 + 4;
            let p = Vec3::from(s.control_points()[i]) + Vec3::from(d);
            s.set_control_point(i, p).unwrap();
            s
        };
        let (first, last) = (
            Vec3::new(-0.0335, 0.0425, 0.0800),
            Vec3::new(-0.1522, 0.1926, 0.3626),
        );
        let mut run = finished(translational_roof_nurbs(), 0.22);
        for k in 0..=3 {
            let d = first + (last - first) * (k as f64 / 3.0);
            let mut next = run.follow(moved(d.into())).unwrap();
            check(&mut next, &format!("oblique step {k}"));
            // Chord steps on the factorisation of the run before: one new factorisation a
            // position (measured: 6-7 least moves, 1 factorisation; five of each without).
            let opt = next.optimiser().unwrap();
            assert!(
                opt.factorizations() <= 2,
                "oblique step {k}: {} factorisations in {} least moves",
                opt.factorizations(),
                opt.iteration()
            );
            run = next;
        }
    }

    #[test]
    fn a_large_move_is_followed_in_steps_the_same_from_any_start_path() {
        let start = finished(translational_roof_nurbs(), 0.3);
        // In one step the optimisation cannot untangle what the move folds ...
        let mut jump = start.follow(raised(6, 4, 1.0)).unwrap();
        jump.run_to_end().unwrap();
        assert!(count_invalid_faces(&jump.mesh()) > 0);
        // ... in steps of at most a hexagon edge of control-point travel it keeps them simple.
        let mut once = start.follow_in_steps(raised(6, 4, 1.0)).unwrap();
        once.run_to_end().unwrap();
        let mesh = once.mesh();
        assert_eq!(count_invalid_faces(&mesh), 0);
        assert!(max_planarity(&mesh) <= 1e-9, "{}", max_planarity(&mesh));
        // Deterministic: the same start and surface give the same mesh bit for bit.
        let mut again = start.follow_in_steps(raised(6, 4, 1.0)).unwrap();
        again.run_to_end().unwrap();
        assert_eq!(again.mesh(), mesh);
    }

    #[test]
    fn a_run_with_self_intersecting_faces_is_not_followed() {
        // A new run on a reshaped roof has invalid faces; following would carry them along at
        // the cost of full optimisations, so it is refused at once, naming them.
        let invalid = finished(raised(6, 4, 0.3), 0.8);
        let n = count_invalid_faces(&invalid.mesh());
        assert!(n > 0);
        let e = invalid.follow_in_steps(raised(6, 4, 0.4)).err().unwrap();
        assert!(matches!(e, PhexError::NotFollowed(_)), "{e}");
        assert!(
            format!("{e}").contains(&format!("the run has {n} self-intersecting faces")),
            "{e}"
        );
        // An unfinished run neither: one with no hexagons yet, or still optimising.
        let mut fresh = PhexPipeline::new(PhexConfig::for_nurbs(
            "roof",
            translational_roof_nurbs(),
            Some(0.8),
        ))
        .unwrap();
        let e = fresh.follow_in_steps(raised(6, 4, 0.1)).err().unwrap();
        assert!(format!("{e}").contains("no hexagonal mesh"), "{e}");
        while fresh.metrics().phase != PhexPhase::Optimisation {
            fresh.step().unwrap();
        }
        let e = fresh.follow_in_steps(raised(6, 4, 0.1)).err().unwrap();
        assert!(format!("{e}").contains("the run has not ended"), "{e}");
    }

    #[test]
    fn only_a_finished_nurbs_run_with_the_same_net_follows() {
        let mut p = PhexPipeline::new(PhexConfig::for_nurbs(
            "roof",
            translational_roof_nurbs(),
            Some(0.8),
        ))
        .unwrap();
        let e = p.follow(raised(6, 4, 0.1)).err().unwrap();
        assert!(format!("{e}").contains("no hexagonal mesh"), "{e}");
        p.run_to_end().unwrap();
        let other = NurbsSurface::try_from(NurbsDefinition {
            degree_u: 1,
            degree_v: 1,
            knots_u: vec![0.0, 0.0, 1.0, 1.0],
            knots_v: vec![0.0, 0.0, 1.0, 1.0],
            control_points: vec![
                vec![[0.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
                vec![[1.0, 0.0, 0.0], [1.0, 1.0, 0.0]],
            ],
            weights: None,
            unit: None,
        })
        .unwrap();
        let e = p.follow(other).err().unwrap();
        assert!(format!("{e}").contains("only control points move"), "{e}");
        let library = PhexPipeline::new(PhexConfig::for_surface(
            "torus",
            &[],
            crate::phex::TriangulationMethod::Prescribed,
            None,
        ))
        .unwrap();
        let e = library.follow(raised(6, 4, 0.1)).err().unwrap();
        assert!(format!("{e}").contains("imported NURBS"), "{e}");
    }
}
