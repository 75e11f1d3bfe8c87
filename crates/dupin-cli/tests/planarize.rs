//! End-to-end tests of `dupin planarize`.

mod common;
use common::{dupin, json, tmp};

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
    let r = json(&report);
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
    let r = json(&report);
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
    // (input, what the one error line must mention)
    let cases = [
        // OBJ syntax error: the line number.
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n", "line 4"),
        // Inconsistent orientation: edge 1 -> 2 used twice in the same direction.
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 1\nf 1 2 3\nf 1 2 4\n",
            "inconsistent",
        ),
        // Repeated vertex in a face.
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 2\n", "repeat"),
        // Zero-length edge.
        ("v 0 0 0\nv 0 0 0\nv 0 1 0\nf 1 2 3\n", "zero length"),
        // Non-manifold edge: three faces on edge (1, 2).
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n",
            "non-manifold",
        ),
        // Non-manifold vertex: two triangles touching at vertex 1 only.
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv -1 0 0\nv 0 -1 0\nf 1 2 3\nf 1 4 5\n",
            "non-manifold",
        ),
    ];
    for (text, needle) in cases {
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
        assert!(
            err.to_lowercase().contains(needle),
            "{needle:?} not in {err}"
        );
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
    // Circular mode on a mesh without quads.
    std::fs::write(
        &input,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0.3\nf 1 2 3\nf 2 4 3\n",
    )
    .unwrap();
    let o = dupin(&[
        "planarize",
        "--input",
        input.to_str().unwrap(),
        "--mode",
        "circular",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.starts_with("error:") && err.contains("quad"), "{err}");
    let _ = std::fs::remove_file(&input);
    let _ = std::fs::remove_file(&out);
}

#[test]
fn iteration_cap_returns_best_mesh_with_converged_false_and_reason() {
    let input = tmp("cap.obj");
    let out = tmp("cap-out.obj");
    let report = tmp("cap.json");
    std::fs::write(&input, skew_grid_obj()).unwrap();
    let o = dupin(&[
        "planarize",
        "--input",
        input.to_str().unwrap(),
        "--max-iterations",
        "1",
        "--out",
        out.to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let r = json(&report);
    assert_eq!(r["converged"], false);
    assert_eq!(r["iterations"], 1);
    assert!(r["reason"].as_str().unwrap().contains("iteration cap"));
    assert!(out.exists());
    for p in [input, out, report] {
        let _ = std::fs::remove_file(p);
    }
}

#[test]
fn hexagons_and_mixed_faces_are_planarized() {
    // Two hexagons and a quad sharing edges, lifted out of plane.
    let input = tmp("hex.obj");
    let out = tmp("hex-out.obj");
    let report = tmp("hex.json");
    let text = "v 0 0 0\nv 1 0 0.2\nv 1.5 0.8 0\nv 1 1.6 0.3\nv 0 1.6 0\nv -0.5 0.8 0.25\n\
                v 2.5 0.8 0.1\nv 3 1.6 -0.2\nv 2.5 2.4 0\nv 1.5 2.4 0.2\nv 0.5 2.6 0\n\
                f 1 2 3 4 5 6\nf 3 7 8 9 10 4\nf 5 4 10 11\n";
    std::fs::write(&input, text).unwrap();
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
    let r = json(&report);
    assert!(r["max_planarity"].as_f64().unwrap() <= 1e-10, "{r}");
    let faces: Vec<usize> = std::fs::read_to_string(&out)
        .unwrap()
        .lines()
        .filter(|l| l.starts_with("f "))
        .map(|l| l.split_whitespace().count() - 1)
        .collect();
    assert_eq!(faces, vec![6, 6, 4]);
    for p in [input, out, report] {
        let _ = std::fs::remove_file(p);
    }
}

#[test]
fn anchors_stay_put_and_bad_anchor_is_rejected() {
    let input = tmp("anchor.obj");
    let out = tmp("anchor-out.obj");
    std::fs::write(&input, skew_grid_obj()).unwrap();
    let o = dupin(&[
        "planarize",
        "--input",
        input.to_str().unwrap(),
        "--fix-vertices",
        "1,25,49",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let a: Vec<String> = std::fs::read_to_string(&input)
        .unwrap()
        .lines()
        .map(String::from)
        .collect();
    let b: Vec<String> = std::fs::read_to_string(&out)
        .unwrap()
        .lines()
        .map(String::from)
        .collect();
    for i in [0, 24, 48] {
        let pa: Vec<f64> = a[i]
            .split_whitespace()
            .skip(1)
            .map(|t| t.parse().unwrap())
            .collect();
        let pb: Vec<f64> = b[i]
            .split_whitespace()
            .skip(1)
            .map(|t| t.parse().unwrap())
            .collect();
        assert_eq!(pa, pb, "vertex {}", i + 1);
    }
    let o = dupin(&[
        "planarize",
        "--input",
        input.to_str().unwrap(),
        "--fix-vertices",
        "50",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let _ = std::fs::remove_file(&input);
    let _ = std::fs::remove_file(&out);
}

#[test]
fn sqp_refinement_reaches_the_same_accuracy() {
    let input = tmp("sqp.obj");
    let out = tmp("sqp-out.obj");
    let report = tmp("sqp.json");
    std::fs::write(&input, skew_grid_obj()).unwrap();
    let o = dupin(&[
        "planarize",
        "--input",
        input.to_str().unwrap(),
        "--refinement",
        "sqp",
        "--out",
        out.to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let r = json(&report);
    assert_eq!(r["converged"], true, "{r}");
    assert!(r["max_planarity"].as_f64().unwrap() <= 1e-10);
    for p in [input, out, report] {
        let _ = std::fs::remove_file(p);
    }
}
