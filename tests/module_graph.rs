//! The structure shows the pipeline: dependencies run one way.
//!
//! - **Crates** (`cargo metadata`): each library crate depends only on the crates before it in
//!   model → dynamics → trace → codegen → macros, with the scene format beside the tracer (the
//!   macros and the simulator read scenes through it) and the simulator after it; only the
//!   facade depends on the CLI (an optional dependency, for the `kanegen` binary).
//! - **Modules**: within every crate, no module uses a module that uses it back. Every path that
//!   starts with `crate::`, `super::` or `self::` — in `use` items and in code — is resolved to
//!   the longest module path it names; a `mod` declaration is not a use, and the crate root
//!   (`lib.rs`, which only declares modules and re-exports) is not counted as a target, so a
//!   re-export does not make a cycle. Code under `#[cfg(test)]` is skipped. The check fails
//!   with every strongly connected set of modules it finds.

use serde_json::Value;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use syn::visit::Visit;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The crates of the workspace and where their sources are.
const CRATES: [(&str, &str); 10] = [
    ("kanegen", "src"),
    ("kanegen-model", "model/src"),
    ("kanegen-dynamics", "dynamics/src"),
    ("kanegen-trace", "trace/src"),
    ("kanegen-codegen", "codegen/src"),
    ("kanegen-scene", "scene/src"),
    ("kanegen-macros", "macros/src"),
    ("kanegen-generated", "generated/src"),
    ("kanegen-sim", "sim/src"),
    ("kanegen-cli", "cli/src"),
];

/// Allowed normal dependencies on workspace crates, per crate.
fn allowed(name: &str) -> &'static [&'static str] {
    match name {
        "kanegen-model" | "kanegen-generated" => &[],
        "kanegen-dynamics" => &["kanegen-model"],
        "kanegen-trace" | "kanegen-scene" => &["kanegen-model", "kanegen-dynamics"],
        "kanegen-sim" => &["kanegen-model", "kanegen-dynamics", "kanegen-scene"],
        "kanegen-codegen" => &["kanegen-model", "kanegen-dynamics", "kanegen-trace"],
        // `scene!` reads scenes with the simulator's parser, not the simulator.
        "kanegen-macros" => &["kanegen-codegen", "kanegen-scene"],
        "kanegen-cli" => &[
            "kanegen-model",
            "kanegen-dynamics",
            "kanegen-trace",
            "kanegen-codegen",
            "kanegen-sim",
            "kanegen-generated",
        ],
        "kanegen" => &[
            "kanegen-macros",
            "kanegen-model",
            "kanegen-dynamics",
            "kanegen-trace",
            "kanegen-codegen",
            "kanegen-sim",
            "kanegen-cli",
        ],
        other => panic!("unknown crate {other}"),
    }
}

#[test]
fn crate_dependencies_follow_the_pipeline() {
    let out = std::process::Command::new(std::env::var("CARGO").unwrap_or("cargo".into()))
        .current_dir(root())
        .args([
            "metadata",
            "--format-version",
            "1",
            "--no-deps",
            "--offline",
        ])
        .output()
        .expect("cargo metadata");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let meta: Value = serde_json::from_slice(&out.stdout).unwrap();
    let names: BTreeSet<&str> = CRATES.iter().map(|c| c.0).collect();
    let mut seen = BTreeSet::new();
    for pkg in meta["packages"].as_array().unwrap() {
        let name = pkg["name"].as_str().unwrap();
        seen.insert(name.to_string());
        for dep in pkg["dependencies"].as_array().unwrap() {
            let d = dep["name"].as_str().unwrap();
            let normal = dep["kind"].is_null();
            if !names.contains(d) || !normal {
                continue;
            }
            assert!(
                allowed(name).contains(&d),
                "{name} must not depend on {d} (the pipeline runs model → dynamics → trace → \
                 codegen → macros; scene beside trace, sim after it; the CLI last)"
            );
            if d == "kanegen-cli" {
                assert!(
                    dep["optional"].as_bool().unwrap(),
                    "the CLI dependency is optional"
                );
            }
        }
    }
    for (name, _) in CRATES {
        assert!(seen.contains(name), "{name} is not a workspace member");
    }
}

