//! Triangle stars in the tangent plane, as a person edits them (P-Hex paper, sections 4.1, 4.2
//! and 6): a mesh vertex's star projected onto the tangent plane in the principal frame, and
//! the rules that move one ring vertex of a lattice star or of a projected mesh star while
//! keeping every triangle non-degenerate. Coordinates are principal-frame (x along the k1
//! direction, y along k2), centred at the star's centre.

use crate::Vec2;
use crate::Vec3;
use crate::phex::{TriangleStar, TriangleStarError};
use crate::surface::Curvature;
use thiserror::Error;

/// Why a star cannot be projected or a ring vertex cannot move there.
#[derive(Debug, Clone, Copy, PartialEq, Error)]
pub enum StarEditError {
    /// A ring vertex of the 3D star is NaN or infinite.
    #[error("star vertices must be finite")]
    NonFiniteStar,
    /// The projection of triangle `index` (centre, `ring[index]`, `ring[index + 1]`) is degenerate.
    #[error("{error}: triangle {index} of the star is flat in the tangent plane")]
    FlatProjection {
        /// What the triangle test found.
        error: TriangleStarError,
        /// The triangle, 0..6.
        index: usize,
    },
    /// The target position is NaN or infinite.
    #[error("vertex position must be finite, got ({0}, {1})")]
    NonFinitePosition(f64, f64),
    /// The ring vertex index is not 0..5.
    #[error("star vertex index must be 0..5, got {0}")]
    BadIndex(usize),
    /// The move would make a triangle of the star degenerate.
    #[error("{0}: the dragged vertex would make the star's triangles flat")]
    FlatAfterDrag(TriangleStarError),
}

/// The projected triangle star of a mesh vertex (section 6, step 2): the six ring neighbours
/// `ring` (counter-clockwise) projected orthogonally onto the tangent plane at `curv.point`,
/// in the principal frame of `curv`.
///
/// Errors: [`StarEditError::NonFiniteStar`] for a non-finite neighbour,
/// [`StarEditError::FlatProjection`] when a projected triangle is degenerate.
pub fn project_star(curv: &Curvature, ring: &[Vec3; 6]) -> Result<[Vec2; 6], StarEditError> {
    if !ring.iter().all(|p| p.iter().all(|x| x.is_finite())) {
        return Err(StarEditError::NonFiniteStar);
    }
    let f = curv.frame();
    let r: [Vec2; 6] = ring.map(|p| f.to_local(&p));
    for i in 0..6 {
        TriangleStar::new(Vec2::zeros(), r[i], r[(i + 1) % 6])
            .map_err(|error| StarEditError::FlatProjection { error, index: i })?;
    }
    Ok(r)
}

fn finite(q: Vec2) -> Result<(), StarEditError> {
    if q.x.is_finite() && q.y.is_finite() {
        Ok(())
    } else {
        Err(StarEditError::NonFinitePosition(q.x, q.y))
    }
}

/// Moves ring vertex `index` of the lattice star with fundamental triangle (0, a, b) to `q`
/// (section 4.2: ring a, b, b - a, -a, -b, a - b). The star stays a lattice star, so the
/// opposite vertex moves symmetrically; returns the new (a, b).
///
/// Errors: a non-finite `q`, an index outside 0..5, a degenerate fundamental triangle after
/// the move.
pub fn drag_lattice_star(
    a: Vec2,
    b: Vec2,
    index: usize,
    q: Vec2,
) -> Result<(Vec2, Vec2), StarEditError> {
    finite(q)?;
    let (a, b) = match index {
        0 => (q, b),
        1 => (a, q),
        2 => (a, q + a),
        3 => (-q, b),
        4 => (a, -q),
        5 => (q + b, b),
        _ => return Err(StarEditError::BadIndex(index)),
    };
    TriangleStar::new(Vec2::zeros(), a, b).map_err(StarEditError::FlatAfterDrag)?;
    Ok((a, b))
}

/// Moves ring vertex `index` of a projected mesh star (six independent triangles, centre at
/// the origin) to `q`; only that vertex moves. Returns the new ring.
///
/// Errors: a non-finite `q`, an index outside 0..5, a degenerate triangle next to the moved
/// vertex.
pub fn drag_star_vertex(
    ring: [Vec2; 6],
    index: usize,
    q: Vec2,
) -> Result<[Vec2; 6], StarEditError> {
    finite(q)?;
    if index >= 6 {
        return Err(StarEditError::BadIndex(index));
    }
    let mut r = ring;
    r[index] = q;
    for i in [(index + 5) % 6, index] {
        TriangleStar::new(Vec2::zeros(), r[i], r[(i + 1) % 6])
            .map_err(StarEditError::FlatAfterDrag)?;
    }
    Ok(r)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::{Surface, Torus};

    #[test]
    fn lattice_drag_moves_the_opposite_vertex_and_refuses_flat_stars() {
        let (a, b) = (Vec2::new(0.3, 0.0), Vec2::new(0.1, 0.4));
        let (a2, b2) = drag_lattice_star(a, b, 3, Vec2::new(-0.2, -0.1)).unwrap();
        assert_eq!((a2, b2), (Vec2::new(0.2, 0.1), b));
        let ring = TriangleStar::new(Vec2::zeros(), a2, b2).unwrap().ring();
        assert_eq!((ring[0], ring[3]), (a2, -a2));
        assert_eq!(
            drag_lattice_star(a2, b2, 1, Vec2::new(0.4, 0.2)),
            Err(StarEditError::FlatAfterDrag(
                TriangleStarError::DegenerateTriangle
            )),
            "b parallel to a"
        );
        assert!(drag_lattice_star(a, b, 0, Vec2::new(f64::NAN, 0.0)).is_err());
        assert_eq!(
            drag_lattice_star(a, b, 6, Vec2::new(0.1, 0.1)),
            Err(StarEditError::BadIndex(6))
        );
    }

    #[test]
    fn star_vertex_drag_moves_one_vertex_and_projection_is_in_the_principal_frame() {
        let torus = Torus {
            major: 2.0,
            minor: 0.7,
        };
        let c = torus.curvature(0.3, 0.2).unwrap();
        let f = c.frame();
        let flat = [
            Vec2::new(0.1, 0.0),
            Vec2::new(0.05, 0.1),
            Vec2::new(-0.05, 0.1),
            Vec2::new(-0.1, 0.0),
            Vec2::new(-0.05, -0.1),
            Vec2::new(0.05, -0.1),
        ];
        // Lifted along the normal: the projection drops the lift.
        let ring = flat.map(|q| f.to_world(&q) + c.normal * 0.01);
        let r = project_star(&c, &ring).unwrap();
        for (got, want) in r.iter().zip(flat) {
            assert!((got - want).norm() < 1e-12);
        }
        let moved = drag_star_vertex(r, 2, Vec2::new(-0.09, 0.11)).unwrap();
        for i in 0..6 {
            assert_eq!(moved[i] == r[i], i != 2, "vertex {i}");
        }
        assert!(drag_star_vertex(r, 2, 2.0 * r[1]).is_err());
        assert_eq!(
            drag_star_vertex(r, 6, Vec2::zeros()),
            Err(StarEditError::BadIndex(6))
        );
        let mut collapsed = ring;
        collapsed[3] = c.point;
        assert!(matches!(
            project_star(&c, &collapsed),
            Err(StarEditError::FlatProjection { .. })
        ));
        collapsed[3] = Vec3::new(f64::NAN, 0.0, 0.0);
        assert_eq!(
            project_star(&c, &collapsed),
            Err(StarEditError::NonFiniteStar)
        );
    }
}
