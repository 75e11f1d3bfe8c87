//! Panel schedule for fabrication: every (planar) face of a panel mesh flattened into its
//! least-squares plane, numbered, with its edge lengths, and packed on rectangular sheets for
//! cutting (what the configurator's export hands to fabrication; the panels are the planar
//! faces the P-Hex paper's section 7 and the conical paper's section 3 produce).
//!
//! Flattening is an orthogonal projection onto the plane of the face's covariance matrix (the
//! contract's `max_planarity` plane), so a planar face keeps its edge lengths and angles up to
//! rounding. Packing is a shelf packing (rows of panels sorted by height): simple, and within a
//! small factor of optimal for panels of similar size, which is what panel meshes have. No crate
//! does this small job for plain 2D polygons, so it is written here.

use crate::mesh::{PolyMesh, least_squares_plane};
use crate::{Vec2, Vec3};
use std::fmt::Write;

/// Errors of [`panel_schedule`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PanelScheduleError {
    /// The sheet size or the gap is not a positive finite length (gap: finite, >= 0).
    #[error("bad sheet: {0}")]
    BadSheet(String),
    /// A face has a zero-length edge or non-finite coordinates, so it has no plane.
    #[error("face {0} is degenerate (zero-length edge or non-finite vertex)")]
    DegenerateFace(usize),
    /// A panel is larger than a sheet.
    #[error(
        "panel {face} is {width:.4} x {height:.4}, larger than the {sheet_width:.4} x {sheet_height:.4} sheet"
    )]
    PanelTooLarge {
        /// Face index.
        face: usize,
        /// Panel width (along its longest edge).
        width: f64,
        /// Panel height.
        height: f64,
        /// Sheet width.
        sheet_width: f64,
        /// Sheet height.
        sheet_height: f64,
    },
}

/// Sheet layout of [`panel_schedule`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SheetOptions {
    /// Sheet width and height in mesh units; `None`: a square of 8 times the largest panel
    /// extent.
    pub sheet: Option<(f64, f64)>,
    /// Space between panels and around the sheet border, in mesh units; `None`: 5 % of the
    /// largest panel extent.
    pub gap: Option<f64>,
}

/// One flattened panel.
#[derive(Debug, Clone, PartialEq)]
pub struct FlatPanel {
    /// Face index in the mesh (panels are numbered by it).
    pub face: usize,
    /// Sheet the panel is on.
    pub sheet: usize,
    /// Corners in sheet coordinates, in the face's vertex order.
    pub corners: Vec<Vec2>,
    /// Length of edge k (corner k to corner k + 1), measured in 3D.
    pub edge_lengths: Vec<f64>,
}

/// The packed schedule.
#[derive(Debug, Clone, PartialEq)]
pub struct PanelSchedule {
    /// Sheet width and height.
    pub sheet_size: (f64, f64),
    /// Number of sheets used.
    pub sheets: usize,
    /// The panels, in face order.
    pub panels: Vec<FlatPanel>,
}

/// Corners of face `i` in an orthonormal frame of its least-squares plane, the first edge along
/// +x. The frame is orthonormal, so lengths in the plane are exact for a planar face.
fn flatten_face(mesh: &PolyMesh, i: usize) -> Result<Vec<Vec2>, PanelScheduleError> {
    let pts: Vec<Vec3> = mesh
        .face(i)
        .iter()
        .map(|&v| mesh.positions[v as usize])
        .collect();
    let n = pts.len();
    if pts.iter().any(|p| !p.iter().all(|x| x.is_finite()))
        || (0..n).any(|k| (pts[(k + 1) % n] - pts[k]).norm() == 0.0)
    {
        return Err(PanelScheduleError::DegenerateFace(i));
    }
    let (c, mut normal) = least_squares_plane(pts.iter().copied());
    // Orient the normal like the face's vertex order (Newell), so panels are not mirrored.
    let mut newell = Vec3::zeros();
    for k in 0..n {
        newell += (pts[k] - c).cross(&(pts[(k + 1) % n] - c));
    }
    if newell.dot(&normal) < 0.0 {
        normal = -normal;
    }
    let first = pts[1] - pts[0];
    let e1 = (first - normal * normal.dot(&first))
        .try_normalize(0.0)
        .ok_or(PanelScheduleError::DegenerateFace(i))?;
    let e2 = normal.cross(&e1);
    Ok(pts
        .iter()
        .map(|p| Vec2::new((p - c).dot(&e1), (p - c).dot(&e2)))
        .collect())
}

