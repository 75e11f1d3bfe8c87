//! Conical and circular meshes, their offsets and support structures (conical paper, Sec. 4-5).

use dupin_core::mesh::{MeshTopology, PolyMesh, max_planarity};

use dupin_core::conical::{
    PqMode, PqOptions, Refinement, VertexType, angle_balance, circular_residual, cone_axes,
    conical_residual, face_normals, offset_mesh, pq_perturb, principal_quad_mesh, spherical_image,
    support_structure, vertex_type,
};

use dupin_core::surface::{SurfaceOfRevolution, Torus};

use dupin_core::Vec3;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A principal patch of the vase with every vertex moved randomly by up to `amp` times the
/// grid spacing: no longer planar, conical or circular.
fn perturbed_vase(seed: u64, n: usize, amp: f64) -> PolyMesh {
    let s = SurfaceOfRevolution::vase();
    let mut m = principal_quad_mesh(&s, (0.0, 1.5), (-0.8, 0.8), n, n);
    let h = 1.5 / n as f64;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    for p in &mut m.positions {
        for k in 0..3 {
            p[k] += amp * h * (rng.random::<f64>() * 2.0 - 1.0);
        }
    }
    m
}

fn conical_mesh() -> PolyMesh {
    let m = perturbed_vase(1, 8, 0.05);
    let r = pq_perturb(
        &m,
        PqOptions {
            mode: PqMode::Conical,
            ..PqOptions::default()
        },
    )
    .unwrap();
    assert!(r.converged, "{:?}", r.reason);
    r.mesh
}

#[test]
fn conical_optimisation_reaches_exact_constraints() {
    let m = perturbed_vase(1, 8, 0.05);
    let topo = MeshTopology::new(&m).unwrap();
    assert!(conical_residual(&m, &topo) > 1e-3);
    let out = conical_mesh();
    assert!(max_planarity(&out) <= 1e-10);
    assert!(conical_residual(&out, &topo) <= 1e-10);
}

#[test]
fn circular_optimisation_reaches_exact_constraints() {
    let m = perturbed_vase(2, 8, 0.05);
    assert!(circular_residual(&m) > 1e-3);
    let r = pq_perturb(
        &m,
        PqOptions {
            mode: PqMode::Circular,
            ..PqOptions::default()
        },
    )
    .unwrap();
    assert!(r.converged, "{:?}", r.reason);
    assert!(max_planarity(&r.mesh) <= 1e-10);
    assert!(r.circular_residual.unwrap() <= 1e-10);
    assert!(circular_residual(&r.mesh) <= 1e-10);
    // Independent check: the four vertices of each quad are equidistant from the centre of
    // the circle through three of them.
    for f in r.mesh.faces() {
        let p: Vec<Vec3> = f.iter().map(|&v| r.mesh.positions[v as usize]).collect();
        let (a, b) = (p[1] - p[0], p[2] - p[0]);
        let axb = a.cross(&b);
        let c = p[0]
            + (a.norm_squared() * b.cross(&axb) + b.norm_squared() * axb.cross(&a))
                / (2.0 * axb.norm_squared());
        let rad = (p[0] - c).norm();
        assert!(((p[3] - c).norm() - rad).abs() <= 1e-9 * rad);
    }
}

#[test]
fn sqp_refinement_and_anchors() {
    let m = perturbed_vase(3, 5, 0.05);
    let r = pq_perturb(
        &m,
        PqOptions {
            refinement: Refinement::Sqp,
            fixed_vertices: vec![0, 7, 20],
            max_iterations: 200,
            ..PqOptions::default()
        },
    )
    .unwrap();
    assert!(r.converged, "{:?}", r.reason);
    assert!(max_planarity(&r.mesh) <= 1e-10);
    for v in [0, 7, 20] {
        assert_eq!(r.mesh.positions[v], m.positions[v]);
    }
    let topo = MeshTopology::new(&m).unwrap();
    let fb = pq_perturb(
        &m,
        PqOptions {
            fix_boundary: true,
            ..PqOptions::default()
        },
    )
    .unwrap();
    assert!(max_planarity(&fb.mesh) <= 1e-10);
    for v in 0..m.num_vertices() {
        if topo.is_boundary(v) {
            assert_eq!(fb.mesh.positions[v], m.positions[v]);
        }
    }
}

