//! What the cases of every plugin kind's suite share: how a case ended,
//! the word its table row shows, the closing count, and how a plugin the
//! sweep could not make, or one that panicked, counts.

use std::fmt::Write;

use lumis_core::{Error, Registry};

/// How a case ended.
pub trait Outcome {
    /// Whether the suite's statistical test passed (read only for a case
    /// that was made and could be decided).
    fn test_passed(&self) -> bool;
    /// Why the plugin refused the case's parameters (its factory's error).
    fn refused(&self) -> Option<&str>;
    /// Why a test could not decide, as the kit established it.
    fn not_testable(&self) -> Option<&str>;
    /// Everything that failed besides the suite's statistical test.
    fn problems(&self) -> &[String];

    /// Whether nothing failed: a refused case passes (it was not tested);
    /// otherwise no problem, and the test passed or could not decide.
    fn passed(&self) -> bool {
        self.refused().is_some()
            || self.problems().is_empty() && (self.not_testable().is_some() || self.test_passed())
    }
}

/// [`Outcome`]'s accessors for a case result whose fields `refused`,
/// `not_testable` and `problems` hold what the names say.
macro_rules! case_fields {
    () => {
        fn refused(&self) -> Option<&str> {
            self.refused.as_deref()
        }
        fn not_testable(&self) -> Option<&str> {
            self.not_testable.as_deref()
        }
        fn problems(&self) -> &[String] {
            &self.problems
        }
    };
}
pub(crate) use case_fields;

/// The result column of a case's row.
pub fn verdict(case: &impl Outcome) -> &'static str {
    match (case.refused(), case.not_testable(), case.passed()) {
        (Some(_), ..) => "refused",
        (None, _, false) => "FAILED",
        (None, Some(_), true) => "not testable",
        (None, None, true) => "ok",
    }
}

/// The lines under a case's row: why the plugin refused it (and nothing
/// more), why a test could not decide, `statistic` (the suite's own line
/// for a failed statistical test), and every problem.
pub fn write_notes(out: &mut String, case: &impl Outcome, statistic: Option<String>) {
    if let Some(why) = case.refused() {
        let _ = writeln!(
            out,
            "    not tested: the plugin refuses these parameters: {why}"
        );
        return;
    }
    if let Some(why) = case.not_testable() {
        let _ = writeln!(out, "    not testable: {why}");
    }
    for line in statistic.iter().chain(case.problems()) {
        let _ = writeln!(out, "    {line}");
    }
}

/// The table's last line: how many cases passed, failed, could not be
/// tested, and were refused.
pub fn summary<T: Outcome>(results: &[T]) -> String {
    let count = |f: &dyn Fn(&T) -> bool| results.iter().filter(|r| f(r)).count();
    let failed = count(&|r| !r.passed());
    let refused = count(&|r| r.refused().is_some());
    let untestable = count(&|r| r.refused().is_none() && r.not_testable().is_some() && r.passed());
    format!(
        "{} passed, {failed} failed, {untestable} not testable, {refused} refused by the plugin",
        results.len() - failed - refused - untestable
    )
}

/// A plugin the sweep could not make, named `owner` in the registry's
/// record of faults: `Ok(why)` if its factory refused the parameters (a
/// setting it declares invalid, left untested), `Err(why)` if it panicked
/// (a failure).
pub fn unmade(registry: &Registry, owner: &str, error: &Error) -> Result<String, String> {
    if registry.faults().faults_of(owner).is_empty() {
        Ok(error.to_string())
    } else {
        Err(error.to_string())
    }
}

/// Adds to `problems` every panic recorded against `owner` that it does not
/// mention yet. A loaded plugin that panicked answered with neutral values
/// (see `lumis_api::guard`), so the panic is what fails its case.
pub fn add_faults(registry: &Registry, owner: &str, problems: &mut Vec<String>) {
    for fault in registry.faults().faults_of(owner) {
        if !problems.iter().any(|p| p.contains(&fault.message)) {
            problems.push(fault.to_string());
        }
    }
}
