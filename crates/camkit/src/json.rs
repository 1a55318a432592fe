//! Reading JSON documents with errors that name the file, line, column and the JSON path of the
//! bad field (`tool.json:3:14 (radius): invalid type: string "5", expected f64`).

use crate::error::{Error, Location, Result};
use crate::io::Input;
use serde::Serialize;
use serde::de::DeserializeOwned;
use serde_json::Value;

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

/// Parses a document (a JSON object) of type `T` from an input as [`from_input`] does, and checks
/// that it and every structure inside it was written as a JSON object: serde reads a structure
/// from an array too, by position (`[1, 2, 3]` as a frame's `xc, yc, za`), which silently takes
/// a misplaced list for a document. A document that is not an object is refused at its first
/// character (line:column); inside it, the shape is compared with `T` written back as JSON, and
/// an array where `T` has an object is refused naming its JSON path.
pub fn document<T: DeserializeOwned + Serialize>(input: &Input) -> Result<T> {
    let text = input.text()?;
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let at = text.len() - text.trim_start().len();
    if let Some(first) = text[at..].chars().next().filter(|&c| c != '{') {
        let line = text[..at].matches('\n').count() + 1;
        let column = text[..at].chars().rev().take_while(|&c| c != '\n').count() + 1;
        let found = match first {
            '[' => "an array",
            '"' => "a string",
            _ => "a value",
        };
        return Err(Error::input(format!("expected a JSON object, found {found}"))
            .at(Location::file(&input.name).line(line as u64).column(column as u64)));
    }
    let value: T = from_input(input)?;
    let found: Value = from_input(input)?;
    let shape = serde_json::to_value(&value).map_err(|e| Error::runtime(e.to_string()))?;
    if let Some(path) = array_for_object(&found, &shape, String::new()) {
        return Err(Error::input("expected a JSON object, found an array").at(Location::file(&input.name).field(path)));
    }
    Ok(value)
}

/// JSON path of the first array in `found` where `shape` has an object.
fn array_for_object(found: &Value, shape: &Value, path: String) -> Option<String> {
    match (found, shape) {
        (Value::Array(_), Value::Object(_)) => Some(path),
        (Value::Object(f), Value::Object(s)) => f.iter().find_map(|(k, v)| {
            let sub = if path.is_empty() { k.clone() } else { format!("{path}.{k}") };
            s.get(k).and_then(|sv| array_for_object(v, sv, sub))
        }),
        (Value::Array(f), Value::Array(s)) => {
            f.iter().zip(s).enumerate().find_map(|(i, (v, sv))| array_for_object(v, sv, format!("{path}[{i}]")))
        }
        _ => None,
    }
}

/// Parses a document as [`document`] does and checks its values with `check` (given the file's
/// name); a value error that names a JSON path of this file gets the line and column where that
/// value begins (the deepest part of the path the text has, for a missing field).
pub fn checked<T: DeserializeOwned + Serialize>(
    input: &Input,
    check: impl FnOnce(&T, &str) -> Result<()>,
) -> Result<T> {
    let value: T = document(input)?;
    check(&value, &input.name).map_err(|e| at_value(input, e))?;
    Ok(value)
}

/// `e` with the line and column of the value its JSON path names in `input`, when it is about a
/// field of that file and names no line yet.
pub fn at_value(input: &Input, mut e: Error) -> Error {
    if let Some(loc) = e.location.as_mut()
        && loc.file == input.name
        && loc.line.is_none()
        && let (Some(path), Ok(text)) = (&loc.field, input.text())
        && let Some((line, column)) = locate(text, path)
    {
        loc.line = Some(line);
        loc.column = Some(column);
    }
    e
}

/// One step of a JSON path: a key, or an index into an array.
#[derive(Debug, PartialEq)]
enum Step<'a> {
    Key(&'a str),
    Index(usize),
}

/// The steps of a path as errors name them: `chain[2].offset`, `surfaces[0].file`, `travel.x`.
fn steps(path: &str) -> Option<Vec<Step<'_>>> {
    let mut out = Vec::new();
    for part in path.split('.') {
        let (key, mut rest) = part.split_once('[').map_or((part, ""), |(k, r)| (k, r));
        if !key.is_empty() {
            out.push(Step::Key(key));
        }
        while !rest.is_empty() {
            let (n, after) = rest.split_once(']')?;
            out.push(Step::Index(n.parse().ok()?));
            rest = after.strip_prefix('[').unwrap_or(after);
        }
    }
    (!out.is_empty()).then_some(out)
}

/// 1-based line and column (in characters) where the value at `path` begins in the JSON `text`;
/// for a path the text lacks, where its deepest present part begins. `None` if the path cannot
/// be read or the text is no JSON.
pub fn locate(text: &str, path: &str) -> Option<(u64, u64)> {
    let steps = steps(path)?;
    let b = text.as_bytes();
    let mut at = skip_space(b, if text.starts_with('\u{feff}') { 3 } else { 0 });
    for step in &steps {
        let found = match (step, b.get(at)?) {
            (Step::Key(key), b'{') => member(b, at, key)?,
            (Step::Index(i), b'[') => element(b, at, *i)?,
            _ => None,
        };
        match found {
            Some(next) => at = next,
            None => break,
        }
    }
    let before = &text[..at];
    let line = before.matches('\n').count() as u64 + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) as u64 + 1;
    Some((line, column))
}

