//! The workspace's two graphs, held as ARCHITECTURE.md draws them:
//!
//! * the crates: each crate's `[dependencies]` on the workspace's crates must be among those
//!   [`ALLOWED`] lists for it (so the ground truth, `clothbake-truth`, and the analytic model,
//!   `clothbake-core`, never see each other, and the loader never sees the model);
//! * the modules of every crate: each top-level module (a file `src/m.rs`, or a folder `src/m/`
//!   with its files) depends on the modules its code names by `crate::m` paths (`use` lines,
//!   grouped `use crate::{a, b}`, inline paths); the graph of those must have no cycle.
//!   Comments and `#[cfg(test)] mod` blocks do not count (a test module may reach anywhere).

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// Every crate of the workspace by folder under its root, with the workspace crates its
/// `[dependencies]` may name (dev-dependencies are free: the model's tests take the truth).
const ALLOWED: [(&str, &[&str]); 14] = [
    ("crates/clothbake-bsdf", &[]),
    ("crates/clothbake-fabric", &["clothbake-bsdf"]),
    ("crates/clothbake-point", &["clothbake-bsdf"]),
    (
        "crates/clothbake-truth",
        &["clothbake-bsdf", "clothbake-fabric"],
    ),
    (
        "crates/clothbake-core",
        &["clothbake-bsdf", "clothbake-fabric", "clothbake-point"],
    ),
    (
        "crates/clothbake-loader",
        &["clothbake-bsdf", "clothbake-point"],
    ),
    ("crates/clothbake-capi", &["clothbake-loader"]),
    (
        "crates/clothbake-bake",
        &["clothbake-core", "clothbake-truth", "clothbake-loader"],
    ),
    (
        "crates/clothbake-export",
        &["clothbake-core", "clothbake-loader"],
    ),
    (
        "crates/clothbake-render",
        &[
            "clothbake-bake",
            "clothbake-core",
            "clothbake-truth",
            "clothbake-loader",
        ],
    ),
    (
        "crates/clothbake-py",
        &[
            "clothbake-core",
            "clothbake-truth",
            "clothbake-loader",
            "clothbake-bake",
        ],
    ),
    (
        "crates/clothbake",
        &[
            "clothbake-core",
            "clothbake-truth",
            "clothbake-loader",
            "clothbake-bake",
            "clothbake-export",
            "clothbake-render",
        ],
    ),
    (
        "xtask",
        &[
            "clothbake-bake",
            "clothbake-render",
            "clothbake-core",
            "clothbake-truth",
            "clothbake-loader",
            "clothbake-export",
            "clothbake-tests",
        ],
    ),
    (
        "tests",
        &[
            "clothbake-core",
            "clothbake-truth",
            "clothbake-bake",
            "clothbake-export",
            "clothbake-loader",
        ],
    ),
];

/// The workspace crates (`clothbake-*`) a Cargo.toml names in its `[dependencies]` sections
/// (`[dependencies]` and `[target.'...'.dependencies]`), not its dev- or build-dependencies.
fn workspace_dependencies(manifest: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    let mut in_deps = false;
    for line in manifest.lines() {
        let t = line.trim();
        if t.starts_with('[') {
            in_deps = t == "[dependencies]"
                || (t.starts_with("[target.") && t.ends_with(".dependencies]"));
            continue;
        }
        if in_deps && t.starts_with("clothbake-") {
            let name: String = t
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '-' || *c == '_')
                .collect();
            out.insert(name);
        }
    }
    out
}

/// A module graph: each module and the modules it names.
type Graph = BTreeMap<String, BTreeSet<String>>;

