//! Why a hexagonal Delaunay triangulation was refused.

use thiserror::Error;

/// Errors of [`crate::hex_delaunay::hex_delaunay`] and [`crate::hex_delaunay::HexDelaunayStepper`].
#[derive(Debug, Clone, PartialEq, Error)]
pub enum HexDelaunayError {
    /// No input points were given.
    #[error("no input points")]
    Empty,
    /// An input coordinate is NaN or infinite.
    #[error("point {index} has a non-finite coordinate")]
    NonFinite {
        /// Index of the point (0-based).
        index: usize,
    },
    /// An input coordinate is too large in magnitude for the lattice arithmetic.
    #[error("point {index} has a coordinate of magnitude {value:e}, above the limit {limit:e}")]
    TooLarge {
        /// Index of the point (0-based).
        index: usize,
        /// The offending magnitude.
        value: f64,
        /// The largest accepted magnitude.
        limit: f64,
    },
    /// The points span so small an extent that the hexagons would underflow.
    #[error("the points span only {extent:e}, below the limit {limit:e}")]
    TooSmall {
        /// Radius of the points' minimum enclosing circle.
        extent: f64,
        /// The smallest accepted radius.
        limit: f64,
    },
    /// Refinement would need hexagons finer than the hierarchy depth cap: two points are too close
    /// relative to the extent and position of the point set for double precision.
    #[error(
        "hexagon hierarchy would exceed its depth cap of {max_level} levels (points too close \
         together relative to their extent and offset from the origin)"
    )]
    DepthLimit {
        /// The cap on full-hexagon levels.
        max_level: u32,
    },
    /// The refinement would split more hexagons than its budget allows.
    #[error(
        "the refinement passes its limit of {limit} split hexagons (about {} triangles): points \
         very close together relative to the extent of the set, above all near segments, need \
         that many; space them out, or raise the limit (--max-splits) if this is intended",
        6 * limit
    )]
    TooManySplits {
        /// The cap on split hexagons.
        limit: usize,
    },
    /// A point inserted into an existing triangulation lies outside (or on) its bounding
    /// hexagon Ω.
    #[error("inserted point {index} lies outside the bounding hexagon")]
    OutsideDomain {
        /// Index of the point in the inserted batch (0-based).
        index: usize,
    },
    /// A segment names a point that does not exist.
    #[error("segment {segment} refers to point {index}, but there are only {points} points")]
    SegmentIndex {
        /// Index of the segment (0-based).
        segment: usize,
        /// The missing point index.
        index: usize,
        /// Number of input points.
        points: usize,
    },
    /// A segment joins a point to itself (or to an exact duplicate of it).
    #[error("segment {segment} has zero length")]
    DegenerateSegment {
        /// Index of the segment (0-based).
        segment: usize,
    },
    /// Two segments join the same two points (in either order).
    #[error(
        "segments {first} and {second} join the same two points (segment lines {} and {}); give \
         each segment once",
        .first + 1,
        .second + 1
    )]
    DuplicateSegment {
        /// Index of the first segment (0-based).
        first: usize,
        /// Index of the repeat (0-based).
        second: usize,
    },
    /// Two segments cross or overlap away from a shared endpoint.
    #[error("segments {first} and {second} cross")]
    SegmentsCross {
        /// Index of the first segment (0-based).
        first: usize,
        /// Index of the second segment (0-based).
        second: usize,
    },
    /// A segment could not be inserted as a chain of triangle edges (a numerical failure of
    /// the walk through the triangles; not expected for valid input, reported rather than
    /// looping or panicking).
    #[error("segment {segment} could not be inserted into the triangulation")]
    SegmentInsertion {
        /// Index of the segment after splitting at points on it (0-based).
        segment: usize,
    },
    /// A requested feature is not implemented yet; the message says which.
    #[error("not implemented: {0}")]
    Unsupported(&'static str),
}
