//! `dupin hexdelaunay`: hexagonal Delaunay triangulation of a point set (contract:
//! `--points pts.txt [--segments segs.txt] [--mode simple|extended] --out tri.obj
//! [--report r.json]`).

use crate::common::{CliError, read_text, write_report, write_text};
use clap::Args;
use dupin_core::Stepper;
use dupin_core::hex_delaunay::{HexDelaunayMode, HexDelaunayStepper, triangulation_quality};
use dupin_core::mesh::{parse_points, parse_segments, write_obj};
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `dupin hexdelaunay`.
#[derive(Args, Debug)]
pub struct HexDelaunayArgs {
    /// Points file: one `x y` per line, `#` comments and blank lines ignored.
    #[arg(long)]
    points: PathBuf,
    /// Segments file: one `i j` per line, 0-based indices into the points file.
    #[arg(long)]
    segments: Option<PathBuf>,
    /// Refinement mode: simple (section 4: angles in [30, 120] degrees) or extended (section
    /// 5: angles in [43.9, 90] degrees).
    #[arg(long, default_value = "simple")]
    mode: HexDelaunayMode,
    /// Output OBJ (triangles, z = 0).
    #[arg(long)]
    out: PathBuf,
    /// JSON report file.
    #[arg(long)]
    report: Option<PathBuf>,
    /// Most split hexagons the refinement may make (each adds about six triangles); a run
    /// that needs more is refused (exit 2).
    #[arg(long, default_value_t = dupin_core::hex_delaunay::MAX_SPLITS)]
    max_splits: usize,
}

/// Runs the command.
pub fn run(args: HexDelaunayArgs) -> Result<(), CliError> {
    let points_path = args.points.display().to_string();
    let points =
        parse_points(&read_text(&args.points)?).map_err(|e| CliError::input(&points_path, e))?;
    if points.is_empty() {
        return Err(CliError::Input(format!("{points_path}: no points")));
    }
    let segments = match &args.segments {
        Some(p) => parse_segments(&read_text(p)?)
            .map_err(|e| CliError::input(&p.display().to_string(), e))?,
        None => Vec::new(),
    };
    let mode = args.mode;
    let start = Instant::now();
    let tri = HexDelaunayStepper::new(&points, &segments, mode)
        .map(|s| s.with_max_splits(args.max_splits))
        .and_then(Stepper::finish)
        .map_err(|e| CliError::input("", e))?;
    let seconds = start.elapsed().as_secs_f64();
    let q = triangulation_quality(&tri.vertices, &tri.triangles);
    // With segments (section 7) the bounds hold only for triangles that do not meet one.
    let meets = tri.meets_segments();
    let away: Vec<[u32; 3]> = tri
        .triangles
        .iter()
        .zip(&meets)
        .filter(|&(_, &m)| !m)
        .map(|(t, _)| *t)
        .collect();
    let qa = triangulation_quality(&tri.vertices, &away);
    write_text(&args.out, &write_obj(&tri.to_mesh()))?;
    let mut report = serde_json::json!({
        "input_points": points.len(),
        "vertices": tri.vertices.len(),
        "triangles": tri.triangles.len(),
        "min_angle_deg": q.min_angle_deg,
        "max_angle_deg": q.max_angle_deg,
        "delaunay": q.is_delaunay(),
        "seconds": seconds,
    });
    if !segments.is_empty() {
        // Contract fields above; these extend the report only when segments were given.
        let extra = serde_json::json!({
            "segments": segments.len(),
            "segment_edges": tri.segment_edges.len(),
            "triangles_meeting_segments": tri.triangles.len() - away.len(),
            "away_min_angle_deg": qa.min_angle_deg,
            "away_max_angle_deg": qa.max_angle_deg,
            "away_delaunay": qa.is_delaunay(),
        });
        if let (Some(r), Some(e)) = (report.as_object_mut(), extra.as_object()) {
            r.extend(e.clone());
        }
    }
    write_report(args.report.as_deref(), &report)?;
    println!(
        "hexdelaunay: {} points -> {} vertices, {} triangles, angles {:.4}..{:.4} deg, delaunay {}, {:.3} s",
        points.len(),
        tri.vertices.len(),
        tri.triangles.len(),
        q.min_angle_deg,
        q.max_angle_deg,
        q.is_delaunay(),
        seconds
    );
    if !segments.is_empty() {
        println!(
            "hexdelaunay: {} segments as {} edges; {} triangles meet them; the others: angles {:.4}..{:.4} deg, delaunay {}",
            segments.len(),
            tri.segment_edges.len(),
            tri.triangles.len() - away.len(),
            qa.min_angle_deg,
            qa.max_angle_deg,
            qa.is_delaunay()
        );
    }
    Ok(())
}
