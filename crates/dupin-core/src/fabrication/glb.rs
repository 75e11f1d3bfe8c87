//! The panels as glTF 2.0 binary (GLB) for viewers and CAD tools (three.js, model-viewer,
//! Rhino 8): one node and mesh per layer (`panels`, and optionally `offset` and `beams`), each
//! polygon fanned into triangles with flat normals, in metres (glTF's unit). The mesh's
//! `extras.panels` lists, per panel, its name and its first triangle and triangle count, so a
//! viewer can pick panel by panel.
//!
//! Written by hand (a JSON document and one binary chunk): the `gltf` crate reads glTF but does
//! not write it; the tests read every file back with it.

use super::units::LengthUnit;
use crate::Vec3;
use crate::mesh::PolyMesh;
use std::fmt::Write as _;

/// One named layer of a GLB: a polygon mesh.
#[derive(Debug, Clone, Copy)]
pub struct GlbLayer<'a> {
    /// Node and mesh name (`panels`, `offset`, `beams`).
    pub name: &'a str,
    /// The polygons.
    pub mesh: &'a PolyMesh,
}

/// Flat-shaded triangle data of one layer: f32 positions and normals (3 per corner) and the
/// panel ranges (first triangle, count).
fn fan(mesh: &PolyMesh, scale: f64) -> (Vec<f32>, Vec<f32>, Vec<(usize, usize)>) {
    let (mut pos, mut nor, mut ranges) = (Vec::new(), Vec::new(), Vec::new());
    let mut triangles = 0;
    for f in mesh.faces() {
        let p: Vec<Vec3> = f
            .iter()
            .map(|&v| mesh.positions[v as usize] * scale)
            .collect();
        let n = p.len();
        let c = p.iter().sum::<Vec3>() / n as f64;
        let normal: Vec3 = (0..n)
            .map(|k| (p[k] - c).cross(&(p[(k + 1) % n] - c)))
            .sum();
        let normal = normal.try_normalize(0.0).unwrap_or(Vec3::z());
        ranges.push((triangles, n - 2));
        for k in 1..n - 1 {
            for q in [p[0], p[k], p[k + 1]] {
                pos.extend([q.x as f32, q.y as f32, q.z as f32]);
                nor.extend([normal.x as f32, normal.y as f32, normal.z as f32]);
            }
        }
        triangles += n - 2;
    }
    (pos, nor, ranges)
}

