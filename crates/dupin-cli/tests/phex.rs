//! End-to-end tests of `dupin phex`.

mod common;
use common::{dupin, listed_scenes, tmp};

#[test]
fn lists_every_contract_scene() {
    let names = listed_scenes("phex");
    for want in [
        "cyclide-architecture",
        "sphere-radial",
        "sphere-diverging",
        "sphere-spiral",
        "hyperboloid-invalid",
        "hyperboloid-valid",
        "cyclide-progressive",
        "cyclide-prescribed",
        "vase-bottom-up",
        "vase-longitudinal",
        "torus-no-bound",
        "torus-bound",
        "minimal-surface",
        "convex-loop",
        "freeform-parabolic",
        "cylinder-developable",
    ] {
        assert!(names.iter().any(|n| n == want), "{want}");
    }
}

#[test]
fn scene_writes_obj_and_contract_report() {
    let mesh = tmp("hv.obj");
    let report = tmp("hv.json");
    let o = dupin(&[
        "phex",
        "--scene",
        "hyperboloid-valid",
        "--out",
        mesh.to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(String::from_utf8_lossy(&o.stdout).lines().count(), 1);
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
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
    let obj = std::fs::read_to_string(&mesh).unwrap();
    let parsed = dupin_core::mesh::parse_obj(&obj).unwrap();
    assert_eq!(parsed.num_faces() as u64, r["faces"].as_u64().unwrap());
    let _ = std::fs::remove_file(mesh);
    let _ = std::fs::remove_file(report);
}

#[test]
fn surface_with_parameters_and_options() {
    let mesh = tmp("torus.obj");
    let o = dupin(&[
        "phex",
        "--surface",
        "torus",
        "--set",
        "R=3",
        "--set",
        "r=1",
        "--method",
        "prescribed",
        "--size",
        "0.4",
        "--no-optimize",
        "--out",
        mesh.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let _ = std::fs::remove_file(mesh);
}

#[test]
fn bad_input_exits_2_with_one_error_line() {
    let mesh = tmp("bad.obj");
    let m = mesh.to_str().unwrap();
    for args in [
        vec!["phex", "--scene", "no-such-scene", "--out", m],
        vec!["phex", "--surface", "no-such-surface", "--out", m],
        vec!["phex", "--surface", "torus", "--set", "r=5", "--out", m],
        vec![
            "phex",
            "--scene",
            "torus-bound",
            "--size",
            "100",
            "--out",
            m,
        ],
        vec![
            "phex",
            "--scene",
            "torus-bound",
            "--size",
            "1e-9",
            "--out",
            m,
        ],
        vec!["phex", "--scene", "torus-bound", "--size", "-1", "--out", m],
        vec![
            "phex",
            "--scene",
            "torus-bound",
            "--method",
            "magic",
            "--out",
            m,
        ],
        vec!["phex", "--scene", "torus-bound"],
        // A first field along an asymptotic (self-conjugate) direction: no valid triangulation.
        vec![
            "phex",
            "--surface",
            "hyperboloid",
            "--field-angle",
            "45",
            "--out",
            m,
        ],
        vec![
            "phex",
            "--scene",
            "torus-bound",
            "--field-angle",
            "120",
            "--out",
            m,
        ],
        vec![
            "phex",
            "--scene",
            "sphere-radial",
            "--field-angle",
            "10",
            "--out",
            m,
        ],
        vec![
            "phex",
            "--scene",
            "torus-bound",
            "--iterations",
            "5000",
            "--out",
            m,
        ],
        vec![
            "phex",
            "--surface",
            "freeform-translational",
            "--set",
            "amplitude=7",
            "--out",
            m,
        ],
        vec![
            "phex",
            "--surface",
            "freeform-translational",
            "--set",
            "wobble=0.1",
            "--out",
            m,
        ],
    ] {
        let o = dupin(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
        assert!(err.starts_with("error:"), "{args:?}: {err}");
    }
}

#[test]
fn field_angle_extension_and_boundary_faces() {
    let mesh = tmp("fa.obj");
    let report = tmp("fa.json");
    let run = |surface: &str, extra: &[&str]| {
        let mut args = vec![
            "phex",
            "--surface",
            surface,
            "--size",
            "0.2",
            "--out",
            mesh.to_str().unwrap(),
            "--report",
            report.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        let o = dupin(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let r: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
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
    let _ = std::fs::remove_file(mesh);
    let _ = std::fs::remove_file(report);
}
