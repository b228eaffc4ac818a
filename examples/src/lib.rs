//! Shared helpers for the limber examples.
