//! `cargo xtask layout`: the architecture's invariants that the compiler does not check
//! (docs/ARCHITECTURE.md, "Invariants"):
//!
//! - the modules of each host crate import one another without a cycle (a `crate::m` path in
//!   module `n` is an edge n → m; the crate root is not a module);
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

/// The top-level module a file of `src` belongs to (`None` for the crate root).
fn module_of(src: &Path, file: &Path) -> Option<String> {
    let rel = file.strip_prefix(src).ok()?;
    let first = rel.components().next()?.as_os_str().to_str()?;
    let name = first.strip_suffix(".rs").unwrap_or(first);
    (!matches!(name, "lib" | "main")).then(|| name.to_string())
}

/// The top-level modules a source text names through `crate::`, including
/// `use crate::{a, b::c}` groups.
fn crate_paths(text: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for (i, _) in text.match_indices("crate::") {
        if text[..i].ends_with(|c: char| c.is_alphanumeric() || c == '_') {
            continue; // e.g. `hemi_crate::`
        }
        let rest = &text[i + "crate::".len()..];
        if let Some(group) = rest.strip_prefix('{') {
            let end = group.find('}').unwrap_or(group.len());
            for item in group[..end].split(',') {
                out.extend(ident(item.trim()));
            }
        } else {
            out.extend(ident(rest));
        }
    }
    out
}

fn ident(s: &str) -> Option<String> {
    let end = s
        .find(|c: char| !(c.is_alphanumeric() || c == '_'))
        .unwrap_or(s.len());
    (end > 0).then(|| s[..end].to_string())
}

/// The cycles among the top-level modules of one crate, one line each.
fn cycles(krate: &str, src: &Path, files: &[PathBuf]) -> Vec<String> {
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for f in files {
        let Some(from) = module_of(src, f) else {
            continue;
        };
        let text = fs::read_to_string(f).unwrap_or_default();
        let code = strip_comments(&text);
        let edges = graph.entry(from.clone()).or_default();
        edges.extend(crate_paths(&code).into_iter().filter(|m| *m != from));
    }
    find_cycles(&graph)
        .into_iter()
        .map(|c| format!("{krate}: import cycle {}", c.join(" → ")))
        .collect()
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

    #[test]
    fn reads_crate_paths_and_groups() {
        let text = "use crate::scene::Scene;\nuse crate::{backend::Backend, shots};\nlet x = crate::solve::grey(f);\nuse hemi_crate::x;";
        let got: Vec<String> = crate_paths(text).into_iter().collect();
        assert_eq!(got, ["backend", "scene", "shots", "solve"]);
    }

    #[test]
    fn measures_functions_by_their_closing_brace() {
        assert_eq!(fn_name("    pub(crate) fn shoot_rows("), Some("shoot_rows"));
        assert_eq!(fn_name("pub const fn f() {"), Some("f"));
        assert_eq!(fn_name("let fn_x = 1;"), None);
    }
}
