//! Deserialization that keeps the exact JSON path of every mistake, through the forms serde's
//! derives lose it in.
//!
//! serde buffers an internally tagged enum (`{"type": "plane", ...}`) or an untagged one before
//! choosing the variant, and `serde_path_to_error` then sees only the enclosing element:
//! `surfaces[0]: invalid type: string "0", expected f64`. Here a tagged enum is read into a
//! [`serde_json::Value`] first, its `type` picks the variant, and the variant is deserialized from
//! the value with its own path tracking; the inner path travels inside the error message between
//! two [`MARK`]s and [`super::from_json`] joins it to the outer one:
//! `surfaces[0].normal[1]: invalid type: string "0", expected f64`. Untagged number-or-object forms
//! (`diameter_m`, `scale`) have visitors that hand the map or sequence on without buffering, so
//! the path is tracked through them as through any struct.

use serde::de::{self, DeserializeOwned, Deserializer, Error as _};
use serde::Deserialize;
use serde_json::Value;

/// Delimits a nested path at the start of an error message (an invisible separator, never in
/// serde's own messages).
pub(crate) const MARK: char = '\u{2063}';

/// Joins a path (`surfaces[0]`, `.` for the top level) and a path inside it (`normal[1]`).
pub(crate) fn join(outer: &str, inner: &str) -> String {
    match (outer, inner) {
        (".", _) | ("", _) => inner.to_string(),
        (_, ".") | (_, "") => outer.to_string(),
        _ if inner.starts_with('[') => format!("{outer}{inner}"),
        _ => format!("{outer}.{inner}"),
    }
}

/// A message carrying the path it is about, relative to where it is raised.
pub(crate) fn nested(path: &str, message: &str) -> String {
    // A message from deeper down already carries its own path: join the two.
    match split(message) {
        Some((inner, rest)) => format!("{MARK}{}{MARK}{rest}", join(path, inner)),
        None => format!("{MARK}{path}{MARK}{message}"),
    }
}

/// The nested path and the rest of a message made by [`nested`].
pub(crate) fn split(message: &str) -> Option<(&str, &str)> {
    message.strip_prefix(MARK)?.split_once(MARK)
}

/// Deserializes `T` from a buffered value, an error keeping the path inside the value.
pub(crate) fn from_value<T: DeserializeOwned, E: de::Error>(v: Value) -> Result<T, E> {
    serde_path_to_error::deserialize(v).map_err(|e| {
        let path = e.path().to_string();
        E::custom(nested(&path, &e.into_inner().to_string()))
    })
}

/// Reads an internally tagged object: returns the `type` (one of `variants`) and the object
/// without it, or an error naming `type`.
pub(crate) fn tagged<'de, D: Deserializer<'de>>(
    d: D,
    variants: &'static [&'static str],
) -> Result<(&'static str, Value), D::Error> {
    let mut v = Value::deserialize(d)?;
    let Value::Object(map) = &mut v else {
        return Err(D::Error::invalid_type(
            unexpected(&v),
            &"an object with a \"type\"",
        ));
    };
    let expected = variants
        .iter()
        .map(|t| format!("`{t}`"))
        .collect::<Vec<_>>()
        .join(", ");
    match map.remove("type") {
        None => Err(D::Error::custom(nested(
            "type",
            &format!("missing: a required field: give one of {expected}"),
        ))),
        Some(Value::String(t)) => match variants.iter().find(|&&n| n == t) {
            Some(&n) => Ok((n, v)),
            None => Err(D::Error::custom(nested(
                "type",
                &format!("unknown variant `{t}`, expected one of {expected}"),
            ))),
        },
        Some(other) => Err(D::Error::custom(nested(
            "type",
            &format!(
                "invalid type: {}, expected one of {expected}",
                unexpected(&other)
            ),
        ))),
    }
}

/// serde's description of a JSON value, for "invalid type" messages.
fn unexpected(v: &Value) -> de::Unexpected<'_> {
    match v {
        Value::Null => de::Unexpected::Unit,
        Value::Bool(b) => de::Unexpected::Bool(*b),
        Value::Number(n) => match (n.as_u64(), n.as_i64(), n.as_f64()) {
            (Some(u), _, _) => de::Unexpected::Unsigned(u),
            (_, Some(i), _) => de::Unexpected::Signed(i),
            (_, _, Some(f)) => de::Unexpected::Float(f),
            _ => de::Unexpected::Other("number"),
        },
        Value::String(s) => de::Unexpected::Str(s),
        Value::Array(_) => de::Unexpected::Seq,
        Value::Object(_) => de::Unexpected::Map,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_join() {
        assert_eq!(join("surfaces[0]", "normal[1]"), "surfaces[0].normal[1]");
        assert_eq!(join("a", "[2]"), "a[2]");
        assert_eq!(join(".", "x"), "x");
        let m = nested("diameter_m", &nested("mean_m", "invalid type"));
        assert_eq!(split(&m), Some(("diameter_m.mean_m", "invalid type")));
    }
}
