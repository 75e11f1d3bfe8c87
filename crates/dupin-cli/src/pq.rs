//! `dupin pq`: the PQ scenes of the conical paper (subdivision with PQ / conical / circular
//! perturbation, developable strips).

use crate::common::{CliError, write_report, write_text};
use clap::Args;
use dupin_core::Stepper;
use dupin_core::conical::pq_scene_shortfall;
use dupin_core::mesh::write_obj;
use dupin_core::scenes::{PQ_SCENES, pq_scene_stepper};
use serde_json::json;
use std::path::PathBuf;

/// Arguments of `dupin pq`.
#[derive(Debug, Args)]
pub struct PqArgs {
    /// Scene name (see --list-scenes).
    #[arg(long, required_unless_present = "list_scenes")]
    pub scene: Option<String>,
    /// Print the scene names, one a line.
    #[arg(long)]
    pub list_scenes: bool,
    /// Output OBJ.
    #[arg(long, required_unless_present = "list_scenes")]
    pub out: Option<PathBuf>,
    /// JSON report file.
    #[arg(long)]
    pub report: Option<PathBuf>,
}

/// Runs `dupin pq`.
pub fn run(args: PqArgs) -> Result<(), CliError> {
    if args.list_scenes {
        for s in PQ_SCENES {
            println!("{s}");
        }
        return Ok(());
    }
    let name = args.scene.unwrap_or_default();
    let out = args
        .out
        .ok_or_else(|| CliError::Input("--out is required".into()))?;
    let start = std::time::Instant::now();
    let r = pq_scene_stepper(&name)
        .and_then(Stepper::finish)
        .map_err(|e| CliError::input("", e))?;
    let seconds = start.elapsed().as_secs_f64();
    write_text(&out, &write_obj(&r.mesh))?;
    let mut report = json!({
        "scene": name,
        "vertices": r.mesh.num_vertices(),
        "faces": r.mesh.num_faces(),
        "max_planarity": r.measures.max_planarity,
        "levels": r.levels,
        "iterations": r.iterations,
        "converged": r.converged,
        "seconds": seconds,
    });
    if let Some(reason) = pq_scene_shortfall(r.converged, &r.measures) {
        report["reason"] = json!(reason);
    }
    if let Some(c) = r.measures.conical_residual {
        report["conical_residual"] = json!(c);
    }
    if let Some(c) = r.measures.circular_residual {
        report["circular_residual"] = json!(c);
    }
    if let Some(d) = r.measures.max_determinant {
        report["max_determinant"] = json!(d);
    }
    if let Some(k) = r.measures.singular_points_inside {
        report["singular_points_inside"] = json!(k);
    }
    write_report(args.report.as_deref(), &report)?;
    println!(
        "pq {name}: {} faces, max_planarity {:.3e}, {} levels, {} iterations, {:.3} s{}",
        r.mesh.num_faces(),
        r.measures.max_planarity,
        r.levels,
        r.iterations,
        seconds,
        if r.converged { "" } else { ", NOT converged" }
    );
    if r.converged {
        Ok(())
    } else {
        Err(CliError::Unmet(format!(
            "scene {name} did not converge: max_planarity {:.3e} after {} iterations",
            r.measures.max_planarity, r.iterations
        )))
    }
}
