//! The one shape of every stepped computation of the core.

/// A computation that can be advanced one observable step at a time and watched: the P-Hex
/// pipeline ([`crate::phex::PhexPipeline`]), the PQ perturbation
/// ([`crate::conical::PqPerturbation`]), a PQ scene ([`crate::conical::PqSceneStepper`]) and the
/// hexagonal Delaunay refinement ([`crate::hex_delaunay::HexDelaunayStepper`]).
///
/// Input: whatever the stepper's constructor takes (a configuration, a mesh, points); its
/// errors surface there. Then:
///
/// - [`step`](Stepper::step) advances one observable step and returns the [`Metrics`] after it
///   (a no-op once done);
/// - [`is_done`](Stepper::is_done) tells whether the run has finished;
/// - [`metrics`](Stepper::metrics) gives the current state's measures without stepping;
/// - [`finish`](Stepper::finish) runs to the end and returns the [`Output`].
///
/// Every one-shot function of the core is its stepper run to the end:
/// [`crate::phex::phex_run`], [`crate::conical::pq_perturb`], [`crate::scenes::pq_scene`] and
/// [`crate::hex_delaunay::hex_delaunay`] each build their stepper and call `finish`.
///
/// [`Metrics`]: Stepper::Metrics
/// [`Output`]: Stepper::Output
pub trait Stepper {
    /// The measures after a step (what a viewer shows).
    type Metrics;
    /// What the finished run produces.
    type Output;
    /// Why a step failed ([`std::convert::Infallible`] where a step cannot fail).
    type Error;

    /// Advances one observable step and returns the metrics after it; once done, changes
    /// nothing.
    fn step(&mut self) -> Result<Self::Metrics, Self::Error>;

    /// Whether the run has finished.
    fn is_done(&self) -> bool;

    /// The current state's measures, without stepping.
    fn metrics(&self) -> Self::Metrics;

    /// An upper bound on the steps still to take before [`is_done`](Stepper::is_done) (0 once
    /// done), for a progress bar; None when the stepper cannot bound it. Iterative phases count
    /// their iteration cap, so a run that converges early finishes under the bound.
    fn steps_left_at_most(&self) -> Option<usize> {
        None
    }

    /// Steps until [`is_done`](Stepper::is_done) (a stepper may take a shortcut to the same
    /// final state).
    fn run_to_end(&mut self) -> Result<(), Self::Error> {
        while !self.is_done() {
            self.step()?;
        }
        Ok(())
    }

    /// Runs to the end and returns the output.
    fn finish(self) -> Result<Self::Output, Self::Error>
    where
        Self: Sized;
}
