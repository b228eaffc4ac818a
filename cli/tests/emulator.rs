//! `limber emulator`'s arguments.

use std::time::Duration;

use clap::Parser;
use limber_cli::emulator::EmulatorArgs;
use limber_emulator::{ArmpacLayout, GripperByteLayout, Timing};

fn ms(n: u64) -> Duration {
    Duration::from_millis(n)
}

#[derive(Parser)]
struct Cli {
    #[command(flatten)]
    args: EmulatorArgs,
}

#[test]
fn cli_arguments() {
    let c = Cli::try_parse_from(["emulator", "--tcp"]).unwrap();
    assert_eq!(c.args.tcp, Some(8101));
    let c =
        Cli::try_parse_from(["emulator", "--tcp", "0", "--cycle-ms", "20", "--no-arm"]).unwrap();
    let cfg = c.args.config().unwrap();
    assert_eq!(c.args.tcp, Some(0));
    assert_eq!(cfg.cycle, ms(20));
    assert!(cfg.model.arm.is_none());
    let c = Cli::try_parse_from(["emulator", "--pty", "--drop-rate", "2"]).unwrap();
    assert!(c.args.config().is_err());
    assert!(Cli::try_parse_from(["emulator", "--pty", "--tcp", "1"]).is_err());
    let c = Cli::try_parse_from(["emulator"]).unwrap();
    assert!(c.args.tcp.is_none() && !c.args.pty);
}

/// Issue 13 items 1 and 3: the controller's timing and the manuals' ARMpac layout by
/// default; `--fast` and `--armpac-layout aria` select the others.
#[test]
fn timing_and_armpac_layout_flags() {
    let cfg = Cli::try_parse_from(["emulator"])
        .unwrap()
        .args
        .config()
        .unwrap();
    assert_eq!(cfg.timing, Timing::Controller);
    assert_eq!(cfg.model.armpac_layout, ArmpacLayout::Manual);
    let c =
        Cli::try_parse_from(["emulator", "--pty", "--fast", "--armpac-layout", "aria"]).unwrap();
    let cfg = c.args.config().unwrap();
    assert_eq!(cfg.timing, Timing::Fast);
    assert_eq!(cfg.model.armpac_layout, ArmpacLayout::Aria);
    let c = Cli::try_parse_from(["emulator", "--armpac-layout", "manual"]).unwrap();
    assert_eq!(
        c.args.config().unwrap().model.armpac_layout,
        ArmpacLayout::Manual
    );
    assert!(Cli::try_parse_from(["emulator", "--armpac-layout", "player"]).is_err());
    // The gripper state byte: the Pioneer Gripper manual's by default, ARIA's on request.
    assert_eq!(cfg.model.gripper_byte, GripperByteLayout::Manual);
    let c = Cli::try_parse_from(["emulator", "--gripper-byte", "aria"]).unwrap();
    assert_eq!(
        c.args.config().unwrap().model.gripper_byte,
        GripperByteLayout::Aria
    );
    assert!(Cli::try_parse_from(["emulator", "--gripper-byte", "player"]).is_err());
}

/// `--drop-arm-info N` (from `limber emulator --help`): the first N ARMINFOpac replies are
/// dropped; none by default.
#[test]
fn drop_arm_info_flag() {
    let cfg = Cli::try_parse_from(["emulator"])
        .unwrap()
        .args
        .config()
        .unwrap();
    assert_eq!(cfg.faults.drop_arm_info_replies, 0);
    let c = Cli::try_parse_from(["emulator", "--pty", "--drop-arm-info", "2"]).unwrap();
    assert_eq!(c.args.config().unwrap().faults.drop_arm_info_replies, 2);
    assert!(Cli::try_parse_from(["emulator", "--drop-arm-info", "-1"]).is_err());
}

/// Issue 13 item 4: `--no-gripper` is a robot without the body gripper (its CONFIGpac says
/// so), `--no-config` a controller that never answers CONFIG; by default it has the
/// gripper and answers.
#[test]
fn gripper_and_config_flags() {
    let cfg = Cli::try_parse_from(["emulator"])
        .unwrap()
        .args
        .config()
        .unwrap();
    assert!(cfg.model.gripper && !cfg.faults.no_config);
    let cfg = Cli::try_parse_from(["emulator", "--pty", "--no-gripper", "--no-config"])
        .unwrap()
        .args
        .config()
        .unwrap();
    assert!(!cfg.model.gripper && cfg.faults.no_config);
}
