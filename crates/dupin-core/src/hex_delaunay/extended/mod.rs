//! The extended mode (section 5): the rules that bring the angles into [43.8979°, 90°].
//!
//! | section | concept | file |
//! |---|---|---|
//! | 5.1, 5.2, 5.4 | classification by fins and occupancy, the extra refinement rules, centre relocations | `refinement.rs` |
//! | 5.4 | MOVED_CENTER_3 runs and MOVED_CENTER_4 tops: their vertices and triangles in the dual | `fin_vertices.rs` |
//! | 5.3 | local coarsening into blossoms (merges, section 3.2) | `coarsening.rs` |

mod coarsening;
mod fin_vertices;
mod refinement;

pub(super) use coarsening::coarsen;
pub(super) use fin_vertices::apply_fin_patches;
#[cfg(test)]
pub(super) use refinement::KEEP_FAILED_CHECKS_FROM;
pub(super) use refinement::{
    ExtendedState, Relocation, after_coarsening, extended_pass, relocated_centres,
    take_relocated_centres,
};
