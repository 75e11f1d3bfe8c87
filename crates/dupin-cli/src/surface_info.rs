//! `dupin surface-info`: position, normal and curvature of a library surface at one parameter
//! point (P-Hex paper, section 3), as JSON on stdout; `--list` prints the library.

use crate::common::{CliError, write_report};
use clap::Args;
use dupin_core::Vec3;
use dupin_core::surface::{CurvatureTolerance, parse_assignment, surface_by_name, surface_catalog};
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `dupin surface-info`.
#[derive(Args, Debug)]
pub struct SurfaceInfoArgs {
    /// Library surface name (see --list).
    #[arg(long, required_unless_present = "list")]
    surface: Option<String>,
    /// Parameter assignment KEY=VALUE (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE", allow_hyphen_values = true)]
    set: Vec<String>,
    /// Parameter point U,V.
    #[arg(
        long,
        value_name = "U,V",
        allow_hyphen_values = true,
        required_unless_present = "list"
    )]
    at: Option<String>,
    /// Print every library surface with its parameters (defaults and ranges) and exit.
    #[arg(long)]
    list: bool,
    /// Also write the JSON object (plus `seconds`) to this file.
    #[arg(long)]
    report: Option<PathBuf>,
}

fn vec(v: &Vec3) -> serde_json::Value {
    serde_json::json!([v.x, v.y, v.z])
}

/// Runs the command.
pub fn run(args: SurfaceInfoArgs) -> Result<(), CliError> {
    if args.list {
        for spec in surface_catalog() {
            let params: Vec<String> = spec
                .params
                .iter()
                .map(|p| {
                    format!(
                        "{}={}[{}..{}]{}",
                        p.key,
                        p.default,
                        p.min,
                        p.max,
                        if p.integer { "(integer)" } else { "" }
                    )
                })
                .collect();
            println!(
                "{} {} : {}",
                spec.name,
                params.join(" "),
                spec.parametrisation
            );
        }
        return Ok(());
    }
    let name = args.surface.unwrap_or_default();
    let at = args.at.unwrap_or_default();
    let mut params = Vec::new();
    for s in &args.set {
        params.push(parse_assignment(s).map_err(|e| CliError::input("--set", e))?);
    }
    let (u, v) = parse_uv(&at)?;
    let start = Instant::now();
    let pairs: Vec<(&str, f64)> = params.iter().map(|(k, v)| (k.as_str(), *v)).collect();
    let surface = surface_by_name(&name, &pairs).map_err(|e| CliError::input("--surface", e))?;
    let dom = surface.domain();
    if !dom.contains(u, v) {
        return Err(CliError::Input(format!(
            "--at {u},{v} is outside the domain u in [{}, {}], v in [{}, {}] of `{name}`",
            dom.u.0, dom.u.1, dom.v.0, dom.v.1
        )));
    }
    let c = surface
        .curvature(u, v)
        .map_err(|e| CliError::input(&format!("at ({u}, {v})"), e))?;
    let seconds = start.elapsed().as_secs_f64();
    let mut out = serde_json::json!({
        "point": vec(&c.point),
        "normal": vec(&c.normal),
        "k1": c.k1,
        "k2": c.k2,
        "dir1": vec(&c.dir1),
        "dir2": vec(&c.dir2),
        "gaussian": c.gaussian,
        "mean": c.mean,
        "type": c.point_type(&CurvatureTolerance::default()).name(),
    });
    println!("{out}");
    if let Some(obj) = out.as_object_mut() {
        obj.insert("seconds".into(), seconds.into());
    }
    write_report(args.report.as_deref(), &out)
}

fn parse_uv(s: &str) -> Result<(f64, f64), CliError> {
    let bad = || CliError::Input(format!("--at `{s}`: expected U,V with two finite numbers"));
    let (a, b) = s.split_once(',').ok_or_else(bad)?;
    let u: f64 = a.trim().parse().map_err(|_| bad())?;
    let v: f64 = b.trim().parse().map_err(|_| bad())?;
    if !(u.is_finite() && v.is_finite()) {
        return Err(bad());
    }
    Ok((u, v))
}
