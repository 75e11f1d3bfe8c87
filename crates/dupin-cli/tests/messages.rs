//! What a user sees when a command line or an input file is wrong: exit code 2 and one stderr
//! line starting `error:` that names the problem, with nothing written.

mod common;
use common::{dupin, dupin_ok, tmp};

/// Runs `dupin args`, asserts exit 2 with exactly one `error: ` line, and returns that line.
fn refused(args: &[&str]) -> String {
    let (_, err) = common::refused(args);
    assert!(err.starts_with("error: "), "{args:?}: {err}");
    err.trim_end().to_string()
}

#[test]
fn no_command_names_the_commands() {
    let e = refused(&[]);
    assert!(e.contains("no command given") && e.contains("phex"), "{e}");
}

#[test]
fn a_missing_argument_is_named() {
    let e = refused(&["planarize", "--input", "x.obj"]);
    assert!(e.contains("--out"), "{e}");
}

#[test]
fn negative_numbers_are_values_not_flags() {
    let out = tmp("neg.obj");
    let out = out.to_str().unwrap();
    let e = refused(&["phex", "--surface", "sphere", "--size", "-1", "--out", out]);
    assert!(e.contains("size -1"), "{e}");
}

/// A report path that cannot be written is refused before the computation, so no OBJ is left.
#[test]
fn unwritable_outputs_are_refused_before_any_work() {
    let out = tmp("report-dir.obj");
    let dir = std::env::temp_dir();
    let e = refused(&[
        "pq",
        "--scene",
        "pq-catmull-clark",
        "--out",
        out.to_str().unwrap(),
        "--report",
        dir.to_str().unwrap(),
    ]);
    assert!(e.contains("is a directory"), "{e}");
    assert!(!out.exists(), "the OBJ was written anyway");
    let missing = tmp("no-such-folder").join("x.obj");
    let e = refused(&[
        "pq",
        "--scene",
        "pq-catmull-clark",
        "--out",
        missing.to_str().unwrap(),
    ]);
    assert!(e.contains("does not exist"), "{e}");
}

