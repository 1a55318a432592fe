//! Numbers at the text boundary: strict parsing (no NaN, no infinity) and fast fixed-decimal
//! formatting whose rounding is exactly what a reader of the text gets back.

/// Why a text is not an acceptable number.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NumError {
    /// Not a decimal number at all.
    NotANumber,
    /// `nan`, `inf` or a value that overflows to infinity.
    NotFinite,
}

impl NumError {
    /// The message for `text`, in the form every filter uses.
    pub fn message(self, text: &str) -> String {
        match self {
            NumError::NotANumber if text.is_empty() => "expected a number, found an empty field".into(),
            NumError::NotANumber => format!("expected a number, found \"{text}\""),
            NumError::NotFinite => format!("expected a finite number, found \"{text}\""),
        }
    }
}

/// Parses a decimal number (`1`, `-2.5`, `.5`, `3.`, `1e-3`), rejecting NaN and infinities.
pub fn parse_finite(text: &str) -> Result<f64, NumError> {
    let t = text.trim();
    // Rust accepts "nan", "inf", "infinity" in any case: those are input errors here.
    match t.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(NumError::NotFinite),
        Err(_) => Err(NumError::NotANumber),
    }
}

/// Powers of ten that are exact in binary64.
const POW10: [f64; 16] = [1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15];

/// Largest number of decimals the fixed formatter supports.
pub const MAX_DECIMALS: u32 = 15;

/// Rounds half away from zero like `f64::round`, by integer conversion (SSE2) instead of the
/// software routine `f64::round` compiles to on baseline x86-64; for |x| < 2^52.
#[inline]
fn round_half_away(x: f64) -> f64 {
    if x >= 0.0 { (x + 0.5) as i64 as f64 } else { (x - 0.5) as i64 as f64 }
}

/// Where a unimodal `f` is largest on [a, b]: `iterations` golden sections (ties keep the lower
/// part), then the better of the last two points.
pub fn golden_arg(f: impl Fn(f64) -> f64, a: f64, b: f64, iterations: usize) -> f64 {
    let r = 0.5 * (5f64.sqrt() - 1.0);
    let (mut lo, mut hi) = (a, b);
    let (mut x1, mut x2) = (hi - r * (hi - lo), lo + r * (hi - lo));
    let (mut f1, mut f2) = (f(x1), f(x2));
    for _ in 0..iterations {
        if f1 < f2 {
            lo = x1;
            (x1, f1) = (x2, f2);
            x2 = lo + r * (hi - lo);
            f2 = f(x2);
        } else {
            hi = x2;
            (x2, f2) = (x1, f1);
            x1 = hi - r * (hi - lo);
            f1 = f(x1);
        }
    }
    if f1 >= f2 { x1 } else { x2 }
}

/// `v` rounded to `decimals` places: exactly the value a reader parses back from
/// [`push_fixed`]'s text (integer / 10^d is correctly rounded, as parsing is).
pub fn round_to(v: f64, decimals: u32) -> f64 {
    let p = POW10[decimals.min(MAX_DECIMALS) as usize];
    let x = v * p;
    if x.abs() < 4.0e15 { round_half_away(x) / p } else { v }
}

/// Appends `v` with `decimals` places; with `trim`, trailing zeros and a bare point are dropped
/// (`1.500` → `1.5`, `2.000` → `2`). Negative zero is written as `0`.
pub fn push_fixed(out: &mut Vec<u8>, v: f64, decimals: u32, trim: bool) {
    let d = decimals.min(MAX_DECIMALS);
    let p = POW10[d as usize];
    let x = v * p;
    // Too large for an exact integer (or not finite): let the standard formatter do it.
    if x.is_nan() || x.abs() >= 4.0e15 {
        out.extend_from_slice(format!("{v:.*}", d as usize).as_bytes());
        return;
    }
    let scaled = round_half_away(x);
    let neg = scaled < 0.0;
    let mut n = scaled.abs() as u64;
    if n == 0 {
        out.push(b'0');
        if !trim && d > 0 {
            out.push(b'.');
            out.extend(std::iter::repeat_n(b'0', d as usize));
        }
        return;
    }
    let mut digits = [0u8; 24];
    let mut len = 0;
    while n > 0 || len <= d as usize {
        digits[len] = b'0' + (n % 10) as u8;
        n /= 10;
        len += 1;
    }
    // digits[0..d] is the fraction (least significant first), the rest the integer part.
    let mut frac_start = 0;
    if trim {
        while frac_start < d as usize && digits[frac_start] == b'0' {
            frac_start += 1;
        }
    }
    if neg {
        out.push(b'-');
    }
    for i in (d as usize..len).rev() {
        out.push(digits[i]);
    }
    if frac_start < d as usize {
        out.push(b'.');
        for i in (frac_start..d as usize).rev() {
            out.push(digits[i]);
        }
    }
}

