//! The P-Hex pipeline (P-Hex paper, sections 5 to 7): triangulation layer after layer, the dual
//! hexagonal mesh, then Gauss-Newton planarity iterations until the contract's `max_planarity`
//! tolerance. [`PhexPipeline`] is the stateful stepper (one observable step per call, for the
//! web page); [`phex_run`] the one-shot function (for the CLI).

use super::PhexError;
use super::dual_hexagons::{DualMesh, DualMeshOptions, dual_mesh};
use super::planarity_optimisation::{PlanarityOptimiser, PlanarityOptions};
use super::report::{PhexReport, phex_report};
use super::triangulation::{
    LayerRule, Triangulation, TriangulationMethod, TriangulationSpec, triangulate,
    triangulate_along_fields,
};
use crate::Stepper;
use crate::mesh::{PolyMesh, SolverFrame};
use crate::surface::{
    FREEFORM, FreeformSurface, NurbsSurface, Surface, TwistedSurface, surface_by_name,
};
use std::sync::Arc;

mod follow;
pub use follow::MAX_FOLLOW_STEPS;

/// Everything a run needs. Build it from a scene ([`crate::scenes::phex_scene`]) or with
/// [`PhexConfig::for_surface`].
#[derive(Debug, Clone, PartialEq)]
pub struct PhexConfig {
    /// Library surface name (see `surface_catalog`), or the label of the imported surface.
    pub surface: String,
    /// An imported NURBS surface (a design from a CAD tool); when set it is the surface meshed,
    /// `surface` only names it and `params` must be empty.
    pub nurbs: Option<Arc<NurbsSurface>>,
    /// Surface parameters.
    pub params: Vec<(String, f64)>,
    /// Shear of the parametrisation, P(u + twist v, v) (0 for none).
    pub twist: f64,
    /// Triangulation method (section 5.2).
    pub method: TriangulationMethod,
    /// Layer height rule (ideal with bound b, or fixed).
    pub rule: LayerRule,
    /// Base curve along v instead of u.
    pub swap: bool,
    /// Across-parameter range (start, end); `None`: the whole domain.
    pub across: Option<(f64, f64)>,
    /// Along-parameter range; `None`: the whole domain.
    pub along: Option<(f64, f64)>,
    /// Target edge length of the base curve (`None`: 1/48 of the base curve's length).
    pub size: Option<f64>,
    /// Largest number of Gauss-Newton iterations.
    pub iterations: usize,
    /// Run the planarity optimisation.
    pub optimize: bool,
    /// Triangulate by Loop subdivision of an icosahedron projected onto the surface instead of
    /// layers (Fig. 21; the surface must be the `ellipsoid`).
    pub loop_subdivision: bool,
    /// How the hexagon vertices are initialised (section 6).
    pub initialisation: super::Initialisation,
    /// Also make faces at boundary triangulation vertices (section 6: the optimisation
    /// "generalised to boundary faces"; see [`super::DualMeshOptions::boundary_faces`]).
    pub boundary_faces: bool,
    /// Method 2 with a user-chosen first direction field: the angle (radians) of the first
    /// field against the first principal direction (the u direction at umbilics); the second
    /// field is its conjugate. `None`: the parameter lines (which must be conjugate).
    pub field_angle: Option<f64>,
    /// Initial fairness weight lambda of the planarity optimisation (section 7; >= 0).
    pub lambda: f64,
    /// Initial surface-distance weight mu of the planarity optimisation (section 7; >= 0).
    pub mu: f64,
    /// Largest number of P-Hex faces (triangulation vertices) the run may make
    /// ([`super::MAX_PHEX_FACES`] by default): a larger triangulation is refused while it is
    /// built.
    pub max_faces: usize,
}

impl PhexConfig {
    /// The dual-mesh options this configuration asks for (initialisation, boundary faces).
    pub fn dual_mesh_options(&self) -> DualMeshOptions {
        DualMeshOptions::default()
            .with_initialisation(self.initialisation)
            .with_boundary_faces(self.boundary_faces)
    }

