//! Polygon meshes and what every algorithm needs of them: the [`PolyMesh`] store, halfedge
//! topology, the contract's planarity measure (one least-squares plane for the whole crate),
//! simple-polygon tests, vertex picking, render buffers, the text formats ([`io`]) and the
//! surface subdivision rules.
//!
//! | concept | file |
//! |---|---|
//! | compact polygon mesh | `polymesh.rs` |
//! | the solvers' coordinates: centred, power-of-two scaled | `frame.rs` |
//! | halfedges, manifold and orientation checks | `topology.rs` |
//! | least-squares plane, `max_planarity` (contract), mean and histogram of planarity | `planarity.rs` |
//! | face colour maps: planarity, convexity, regularity (P-Hex secs. 4.1, 4.2) and legend stops | `colors.rs` |
//! | simple polygons, exact predicates (P-Hex sec. 4.2) | `polygon.rs` |
//! | vertex under a ray, triangle star of a vertex (P-Hex sec. 4.1) | `picking.rs` |
//! | triangle buffers for renderers | `render_buffers.rs` |
//! | OBJ, point sets, segments | `io/` |
//! | Catmull-Clark, Doo-Sabin, Chaikin, Lane-Riesenfeld (conical paper, sec. 3) | `subdivision/` |

mod colors;
mod frame;
pub mod io;
mod picking;
mod planarity;
mod polygon;
mod polymesh;
mod render_buffers;
mod subdivision;
mod topology;

pub use colors::{
    CONVEX, ColorMode, ColorModeError, INVALID, NONCONVEX, NOT_HEX, PLANARITY_LEGEND_LOG10,
    REGULARITY_LEGEND, convexity_color, planarity_color, regularity_color,
};
pub use frame::SolverFrame;
pub use io::{ObjError, PointSetError, parse_obj, parse_points, parse_segments, write_obj};
pub use picking::{VertexPick, VertexStarError, pick_vertex, vertex_ring};
pub use planarity::{
    PLANARITY_HIST_BINS, PLANARITY_HIST_HI, PLANARITY_HIST_LO, coordinate_precision_note,
    face_planarities, face_planarity, flipped_faces, least_squares_plane, max_planarity,
    mean_planarity, planarity_histogram, plane_basis, representable_planarity,
};
pub use polygon::{PolygonError, is_simple_polygon, segments_intersect, strictly_inside_triangle};
pub use polymesh::{MeshError, PolyMesh};
pub use render_buffers::{
    PanelBuffers, PanelTail, TriangleBuffers, polymesh_buffers, polymesh_edges, view_origin,
};
pub use subdivision::{catmull_clark, chaikin, doo_sabin, lane_riesenfeld_cubic};
pub use topology::{MeshTopology, TopologyError};
