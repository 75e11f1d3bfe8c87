//! wasm-bindgen tests of the teaching inset's and the 2D tab's JS API (included by `node.rs`).

use dupin_web::{DupinLesson, HexDelaunayLab};
use wasm_bindgen::JsValue;
use wasm_bindgen_test::*;

fn get(v: &JsValue, k: &str) -> JsValue {
    js_sys::Reflect::get(v, &k.into()).unwrap()
}

fn pair(v: &JsValue) -> (f64, f64) {
    let a = js_sys::Array::from(v);
    (a.get(0).as_f64().unwrap(), a.get(1).as_f64().unwrap())
}

/// Proposition 4 through the JS API: the apex dragged along the conjugate line through the
/// base midpoint is valid beyond DE and invalid below it (section 5.1).
#[wasm_bindgen_test]
fn lesson_validity_flips_across_de() {
    let params = js_sys::JSON::parse(r#"{"R":2,"r":0.7}"#).unwrap();
    let mut l = DupinLesson::new("torus".into(), params, 0.3, 0.4).unwrap();
    let s = l.state().unwrap();
    assert_eq!(get(&s, "kind").as_string().as_deref(), Some("elliptic"));
    assert_eq!(get(&s, "verdict").as_string().as_deref(), Some("valid"));
    let ring = js_sys::Array::from(&get(&s, "ring"));
    assert_eq!(ring.length(), 6);
    let steps = js_sys::Array::from(&l.ideal_triangle_steps().unwrap());
    assert_eq!(steps.length(), 5);
    // M from step 2, C from step 5: the apex path is M + s (C - M); |CM| = sqrt(3) |MD|, so DE is at s = 1/sqrt(3).
    let m = js_sys::Array::from(&get(&steps.get(1), "points")).get(0);
    let c = js_sys::Array::from(&get(&steps.get(4), "points")).get(0);
    let xy = |p: JsValue| {
        let a = js_sys::Array::from(&p);
        (a.get(1).as_f64().unwrap(), a.get(2).as_f64().unwrap())
    };
    let ((mx, my), (cx, cy)) = (xy(m), xy(c));
    let at = |s: f64| (mx + s * (cx - mx), my + s * (cy - my));
    let (x, y) = at(0.7);
    let s = l.drag_vertex(1, x, y).unwrap();
    assert_eq!(get(&s, "verdict").as_string().as_deref(), Some("valid"));
    let (x, y) = at(0.45);
    let s = l.drag_vertex(1, x, y).unwrap();
    assert_eq!(get(&s, "verdict").as_string().as_deref(), Some("invalid"));
    // The dragged direction and its conjugate come back with the state.
    let (dx, dy) = pair(&get(&s, "dragged"));
    let (ex, ey) = pair(&get(&s, "conjugate"));
    let (k1, k2) = (
        get(&s, "k1").as_f64().unwrap(),
        get(&s, "k2").as_f64().unwrap(),
    );
    assert!((k1 * dx * ex + k2 * dy * ey).abs() < 1e-9);
    let e = l.conjugate_of(dx, dy).unwrap();
    assert!((e[0] - ex).abs() < 1e-12 && (e[1] - ey).abs() < 1e-12);
    assert!(l.conjugate_of(0.0, 0.0).is_err());
    assert!(l.drag_vertex(9, 0.1, 0.1).is_err());
    let s = l.make_ideal_js().unwrap();
    assert_eq!(get(&s, "verdict").as_string().as_deref(), Some("valid"));
}

#[wasm_bindgen_test]
fn lesson_errors_are_js_errors() {
    assert!(DupinLesson::new("nope".into(), JsValue::UNDEFINED, 0.0, 0.0).is_err());
    assert!(DupinLesson::new("sphere".into(), JsValue::UNDEFINED, f64::NAN, 0.0).is_err());
    let bad = js_sys::JSON::parse(r#"{"radius":"big"}"#).unwrap();
    assert!(DupinLesson::new("sphere".into(), bad, 0.0, 0.0).is_err());
    assert!(DupinLesson::from_curvatures_js(0.0, 0.0).is_err());
    // A number where the surface name belongs is an Error, not a trap in wasm memory.
    assert!(DupinLesson::new(JsValue::from(42), JsValue::UNDEFINED, 0.0, 0.0).is_err());
    assert!(DupinLesson::new(JsValue::NULL, JsValue::UNDEFINED, 0.0, 0.0).is_err());
}

#[wasm_bindgen_test]
fn hex_lab_steps_to_the_simple_bounds() {
    let mut lab = HexDelaunayLab::new("simple".into()).unwrap();
    let xy = vec![0.0, 0.0, 0.3, 0.1, -0.2, 0.25, 0.05, -0.3, 0.31, 0.12];
    lab.set_input_js(xy, vec![]).unwrap();
    let mut n = 0;
    while lab.step().unwrap() {
        n += 1;
        assert!(n < 10_000);
    }
    assert!(lab.done() && lab.steps() == n && n > 0);
    let d = lab.dual().unwrap();
    let (lo, hi) = (
        get(&d, "minAngle").as_f64().unwrap(),
        get(&d, "maxAngle").as_f64().unwrap(),
    );
    assert!(lo >= 30.0 - 1e-9 && hi <= 120.0 + 1e-9, "{lo}..{hi}");
    // PSLG input (section 7): a segment is accepted; one naming a missing point is an error.
    assert!(
        lab.set_input_js(vec![0.0, 0.0, 1.0, 1.0], vec![0, 1])
            .is_ok()
    );
    assert!(
        lab.set_input_js(vec![0.0, 0.0, 1.0, 1.0], vec![0, 5])
            .is_err()
    );
    assert!(HexDelaunayLab::new("other".into()).is_err());
    assert!(HexDelaunayLab::new(JsValue::from(42)).is_err());
}
