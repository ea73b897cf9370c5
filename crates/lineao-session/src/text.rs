//! A keyword argument's value as the command line's text, so that Python's keywords (JSON) are
//! parsed by the command line's own parsers ([`crate::kwargs`], [`crate::method_args`]).

use serde::Deserialize;

/// A value as the command line's text: a string as it is, a number or bool as written, a
/// sequence of them joined by commas (`(0, 0, 0)` → `0,0,0`, `("lineao", "ssao")` → `lineao,ssao`).
pub(crate) struct Text(pub(crate) String);

impl<'de> Deserialize<'de> for Text {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Text, D::Error> {
        match serde_json::Value::deserialize(d)? {
            serde_json::Value::Array(items) => {
                let items: Result<Vec<String>, String> = items.iter().map(scalar).collect();
                items.map(|items| Text(items.join(","))).map_err(serde::de::Error::custom)
            }
            value => scalar(&value).map(Text).map_err(serde::de::Error::custom),
        }
    }
}

fn scalar(value: &serde_json::Value) -> Result<String, String> {
    match value {
        serde_json::Value::String(s) => Ok(s.clone()),
        serde_json::Value::Number(n) => Ok(n.to_string()),
        serde_json::Value::Bool(b) => Ok(b.to_string()),
        other => Err(format!("expected a string, a number or a sequence of them, got {other}")),
    }
}
