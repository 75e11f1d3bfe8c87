//! Valid triangulations of a surface (P-Hex paper, section 5): layer after layer along a base
//! curve, by method 1 (progressive) or method 2 (prescribed conjugate directions), with the
//! parabolic-region rules, or by Loop subdivision for closed convex surfaces.
//!
//! | section | concept | file |
//! |---|---|---|
//! | 5.2, 5.3 | methods 1 and 2, layer heights from the ideal triangle, the bound b | `layers.rs` |
//! | 5.2 | method 2 along a chosen direction field and its conjugate | `conjugate_fields.rs` |
//! | 5.3, 7 (Fig. 22) | which parameter direction runs along the parabolic curves | `parabolic_curves.rs` |
//! | 7, Fig. 21 | Loop subdivision of an icosahedron projected onto a convex surface | `loop_subdivision.rs` |

mod conjugate_fields;
mod layers;
mod loop_subdivision;
mod parabolic_curves;

pub use conjugate_fields::{ConjugateFields, triangulate_along_fields};
pub use layers::{
    DEFAULT_BOUND, LayerRule, MAX_PHEX_FACES, MAX_RATIO, MAX_RATIO_ELLIPTIC, Triangulation,
    TriangulationMethod, TriangulationSpec, bounded_ratio, triangulate,
};
pub use loop_subdivision::{convex_loop_triangulation, loop_subdivide};
pub use parabolic_curves::ParabolicCrossings;
