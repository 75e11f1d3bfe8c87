//! End-to-end tests of `dupin surface-info` against the outside contract.

mod common;
use common::{command_line, dupin_text as dupin, json as json_file, refused, tmp};

/// The one JSON object `surface-info` prints on stdout.
fn json(s: &str) -> serde_json::Value {
    serde_json::from_str(s.trim()).expect("one JSON object on stdout")
}

fn arr(v: &serde_json::Value) -> [f64; 3] {
    let a = v.as_array().expect("array");
    [
        a[0].as_f64().unwrap(),
        a[1].as_f64().unwrap(),
        a[2].as_f64().unwrap(),
    ]
}

#[test]
fn torus_matches_the_contract_parametrisation_and_closed_forms() {
    let (code, out, err) = dupin(&command_line(
        "surface-info",
        "--surface torus --set R=3 --set r=1 --at 0.5,0.4",
        "",
    ));
    assert_eq!(code, 0, "{err}");
    assert_eq!(out.lines().count(), 1, "one line on stdout");
    let j = json(&out);
    let (u, v) = (0.5f64, 0.4f64);
    let w = 3.0 + v.cos();
    let p = arr(&j["point"]);
    let want = [w * u.cos(), w * u.sin(), v.sin()];
    for i in 0..3 {
        assert!((p[i] - want[i]).abs() < 1e-12);
    }
    // Outward normal along Pu x Pv.
    let n = arr(&j["normal"]);
    let nw = [v.cos() * u.cos(), v.cos() * u.sin(), v.sin()];
    for i in 0..3 {
        assert!((n[i] - nw[i]).abs() < 1e-12);
    }
    let (k1, k2) = (j["k1"].as_f64().unwrap(), j["k2"].as_f64().unwrap());
    let (ku, kv) = (-v.cos() / w, -1.0);
    assert!((k1 - ku.max(kv)).abs() < 1e-12 && (k2 - ku.min(kv)).abs() < 1e-12);
    assert!((j["gaussian"].as_f64().unwrap() - k1 * k2).abs() < 1e-12);
    assert!((j["mean"].as_f64().unwrap() - 0.5 * (k1 + k2)).abs() < 1e-12);
    assert_eq!(j["type"], "elliptic");
    for key in ["dir1", "dir2"] {
        let d = arr(&j[key]);
        assert!(((d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() - 1.0).abs() < 1e-12);
    }
}

#[test]
fn point_types_and_negative_parameters() {
    let t = |args: &[&str]| json(&dupin(args).1)["type"].as_str().unwrap().to_string();
    assert_eq!(
        t(&["surface-info", "--surface", "torus", "--at", "0,3.0"]),
        "hyperbolic"
    );
    assert_eq!(
        t(&[
            "surface-info",
            "--surface",
            "hyperboloid",
            "--at",
            "-1.0,-0.5"
        ]),
        "hyperbolic"
    );
    assert_eq!(
        t(&["surface-info", "--surface", "cylinder", "--at", "1,0.5"]),
        "parabolic"
    );
    assert_eq!(
        t(&["surface-info", "--surface", "vase", "--at", "0.3,1.5"]),
        "parabolic"
    );
    assert_eq!(
        t(&[
            "surface-info",
            "--surface",
            "sphere",
            "--set",
            "radius=2",
            "--at",
            "1,0.3"
        ]),
        "elliptic"
    );
    let j = json(
        &dupin(&[
            "surface-info",
            "--surface",
            "hyperboloid",
            "--set",
            "a=2",
            "--set",
            "c=0.5",
            "--at",
            "1.0,-0.5",
        ])
        .1,
    );
    let p = arr(&j["point"]);
    let (u, v) = (1.0f64, -0.5f64);
    assert!((p[0] - 2.0 * v.cosh() * u.cos()).abs() < 1e-12);
    assert!((p[2] - 0.5 * v.sinh()).abs() < 1e-12);
}

#[test]
fn list_names_every_surface_with_parameters() {
    let (code, out, _) = dupin(&["surface-info", "--list"]);
    assert_eq!(code, 0);
    let names: Vec<&str> = out.lines().map(|l| l.split(' ').next().unwrap()).collect();
    for n in [
        "sphere",
        "torus",
        "hyperboloid",
        "ellipsoid",
        "hyperbolic-paraboloid",
        "dupin-cyclide",
        "vase",
        "catenoid",
        "enneper",
        "cylinder",
        "bspline",
    ] {
        assert!(names.contains(&n), "{n} missing from --list");
    }
    assert!(out.contains("R=2") && out.contains("r=0.7"));
}

#[test]
fn report_file_has_the_fields_and_seconds() {
    let path = tmp("surface-info.json");
    let p = path.to_str().unwrap();
    let (code, out, _) = dupin(&[
        "surface-info",
        "--surface",
        "enneper",
        "--at",
        "0.2,0.1",
        "--report",
        p,
    ]);
    assert_eq!(code, 0);
    let r = json_file(&path);
    std::fs::remove_file(&path).ok();
    let o = json(&out);
    for key in [
        "point", "normal", "k1", "k2", "dir1", "dir2", "gaussian", "mean", "type",
    ] {
        assert_eq!(r[key], o[key], "{key}");
    }
    assert!(r["seconds"].as_f64().unwrap() >= 0.0);
}

#[test]
fn bad_input_exits_2_with_one_error_line() {
    // One command line a case.
    for line in [
        "--surface klein --at 0,0",
        "--surface torus --set q=1 --at 0,0",
        "--surface torus --set r=5 --at 0,0",
        "--surface torus --set r --at 0,0",
        "--surface torus --set r=nan --at 0,0",
        "--surface torus --at 0",
        "--surface torus --at nan,1",
        "--surface sphere --at 0,9",
        "--surface sphere --at 0,1.5707963267948966",
        "--surface torus",
        "--at 0,0",
    ] {
        let args = command_line("surface-info", line, "");
        let (out, _) = refused(&args);
        assert!(out.is_empty(), "{args:?}");
    }
}
