//! The names of the core's choices (methods, initialisations, modes) as the CLI and the page
//! spell them: each enum's [`FromStr`](std::str::FromStr), `name()` and `Display` are made here,
//! in one place, by `named_choices!`.

use thiserror::Error;

/// A name that is none of a choice's names.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[error(
    "{what} must be {}, not {}",
    one_of(expected),
    crate::mesh::io::quoted(given)
)]
pub struct UnknownName {
    /// What was being named (`method`, `init`, `mode`).
    pub what: &'static str,
    /// The name given.
    pub given: String,
    /// The accepted names.
    pub expected: &'static [&'static str],
}

/// "`a` or `b`", "`a`, `b` or `c`".
fn one_of(names: &[&str]) -> String {
    let quoted: Vec<String> = names.iter().map(|n| format!("`{n}`")).collect();
    match quoted.split_last() {
        None => String::new(),
        Some((last, [])) => last.clone(),
        Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
    }
}

/// Gives a fieldless enum its names: `NAMES`, `name()`, `Display` and `FromStr` (error
/// [`UnknownName`] with `what`).
macro_rules! named_choices {
    ($ty:ty, $what:literal, { $($variant:ident => $name:literal),+ $(,)? }) => {
        impl $ty {
            /// Every accepted name, in declaration order.
            pub const NAMES: &'static [&'static str] = &[$($name),+];

            /// The name the CLI and the page use.
            pub fn name(self) -> &'static str {
                match self {
                    $(<$ty>::$variant => $name),+
                }
            }
        }

        impl std::fmt::Display for $ty {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str(self.name())
            }
        }

        impl std::str::FromStr for $ty {
            type Err = $crate::UnknownName;

            fn from_str(s: &str) -> Result<Self, Self::Err> {
                match s {
                    $($name => Ok(<$ty>::$variant),)+
                    _ => Err($crate::UnknownName {
                        what: $what,
                        given: s.to_string(),
                        expected: Self::NAMES,
                    }),
                }
            }
        }
    };
}
pub(crate) use named_choices;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_list_the_names() {
        let e = |expected| UnknownName {
            what: "mode",
            given: "fancy".into(),
            expected,
        };
        assert_eq!(
            e(&["simple", "extended"]).to_string(),
            "mode must be `simple` or `extended`, not `fancy`"
        );
        assert_eq!(
            e(&["planar", "conical", "circular"]).to_string(),
            "mode must be `planar`, `conical` or `circular`, not `fancy`"
        );
    }

    /// Every accepted name parses to the choice whose `name()` and `Display` give it back;
    /// the strings are those of the CLI and the page.
    #[test]
    fn names_round_trip() {
        use crate::conical::PqMode;
        use crate::hex_delaunay::HexDelaunayMode;
        use crate::phex::{Initialisation, TriangulationMethod};
        fn check<T>(names: &[&str])
        where
            T: std::str::FromStr<Err = UnknownName> + std::fmt::Display,
        {
            for n in names {
                let t: T = n.parse().unwrap();
                assert_eq!(t.to_string(), *n);
            }
            let e = "nope".parse::<T>().err().unwrap();
            assert_eq!(e.given, "nope");
        }
        assert_eq!(TriangulationMethod::NAMES, ["progressive", "prescribed"]);
        assert_eq!(Initialisation::NAMES, ["tangent-duality", "dupin-duality"]);
        assert_eq!(PqMode::NAMES, ["planar", "conical", "circular"]);
        assert_eq!(HexDelaunayMode::NAMES, ["simple", "extended"]);
        check::<TriangulationMethod>(TriangulationMethod::NAMES);
        check::<Initialisation>(Initialisation::NAMES);
        check::<PqMode>(PqMode::NAMES);
        check::<HexDelaunayMode>(HexDelaunayMode::NAMES);
        assert_eq!(
            "x".parse::<Initialisation>().unwrap_err().to_string(),
            "init must be `tangent-duality` or `dupin-duality`, not `x`"
        );
        assert_eq!(
            "x".parse::<TriangulationMethod>().unwrap_err().to_string(),
            "method must be `progressive` or `prescribed`, not `x`"
        );
    }
}
