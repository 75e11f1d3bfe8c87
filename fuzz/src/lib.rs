//! Fuzz targets: one function per entry point that takes outside data, called by the libFuzzer
//! binaries in `fuzz_targets/` (`cargo xtask fuzz`) and, on every file of the kept corpus and
//! every input that once failed, by the ordinary test run (`tests/corpus.rs`).
//!
//! A target returns normally for every input: a typed error is a correct answer. It panics (the
//! fuzzer's "crash") only when Dupin panics or when an invariant that must hold for every
//! accepted input fails; those invariants are asserted here, so the fuzzer searches for inputs
//! that break them too. Each target keeps its work small (a few dozen faces or points) so that
//! the fuzzer runs thousands of inputs a second; the size limits themselves are checked by the
//! inputs' budgets, which the targets leave in place.

use arbitrary::{Result as ArbitraryResult, Unstructured};
use dupin_core::Stepper;
use dupin_core::Vec2;
use dupin_core::conical::{PqMode, PqOptions, PqPerturbation};
use dupin_core::hex_delaunay::{HexDelaunayMode, HexDelaunayStepper};
use dupin_core::mesh::io::{ImportOptions, read_mesh};
use dupin_core::mesh::{
    PolyMesh, face_planarity, max_planarity, parse_obj, parse_points, parse_segments, write_obj,
};
use dupin_core::phex::{
    DupinIndicatrix, Initialisation, PhexConfig, PhexPipeline, TriangulationMethod, ideal_triangle,
};
use dupin_core::scenes::{phex_scene, pq_scene_spec};
use dupin_core::surface::{
    MeshFitOptions, NurbsSurface, Surface, fit_mesh_surface, surface_by_name, surface_catalog,
};

/// A fuzz target: takes any bytes, panics only on a bug.
pub type Target = fn(&[u8]);

/// The names of the targets, as the binaries, corpus folders and `cargo xtask fuzz` call them.
pub const TARGETS: &[(&str, Target)] = &[
    ("obj", obj),
    ("point_set", point_set),
    ("mesh_file", mesh_file),
    ("hex_delaunay", hex_delaunay),
    ("session_config", session_config),
    ("dupin_lesson", dupin_lesson),
    ("planarize", planarize),
    ("nurbs_json", nurbs_json),
    ("mesh_fit", mesh_fit),
];

/// OBJ text (`dupin planarize --input`, the page's file input): whatever parses writes back and
/// reads again to the same faces and the same position bits, and measures without panicking.
pub fn obj(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(mesh) = parse_obj(text) else {
        return;
    };
    assert_round_trip(&mesh);
    for i in 0..mesh.num_faces() {
        let _ = face_planarity(&mesh, i);
    }
    let _ = (mesh.bbox_diagonal(), mesh.mean_edge());
}

fn assert_round_trip(mesh: &PolyMesh) {
    let back = parse_obj(&write_obj(mesh)).expect("a written OBJ reads back");
    assert_eq!(back.num_faces(), mesh.num_faces());
    assert!(
        back.faces().eq(mesh.faces()),
        "faces change in the round trip"
    );
    let bits = |m: &PolyMesh| -> Vec<[u64; 3]> {
        m.positions
            .iter()
            .map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
            .collect()
    };
    assert_eq!(
        bits(&back),
        bits(mesh),
        "positions change in the round trip"
    );
}

/// Point and segment files of `dupin hexdelaunay --points/--segments`: both parsers on the same
/// text; accepted points are finite.
pub fn point_set(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(points) = parse_points(text) {
        assert!(points.iter().all(|p| p.x.is_finite() && p.y.is_finite()));
    }
    let _ = parse_segments(text);
}

/// Any mesh file by its first bytes (OBJ, ASCII or binary STL, glTF or GLB), with an import
/// limit of 100 000 triangles as a small tab would set it.
pub fn mesh_file(data: &[u8]) {
    let options = ImportOptions::default().with_max_triangles(100_000);
    for name in ["design.obj", "design.stl", "design.glb", "design.gltf"] {
        if let Ok(imported) = read_mesh(name, data, &options) {
            assert!(imported.mesh.num_faces() <= 100_000);
            assert!(
                imported
                    .mesh
                    .positions
                    .iter()
                    .all(|p| p.x.is_finite() && p.y.is_finite() && p.z.is_finite()),
                "an imported position is not finite"
            );
        }
    }
}

/// `HexDelaunayLab.setInput` and `dupin hexdelaunay`: up to 24 points (any f64, including
/// NaN and extremes), up to 8 segments, either mode, run to the end. Every input point must be a
/// vertex of the result, at its exact position.
pub fn hex_delaunay(data: &[u8]) {
    let Ok((points, segments, mode)) = hex_delaunay_case(data) else {
        return;
    };
    // A budget of 1 000 splits (about 6 000 triangles) keeps each input within ~0.1 s even in the
    // instrumented build: inputs with features 1e-11 apart reach the budget deep in the hierarchy.
    let Ok(stepper) = HexDelaunayStepper::new(&points, &segments, mode) else {
        return;
    };
    let mut stepper = stepper.with_max_splits(1_000);
    if stepper.run_to_end().is_err() {
        return;
    }
    let t = stepper.triangulation();
    for (i, p) in points.iter().enumerate() {
        let v = t.input_vertex[i] as usize;
        assert_eq!(t.vertices[v], *p, "input point {i} is not an exact vertex");
    }
}

