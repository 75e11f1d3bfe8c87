//! Vector aliases shared by the whole core (nalgebra, double precision).

/// A point or vector in 3D space.
pub type Vec3 = nalgebra::Vector3<f64>;
/// A point or vector in a 2D parameter domain or tangent plane.
pub type Vec2 = nalgebra::Vector2<f64>;
