//! The contract's point-set and segment text formats: one `x y` (or `i j`) per line, `#`
//! comments and blank lines ignored. Parsing only (no filesystem), so the web page can use it.

use crate::Vec2;
use thiserror::Error;

/// Why a point or segment file was rejected.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum PointSetError {
    /// A line does not hold exactly two numbers of the expected kind.
    #[error("line {line}: expected {expected}, found {text}")]
    Malformed {
        /// Line number (1-based).
        line: usize,
        /// What the line should hold.
        expected: &'static str,
        /// The offending line (trimmed, at most 80 characters).
        text: String,
    },
    /// A coordinate is NaN or infinite.
    #[error("line {line}: coordinate is not finite")]
    NonFinite {
        /// Line number (1-based).
        line: usize,
    },
}

fn fields(text: &str) -> impl Iterator<Item = (usize, &str)> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    super::obj::lines_any_end(text)
        .enumerate()
        .filter_map(|(i, l)| {
            let l = l.split('#').next().unwrap_or("").trim();
            (!l.is_empty()).then_some((i + 1, l))
        })
}

fn malformed(line: usize, expected: &'static str, l: &str) -> PointSetError {
    PointSetError::Malformed {
        line,
        expected,
        text: super::obj::quoted(l),
    }
}

/// Parses `x y` lines into points. An empty result is not an error here.
pub fn parse_points(text: &str) -> Result<Vec<Vec2>, PointSetError> {
    let mut out = Vec::new();
    for (line, l) in fields(text) {
        const WHAT: &str = "two numbers `x y`";
        let mut it = l.split_whitespace();
        let (Some(a), Some(b), None) = (it.next(), it.next(), it.next()) else {
            return Err(malformed(line, WHAT, l));
        };
        let (Ok(x), Ok(y)) = (a.parse::<f64>(), b.parse::<f64>()) else {
            return Err(malformed(line, WHAT, l));
        };
        if !x.is_finite() || !y.is_finite() {
            return Err(PointSetError::NonFinite { line });
        }
        out.push(Vec2::new(x, y));
    }
    Ok(out)
}

/// Parses `i j` lines (0-based point indices) into segments.
pub fn parse_segments(text: &str) -> Result<Vec<[usize; 2]>, PointSetError> {
    let mut out = Vec::new();
    for (line, l) in fields(text) {
        const WHAT: &str = "two point indices `i j`";
        let mut it = l.split_whitespace();
        let (Some(a), Some(b), None) = (it.next(), it.next(), it.next()) else {
            return Err(malformed(line, WHAT, l));
        };
        let (Ok(i), Ok(j)) = (a.parse::<usize>(), b.parse::<usize>()) else {
            return Err(malformed(line, WHAT, l));
        };
        out.push([i, j]);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_and_reports_line_numbers() {
        let p = parse_points("# c\n\n1 2\n 3.5e1\t-4 # tail\n").unwrap();
        assert_eq!(p, vec![Vec2::new(1.0, 2.0), Vec2::new(35.0, -4.0)]);
        assert!(matches!(
            parse_points("1 2\n3\n"),
            Err(PointSetError::Malformed { line: 2, .. })
        ));
        assert!(matches!(
            parse_points("1 2\n\n1 x\n"),
            Err(PointSetError::Malformed { line: 3, .. })
        ));
        assert!(matches!(
            parse_points("1 2 3\n"),
            Err(PointSetError::Malformed { line: 1, .. })
        ));
        assert_eq!(
            parse_points("1 nan\n"),
            Err(PointSetError::NonFinite { line: 1 })
        );
        assert_eq!(
            parse_points("inf 0\n"),
            Err(PointSetError::NonFinite { line: 1 })
        );
        assert_eq!(
            parse_segments("0 1\n# x\n2 3").unwrap(),
            vec![[0, 1], [2, 3]]
        );
        assert!(matches!(
            parse_segments("0 -1\n"),
            Err(PointSetError::Malformed { line: 1, .. })
        ));
    }
}
