//! `cargo xtask layering`: the top-level modules of every workspace crate must form layers, that
//! is, their dependency graph must have no cycle.
//!
//! A crate's top-level modules are the `mod x;` declarations of its `src/lib.rs` (or
//! `src/main.rs`); module `x` is `src/x.rs` plus everything under `src/x/`. Module `a` depends on
//! `b` when a file of `a` names `crate::b` (in a `use` tree or an inline path), reaches `b` through
//! `super::` past the top of `a`, or names an item the crate root re-exports from `b`
//! (`pub use b::Item;` in lib.rs, then `crate::Item`). The crate root itself is not a module.
//! `#[cfg(test)]` items and `#[cfg(test)] mod tests;` files are left out: tests may use higher
//! layers.
//!
//! The scanner is hand-written on purpose: no crate resolves Rust module paths without compiling
//! the crate (`syn` parses but does not resolve `use`, `super` or re-exports; rustc and
//! rust-analyzer need a build), and xtask keeps its dependencies to toml, serde and clap. Tokens
//! are enough here: comments and literals are blanked, `#[cfg(test)]` items dropped, and `use`
//! trees and `crate::`/`super::`/`self::` paths resolved against each file's module path
//! (`#[path]` attributes and macro-generated paths are not followed).

use crate::util::{Result, root};
use std::collections::{BTreeMap, BTreeSet};
use std::fmt;
use std::path::{Path, PathBuf};

/// Where an edge `a -> b` was seen (the first reference, files in path order).
#[derive(Debug, Clone, PartialEq)]
pub struct Evidence {
    /// The file, relative to the workspace root when it is inside it.
    pub file: String,
    /// 1-based line of the reference.
    pub line: usize,
    /// The path as written up to the module it reaches, e.g. `crate::surface` or `super::b`.
    pub path: String,
}

/// The top-level module graph of one crate target.
#[derive(Debug)]
pub struct Graph {
    /// The crate name (with ` (main.rs)` for the binary of a crate that also has a library).
    pub name: String,
    /// Top-level modules, sorted.
    pub modules: Vec<String>,
    /// Edges `(from, to)` with their first evidence.
    pub edges: BTreeMap<(String, String), Evidence>,
    /// Things the scan could not follow (a declared module without a file, an unreadable file).
    pub warnings: Vec<String>,
}

/// One strongly connected component of more than one module, with one concrete cycle through it.
#[derive(Debug)]
pub struct Cycle {
    /// The crate name.
    pub krate: String,
    /// Every module of the component, sorted.
    pub component: Vec<String>,
    /// A closed path `a -> b -> ... -> a` (first and last equal).
    pub path: Vec<String>,
    /// The evidence of each edge of `path`.
    pub evidence: Vec<Evidence>,
}

impl fmt::Display for Cycle {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let uses: Vec<String> = self
            .evidence
            .iter()
            .map(|e| format!("{}:{} uses {}", e.file, e.line, e.path))
            .collect();
        write!(
            f,
            "{}: cycle {} ({})",
            self.krate,
            self.path.join(" -> "),
            uses.join("; ")
        )?;
        if self.component.len() + 1 > self.path.len() {
            write!(f, " [strongly connected: {}]", self.component.join(", "))?;
        }
        Ok(())
    }
}

/// `cargo xtask test` step: fails when any crate has a cycle; prints a one-line summary per crate.
pub fn check() -> Result<()> {
    let graphs = workspace_graphs(&root())?;
    let mut cycles = Vec::new();
    for g in &graphs {
        for w in &g.warnings {
            println!("warning: {}: {w}", g.name);
        }
        let found = cycles_of(g);
        println!(
            "{}: {} modules, {} edges, {} cycle(s)",
            g.name,
            g.modules.len(),
            g.edges.len(),
            found.len()
        );
        cycles.extend(found);
    }
    report(&cycles, true)
}

/// `cargo xtask layering [--workspace DIR]`: prints every crate's module graph and its cycles
/// (of this workspace, or of another checkout at `DIR`); fails on a cycle.
pub fn print(workspace: Option<&Path>) -> Result<()> {
    let graphs = workspace_graphs(workspace.unwrap_or(&root()))?;
    let mut cycles = Vec::new();
    for g in &graphs {
        println!(
            "\n{} ({} modules, {} edges)",
            g.name,
            g.modules.len(),
            g.edges.len()
        );
        for w in &g.warnings {
            println!("  warning: {w}");
        }
        for ((a, b), e) in &g.edges {
            println!("  {a} -> {b}    ({}:{} uses {})", e.file, e.line, e.path);
        }
        let found = cycles_of(g);
        for c in &found {
            println!("  {c}");
        }
        cycles.extend(found);
    }
    println!();
    report(&cycles, false)
}

