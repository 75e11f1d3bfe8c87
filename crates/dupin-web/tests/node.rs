//! wasm-bindgen tests of the JS-facing API, run in Node (`wasm-pack test --node -- --test node`).
#![cfg(target_arch = "wasm32")]

use dupin_web::torus_mesh;
use wasm_bindgen::JsValue;
use wasm_bindgen_test::*;

#[wasm_bindgen_test]
fn torus_mesh_has_the_promised_shape() {
    let m = torus_mesh(2.0, 0.5, 40, 20).unwrap();
    assert_eq!(m.vertex_count(), 800);
    assert_eq!(m.triangle_count(), 1600);
    let p = m.positions().to_vec();
    let n = m.normals().to_vec();
    let idx = m.indices().to_vec();
    assert_eq!(p.len(), 2400);
    assert_eq!(idx.len(), 4800);
    assert!(idx.iter().all(|&i| (i as usize) < 800));
    for k in 0..800 {
        let (x, y, z) = (p[3 * k] as f64, p[3 * k + 1] as f64, p[3 * k + 2] as f64);
        let rho = (x * x + y * y).sqrt() - 2.0;
        assert!(
            ((rho * rho + z * z).sqrt() - 0.5).abs() < 1e-5,
            "vertex {k} is off the torus"
        );
        let len = (n[3 * k] as f64)
            .hypot(n[3 * k + 1] as f64)
            .hypot(n[3 * k + 2] as f64);
        assert!((len - 1.0).abs() < 1e-5);
    }
}

#[wasm_bindgen_test]
fn bad_torus_parameters_are_errors() {
    assert!(torus_mesh(-1.0, 0.5, 40, 20).is_err());
    assert!(torus_mesh(2.0, f64::NAN, 40, 20).is_err());
    assert!(torus_mesh(2.0, 0.5, 1, 20).is_err());
}

