//! End-to-end tests of `dupin planarize`.

mod common;
use common::{Run, refused, run_reported, tmp};

/// A 6 x 6 quad grid on the saddle z = xy, rotated 30 degrees: far from planar.
fn skew_grid_obj() -> String {
    skew_grid(6, 30.0)
}

/// An `n x n` quad grid on the saddle z = xy over [-1, 1]², rotated by `degrees`.
fn skew_grid(n: usize, degrees: f64) -> String {
    let (s, c) = degrees.to_radians().sin_cos();
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

/// Runs `dupin planarize --input <obj> <args> --out .. --report ..` on `obj` (test `name`).
fn planarize(name: &str, obj: &str, args: &[&str]) -> Run {
    let input = tmp(&format!("{name}.obj"));
    std::fs::write(&input, obj).unwrap();
    let mut all = vec!["planarize", "--input", input.to_str().unwrap()];
    all.extend_from_slice(args);
    let run = run_reported(name, &all);
    let _ = std::fs::remove_file(input);
    run
}

/// Coordinates of OBJ vertex line `i` (0-based).
fn vertex(obj: &str, i: usize) -> Vec<f64> {
    obj.lines()
        .filter(|l| l.starts_with("v "))
        .nth(i)
        .unwrap()
        .split_whitespace()
        .skip(1)
        .map(|t| t.parse().unwrap())
        .collect()
}

#[test]
fn planarizes_a_skew_grid_and_reports_exact_fields() {
    let run = planarize("grid", &skew_grid_obj(), &[]);
    let r = run.ok();
    assert_eq!(run.stdout().lines().count(), 1);
    for key in [
        "vertices",
        "faces",
        "max_planarity",
        "max_move",
        "max_normal_move",
        "max_tangential_move",
        "iterations",
        "seconds",
    ] {
        assert!(r.get(key).is_some(), "missing {key}");
    }
    // The move splits into its parts along and across the input's normals.
    let (all, normal, tangential) = (
        r["max_move"].as_f64().unwrap(),
        r["max_normal_move"].as_f64().unwrap(),
        r["max_tangential_move"].as_f64().unwrap(),
    );
    assert!(normal > 0.0 && normal <= all && tangential <= all, "{r}");
    assert!(all <= (normal * normal + tangential * tangential).sqrt() * (1.0 + 1e-12));
    assert_eq!(r["faces"], 36);
    assert_eq!(r["vertices"], 49);
    assert!(r["max_planarity"].as_f64().unwrap() <= 1e-10);
    assert_eq!(r["converged"], true);
    // The output OBJ is a valid mesh that re-measures as planar.
    let text = run.out.as_deref().unwrap();
    assert_eq!(text.lines().filter(|l| l.starts_with("f ")).count(), 36);
}

#[test]
fn conical_mode_reports_its_residual_and_fix_boundary_keeps_boundary() {
    let input = skew_grid_obj();
    let run = planarize("c", &input, &["--mode", "conical", "--fix-boundary"]);
    // With its boundary held, this saddle grid admits no conical mesh within the iteration
    // cap: exit 3, the best mesh and the report still written.
    assert!(run.unmet().get("conical_residual").is_some());
    // Vertex 1 (a corner) is on the boundary: unchanged coordinates.
    assert_eq!(vertex(&input, 0), vertex(run.out.as_deref().unwrap(), 0));
}

#[test]
fn bad_input_exits_2_with_one_error_line() {
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
        let err = planarize("bad", text, &[]).fails();
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.starts_with("error:"), "{err}");
        assert!(
            err.to_lowercase().contains(needle),
            "{needle:?} not in {err}"
        );
    }
    // Conical mode on a mesh without interior valence-4 vertex.
    let quad = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0.2\nf 1 2 3 4\n";
    let err = planarize("bad", quad, &["--mode", "conical"]).fails();
    assert!(err.contains("valence 4"), "{err}");
    // Circular mode on a mesh without quads.
    let triangles = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0.3\nf 1 2 3\nf 2 4 3\n";
    let err = planarize("bad", triangles, &["--mode", "circular"]).fails();
    assert!(err.starts_with("error:") && err.contains("quad"), "{err}");
}

