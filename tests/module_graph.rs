//! The modules of `src/` depend on each other one way: no module names, in code that is not
//! test-only, a module that names it back, directly or through others. At each level of the
//! module tree the nodes are the child modules (each with everything under it) and the
//! parent's own file, so `accel` and `scene` may not name each other, nor `mlt/pssmlt` and
//! `mlt/path_space`, nor `integrators/mod.rs` a child that uses its shared code.
//!
//! A module names another through `use` items and paths in its code (`crate::`, `super::`,
//! `self::` and child-relative paths); re-exports (`pub use`) only shape an interface and do
//! not count, nor do paths inside macro invocations (syn does not parse them).
//!
//! Runs in under a second on 2 cores (`cargo test --test module_graph`).

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
use syn::visit::Visit;

type Module = Vec<String>;

/// A dependency of one module on another, found in a file.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
struct Edge {
    from: Module,
    to: Module,
}

/// The dependencies, each with the first path that makes it (for the failure message).
type Edges = BTreeMap<Edge, String>;

/// A set of modules that name each other in a circle, at one level of the tree (`level`),
/// and the dependencies that close it (`from -> to: path`).
#[derive(Debug)]
#[allow(dead_code)] // Read through Debug, in the failure message.
struct Cycle {
    level: String,
    nodes: Vec<String>,
    edges: Vec<String>,
}

/// The module a source file of `src/` defines (`lib.rs` is the crate root).
fn module_of(relative: &Path) -> Module {
    let mut parts: Vec<String> = relative
        .with_extension("")
        .iter()
        .map(|p| p.to_string_lossy().into_owned())
        .collect();
    if matches!(parts.last().map(String::as_str), Some("mod" | "lib")) {
        parts.pop();
    }
    parts
}

fn read_sources(dir: &Path, root: &Path, out: &mut Vec<(Module, String)>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        let relative = path.strip_prefix(root).unwrap();
        if path.is_dir() {
            // The command-line binary is a separate crate.
            if relative != Path::new("bin") {
                read_sources(&path, root, out);
            }
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push((module_of(relative), std::fs::read_to_string(&path).unwrap()));
        }
    }
}

fn is_test_only(attrs: &[syn::Attribute]) -> bool {
    attrs.iter().any(|a| {
        a.path().is_ident("cfg")
            && a.meta.require_list().is_ok_and(|list| {
                list.tokens
                    .to_string()
                    .split(|c: char| !c.is_alphanumeric() && c != '_')
                    .any(|word| word == "test")
            })
    })
}

fn item_attrs(item: &syn::Item) -> &[syn::Attribute] {
    use syn::Item;
    match item {
        Item::Const(i) => &i.attrs,
        Item::Enum(i) => &i.attrs,
        Item::ExternCrate(i) => &i.attrs,
        Item::Fn(i) => &i.attrs,
        Item::ForeignMod(i) => &i.attrs,
        Item::Impl(i) => &i.attrs,
        Item::Macro(i) => &i.attrs,
        Item::Mod(i) => &i.attrs,
        Item::Static(i) => &i.attrs,
        Item::Struct(i) => &i.attrs,
        Item::Trait(i) => &i.attrs,
        Item::TraitAlias(i) => &i.attrs,
        Item::Type(i) => &i.attrs,
        Item::Union(i) => &i.attrs,
        Item::Use(i) => &i.attrs,
        _ => &[],
    }
}

/// The paths a file names outside test-only code, each with the module it is named in
/// (an inline module's own path).
struct Names {
    module: Module,
    paths: Vec<(Module, Vec<String>)>,
}

impl Names {
    fn add_use_tree(&mut self, prefix: &mut Vec<String>, tree: &syn::UseTree) {
        match tree {
            syn::UseTree::Path(p) => {
                prefix.push(p.ident.to_string());
                self.add_use_tree(prefix, &p.tree);
                prefix.pop();
            }
            syn::UseTree::Name(n) => self.add(prefix, Some(n.ident.to_string())),
            syn::UseTree::Rename(r) => self.add(prefix, Some(r.ident.to_string())),
            syn::UseTree::Glob(_) => self.add(prefix, None),
            syn::UseTree::Group(g) => {
                for tree in &g.items {
                    self.add_use_tree(prefix, tree);
                }
            }
        }
    }

