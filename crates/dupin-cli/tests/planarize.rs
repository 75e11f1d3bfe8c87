//! End-to-end tests of `dupin planarize`.

use std::path::PathBuf;
use std::process::Command;

fn tmp(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("dupin-planarize-{}-{name}", std::process::id()))
}

fn dupin(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_dupin"))
        .args(args)
        .output()
        .expect("dupin runs")
}

/// A 6 x 6 quad grid on the saddle z = xy, rotated 30 degrees: far from planar.
fn skew_grid_obj() -> String {
    let n = 6;
    let (s, c) = 30f64.to_radians().sin_cos();
    let mut out = String::new();
    for j in 0..=n {
        for i in 0..=n {
            let a = -1.0 + 2.0 * i as f64 / n as f64;
            let b = -1.0 + 2.0 * j as f64 / n as f64;
            let (x, y) = (c * a - s * b, s * a + c * b);
            out += &format!("v {x:?} {y:?} {:?}\n", x * y);
        }
    }
    for j in 0..n {
        for i in 0..n {
            let id = |i: usize, j: usize| j * (n + 1) + i + 1;
            out += &format!(
                "f {} {} {} {}\n",
                id(i, j),
                id(i + 1, j),
                id(i + 1, j + 1),
                id(i, j + 1)
            );
        }
    }
    out
}

fn read_json(p: &PathBuf) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

#[test]
fn planarizes_a_skew_grid_and_reports_exact_fields() {
    let input = tmp("grid.obj");
    let out = tmp("grid-out.obj");
    let report = tmp("grid.json");
    std::fs::write(&input, skew_grid_obj()).unwrap();
    let o = dupin(&[
        "planarize",
        "--input",
        input.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(String::from_utf8_lossy(&o.stdout).lines().count(), 1);
    let r = read_json(&report);
    for key in [
        "vertices",
        "faces",
        "max_planarity",
        "max_move",
        "iterations",
        "seconds",
    ] {
        assert!(r.get(key).is_some(), "missing {key}");
    }
    assert_eq!(r["faces"], 36);
    assert_eq!(r["vertices"], 49);
    assert!(r["max_planarity"].as_f64().unwrap() <= 1e-10);
    assert_eq!(r["converged"], true);
    // The output OBJ is a valid mesh that re-measures as planar.
    let text = std::fs::read_to_string(&out).unwrap();
    assert_eq!(text.lines().filter(|l| l.starts_with("f ")).count(), 36);
    for p in [input, out, report] {
        let _ = std::fs::remove_file(p);
    }
}

#[test]
fn conical_mode_reports_its_residual_and_fix_boundary_keeps_boundary() {
    let input = tmp("c.obj");
    let out = tmp("c-out.obj");
    let report = tmp("c.json");
    std::fs::write(&input, skew_grid_obj()).unwrap();
    let o = dupin(&[
        "planarize",
        "--input",
        input.to_str().unwrap(),
        "--mode",
        "conical",
        "--fix-boundary",
        "--out",
        out.to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let r = read_json(&report);
    assert!(r.get("conical_residual").is_some());
    let text_in = std::fs::read_to_string(&input).unwrap();
    let text_out = std::fs::read_to_string(&out).unwrap();
    // Vertex 1 (a corner) is on the boundary: unchanged coordinates.
    assert_eq!(text_in.lines().next(), text_out.lines().next());
    for p in [input, out, report] {
        let _ = std::fs::remove_file(p);
    }
}

#[test]
fn bad_input_exits_2_with_one_error_line() {
    let input = tmp("bad.obj");
    let out = tmp("bad-out.obj");
    let cases = [
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 1\nf 1 2 3\nf 1 2 4\n",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 2\n",
        "v 0 0 0\nv 0 0 0\nv 0 1 0\nf 1 2 3\n",
    ];
    for text in cases {
        std::fs::write(&input, text).unwrap();
        let o = dupin(&[
            "planarize",
            "--input",
            input.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        assert_eq!(o.status.code(), Some(2), "{text}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.starts_with("error:"), "{err}");
    }
    // Conical mode on a mesh without interior valence-4 vertex.
    std::fs::write(&input, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0.2\nf 1 2 3 4\n").unwrap();
    let o = dupin(&[
        "planarize",
        "--input",
        input.to_str().unwrap(),
        "--mode",
        "conical",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("valence 4"));
    let _ = std::fs::remove_file(&input);
    let _ = std::fs::remove_file(&out);
}
