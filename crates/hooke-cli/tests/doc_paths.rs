//! Every file or folder of the repository that the Markdown files, the source comments and
//! the `--help` texts mention exists in a clone: the documentation stands on its own. And
//! every Rust source says what it holds in its first line.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .canonicalize()
        .unwrap()
}

/// Where a mentioned path starts when it names something in the repository. Anything else
/// (`out/`, `t.csv`, `mine.toml`) is an example output or the user's own file.
const REPO_PREFIXES: [&str; 12] = [
    "examples/",
    "blender/",
    "crates/",
    "assets/",
    "tests/",
    "golden/",
    "benches/",
    "docs/",
    "fuzz/",
    ".ci/",
    "python/",
    "yardsticks/",
];
const REPO_FILES: [&str; 6] = [
    "README.md",
    "ARCHITECTURE.md",
    "Cargo.toml",
    "Cargo.lock",
    "LICENSE-MIT",
    "LICENSE-APACHE",
];

/// Tokens that look like paths: runs of path characters.
fn path_tokens(text: &str) -> impl Iterator<Item = &str> {
    text.split(|c: char| !(c.is_ascii_alphanumeric() || "._-/<>*{}:".contains(c)))
        .map(|t| t.trim_end_matches(['.', ':', ',']))
        .filter(|t| !t.is_empty())
}

/// The repository paths a text mentions: `(path, also relative to this folder)`.
fn mentioned(text: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for token in path_tokens(text) {
        // `builtin:table.obj`, URLs and placeholders such as `golden/<name>.new.png`.
        if token.contains("://") || token.contains(['<', '*', '{']) {
            continue;
        }
        let token = token.trim_start_matches("./");
        let moved_out = token.starts_with("../") || token.starts_with("shared/");
        let names_repo = REPO_PREFIXES.iter().any(|p| token.starts_with(p))
            || REPO_FILES.contains(&token)
            || (token.ends_with(".md") && token.len() > 3);
        if (names_repo || moved_out) && !token.contains(':') {
            out.insert(token.to_string());
        }
    }
    out
}

/// Markdown links `[text](target)` resolve against the file's own folder.
fn links(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(at) = rest.find("](") {
        rest = &rest[at + 2..];
        if let Some(end) = rest.find(')') {
            let target = rest[..end].split('#').next().unwrap_or("");
            if !target.is_empty() && !target.contains("://") && !target.starts_with("mailto:") {
                out.push(target.to_string());
            }
        }
    }
    out
}

/// Files under `dir` with extension `ext`, skipping build output and hidden folders. Other
/// tests running beside this one make and remove scratch folders and files in the clone
/// (issue 54 saw this test fail once in a full run): whatever vanishes during the walk is
/// skipped, as it holds nothing the documentation mentions; any other error fails.
fn files(dir: &Path, ext: &str, out: &mut Vec<PathBuf>) {
    let gone = |e: &std::io::Error| e.kind() == std::io::ErrorKind::NotFound;
    let entries = match std::fs::read_dir(dir) {
        Ok(entries) => entries,
        Err(e) if gone(&e) => return,
        Err(e) => panic!("{}: {e}", dir.display()),
    };
    for entry in entries {
        let path = match entry {
            Ok(entry) => entry.path(),
            Err(e) if gone(&e) => continue,
            Err(e) => panic!("{}: {e}", dir.display()),
        };
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        if path.is_dir() {
            if name != "target" && !name.starts_with('.') {
                files(&path, ext, out);
            }
        } else if path.extension().is_some_and(|e| e == ext) {
            out.push(path);
        }
    }
}

/// Whether `mention`, found in `file`, names something that exists: relative to the
/// repository root, to the file's folder or to its crate (code joins paths to
/// `CARGO_MANIFEST_DIR`). `target/` is build output; a `.new.png` is what a failing golden
/// comparison writes, named in the instructions for accepting it.
fn exists(root: &Path, file: &Path, mention: &str) -> bool {
    let trimmed = mention.trim_end_matches('/');
    if trimmed.starts_with("target/") || trimmed.ends_with(".new.png") {
        return true;
    }
    file.ancestors()
        .skip(1)
        .take_while(|d| d.starts_with(root))
        .any(|d| d.join(trimmed).exists())
}

/// The text of `file`, or `None` when another test removed it since the walk saw it.
fn read_unless_gone(file: &Path) -> Option<String> {
    match std::fs::read_to_string(file) {
        Ok(text) => Some(text),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => None,
        Err(e) => panic!("{}: {e}", file.display()),
    }
}

