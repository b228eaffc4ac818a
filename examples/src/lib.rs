#![doc = include_str!("../README.md")]
//! ## The library
//!
//! The two sample programs of Biggs & MacDonald's paper, written against the limber client
//! API only, so they run unchanged on the Pioneer arm and on a simulated arm:
//!
//! * [`random_moves`] (Listing 1): random joint moves within the limits read from the
//!   actuator array's geometry.
//! * [`pick_block`] (Listing 2): pick up a block with the limb and gripper interfaces,
//!   carry it and put it down.
//! * [`square`] (limber's, issue 28): draw a square with the limb's tool, each edge a
//!   straight line (LINE), each motion followed to its result.
//!
//! Each is a library function (the `limber demo` command runs the same code) and a
//! binary with its own README: `cargo run -p limber-examples --bin pick_block`.

#![warn(missing_docs)]

pub mod pick_block;
pub mod random_moves;
pub mod square;

/// The book's pages and the top-level files that hold Rust blocks, one item each, so that
/// `cargo test --doc -p limber-examples` compiles (and runs) their blocks (examples/build.rs).
#[cfg(doctest)]
mod doc_pages {
    include!(concat!(env!("OUT_DIR"), "/doc_pages.rs"));
}
