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

use serde::de::{self, DeserializeOwned, Deserializer, Error as _, Visitor};
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
    serde_path_to_error::deserialize(Strict(v)).map_err(|e| {
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
    let UniqueValue(mut v) = UniqueValue::deserialize(d)?;
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

/// A JSON value read with every key of every object unique: [`serde_json::Value`] would keep
/// the last of two in silence (`{"type": "plane", ..., "type": "box"}`).
struct UniqueValue(Value);

impl<'de> Deserialize<'de> for UniqueValue {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = UniqueValue;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("any JSON value")
            }
            fn visit_bool<E: de::Error>(self, b: bool) -> Result<UniqueValue, E> {
                Ok(UniqueValue(Value::Bool(b)))
            }
            fn visit_i64<E: de::Error>(self, x: i64) -> Result<UniqueValue, E> {
                Ok(UniqueValue(Value::from(x)))
            }
            fn visit_u64<E: de::Error>(self, x: u64) -> Result<UniqueValue, E> {
                Ok(UniqueValue(Value::from(x)))
            }
            fn visit_f64<E: de::Error>(self, x: f64) -> Result<UniqueValue, E> {
                Ok(UniqueValue(Value::from(x)))
            }
            fn visit_str<E: de::Error>(self, s: &str) -> Result<UniqueValue, E> {
                Ok(UniqueValue(Value::String(s.to_string())))
            }
            fn visit_string<E: de::Error>(self, s: String) -> Result<UniqueValue, E> {
                Ok(UniqueValue(Value::String(s)))
            }
            fn visit_unit<E: de::Error>(self) -> Result<UniqueValue, E> {
                Ok(UniqueValue(Value::Null))
            }
            fn visit_none<E: de::Error>(self) -> Result<UniqueValue, E> {
                Ok(UniqueValue(Value::Null))
            }
            fn visit_some<D2: Deserializer<'de>>(self, d: D2) -> Result<UniqueValue, D2::Error> {
                UniqueValue::deserialize(d)
            }
            fn visit_seq<A: de::SeqAccess<'de>>(self, mut seq: A) -> Result<UniqueValue, A::Error> {
                let mut out = Vec::new();
                while let Some(UniqueValue(x)) = seq.next_element()? {
                    out.push(x);
                }
                Ok(UniqueValue(Value::Array(out)))
            }
            fn visit_map<A: de::MapAccess<'de>>(self, mut map: A) -> Result<UniqueValue, A::Error> {
                let mut out = serde_json::Map::new();
                while let Some(key) = map.next_key::<String>()? {
                    let UniqueValue(x) = map.next_value()?;
                    if out.contains_key(&key) {
                        return Err(A::Error::custom(nested(
                            &key,
                            "given twice: give each field once",
                        )));
                    }
                    out.insert(key, x);
                }
                Ok(UniqueValue(Value::Object(out)))
            }
        }
        d.deserialize_any(V)
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

/// A map whose keys are names (`materials`): a name given twice is refused, where a map would
/// keep the last one in silence.
pub(crate) fn unique_map<'de, D, V>(d: D) -> Result<std::collections::BTreeMap<String, V>, D::Error>
where
    D: Deserializer<'de>,
    V: Deserialize<'de>,
{
    struct M<V>(std::marker::PhantomData<V>);
    impl<'de, V: Deserialize<'de>> Visitor<'de> for M<V> {
        type Value = std::collections::BTreeMap<String, V>;
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str("an object of named entries")
        }
        fn visit_map<A: de::MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
            let mut out = std::collections::BTreeMap::new();
            while let Some(key) = map.next_key::<String>()? {
                let value = map.next_value()?;
                if out.insert(key.clone(), value).is_some() {
                    return Err(A::Error::custom(nested(
                        &key,
                        &format!("'{key}' is defined twice: names must be unique"),
                    )));
                }
            }
            Ok(out)
        }
    }
    d.deserialize_map(M(std::marker::PhantomData))
}

/// A deserializer that refuses a JSON array where an object is expected. serde's derived structs
/// also accept their fields as an array in order, so `"contact": [0.3, 1, 1000]` would be read as
/// friction 0.3, ke 1, lambda 1000, and `"model": [1, 2]` as two of its fields with the rest
/// defaulted: accepted in silence. Everything else is passed through unchanged, at every depth.
pub(crate) struct Strict<D>(pub D);

