//! glTF 2.0 in (`.gltf` with embedded buffers, or binary `.glb`): every triangle primitive of
//! every mesh of every node of the scene, placed by the node transforms, welded by exact
//! position into one triangle mesh.
//!
//! Parsing and validation are the `gltf` crate's (without its file-system `import` feature:
//! the core reads bytes only). Buffers come from the GLB's binary chunk or from base64 `data:`
//! URIs; a buffer in a separate file is refused with what to do, since the page and the core
//! see one file at a time.

use super::{ImportError, ImportOptions};
use crate::Vec3;
use crate::mesh::PolyMesh;
use base64::Engine as _;
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Mode;
use nalgebra::Matrix4;
use rustc_hash::FxHashMap;

const FORMAT: &str = "glTF";

/// The bytes of every buffer, checked against their declared length.
fn buffers(doc: &gltf::Gltf) -> Result<Vec<Vec<u8>>, ImportError> {
    let mut out = Vec::new();
    for b in doc.buffers() {
        let data = match b.source() {
            gltf::buffer::Source::Bin => doc.blob.clone().ok_or(ImportError::Syntax {
                format: FORMAT,
                message: format!(
                    "buffer {} refers to a binary chunk the file lacks",
                    b.index()
                ),
            })?,
            gltf::buffer::Source::Uri(uri) => {
                let Some(encoded) = uri
                    .strip_prefix("data:")
                    .and_then(|rest| rest.split_once(";base64,"))
                    .map(|(_, d)| d)
                else {
                    return Err(ImportError::ExternalBuffer {
                        uri: super::obj::quoted(uri),
                    });
                };
                base64::engine::general_purpose::STANDARD
                    .decode(encoded)
                    .map_err(|e| ImportError::Syntax {
                        format: FORMAT,
                        message: format!("buffer {}: bad base64 data ({e})", b.index()),
                    })?
            }
        };
        if data.len() < b.length() {
            return Err(ImportError::Truncated {
                format: FORMAT,
                offset: data.len(),
                expected: format!("buffer {} of {} bytes", b.index(), b.length()),
            });
        }
        out.push(data);
    }
    Ok(out)
}

/// Welds positions by their exact bits while collecting triangles. The keys are hashed with
/// FxHash: a million-triangle file welds millions of keys, and SipHash's protection against
/// chosen collisions buys nothing here (a hostile file can only slow its own import).
#[derive(Default)]
struct Welder {
    positions: Vec<Vec3>,
    index: FxHashMap<[u64; 3], u32>,
    faces: Vec<[u32; 3]>,
    dropped: usize,
}

impl Welder {
    fn vertex(&mut self, p: Vec3) -> u32 {
        let key = [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
        *self.index.entry(key).or_insert_with(|| {
            self.positions.push(p);
            (self.positions.len() - 1) as u32
        })
    }

    fn triangle(&mut self, t: [u32; 3]) {
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
            self.dropped += 1;
        } else {
            self.faces.push(t);
        }
    }
}

