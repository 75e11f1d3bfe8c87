//! End-to-end tests of `dupin hexdelaunay`.

mod common;
use common::{dupin_text as run, refused, run_reported};
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};

static COUNTER: AtomicUsize = AtomicUsize::new(0);

fn temp(name: &str, content: Option<&str>) -> PathBuf {
    let n = COUNTER.fetch_add(1, Ordering::SeqCst);
    let p = std::env::temp_dir().join(format!("dupin-hexd-{}-{n}-{name}", std::process::id()));
    if let Some(c) = content {
        std::fs::write(&p, c).unwrap();
    }
    p
}

fn bad(points: &str, segments: Option<&str>, extra: &[&str]) -> String {
    let pts = temp("pts.txt", Some(points));
    let out = temp("out.obj", None);
    let mut args = vec![
        "hexdelaunay",
        "--points",
        pts.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    let segs = segments.map(|s| temp("segs.txt", Some(s)));
    if let Some(s) = &segs {
        args.extend(["--segments", s.to_str().unwrap()]);
    }
    args.extend(extra);
    let (_, stderr) = refused(&args);
    assert!(!stderr.contains("panicked"));
    stderr
}

#[test]
fn triangulates_and_reports_contract_fields() {
    let text = "# points\n0 0\n1 0\n0.25 0.5\n\n0.7 0.9\n0.7 0.9\n0.123456789012345678 0.3\n";
    let pts = temp("pts.txt", Some(text));
    let run = run_reported(
        "hexd-simple",
        &["hexdelaunay", "--points", pts.to_str().unwrap()],
    );
    let r = run.ok();
    assert_eq!(run.stdout().lines().count(), 1);
    let keys: Vec<&String> = r.as_object().unwrap().keys().collect();
    let mut expected = [
        "input_points",
        "vertices",
        "triangles",
        "min_angle_deg",
        "max_angle_deg",
        "delaunay",
        "seconds",
    ];
    expected.sort();
    let mut keys: Vec<&str> = keys.iter().map(|s| s.as_str()).collect();
    keys.sort();
    assert_eq!(keys, expected);
    assert_eq!(r["input_points"], 6);
    assert!(r["min_angle_deg"].as_f64().unwrap() >= 29.99);
    assert!(r["max_angle_deg"].as_f64().unwrap() <= 120.01);
    assert_eq!(r["delaunay"], true);
    assert!(r["seconds"].as_f64().unwrap() >= 0.0);
    let mesh = run.mesh();
    assert_eq!(mesh.num_vertices() as u64, r["vertices"].as_u64().unwrap());
    assert_eq!(mesh.num_faces() as u64, r["triangles"].as_u64().unwrap());
    for p in dupin_core::mesh::parse_points(text).unwrap() {
        assert!(
            mesh.positions
                .iter()
                .any(|v| v.x == p.x && v.y == p.y && v.z == 0.0),
            "input point {p:?} is not an exact vertex"
        );
    }
    assert!(mesh.positions.iter().all(|v| v.z == 0.0));
}

#[test]
fn extended_mode_keeps_43_9_to_90_degrees() {
    let text = "0 0\n1 0\n0.25 0.5\n0.7 0.9\n0.7 0.9\n0.123456789012345678 0.3\n0.5 0.5\n";
    let pts = temp("pts.txt", Some(text));
    let run = run_reported(
        "hexd-extended",
        &[
            "hexdelaunay",
            "--points",
            pts.to_str().unwrap(),
            "--mode",
            "extended",
        ],
    );
    let r = run.ok();
    assert!(run.stdout().contains("hexdelaunay"));
    assert_eq!(r["input_points"], 7);
    assert!(r["min_angle_deg"].as_f64().unwrap() >= 43.89, "{r}");
    assert!(r["max_angle_deg"].as_f64().unwrap() <= 90.0001, "{r}");
    assert_eq!(r["delaunay"], true);
    let mesh = run.mesh();
    assert_eq!(mesh.num_faces() as u64, r["triangles"].as_u64().unwrap());
    for p in dupin_core::mesh::parse_points(text).unwrap() {
        assert!(
            mesh.positions.iter().any(|v| v.x == p.x && v.y == p.y),
            "input point {p:?} is not an exact vertex"
        );
    }
}

#[test]
fn bad_input_exits_2_with_one_error_line() {
    assert!(bad("", None, &[]).contains("no points"));
    assert!(bad("# only a comment\n\n", None, &[]).contains("no points"));
    assert!(bad("0 0\n1 1\n2 x\n", None, &[]).contains("line 3"));
    assert!(bad("0 0\n1\n", None, &[]).contains("line 2"));
    assert!(bad("0 0\nnan 1\n", None, &[]).contains("line 2"));
    assert!(bad("0 0\n1 inf\n", None, &[]).contains("line 2"));
    assert!(bad("0 0\n1e300 0\n", None, &[]).contains("magnitude"));
    assert!(bad("0 0\n1e-300 0\n", None, &[]).contains("span"));
    assert!(bad("1e6 0\n1000000.000000001 0\n", None, &[]).contains("depth cap"));
    let square = "0 0\n1 1\n0 1\n1 0\n";
    assert!(bad(square, Some("0 1\n2 3\n"), &[]).contains("cross"));
    assert!(bad(square, Some("0 9\n"), &[]).contains("point 9"));
    assert!(bad(square, Some("0 1\nx\n"), &[]).contains("line 2"));
    // Overlapping collinear segments and zero-length ones are refused too.
    let line = "0 0\n1 0\n2 0\n3 0\n";
    assert!(bad(line, Some("0 2\n1 3\n"), &[]).contains("cross"));
    assert!(bad(line, Some("0 3\n1 2\n"), &["--mode", "extended"]).contains("cross"));
    assert!(bad("0 0\n1 0\n0 0\n", Some("0 2\n"), &[]).contains("zero length"));
    // The same segment twice, in either order, is named as a repeat, not as a crossing.
    let e = bad(square, Some("0 1\n1 0\n"), &[]);
    assert!(
        e.contains("join the same two points") && !e.contains("cross"),
        "{e}"
    );
    assert!(bad(square, None, &["--mode", "fancy"]).contains("error"));
    let missing = temp("missing.txt", None);
    let out = temp("out.obj", None);
    let (code, _, stderr) = run(&[
        "hexdelaunay",
        "--points",
        missing.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 2);
    assert!(stderr.starts_with("error:"));
}

#[test]
fn pslg_segments_become_edges_and_report_the_exempt_triangles() {
    let data = concat!(env!("CARGO_MANIFEST_DIR"), "/../dupin-core/tests/data/");
    let pts = format!("{data}imr_points.txt");
    let segs = format!("{data}imr_segments.txt");
    for (mode, lo, hi) in [("simple", 29.99, 120.01), ("extended", 43.89, 90.0001)] {
        let args: &[&str] = &[
            "hexdelaunay",
            "--points",
            &pts,
            "--segments",
            &segs,
            "--mode",
            mode,
        ];
        let run = run_reported("hexd-pslg", args);
        let r = run.ok();
        let stdout = run.stdout();
        assert!(stdout.contains("75 segments"), "{stdout}");
        assert_eq!(r["input_points"], 75);
        assert_eq!(r["segments"], 75);
        assert!(r["segment_edges"].as_u64().unwrap() >= 75, "{r}");
        assert!(r["triangles_meeting_segments"].as_u64().unwrap() > 0, "{r}");
        assert!(r["away_min_angle_deg"].as_f64().unwrap() >= lo, "{r}");
        assert!(r["away_max_angle_deg"].as_f64().unwrap() <= hi, "{r}");
        assert_eq!(r["away_delaunay"], true, "{r}");
        let mesh = run.mesh();
        assert_eq!(mesh.num_faces() as u64, r["triangles"].as_u64().unwrap());
        // Each segment's endpoints are exact vertices and the segment is covered by edges:
        // the edges lying on it (all vertices within 2e-9 of its length) sum to its length.
        let p = dupin_core::mesh::parse_points(&std::fs::read_to_string(&pts).unwrap()).unwrap();
        let s = dupin_core::mesh::parse_segments(&std::fs::read_to_string(&segs).unwrap()).unwrap();
        let mut edges = std::collections::HashSet::new();
        for vs in mesh.faces() {
            for i in 0..vs.len() {
                let (a, b) = (vs[i] as usize, vs[(i + 1) % vs.len()] as usize);
                edges.insert((a.min(b), a.max(b)));
            }
        }
        for [i, j] in s {
            let (a, b) = (p[i], p[j]);
            let d = b - a;
            let on = |v: usize| {
                let q = mesh.positions[v];
                let q = dupin_core::Vec2::new(q.x, q.y);
                let t = (q - a).dot(&d) / d.norm_squared();
                d.perp(&(q - a)).abs() <= 2e-9 * d.norm_squared() && (0.0..=1.0).contains(&t)
            };
            let covered: f64 = edges
                .iter()
                .filter(|&&(u, v)| on(u) && on(v))
                .map(|&(u, v)| (mesh.positions[u] - mesh.positions[v]).norm())
                .sum();
            assert!(
                (covered - d.norm()).abs() <= 1e-9 * d.norm(),
                "{mode}: segment {i}-{j} covered {covered} of {}",
                d.norm()
            );
        }
    }
}
