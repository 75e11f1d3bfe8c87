//! The panel list a fabricator prices and orders from: one CSV row per panel in face order.

use super::units::LengthUnit;
use crate::Vec3;
use crate::mesh::{MeshTopology, PolyMesh, TopologyError, least_squares_plane};
use std::fmt::Write as _;

/// The header row of the node section of [`support_csv`].
pub const NODE_HEADER: &str = "node,x_m,y_m,z_m,axis_x,axis_y,axis_z,offset_mm";
/// The header row of the beam section of [`support_csv`].
pub const BEAM_HEADER: &str = "beam,node_a,node_b,length_mm,max_planarity_mm";

/// The largest distance of `p` from its least-squares plane.
fn off_plane(p: &[Vec3]) -> f64 {
    let (c, normal) = least_squares_plane(p.iter().copied());
    p.iter()
        .map(|q| (q - c).dot(&normal).abs())
        .fold(0.0, f64::max)
}

/// The support structure of a conical mesh as two CSV tables, each after a blank line and its
/// header (appended to [`panel_csv`]'s, a spreadsheet shows three tables; conical paper, Sec. 4):
/// - nodes ([`NODE_HEADER`]): every vertex in a face, numbered as the panels' corners (from 1),
///   its position in m, the unit direction of its node axis (from the panel vertex to the same
///   vertex of `offset`: the cone axis at an interior conical vertex) and the offset distance
///   along it in mm;
/// - beams ([`BEAM_HEADER`]): one per mesh edge, the quad between the edge and its offset, by
///   its two nodes, its length in mm and the largest distance of its corners from their
///   least-squares plane in mm (0 up to rounding for a conical mesh: the beams are planar).
///
/// `offset` must have `panels`' vertices in the same order (as [`crate::conical::offset_mesh`]
/// makes it). Errors: the panels' topology ([`TopologyError`]).
pub fn support_csv(
    panels: &PolyMesh,
    offset: &PolyMesh,
    unit: LengthUnit,
) -> Result<String, TopologyError> {
    let (mm, m) = (unit.to_mm(), unit.to_m());
    let topo = MeshTopology::new(panels)?;
    let mut used = vec![false; panels.num_vertices()];
    for f in panels.faces() {
        for &v in f {
            used[v as usize] = true;
        }
    }
    let at = |v: usize| (panels.positions[v], offset.positions.get(v).copied());
    let mut s = String::with_capacity(64 * panels.num_vertices() + 48 * topo.edges().len());
    s.push('\n');
    s.push_str(NODE_HEADER);
    s.push('\n');
    for v in (0..panels.num_vertices()).filter(|&v| used[v]) {
        let (p, q) = at(v);
        let d = q.map_or(Vec3::zeros(), |q| q - p);
        let axis = d.try_normalize(0.0).unwrap_or_else(Vec3::zeros);
        let _ = writeln!(
            s,
            "{},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{:.3}",
            v + 1,
            p.x * m,
            p.y * m,
            p.z * m,
            axis.x,
            axis.y,
            axis.z,
            d.norm() * mm
        );
    }
    s.push('\n');
    s.push_str(BEAM_HEADER);
    s.push('\n');
    for (i, (a, b)) in topo.edges().into_iter().enumerate() {
        let (pa, qa) = at(a as usize);
        let (pb, qb) = at(b as usize);
        let corners = [pa, pb, qb.unwrap_or(pb), qa.unwrap_or(pa)];
        let _ = writeln!(
            s,
            "{},{},{},{:.1},{:.3}",
            i + 1,
            a + 1,
            b + 1,
            (pb - pa).norm() * mm,
            off_plane(&corners) * mm
        );
    }
    Ok(s)
}

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
        let (c, _) = least_squares_plane(p.iter().copied());
        let flat = off_plane(&p);
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

    /// Parses the section of `csv` under `header` into rows of numbers.
    fn section(csv: &str, header: &str) -> Vec<Vec<f64>> {
        csv.split("\n\n")
            .find(|t| t.starts_with(header))
            .unwrap_or_else(|| panic!("no {header} section"))
            .lines()
            .skip(1)
            .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
            .collect()
    }

    #[test]
    fn a_conical_mesh_lists_its_node_axes_and_planar_beams() {
        let mesh = crate::scenes::pq_scene("conical-station").unwrap().mesh;
        let offset = crate::conical::offset_mesh(&mesh, 0.05).unwrap();
        let csv = panel_csv(&mesh, LengthUnit::Metre, None)
            + &support_csv(&mesh, &offset, LengthUnit::Metre).unwrap();
        let nodes = section(&csv, NODE_HEADER);
        let beams = section(&csv, BEAM_HEADER);
        assert_eq!(beams.len(), MeshTopology::new(&mesh).unwrap().edges().len());
        assert!(nodes.len() > 100 && nodes.len() <= mesh.num_vertices());
        for n in &nodes {
            let v = n[0] as usize - 1;
            let d = offset.positions[v] - mesh.positions[v];
            let axis = Vec3::new(n[4], n[5], n[6]);
            assert!(
                (axis.norm() - 1.0).abs() < 1e-5,
                "node {} axis {axis}",
                n[0]
            );
            assert!((axis.dot(&d) * 1000.0 - n[7]).abs() < 2e-3, "node {}", n[0]);
            // The face distance is 50 mm; along a tilted axis the node moves at least that.
            assert!(n[7] >= 50.0 - 1e-3, "node {} offset {} mm", n[0], n[7]);
        }
        let worst = beams.iter().map(|b| b[4]).fold(0.0, f64::max);
        assert!(worst <= 1e-3, "a beam is {worst} mm off its plane");
        assert!(beams.iter().all(|b| b[3] > 0.0));
        // A mesh that is not conical gets twisted beams, and the table says so.
        let mut bent = mesh.clone();
        bent.positions[mesh.faces().next().unwrap()[0] as usize].z += 0.05;
        let twisted = section(
            &support_csv(&bent, &offset, LengthUnit::Metre).unwrap(),
            BEAM_HEADER,
        );
        assert!(twisted.iter().any(|b| b[4] > 1.0));
    }

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
