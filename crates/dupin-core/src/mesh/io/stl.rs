//! STL in, ASCII or binary, welded by exact position: the format every CAD and mesh tool
//! exports, one triangle at a time with no shared vertices.
//!
//! Parsing is the `stl_io` crate's (it reads triangles one by one, without trusting the
//! header's count for allocation, and welds by the bits of each f32 coordinate). Before it runs,
//! a binary file's triangle count is checked against the file's length and the import limit, so
//! a truncated or lying header gets a message with the byte offset instead of a partial mesh.

use super::{ImportError, ImportOptions};
use crate::Vec3;
use crate::mesh::PolyMesh;
use std::io::Cursor;

/// Size of a binary STL header (80 bytes of text, then the u32 triangle count).
const HEADER: usize = 84;
/// Size of one binary STL triangle record (normal, three vertices, attribute count).
const RECORD: usize = 50;

/// Whether `bytes` is an ASCII STL (`solid` followed by a `facet`), as opposed to a binary one
/// (whose 80-byte header may also start with `solid`, as some exporters write it).
fn is_ascii(bytes: &[u8]) -> bool {
    let head = &bytes[..bytes.len().min(1024)];
    let text = String::from_utf8_lossy(head);
    text.trim_start().starts_with("solid") && (text.contains("facet") || bytes.len() < HEADER)
}

/// Reads an STL (ASCII or binary) into a triangle mesh, welding vertices of bit-identical
/// position. Triangles that collapse after welding (two equal corners) are dropped and counted
/// in the second result.
pub fn read_stl(bytes: &[u8], options: &ImportOptions) -> Result<(PolyMesh, usize), ImportError> {
    let ascii = is_ascii(bytes);
    if !ascii {
        if bytes.len() < HEADER {
            return Err(ImportError::Truncated {
                format: "binary STL",
                offset: bytes.len(),
                expected: format!("an {HEADER}-byte header"),
            });
        }
        let count = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
        options.check_triangles(count)?;
        let need = HEADER + RECORD * count;
        if bytes.len() < need {
            return Err(ImportError::Truncated {
                format: "binary STL",
                offset: bytes.len(),
                expected: format!("{count} triangles ({need} bytes) as its header says"),
            });
        }
    } else {
        // Each ASCII facet takes at least ~100 bytes: a cheap upper bound before parsing.
        options.check_triangles(bytes.len() / 100)?;
    }
    let indexed = stl_io::read_stl(&mut Cursor::new(bytes)).map_err(|e| ImportError::Syntax {
        format: if ascii { "ASCII STL" } else { "binary STL" },
        message: e.to_string(),
    })?;
    options.check_triangles(indexed.faces.len())?;
    let positions: Vec<Vec3> = indexed
        .vertices
        .iter()
        .map(|v| Vec3::new(v[0] as f64, v[1] as f64, v[2] as f64))
        .collect();
    if let Some(k) = positions
        .iter()
        .position(|p| !p.iter().all(|c| c.is_finite()))
    {
        return Err(ImportError::Syntax {
            format: if ascii { "ASCII STL" } else { "binary STL" },
            message: format!("vertex {} has a non-finite coordinate", k + 1),
        });
    }
    let mut faces = Vec::with_capacity(indexed.faces.len());
    let mut dropped = 0;
    for t in &indexed.faces {
        let [a, b, c] = t.vertices.map(|i| i as u32);
        if a == b || b == c || a == c {
            dropped += 1;
        } else {
            faces.push([a, b, c]);
        }
    }
    if faces.is_empty() {
        return Err(ImportError::NoMesh {
            format: if ascii { "ASCII STL" } else { "binary STL" },
            hint: "it holds no triangle with three distinct corners",
        });
    }
    Ok((PolyMesh::new(positions, faces)?, dropped))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two triangles of a unit square as a binary STL, the header starting with `solid` as some
    /// exporters write it.
    fn binary_square() -> Vec<u8> {
        let tris = [
            [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]],
            [[0.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
        ];
        let mut b = b"solid exported by a CAD tool".to_vec();
        b.resize(80, b' ');
        b.extend((tris.len() as u32).to_le_bytes());
        for t in tris {
            b.extend([0.0f32, 0.0, 1.0].iter().flat_map(|x| x.to_le_bytes()));
            for v in t {
                b.extend(v.iter().flat_map(|x| x.to_le_bytes()));
            }
            b.extend([0u8, 0]);
        }
        b
    }

    #[test]
    fn binary_and_ascii_weld_to_the_same_mesh() {
        let (m, dropped) = read_stl(&binary_square(), &ImportOptions::default()).unwrap();
        assert_eq!((m.num_vertices(), m.num_faces(), dropped), (4, 2, 0));
        let ascii = "solid sq\n\
            facet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n  vertex 1 1 0\n \
            endloop\nendfacet\n\
            facet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 1 0\n  vertex 0 1 0\n \
            endloop\nendfacet\nendsolid sq\n";
        let (a, _) = read_stl(ascii.as_bytes(), &ImportOptions::default()).unwrap();
        assert_eq!(a, m);
    }

    #[test]
    fn truncated_and_oversized_files_are_refused_before_parsing() {
        let full = binary_square();
        let e = read_stl(&full[..full.len() - 10], &ImportOptions::default()).unwrap_err();
        assert!(e.to_string().contains("byte 174"), "{e}");
        let mut lying = full.clone();
        lying[80..84].copy_from_slice(&u32::MAX.to_le_bytes());
        let e = read_stl(&lying, &ImportOptions::default()).unwrap_err();
        assert!(matches!(e, ImportError::TooLarge { .. }), "{e}");
        let e = read_stl(&[7u8; 40], &ImportOptions::default()).unwrap_err();
        assert!(matches!(e, ImportError::Truncated { .. }), "{e}");
        // Cut inside the header text: read as a broken ASCII file, named so.
        let e = read_stl(&full[..40], &ImportOptions::default()).unwrap_err();
        assert!(e.to_string().starts_with("ASCII STL: "), "{e}");
        let small = ImportOptions::default().with_max_triangles(1);
        assert!(matches!(
            read_stl(&full, &small),
            Err(ImportError::TooLarge { .. })
        ));
    }
}