/// Appends the shortest text that reads back as exactly `v` (ryu).
pub fn push_shortest(out: &mut Vec<u8>, v: f64) {
    let mut buf = ryu::Buffer::new();
    let s = buf.format(v);
    // ryu writes integers as "3.0"; keep that (unambiguous as a float) but drop "-0.0".
    if v == 0.0 {
        out.extend_from_slice(b"0.0");
    } else {
        out.extend_from_slice(s.as_bytes());
    }
}

/// Number of digits after the decimal point in a number's text (`1.250` → 3, `7` → 0).
pub fn decimals_in(text: &str) -> u32 {
    let mantissa = text.split(['e', 'E']).next().unwrap_or("");
    mantissa.find('.').map_or(0, |dot| (mantissa.len() - dot - 1) as u32)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn fixed(v: f64, d: u32, trim: bool) -> String {
        let mut out = Vec::new();
        push_fixed(&mut out, v, d, trim);
        String::from_utf8(out).unwrap()
    }

    #[test]
    fn parse_rejects_non_finite() {
        assert_eq!(parse_finite("1.5"), Ok(1.5));
        assert_eq!(parse_finite(".5"), Ok(0.5));
        assert_eq!(parse_finite("3."), Ok(3.0));
        assert_eq!(parse_finite("1,2x"), Err(NumError::NotANumber));
        assert_eq!(parse_finite("NaN"), Err(NumError::NotFinite));
        assert_eq!(parse_finite("-inf"), Err(NumError::NotFinite));
        assert_eq!(parse_finite("1e999"), Err(NumError::NotFinite));
        assert_eq!(parse_finite(""), Err(NumError::NotANumber));
    }

    #[test]
    fn fixed_formatting() {
        assert_eq!(fixed(1.5, 3, false), "1.500");
        assert_eq!(fixed(1.5, 3, true), "1.5");
        assert_eq!(fixed(2.0, 3, true), "2");
        assert_eq!(fixed(-0.0004, 3, true), "0");
        assert_eq!(fixed(-0.0006, 3, true), "-0.001");
        assert_eq!(fixed(0.05, 4, false), "0.0500");
        assert_eq!(fixed(-12.34567, 2, false), "-12.35");
        assert_eq!(fixed(0.0, 2, false), "0.00");
        assert_eq!(fixed(123.0, 0, false), "123");
        assert_eq!(decimals_in("1.250"), 3);
        assert_eq!(decimals_in("-7"), 0);
        assert_eq!(decimals_in("1.5e-3"), 1);
    }

    proptest! {
        /// The written text parses back to exactly `round_to`'s value.
        #[test]
        fn fixed_reads_back_as_round_to(v in -1.0e6f64..1.0e6, d in 0u32..9) {
            let text = fixed(v, d, true);
            let back: f64 = text.parse().unwrap();
            prop_assert_eq!(back, round_to(v, d));
            prop_assert!((back - v).abs() <= 0.5 / POW10[d as usize] * (1.0 + 1e-9) + 1e-9);
        }

        #[test]
        fn shortest_round_trips(v in proptest::num::f64::NORMAL) {
            let mut out = Vec::new();
            push_shortest(&mut out, v);
            let back: f64 = std::str::from_utf8(&out).unwrap().parse().unwrap();
            prop_assert_eq!(back, v);
        }
    }
}
