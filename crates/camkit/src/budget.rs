//! The memory a run will hold, estimated from its inputs before any work starts, and the bound
//! it is held to (`--max-memory`, MB). A run past it is refused as bad input naming the option
//! that drives it and the estimate, instead of aborting on an allocation or running for days
//! (the same rule as rough-sim's budget, for the filters whose size follows from lengths and
//! spacings: passes, samples, points).

use crate::error::{Error, Result};
use std::cmp::Ordering;

/// Default `--max-memory` (MB): 2 GiB.
pub const DEFAULT_MEMORY_MB: u64 = 2 << 30 >> 20;

/// Bytes of one toolpath row held in memory (its fields; the tag and extra columns are empty
/// for rows a filter makes).
pub const ROW_BYTES: f64 = std::mem::size_of::<crate::table::Row>() as f64;

/// Bytes of `mb` megabytes (`--max-memory`).
pub fn bytes_of(mb: u64) -> f64 {
    mb as f64 * (1u64 << 20) as f64
}

/// A need within its bound; an estimate that is not a number (from infinite inputs) is not.
pub fn fits(need: f64, bound: f64) -> bool {
    matches!(need.partial_cmp(&bound), Some(Ordering::Less | Ordering::Equal))
}

/// Refuses an estimated `need` (bytes) beyond `bound` (bytes): `what` names the run and the
/// options that drive it, `hint` what to change. An estimate that is not a number (from
/// infinite inputs) is refused too.
pub fn check_memory(need: f64, bound: f64, what: &str, hint: &str) -> Result<()> {
    if fits(need, bound) {
        return Ok(());
    }
    let need = if need.is_finite() {
        format!("an estimated {:.3e} MB", need / (1u64 << 20) as f64)
    } else {
        "unbounded memory".into()
    };
    Err(Error::input(format!(
        "{what} needs {need}, more than the bound of {:.0} MB (--max-memory): {hint} or raise --max-memory",
        bound / (1u64 << 20) as f64
    )))
}

/// Refuses an estimated `need` of work (counted in `unit`, e.g. "engagement samples") beyond
/// `bound` (`--max-work`), as [`check_memory`] does for memory.
pub fn check_work(need: f64, bound: f64, unit: &str, what: &str, hint: &str) -> Result<()> {
    if fits(need, bound) {
        return Ok(());
    }
    let need = if need.is_finite() { format!("an estimated {need:.3e} {unit}") } else { format!("unbounded {unit}") };
    Err(Error::input(format!(
        "{what} needs {need}, more than the bound of {bound:.3e} (--max-work): {hint} or raise --max-work"
    )))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn needs_past_the_bound_or_not_numbers_are_refused() {
        assert!(check_memory(1e6, bytes_of(1), "a", "b").is_ok());
        let e = check_memory(3e9, bytes_of(DEFAULT_MEMORY_MB), "a run (--step)", "coarsen --step").unwrap_err();
        assert!(e.to_string().contains("--max-memory") && e.to_string().contains("--step"), "{e}");
        assert!(check_memory(f64::NAN, 1e9, "a", "b").is_err());
        assert!(check_memory(f64::INFINITY, 1e9, "a", "b").is_err());
    }

    #[test]
    fn work_past_the_bound_or_not_a_number_is_refused() {
        assert!(check_work(1e5, 1e5, "samples", "a", "b").is_ok());
        let e = check_work(2e5, 1e5, "samples", "the plan (--sample)", "coarsen --sample").unwrap_err();
        assert!(e.to_string().contains("2.000e5 samples") && e.to_string().contains("--max-work"), "{e}");
        assert!(check_work(f64::NAN, 1e5, "samples", "a", "b").is_err());
    }
}