/// In the object at `at`, where the value of `key` begins (`Some(None)`: no such key).
fn member(b: &[u8], at: usize, key: &str) -> Option<Option<usize>> {
    let mut i = skip_space(b, at + 1);
    if b.get(i) == Some(&b'}') {
        return Some(None);
    }
    loop {
        let end = skip_string(b, i)?;
        let name: String = serde_json::from_slice(&b[i..end]).ok()?;
        i = skip_space(b, end);
        if b.get(i) != Some(&b':') {
            return None;
        }
        i = skip_space(b, i + 1);
        if name == key {
            return Some(Some(i));
        }
        i = skip_space(b, skip_value(b, i)?);
        match b.get(i)? {
            b',' => i = skip_space(b, i + 1),
            b'}' => return Some(None),
            _ => return None,
        }
    }
}

/// In the array at `at`, where element `index` begins (`Some(None)`: the array is shorter).
fn element(b: &[u8], at: usize, index: usize) -> Option<Option<usize>> {
    let mut i = skip_space(b, at + 1);
    if b.get(i) == Some(&b']') {
        return Some(None);
    }
    for _ in 0..index {
        i = skip_space(b, skip_value(b, i)?);
        match b.get(i)? {
            b',' => i = skip_space(b, i + 1),
            b']' => return Some(None),
            _ => return None,
        }
    }
    Some(Some(i))
}

fn skip_space(b: &[u8], mut i: usize) -> usize {
    while b.get(i).is_some_and(|c| c.is_ascii_whitespace()) {
        i += 1;
    }
    i
}

/// The index after the string starting at `i`.
fn skip_string(b: &[u8], i: usize) -> Option<usize> {
    if b.get(i) != Some(&b'"') {
        return None;
    }
    let mut j = i + 1;
    loop {
        match b.get(j)? {
            b'\\' => j += 2,
            b'"' => return Some(j + 1),
            _ => j += 1,
        }
    }
}

/// The index after the value starting at `i` (the text parsed before, so only its extent is
/// found: strings skipped whole, brackets counted).
fn skip_value(b: &[u8], i: usize) -> Option<usize> {
    match b.get(i)? {
        b'"' => skip_string(b, i),
        b'{' | b'[' => {
            let mut depth = 0usize;
            let mut j = i;
            loop {
                match b.get(j)? {
                    b'"' => {
                        j = skip_string(b, j)?;
                        continue;
                    }
                    b'{' | b'[' => depth += 1,
                    b'}' | b']' => {
                        depth -= 1;
                        if depth == 0 {
                            return Some(j + 1);
                        }
                    }
                    _ => {}
                }
                j += 1;
            }
        }
        _ => {
            let mut j = i;
            while b.get(j).is_some_and(|c| !matches!(c, b',' | b'}' | b']') && !c.is_ascii_whitespace()) {
                j += 1;
            }
            Some(j)
        }
    }
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

    #[derive(Debug, Deserialize, Serialize)]
    #[serde(deny_unknown_fields)]
    struct Frame {
        xc: f64,
        yc: f64,
        inner: Option<Inner>,
        list: Vec<Inner>,
    }

    #[derive(Debug, Deserialize, Serialize)]
    #[serde(deny_unknown_fields)]
    struct Inner {
        a: f64,
    }

    /// The span finder lands on the value a path names, or on the deepest part present.
    #[test]
    fn paths_are_located() {
        let text = "{\n  \"a\": {\"b\": [1, {\"c\": \"x]\\\"\"}, [2, 3]]},\n  \"é\": 1,\n  \"d\": 7e-1\n}";
        assert_eq!(locate(text, "a"), Some((2, 8)));
        assert_eq!(locate(text, "a.b[1].c"), Some((2, 24)));
        assert_eq!(locate(text, "a.b[2][1]"), Some((2, 37)));
        assert_eq!(locate(text, "d"), Some((4, 8)));
        // Missing: the deepest part present.
        assert_eq!(locate(text, "a.b[5]"), Some((2, 14)));
        assert_eq!(locate(text, "zz"), Some((1, 1)));
        assert_eq!(locate(text, "facet 3"), Some((1, 1)));
        assert_eq!(locate(text, "a[x]"), None);
        let input = Input { name: "d.json".into(), data: text.as_bytes().to_vec() };
        let e = at_value(&input, field_error("d.json", "d", "d must be below 0.5"));
        assert_eq!(e.to_string(), "d.json:4:8 (d): d must be below 0.5");
        let other = at_value(&input, field_error("e.json", "d", "x"));
        assert_eq!(other.to_string(), "e.json (d): x");
    }

    /// serde reads a structure from an array by position; a document refuses it, naming where.
    #[test]
    fn documents_are_objects() {
        let doc = |text: &str| document::<Frame>(&Input { name: "f.json".into(), data: text.as_bytes().to_vec() });
        assert!(doc(r#"{"xc": 1, "yc": 2, "inner": {"a": 3}, "list": [{"a": 1}]}"#).is_ok());
        assert_eq!(
            doc("\n  [1, 2, null, []]").unwrap_err().to_string(),
            "f.json:2:3: expected a JSON object, found an array"
        );
        assert_eq!(doc("\u{feff}3").unwrap_err().to_string(), "f.json:1:1: expected a JSON object, found a value");
        assert!(doc(" \n").unwrap_err().to_string().contains("empty input"));
        let e = doc(r#"{"xc": 1, "yc": 2, "inner": [3], "list": []}"#).unwrap_err();
        assert_eq!(e.to_string(), "f.json (inner): expected a JSON object, found an array");
        let e = doc(r#"{"xc": 1, "yc": 2, "inner": null, "list": [{"a": 1}, [2]]}"#).unwrap_err();
        assert_eq!(e.to_string(), "f.json (list[1]): expected a JSON object, found an array");
    }
}
