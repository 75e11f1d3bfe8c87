//! Vector aliases shared by the whole core (nalgebra, double precision).

/// A point or vector in 3D space.
pub type Vec3 = nalgebra::Vector3<f64>;
/// A point or vector in a 2D parameter domain or tangent plane.
pub type Vec2 = nalgebra::Vector2<f64>;

/// A number as a message shows it: as typed for everyday magnitudes (`0.25`, `1500`), in
/// exponent form beyond (`1e300`, `2.5e-9`) so that no message prints 300 digits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Num(pub f64);

impl std::fmt::Display for Num {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let a = self.0.abs();
        if a == 0.0 || !a.is_finite() || (1e-4..1e9).contains(&a) {
            write!(f, "{}", self.0)
        } else {
            write!(f, "{:e}", self.0)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Num;

    #[test]
    fn numbers_in_messages_stay_short() {
        let shown = |x: f64| Num(x).to_string();
        assert_eq!(shown(0.25), "0.25");
        assert_eq!(shown(-1500.0), "-1500");
        assert_eq!(shown(1e300), "1e300");
        assert_eq!(shown(-2.5e-9), "-2.5e-9");
        assert_eq!(shown(f64::NAN), "NaN");
        assert_eq!(shown(0.0), "0");
    }
}
