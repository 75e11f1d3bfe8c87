//! End-to-end tests of `dupin pq` and `dupin offset`.

mod common;
use common::{documented_scenes, dupin, listed_scenes, run_reported, tmp};

#[test]
fn lists_the_contract_scenes() {
    let documented = documented_scenes("pq");
    assert!(documented.len() >= 5, "{documented:?}");
    assert_eq!(listed_scenes("pq"), documented);
}

#[test]
fn conical_station_then_offset_with_support() {
    let station = run_reported("station", &["pq", "--scene", "conical-station"]);
    let r = station.ok();
    assert!(r["max_planarity"].as_f64().unwrap() <= 1e-10);
    assert!(r["conical_residual"].as_f64().unwrap() <= 1e-10);
    let mesh = tmp("station.obj");
    std::fs::write(&mesh, station.out.as_deref().unwrap()).unwrap();

    let beams = tmp("station-beams.obj");
    let offset = run_reported(
        "station-off",
        &[
            "offset",
            "--input",
            mesh.to_str().unwrap(),
            "--distance",
            "0.05",
            "--support",
            beams.to_str().unwrap(),
        ],
    );
    let r = offset.ok();
    assert!(r["max_distance_error"].as_f64().unwrap() <= 1e-9 * 0.05 * 10.0);
    assert!(r["warnings"].as_array().unwrap().is_empty());
    assert!(std::fs::read_to_string(&beams).unwrap().contains("\nf "));
    // Every beam planar, the boundary ones included.
    let sp = r["support_max_planarity"].as_f64().unwrap();
    assert!(sp <= 1e-10, "support_max_planarity {sp}");
    for p in [mesh, beams] {
        let _ = std::fs::remove_file(p);
    }
}

#[test]
fn unknown_scene_and_bad_distance_exit_2() {
    let out = tmp("x.obj");
    let o = dupin(&["pq", "--scene", "nope", "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).starts_with("error:"));
    let input = tmp("in.obj");
    std::fs::write(&input, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n").unwrap();
    let o = dupin(&[
        "offset",
        "--input",
        input.to_str().unwrap(),
        "--distance",
        "nan",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    // A non-planar input is offset anyway, with warnings in the report (exit 0).
    std::fs::write(&input, "v 0 0 0\nv 1 0 0\nv 1 1 0.3\nv 0 1 0\nf 1 2 3 4\n").unwrap();
    let warned = run_reported(
        "warn",
        &[
            "offset",
            "--input",
            input.to_str().unwrap(),
            "--distance",
            "0.1",
        ],
    );
    let w = warned.ok()["warnings"].as_array().unwrap().clone();
    assert!(
        w.iter().any(|x| x.as_str().unwrap().contains("not planar")),
        "{w:?}"
    );
    for p in [input, out] {
        let _ = std::fs::remove_file(p);
    }
}
