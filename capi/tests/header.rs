//! The committed header `include/limber_client.h` is what cbindgen makes of `src/` now:
//! regenerated here and compared (run with `LIMBER_BLESS=1` to rewrite it after a
//! change of the API). Normal builds never run cbindgen.

use std::path::PathBuf;

#[test]
fn committed_header_is_what_cbindgen_generates() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let config = cbindgen::Config::from_file(dir.join("cbindgen.toml")).expect("cbindgen.toml");
    let mut out = Vec::new();
    cbindgen::Builder::new()
        .with_crate(&dir)
        .with_config(config)
        .generate()
        .expect("cbindgen generates the header")
        .write(&mut out);
    let generated = String::from_utf8(out).expect("a UTF-8 header");
    let path = dir.join("include/limber_client.h");
    if std::env::var_os("LIMBER_BLESS").is_some() {
        std::fs::write(&path, &generated).expect("write the header");
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == generated,
        "include/limber_client.h is stale: regenerate it with \
         `LIMBER_BLESS=1 cargo test -p limber-c --test header` and commit it"
    );
}
