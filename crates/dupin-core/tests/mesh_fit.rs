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
        rep.max_planarity,
        rep.iterations,
        rep.invalid_faces,
        rep.faces,
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
