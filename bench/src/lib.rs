//! limber-bench: latency scenarios (built by the benchmarks issue).
