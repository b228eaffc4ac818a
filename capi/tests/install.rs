//! `capi/install.sh`: what it installs, and what it refuses before installing anything: a
//! library that is not of this tree's layout, a static library that is missing when it is
//! wanted. The library is the one cargo built for this test.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Duration;

const RUN_LIMIT: Duration = Duration::from_secs(120);

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap()
        .to_path_buf()
}

/// The directory of this test's executable, where cargo put liblimber.so and liblimber.a.
fn lib_dir() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    exe.parent().unwrap().to_path_buf()
}

fn scratch(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("install-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn install(args: &[&str], prefix: &Path, build: &Path) -> Output {
    let mut cmd = Command::new("sh");
    cmd.arg(root().join("capi/install.sh"))
        .args(args)
        .arg(prefix)
        .arg(build);
    limber_bounded_run::output_within(cmd, RUN_LIMIT)
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

#[test]
fn a_shared_only_install_needs_no_static_library_and_is_stripped() {
    let dir = scratch("shared");
    // A build directory with the shared library alone.
    let build = dir.join("build");
    std::fs::create_dir_all(&build).unwrap();
    std::fs::copy(lib_dir().join("liblimber.so"), build.join("liblimber.so")).unwrap();
    let prefix = dir.join("prefix");
    let o = install(&[], &prefix, &build);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o.stdout));
    assert!(
        text(&o.stderr).contains("liblimber.a not found")
            && text(&o.stderr).contains("--shared-only"),
        "{}",
        text(&o.stderr)
    );
    assert!(!prefix.exists(), "nothing is installed when it refuses");
    let o = install(&["--shared-only"], &prefix, &build);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(
        text(&o.stdout).contains("shared only"),
        "{}",
        text(&o.stdout)
    );
    assert!(prefix.join("lib/liblimber.so").is_file());
    assert!(!prefix.join("lib/liblimber.a").exists());
    assert!(prefix.join("lib/pkgconfig/limber.pc").is_file());
    // The debug information went (strip is part of binutils, here with gcc).
    let built = std::fs::metadata(build.join("liblimber.so")).unwrap().len();
    let installed = std::fs::metadata(prefix.join("lib/liblimber.so"))
        .unwrap()
        .len();
    assert!(
        installed < built,
        "installed {installed} bytes, built {built}"
    );
    // --keep-debug installs the library as built.
    let kept = dir.join("kept");
    let o = install(&["--shared-only", "--keep-debug"], &kept, &build);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let kept_size = std::fs::metadata(kept.join("lib/liblimber.so"))
        .unwrap()
        .len();
    assert_eq!(kept_size, built);
}

#[test]
fn a_library_of_another_layout_is_refused_before_anything_is_installed() {
    let dir = scratch("other");
    let build = dir.join("build");
    std::fs::create_dir_all(&build).unwrap();
    // A liblimber that speaks layout version 99 (and a static library beside it).
    let src = dir.join("fake.c");
    std::fs::write(
        &src,
        "unsigned limber_layout_version(void) { return 99; }\n",
    )
    .unwrap();
    let mut cc = Command::new("gcc");
    cc.args(["-shared", "-fPIC", "-o"])
        .arg(build.join("liblimber.so"))
        .arg(&src);
    let o = limber_bounded_run::output_within(cc, RUN_LIMIT);
    assert!(o.status.success(), "{}", text(&o.stderr));
    std::fs::copy(lib_dir().join("liblimber.a"), build.join("liblimber.a")).unwrap();
    let prefix = dir.join("prefix");
    let o = install(&[], &prefix, &build);
    assert_eq!(o.status.code(), Some(1));
    let err = text(&o.stderr);
    assert!(
        err.contains("was not built from this tree")
            && err.contains(&format!(
                "the headers speak layout version {}, the library 99",
                limber_interfaces::LAYOUT_VERSION
            )),
        "{err}"
    );
    assert!(!prefix.exists(), "nothing is installed when it refuses");
}

#[test]
fn an_unknown_option_is_a_usage_error() {
    let dir = scratch("usage");
    let o = install(&["--static"], &dir.join("p"), &lib_dir());
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o.stderr).contains("usage: capi/install.sh"));
}