    /// The optimiser's options this configuration asks for (iteration cap, lambda, mu).
    pub fn planarity_options(&self) -> PlanarityOptions {
        PlanarityOptions {
            max_iterations: self.iterations,
            lambda: self.lambda,
            mu: self.mu,
            ..PlanarityOptions::default()
        }
    }

    /// A configuration for an imported NURBS surface named `label`: its whole domain, method 2
    /// along the parameter lines with the tangent-duality start (section 6: every hexagon lies
    /// in a tangent plane, so the faces start planar), lower bound b = 0.3. Method 2 asks for
    /// conjugate parameter lines; where a design's lines are far from conjugate the hexagons
    /// come out non-simple and the report counts them as invalid (then try
    /// `field_angle = Some(0.0)`, the principal directions, or method 1). Measured: on a
    /// translational roof (conjugate lines) and on the mean-value fit of a dome mesh, method 2
    /// gave no invalid face where method 1 gave 34 of 166 and 64 of 339.
    pub fn for_nurbs(label: &str, surface: NurbsSurface, size: Option<f64>) -> PhexConfig {
        PhexConfig {
            nurbs: Some(Arc::new(surface)),
            ..PhexConfig::for_surface(label, &[], TriangulationMethod::Prescribed, size)
        }
    }

    /// [`PhexConfig::for_nurbs`] for a surface fitted to a triangle mesh
    /// ([`crate::surface::fit_mesh_surface`]), whose u and v come from an arbitrary corner of
    /// the mesh: the layers are laid across the parabolic curves, which then run along the
    /// base curves (sections 5.3 and 7, Fig. 22; [`super::ParabolicCrossings`]), whichever
    /// parameter that makes the layer direction. Measured on a translational roof mesh with a
    /// parabolic line (`translational_roof_triangle_mesh`): the fit's two orientations gave 0
    /// and 10 invalid faces along the parameter it happened to pick, 0 and 0 so.
    pub fn for_fitted_mesh(label: &str, surface: NurbsSurface, size: Option<f64>) -> PhexConfig {
        let swap = super::ParabolicCrossings::of(&surface, 32).layers_along_v();
        PhexConfig {
            swap,
            ..PhexConfig::for_nurbs(label, surface, size)
        }
    }

    /// A configuration for a library surface with the whole domain (the sphere and ellipsoid
    /// stop at latitude +-1.2 to avoid the singular poles), lower bound b = 0.3.
    pub fn for_surface(
        surface: &str,
        params: &[(String, f64)],
        method: TriangulationMethod,
        size: Option<f64>,
    ) -> PhexConfig {
        let across = matches!(surface, "sphere" | "ellipsoid").then_some((-1.2, 1.2));
        PhexConfig {
            surface: surface.to_string(),
            nurbs: None,
            params: params.to_vec(),
            twist: 0.0,
            method,
            rule: LayerRule::Ideal {
                bound: super::DEFAULT_BOUND,
            },
            swap: false,
            across,
            along: None,
            size,
            iterations: 10,
            optimize: true,
            loop_subdivision: false,
            initialisation: super::Initialisation::TangentDuality,
            boundary_faces: true,
            field_angle: None,
            lambda: PlanarityOptions::default().lambda,
            mu: PlanarityOptions::default().mu,
            max_faces: crate::phex::MAX_PHEX_FACES,
        }
    }
}

/// Which phase the pipeline is in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PhexPhase {
    /// Revealing triangulation layers.
    Triangulation,
    /// The dual hexagonal mesh was just built.
    Hexagons,
    /// Gauss-Newton planarity iterations.
    Optimisation,
    /// Finished.
    Done,
}

impl PhexPhase {
    /// Lower-case name (`triangulation`, `hexagons`, `optimisation`, `done`).
    pub fn name(self) -> &'static str {
        match self {
            PhexPhase::Triangulation => "triangulation",
            PhexPhase::Hexagons => "hexagons",
            PhexPhase::Optimisation => "optimisation",
            PhexPhase::Done => "done",
        }
    }
}

