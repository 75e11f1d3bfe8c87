//! Convex genus-0 shapes (P-Hex paper, section 5, Fig. 21): Loop subdivision of a convex control
//! polyhedron (an icosahedron) gives a triangulation whose vertices all have valence 6 except
//! the 12 original ones (valence 5); its dual is a P-Hex-dominant mesh with 12 pentagons, as
//! Euler's formula demands (F5 - F7 = 12 (1 - g) for genus g = 0). The subdivided vertices are
//! projected onto the ellipsoid so that distances and normals are those of an analytic convex
//! surface.

use super::layers::Triangulation;
use crate::phex::PhexError;
use crate::{Vec2, Vec3};
use std::collections::HashMap;

/// One step of Loop subdivision of a closed triangle mesh (Loop 1987; Warren's weights
/// beta = 3/(8n) for n > 3, 3/16 for n = 3). Written by hand: no maintained crate offers Loop
/// subdivision on plain index buffers.
pub fn loop_subdivide(pos: &[Vec3], tris: &[[u32; 3]]) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut nb: Vec<Vec<u32>> = vec![vec![]; pos.len()];
    let mut opposite: HashMap<(u32, u32), Vec<u32>> = HashMap::new();
    for t in tris {
        for k in 0..3 {
            let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
            if !nb[a as usize].contains(&b) {
                nb[a as usize].push(b);
            }
            if !nb[b as usize].contains(&a) {
                nb[b as usize].push(a);
            }
            opposite.entry((a.min(b), a.max(b))).or_default().push(c);
        }
    }
    let mut out: Vec<Vec3> = pos
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let n = nb[i].len();
            let beta = if n == 3 {
                3.0 / 16.0
            } else {
                3.0 / (8.0 * n as f64)
            };
            let sum: Vec3 = nb[i].iter().map(|&j| pos[j as usize]).sum();
            p * (1.0 - n as f64 * beta) + sum * beta
        })
        .collect();
    let mut edge_vertex: HashMap<(u32, u32), u32> = HashMap::new();
    let mut mid = |a: u32, b: u32, out: &mut Vec<Vec3>| -> u32 {
        let key = (a.min(b), a.max(b));
        if let Some(&v) = edge_vertex.get(&key) {
            return v;
        }
        let opp = &opposite[&key];
        let p = if opp.len() == 2 {
            (pos[a as usize] + pos[b as usize]) * 0.375
                + (pos[opp[0] as usize] + pos[opp[1] as usize]) * 0.125
        } else {
            (pos[a as usize] + pos[b as usize]) * 0.5
        };
        out.push(p);
        let v = (out.len() - 1) as u32;
        edge_vertex.insert(key, v);
        v
    };
    let mut new_tris = Vec::with_capacity(4 * tris.len());
    for t in tris {
        let ab = mid(t[0], t[1], &mut out);
        let bc = mid(t[1], t[2], &mut out);
        let ca = mid(t[2], t[0], &mut out);
        new_tris.push([t[0], ab, ca]);
        new_tris.push([ab, t[1], bc]);
        new_tris.push([ca, bc, t[2]]);
        new_tris.push([ab, bc, ca]);
    }
    (out, new_tris)
}

/// The icosahedron (outward counter-clockwise triangles), slightly rotated so that no vertex
/// sits on the z axis.
fn icosahedron() -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let g = (1.0 + 5f64.sqrt()) / 2.0;
    let raw = [
        (-1.0, g, 0.0),
        (1.0, g, 0.0),
        (-1.0, -g, 0.0),
        (1.0, -g, 0.0),
        (0.0, -1.0, g),
        (0.0, 1.0, g),
        (0.0, -1.0, -g),
        (0.0, 1.0, -g),
        (g, 0.0, -1.0),
        (g, 0.0, 1.0),
        (-g, 0.0, -1.0),
        (-g, 0.0, 1.0),
    ];
    let rot = nalgebra::Rotation3::from_euler_angles(0.3, 0.2, 0.1);
    let pos = raw
        .iter()
        .map(|&(x, y, z)| rot * Vec3::new(x, y, z).normalize())
        .collect();
    let tris = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    (pos, tris)
}

/// Triangulation of the ellipsoid x^2/a^2 + y^2/b^2 + z^2/c^2 = 1 by `levels` Loop subdivisions
/// of the icosahedron scaled to (a, b, c), every vertex projected radially onto the ellipsoid,
/// with the ellipsoid's normals and parameters of the library parametrisation.
///
/// Errors: [`PhexError::BadSize`] for more than 7 levels, [`PhexError::BadParameter`] for
/// non-positive semi-axes.
pub fn convex_loop_triangulation(
    axes: (f64, f64, f64),
    levels: usize,
) -> Result<Triangulation, PhexError> {
    let (a, b, c) = axes;
    if !(a > 0.0 && b > 0.0 && c > 0.0 && a.is_finite() && b.is_finite() && c.is_finite()) {
        return Err(PhexError::BadParameter(
            "the ellipsoid semi-axes must be positive".into(),
        ));
    }
    if levels > 7 {
        return Err(PhexError::BadSize(format!(
            "{levels} Loop levels (over 300k triangles); use a larger size"
        )));
    }
    let (mut pos, mut tris) = icosahedron();
    for p in pos.iter_mut() {
        *p = Vec3::new(p.x * a, p.y * b, p.z * c);
    }
    for _ in 0..levels {
        let (p, t) = loop_subdivide(&pos, &tris);
        pos = p;
        tris = t;
    }
    let mut uv = Vec::with_capacity(pos.len());
    let mut normals = Vec::with_capacity(pos.len());
    for p in pos.iter_mut() {
        let s = ((p.x / a).powi(2) + (p.y / b).powi(2) + (p.z / c).powi(2)).sqrt();
        *p /= s;
        normals.push(Vec3::new(p.x / (a * a), p.y / (b * b), p.z / (c * c)).normalize());
        let u = (p.y / b).atan2(p.x / a).rem_euclid(std::f64::consts::TAU);
        let v = (p.z / c).clamp(-1.0, 1.0).asin();
        uv.push(Vec2::new(u, v));
    }
    let all: Vec<u32> = (0..pos.len() as u32).collect();
    Ok(Triangulation {
        uv,
        positions: pos,
        normals,
        triangles: tris,
        layers: vec![all],
        closed_along: true,
        layer_steps: vec![],
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn loop_subdivision_keeps_euler_characteristic_and_valences() {
        let t = convex_loop_triangulation((1.4, 1.0, 0.8), 3).unwrap();
        let v = t.positions.len() as i64;
        let f = t.triangles.len() as i64;
        assert_eq!(f, 20 * 64);
        // Closed triangle mesh: E = 3F/2, V - E + F = 2.
        assert_eq!(v - 3 * f / 2 + f, 2);
        let mut valence = vec![0usize; t.positions.len()];
        for tr in &t.triangles {
            for &i in tr {
                valence[i as usize] += 1;
            }
        }
        assert_eq!(valence.iter().filter(|&&k| k == 5).count(), 12);
        assert!(valence.iter().all(|&k| k == 5 || k == 6));
        for p in &t.positions {
            let s = (p.x / 1.4).powi(2) + (p.y / 1.0).powi(2) + (p.z / 0.8).powi(2);
            assert!((s - 1.0).abs() < 1e-12);
        }
    }
}
