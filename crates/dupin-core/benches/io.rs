//! Designs in and fabrication files out: reading a 1M-triangle OBJ (ours and the `tobj` crate
//! side by side) and GLB, and the DXF cutting file of 10k hexagonal panels. Targets of the
//! design-import issue: OBJ <= 1 s, GLB <= 0.3 s, DXF <= 0.5 s, natively.

use criterion::{Criterion, criterion_group, criterion_main};
use dupin_core::fabrication::{DxfOptions, GlbLayer, LengthUnit, panel_dxf, panels_glb};
use dupin_core::mesh::io::{ImportOptions, read_mesh, write_obj};
use dupin_core::scenes::benchmark_meshes::{dome_triangle_mesh, torus_centroid_dual};
use std::hint::black_box;
use std::time::Duration;

fn bench(c: &mut Criterion) {
    // 2 * 708^2 = 1 002 528 triangles on 502 681 vertices.
    let dome = dome_triangle_mesh(708, 1);
    let obj = write_obj(&dome);
    // Dupin's own GLB (flat-shaded panels: three corners a triangle, and each panel's name
    // and triangle range in `extras`), and the indexed GLB exporters usually write.
    let ours = panels_glb(
        &[GlbLayer {
            name: "panels",
            mesh: &dome,
        }],
        LengthUnit::Metre,
    );
    let glb = indexed_glb(&dome);
    let options = ImportOptions::default();
    let mut g = c.benchmark_group("io");
    g.sample_size(10).measurement_time(Duration::from_secs(20));
    g.bench_function("obj_1m_triangles/dupin", |b| {
        b.iter(|| read_mesh("dome.obj", black_box(obj.as_bytes()), &options).unwrap())
    });
    g.bench_function("obj_1m_triangles/tobj", |b| {
        b.iter(|| {
            let mut reader = std::io::BufReader::new(black_box(obj.as_bytes()));
            tobj::load_obj_buf(&mut reader, &tobj::LoadOptions::default(), |_| {
                Err(tobj::LoadError::OpenFileFailed)
            })
            .unwrap()
        })
    });
    g.bench_function("glb_1m_triangles/dupin", |b| {
        b.iter(|| read_mesh("dome.glb", black_box(&glb), &options).unwrap())
    });
    g.bench_function("glb_1m_triangles_flat_named/dupin", |b| {
        b.iter(|| read_mesh("dome.glb", black_box(&ours), &options).unwrap())
    });
    // 200 x 50 hexagons of the torus's centroid dual.
    let hexagons = torus_centroid_dual(200, 50, 3.0, 1.0);
    let dxf = DxfOptions::default();
    g.bench_function("dxf_10k_hexagons", |b| {
        b.iter(|| panel_dxf(black_box(&hexagons), &dxf).unwrap())
    });
    g.finish();
    println!(
        "io: OBJ {} MB, {} triangles; GLB {} MB indexed, {} MB flat with names; DXF of {} hexagons",
        obj.len() / 1_000_000,
        dome.num_faces(),
        glb.len() / 1_000_000,
        ours.len() / 1_000_000,
        hexagons.num_faces()
    );
}

/// A binary glTF of `mesh`'s triangles as most exporters write one: f32 positions, u32
/// indices, one primitive (written here because Dupin's own writer emits flat-shaded panels).
fn indexed_glb(mesh: &dupin_core::mesh::PolyMesh) -> Vec<u8> {
    let mut bin = Vec::new();
    for p in &mesh.positions {
        for c in [p.x, p.y, p.z] {
            bin.extend_from_slice(&(c as f32).to_le_bytes());
        }
    }
    let index_offset = bin.len();
    for f in mesh.faces() {
        for &i in f {
            bin.extend_from_slice(&i.to_le_bytes());
        }
    }
    let (nv, ni) = (mesh.num_vertices(), mesh.num_faces() * 3);
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1,"mode":4}}]}}],"buffers":[{{"byteLength":{}}}],"bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":{index_offset}}},{{"buffer":0,"byteOffset":{index_offset},"byteLength":{}}}],"accessors":[{{"bufferView":0,"componentType":5126,"count":{nv},"type":"VEC3","min":[-1e9,-1e9,-1e9],"max":[1e9,1e9,1e9]}},{{"bufferView":1,"componentType":5125,"count":{ni},"type":"SCALAR"}}]}}"#,
        bin.len(),
        bin.len() - index_offset
    );
    let mut json = json.into_bytes();
    while json.len() % 4 != 0 {
        json.push(b' ');
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    out
}

criterion_group!(benches, bench);
criterion_main!(benches);
