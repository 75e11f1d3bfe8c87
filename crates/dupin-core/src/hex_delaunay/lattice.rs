//! Hexagon coordinates and levels (paper section 3.1).
//!
//! All full hexagons share one orientation (corners at 0°, 60°, ...). Full hexagons of hierarchy
//! level `k` (the paper's level `2k`) have circumradius `R / 2^k` and their centres form the
//! triangular lattice `L_k = 2^-k L_0`. A centre is named by integer axial coordinates `(a, b)`:
//! position `origin + r_k (1.5 a, (√3/2) a + √3 b)`. The central child of hexagon `v` at level
//! `k` is `2v` at level `k + 1`; the hexagon joined from two semi-hexagons of adjacent `v`, `v+d`
//! is `2v + d`. Semi-hexagons (the paper's odd levels) are the halves of a level-`k+1` hexagon
//! `2v + d` whose other half still belongs to an unsplit `v + d`.
//!
//! The triangulated domain Ω is the hexagon whose corners are the six level-1 lattice points
//! `D[i]` (the edge midpoints of the root hexagon): its edges are lattice lines at every level
//! `k >= 1`, so lattice points on them are boundary hexagons, the paper's "virtual full
//! hexagons" (Fig. 1 right). At level `k` a lattice point lies in Ω iff its hexagonal distance
//! from the origin is at most `2^(k-1)`.

use crate::Vec2;

/// Axial lattice coordinates of a hexagon centre at some level.
pub type Axial = (i64, i64);

/// The six neighbour directions, counter-clockwise, starting at 30°.
pub const DIRS: [Axial; 6] = [(1, 0), (0, 1), (-1, 1), (-1, 0), (0, -1), (1, -1)];

const SQRT3: f64 = 1.732_050_807_568_877_2;

/// Hexagonal (cube) distance of a lattice point from the origin.
#[inline]
pub fn hex_norm(v: Axial) -> i64 {
    v.0.abs().max(v.1.abs()).max((v.0 + v.1).abs())
}

/// Whether `v` at `level` lies in the closed domain Ω.
#[inline]
pub fn in_domain(level: u32, v: Axial) -> bool {
    if level == 0 {
        v == (0, 0)
    } else {
        hex_norm(v) <= 1i64 << (level - 1)
    }
}

/// Whether `v` at `level >= 1` lies on the boundary of Ω (a virtual full hexagon).
#[inline]
pub fn on_boundary(level: u32, v: Axial) -> bool {
    level >= 1 && hex_norm(v) == 1i64 << (level - 1)
}

/// Whether both coordinates are even (the point is also a lattice point one level up).
#[inline]
pub fn is_even(v: Axial) -> bool {
    v.0 & 1 == 0 && v.1 & 1 == 0
}

/// For a point `v` that is not even: the two level-`k-1` centres whose midpoint it is.
#[inline]
pub fn parents_of_midpoint(v: Axial) -> (Axial, Axial) {
    // The first direction `d` of DIRS with `v - d` even, by the parities of `v`: (1, 0),
    // (0, 1) or (-1, 1).
    let d = match (v.0 & 1, v.1 & 1) {
        (1, 0) => DIRS[0],
        (0, 1) => DIRS[1],
        _ => DIRS[2],
    };
    let a = ((v.0 - d.0) >> 1, (v.1 - d.1) >> 1);
    (a, (a.0 + d.0, a.1 + d.1))
}

/// Adds two axial vectors.
#[inline]
pub fn add(a: Axial, b: Axial) -> Axial {
    (a.0 + b.0, a.1 + b.1)
}

/// Reduces `(level, v)` to its coarsest level where the same point is a lattice point, so that
/// one position has one key.
#[inline]
pub fn normalize(mut level: u32, mut v: Axial) -> (u32, Axial) {
    while level > 0 && is_even(v) {
        v = (v.0 >> 1, v.1 >> 1);
        level -= 1;
    }
    (level, v)
}

