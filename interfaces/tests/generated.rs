//! The C header and the Python classes agree with the Rust layout: the checked-in files
//! are what the generators produce now, and gcc/g++ see the same sizes and offsets.

use std::path::{Path, PathBuf};
use std::process::Command;

use limber_interfaces::codegen::{self, c_name};
use limber_interfaces::manifest::Manifest;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap()
        .to_path_buf()
}

fn m() -> Manifest {
    limber_interfaces::manifest()
}

#[test]
fn checked_in_c_header_is_current() {
    let path = root().join("interfaces/include/limber.h");
    let on_disk = std::fs::read_to_string(&path).expect("interfaces/include/limber.h exists");
    assert!(
        on_disk == codegen::c_header(&m()),
        "{} is stale: regenerate it with `cargo run -p limber-cli -- layout --c-header > interfaces/include/limber.h`",
        path.display()
    );
}

#[test]
fn checked_in_python_module_is_current() {
    let path = root().join("python/limber/_layout.py");
    let on_disk = std::fs::read_to_string(&path).expect("python/limber/_layout.py exists");
    assert!(
        on_disk == codegen::python_module(&m()),
        "{} is stale: regenerate it with `cargo run -p limber-cli -- layout --python > python/limber/_layout.py`",
        path.display()
    );
}

/// A C program that checks every size, alignment and offset of the manifest at run time.
fn checker(m: &Manifest) -> String {
    let mut s = String::from(
        "#include <stdio.h>\n#include <stddef.h>\n#include \"limber.h\"\nint main(void) {\n  int bad = 0;\n",
    );
    for st in &m.structs {
        let cn = c_name(st.name);
        s += &format!(
            "  if (sizeof({cn}) != {}) {{ printf(\"size {cn} %zu\\n\", sizeof({cn})); bad++; }}\n",
            st.size
        );
        s += &format!(
            "  if (_Alignof({cn}) != {}) {{ printf(\"align {cn}\\n\"); bad++; }}\n",
            st.align
        );
        for f in st.fields {
            s += &format!(
                "  if (offsetof({cn}, {f}) != {o} || sizeof((({cn}*)0)->{f}) != {z}) {{ printf(\"field {cn}.{f}\\n\"); bad++; }}\n",
                f = f.name,
                o = f.offset,
                z = f.size
            );
        }
    }
    s += "  printf(\"%d mismatches\\n\", bad);\n  return bad != 0;\n}\n";
    s
}

fn compile_and_run(name: &str, program: &str) -> Result<String, String> {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    std::fs::create_dir_all(&dir).unwrap();
    let src = dir.join("check.c");
    let exe = dir.join("check");
    std::fs::write(&src, program).unwrap();
    let include = root().join("interfaces/include");
    let out = Command::new("gcc")
        .args(["-std=c11", "-Wall", "-Wextra", "-Wpadded", "-Werror", "-I"])
        .arg(&include)
        .arg(&src)
        .arg("-o")
        .arg(&exe)
        .output()
        .expect("gcc runs");
    if !out.status.success() {
        return Err(format!("gcc: {}", String::from_utf8_lossy(&out.stderr)));
    }
    let run = Command::new(&exe).output().expect("checker runs");
    let stdout = String::from_utf8_lossy(&run.stdout).to_string();
    if run.status.success() {
        Ok(stdout)
    } else {
        Err(stdout)
    }
}

#[test]
fn gcc_sees_the_manifest_layout() {
    let out = compile_and_run("agree", &checker(&m())).unwrap();
    assert!(out.contains("0 mismatches"), "{out}");
}

#[test]
fn gxx_compiles_the_header_as_cxx() {
    let out = Command::new("g++")
        .args([
            "-std=c++11",
            "-Wall",
            "-Wpadded",
            "-Werror",
            "-fsyntax-only",
            "-x",
            "c++",
        ])
        .arg(root().join("interfaces/include/limber.h"))
        .output()
        .expect("g++ runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The check is not vacuous: a manifest in which one field moved is caught.
#[test]
fn a_moved_field_is_caught() {
    let mut moved = m();
    let idx = moved
        .structs
        .iter()
        .position(|s| s.name == "ActArrayData")
        .unwrap();
    let mut fields = moved.structs[idx].fields.to_vec();
    fields[1].offset += 4; // actuators_count
    let leaked: &'static [_] = Box::leak(fields.into_boxed_slice());
    moved.structs[idx].fields = leaked;
    let err = compile_and_run("moved", &checker(&moved)).unwrap_err();
    assert!(
        err.contains("field limber_actarray_data.actuators_count"),
        "{err}"
    );
    // And the generated header itself would no longer be current.
    assert_ne!(codegen::c_header(&moved), codegen::c_header(&m()));
}
