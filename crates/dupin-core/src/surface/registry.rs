//! Surfaces by name with `KEY=VALUE` parameters: the library the CLI (`dupin surface-info`,
//! `dupin phex --surface`) and the web page choose from (P-Hex paper, sections 3 and 7).

use super::{
    BSplinePatch, Catenoid, Cylinder, DupinCyclide, Ellipsoid, Enneper, HyperbolicParaboloid,
    Hyperboloid, Sphere, Surface, Torus, Vase,
};
use thiserror::Error;

/// Why a surface could not be built from a name and parameters.
///
/// (P-Hex paper, sections 3 and 7.)
#[derive(Debug, Clone, PartialEq, Error)]
pub enum RegistryError {
    /// No surface has this name.
    #[error("unknown surface `{name}` (known: {known})")]
    UnknownSurface {
        /// The name asked for.
        name: String,
        /// Comma-separated list of valid names.
        known: String,
    },
    /// The surface has no parameter with this key.
    #[error("surface `{surface}` has no parameter `{key}` (parameters: {known})")]
    UnknownParameter {
        /// The surface.
        surface: String,
        /// The key given.
        key: String,
        /// Comma-separated list of valid keys.
        known: String,
    },
    /// A `KEY=VALUE` assignment could not be parsed.
    #[error("`{0}` is not of the form KEY=VALUE with a numeric VALUE")]
    Malformed(String),
    /// A value lies outside its documented range (or is not finite, or not an integer where one
    /// is required).
    #[error(
        "parameter `{key}` = {} is out of range [{}, {}]{integer}",
        crate::math::Num(*.value),
        crate::math::Num(*.min),
        crate::math::Num(*.max),
        integer = if *.integer { " (integer)" } else { "" }
    )]
    OutOfRange {
        /// The key.
        key: String,
        /// The value given.
        value: f64,
        /// Smallest allowed value.
        min: f64,
        /// Largest allowed value.
        max: f64,
        /// Whether the value must be an integer.
        integer: bool,
    },
    /// The values are each in range but violate a relation between parameters (e.g. r < R).
    #[error("{0}")]
    Constraint(String),
}

/// One parameter of a library surface.
///
/// (P-Hex paper, sections 3 and 7.)
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParamSpec {
    /// The key used in `KEY=VALUE`.
    pub key: &'static str,
    /// Value when not given.
    pub default: f64,
    /// Smallest allowed value (inclusive).
    pub min: f64,
    /// Largest allowed value (inclusive).
    pub max: f64,
    /// Whether the value must be an integer.
    pub integer: bool,
    /// What the parameter means.
    pub doc: &'static str,
}

/// A library surface: name, parametrisation and parameters (see [`surface_catalog`]).
///
/// (P-Hex paper, sections 3 and 7.)
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceSpec {
    /// The name used by `--surface NAME`.
    pub name: &'static str,
    /// The parametrisation P(u, v) and its domain.
    pub parametrisation: &'static str,
    /// Parameters with defaults and ranges.
    pub params: &'static [ParamSpec],
}

/// A real parameter with its own range `[min, max]`: the one place a catalogue entry is spelt
/// out, so the catalogue below reads as a table of (key, default, range, meaning).
const fn real(key: &'static str, default: f64, min: f64, max: f64, doc: &'static str) -> ParamSpec {
    ParamSpec {
        key,
        default,
        min,
        max,
        integer: false,
        doc,
    }
}

/// A length (radius, semi-axis, extent): positive, with the range every length shares.
const fn len(key: &'static str, default: f64, doc: &'static str) -> ParamSpec {
    real(key, default, 1e-6, 1e6, doc)
}

/// A count of control points: a real range whose values must also be integers.
const fn count(
    key: &'static str,
    default: f64,
    min: f64,
    max: f64,
    doc: &'static str,
) -> ParamSpec {
    ParamSpec {
        integer: true,
        ..real(key, default, min, max, doc)
    }
}

