//! The panel list a fabricator prices and orders from: one CSV row per panel in face order.

use super::units::LengthUnit;
use crate::Vec3;
use crate::mesh::{PolyMesh, least_squares_plane};
use std::fmt::Write as _;

/// The header row of [`panel_csv`].
pub const CSV_HEADER: &str =
    "panel,vertices,area_m2,perimeter_m,max_planarity_mm,max_deviation_mm,edge_lengths_mm";

/// One row per panel: its number (from 1, in face order), vertex count, area in m², perimeter in
/// m, largest distance of a vertex from the panel's least-squares plane in mm, largest distance
/// of a vertex from `design` (the same vertex of the design the panels were made from, if
/// given) in mm, and its edge lengths in mm separated by `;`. Figures to 0.001 mm, 1e-6 m².
pub fn panel_csv(mesh: &PolyMesh, unit: LengthUnit, design: Option<&[Vec3]>) -> String {
    let (mm, m) = (unit.to_mm(), unit.to_m());
    let mut s = String::with_capacity(80 * mesh.num_faces() + 100);
    s.push_str(CSV_HEADER);
    s.push('\n');
    for (i, f) in mesh.faces().enumerate() {
        let p: Vec<Vec3> = f.iter().map(|&v| mesh.positions[v as usize]).collect();
        let n = p.len();
        let (c, normal) = least_squares_plane(p.iter().copied());
        let flat = p
            .iter()
            .map(|q| (q - c).dot(&normal).abs())
            .fold(0.0, f64::max);
        // Newell's vector: twice the area of a planar polygon, its projection's otherwise.
        let newell: Vec3 = (0..n)
            .map(|k| (p[k] - c).cross(&(p[(k + 1) % n] - c)))
            .sum();
        let edges: Vec<f64> = (0..n).map(|k| (p[(k + 1) % n] - p[k]).norm()).collect();
        let deviation = design.map_or(String::new(), |d| {
            let worst = f
                .iter()
                .map(|&v| {
                    d.get(v as usize)
                        .map_or(f64::NAN, |q| (mesh.positions[v as usize] - q).norm())
                })
                .fold(0.0, f64::max);
            format!("{:.3}", worst * mm)
        });
        let lengths: Vec<String> = edges.iter().map(|e| format!("{:.1}", e * mm)).collect();
        let _ = writeln!(
            s,
            "{},{},{:.6},{:.6},{:.3},{},{}",
            i + 1,
            n,
            0.5 * newell.norm() * m * m,
            edges.iter().sum::<f64>() * m,
            flat * mm,
            deviation,
            lengths.join(";")
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_carry_areas_lengths_and_deviations_in_real_units() {
        let mut p = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(2000.0, 0.0, 0.0),
            Vec3::new(2000.0, 1000.0, 0.0),
            Vec3::new(0.0, 1000.0, 0.0),
        ];
        let design = p.clone();
        p[2].z = 4.0;
        let m = PolyMesh::new(p, [[0u32, 1, 2, 3]]).unwrap();
        let csv = panel_csv(&m, LengthUnit::Millimetre, Some(&design));
        let mut lines = csv.lines();
        assert_eq!(lines.next(), Some(CSV_HEADER));
        let row: Vec<&str> = lines.next().unwrap().split(',').collect();
        assert_eq!(&row[..2], &["1", "4"]);
        assert!(
            (row[2].parse::<f64>().unwrap() - 2.0).abs() < 1e-4,
            "{row:?}"
        );
        assert!(
            (row[3].parse::<f64>().unwrap() - 6.0).abs() < 1e-4,
            "{row:?}"
        );
        // Lifting one corner by 4 mm leaves every corner 1 mm from the least-squares plane.
        assert_eq!(row[4], "1.000");
        assert_eq!(row[5], "4.000");
        assert_eq!(row[6].split(';').count(), 4);
        let no_design = panel_csv(&m, LengthUnit::Millimetre, None);
        assert!(no_design.lines().nth(1).unwrap().contains(",1.000,,"));
    }
}
