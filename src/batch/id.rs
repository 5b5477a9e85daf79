//! Run ids: the first 16 hex digits (64 bits) of the SHA-256 of the expanded scenario's
//! canonical JSON.
//!
//! The id depends on the scenario alone, not on where the run sits in the expansion, which
//! shard or thread ran it, or the order of the spec's parameters: so a rerun, a resumed batch
//! and a grown sweep all find the runs already done, and a changed base scenario gets new ids
//! (its old results are not reused by mistake). 64 bits make an accidental collision in a batch
//! of a million runs about a 3e-8 chance; an expansion that does produce a repeated id is
//! refused (see [`super::spec`]).

use serde_json::Value;
use sha2::{Digest, Sha256};
use std::fmt::Write;

/// Hex digits kept from the SHA-256.
pub const ID_HEX_DIGITS: usize = 16;

/// Canonical JSON text: no white space, object keys sorted (byte order) at every level, numbers
/// and strings as serde_json writes them. Keys are sorted here rather than relying on
/// `serde_json::Map` being a `BTreeMap`, which holds only while no crate in the build turns on
/// serde_json's `preserve_order` feature.
pub fn canonical_json(v: &Value) -> String {
    let mut out = String::new();
    write_canonical(v, &mut out);
    out
}

fn write_canonical(v: &Value, out: &mut String) {
    match v {
        Value::Object(map) => {
            let mut keys: Vec<&String> = map.keys().collect();
            keys.sort();
            out.push('{');
            for (k, key) in keys.into_iter().enumerate() {
                if k > 0 {
                    out.push(',');
                }
                out.push_str(&Value::String(key.clone()).to_string());
                out.push(':');
                write_canonical(&map[key], out);
            }
            out.push('}');
        }
        Value::Array(items) => {
            out.push('[');
            for (k, item) in items.iter().enumerate() {
                if k > 0 {
                    out.push(',');
                }
                write_canonical(item, out);
            }
            out.push(']');
        }
        scalar => out.push_str(&scalar.to_string()),
    }
}

/// The run id of an expanded scenario.
pub fn run_id(scenario: &Value) -> String {
    bytes_id(canonical_json(scenario).as_bytes())
}

/// The id of raw bytes (a scenario file that is not valid JSON still needs a stable id).
pub fn bytes_id(bytes: &[u8]) -> String {
    let digest = Sha256::digest(bytes);
    let mut hex = String::with_capacity(ID_HEX_DIGITS);
    for b in digest.iter().take(ID_HEX_DIGITS / 2) {
        write!(hex, "{b:02x}").expect("writing to a String");
    }
    hex
}

/// True for a string shaped like a run id (16 lower-case hex digits).
pub fn is_id(s: &str) -> bool {
    s.len() == ID_HEX_DIGITS && s.bytes().all(|b| matches!(b, b'0'..=b'9' | b'a'..=b'f'))
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn canonical_json_sorts_keys_at_every_level() {
        let v: Value =
            serde_json::from_str(r#"{"b": 1, "a": {"y": [1, {"d": 2, "c": 3}], "x": "s"}}"#)
                .unwrap();
        assert_eq!(
            canonical_json(&v),
            r#"{"a":{"x":"s","y":[1,{"c":3,"d":2}]},"b":1}"#
        );
    }

    #[test]
    fn ids_are_stable_and_ignore_key_order_and_spacing() {
        let a: Value =
            serde_json::from_str(r#"{"duration_s": 0.03, "apples": [{"diameter_m": 0.08}]}"#)
                .unwrap();
        let b: Value =
            serde_json::from_str("{\"apples\":[{\"diameter_m\":0.08}],\n \"duration_s\":0.03}")
                .unwrap();
        assert_eq!(run_id(&a), run_id(&b));
        // The value is pinned: an id must not change between versions of applesim, or a
        // resumed batch would rerun everything. sha256('{"apples":[{"diameter_m":0.08}],"duration_s":0.03}').
        assert_eq!(run_id(&a), "5d7e3404d22a4729");
        assert!(is_id(&run_id(&a)));
        let c = json!({"duration_s": 0.031, "apples": [{"diameter_m": 0.08}]});
        assert_ne!(run_id(&a), run_id(&c));
    }
}
