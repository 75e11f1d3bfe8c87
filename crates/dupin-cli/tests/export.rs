//! End-to-end tests of `dupin export`: a P-Hex panel mesh as DXF, CSV, GLB and SVG, each read
//! back and checked against the 3D panels.

mod common;
use common::{dupin, dupin_ok, tmp};

/// The panels of a P-Hex scene (planar hexagons) as an OBJ, in metres.
fn panels(name: &str) -> (std::path::PathBuf, Vec<[f64; 3]>, Vec<Vec<usize>>) {
    let obj = tmp(&format!("export-{name}.obj"));
    dupin_ok(&[
        "phex",
        "--scene",
        "torus-bound",
        "--out",
        obj.to_str().unwrap(),
    ]);
    let text = std::fs::read_to_string(&obj).unwrap();
    let mut v = Vec::new();
    let mut f = Vec::new();
    for l in text.lines() {
        let t: Vec<&str> = l.split_whitespace().collect();
        match t.first() {
            Some(&"v") => v.push([t[1], t[2], t[3]].map(|x| x.parse::<f64>().unwrap())),
            Some(&"f") => f.push(
                t[1..]
                    .iter()
                    .map(|i| i.parse::<usize>().unwrap() - 1)
                    .collect(),
            ),
            _ => {}
        }
    }
    (obj, v, f)
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// The closed LWPOLYLINEs of a DXF by layer, as (layer, corners), read from its group codes.
fn polylines(dxf: &str) -> Vec<(String, Vec<[f64; 2]>)> {
    let lines: Vec<&str> = dxf.lines().map(str::trim).collect();
    let mut out = Vec::new();
    let mut k = 0;
    while k + 1 < lines.len() {
        if lines[k] == "0" && lines[k + 1] == "LWPOLYLINE" {
            let (mut layer, mut pts, mut x) = (String::new(), Vec::new(), None);
            let mut j = k + 2;
            while j + 1 < lines.len() && lines[j] != "0" {
                match lines[j] {
                    "8" => layer = lines[j + 1].to_string(),
                    "70" => assert_eq!(lines[j + 1], "1", "closed"),
                    "10" => x = Some(lines[j + 1].parse::<f64>().unwrap()),
                    "20" => pts.push([x.take().unwrap(), lines[j + 1].parse::<f64>().unwrap()]),
                    _ => {}
                }
                j += 2;
            }
            out.push((layer, pts));
            k = j;
        } else {
            k += 2;
        }
    }
    out
}

#[test]
fn dxf_panels_are_true_size_in_mm_and_do_not_overlap() {
    let (obj, v, faces) = panels("dxf");
    let dxf_path = tmp("export.dxf");
    dupin_ok(&[
        "export",
        "--input",
        obj.to_str().unwrap(),
        "--format",
        "dxf",
        "--out",
        dxf_path.to_str().unwrap(),
    ]);
    let dxf = std::fs::read_to_string(&dxf_path).unwrap();
    assert!(dxf.contains("$INSUNITS\n 70\n4\n"));
    let polys = polylines(&dxf);
    let panels: Vec<&Vec<[f64; 2]>> = polys
        .iter()
        .filter(|(l, _)| l == "PANELS")
        .map(|(_, p)| p)
        .collect();
    assert_eq!(panels.len(), faces.len());
    let sheets = polys.iter().filter(|(l, _)| l == "SHEETS").count();
    assert!(sheets >= 1);
    // Flattened edges equal the 3D edges (in mm) to 1e-9 relative.
    for (p, f) in panels.iter().zip(&faces) {
        assert_eq!(p.len(), f.len());
        for k in 0..f.len() {
            let flat = ((p[k][0] - p[(k + 1) % f.len()][0]).powi(2)
                + (p[k][1] - p[(k + 1) % f.len()][1]).powi(2))
            .sqrt();
            let real = 1000.0 * dist(v[f[k]], v[f[(k + 1) % f.len()]]);
            assert!((flat / real - 1.0).abs() < 1e-9, "{flat} vs {real}");
        }
    }
    // No two panels overlap: their bounding boxes are disjoint (the packing is by boxes).
    let boxes: Vec<[f64; 4]> = panels
        .iter()
        .map(|p| {
            p.iter()
                .fold([f64::MAX, f64::MAX, f64::MIN, f64::MIN], |b, q| {
                    [
                        b[0].min(q[0]),
                        b[1].min(q[1]),
                        b[2].max(q[0]),
                        b[3].max(q[1]),
                    ]
                })
        })
        .collect();
    for i in 0..boxes.len() {
        for j in i + 1..boxes.len() {
            let (a, b) = (boxes[i], boxes[j]);
            let apart = a[2] <= b[0] || b[2] <= a[0] || a[3] <= b[1] || b[3] <= a[1];
            assert!(apart, "panels {} and {} overlap", i + 1, j + 1);
        }
    }
    let _ = std::fs::remove_file(&dxf_path);
    let _ = std::fs::remove_file(&obj);
}

#[test]
fn csv_glb_and_svg_carry_every_panel() {
    let (obj, v, faces) = panels("others");
    let out = |ext: &str| tmp(&format!("export-out.{ext}"));
    for ext in ["csv", "glb", "svg"] {
        let o = dupin(&[
            "export",
            "--input",
            obj.to_str().unwrap(),
            "--format",
            ext,
            "--unit",
            "m",
            "--out",
            out(ext).to_str().unwrap(),
        ]);
        assert!(
            o.status.success(),
            "{ext}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
    let csv = std::fs::read_to_string(out("csv")).unwrap();
    let mut rows = csv.lines();
    let header: Vec<&str> = rows.next().unwrap().split(',').collect();
    for col in [
        "panel",
        "vertices",
        "area_m2",
        "perimeter_m",
        "max_planarity_mm",
    ] {
        assert!(header.contains(&col), "{col}");
    }
    let rows: Vec<Vec<&str>> = rows.map(|r| r.split(',').collect()).collect();
    assert_eq!(rows.len(), faces.len());
    for (r, f) in rows.iter().zip(&faces) {
        assert_eq!(r[1].parse::<usize>().unwrap(), f.len());
        let perimeter: f64 = (0..f.len())
            .map(|k| dist(v[f[k]], v[f[(k + 1) % f.len()]]))
            .sum();
        assert!((r[3].parse::<f64>().unwrap() - perimeter).abs() < 1e-6);
        assert!(r[4].parse::<f64>().unwrap() < 1e-3, "planar panels");
    }
    // The GLB's panels read back as triangles (the fans of the faces).
    let glb = std::fs::read(out("glb")).unwrap();
    assert_eq!(&glb[..4], b"glTF");
    let o = dupin_ok(&[
        "planarize",
        "--input",
        out("glb").to_str().unwrap(),
        "--max-iterations",
        "1",
        "--out",
        tmp("export-glb-back.obj").to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    let triangles: usize = faces.iter().map(|f| f.len() - 2).sum();
    assert!(stdout.contains(&format!("{triangles} faces")), "{stdout}");
    let svg = std::fs::read_to_string(out("svg")).unwrap();
    assert_eq!(svg.matches("<polygon data-panel=").count(), faces.len());
    for ext in ["csv", "glb", "svg"] {
        let _ = std::fs::remove_file(out(ext));
    }
    let _ = std::fs::remove_file(tmp("export-glb-back.obj"));
    let _ = std::fs::remove_file(&obj);
}

#[test]
fn csv_of_a_conical_mesh_lists_node_axes_and_planar_beams() {
    let obj = tmp("export-conical-station.obj");
    dupin_ok(&[
        "pq",
        "--scene",
        "conical-station",
        "--out",
        obj.to_str().unwrap(),
    ]);
    let csv = tmp("export-conical-station.csv");
    let (i, o) = (obj.to_str().unwrap(), csv.to_str().unwrap());
    dupin_ok(&[
        "export",
        "--input",
        i,
        "--format",
        "csv",
        "--out",
        o,
        "--support",
        "0.05",
    ]);
    let text = std::fs::read_to_string(&csv).unwrap();
    let tables: Vec<&str> = text.split("\n\n").collect();
    assert_eq!(tables.len(), 3, "panels, nodes and beams");
    assert!(tables[1].starts_with("node,x_m,y_m,z_m,axis_x,axis_y,axis_z,offset_mm\n"));
    assert!(tables[2].starts_with("beam,node_a,node_b,length_mm,max_planarity_mm\n"));
    // Beams of a conical mesh are planar (conical paper, Sec. 4), to the CSV's 0.001 mm.
    for row in tables[2].lines().skip(1) {
        let planarity: f64 = row.rsplit(',').next().unwrap().parse().unwrap();
        assert!(planarity <= 0.001, "{row}");
    }
    // --support belongs to the CSV.
    let out = dupin(&[
        "export",
        "--input",
        i,
        "--format",
        "dxf",
        "--out",
        o,
        "--support",
        "0.05",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--format csv"));
    // A zero distance has no support structure: refused, not written as zero-length axes.
    let out = dupin(&[
        "export",
        "--input",
        i,
        "--format",
        "csv",
        "--out",
        o,
        "--support",
        "0",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("other than 0"));
}