static CATALOG: &[SurfaceSpec] = &[
    SurfaceSpec {
        name: "sphere",
        parametrisation: "radius (cos v cos u, cos v sin u, sin v), u in [0, 2pi) periodic, v in [-pi/2, pi/2]",
        params: &[len("radius", 1.0, "radius")],
    },
    SurfaceSpec {
        name: "ellipsoid",
        parametrisation: "(a cos v cos u, b cos v sin u, c sin v), u in [0, 2pi) periodic, v in [-pi/2, pi/2]",
        params: &[
            len("a", 1.5, "semi-axis along x"),
            len("b", 1.0, "semi-axis along y"),
            len("c", 0.8, "semi-axis along z"),
        ],
    },
    SurfaceSpec {
        name: "torus",
        parametrisation: "((R + r cos v) cos u, (R + r cos v) sin u, r sin v), u, v in [0, 2pi) periodic; needs r < R",
        params: &[
            len("R", 2.0, "distance from the axis to the tube centre"),
            len("r", 0.7, "tube radius (< R)"),
        ],
    },
    SurfaceSpec {
        name: "hyperboloid",
        parametrisation: "(a cosh v cos u, a cosh v sin u, c sinh v), u in [0, 2pi) periodic, v in [-vmax, vmax]",
        params: &[
            len("a", 1.0, "waist radius"),
            len("c", 1.0, "vertical scale"),
            real("vmax", 1.2, 1e-3, 10.0, "half-range of v"),
        ],
    },
    SurfaceSpec {
        name: "hyperbolic-paraboloid",
        parametrisation: "(u, v, u^2/(2a) - v^2/(2b)), u, v in [-size, size]",
        params: &[
            len("a", 1.0, "radius of curvature along x at the apex"),
            len("b", 1.0, "radius of curvature along y at the apex"),
            len("size", 1.5, "half-extent of the square domain"),
        ],
    },
    SurfaceSpec {
        name: "dupin-cyclide",
        parametrisation: "ring cyclide, d = a - c cos u cos v: ((mu (c - a cos u cos v) + b^2 cos u)/d, b sin u (a - mu cos v)/d, b sin v (c cos u - mu)/d), b^2 = a^2 - c^2, u, v in [0, 2pi) periodic; needs 0 <= c < mu < a",
        params: &[
            len("a", 2.0, "semi-major axis of the focal ellipse"),
            real("c", 0.6, 0.0, 1e6, "focal distance (0 gives a torus)"),
            len("mu", 1.1, "sphere-radius parameter (c < mu < a)"),
        ],
    },
    SurfaceSpec {
        name: "vase",
        parametrisation: "(rho cos u, rho sin u, v), rho = radius + amplitude sin(2 pi v / height), u in [0, 2pi) periodic, v in [0, height]; parabolic circle at v = height/2",
        params: &[
            len("radius", 1.0, "mean radius"),
            len("amplitude", 0.35, "profile amplitude (< radius)"),
            len("height", 3.0, "height"),
        ],
    },
    SurfaceSpec {
        name: "catenoid",
        parametrisation: "(c cosh(v/c) cos u, c cosh(v/c) sin u, v), u in [0, 2pi) periodic, v in [-height/2, height/2]",
        params: &[len("c", 1.0, "waist radius"), len("height", 3.0, "height")],
    },
    SurfaceSpec {
        name: "enneper",
        parametrisation: "scale (u - u^3/3 + u v^2, v - v^3/3 + v u^2, u^2 - v^2), u, v in [-extent, extent]",
        params: &[
            len("scale", 1.0, "uniform scale"),
            real(
                "extent",
                1.0,
                1e-3,
                1.2,
                "half-extent of the square domain (embedded up to 1.2)",
            ),
        ],
    },
    SurfaceSpec {
        name: "cylinder",
        parametrisation: "(radius cos u, radius sin u, v), u in [0, 2pi) periodic, v in [0, height]",
        params: &[len("radius", 1.0, "radius"), len("height", 2.0, "height")],
    },
    SurfaceSpec {
        name: "bspline",
        parametrisation: "uniform bicubic B-spline patch, control net (x_i, y_j, amplitude sin(1.2 x_i) cos(0.9 y_j) + 0.1 (x_i^2 + y_j^2)) on an nu x nv grid over [-size, size]^2, u in [0, nu - 3], v in [0, nv - 3]",
        params: &[
            count("nu", 8.0, 4.0, 256.0, "control points along u"),
            count("nv", 8.0, 4.0, 256.0, "control points along v"),
            len("size", 2.0, "half-extent of the control net"),
            real("amplitude", 0.5, -1e6, 1e6, "height of the waves"),
        ],
    },
];