/// Ok without cycles; otherwise an error counting them, after listing them when `list`.
fn report(cycles: &[Cycle], list: bool) -> Result<()> {
    if cycles.is_empty() {
        println!("module layering: no cycles");
        return Ok(());
    }
    for c in cycles.iter().filter(|_| list) {
        println!("{c}");
    }
    Err(format!(
        "{} dependency cycle(s) between top-level modules (listed above)",
        cycles.len()
    ))
}

/// The graphs of every workspace member (from the root Cargo.toml), library before binary.
pub fn workspace_graphs(ws: &Path) -> Result<Vec<Graph>> {
    let manifest = read(&ws.join("Cargo.toml"))?;
    let doc: toml::Table = manifest.parse().map_err(|e| format!("Cargo.toml: {e}"))?;
    let members = doc
        .get("workspace")
        .and_then(|w| w.get("members"))
        .and_then(|m| m.as_array())
        .ok_or("Cargo.toml has no [workspace] members")?;
    let mut graphs = Vec::new();
    for member in members {
        let Some(member) = member.as_str() else {
            continue;
        };
        let dir = ws.join(member);
        let name = read(&dir.join("Cargo.toml"))
            .ok()
            .and_then(|m| m.parse::<toml::Table>().ok())
            .and_then(|t| t.get("package")?.get("name")?.as_str().map(str::to_string))
            .unwrap_or_else(|| member.to_string());
        let src = dir.join("src");
        let lib = src.join("lib.rs").is_file();
        if lib {
            graphs.push(analyze(&name, &src.join("lib.rs"), ws)?);
        }
        if src.join("main.rs").is_file() {
            let label = if lib {
                format!("{name} (main.rs)")
            } else {
                name.clone()
            };
            graphs.push(analyze(&label, &src.join("main.rs"), ws)?);
        }
    }
    Ok(graphs)
}

/// Scans the crate whose root file is `root_file` (its `src/lib.rs` or `src/main.rs`); file
/// names in evidence are shown relative to `shown_from` when they are inside it.
pub fn analyze(name: &str, root_file: &Path, shown_from: &Path) -> Result<Graph> {
    let src = root_file.parent().ok_or("crate root has no directory")?;
    let root_scan = scan(&read(root_file)?);
    let modules: BTreeSet<String> = root_scan.mods.iter().cloned().collect();
    // Names the crate root brings into scope (`pub use b::X as Y;`, also private `use`, which
    // every module may name as `crate::Y` too), mapped to the top-level module they come from.
    let mut reexports = BTreeMap::new();
    for r in root_scan
        .refs
        .iter()
        .filter(|r| r.is_use && r.inline.is_empty())
    {
        let mut segs = r.segs.iter().map(|(s, _)| s.as_str());
        let mut first = segs.next();
        if matches!(first, Some("crate" | "self")) {
            first = segs.next();
        }
        let (Some(module), Some(last)) = (first, r.segs.last()) else {
            continue;
        };
        if modules.contains(module) && r.segs.len() >= 2 && last.0 != "*" {
            let visible = r.alias.clone().unwrap_or_else(|| last.0.clone());
            if visible != "_" {
                reexports
                    .entry(visible)
                    .or_insert_with(|| module.to_string());
            }
        }
    }

    let mut graph = Graph {
        name: name.to_string(),
        modules: modules.iter().cloned().collect(),
        edges: BTreeMap::new(),
        warnings: Vec::new(),
    };
    for module in &modules {
        let mut files = Vec::new();
        let flat = src.join(format!("{module}.rs"));
        let dir = src.join(module);
        if flat.is_file() {
            files.push(flat);
        }
        if dir.is_dir() {
            walk(&dir, &mut files);
        }
        if files.is_empty() {
            graph.warnings.push(format!(
                "module {module}: no src/{module}.rs or src/{module}/"
            ));
            continue;
        }
        files.sort();
        // Scan everything first: `#[cfg(test)] mod tests;` in a parent removes the child's files.
        let mut scans = Vec::new();
        let mut excluded: Vec<PathBuf> = Vec::new();
        for file in files {
            let text = match std::fs::read_to_string(&file) {
                Ok(t) => t,
                // The tree may be changing under us; a vanished file is not an error.
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => continue,
                Err(e) => {
                    graph
                        .warnings
                        .push(format!("could not read {}: {e}", file.display()));
                    continue;
                }
            };
            let s = scan(&text);
            let children = children_dir(&file);
            for t in &s.test_mods {
                excluded.push(children.join(format!("{t}.rs")));
                excluded.push(children.join(t));
            }
            scans.push((file, s));
        }
        for (file, s) in scans {
            if s.test_only || excluded.iter().any(|x| file.starts_with(x)) {
                continue;
            }
            let Some(base) = module_path(src, &file) else {
                continue;
            };
            for r in &s.refs {
                let Some((target, line, shown)) = resolve(&base, r, &modules, &reexports) else {
                    continue;
                };
                if &target == module {
                    continue;
                }
                let shown_file = file
                    .strip_prefix(shown_from)
                    .unwrap_or(&file)
                    .display()
                    .to_string();
                graph
                    .edges
                    .entry((module.clone(), target))
                    .or_insert(Evidence {
                        file: shown_file,
                        line,
                        path: shown,
                    });
            }
        }
    }
    Ok(graph)
}

