//! A triangle mesh of a smooth design, with no UVs, fitted by a smooth surface
//! (`surface/mesh_fit.rs`) and panelled by P-Hex: the fit is close to the mesh, the map is one to
//! one, and the panels are planar, valid and close to the input mesh.

use dupin_core::Vec3;
use dupin_core::mesh::PolyMesh;
use dupin_core::scenes::benchmark_meshes::{bump_triangle_mesh, dome_triangle_mesh};
use dupin_core::surface::{MeshFitError, MeshFitOptions, MeshSurface, fit_mesh_surface};

#[test]
fn a_dome_mesh_is_fitted_within_a_millimetre_and_the_map_is_one_to_one() {
    let mesh = dome_triangle_mesh(104, 1);
    assert!(mesh.num_faces() >= 20_000);
    let fit = fit_mesh_surface(&mesh, &MeshFitOptions::default()).unwrap();
    eprintln!(
        "fit: {:?} control points, max {:.3e} m, mean {:.3e} m",
        fit.surface.control_net_size(),
        fit.max_distance,
        fit.mean_distance
    );
    assert!(fit.max_distance < 1e-3, "{}", fit.max_distance);
    // One to one: every triangle keeps its orientation in the parameter square.
    for f in mesh.faces() {
        let [a, b, c] = [0, 1, 2].map(|k| fit.uv[f[k] as usize]);
        let area = (b - a).perp(&(c - a));
        assert!(area > 0.0, "a flipped triangle {f:?}");
    }
    // The four corners of the square are the four corners of the dome.
    for v in fit.corners {
        let p = mesh.positions[v];
        assert!(
            (p.x.abs() - 6.0).abs() < 1e-12 && (p.y.abs() - 6.0).abs() < 1e-12,
            "{p:?}"
        );
    }
}

#[test]
fn phex_panels_the_fitted_dome_close_to_the_mesh() {
    use dupin_core::Stepper;
    use dupin_core::phex::{PhexConfig, PhexPipeline};
    let mesh = dome_triangle_mesh(104, 2);
    let fit = fit_mesh_surface(&mesh, &MeshFitOptions::default()).unwrap();
    let config = PhexConfig::for_nurbs("dome", fit.surface, Some(0.3));
    let r = PhexPipeline::new(config).and_then(Stepper::finish).unwrap();
    let rep = &r.report;
    eprintln!(
        "{} faces, {} invalid, planarity {:e}",
        rep.faces, rep.invalid_faces, rep.max_planarity
    );
    assert!(rep.faces > 300);
    assert_eq!(rep.invalid_faces, 0);
    assert!(rep.max_planarity <= 1e-10);
    let input = MeshSurface::from_mesh(mesh.clone());
    let diagonal = mesh.bbox_diagonal();
    let far = r
        .mesh
        .positions
        .iter()
        .map(|p| input.closest_point(p).unwrap().distance)
        .fold(0.0, f64::max);
    eprintln!("max distance to the input mesh {far:.3e} of a {diagonal:.2} m diagonal");
    assert!(far <= 0.005 * diagonal, "{far}");
}

