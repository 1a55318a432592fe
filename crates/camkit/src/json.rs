//! Reading JSON documents with errors that name the file, line, column and the JSON path of the
//! bad field (`tool.json:3:14 (radius): invalid type: string "5", expected f64`).

use crate::error::{Error, Location, Result};
use crate::io::Input;
use serde::de::DeserializeOwned;

/// Parses a JSON document of type `T` from an input.
pub fn from_input<T: DeserializeOwned>(input: &Input) -> Result<T> {
    let text = input.text()?;
    // A byte order mark some editors put first is not part of the document.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    if text.trim().is_empty() {
        return Err(Error::input("empty input: expected a JSON document").at(Location::file(&input.name)));
    }
    let mut de = serde_json::Deserializer::from_str(text);
    let value: T = serde_path_to_error::deserialize(&mut de).map_err(|e| {
        let path = e.path().to_string();
        let inner = e.into_inner();
        let message = inner.to_string();
        // serde_json appends " at line L column C"; the location says it already.
        let message = message.find(" at line ").map_or(message.clone(), |cut| message[..cut].to_string());
        let mut loc = Location::file(&input.name).line(inner.line() as u64).column(inner.column() as u64);
        if path != "." {
            loc = loc.field(path);
        }
        Error::input(message).at(loc)
    })?;
    de.end().map_err(|e| {
        Error::input("trailing characters after the JSON document")
            .at(Location::file(&input.name).line(e.line() as u64).column(e.column() as u64))
    })?;
    Ok(value)
}

/// Reads and parses a JSON document from a path (or `-`).
pub fn read<T: DeserializeOwned>(path: &str) -> Result<T> {
    from_input(&Input::open(path)?)
}

/// An input error about a field of a document that parsed but does not make sense.
pub fn field_error(file: &str, path: &str, message: impl Into<String>) -> Error {
    Error::input(message).at(Location::file(file).field(path))
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde::Deserialize;

    #[derive(Debug, Deserialize)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    struct Doc {
        items: Vec<Item>,
    }

    #[derive(Debug, Deserialize)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    struct Item {
        radius: f64,
    }

    fn parse(text: &str) -> Result<Doc> {
        from_input(&Input { name: "d.json".into(), data: text.as_bytes().to_vec() })
    }

    #[test]
    fn errors_name_the_json_path() {
        let e = parse("{\"items\": [{\"radius\": 1}, {\"radius\": \"5\"}]}").unwrap_err();
        assert_eq!(e.to_string(), "d.json:1:40 (items[1].radius): invalid type: string \"5\", expected f64");
        let e = parse("{\"items\": [{\"radus\": 1}]}").unwrap_err();
        assert_eq!(e.to_string(), "d.json:1:19 (items[0].radus): unknown field `radus`, expected `radius`");
        let e = parse("{\"items\": [{}]}").unwrap_err();
        assert!(e.to_string().contains("(items[0]): missing field `radius`"), "{e}");
        assert!(parse("").unwrap_err().to_string().contains("empty input"));
        assert_eq!(parse("{\"items\": []} x").unwrap_err().exit_status(), 2);
    }
}
