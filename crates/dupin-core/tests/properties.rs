//! Property tests (proptest, seeded by its deterministic default runner): PQ perturbation keeps
//! the topology and reports the planarity of its result, every hexagonal Delaunay input point
//! is an exact output vertex with the mode's angle bounds, and OBJ text round-trips positions.
//! Native only (the wasm tests run `--test wasm_smoke`).
#![cfg(not(target_arch = "wasm32"))]

use dupin_core::conical::{PqMode, PqOptions, pq_perturb};
use dupin_core::hex_delaunay::{HexDelaunayMode, hex_delaunay, triangulation_quality};
use dupin_core::mesh::{PolyMesh, max_planarity, parse_obj, write_obj};
use dupin_core::{Vec2, Vec3};
use proptest::prelude::*;

/// Lower angle bound of the extended mode, degrees (tan α = 5/(3√3), section 5.4).
const EXTENDED_MIN: f64 = 43.897_886_248_013_99;

/// An `nx x ny` quad grid with jittered positions and heights (non-planar quads).
fn quad_grid(nx: usize, ny: usize, jitter: &[(f64, f64, f64)]) -> PolyMesh {
    let mut p = Vec::with_capacity((nx + 1) * (ny + 1));
    for j in 0..=ny {
        for i in 0..=nx {
            let (dx, dy, z) = jitter[j * (nx + 1) + i];
            p.push(Vec3::new(i as f64 + dx, j as f64 + dy, z));
        }
    }
    PolyMesh::quad_grid(p, nx, ny).expect("grid indices are valid")
}

/// Grid size and one jitter triple per vertex.
fn grid_input() -> impl Strategy<Value = (usize, usize, Vec<(f64, f64, f64)>)> {
    (1usize..=4, 1usize..=4).prop_flat_map(|(nx, ny)| {
        let n = (nx + 1) * (ny + 1);
        (
            Just(nx),
            Just(ny),
            prop::collection::vec((-0.2f64..0.2, -0.2f64..0.2, -0.3f64..0.3), n),
        )
    })
}

/// Points on a 0.01 grid in [-10, 10]² (duplicates allowed: they share a vertex).
fn points(max: usize) -> impl Strategy<Value = Vec<Vec2>> {
    prop::collection::vec((-1000i32..=1000, -1000i32..=1000), 1..=max).prop_map(|v| {
        v.into_iter()
            .map(|(x, y)| Vec2::new(f64::from(x) * 0.01, f64::from(y) * 0.01))
            .collect()
    })
}

fn faces(m: &PolyMesh) -> Vec<Vec<u32>> {
    m.faces().map(<[u32]>::to_vec).collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// (a) Planar-mode PQ perturbation keeps every face's vertex list, reports the contract
    /// `max_planarity` of the mesh it returns, and leaves anchored (and, when asked, boundary)
    /// vertices exactly where they were; the paper's way and keeping the design (the least
    /// move in face space when the grid is near planar) alike.
    #[test]
    fn pq_perturb_keeps_topology_and_anchors(
        (nx, ny, jitter) in grid_input(),
        anchor in any::<prop::sample::Index>(),
        fix_boundary in any::<bool>(),
        keep_design in any::<bool>(),
    ) {
        let m = quad_grid(nx, ny, &jitter);
        let anchor = anchor.index(m.num_vertices());
        let r = pq_perturb(
            &m,
            PqOptions {
                mode: PqMode::Planar,
                fixed_vertices: vec![anchor],
                fix_boundary,
                keep_design,
                max_iterations: 30,
                ..PqOptions::default()
            },
        )
        .unwrap();
        prop_assert_eq!(faces(&r.mesh), faces(&m));
        prop_assert_eq!(r.mesh.num_vertices(), m.num_vertices());
        prop_assert_eq!(r.max_planarity, max_planarity(&r.mesh));
        prop_assert_eq!(r.mesh.positions[anchor], m.positions[anchor]);
        if fix_boundary {
            for j in 0..=ny {
                for i in 0..=nx {
                    if i == 0 || j == 0 || i == nx || j == ny {
                        let v = j * (nx + 1) + i;
                        prop_assert_eq!(r.mesh.positions[v], m.positions[v], "boundary {}", v);
                    }
                }
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// (b) Every input point is an output vertex with its exact coordinates, and every angle
    /// lies in the mode's bounds ([30°, 120°] simple, [43.8979°, 90°] extended; 1e-3° as in
    /// the unit tests).
    #[test]
    fn hex_delaunay_keeps_points_and_angle_bounds(
        pts in points(40),
        extended in any::<bool>(),
    ) {
        let (mode, lo, hi) = if extended {
            (HexDelaunayMode::Extended, EXTENDED_MIN, 90.0)
        } else {
            (HexDelaunayMode::Simple, 30.0, 120.0)
        };
        let t = hex_delaunay(&pts, &[], mode).unwrap();
        prop_assert_eq!(t.input_vertex.len(), pts.len());
        for (p, &v) in pts.iter().zip(&t.input_vertex) {
            prop_assert_eq!(t.vertices[v as usize], *p);
        }
        let q = triangulation_quality(&t.vertices, &t.triangles);
        prop_assert!(
            q.min_angle_deg >= lo - 1e-3 && q.max_angle_deg <= hi + 1e-3,
            "angles [{}, {}] outside [{}, {}]",
            q.min_angle_deg,
            q.max_angle_deg,
            lo,
            hi
        );
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// (c) `parse_obj(write_obj(m))` gives back every position bit for bit, and the faces.
    #[test]
    fn obj_round_trips_positions_exactly(
        (nx, ny, jitter) in grid_input(),
        scale in prop_oneof![Just(1.0), 1e-300f64..1e-290, 1e290f64..1e300, -1e6f64..1e6],
    ) {
        let mut m = quad_grid(nx, ny, &jitter);
        for p in &mut m.positions {
            *p *= scale;
        }
        let back = parse_obj(&write_obj(&m)).unwrap();
        prop_assert_eq!(back.positions.len(), m.positions.len());
        for (a, b) in back.positions.iter().zip(&m.positions) {
            prop_assert_eq!(a.map(f64::to_bits), b.map(f64::to_bits));
        }
        prop_assert_eq!(faces(&back), faces(&m));
    }
}