/// `HALF_POWERS[i]` = 2^-i, exactly.
const HALF_POWERS: [f64; 64] = {
    let mut t = [1.0; 64];
    let mut i = 1;
    while i < 64 {
        t[i] = t[i - 1] * 0.5;
        i += 1;
    }
    t
};

/// Placement of the lattice in the plane: the root hexagon's centre and circumradius.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// Centre of the root hexagon and of Ω.
    pub origin: Vec2,
    /// Circumradius `R` of the root hexagon (level 0). Ω has inradius `3R/4`.
    pub root_radius: f64,
}

impl Frame {
    /// Circumradius of the full hexagons of `level`.
    #[inline]
    pub fn radius(&self, level: u32) -> f64 {
        // 2^-level from a table (exact either way; `powi` is a call on this hot path).
        match HALF_POWERS.get(level as usize) {
            Some(&s) => self.root_radius * s,
            None => self.root_radius * 0.5f64.powi(level as i32),
        }
    }

    /// Position of the centre `v` at `level`.
    #[inline]
    pub fn position(&self, level: u32, v: Axial) -> Vec2 {
        let r = self.radius(level);
        let (a, b) = (v.0 as f64, v.1 as f64);
        Vec2::new(
            self.origin.x + r * 1.5 * a,
            self.origin.y + r * (0.5 * SQRT3 * a + SQRT3 * b),
        )
    }

    /// The six corners of the hexagon `v` at `level`, counter-clockwise from 0°.
    pub fn hexagon(&self, level: u32, v: Axial) -> [Vec2; 6] {
        let c = self.position(level, v);
        let r = self.radius(level);
        std::array::from_fn(|i| {
            let t = std::f64::consts::FRAC_PI_3 * i as f64;
            Vec2::new(c.x + r * t.cos(), c.y + r * t.sin())
        })
    }

    /// The six corners of Ω, counter-clockwise from 30°.
    pub fn domain_corners(&self) -> [Vec2; 6] {
        std::array::from_fn(|i| self.position(1, DIRS[i]))
    }
}

#[cfg(test)]
/// Inradius of Ω for a root hexagon of circumradius `root_radius`.
pub fn domain_inradius(root_radius: f64) -> f64 {
    0.75 * root_radius
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn neighbours_are_sqrt3_r_apart_and_midpoints_decompose() {
        let f = Frame {
            origin: Vec2::new(0.3, -0.2),
            root_radius: 2.0,
        };
        for level in 0..6 {
            let c = f.position(level, (3, -1));
            for d in DIRS {
                let n = f.position(level, add((3, -1), d));
                assert!(((n - c).norm() - SQRT3 * f.radius(level)).abs() < 1e-12);
            }
        }
        for a in -5..5 {
            for b in -5..5 {
                let v = (a, b);
                if !is_even(v) {
                    let (p, q) = parents_of_midpoint(v);
                    assert_eq!(add(p, q), v);
                    assert!(DIRS.contains(&(q.0 - p.0, q.1 - p.1)));
                    // The first parent is the one reached through the first direction of
                    // DIRS (leaf enumeration counts a joined hexagon from that parent).
                    let d = DIRS
                        .into_iter()
                        .find(|d| is_even((v.0 - d.0, v.1 - d.1)))
                        .unwrap();
                    assert_eq!(p, ((v.0 - d.0) / 2, (v.1 - d.1) / 2));
                }
            }
        }
        // Ω's inradius and corners.
        let corners = f.domain_corners();
        for (i, c) in corners.iter().enumerate() {
            assert!(((c - f.origin).norm() - SQRT3 / 2.0 * 2.0).abs() < 1e-12);
            let m = (c + corners[(i + 1) % 6]) * 0.5;
            assert!(((m - f.origin).norm() - domain_inradius(2.0)).abs() < 1e-12);
        }
    }
}