/// The top-level module a reference reaches from a file whose module path is `base`, with the
/// line of the segment naming it and the path as written up to there.
fn resolve(
    base: &[String],
    r: &Ref,
    modules: &BTreeSet<String>,
    reexports: &BTreeMap<String, String>,
) -> Option<(String, usize, String)> {
    let mut at: Vec<String> = base.iter().chain(&r.inline).cloned().collect();
    let mut i = 0;
    match r.segs.first()?.0.as_str() {
        "crate" | "$crate" => {
            at.clear();
            i = 1;
        }
        "super" | "self" => {}
        // A plain path is relative to the current module (or an extern crate): never the root.
        _ => return None,
    }
    while let Some((seg, _)) = r.segs.get(i) {
        match seg.as_str() {
            "super" => {
                at.pop()?;
            }
            "self" => {}
            _ => break,
        }
        i += 1;
    }
    if !at.is_empty() {
        return None; // still inside a top-level module: its own business
    }
    let (name, line) = r.segs.get(i)?;
    let shown = r.segs[..=i]
        .iter()
        .map(|(s, _)| s.as_str())
        .collect::<Vec<_>>()
        .join("::");
    if modules.contains(name) {
        Some((name.clone(), *line, shown))
    } else {
        let from = reexports.get(name)?;
        Some((from.clone(), *line, format!("{shown} (from {from})")))
    }
}

/// The module path of `file` under `src`: `a.rs` and `a/mod.rs` are `[a]`, `a/x.rs` is `[a, x]`.
fn module_path(src: &Path, file: &Path) -> Option<Vec<String>> {
    let rel = file.strip_prefix(src).ok()?.with_extension("");
    let mut parts: Vec<String> = rel
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    if parts.last().is_some_and(|p| p == "mod") {
        parts.pop();
    }
    Some(parts)
}

/// The directory holding the files of the modules `file` declares.
fn children_dir(file: &Path) -> PathBuf {
    match file.file_name().and_then(|n| n.to_str()) {
        Some("mod.rs" | "lib.rs" | "main.rs") => file.parent().unwrap_or(file).to_path_buf(),
        _ => file.with_extension(""),
    }
}

/// Every `.rs` file under `dir` (a missing or vanishing directory gives none).
fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            walk(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

fn read(path: &Path) -> Result<String> {
    std::fs::read_to_string(path).map_err(|e| format!("could not read {}: {e}", path.display()))
}

// ---------------------------------------------------------------------------------------------
// Cycles: Tarjan's strongly connected components, then a shortest cycle inside each.

/// Every strongly connected component of more than one module, with a shortest cycle through
/// its first module (components and cycles in name order, so the output is stable).
pub fn cycles_of(g: &Graph) -> Vec<Cycle> {
    let index: BTreeMap<&str, usize> = g
        .modules
        .iter()
        .enumerate()
        .map(|(i, m)| (m.as_str(), i))
        .collect();
    let mut adj = vec![Vec::new(); g.modules.len()];
    for (a, b) in g.edges.keys() {
        if let (Some(&i), Some(&j)) = (index.get(a.as_str()), index.get(b.as_str())) {
            adj[i].push(j);
        }
    }
    let mut cycles = Vec::new();
    for mut comp in tarjan(&adj) {
        if comp.len() < 2 {
            continue;
        }
        comp.sort_unstable();
        let path = shortest_cycle(&adj, comp[0], &comp);
        let names: Vec<String> = path.iter().map(|&i| g.modules[i].clone()).collect();
        let evidence = names
            .windows(2)
            .map(|w| g.edges[&(w[0].clone(), w[1].clone())].clone())
            .collect();
        cycles.push(Cycle {
            krate: g.name.clone(),
            component: comp.iter().map(|&i| g.modules[i].clone()).collect(),
            path: names,
            evidence,
        });
    }
    cycles.sort_by(|a, b| a.component.cmp(&b.component));
    cycles
}

/// Tarjan's algorithm: the strongly connected components of `adj`.
fn tarjan(adj: &[Vec<usize>]) -> Vec<Vec<usize>> {
    struct State<'a> {
        adj: &'a [Vec<usize>],
        next: usize,
        index: Vec<Option<usize>>,
        low: Vec<usize>,
        on_stack: Vec<bool>,
        stack: Vec<usize>,
        comps: Vec<Vec<usize>>,
    }
    fn visit(s: &mut State<'_>, v: usize) {
        s.index[v] = Some(s.next);
        s.low[v] = s.next;
        s.next += 1;
        s.stack.push(v);
        s.on_stack[v] = true;
        let adj = s.adj;
        for &w in &adj[v] {
            match s.index[w] {
                None => {
                    visit(s, w);
                    s.low[v] = s.low[v].min(s.low[w]);
                }
                Some(iw) if s.on_stack[w] => s.low[v] = s.low[v].min(iw),
                Some(_) => {}
            }
        }
        if Some(s.low[v]) == s.index[v] {
            let mut comp = Vec::new();
            while let Some(w) = s.stack.pop() {
                s.on_stack[w] = false;
                comp.push(w);
                if w == v {
                    break;
                }
            }
            s.comps.push(comp);
        }
    }
    let n = adj.len();
    let mut s = State {
        adj,
        next: 0,
        index: vec![None; n],
        low: vec![0; n],
        on_stack: vec![false; n],
        stack: Vec::new(),
        comps: Vec::new(),
    };
    for v in 0..n {
        if s.index[v].is_none() {
            visit(&mut s, v);
        }
    }
    s.comps
}

