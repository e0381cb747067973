//! Plugin parameters given on the command line as `--set key=value`, the
//! value a TOML value or else a bare string (`--set sampling=cosine`).

use lumis_core::{doc, Error, Result};

/// The assignments as TOML lines, one per `key=value`.
pub fn parameter_text(assignments: &[String]) -> Result<String> {
    let mut text = String::new();
    for assignment in assignments {
        let (key, value) = assignment
            .split_once('=')
            .ok_or_else(|| Error::msg(format!("--set {assignment}: expected key=value")))?;
        let (key, value) = (key.trim(), value.trim());
        let line = format!("{key} = {value}\n");
        text += &if doc::parse(&line, "--set").is_ok() {
            line
        } else {
            format!("{key} = {value:?}\n")
        };
    }
    Ok(text)
}

/// A table of plugin parameters from `key=value` strings.
pub fn parameter_table(assignments: &[String]) -> Result<doc::Table> {
    doc::parse(&parameter_text(assignments)?, "--set")
}

/// `key=value` strings as `(key, TOML value)` pairs (a bare word becomes a
/// string), for `check-plugin --set`.
pub fn fixed_parameters(assignments: &[String]) -> Result<Vec<(String, String)>> {
    // Parsing them as one table checks the syntax and rejects repeated keys.
    parameter_table(assignments)?;
    Ok(assignments
        .iter()
        .filter_map(|a| a.split_once('='))
        .map(|(key, value)| {
            let value = value.trim();
            let toml = if doc::parse(&format!("v = {value}\n"), "--set").is_ok() {
                value.to_string()
            } else {
                format!("{value:?}")
            };
            (key.trim().to_string(), toml)
        })
        .collect())
}
