//! End-to-end tests of `dupin phex`.

mod common;
use common::{
    command_line, documented_scenes, dupin_ok, listed_scenes, refused, run_reported, tmp,
};

#[test]
fn lists_every_contract_scene() {
    let documented = documented_scenes("phex");
    assert!(documented.len() >= 5, "{documented:?}");
    assert_eq!(listed_scenes("phex"), documented);
}

#[test]
fn scene_writes_obj_and_contract_report() {
    let run = run_reported("hv", &["phex", "--scene", "hyperboloid-valid"]);
    let r = run.ok();
    assert_eq!(run.stdout().lines().count(), 1);
    for key in [
        "vertices",
        "faces",
        "face_sizes",
        "max_planarity",
        "invalid_faces",
        "iterations",
        "max_surface_distance",
        "bbox_diagonal",
        "seconds",
    ] {
        assert!(r.get(key).is_some(), "missing {key}");
    }
    assert!(r["max_planarity"].as_f64().unwrap() <= 1e-10);
    assert_eq!(r["invalid_faces"].as_u64().unwrap(), 0);
    assert!(r["face_sizes"]["6"].as_u64().unwrap() > 100);
    assert_eq!(run.mesh().num_faces() as u64, r["faces"].as_u64().unwrap());
}

#[test]
fn surface_with_parameters_and_options() {
    let mesh = tmp("torus.obj");
    dupin_ok(&command_line(
        "phex",
        "--surface torus --set R=3 --set r=1 --method prescribed --size 0.4 --no-optimize --out OUT",
        mesh.to_str().unwrap(),
    ));
    let _ = std::fs::remove_file(mesh);
}

#[test]
fn bad_input_exits_2_with_one_error_line() {
    let mesh = tmp("bad.obj");
    // One command line a case, OUT standing for the output file.
    for line in [
        "--scene no-such-scene --out OUT",
        "--surface no-such-surface --out OUT",
        "--surface torus --set r=5 --out OUT",
        "--scene torus-bound --size 100 --out OUT",
        "--scene torus-bound --size 1e-9 --out OUT",
        "--scene torus-bound --size -1 --out OUT",
        "--scene torus-bound --method magic --out OUT",
        "--scene torus-bound",
        // A first field along an asymptotic (self-conjugate) direction: no valid triangulation.
        "--surface hyperboloid --field-angle 45 --out OUT",
        "--scene torus-bound --field-angle 120 --out OUT",
        "--scene sphere-radial --field-angle 10 --out OUT",
        "--scene torus-bound --iterations 5000 --out OUT",
        "--surface freeform-translational --set amplitude=7 --out OUT",
        "--surface freeform-translational --set wobble=0.1 --out OUT",
    ] {
        refused(&command_line("phex", line, mesh.to_str().unwrap()));
    }
}

#[test]
fn field_angle_extension_and_boundary_faces() {
    let run = |surface: &str, extra: &[&str]| {
        let mut args = vec!["phex", "--surface", surface, "--size", "0.2"];
        args.extend_from_slice(extra);
        let run = run_reported("fa", &args);
        let r = run.ok();
        assert!(r["max_planarity"].as_f64().unwrap() <= 1e-10, "{r}");
        assert_eq!(r["invalid_faces"].as_u64().unwrap(), 0, "{r}");
        r["faces"].as_u64().unwrap()
    };
    // Method 2 along a field at -15 degrees from the principal direction (negative value).
    assert!(run("torus", &["--field-angle", "-15"]) > 100);
    // Boundary faces are on by default: the open sphere band has more faces with them.
    let with = run("sphere", &[]);
    let without = run("sphere", &["--no-boundary-faces"]);
    assert!(with > without, "{with} vs {without}");
}