/// A shortest closed path `start -> ... -> start` inside `comp` (breadth-first).
fn shortest_cycle(adj: &[Vec<usize>], start: usize, comp: &[usize]) -> Vec<usize> {
    let mut parent: BTreeMap<usize, usize> = BTreeMap::new();
    let mut queue = std::collections::VecDeque::from([start]);
    while let Some(v) = queue.pop_front() {
        let mut next = adj[v].clone();
        next.sort_unstable();
        for w in next {
            if w == start {
                let mut path = vec![start, v];
                let mut at = v;
                while at != start {
                    at = parent[&at];
                    path.push(at);
                }
                path.reverse(); // [start, ..., v, start]
                return path;
            }
            if comp.contains(&w) && !parent.contains_key(&w) {
                parent.insert(w, v);
                queue.push_back(w);
            }
        }
    }
    vec![start, start] // unreachable for a component of two or more
}

// ---------------------------------------------------------------------------------------------
// Scanning one file: blank comments and literals, tokenize, drop `#[cfg(test)]` items, collect
// `use` trees and `crate::`/`super::`/`self::` paths.

/// A path found in a file.
#[derive(Debug, Clone, PartialEq)]
struct Ref {
    /// Segments with their lines, e.g. `crate`, `b`, `X`.
    segs: Vec<(String, usize)>,
    /// `as` rename of a `use` leaf.
    alias: Option<String>,
    /// Inline `mod x { ... }` blocks around the reference, outermost first.
    inline: Vec<String>,
    /// Whether it comes from a `use` declaration.
    is_use: bool,
}

#[derive(Debug, Default)]
struct Scan {
    refs: Vec<Ref>,
    /// `mod x;` declarations at file level (not `#[cfg(test)]`).
    mods: Vec<String>,
    /// `#[cfg(test)] mod x;` declarations at file level.
    test_mods: Vec<String>,
    /// The file starts with `#![cfg(test)]`.
    test_only: bool,
}

fn scan(text: &str) -> Scan {
    let toks = tokenize(&strip(text));
    let mut out = Scan::default();
    let toks = drop_test_items(toks, &mut out);
    let t = |i: usize| toks.get(i).map_or("", |t| t.text.as_str());
    let mut depth = 0usize;
    let mut inline: Vec<(String, usize)> = Vec::new();
    let mut i = 0;
    while i < toks.len() {
        match t(i) {
            "{" => depth += 1,
            "}" => {
                depth = depth.saturating_sub(1);
                while inline.last().is_some_and(|(_, d)| *d > depth) {
                    inline.pop();
                }
            }
            "mod" if is_ident(t(i + 1)) && t(i + 2) == "{" => {
                depth += 1;
                inline.push((t(i + 1).to_string(), depth));
                i += 3;
                continue;
            }
            "mod" if is_ident(t(i + 1)) && t(i + 2) == ";" && depth == 0 => {
                out.mods.push(t(i + 1).to_string());
            }
            "use" if t(i.wrapping_sub(1)) != "::" => {
                let names: Vec<String> = inline.iter().map(|(n, _)| n.clone()).collect();
                let mut paths = Vec::new();
                let end = if t(i + 1) == "::" {
                    i + 1 // `use ::extern_crate`: not ours
                } else {
                    use_tree(&toks, i + 1, &[], &mut paths)
                };
                for (segs, alias) in paths {
                    out.refs.push(Ref {
                        segs,
                        alias,
                        inline: names.clone(),
                        is_use: true,
                    });
                }
                // Continue after the `;` (or wherever the tree stopped, if malformed).
                i = end;
                while i < toks.len() && t(i) != ";" && t(i) != "}" {
                    i += 1;
                }
                continue;
            }
            "crate" | "super" | "self"
                if t(i + 1) == "::"
                    && t(i.wrapping_sub(1)) != "::"
                    && !(t(i.wrapping_sub(1)) == "in" && t(i.wrapping_sub(2)) == "(") =>
            {
                let first = if t(i.wrapping_sub(1)) == "$" {
                    "$crate".to_string()
                } else {
                    t(i).to_string()
                };
                let mut segs = vec![(first, toks[i].line)];
                let mut j = i + 1;
                while t(j) == "::" && is_ident(t(j + 1)) {
                    segs.push((t(j + 1).to_string(), toks[j + 1].line));
                    j += 2;
                }
                out.refs.push(Ref {
                    segs,
                    alias: None,
                    inline: inline.iter().map(|(n, _)| n.clone()).collect(),
                    is_use: false,
                });
                i = j;
                continue;
            }
            _ => {}
        }
        i += 1;
    }
    out
}

