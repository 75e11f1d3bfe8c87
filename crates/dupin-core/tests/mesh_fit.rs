//! A triangle mesh of a smooth design, with no UVs, fitted by a smooth surface
//! (`surface/mesh_fit.rs`) and panelled by P-Hex: the fit is close to the mesh, the map is one to
//! one, and the panels are planar, valid and close to the input mesh.

mod common;

use dupin_core::Vec3;
use dupin_core::mesh::PolyMesh;
use dupin_core::scenes::benchmark_meshes::{
    bump_triangle_mesh, dome_triangle_mesh, translational_roof_triangle_mesh,
};
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

/// A sliver triangle (three nearly collinear vertices, an angle of almost 180 degrees) gives its
/// apex a mean-value weight near 1e16; the map must still keep every vertex inside the square
/// (found by the `mesh_fit` fuzz target: a vertex was put at u = 18).
#[test]
fn a_sliver_triangle_keeps_every_parameter_inside_the_square() {
    let data = include_bytes!(
        "../../../fuzz/regressions/mesh_fit/crash-87c6a8a0eddffdbd42961af247a5dcfb2bf7cce4"
    );
    let options = dupin_core::mesh::io::ImportOptions::default();
    let mesh = dupin_core::mesh::io::read_mesh("sliver.obj", data, &options)
        .unwrap()
        .mesh;
    // The sliver: vertices 11, 16 and 12 (OBJ numbering) on one line to 1e-15.
    let [a, b, c] = [10, 15, 11].map(|v| mesh.positions[v]);
    assert!((b - a).cross(&(c - a)).norm() < 1e-12 * (b - a).norm() * (c - a).norm());
    let fit = fit_mesh_surface(&mesh, &MeshFitOptions::default()).unwrap();
    for t in &fit.uv {
        assert!(
            (-1e-12..=1.0 + 1e-12).contains(&t.x) && (-1e-12..=1.0 + 1e-12).contains(&t.y),
            "{t:?} is outside the square"
        );
    }
    // The one vertex whose neighbours all lie on the side v = 1 is there too.
    assert!((fit.uv[6].y - 1.0).abs() < 1e-12, "{:?}", fit.uv[6]);
}

#[test]
fn phex_panels_the_fitted_dome_close_to_the_mesh() {
    use dupin_core::Stepper;
    use dupin_core::phex::{PhexConfig, PhexPipeline};
    let mesh = dome_triangle_mesh(104, 2);
    let fit = fit_mesh_surface(&mesh, &MeshFitOptions::default()).unwrap();
    let config = PhexConfig::for_fitted_mesh("dome", fit.surface, Some(0.3));
    let r = PhexPipeline::new(config).and_then(Stepper::finish).unwrap();
    let rep = &r.report;
    eprintln!(
        "{} faces, {} invalid, planarity {:e}",
        rep.faces, rep.invalid_faces, rep.max_planarity
    );
    assert!(rep.faces > 300);
    assert_eq!(rep.invalid_faces, 0);
    assert!(rep.max_planarity <= 1e-10);
    let diagonal = mesh.bbox_diagonal();
    let far = farthest_from(&mesh, &r.mesh);
    eprintln!("max distance to the input mesh {far:.3e} of a {diagonal:.2} m diagonal");
    assert!(far <= 0.005 * diagonal, "{far}");
}

/// The largest distance from a vertex of `panels` to the triangle mesh `input`.
fn farthest_from(input: &PolyMesh, panels: &PolyMesh) -> f64 {
    let input = MeshSurface::from_mesh(input.clone());
    panels
        .positions
        .iter()
        .map(|p| input.closest_point(p).unwrap().distance)
        .fold(0.0, f64::max)
}

