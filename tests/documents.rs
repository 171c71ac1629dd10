//! The house's documents and packages, checked on the files: ARCHITECTURE.md names only
//! files that exist, every relative link in the docs resolves, each publishable crate
//! packages from its own folder, the README stays a first read, and the Rust version is
//! the same wherever it is named.

use crate::layout::workspace;
use std::path::Path;

/// Every source path ARCHITECTURE.md names in a crate's section (`contact/respond.rs`,
/// `forces/`, `lib.rs`) is a file or folder of that crate: the map stays true.
#[test]
fn architecture_names_only_files_that_exist() {
    let root = workspace();
    let text = std::fs::read_to_string(root.join("ARCHITECTURE.md")).unwrap();
    let mut missing = Vec::new();
    let mut checked = 0;
    for section in text.split("\n### `").skip(1) {
        let Some((krate, body)) = section.split_once('`') else {
            continue;
        };
        let src = root.join("crates").join(krate).join("src");
        if !src.is_dir() {
            continue;
        }
        let body = body.split("\n## ").next().unwrap();
        for token in body.split('`').skip(1).step_by(2) {
            let path = token.split_whitespace().next().unwrap_or("");
            let is_path = path.ends_with(".rs") || (path.ends_with('/') && !path.contains(' '));
            if !is_path || path.starts_with("../") {
                continue;
            }
            // `integrator/{euler,rk4}.rs` names each of them.
            let paths: Vec<String> = match (path.find('{'), path.find('}')) {
                (Some(a), Some(b)) if a < b => path[a + 1..b]
                    .split(',')
                    .map(|one| format!("{}{one}{}", &path[..a], &path[b + 1..]))
                    .collect(),
                _ => vec![path.to_string()],
            };
            for path in &paths {
                let path = path.as_str();
                checked += 1;
                // A bare file name may sit in any folder of the crate: the section says which.
                let found = src.join(path).exists() || root.join(path).exists() || {
                    let name = path.trim_end_matches('/');
                    let mut stack = vec![src.clone()];
                    let mut hit = false;
                    while let Some(dir) = stack.pop() {
                        for entry in std::fs::read_dir(&dir).unwrap() {
                            let p = entry.unwrap().path();
                            if p.ends_with(name) {
                                hit = true;
                            }
                            if p.is_dir() {
                                stack.push(p);
                            }
                        }
                    }
                    hit
                };
                if !found {
                    missing.push(format!("{krate}: {path}"));
                }
            }
        }
    }
    assert!(
        checked > 50,
        "only {checked} paths found: has the page's form changed?"
    );
    assert!(
        missing.is_empty(),
        "ARCHITECTURE.md names files that do not exist: {missing:?}"
    );
}

/// GitHub's anchor for a heading: lower case, spaces to hyphens, other punctuation dropped.
fn anchor_of(heading: &str) -> String {
    heading
        .trim()
        .chars()
        .filter_map(|c| match c {
            ' ' => Some('-'),
            c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c.to_ascii_lowercase()),
            _ => None,
        })
        .collect()
}

/// The relative link targets of a Markdown page outside its fenced code: `[text](target)`
/// and HTML `src="target"` / `href="target"`; web addresses are left out.
fn relative_links(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut fenced = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced {
            continue;
        }
        let mut rest = line;
        while let Some(at) = rest.find("](") {
            let after = &rest[at + 2..];
            let end = after.find(')').unwrap_or(after.len());
            out.push(after[..end].trim().to_string());
            rest = &after[end..];
        }
        for attr in ["src=\"", "href=\""] {
            let mut rest = line;
            while let Some(at) = rest.find(attr) {
                let after = &rest[at + attr.len()..];
                let end = after.find('"').unwrap_or(after.len());
                out.push(after[..end].to_string());
                rest = &after[end..];
            }
        }
    }
    out.retain(|t| !t.contains("://") && !t.starts_with("mailto:") && !t.is_empty());
    out
}

/// Whether page `file` has a heading whose anchor is `anchor`.
fn has_anchor(file: &Path, anchor: &str) -> bool {
    let text = std::fs::read_to_string(file).unwrap_or_default();
    let mut fenced = false;
    text.lines().any(|line| {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
        }
        !fenced && line.starts_with('#') && anchor_of(line.trim_start_matches('#')) == anchor
    })
}

/// Every relative link in README.md, ARCHITECTURE.md, benches/README.md and docs/*.md names
/// a file or folder that exists, and a `#anchor` into a Markdown page names one of its
/// headings: a page moved or a section renamed leaves no dead link.
#[test]
fn every_relative_link_in_the_docs_resolves() {
    let root = workspace();
    let mut pages = vec![
        root.join("README.md"),
        root.join("ARCHITECTURE.md"),
        root.join("benches/README.md"),
    ];
    for entry in std::fs::read_dir(root.join("docs")).unwrap() {
        let p = entry.unwrap().path();
        if p.extension().is_some_and(|e| e == "md") {
            pages.push(p);
        }
    }
    let (mut checked, mut dead) = (0, Vec::new());
    for page in &pages {
        let text = std::fs::read_to_string(page).unwrap();
        let here = page.parent().unwrap();
        for link in relative_links(&text) {
            checked += 1;
            let (file, anchor) = link.split_once('#').unwrap_or((&link, ""));
            let target = if file.is_empty() {
                page.clone()
            } else {
                here.join(file)
            };
            let ok = target.exists()
                && (anchor.is_empty()
                    || target.extension().is_none_or(|e| e != "md")
                    || has_anchor(&target, anchor));
            if !ok {
                dead.push(format!(
                    "{}: {link}",
                    page.strip_prefix(&root).unwrap().display()
                ));
            }
        }
    }
    assert!(
        checked > 40,
        "only {checked} links found: has the pages' form changed?"
    );
    assert!(dead.is_empty(), "dead links: {dead:#?}");
}

