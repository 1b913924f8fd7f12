//! `cargo xtask layout`: the architecture's invariants that the compiler does not check
//! (docs/ARCHITECTURE.md, "Invariants"):
//!
//! - the modules of each host crate import one another without a cycle: among the children of
//!   any module (the crate root included), a path from one into another (`crate::`, `super::`
//!   or `self::`, through the parent's re-exports) is an edge, and the edges form no cycle (a
//!   parent may use its children, and a child its parent's own items);
//! - the library crate `hemi` depends on no CLI, terminal, serial or process crate and reads no
//!   environment variable;
//! - no function of a host crate is longer than [`MAX_FN_LINES`] lines, and the CLI's `main` no
//!   longer than [`MAX_MAIN_LINES`].

use crate::util::{cargo, root};
use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

/// The host crates, by folder.
const HOST_CRATES: [&str; 4] = ["host/hemi", "host/boards", "host/bench", "host/cli"];
/// Crates the library must not depend on.
const NOT_IN_LIBRARY: [&str; 4] = ["clap", "indicatif", "serialport", "ctrlc"];
/// The longest function allowed in a host crate.
const MAX_FN_LINES: usize = 150;
/// The longest `main` allowed in the CLI.
const MAX_MAIN_LINES: usize = 60;

/// Runs every check; the error lists every violation.
pub fn check() -> Result<(), String> {
    let mut problems = Vec::new();
    for krate in HOST_CRATES {
        let src = root().join(krate).join("src");
        let files = rust_files(&src);
        problems.extend(cycles(krate, &src, &files));
        for f in &files {
            problems.extend(long_functions(f));
        }
    }
    problems.extend(library_dependencies());
    problems.extend(library_environment());
    if problems.is_empty() {
        eprintln!("layout: host module graphs acyclic, library free of CLI/serial crates and environment variables, functions within {MAX_FN_LINES} lines");
        Ok(())
    } else {
        Err(problems.join("\n"))
    }
}

/// Every `.rs` file below `dir`.
fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let Ok(entries) = fs::read_dir(dir) else {
        return out;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            out.extend(rust_files(&p));
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
    out.sort();
    out
}

/// The module path of a file of `src`: `[]` for the crate root, `[a]` for `a.rs` or
/// `a/mod.rs`, `[a, b]` for `a/b.rs`.
fn module_path(src: &Path, file: &Path) -> Vec<String> {
    let Ok(rel) = file.strip_prefix(src) else {
        return Vec::new();
    };
    let mut parts: Vec<String> = rel
        .components()
        .filter_map(|c| c.as_os_str().to_str().map(str::to_string))
        .collect();
    let last = parts.pop().unwrap_or_default();
    let stem = last.strip_suffix(".rs").unwrap_or(&last).to_string();
    let root = parts.is_empty() && (stem == "lib" || stem == "main");
    if stem != "mod" && !root {
        parts.push(stem);
    }
    parts
}

/// Every path a source text names from inside its crate (`crate::…`, `super::…`, `self::…`),
/// made absolute from the module `here`, with `use` groups (`a::{b, c::{d}}`) expanded.
fn named_paths(text: &str, here: &[String]) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    for start in ["crate::", "super::", "self::"] {
        for (i, _) in text.match_indices(start) {
            if text[..i].ends_with(|c: char| c.is_alphanumeric() || c == '_' || c == ':') {
                continue; // e.g. `hemi_crate::`, or the second `super::` of `super::super::`
            }
            let mut rest = &text[i + start.len()..];
            let mut base: Vec<String> = match start {
                "crate::" => Vec::new(),
                "self::" => here.to_vec(),
                _ => here[..here.len().saturating_sub(1)].to_vec(),
            };
            while let Some(more) = rest.strip_prefix("super::") {
                base.pop();
                rest = more;
            }
            expand(rest, &base, &mut out);
        }
    }
    out
}