/// A random conical vertex star: four tangent planes of a random cone through the origin,
/// edges along the intersections of consecutive planes.
fn conical_star(rng: &mut ChaCha8Rng) -> (PolyMesh, Vec<Vec3>) {
    let axis = Vec3::new(rng.random::<f64>() - 0.5, rng.random::<f64>() - 0.5, 1.0).normalize();
    let t = axis.cross(&Vec3::x()).normalize();
    let b = axis.cross(&t);
    let cos_t: f64 = 0.4 + 0.5 * rng.random::<f64>();
    let sin_t = (1.0 - cos_t * cos_t).sqrt();
    let mut angles: Vec<f64> = (0..4)
        .map(|k| (k as f64 + 0.3 * (rng.random::<f64>() - 0.5)) * std::f64::consts::FRAC_PI_2)
        .collect();
    angles.sort_by(f64::total_cmp);
    let normals: Vec<Vec3> = angles
        .iter()
        .map(|&a| cos_t * axis + sin_t * (a.cos() * t + a.sin() * b))
        .collect();
    star_from_normals(&normals, rng)
}

/// Builds a valence-4 star at the origin whose faces have the given normals (in order).
fn star_from_normals(normals: &[Vec3], rng: &mut ChaCha8Rng) -> (PolyMesh, Vec<Vec3>) {
    // Edge k is the intersection of planes k-1 and k (through the origin).
    let mut pos = vec![Vec3::zeros()];
    let mut dirs = Vec::new();
    for k in 0..4 {
        let d = normals[(k + 3) % 4].cross(&normals[k]).normalize();
        dirs.push(d);
        pos.push(d * (0.5 + rng.random::<f64>()));
    }
    // Outer corner of face k (between edges k and k+1) in plane k.
    for k in 0..4 {
        let c = dirs[k] + dirs[(k + 1) % 4];
        let c = c - normals[k] * normals[k].dot(&c);
        pos.push(c * (0.8 + 0.4 * rng.random::<f64>()));
    }
    let faces: Vec<[u32; 4]> = (0..4u32)
        .map(|k| [0, 1 + k, 5 + k, 1 + (k + 1) % 4])
        .collect();
    (PolyMesh::new(pos, faces).unwrap(), normals.to_vec())
}

/// The four oriented planes through the origin with unit normals n_i touch one sphere (centre
/// c, radius r: n_i·c = r for all i) iff det\[n_i | 1\] = 0.
fn sphere_det(n: &[Vec3]) -> f64 {
    let m = nalgebra::Matrix4::from_fn(|i, j| if j < 3 { n[i][j] } else { 1.0 });
    m.determinant()
}

#[test]
fn geometry_fact_1_both_ways() {
    let mut rng = ChaCha8Rng::seed_from_u64(42);
    let mut tested = 0;
    for _ in 0..300 {
        // Conical stars: balance 0 and the sphere exists.
        let (m, normals) = conical_star(&mut rng);
        let topo = MeshTopology::new(&m).unwrap();
        let fn_ = face_normals(&m);
        // The star's faces really have the planned normals (orientation may flip).
        for k in 0..4 {
            assert!(fn_[k].cross(&normals[k]).norm() < 1e-9);
        }
        let bal = angle_balance(&m, &topo, 0).unwrap();
        assert!(bal.abs() < 1e-12, "conical star: balance {bal}");
        assert!(sphere_det(&normals).abs() < 1e-12);
        // Random stars: the sphere test and the balance fail together.
        let normals: Vec<Vec3> = {
            let mut a: Vec<f64> = (0..4)
                .map(|k| {
                    (k as f64 + 0.3 * (rng.random::<f64>() - 0.5)) * std::f64::consts::FRAC_PI_2
                })
                .collect();
            a.sort_by(f64::total_cmp);
            a.iter()
                .map(|&t| {
                    let c: f64 = 0.4 + 0.5 * rng.random::<f64>();
                    Vec3::new(
                        (1.0 - c * c).sqrt() * t.cos(),
                        (1.0 - c * c).sqrt() * t.sin(),
                        c,
                    )
                })
                .collect()
        };
        let (m, normals) = star_from_normals(&normals, &mut rng);
        let topo = MeshTopology::new(&m).unwrap();
        let bal = angle_balance(&m, &topo, 0).unwrap();
        let det = sphere_det(&normals);
        if det.abs() > 1e-6 {
            assert!(
                bal.abs() > 1e-9,
                "non-conical star with balance {bal}, det {det}"
            );
            tested += 1;
        } else {
            assert!(bal.abs() < 1e-4);
        }
    }
    assert!(tested > 250);
}