/// The surface library: every name with its parametrisation and parameters (what
/// `dupin surface-info --list` prints).
///
/// (P-Hex paper, sections 3 and 7.)
pub fn surface_catalog() -> &'static [SurfaceSpec] {
    CATALOG
}

/// Builds the library surface `name` with `params` (`(key, value)` pairs; missing keys take
/// their defaults, later pairs override earlier ones).
///
/// Errors: unknown name or key, value out of its documented range, non-integer where an integer
/// is required, or a violated relation between parameters (torus r < R, cyclide c < mu < a,
/// vase amplitude < radius).
///
/// (P-Hex paper, sections 3 and 7.)
pub fn surface_by_name(
    name: &str,
    params: &[(&str, f64)],
) -> Result<Box<dyn Surface>, RegistryError> {
    let spec =
        CATALOG
            .iter()
            .find(|s| s.name == name)
            .ok_or_else(|| RegistryError::UnknownSurface {
                name: name.to_string(),
                known: CATALOG
                    .iter()
                    .map(|s| s.name)
                    .collect::<Vec<_>>()
                    .join(", "),
            })?;
    let mut values: Vec<f64> = spec.params.iter().map(|p| p.default).collect();
    for &(key, value) in params {
        let k = spec
            .params
            .iter()
            .position(|p| p.key == key)
            .ok_or_else(|| RegistryError::UnknownParameter {
                surface: name.to_string(),
                key: key.to_string(),
                known: spec
                    .params
                    .iter()
                    .map(|p| p.key)
                    .collect::<Vec<_>>()
                    .join(", "),
            })?;
        let p = &spec.params[k];
        if !(value.is_finite() && value >= p.min && value <= p.max)
            || (p.integer && value.fract() != 0.0)
        {
            return Err(RegistryError::OutOfRange {
                key: key.to_string(),
                value,
                min: p.min,
                max: p.max,
                integer: p.integer,
            });
        }
        values[k] = value;
    }
    let v = &values;
    Ok(match name {
        "sphere" => Box::new(Sphere { radius: v[0] }),
        "ellipsoid" => Box::new(Ellipsoid::new(v[0], v[1], v[2])?),
        "torus" => {
            if v[1] >= v[0] {
                return Err(RegistryError::Constraint(format!(
                    "torus needs r < R, got R = {}, r = {}",
                    v[0], v[1]
                )));
            }
            Box::new(Torus {
                major: v[0],
                minor: v[1],
            })
        }
        "hyperboloid" => Box::new(Hyperboloid::new(v[0], v[1], v[2])?),
        "hyperbolic-paraboloid" => Box::new(HyperbolicParaboloid::new(v[0], v[1], v[2])?),
        "dupin-cyclide" => Box::new(DupinCyclide::new(v[0], v[1], v[2])?),
        "vase" => Box::new(Vase::new(v[0], v[1], v[2])?),
        "catenoid" => Box::new(Catenoid::new(v[0], v[1])?),
        "enneper" => Box::new(Enneper::new(v[0], v[1])?),
        "cylinder" => Box::new(Cylinder::new(v[0], v[1])?),
        "bspline" => {
            let amp = v[3];
            let patch =
                BSplinePatch::from_height_field(v[0] as usize, v[1] as usize, v[2], |x, y| {
                    amp * (1.2 * x).sin() * (0.9 * y).cos() + 0.1 * (x * x + y * y)
                })
                .map_err(|e| RegistryError::Constraint(e.to_string()))?;
            Box::new(patch)
        }
        _ => unreachable!("every catalog name is constructed above"),
    })
}