/// A result that misses what was asked exits 3 with the output and the report written: faces
/// not yet planar when the iterations run out, and self-intersecting faces where the paper's
/// validity was asked for. A scene made to show invalid faces (Fig. 11) is not a miss.
#[test]
fn missed_results_exit_3_with_output_and_reason() {
    let r = run_reported(
        "phex-cap",
        &["phex", "--scene", "vase-bottom-up", "--iterations", "1"],
    );
    let rep = r.unmet();
    assert!(
        rep["reason"]
            .as_str()
            .unwrap()
            .contains("above the tolerance"),
        "{rep}"
    );
    assert!(r.stderr().contains("max_planarity"));
    let r = run_reported(
        "phex-invalid",
        &[
            "phex",
            "--surface",
            "torus",
            "--method",
            "progressive",
            "--size",
            "0.2",
            "--no-optimize",
        ],
    );
    let rep = r.unmet();
    assert!(rep["invalid_faces"].as_u64().unwrap() > 0);
    assert!(
        rep["reason"]
            .as_str()
            .unwrap()
            .contains("self-intersecting"),
        "{rep}"
    );
    let shown = run_reported("phex-shown", &["phex", "--scene", "hyperboloid-invalid"]);
    let rep = shown.ok();
    assert!(rep["invalid_faces"].as_u64().unwrap() > 0);
    assert_eq!(rep["converged"], true);
}

/// A design from a CAD tool: a bicubic NURBS dome 12 m x 12 m in metres, written as
/// the documented JSON; its control heights are f(x) + g(y), so the parameter lines are
/// conjugate and method 2 applies.
fn nurbs_dome_json() -> String {
    let knots = serde_json::json!([0, 0, 0, 0, 1, 2, 3, 3, 3, 3]);
    let points: Vec<Vec<[f64; 3]>> = (0..6)
        .map(|i| {
            (0..6)
                .map(|j| {
                    let (x, y) = (2.4 * i as f64 - 6.0, 2.4 * j as f64 - 6.0);
                    [x, y, 3.0 - (x * x + y * y) / 24.0]
                })
                .collect()
        })
        .collect();
    serde_json::json!({
        "degree_u": 3, "degree_v": 3, "knots_u": knots, "knots_v": knots,
        "control_points": points, "unit": "m"
    })
    .to_string()
}

