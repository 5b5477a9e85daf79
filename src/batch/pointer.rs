//! JSON Pointers (RFC 6901) that name the field a batch parameter sets, e.g.
//! `/apples/0/velocity_m_s/2`.
//!
//! serde_json can read through a pointer (`Value::pointer_mut`) but not add a key, and a batch
//! must be able to set an optional field the base scenario leaves out (`/output/force_history`).
//! So setting is done here, with errors that say which part of the pointer is missing.

use serde_json::Value;

/// The reference tokens of a pointer, unescaped (`~1` is `/`, `~0` is `~`).
pub fn tokens(pointer: &str) -> Result<Vec<String>, String> {
    if pointer.is_empty() {
        return Err(
            "the empty pointer names the whole scenario; name a field, e.g. \"/duration_s\"".into(),
        );
    }
    let Some(rest) = pointer.strip_prefix('/') else {
        return Err(format!(
            "'{pointer}' is not a JSON Pointer: it must start with '/', e.g. \"/apples/0/diameter_m\""
        ));
    };
    rest.split('/')
        .map(|t| {
            let b = t.as_bytes();
            let bad = (0..b.len()).any(|i| b[i] == b'~' && !matches!(b.get(i + 1), Some(b'0' | b'1')));
            if bad {
                return Err(format!(
                    "'{pointer}': '{t}' has a '~' not followed by 0 or 1 (write ~0 for '~', ~1 for '/')"
                ));
            }
            Ok(t.replace("~1", "/").replace("~0", "~"))
        })
        .collect()
}

/// Sets the value at `pointer` in `doc`. The parent of the last token must exist; an object
/// parent gains the key if it lacks it, an array parent must already hold the index (a batch
/// changes a scenario, it does not grow its lists by accident).
pub fn set(doc: &mut Value, pointer: &str, value: Value) -> Result<(), String> {
    let toks = tokens(pointer)?;
    let (last, parents) = toks
        .split_last()
        .expect("tokens() returns at least one token");
    let mut here = doc;
    let mut walked = String::new();
    for t in parents {
        let shown = if walked.is_empty() {
            "the scenario".to_string()
        } else {
            format!("'{walked}'")
        };
        here = match here {
            Value::Object(map) => map
                .get_mut(t)
                .ok_or_else(|| format!("'{pointer}': {shown} has no field '{t}'"))?,
            Value::Array(items) => {
                let n = items.len();
                let k = index(t, n).map_err(|m| format!("'{pointer}': {shown} {m}"))?;
                &mut items[k]
            }
            other => {
                return Err(format!(
                    "'{pointer}': {shown} is {}, not an object or array",
                    kind(other)
                ))
            }
        };
        walked.push('/');
        walked.push_str(t);
    }
    let shown = if walked.is_empty() {
        "the scenario".to_string()
    } else {
        format!("'{walked}'")
    };
    match here {
        Value::Object(map) => {
            map.insert(last.clone(), value);
            Ok(())
        }
        Value::Array(items) => {
            let k = index(last, items.len()).map_err(|m| format!("'{pointer}': {shown} {m}"))?;
            items[k] = value;
            Ok(())
        }
        other => Err(format!(
            "'{pointer}': {shown} is {}, not an object or array",
            kind(other)
        )),
    }
}

fn index(t: &str, len: usize) -> Result<usize, String> {
    // RFC 6901: decimal digits without a leading zero.
    let ok =
        !t.is_empty() && t.bytes().all(|b| b.is_ascii_digit()) && (t == "0" || !t.starts_with('0'));
    let k: usize = if ok {
        t.parse().map_err(|_| format!("has no index {t}"))?
    } else {
        return Err(format!("is a list: '{t}' is not an index (0, 1, ...)"));
    };
    if k < len {
        Ok(k)
    } else {
        Err(format!("has {len} element(s), no index {k}"))
    }
}

fn kind(v: &Value) -> &'static str {
    match v {
        Value::Null => "null",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "a list",
        Value::Object(_) => "an object",
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn sets_nested_fields_and_adds_missing_keys() {
        let mut v = json!({"apples": [{"velocity_m_s": [0, 0, -1]}], "output": {}});
        set(&mut v, "/apples/0/velocity_m_s/2", json!(-2.5)).unwrap();
        set(&mut v, "/output/force_history", json!(false)).unwrap();
        assert_eq!(
            v,
            json!({"apples": [{"velocity_m_s": [0, 0, -2.5]}], "output": {"force_history": false}})
        );
    }

    #[test]
    fn unescapes_tokens() {
        assert_eq!(tokens("/a~1b/c~0d").unwrap(), vec!["a/b", "c~d"]);
        assert!(tokens("/a~2").unwrap_err().contains("'~'"));
    }

    #[test]
    fn bad_pointers_say_what_is_missing() {
        let mut v = json!({"apples": [{"diameter_m": 0.08}], "duration_s": 1});
        let e = set(&mut v, "/apples/3/diameter_m", json!(1)).unwrap_err();
        assert!(e.contains("'/apples' has 1 element(s), no index 3"), "{e}");
        let e = set(&mut v, "/surfaces/0/point_m", json!(1)).unwrap_err();
        assert!(e.contains("the scenario has no field 'surfaces'"), "{e}");
        let e = set(&mut v, "/duration_s/x", json!(1)).unwrap_err();
        assert!(e.contains("'/duration_s' is a number"), "{e}");
        let e = set(&mut v, "/apples/01/diameter_m", json!(1)).unwrap_err();
        assert!(e.contains("not an index"), "{e}");
        let e = set(&mut v, "apples", json!(1)).unwrap_err();
        assert!(e.contains("must start with '/'"), "{e}");
        assert!(set(&mut v, "", json!(1)).is_err());
    }
}