#[test]
fn offsets_support_structure_and_fact_2() {
    let m = conical_mesh();
    let topo = MeshTopology::new(&m).unwrap();
    let d = 0.05;
    let off = offset_mesh(&m, d).unwrap();
    // Same connectivity.
    assert!(m.faces().zip(off.faces()).all(|(a, b)| a == b));
    // Each offset face plane is parallel at distance d.
    let (n0, n1) = (face_normals(&m), face_normals(&off));
    for (f, face) in m.faces().enumerate() {
        assert!((n0[f] - n1[f]).norm() < 1e-9);
        let c0 = m.positions[face[0] as usize];
        for &v in face {
            let dist = (off.positions[v as usize] - c0).dot(&n0[f]);
            assert!((dist - d).abs() <= 1e-9 * d, "face {f}: {dist}");
        }
    }
    assert!(max_planarity(&off) <= 1e-10);
    let (c0, c1) = (conical_residual(&m, &topo), conical_residual(&off, &topo));
    assert!(c1 <= 1e-9, "offset conical residual {c1} (original {c0})");
    // Every support beam is planar, the ones touching the boundary too (there the offset
    // vertices are placed so that offset edges stay parallel to the originals).
    let (beams, off2) = support_structure(&m, d).unwrap();
    assert_eq!(off2.positions, off.positions);
    assert_eq!(beams.num_faces(), topo.edges().len());
    let axes = cone_axes(&m, &topo);
    let (mut interior_beams, mut boundary_beams) = (0, 0);
    for (k, (a, b)) in topo.edges().into_iter().enumerate() {
        let p = dupin_core::mesh::face_planarity(&beams, k);
        assert!(p <= 1e-10, "beam {k} ({a}, {b}): planarity {p}");
        if axes[a as usize].is_some() && axes[b as usize].is_some() {
            interior_beams += 1;
        } else {
            boundary_beams += 1;
        }
        // Beams have the offset's height: the far edge is at distance ~d, not degenerate.
        let (pa, qa) = (m.positions[a as usize], off.positions[a as usize]);
        assert!((qa - pa).norm() < 3.0 * d, "beam {k} too long");
    }
    assert!(interior_beams > 50 && boundary_beams >= 32);
    // Geometry Fact 2: neighbouring cone axes are coplanar.
    let mut pairs = 0;
    for (a, b) in topo.edges() {
        if let (Some(x), Some(y)) = (axes[a as usize], axes[b as usize]) {
            let e = m.positions[b as usize] - m.positions[a as usize];
            let vol = x.cross(&y).dot(&e) / e.norm();
            assert!(
                vol.abs() < 1e-9,
                "axes of edge ({a}, {b}) not coplanar: {vol}"
            );
            pairs += 1;
        }
    }
    assert!(pairs > 50);
    // The spherical image of a conical mesh is circular (its faces are planar).
    let img = spherical_image(&m, &topo);
    assert!(img.num_faces() > 0);
    for f in 0..img.num_faces() {
        if img.face(f).len() == 4 {
            assert!(dupin_core::mesh::face_planarity(&img, f) <= 1e-9);
        }
    }
}

