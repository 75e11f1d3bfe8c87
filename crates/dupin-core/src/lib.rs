//! # dupin-core
//!
//! The geometry core of Dupin: smooth surfaces, Dupin duality, P-Hex meshes, planar-quad and
//! conical meshes, and hexagonal Delaunay triangulation. Plain Rust: no wasm, DOM or GPU
//! dependency, so the same code runs natively, in the CLI and inside the browser.
//!
//! The modules are private; this page lists the public API (spade's style: a small, flat
//! surface chosen by `pub use`). See `ARCHITECTURE.md` for layering rules.
//!
//! ## Surfaces, curvature and Dupin duality (P-Hex paper, sections 3 to 5.1)
//! - [`Surface`] and the library ([`surface_by_name`], [`surface_catalog`]), [`MeshSurface`];
//! - [`Curvature`], [`PointType`], [`CurvatureTolerance`] (section 3);
//! - [`DupinIndicatrix`], [`DupinConic`], conjugate and asymptotic directions (sections 3, 4.2);
//! - [`dupin_center`], [`tangent_dual_point`], [`TriangleStar`] (section 4, Propositions 3-5);
//! - [`ideal_triangle`] (section 5.1); [`is_simple_polygon`] (exact predicates);
//! - [`pick_vertex`] and [`vertex_ring`]: the mesh vertex under a view ray and its triangle star
//!   (section 4.1), for the page's teaching inset.
//! ## P-Hex meshes (P-Hex paper, sections 5 to 7)
//! - [`triangulate`] (methods 1 and 2 of section 5.2, parabolic rules of 5.3, [`bounded_ratio`]);
//! - [`dual_mesh`] (section 6 initialisation, tangent duality), [`PlanarityOptimiser`]
//!   (section 6 Gauss-Newton planarity);
//! - [`PhexPipeline`] (stepper), [`phex_run`] (one shot), [`phex_scene`] / [`PHEX_SCENES`],
//!   [`phex_report`] / [`face_info`] (contract report and per-face data).

// `!(x > t)` is used on purpose throughout: unlike `x <= t` it also rejects NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod circular;
mod conical;
mod curvature;
mod developable_strip;
mod discrete_terms;
mod dupin_center;
mod dupin_indicatrix;
mod hex_delaunay;
mod ideal_triangle;
mod math;
mod mesh;
mod mesh_topology;
mod obj;
mod offset;
mod panel_schedule;
mod phex;
mod planarity;
mod point_set;
mod polygon;
mod pq_perturbation;
mod pq_scene_stepper;
mod pq_scenes;
mod principal_quad_mesh;
mod render_buffers;
mod solver;
mod subdivision;
mod support_structure;
mod surface;
mod tangent_duality;
mod triangle_star;
mod vertex_pick;

pub use circular::{circular_residual, quad_circularity};
pub use conical::{
    VertexType, angle_balance, cone_axes, conical_residual, face_normals, focal_points,
    spherical_image, vertex_type,
};
pub use curvature::{Curvature, CurvatureError, CurvatureTolerance, PointType, TangentFrame};
pub use developable_strip::{
    PqStrip, StripClosure, StripRule, developable_subdivision, trefoil_moebius,
};
pub use dupin_center::{
    DupinCenterError, DupinCenterMethod, approximate_dupin_center, dupin_center, dupin_center_3d,
    dupin_conic_through,
};
pub use dupin_indicatrix::{DupinConic, DupinIndicatrix, IndicatrixError};
pub use hex_delaunay::{
    Circle, HexCell, HexDelaunayError, HexDelaunayMode, HexDelaunayStepper, HexTriangulation,
    MAX_COORDINATE, MAX_LEVEL, MIN_EXTENT, TriangulationQuality, hex_delaunay,
    min_enclosing_circle, triangulation_quality,
};
pub use ideal_triangle::{
    IdealTriangle, IdealTriangleError, ideal_apex_3d, ideal_triangle,
    is_affine_quasi_regular_hexagon, is_affine_regular_hexagon,
};
pub use math::{Vec2, Vec3};
pub use mesh::{MeshError, PolyMesh};
pub use mesh_topology::{MeshTopology, TopologyError};
pub use obj::{ObjError, parse_obj, write_obj};
pub use offset::{OffsetError, offset_mesh};
pub use panel_schedule::{
    FlatPanel, PanelSchedule, PanelScheduleError, SheetOptions, panel_schedule, panel_schedule_svg,
};
pub use phex::{
    ConjugateFields, DualMesh, FREEFORM, FaceInfo, FreeformSurface, Initialisation, LayerRule,
    PARABOLIC_THRESHOLD, PHEX_SCENES, PhexConfig, PhexError, PhexMetrics, PhexPhase, PhexPipeline,
    PhexReport, PhexResult, PhexScene, PlanarityOptimiser, PlanarityOptions, PlanarityStep,
    Triangulation, TriangulationMethod, TriangulationSpec, TwistedSurface, bounded_ratio,
    convex_loop_triangulation, dual_mesh, dual_mesh_options, dual_mesh_with, face_info,
    loop_subdivide, phex_report, phex_run, phex_scene, tangent_plane_point, triangulate,
    triangulate_along_fields,
};
pub use planarity::{face_planarity, max_planarity};
pub use point_set::{PointSetError, parse_points, parse_segments};
pub use polygon::{PolygonError, is_simple_polygon, segments_intersect, strictly_inside_triangle};
pub use pq_perturbation::{
    PqError, PqMode, PqOptions, PqPerturbation, PqPhase, PqResult, PqStepInfo, Refinement,
    pq_perturb,
};
pub use pq_scene_stepper::{MeshRule, PqScenePhase, PqSceneStepInfo, PqSceneStepper};
pub use pq_scenes::{
    PQ_SCENES, PqSceneError, PqSceneResult, noisy_vase, pq_scene, skew_quad_grid,
    torus_centroid_dual, torus_quad_mesh,
};
pub use principal_quad_mesh::{SurfaceOfRevolution, principal_quad_mesh};
pub use render_buffers::{TriangleBuffers, polymesh_buffers, polymesh_edges, sample_surface};
pub use solver::{
    ConstrainedLeastSquares, JacobianEntry, LevenbergMarquardt, LmOptions, LmStep,
    NonlinearLeastSquares, SolverError, SparseSystem, Sqp, SqpOptions, SqpStep,
};
pub use subdivision::{catmull_clark, chaikin, doo_sabin, lane_riesenfeld_cubic};
pub use support_structure::support_structure;
pub use surface::{
    BSplinePatch, BSplinePatchError, Catenoid, ClosestPoint, ClosestPointError, Cylinder, Domain,
    DupinCyclide, Ellipsoid, Enneper, FundamentalForms, HyperbolicParaboloid, Hyperboloid,
    MeshClosestPoint, MeshSurface, MeshSurfaceError, ParamSpec, RegistryError, Sphere, Surface,
    SurfaceDerivatives, SurfaceSpec, Torus, Vase, VertexCurvature, parse_assignment,
    surface_by_name, surface_catalog,
};
pub use tangent_duality::{TangentDualPoint, TangentDualityError, tangent_dual_point};
pub use triangle_star::{DupinHexagon, TriangleStar, TriangleStarError};
pub use vertex_pick::{VertexPick, VertexStarError, pick_vertex, vertex_ring};