/// A leaf of a use tree: its segments with lines, and its `as` alias.
type UsePath = (Vec<(String, usize)>, Option<String>);

/// Parses a use tree from `i` with segments `prefix` before it; pushes each leaf path (with its
/// `as` alias) and returns the index after the tree.
fn use_tree(
    toks: &[Tok],
    mut i: usize,
    prefix: &[(String, usize)],
    out: &mut Vec<UsePath>,
) -> usize {
    let t = |i: usize| toks.get(i).map_or("", |t| t.text.as_str());
    let mut segs = prefix.to_vec();
    loop {
        match t(i) {
            "{" => {
                i += 1;
                while i < toks.len() && t(i) != "}" {
                    i = use_tree(toks, i, &segs, out);
                    if t(i) == "," {
                        i += 1;
                    } else if t(i) != "}" {
                        // Malformed: skip to the end of the group.
                        while i < toks.len() && t(i) != "}" {
                            i += 1;
                        }
                    }
                }
                return i + 1;
            }
            "*" => {
                segs.push(("*".to_string(), toks[i].line));
                out.push((segs, None));
                return i + 1;
            }
            s if is_ident(s) => {
                let seg = if s == "self" && !segs.is_empty() {
                    None // `a::{self}` names `a` itself
                } else {
                    Some((s.to_string(), toks[i].line))
                };
                segs.extend(seg);
                i += 1;
                if t(i) == "::" {
                    i += 1;
                    continue;
                }
                let mut alias = None;
                if t(i) == "as" {
                    alias = Some(t(i + 1).to_string());
                    i += 2;
                }
                out.push((segs, alias));
                return i;
            }
            _ => return i,
        }
    }
}

/// Drops `#[cfg(test)]` (and `#[cfg(all(test, ...))]`) items, recording file-level
/// `#[cfg(test)] mod x;` declarations and a file-level `#![cfg(test)]`.
fn drop_test_items(toks: Vec<Tok>, out: &mut Scan) -> Vec<Tok> {
    let t = |i: usize| toks.get(i).map_or("", |t| t.text.as_str());
    let mut kept = Vec::with_capacity(toks.len());
    let mut depth = 0usize;
    let mut i = 0;
    while i < toks.len() {
        if t(i) == "#" {
            let inner = t(i + 1) == "!";
            let open = if inner { i + 2 } else { i + 1 };
            if t(open) == "[" {
                let close = matching(&toks, open);
                let attr: String = toks[open + 1..close.min(toks.len())]
                    .iter()
                    .map(|t| t.text.as_str())
                    .collect();
                if is_test_cfg(&attr) {
                    if inner {
                        out.test_only |= depth == 0;
                        i = close + 1;
                        continue;
                    }
                    let mut j = close + 1;
                    while t(j) == "#" && t(j + 1) == "[" {
                        j = matching(&toks, j + 1) + 1;
                    }
                    let start = skip_visibility(&toks, j);
                    if depth == 0 && t(start) == "mod" && t(start + 2) == ";" {
                        out.test_mods.push(t(start + 1).to_string());
                    }
                    i = item_end(&toks, j);
                    continue;
                }
            }
        }
        match t(i) {
            "{" => depth += 1,
            "}" => depth = depth.saturating_sub(1),
            _ => {}
        }
        kept.push(toks[i].clone());
        i += 1;
    }
    kept
}

fn is_test_cfg(attr: &str) -> bool {
    attr == "cfg(test)" || attr.starts_with("cfg(all(test,") || attr.starts_with("cfg(all(test)")
}

