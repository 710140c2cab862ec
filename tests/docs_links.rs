//! The README and the pages of docs/ link to files and headings that exist: every relative
//! link names a file of the repository, and every `#anchor` one of the target page's
//! headings (as GitHub makes anchors of them). docs/layout.md's tree of `src/` names every
//! source file there is, and no other. Reads files only; takes milliseconds.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

fn crate_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The README and every Markdown page of docs/.
fn pages() -> Vec<PathBuf> {
    let mut pages = vec![crate_dir().join("README.md")];
    let docs = std::fs::read_dir(crate_dir().join("docs")).expect("docs/ exists");
    for entry in docs {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "md") {
            pages.push(path);
        }
    }
    pages.sort();
    pages
}

/// The lines of a page outside its fenced code blocks.
fn prose_lines(text: &str) -> Vec<&str> {
    let mut in_code = false;
    let mut lines = Vec::new();
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            in_code = !in_code;
        } else if !in_code {
            lines.push(line);
        }
    }
    lines
}

/// The targets of the page's inline links and images, `[text](target)`.
fn link_targets(text: &str) -> Vec<String> {
    let mut targets = Vec::new();
    for line in prose_lines(text) {
        let mut rest = line;
        while let Some(start) = rest.find("](") {
            let after = &rest[start + 2..];
            let Some(end) = after.find(')') else { break };
            targets.push(after[..end].to_string());
            rest = &after[end..];
        }
    }
    targets
}

/// GitHub's anchor for a heading: lower case, punctuation dropped, spaces as hyphens.
fn anchor(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || *c == ' ' || *c == '-' || *c == '_')
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

fn anchors(page: &Path) -> BTreeSet<String> {
    let text = std::fs::read_to_string(page).unwrap();
    prose_lines(&text)
        .into_iter()
        .filter(|line| line.starts_with('#'))
        .map(|line| anchor(line.trim_start_matches('#')))
        .collect()
}

#[test]
fn every_relative_link_resolves() {
    let mut broken = Vec::new();
    for page in pages() {
        let text = std::fs::read_to_string(&page).unwrap();
        let dir = page.parent().unwrap();
        for target in link_targets(&text) {
            if target.starts_with("http://") || target.starts_with("https://") {
                continue;
            }
            let (file, fragment) = match target.split_once('#') {
                Some((file, fragment)) => (file, Some(fragment)),
                None => (target.as_str(), None),
            };
            let resolved = if file.is_empty() {
                page.clone()
            } else {
                dir.join(file)
            };
            if !resolved.exists() {
                broken.push(format!("{}: {target} (no such file)", page.display()));
                continue;
            }
            if let Some(fragment) = fragment
                && !anchors(&resolved).contains(fragment)
            {
                broken.push(format!("{}: {target} (no such heading)", page.display()));
            }
        }
    }
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
}

#[test]
fn anchors_follow_github() {
    assert_eq!(anchor(" The C and C++ API"), "the-c-and-c-api");
    assert_eq!(
        anchor("The Embree backend (optional)"),
        "the-embree-backend-optional"
    );
    assert_eq!(anchor("Jobs and Dask"), "jobs-and-dask");
}

/// The `.rs` files docs/layout.md's first code block names: a tree whose lines are a name
/// (a folder ends in `/`; several files are separated by `, `), then its description after
/// two spaces or more, each line indented under the folder it is in.
fn layout_files() -> BTreeSet<String> {
    let text = std::fs::read_to_string(crate_dir().join("docs/layout.md")).unwrap();
    let block = text
        .split("```text\n")
        .nth(1)
        .and_then(|rest| rest.split("```").next())
        .expect("docs/layout.md has a text block");
    let mut folders: Vec<(usize, String)> = Vec::new();
    let mut files = BTreeSet::new();
    for line in block.lines() {
        let indent = line.len() - line.trim_start().len();
        let names = line.trim_start().split("  ").next().unwrap_or("");
        folders.retain(|(folder_indent, _)| *folder_indent < indent);
        let folder: String = folders.iter().map(|(_, name)| name.as_str()).collect();
        for name in names.split(", ") {
            let path = format!("{folder}{name}");
            if name.ends_with('/') {
                folders.push((indent, name.to_string()));
            } else if name.ends_with(".rs") {
                files.insert(path);
            }
        }
    }
    files
}

fn source_files(dir: &Path, files: &mut BTreeSet<String>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            source_files(&path, files);
        } else if path.extension().is_some_and(|e| e == "rs") {
            let relative = path.strip_prefix(crate_dir()).unwrap();
            files.insert(relative.to_string_lossy().replace('\\', "/"));
        }
    }
}

#[test]
fn the_layout_names_every_source_file() {
    let listed = layout_files();
    let mut present = BTreeSet::new();
    source_files(&crate_dir().join("src"), &mut present);
    let unlisted: Vec<_> = present.difference(&listed).collect();
    let gone: Vec<_> = listed.difference(&present).collect();
    assert!(
        unlisted.is_empty() && gone.is_empty(),
        "docs/layout.md does not list {unlisted:?} and lists {gone:?}, which do not exist"
    );
}
