//! `dupin phex`: P-Hex meshes from a scene or a library surface (P-Hex paper, sections 5-7).

use crate::common::read_mesh_file;
use crate::common::{CliError, write_report, write_text};
use clap::Args;
use dupin_core::Stepper;
use dupin_core::mesh::write_obj;
use dupin_core::phex::{PhexConfig, PhexError, PhexGoals, PhexPipeline, TriangulationMethod};
use dupin_core::scenes::{PHEX_SCENES, phex_scene};
use dupin_core::surface::parse_assignment;
use dupin_core::surface::{MeshFitOptions, MeshSurface, NurbsSurface, fit_mesh_surface};
use serde_json::json;
use std::path::{Path, PathBuf};

/// Arguments of `dupin phex`.
#[derive(Debug, Args)]
pub struct PhexArgs {
    /// Scene name (see --list-scenes).
    #[arg(long, conflicts_with = "surface")]
    pub scene: Option<String>,
    /// Library surface name (see `dupin surface-info --list`).
    #[arg(long, conflicts_with = "input")]
    pub surface: Option<String>,
    /// A design to panel: a NURBS surface as JSON (docs/nurbs-json.md), or a triangle mesh of a
    /// smooth disk- or cylinder-like surface (OBJ, STL, glTF/GLB) that is fitted first (a
    /// cylinder cut open along a seam); --size is in the file's unit.
    #[arg(long, conflicts_with = "scene")]
    pub input: Option<PathBuf>,
    /// Surface parameter KEY=VALUE (repeatable).
    #[arg(long = "set")]
    pub set: Vec<String>,
    /// Triangulation method: progressive (method 1) or prescribed (method 2).
    #[arg(long)]
    pub method: Option<TriangulationMethod>,
    /// Target edge length of the base curve.
    #[arg(long)]
    pub size: Option<f64>,
    /// Largest number of Gauss-Newton iterations.
    #[arg(long)]
    pub iterations: Option<usize>,
    /// Skip the planarity optimisation.
    #[arg(long)]
    pub no_optimize: bool,
    /// Extension: method 2 along a user-chosen first direction field at DEG degrees from the
    /// first principal direction (the u direction at umbilics) and its conjugate field.
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    pub field_angle: Option<f64>,
    /// Extension: no faces at boundary vertices of the triangulation (closed stars only).
    #[arg(long)]
    pub no_boundary_faces: bool,
    /// Largest number of P-Hex faces (default 100000): a run that would make more is refused
    /// while its triangulation is built.
    #[arg(long)]
    pub max_faces: Option<usize>,
    /// Extension: panel --input, a NURBS design reshaped from ORIGINAL (a NURBS JSON with the
    /// same knots, degrees and net: only control points moved), by following ORIGINAL's
    /// panels, as the page does when a control point is dragged: ORIGINAL is panelled with the
    /// same options, its hexagons moved with the reshaped surface and optimised again, in steps
    /// of at most a hexagon edge of control-point travel. A new run on a reshaped design can
    /// fold hexagons where the move bent the parameter lines away from conjugate. Where
    /// ORIGINAL's panels cannot be followed (its run ends with invalid faces), --input is
    /// panelled afresh, with a note.
    #[arg(long, value_name = "ORIGINAL", requires = "input")]
    pub follow: Option<PathBuf>,
    /// Print the scene names, one a line.
    #[arg(long)]
    pub list_scenes: bool,
    /// Output OBJ.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// JSON report file.
    #[arg(long)]
    pub report: Option<PathBuf>,
}