/// Skips `pub`, `pub(crate)`, `pub(in path)` at `i`.
fn skip_visibility(toks: &[Tok], i: usize) -> usize {
    let t = |i: usize| toks.get(i).map_or("", |t| t.text.as_str());
    match (t(i), t(i + 1)) {
        ("pub", "(") => matching(toks, i + 1) + 1,
        ("pub", _) => i + 1,
        _ => i,
    }
}

/// The index after the item (or statement, field, variant, block) starting at `i`: after its
/// `;` or its brace block; a field or variant ends at its `,`; the end of the enclosing block
/// ends it too.
fn item_end(toks: &[Tok], i: usize) -> usize {
    const ITEM: &[&str] = &[
        "fn",
        "struct",
        "enum",
        "union",
        "impl",
        "trait",
        "mod",
        "use",
        "const",
        "static",
        "type",
        "unsafe",
        "async",
        "extern",
        "macro_rules",
        "let",
    ];
    let t = |i: usize| toks.get(i).map_or("", |t| t.text.as_str());
    let item = ITEM.contains(&t(skip_visibility(toks, i)));
    let mut angle = 0usize;
    let mut j = i;
    while j < toks.len() {
        match t(j) {
            ";" => return j + 1,
            "{" => return matching(toks, j) + 1,
            "(" | "[" => j = matching(toks, j),
            "}" | ")" | "]" => return j,
            "<" => angle += 1,
            ">" if !matches!(t(j.wrapping_sub(1)), "-" | "=") => angle = angle.saturating_sub(1),
            "," if !item && angle == 0 => return j + 1,
            _ => {}
        }
        j += 1;
    }
    toks.len()
}

/// The index of the bracket closing the one at `open` (or the last index if unbalanced).
fn matching(toks: &[Tok], open: usize) -> usize {
    let mut depth = 0usize;
    for (j, tok) in toks.iter().enumerate().skip(open) {
        match tok.text.as_str() {
            "(" | "[" | "{" => depth += 1,
            ")" | "]" | "}" => {
                depth = depth.saturating_sub(1);
                if depth == 0 {
                    return j;
                }
            }
            _ => {}
        }
    }
    toks.len().saturating_sub(1).max(open)
}

fn is_ident(s: &str) -> bool {
    s.chars()
        .next()
        .is_some_and(|c| c.is_alphabetic() || c == '_')
}

#[derive(Debug, Clone, PartialEq)]
struct Tok {
    text: String,
    line: usize,
}

/// Identifiers (raw `r#x` as `x`), numbers, `::`, and single punctuation characters.
fn tokenize(text: &str) -> Vec<Tok> {
    let c: Vec<char> = text.chars().collect();
    let word = |ch: char| ch.is_alphanumeric() || ch == '_';
    let mut toks = Vec::new();
    let mut line = 1;
    let mut i = 0;
    while i < c.len() {
        let ch = c[i];
        if ch == '\n' {
            line += 1;
            i += 1;
        } else if ch.is_whitespace() {
            i += 1;
        } else if word(ch) {
            let mut j = i;
            while j < c.len() && word(c[j]) {
                j += 1;
            }
            let mut text: String = c[i..j].iter().collect();
            if text == "r" && c.get(j) == Some(&'#') && c.get(j + 1).is_some_and(|&x| word(x)) {
                let k = j + 1;
                j = k;
                while j < c.len() && word(c[j]) {
                    j += 1;
                }
                text = c[k..j].iter().collect();
            }
            toks.push(Tok { text, line });
            i = j;
        } else if ch == ':' && c.get(i + 1) == Some(&':') {
            toks.push(Tok {
                text: "::".into(),
                line,
            });
            i += 2;
        } else {
            toks.push(Tok {
                text: ch.to_string(),
                line,
            });
            i += 1;
        }
    }
    toks
}

