//! The ISO 10303-21 exchange structure (the text of a `.step` file): the DATA section's entity
//! instances as a map from `#id` to keyword and parameters, with the line each starts on, and
//! errors naming the file, line and column.
//!
//! Written here rather than taken from a crate: the STEP reader needs only the raw instances
//! (keyword, parameters, references), which this gives in 200 lines; `ruststep` and
//! `truck-stepio` bring whole generated AP schemas or a modelling kernel to get there.

use crate::error::{Error, Location, Result};
use std::collections::HashMap;

/// One parameter of an entity instance.
#[derive(Clone, Debug, PartialEq)]
pub enum Param {
    /// `#123`.
    Ref(usize),
    /// An integer or real.
    Num(f64),
    /// `'text'`.
    Str(String),
    /// `.ENUM.` (booleans are `.T.` / `.F.`).
    Enum(String),
    /// `( ... )`.
    List(Vec<Param>),
    /// A typed value, `LENGTH_MEASURE(1.E-06)`.
    Typed(String, Vec<Param>),
    /// `$` (unset) or `*` (derived).
    Unset,
}

/// An entity instance: one `(keyword, parameters)` part for a simple instance, several for a
/// complex one (`( BOUNDED_SURFACE() B_SPLINE_SURFACE(...) ... )`).
#[derive(Clone, Debug, PartialEq)]
pub struct Instance {
    /// Line of the file where the instance starts (1-based).
    pub line: u64,
    /// The keywords and their parameters.
    pub parts: Vec<(String, Vec<Param>)>,
}

impl Instance {
    /// The parameters of the part named `keyword`, if the instance has one.
    pub fn part(&self, keyword: &str) -> Option<&[Param]> {
        self.parts.iter().find(|(k, _)| k == keyword).map(|(_, p)| p.as_slice())
    }

    /// The instance's name: the keyword of a simple instance, the keywords joined for a complex
    /// one.
    pub fn keyword(&self) -> String {
        self.parts.iter().map(|(k, _)| k.as_str()).collect::<Vec<_>>().join("+")
    }
}

/// The DATA section of an exchange structure.
#[derive(Clone, Debug, Default)]
pub struct Exchange {
    /// Instances by id.
    pub instances: HashMap<usize, Instance>,
}

/// A cursor over the text with its line and column.
struct Cursor<'a> {
    text: &'a [u8],
    pos: usize,
    line: u64,
    line_start: usize,
    file: &'a str,
}