/// Fits `mesh` (within a thousandth of its diagonal) and panels the fit as `--input` and the
/// page do (`PhexConfig::for_fitted_mesh`) at `size`: the configuration, the result and its
/// faces with K > 0 and with K < 0.
fn fit_and_panel(
    mesh: &PolyMesh,
    size: f64,
) -> (
    dupin_core::phex::PhexConfig,
    dupin_core::phex::PhexResult,
    [usize; 2],
) {
    use dupin_core::Stepper;
    use dupin_core::phex::{PhexConfig, PhexPipeline};
    assert!(mesh.num_faces() >= 20_000);
    let fit = fit_mesh_surface(mesh, &MeshFitOptions::default()).unwrap();
    let diagonal = mesh.bbox_diagonal();
    assert!(fit.max_distance < 1e-3 * diagonal, "{}", fit.max_distance);
    let config = PhexConfig::for_fitted_mesh("design", fit.surface, Some(size));
    let r = PhexPipeline::new(config.clone())
        .and_then(Stepper::finish)
        .unwrap();
    let rep = &r.report;
    let gaussian = |s: f64| rep.per_face.iter().filter(|f| f.gaussian * s > 0.0).count();
    let signs = [gaussian(1.0), gaussian(-1.0)];
    eprintln!(
        "{} faces ({} with K > 0, {} with K < 0), {} invalid, planarity {:e}",
        rep.faces, signs[0], signs[1], rep.invalid_faces, rep.max_planarity
    );
    (config, r, signs)
}

/// A mixed-curvature freeform mesh with a conjugate network (a translational roof, whose x and
/// y lines are conjugate, K > 0 on one side of a parabolic line and K < 0 on the other), over
/// 20 000 triangles and no UVs: the paper's setting (sections 5.2 and 7: a singularity-free
/// conjugate network), so every face is valid, planar to 1e-10 and within 0.5% of the
/// diagonal of the mesh. Two jitters whose fits take u along x and along y: either way the
/// layers are laid across the parabolic line (`for_fitted_mesh`; along the line, one of them
/// gave 10 invalid faces of 1 532).
#[test]
fn phex_panels_a_fitted_mixed_curvature_mesh_with_a_conjugate_network() {
    let mut swaps = vec![];
    for seed in [2, 3] {
        let mesh = translational_roof_triangle_mesh(104, seed);
        let (config, r, [elliptic, hyperbolic]) = fit_and_panel(&mesh, 0.3);
        swaps.push(config.swap);
        let (rep, diagonal) = (&r.report, mesh.bbox_diagonal());
        assert!(elliptic > 500 && hyperbolic > 500, "both signs of K");
        assert_eq!(rep.invalid_faces, 0);
        assert!(rep.max_planarity <= 1e-10, "{}", rep.max_planarity);
        let far = farthest_from(&mesh, &r.mesh);
        assert!(far <= 0.005 * diagonal, "{far} of {diagonal}");
    }
    assert_eq!(
        swaps,
        [false, true],
        "the two fits' u runs along x, then along y"
    );
}

/// The 20 m x 15 m translational NURBS roof (`nurbs_roof`: K > 0 for x < 0, K < 0 for x > 0)
/// sampled as 24 200 triangles and fitted: on a rectangle the mean-value parameter lines
/// depart further from the roof's conjugate x and y lines than on the square above, and where
/// the Dupin indicatrix degenerates, beside the parabolic line x = 0, that is enough to fold
/// a few hexagons: every invalid face lies there (|K| at most a tenth of the largest, within
/// 1.5 m of the line; measured 14 of 3 330 at size 0.3, at x = -0.7 and x = +0.8 m), none
/// where K is clearly of one sign, as Propositions 4 and 5 promise. The run reports them.
#[test]
fn on_a_fitted_roof_mesh_only_faces_beside_the_parabolic_line_are_invalid() {
    use dupin_core::Stepper;
    use dupin_core::phex::{PhexConfig, PhexPipeline};
    use dupin_core::scenes::benchmark_meshes::nurbs_roof;
    use dupin_core::surface::{NurbsSurface, Surface};
    let roof = NurbsSurface::try_from(nurbs_roof()).unwrap();
    let d = roof.domain();
    let n = 110;
    let at = |k: usize, r: (f64, f64)| r.0 + (r.1 - r.0) * k as f64 / n as f64;
    let positions = (0..=n)
        .flat_map(|i| (0..=n).map(move |j| (i, j)))
        .map(|(i, j)| roof.derivatives(at(i, d.u), at(j, d.v)).p)
        .collect();
    let id = |i: usize, j: usize| (i * (n + 1) + j) as u32;
    let faces: Vec<[u32; 3]> = (0..n)
        .flat_map(|i| (0..n).map(move |j| (i, j)))
        .flat_map(|(i, j)| {
            [
                [id(i, j), id(i + 1, j), id(i + 1, j + 1)],
                [id(i, j), id(i + 1, j + 1), id(i, j + 1)],
            ]
        })
        .collect();
    let mesh = PolyMesh::new(positions, faces).unwrap();
    assert!(mesh.num_faces() >= 20_000);
    let fit = fit_mesh_surface(&mesh, &MeshFitOptions::default()).unwrap();
    let config = PhexConfig::for_fitted_mesh("roof", fit.surface, Some(0.3));
    let r = PhexPipeline::new(config).and_then(Stepper::finish).unwrap();
    let rep = &r.report;
    let largest = rep
        .per_face
        .iter()
        .fold(0.0, |a: f64, f| a.max(f.gaussian.abs()));
    let beside: Vec<(f64, f64)> = (0..rep.faces)
        .filter(|&i| !rep.per_face[i].simple)
        .map(|i| {
            let f = r.mesh.face(i);
            let x = f
                .iter()
                .map(|&v| r.mesh.positions[v as usize].x)
                .sum::<f64>()
                / f.len() as f64;
            (x, rep.per_face[i].gaussian)
        })
        .collect();
    eprintln!(
        "{} faces, {} invalid at (x, K) {beside:?}, largest |K| {largest:.2e}, planarity {:e}",
        rep.faces, rep.invalid_faces, rep.max_planarity
    );
    assert!(rep.faces > 3000);
    assert!(
        rep.invalid_faces * 100 <= rep.faces,
        "{}",
        rep.invalid_faces
    );
    for (x, k) in beside {
        assert!(x.abs() <= 1.5 && k.abs() <= 0.1 * largest, "x {x}, K {k}");
    }
    assert!(rep.max_planarity <= 1e-10, "{}", rep.max_planarity);
    assert!(rep.max_surface_distance <= 0.005 * mesh.bbox_diagonal());
}

