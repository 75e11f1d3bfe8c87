//! wasm-bindgen tests in headless Chromium (`wasm-pack test --headless --chrome -- --test
//! browser`; Chrome flags come from ../webdriver.json): the viewer draws with WebGPU, and with
//! WebGL2 when forced.
#![cfg(target_arch = "wasm32")]

use dupin_web::{Viewer, torus_mesh};
use wasm_bindgen::JsCast;
use wasm_bindgen_test::*;

wasm_bindgen_test_configure!(run_in_browser);

fn canvas() -> web_sys::HtmlCanvasElement {
    let doc = web_sys::window().unwrap().document().unwrap();
    let c: web_sys::HtmlCanvasElement = doc.create_element("canvas").unwrap().dyn_into().unwrap();
    c.set_width(64);
    c.set_height(48);
    doc.body().unwrap().append_child(&c).unwrap();
    c
}

async fn draw(force_webgl2: bool) -> String {
    let mut v = Viewer::create(canvas(), force_webgl2)
        .await
        .expect("viewer");
    let mesh = torus_mesh(2.0, 0.5, 32, 16).unwrap();
    v.set_mesh(&mesh, true).unwrap();
    v.orbit(0.3, 0.1);
    v.resize(80, 60);
    v.render().expect("render");
    v.backend()
}

#[wasm_bindgen_test]
async fn viewer_draws_with_webgpu() {
    assert_eq!(draw(false).await, "WebGPU");
}

#[wasm_bindgen_test]
async fn viewer_falls_back_to_webgl2() {
    assert_eq!(draw(true).await, "WebGL2");
}

#[wasm_bindgen_test]
fn errors_cross_as_js_errors() {
    let err = match torus_mesh(0.0, 1.0, 8, 8) {
        Err(e) => wasm_bindgen::JsValue::from(e),
        Ok(_) => panic!("accepted R = 0"),
    };
    let err: js_sys::Error = err.dyn_into().expect("a JS Error");
    assert!(String::from(err.message()).contains("R must be a positive number"));
}
