//! The house's layering, checked on its sources: no two modules of a crate import each
//! other (directly or round a circle), and `hooke-core`'s root re-exports only names
//! another crate uses. A module may use its parent's and its children's items (that is how
//! a folder module is written); the circles looked for are between siblings, each counted
//! with everything inside it.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// A crate's module tree: each module's path (`["contact", "grid"]`) and its file.
struct Crate {
    name: String,
    modules: BTreeMap<Vec<String>, PathBuf>,
}

/// The workspace's root folder.
pub(crate) fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The source text with comments and string contents blanked (so a path in a doc comment or
/// a message is not an import), up to its `#[cfg(test)]` module: tests may reach anywhere.
fn code(path: &Path) -> String {
    let text = std::fs::read_to_string(path).unwrap();
    let text = match text.find("#[cfg(test)]\nmod ") {
        Some(k) => &text[..k],
        None => &text[..],
    };
    let mut out = String::with_capacity(text.len());
    let mut chars = text.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '/' if chars.peek() == Some(&'/') => {
                for c in chars.by_ref() {
                    if c == '\n' {
                        out.push('\n');
                        break;
                    }
                }
            }
            '"' => {
                out.push('"');
                let mut escaped = false;
                for c in chars.by_ref() {
                    if c == '"' && !escaped {
                        break;
                    }
                    escaped = c == '\\' && !escaped;
                }
                out.push('"');
            }
            _ => out.push(c),
        }
    }
    out
}

/// `mod NAME;` declarations (inline `mod NAME {` blocks are part of their file).
fn declared(code: &str) -> Vec<String> {
    code.lines()
        .filter_map(|l| {
            let l = l.trim();
            // Any visibility: `pub`, `pub(crate)`, `pub(super)`, `pub(in path)`.
            let l = match l.strip_prefix("pub") {
                Some(rest) if rest.starts_with('(') => rest.split_once(") ").map_or(l, |(_, r)| r),
                Some(rest) if rest.starts_with(' ') => rest.trim_start(),
                _ => l,
            };
            let name = l.strip_prefix("mod ")?.strip_suffix(';')?;
            Some(name.trim().to_string())
        })
        .collect()
}

fn load(name: &str, root: &Path) -> Crate {
    let mut modules = BTreeMap::new();
    let mut todo = vec![(Vec::new(), root.to_path_buf())];
    while let Some((path, file)) = todo.pop() {
        let dir = match file.file_name().and_then(|f| f.to_str()) {
            Some("lib.rs" | "main.rs" | "mod.rs") => file.parent().unwrap().to_path_buf(),
            _ => file.with_extension(""),
        };
        for child in declared(&code(&file)) {
            let flat = dir.join(format!("{child}.rs"));
            let folder = dir.join(&child).join("mod.rs");
            let child_file = if flat.exists() { flat } else { folder };
            assert!(
                child_file.exists(),
                "{}: mod {child}: no file",
                file.display()
            );
            let mut child_path = path.clone();
            child_path.push(child);
            todo.push((child_path, child_file));
        }
        modules.insert(path, file);
    }
    Crate {
        name: name.to_string(),
        modules,
    }
}

/// The paths of a `use` tree, braces expanded: `crate::{a::X, b::{Y, Z}}` gives
/// `crate::a::X`, `crate::b::Y`, `crate::b::Z`.
fn expand(tree: &str) -> Vec<String> {
    fn go(prefix: &str, s: &str, out: &mut Vec<String>) {
        let s = s.trim();
        match s.find('{') {
            None => {
                let item = s.split(" as ").next().unwrap().trim();
                if !item.is_empty() {
                    out.push(format!("{prefix}{item}"));
                }
            }
            Some(open) => {
                let head = &s[..open];
                let inner = &s[open + 1..s.rfind('}').unwrap()];
                let mut depth = 0;
                let mut start = 0;
                for (k, c) in inner.char_indices() {
                    match c {
                        '{' => depth += 1,
                        '}' => depth -= 1,
                        ',' if depth == 0 => {
                            go(&format!("{prefix}{head}"), &inner[start..k], out);
                            start = k + 1;
                        }
                        _ => {}
                    }
                }
                go(&format!("{prefix}{head}"), &inner[start..], out);
            }
        }
    }
    let mut out = Vec::new();
    go("", tree, &mut out);
    out
}

