//! The cutting file: every panel flattened into its plane at true size, in millimetres, packed
//! on sheets, as an AutoCAD 2000 DXF (ASCII) that CAD and CAM tools read.
//!
//! Layers: `PANELS` (one closed LWPOLYLINE per panel), `LABELS` (its number as TEXT at its
//! centroid), `DIMENSIONS` (each edge's length in mm as TEXT at the edge's midpoint, inside the
//! panel), `SHEETS` (the sheet outlines). Sheets lie side by side along +x. `$INSUNITS` is 4
//! (millimetres).
//!
//! Written by hand: the `dxf` crate (which the tests use to read the files back) pulls image
//! codecs, chrono and uuid into the browser build for what is a few hundred lines of group
//! codes here.

use super::panel_schedule::{PanelSchedule, PanelScheduleError, SheetOptions, panel_schedule};
use super::units::LengthUnit;
use crate::Vec2;
use crate::mesh::PolyMesh;
use std::fmt::Write as _;

/// Options of [`panel_dxf`] (lyon's builder style).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DxfOptions {
    /// The unit of the mesh's coordinates.
    pub unit: LengthUnit,
    /// Sheet width and height in mm.
    pub sheet_mm: (f64, f64),
    /// Space between panels and around the sheet border, in mm.
    pub gap_mm: f64,
}

/// The default sheet: 2500 x 1250 mm, a standard glass and aluminium sheet.
pub const DEFAULT_SHEET_MM: (f64, f64) = (2500.0, 1250.0);

impl Default for DxfOptions {
    fn default() -> Self {
        DxfOptions {
            unit: LengthUnit::Metre,
            sheet_mm: DEFAULT_SHEET_MM,
            gap_mm: 10.0,
        }
    }
}

impl DxfOptions {
    /// The same options for a mesh in `unit`.
    pub fn with_unit(mut self, unit: LengthUnit) -> Self {
        self.unit = unit;
        self
    }

    /// The same options with sheets of `width` x `height` mm.
    pub fn with_sheet_mm(mut self, width: f64, height: f64) -> Self {
        self.sheet_mm = (width, height);
        self
    }
}

/// The panels of `mesh` flattened at true size in mm and packed on sheets: the schedule the
/// DXF, SVG and CSV exports share.
pub fn schedule_mm(
    mesh: &PolyMesh,
    options: &DxfOptions,
) -> Result<PanelSchedule, PanelScheduleError> {
    let k = options.unit.to_mm();
    let mut mm = mesh.clone();
    for p in &mut mm.positions {
        *p *= k;
    }
    panel_schedule(
        &mm,
        &SheetOptions {
            sheet: Some(options.sheet_mm),
            gap: Some(options.gap_mm),
        },
    )
}

/// Group codes with entity handles counted from 0x100 (below are the tables' own).
struct Dxf {
    out: String,
    next_handle: u32,
}

impl Dxf {
    fn pair(&mut self, code: i32, value: impl std::fmt::Display) {
        let _ = write!(self.out, "{code:>3}\n{value}\n");
    }

    fn handle(&mut self) -> u32 {
        self.next_handle += 1;
        self.next_handle
    }

    /// An entity's common head: type, a new handle, owner (the model space block record),
    /// layer.
    fn entity(&mut self, kind: &str, layer: &str, subclass: &str) {
        let h = self.handle();
        self.entity_head(kind, &format!("{h:X}"), "1F", layer, subclass);
    }

    /// The head every entity shares, with its handle and owner given: the drawing's entities
    /// ([`Dxf::entity`]) and the BLOCK / ENDBLK markers, whose owner is their block record.
    fn entity_head(&mut self, kind: &str, handle: &str, owner: &str, layer: &str, subclass: &str) {
        self.pair(0, kind);
        self.pair(5, handle);
        self.pair(330, owner);
        self.pair(100, "AcDbEntity");
        self.pair(8, layer);
        self.pair(100, subclass);
    }

    /// A symbol-table record's common head: its type, handle, owner (the handle of the table it
    /// stands in), the two subclass markers and its name; the group codes that follow differ per
    /// table (flags, colour, line pattern, font). The tables' counterpart of [`Dxf::entity`].
    fn record(&mut self, kind: &str, handle: &str, owner: &str, subclass: &str, name: &str) {
        self.pair(0, kind);
        self.pair(5, handle);
        self.pair(330, owner);
        self.pair(100, "AcDbSymbolTableRecord");
        self.pair(100, subclass);
        self.pair(2, name);
    }

