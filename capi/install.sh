#!/bin/sh
# Installs liblimber, its headers and limber.pc under PREFIX:
#   PREFIX/lib/liblimber.so, PREFIX/lib/liblimber.a (when built), PREFIX/lib/pkgconfig/limber.pc,
#   PREFIX/include/limber/{limber.h, limber_client.h, limber.hpp}
# Usage: capi/install.sh [--shared-only] [--keep-debug] PREFIX [BUILD_DIR]
#   BUILD_DIR holds liblimber.so (and liblimber.a) (default: target/release, or
#   $CARGO_TARGET_DIR/release): build them first with `cargo build --release -p limber-c`.
#   --shared-only   install the shared library alone (liblimber.a is not needed).
#   --keep-debug    keep the debug information (the release profile keeps line tables for
#                   backtraces: most of the library's size); stripped by default when
#                   `strip` is found.
# The headers come from this source tree and the library from BUILD_DIR: before anything is
# copied, a program compiled against these headers is linked with that library and must find
# the same layout version (a library built from another checkout is refused, exit 1).
set -eu
shared_only=0
keep_debug=0
while [ $# -gt 0 ]; do
    case "$1" in
    --shared-only) shared_only=1; shift ;;
    --keep-debug) keep_debug=1; shift ;;
    --) shift; break ;;
    -*) echo "capi/install.sh: unknown option $1" >&2
        echo "usage: capi/install.sh [--shared-only] [--keep-debug] PREFIX [BUILD_DIR]" >&2
        exit 2 ;;
    *) break ;;
    esac
done
if [ $# -lt 1 ] || [ $# -gt 2 ]; then
    echo "usage: capi/install.sh [--shared-only] [--keep-debug] PREFIX [BUILD_DIR]" >&2
    exit 2
fi
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
build=${2:-${CARGO_TARGET_DIR:-$root/target}/release}
need="liblimber.so"
[ "$shared_only" = 1 ] || need="$need liblimber.a"
for f in $need; do
    if [ ! -f "$build/$f" ]; then
        echo "capi/install.sh: $build/$f not found (run: cargo build --release -p limber-c$( [ "$f" = liblimber.a ] && echo ', or install with --shared-only'))" >&2
        exit 1
    fi
done
# The headers of this tree and the library of BUILD_DIR must speak one layout.
cc=${CC:-cc}
if command -v "$cc" >/dev/null 2>&1; then
    check=$(mktemp -d)
    trap 'rm -rf "$check"' EXIT
    printf '#include "limber_client.h"\n#include <stdio.h>\nint main(void) {\n  if (limber_layout_version() == LIMBER_LAYOUT_VERSION) return 0;\n  fprintf(stderr, "the headers speak layout version %%u, the library %%u", (unsigned)LIMBER_LAYOUT_VERSION, limber_layout_version());\n  return 1;\n}\n' >"$check/check.c"
    if ! "$cc" -I "$here/include" -I "$root/interfaces/include" "$check/check.c" -o "$check/check" \
        -L "$build" -llimber -Wl,--disable-new-dtags,-rpath,"$build" 2>"$check/err"; then
        echo "capi/install.sh: cannot link a program against $build/liblimber.so:" >&2
        cat "$check/err" >&2
        exit 1
    fi
    if ! "$check/check" 2>"$check/err"; then
        echo "capi/install.sh: $build/liblimber.so was not built from this tree: $(cat "$check/err") (rebuild it: cargo build --release -p limber-c)" >&2
        exit 1
    fi
else
    echo "capi/install.sh: no C compiler ($cc): the library's layout version is not checked against the headers" >&2
fi
mkdir -p "$1/lib/pkgconfig" "$1/include/limber"
prefix=$(cd "$1" && pwd)
cp "$build/liblimber.so" "$prefix/lib/"
if [ "$shared_only" = 0 ]; then
    cp "$build/liblimber.a" "$prefix/lib/"
fi
if [ "$keep_debug" = 0 ] && command -v strip >/dev/null 2>&1; then
    strip --strip-debug "$prefix/lib/liblimber.so"
fi
cp "$root/interfaces/include/limber.h" "$here/include/limber_client.h" \
    "$here/include/limber.hpp" "$prefix/include/limber/"
version=$(sed -n 's/^version = "\(.*\)"$/\1/p' "$root/Cargo.toml" | head -n 1)
# What a program linked with liblimber.a needs besides it (rustc --print native-static-libs).
native="-lgcc_s -lutil -lrt -lpthread -lm -ldl -lc"
sed -e "s|@PREFIX@|$prefix|" -e "s|@VERSION@|$version|" -e "s|@NATIVE_LIBS@|$native|" \
    "$here/limber.pc.in" >"$prefix/lib/pkgconfig/limber.pc"
size=$(wc -c <"$prefix/lib/liblimber.so")
echo "installed liblimber $version in $prefix ($(( size / 1024 )) KiB shared library$( [ "$shared_only" = 1 ] && echo ', shared only')) (PKG_CONFIG_PATH=$prefix/lib/pkgconfig)"