/// The points, segments and mode [`hex_delaunay`] reads from `data` (for looking at a failing
/// input).
pub fn hex_delaunay_case(data: &[u8]) -> ArbitraryResult<HexDelaunayCase> {
    let u = &mut Unstructured::new(data);
    let mode = if u.arbitrary()? {
        HexDelaunayMode::Extended
    } else {
        HexDelaunayMode::Simple
    };
    let n = u.int_in_range(0..=24)?;
    let mut points = Vec::with_capacity(n);
    for _ in 0..n {
        points.push(Vec2::new(coordinate(u)?, coordinate(u)?));
    }
    let m = u.int_in_range(0..=8)?;
    let mut segments = Vec::with_capacity(m);
    for _ in 0..m {
        segments.push([u.int_in_range(0..=n + 1)?, u.int_in_range(0..=n + 1)?]);
    }
    Ok((points, segments, mode))
}

/// Input points, segments (point index pairs) and mode of a hexagonal Delaunay run.
pub type HexDelaunayCase = (Vec<Vec2>, Vec<[usize; 2]>, HexDelaunayMode);

/// A coordinate as people and programs write them: small integers and decimals mostly, with
/// every f64 (NaN, infinities, subnormals, 1e300) reachable.
fn coordinate(u: &mut Unstructured) -> ArbitraryResult<f64> {
    Ok(match u.int_in_range(0..=3u8)? {
        0 => f64::from(u.int_in_range(-50..=50i8)?),
        1 => f64::from(u.arbitrary::<i16>()?) / 256.0,
        2 => f64::from(u.arbitrary::<f32>()?),
        _ => u.arbitrary::<f64>()?,
    })
}

/// `new Session(config)` of the page and `dupin phex --surface`: a scene name, or a surface with
/// parameters, method, size, bound, lambda, mu and initialisation; then the first steps of the
/// run (a face budget of 2 000 keeps them short; the budget check is part of what is fuzzed).
pub fn session_config(data: &[u8]) {
    let _ = session_config_input(&mut Unstructured::new(data));
}