/// A mixed-curvature freeform with no singularity-free conjugate network (a Gaussian bump:
/// K > 0 on top, K < 0 on its flanks), of over 20 000 triangles, no UVs: outside the paper's
/// setting. A conjugate pair at a hyperbolic point has one direction on each side of the
/// asymptotic ones, so around the parabolic circle it turns once with the radial direction,
/// and a field that turns once around a loop has a singularity inside it (Poincaré-Hopf); the
/// paper's methods "assume that a singularity-free conjugate network is available" (section 7). The fit is as close as on the dome, but P-Hex
/// on it misses: the fitted parameter lines are far from conjugate, so method 2's hexagons
/// come out self-intersecting and the optimisation stalls (measured 135 of 1 572 faces invalid,
/// max planarity 5.2e-3 after 10 iterations, 143 and the same planarity after 40); the
/// principal directions, `field_angle = Some(0.0)`, stop at the umbilic on top (121 faces, 8
/// invalid). The run must say so: its shortfall (the CLI's exit 3, the page's warning) names
/// both misses.
#[test]
fn phex_on_a_fitted_mixed_curvature_mesh_reports_what_it_misses() {
    use dupin_core::phex::PhexGoals;
    let (config, r, [elliptic, hyperbolic]) = fit_and_panel(&bump_triangle_mesh(104, 3), 0.3);
    let goals = PhexGoals::of(&config, true);
    let rep = &r.report;
    assert!(elliptic > 10 && hyperbolic > 10, "both signs of K");
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
fn a_cylinder_mesh_is_cut_open_fitted_closed_and_panelled_all_around() {
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
    // The fit is closed in u, the seam's sides u = 0 and u = 1 one curve.
    use dupin_core::surface::Surface;
    assert!(fit.surface.is_closed_in_u());
    for v in [0.0, 0.3, 0.7, 1.0] {
        let (a, b) = (
            fit.surface.derivatives(0.0, v),
            fit.surface.derivatives(1.0, v),
        );
        for (x, y) in [(a.p, b.p), (a.pu, b.pu), (a.puu, b.puu)] {
            assert!(
                (x - y).norm() <= 1e-9 * (1.0 + x.norm()),
                "{x:?} {y:?} at v {v}"
            );
        }
    }
    // P-Hex panels it all around with no seam: its only boundary is the two loops.
    let config = PhexConfig::for_fitted_mesh("vault", fit.surface, Some(0.5));
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
    let seam = common::boundary_vertices_between_ends(&r.mesh, 0.8);
    assert!(
        seam.is_empty(),
        "boundary vertices away from the loops: {seam:?}"
    );
    // The layers are laid across the parabolic circle (z = 1.96 m, where K changes sign), which
    // runs along them (`for_fitted_mesh`). Measured: 380 faces; open along a seam, 4 of 759 (the
    // layers along the circle) came out invalid.
    assert_eq!(rep.invalid_faces, 0);
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
