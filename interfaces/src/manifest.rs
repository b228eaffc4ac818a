//! The layout manifest: every wire struct's type name, size, alignment and fields, and
//! every constant group. It is the single source of the generated C header
//! (`interfaces/include/limber.h`) and the Python ctypes classes (`python/limber/_layout.py`),
//! and `limber layout --json` prints it.

use serde::Serialize;

/// One field of a wire struct.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct FieldLayout {
    /// Field name, as in Rust, C and Python.
    pub name: &'static str,
    /// The field's rustdoc, one line per element (what `limber layout --markdown` prints;
    /// not in the JSON manifest, which generators read).
    #[serde(skip)]
    pub doc: &'static [&'static str],
    /// Byte offset from the start of the struct.
    pub offset: usize,
    /// Size in bytes of the whole field (all elements for an array).
    pub size: usize,
    /// Element type: a scalar (`u8`, `u16`, `u32`, `u64`, `i8`..`i64`, `f32`, `f64`) or the
    /// name of another wire struct.
    #[serde(rename = "type")]
    pub ty: &'static str,
    /// 0 for a plain field, N for a fixed array of N elements.
    pub array_len: usize,
}

/// One wire struct.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct StructLayout {
    /// Rust name of the struct (the C name is `limber_` + snake case of it).
    pub name: &'static str,
    /// The versioned type name iceoryx2 checks when a service is opened.
    pub type_name: &'static str,
    /// `size_of` in bytes.
    pub size: usize,
    /// `align_of` in bytes.
    pub align: usize,
    /// Every field, in declaration (= offset) order.
    pub fields: &'static [FieldLayout],
}

/// One named constant.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Constant {
    /// Name, upper snake case, unique within its group.
    pub name: &'static str,
    /// Value.
    pub value: i64,
    /// One line saying what it means.
    pub doc: &'static str,
}

/// A group of related constants (the codes of one field, the kinds of one channel, ...).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct ConstantGroup {
    /// Group name, upper snake case (the C prefix is `LIMBER_<GROUP>_`).
    pub name: &'static str,
    /// What the group is for.
    pub doc: &'static str,
    /// The constants.
    pub constants: &'static [Constant],
}

/// The whole contract.
#[derive(Debug, Clone, Serialize)]
pub struct Manifest {
    /// The layout version; every type name carries it (`limber.v<N>.<Name>`).
    pub layout_version: u32,
    /// Every wire struct, dependencies first.
    pub structs: Vec<StructLayout>,
    /// Every constant group.
    pub constants: Vec<ConstantGroup>,
    /// The text of every status code (`Status::describe`), in code order.
    pub status_texts: Vec<StatusText>,
}

/// The human-readable text of one status code.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct StatusText {
    /// The wire code.
    pub code: u32,
    /// What `Status::describe` says.
    pub text: &'static str,
}

impl Manifest {
    /// The manifest as pretty JSON (what `limber layout --json` prints).
    pub fn to_json(&self) -> String {
        // Serialising plain data with string keys cannot fail.
        serde_json::to_string_pretty(self).unwrap_or_default()
    }

    /// Looks a struct up by its Rust name.
    pub fn find(&self, name: &str) -> Option<&StructLayout> {
        self.structs.iter().find(|s| s.name == name)
    }
}