fn name_from<'a>(u: &mut Unstructured<'a>, known: &[&'a str]) -> ArbitraryResult<&'a str> {
    if u.ratio(1, 8)? {
        u.arbitrary()
    } else {
        Ok(known[u.choose_index(known.len())?])
    }
}

fn session_config_input(u: &mut Unstructured) -> ArbitraryResult<()> {
    if u.ratio(1, 16)? {
        let scene: &str = u.arbitrary()?;
        let _ = (phex_scene(scene), pq_scene_spec(scene));
        return Ok(());
    }
    let catalog = surface_catalog();
    let names: Vec<&str> = catalog.iter().map(|s| s.name).collect();
    let surface = name_from(u, &names)?;
    let keys: Vec<&str> = catalog
        .iter()
        .find(|s| s.name == surface)
        .map_or_else(Vec::new, |s| s.params.iter().map(|p| p.key).collect());
    let mut params = Vec::new();
    for _ in 0..u.int_in_range(0..=3)? {
        let key = if keys.is_empty() {
            u.arbitrary()?
        } else {
            name_from(u, &keys)?
        };
        params.push((key.to_string(), coordinate(u)?));
    }
    let method: TriangulationMethod = match name_from(u, &["progressive", "prescribed"])?.parse() {
        Ok(m) => m,
        Err(_) => return Ok(()),
    };
    let size = if u.arbitrary()? {
        Some(coordinate(u)?)
    } else {
        None
    };
    let mut config = PhexConfig::for_surface(surface, &params, method, size);
    if u.arbitrary()? {
        config.rule = dupin_core::phex::LayerRule::Ideal {
            bound: coordinate(u)?,
        };
    }
    if u.arbitrary()? {
        config.lambda = coordinate(u)?;
    }
    if u.arbitrary()? {
        config.mu = coordinate(u)?;
    }
    match name_from(u, &["tangent-duality", "dupin-duality"])?.parse::<Initialisation>() {
        Ok(init) => config.initialisation = init,
        Err(_) => return Ok(()),
    }
    config.max_faces = 2_000;
    config.iterations = 2;
    let Ok(mut pipeline) = PhexPipeline::new(config) else {
        return Ok(());
    };
    for _ in 0..u.int_in_range(0..=6)? {
        if pipeline.is_done() || pipeline.step().is_err() {
            break;
        }
    }
    let _ = pipeline.metrics();
    Ok(())
}

/// `new DupinLesson(surface, params, u, v)`: the surface point's curvature, its Dupin
/// indicatrix and an ideal triangle on it (section 5.1), for any surface, parameters and point.
pub fn dupin_lesson(data: &[u8]) {
    let _ = dupin_lesson_input(&mut Unstructured::new(data));
}

fn dupin_lesson_input(u: &mut Unstructured) -> ArbitraryResult<()> {
    let catalog = surface_catalog();
    let names: Vec<&str> = catalog.iter().map(|s| s.name).collect();
    let surface = name_from(u, &names)?;
    let mut params: Vec<(&str, f64)> = Vec::new();
    let keys: Vec<&str> = catalog
        .iter()
        .find(|s| s.name == surface)
        .map_or_else(Vec::new, |s| s.params.iter().map(|p| p.key).collect());
    for _ in 0..u.int_in_range(0..=3)? {
        let key = if keys.is_empty() {
            u.arbitrary()?
        } else {
            name_from(u, &keys)?
        };
        params.push((key, coordinate(u)?));
    }
    let (pu, pv) = (coordinate(u)?, coordinate(u)?);
    let Ok(s) = surface_by_name(surface, &params) else {
        return Ok(());
    };
    let Ok(c) = s.curvature(pu, pv) else {
        return Ok(());
    };
    let Ok(ind) = DupinIndicatrix::new(c.k1, c.k2) else {
        return Ok(());
    };
    let a = Vec2::new(coordinate(u)?, coordinate(u)?);
    let b = Vec2::new(coordinate(u)?, coordinate(u)?);
    if let Ok(t) = ideal_triangle(&ind, &a, &b) {
        assert!(t.c.x.is_finite() && t.c.y.is_finite(), "a non-finite apex");
    }
    Ok(())
}

/// `dupin planarize` on a small OBJ (up to 48 faces; a few iterations) in each mode, with an
/// anchor: the result keeps the faces and the anchor's bits, and reports the planarity of the
/// mesh it returns.
pub fn planarize(data: &[u8]) {
    let Some((&selector, rest)) = data.split_first() else {
        return;
    };
    let Ok(text) = std::str::from_utf8(rest) else {
        return;
    };
    let Ok(mesh) = parse_obj(text) else {
        return;
    };
    if mesh.num_faces() > 48 || mesh.num_vertices() == 0 {
        return;
    }
    let mode = match selector % 3 {
        0 => PqMode::Planar,
        1 => PqMode::Conical,
        _ => PqMode::Circular,
    };
    let anchor = usize::from(selector / 3) % mesh.num_vertices();
    let options = PqOptions {
        mode,
        fixed_vertices: vec![anchor],
        max_iterations: 4,
        ..PqOptions::default()
    };
    let Ok(stepper) = PqPerturbation::new(&mesh, options) else {
        return;
    };
    let Ok(result) = stepper.finish();
    assert!(
        result.mesh.faces().eq(mesh.faces()),
        "planarize changed the faces"
    );
    assert_eq!(
        result.mesh.positions[anchor], mesh.positions[anchor],
        "planarize moved the anchor"
    );
    let recomputed = max_planarity(&result.mesh);
    assert!(
        result.max_planarity.to_bits() == recomputed.to_bits()
            || (result.max_planarity.is_nan() && recomputed.is_nan()),
        "reported planarity {} but the mesh has {recomputed}",
        result.max_planarity
    );
}

/// A NURBS surface as JSON (`dupin phex --input design.json`): whatever is accepted writes back
/// to JSON that reads to the same surface, bit for bit, and evaluates (corners, middle, a point
/// outside the domain) and projects a point without panicking.
pub fn nurbs_json(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(s) = NurbsSurface::from_json(text) else {
        return;
    };
    let back = NurbsSurface::from_json(&s.to_json()).expect("a written surface reads back");
    assert_eq!(back, s, "the JSON round trip changed the surface");
    let d = s.domain();
    let mid = ((d.u.0 + d.u.1) / 2.0, (d.v.0 + d.v.1) / 2.0);
    for (u, v) in [
        (d.u.0, d.v.0),
        (d.u.1, d.v.1),
        mid,
        (d.u.1 + 1.0, d.v.0 - 1.0),
    ] {
        let _ = s.derivatives(u, v);
    }
    let p = s.position(mid.0, mid.1);
    let _ = s.closest_point(&(p + dupin_core::Vec3::new(0.1, 0.2, 0.3)), None);
}

/// A triangle mesh fitted by a surface (`dupin phex --input mesh.obj`, up to 2 000 triangles
/// here): an accepted fit has finite parameters inside the unit square, with the boundary on
/// it, and a finite distance.
pub fn mesh_fit(data: &[u8]) {
    let options = ImportOptions::default().with_max_triangles(2_000);
    let Ok(imported) = read_mesh("design.obj", data, &options) else {
        return;
    };
    let fit = match fit_mesh_surface(&imported.mesh, &MeshFitOptions::default()) {
        Ok(f) => f,
        Err(_) => return,
    };
    let tol = 1e-9;
    for t in &fit.uv {
        assert!(
            t.x.is_finite() && t.y.is_finite(),
            "a parameter is not finite"
        );
        assert!(
            (-tol..=1.0 + tol).contains(&t.x) && (-tol..=1.0 + tol).contains(&t.y),
            "a parameter {t:?} is outside the square"
        );
    }
    assert!(!fit.max_distance.is_nan() && fit.mean_distance <= fit.max_distance + tol);
}
