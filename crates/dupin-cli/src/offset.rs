//! `dupin offset`: face offset of a conical mesh at distance D, optionally with its support
//! structure (conical paper, Sec. 4).

use crate::common::{CliError, read_text, write_report, write_text};
use clap::Args;
use dupin_core::conical::{conical_residual, face_normals, support_structure};
use dupin_core::mesh::{MeshTopology, max_planarity, parse_obj, write_obj};
use serde_json::json;
use std::path::PathBuf;

/// Arguments of `dupin offset`.
#[derive(Debug, Args)]
pub struct OffsetArgs {
    /// Input OBJ: a conical mesh (planar faces, conical interior valence-4 vertices).
    #[arg(long)]
    pub input: PathBuf,
    /// Offset distance along the face normals (negative: the other side).
    #[arg(long, allow_hyphen_values = true)]
    pub distance: f64,
    /// Output OBJ of the offset mesh.
    #[arg(long)]
    pub out: PathBuf,
    /// Output OBJ of the support structure (one quad per edge).
    #[arg(long)]
    pub support: Option<PathBuf>,
    /// JSON report file.
    #[arg(long)]
    pub report: Option<PathBuf>,
}

/// Runs `dupin offset`.
pub fn run(args: OffsetArgs) -> Result<(), CliError> {
    let text = read_text(&args.input)?;
    let mesh =
        parse_obj(&text).map_err(|e| CliError::input(&args.input.display().to_string(), e))?;
    if !args.distance.is_finite() {
        return Err(CliError::Input(format!(
            "--distance must be finite, got {}",
            args.distance
        )));
    }
    let start = std::time::Instant::now();
    let topo = MeshTopology::new(&mesh).map_err(|e| CliError::input("input mesh", e))?;
    let (beams, offset) =
        support_structure(&mesh, args.distance).map_err(|e| CliError::input("offset", e))?;
    // How far each offset face plane is from distance D (relative).
    let (n0, n1) = (face_normals(&mesh), face_normals(&offset));
    let mut distance_error: f64 = 0.0;
    for (f, face) in mesh.faces().enumerate() {
        let c0 = mesh.positions[face[0] as usize];
        for &v in face {
            let d = (offset.positions[v as usize] - c0).dot(&n0[f]);
            distance_error = distance_error.max((d - args.distance).abs());
        }
        distance_error = distance_error.max((n0[f] - n1[f]).norm() * args.distance.abs());
    }
    let seconds = start.elapsed().as_secs_f64();
    let planarity = max_planarity(&mesh);
    let conical = conical_residual(&mesh, &topo);
    let mut warnings = Vec::new();
    if planarity > 1e-8 {
        warnings.push(format!(
            "input faces are not planar (max_planarity {planarity:.3e}): run `dupin planarize --mode conical` first"
        ));
    }
    if conical > 1e-8 {
        warnings.push(format!(
            "input is not conical (conical_residual {conical:.3e}): offset faces are not at exact distance"
        ));
    }
    write_text(&args.out, &write_obj(&offset))?;
    if let Some(p) = &args.support {
        write_text(p, &write_obj(&beams))?;
    }
    let report = json!({
        "vertices": offset.num_vertices(),
        "faces": offset.num_faces(),
        "distance": args.distance,
        "max_planarity": max_planarity(&offset),
        "conical_residual": conical_residual(&offset, &topo),
        "max_distance_error": distance_error,
        "support_beams": beams.num_faces(),
        "support_max_planarity": max_planarity(&beams),
        "warnings": warnings,
        "seconds": seconds,
    });
    write_report(args.report.as_deref(), &report)?;
    for w in &warnings {
        eprintln!("warning: {w}");
    }
    println!(
        "offset: {} faces at distance {}, max distance error {:.3e}, {} support beams, {:.3} s",
        offset.num_faces(),
        args.distance,
        distance_error,
        beams.num_faces(),
        seconds
    );
    Ok(())
}
