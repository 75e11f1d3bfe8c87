//! Length units of a design. Every import has one (from the file, or chosen: mm, cm, m, in,
//! ft; default m); fabrication files are written in millimetres and reports in m, m² and mm.

use std::fmt;
use std::str::FromStr;

/// A length unit of a design's coordinates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LengthUnit {
    /// Millimetres.
    Millimetre,
    /// Centimetres.
    Centimetre,
    /// Metres (the default).
    #[default]
    Metre,
    /// Inches.
    Inch,
    /// Feet.
    Foot,
}

/// Every unit, in the order a page offers them.
pub const LENGTH_UNITS: [LengthUnit; 5] = [
    LengthUnit::Millimetre,
    LengthUnit::Centimetre,
    LengthUnit::Metre,
    LengthUnit::Inch,
    LengthUnit::Foot,
];

impl LengthUnit {
    /// The unit's short name: `mm`, `cm`, `m`, `in`, `ft`.
    pub fn name(self) -> &'static str {
        match self {
            LengthUnit::Millimetre => "mm",
            LengthUnit::Centimetre => "cm",
            LengthUnit::Metre => "m",
            LengthUnit::Inch => "in",
            LengthUnit::Foot => "ft",
        }
    }

    /// Millimetres in one unit (exact by the definitions of the inch and the foot).
    pub fn to_mm(self) -> f64 {
        match self {
            LengthUnit::Millimetre => 1.0,
            LengthUnit::Centimetre => 10.0,
            LengthUnit::Metre => 1000.0,
            LengthUnit::Inch => 25.4,
            LengthUnit::Foot => 304.8,
        }
    }

    /// Metres in one unit.
    pub fn to_m(self) -> f64 {
        self.to_mm() / 1000.0
    }
}

impl fmt::Display for LengthUnit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A unit name that is not one of `mm`, `cm`, `m`, `in`, `ft`.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown length unit {0}; use mm, cm, m, in or ft")]
pub struct UnknownUnit(String);

impl FromStr for LengthUnit {
    type Err = UnknownUnit;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        LENGTH_UNITS
            .into_iter()
            .find(|u| u.name() == s)
            .ok_or_else(|| UnknownUnit(crate::mesh::io::quoted(s)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_scales_are_exact() {
        for u in LENGTH_UNITS {
            assert_eq!(u.name().parse::<LengthUnit>(), Ok(u));
        }
        assert!((LengthUnit::Foot.to_mm() - 12.0 * LengthUnit::Inch.to_mm()).abs() < 1e-12);
        assert_eq!(LengthUnit::default(), LengthUnit::Metre);
        let e = "yd".parse::<LengthUnit>().unwrap_err().to_string();
        assert_eq!(e, "unknown length unit `yd`; use mm, cm, m, in or ft");
    }
}
