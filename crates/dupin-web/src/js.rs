//! Rust values and errors as JS values: the two conversions every page API module uses.

use serde::Serialize;
use wasm_bindgen::prelude::*;

/// `v` as a plain JS value (objects, arrays, numbers; maps as objects, `None` as `null`).
pub(crate) fn to_js<T: Serialize>(v: &T) -> Result<JsValue, JsError> {
    v.serialize(&serde_wasm_bindgen::Serializer::json_compatible())
        .map_err(err)
}

/// A JS `Error` carrying the Rust message.
pub(crate) fn err(e: impl std::fmt::Display) -> JsError {
    JsError::new(&e.to_string())
}
