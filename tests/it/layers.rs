//! The library's modules form layers that point one way: each module uses
//! only the modules below it (documentation links aside).

use std::path::{Path, PathBuf};

/// Bottom first. `gui` may use everything.
const LAYERS: &[&str] = &[
    "validate",
    "lane",
    "geometry",
    "reference",
    "solver",
    "dynamics",
    "plugin",
    "controls",
    "preset",
    "headless",
    "gui",
];

/// The source files of `module`: its file, or every file in its folder
/// and the folders below.
fn sources(module: &str) -> Vec<PathBuf> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let file = src.join(format!("{module}.rs"));
    if file.exists() {
        return vec![file];
    }
    let mut files = Vec::new();
    let mut folders = vec![src.join(module)];
    while let Some(folder) = folders.pop() {
        for entry in std::fs::read_dir(&folder).unwrap_or_else(|e| panic!("module {module}: {e}")) {
            let path = entry.unwrap().path();
            if path.is_dir() {
                folders.push(path);
            } else {
                files.push(path);
            }
        }
    }
    files
}

/// The `crate::…` modules a file names in its code (not in comments).
fn used_modules(path: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut used = Vec::new();
    for line in text.lines().filter(|l| !l.trim_start().starts_with("//")) {
        for (i, _) in line.match_indices("crate::") {
            let name: String = line[i + 7..]
                .chars()
                .take_while(|c| c.is_ascii_lowercase() || *c == '_')
                .collect();
            used.push(name);
        }
    }
    used
}

#[test]
fn no_module_uses_one_above_it() {
    for (level, module) in LAYERS.iter().enumerate() {
        for path in sources(module) {
            for used in used_modules(&path) {
                let Some(used_level) = LAYERS.iter().position(|m| *m == used) else {
                    continue; // a re-export at the crate root
                };
                assert!(
                    used_level <= level,
                    "{} ({module}) uses crate::{used}, a layer above it",
                    path.display()
                );
            }
        }
    }
}
