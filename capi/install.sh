#!/bin/sh
# Installs liblimber (shared and static), its headers and limber.pc under PREFIX:
#   PREFIX/lib/liblimber.so, PREFIX/lib/liblimber.a, PREFIX/lib/pkgconfig/limber.pc,
#   PREFIX/include/limber/{limber.h, limber_client.h, limber.hpp}
# Usage: capi/install.sh PREFIX [BUILD_DIR]
#   BUILD_DIR holds liblimber.so and liblimber.a (default: target/release, or
#   $CARGO_TARGET_DIR/release): build them first with `cargo build --release -p limber-c`.
set -eu
if [ $# -lt 1 ] || [ $# -gt 2 ]; then
    echo "usage: capi/install.sh PREFIX [BUILD_DIR]" >&2
    exit 2
fi
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
build=${2:-${CARGO_TARGET_DIR:-$root/target}/release}
for f in liblimber.so liblimber.a; do
    if [ ! -f "$build/$f" ]; then
        echo "capi/install.sh: $build/$f not found (run: cargo build --release -p limber-c)" >&2
        exit 1
    fi
done
mkdir -p "$1/lib/pkgconfig" "$1/include/limber"
prefix=$(cd "$1" && pwd)
cp "$build/liblimber.so" "$build/liblimber.a" "$prefix/lib/"
cp "$root/interfaces/include/limber.h" "$here/include/limber_client.h" \
    "$here/include/limber.hpp" "$prefix/include/limber/"
version=$(sed -n 's/^version = "\(.*\)"$/\1/p' "$root/Cargo.toml" | head -n 1)
# What a program linked with liblimber.a needs besides it (rustc --print native-static-libs).
native="-lgcc_s -lutil -lrt -lpthread -lm -ldl -lc"
sed -e "s|@PREFIX@|$prefix|" -e "s|@VERSION@|$version|" -e "s|@NATIVE_LIBS@|$native|" \
    "$here/limber.pc.in" >"$prefix/lib/pkgconfig/limber.pc"
echo "installed liblimber $version in $prefix (PKG_CONFIG_PATH=$prefix/lib/pkgconfig)"