    fn add(&mut self, prefix: &[String], last: Option<String>) {
        let mut path = prefix.to_vec();
        // `use a::b::{self}` names a::b.
        path.extend(last.filter(|l| l != "self"));
        self.paths.push((self.module.clone(), path));
    }
}

impl<'ast> Visit<'ast> for Names {
    fn visit_item(&mut self, item: &'ast syn::Item) {
        if is_test_only(item_attrs(item)) {
            return;
        }
        match item {
            syn::Item::Use(u) => {
                if matches!(u.vis, syn::Visibility::Inherited) {
                    self.add_use_tree(&mut Vec::new(), &u.tree);
                }
            }
            syn::Item::Mod(m) if m.content.is_some() => {
                self.module.push(m.ident.to_string());
                syn::visit::visit_item(self, item);
                self.module.pop();
            }
            _ => syn::visit::visit_item(self, item),
        }
    }

    fn visit_impl_item(&mut self, item: &'ast syn::ImplItem) {
        let attrs = match item {
            syn::ImplItem::Fn(f) => &f.attrs[..],
            syn::ImplItem::Const(c) => &c.attrs[..],
            _ => &[],
        };
        if !is_test_only(attrs) {
            syn::visit::visit_impl_item(self, item);
        }
    }

    /// `pub(super)` and `pub(in path)` say who may see an item, not what it uses.
    fn visit_visibility(&mut self, _: &'ast syn::Visibility) {}

    fn visit_path(&mut self, path: &'ast syn::Path) {
        // A path of one segment is a local name or an item in scope, never a module (a
        // variable may share a module's name).
        if path.segments.len() > 1 {
            let segments = path.segments.iter().map(|s| s.ident.to_string()).collect();
            self.paths.push((self.module.clone(), segments));
        }
        syn::visit::visit_path(self, path);
    }
}

/// The module `path`, named in `module`, points into: the longest known module it starts
/// with, or `None` for paths into other crates or to `module`'s own items.
fn resolve(modules: &BTreeSet<Module>, module: &Module, path: &[String]) -> Option<Module> {
    let (mut base, rest) = match path.first().map(String::as_str) {
        Some("crate") => (Vec::new(), &path[1..]),
        Some("self") => (module.clone(), &path[1..]),
        Some("super") => {
            let mut base = module.clone();
            let mut rest = path;
            while rest.first().is_some_and(|s| s == "super") {
                base.pop();
                rest = &rest[1..];
            }
            (base, rest)
        }
        Some(first) => {
            let mut child = module.clone();
            child.push(first.to_owned());
            if !modules.contains(&child) {
                return None;
            }
            (module.clone(), path)
        }
        None => return None,
    };
    for segment in rest {
        base.push(segment.clone());
        if !modules.contains(&base) {
            base.pop();
            break;
        }
    }
    Some(base)
}

/// The module-to-module dependencies of the sources.
fn edges(sources: &[(Module, String)]) -> Edges {
    let modules: BTreeSet<Module> = sources.iter().map(|(m, _)| m.clone()).collect();
    let mut edges = Edges::new();
    for (module, text) in sources {
        let file = syn::parse_file(text).unwrap_or_else(|e| panic!("{module:?}: {e}"));
        let mut names = Names {
            module: module.clone(),
            paths: Vec::new(),
        };
        names.visit_file(&file);
        for (named_in, path) in &names.paths {
            let Some(to) = resolve(&modules, named_in, path) else {
                continue;
            };
            if &to != module {
                let edge = Edge {
                    from: module.clone(),
                    to,
                };
                edges.entry(edge).or_insert_with(|| path.join("::"));
            }
        }
    }
    edges
}

/// The node of `module` at the level of the tree under `level`: its child of `level`, or
/// the level's own file.
fn node(level: &[String], module: &[String]) -> String {
    module
        .get(level.len())
        .cloned()
        .unwrap_or_else(|| "(own file)".to_owned())
}

/// Strongly connected sets of more than one node, at every level of the tree.
fn cycles(edges: &Edges) -> Vec<Cycle> {
    // Per level, the edges between its nodes.
    let mut levels: BTreeMap<Module, BTreeMap<(String, String), Vec<String>>> = BTreeMap::new();
    for (edge, path) in edges {
        let common = edge
            .from
            .iter()
            .zip(&edge.to)
            .take_while(|(a, b)| a == b)
            .count();
        let level = edge.from[..common].to_vec();
        let (a, b) = (node(&level, &edge.from), node(&level, &edge.to));
        levels
            .entry(level)
            .or_default()
            .entry((a, b))
            .or_default()
            .push(format!(
                "{} -> {}: {path}",
                edge.from.join("/"),
                edge.to.join("/")
            ));
    }
    let mut found = Vec::new();
    for (level, graph) in levels {
        let nodes: BTreeSet<&String> = graph.keys().flat_map(|(a, b)| [a, b]).collect();
        let reaches = |from: &String| {
            let mut seen = BTreeSet::from([from.clone()]);
            let mut stack = vec![from.clone()];
            while let Some(n) = stack.pop() {
                for (a, b) in graph.keys() {
                    if *a == n && seen.insert(b.clone()) {
                        stack.push(b.clone());
                    }
                }
            }
            seen
        };
        let reach: BTreeMap<&String, BTreeSet<String>> =
            nodes.iter().map(|&n| (n, reaches(n))).collect();
        let mut done = BTreeSet::new();
        for &n in &nodes {
            if done.contains(n) {
                continue;
            }
            let component: Vec<String> = nodes
                .iter()
                .filter(|&&m| reach[n].contains(m) && reach[m].contains(n))
                .map(|&m| m.clone())
                .collect();
            done.extend(component.iter().cloned());
            if component.len() > 1 {
                let edges = graph
                    .iter()
                    .filter(|((a, b), _)| component.contains(a) && component.contains(b))
                    .flat_map(|(_, e)| e.iter().cloned())
                    .collect();
                found.push(Cycle {
                    level: level.join("/"),
                    nodes: component,
                    edges,
                });
            }
        }
    }
    found
}

fn sources(files: &[(&str, &str)]) -> Vec<(Module, String)> {
    files
        .iter()
        .map(|(path, text)| (module_of(Path::new(path)), text.to_string()))
        .collect()
}

#[test]
fn src_modules_depend_one_way() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    read_sources(&root, &root, &mut files);
    let edges = edges(&files);
    // The parser sees the crate: the film names the filter, the scene the accel.
    let film_filter = Edge {
        from: vec!["film".into()],
        to: vec!["filter".into()],
    };
    assert!(edges.contains_key(&film_filter), "{edges:#?}");
    let cycles = cycles(&edges);
    assert!(
        cycles.is_empty(),
        "modules that name each other (move what both need to a module below them):\n{cycles:#?}"
    );
}