/// Flattens every face of `mesh` into its plane and packs the panels on sheets.
///
/// Input: any polygon mesh (meant for planar faces: then the flattened edges equal the 3D edges
/// to rounding). Output: the panels in face order, each with its sheet, its corners in sheet
/// coordinates and its 3D edge lengths. Errors: see [`PanelScheduleError`].
pub fn panel_schedule(
    mesh: &PolyMesh,
    options: &SheetOptions,
) -> Result<PanelSchedule, PanelScheduleError> {
    let flat: Vec<Vec<Vec2>> = (0..mesh.num_faces())
        .map(|i| flatten_face(mesh, i))
        .collect::<Result<_, _>>()?;
    let bbox = |q: &[Vec2]| {
        q.iter().fold(
            (Vec2::repeat(f64::INFINITY), Vec2::repeat(f64::NEG_INFINITY)),
            |(lo, hi), p| (lo.inf(p), hi.sup(p)),
        )
    };
    let extent = flat
        .iter()
        .map(|q| {
            let (lo, hi) = bbox(q);
            (hi - lo).max()
        })
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE);
    let gap = options.gap.unwrap_or(0.05 * extent);
    let (sw, sh) = options.sheet.unwrap_or((8.0 * extent, 8.0 * extent));
    if !(sw.is_finite() && sh.is_finite() && sw > 0.0 && sh > 0.0) {
        return Err(PanelScheduleError::BadSheet(format!(
            "sheet {sw} x {sh} must be positive and finite"
        )));
    }
    if !(gap.is_finite() && gap >= 0.0) {
        return Err(PanelScheduleError::BadSheet(format!(
            "gap {gap} must be finite and >= 0"
        )));
    }
    // Shelf packing, tallest panels first.
    let mut order: Vec<usize> = (0..flat.len()).collect();
    let dims: Vec<(Vec2, Vec2)> = flat.iter().map(|q| bbox(q)).collect();
    let height = |i: usize| dims[i].1.y - dims[i].0.y;
    order.sort_by(|&a, &b| height(b).total_cmp(&height(a)).then(a.cmp(&b)));
    let mut placed: Vec<Option<(usize, Vec2)>> = vec![None; flat.len()];
    let (mut sheet, mut x, mut y, mut row_h) = (0usize, gap, gap, 0.0f64);
    for &i in &order {
        let (lo, hi) = dims[i];
        let (w, h) = (hi.x - lo.x, hi.y - lo.y);
        if w + 2.0 * gap > sw || h + 2.0 * gap > sh {
            return Err(PanelScheduleError::PanelTooLarge {
                face: i,
                width: w,
                height: h,
                sheet_width: sw,
                sheet_height: sh,
            });
        }
        if x + w + gap > sw {
            x = gap;
            y += row_h + gap;
            row_h = 0.0;
        }
        if y + h + gap > sh {
            sheet += 1;
            x = gap;
            y = gap;
            row_h = 0.0;
        }
        placed[i] = Some((sheet, Vec2::new(x, y) - lo));
        x += w + gap;
        row_h = row_h.max(h);
    }
    let panels = flat
        .into_iter()
        .enumerate()
        .map(|(i, q)| {
            let (sheet, shift) = placed[i].unwrap_or((0, Vec2::zeros()));
            let f = mesh.face(i);
            let edge_lengths = (0..f.len())
                .map(|k| {
                    (mesh.positions[f[(k + 1) % f.len()] as usize] - mesh.positions[f[k] as usize])
                        .norm()
                })
                .collect();
            FlatPanel {
                face: i,
                sheet,
                corners: q.into_iter().map(|p| p + shift).collect(),
                edge_lengths,
            }
        })
        .collect::<Vec<_>>();
    Ok(PanelSchedule {
        sheet_size: (sw, sh),
        sheets: if panels.is_empty() { 0 } else { sheet + 1 },
        panels,
    })
}

