//! The environment variables the program reads, checked in one place: every `DIFFBVP_*`
//! variable against its range ([`check_diffbvp_variables`]: a value out of range, or a name
//! the program does not know, is refused with the name and the range, never silently replaced
//! by a default), and `RAYON_NUM_THREADS`, the size of the thread pool, clamped to a number a
//! machine can run ([`thread_count`]).

use crate::report::output_files::{FIFO_WAIT_RANGE, FIFO_WAIT_VARIABLE};

/// A numeric `DIFFBVP_*` variable: its name, range and meaning.
#[derive(Debug, Clone, Copy)]
pub(crate) struct NumericVariable {
    /// The name (`DIFFBVP_FIFO_WAIT_S`).
    pub name: &'static str,
    /// The accepted values, inclusive.
    pub range: [f64; 2],
    /// The unit and meaning, for messages.
    pub meaning: &'static str,
}

/// Every `DIFFBVP_*` variable the program reads.
pub(crate) const DIFFBVP_VARIABLES: [NumericVariable; 1] = [NumericVariable {
    name: FIFO_WAIT_VARIABLE,
    range: FIFO_WAIT_RANGE,
    meaning: "seconds a write into a FIFO waits for a reader (default 10)",
}];

/// The value of `var` from the text `value`: a finite number within its range, else an error
/// naming the variable, the value and the range.
pub(crate) fn parse_numeric(var: &NumericVariable, value: &str) -> Result<f64, String> {
    let [lo, hi] = var.range;
    match value.trim().parse::<f64>() {
        Ok(x) if x.is_finite() && (lo..=hi).contains(&x) => Ok(x),
        _ => Err(format!(
            "environment variable {}={value:?} is not a number in [{lo}, {hi}] ({}); set it \
             within the range or unset it (`unset {}`)",
            var.name, var.meaning, var.name
        )),
    }
}

/// Checks every `DIFFBVP_*` variable of `vars` (name, value pairs, as
/// [`std::env::vars_os`] gives them): each must be one the program reads
/// (`DIFFBVP_VARIABLES`) with a value in its range.
pub fn check_diffbvp_variables<I>(vars: I) -> Result<(), String>
where
    I: IntoIterator<Item = (std::ffi::OsString, std::ffi::OsString)>,
{
    for (name, value) in vars {
        let Some(name) = name.to_str().filter(|n| n.starts_with("DIFFBVP_")) else {
            continue;
        };
        let Some(var) = DIFFBVP_VARIABLES.iter().find(|v| v.name == name) else {
            let known: Vec<&str> = DIFFBVP_VARIABLES.iter().map(|v| v.name).collect();
            return Err(format!(
                "environment variable {name} is not one this program reads (it reads {}); \
                 a misspelt name would be ignored, so it is refused: correct or unset it",
                known.join(", ")
            ));
        };
        let value = value.to_string_lossy();
        parse_numeric(var, &value)?;
    }
    Ok(())
}

/// The most threads per core the pool is given from `RAYON_NUM_THREADS`: more only add
/// switching and memory (each thread has its own stack), and a huge count makes thread
/// creation itself the bottleneck or exhausts memory.
pub(crate) const MAX_THREADS_PER_CORE: usize = 4;

/// The size of the thread pool from the value of `RAYON_NUM_THREADS` (`None`: unset) on a
/// machine of `cores` cores, and a warning where the value was not used as given: a whole
/// number from 1 to `MAX_THREADS_PER_CORE` × `cores` is used as it is; a larger one is
/// clamped to that; `0`, unset or an empty value mean one thread per core; anything else is
/// ignored with a warning (one thread per core).
pub fn thread_count(value: Option<&str>, cores: usize) -> (usize, Option<String>) {
    let cores = cores.max(1);
    let max = MAX_THREADS_PER_CORE * cores;
    let Some(v) = value.map(str::trim).filter(|v| !v.is_empty()) else {
        return (cores, None);
    };
    match v.parse::<u64>() {
        Ok(0) => (cores, None),
        Ok(n) if n <= max as u64 => (n as usize, None),
        Ok(n) => (
            max,
            Some(format!(
                "RAYON_NUM_THREADS={n} is more than {MAX_THREADS_PER_CORE} threads per core \
                 ({cores} cores here): using {max} threads"
            )),
        ),
        Err(_) => (
            cores,
            Some(format!(
                "RAYON_NUM_THREADS={v:?} is not a whole number of threads: using one per core \
                 ({cores}); set it to a number from 1 to {max} or unset it"
            )),
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::ffi::OsString;

    fn vars(pairs: &[(&str, &str)]) -> Vec<(OsString, OsString)> {
        pairs
            .iter()
            .map(|(a, b)| (OsString::from(a), OsString::from(b)))
            .collect()
    }

    #[test]
    fn diffbvp_variables_are_checked_by_name_and_range() {
        assert!(check_diffbvp_variables(vars(&[("DIFFBVP_FIFO_WAIT_S", "60")])).is_ok());
        assert!(check_diffbvp_variables(vars(&[("PATH", "/bin")])).is_ok());
        for bad in ["abc", "0", "-1", "1e10", "nan", "inf", ""] {
            let e = check_diffbvp_variables(vars(&[("DIFFBVP_FIFO_WAIT_S", bad)])).unwrap_err();
            assert!(
                e.contains("DIFFBVP_FIFO_WAIT_S") && e.contains("[0.1, 3600]"),
                "{bad}: {e}"
            );
        }
        let e = check_diffbvp_variables(vars(&[("DIFFBVP_FIFO_WAIT", "60")])).unwrap_err();
        assert!(e.contains("DIFFBVP_FIFO_WAIT_S"), "{e}");
    }

    #[test]
    fn thread_counts_are_clamped() {
        assert_eq!(thread_count(None, 2), (2, None));
        assert_eq!(thread_count(Some("0"), 2), (2, None));
        assert_eq!(thread_count(Some("3"), 2), (3, None));
        assert_eq!(thread_count(Some("8"), 2), (8, None));
        let (n, w) = thread_count(Some("100000"), 2);
        assert_eq!(n, 8);
        assert!(w.unwrap().contains("using 8 threads"));
        let (n, w) = thread_count(Some("abc"), 2);
        assert_eq!(n, 2);
        assert!(w.unwrap().contains("\"abc\""));
        let (n, _) = thread_count(Some("-3"), 2);
        assert_eq!(n, 2);
    }
}