/// What the page shows after every step (maps to the contract's JS `metrics()`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhexMetrics {
    /// Current phase.
    pub phase: PhexPhase,
    /// Triangulation layers shown.
    pub layer: usize,
    /// Gauss-Newton iterations done.
    pub iteration: usize,
    /// Faces of the current mesh (triangles during triangulation).
    pub faces: usize,
    /// Vertices of the current mesh.
    pub vertices: usize,
    /// `max_planarity` of the current mesh (0 for triangles).
    pub max_planarity: f64,
    /// Self-intersecting faces of the current mesh.
    pub invalid_faces: usize,
}

/// The stateful P-Hex pipeline.
///
/// The triangulation is computed when the pipeline is created (it is cheap and its errors must
/// surface at once); [`Stepper::step`] then reveals it one layer per step, builds the dual
/// mesh, and runs one Gauss-Newton iteration per step.
pub struct PhexPipeline {
    /// The surface in the solver's frame: what the triangulation, the dual mesh and the
    /// optimisation work on.
    surface: Box<dyn Surface>,
    /// Where the solver works (see [`PhexPipeline::frame`]).
    frame: SolverFrame,
    /// With a frame other than the identity: the user's surface, and the triangulation in the
    /// user's coordinates (what `surface()` and `triangulation()` hand out).
    user: Option<(Box<dyn Surface>, Triangulation)>,
    config: PhexConfig,
    tri: Triangulation,
    /// Number of triangles complete after each layer.
    layer_triangles: Vec<usize>,
    shown: usize,
    dual: Option<DualMesh>,
    optimiser: Option<PlanarityOptimiser>,
    phase: PhexPhase,
    metrics: PhexMetrics,
}

/// Result of [`phex_run`].
#[derive(Debug, Clone, PartialEq)]
pub struct PhexResult {
    /// The P-Hex mesh.
    pub mesh: PolyMesh,
    /// The triangulation it is dual to.
    pub triangulation: Triangulation,
    /// Report (contract fields plus per-face data).
    pub report: PhexReport,
}

/// The frame an imported design is solved in: the unit box of its control net
/// ([`SolverFrame::unit_box`]: centred, scaled by a power of two into about `[-1, 1]^3`). P-Hex's
/// absolute thresholds (the paper's parabolic |K| < 1e-8, the optimiser's weights λ and μ) are
/// set for the library's surfaces, a few units across: a design drawn in millimetres or at
/// state-plane offsets must be panelled as the same design in metres near the origin. The
/// library surfaces (and a twisted import, whose twist is about the user's axis) keep the
/// identity.
fn solver_frame(config: &PhexConfig) -> SolverFrame {
    match &config.nurbs {
        Some(n) if config.twist == 0.0 => {
            let (lo, hi) = n.control_bounds();
            SolverFrame::unit_box(&[lo, hi])
        }
        _ => SolverFrame::identity(),
    }
}

/// `config`'s surface in `frame` (the identity: the user's).
fn build_surface(config: &PhexConfig, frame: &SolverFrame) -> Result<Box<dyn Surface>, PhexError> {
    let params: Vec<(&str, f64)> = config
        .params
        .iter()
        .map(|(k, v)| (k.as_str(), *v))
        .collect();
    let s: Box<dyn Surface> = if let Some(nurbs) = &config.nurbs {
        if !params.is_empty() {
            return Err(PhexError::BadParameter(
                "an imported surface has no parameters to set".into(),
            ));
        }
        if *frame == SolverFrame::identity() {
            Box::new(NurbsSurface::clone(nurbs))
        } else {
            Box::new(nurbs.in_frame(frame))
        }
    } else if config.surface == FREEFORM {
        let (mut amplitude, mut curl) = (0.4, 0.3);
        for (k, v) in &params {
            let slot = match *k {
                "amplitude" => &mut amplitude,
                "curl" => &mut curl,
                _ => {
                    return Err(PhexError::BadParameter(format!(
                        "{} has no parameter '{k}'; use amplitude or curl",
                        FREEFORM
                    )));
                }
            };
            if !(v.is_finite() && v.abs() <= 1.0) {
                return Err(PhexError::BadParameter(format!(
                    "{k} = {v}; use a value in [-1, 1]"
                )));
            }
            *slot = *v;
        }
        Box::new(FreeformSurface { amplitude, curl })
    } else {
        surface_by_name(&config.surface, &params)?
    };
    if !config.twist.is_finite() {
        return Err(PhexError::BadParameter("twist must be finite".into()));
    }
    Ok(if config.twist != 0.0 {
        Box::new(TwistedSurface {
            inner: s,
            twist: config.twist,
        })
    } else {
        s
    })
}

