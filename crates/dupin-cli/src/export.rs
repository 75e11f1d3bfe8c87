//! `dupin export`: a panel mesh as fabrication files: DXF cutting sheets, a CSV panel list, an
//! SVG schedule or a GLB model, in real units.

use crate::common::{CliError, read_mesh_file};
use clap::{Args, ValueEnum};
use dupin_core::conical::offset_mesh;
use dupin_core::fabrication::{
    DEFAULT_SHEET_MM, DxfOptions, GlbLayer, LengthUnit, panel_csv, panel_dxf, panel_schedule_svg,
    panels_glb, schedule_mm, support_csv,
};
use std::path::PathBuf;

/// The file to write.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Format {
    /// AutoCAD 2000 DXF in mm: panels flattened and packed on sheets, numbers, edge lengths.
    Dxf,
    /// glTF 2.0 binary, in metres.
    Glb,
    /// One row per panel: area, perimeter, planarity, edge lengths.
    Csv,
    /// The sheets as SVG, lengths in mm.
    Svg,
}

/// Arguments of `dupin export`.
#[derive(Debug, Args)]
pub struct ExportArgs {
    /// Input panel mesh (OBJ, STL, glTF or GLB).
    #[arg(long)]
    pub input: PathBuf,
    /// Output format.
    #[arg(long, value_enum)]
    pub format: Format,
    /// Output file.
    #[arg(long)]
    pub out: PathBuf,
    /// Length unit of the input's coordinates: mm, cm, m, in or ft.
    #[arg(long, default_value = "m")]
    pub unit: LengthUnit,
    /// Sheet size in mm, WIDTHxHEIGHT (DXF and SVG).
    #[arg(long, value_parser = parse_sheet)]
    pub sheet: Option<(f64, f64)>,
    /// CSV of a conical mesh: also its support structure at this face distance (in the
    /// input's unit; conical paper, Sec. 4): node axes and beams, as two more tables.
    #[arg(long, allow_negative_numbers = true)]
    pub support: Option<f64>,
}

/// `2500x1250` -> (2500, 1250), both positive and finite.
fn parse_sheet(s: &str) -> Result<(f64, f64), String> {
    let bad = || format!("sheet `{s}`: expected WIDTHxHEIGHT in mm, e.g. 2500x1250");
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    let (w, h): (f64, f64) = (
        w.trim().parse().map_err(|_| bad())?,
        h.trim().parse().map_err(|_| bad())?,
    );
    if !(w.is_finite() && h.is_finite() && w > 0.0 && h > 0.0) {
        return Err(bad());
    }
    Ok((w, h))
}

/// Runs `dupin export`.
pub fn run(args: ExportArgs) -> Result<(), CliError> {
    if args.support.is_some() && args.format != Format::Csv {
        return Err(CliError::Input(
            "--support adds the node and beam tables of a CSV: use it with --format csv".into(),
        ));
    }
    if args.support == Some(0.0) {
        return Err(CliError::Input(
            "--support 0: the support structure needs a face distance other than 0".into(),
        ));
    }
    let mesh = read_mesh_file(&args.input)?;
    let (w, h) = args.sheet.unwrap_or(DEFAULT_SHEET_MM);
    let options = DxfOptions::default()
        .with_unit(args.unit)
        .with_sheet_mm(w, h);
    let start = std::time::Instant::now();
    let bytes = match args.format {
        Format::Dxf => panel_dxf(&mesh, &options)
            .map_err(|e| CliError::input("dxf", e))?
            .into_bytes(),
        Format::Svg => {
            let schedule = schedule_mm(&mesh, &options).map_err(|e| CliError::input("svg", e))?;
            panel_schedule_svg(&schedule, 1.0).into_bytes()
        }
        Format::Csv => {
            let mut csv = panel_csv(&mesh, args.unit, None);
            if let Some(d) = args.support {
                let offset = offset_mesh(&mesh, d).map_err(|e| CliError::input("support", e))?;
                csv += &support_csv(&mesh, &offset, args.unit)
                    .map_err(|e| CliError::input("support", e))?;
            }
            csv.into_bytes()
        }
        Format::Glb => panels_glb(
            &[GlbLayer {
                name: "panels",
                mesh: &mesh,
            }],
            args.unit,
        ),
    };
    let seconds = start.elapsed().as_secs_f64();
    std::fs::write(&args.out, &bytes).map_err(|source| CliError::Io {
        path: args.out.display().to_string(),
        source,
    })?;
    println!(
        "export: {} panels as {:?} ({} bytes, input in {}), {seconds:.3} s",
        mesh.num_faces(),
        args.format,
        bytes.len(),
        args.unit
    );
    Ok(())
}
