//! The crate's layout: no source file under `src/` over 600 lines, so
//! that each stays one job a reader can hold.

use std::path::Path;

/// The most lines a file under `src/` may have.
const MOST_LINES: usize = 600;

/// Every `.rs` file under `dir`, with its line count.
fn line_counts(dir: &Path, out: &mut Vec<(String, usize)>) {
    let entries = std::fs::read_dir(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
    for entry in entries {
        let path = entry.expect("a directory entry").path();
        if path.is_dir() {
            line_counts(&path, out);
        } else if path.extension().is_some_and(|x| x == "rs") {
            let text = std::fs::read_to_string(&path)
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            out.push((path.display().to_string(), text.lines().count()));
        }
    }
}

/// Each file under `src/` has at most 600 lines, those of features off
/// by default included; the walk finds the solver's island, touch and
/// impact files, the window's and the path joints' among them.
#[test]
fn no_source_file_is_over_600_lines() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut counts = Vec::new();
    line_counts(&root, &mut counts);
    for name in [
        "island/mod.rs",
        "touch/group.rs",
        "impact.rs",
        "gui/render.rs",
        "avian/mod.rs",
    ] {
        assert!(
            counts.iter().any(|(path, _)| path.ends_with(name)),
            "{name} not found under src"
        );
    }
    let long: Vec<String> = counts
        .iter()
        .filter(|&&(_, lines)| lines > MOST_LINES)
        .map(|(path, lines)| format!("{path}: {lines} lines"))
        .collect();
    assert!(
        long.is_empty(),
        "over {MOST_LINES} lines: {}",
        long.join("; ")
    );
}