/// The lines of `text` that are code: without comment lines, trailing ` //` comments and the
/// `#[cfg(test)] mod ... { ... }` blocks (to the `}` at the `mod` line's indentation, as
/// rustfmt writes it).
fn code(text: &str) -> String {
    let lines: Vec<&str> = text.lines().collect();
    let mut out = String::new();
    let mut k = 0;
    while k < lines.len() {
        let line = lines[k];
        let t = line.trim_start();
        k += 1;
        if t.starts_with("#[cfg(test)]") {
            let m = lines.get(k).copied().unwrap_or("");
            if m.trim_start().starts_with("mod ") && m.trim_end().ends_with('{') {
                let close = format!("{}}}", &m[..m.len() - m.trim_start().len()]);
                while k < lines.len() && lines[k] != close {
                    k += 1;
                }
                k += 1;
                continue;
            }
        }
        if t.starts_with("//") {
            continue;
        }
        out.push_str(line.split(" //").next().unwrap_or(""));
        out.push('\n');
    }
    out
}

/// The names `code` reaches by `crate::` paths: the first segment of each path, and of each
/// path in a group `crate::{a::X, b}`.
fn named(code: &str) -> BTreeSet<String> {
    let ident = |s: &str| -> String {
        s.trim_start()
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect()
    };
    let mut out = BTreeSet::new();
    for (at, _) in code.match_indices("crate::") {
        // Not the end of a longer name (`clothbake_crate::`), nor a macro's `$crate::`.
        let before = code[..at].chars().next_back();
        if before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == '$') {
            continue;
        }
        let rest = &code[at + "crate::".len()..];
        if let Some(group) = rest.strip_prefix('{') {
            // The group's top-level paths, split at commas outside nested braces.
            let (mut depth, mut start) = (0usize, 0usize);
            for (k, c) in group.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => {
                        out.insert(ident(&group[start..k]));
                        break;
                    }
                    '}' => depth -= 1,
                    ',' if depth == 0 => {
                        out.insert(ident(&group[start..k]));
                        start = k + 1;
                    }
                    _ => {}
                }
            }
        } else {
            out.insert(ident(rest));
        }
    }
    out.remove("");
    out
}

/// The module graph of the crate whose sources are in `src`: its top-level modules (not the
/// crate root, `lib.rs` or `main.rs`) and the others each names.
fn graph_of(src: &Path) -> Graph {
    let mut files: BTreeMap<String, Vec<std::path::PathBuf>> = BTreeMap::new();
    let mut stack = vec![src.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for e in std::fs::read_dir(&dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
                continue;
            }
            if p.extension().is_none_or(|x| x != "rs") {
                continue;
            }
            let rel = p.strip_prefix(src).unwrap();
            let top = rel
                .components()
                .next()
                .unwrap()
                .as_os_str()
                .to_string_lossy();
            let module = top.strip_suffix(".rs").unwrap_or(&top).to_string();
            if module != "lib" && module != "main" {
                files.entry(module).or_default().push(p);
            }
        }
    }
    let modules: BTreeSet<String> = files.keys().cloned().collect();
    files
        .iter()
        .map(|(m, paths)| {
            let deps = paths
                .iter()
                .flat_map(|p| named(&code(&std::fs::read_to_string(p).unwrap())))
                .filter(|d| d != m && modules.contains(d))
                .collect();
            (m.clone(), deps)
        })
        .collect()
}

/// A cycle of `g` as its modules in order, the first repeated at the end; `None` when the
/// graph has none.
fn cycle(g: &Graph) -> Option<Vec<String>> {
    // Depth-first, iteratively: 1 on the current path, 2 done.
    let mut state: BTreeMap<&str, u8> = BTreeMap::new();
    for start in g.keys() {
        if state.contains_key(start.as_str()) {
            continue;
        }
        let mut path: Vec<(&str, Vec<&str>)> = Vec::new();
        state.insert(start, 1);
        path.push((start, g[start].iter().map(String::as_str).rev().collect()));
        while let Some((m, todo)) = path.last_mut() {
            let m = *m;
            match todo.pop() {
                Some(d) => match state.get(d) {
                    Some(1) => {
                        let at = path.iter().position(|(x, _)| *x == d).unwrap();
                        let mut c: Vec<String> =
                            path[at..].iter().map(|(x, _)| x.to_string()).collect();
                        c.push(d.to_string());
                        return Some(c);
                    }
                    Some(_) => {}
                    None => {
                        state.insert(d, 1);
                        let next = g
                            .get(d)
                            .map_or(Vec::new(), |s| s.iter().map(String::as_str).rev().collect());
                        path.push((d, next));
                    }
                },
                None => {
                    state.insert(m, 2);
                    path.pop();
                }
            }
        }
    }
    None
}

