//! The documentation's Markdown files and their fenced blocks: which files there are, what
//! each block holds, and which other test runs a block of code (cli/tests/readme.rs runs
//! the shell blocks and reports the rest).

use std::path::{Path, PathBuf};

pub const MARKER: &str = "<!-- not run by tests:";

pub fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// A fenced block: its file, first line, language, commands (of a shell block) and
/// markers.
#[derive(Debug)]
pub struct Block {
    /// The Markdown file, relative to the repository (or absolute).
    pub file: String,
    /// The line of the opening fence.
    pub line: usize,
    /// The fence's language, without its attributes (`rust,no_run` is `rust`).
    pub lang: String,
    /// A shell block's commands, comments stripped and continuation lines joined.
    pub commands: Vec<String>,
    /// (prefix, reason)
    pub not_run: Vec<(String, String)>,
}

/// Languages of a shell block.
pub const SHELL: &[&str] = &["sh", "bash", "shell", "console"];
/// Languages of data or output: shown, not run.
pub const DATA: &[&str] = &["text", "json", "json5", "toml"];
/// The blocks of code that another test runs: (page, language, the test that runs them; it
/// names the page).
pub const ELSEWHERE: &[(&str, &str, &str)] = &[
    ("docs/guide/c-and-cpp.md", "c", "capi/tests/c_programs.rs"),
    ("docs/guide/c-and-cpp.md", "cpp", "capi/tests/c_programs.rs"),
    ("python/README.md", "python", "python/tests/test_readme.py"),
];

/// The fenced blocks of a Markdown file, the shell blocks' comments stripped and
/// continuation lines joined.
pub fn blocks(file: &str) -> Vec<Block> {
    let text = std::fs::read_to_string(repo().join(file)).unwrap();
    let mut out = Vec::new();
    let mut markers: Vec<(String, String)> = Vec::new();
    let mut lines = text.lines().enumerate();
    while let Some((i, l)) = lines.next() {
        let t = l.trim();
        if let Some(m) = t.strip_prefix(MARKER) {
            let m = m.trim_end_matches("-->").trim();
            let (prefix, why) = m.split_once('|').unwrap_or((m, ""));
            markers.push((prefix.trim().to_string(), why.trim().to_string()));
            continue;
        }
        if !t.starts_with("```") {
            if !t.is_empty() {
                markers.clear();
            }
            continue;
        }
        let lang = t.trim_start_matches('`');
        let lang = lang
            .split([',', ' '])
            .next()
            .unwrap_or("")
            .trim()
            .to_string();
        let shell = SHELL.contains(&lang.as_str());
        let mut commands = Vec::new();
        let mut pending = String::new();
        for (_, l) in lines.by_ref() {
            if l.trim_start().starts_with("```") {
                break;
            }
            if !shell {
                continue;
            }
            let l = strip_comment(l);
            if let Some(head) = l.strip_suffix('\\') {
                pending.push_str(head);
                pending.push(' ');
                continue;
            }
            pending.push_str(&l);
            let cmd = pending.split_whitespace().collect::<Vec<_>>().join(" ");
            pending.clear();
            if !cmd.is_empty() {
                commands.push(cmd);
            }
        }
        out.push(Block {
            file: file.to_string(),
            line: i + 1,
            lang,
            commands,
            not_run: std::mem::take(&mut markers),
        });
    }
    out
}

/// The line without its shell comment (a `#` at the start or after a blank, outside
/// quotes).
pub fn strip_comment(l: &str) -> String {
    let mut quote = None;
    let mut prev = ' ';
    for (i, c) in l.char_indices() {
        match (quote, c) {
            (None, '"' | '\'') => quote = Some(c),
            (Some(q), c) if c == q => quote = None,
            (None, '#') if prev.is_whitespace() => return l[..i].trim_end().to_string(),
            _ => {}
        }
        prev = c;
    }
    l.trim_end().to_string()
}

/// Every Markdown file of the repository (relative paths, sorted), but the build's and
/// hidden directories.
pub fn doc_files() -> Vec<String> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap().map(Result::unwrap) {
            let p = e.path();
            let name = e.file_name().to_string_lossy().into_owned();
            if p.is_dir() {
                if !name.starts_with('.') && name != "target" && name != "node_modules" {
                    walk(&p, out);
                }
            } else if name.ends_with(".md") {
                out.push(p);
            }
        }
    }
    let root = repo().canonicalize().unwrap();
    let mut found = Vec::new();
    walk(&root, &mut found);
    let mut files: Vec<String> = found
        .iter()
        .map(|p| p.strip_prefix(&root).unwrap().display().to_string())
        .collect();
    files.sort();
    files
}

/// Which test runs a documentation file: the README, the guide, the rest of the book and
/// the top-level files, or a crate's or example's README. Every file is in one group.
pub fn group(file: &str) -> &'static str {
    if file == "README.md" {
        "readme"
    } else if file.starts_with("docs/guide/") {
        "guide"
    } else if file.starts_with("docs/") || !file.contains('/') || file.starts_with("bench/results/")
    {
        "book"
    } else {
        "crates"
    }
}

/// The documentation files of `g`.
pub fn files_of(g: &str) -> Vec<String> {
    doc_files().into_iter().filter(|f| group(f) == g).collect()
}

/// Why a block of code (not a shell block) needs no marker: the test that runs it, or
/// `None` when none does.
pub fn runs_elsewhere(b: &Block) -> Option<String> {
    let file = b.file.as_str();
    if b.lang == "rust" {
        // A crate's README is its rustdoc front page; the book and the top-level files are
        // included by the examples crate's build script: either way a doctest.
        let dir = Path::new(file).parent().unwrap_or(Path::new(""));
        let lib = std::fs::read_to_string(repo().join(dir).join("src/lib.rs")).unwrap_or_default();
        let top = !file.contains('/') || file.starts_with("docs/");
        return if file.ends_with("README.md") && lib.contains("include_str!(\"../README.md\")") {
            Some(format!("a doctest of {}", dir.display()))
        } else if top {
            Some("a doctest of limber-examples (examples/build.rs)".to_string())
        } else {
            None
        };
    }
    if b.lang == "python" && file.starts_with("docs/") {
        // The book's python blocks: every one under `mypy --strict`.
        let test = "python/tests/test_readme.py";
        let source = std::fs::read_to_string(repo().join(test)).unwrap_or_default();
        return source
            .contains("docs_python_blocks")
            .then(|| test.to_string());
    }
    let (_, _, test) = ELSEWHERE
        .iter()
        .find(|(page, lang, _)| *page == file && *lang == b.lang)?;
    let source = std::fs::read_to_string(repo().join(test)).unwrap_or_default();
    source.contains(file).then(|| test.to_string())
}

/// What is wrong with a block of code that no test of this file runs: `None` when another
/// test runs it, it holds data, or a marker says why not.
pub fn code_failure(b: &Block, place: &str) -> Option<String> {
    if SHELL.contains(&b.lang.as_str()) || DATA.contains(&b.lang.as_str()) {
        return None;
    }
    if b.not_run.iter().any(|(p, why)| p == "*" && !why.is_empty()) {
        return None;
    }
    if b.lang.is_empty() {
        return Some(format!(
            "{place}: a fence without a language: say what the block holds (sh, rust, c, \
             text, ...)"
        ));
    }
    if runs_elsewhere(b).is_some() {
        return None;
    }
    Some(format!(
        "{place}: a {} block that no test runs, and no marker says why",
        b.lang
    ))
}