/// A mixed-curvature freeform (a Gaussian bump: K > 0 on top, K < 0 on its flanks) of over
/// 20 000 triangles, no UVs: the fit is as close as on the dome, but P-Hex on it misses (open:
/// the fitted parameter lines are far from conjugate, so method 2's hexagons come out
/// self-intersecting and the optimisation stalls: measured 135 of 1 572 faces invalid, max
/// planarity 5.2e-3 after 10 iterations, 143 and the same planarity after 40; the principal
/// directions, `field_angle = Some(0.0)`, stop at the umbilic on top: 121 faces, 8 invalid).
/// The run must say so: its shortfall (the CLI's exit 3, the page's warning) names both misses.
#[test]
fn phex_on_a_fitted_mixed_curvature_mesh_reports_what_it_misses() {
    use dupin_core::Stepper;
    use dupin_core::phex::{PhexConfig, PhexGoals, PhexPipeline};
    let mesh = bump_triangle_mesh(104, 3);
    assert!(mesh.num_faces() >= 20_000);
    let fit = fit_mesh_surface(&mesh, &MeshFitOptions::default()).unwrap();
    let diagonal = mesh.bbox_diagonal();
    assert!(fit.max_distance < 1e-3 * diagonal, "{}", fit.max_distance);
    let config = PhexConfig::for_nurbs("bump", fit.surface, Some(0.3));
    let goals = PhexGoals::of(&config, true);
    let r = PhexPipeline::new(config).and_then(Stepper::finish).unwrap();
    let rep = &r.report;
    let gaussian = |s: f64| rep.per_face.iter().filter(|f| f.gaussian * s > 0.0).count();
    eprintln!(
        "{} faces ({} with K > 0, {} with K < 0), {} invalid, planarity {:e}",
        rep.faces,
        gaussian(1.0),
        gaussian(-1.0),
        rep.invalid_faces,
        rep.max_planarity
    );
    assert!(gaussian(1.0) > 10 && gaussian(-1.0) > 10, "both signs of K");
    let missed = goals.shortfall(
        &r.mesh,
        rep.max_planarity,
        rep.iterations,
        rep.invalid_faces,
    );
    if rep.invalid_faces > 0 || rep.max_planarity > 1e-10 {
        let missed = missed.expect("a run that misses says so");
        assert!(
            missed.contains("self-intersecting") || missed.contains("above the tolerance"),
            "{missed}"
        );
    } else {
        // Solved: the acceptance figures of the import issue hold.
        assert!(missed.is_none());
    }
}

#[test]
fn what_is_not_a_triangulated_disk_is_refused() {
    let quads = PolyMesh::quad_grid(
        (0..9)
            .map(|k| Vec3::new((k % 3) as f64, (k / 3) as f64, 0.0))
            .collect(),
        2,
        2,
    )
    .unwrap();
    let e = fit_mesh_surface(&quads, &MeshFitOptions::default()).unwrap_err();
    assert!(
        matches!(e, MeshFitError::NotTriangles { face: 0, size: 4 }),
        "{e}"
    );
    // A closed tetrahedron: no boundary.
    let p = vec![Vec3::zeros(), Vec3::x(), Vec3::y(), Vec3::z()];
    let tet = PolyMesh::new(p, vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]]).unwrap();
    let e = fit_mesh_surface(&tet, &MeshFitOptions::default()).unwrap_err();
    assert!(
        e.to_string()
            .contains("0 boundary loops and Euler characteristic 2"),
        "{e}"
    );
    let dome = dome_triangle_mesh(6, 3);
    for options in [
        MeshFitOptions::default().with_fairness(-1.0),
        MeshFitOptions::default().with_control_points(3, 10),
    ] {
        assert!(matches!(
            fit_mesh_surface(&dome, &options),
            Err(MeshFitError::BadOption(_))
        ));
    }
}

/// A vault closed around: a surface of revolution about the z axis, radius 3 + 0.4 cos(0.8 z)
/// for z in [0, 6] m (K > 0 at the bulge, K < 0 at the waist, parabolic circles at
/// z = 1.96 m and 5.89 m), `nu` x `nv` quads split into
/// triangles, vertex order shuffled by a stride: a mesh of cylinder topology with no UVs.
fn vault_triangle_mesh(nu: usize, nv: usize) -> PolyMesh {
    let n = nu * (nv + 1);
    let stride = (0..n).map(|s| 7919 + s).find(|s| gcd(*s, n) == 1).unwrap();
    let order = |k: usize| (k * stride) % n;
    let mut positions = vec![Vec3::zeros(); n];
    for j in 0..=nv {
        for i in 0..nu {
            let a = std::f64::consts::TAU * i as f64 / nu as f64;
            let z = 6.0 * j as f64 / nv as f64;
            let r = 3.0 + 0.4 * (0.8 * z).cos();
            positions[order(j * nu + i)] = Vec3::new(r * a.cos(), r * a.sin(), z);
        }
    }
    let id = |i: usize, j: usize| order(j * nu + i % nu) as u32;
    let faces: Vec<[u32; 3]> = (0..nv)
        .flat_map(|j| {
            (0..nu).flat_map(move |i| {
                [
                    [id(i, j), id(i + 1, j), id(i + 1, j + 1)],
                    [id(i, j), id(i + 1, j + 1), id(i, j + 1)],
                ]
            })
        })
        .collect();
    PolyMesh::new(positions, faces).unwrap()
}

