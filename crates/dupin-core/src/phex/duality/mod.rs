//! Dupin duality (P-Hex paper, sections 3 to 5.1): the Dupin indicatrix and its conics, the
//! Dupin center of a triangle, tangent duality, valid triangle stars and their Dupin hexagons,
//! and the ideal triangle.
//!
//! | section | concept | file |
//! |---|---|---|
//! | 3, 4.2 | Dupin indicatrix, Dupin conics, conjugate and asymptotic directions | `indicatrix.rs` |
//! | 4.1, Props. 1-3 | Dupin center of a triangle | `dupin_center.rs` |
//! | 4.1 | tangent duality: the tangent planes' common point | `tangent_duality.rs` |
//! | 4.2, Props. 4-5 | valid triangle stars, the Dupin hexagon | `triangle_star.rs` |
//! | 5.1 | the ideal triangle, the line DE, affine regular hexagons | `ideal_triangle.rs` |
//! | 4.2, 6 | a mesh star projected onto the tangent plane; moving a star's ring vertex | `star_editing.rs` |

mod dupin_center;
mod ideal_triangle;
mod indicatrix;
mod star_editing;
mod tangent_duality;
mod triangle_star;

pub use dupin_center::{
    DupinCenterError, DupinCenterMethod, approximate_dupin_center, dupin_center, dupin_center_3d,
    dupin_conic_through,
};
pub use ideal_triangle::{
    IdealTriangle, IdealTriangleError, ideal_apex_3d, ideal_triangle,
    is_affine_quasi_regular_hexagon, is_affine_regular_hexagon,
};
pub use indicatrix::{DupinConic, DupinIndicatrix, IndicatrixError};
pub use star_editing::{StarEditError, drag_lattice_star, drag_star_vertex, project_star};
pub use tangent_duality::{TangentDualPoint, TangentDualityError, tangent_dual_point};
pub use triangle_star::{DupinHexagon, TriangleStar, TriangleStarError};