/// `a::b::c` module paths of a crate's files.
fn modules(src: &Path) -> BTreeMap<String, PathBuf> {
    let mut out = BTreeMap::new();
    let mut stack = vec![src.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for e in std::fs::read_dir(&dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "rs") {
                let rel = p.strip_prefix(src).unwrap().with_extension("");
                let mut parts: Vec<String> = rel
                    .components()
                    .map(|c| c.as_os_str().to_string_lossy().into_owned())
                    .collect();
                if matches!(
                    parts.last().map(String::as_str),
                    Some("mod" | "lib" | "main")
                ) {
                    parts.pop();
                }
                out.insert(parts.join("::"), p);
            }
        }
    }
    out
}

/// The module-path prefixes a file's code names, resolved from `crate::`, `super::`, `self::`.
struct Uses<'a> {
    here: Vec<String>,
    known: &'a BTreeMap<String, PathBuf>,
    found: BTreeSet<String>,
}

impl Uses<'_> {
    fn resolve(&mut self, segments: &[String]) {
        let Some(first) = segments.first() else {
            return;
        };
        let mut base: Vec<String> = match first.as_str() {
            "crate" => Vec::new(),
            "self" => self.here.clone(),
            "super" => {
                let mut b = self.here.clone();
                let mut rest = segments;
                while rest.first().map(String::as_str) == Some("super") {
                    b.pop();
                    rest = &rest[1..];
                }
                b.extend(rest.iter().cloned());
                return self.longest(b);
            }
            _ => return,
        };
        base.extend(segments[1..].iter().cloned());
        self.longest(base);
    }

    fn longest(&mut self, path: Vec<String>) {
        for k in (1..=path.len()).rev() {
            let m = path[..k].join("::");
            if self.known.contains_key(&m) {
                self.found.insert(m);
                return;
            }
        }
    }
}

fn use_paths(tree: &syn::UseTree, prefix: &mut Vec<String>, out: &mut Vec<Vec<String>>) {
    match tree {
        syn::UseTree::Path(p) => {
            prefix.push(p.ident.to_string());
            use_paths(&p.tree, prefix, out);
            prefix.pop();
        }
        syn::UseTree::Name(n) => {
            let mut v = prefix.clone();
            v.push(n.ident.to_string());
            out.push(v);
        }
        syn::UseTree::Rename(r) => {
            let mut v = prefix.clone();
            v.push(r.ident.to_string());
            out.push(v);
        }
        syn::UseTree::Glob(_) => out.push(prefix.clone()),
        syn::UseTree::Group(g) => {
            for t in &g.items {
                use_paths(t, prefix, out);
            }
        }
    }
}

fn is_test_cfg(attrs: &[syn::Attribute]) -> bool {
    attrs.iter().any(|a| {
        a.path().is_ident("cfg")
            && a.meta
                .require_list()
                .is_ok_and(|l| l.tokens.to_string().contains("test"))
    })
}

impl<'ast> Visit<'ast> for Uses<'_> {
    fn visit_item_use(&mut self, u: &'ast syn::ItemUse) {
        let mut out = Vec::new();
        use_paths(&u.tree, &mut Vec::new(), &mut out);
        for p in out {
            self.resolve(&p);
        }
    }
    fn visit_path(&mut self, p: &'ast syn::Path) {
        let segs: Vec<String> = p.segments.iter().map(|s| s.ident.to_string()).collect();
        self.resolve(&segs);
        syn::visit::visit_path(self, p);
    }
    fn visit_item_mod(&mut self, m: &'ast syn::ItemMod) {
        if !is_test_cfg(&m.attrs) {
            syn::visit::visit_item_mod(self, m);
        }
    }
    fn visit_item_fn(&mut self, f: &'ast syn::ItemFn) {
        if !is_test_cfg(&f.attrs) {
            syn::visit::visit_item_fn(self, f);
        }
    }
}