    fn text(&mut self, layer: &str, at: Vec2, height: f64, value: &str) {
        self.entity("TEXT", layer, "AcDbText");
        self.pair(10, at.x);
        self.pair(20, at.y);
        self.pair(30, 0.0);
        self.pair(40, height);
        self.pair(1, value);
        // Centred on the point: horizontal 1 (centre), vertical 2 (middle), at the 11/21 point.
        self.pair(72, 1);
        self.pair(11, at.x);
        self.pair(21, at.y);
        self.pair(31, 0.0);
        self.pair(100, "AcDbText");
        self.pair(73, 2);
    }

    fn polyline(&mut self, layer: &str, corners: &[Vec2]) {
        self.entity("LWPOLYLINE", layer, "AcDbPolyline");
        self.pair(90, corners.len());
        self.pair(70, 1);
        for c in corners {
            self.pair(10, c.x);
            self.pair(20, c.y);
        }
    }
}

const LAYERS: [(&str, i32); 4] = [
    ("PANELS", 7),
    ("LABELS", 1),
    ("DIMENSIONS", 8),
    ("SHEETS", 5),
];

/// Header, tables and blocks of an AutoCAD 2000 drawing in millimetres with the four layers.
fn head(d: &mut Dxf, extent: Vec2) {
    for (code, value) in [
        (0, "SECTION"),
        (2, "HEADER"),
        (9, "$ACADVER"),
        (1, "AC1015"),
    ] {
        d.pair(code, value);
    }
    d.pair(9, "$HANDSEED");
    d.pair(5, "FFFFF");
    d.pair(9, "$INSUNITS");
    d.pair(70, 4);
    d.pair(9, "$MEASUREMENT");
    d.pair(70, 1);
    d.pair(9, "$EXTMIN");
    for (c, v) in [(10, 0.0), (20, 0.0), (30, 0.0)] {
        d.pair(c, v);
    }
    d.pair(9, "$EXTMAX");
    for (c, v) in [(10, extent.x), (20, extent.y), (30, 0.0)] {
        d.pair(c, v);
    }
    d.pair(0, "ENDSEC");
    d.pair(0, "SECTION");
    d.pair(2, "TABLES");
    // Line types: CONTINUOUS only.
    table(d, "LTYPE", "5", 1);
    d.record("LTYPE", "14", "5", "AcDbLinetypeTableRecord", "CONTINUOUS");
    d.pair(70, 0);
    d.pair(3, "Solid line");
    d.pair(72, 65);
    d.pair(73, 0);
    d.pair(40, 0.0);
    d.pair(0, "ENDTAB");
    table(d, "LAYER", "2", LAYERS.len() + 1);
    for (k, (name, colour)) in [("0", 7)].into_iter().chain(LAYERS).enumerate() {
        let handle = format!("{:X}", 0x40 + k);
        d.record("LAYER", &handle, "2", "AcDbLayerTableRecord", name);
        d.pair(70, 0);
        d.pair(62, colour);
        d.pair(6, "CONTINUOUS");
    }
    d.pair(0, "ENDTAB");
    table(d, "STYLE", "3", 1);
    d.record("STYLE", "11", "3", "AcDbTextStyleTableRecord", "STANDARD");
    d.pair(70, 0);
    d.pair(40, 0.0);
    d.pair(41, 1.0);
    d.pair(50, 0.0);
    d.pair(71, 0);
    d.pair(42, 2.5);
    d.pair(3, "txt");
    d.pair(4, "");
    d.pair(0, "ENDTAB");
    table(d, "BLOCK_RECORD", "1", 2);
    for (handle, name) in [("1F", "*Model_Space"), ("1B", "*Paper_Space")] {
        d.record("BLOCK_RECORD", handle, "1", "AcDbBlockTableRecord", name);
    }
    d.pair(0, "ENDTAB");
    d.pair(0, "ENDSEC");
    d.pair(0, "SECTION");
    d.pair(2, "BLOCKS");
    for (block, end, owner, name) in [
        ("20", "21", "1F", "*Model_Space"),
        ("1C", "1D", "1B", "*Paper_Space"),
    ] {
        d.entity_head("BLOCK", block, owner, "0", "AcDbBlockBegin");
        d.pair(2, name);
        d.pair(70, 0);
        for (c, v) in [(10, 0.0), (20, 0.0), (30, 0.0)] {
            d.pair(c, v);
        }
        d.pair(3, name);
        d.pair(1, "");
        d.entity_head("ENDBLK", end, owner, "0", "AcDbBlockEnd");
    }
    d.pair(0, "ENDSEC");
}

