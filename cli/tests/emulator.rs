//! `limber emulator`'s arguments.

use std::time::Duration;

use clap::Parser;
use limber_cli::emulator::EmulatorArgs;

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
