//! Meshes in and out: the text formats of the outside contract (OBJ meshes, point sets,
//! segments) and the exchange formats designs arrive in (STL, glTF/GLB). Bytes or text in,
//! typed data out: no file system here, so the page uses the same readers as the CLI.
//!
//! | format | file |
//! |---|---|
//! | Wavefront OBJ (in and out) | `obj.rs` |
//! | point sets and segments | `point_set.rs` |
//! | STL, ASCII and binary | `stl.rs` |
//! | glTF 2.0, JSON and binary | `gltf.rs` |

mod gltf;
mod obj;
mod point_set;
mod stl;

pub use gltf::read_gltf;
pub(crate) use obj::quoted;
pub use obj::{ObjError, parse_obj, write_obj};
pub use point_set::{PointSetError, parse_points, parse_segments};
pub use stl::read_stl;

use crate::mesh::{MeshError, PolyMesh};
use thiserror::Error;

/// Why a mesh file could not be read. Every message names the format and, where it can, the
/// line or byte offset, and says what to do.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ImportError {
    /// Neither the file name nor the first bytes tell a known format.
    #[error(
        "{name}: unknown mesh format; use OBJ (.obj), STL (.stl), glTF (.gltf) or binary glTF \
         (.glb)"
    )]
    UnknownFormat {
        /// The file name given, quoted.
        name: String,
    },
    /// The file ends before what its own header announces.
    #[error("{format}: the file ends at byte {offset}, before {expected}; is it truncated?")]
    Truncated {
        /// The format being read.
        format: &'static str,
        /// Where the data stops.
        offset: usize,
        /// What was still expected.
        expected: String,
    },
    /// The file's text or structure is malformed.
    #[error("{format}: {message}")]
    Syntax {
        /// The format being read.
        format: &'static str,
        /// What is wrong, with the line or index where known.
        message: String,
    },
    /// An OBJ text could not be read.
    #[error("OBJ: {0}")]
    Obj(#[from] ObjError),
    /// A glTF buffer lives in a separate file.
    #[error(
        "glTF: buffer {uri} is a separate file; export a binary .glb or embed the buffers \
         (data URIs)"
    )]
    ExternalBuffer {
        /// The buffer's URI, quoted.
        uri: String,
    },
    /// The file holds no usable triangle mesh.
    #[error("{format}: no mesh to read: {hint}")]
    NoMesh {
        /// The format being read.
        format: &'static str,
        /// What was found instead, and what to do.
        hint: &'static str,
    },
    /// The mesh is larger than the import limit.
    #[error(
        "the file holds at least {triangles} triangles, more than the limit of {limit}; \
         simplify the mesh or raise the limit"
    )]
    TooLarge {
        /// Triangles (or a lower bound) found.
        triangles: usize,
        /// The limit in force.
        limit: usize,
    },
    /// The triangles do not form a valid polygon mesh.
    #[error(transparent)]
    Mesh(#[from] MeshError),
}

/// Limits of an import, checked before the work (lyon's options-builder style).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImportOptions {
    /// Largest number of triangles (faces) read.
    pub max_triangles: usize,
}

/// The most bytes a glTF is taken to spend on a triangle (see
/// [`ImportOptions::check_gltf_bytes`]).
const GLTF_BYTES_PER_TRIANGLE: usize = 160;

/// The default import limit: 5 million triangles (about 150 MB as a [`PolyMesh`]), what a
/// browser tab holds with room for the computation.
pub const MAX_IMPORT_TRIANGLES: usize = 5_000_000;

impl Default for ImportOptions {
    fn default() -> Self {
        ImportOptions {
            max_triangles: MAX_IMPORT_TRIANGLES,
        }
    }
}

impl ImportOptions {
    /// The same options with another triangle limit.
    pub fn with_max_triangles(mut self, max_triangles: usize) -> Self {
        self.max_triangles = max_triangles;
        self
    }

