#!/bin/sh
# The soak run (not in CI): builds the test binaries and runs `limber-soak` for MINUTES
# minutes (default 10) with CLIENTS client threads (default 6), under nice.
# Usage: tests/soak/soak.sh [MINUTES] [CLIENTS]
# Exits 1 on a crash or an accounting mismatch; prints one line per epoch and a summary.
set -eu
minutes="${1:-10}"
clients="${2:-6}"
cd "$(dirname "$0")/../.."
cargo build -q -p limber-tests --bins
bin="${CARGO_TARGET_DIR:-$PWD/target}/debug"
exec nice "$bin/limber-soak" --minutes "$minutes" --clients "$clients"