fn table(d: &mut Dxf, name: &str, handle: &str, entries: usize) {
    d.pair(0, "TABLE");
    d.pair(2, name);
    d.pair(5, handle);
    d.pair(330, "0");
    d.pair(100, "AcDbSymbolTable");
    d.pair(70, entries);
}

/// The objects section every AutoCAD 2000 file ends with: the root dictionary.
fn objects(d: &mut Dxf) {
    d.pair(0, "SECTION");
    d.pair(2, "OBJECTS");
    d.pair(0, "DICTIONARY");
    d.pair(5, "C");
    d.pair(330, "0");
    d.pair(100, "AcDbDictionary");
    d.pair(281, 1);
    d.pair(0, "ENDSEC");
}

/// The DXF of `mesh`'s panels (see the module documentation): numbers count from 1 in face
/// order, edge lengths are the 3D lengths in mm to 0.1 mm.
pub fn panel_dxf(mesh: &PolyMesh, options: &DxfOptions) -> Result<String, PanelScheduleError> {
    let schedule = schedule_mm(mesh, options)?;
    Ok(schedule_dxf(&schedule, options.gap_mm))
}

/// The DXF of an already packed schedule in mm, sheets `gap_mm` apart.
pub fn schedule_dxf(schedule: &PanelSchedule, gap_mm: f64) -> String {
    let (sw, sh) = schedule.sheet_size;
    let pitch = sw + (4.0 * gap_mm).max(0.02 * sw);
    let sheets = schedule.sheets.max(1);
    let mut d = Dxf {
        out: String::with_capacity(600 * schedule.panels.len() + 8000),
        next_handle: 0x100,
    };
    head(&mut d, Vec2::new(pitch * sheets as f64, sh));
    d.pair(0, "SECTION");
    d.pair(2, "ENTITIES");
    for k in 0..schedule.sheets {
        let o = Vec2::new(k as f64 * pitch, 0.0);
        let corners = [
            o,
            o + Vec2::new(sw, 0.0),
            o + Vec2::new(sw, sh),
            o + Vec2::new(0.0, sh),
        ];
        d.polyline("SHEETS", &corners);
    }
    for p in &schedule.panels {
        let o = Vec2::new(p.sheet as f64 * pitch, 0.0);
        let corners: Vec<Vec2> = p.corners.iter().map(|c| c + o).collect();
        d.polyline("PANELS", &corners);
        let n = corners.len();
        let centroid = corners.iter().sum::<Vec2>() / n as f64;
        let shortest = p.edge_lengths.iter().copied().fold(f64::INFINITY, f64::min);
        let height = (0.12 * shortest).clamp(1.0, 50.0);
        d.text("LABELS", centroid, height, &(p.face + 1).to_string());
        for (k, len) in p.edge_lengths.iter().enumerate() {
            let mid = (corners[k] + corners[(k + 1) % n]) / 2.0;
            // Inside the panel, a fifth of the way to the centroid.
            let at = mid + (centroid - mid) * 0.2;
            d.text("DIMENSIONS", at, 0.6 * height, &format!("{len:.1}"));
        }
    }
    d.pair(0, "ENDSEC");
    objects(&mut d);
    d.pair(0, "EOF");
    d.out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Vec3;

    #[test]
    fn panels_are_closed_polylines_in_mm_with_labels() {
        // A 1 x 0.5 m rectangle and a triangle next to it.
        let p = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 0.5, 0.0),
            Vec3::new(0.0, 0.5, 0.0),
            Vec3::new(2.0, 0.25, 0.0),
        ];
        let m = PolyMesh::new(p, [vec![0u32, 1, 2, 3], vec![1, 4, 2]]).unwrap();
        let dxf = panel_dxf(&m, &DxfOptions::default()).unwrap();
        assert!(dxf.contains("$INSUNITS\n 70\n4\n"));
        assert_eq!(
            dxf.matches("\nLWPOLYLINE\n").count(),
            2 + 1,
            "two panels and one sheet"
        );
        assert!(dxf.contains("\n  1\n1000.0\n") && dxf.contains("\n  1\n500.0\n"));
        assert!(dxf.contains("\n  1\n2\n"), "panel 2 labelled");
        assert!(dxf.ends_with("  0\nEOF\n"));
        let e = panel_dxf(&m, &DxfOptions::default().with_sheet_mm(300.0, 300.0)).unwrap_err();
        assert!(matches!(e, PanelScheduleError::PanelTooLarge { .. }));
    }
}
