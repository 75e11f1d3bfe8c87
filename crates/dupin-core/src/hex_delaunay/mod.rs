//! Hexagonal Delaunay triangulation (Sußner & Greiner, "Hexagonal Delaunay Triangulation").
//!
//! Input: points in the plane (optionally segments, see below). Output: a triangulation of a
//! bounding hexagon Ω in which every input point is a vertex with its exact coordinates, dual to
//! an adaptive hexagon subdivision (sections 3 and 4). With [`HexDelaunayMode::Simple`] every
//! angle lies in [30°, 120°], with [`HexDelaunayMode::Extended`] (section 5) in
//! [43.8979°, 90°]; both meshes are Delaunay.
//!
//! | section | concept | file |
//! |---|---|---|
//! | 3.1 | hexagon coordinates and levels, the lattice frame and Ω | `lattice.rs` |
//! | 3 | the hexagon hierarchy: split, join, balancing, point location; split counters, merge and break (3.2) | `hierarchy.rs` |
//! | 3 | the split sets: 16×16 tiles of bits per level | `tile_set.rs` |
//! | 4.1 | the bounding circle (Welzl) | `min_enclosing_circle.rs` |
//! | 4.1 | simple refinement: rules 1 to 5 on a work queue, angles in [30°, 120°] | `simple_refinement.rs` |
//! | 4.2 | the dual triangulation of the hexagon mesh | `dual.rs` |
//! | 5 | extended refinement (5.1, 5.2, 5.4), MOVED_CENTER_3/4 fin vertices (5.4), local coarsening into blossoms (5.3) | `extended/` |
//! | 7 | PSLG input: segments refine, snap and become edge chains (both modes) | `pslg.rs` |
//! | 4 to 7 | the stepper, input checks and Ω's set-up; the one-shot [`hex_delaunay`] | `stepper.rs`, this file |
//! | 4, 5 | angle and Delaunay checks of a result | `quality.rs` |
//!
//! Bounding hexagon (section 4.1): the minimum enclosing circle (Welzl) of the points, radius
//! ρ, is the inner circle of the hexagon the paper places around the points; here Ω is that
//! hexagon enlarged by half (inradius 1.5ρ) and turned by 30°, so that (a) its corners are
//! hexagon centres and its edges lattice lines, making the dual triangles tile Ω exactly, and
//! (b) every point is at least ρ/2 from Ω's boundary, so boundary hexagons (the paper's virtual
//! full hexagons, whose centres stay on Ω's edges) never need refining below the size the
//! points' spacing requires.
//!
//! Data structure (O(n log n) in the number of points): split hexagons are kept per level in
//! 16×16 tiles of lattice coordinates (a hash map of 256-bit sets), points are re-checked from
//! a work queue only when a nearby hexagon changes, and the dual is extracted by a recursion
//! over the lattice triangles that costs O(1) per output triangle. See `hierarchy.rs`,
//! `tile_set.rs`, `simple_refinement.rs`, `dual.rs`.
//!
//! PSLG input (section 7, `pslg.rs`): segments refine the hexagons they meet, the centres of
//! met hexagons move onto them, and each segment becomes a chain of output edges
//! ([`HexTriangulation::segment_edges`]); the mode's angle bounds and the Delaunay property
//! hold for every triangle that does not meet a segment ([`HexTriangulation::meets_segments`]).
//!
//! Split counters, merge and break (section 3.2) are in `hierarchy.rs`; the extended mode ends
//! with the local coarsening into blossoms (section 5.3, `extended/coarsening.rs`);
//! MOVED_CENTER_3/4 are relocated under a local check (`extended/refinement.rs`,
//! `extended/fin_vertices.rs`). Section 6.3's shortest-edge bound d·√7/(12√3) does not hold
//! with the paper's construction (a counterexample in docs/hexdelaunay.md); every edge is at
//! least √7·d/(4(3√3 + 2)).
//! Incremental insertion is [`HexDelaunayStepper::insert`].

mod dual;
mod error;
mod extended;
mod hierarchy;
mod lattice;
mod min_enclosing_circle;
mod pslg;
mod quality;
mod simple_refinement;
mod stepper;
mod tile_set;

pub use error::HexDelaunayError;
pub use min_enclosing_circle::{Circle, min_enclosing_circle};
pub use quality::{
    TriangulationQuality, angle_histogram, triangle_angles_deg, triangulation_quality,
};
pub use stepper::{HexCell, HexDelaunayMetrics, HexDelaunayStepper};

use crate::Stepper;
use crate::mesh::PolyMesh;
use crate::{Vec2, Vec3};