/// The GLB of `layers` (coordinates in `unit`, written in metres).
pub fn panels_glb(layers: &[GlbLayer<'_>], unit: LengthUnit) -> Vec<u8> {
    let scale = unit.to_m();
    let mut bin: Vec<u8> = Vec::new();
    let (mut views, mut accessors, mut meshes, mut nodes) =
        (String::new(), String::new(), String::new(), String::new());
    let mut accessor_count = 0;
    for layer in layers {
        let (pos, nor, ranges) = fan(layer.mesh, scale);
        let count = pos.len() / 3;
        if count == 0 {
            continue;
        }
        let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        for q in pos.chunks(3) {
            for k in 0..3 {
                lo[k] = lo[k].min(q[k]);
                hi[k] = hi[k].max(q[k]);
            }
        }
        for (data, with_bounds) in [(&pos, true), (&nor, false)] {
            let offset = bin.len();
            bin.extend(data.iter().flat_map(|x| x.to_le_bytes()));
            let sep = if accessor_count == 0 { "" } else { "," };
            let _ = write!(
                views,
                r#"{sep}{{"buffer":0,"byteOffset":{offset},"byteLength":{},"target":34962}}"#,
                data.len() * 4
            );
            let bounds = if with_bounds {
                format!(r#","min":{lo:?},"max":{hi:?}"#)
            } else {
                String::new()
            };
            let _ = write!(
                accessors,
                r#"{sep}{{"bufferView":{accessor_count},"componentType":5126,"count":{count},"type":"VEC3"{bounds}}}"#
            );
            accessor_count += 1;
        }
        let panels: Vec<String> = ranges
            .iter()
            .enumerate()
            .map(|(i, (first, n))| {
                format!(
                    r#"{{"name":"{}","first_triangle":{first},"triangles":{n}}}"#,
                    i + 1
                )
            })
            .collect();
        let sep = if meshes.is_empty() { "" } else { "," };
        let name = json_string(layer.name);
        let _ = write!(
            meshes,
            r#"{sep}{{"name":{name},"primitives":[{{"attributes":{{"POSITION":{},"NORMAL":{}}},"mode":4}}],"extras":{{"panels":[{}]}}}}"#,
            accessor_count - 2,
            accessor_count - 1,
            panels.join(",")
        );
        let mesh_index = meshes.matches(r#""primitives""#).count() - 1;
        let sep = if nodes.is_empty() { "" } else { "," };
        let _ = write!(nodes, r#"{sep}{{"name":{name},"mesh":{mesh_index}}}"#);
    }
    let node_count = nodes.matches(r#""mesh""#).count();
    let scene_nodes: Vec<String> = (0..node_count).map(|i| i.to_string()).collect();
    let json = format!(
        r#"{{"asset":{{"version":"2.0","generator":"Dupin"}},"scene":0,"scenes":[{{"nodes":[{}]}}],"nodes":[{nodes}],"meshes":[{meshes}],"accessors":[{accessors}],"bufferViews":[{views}],"buffers":[{{"byteLength":{}}}]}}"#,
        scene_nodes.join(","),
        bin.len()
    );
    glb_container(json.into_bytes(), bin)
}

/// A JSON string literal of `s` (quotes, backslashes and control characters escaped), for names
/// that come from outside.
fn json_string(s: &str) -> String {
    let mut out = String::from("\"");
    for ch in s.chars() {
        match ch {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if (c as u32) < 0x20 => {
                let _ = write!(out, "\\u{:04x}", c as u32);
            }
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// The GLB container: a 12-byte header, the JSON chunk padded with spaces and the binary chunk
/// padded with zeros to 4 bytes (glTF 2.0, section 4.4).
fn glb_container(mut json: Vec<u8>, mut bin: Vec<u8>) -> Vec<u8> {
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let total = 12 + 8 + json.len() + if bin.is_empty() { 0 } else { 8 + bin.len() };
    let mut out = Vec::with_capacity(total);
    out.extend(b"glTF");
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    out.extend((json.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(json);
    if !bin.is_empty() {
        out.extend((bin.len() as u32).to_le_bytes());
        out.extend(b"BIN\0");
        out.extend(bin);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::io::{ImportOptions, read_gltf};

    #[test]
    fn the_gltf_reader_gets_the_panels_back() {
        let p = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1000.0, 0.0, 0.0),
            Vec3::new(1000.0, 1000.0, 0.0),
            Vec3::new(0.0, 1000.0, 0.0),
            Vec3::new(1500.0, 500.0, 0.0),
            Vec3::new(1200.0, 1300.0, 0.0),
        ];
        let m = PolyMesh::new(p, [vec![0u32, 1, 2, 3], vec![1, 4, 5, 2]]).unwrap();
        let glb = panels_glb(
            &[GlbLayer {
                name: "panels \"A\"",
                mesh: &m,
            }],
            LengthUnit::Millimetre,
        );
        assert_eq!(&glb[..4], b"glTF");
        assert_eq!(glb.len() % 4, 0);
        let doc = gltf::Gltf::from_slice(&glb).unwrap();
        assert_eq!(doc.meshes().next().unwrap().name(), Some("panels \"A\""));
        let (back, dropped) = read_gltf(&glb, &ImportOptions::default()).unwrap();
        assert_eq!((back.num_faces(), dropped), (4, 0));
        // Welded back to the six corners, in metres.
        assert_eq!(back.num_vertices(), 6);
        assert!(
            back.positions
                .iter()
                .any(|q| (q - Vec3::new(1.5, 0.5, 0.0)).norm() < 1e-7)
        );
    }
}
