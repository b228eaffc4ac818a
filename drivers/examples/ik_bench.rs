//! IK solve-time percentiles: `cargo run --release -p limber-drivers --example ik_bench [N]`.

fn main() {
    let n = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(20_000);
    println!("{}", limber_drivers::kinematics::bench::ik_solve_times(n));
}