#[wasm_bindgen_test]
fn session_steps_a_phex_scene_to_planar_hexagons() {
    use dupin_web::Session;
    let config = js_sys::JSON::parse(r#"{"scene":"sphere-spiral"}"#).unwrap();
    let mut s = Session::new(config).unwrap();
    let mut steps = 0;
    while !s.done() {
        s.step().unwrap();
        steps += 1;
        assert!(steps < 10_000, "the session never finishes");
    }
    assert!(steps > 2, "a P-Hex run has several observable steps");
    let m = s.metrics().unwrap();
    let get = |k: &str| js_sys::Reflect::get(&m, &k.into()).unwrap();
    assert_eq!(get("phase").as_string().as_deref(), Some("done"));
    assert!(get("maxPlanarity").as_f64().unwrap() <= 1e-10);
    assert_eq!(get("invalidFaces").as_f64(), Some(0.0));
    let faces = get("faces").as_f64().unwrap() as usize;
    let obj = s.export_obj();
    assert_eq!(obj.lines().filter(|l| l.starts_with("f ")).count(), faces);
    assert!(s.mesh(JsValue::UNDEFINED).unwrap().edges().length() > 0);
    // Colour modes colour every vertex; an unknown mode is an error.
    for mode in ["planarity", "convexity", "regularity"] {
        let md = s.mesh(JsValue::from(mode)).unwrap();
        assert_eq!(md.colors().length(), md.positions().length(), "{mode}");
    }
    assert!(s.mesh(JsValue::from("rainbow")).is_err());
    // A number where a string belongs is an Error, not a trap in wasm memory.
    assert!(s.mesh(JsValue::from(42)).is_err());
    assert!(dupin_web::color_legend(JsValue::from(42)).is_err());
    // JSON: the report's face count and one face list per face.
    let json: serde_json::Value = serde_json::from_str(&s.export_json().unwrap()).unwrap();
    assert_eq!(json["report"]["faces"].as_u64(), Some(faces as u64));
    assert_eq!(json["mesh"]["faces"].as_array().unwrap().len(), faces);
    assert_eq!(json["report"]["per_face"].as_array().unwrap().len(), faces);
    // SVG schedule: one numbered polygon per panel.
    let svg = s.export_svg(1.5).unwrap();
    assert_eq!(svg.matches("<polygon").count(), faces);
    assert!(s.export_svg(-1.0).is_err());
    // Histogram: every face counted.
    let hist = js_sys::Array::from(&get("histogram"));
    let total: f64 = hist.iter().map(|v| v.as_f64().unwrap()).sum();
    assert_eq!(total as usize, faces);
}

/// `meshSince` across the JS boundary: while the triangulation is revealed each state's mesh
/// comes as only its new triangles and panels, appended to the last key's (the whole mesh's
/// triangle and panel counts add up); a bad key is an Error naming it; another colour mode is
/// whole and cannot be added to.
#[wasm_bindgen_test]
fn mesh_since_hands_out_what_each_reveal_state_added() {
    use dupin_web::Session;
    let mut s = Session::new(js_sys::JSON::parse(r#"{"scene":"sphere-spiral"}"#).unwrap()).unwrap();
    let get = |v: &JsValue, k: &str| js_sys::Reflect::get(v, &k.into()).unwrap();
    let (mut key, mut triangles, mut panels, mut appended) = (JsValue::UNDEFINED, 0, 0, 0);
    while !s.done() {
        s.step().unwrap();
        let part = s.mesh_since(JsValue::UNDEFINED, key.clone()).unwrap();
        let whole = s.mesh(JsValue::UNDEFINED).unwrap();
        let append_to = part.append_to().unwrap();
        if append_to.is_undefined() {
            (triangles, panels) = (0, 0);
        } else {
            assert_eq!(get(&append_to, "faces"), get(&key, "faces"));
            appended += 1;
        }
        triangles += part.triangle_count();
        let faces = part.panel_faces().to_vec();
        let mut rest = faces.as_slice();
        while let Some((&n, tail)) = rest.split_first() {
            panels += 1;
            rest = &tail[n as usize..];
        }
        assert_eq!(triangles, whole.triangle_count());
        assert_eq!(panels, whole.panel_count());
        key = part.key().unwrap();
        assert_eq!(
            get(&key, "faces").as_f64(),
            Some(whole.panel_count() as f64)
        );
    }
    assert!(appended > 3, "{appended} states were appended");
    for bad in [
        r#"{"revision":1}"#,
        r#"{"revision":1,"faces":2,"vertices":3,"x":4}"#,
        "42",
        r#""key""#,
    ] {
        assert!(
            s.mesh_since(JsValue::UNDEFINED, js_sys::JSON::parse(bad).unwrap())
                .is_err(),
            "{bad}"
        );
    }
    let convexity = s.mesh_since(JsValue::from("convexity"), key).unwrap();
    assert!(convexity.append_to().unwrap().is_undefined());
    assert!(convexity.key().unwrap().is_undefined());
}

#[wasm_bindgen_test]
fn bad_session_configs_throw_readable_errors() {
    use dupin_web::Session;
    for (json, needle) in [
        (r#"{"scene":"no-such-scene"}"#, "no-such-scene"),
        (r#"{"surface":"torus","method":"sideways"}"#, "method"),
        (r#"{}"#, "scene"),
        (r#"{"scene":1}"#, "bad session config"),
        (r#"{"surface":"torus","lambda":-1}"#, "lambda"),
        (r#"{"surface":"torus","mu":-0.5}"#, "mu"),
        (r#"{"surface":"torus","bound":7}"#, "lower bound b"),
        (r#"{"surface":"torus","params":{"r":-1}}"#, "r"),
        (r#"{"surface":"torus","size":1000}"#, "size"),
        (r#"{"surface":"torus","init":"magic"}"#, "init"),
        (r#"{"surface":"torus","sise":0.2}"#, "unknown field `sise`"),
        (
            r#"{"scene":"sphere-radial","iterations":3}"#,
            "unknown field `iterations`",
        ),
        // Sizes the page suggested made the worker run out of memory ("capacity overflow")
        // or return 180k self-intersecting faces: refused at once by the face budget.
        (r#"{"surface":"torus","size":0.0043}"#, "limit of 100000"),
        (r#"{"surface":"sphere","size":0.001}"#, "limit of 100000"),
    ] {
        let err = match Session::new(js_sys::JSON::parse(json).unwrap()) {
            Err(e) => wasm_bindgen::JsValue::from(e),
            Ok(_) => panic!("accepted {json}"),
        };
        let msg: String = js_sys::Reflect::get(&err, &"message".into())
            .unwrap()
            .as_string()
            .unwrap();
        assert!(msg.contains(needle), "{json}: {msg}");
    }
}

#[wasm_bindgen_test]
fn mesh_arrays_round_trip_and_reject_bad_lengths() {
    use dupin_web::MeshData;
    let m = torus_mesh(2.0, 0.5, 12, 8).unwrap();
    let back = MeshData::from_arrays(
        m.positions().to_vec(),
        m.normals().to_vec(),
        m.indices().to_vec(),
        vec![],
        vec![],
    )
    .unwrap();
    assert_eq!(back.triangle_count(), m.triangle_count());
    assert!(MeshData::from_arrays(vec![0.0; 4], vec![0.0; 4], vec![], vec![], vec![]).is_err());
    assert!(
        MeshData::from_arrays(vec![0.0; 9], vec![0.0; 9], vec![0, 1, 3], vec![], vec![]).is_err()
    );
}

#[wasm_bindgen_test]
fn surface_catalog_lists_every_library_surface_with_ranges() {
    let cat = js_sys::Array::from(&dupin_web::surface_catalog_js().unwrap());
    assert_eq!(
        cat.length() as usize,
        dupin_core::surface::surface_catalog().len()
    );
    for s in cat.iter() {
        let params = js_sys::Array::from(&js_sys::Reflect::get(&s, &"params".into()).unwrap());
        for p in params.iter() {
            let f = |k: &str| {
                js_sys::Reflect::get(&p, &k.into())
                    .unwrap()
                    .as_f64()
                    .unwrap()
            };
            assert!(f("min") <= f("default") && f("default") <= f("max"));
        }
    }
}

#[path = "web_api/teach.rs"]
mod teach_node;

#[wasm_bindgen_test]
fn pq_session_steps_levels_and_draws_conical_layers() {
    use dupin_web::Session;
    let parse = |s: &str| js_sys::JSON::parse(s).unwrap();
    let get = |m: &wasm_bindgen::JsValue, k: &str| js_sys::Reflect::get(m, &k.into()).unwrap();
    let message = |e: wasm_bindgen::JsError| -> String {
        let v = wasm_bindgen::JsValue::from(e);
        get(&v, "message").as_string().unwrap()
    };
    let mut s = Session::new(parse(r#"{"scene":"conical-station"}"#)).unwrap();
    let first = s.step().unwrap();
    assert_eq!(get(&first, "phase").as_string().as_deref(), Some("control"));
    assert_eq!(get(&first, "level").as_f64(), Some(0.0));
    assert!(s.offset_unavailable().is_none());
    for (json, needle) in [
        (r#"{"offset":true,"distance":0}"#, "distance"),
        (r#"{"offsets":true}"#, "bad layers"),
    ] {
        let msg = message(s.set_layers(parse(json)).unwrap_err());
        assert!(msg.contains(needle), "{json}: {msg}");
    }
    let plain = s.mesh(JsValue::UNDEFINED).unwrap().triangle_count();
    s.set_layers(parse(r#"{"offset":true,"support":true,"distance":0.2}"#))
        .unwrap();
    assert!(s.mesh(JsValue::UNDEFINED).unwrap().triangle_count() > 2 * plain);
    let mut levels = std::collections::BTreeSet::from([0]);
    while !s.done() {
        let m = s.step().unwrap();
        levels.insert(get(&m, "level").as_f64().unwrap() as usize);
    }
    assert_eq!(levels.into_iter().collect::<Vec<_>>(), vec![0, 1, 2]);
    let m = s.metrics().unwrap();
    assert!(get(&m, "maxPlanarity").as_f64().unwrap() <= 1e-10);
    assert!(get(&m, "conicalResidual").as_f64().unwrap() <= 1e-10);
    let info = s.layer_info().unwrap();
    assert!(get(&info, "beams").as_f64().unwrap() > 0.0);
    assert!(get(&info, "beamPlanarity").as_f64().unwrap() <= 1e-9);
    // A non-conical scene has no offset layer and says why.
    let mut t = Session::new(parse(r#"{"scene":"developable-strips"}"#)).unwrap();
    assert!(t.offset_unavailable().unwrap().contains("conical"));
    assert!(message(t.set_layers(parse(r#"{"support":true}"#)).unwrap_err()).contains("conical"));
    t.set_layers(wasm_bindgen::JsValue::NULL).unwrap();
    assert!(t.layer_info().unwrap().is_null());
}

/// A panel design at state-plane coordinates (3.1e6, 5.2e6) is shown relative to its view
/// origin, so `f32` draws it as finely as the same design at zero: its render buffers are that
/// design's bit for bit; a pick, a drag and a box selection speak the view's coordinates; the
/// OBJ (the page's and the session's) and the metrics stay where the file put the design.
#[wasm_bindgen_test]
fn a_far_design_is_shown_relative_to_its_view_origin() {
    use dupin_web::Session;
    let get = |m: &JsValue, k: &str| js_sys::Reflect::get(m, &k.into()).unwrap();
    let numbers = |v: JsValue| -> Vec<f64> {
        js_sys::Array::from(&v)
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect()
    };
    // A 4 x 4 quad grid centred on zero, slightly warped, in numbers a shift keeps exact.
    let grid = |shift: [f64; 3]| -> String {
        let mut obj = String::new();
        for j in 0..5 {
            for i in 0..5 {
                let z = [0.0, 1.0, -1.0][(i * 7 + j * 3) % 3] / 16.0;
                let p = [i as f64 - 2.0, j as f64 - 2.0, z];
                obj += &format!(
                    "v {} {} {}\n",
                    p[0] + shift[0],
                    p[1] + shift[1],
                    p[2] + shift[2]
                );
            }
        }
        for j in 0..4 {
            for i in 0..4 {
                let v = |a: usize, b: usize| b * 5 + a + 1;
                obj += &format!(
                    "f {} {} {} {}\n",
                    v(i, j),
                    v(i + 1, j),
                    v(i + 1, j + 1),
                    v(i, j + 1)
                );
            }
        }
        obj
    };
    let shift = [3.0 * 2f64.powi(20), 5.0 * 2f64.powi(20), 64.0];
    let far_obj = grid(shift);
    let open = |obj: &str| Session::from_file("grid.obj", obj.as_bytes(), JsValue::UNDEFINED);
    let mut far = open(&far_obj).unwrap();
    let mut near = open(&grid([0.0; 3])).unwrap();
    assert_eq!(numbers(get(&far.metrics().unwrap(), "viewOrigin")), shift);
    assert_eq!(
        numbers(get(&near.metrics().unwrap(), "viewOrigin")),
        [0.0; 3]
    );
    let (m, n) = (
        far.mesh(JsValue::UNDEFINED).unwrap(),
        near.mesh(JsValue::UNDEFINED).unwrap(),
    );
    assert_eq!(m.positions().to_vec(), n.positions().to_vec());
    assert_eq!(m.normals().to_vec(), n.normals().to_vec());
    assert_eq!(m.edges().to_vec(), n.edges().to_vec());
    assert_eq!(m.view_origin(), shift);
    // The page's OBJ of the drawn mesh is the file's design, where the file put it.
    let vertices = |obj: &str| -> Vec<String> {
        obj.lines()
            .filter(|l| l.starts_with("v "))
            .map(str::to_string)
            .collect()
    };
    let numbers_of = |line: &str| -> Vec<f64> {
        line.split_whitespace()
            .skip(1)
            .map(|x| x.parse().unwrap())
            .collect()
    };
    let page_obj = m.to_obj().unwrap();
    for (a, b) in vertices(&page_obj).iter().zip(vertices(&far_obj).iter()) {
        assert_eq!(numbers_of(a), numbers_of(b));
    }
    // A click above grid vertex (3, 3) of the view picks it and answers in the view.
    let pick = far
        .pick_panel_vertex(vec![1.0, 1.0, 10.0], vec![0.0, 0.0, -1.0])
        .unwrap();
    let vertex = get(&pick, "vertex").as_f64().unwrap() as usize;
    assert_eq!(vertex, 3 * 5 + 3);
    let point = numbers(get(&pick, "point"));
    assert_eq!(&point[..2], &[1.0, 1.0]);
    // A box selection through the identity view, in the view's coordinates.
    let identity: Vec<f64> = (0..16)
        .map(|k| if k % 5 == 0 { 1.0 } else { 0.0 })
        .collect();
    let sel = far
        .vertices_in_rect(identity, -0.5, -0.5, 1.5, 1.5)
        .unwrap();
    let chosen = numbers(get(&sel, "vertices"));
    assert_eq!(chosen, [12.0, 13.0, 17.0, 18.0]);
    let points = numbers(get(&sel, "points"));
    assert!(
        points.chunks(3).all(|p| p[0] >= -0.5 && p[1] <= 1.5),
        "{points:?}"
    );
    // A drag to a point of the view holds the vertex at that point plus the origin, exactly.
    far.drag_vertex(vertex, 1.0, 1.0, 0.5, true).unwrap();
    far.step().unwrap();
    let moved = vertices(&far.export_obj())[vertex].clone();
    assert_eq!(
        numbers_of(&moved),
        [1.0 + shift[0], 1.0 + shift[1], 0.5 + shift[2]]
    );
}

/// An opened NURBS surface far from zero is drawn relative to a view origin near its control
/// net, fixed while its control points move.
#[wasm_bindgen_test]
fn a_far_surface_is_shown_relative_to_its_view_origin() {
    use dupin_web::Session;
    let get = |m: &JsValue, k: &str| js_sys::Reflect::get(m, &k.into()).unwrap();
    let net = |dx: f64, dy: f64| {
        format!(
            r#"{{"degree_u":2,"degree_v":2,"knots_u":[0,0,0,1,1,1],"knots_v":[0,0,0,1,1,1],
            "control_points":[[[{a},{b},0],[{a},{c},1],[{a},{d},0]],
                              [[{e},{b},1],[{e},{c},3],[{e},{d},1]],
                              [[{f},{b},0],[{f},{c},1],[{f},{d},0]]]}}"#,
            a = dx,
            e = dx + 5.0,
            f = dx + 10.0,
            b = dy,
            c = dy + 5.0,
            d = dy + 10.0
        )
    };
    let config = js_sys::JSON::parse(r#"{"size":1.5}"#).unwrap();
    let mut s = Session::from_file(
        "dome.json",
        net(3_000_000.0, 5_000_000.0).as_bytes(),
        config,
    )
    .unwrap();
    let origin: Vec<f64> = js_sys::Array::from(&get(&s.metrics().unwrap(), "viewOrigin"))
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert!((origin[0] - 3_000_005.0).abs() <= 16.0, "{origin:?}");
    assert!((origin[1] - 5_000_005.0).abs() <= 16.0, "{origin:?}");
    for _ in 0..5 {
        s.step().unwrap();
    }
    let p = s.mesh(JsValue::UNDEFINED).unwrap().positions().to_vec();
    assert!(
        !p.is_empty() && p.iter().all(|c| c.abs() <= 32.0),
        "{:?}",
        &p[..3]
    );
    s.move_control_point(4.0, 3_000_005.0, 5_000_005.0, 4.0)
        .unwrap();
    let after: Vec<f64> = js_sys::Array::from(&get(&s.metrics().unwrap(), "viewOrigin"))
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert_eq!(after, origin);
}
