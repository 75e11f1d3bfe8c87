//! Face colour maps of the three per-face measures a panel mesh is judged by: planarity (the
//! contract's measure, [`super::face_planarity`]), convexity and validity (P-Hex paper,
//! section 4.1: a valid hexagon is a simple polygon) and shape regularity (P-Hex paper,
//! section 4.2: the deviation from the affine regular or quasi-regular hexagon). Colours are
//! linear RGB in 0..1; each map comes with the stops a legend shows, so the legend and the
//! panels cannot disagree.

use thiserror::Error;

/// What the panels are coloured by.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ColorMode {
    /// Log planarity error, [`planarity_color`].
    Planarity,
    /// Convex, non-convex or self-intersecting, [`convexity_color`].
    Convexity,
    /// Hexagon shape deviation, [`regularity_color`].
    Regularity,
}

/// A colour mode name that is not one of [`ColorMode::ALL`]'s.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[error("colour mode must be `planarity`, `convexity` or `regularity`, not `{0}`")]
pub struct ColorModeError(pub String);

impl ColorMode {
    /// Every mode, the default ([`ColorMode::Planarity`]) first.
    pub const ALL: [ColorMode; 3] = [
        ColorMode::Planarity,
        ColorMode::Convexity,
        ColorMode::Regularity,
    ];

    /// The mode's name: `planarity`, `convexity` or `regularity`.
    pub fn name(self) -> &'static str {
        match self {
            ColorMode::Planarity => "planarity",
            ColorMode::Convexity => "convexity",
            ColorMode::Regularity => "regularity",
        }
    }

    /// The mode of `name` ([`ColorMode::name`]); the empty name is the default, planarity.
    ///
    /// Errors: [`ColorModeError`] for any other name.
    pub fn parse(name: &str) -> Result<Self, ColorModeError> {
        if name.is_empty() {
            return Ok(ColorMode::Planarity);
        }
        Self::ALL
            .into_iter()
            .find(|m| m.name() == name)
            .ok_or_else(|| ColorModeError(name.to_string()))
    }
}

/// A strictly convex face.
pub const CONVEX: [f32; 3] = [0.25, 0.6, 0.35];
/// A simple face that is not convex.
pub const NONCONVEX: [f32; 3] = [0.9, 0.65, 0.15];
/// A self-intersecting face (not a valid panel).
pub const INVALID: [f32; 3] = [0.85, 0.15, 0.15];
/// A face with no regularity measure (not a hexagon).
pub const NOT_HEX: [f32; 3] = [0.45, 0.45, 0.48];

/// log10 of the planarity values a planarity legend labels (1e-15 to 1e-2: the ramp's ends
/// and its white middle).
pub const PLANARITY_LEGEND_LOG10: [f64; 5] = [-15.0, -12.0, -8.5, -5.0, -2.0];
/// The shape deviations a regularity legend labels (0 to the ramp's end, 0.4).
pub const REGULARITY_LEGEND: [f64; 5] = [0.0, 0.1, 0.2, 0.3, 0.4];

/// Colour of a face by validity and convexity: [`INVALID`] when not `simple`, else
/// [`CONVEX`] or [`NONCONVEX`].
pub fn convexity_color(simple: bool, convex: bool) -> [f32; 3] {
    if !simple {
        INVALID
    } else if convex {
        CONVEX
    } else {
        NONCONVEX
    }
}

/// Shape deviation `d` (P-Hex paper, section 4.2) 0 (regular: blue) -> 0.4 and above (red),
/// linear.
pub fn regularity_color(d: f64) -> [f32; 3] {
    let t = (d / 0.4).clamp(0.0, 1.0) as f32;
    let (a, b) = ([0.20, 0.45, 0.85], [0.85, 0.20, 0.15]);
    [0, 1, 2].map(|k| a[k] + (b[k] - a[k]) * t)
}

/// Planarity error `p` ([`super::face_planarity`]): blue (planar to 1e-15, about the rounding
/// of f64) -> white (1e-8.5) -> red (1e-2 and worse), log scale. The floor is that low so the
/// last exact (SQP) steps, which take planarity from ~1e-12 to ~1e-15 by sub-pixel moves,
/// still show as a change.
pub fn planarity_color(p: f64) -> [f32; 3] {
    let t = ((p.max(1e-15).log10() + 15.0) / 13.0).clamp(0.0, 1.0) as f32;
    let (blue, white, red) = ([0.20, 0.45, 0.85], [0.92, 0.92, 0.92], [0.85, 0.20, 0.15]);
    let mix = |a: [f32; 3], b: [f32; 3], s: f32| [0, 1, 2].map(|k| a[k] + (b[k] - a[k]) * s);
    if t < 0.5 {
        mix(blue, white, t * 2.0)
    } else {
        mix(white, red, t * 2.0 - 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colour_ramps_are_ordered_and_clamped() {
        assert_eq!(planarity_color(0.0), planarity_color(1e-15));
        assert_eq!(planarity_color(1.0), planarity_color(1e-2));
        assert!(planarity_color(1e-15)[2] > planarity_color(1e-15)[0]);
        assert_ne!(planarity_color(1e-12), planarity_color(1e-15));
        assert!(planarity_color(1e-2)[0] > planarity_color(1e-2)[2]);
        assert_eq!(regularity_color(0.4), regularity_color(3.0));
        assert!(regularity_color(0.0)[2] > regularity_color(0.0)[0]);
    }

    #[test]
    fn modes_round_trip_and_the_empty_name_is_planarity() {
        for m in ColorMode::ALL {
            assert_eq!(ColorMode::parse(m.name()), Ok(m));
        }
        assert_eq!(ColorMode::parse(""), Ok(ColorMode::Planarity));
        assert_eq!(
            ColorMode::parse("heat").unwrap_err().to_string(),
            "colour mode must be `planarity`, `convexity` or `regularity`, not `heat`"
        );
        assert_eq!(convexity_color(false, true), INVALID);
        assert_eq!(convexity_color(true, false), NONCONVEX);
    }
}