/// Adds the triangle primitives of `mesh` placed by `world`.
fn add_mesh(
    mesh: gltf::Mesh<'_>,
    world: &Matrix4<f64>,
    data: &[Vec<u8>],
    options: &ImportOptions,
    out: &mut Welder,
) -> Result<(), ImportError> {
    // A mirroring transform reverses the winding (glTF 2.0, section 3.7.4).
    let flip = world.fixed_view::<3, 3>(0, 0).determinant() < 0.0;
    for prim in mesh.primitives() {
        if !matches!(
            prim.mode(),
            Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
        ) {
            continue;
        }
        if let Some(a) = prim.get(&gltf::Semantic::Positions) {
            check_accessor(
                &a,
                Dimensions::Vec3,
                &[DataType::F32],
                mesh.index(),
                "POSITION",
            )?;
        }
        if let Some(a) = prim.indices() {
            let types = [DataType::U8, DataType::U16, DataType::U32];
            check_accessor(&a, Dimensions::Scalar, &types, mesh.index(), "indices")?;
        }
        let reader = prim.reader(|b| data.get(b.index()).map(Vec::as_slice));
        let Some(positions) = reader.read_positions() else {
            continue;
        };
        // Unindexed corners make a triangle of three positions; indexed ones fewer: a lower
        // bound on the triangles to come.
        options.check_triangles(out.faces.len() + positions.len() / 3)?;
        let ids: Vec<u32> = positions
            .map(|p| {
                let q = world.transform_point(&nalgebra::Point3::new(
                    p[0] as f64,
                    p[1] as f64,
                    p[2] as f64,
                ));
                out.vertex(q.coords)
            })
            .collect();
        let corners: Vec<u32> = match reader.read_indices() {
            Some(i) => i.into_u32().collect(),
            None => (0..ids.len() as u32).collect(),
        };
        options.check_triangles(out.faces.len() + corners.len() / 3)?;
        let at = |k: usize| -> Result<u32, ImportError> {
            let i = corners[k] as usize;
            ids.get(i).copied().ok_or_else(|| ImportError::Syntax {
                format: FORMAT,
                message: format!(
                    "mesh {}: index {i} is out of range ({} vertices)",
                    mesh.index(),
                    ids.len()
                ),
            })
        };
        let n = corners.len();
        let mut tri = |a: usize, b: usize, c: usize| -> Result<(), ImportError> {
            let t = [at(a)?, at(b)?, at(c)?];
            out.triangle(if flip { [t[0], t[2], t[1]] } else { t });
            Ok(())
        };
        match prim.mode() {
            Mode::Triangles => {
                for k in (0..n / 3 * 3).step_by(3) {
                    tri(k, k + 1, k + 2)?;
                }
            }
            Mode::TriangleStrip => {
                for k in 0..n.saturating_sub(2) {
                    if k % 2 == 0 {
                        tri(k, k + 1, k + 2)?;
                    } else {
                        tri(k + 1, k, k + 2)?;
                    }
                }
            }
            _ => {
                for k in 1..n.saturating_sub(1) {
                    tri(0, k, k + 1)?;
                }
            }
        }
    }
    Ok(())
}

/// The GLB header's total length must cover the 12-byte header itself: gltf 1.4 subtracts the
/// header size from it unchecked (a panic in builds with overflow checks, found by fuzzing).
fn check_glb_header(bytes: &[u8]) -> Result<(), ImportError> {
    let Some(length) = bytes
        .strip_prefix(b"glTF")
        .and_then(|rest| rest.get(4..8))
        .map(|l| u32::from_le_bytes([l[0], l[1], l[2], l[3]]))
    else {
        return Ok(()); // JSON glTF, or too short for gltf's own header check.
    };
    if length < 12 {
        return Err(ImportError::Syntax {
            format: FORMAT,
            message: format!(
                "the GLB header gives a total length of {length} bytes, less than the header's 12"
            ),
        });
    }
    Ok(())
}

