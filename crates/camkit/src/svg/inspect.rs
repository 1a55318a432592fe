//! Reading back what a plot shows, for tests: the legend entries, the names of the drawn marks
//! and the colour bars' ranges, from the SVG text with a small well-formedness check (tags
//! balanced, attributes quoted). Enough for the documents [`super::Plot`] writes; no general XML.

use std::collections::BTreeSet;

/// What an SVG document shows.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Seen {
    /// Legend entries in order.
    pub legend: Vec<String>,
    /// Names of the drawn marks (outside the legend).
    pub drawn: BTreeSet<String>,
    /// Colour bars: low end, high end, label.
    pub bars: Vec<(f64, f64, String)>,
    /// Elements of height maps and value-coloured paths (`class="raster"` or `"heat"` groups).
    pub coloured: usize,
}

/// The elements' attributes of `svg`, checked for balanced tags; an error names the offset.
pub fn inspect(svg: &str) -> Result<Seen, String> {
    let mut seen = Seen::default();
    let mut open: Vec<&str> = Vec::new();
    let mut in_legend = 0usize;
    let mut rest = svg;
    let mut offset = 0;
    while let Some(lt) = rest.find('<') {
        let gt = rest[lt..].find('>').ok_or(format!("tag at byte {} is not closed", offset + lt))? + lt;
        let tag = &rest[lt + 1..gt];
        offset += gt + 1;
        rest = &rest[gt + 1..];
        if let Some(name) = tag.strip_prefix('/') {
            match open.pop() {
                Some(o) if o == name.trim() => {}
                o => return Err(format!("`</{name}>` at byte {offset} closes `{o:?}`")),
            }
            if name.trim() == "g" && in_legend > open.len() {
                in_legend = 0;
            }
            continue;
        }
        let self_closing = tag.ends_with('/');
        let tag = tag.trim_end_matches('/');
        let name = tag.split_whitespace().next().unwrap_or("");
        let attr = |key: &str| attribute(tag, key);
        match attr("class").as_deref() {
            Some("legend-entry") => {
                seen.legend.push(attr("data-series").unwrap_or_default());
                in_legend = open.len() + 1;
            }
            Some("colour-bar") => {
                let num = |k: &str| attr(k).and_then(|v| v.parse::<f64>().ok()).unwrap_or(f64::NAN);
                seen.bars.push((num("data-min"), num("data-max"), attr("data-label").unwrap_or_default()));
            }
            Some("raster" | "heat") => seen.coloured += 1,
            _ => {
                if in_legend == 0
                    && let Some(series) = attr("data-series")
                {
                    seen.drawn.insert(series);
                }
            }
        }
        if !self_closing {
            open.push(name);
        }
    }
    match open.last() {
        Some(o) => Err(format!("`<{o}>` is not closed")),
        None => Ok(seen),
    }
}

/// The value of attribute `key` in a tag's text, unescaped.
fn attribute(tag: &str, key: &str) -> Option<String> {
    let pat = format!(" {key}=\"");
    let at = tag.find(&pat)? + pat.len();
    let end = tag[at..].find('"')? + at;
    Some(tag[at..end].replace("&lt;", "<").replace("&gt;", ">").replace("&quot;", "\"").replace("&amp;", "&"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unbalanced_tags_are_refused() {
        assert!(inspect("<svg><g></svg>").is_err());
        assert!(inspect("<svg><g/></svg>").is_ok());
    }
}
