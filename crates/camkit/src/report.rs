//! The `--report` document: figures of a run as JSON, keys in the order they were set.

use crate::error::Result;
use serde::Serialize;
use serde_json::{Map, Value};
use std::path::Path;

/// Figures of one run of a filter.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Report {
    fields: Map<String, Value>,
}

impl Report {
    /// A report of `filter`'s run.
    pub fn new(filter: &str) -> Report {
        let mut r = Report::default();
        r.set("filter", filter);
        r.set("version", env!("CARGO_PKG_VERSION"));
        r
    }

    /// Sets a figure; values that do not serialise (NaN) are written as null.
    pub fn set(&mut self, key: &str, value: impl Serialize) -> &mut Self {
        let v = serde_json::to_value(value).unwrap_or(Value::Null);
        self.fields.insert(key.to_string(), v);
        self
    }

    /// The value of a figure.
    pub fn get(&self, key: &str) -> Option<&Value> {
        self.fields.get(key)
    }

    /// The report as pretty JSON text.
    pub fn to_json(&self) -> String {
        let mut s = serde_json::to_string_pretty(&self.fields).unwrap_or_else(|_| "{}".into());
        s.push('\n');
        s
    }

    /// Writes the report to `path` whole or not at all.
    pub fn write(&self, path: &Path) -> Result<()> {
        crate::io::write_atomic(path, self.to_json().as_bytes())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_keep_their_order() {
        let mut r = Report::new("curve-fit-arcs");
        r.set("input_moves", 10).set("largest_deviation_mm", 0.004).set("bad", f64::NAN);
        let text = r.to_json();
        let a = text.find("input_moves").unwrap();
        let b = text.find("largest_deviation_mm").unwrap();
        assert!(text.find("filter").unwrap() < a && a < b);
        assert!(text.contains("\"bad\": null"));
    }
}