/// The link reader finds links, skips code and web addresses, and makes GitHub's anchors.
#[test]
fn the_link_reader_finds_links_and_anchors() {
    let text =
        "see [a](<p>.md#x) and <img src=\"<g>.png\">\n```\n[no](<b>.md)\n```\n[web](https://x.org)";
    assert_eq!(relative_links(text), vec!["<p>.md#x", "<g>.png"]);
    assert_eq!(
        anchor_of(" 4.1 Block descent (`vbd`): large steps without crossings"),
        "41-block-descent-vbd-large-steps-without-crossings"
    );
}

/// What cargo writes into every package itself, not taken from the crate's folder.
const GENERATED: [&str; 4] = [
    ".cargo_vcs_info.json",
    "Cargo.lock",
    "Cargo.toml",
    "Cargo.toml.orig",
];

/// `cargo package --workspace --no-verify` succeeds (every path dependency has a version),
/// and each publishable crate's package holds only files of its own folder, with the
/// metadata crates.io shows.
#[test]
fn every_publishable_crate_packages_from_its_own_folder() {
    let root = workspace();
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let target = std::env::temp_dir().join(format!("hooke-package-{}", std::process::id()));
    let cargo_run = |args: &[&str]| {
        let out = std::process::Command::new(&cargo)
            .args(args)
            .args(["--allow-dirty", "--offline", "--target-dir"])
            .arg(&target)
            .current_dir(&root)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "cargo {}: {}",
            args.join(" "),
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8(out.stdout).unwrap()
    };
    cargo_run(&["package", "--workspace", "--no-verify"]);
    let mut published = 0;
    for entry in std::fs::read_dir(root.join("crates")).unwrap() {
        let dir = entry.unwrap().path();
        let manifest = std::fs::read_to_string(dir.join("Cargo.toml")).unwrap();
        if manifest.contains("publish = false") {
            continue;
        }
        published += 1;
        let name = dir.file_name().unwrap().to_str().unwrap();
        for key in ["description", "license", "keywords", "categories", "readme"] {
            assert!(
                manifest.lines().any(|l| l.starts_with(key)),
                "{name}: no `{key}` in its Cargo.toml"
            );
        }
        let list = cargo_run(&["package", "--list", "-p", name]);
        for file in list.lines().filter(|f| !GENERATED.contains(f)) {
            assert!(
                dir.join(file).is_file(),
                "{name} packages {file}, which is not a file of crates/{name}/"
            );
        }
    }
    let _ = std::fs::remove_dir_all(&target);
    assert!(published >= 6, "only {published} publishable crates found");
}

/// The README stays a first read: at most 200 lines, its first 40 holding a picture and the
/// two commands, and no commit named (a hex word of 7 to 40 digits and letters).
#[test]
fn the_readme_is_short_and_its_first_screen_shows_and_tells() {
    let text = std::fs::read_to_string(workspace().join("README.md")).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert!(lines.len() <= 200, "README.md has {} lines", lines.len());
    let first = lines[..40.min(lines.len())].join("\n");
    for needed in [
        "cargo run --release -p hooke-cli -- demo",
        "cargo xtask test",
        "<img src=",
    ] {
        assert!(
            first.contains(needed),
            "no {needed:?} in README.md's first 40 lines"
        );
    }
    let commits: Vec<&str> = text
        .split(|c: char| !c.is_ascii_alphanumeric())
        .filter(|w| {
            (7..=40).contains(&w.len())
                && w.chars()
                    .all(|c| c.is_ascii_digit() || ('a'..='f').contains(&c))
                && w.chars().any(|c| c.is_ascii_digit())
                && w.chars().any(|c| c.is_ascii_alphabetic())
        })
        .collect();
    assert!(commits.is_empty(), "README.md names commits: {commits:?}");
}

/// Issue 54: one Rust version everywhere it is named: the workspace's `rust-version`, the
/// Python package's, `.ci/run`'s message and the README's first command.
#[test]
fn the_rust_version_is_the_same_wherever_it_is_named() {
    let root = workspace();
    let read = |p: &str| std::fs::read_to_string(root.join(p)).unwrap();
    let version = |manifest: &str| {
        manifest
            .lines()
            .find_map(|l| l.strip_prefix("rust-version = \""))
            .and_then(|v| v.strip_suffix('"'))
            .map(str::to_string)
            .unwrap()
    };
    let workspace_version = version(&read("Cargo.toml"));
    assert_eq!(version(&read("python/Cargo.toml")), workspace_version);
    for (file, phrase) in [
        (".ci/run", format!("({workspace_version} or newer)")),
        ("README.md", format!("Rust {workspace_version} or newer")),
        ("docs/python.md", format!("(Rust {workspace_version}+)")),
    ] {
        assert!(
            read(file).contains(&phrase),
            "{file} does not say {phrase:?}"
        );
    }
}