    pub(crate) fn check_triangles(&self, triangles: usize) -> Result<(), ImportError> {
        if triangles > self.max_triangles {
            return Err(ImportError::TooLarge {
                triangles,
                limit: self.max_triangles,
            });
        }
        Ok(())
    }

    /// A glTF of `len` bytes: refused unread when, past 64 KiB of JSON and headers, even at 160
    /// bytes a triangle (unindexed corners with position, normal, UV and colour: 3 x 48 bytes)
    /// it would hold more triangles than the limit. The accessors' counts are checked again as
    /// they are read.
    pub(crate) fn check_gltf_bytes(&self, len: usize) -> Result<(), ImportError> {
        self.check_triangles(len.saturating_sub(1 << 16) / GLTF_BYTES_PER_TRIANGLE)
    }

    /// An OBJ text: its `f` and `v` lines counted (a byte scan, no parsing) and checked before
    /// it is parsed, so a huge file is refused before its mesh is built. Every face counts as
    /// one; vertices may number at most three per allowed face.
    pub(crate) fn check_obj_text(&self, text: &[u8]) -> Result<(), ImportError> {
        let (mut faces, mut vertices) = (0usize, 0usize);
        for line in text.split(|&b| b == b'\n' || b == b'\r') {
            let line = line.trim_ascii_start();
            match line {
                [b'f', b' ' | b'\t', ..] => faces += 1,
                [b'v', b' ' | b'\t', ..] => vertices += 1,
                _ => {}
            }
        }
        self.check_triangles(faces.max(vertices.div_ceil(3)))
    }
}

/// A mesh file format Dupin reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeshFormat {
    /// Wavefront OBJ (polygons of any size).
    Obj,
    /// STL, ASCII or binary (triangles).
    Stl,
    /// glTF 2.0, JSON with embedded buffers or binary GLB (triangles).
    Gltf,
}

impl MeshFormat {
    /// The format of a file named `name` holding `bytes`: by its extension, else by its first
    /// bytes (`glTF` magic, a `{`, `solid`, or `v`/`f`/`#` lines).
    pub fn detect(name: &str, bytes: &[u8]) -> Option<MeshFormat> {
        let ext = name.rsplit_once('.').map(|(_, e)| e.to_ascii_lowercase());
        match ext.as_deref() {
            Some("obj") => return Some(MeshFormat::Obj),
            Some("stl") => return Some(MeshFormat::Stl),
            Some("gltf" | "glb") => return Some(MeshFormat::Gltf),
            _ => {}
        }
        let head = &bytes[..bytes.len().min(256)];
        let text = String::from_utf8_lossy(head);
        let text = text.trim_start_matches('\u{feff}').trim_start();
        if head.starts_with(b"glTF") || text.starts_with('{') {
            Some(MeshFormat::Gltf)
        } else if text.starts_with("solid") {
            Some(MeshFormat::Stl)
        } else if text.starts_with("v ") || text.starts_with('#') || text.starts_with("o ") {
            Some(MeshFormat::Obj)
        } else {
            None
        }
    }
}

/// A mesh read from a file, with what the reader had to drop.
#[derive(Debug, Clone, PartialEq)]
pub struct ImportedMesh {
    /// The mesh (triangles for STL and glTF, the file's polygons for OBJ).
    pub mesh: PolyMesh,
    /// The format it was read as.
    pub format: MeshFormat,
    /// Triangles dropped because two corners welded into one.
    pub dropped_triangles: usize,
}