#[test]
fn support_beams_planar_on_a_symmetric_principal_mesh() {
    // The exact principal grid of the vase: isosceles trapezoids, conical by symmetry. The
    // boundary's parallelism conditions are rank deficient here (moving both ends of a
    // boundary edge along their meridians keeps it parallel), which the offset must survive.
    let m = principal_quad_mesh(&SurfaceOfRevolution::vase(), (0.0, 1.2), (-0.6, 0.9), 6, 5);
    let topo = MeshTopology::new(&m).unwrap();
    assert!(conical_residual(&m, &topo) <= 1e-12);
    for d in [0.03, -0.08] {
        let (beams, off) = support_structure(&m, d).unwrap();
        for (k, (a, b)) in topo.edges().into_iter().enumerate() {
            let p = dupin_core::mesh::face_planarity(&beams, k);
            assert!(p <= 1e-10, "d {d}: beam ({a}, {b}) planarity {p}");
            let h = (off.positions[a as usize] - m.positions[a as usize]).norm();
            assert!(
                h >= 0.99 * d.abs() && h < 2.0 * d.abs(),
                "d {d}: beam height {h}"
            );
        }
        assert!(max_planarity(&off) <= 1e-10);
    }
}

#[test]
fn vertex_types_on_the_torus() {
    let torus = Torus {
        major: 3.0,
        minor: 1.0,
    };
    let m = principal_quad_mesh(&torus, (0.0, 1.0), (-3.2, 3.2), 4, 16);
    let topo = MeshTopology::new(&m).unwrap();
    let mut seen = (0, 0);
    for v in topo.interior_valence4() {
        let vv = -3.2 + 6.4 * (v / 5) as f64 / 16.0;
        let t = vertex_type(&m, &topo, v).unwrap();
        if vv.cos() > 0.2 {
            assert_eq!(t, VertexType::Elliptic, "outer vertex {v}");
            seen.0 += 1;
        } else if vv.cos() < -0.2 {
            assert_eq!(t, VertexType::Hyperbolic, "inner vertex {v}");
            seen.1 += 1;
        }
    }
    assert!(seen.0 > 0 && seen.1 > 0);
}

/// A valence-4 star at the origin with the given edge directions (in rotation order).
fn star_with_edges(dirs: [Vec3; 4]) -> PolyMesh {
    let mut pos = vec![Vec3::zeros()];
    pos.extend(dirs.iter().copied());
    for k in 0..4 {
        pos.push(1.2 * (dirs[k] + dirs[(k + 1) % 4]));
    }
    let faces: Vec<[u32; 4]> = (0..4u32)
        .map(|k| [0, 1 + k, 5 + k, 1 + (k + 1) % 4])
        .collect();
    PolyMesh::new(pos, faces).unwrap()
}

#[test]
fn vertex_types_elliptic_hyperbolic_parabolic() {
    let e = |x: f64, y: f64, z: f64| Vec3::new(x, y, z).normalize();
    // Convex spherical quad in the upper hemisphere: elliptic.
    let m = star_with_edges([
        e(1.0, 0.0, -0.3),
        e(0.0, 1.0, -0.3),
        e(-1.0, 0.0, -0.3),
        e(0.0, -1.0, -0.3),
    ]);
    let t = MeshTopology::new(&m).unwrap();
    assert_eq!(vertex_type(&m, &t, 0), Some(VertexType::Elliptic));
    // Saddle: up, down, up, down: no hemisphere holds them.
    let m = star_with_edges([
        e(1.0, 0.0, 0.4),
        e(0.0, 1.0, -0.4),
        e(-1.0, 0.0, 0.4),
        e(0.0, -1.0, -0.4),
    ]);
    let t = MeshTopology::new(&m).unwrap();
    assert_eq!(vertex_type(&m, &t, 0), Some(VertexType::Hyperbolic));
    // In one hemisphere (z < 0.3) but one direction folded inwards: parabolic.
    let m = star_with_edges([
        e(1.0, 0.0, -0.2),
        e(0.0, 1.0, -0.2),
        e(-1.0, 0.0, -0.2),
        e(0.0, 0.3, -1.0),
    ]);
    let t = MeshTopology::new(&m).unwrap();
    assert_eq!(vertex_type(&m, &t, 0), Some(VertexType::Parabolic));
}