/// OBJ problems are named by their 1-based line, vertex and face numbers; control characters of
/// the file are escaped; files with a byte-order mark or CR-only line ends are read.
#[test]
fn obj_messages_name_lines_and_escape_the_input() {
    let input = tmp("msg-in.obj");
    let out = tmp("msg-out.obj");
    let run = |text: &str| {
        std::fs::write(&input, text).unwrap();
        let args = [
            "planarize",
            "--input",
            input.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ];
        let o = dupin(&args);
        let _ = std::fs::remove_file(&out);
        o
    };
    let quad = "v 0 0 0\nv 1 0 0\nv 1 1 0.1\nv 0 1 0\nf 1 2 3 4\n";
    for text in [format!("\u{feff}{quad}"), quad.replace('\n', "\r")] {
        let o = run(&text);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let cases = [
        (format!("{quad}f 1 2 3 4\n"), "face 2 repeats face 1"),
        (
            "v 0 0 0\nv 0 0 0\nv 0 1 0\nf 1 2 3\n".to_string(),
            "vertices 1 and 2 has zero length",
        ),
        (
            format!("{quad}f 1 2 1\n"),
            "line 6: the face repeats vertex 1",
        ),
        ("v 0 0 \u{7}x\n".to_string(), "`\\u{7}x` is not a number"),
    ];
    for (text, want) in cases {
        let o = run(&text);
        let e = String::from_utf8_lossy(&o.stderr).to_string();
        assert_eq!(o.status.code(), Some(2), "{e}");
        assert!(e.contains(want), "{text:?}: {e}");
        assert!(!e.trim_end().chars().any(char::is_control), "{e:?}");
    }
    let _ = std::fs::remove_file(&input);
}

/// An offset distance far beyond the mesh's size is refused with the limit, not reported as a
/// perfect offset of planarity 0 (its numbers would overflow).
#[test]
fn huge_offset_distances_are_refused_with_the_limit() {
    let mesh = tmp("station.obj");
    let out = tmp("station-offset.obj");
    dupin_ok(&[
        "pq",
        "--scene",
        "conical-station",
        "--out",
        mesh.to_str().unwrap(),
    ]);
    for d in ["1e300", "-1e6"] {
        let e = refused(&[
            "offset",
            "--input",
            mesh.to_str().unwrap(),
            "--distance",
            d,
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(e.contains("times the mesh's size"), "{e}");
        assert!(e.len() < 300, "{e}");
        assert!(!out.exists());
    }
    let _ = std::fs::remove_file(&mesh);
}

/// Runs that would make far more P-Hex faces than the limit are refused while the
/// triangulation is built, in well under a second, naming the limit and the option: a field
/// angle whose layers come out thin (it made 563,566 faces where the scene has 2,444), the
/// progressive method on a hyperboloid, a tiny size.
#[test]
fn phex_runs_beyond_the_face_limit_are_refused_early() {
    let out = tmp("budget.obj");
    let out = out.to_str().unwrap();
    for args in [
        &[
            "phex",
            "--scene",
            "cyclide-prescribed",
            "--field-angle",
            "45",
            "--out",
            out,
        ][..],
        &[
            "phex",
            "--surface",
            "hyperboloid",
            "--method",
            "progressive",
            "--out",
            out,
        ],
        &[
            "phex",
            "--surface",
            "sphere",
            "--method",
            "progressive",
            "--size",
            "1e-3",
            "--out",
            out,
        ],
    ] {
        let start = std::time::Instant::now();
        let e = refused(args);
        assert!(
            e.contains("limit of 100000") && e.contains("--max-faces"),
            "{e}"
        );
        assert!(
            start.elapsed().as_secs_f64() < 20.0,
            "{args:?} took {:?}",
            start.elapsed()
        );
    }
}

/// Points 1e-9 apart in a set 100 across, with segments, ask the extended refinement for
/// millions of triangles (found by fuzzing: 5.9 million in 9 s); the split budget stops it
/// with the limit and the option that raises it.
#[test]
fn hexdelaunay_beyond_the_split_limit_is_refused() {
    let points = tmp("split_budget_points.txt");
    std::fs::write(
        &points,
        concat!(
            "1.1e1 -9.89119786076742e-10\n",
            "-5e1 -5e1\n",
            "-5e1 2.5e1\n",
            "-5e1 -5e1\n",
            "1.6e1 4.237890625e1\n",
            "8.53515625e0 -5e1\n",
            "-2.715625e1 -1.9e1\n",
            "1.1e1 -4.1088091785398e-34\n",
            "-1.6650619771851893e-9 -5e1\n",
            "-5e1 -2.715625e1\n",
            "-1.9e1 1.1e1\n",
            "-4.1088091785398e-34 -1.6650619771851893e-9\n",
            "-5e1 -5e1\n",
            "-5e1 -1.4e1\n",
            "-1.5e1 2.1016036777142339e-38\n",
            "-1.19e2 -5e1\n",
            "-5e1 3.125e-2\n",
            "2e0 -5e1\n",
            "5.8055575e-316 -5e1\n",
            "-5e1 -5e1\n",
            "-3.7e1 8.05078125e0\n",
            "3.5e1 0e0\n",
            "-5e1 -4.7e1\n",
            "1.4e1 2.5e1\n",
        ),
    )
    .unwrap();
    let segments = tmp("split_budget_segments.txt");
    std::fs::write(&segments, "0 16\n21 11\n").unwrap();
    let out = tmp("split_budget.obj");
    let start = std::time::Instant::now();
    let e = refused(&[
        "hexdelaunay",
        "--points",
        points.to_str().unwrap(),
        "--segments",
        segments.to_str().unwrap(),
        "--mode",
        "extended",
        "--max-splits",
        "20000",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(
        e.contains("limit of 20000 split hexagons") && e.contains("--max-splits"),
        "{e}"
    );
    assert!(
        start.elapsed().as_secs_f64() < 10.0,
        "{:?}",
        start.elapsed()
    );
}

/// Huge numbers print in exponent form, not in 300 digits.
#[test]
fn huge_numbers_stay_short_in_messages() {
    let out = tmp("huge.obj");
    let out = out.to_str().unwrap();
    for args in [
        &[
            "phex",
            "--surface",
            "sphere",
            "--size",
            "1e300",
            "--out",
            out,
        ][..],
        &[
            "phex",
            "--surface",
            "torus",
            "--set",
            "R=1e300",
            "--out",
            out,
        ],
    ] {
        let e = refused(args);
        assert!(e.contains("1e300") && e.len() < 200, "{e}");
    }
}