/// The deliberate error: two modules naming each other are found, through a longer circle
/// and a parent's own file too; re-exports, test-only code, visibility restrictions and a
/// variable named like a module do not count.
#[test]
fn a_cycle_between_modules_is_found() {
    let files = sources(&[
        ("lib.rs", "pub mod a; pub mod b; pub use a::X;"),
        (
            "a.rs",
            "use crate::b::Y; pub(crate) struct X; pub(super) fn f() {}",
        ),
        (
            "b.rs",
            "pub struct Y; fn f() -> crate::a::X { crate::a::X }",
        ),
    ]);
    let found = cycles(&edges(&files));
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(found[0].nodes, ["a", "b"]);

    let files = sources(&[
        ("lib.rs", "pub mod a; pub mod b; pub mod c;"),
        ("a.rs", "use crate::b::Y;"),
        ("b.rs", "use crate::c::Z; pub struct Y;"),
        ("c.rs", "use crate::a; pub struct Z;"),
    ]);
    assert_eq!(cycles(&edges(&files))[0].nodes, ["a", "b", "c"]);

    let files = sources(&[
        (
            "m/mod.rs",
            "mod child; pub struct Shared; fn f() { child::g() }",
        ),
        ("m/child.rs", "use super::Shared; pub fn g() {}"),
    ]);
    assert_eq!(cycles(&edges(&files))[0].nodes, ["(own file)", "child"]);

    let files = sources(&[
        (
            "m/mod.rs",
            "mod child; pub use child::g; pub struct Shared; fn h(child: u8) -> u8 { child }",
        ),
        (
            "m/child.rs",
            "use super::Shared; pub fn g() {} #[cfg(test)] mod tests { use super::super::*; }",
        ),
        (
            "n.rs",
            "#[cfg(test)] use crate::m::g; use crate::m::Shared;",
        ),
    ]);
    assert!(cycles(&edges(&files)).is_empty());
}
