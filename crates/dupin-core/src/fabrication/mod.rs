//! From panels to what a fabricator cuts and a viewer shows: every planar face flattened into
//! its plane at true size, numbered and packed on sheets (SVG, DXF), the panel list (CSV), and
//! the panels in 3D (GLB), all in real units.
//!
//! | concept | file |
//! |---|---|
//! | panel schedule, sheet packing, SVG | `panel_schedule.rs` |
//! | cutting file: AutoCAD 2000 DXF in mm | `dxf.rs` |
//! | panel list: CSV | `schedule_csv.rs` |
//! | glTF 2.0 binary | `glb.rs` |
//! | length units | `units.rs` |

mod dxf;
mod glb;
mod panel_schedule;
mod schedule_csv;
mod units;

pub use dxf::{DEFAULT_SHEET_MM, DxfOptions, panel_dxf, schedule_dxf, schedule_mm};
pub use glb::{GlbLayer, panels_glb};
pub use panel_schedule::{
    FlatPanel, PanelSchedule, PanelScheduleError, SheetOptions, panel_schedule, panel_schedule_svg,
};
pub use schedule_csv::{BEAM_HEADER, CSV_HEADER, NODE_HEADER, panel_csv, support_csv};
pub use units::{LENGTH_UNITS, LengthUnit, UnknownUnit};