/// Which refinement to run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum HexDelaunayMode {
    /// Section 4: angles in [30°, 120°].
    #[default]
    Simple,
    /// Section 5: angles in [43.9°, 90°] (Ω with inradius 3ρ instead of 1.5ρ).
    Extended,
}

crate::names::named_choices!(HexDelaunayMode, "mode", {
    Simple => "simple",
    Extended => "extended",
});

impl HexDelaunayMode {
    /// Both modes, the default ([`HexDelaunayMode::Simple`]) first.
    pub const ALL: [HexDelaunayMode; 2] = [HexDelaunayMode::Simple, HexDelaunayMode::Extended];

    /// The interior angle bounds (degrees, min and max) the mode guarantees away from input
    /// segments: [30, 120] for the simple refinement (section 4), [43.9, 90] for the extended
    /// one (section 5).
    pub fn angle_bounds_deg(self) -> [f64; 2] {
        match self {
            HexDelaunayMode::Simple => [30.0, 120.0],
            HexDelaunayMode::Extended => [43.9, 90.0],
        }
    }
}

/// The result of [`hex_delaunay`].
#[derive(Debug, Clone, PartialEq)]
pub struct HexTriangulation {
    /// Vertex positions; input points keep their exact coordinates.
    pub vertices: Vec<Vec2>,
    /// Triangles as counter-clockwise vertex index triples.
    pub triangles: Vec<[u32; 3]>,
    /// For every input point (duplicates included), the index of its vertex.
    pub input_vertex: Vec<u32>,
    /// Corners of the bounding hexagon Ω that the triangles tile, counter-clockwise.
    pub domain: [Vec2; 6],
    /// Deepest full-hexagon level reached (the paper's level is twice this).
    pub depth: u32,
    /// The input segments as chains of triangle edges (vertex index pairs); empty without
    /// segments. A triangle meets a segment iff it has a vertex of one of these edges; the
    /// others keep the mode's angle bounds and the Delaunay property (section 7).
    pub segment_edges: Vec<[u32; 2]>,
}

impl HexTriangulation {
    /// Area of Ω.
    pub fn domain_area(&self) -> f64 {
        let c = self.domain;
        let mut a = 0.0;
        for i in 1..5 {
            // Fan from corner 0: differences keep the precision of offset hexagons.
            a += (c[i] - c[0]).perp(&(c[i + 1] - c[0]));
        }
        0.5 * a
    }

    /// For every triangle, whether it meets a segment, i.e. has a vertex of
    /// [`segment_edges`](Self::segment_edges): the triangles exempt from the mode's angle
    /// bounds and the Delaunay property (section 7). All `false` without segments.
    pub fn meets_segments(&self) -> Vec<bool> {
        let mut on = vec![false; self.vertices.len()];
        for e in &self.segment_edges {
            on[e[0] as usize] = true;
            on[e[1] as usize] = true;
        }
        self.triangles
            .iter()
            .map(|t| t.iter().any(|&v| on[v as usize]))
            .collect()
    }

    /// The triangles as a polygon mesh with z = 0 (for OBJ output).
    pub fn to_mesh(&self) -> PolyMesh {
        let pos = self
            .vertices
            .iter()
            .map(|p| Vec3::new(p.x, p.y, 0.0))
            .collect();
        PolyMesh::new(pos, &self.triangles).expect("triangles index existing distinct vertices")
    }
}

/// Largest accepted coordinate magnitude.
pub const MAX_COORDINATE: f64 = 1e100;
/// Smallest accepted radius of the points' enclosing circle (unless all points coincide).
pub const MIN_EXTENT: f64 = 1e-100;
/// Cap on the full-hexagon levels of the hierarchy.
pub const MAX_LEVEL: u32 = 48;
/// Default cap on split hexagons, about 3 million triangles (each split adds about six; a few
/// seconds and under a gigabyte natively). Points far closer together than their extent, with
/// segments, can ask for tens of millions; the refinement stops there with
/// [`HexDelaunayError::TooManySplits`] instead ([`HexDelaunayStepper::with_max_splits`]
/// raises it).
pub const MAX_SPLITS: usize = 500_000;

/// Triangulates `points` and the segments `segments` (each a pair of point indices; they may
/// share endpoints but not cross or overlap) by hexagonal subdivision: [`HexDelaunayStepper`]
/// run to its end.
///
/// Errors: empty input, NaN/infinite or out-of-range coordinates, points too close for the
/// hierarchy depth cap, bad segments, or a numerical breakdown of the segment insertion.
pub fn hex_delaunay(
    points: &[Vec2],
    segments: &[[usize; 2]],
    mode: HexDelaunayMode,
) -> Result<HexTriangulation, HexDelaunayError> {
    HexDelaunayStepper::new(points, segments, mode)?.finish()
}

#[cfg(test)]
mod tests;