impl PhexPipeline {
    /// The hexagonal mesh dual to the current triangulation, by the configured initialisation
    /// (section 6), before any optimisation, in the solver's frame (with
    /// [`PhexPipeline::solver_surface`]).
    pub fn initial_dual_mesh(&self) -> Result<DualMesh, PhexError> {
        dual_mesh(
            &self.tri,
            Some(self.surface.as_ref()),
            &self.config.dual_mesh_options(),
        )
    }

    /// Validates `config`, builds the surface and the triangulation.
    ///
    /// Errors: unknown surface or bad parameters ([`PhexError::Surface`]), a size too large or
    /// too small ([`PhexError::BadSize`]), iterations outside 0..=1000
    /// ([`PhexError::BadParameter`]), no valid triangulation
    /// ([`PhexError::NoValidTriangulation`]).
    pub fn new(config: PhexConfig) -> Result<Self, PhexError> {
        if config.iterations > 1000 {
            return Err(PhexError::BadParameter(format!(
                "{} iterations; use at most 1000",
                config.iterations
            )));
        }
        for (name, w) in [("lambda", config.lambda), ("mu", config.mu)] {
            if !(w.is_finite() && w >= 0.0) {
                return Err(PhexError::BadParameter(format!(
                    "{name} = {w} must be a finite weight >= 0"
                )));
            }
        }
        if let LayerRule::Ideal { bound } = config.rule
            && !(bound.is_finite() && (0.0..=1.0).contains(&bound))
        {
            return Err(PhexError::BadParameter(format!(
                "lower bound b = {bound} must be in [0, 1]"
            )));
        }
        let frame = solver_frame(&config);
        let surface = build_surface(&config, &frame)?;
        if config.loop_subdivision {
            return Self::from_loop(config, surface);
        }
        // Lengths in the user's unit, for messages.
        let user_len = |l: f64| crate::math::Num(l * frame.scale());
        let dom = surface.domain();
        let (along_dom, across_dom) = if config.swap {
            (dom.v, dom.u)
        } else {
            (dom.u, dom.v)
        };
        let along = config.along.unwrap_or(along_dom);
        let across = config.across.unwrap_or(across_dom);
        // Base curve length, to turn the target edge length into a sample count.
        let base_len: f64 = (0..256)
            .map(|i| {
                let t = |k: f64| along.0 + (along.1 - along.0) * k / 256.0;
                let uv = |a: f64| {
                    if config.swap {
                        (across.0, a)
                    } else {
                        (a, across.0)
                    }
                };
                let (u0, v0) = uv(t(i as f64));
                let (u1, v1) = uv(t(i as f64 + 1.0));
                (surface.position(u1, v1) - surface.position(u0, v0)).norm()
            })
            .sum();
        if !(base_len.is_finite() && base_len > 0.0) {
            return Err(PhexError::NoValidTriangulation(
                "the base curve has zero or non-finite length: change the region".into(),
            ));
        }
        let size = config.size.map_or(base_len / 48.0, |s| s / frame.scale());
        if !(size.is_finite() && size > 0.0) {
            return Err(PhexError::BadSize(format!(
                "size {} must be a positive length",
                user_len(size)
            )));
        }
        let samples_f = (base_len / size).round();
        if !(6.0..=4000.0).contains(&samples_f) {
            return Err(PhexError::BadSize(format!(
                "size {} gives {samples_f} samples on a base curve of length {}; \
                 use a size between {:.3e} and {:.3e}",
                user_len(size),
                user_len(base_len),
                base_len / 4000.0 * frame.scale(),
                base_len / 6.0 * frame.scale()
            )));
        }
        let spec = TriangulationSpec {
            method: config.method,
            rule: config.rule,
            samples: samples_f as usize,
            swap: config.swap,
            start: across.0,
            end: across.1,
            along,
            max_layers: 4000,
            max_vertices: config.max_faces,
        };
        let tri = match config.field_angle {
            None => triangulate(surface.as_ref(), &spec)?,
            Some(angle) => {
                if config.method != TriangulationMethod::Prescribed {
                    return Err(PhexError::BadParameter(
                        "a field angle needs method 2 (prescribed); drop it or use \
                         --method prescribed"
                            .into(),
                    ));
                }
                if !(angle.is_finite() && angle.abs() <= std::f64::consts::FRAC_PI_2) {
                    return Err(PhexError::BadParameter(format!(
                        "field angle {:.3} degrees; use a value in [-90, 90]",
                        angle.to_degrees()
                    )));
                }
                triangulate_along_fields(surface.as_ref(), &spec, angle, size)?
            }
        };
        if tri.triangles.len() > 4_000_000 {
            return Err(PhexError::BadSize(format!(
                "{} triangles; use a larger size",
                tri.triangles.len()
            )));
        }
        let mut layer_of = vec![0usize; tri.positions.len()];
        for (j, l) in tri.layers.iter().enumerate().rev() {
            for &v in l {
                layer_of[v as usize] = j;
            }
        }
        let mut layer_triangles = vec![0usize; tri.layers.len()];
        for t in &tri.triangles {
            let j = t.iter().map(|&v| layer_of[v as usize]).max().unwrap_or(0);
            layer_triangles[j] += 1;
        }
        for j in 1..layer_triangles.len() {
            layer_triangles[j] += layer_triangles[j - 1];
        }
        let mut pipeline = Self::at_start(surface, config, tri, layer_triangles);
        if frame != SolverFrame::identity() {
            let mut user_tri = pipeline.tri.clone();
            for p in &mut user_tri.positions {
                *p = frame.to_user(*p);
            }
            pipeline.user = Some((
                build_surface(&pipeline.config, &SolverFrame::identity())?,
                user_tri,
            ));
            pipeline.frame = frame;
        }
        Ok(pipeline)
    }