/// Wraps a visitor: refuses sequences for structs (`no_seq`), wraps whatever it hands on.
struct Wrap<V> {
    v: V,
    fields: Option<&'static [&'static str]>,
}

struct Seed<S>(S);
struct Seq<A>(A);
struct MapA<A>(A);
struct Enum<A>(A);
struct Variant<A>(A);

macro_rules! forward {
    ($($method:ident),*) => {$(
        fn $method<V: Visitor<'de>>(self, v: V) -> Result<V::Value, D::Error> {
            self.0.$method(Wrap { v, fields: None })
        }
    )*};
}

impl<'de, D: Deserializer<'de>> Deserializer<'de> for Strict<D> {
    type Error = D::Error;
    forward!(
        deserialize_any,
        deserialize_bool,
        deserialize_i8,
        deserialize_i16,
        deserialize_i32,
        deserialize_i64,
        deserialize_i128,
        deserialize_u8,
        deserialize_u16,
        deserialize_u32,
        deserialize_u64,
        deserialize_u128,
        deserialize_f32,
        deserialize_f64,
        deserialize_char,
        deserialize_str,
        deserialize_string,
        deserialize_bytes,
        deserialize_byte_buf,
        deserialize_option,
        deserialize_unit,
        deserialize_seq,
        deserialize_map,
        deserialize_identifier,
        deserialize_ignored_any
    );
    fn deserialize_unit_struct<V: Visitor<'de>>(
        self,
        name: &'static str,
        v: V,
    ) -> Result<V::Value, D::Error> {
        self.0
            .deserialize_unit_struct(name, Wrap { v, fields: None })
    }
    fn deserialize_newtype_struct<V: Visitor<'de>>(
        self,
        name: &'static str,
        v: V,
    ) -> Result<V::Value, D::Error> {
        self.0
            .deserialize_newtype_struct(name, Wrap { v, fields: None })
    }
    fn deserialize_tuple<V: Visitor<'de>>(self, len: usize, v: V) -> Result<V::Value, D::Error> {
        self.0.deserialize_tuple(len, Wrap { v, fields: None })
    }
    fn deserialize_tuple_struct<V: Visitor<'de>>(
        self,
        name: &'static str,
        len: usize,
        v: V,
    ) -> Result<V::Value, D::Error> {
        self.0
            .deserialize_tuple_struct(name, len, Wrap { v, fields: None })
    }
    fn deserialize_struct<V: Visitor<'de>>(
        self,
        name: &'static str,
        fields: &'static [&'static str],
        v: V,
    ) -> Result<V::Value, D::Error> {
        self.0.deserialize_struct(
            name,
            fields,
            Wrap {
                v,
                fields: Some(fields),
            },
        )
    }
    fn deserialize_enum<V: Visitor<'de>>(
        self,
        name: &'static str,
        variants: &'static [&'static str],
        v: V,
    ) -> Result<V::Value, D::Error> {
        self.0
            .deserialize_enum(name, variants, Wrap { v, fields: None })
    }
    fn is_human_readable(&self) -> bool {
        self.0.is_human_readable()
    }
}

/// "an object with friction, ke, lambda_s_m" for a refused array.
struct ObjectOf(&'static [&'static str]);

impl de::Expected for ObjectOf {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        write!(f, "an object {{{}}}", self.0.join(", "))
    }
}

macro_rules! pass {
    ($($method:ident($t:ty)),*) => {$(
        fn $method<E: de::Error>(self, x: $t) -> Result<V::Value, E> {
            self.v.$method(x)
        }
    )*};
}

