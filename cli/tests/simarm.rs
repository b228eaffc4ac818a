//! `limber simarm`'s arguments.

use std::time::Duration;

use clap::Parser;
use limber_cli::simarm::SimArmArgs;
use limber_simarm::SimObject;

#[derive(Parser)]
struct Cmd {
    #[command(flatten)]
    args: SimArmArgs,
}

fn parse(a: &[&str]) -> Result<SimArmArgs, clap::Error> {
    Cmd::try_parse_from(std::iter::once("simarm").chain(a.iter().copied())).map(|c| c.args)
}

#[test]
fn defaults_are_the_6dof_arm_named_simarm() {
    let a = parse(&[]).unwrap();
    assert_eq!(a.chain().unwrap().dof(), 6);
    let o = a.options();
    assert_eq!(o.robot, "simarm");
    assert_eq!(o.tick, Duration::from_millis(10));
    assert_eq!(o.time_scale, 1.0);
    assert_eq!(o.object, None);
    assert_eq!(o.store_capacity, 0);
    assert!(o.brakes);
}

#[test]
fn chains_and_options() {
    assert_eq!(
        parse(&["--builtin", "7dof"])
            .unwrap()
            .chain()
            .unwrap()
            .dof(),
        7
    );
    assert_eq!(parse(&["--chain-7dof"]).unwrap().chain().unwrap().dof(), 7);
    let dir = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../drivers/kinematics/chains/arm7.toml"
    );
    assert_eq!(
        parse(&["--chain", dir]).unwrap().chain().unwrap().name(),
        "arm7"
    );
    assert!(
        parse(&["--chain", "/nonexistent.toml"])
            .unwrap()
            .chain()
            .is_err()
    );
    assert!(parse(&["--chain", dir, "--builtin", "6dof"]).is_err());
    assert!(parse(&["--tick-ms", "0"]).is_err());
    let a = parse(&[
        "--robot",
        "arm2",
        "--tick-ms",
        "5",
        "--time-scale",
        "2.5",
        "--object",
        "0.45,0.1,0.15,0.04",
    ])
    .unwrap();
    let o = a.options();
    assert_eq!(o.robot, "arm2");
    assert_eq!(o.tick, Duration::from_millis(5));
    assert_eq!(o.time_scale, 2.5);
    assert_eq!(o.object, Some(SimObject::block([0.45, 0.1, 0.15], 0.04)));
    assert!(parse(&["--object", "0.45,0.1"]).is_err());
    let o = parse(&["--store-capacity", "3", "--no-brakes"])
        .unwrap()
        .options();
    assert_eq!(o.store_capacity, 3);
    assert!(!o.brakes);
    assert!(parse(&["--store-capacity", "5000"]).is_err());
}