impl Cursor<'_> {
    fn error(&self, message: impl Into<String>) -> Error {
        let column = (self.pos - self.line_start) as u64 + 1;
        Error::input(message).at(Location::file(self.file).line(self.line).column(column))
    }

    fn peek(&self) -> Option<u8> {
        self.text.get(self.pos).copied()
    }

    fn bump(&mut self) {
        if self.peek() == Some(b'\n') {
            self.line += 1;
            self.line_start = self.pos + 1;
        }
        self.pos += 1;
    }

    /// Skips white space and `/* comments */`.
    fn skip(&mut self) -> Result<()> {
        loop {
            match self.peek() {
                Some(c) if c.is_ascii_whitespace() => self.bump(),
                Some(b'/') if self.text.get(self.pos + 1) == Some(&b'*') => {
                    while !(self.peek() == Some(b'*') && self.text.get(self.pos + 1) == Some(&b'/')) {
                        if self.peek().is_none() {
                            return Err(self.error("unterminated comment"));
                        }
                        self.bump();
                    }
                    self.bump();
                    self.bump();
                }
                _ => return Ok(()),
            }
        }
    }

    fn expect(&mut self, c: u8) -> Result<()> {
        self.skip()?;
        if self.peek() != Some(c) {
            let found = self.peek().map_or("the end of the file".into(), |f| format!("{:?}", f as char));
            return Err(self.error(format!("expected {:?}, found {found}", c as char)));
        }
        self.bump();
        Ok(())
    }

    /// A run of bytes that `ok` accepts.
    fn take(&mut self, ok: impl Fn(u8) -> bool) -> &str {
        let start = self.pos;
        while self.peek().is_some_and(&ok) {
            self.bump();
        }
        std::str::from_utf8(&self.text[start..self.pos]).unwrap_or("")
    }

    fn keyword(&mut self) -> Result<String> {
        self.skip()?;
        let k = self.take(|c| c.is_ascii_alphanumeric() || c == b'_' || c == b'!').to_ascii_uppercase();
        if k.is_empty() { Err(self.error("expected a keyword")) } else { Ok(k) }
    }

    /// `( param, ... )`.
    fn list(&mut self) -> Result<Vec<Param>> {
        self.expect(b'(')?;
        let mut out = Vec::new();
        self.skip()?;
        if self.peek() == Some(b')') {
            self.bump();
            return Ok(out);
        }
        loop {
            out.push(self.param()?);
            self.skip()?;
            match self.peek() {
                Some(b',') => self.bump(),
                Some(b')') => {
                    self.bump();
                    return Ok(out);
                }
                _ => return Err(self.error("expected ',' or ')' in a parameter list")),
            }
        }
    }

    fn param(&mut self) -> Result<Param> {
        self.skip()?;
        match self.peek() {
            Some(b'#') => {
                self.bump();
                let digits = self.take(|c| c.is_ascii_digit());
                digits.parse().map(Param::Ref).map_err(|_| self.error("expected an instance number after '#'"))
            }
            Some(b'\'') => {
                self.bump();
                let mut s = Vec::new();
                loop {
                    match self.peek() {
                        None => return Err(self.error("unterminated string")),
                        Some(b'\'') if self.text.get(self.pos + 1) == Some(&b'\'') => {
                            s.push(b'\'');
                            self.bump();
                            self.bump();
                        }
                        Some(b'\'') => {
                            self.bump();
                            return Ok(Param::Str(String::from_utf8_lossy(&s).into_owned()));
                        }
                        Some(c) => {
                            s.push(c);
                            self.bump();
                        }
                    }
                }
            }
            Some(b'.') => {
                self.bump();
                let e = self.take(|c| c.is_ascii_alphanumeric() || c == b'_').to_ascii_uppercase();
                self.expect(b'.')?;
                Ok(Param::Enum(e))
            }
            Some(b'$' | b'*') => {
                self.bump();
                Ok(Param::Unset)
            }
            Some(b'(') => self.list().map(Param::List),
            Some(b'"') => {
                // Binary: hex digits in quotes, never geometry.
                self.bump();
                self.take(|c| c != b'"');
                self.expect(b'"')?;
                Ok(Param::Unset)
            }
            Some(c) if c.is_ascii_digit() || c == b'-' || c == b'+' => {
                let (line, col) = (self.line, self.pos);
                let t = self.take(|c| c.is_ascii_digit() || matches!(c, b'-' | b'+' | b'.' | b'E' | b'e'));
                let t = t.to_string();
                // Part 21 allows "1." (no digits after the point): Rust's parser does too.
                t.parse::<f64>().ok().filter(|v| v.is_finite()).map(Param::Num).ok_or_else(|| {
                    Error::input(format!("{t:?} is not a number"))
                        .at(Location::file(self.file).line(line).column((col - self.line_start) as u64 + 1))
                })
            }
            Some(c) if c.is_ascii_alphabetic() => {
                let k = self.keyword()?;
                Ok(Param::Typed(k, self.list()?))
            }
            _ => Err(self.error("expected a parameter")),
        }
    }
}