/// Blanks comments (line, nested block, doc) and string, raw string, byte and char literals,
/// keeping newlines so line numbers stay right.
fn strip(src: &str) -> String {
    let c: Vec<char> = src.chars().collect();
    let n = c.len();
    let word = |ch: char| ch.is_alphanumeric() || ch == '_';
    let mut out = String::with_capacity(src.len());
    let blank = |out: &mut String, s: &[char]| {
        out.extend(s.iter().map(|&ch| if ch == '\n' { '\n' } else { ' ' }));
    };
    let mut i = 0;
    while i < n {
        let ch = c[i];
        let next = c.get(i + 1).copied();
        let end = if ch == '/' && next == Some('/') {
            (i..n).find(|&j| c[j] == '\n').unwrap_or(n)
        } else if ch == '/' && next == Some('*') {
            let mut depth = 0;
            let mut j = i;
            while j < n {
                if c[j] == '/' && c.get(j + 1) == Some(&'*') {
                    depth += 1;
                    j += 2;
                } else if c[j] == '*' && c.get(j + 1) == Some(&'/') {
                    depth -= 1;
                    j += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    j += 1;
                }
            }
            j.min(n)
        } else if let Some(end) = raw_string_end(&c, i, word) {
            end
        } else if ch == '"' {
            let mut j = i + 1;
            while j < n && c[j] != '"' {
                j += if c[j] == '\\' { 2 } else { 1 };
            }
            (j + 1).min(n)
        } else if ch == '\'' && next == Some('\\') {
            let mut j = i + 3; // past the escaped character
            while j < n && c[j] != '\'' {
                j += 1;
            }
            (j + 1).min(n)
        } else if ch == '\'' && c.get(i + 2) == Some(&'\'') {
            i + 3
        } else {
            out.push(ch);
            i += 1;
            continue;
        };
        blank(&mut out, &c[i..end]);
        i = end;
    }
    out
}

