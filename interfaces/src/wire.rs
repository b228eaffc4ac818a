//! The machinery behind every wire struct: the `wire_struct!` macro, which defines a
//! `#[repr(C)]` zero-copy struct *and* its entry in the layout manifest from one
//! declaration, so the manifest cannot drift from the code.

use crate::manifest::{FieldLayout, StructLayout};

/// iceoryx2's marker trait for types that may be sent through shared memory (the
/// `ZeroCopySend` derive names it unqualified, so modules that declare wire structs import it).
pub use iceoryx2_bb_elementary_traits::zero_copy_send::ZeroCopySend;

/// A type that may appear as a field of a wire struct.
///
/// Implemented for the fixed-width scalars, for fixed-size arrays of them and for every
/// struct declared with `wire_struct!`. Its constants feed the layout manifest.
pub trait WireField {
    /// The element type's name: a scalar name (`"u32"`, `"f64"`, ...) or a wire struct's
    /// Rust name.
    const ELEM: &'static str;
    /// Number of elements: 0 for a plain field, N for `[T; N]`.
    const ARRAY_LEN: usize;
}

/// A struct of the wire contract, with its layout description.
pub trait WireStruct: Sized {
    /// Size, alignment, type name and every field of this struct.
    const LAYOUT: StructLayout;
}

macro_rules! scalar_wire_field {
    ($($t:ty => $n:literal),* $(,)?) => {
        $(impl WireField for $t {
            const ELEM: &'static str = $n;
            const ARRAY_LEN: usize = 0;
        })*
    };
}
scalar_wire_field!(u8 => "u8", u16 => "u16", u32 => "u32", u64 => "u64", i8 => "i8",
    i16 => "i16", i32 => "i32", i64 => "i64", f32 => "f32", f64 => "f64");

impl<T: WireField, const N: usize> WireField for [T; N] {
    const ELEM: &'static str = T::ELEM;
    const ARRAY_LEN: usize = N;
}

/// Builds the [`FieldLayout`] of one field (used by `wire_struct!`).
#[doc(hidden)]
pub const fn field<T: WireField>(
    name: &'static str,
    offset: usize,
    doc: &'static [&'static str],
) -> FieldLayout {
    FieldLayout {
        name,
        doc,
        offset,
        size: core::mem::size_of::<T>(),
        ty: T::ELEM,
        array_len: T::ARRAY_LEN,
    }
}

/// Defines a wire struct: `#[repr(C)]`, zerocopy traits, iceoryx2 `ZeroCopySend` with an
/// explicit versioned type name, `Default` (all zero), its manifest entry, and compile-time
/// checks that the declared size and alignment hold and that no byte is padding.
macro_rules! wire_struct {
    (
        $(#[$meta:meta])*
        pub struct $name:ident : $type_name:literal, size = $size:literal, align = $align:literal {
            $( $(#[doc = $fdoc:literal])* pub $field:ident : $ty:ty ),* $(,)?
        }
    ) => {
        $(#[$meta])*
        #[derive(
            Debug, Clone, Copy, PartialEq,
            zerocopy::FromBytes, zerocopy::IntoBytes, zerocopy::KnownLayout, zerocopy::Immutable,
            iceoryx2_bb_derive_macros::ZeroCopySend,
        )]
        #[repr(C)]
        #[type_name($type_name)]
        pub struct $name {
            $( $(#[doc = $fdoc])* pub $field: $ty ),*
        }

        impl Default for $name {
            fn default() -> Self {
                <Self as zerocopy::FromZeros>::new_zeroed()
            }
        }

        impl $crate::wire::WireField for $name {
            const ELEM: &'static str = stringify!($name);
            const ARRAY_LEN: usize = 0;
        }

        impl $crate::wire::WireStruct for $name {
            const LAYOUT: $crate::manifest::StructLayout = $crate::manifest::StructLayout {
                name: stringify!($name),
                type_name: $type_name,
                size: core::mem::size_of::<$name>(),
                align: core::mem::align_of::<$name>(),
                fields: &[
                    $( $crate::wire::field::<$ty>(stringify!($field), core::mem::offset_of!($name, $field), &[$($fdoc),*]) ),*
                ],
            };
        }

        const _: () = {
            assert!(core::mem::size_of::<$name>() == $size, concat!("size of ", stringify!($name), " changed: update the declaration and the type-name version"));
            assert!(core::mem::align_of::<$name>() == $align, concat!("alignment of ", stringify!($name), " changed"));
            // No padding: the fields' sizes add up to the struct's size. (zerocopy's IntoBytes
            // derive refuses padding too; this states it where the struct is declared.)
            assert!(0 $( + core::mem::size_of::<$ty>() )* == core::mem::size_of::<$name>(), concat!(stringify!($name), " has padding"));
        };
    };
}
pub(crate) use wire_struct;
