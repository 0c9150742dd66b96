//! The README is a front door and the documentation holds together: `README.md` stays within
//! 300 lines and links every page of `docs/`, and every relative link in `README.md` and
//! `docs/**/*.md` resolves (the file exists and, for `page.md#anchor`, the anchor is one of the
//! page's headings as GitHub slugs them).

use std::collections::HashSet;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The Markdown files checked: the README and every page under `docs/`.
fn pages() -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        let mut entries: Vec<_> = std::fs::read_dir(dir)
            .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
            .map(|e| e.unwrap().path())
            .collect();
        entries.sort();
        for p in entries {
            if p.is_dir() {
                walk(&p, out);
            } else if p.extension().is_some_and(|x| x == "md") {
                out.push(p);
            }
        }
    }
    let mut out = vec![root().join("README.md")];
    walk(&root().join("docs"), &mut out);
    out
}

/// The lines of `text` outside fenced code blocks, numbered from 1.
fn prose(text: &str) -> Vec<(usize, &str)> {
    let mut fenced = false;
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        if line.starts_with("```") || line.starts_with("~~~") {
            fenced = !fenced;
        } else if !fenced {
            out.push((i + 1, line));
        }
    }
    out
}

/// GitHub's anchor of a heading: lower case, markup and punctuation dropped, spaces as `-`.
fn slug(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || *c == '-' || *c == ' ' || *c == '_')
        .filter(|c| *c != '_')
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

/// The anchors of a page's headings (a repeated heading gets `-1`, `-2`, … as on GitHub).
fn anchors(text: &str) -> HashSet<String> {
    let mut seen = std::collections::HashMap::<String, usize>::new();
    let mut out = HashSet::new();
    for (_, line) in prose(text) {
        if line.starts_with('#') {
            let base = slug(line.trim_start_matches('#'));
            let n = seen.entry(base.clone()).or_insert(0);
            out.insert(if *n == 0 {
                base.clone()
            } else {
                format!("{base}-{n}")
            });
            *n += 1;
        }
    }
    out
}

/// The targets of the inline links `[text](target)` and images `![alt](target)` of a line.
fn link_targets(line: &str) -> Vec<&str> {
    let mut out = Vec::new();
    let mut rest = line;
    while let Some(i) = rest.find("](") {
        let after = &rest[i + 2..];
        let end = after.find(')').unwrap_or(after.len());
        let target = &after[..end];
        if !target.is_empty() && !target.contains(char::is_whitespace) {
            out.push(target);
        }
        rest = &after[end..];
    }
    out
}

#[test]
fn every_relative_link_resolves() {
    let mut broken = Vec::new();
    for page in pages() {
        let text = std::fs::read_to_string(&page).unwrap();
        for (no, line) in prose(&text) {
            for target in link_targets(line) {
                if target.contains("://") || target.starts_with("mailto:") {
                    continue;
                }
                let (name, frag) = target.split_once('#').unwrap_or((target, ""));
                let dest = if name.is_empty() {
                    page.clone()
                } else {
                    page.parent().unwrap().join(name)
                };
                let at = format!(
                    "{}:{no}: {target}",
                    page.strip_prefix(root()).unwrap().display()
                );
                if !dest.exists() {
                    broken.push(format!("missing file   {at}"));
                } else if !frag.is_empty()
                    && dest.extension().is_some_and(|x| x == "md")
                    && !anchors(&std::fs::read_to_string(&dest).unwrap()).contains(frag)
                {
                    broken.push(format!("missing anchor {at}"));
                }
            }
        }
    }
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
}

#[test]
fn readme_is_a_front_door_linking_every_page() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let lines = readme.lines().count();
    assert!(lines <= 300, "README.md has {lines} lines (at most 300)");
    let start = readme.lines().take(6).collect::<Vec<_>>().join("\n");
    assert!(
        start.contains("cargo run --release -- table1")
            && start.contains("cargo test --workspace --release"),
        "README.md starts with the main job and the tests:\n{start}"
    );
    for page in pages().iter().skip(1) {
        let rel = page
            .strip_prefix(root())
            .unwrap()
            .to_string_lossy()
            .into_owned();
        assert!(
            readme.contains(&format!("({rel})")) || readme.contains(&format!("({rel}#")),
            "README.md does not link {rel}"
        );
    }
}

#[test]
fn slugs_follow_github() {
    assert_eq!(
        slug(" Two conventions, one meaning"),
        "two-conventions-one-meaning"
    );
    assert_eq!(slug(" `count` and Table 1"), "count-and-table-1");
    let text = "# A\n```\n# not a heading\n```\n## A\n";
    let a = anchors(text);
    assert!(a.contains("a") && a.contains("a-1") && !a.contains("not-a-heading"));
}
