//! The README's version table matches Cargo.toml.

#[test]
fn readme_versions_match_cargo_toml() {
    let manifest = include_str!("../../Cargo.toml");
    let readme = include_str!("../../README.md");
    let pinned = |name: &str| {
        let line = manifest
            .lines()
            .find(|l| l.starts_with(&format!("{name} = ")))
            .unwrap_or_else(|| panic!("{name} in Cargo.toml"));
        let start = line.find("\"=").expect("pinned version") + 2;
        line[start..].split('"').next().unwrap().to_owned()
    };
    let row = format!(
        "| 0.1 | {} | {} | 1.95 |",
        pinned("bevy"),
        pinned("bevy_egui")
    );
    assert!(readme.contains(&row), "README lacks {row}");
}