    /// A pipeline before its first step: no layer shown, no dual mesh, no optimiser.
    fn at_start(
        surface: Box<dyn Surface>,
        config: PhexConfig,
        tri: Triangulation,
        layer_triangles: Vec<usize>,
    ) -> Self {
        PhexPipeline {
            surface,
            frame: SolverFrame::identity(),
            user: None,
            config,
            tri,
            layer_triangles,
            shown: 0,
            dual: None,
            optimiser: None,
            phase: PhexPhase::Triangulation,
            metrics: PhexMetrics {
                phase: PhexPhase::Triangulation,
                layer: 0,
                iteration: 0,
                faces: 0,
                vertices: 0,
                max_planarity: 0.0,
                invalid_faces: 0,
            },
        }
    }

    fn from_loop(config: PhexConfig, surface: Box<dyn Surface>) -> Result<Self, PhexError> {
        if config.surface != "ellipsoid" || config.nurbs.is_some() {
            return Err(PhexError::BadParameter(
                "Loop subdivision (convex genus 0) needs --surface ellipsoid".into(),
            ));
        }
        let get = |k: &str, d: f64| {
            config
                .params
                .iter()
                .rev()
                .find(|(n, _)| n == k)
                .map_or(d, |p| p.1)
        };
        let axes = (get("a", 1.5), get("b", 1.0), get("c", 0.8));
        // Icosahedron edge ~1.05 x the mean semi-axis; every level halves it.
        let mean_axis = (axes.0 + axes.1 + axes.2) / 3.0;
        let size = config.size.unwrap_or(mean_axis / 12.0);
        if !(size.is_finite() && size > 0.0) {
            return Err(PhexError::BadSize(format!(
                "size {} must be a positive length",
                crate::math::Num(size)
            )));
        }
        let levels = (1.05 * mean_axis / size).log2().ceil().max(1.0) as usize;
        let tri = super::triangulation::convex_loop_triangulation(axes, levels)?;
        let n = tri.triangles.len();
        Ok(Self::at_start(surface, config, tri, vec![n]))
    }