/// Every `crate::…`, `super::…` and `self::…` path a file names, in `use` items and inline.
fn paths(code: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = code;
    while let Some(k) = rest.find("use ") {
        let before = rest[..k].chars().last();
        rest = &rest[k + 4..];
        if before.is_some_and(|c| c.is_alphanumeric() || c == '_') {
            continue;
        }
        if let Some(end) = rest.find(';') {
            out.extend(expand(&rest[..end]));
        }
    }
    let bytes = code.as_bytes();
    for start in ["crate::", "super::", "self::"] {
        let mut from = 0;
        while let Some(k) = code[from..].find(start) {
            let at = from + k;
            from = at + start.len();
            if at > 0 && (bytes[at - 1].is_ascii_alphanumeric() || bytes[at - 1] == b'_') {
                continue;
            }
            let end = code[at..]
                .find(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
                .map_or(code.len(), |e| at + e);
            out.push(code[at..end].trim_end_matches(':').to_string());
        }
    }
    out
}

/// `pub use` re-exports of a module: exported name → the path it stands for.
fn reexports(code: &str) -> BTreeMap<String, String> {
    let mut map = BTreeMap::new();
    for line in code.split(';') {
        let line = line.trim();
        let Some(tree) = line
            .strip_prefix("pub use ")
            .or(line.strip_prefix("pub(crate) use "))
        else {
            continue;
        };
        for path in expand(tree) {
            let name = path.rsplit("::").next().unwrap().to_string();
            map.insert(name, path);
        }
    }
    map
}

impl Crate {
    /// The module a path names from module `at`: the deepest module it walks into, through
    /// re-exports; `None` for other crates and the standard library.
    fn resolve(&self, at: &[String], path: &str, depth: usize) -> Option<Vec<String>> {
        let mut segments = path.split("::").filter(|s| !s.is_empty()).peekable();
        let mut module: Vec<String> = match *segments.peek()? {
            "crate" => Vec::new(),
            "super" => at.to_vec(),
            "self" => at.to_vec(),
            first => {
                // A path relative to this module: a child module or a re-export here.
                let mut child = at.to_vec();
                child.push(first.to_string());
                if !self.modules.contains_key(&child) {
                    return None;
                }
                at.to_vec()
            }
        };
        while let Some(&s) = segments.peek() {
            match s {
                "crate" => module.clear(),
                "super" => {
                    module.pop()?;
                }
                "self" => {}
                _ => break,
            }
            segments.next();
        }
        for s in segments {
            let mut child = module.clone();
            child.push(s.to_string());
            if self.modules.contains_key(&child) {
                module = child;
                continue;
            }
            // An item of `module`, perhaps re-exported from elsewhere.
            if depth < 8
                && let Some(target) = reexports(&code(&self.modules[&module])).get(s)
            {
                return self.resolve(&module, target, depth + 1).or(Some(module));
            }
            break;
        }
        Some(module)
    }

    /// Import edges between siblings: parent module → (from child, to child).
    fn sibling_edges(&self) -> BTreeMap<Vec<String>, BTreeSet<(String, String)>> {
        let mut edges: BTreeMap<Vec<String>, BTreeSet<(String, String)>> = BTreeMap::new();
        for (module, file) in &self.modules {
            for path in paths(&code(file)) {
                let Some(target) = self.resolve(module, &path, 0) else {
                    continue;
                };
                let common = module
                    .iter()
                    .zip(&target)
                    .take_while(|(a, b)| a == b)
                    .count();
                // Within one module, or between a module and its ancestors: not a circle.
                if common == module.len() || common == target.len() {
                    continue;
                }
                edges
                    .entry(module[..common].to_vec())
                    .or_default()
                    .insert((module[common].clone(), target[common].clone()));
            }
        }
        edges
    }
}

/// The circles of a directed graph, each as the sorted names of a strongly connected
/// component of more than one node.
fn circles(edges: &BTreeSet<(String, String)>) -> Vec<Vec<String>> {
    let nodes: BTreeSet<&String> = edges.iter().flat_map(|(a, b)| [a, b]).collect();
    let reach = |from: &String| {
        let mut seen = BTreeSet::from([from.clone()]);
        let mut todo = vec![from.clone()];
        while let Some(n) = todo.pop() {
            for (a, b) in edges {
                if *a == n && seen.insert(b.clone()) {
                    todo.push(b.clone());
                }
            }
        }
        seen
    };
    let mut found: BTreeSet<Vec<String>> = BTreeSet::new();
    for n in &nodes {
        let from_n = reach(n);
        let component: Vec<String> = from_n
            .iter()
            .filter(|m| reach(m).contains(*n))
            .cloned()
            .collect();
        if component.len() > 1 {
            found.insert(component);
        }
    }
    found.into_iter().collect()
}

fn crates() -> Vec<Crate> {
    let root = workspace();
    let mut all = Vec::new();
    for entry in std::fs::read_dir(root.join("crates")).unwrap() {
        let dir = entry.unwrap().path();
        let name = dir.file_name().unwrap().to_string_lossy().into_owned();
        for top in ["src/lib.rs", "src/main.rs", "lib.rs"] {
            if dir.join(top).exists() {
                all.push(load(&format!("{name} ({top})"), &dir.join(top)));
            }
        }
    }
    all.push(load("hooke-python", &root.join("python/src/lib.rs")));
    all
}

#[test]
fn no_module_imports_a_sibling_that_imports_it_back() {
    let mut problems = Vec::new();
    for krate in crates() {
        for (parent, edges) in krate.sibling_edges() {
            for circle in circles(&edges) {
                let at = if parent.is_empty() {
                    "the crate root".to_string()
                } else {
                    parent.join("::")
                };
                problems.push(format!("{}: in {at}: {}", krate.name, circle.join(" <-> ")));
            }
        }
    }
    assert!(
        problems.is_empty(),
        "import circles:\n{}",
        problems.join("\n")
    );
}

#[test]
fn the_checker_finds_a_circle_and_resolves_reexports() {
    let edges = BTreeSet::from([
        ("a".to_string(), "b".to_string()),
        ("b".to_string(), "c".to_string()),
        ("c".to_string(), "a".to_string()),
        ("c".to_string(), "d".to_string()),
    ]);
    assert_eq!(circles(&edges), vec![vec!["a", "b", "c"]]);
    assert_eq!(
        expand("crate::{a::X, b::{Y, Z as W}}"),
        ["crate::a::X", "crate::b::Y", "crate::b::Z"]
    );
    // Modules of every visibility are read (`pub(in path)` ones were once skipped, and
    // with them the circle between block descent's detection and its pair list).
    assert_eq!(
        declared(
            "mod a;\npub mod b;\npub(crate) mod c;\npub(super) mod d;\npub(in crate::x) mod e;"
        ),
        ["a", "b", "c", "d", "e"]
    );
    let core = load(
        "hooke-core",
        &workspace().join("crates/hooke-core/src/lib.rs"),
    );
    // `crate::Model` is re-exported at the root from the model's module.
    let model = core.resolve(&[], "crate::Model", 0).unwrap();
    assert_eq!(model.first().map(String::as_str), Some("model"));
}

/// The names `hooke-core`'s root makes public: its `pub use` names and `pub mod` modules.
fn core_surface() -> Vec<String> {
    let lib = code(&workspace().join("crates/hooke-core/src/lib.rs"));
    let mut names: Vec<String> = reexports(&lib)
        .into_keys()
        .filter(|n| n != "self" && n != "*")
        .collect();
    names.extend(lib.lines().filter_map(|l| {
        let name = l.trim().strip_prefix("pub mod ")?.strip_suffix(';')?;
        Some(name.to_string())
    }));
    names
}

#[test]
fn hooke_core_makes_public_only_what_another_crate_uses() {
    let root = workspace();
    let mut others = String::new();
    let mut stack = vec![
        root.join("crates"),
        root.join("python/src"),
        root.join("tests"),
        root.join("benches"),
        root.join("examples"),
        root.join("fuzz/fuzz_targets"),
    ];
    while let Some(dir) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        for entry in entries {
            let path = entry.unwrap().path();
            if path.ends_with("hooke-core") {
                continue;
            }
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                others.push_str(&code(&path));
            }
        }
    }
    let used = |name: &str| {
        others.match_indices(name).any(|(k, _)| {
            let before = others[..k].chars().last();
            let after = others[k + name.len()..].chars().next();
            let word = |c: Option<char>| c.is_some_and(|c| c.is_alphanumeric() || c == '_');
            !word(before) && !word(after)
        })
    };
    // Returned by `Simulation::renumber`, which the scene crate calls: a caller must be able
    // to name the error it gets, though none matches it yet.
    let named_by_signatures = ["RenumberError"];
    let unused: Vec<String> = core_surface()
        .into_iter()
        .filter(|n| !used(n) && !named_by_signatures.contains(&n.as_str()))
        .collect();
    assert!(
        unused.is_empty(),
        "hooke-core's root makes public what no other crate uses (make it pub(crate)): {unused:?}"
    );
}

#[test]
#[ignore = "a listing for the developer: cargo test … layout::print -- --ignored --nocapture"]
fn print_root_edges_of_hooke_core() {
    let core = load(
        "hooke-core",
        &workspace().join("crates/hooke-core/src/lib.rs"),
    );
    for (parent, edges) in core.sibling_edges() {
        for (a, b) in edges {
            println!("{}: {a} -> {b}", parent.join("::"));
        }
    }
}
