//! The Rust blocks of the book (every page under `docs/`) and of the top-level Markdown
//! files (README.md, TESTING.md, CHANGELOG.md) as doctests of this crate: one item per
//! page that holds a `rust` fence, its rustdoc the page itself (`src/lib.rs` includes the
//! list under `cfg(doctest)`). Found by walking the tree, so a new page is covered without
//! editing a list (cli/tests/readme.rs relies on it).

use std::path::{Path, PathBuf};

fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            walk(&p, out);
        } else if p.extension().is_some_and(|x| x == "md") {
            out.push(p);
        }
    }
}

fn main() {
    let manifest = std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR");
    let root = Path::new(&manifest).join("..");
    let docs = root.join("docs");
    println!("cargo:rerun-if-changed={}", docs.display());
    let mut pages = Vec::new();
    walk(&docs, &mut pages);
    for top in ["README.md", "TESTING.md", "CHANGELOG.md"] {
        println!("cargo:rerun-if-changed={}", root.join(top).display());
        pages.push(root.join(top));
    }
    pages.sort();
    let mut out = String::new();
    for (i, page) in pages.iter().enumerate() {
        let text = std::fs::read_to_string(page).unwrap_or_default();
        if text.lines().any(|l| l.trim_start().starts_with("```rust")) {
            let path = page.canonicalize().unwrap_or_else(|_| page.clone());
            out.push_str(&format!(
                "#[doc = include_str!({:?})]\npub struct Page{i};\n",
                path.display().to_string()
            ));
        }
    }
    let dest =
        Path::new(&std::env::var("OUT_DIR").expect("cargo sets OUT_DIR")).join("doc_pages.rs");
    std::fs::write(&dest, out).expect("OUT_DIR is writable");
}