impl Exchange {
    /// Reads the text of a STEP file; `file` names it in errors.
    pub fn parse(text: &str, file: &str) -> Result<Exchange> {
        let body = text.trim_start_matches('\u{feff}').trim_start();
        if !body.starts_with("ISO-10303-21;") {
            return Err(
                Error::input("not a STEP file: it does not start with ISO-10303-21;").at(Location::file(file).line(1))
            );
        }
        let Some(data) = find_section(text) else {
            return Err(Error::input("not a STEP file: no DATA; section").at(Location::file(file)));
        };
        let line = text[..data].matches('\n').count() as u64 + 1;
        let line_start = text[..data].rfind('\n').map_or(0, |i| i + 1);
        let mut c = Cursor { text: text.as_bytes(), pos: data, line, line_start, file };
        let mut ex = Exchange::default();
        loop {
            c.skip()?;
            match c.peek() {
                None => return Err(c.error("the DATA section has no ENDSEC;")),
                Some(b'#') => {
                    let line = c.line;
                    let Param::Ref(id) = c.param()? else { unreachable!("'#' starts a reference") };
                    c.expect(b'=')?;
                    c.skip()?;
                    let parts = if c.peek() == Some(b'(') {
                        c.bump();
                        let mut parts = Vec::new();
                        loop {
                            c.skip()?;
                            if c.peek() == Some(b')') {
                                c.bump();
                                break;
                            }
                            let k = c.keyword()?;
                            parts.push((k, c.list()?));
                        }
                        parts
                    } else {
                        let k = c.keyword()?;
                        vec![(k, c.list()?)]
                    };
                    c.expect(b';')?;
                    if ex.instances.insert(id, Instance { line, parts }).is_some() {
                        return Err(Error::input(format!("instance #{id} is defined twice"))
                            .at(Location::file(file).line(line)));
                    }
                }
                Some(_) => {
                    let k = c.keyword()?;
                    if k == "ENDSEC" {
                        c.expect(b';')?;
                        return Ok(ex);
                    }
                    return Err(c.error(format!("expected an instance '#n = ...' or ENDSEC, found {k}")));
                }
            }
        }
    }
}

/// Byte offset just after the `DATA;` (or `DATA(...);`) keyword, outside strings.
fn find_section(text: &str) -> Option<usize> {
    let b = text.as_bytes();
    let mut in_string = false;
    let mut i = 0;
    while i < b.len() {
        match b[i] {
            b'\'' => in_string = !in_string,
            b'D' if !in_string && text[i..].starts_with("DATA") && (i == 0 || !b[i - 1].is_ascii_alphanumeric()) => {
                let rest = text[i + 4..].trim_start();
                if rest.starts_with(';') || rest.starts_with('(') {
                    return Some(i + 4 + text[i + 4..].find(';')? + 1);
                }
            }
            _ => {}
        }
        i += 1;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEAD: &str = "ISO-10303-21;\nHEADER;\nFILE_NAME('a;DATA;b','',(''),(''),'','','');\nENDSEC;\nDATA;\n";

    #[test]
    fn reads_simple_and_complex_instances() {
        let text = format!(
            "{HEAD}#1 = CARTESIAN_POINT('it''s',(1.,-2.5E1,3));\n/* note */ #2=( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.) );\n#3 = X(#1,$,(#1,#2),LENGTH_MEASURE(1.E-06));\nENDSEC;\nEND-ISO-10303-21;\n"
        );
        let ex = Exchange::parse(&text, "t.step").unwrap();
        let p = &ex.instances[&1];
        assert_eq!(p.line, 6);
        assert_eq!(
            p.parts[0].1,
            vec![Param::Str("it's".into()), Param::List(vec![Param::Num(1.0), Param::Num(-25.0), Param::Num(3.0)])]
        );
        let u = &ex.instances[&2];
        assert_eq!(u.keyword(), "LENGTH_UNIT+NAMED_UNIT+SI_UNIT");
        assert_eq!(u.part("SI_UNIT").unwrap(), &[Param::Enum("MILLI".into()), Param::Enum("METRE".into())]);
        assert_eq!(ex.instances[&3].parts[0].1[3], Param::Typed("LENGTH_MEASURE".into(), vec![Param::Num(1e-6)]));
    }

    #[test]
    fn names_line_and_column_of_bad_text() {
        let e = Exchange::parse("solid x\nfacet normal 0 0 1\n", "a.stp").unwrap_err();
        assert_eq!(e.to_string(), "a.stp:1: not a STEP file: it does not start with ISO-10303-21;");
        let e =
            Exchange::parse(&format!("{HEAD}#1 = CARTESIAN_POINT('',(1.,2x,3.));\nENDSEC;\n"), "a.stp").unwrap_err();
        assert!(e.to_string().starts_with("a.stp:6:30: expected ',' or ')'"), "{e}");
        let e = Exchange::parse(&format!("{HEAD}#1 = A(1.);\n#1 = B(2.);\nENDSEC;\n"), "a.stp").unwrap_err();
        assert_eq!(e.to_string(), "a.stp:7: instance #1 is defined twice");
        assert_eq!(Exchange::parse(&format!("{HEAD}#1 = A(1.);\n"), "a.stp").unwrap_err().exit_status(), 2);
    }
}