/// The shape glTF 2.0 (section 3.7.2.1) requires of a primitive's POSITION (VEC3 of FLOAT) and
/// indices (SCALAR of unsigned integers), counts of at least one, a buffer-view stride of at
/// least one element, elements inside their view: gltf's readers assume them (debug assertions
/// and unchecked `count - 1` and `stride * count`), found by fuzzing.
fn check_accessor(
    a: &gltf::Accessor<'_>,
    dimensions: Dimensions,
    types: &[DataType],
    mesh: usize,
    what: &str,
) -> Result<(), ImportError> {
    let fail = |problem: String| ImportError::Syntax {
        format: FORMAT,
        message: format!("mesh {mesh}: {what} accessor {}: {problem}", a.index()),
    };
    if a.dimensions() != dimensions || !types.contains(&a.data_type()) {
        return Err(fail(format!(
            "is {:?} of {:?}, glTF 2.0 requires {dimensions:?} of {types:?}",
            a.dimensions(),
            a.data_type()
        )));
    }
    if a.count() == 0 {
        return Err(fail("count 0 (glTF 2.0 requires at least 1)".into()));
    }
    if let Some(view) = a.view() {
        let stride = view.stride().unwrap_or(a.size());
        if stride < a.size() {
            return Err(fail(format!(
                "its buffer view's stride {stride} is shorter than one element ({} bytes)",
                a.size()
            )));
        }
        // The last element's end, computed without overflow, must lie inside the view.
        let end = (a.count() - 1)
            .checked_mul(stride)
            .and_then(|x| x.checked_add(a.size()))
            .and_then(|x| x.checked_add(a.offset()));
        if end.is_none_or(|e| e > view.length()) {
            return Err(fail(format!(
                "{} elements of {} bytes from offset {} do not fit its buffer view of {} bytes",
                a.count(),
                stride,
                a.offset(),
                view.length()
            )));
        }
    }
    if let Some(sparse) = a.sparse()
        && sparse.count() == 0
    {
        return Err(fail("a sparse accessor with count 0".into()));
    }
    Ok(())
}

/// gltf's own validation with one check first: its primitive hook indexes the accessors by the
/// POSITION attribute unchecked (a panic on a file whose POSITION names a missing accessor,
/// found by fuzzing), so that index is checked here before it runs.
fn validate(root: &gltf::json::Root) -> Result<(), String> {
    use gltf::json::validation::{Checked, Validate};
    let accessors = root.accessors.len();
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            if let Some(a) = primitive
                .attributes
                .get(&Checked::Valid(gltf::Semantic::Positions))
                && a.value() >= accessors
            {
                return Err(format!(
                    "meshes[{m}].primitives[{p}]: POSITION names accessor {}, but the file has \
                     {accessors}",
                    a.value()
                ));
            }
        }
    }
    let mut errors = Vec::new();
    root.validate(root, gltf::json::Path::new, &mut |path, error| {
        errors.push(format!("{}: {error}", path()))
    });
    match errors.first() {
        None => Ok(()),
        Some(first) => Err(format!(
            "invalid glTF: {first}{}",
            match errors.len() {
                1 => String::new(),
                n => format!(" (and {} more)", n - 1),
            }
        )),
    }
}