/// Expands the path (or `{…}` group) at the start of `rest` onto `base`.
fn expand(rest: &str, base: &[String], out: &mut Vec<Vec<String>>) {
    let mut path = base.to_vec();
    let mut s = rest;
    loop {
        if let Some(group) = s.strip_prefix('{') {
            for item in split_group(group) {
                expand(item.trim(), &path, out);
            }
            return;
        }
        let Some(name) = ident(s) else {
            break;
        };
        s = &s[name.len()..];
        path.push(name);
        match s.strip_prefix("::") {
            Some(more) => s = more,
            None => break,
        }
    }
    if path.len() > base.len() {
        out.push(path);
    }
}

/// The items of a `{…}` group (`group` starts after the `{`), split at its own commas.
fn split_group(group: &str) -> Vec<&str> {
    let (mut depth, mut from, mut items) = (0usize, 0usize, Vec::new());
    for (i, c) in group.char_indices() {
        match c {
            '{' => depth += 1,
            '}' if depth == 0 => {
                items.push(&group[from..i]);
                return items;
            }
            '}' => depth -= 1,
            ',' if depth == 0 => {
                items.push(&group[from..i]);
                from = i + 1;
            }
            _ => {}
        }
    }
    items.push(&group[from..]);
    items
}

fn ident(s: &str) -> Option<String> {
    let end = s
        .find(|c: char| !(c.is_alphanumeric() || c == '_'))
        .unwrap_or(s.len());
    (end > 0).then(|| s[..end].to_string())
}

/// The cycles among sibling modules of one crate (the children of one module, the crate root
/// included), one line each. A path into a module's re-export counts as a path into the child
/// it re-exports from; a parent may use its children, and a child its parent's own items.
fn cycles(krate: &str, src: &Path, files: &[PathBuf]) -> Vec<String> {
    let texts: Vec<(Vec<String>, String)> = files
        .iter()
        .map(|f| {
            let text = fs::read_to_string(f).unwrap_or_default();
            (module_path(src, f), strip_comments(strip_tests(&text)))
        })
        .collect();
    let modules: BTreeSet<Vec<String>> = texts.iter().map(|(m, _)| m.clone()).collect();
    let reexports = reexports(&texts, &modules);
    // parent module → its children's edges
    let mut graphs: BTreeMap<Vec<String>, BTreeMap<String, BTreeSet<String>>> = BTreeMap::new();
    for (from, text) in &texts {
        for path in named_paths(text, from) {
            let Some(to) = target_module(&path, &modules, &reexports) else {
                continue;
            };
            let common = from.iter().zip(&to).take_while(|(a, b)| a == b).count();
            if from.len() > common && to.len() > common {
                let graph = graphs.entry(from[..common].to_vec()).or_default();
                let edges = graph.entry(from[common].clone()).or_default();
                edges.insert(to[common].clone());
            }
        }
    }
    let mut out = Vec::new();
    for (parent, graph) in &graphs {
        let at = match parent.is_empty() {
            true => "the crate root".to_string(),
            false => parent.join("::"),
        };
        for c in find_cycles(graph) {
            out.push(format!(
                "{krate}: import cycle under {at}: {}",
                c.join(" → ")
            ));
        }
    }
    out
}

/// `pub use child::{A, B}` in a module: the item path `module::A` → the module `module::child`.
fn reexports(
    texts: &[(Vec<String>, String)],
    modules: &BTreeSet<Vec<String>>,
) -> BTreeMap<Vec<String>, Vec<String>> {
    let mut map = BTreeMap::new();
    for (here, text) in texts {
        for statement in text.split(';') {
            let Some(rest) = statement.trim().strip_prefix("pub use ") else {
                continue;
            };
            let rest = rest.strip_prefix("self::").unwrap_or(rest);
            let mut paths = Vec::new();
            expand(rest, here, &mut paths);
            for p in paths {
                let child = p[..(here.len() + 1).min(p.len())].to_vec();
                let (Some(item), true) = (p.last(), modules.contains(&child)) else {
                    continue;
                };
                let mut key = here.clone();
                key.push(item.clone());
                if child.len() == here.len() + 1 && !modules.contains(&key) {
                    map.insert(key, child);
                }
            }
        }
    }
    map
}

