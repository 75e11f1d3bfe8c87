//! Wavefront OBJ in and out, as the outside contract fixes it: `v` and `f` only, full double
//! precision, 1-based indices, faces kept at their true size.

use crate::Vec3;
use crate::mesh::{MeshError, PolyMesh};
use std::fmt::Write as _;
use thiserror::Error;

/// Why an OBJ text could not be read.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ObjError {
    /// A line could not be parsed.
    #[error("line {line}: {message}")]
    Syntax {
        /// 1-based line number.
        line: usize,
        /// What was wrong with it.
        message: String,
    },
    /// The text has no vertices or no faces.
    #[error("the OBJ has no {0}")]
    Empty(&'static str),
    /// The parsed faces do not form a valid polygon mesh.
    #[error(transparent)]
    Mesh(#[from] MeshError),
}

/// Parses an OBJ: `v x y z`, `f i j k ...` (with or without `/vt/vn` parts, negative indices
/// relative to the end), `#` comments; `v x y z r g b` (vertex colours dropped); `o`, `g`, `s`,
/// `vt`, `vn`, `vp`, `usemtl`, `mtllib`
/// and `l` lines ignored. Line ends may be LF, CRLF or CR alone, and a UTF-8 byte-order mark is
/// skipped. Errors name the 1-based line and quote the offending text with control characters
/// escaped.
pub fn parse_obj(text: &str) -> Result<PolyMesh, ObjError> {
    let mut positions = Vec::new();
    let mut faces: Vec<Vec<u32>> = Vec::new();
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    for (ln, raw) in lines_any_end(text).enumerate() {
        let line = ln + 1;
        let content = raw.split('#').next().unwrap_or("").trim();
        let mut it = content.split_whitespace();
        let Some(tag) = it.next() else { continue };
        let err = |message: String| ObjError::Syntax { line, message };
        match tag {
            "v" => {
                // Only x y z: exporters append an optional w or r g b colour.
                let mut c = [0.0; 3];
                for (k, slot) in c.iter_mut().enumerate() {
                    let tok = it
                        .next()
                        .ok_or_else(|| err(format!("vertex needs 3 coordinates, found {k}")))?;
                    *slot = tok
                        .parse::<f64>()
                        .map_err(|_| err(format!("{} is not a number", quoted(tok))))?;
                    if !slot.is_finite() {
                        return Err(err(format!("coordinate {} is not finite", quoted(tok))));
                    }
                }
                positions.push(Vec3::new(c[0], c[1], c[2]));
            }
            "f" => {
                let mut f = Vec::new();
                for tok in it {
                    let first = tok.split('/').next().unwrap_or("");
                    let i: i64 = first
                        .parse()
                        .map_err(|_| err(format!("{} is not a vertex index", quoted(tok))))?;
                    let n = positions.len() as i64;
                    let idx = if i > 0 {
                        i - 1
                    } else if i < 0 {
                        n + i
                    } else {
                        return Err(err("vertex index 0 is not allowed (OBJ is 1-based)".into()));
                    };
                    if idx < 0 || idx >= n {
                        return Err(err(format!(
                            "vertex index {i} is out of range: {n} vertices defined so far"
                        )));
                    }
                    if f.contains(&(idx as u32)) {
                        return Err(err(format!("the face repeats vertex {}", idx + 1)));
                    }
                    f.push(idx as u32);
                }
                if f.len() < 3 {
                    return Err(err(format!(
                        "a face needs at least 3 vertices, found {}",
                        f.len()
                    )));
                }
                faces.push(f);
            }
            "vt" | "vn" | "vp" | "o" | "g" | "s" | "usemtl" | "mtllib" | "l" => {}
            other => return Err(err(format!("unknown statement {}", quoted(other)))),
        }
    }
    if positions.is_empty() {
        return Err(ObjError::Empty("vertices"));
    }
    if faces.is_empty() {
        return Err(ObjError::Empty("faces"));
    }
    Ok(PolyMesh::new(positions, faces)?)
}

/// The lines of `text` whatever their ends: LF, CRLF or CR alone (old Mac exporters).
pub(crate) fn lines_any_end(text: &str) -> impl Iterator<Item = &str> {
    text.split('\n')
        .flat_map(|l| l.strip_suffix('\r').unwrap_or(l).split('\r'))
}

/// `text` in backquotes for a message, shortened to 40 characters, control characters and
/// other invisible ones escaped (a binary file must not write raw bytes to a terminal).
pub(crate) fn quoted(text: &str) -> String {
    let mut s: String = text.chars().take(40).flat_map(char::escape_debug).collect();
    if text.chars().count() > 40 {
        s.push_str("...");
    }
    format!("`{s}`")
}

/// Writes `mesh` as OBJ: `v x y z` with Rust's shortest round-trip formatting (`{:?}`), faces
/// 1-based in their stored order.
pub fn write_obj(mesh: &PolyMesh) -> String {
    let mut s = String::with_capacity(mesh.num_vertices() * 64 + mesh.num_faces() * 40);
    for p in &mesh.positions {
        let _ = writeln!(s, "v {:?} {:?} {:?}", p.x, p.y, p.z);
    }
    for f in mesh.faces() {
        s.push('f');
        for &i in f {
            let _ = write!(s, " {}", i + 1);
        }
        s.push('\n');
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_is_exact() {
        let text = "# hex\no x\nv 0.1 0.2 0.30000000000000004\nv 1 0 0\nv 1 1 0\nv 0 1 1e-300\n\
                    f 1/1/1 2//2 3 4\n";
        let m = parse_obj(text).unwrap();
        assert_eq!(m.face(0), &[0, 1, 2, 3]);
        let again = parse_obj(&write_obj(&m)).unwrap();
        assert_eq!(m, again);
        assert_eq!(again.positions[0].z, 0.30000000000000004);
    }

    #[test]
    fn errors_name_the_line() {
        let e = parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n").unwrap_err();
        assert_eq!(e.to_string(), "line 4: `x` is not a vertex index");
        let e = parse_obj("v 0 0\n").unwrap_err();
        assert!(e.to_string().starts_with("line 1:"));
        assert_eq!(
            parse_obj("# nothing\n").unwrap_err(),
            ObjError::Empty("vertices")
        );
        let e = parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 1\n").unwrap_err();
        assert_eq!(e.to_string(), "line 4: the face repeats vertex 1");
        let e = parse_obj("v 0 0 0\nv 1 0 0\nv nan 1 0\n").unwrap_err();
        assert!(e.to_string().contains("not finite"));
    }

    /// What exporters write: a byte-order mark, CRLF or CR-only line ends, vertex colours,
    /// texture and normal references, groups, smoothing and material statements.
    #[test]
    fn exporter_dialects_are_read() {
        let body = "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 1\nvt 0 0\nvn 0 0 1\ns off\n\
                    usemtl glass\nmtllib a.mtl\ng roof\nl 1 2\nf 1/1/1 2/1/1 3/1/1\n";
        let want = parse_obj(body).unwrap();
        assert_eq!(want.num_faces(), 1);
        assert_eq!(want.positions[1], Vec3::new(1.0, 0.0, 0.0));
        for text in [
            format!("\u{feff}{body}"),
            body.replace('\n', "\r\n"),
            body.replace('\n', "\r"),
        ] {
            assert_eq!(parse_obj(&text).unwrap(), want, "{text:?}");
        }
        // A line number counts CR-only ends as line ends.
        let e = parse_obj("v 0 0 0\rv 1 0 0\rq\r").unwrap_err();
        assert_eq!(e.to_string(), "line 3: unknown statement `q`");
    }

    /// Control characters of the input are escaped in messages, and long tokens shortened.
    #[test]
    fn messages_escape_what_they_quote() {
        let e = parse_obj("v 0 0 \u{1b}[31m\n").unwrap_err().to_string();
        assert_eq!(e, "line 1: `\\u{1b}[31m` is not a number");
        assert!(!e.chars().any(char::is_control));
        let long = "x".repeat(100);
        let e = parse_obj(&format!("{long}\n")).unwrap_err().to_string();
        assert!(e.ends_with("...`") && e.len() < 80, "{e}");
    }

    #[test]
    fn negative_indices_are_relative() {
        let m = parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n").unwrap();
        assert_eq!(m.face(0), &[0, 1, 2]);
    }
}