/// Runs `dupin phex`.
pub fn run(args: PhexArgs) -> Result<(), CliError> {
    if args.list_scenes {
        for s in PHEX_SCENES {
            println!("{s}");
        }
        return Ok(());
    }
    let out = args
        .out
        .clone()
        .ok_or_else(|| CliError::Input("--out is required".into()))?;
    let method = args.method;
    // A scene made to show invalid faces (Fig. 11's hyperboloid) has them by design.
    let mut expect_valid = true;
    let mut fitted = None;
    let mut config = match (&args.scene, &args.surface) {
        _ if args.input.is_some() => {
            if !args.set.is_empty() {
                return Err(CliError::Input(
                    "--set applies to --surface, not to --input".into(),
                ));
            }
            let path = args.input.as_deref().unwrap_or(Path::new(""));
            let (surface, mesh) = read_design_surface(path)?;
            let label = path.display().to_string();
            // A fitted surface's u and v are ours: lay the layers across its parabolic curves.
            let config = if mesh.is_some() {
                PhexConfig::for_fitted_mesh(&label, surface, None)
            } else {
                PhexConfig::for_nurbs(&label, surface, None)
            };
            fitted = mesh;
            config
        }
        (Some(name), None) => {
            if !args.set.is_empty() {
                return Err(CliError::Input(
                    "--set applies to --surface, not to --scene".into(),
                ));
            }
            let scene = phex_scene(name).map_err(|e| CliError::input("", e))?;
            expect_valid = scene.expect_valid;
            scene.config
        }
        (None, Some(name)) => {
            let mut params = vec![];
            for s in &args.set {
                let (k, v) = parse_assignment(s).map_err(|e| CliError::input("--set", e))?;
                params.push((k, v));
            }
            PhexConfig::for_surface(
                name,
                &params,
                method.unwrap_or(TriangulationMethod::Prescribed),
                None,
            )
        }
        _ => {
            return Err(CliError::Input(
                "give exactly one of --scene NAME, --surface NAME or --input FILE".into(),
            ));
        }
    };
    apply_options(&args, &mut config)?;
    // The design before the change, panelled with the same options, to follow from.
    let original = match &args.follow {
        None => None,
        Some(path) => {
            let name = path.display().to_string();
            if fitted.is_some() {
                return Err(CliError::Input(
                    "--follow applies to a NURBS design (.json), not to a fitted mesh".into(),
                ));
            }
            let (surface, mesh) = read_design_surface(path)?;
            if mesh.is_some() {
                return Err(CliError::Input(format!(
                    "--follow {name}: the original must be a NURBS design (.json), not a mesh"
                )));
            }
            let mut first = PhexConfig::for_nurbs(&name, surface, None);
            apply_options(&args, &mut first)?;
            Some((name, first))
        }
    };
    let label = args
        .scene
        .clone()
        .or(args.surface.clone())
        .unwrap_or_else(|| config.surface.clone());
    let unit = config.nurbs.as_ref().and_then(|n| n.unit());
    // Planar faces (unless the optimisation is off) and simple faces (unless the scene shows
    // invalid ones).
    let goals = PhexGoals::of(&config, expect_valid);
    let start = std::time::Instant::now();
    // With --follow: whether it followed, or why not.
    let mut followed: Option<Result<(), String>> = None;
    let mut pipeline = None;
    if let Some((name, first)) = original {
        match following_run(&name, first, &config)? {
            Ok(p) => {
                pipeline = Some(p);
                followed = Some(Ok(()));
            }
            Err(why) => followed = Some(Err(why)),
        }
    }
    let pipeline = match pipeline {
        Some(p) => p,
        None => PhexPipeline::new(config).map_err(|e| CliError::input("", e))?,
    };
    let r = pipeline.finish().map_err(|e| CliError::input("", e))?;
    let seconds = start.elapsed().as_secs_f64();
    write_text(&out, &write_obj(&r.mesh))?;
    let rep = &r.report;
    let sizes: serde_json::Map<String, serde_json::Value> = rep
        .face_sizes
        .iter()
        .map(|(k, v)| (k.to_string(), json!(v)))
        .collect();
    let reason = goals.shortfall(
        &r.mesh,
        rep.max_planarity,
        rep.iterations,
        rep.invalid_faces,
    );
    let mut report = json!({
        "vertices": rep.vertices,
        "faces": rep.faces,
        "face_sizes": sizes,
        "max_planarity": rep.max_planarity,
        "invalid_faces": rep.invalid_faces,
        "iterations": rep.iterations,
        "max_surface_distance": rep.max_surface_distance,
        "bbox_diagonal": rep.bbox_diagonal,
        "seconds": seconds,
        "converged": reason.is_none(),
    });
    if let Some(r) = &reason {
        report["reason"] = json!(r);
    }
    if let Some(u) = unit {
        report["unit"] = json!(u.name());
    }
    if let Some(f) = &followed {
        report["followed"] = json!(f.is_ok());
        if let Err(why) = f {
            report["follow_note"] = json!(why);
        }
    }
    if let Some(f) = &fitted {
        // How far the fitted surface is from the mesh, and the panels from the mesh itself.
        let far = r
            .mesh
            .positions
            .iter()
            .filter_map(|p| f.mesh.closest_point(p).ok())
            .map(|c| c.distance)
            .fold(0.0, f64::max);
        report["fit_max_distance"] = json!(f.max_distance);
        report["fit_mean_distance"] = json!(f.mean_distance);
        report["max_input_distance"] = json!(far);
    }
    write_report(args.report.as_deref(), &report)?;
    println!(
        "phex {label}: {} faces, max_planarity {:.3e}, {} invalid faces, {} iterations, {:.3} s{}",
        rep.faces,
        rep.max_planarity,
        rep.invalid_faces,
        rep.iterations,
        seconds,
        reason
            .as_ref()
            .map_or(String::new(), |r| format!(", NOT done: {r}"))
    );
    match reason {
        Some(r) => Err(CliError::Unmet(r)),
        None => Ok(()),
    }
}