#[test]
fn every_crate_depends_only_on_the_crates_allowed_it() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    // Every crate of the workspace is listed: a new one must say what it may see.
    let workspace = std::fs::read_to_string(root.join("Cargo.toml")).unwrap();
    let members = workspace
        .lines()
        .find(|l| l.starts_with("members"))
        .expect("the workspace's members");
    let listed = members.matches('"').count() / 2;
    assert_eq!(
        listed,
        ALLOWED.len(),
        "ALLOWED lists every member: {members}"
    );
    let mut edges = 0;
    for (krate, allowed) in ALLOWED {
        assert!(
            members.contains(&format!("\"{krate}\"")),
            "{krate} is not a member"
        );
        let manifest = std::fs::read_to_string(root.join(krate).join("Cargo.toml")).unwrap();
        for dep in workspace_dependencies(&manifest) {
            assert!(
                allowed.contains(&dep.as_str()),
                "{krate} depends on {dep}, which ARCHITECTURE.md's layers do not allow it \
                 (move what it needs into a crate below both, or change the map first)"
            );
            edges += 1;
        }
    }
    assert!(edges >= 30, "{edges} dependencies found");
}

#[test]
fn the_dependency_reader_sees_what_it_should() {
    let manifest = "\
[package]
name = \"clothbake-x\"
[dependencies]
clothbake-core.workspace = true
clothbake-truth = { path = \"../t\" }
serde = \"1\"
[target.'cfg(unix)'.dependencies]
clothbake-loader.workspace = true
[dev-dependencies]
clothbake-point.workspace = true
[build-dependencies]
clothbake-bsdf.workspace = true
";
    let want: BTreeSet<String> = ["clothbake-core", "clothbake-truth", "clothbake-loader"]
        .map(String::from)
        .into();
    assert_eq!(workspace_dependencies(manifest), want);
}

#[test]
fn no_crates_modules_form_a_cycle() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut modules = 0;
    for (krate, _) in ALLOWED {
        let g = graph_of(&root.join(krate).join("src"));
        modules += g.len();
        if let Some(c) = cycle(&g) {
            panic!(
                "{krate}: its modules depend on each other in a circle: {} (ARCHITECTURE.md \
                 lists the layers; move what both sides need into a module below them)",
                c.join(" -> ")
            );
        }
    }
    assert!(modules >= 100, "{modules} modules found");
}

#[test]
fn the_scanner_reads_every_kind_of_path_and_finds_cycles() {
    let text = "\
use crate::grid::Grid;
use crate::{axis::{Axis, Span}, error::TableError,
    nodes};
// use crate::commented::X;
let x = crate::inline::f(); // crate::trailing
let y = clothbake_crate::not_ours; $crate::macro_path;
pub(crate) fn f() {}
#[cfg(test)]
fn only_in_tests() -> crate::test_item::X {}
#[cfg(test)]
mod tests {
    use crate::in_tests::X;
    fn f() {
        crate::in_tests_too::g();
    }
}
use crate::after_tests::Y;
";
    let want: BTreeSet<String> = [
        "grid",
        "axis",
        "error",
        "nodes",
        "inline",
        "test_item",
        "after_tests",
    ]
    .map(String::from)
    .into();
    assert_eq!(named(&code(text)), want);

    let g = |edges: &[(&str, &str)]| {
        let mut g = Graph::new();
        for (a, b) in edges {
            g.entry(a.to_string()).or_default().insert(b.to_string());
            g.entry(b.to_string()).or_default();
        }
        g
    };
    assert_eq!(cycle(&g(&[("a", "b"), ("b", "c"), ("a", "c")])), None);
    let c = cycle(&g(&[("a", "b"), ("b", "c"), ("c", "d"), ("d", "b")])).unwrap();
    assert_eq!(c, ["b", "c", "d", "b"]);
    assert!(cycle(&g(&[("x", "y"), ("y", "x")])).is_some());
}
