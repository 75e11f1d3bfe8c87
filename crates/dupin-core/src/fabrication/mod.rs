//! From panels to what a fabricator cuts: every planar face flattened into its plane at true
//! size, numbered, and packed on sheets.
//!
//! | concept | file |
//! |---|---|
//! | panel schedule, sheet packing, SVG | `panel_schedule.rs` |

mod panel_schedule;

pub use panel_schedule::{
    FlatPanel, PanelSchedule, PanelScheduleError, SheetOptions, panel_schedule, panel_schedule_svg,
};
