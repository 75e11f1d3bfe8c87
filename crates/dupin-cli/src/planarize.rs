//! `dupin planarize`: PQ / conical / circular perturbation of any polygon mesh (conical paper,
//! Sec. 2.2 and 5).

use crate::common::{CliError, read_mesh_file, write_report, write_text};
use clap::{Args, ValueEnum};
use dupin_core::Stepper;
use dupin_core::conical::{PqMode, PqOptions, PqPerturbation, Refinement};
use dupin_core::mesh::{flipped_faces, write_obj};
use serde_json::json;
use std::path::PathBuf;

/// Solver of the exact phase after the penalty iterations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum RefineArg {
    /// Gauss-Newton on the constraints (fast; default).
    GaussNewton,
    /// SQP on the KKT system (paper's eq. (3); slower on large meshes).
    Sqp,
}

/// Arguments of `dupin planarize`.
#[derive(Debug, Args)]
pub struct PlanarizeArgs {
    /// Input mesh: OBJ (any polygons), STL or glTF/GLB (triangles).
    #[arg(long)]
    pub input: PathBuf,
    /// Property to enforce besides planar faces: planar, conical (angle balance at interior
    /// valence-4 vertices) or circular (opposite angles of every quad sum to pi).
    #[arg(long, default_value = "planar")]
    pub mode: PqMode,
    /// Keep the boundary vertices fixed.
    #[arg(long)]
    pub fix_boundary: bool,
    /// Anchors: vertices that must not move, 1-based OBJ indices, comma separated.
    #[arg(long, value_delimiter = ',')]
    pub fix_vertices: Vec<usize>,
    /// Initial closeness weight (>= 0).
    #[arg(long, default_value_t = 0.01, allow_hyphen_values = true)]
    pub closeness: f64,
    /// Make a fair mesh rather than keep the design: the paper's fairness of the mesh itself
    /// (which also straightens boundaries and pulls corners in) and its step metric, as for
    /// the `pq` scenes. By default the design is kept: fairness smooths the move from the
    /// input and steps turn face planes rather than slide vertices.
    #[arg(long)]
    pub fair_mesh: bool,
    /// The most memory the sparse factorisation may take, in GB: a mesh whose factor needs
    /// more is refused (exit 2) before the factor is allocated.
    #[arg(long, default_value_t = 2.0, allow_hyphen_values = true)]
    pub max_memory: f64,
    /// Iteration cap.
    #[arg(long, default_value_t = 100)]
    pub max_iterations: usize,
    /// Target for max_planarity and the mode residual.
    #[arg(long, default_value_t = 1e-11, allow_hyphen_values = true)]
    pub tolerance: f64,
    /// Solver of the exact phase.
    #[arg(long, value_enum, default_value = "gauss-newton")]
    pub refinement: RefineArg,
    /// Output OBJ.
    #[arg(long)]
    pub out: PathBuf,
    /// JSON report file.
    #[arg(long)]
    pub report: Option<PathBuf>,
}

/// A size in GB as a person reads it (exponent form beyond everyday magnitudes).
fn gigabytes(v: f64) -> String {
    if (1e-3..1e6).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// Runs `dupin planarize`.
pub fn run(args: PlanarizeArgs) -> Result<(), CliError> {
    let mesh = read_mesh_file(&args.input)?;
    let mode = args.mode;
    let mut fixed_vertices = Vec::with_capacity(args.fix_vertices.len());
    for &i in &args.fix_vertices {
        if i == 0 || i > mesh.num_vertices() {
            return Err(CliError::Input(format!(
                "--fix-vertices: vertex {i} does not exist (1-based, the mesh has {} vertices)",
                mesh.num_vertices()
            )));
        }
        fixed_vertices.push(i - 1);
    }
    if !(args.max_memory.is_finite() && args.max_memory > 0.0) {
        return Err(CliError::Input(format!(
            "bad --max-memory {}: must be a positive number of GB",
            gigabytes(args.max_memory)
        )));
    }
    let options = PqOptions {
        mode,
        max_factor_bytes: (args.max_memory * 1e9).min(usize::MAX as f64).max(1.0) as usize,
        fixed_vertices,
        refinement: match args.refinement {
            RefineArg::GaussNewton => Refinement::GaussNewton,
            RefineArg::Sqp => Refinement::Sqp,
        },
        fix_boundary: args.fix_boundary,
        closeness: args.closeness,
        keep_design: !args.fair_mesh,
        max_iterations: args.max_iterations,
        tolerance: args.tolerance,
        ..PqOptions::default()
    };
    let start = std::time::Instant::now();
    let Ok(result) = PqPerturbation::new(&mesh, options)
        .map_err(|e| CliError::input("", e))?
        .finish();
    let seconds = start.elapsed().as_secs_f64();
    if result.refused {
        return Err(CliError::Input(format!(
            "{}; or raise --max-memory (now {} GB)",
            result.reason.as_deref().unwrap_or("the mesh is too large"),
            gigabytes(args.max_memory)
        )));
    }
    write_text(&args.out, &write_obj(&result.mesh))?;
    let mut report = json!({
        "vertices": result.mesh.num_vertices(),
        "faces": result.mesh.num_faces(),
        "max_planarity": result.max_planarity,
        "max_move": result.max_move,
        "max_normal_move": result.max_normal_move,
        "max_tangential_move": result.max_tangential_move,
        "iterations": result.iterations,
        "seconds": seconds,
        "converged": result.converged,
    });
    if let Some(c) = result.conical_residual {
        report["conical_residual"] = json!(c);
    }
    if let Some(c) = result.circular_residual {
        report["circular_residual"] = json!(c);
    }
    // Planar faces that turned over are a folded design, not a planarised one.
    let flipped = flipped_faces(&mesh, &result.mesh);
    report["flipped_faces"] = json!(flipped.len());
    let mut reason = result.reason.clone();
    if !flipped.is_empty() {
        report["converged"] = json!(false);
        let shown: Vec<String> = flipped
            .iter()
            .take(5)
            .map(|f| (f + 1).to_string())
            .collect();
        let folded = format!(
            "{} faces turned over (folded), e.g. faces {}; anchor the boundary or raise \
             --closeness",
            flipped.len(),
            shown.join(", ")
        );
        reason = Some(match reason {
            Some(r) => format!("{r}; {folded}"),
            None => folded,
        });
    }
    if let Some(r) = &reason {
        report["reason"] = json!(r);
    }
    write_report(args.report.as_deref(), &report)?;
    let mut line = format!(
        "planarize: {} faces, max_planarity {:.3e}, max_move {:.3e}, {} iterations, {:.3} s",
        result.mesh.num_faces(),
        result.max_planarity,
        result.max_move,
        result.iterations,
        seconds
    );
    if let Some(c) = result.conical_residual {
        line += &format!(", conical_residual {c:.3e}");
    }
    if let Some(c) = result.circular_residual {
        line += &format!(", circular_residual {c:.3e}");
    }
    let done = result.converged && flipped.is_empty();
    if !done {
        line += &format!(", NOT done: {}", reason.as_deref().unwrap_or("unknown"));
    }
    println!("{line}");
    if done {
        Ok(())
    } else {
        Err(CliError::Unmet(format!(
            "not done: {}",
            reason.as_deref().unwrap_or("unknown")
        )))
    }
}
