//! The book's generated pages match the code they describe.

use std::path::Path;
use std::process::Command;

use lumis_cli::PLUGIN_MARKDOWN_COMMAND;

/// `docs/src/plugins.md` is what `lumis plugins --markdown` prints for the
/// built-in plugins (no library from `LUMIS_PLUGIN_PATH` joins them).
#[test]
fn plugin_reference_is_current() {
    let output = Command::new(env!("CARGO_BIN_EXE_lumis"))
        .args(["plugins", "--markdown"])
        .env_remove("LUMIS_PLUGIN_PATH")
        .output()
        .expect("lumis runs");
    assert!(
        output.status.success(),
        "lumis plugins --markdown failed: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    let generated = String::from_utf8(output.stdout).unwrap();
    let page = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/src/plugins.md");
    let committed = std::fs::read_to_string(&page).unwrap_or_default();
    if committed != generated {
        let line = committed
            .lines()
            .zip(generated.lines())
            .position(|(a, b)| a != b)
            .unwrap_or_else(|| committed.lines().count().min(generated.lines().count()));
        panic!(
            "docs/src/plugins.md differs from the plugins' declarations (first at line {}).\n\
             Regenerate it from the repository root, with LUMIS_PLUGIN_PATH unset:\n\n    \
             {PLUGIN_MARKDOWN_COMMAND}\n",
            line + 1
        );
    }
}