fn gcd(a: usize, b: usize) -> usize {
    if b == 0 { a } else { gcd(b, a % b) }
}

#[test]
fn a_cylinder_mesh_is_cut_open_along_a_seam_fitted_and_panelled() {
    use dupin_core::Stepper;
    use dupin_core::phex::{PhexConfig, PhexGoals, PhexPipeline};
    let mesh = vault_triangle_mesh(96, 48);
    let fit = fit_mesh_surface(&mesh, &MeshFitOptions::default()).unwrap();
    let diagonal = mesh.bbox_diagonal();
    eprintln!(
        "vault fit: {:?} control points, max {:.3e} m, mean {:.3e} m on a {diagonal:.2} m diagonal",
        fit.surface.control_net_size(),
        fit.max_distance,
        fit.mean_distance
    );
    assert!(fit.max_distance < 1e-3 * diagonal, "{}", fit.max_distance);
    // The corners are the seam's ends: two on each loop (z = 0 and z = 6), the same vertex twice.
    let z: Vec<f64> = fit.corners.iter().map(|&v| mesh.positions[v].z).collect();
    assert_eq!(z.iter().filter(|z| z.abs() < 1e-12).count(), 2, "{z:?}");
    assert_eq!(
        z.iter().filter(|z| (*z - 6.0).abs() < 1e-12).count(),
        2,
        "{z:?}"
    );
    // One to one away from the seam: no triangle off the seam flips in the parameter square.
    let flipped = mesh
        .faces()
        .filter(|f| {
            let [a, b, c] = [0, 1, 2].map(|k| fit.uv[f[k] as usize]);
            (b - a).perp(&(c - a)) <= 0.0
        })
        .count();
    assert!(
        flipped <= 2 * 48,
        "{flipped} triangles flipped (the seam's are at u = 0)"
    );
    // P-Hex panels it all around, as an open patch with a seam.
    let config = PhexConfig::for_nurbs("vault", fit.surface, Some(0.5));
    let goals = PhexGoals::of(&config, true);
    let r = PhexPipeline::new(config).and_then(Stepper::finish).unwrap();
    let rep = &r.report;
    let angles: Vec<f64> = r.mesh.positions.iter().map(|p| p.y.atan2(p.x)).collect();
    let quadrants = (0..4)
        .filter(|q| {
            let lo = -std::f64::consts::PI + *q as f64 * std::f64::consts::FRAC_PI_2;
            angles
                .iter()
                .any(|a| (lo..lo + std::f64::consts::FRAC_PI_2).contains(a))
        })
        .count();
    eprintln!(
        "vault P-Hex: {} faces, {} invalid, planarity {:e}",
        rep.faces, rep.invalid_faces, rep.max_planarity
    );
    assert!(rep.faces > 100);
    assert_eq!(quadrants, 4, "the panels go all around");
    // Measured 4 of 759 invalid, all hexagons beside the parabolic circle (z = 1.96 m, where K
    // changes sign), none at the seam: a regression shows as more.
    assert!(
        rep.invalid_faces * 100 <= rep.faces,
        "{} invalid",
        rep.invalid_faces
    );
    assert!(rep.max_planarity <= 1e-10, "{}", rep.max_planarity);
    let missed = goals.shortfall(
        &r.mesh,
        rep.max_planarity,
        rep.iterations,
        rep.invalid_faces,
    );
    assert_eq!(
        missed.is_some(),
        rep.invalid_faces > 0 || rep.max_planarity > 1e-10,
        "{missed:?}"
    );
}