#[test]
fn input_panels_a_nurbs_design_in_its_unit() {
    let design = tmp("dome-design.json");
    std::fs::write(&design, nurbs_dome_json()).unwrap();
    let path = design.to_str().unwrap();
    let run = run_reported(
        "dome",
        &[
            "phex",
            "--input",
            path,
            "--method",
            "prescribed",
            "--size",
            "0.8",
        ],
    );
    let r = run.ok();
    assert_eq!(r["unit"], "m");
    assert_eq!(r["invalid_faces"], 0);
    assert!(r["max_planarity"].as_f64().unwrap() <= 1e-10);
    assert!(r["faces"].as_u64().unwrap() > 100, "{r}");
    // The panels lie on the 12 m dome, within 0.5% of its diagonal.
    assert!(
        r["max_surface_distance"].as_f64().unwrap() <= 0.005 * r["bbox_diagonal"].as_f64().unwrap()
    );
    assert!(run.stdout().contains("dome-design.json"));
    let out = tmp("dome-bad.obj");
    let out = out.to_str().unwrap();
    // Malformed JSON names the file and the line; panels are sent to planarize.
    let broken = tmp("broken.json");
    std::fs::write(&broken, "{\n  \"degree_u\": 3,\n  \"degree_v\": x\n}").unwrap();
    let (_, err) = refused(&["phex", "--input", broken.to_str().unwrap(), "--out", out]);
    assert!(
        err.contains("broken.json") && err.contains("line 3"),
        "{err}"
    );
    let mesh = tmp("mesh.obj");
    std::fs::write(&mesh, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n").unwrap();
    let (_, err) = refused(&["phex", "--input", mesh.to_str().unwrap(), "--out", out]);
    assert!(err.contains("mesh.obj: face 1 has 4 corners"), "{err}");
    assert!(err.contains("planarised"), "{err}");
    refused(&["phex", "--input", path, "--set", "R=2", "--out", out]);
    refused(&[
        "phex",
        "--input",
        path,
        "--scene",
        "torus-bound",
        "--out",
        out,
    ]);
    refused(&["phex", "--input", "/no/such/file.json", "--out", out]);
    for p in [design, broken, mesh] {
        let _ = std::fs::remove_file(p);
    }
}

/// The same dome as a triangle mesh with no UVs (an exporter's OBJ): fitted, then panelled; the
/// report gives the fit's distances and the panels' distance to the mesh.
#[test]
fn input_fits_and_panels_a_triangle_mesh() {
    let n = 30;
    let mut obj = String::from("# dome, metres\n");
    for i in 0..=n {
        for j in 0..=n {
            let (x, y) = (
                12.0 * i as f64 / n as f64 - 6.0,
                12.0 * j as f64 / n as f64 - 6.0,
            );
            obj += &format!("v {x} {y} {}\n", 3.0 - (x * x + y * y) / 24.0);
        }
    }
    let id = |i: usize, j: usize| i * (n + 1) + j + 1;
    for i in 0..n {
        for j in 0..n {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            obj += &format!("f {a} {b} {c}\nf {a} {c} {d}\n");
        }
    }
    let design = tmp("dome-mesh.obj");
    std::fs::write(&design, obj).unwrap();
    let run = run_reported(
        "dome-mesh",
        &["phex", "--input", design.to_str().unwrap(), "--size", "0.5"],
    );
    let r = run.ok();
    assert_eq!(r["invalid_faces"], 0, "{r}");
    assert!(r["max_planarity"].as_f64().unwrap() <= 1e-10);
    // A 30 x 30 grid of a paraboloid: the fit is within a few millimetres of its vertices.
    assert!(r["fit_max_distance"].as_f64().unwrap() < 5e-3, "{r}");
    assert!(r["fit_mean_distance"].as_f64().unwrap() <= r["fit_max_distance"].as_f64().unwrap());
    let diagonal = r["bbox_diagonal"].as_f64().unwrap();
    assert!(
        r["max_input_distance"].as_f64().unwrap() <= 0.005 * diagonal,
        "{r}"
    );
    let _ = std::fs::remove_file(design);
}

/// A vault closed around (cylinder topology: two boundary loops) as a triangle OBJ: cut open
/// along a seam, fitted closed around and panelled all around, where it used to be refused.
#[test]
fn input_fits_and_panels_a_cylinder_mesh() {
    let (nu, nv) = (64, 24);
    let mut obj = String::from("# vault, metres\n");
    for j in 0..=nv {
        for i in 0..nu {
            let a = std::f64::consts::TAU * i as f64 / nu as f64;
            let z = 6.0 * j as f64 / nv as f64;
            let r = 3.0 + 0.4 * (0.8 * z).cos();
            obj += &format!("v {} {} {z}\n", r * a.cos(), r * a.sin());
        }
    }
    let id = |i: usize, j: usize| j * nu + i % nu + 1;
    for j in 0..nv {
        for i in 0..nu {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            obj += &format!("f {a} {b} {c}\nf {a} {c} {d}\n");
        }
    }
    let design = tmp("vault-mesh.obj");
    std::fs::write(&design, obj).unwrap();
    let run = run_reported(
        "vault-mesh",
        &[
            "phex",
            "--input",
            design.to_str().unwrap(),
            "--size",
            "0.45",
        ],
    );
    // Measured: 378 faces, none invalid, planar to 4e-15, 0.23% of the diagonal from the mesh,
    // the layers laid along the axis across the parabolic circle at z = 1.96 m. Beside that
    // circle some sizes fold a few hexagons (6 of 342 at 0.5, 29 of 528 at 0.4): those runs
    // exit 3 with the panels and the report written (`missed_results_exit_3_...`).
    let r = run.ok();
    assert_eq!(r["invalid_faces"], 0, "{r}");
    assert!(r["faces"].as_u64().unwrap() > 300, "{r}");
    assert!(r["max_planarity"].as_f64().unwrap() <= 1e-10, "{r}");
    assert!(r["fit_max_distance"].as_f64().unwrap() < 5e-3, "{r}");
    let diagonal = r["bbox_diagonal"].as_f64().unwrap();
    assert!(
        r["max_input_distance"].as_f64().unwrap() <= 0.005 * diagonal,
        "{r}"
    );
    let _ = std::fs::remove_file(design);
}

/// The 20 x 15 m translational roof with control point (6, 4) raised by `dz` metres, as the
/// documented JSON.
fn roof_json(dz: f64) -> String {
    use dupin_core::surface::NurbsSurface;
    let mut roof =
        NurbsSurface::try_from(dupin_core::scenes::benchmark_meshes::nurbs_roof()).unwrap();
    let nv = roof.control_net_size().1;
    let [x, y, z] = roof.control_points()[6 * nv + 4];
    roof.set_control_point(6 * nv + 4, [x, y, z + dz].into())
        .unwrap();
    roof.to_json()
}

/// `--follow ORIGINAL`: a reshaped design panelled afresh folds hexagons where the move bent
/// the parameter lines away from conjugate (exit 3); following the original's panels gives
/// planar, simple ones (exit 0), as the page's control-point drag does.
#[test]
fn follow_panels_a_reshaped_design_from_the_original() {
    let (original, reshaped) = (tmp("roof-original.json"), tmp("roof-raised.json"));
    std::fs::write(&original, roof_json(0.0)).unwrap();
    std::fs::write(&reshaped, roof_json(0.3)).unwrap();
    let (original, reshaped) = (original.to_str().unwrap(), reshaped.to_str().unwrap());
    let fresh = run_reported(
        "roof-fresh",
        &["phex", "--input", reshaped, "--size", "0.8"],
    );
    let fresh = fresh.unmet();
    assert!(fresh["invalid_faces"].as_u64().unwrap() > 0, "{fresh}");
    assert!(fresh.get("followed").is_none());
    let run = run_reported(
        "roof-followed",
        &[
            "phex", "--input", reshaped, "--follow", original, "--size", "0.8",
        ],
    );
    let r = run.ok();
    assert_eq!(r["followed"], true);
    assert_eq!(r["invalid_faces"], 0, "{r}");
    assert!(r["max_planarity"].as_f64().unwrap() <= 1e-10, "{r}");
    assert_eq!(r["faces"], fresh["faces"]);
    // The panels lie on the reshaped roof, not the original: within 1% of the diagonal.
    assert!(
        r["max_surface_distance"].as_f64().unwrap() <= 0.01 * r["bbox_diagonal"].as_f64().unwrap(),
        "{r}"
    );
    // An original whose own panels fold cannot be followed: said, then panelled afresh.
    let unfollowed = run_reported(
        "roof-unfollowed",
        &[
            "phex", "--input", original, "--follow", reshaped, "--size", "0.8",
        ],
    );
    let u = unfollowed.ok();
    assert_eq!(u["followed"], false);
    assert!(
        u["follow_note"]
            .as_str()
            .unwrap()
            .contains("self-intersecting faces; the design is panelled afresh"),
        "{u}"
    );
    assert!(
        unfollowed.stderr().starts_with("note: "),
        "{}",
        unfollowed.stderr()
    );
    // A design with another net is no reshape of the original; --follow needs --input.
    let dome = tmp("follow-dome.json");
    std::fs::write(&dome, nurbs_dome_json()).unwrap();
    let out = tmp("follow-bad.obj");
    let out = out.to_str().unwrap();
    let (_, err) = refused(&[
        "phex",
        "--input",
        dome.to_str().unwrap(),
        "--follow",
        original,
        "--size",
        "0.8",
        "--out",
        out,
    ]);
    assert!(err.contains("only control points move"), "{err}");
    refused(&[
        "phex",
        "--scene",
        "torus-bound",
        "--follow",
        original,
        "--out",
        out,
    ]);
    for p in [original, reshaped, dome.to_str().unwrap()] {
        let _ = std::fs::remove_file(p);
    }
}