impl<'de, V: Visitor<'de>> Visitor<'de> for Wrap<V> {
    type Value = V::Value;
    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        self.v.expecting(f)
    }
    pass!(
        visit_bool(bool),
        visit_i8(i8),
        visit_i16(i16),
        visit_i32(i32),
        visit_i64(i64),
        visit_i128(i128),
        visit_u8(u8),
        visit_u16(u16),
        visit_u32(u32),
        visit_u64(u64),
        visit_u128(u128),
        visit_f32(f32),
        visit_f64(f64),
        visit_char(char),
        visit_str(&str),
        visit_borrowed_str(&'de str),
        visit_string(String),
        visit_bytes(&[u8]),
        visit_borrowed_bytes(&'de [u8]),
        visit_byte_buf(Vec<u8>)
    );
    fn visit_none<E: de::Error>(self) -> Result<V::Value, E> {
        self.v.visit_none()
    }
    fn visit_unit<E: de::Error>(self) -> Result<V::Value, E> {
        self.v.visit_unit()
    }
    fn visit_some<D2: Deserializer<'de>>(self, d: D2) -> Result<V::Value, D2::Error> {
        self.v.visit_some(Strict(d))
    }
    fn visit_newtype_struct<D2: Deserializer<'de>>(self, d: D2) -> Result<V::Value, D2::Error> {
        self.v.visit_newtype_struct(Strict(d))
    }
    fn visit_seq<A: de::SeqAccess<'de>>(self, seq: A) -> Result<V::Value, A::Error> {
        match self.fields {
            Some(fields) => Err(A::Error::invalid_type(
                de::Unexpected::Seq,
                &ObjectOf(fields),
            )),
            None => self.v.visit_seq(Seq(seq)),
        }
    }
    fn visit_map<A: de::MapAccess<'de>>(self, map: A) -> Result<V::Value, A::Error> {
        self.v.visit_map(MapA(map))
    }
    fn visit_enum<A: de::EnumAccess<'de>>(self, data: A) -> Result<V::Value, A::Error> {
        self.v.visit_enum(Enum(data))
    }
}

impl<'de, S: de::DeserializeSeed<'de>> de::DeserializeSeed<'de> for Seed<S> {
    type Value = S::Value;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<S::Value, D::Error> {
        self.0.deserialize(Strict(d))
    }
}

impl<'de, A: de::SeqAccess<'de>> de::SeqAccess<'de> for Seq<A> {
    type Error = A::Error;
    fn next_element_seed<T: de::DeserializeSeed<'de>>(
        &mut self,
        seed: T,
    ) -> Result<Option<T::Value>, A::Error> {
        self.0.next_element_seed(Seed(seed))
    }
    fn size_hint(&self) -> Option<usize> {
        self.0.size_hint()
    }
}

impl<'de, A: de::MapAccess<'de>> de::MapAccess<'de> for MapA<A> {
    type Error = A::Error;
    fn next_key_seed<K: de::DeserializeSeed<'de>>(
        &mut self,
        seed: K,
    ) -> Result<Option<K::Value>, A::Error> {
        self.0.next_key_seed(seed)
    }
    fn next_value_seed<T: de::DeserializeSeed<'de>>(
        &mut self,
        seed: T,
    ) -> Result<T::Value, A::Error> {
        self.0.next_value_seed(Seed(seed))
    }
    fn size_hint(&self) -> Option<usize> {
        self.0.size_hint()
    }
}

impl<'de, A: de::EnumAccess<'de>> de::EnumAccess<'de> for Enum<A> {
    type Error = A::Error;
    type Variant = Variant<A::Variant>;
    fn variant_seed<T: de::DeserializeSeed<'de>>(
        self,
        seed: T,
    ) -> Result<(T::Value, Self::Variant), A::Error> {
        self.0.variant_seed(seed).map(|(v, a)| (v, Variant(a)))
    }
}

impl<'de, A: de::VariantAccess<'de>> de::VariantAccess<'de> for Variant<A> {
    type Error = A::Error;
    fn unit_variant(self) -> Result<(), A::Error> {
        self.0.unit_variant()
    }
    fn newtype_variant_seed<T: de::DeserializeSeed<'de>>(
        self,
        seed: T,
    ) -> Result<T::Value, A::Error> {
        self.0.newtype_variant_seed(Seed(seed))
    }
    fn tuple_variant<V: Visitor<'de>>(self, len: usize, v: V) -> Result<V::Value, A::Error> {
        self.0.tuple_variant(len, Wrap { v, fields: None })
    }
    fn struct_variant<V: Visitor<'de>>(
        self,
        fields: &'static [&'static str],
        v: V,
    ) -> Result<V::Value, A::Error> {
        self.0.struct_variant(
            fields,
            Wrap {
                v,
                fields: Some(fields),
            },
        )
    }
}