/// The schedule as one SVG document: sheets stacked vertically, each panel outlined in a
/// `<polygon data-panel="i">` with its number at its centroid and each edge's length at the
/// edge's midpoint (`unit_scale` converts mesh units to the label's unit, e.g. 1000 for mm).
pub fn panel_schedule_svg(schedule: &PanelSchedule, unit_scale: f64) -> String {
    let (sw, sh) = schedule.sheet_size;
    let pitch = sh * 1.05;
    let total_h = pitch * schedule.sheets.max(1) as f64;
    let font = sw / 160.0;
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 {sw} {total_h}" width="{w}mm" height="{h}mm" data-panels="{n}" data-sheets="{sheets}">"#,
        w = 200.0,
        h = 200.0 * total_h / sw,
        n = schedule.panels.len(),
        sheets = schedule.sheets
    );
    for k in 0..schedule.sheets {
        let _ = writeln!(
            s,
            r##"<rect data-sheet="{k}" x="0" y="{y}" width="{sw}" height="{sh}" fill="none" stroke="#888" stroke-width="{sw2}"/>"##,
            y = k as f64 * pitch,
            sw2 = font / 10.0
        );
    }
    for p in &schedule.panels {
        let oy = p.sheet as f64 * pitch;
        let pts: Vec<String> = p
            .corners
            .iter()
            .map(|c| format!("{},{}", c.x, c.y + oy))
            .collect();
        let _ = writeln!(
            s,
            r##"<polygon data-panel="{i}" points="{pts}" fill="none" stroke="#000" stroke-width="{w}"/>"##,
            i = p.face,
            pts = pts.join(" "),
            w = font / 10.0
        );
        let c = p.corners.iter().sum::<Vec2>() / p.corners.len().max(1) as f64;
        let _ = writeln!(
            s,
            r#"<text x="{x}" y="{y}" font-size="{font}" text-anchor="middle">{i}</text>"#,
            x = c.x,
            y = c.y + oy,
            i = p.face
        );
        let n = p.corners.len();
        for (k, len) in p.edge_lengths.iter().enumerate() {
            let m = (p.corners[k] + p.corners[(k + 1) % n]) / 2.0;
            // Pull the label a little towards the centroid so it sits inside the panel.
            let m = m + (c - m) * 0.15;
            let _ = writeln!(
                s,
                r##"<text x="{x}" y="{y}" font-size="{f}" text-anchor="middle" fill="#555">{l:.1}</text>"##,
                x = m.x,
                y = m.y + oy,
                f = font * 0.6,
                l = len * unit_scale
            );
        }
    }
    s.push_str("</svg>\n");
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Vec3;
    use crate::phex::phex_run;
    use crate::scenes::phex_scene;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn dist(a: &Vec2, b: &Vec2) -> f64 {
        (a - b).norm()
    }

    /// Random planar polygons (convex, in random planes): flattened edge lengths and diagonals
    /// equal the 3D ones to 1e-9, and no two panels on a sheet overlap.
    #[test]
    fn planar_faces_keep_lengths_and_do_not_overlap() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let mut positions = Vec::new();
        let mut faces = Vec::new();
        for _ in 0..60 {
            let n = rng.random_range(3..8usize);
            let r = rng.random_range(0.2..2.0);
            let origin = Vec3::new(
                rng.random_range(-5.0..5.0),
                rng.random_range(-5.0..5.0),
                rng.random_range(-5.0..5.0),
            );
            let a = Vec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                0.3,
            )
            .normalize();
            let b = a.cross(&Vec3::new(0.1, 0.9, -0.4)).normalize();
            let start = positions.len() as u32;
            for k in 0..n {
                let t = std::f64::consts::TAU * (k as f64 + rng.random_range(0.0..0.5)) / n as f64;
                positions.push(origin + a * (r * t.cos()) + b * (r * 1.3 * t.sin()));
            }
            faces.push((start..start + n as u32).collect::<Vec<u32>>());
        }
        let mesh = PolyMesh::new(positions, faces).unwrap();
        let sched = panel_schedule(
            &mesh,
            &SheetOptions {
                sheet: Some((12.0, 9.0)),
                gap: Some(0.1),
            },
        )
        .unwrap();
        assert_eq!(sched.panels.len(), mesh.num_faces());
        assert!(sched.sheets > 1, "the test should span several sheets");
        for p in &sched.panels {
            let f = mesh.face(p.face);
            let n = f.len();
            for i in 0..n {
                for j in i + 1..n {
                    let d3 = (mesh.positions[f[i] as usize] - mesh.positions[f[j] as usize]).norm();
                    let d2 = dist(&p.corners[i], &p.corners[j]);
                    assert!(
                        (d3 - d2).abs() <= 1e-9,
                        "face {} pair {i},{j}: {d3} vs {d2}",
                        p.face
                    );
                }
                let e = dist(&p.corners[i], &p.corners[(i + 1) % n]);
                assert!((e - p.edge_lengths[i]).abs() <= 1e-9);
            }
            for c in &p.corners {
                assert!(c.x >= 0.1 - 1e-12 && c.x <= 12.0 - 0.1 + 1e-12);
                assert!(c.y >= 0.1 - 1e-12 && c.y <= 9.0 - 0.1 + 1e-12);
            }
        }
        // Bounding boxes on the same sheet are disjoint (shelf packing separates boxes).
        let boxes: Vec<(usize, Vec2, Vec2)> = sched
            .panels
            .iter()
            .map(|p| {
                let lo = p
                    .corners
                    .iter()
                    .fold(Vec2::repeat(f64::INFINITY), |a, c| a.inf(c));
                let hi = p
                    .corners
                    .iter()
                    .fold(Vec2::repeat(f64::NEG_INFINITY), |a, c| a.sup(c));
                (p.sheet, lo, hi)
            })
            .collect();
        for i in 0..boxes.len() {
            for j in i + 1..boxes.len() {
                let (si, li, hi) = boxes[i];
                let (sj, lj, hj) = boxes[j];
                if si != sj {
                    continue;
                }
                let overlap = li.x < hj.x - 1e-12
                    && lj.x < hi.x - 1e-12
                    && li.y < hj.y - 1e-12
                    && lj.y < hi.y - 1e-12;
                assert!(!overlap, "panels {i} and {j} overlap on sheet {si}");
            }
        }
    }

    /// A P-Hex result: every hexagon's flattened edges match its 3D edges to 1e-9, and the SVG
    /// has one polygon per face.
    #[test]
    fn phex_scene_schedule_and_svg() {
        let mut cfg = phex_scene("sphere-radial").unwrap().config;
        cfg.size = Some(cfg.size.unwrap() * 2.0);
        let r = phex_run(cfg).unwrap();
        assert!(r.report.max_planarity <= 1e-10);
        let sched = panel_schedule(
            &r.mesh,
            &SheetOptions {
                sheet: None,
                gap: None,
            },
        )
        .unwrap();
        for p in &sched.panels {
            let n = p.corners.len();
            for k in 0..n {
                let e = dist(&p.corners[k], &p.corners[(k + 1) % n]);
                assert!((e - p.edge_lengths[k]).abs() <= 1e-9 * p.edge_lengths[k].max(1.0));
            }
        }
        let svg = panel_schedule_svg(&sched, 1000.0);
        assert_eq!(svg.matches("<polygon").count(), r.mesh.num_faces());
        assert_eq!(svg.matches("<rect").count(), sched.sheets);
    }

    /// Bad sheets and oversize panels are errors, not panics.
    #[test]
    fn bad_input_is_an_error() {
        let mesh = PolyMesh::new(
            vec![
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(2.0, 0.0, 0.0),
                Vec3::new(0.0, 2.0, 0.0),
            ],
            [[0u32, 1, 2]],
        )
        .unwrap();
        for sheet in [(0.0, 1.0), (f64::NAN, 1.0), (1.0, -1.0)] {
            let e = panel_schedule(
                &mesh,
                &SheetOptions {
                    sheet: Some(sheet),
                    gap: None,
                },
            );
            assert!(matches!(e, Err(PanelScheduleError::BadSheet(_))));
        }
        let e = panel_schedule(
            &mesh,
            &SheetOptions {
                sheet: Some((1.0, 1.0)),
                gap: Some(0.0),
            },
        );
        assert!(matches!(
            e,
            Err(PanelScheduleError::PanelTooLarge { face: 0, .. })
        ));
        let degenerate = PolyMesh::new(
            vec![Vec3::zeros(), Vec3::zeros(), Vec3::new(0.0, 1.0, 0.0)],
            [[0u32, 1, 2]],
        );
        if let Ok(m) = degenerate {
            let e = panel_schedule(
                &m,
                &SheetOptions {
                    sheet: None,
                    gap: None,
                },
            );
            assert!(matches!(e, Err(PanelScheduleError::DegenerateFace(0))));
        }
    }
}