/// The module a named path lands in: its longest prefix that is a module, following a
/// re-export where the path meets one.
fn target_module(
    path: &[String],
    modules: &BTreeSet<Vec<String>>,
    reexports: &BTreeMap<Vec<String>, Vec<String>>,
) -> Option<Vec<String>> {
    let mut best = None;
    for n in 1..=path.len() {
        let prefix = path[..n].to_vec();
        if modules.contains(&prefix) {
            best = Some(prefix);
        } else {
            if let Some(child) = reexports.get(&prefix) {
                best = Some(child.clone());
            }
            break;
        }
    }
    best
}

/// Source text without its `#[cfg(test)]` module (by convention the file's last item): its
/// `super::` paths are one level deeper than the file's, and tests are not the architecture.
fn strip_tests(text: &str) -> &str {
    match text.find("#[cfg(test)]\nmod ") {
        Some(i) => &text[..i],
        None => text,
    }
}

/// Source text without `//` comments (doc links name modules without importing them).
fn strip_comments(text: &str) -> String {
    text.lines()
        .map(|l| match l.find("//") {
            Some(i) => &l[..i],
            None => l,
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// One cycle through each strongly connected part of `graph` that has one, by depth-first
/// search.
fn find_cycles(graph: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    let mut found = Vec::new();
    let mut done: BTreeSet<String> = BTreeSet::new();
    for start in graph.keys() {
        let mut path = vec![start.clone()];
        if let Some(c) = walk(graph, &mut path, &mut done) {
            if !found.iter().any(|f: &Vec<String>| f.contains(&c[0])) {
                found.push(c);
            }
        }
        done.insert(start.clone());
    }
    found
}

fn walk(
    graph: &BTreeMap<String, BTreeSet<String>>,
    path: &mut Vec<String>,
    done: &mut BTreeSet<String>,
) -> Option<Vec<String>> {
    let here = path.last()?.clone();
    for next in graph.get(&here).into_iter().flatten() {
        if let Some(i) = path.iter().position(|p| p == next) {
            let mut cycle = path[i..].to_vec();
            cycle.push(next.clone());
            return Some(cycle);
        }
        if done.contains(next) {
            continue;
        }
        path.push(next.clone());
        if let Some(c) = walk(graph, path, done) {
            return Some(c);
        }
        path.pop();
        done.insert(next.clone());
    }
    None
}

/// Functions longer than allowed in one file (rustfmt puts a function's closing brace alone
/// on a line at the indentation of its `fn`).
fn long_functions(file: &Path) -> Vec<String> {
    let text = fs::read_to_string(file).unwrap_or_default();
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        let Some(name) = fn_name(line) else {
            continue;
        };
        let indent = line.len() - line.trim_start().len();
        let close = format!("{}}}", " ".repeat(indent));
        let Some(len) = lines[i..].iter().position(|l| *l == close) else {
            continue; // a declaration without a body
        };
        let len = len + 1;
        let limit = if name == "main" && file.ends_with("cli/src/main.rs") {
            MAX_MAIN_LINES
        } else {
            MAX_FN_LINES
        };
        if len > limit {
            out.push(format!(
                "{}:{}: fn {name} is {len} lines (at most {limit})",
                file.display(),
                i + 1
            ));
        }
    }
    out
}

/// The name of the function a line declares, if it does.
fn fn_name(line: &str) -> Option<&str> {
    let mut rest = line.trim_start();
    for prefix in [
        "pub(crate) ",
        "pub(super) ",
        "pub ",
        "const ",
        "async ",
        "unsafe ",
    ] {
        rest = rest.strip_prefix(prefix).unwrap_or(rest);
    }
    let rest = rest.strip_prefix("fn ")?;
    let end = rest.find(|c: char| !(c.is_alphanumeric() || c == '_'))?;
    Some(&rest[..end])
}

/// The library's normal dependency tree must not hold the CLI's, the boards' or a terminal's
/// crates.
fn library_dependencies() -> Vec<String> {
    let mut c = cargo(["tree", "-p", "hemi", "-e", "normal", "--prefix", "none"]);
    let out = match c.output() {
        Ok(o) if o.status.success() => String::from_utf8_lossy(&o.stdout).into_owned(),
        Ok(o) => {
            return vec![format!(
                "cargo tree -p hemi failed: {}",
                String::from_utf8_lossy(&o.stderr)
            )]
        }
        Err(e) => return vec![format!("cargo tree -p hemi: {e}")],
    };
    let names: BTreeSet<&str> = out.lines().filter_map(|l| l.split(' ').next()).collect();
    NOT_IN_LIBRARY
        .iter()
        .filter(|n| names.contains(*n))
        .map(|n| format!("host/hemi depends on `{n}` (cargo tree -p hemi -e normal)"))
        .collect()
}

/// The library reads no environment variable: options arrive in typed structs.
fn library_environment() -> Vec<String> {
    let src = root().join("host/hemi/src");
    rust_files(&src)
        .into_iter()
        .filter(|f| {
            let text = fs::read_to_string(f).unwrap_or_default();
            strip_comments(&text).contains("env::var")
        })
        .map(|f| format!("{}: reads an environment variable", f.display()))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn graph(edges: &[(&str, &str)]) -> BTreeMap<String, BTreeSet<String>> {
        let mut g: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
        for (a, b) in edges {
            g.entry(a.to_string()).or_default().insert(b.to_string());
            g.entry(b.to_string()).or_default();
        }
        g
    }

    #[test]
    fn finds_a_cycle_and_passes_a_dag() {
        let dag = graph(&[("a", "b"), ("b", "c"), ("a", "c")]);
        assert!(find_cycles(&dag).is_empty());
        let cyclic = graph(&[("a", "b"), ("b", "c"), ("c", "a"), ("d", "a")]);
        let found = find_cycles(&cyclic);
        assert_eq!(found.len(), 1, "{found:?}");
        assert_eq!(found[0].first(), found[0].last());
    }

    fn strings(v: &[&str]) -> Vec<String> {
        v.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn reads_crate_super_and_nested_group_paths() {
        let here = strings(&["solve", "system"]);
        let text = "use crate::scene::Scene;\nuse crate::{backend::{Backend, Seen}, shots};\n\
                    use super::{diagnose, Solution};\nlet x = hemi_crate::x;";
        let got = named_paths(text, &here);
        for want in [
            &["scene", "Scene"][..],
            &["backend", "Backend"],
            &["backend", "Seen"],
            &["shots"],
            &["solve", "diagnose"],
            &["solve", "Solution"],
        ] {
            assert!(got.contains(&strings(want)), "{want:?} in {got:?}");
        }
        assert_eq!(got.len(), 6, "{got:?}");
    }

    #[test]
    fn finds_a_cycle_between_siblings_through_a_reexport() {
        let dir = std::env::temp_dir().join(format!("xtask-layout-{}", std::process::id()));
        let src = dir.join("src");
        fs::create_dir_all(src.join("solve")).unwrap();
        let write = |p: &str, t: &str| fs::write(src.join(p), t).unwrap();
        write("lib.rs", "pub mod solve;\n");
        write("solve/mod.rs", "mod a;\nmod b;\npub use a::Alpha;\n");
        write("solve/a.rs", "use super::b::beta;\npub struct Alpha;\n");
        write("solve/b.rs", "use super::Alpha;\npub fn beta() {}\n");
        let found = cycles("t", &src, &rust_files(&src));
        write("solve/b.rs", "pub fn beta() {}\n");
        let none = cycles("t", &src, &rust_files(&src));
        fs::remove_dir_all(&dir).unwrap();
        assert_eq!(found.len(), 1, "{found:?}");
        assert!(found[0].contains("under solve"), "{found:?}");
        assert!(none.is_empty(), "{none:?}");
    }

    #[test]
    fn measures_functions_by_their_closing_brace() {
        assert_eq!(fn_name("    pub(crate) fn shoot_rows("), Some("shoot_rows"));
        assert_eq!(fn_name("pub const fn f() {"), Some("f"));
        assert_eq!(fn_name("let fn_x = 1;"), None);
    }
}