/// Reads the mesh file `name` (the name only chooses the format; nothing is opened) from its
/// `bytes`: OBJ, STL or glTF/GLB, within `options`' limits.
pub fn read_mesh(
    name: &str,
    bytes: &[u8],
    options: &ImportOptions,
) -> Result<ImportedMesh, ImportError> {
    let format = MeshFormat::detect(name, bytes)
        .ok_or_else(|| ImportError::UnknownFormat { name: quoted(name) })?;
    let (mesh, dropped_triangles) = match format {
        MeshFormat::Obj => {
            options.check_obj_text(bytes)?;
            let text = std::str::from_utf8(bytes).map_err(|e| ImportError::Syntax {
                format: "OBJ",
                message: format!(
                    "byte {} is not UTF-8 text; is this a binary file?",
                    e.valid_up_to()
                ),
            })?;
            let mesh = parse_obj(text)?;
            options.check_triangles(mesh.num_faces())?;
            (mesh, 0)
        }
        MeshFormat::Stl => read_stl(bytes, options)?,
        MeshFormat::Gltf => read_gltf(bytes, options)?,
    };
    Ok(ImportedMesh {
        mesh,
        format,
        dropped_triangles,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats_are_told_by_name_then_by_content() {
        let obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
        assert_eq!(MeshFormat::detect("roof.OBJ", b""), Some(MeshFormat::Obj));
        assert_eq!(MeshFormat::detect("a.glb", b""), Some(MeshFormat::Gltf));
        assert_eq!(MeshFormat::detect("upload", obj), Some(MeshFormat::Obj));
        assert_eq!(
            MeshFormat::detect("x", b"glTF\x02\0\0\0"),
            Some(MeshFormat::Gltf)
        );
        assert_eq!(
            MeshFormat::detect("x", b"solid a\nfacet"),
            Some(MeshFormat::Stl)
        );
        assert_eq!(MeshFormat::detect("x.3ds", b"\x4d\x4d"), None);
        let m = read_mesh("roof.obj", obj, &ImportOptions::default()).unwrap();
        assert_eq!((m.mesh.num_faces(), m.format), (1, MeshFormat::Obj));
        let e = read_mesh("x.3ds\u{1b}", b"\x4d\x4d", &ImportOptions::default()).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("`x.3ds\\u{1b}`: unknown mesh format"),
            "{e}"
        );
        let e = read_mesh("bin.obj", b"v 0 0 0\n\xff\xfe", &ImportOptions::default());
        assert!(e.unwrap_err().to_string().contains("byte 8 is not UTF-8"));
    }

    /// The limit counts faces, not bytes: long lines, comments and flat-shaded glTF corners
    /// do not make a file within the limit look too large, and a file over it is refused
    /// before its mesh is built.
    #[test]
    fn the_triangle_limit_counts_faces_not_bytes() {
        let limited = ImportOptions::default().with_max_triangles(8);
        let mut obj = String::from("# a long header\n").repeat(50);
        for k in 0..9 {
            obj += &format!("v {k}.000000000000001 0.000000000000001 {}.5\n", k % 2);
        }
        for k in 1..=7 {
            obj += &format!("f {k} {} {}\n", k + 1, k + 2);
        }
        assert!(obj.len() / 12 > 8, "the old byte bound would refuse it");
        let read = read_mesh("long.obj", obj.as_bytes(), &limited).unwrap();
        assert_eq!(read.mesh.num_faces(), 7);
        let over = obj.clone() + "f 1 3 5\nf 2 4 6\n";
        let e = read_mesh("over.obj", over.as_bytes(), &limited).unwrap_err();
        assert!(
            matches!(
                e,
                ImportError::TooLarge {
                    triangles: 9,
                    limit: 8
                }
            ),
            "{e}"
        );

        let glb = crate::fabrication::panels_glb(
            &[crate::fabrication::GlbLayer {
                name: "panels",
                mesh: &read.mesh,
            }],
            crate::fabrication::LengthUnit::Metre,
        );
        assert!(glb.len() / 12 > 8, "the old byte bound would refuse it");
        assert_eq!(
            read_mesh("p.glb", &glb, &limited).unwrap().mesh.num_faces(),
            7
        );
        let tight = ImportOptions::default().with_max_triangles(6);
        assert!(matches!(
            read_mesh("p.glb", &glb, &tight),
            Err(ImportError::TooLarge { .. })
        ));
    }
}