    /// The configuration the pipeline runs.
    pub fn config(&self) -> &PhexConfig {
        &self.config
    }

    /// The planarity optimiser (section 7), once the hexagons exist: its counters say how the
    /// optimisation went (iterations, factorisations, least moves).
    pub fn optimiser(&self) -> Option<&PlanarityOptimiser> {
        self.optimiser.as_ref()
    }

    /// The surface being meshed, in the user's coordinates.
    pub fn surface(&self) -> &dyn Surface {
        match &self.user {
            Some((s, _)) => s.as_ref(),
            None => self.surface.as_ref(),
        }
    }

    /// The frame the solver works in: the identity for a library surface, the unit box of the
    /// control net for an imported design (see `solver_frame`). Everything the pipeline hands
    /// out is in the user's coordinates, but for [`PhexPipeline::solver_surface`] and
    /// [`PhexPipeline::initial_dual_mesh`].
    pub fn frame(&self) -> SolverFrame {
        self.frame
    }

    /// The surface as the solver sees it, in [`PhexPipeline::frame`].
    pub fn solver_surface(&self) -> &dyn Surface {
        self.surface.as_ref()
    }

    /// The full triangulation, in the user's coordinates.
    pub fn triangulation(&self) -> &Triangulation {
        match &self.user {
            Some((_, t)) => t,
            None => &self.tri,
        }
    }

    /// `mesh` (in the solver's frame) in the user's coordinates.
    fn to_user(&self, mut mesh: PolyMesh) -> PolyMesh {
        if self.user.is_some() {
            for p in &mut mesh.positions {
                *p = self.frame.to_user(*p);
            }
        }
        mesh
    }

    /// The current mesh, in the user's coordinates: the triangles of the layers shown so far,
    /// then the hexagonal mesh.
    pub fn mesh(&self) -> PolyMesh {
        match &self.dual {
            Some(d) => self.to_user(d.mesh.clone()),
            None => {
                let k = if self.shown == 0 {
                    0
                } else {
                    self.layer_triangles[self.shown - 1]
                };
                let tri = self.triangulation();
                PolyMesh::new(tri.positions.clone(), &tri.triangles[..k]).unwrap_or_default()
            }
        }
    }

    /// The Gaussian curvature (in the user's unit) at every face's triangulation vertex.
    fn face_gaussian(&self, d: &DualMesh) -> Vec<f64> {
        d.face_vertex
            .iter()
            .map(|&v| {
                let uv = self.tri.uv[v as usize];
                self.surface()
                    .curvature(uv.x, uv.y)
                    .map(|c| c.gaussian)
                    .unwrap_or(0.0)
            })
            .collect()
    }

    /// Surface parameters near every vertex of `d`: the optimiser's last foot points (the
    /// vertices have moved since the dual mesh's parameters), or the dual mesh's.
    fn foot_parameters(&self, d: &DualMesh) -> Vec<crate::Vec2> {
        match &self.optimiser {
            Some(o) => o
                .foot_parameters()
                .iter()
                .zip(&d.vertex_uv)
                .map(|(foot, &start)| foot.unwrap_or(start))
                .collect(),
            None => d.vertex_uv.clone(),
        }
    }

    /// The report of the current hexagonal mesh (`None` before it exists), measured in the
    /// user's coordinates: the mesh a fabricator gets, not the solver's.
    pub fn report(&self) -> Option<PhexReport> {
        let d = self.dual.as_ref()?;
        let seeds = self.foot_parameters(d);
        Some(phex_report(
            &self.to_user(d.mesh.clone()),
            self.surface(),
            &self.face_gaussian(d),
            &seeds,
            self.optimiser.as_ref().map_or(0, |o| o.iteration()),
        ))
    }
}

/// One step reveals a triangulation layer, builds the dual mesh, or runs one Gauss-Newton
/// iteration.
impl Stepper for PhexPipeline {
    type Metrics = PhexMetrics;
    type Output = PhexResult;
    type Error = PhexError;