/// Reads a glTF 2.0 file (JSON `.gltf` or binary `.glb`) into one welded triangle mesh: every
/// triangle primitive of every mesh of the default scene's nodes (of all scenes if there is no
/// default, of every mesh if there are no nodes), transformed by the node hierarchy. Triangles
/// that collapse after welding are dropped and counted in the second result.
pub fn read_gltf(bytes: &[u8], options: &ImportOptions) -> Result<(PolyMesh, usize), ImportError> {
    options.check_gltf_bytes(bytes.len())?;
    check_glb_header(bytes)?;
    let syntax = |message: String| ImportError::Syntax {
        format: FORMAT,
        message,
    };
    let doc =
        gltf::Gltf::from_slice_without_validation(bytes).map_err(|e| syntax(e.to_string()))?;
    validate(doc.document.as_json()).map_err(syntax)?;
    let data = buffers(&doc)?;
    let mut out = Welder::default();
    let roots: Vec<gltf::Node<'_>> = match doc.default_scene() {
        Some(s) => s.nodes().collect(),
        None => doc.scenes().flat_map(|s| s.nodes()).collect(),
    };
    if roots.is_empty() {
        for mesh in doc.meshes() {
            add_mesh(mesh, &Matrix4::identity(), &data, options, &mut out)?;
        }
    }
    // Depth-first over the node tree, with a depth bound: validation rejects cycles, and a
    // bound keeps a deep chain from exhausting anything.
    let mut stack: Vec<(gltf::Node<'_>, Matrix4<f64>, usize)> = roots
        .into_iter()
        .map(|n| (n, Matrix4::identity(), 0))
        .collect();
    while let Some((node, parent, depth)) = stack.pop() {
        if depth > 1000 {
            return Err(ImportError::Syntax {
                format: FORMAT,
                message: "the node hierarchy is deeper than 1000 levels".into(),
            });
        }
        let local = node.transform().matrix();
        let local = Matrix4::from_fn(|r, c| local[c][r] as f64);
        let world = parent * local;
        if let Some(mesh) = node.mesh() {
            add_mesh(mesh, &world, &data, options, &mut out)?;
        }
        stack.extend(node.children().map(|c| (c, world, depth + 1)));
    }
    if out.faces.is_empty() {
        return Err(ImportError::NoMesh {
            format: FORMAT,
            hint: "no node of the scene holds a triangle mesh; export the geometry as a mesh",
        });
    }
    Ok((PolyMesh::new(out.positions, out.faces)?, out.dropped))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A glTF with one quad (two triangles) whose buffer is a base64 data URI, used by two
    /// nodes: one translated by (10, 0, 0), one mirrored in x inside a parent scaled by 2.
    fn two_nodes() -> String {
        let pos: [[f32; 3]; 4] = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        let idx: [u16; 6] = [0, 1, 2, 0, 2, 3];
        let mut bin: Vec<u8> = pos.iter().flatten().flat_map(|x| x.to_le_bytes()).collect();
        bin.extend(idx.iter().flat_map(|i| i.to_le_bytes()));
        let b64 = base64::engine::general_purpose::STANDARD.encode(&bin);
        format!(
            r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0,1]}}],
            "nodes":[{{"mesh":0,"translation":[10,0,0]}},{{"scale":[2,2,2],"children":[2]}},
                     {{"mesh":0,"scale":[-1,1,1]}}],
            "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
            "buffers":[{{"byteLength":{},"uri":"data:application/octet-stream;base64,{b64}"}}],
            "bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":48}},
                           {{"buffer":0,"byteOffset":48,"byteLength":12}}],
            "accessors":[{{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3",
                           "min":[0,0,0],"max":[1,1,0]}},
                         {{"bufferView":1,"componentType":5123,"count":6,"type":"SCALAR"}}]}}"#,
            bin.len()
        )
    }

    #[test]
    fn nodes_place_and_mirror_their_meshes() {
        let (m, dropped) = read_gltf(two_nodes().as_bytes(), &ImportOptions::default()).unwrap();
        assert_eq!((m.num_vertices(), m.num_faces(), dropped), (8, 4, 0));
        let has = |x: f64, y: f64| m.positions.iter().any(|p| *p == Vec3::new(x, y, 0.0));
        assert!(has(10.0, 0.0) && has(11.0, 1.0), "translated");
        assert!(has(-2.0, 2.0), "mirrored and scaled by the parent");
        // Every triangle keeps facing +z, the mirrored ones too.
        for f in m.faces() {
            let p = |k: usize| m.positions[f[k] as usize];
            assert!((p(1) - p(0)).cross(&(p(2) - p(0))).z > 0.0, "{f:?}");
        }
    }

    #[test]
    fn bad_files_are_named() {
        let opts = ImportOptions::default();
        let e = read_gltf(b"{not json", &opts).unwrap_err();
        assert!(e.to_string().starts_with("glTF:"), "{e}");
        let external = two_nodes().replace("data:application/octet-stream;base64,", "mesh.bin#");
        let e = read_gltf(external.as_bytes(), &opts).unwrap_err();
        assert!(matches!(e, ImportError::ExternalBuffer { .. }), "{e}");
        let no_mesh = r#"{"asset":{"version":"2.0"},"scenes":[{"nodes":[0]}],"nodes":[{}]}"#;
        let e = read_gltf(no_mesh.as_bytes(), &opts).unwrap_err();
        assert!(matches!(e, ImportError::NoMesh { .. }), "{e}");
        let short = two_nodes().replace("\"byteLength\":60", "\"byteLength\":600");
        let e = read_gltf(short.as_bytes(), &opts).unwrap_err();
        assert!(e.to_string().contains("glTF"), "{e}");
    }
}
