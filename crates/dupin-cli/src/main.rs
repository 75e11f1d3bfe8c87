//! The `dupin` command line (see `../shared/contract.md` and the README).
//!
//! Exit code 0 on success; 2 on bad input with one line on stderr starting `error:`.

use clap::{Parser, Subcommand};
use std::process::ExitCode;

mod common;
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
}

fn run(cli: Cli) -> Result<(), common::CliError> {
    match cli.command {
        Command::SurfaceInfo(args) => surface_info::run(args),
        Command::Hexdelaunay(args) => hexdelaunay::run(args),
        Command::Planarize(a) => planarize::run(a),
        Command::Offset(a) => offset::run(a),
        Command::Phex(a) => phex::run(a),
        Command::Pq(a) => pq::run(a),
    }
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            use clap::error::ErrorKind;
            if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) {
                let _ = e.print();
                return ExitCode::SUCCESS;
            }
            // clap's message already starts with `error:`; keep it to one line.
            let msg = e.to_string();
            let first = msg.lines().next().unwrap_or("error: bad arguments");
            eprintln!("{first}");
            return ExitCode::from(2);
        }
    };
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", e.to_string().replace('\n', " "));
            ExitCode::from(2)
        }
    }
}