    /// Advances one observable step and returns the metrics.
    ///
    /// Errors: [`PhexError::NoValidTriangulation`] when the dual mesh cannot be formed,
    /// [`PhexError::Solver`] when an optimisation step fails.
    fn step(&mut self) -> Result<PhexMetrics, PhexError> {
        match self.phase {
            PhexPhase::Triangulation => {
                self.shown += 1;
                let k = self.layer_triangles[self.shown - 1];
                let verts: usize = self.tri.layers[..self.shown].iter().map(|l| l.len()).sum();
                self.metrics.layer = self.shown;
                self.metrics.faces = k;
                self.metrics.vertices = verts;
                if self.shown == self.tri.layers.len() {
                    self.phase = PhexPhase::Hexagons;
                }
            }
            PhexPhase::Hexagons => {
                let d = self.initial_dual_mesh()?;
                self.metrics.faces = d.mesh.num_faces();
                self.metrics.vertices = d.mesh.num_vertices();
                let opt = PlanarityOptimiser::new(
                    &d.mesh,
                    Some(&d.vertex_uv),
                    self.config.planarity_options(),
                )?;
                self.metrics.max_planarity = opt.max_planarity();
                self.metrics.invalid_faces = opt.invalid_faces();
                self.phase = if self.config.optimize && !opt.is_done() {
                    PhexPhase::Optimisation
                } else {
                    PhexPhase::Done
                };
                self.optimiser = Some(opt);
                self.dual = Some(d);
            }
            PhexPhase::Optimisation => {
                let (Some(opt), Some(d)) = (self.optimiser.as_mut(), self.dual.as_mut()) else {
                    self.phase = PhexPhase::Done;
                    return Ok(self.metrics);
                };
                let s = opt.step(&mut d.mesh, self.surface.as_ref())?;
                self.metrics.iteration = s.iteration;
                self.metrics.max_planarity = s.max_planarity;
                self.metrics.invalid_faces = opt.invalid_faces();
                if opt.is_done() {
                    self.phase = PhexPhase::Done;
                }
            }
            PhexPhase::Done => {}
        }
        self.metrics.phase = self.phase;
        Ok(self.metrics)
    }

    fn is_done(&self) -> bool {
        self.phase == PhexPhase::Done
    }

    /// The layers still to show, the hexagon step, and the optimisation's iteration cap.
    fn steps_left_at_most(&self) -> Option<usize> {
        let iterations = if self.config.optimize {
            self.config.iterations
        } else {
            0
        };
        Some(match self.phase {
            PhexPhase::Triangulation => self.tri.layers.len() - self.shown + 1 + iterations,
            PhexPhase::Hexagons => 1 + iterations,
            PhexPhase::Optimisation => iterations.saturating_sub(self.metrics.iteration),
            PhexPhase::Done => 0,
        })
    }

    /// Metrics after the last step.
    fn metrics(&self) -> PhexMetrics {
        self.metrics
    }

    /// Runs to the end (skipping the rest of the layer-by-layer reveal) and returns the mesh,
    /// its triangulation and report.
    ///
    /// Errors: see [`Stepper::step`]; [`PhexError::NoValidTriangulation`] when no hexagonal
    /// mesh was produced.
    fn finish(mut self) -> Result<PhexResult, PhexError> {
        if self.phase == PhexPhase::Triangulation {
            self.shown = self.tri.layers.len();
            self.phase = PhexPhase::Hexagons;
        }
        self.run_to_end()?;
        let report = self.report().ok_or_else(|| {
            PhexError::NoValidTriangulation("no hexagonal mesh was produced".into())
        })?;
        let dual = self.dual.take().ok_or_else(|| {
            PhexError::NoValidTriangulation("no hexagonal mesh was produced".into())
        })?;
        let mesh = self.to_user(dual.mesh);
        Ok(PhexResult {
            mesh,
            triangulation: match self.user {
                Some((_, t)) => t,
                None => self.tri,
            },
            report,
        })
    }
}

/// One-shot P-Hex run: triangulation, dual mesh, planarity optimisation, report;
/// [`PhexPipeline`] run to its end.
///
/// Errors: see [`PhexPipeline::new`] and [`Stepper::step`].
pub fn phex_run(config: PhexConfig) -> Result<PhexResult, PhexError> {
    PhexPipeline::new(config)?.finish()
}
