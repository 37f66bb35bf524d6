//! The library's modules form layers that point one way, and no files
//! import each other in a circle.
//!
//! Every source file is read as Rust: comments and string literals are
//! dropped, `#[cfg(test)]` inline modules are left out, every `use` tree
//! (`crate::`, `super::`, `self::`, a child module's name, nested
//! `{…}` groups, `as` renames) is expanded, and every `crate::…`,
//! `super::…` and `self::…` path written in code is read too. Each path is
//! followed through the modules it names and through re-exports (a
//! `use` in the module that holds the item) to the file that defines the
//! item. The files and those edges form a graph (a module's edges to its
//! own children left out: it holds them); the test asserts that the graph
//! has no cycle and that no edge points from a layer to one above it.

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::{Path, PathBuf};

/// The crate's top-level modules, bottom first. A module uses only the
/// ones at its level or below.
const LAYERS: &[&str] = &[
    "validate",
    "lane",
    "geometry",
    "reference",
    "solver",
    "dynamics",
    "plugin",
    "carrier",
    "avian",
    "avian3d",
    "controls",
    "preset",
    "headless",
    "ghost",
    "debug_render",
    "gui",
];

/// A module path from the crate root: `[]` is `lib.rs`, `["plugin", "step"]`
/// is `plugin/step.rs` (or `plugin/step/mod.rs`).
type Module = Vec<String>;

/// The crate's source as a graph of modules.
struct Crate {
    /// Each module's file and its code without comments, strings and test
    /// modules.
    files: BTreeMap<Module, (PathBuf, String)>,
    /// For each module, every name a `use` in it brings into scope, with
    /// the path it stands for.
    imports: HashMap<Module, HashMap<String, Vec<String>>>,
}