/// Parses one `KEY=VALUE` assignment (as given to `--set`).
///
/// (P-Hex paper, sections 3 and 7.)
pub fn parse_assignment(s: &str) -> Result<(String, f64), RegistryError> {
    let (k, v) = s
        .split_once('=')
        .ok_or_else(|| RegistryError::Malformed(s.to_string()))?;
    let key = k.trim();
    let value: f64 = v
        .trim()
        .parse()
        .map_err(|_| RegistryError::Malformed(s.to_string()))?;
    if key.is_empty() {
        return Err(RegistryError::Malformed(s.to_string()));
    }
    Ok((key.to_string(), value))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::{CurvatureTolerance, PointType};

    #[test]
    fn every_catalog_surface_builds_with_defaults_and_is_regular_inside() {
        for spec in surface_catalog() {
            let s = surface_by_name(spec.name, &[]).unwrap();
            let d = s.domain();
            for i in 1..8 {
                for j in 1..8 {
                    let u = d.u.0 + (d.u.1 - d.u.0) * i as f64 / 8.0;
                    let v = d.v.0 + (d.v.1 - d.v.0) * j as f64 / 8.0;
                    let c = s.curvature(u, v).unwrap();
                    assert!(c.k1.is_finite() && c.k2.is_finite(), "{}", spec.name);
                }
            }
            for p in spec.params {
                assert!(
                    p.min <= p.default && p.default <= p.max,
                    "{}.{}",
                    spec.name,
                    p.key
                );
            }
        }
    }

    #[test]
    fn contract_parametrisations() {
        let s = surface_by_name("torus", &[("R", 3.0), ("r", 1.0)]).unwrap();
        let (u, v) = (0.4_f64, 1.1_f64);
        let w = 3.0 + v.cos();
        let want = crate::Vec3::new(w * u.cos(), w * u.sin(), v.sin());
        assert!((s.position(u, v) - want).norm() < 1e-14);
        let s = surface_by_name("hyperboloid", &[("a", 2.0), ("c", 0.5)]).unwrap();
        let want = crate::Vec3::new(
            2.0 * v.cosh() * u.cos(),
            2.0 * v.cosh() * u.sin(),
            0.5 * v.sinh(),
        );
        assert!((s.position(u, v) - want).norm() < 1e-14);
        let s = surface_by_name("sphere", &[("radius", 2.0)]).unwrap();
        let want = 2.0 * crate::Vec3::new(v.cos() * u.cos(), v.cos() * u.sin(), v.sin());
        assert!((s.position(u, v) - want).norm() < 1e-14);
    }

    #[test]
    fn typed_errors_for_bad_input() {
        assert!(matches!(
            surface_by_name("klein-bottle", &[]),
            Err(RegistryError::UnknownSurface { .. })
        ));
        assert!(matches!(
            surface_by_name("torus", &[("q", 1.0)]),
            Err(RegistryError::UnknownParameter { .. })
        ));
        assert!(matches!(
            surface_by_name("torus", &[("r", -1.0)]),
            Err(RegistryError::OutOfRange { .. })
        ));
        assert!(matches!(
            surface_by_name("torus", &[("r", f64::NAN)]),
            Err(RegistryError::OutOfRange { .. })
        ));
        assert!(matches!(
            surface_by_name("torus", &[("r", 3.0)]),
            Err(RegistryError::Constraint(_))
        ));
        assert!(matches!(
            surface_by_name("bspline", &[("nu", 5.5)]),
            Err(RegistryError::OutOfRange { .. })
        ));
        assert!(matches!(
            surface_by_name("dupin-cyclide", &[("mu", 0.5)]),
            Err(RegistryError::Constraint(_))
        ));
        assert!(parse_assignment("R=2.5").unwrap() == ("R".to_string(), 2.5));
        assert!(parse_assignment("R2.5").is_err());
        assert!(parse_assignment("R=abc").is_err());
        assert!(parse_assignment("=1").is_err());
    }

    #[test]
    fn default_freeform_and_vase_carry_both_signs_of_k() {
        let tol = CurvatureTolerance::default();
        for name in ["bspline", "vase", "dupin-cyclide", "torus"] {
            let s = surface_by_name(name, &[]).unwrap();
            let d = s.domain();
            let (mut pos, mut neg) = (0, 0);
            for i in 0..20 {
                for j in 0..20 {
                    let u = d.u.0 + (d.u.1 - d.u.0) * (i as f64 + 0.5) / 20.0;
                    let v = d.v.0 + (d.v.1 - d.v.0) * (j as f64 + 0.5) / 20.0;
                    match s.curvature(u, v).unwrap().point_type(&tol) {
                        PointType::Elliptic => pos += 1,
                        PointType::Hyperbolic => neg += 1,
                        _ => {}
                    }
                }
            }
            assert!(
                pos > 20 && neg > 20,
                "{name}: {pos} elliptic, {neg} hyperbolic"
            );
        }
    }
}