/// The end of a raw string literal `r"..."`, `r#"..."#`, `br"..."`, `cr#"..."#` starting at `i`.
fn raw_string_end(c: &[char], i: usize, word: impl Fn(char) -> bool) -> Option<usize> {
    if c[i] != 'r' {
        return None;
    }
    let starts_word = |k: usize| k == 0 || !word(c[k - 1]);
    let prefixed = i >= 1 && matches!(c[i - 1], 'b' | 'c') && starts_word(i - 1);
    if !starts_word(i) && !prefixed {
        return None;
    }
    let mut j = i + 1;
    while c.get(j) == Some(&'#') {
        j += 1;
    }
    let hashes = j - i - 1;
    if c.get(j) != Some(&'"') {
        return None;
    }
    j += 1;
    while j < c.len() {
        if c[j] == '"' && (1..=hashes).all(|k| c.get(j + k) == Some(&'#')) {
            return Some(j + 1 + hashes);
        }
        j += 1;
    }
    Some(c.len())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};

    /// A synthetic crate in a fresh temp directory: `files` are (path under src/, text).
    struct TempCrate(PathBuf);

    impl TempCrate {
        fn new(files: &[(&str, &str)]) -> TempCrate {
            static N: AtomicUsize = AtomicUsize::new(0);
            let dir = std::env::temp_dir().join(format!(
                "xtask-layering-{}-{}",
                std::process::id(),
                N.fetch_add(1, Ordering::Relaxed)
            ));
            let _ = std::fs::remove_dir_all(&dir);
            for (path, text) in files {
                let p = dir.join("src").join(path);
                std::fs::create_dir_all(p.parent().unwrap()).unwrap();
                std::fs::write(p, text).unwrap();
            }
            TempCrate(dir)
        }

        fn graph(&self) -> Graph {
            analyze("demo", &self.0.join("src/lib.rs"), &self.0).unwrap()
        }
    }

    impl Drop for TempCrate {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }

    fn edges(g: &Graph) -> Vec<String> {
        g.edges.keys().map(|(a, b)| format!("{a} -> {b}")).collect()
    }

    #[test]
    fn cycle_through_nested_use_trees_is_found() {
        let c = TempCrate::new(&[
            ("lib.rs", "mod a;\nmod b;\nmod c;\nmod d;\n"),
            ("a.rs", "use crate::{b::X, c::{Y, Z}};\n"),
            ("b/mod.rs", "mod inner;\npub struct X;\n"),
            ("b/inner.rs", "\n\nuse crate::{\n    d::{self as dd},\n};\n"),
            ("c.rs", "pub struct Y;\npub struct Z;\n"),
            ("d.rs", "fn f() { let _ = crate::a::g(); }\n"),
        ]);
        let g = c.graph();
        assert_eq!(
            edges(&g),
            ["a -> b", "a -> c", "b -> d", "d -> a"].map(String::from)
        );
        let cycles = cycles_of(&g);
        assert_eq!(cycles.len(), 1);
        assert_eq!(cycles[0].path, ["a", "b", "d", "a"]);
        assert_eq!(cycles[0].component, ["a", "b", "d"]);
        let shown = cycles[0].to_string();
        assert!(
            shown.starts_with("demo: cycle a -> b -> d -> a ("),
            "{shown}"
        );
        assert!(shown.contains("src/b/inner.rs:4 uses crate::d"), "{shown}");
        assert!(shown.contains("src/d.rs:1 uses crate::a"), "{shown}");
    }

    #[test]
    fn super_paths_leaving_the_module_are_dependencies() {
        let c = TempCrate::new(&[
            ("lib.rs", "mod a;\nmod b;\nmod c;\n"),
            ("a.rs", "mod x;\nuse super::b::B;\nuse self::x::Y;\n"),
            (
                "a/x.rs",
                "pub fn y() { super::super::c::f(); super::z(); }\n",
            ),
            ("b/mod.rs", "pub struct B;\nfn g() { super::a::h(); }\n"),
            ("c.rs", "pub fn f() {}\n"),
        ]);
        let g = c.graph();
        assert_eq!(edges(&g), ["a -> b", "a -> c", "b -> a"].map(String::from));
        assert_eq!(cycles_of(&g)[0].path, ["a", "b", "a"]);
    }

    #[test]
    fn cycle_only_inside_cfg_test_is_not_reported() {
        let c = TempCrate::new(&[
            ("lib.rs", "mod a;\nmod b;\n#[cfg(test)]\nmod tests;\n"),
            ("a.rs", "use crate::b::B;\n"),
            (
                "b/mod.rs",
                "pub struct B;\n#[cfg(test)]\nmod tests;\n#[cfg(test)]\n#[allow(dead_code)]\n\
                 mod more {\n    use crate::a::A;\n    mod deeper { fn f() { crate::a::g() } }\n}\n\
                 impl B {\n    #[cfg(test)]\n    fn t(&self) -> Result<(), u8> { crate::a::g(); Ok(()) }\n}\n",
            ),
            ("b/tests.rs", "use crate::a::A;\n"),
            ("b/tests/helpers.rs", "use crate::a::A;\n"),
            ("tests.rs", "use crate::a::A;\n"),
        ]);
        let g = c.graph();
        assert_eq!(g.modules, ["a", "b"]);
        assert_eq!(edges(&g), ["a -> b"].map(String::from));
        assert!(cycles_of(&g).is_empty());
    }

    #[test]
    fn root_reexport_resolves_to_its_module() {
        let c = TempCrate::new(&[
            (
                "lib.rs",
                "mod a;\nmod b;\nmod c;\npub use b::{Bee, inner::Deep as Renamed};\n\
                 pub(crate) use self::c::Sea;\npub use wgpu;\n",
            ),
            (
                "a.rs",
                "use crate::Renamed;\nfn f() -> crate::Sea { todo!() }\n",
            ),
            ("b.rs", "pub struct Bee;\nuse crate::wgpu::Device;\n"),
            ("c.rs", "use crate::{Bee, a};\n"),
        ]);
        let g = c.graph();
        assert_eq!(
            edges(&g),
            ["a -> b", "a -> c", "c -> a", "c -> b"].map(String::from)
        );
        let ab = &g.edges[&("a".to_string(), "b".to_string())];
        assert_eq!((ab.line, ab.path.as_str()), (1, "crate::Renamed (from b)"));
        let cycles = cycles_of(&g);
        assert_eq!(cycles.len(), 1);
        assert_eq!(cycles[0].path, ["a", "c", "a"]);
    }

    #[test]
    fn comments_and_strings_are_ignored() {
        let c = TempCrate::new(&[
            ("lib.rs", "//! Uses crate::a everywhere.\nmod a;\nmod b;\n"),
            (
                "a.rs",
                "//! See [`crate::b::B`].\n/* use crate::b; /* nested crate::b */ still */\n\
                 /// Doc: crate::b::f()\nfn f() -> char { let _ = '\"'; let _ = b'\\''; '{' }\n\
                 fn g<'a>(x: &'a str) -> &'a str { x }\n\
                 const S: &str = \"use crate::b::B; // not code\";\n\
                 const R: &str = r#\"crate::b::B \" still a string\"#;\n\
                 const E: &str = \"escaped \\\" crate::b::B\";\n",
            ),
            ("b.rs", "pub fn f() { crate::a::g(\"x\"); }\n"),
        ]);
        let g = c.graph();
        assert_eq!(edges(&g), ["b -> a"].map(String::from));
        assert!(cycles_of(&g).is_empty());
    }

    #[test]
    fn no_false_positive_on_crate_path_inside_a_string() {
        let c = TempCrate::new(&[
            ("lib.rs", "mod a;\nmod b;\n"),
            (
                "a.rs",
                "pub fn msg() -> &'static str { \"see crate::b for details\" }\n",
            ),
            (
                "b.rs",
                "pub fn f() -> String { crate::a::msg().to_string() }\n",
            ),
        ]);
        let g = c.graph();
        assert_eq!(edges(&g), ["b -> a"].map(String::from));
        assert!(cycles_of(&g).is_empty());
    }

    #[test]
    fn strip_keeps_lines_and_lifetimes() {
        let s = strip("a // x\n\"s\ntr\" 'b' 'c: loop {}\n");
        assert_eq!(s.lines().count(), 3);
        assert!(s.contains("'c: loop"));
        assert!(
            !s.contains("tr") && !s.contains('b') && !s.contains('x'),
            "{s:?}"
        );
    }
}
