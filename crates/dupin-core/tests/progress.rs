//! `Stepper::steps_left_at_most` is a true upper bound a progress bar can rely on: on every
//! scene of both papers it falls by at least one each step, never under the steps really left,
//! and is 0 once done.
#![cfg(not(target_arch = "wasm32"))]

use dupin_core::Stepper;
use dupin_core::phex::PhexPipeline;
use dupin_core::scenes::{PHEX_SCENES, PQ_SCENES, phex_scene, pq_scene_stepper};

/// Steps `s` to the end, checking the bound before and after every step; returns (steps taken,
/// bound at the start).
fn check<S: Stepper>(name: &str, mut s: S) -> (usize, usize)
where
    S::Error: std::fmt::Debug,
{
    let start = s
        .steps_left_at_most()
        .expect("the scene's stepper bounds its steps");
    let mut taken = 0;
    while !s.is_done() {
        let before = s.steps_left_at_most().unwrap();
        assert!(
            before >= 1,
            "{name}: bound 0 at step {taken} before the end"
        );
        s.step().unwrap();
        taken += 1;
        let after = s.steps_left_at_most().unwrap();
        assert!(
            after < before,
            "{name}: bound {before} -> {after} at step {taken}"
        );
        assert!(
            taken <= start,
            "{name}: {taken} steps under a bound of {start}"
        );
    }
    assert_eq!(s.steps_left_at_most(), Some(0), "{name}: done");
    (taken, start)
}

#[test]
fn phex_scenes_never_take_more_steps_than_their_bound() {
    for name in PHEX_SCENES {
        let scene = phex_scene(name).unwrap();
        let (taken, bound) = check(name, PhexPipeline::new(scene.config).unwrap());
        assert!(taken >= 2, "{name}: {taken} steps");
        eprintln!("{name}: {taken} steps, bound {bound}");
    }
}

#[test]
fn pq_scenes_never_take_more_steps_than_their_bound() {
    for name in PQ_SCENES {
        let (taken, bound) = check(name, pq_scene_stepper(name).unwrap());
        eprintln!("{name}: {taken} steps, bound {bound}");
    }
}