/// Strongly connected sets of more than one module (Tarjan).
fn cycles(graph: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    struct T<'g> {
        g: &'g BTreeMap<String, BTreeSet<String>>,
        index: BTreeMap<String, usize>,
        low: BTreeMap<String, usize>,
        stack: Vec<String>,
        on: BTreeSet<String>,
        next: usize,
        out: Vec<Vec<String>>,
    }
    impl T<'_> {
        fn visit(&mut self, v: &str) {
            self.index.insert(v.into(), self.next);
            self.low.insert(v.into(), self.next);
            self.next += 1;
            self.stack.push(v.into());
            self.on.insert(v.into());
            for w in self.g.get(v).into_iter().flatten() {
                if !self.index.contains_key(w) {
                    self.visit(w);
                    let l = self.low[v].min(self.low[w]);
                    self.low.insert(v.into(), l);
                } else if self.on.contains(w) {
                    let l = self.low[v].min(self.index[w]);
                    self.low.insert(v.into(), l);
                }
            }
            if self.low[v] == self.index[v] {
                let mut scc = Vec::new();
                loop {
                    let w = self.stack.pop().unwrap();
                    self.on.remove(&w);
                    let done = w == v;
                    scc.push(w);
                    if done {
                        break;
                    }
                }
                if scc.len() > 1 {
                    scc.sort();
                    self.out.push(scc);
                }
            }
        }
    }
    let mut t = T {
        g: graph,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on: BTreeSet::new(),
        next: 0,
        out: Vec::new(),
    };
    for v in graph.keys() {
        if !t.index.contains_key(v) {
            t.visit(v);
        }
    }
    t.out
}

/// The module graph of one crate: `module → modules it uses` (crate root excluded as target).
fn module_graph(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let known = modules(src);
    let mut graph = BTreeMap::new();
    for (m, file) in &known {
        let text = std::fs::read_to_string(file).unwrap();
        let parsed = syn::parse_file(&text).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        let here: Vec<String> = if m.is_empty() {
            Vec::new()
        } else {
            m.split("::").map(String::from).collect()
        };
        let mut v = Uses {
            here,
            known: &known,
            found: BTreeSet::new(),
        };
        v.visit_file(&parsed);
        let targets: BTreeSet<String> = v
            .found
            .into_iter()
            .filter(|t| t != m && !t.is_empty())
            .collect();
        graph.insert(m.clone(), targets);
    }
    graph
}

#[test]
fn no_module_uses_a_module_that_uses_it_back() {
    let mut edges = 0;
    for (name, src) in CRATES {
        let g = module_graph(&root().join(src));
        edges += g.values().map(BTreeSet::len).sum::<usize>();
        let c = cycles(&g);
        assert!(c.is_empty(), "{name}: module cycles {c:?}");
    }
    // The checker sees the code: the crates use each other's modules hundreds of times.
    assert!(edges > 50, "only {edges} module uses found");
}

/// The checker finds a cycle when there is one (a two-file crate written on the fly).
#[test]
fn the_checker_finds_a_planted_cycle() {
    let dir = std::env::temp_dir().join(format!("kanegen-modgraph-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("a")).unwrap();
    std::fs::write(dir.join("lib.rs"), "mod a;\nmod b;\n").unwrap();
    std::fs::write(
        dir.join("a/mod.rs"),
        "pub mod c;\npub fn f() { crate::b::g() }\n",
    )
    .unwrap();
    std::fs::write(dir.join("a/c.rs"), "pub fn h() {}\n").unwrap();
    std::fs::write(
        dir.join("b.rs"),
        "use super::a::c::h;\npub fn g() { h(); crate::a::f() }\n",
    )
    .unwrap();
    let g = module_graph(&dir);
    let c = cycles(&g);
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(c, vec![vec!["a".to_string(), "b".to_string()]], "{g:?}");
}