#[test]
fn iteration_cap_returns_best_mesh_with_converged_false_and_reason() {
    let run = planarize("cap", &skew_grid_obj(), &["--max-iterations", "1"]);
    let r = run.unmet();
    assert_eq!(r["converged"], false);
    assert_eq!(r["iterations"], 1);
    assert!(r["reason"].as_str().unwrap().contains("iteration cap"));
    assert!(run.out.is_some());
}

#[test]
fn hexagons_and_mixed_faces_are_planarized() {
    // Two hexagons and a quad sharing edges, lifted out of plane.
    let text = "v 0 0 0\nv 1 0 0.2\nv 1.5 0.8 0\nv 1 1.6 0.3\nv 0 1.6 0\nv -0.5 0.8 0.25\n\
                v 2.5 0.8 0.1\nv 3 1.6 -0.2\nv 2.5 2.4 0\nv 1.5 2.4 0.2\nv 0.5 2.6 0\n\
                f 1 2 3 4 5 6\nf 3 7 8 9 10 4\nf 5 4 10 11\n";
    let run = planarize("hex", text, &[]);
    let r = run.ok();
    assert!(r["max_planarity"].as_f64().unwrap() <= 1e-10, "{r}");
    let faces: Vec<usize> = run
        .out
        .as_deref()
        .unwrap()
        .lines()
        .filter(|l| l.starts_with("f "))
        .map(|l| l.split_whitespace().count() - 1)
        .collect();
    assert_eq!(faces, vec![6, 6, 4]);
}

#[test]
fn anchors_stay_put_and_bad_anchor_is_rejected() {
    let input = skew_grid_obj();
    let run = planarize("anchor", &input, &["--fix-vertices", "1,25,49"]);
    run.ok();
    let out = run.out.as_deref().unwrap();
    for i in [0, 24, 48] {
        assert_eq!(vertex(&input, i), vertex(out, i), "vertex {}", i + 1);
    }
    planarize("anchor", &input, &["--fix-vertices", "50"]).fails();
}

#[test]
fn sqp_refinement_reaches_the_same_accuracy() {
    let run = planarize("sqp", &skew_grid_obj(), &["--refinement", "sqp"]);
    let r = run.ok();
    assert_eq!(r["converged"], true, "{r}");
    assert!(r["max_planarity"].as_f64().unwrap() <= 1e-10);
}

/// Planar faces that turned over are a folded design: exit 3 with the count, though every face
/// is planar (the 20 x 20 grid at 15 degrees folds with `--fair-mesh`; keeping the design, the
/// default, it does not fold).
#[test]
fn folded_faces_are_not_a_planarised_design() {
    let kept = planarize("kept", &skew_grid(20, 15.0), &[]);
    assert_eq!(kept.ok()["flipped_faces"], 0);
    let run = planarize("fold", &skew_grid(20, 15.0), &["--fair-mesh"]);
    let r = run.unmet();
    assert!(r["max_planarity"].as_f64().unwrap() <= 1e-10, "{r}");
    assert!(r["flipped_faces"].as_u64().unwrap() > 0, "{r}");
    assert!(r["reason"].as_str().unwrap().contains("turned over"), "{r}");
    let fine = planarize("nofold", &skew_grid_obj(), &[]);
    assert_eq!(fine.ok()["flipped_faces"], 0);
}

/// A mesh whose sparse factor would pass `--max-memory` is refused from its pattern alone,
/// before the factor is allocated: exit 2, one line naming both sizes and the option, no
/// output file.
#[test]
fn beyond_the_memory_limit_is_refused_before_the_factor() {
    let input = tmp("memory_limit.obj");
    std::fs::write(&input, skew_grid(20, 15.0)).unwrap();
    let out = tmp("memory_limit_out.obj");
    let _ = std::fs::remove_file(&out);
    let with_limit = |gb: &str| {
        refused(&[
            "planarize",
            "--input",
            input.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--max-memory",
            gb,
        ])
        .1
    };
    let err = with_limit("1e-6");
    assert!(
        err.contains("sparse factorisation needs")
            && err.contains("raise --max-memory (now 1e-6 GB)"),
        "{err}"
    );
    assert!(!out.exists());
    for bad in ["0", "-1", "nan"] {
        with_limit(bad);
    }
    let _ = std::fs::remove_file(input);
}
