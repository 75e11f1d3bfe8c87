//! The `dupin` command line (see `../shared/contract.md` and the README).
//!
//! Exit code 0 on success; 2 on bad input and 3 on a result that misses what was asked (not
//! converged, invalid faces), each with one line on stderr starting `error:`.

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};
use std::process::ExitCode;

mod common;
mod export;
mod hexdelaunay;
mod offset;
mod phex;
mod planarize;
mod pq;
mod surface_info;

/// Planar-panel geometry for architecture.
#[derive(Parser)]
#[command(name = "dupin", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Position, normal and curvature of a library surface at (U, V), as JSON.
    SurfaceInfo(surface_info::SurfaceInfoArgs),
    /// Hexagonal Delaunay triangulation of a point set (angles in [30, 120] degrees).
    Hexdelaunay(hexdelaunay::HexDelaunayArgs),
    /// Make every face planar (optionally conical or circular) by minimal vertex moves.
    Planarize(planarize::PlanarizeArgs),
    /// Offset a conical mesh by a face distance, with its support structure.
    Offset(offset::OffsetArgs),
    /// Build a P-Hex mesh (planar hexagons) from a scene or a library surface.
    Phex(phex::PhexArgs),
    /// Build a PQ scene of the conical paper (see --list-scenes).
    Pq(pq::PqArgs),
    /// Write a panel mesh as fabrication files: DXF sheets, CSV list, SVG or GLB.
    Export(export::ExportArgs),
}

fn run(cli: Cli) -> Result<(), common::CliError> {
    match cli.command {
        Command::SurfaceInfo(args) => surface_info::run(args),
        Command::Hexdelaunay(args) => hexdelaunay::run(args),
        Command::Planarize(a) => planarize::run(a),
        Command::Offset(a) => offset::run(a),
        Command::Phex(a) => phex::run(a),
        Command::Pq(a) => pq::run(a),
        Command::Export(a) => export::run(a),
    }
}

/// The command line with the settings every subcommand shares: negative numbers are values
/// (`--size -1` is a bad size, not an unknown flag).
fn command() -> clap::Command {
    let mut cmd = Cli::command();
    let names: Vec<String> = cmd
        .get_subcommands()
        .map(|c| c.get_name().to_string())
        .collect();
    for name in names {
        cmd = cmd.mut_subcommand(name, |c| c.allow_negative_numbers(true));
    }
    cmd
}

/// Refuses output paths that cannot be written before any work is done, so that a bad
/// `--report` does not leave a fresh `--out` behind it.
fn check_outputs(matches: &clap::ArgMatches) -> Result<(), common::CliError> {
    let Some((_, sub)) = matches.subcommand() else {
        return Ok(());
    };
    for id in ["out", "report", "support"] {
        if let Some(path) = sub.try_get_one::<std::path::PathBuf>(id).ok().flatten() {
            common::check_writable(path)?;
        }
    }
    Ok(())
}

/// clap's message on one line: its first line, with the lines that name what is missing or
/// wrong appended (`error: the following required arguments were not provided: --out <OUT>`).
fn one_line(e: &clap::Error) -> String {
    let msg = e.to_string();
    let mut lines = msg
        .lines()
        .map(str::trim)
        .take_while(|l| !l.starts_with("Usage:") && !l.starts_with("For more information"))
        .filter(|l| !l.is_empty());
    let first = lines.next().unwrap_or("error: bad arguments").to_string();
    lines.fold(first, |acc, l| format!("{acc} {l}"))
}

fn main() -> ExitCode {
    let matches = match command().try_get_matches() {
        Ok(m) => m,
        Err(e) => {
            use clap::error::ErrorKind;
            match e.kind() {
                ErrorKind::DisplayHelp | ErrorKind::DisplayVersion => {
                    let _ = e.print();
                    return ExitCode::SUCCESS;
                }
                ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
                    let names: Vec<String> = command()
                        .get_subcommands()
                        .map(|c| c.get_name().to_string())
                        .collect();
                    eprintln!(
                        "error: no command given; use one of {} (dupin --help)",
                        names.join(", ")
                    );
                }
                _ => eprintln!("{}", one_line(&e)),
            }
            return ExitCode::from(2);
        }
    };
    let cli = match Cli::from_arg_matches(&matches) {
        Ok(cli) => cli,
        Err(e) => {
            eprintln!("{}", one_line(&e));
            return ExitCode::from(2);
        }
    };
    match check_outputs(&matches).and_then(|()| run(cli)) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", e.to_string().replace('\n', " "));
            ExitCode::from(e.exit_code())
        }
    }
}