/// The JSON path of the value being read at byte `offset` of `text`, found by scanning the text
/// up to there: for a syntax error, where serde knows only the enclosing object
/// (`model.?: expected `,` or `}``) or nothing at all (`EOF while parsing` in a truncated file).
pub(crate) fn path_at(text: &str, offset: usize) -> String {
    enum Frame {
        Object { key: Option<String> },
        Array { index: usize },
    }
    let bytes = text.as_bytes();
    let end = offset.min(bytes.len());
    let mut stack: Vec<Frame> = Vec::new();
    let mut expecting_key = false;
    let mut i = 0;
    while i < end {
        match bytes[i] {
            b'{' => {
                stack.push(Frame::Object { key: None });
                expecting_key = true;
            }
            b'[' => {
                stack.push(Frame::Array { index: 0 });
                expecting_key = false;
            }
            b'}' | b']' => {
                stack.pop();
                expecting_key = false;
            }
            b',' => match stack.last_mut() {
                Some(Frame::Array { index }) => *index += 1,
                Some(Frame::Object { key }) => {
                    *key = None;
                    expecting_key = true;
                }
                None => {}
            },
            b':' => expecting_key = false,
            b'"' => {
                let start = i;
                i += 1;
                while i < end && bytes[i] != b'"' {
                    i += if bytes[i] == b'\\' { 2 } else { 1 };
                }
                if i >= end {
                    // The text stops inside this string: a value's key is known; a key's is not.
                    break;
                }
                if expecting_key {
                    if let Some(Frame::Object { key }) = stack.last_mut() {
                        *key = serde_json::from_str::<String>(&text[start..=i]).ok();
                    }
                    expecting_key = false;
                }
            }
            _ => {}
        }
        i += 1;
    }
    let mut path = String::new();
    for f in &stack {
        match f {
            Frame::Object { key: Some(k) } => {
                if !path.is_empty() {
                    path.push('.');
                }
                path.push_str(k);
            }
            Frame::Object { key: None } => break,
            Frame::Array { index } => path.push_str(&format!("[{index}]")),
        }
    }
    if path.is_empty() {
        ".".into()
    } else {
        path
    }
}

/// The byte offset of serde_json's (line, column) in `text` (both 1-based; column in bytes).
pub(crate) fn offset_of(text: &str, line: usize, column: usize) -> usize {
    let start: usize = text
        .split_inclusive('\n')
        .take(line.saturating_sub(1))
        .map(str::len)
        .sum();
    (start + column).min(text.len())
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

    #[test]
    fn a_struct_given_as_an_array_is_refused() {
        #[derive(Debug, serde::Deserialize)]
        #[allow(dead_code)]
        struct C {
            friction: f64,
            #[serde(default)]
            ke: f64,
        }
        assert!(
            serde_json::from_str::<C>("[0.3, 1]").is_ok(),
            "serde's own form"
        );
        let e = from_value::<C, serde_json::Error>(serde_json::json!([0.3, 1])).unwrap_err();
        assert!(
            e.to_string().contains("expected an object {friction, ke}"),
            "{e}"
        );
        let v: Vec<C> =
            from_value::<_, serde_json::Error>(serde_json::json!([{"friction": 1}])).unwrap();
        assert_eq!(v.len(), 1);
    }

    #[test]
    fn path_of_a_syntax_error() {
        let t = "{\"model\": {\"max_steps\": 0x10}}";
        assert_eq!(path_at(t, t.find("0x").unwrap() + 1), "model.max_steps");
        let t = "{\"apples\": [{\"name\": \"a\"}, {\"name\": \"b";
        assert_eq!(path_at(t, t.len()), "apples[1].name");
        let t = "{\"apples\": [{\"name\": \"a\"}, {\"na";
        assert_eq!(path_at(t, t.len()), "apples[1]");
        assert_eq!(path_at("{\"a\": 1} x", 10), ".");
        assert_eq!(offset_of("ab\ncd", 2, 1), 4);
    }
}
