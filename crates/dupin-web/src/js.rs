//! Rust values and errors as JS values, and JS arguments checked before use: the conversions
//! every page API module uses.

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

/// A string argument from JS, checked: a number or an object where a string is expected is a
/// JS `Error` naming the argument, not a trap in wasm memory.
pub(crate) fn string_arg(value: &JsValue, what: &str) -> Result<String, JsError> {
    value.as_string().ok_or_else(|| {
        let got = if value.is_undefined() || value.is_null() {
            "nothing".to_string()
        } else {
            value.js_typeof().as_string().unwrap_or_default()
        };
        err(format!("{what} must be a string, got {got}"))
    })
}

/// A number argument from JS, checked to be a finite number.
pub(crate) fn number_arg(value: f64, what: &str) -> Result<f64, JsError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(err(format!("{what} must be a finite number, got {value}")))
    }
}

/// serde_wasm_bindgen reads a JS object's known fields only (`deny_unknown_fields` never
/// fires), so a misspelt key would be silently ignored: refuse it with a readable message.
pub(crate) fn refuse_unknown_keys(
    value: &JsValue,
    what: &str,
    allowed: &[&str],
) -> Result<(), JsError> {
    if !value.is_object() {
        return Ok(()); // serde reports the wrong type itself.
    }
    let keys = js_sys::Object::keys(&js_sys::Object::from(value.clone()));
    match keys
        .iter()
        .filter_map(|k| k.as_string())
        .find(|k| !allowed.contains(&k.as_str()))
    {
        Some(k) => Err(JsError::new(&format!(
            "bad {what}: unknown field `{k}`, expected one of `{}`",
            allowed.join("`, `")
        ))),
        None => Ok(()),
    }
}