fn help_texts() -> Vec<(String, String)> {
    let hooke = env!("CARGO_BIN_EXE_hooke");
    let help = |args: &[&str]| {
        let out = Command::new(hooke)
            .args(args)
            .arg("--help")
            .output()
            .unwrap();
        assert!(out.status.success(), "hooke {args:?} --help failed");
        String::from_utf8(out.stdout).unwrap()
    };
    // Subcommands are the indented first words of the "Commands:" section.
    let commands = |text: &str| -> Vec<String> {
        text.split("Commands:")
            .nth(1)
            .map(|s| s.split("\n\n").next().unwrap_or(""))
            .unwrap_or("")
            .lines()
            .filter_map(|l| l.split_whitespace().next())
            .filter(|c| *c != "help")
            .map(str::to_string)
            .collect()
    };
    let top = help(&[]);
    let mut texts = vec![("hooke --help".to_string(), top.clone())];
    for command in commands(&top) {
        let text = help(&[&command]);
        for sub in commands(&text) {
            let name = format!("hooke {command} {sub} --help");
            texts.push((name, help(&[&command, &sub])));
        }
        texts.push((format!("hooke {command} --help"), text));
    }
    texts
}

/// The repository's files ending in one of `exts`: those git lists (tracked, and new ones it
/// does not ignore) in a checkout, so that nothing another process makes or removes in the
/// clone while the test reads it — a second test run's build output or scratch, an editor's
/// swap file — is read half-written or vanishes between the listing and the check; a walk
/// of the folder where git cannot say.
fn repository_files(root: &Path, exts: &[&str]) -> Vec<PathBuf> {
    let listed = Command::new("git")
        .args([
            "ls-files",
            "-z",
            "--cached",
            "--others",
            "--exclude-standard",
        ])
        .current_dir(root)
        .output()
        .ok()
        .filter(|o| o.status.success());
    let Some(listed) = listed else {
        let mut out = Vec::new();
        for ext in exts {
            files(root, ext, &mut out);
        }
        return out;
    };
    String::from_utf8_lossy(&listed.stdout)
        .split('\0')
        .filter(|name| {
            !name.is_empty()
                && Path::new(name)
                    .extension()
                    .is_some_and(|e| exts.iter().any(|x| e == *x))
        })
        .map(|name| root.join(name))
        .filter(|path| path.is_file())
        .collect()
}

#[test]
fn every_mentioned_repository_path_exists() {
    let root = root();
    let sources = repository_files(&root, &["md", "rs", "toml"]);
    assert!(sources.len() > 50, "found only {} files", sources.len());
    let mut missing = Vec::new();
    let mut checked = 0;
    for file in sources.iter().filter(|f| !f.ends_with(file!())) {
        let Some(text) = read_unless_gone(file) else {
            continue;
        };
        let is_markdown = file.extension().is_some_and(|e| e == "md");
        let mut mentions: Vec<String> = mentioned(&text).into_iter().collect();
        if is_markdown {
            mentions.extend(links(&text));
        }
        for m in mentions {
            checked += 1;
            if !exists(&root, file, &m) {
                missing.push(format!(
                    "{}: {m}",
                    file.strip_prefix(&root).unwrap().display()
                ));
            }
        }
    }
    for (name, text) in help_texts() {
        for m in mentioned(&text) {
            checked += 1;
            if !exists(&root, &root.join("Cargo.toml"), &m) {
                missing.push(format!("{name}: {m}"));
            }
        }
    }
    assert!(checked > 100, "only {checked} mentions checked");
    assert!(
        missing.is_empty(),
        "paths mentioned but not in the repository:\n  {}",
        missing.join("\n  ")
    );
}

#[test]
fn the_path_finder_sees_what_it_should() {
    let found = mentioned(
        "see `docs/physics.md` §6, shared/SPEC.md, ../shared/worlds/, out/1-a.png, \
         golden/<name>.png and builtin:table.obj",
    );
    let found: Vec<&str> = found.iter().map(String::as_str).collect();
    assert_eq!(
        found,
        ["../shared/worlds/", "docs/physics.md", "shared/SPEC.md"]
    );
    assert_eq!(links("[a](../x.md#top) [b](https://e.org)"), ["../x.md"]);
}

/// Every Rust file in the repository opens with a `//!` comment saying what it holds
/// (ARCHITECTURE.md's habit, checked).
#[test]
fn every_rust_source_opens_with_a_module_comment() {
    let root = root();
    let sources = repository_files(&root, &["rs"]);
    assert!(sources.len() > 50, "found only {} files", sources.len());
    let silent: Vec<String> = sources
        .iter()
        .filter(|f| {
            let Some(text) = read_unless_gone(f) else {
                return false;
            };
            let first = text.lines().find(|l| !l.trim().is_empty()).unwrap_or("");
            !first.starts_with("//!")
        })
        .map(|f| f.strip_prefix(&root).unwrap().display().to_string())
        .collect();
    assert!(
        silent.is_empty(),
        "files without an opening //! comment: {silent:?}"
    );
}
