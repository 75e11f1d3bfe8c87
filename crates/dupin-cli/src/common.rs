//! What every command shares: the error type, file I/O, timing and the JSON report.

use std::path::Path;
use thiserror::Error;

/// Any failure of a command; printed as one `error:` line, exit code 2 (bad input) or 3 (the
/// computation ran, its output and report are written, but the result misses what was asked).
#[derive(Debug, Error)]
pub enum CliError {
    /// Reading or writing a file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// What the OS said.
        source: std::io::Error,
    },
    /// Input was malformed or out of range; the message says what to change.
    #[error("{0}")]
    Input(String),
    /// The result misses what was asked (not converged, invalid faces, beyond tolerance): the
    /// output and the report (with `converged: false` and the `reason`) are already written.
    #[error("{0}")]
    Unmet(String),
}

impl CliError {
    /// The exit code of this error: 3 for a result that misses what was asked, 2 otherwise.
    pub fn exit_code(&self) -> u8 {
        match self {
            CliError::Unmet(_) => 3,
            _ => 2,
        }
    }

    /// Wraps any displayable error as bad input, prefixed with context.
    pub fn input(context: &str, e: impl std::fmt::Display) -> Self {
        if context.is_empty() {
            CliError::Input(e.to_string())
        } else {
            CliError::Input(format!("{context}: {e}"))
        }
    }
}

/// Refuses a path that cannot become an output file: a directory, or a file in a folder that
/// does not exist.
pub fn check_writable(path: &Path) -> Result<(), CliError> {
    let shown = path.display();
    if path.is_dir() {
        return Err(CliError::Input(format!(
            "{shown} is a directory; give a file name to write"
        )));
    }
    let parent = path.parent().filter(|p| !p.as_os_str().is_empty());
    if let Some(dir) = parent.filter(|d| !d.is_dir()) {
        return Err(CliError::Input(format!(
            "{shown}: folder {} does not exist",
            dir.display()
        )));
    }
    Ok(())
}

/// Reads a mesh file (OBJ, STL, glTF or GLB, told by its name or its first bytes), naming the
/// file in any error and noting welded-away triangles on stderr.
#[allow(dead_code)]
pub fn read_mesh_file(path: &Path) -> Result<dupin_core::mesh::PolyMesh, CliError> {
    use dupin_core::mesh::io::{ImportOptions, read_mesh};
    let bytes = std::fs::read(path).map_err(|source| CliError::Io {
        path: path.display().to_string(),
        source,
    })?;
    let name = path.display().to_string();
    let m = read_mesh(&name, &bytes, &ImportOptions::default())
        .map_err(|e| CliError::input(&name, e))?;
    if m.dropped_triangles > 0 {
        eprintln!(
            "note: {name}: {} degenerate triangles dropped (two corners at one point)",
            m.dropped_triangles
        );
    }
    Ok(m.mesh)
}

/// Reads a whole text file.
#[allow(dead_code)]
pub fn read_text(path: &Path) -> Result<String, CliError> {
    std::fs::read_to_string(path).map_err(|source| CliError::Io {
        path: path.display().to_string(),
        source,
    })
}

/// Writes a whole text file.
#[allow(dead_code)]
pub fn write_text(path: &Path, text: &str) -> Result<(), CliError> {
    std::fs::write(path, text).map_err(|source| CliError::Io {
        path: path.display().to_string(),
        source,
    })
}

/// Writes `report` as one JSON object to `path` when a report was asked for.
#[allow(dead_code)]
pub fn write_report(path: Option<&Path>, report: &serde_json::Value) -> Result<(), CliError> {
    match path {
        Some(p) => write_text(
            p,
            &format!(
                "{}\n",
                serde_json::to_string_pretty(report).unwrap_or_default()
            ),
        ),
        None => Ok(()),
    }
}