/// Drops comments and the contents of string and char literals, keeping
/// lifetimes and everything else.
fn strip(code: &str) -> String {
    let c: Vec<char> = code.chars().collect();
    let mut out = String::with_capacity(code.len());
    let mut i = 0;
    while i < c.len() {
        let next = c.get(i + 1).copied();
        if c[i] == '/' && next == Some('/') {
            while i < c.len() && c[i] != '\n' {
                i += 1;
            }
        } else if c[i] == '/' && next == Some('*') {
            let mut depth = 0;
            while i < c.len() {
                if c[i] == '/' && c.get(i + 1) == Some(&'*') {
                    depth += 1;
                    i += 2;
                } else if c[i] == '*' && c.get(i + 1) == Some(&'/') {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
            out.push(' ');
        } else if c[i] == 'r'
            && matches!(next, Some('"') | Some('#'))
            && (i == 0 || !is_ident(c[i - 1]))
        {
            // A raw string: r"…", r#"…"#.
            let mut j = i + 1;
            let mut hashes = 0;
            while c.get(j) == Some(&'#') {
                hashes += 1;
                j += 1;
            }
            if c.get(j) != Some(&'"') {
                out.push(c[i]);
                i += 1;
                continue;
            }
            j += 1;
            loop {
                if j >= c.len() {
                    break;
                }
                if c[j] == '"' && (0..hashes).all(|k| c.get(j + 1 + k) == Some(&'#')) {
                    j += 1 + hashes;
                    break;
                }
                j += 1;
            }
            out.push_str("\"\"");
            i = j;
        } else if c[i] == '"' {
            i += 1;
            while i < c.len() && c[i] != '"' {
                i += if c[i] == '\\' { 2 } else { 1 };
            }
            i += 1;
            out.push_str("\"\"");
        } else if c[i] == '\'' {
            // A char literal ('x', '\n', '\u{..}') or a lifetime ('a).
            if next == Some('\\') {
                let mut j = i + 2;
                while j < c.len() && c[j] != '\'' {
                    j += 1;
                }
                i = j + 1;
                out.push_str("' '");
            } else if c.get(i + 2) == Some(&'\'') {
                i += 3;
                out.push_str("' '");
            } else {
                out.push(c[i]);
                i += 1;
            }
        } else {
            out.push(c[i]);
            i += 1;
        }
    }
    out
}

fn is_ident(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

/// Leaves out every inline module under `#[cfg(test)]`.
fn without_test_modules(code: &str) -> String {
    let mut out = code.to_owned();
    while let Some(at) = out.find("#[cfg(test)]") {
        let after = at + "#[cfg(test)]".len();
        let rest = out[after..].trim_start();
        let Some(body) = rest.strip_prefix("mod ") else {
            out.replace_range(at..after, "");
            continue;
        };
        let start = out.len() - rest.len();
        let Some(open) = body.find(['{', ';']) else {
            break;
        };
        if body.as_bytes()[open] == b';' {
            // A test module in a file of its own: kept, it is read there.
            out.replace_range(at..after, "");
            continue;
        }
        let open = start + 4 + open;
        let mut depth = 0;
        let mut end = out.len();
        for (k, ch) in out[open..].char_indices() {
            match ch {
                '{' => depth += 1,
                '}' => {
                    depth -= 1;
                    if depth == 0 {
                        end = open + k + 1;
                        break;
                    }
                }
                _ => {}
            }
        }
        out.replace_range(at..end, "");
    }
    out
}

/// Splits `s` at top-level (outside braces) occurrences of `sep`.
fn split_top(s: &str, sep: &str) -> Vec<String> {
    let mut parts = Vec::new();
    let mut depth = 0;
    let mut start = 0;
    let bytes = s.as_bytes();
    let mut i = 0;
    while i < s.len() {
        match bytes[i] {
            b'{' => depth += 1,
            b'}' => depth -= 1,
            _ if depth == 0 && s[i..].starts_with(sep) => {
                parts.push(s[start..i].trim().to_owned());
                i += sep.len();
                start = i;
                continue;
            }
            _ => {}
        }
        i += 1;
    }
    parts.push(s[start..].trim().to_owned());
    parts.retain(|p| !p.is_empty());
    parts
}

/// Expands a use tree into `(name in scope, path)` pairs: `a::{b, c::{d
/// as e}}` gives `(b, a::b)` and `(e, a::c::d)`; a glob gives `*`.
fn expand(tree: &str, prefix: &[String]) -> Vec<(String, Vec<String>)> {
    let segments = split_top(tree.trim().trim_start_matches("::"), "::");
    let mut path = prefix.to_vec();
    for (k, segment) in segments.iter().enumerate() {
        if let Some(group) = segment.strip_prefix('{') {
            let group = group.strip_suffix('}').unwrap_or(group);
            return split_top(group, ",")
                .iter()
                .flat_map(|item| expand(item, &path))
                .collect();
        }
        let last = k + 1 == segments.len();
        if last {
            let (name, alias) = match segment.split_once(" as ") {
                Some((name, alias)) => (name.trim(), alias.trim()),
                None => (segment.as_str(), segment.as_str()),
            };
            if name == "self" {
                let alias = if alias == "self" {
                    path.last().cloned().unwrap_or_default()
                } else {
                    alias.to_owned()
                };
                return vec![(alias, path)];
            }
            path.push(name.to_owned());
            return vec![(alias.to_owned(), path)];
        }
        path.push(segment.clone());
    }
    Vec::new()
}

/// Every `use` item in `code` (after `strip`), with its visibility
/// dropped, and the code outside them.
fn use_items(code: &str) -> (Vec<String>, String) {
    let mut trees = Vec::new();
    let mut rest = String::with_capacity(code.len());
    let mut i = 0;
    let bytes = code.as_bytes();
    while i < code.len() {
        let at_word = i == 0 || !is_ident(code[..i].chars().next_back().unwrap_or(' '));
        if at_word && code[i..].starts_with("use ") {
            let end = code[i..].find(';').map_or(code.len(), |k| i + k);
            trees.push(
                code[i + 4..end]
                    .split_whitespace()
                    .collect::<Vec<_>>()
                    .join(" "),
            );
            i = end + 1;
            continue;
        }
        rest.push(bytes[i] as char);
        i += 1;
    }
    (trees, rest)
}

/// Every `crate::…`, `super::…` and `self::…` path written in code (not
/// in a `use`).
fn code_paths(code: &str) -> Vec<Vec<String>> {
    let mut paths = Vec::new();
    for start in ["crate::", "super::", "self::"] {
        for (i, _) in code.match_indices(start) {
            if code[..i].chars().next_back().is_some_and(is_ident) {
                continue;
            }
            let tail: String = code[i..]
                .chars()
                .take_while(|&c| is_ident(c) || c == ':')
                .collect();
            paths.push(
                tail.split("::")
                    .filter(|s| !s.is_empty())
                    .map(str::to_owned)
                    .collect(),
            );
        }
    }
    paths
}

impl Crate {
    fn read(src: &Path) -> Self {
        let mut files = BTreeMap::new();
        let mut folders = vec![src.to_path_buf()];
        while let Some(folder) = folders.pop() {
            for entry in std::fs::read_dir(&folder).unwrap() {
                let path = entry.unwrap().path();
                if path.is_dir() {
                    folders.push(path);
                    continue;
                }
                if path.extension().is_none_or(|e| e != "rs") {
                    continue;
                }
                let relative = path.strip_prefix(src).unwrap().with_extension("");
                let mut module: Module = relative
                    .components()
                    .map(|c| c.as_os_str().to_string_lossy().into_owned())
                    .collect();
                if module.last().is_some_and(|m| m == "mod" || m == "lib") {
                    module.pop();
                }
                let code = std::fs::read_to_string(&path).unwrap();
                files.insert(module, (path, without_test_modules(&strip(&code))));
            }
        }
        let mut krate = Self {
            files,
            imports: HashMap::new(),
        };
        let modules: Vec<Module> = krate.files.keys().cloned().collect();
        for module in modules {
            let (trees, _) = use_items(&krate.files[&module].1);
            // The first `use` of a name is the module's own; a later one
            // is an inline module's (the prelude's `crate::…`).
            let mut imports = HashMap::new();
            for (name, path) in trees.iter().flat_map(|t| expand(t, &[])) {
                imports.entry(name).or_insert(path);
            }
            krate.imports.insert(module, imports);
        }
        krate
    }

    fn is_module(&self, module: &[String]) -> bool {
        self.files.contains_key(module)
    }

    /// The module that defines what `path` names, seen from `from`; `None`
    /// for another crate's path.
    fn resolve(&self, from: &[String], path: &[String], depth: usize) -> Option<Module> {
        let (mut at, mut rest): (Module, &[String]) = match path.first()?.as_str() {
            "crate" => (Vec::new(), &path[1..]),
            "self" => (from.to_vec(), &path[1..]),
            "super" => {
                let mut at = from.to_vec();
                let mut rest = path;
                while rest.first().is_some_and(|s| s == "super") {
                    at.pop()?;
                    rest = &rest[1..];
                }
                (at, rest)
            }
            child if self.is_module(&[from, &[child.to_owned()]].concat()) => (from.to_vec(), path),
            _ => return None,
        };
        while let Some(segment) = rest.first() {
            let deeper = [at.as_slice(), std::slice::from_ref(segment)].concat();
            if !self.is_module(&deeper) {
                break;
            }
            at = deeper;
            rest = &rest[1..];
        }
        if let (Some(item), true) = (rest.first(), depth < 16)
            && let Some(target) = self.imports.get(&at).and_then(|m| m.get(item))
            && let Some(defined) = self.resolve(&at, target, depth + 1)
        {
            return Some(defined);
        }
        Some(at)
    }

    /// Each module's edges: the modules its code names.
    fn edges(&self) -> BTreeMap<Module, BTreeSet<Module>> {
        let mut edges = BTreeMap::new();
        for (module, (_, code)) in &self.files {
            let (trees, rest) = use_items(code);
            let mut targets = BTreeSet::new();
            let paths = trees
                .iter()
                .flat_map(|t| expand(t, &[]).into_iter().map(|(_, p)| p))
                .chain(code_paths(&rest));
            for path in paths {
                let path: Vec<String> = path.into_iter().filter(|s| s != "*").collect();
                // A module holds its children: its `mod` and re-export of
                // them is not a use (their use of it is).
                if let Some(target) = self.resolve(module, &path, 0)
                    && !target.starts_with(module)
                {
                    targets.insert(target);
                }
            }
            edges.insert(module.clone(), targets);
        }
        edges
    }
}

fn name(module: &[String]) -> String {
    if module.is_empty() {
        "crate".to_owned()
    } else {
        module.join("::")
    }
}

/// Every import circle in `edges`: each set of two or more modules that
/// reach each other (a strongly connected component, by Kosaraju's two
/// passes).
fn circles(edges: &BTreeMap<Module, BTreeSet<Module>>) -> Vec<Vec<Module>> {
    fn finish<'a>(
        node: &'a Module,
        edges: &'a BTreeMap<Module, BTreeSet<Module>>,
        seen: &mut BTreeSet<&'a Module>,
        order: &mut Vec<&'a Module>,
    ) {
        if !seen.insert(node) {
            return;
        }
        for next in edges.get(node).into_iter().flatten() {
            finish(next, edges, seen, order);
        }
        order.push(node);
    }
    let mut reverse: BTreeMap<&Module, Vec<&Module>> = BTreeMap::new();
    for (from, targets) in edges {
        for to in targets {
            reverse.entry(to).or_default().push(from);
        }
    }
    let (mut seen, mut order) = (BTreeSet::new(), Vec::new());
    for node in edges.keys() {
        finish(node, edges, &mut seen, &mut order);
    }
    let mut placed: BTreeSet<&Module> = BTreeSet::new();
    let mut found = Vec::new();
    for &root in order.iter().rev() {
        if placed.contains(root) {
            continue;
        }
        let mut component = Vec::new();
        let mut stack = vec![root];
        placed.insert(root);
        while let Some(node) = stack.pop() {
            component.push(node.clone());
            for &back in reverse.get(node).into_iter().flatten() {
                if placed.insert(back) {
                    stack.push(back);
                }
            }
        }
        if component.len() > 1 {
            component.sort();
            found.push(component);
        }
    }
    found
}

fn library() -> Crate {
    Crate::read(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src"))
}

#[test]
fn use_trees_expand_to_every_path_they_name() {
    let got: Vec<(String, String)> = expand("crate::{a::{B, c::D as E}, f, g::self}", &[])
        .into_iter()
        .map(|(n, p)| (n, p.join("::")))
        .collect();
    let want = [
        ("B", "crate::a::B"),
        ("E", "crate::a::c::D"),
        ("f", "crate::f"),
        ("g", "crate::g"),
    ];
    assert_eq!(got.len(), want.len(), "{got:?}");
    for ((n, p), (wn, wp)) in got.iter().zip(want) {
        assert_eq!((n.as_str(), p.as_str()), (wn, wp));
    }
    let (trees, rest) = use_items(&strip(
        "use super::x::{Y, z}; // use crate::not_this;\nfn f() { let s = \"crate::nor_this\"; crate::w::v(); }",
    ));
    assert_eq!(trees, ["super::x::{Y, z}"]);
    assert_eq!(code_paths(&rest), [["crate", "w", "v"]]);
}

#[test]
fn a_path_is_followed_through_re_exports_to_its_defining_file() {
    let krate = library();
    let from = vec!["gui".to_owned()];
    let path: Vec<String> = ["crate", "Bead"].map(str::to_owned).to_vec();
    let defined = krate
        .resolve(&from, &path, 0)
        .expect("crate::Bead resolves");
    assert_eq!(name(&defined), "dynamics::bead");
}

#[test]
fn no_module_uses_one_above_it() {
    let krate = library();
    let edges = krate.edges();
    let count: usize = edges.values().map(BTreeSet::len).sum();
    assert!(
        count > 100,
        "only {count} edges read: the parser missed the uses"
    );
    for (module, targets) in &edges {
        let Some(top) = module.first() else { continue };
        let level = LAYERS
            .iter()
            .position(|m| m == top)
            .unwrap_or_else(|| panic!("module {top} is not in LAYERS: place it there"));
        for target in targets {
            let Some(used) = target.first() else { continue };
            let used_level = LAYERS.iter().position(|m| m == used).unwrap_or(level);
            assert!(
                used_level <= level,
                "{} uses {}, a layer above it",
                krate.files[module].0.display(),
                name(target)
            );
        }
    }
}

#[test]
fn no_files_import_each_other_in_a_circle() {
    let found: Vec<String> = circles(&library().edges())
        .iter()
        .map(|circle| {
            circle
                .iter()
                .map(|m| name(m))
                .collect::<Vec<_>>()
                .join(", ")
        })
        .collect();
    assert!(
        found.is_empty(),
        "import circles among these modules: {}",
        found.join("; ")
    );
}

#[test]
fn a_circle_is_found_whatever_its_length() {
    let module = |n: &str| vec![n.to_owned()];
    let mut edges = BTreeMap::new();
    edges.insert(module("a"), BTreeSet::from([module("b")]));
    edges.insert(module("b"), BTreeSet::from([module("c")]));
    edges.insert(module("c"), BTreeSet::from([module("a"), module("d")]));
    edges.insert(module("d"), BTreeSet::new());
    edges.insert(module("e"), BTreeSet::from([module("e"), module("a")]));
    assert_eq!(circles(&edges), [[module("a"), module("b"), module("c")]]);
}