/// The options of the command line on `config` (they apply to --input and --follow alike).
fn apply_options(args: &PhexArgs, config: &mut PhexConfig) -> Result<(), CliError> {
    if let Some(m) = args.method {
        config.method = m;
    }
    if let Some(h) = args.size {
        config.size = Some(h);
    }
    if let Some(n) = args.iterations {
        config.iterations = n;
    }
    if args.no_optimize {
        config.optimize = false;
    }
    if let Some(deg) = args.field_angle {
        if !(deg.is_finite() && deg.abs() <= 90.0) {
            return Err(CliError::Input(format!(
                "--field-angle {deg}: use degrees in [-90, 90]"
            )));
        }
        config.field_angle = Some(deg.to_radians());
    }
    if args.no_boundary_faces {
        config.boundary_faces = false;
    }
    if let Some(n) = args.max_faces {
        config.max_faces = n;
    }
    Ok(())
}

/// `--follow`: the run of `first` (the design before the change, file `name`) to its end, then
/// followed onto the reshaped surface of `config` (`PhexPipeline::follow_in_steps`). Ok(Err)
/// with the reason, also printed as a note, when the original's panels cannot be followed (the
/// reshaped design is then panelled afresh); Err when the two designs do not match or the
/// original cannot be panelled.
fn following_run(
    name: &str,
    first: PhexConfig,
    config: &PhexConfig,
) -> Result<Result<PhexPipeline, String>, CliError> {
    let Some(reshaped) = config.nurbs.as_deref() else {
        return Err(CliError::Input(
            "--follow applies to a NURBS design (.json) given with --input".into(),
        ));
    };
    let mut original = PhexPipeline::new(first).map_err(|e| CliError::input(name, e))?;
    original
        .run_to_end()
        .map_err(|e| CliError::input(name, e))?;
    match original.follow_in_steps(reshaped.clone()) {
        Ok(p) => Ok(Ok(p)),
        Err(PhexError::NotFollowed(why)) => {
            let why = format!("{name}: {why}; the design is panelled afresh");
            eprintln!("note: {why}");
            Ok(Err(why))
        }
        Err(e) => Err(CliError::input(&format!("--follow {name}"), e)),
    }
}

/// The input mesh a fitted surface stands for, to measure the panels against.
struct FittedMesh {
    mesh: MeshSurface,
    max_distance: f64,
    mean_distance: f64,
}

/// Reads the surface of a design file: a NURBS surface as JSON (told by the `.json` name or a
/// first `{`), or a triangle mesh (OBJ, STL, glTF/GLB) fitted by a smooth surface. Errors name
/// the file.
fn read_design_surface(path: &Path) -> Result<(NurbsSurface, Option<FittedMesh>), CliError> {
    let name = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|source| CliError::Io {
        path: name.clone(),
        source,
    })?;
    let is_json = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"))
        || bytes
            .iter()
            .find(|b| !b.is_ascii_whitespace())
            .is_some_and(|&b| b == b'{');
    if is_json {
        let text = String::from_utf8(bytes).map_err(|e| {
            CliError::Input(format!(
                "{name}: not UTF-8 text (byte {})",
                e.utf8_error().valid_up_to()
            ))
        })?;
        let surface = NurbsSurface::from_json(&text).map_err(|e| CliError::input(&name, e))?;
        return Ok((surface, None));
    }
    let mesh = read_mesh_file(path)?;
    let fit = fit_mesh_surface(&mesh, &MeshFitOptions::default())
        .map_err(|e| CliError::input(&name, e))?;
    let fitted = FittedMesh {
        mesh: MeshSurface::from_mesh(mesh),
        max_distance: fit.max_distance,
        mean_distance: fit.mean_distance,
    };
    Ok((fit.surface, Some(fitted)))
}
