//! Any byte stream sent to the emulated controller (after a handshake): it
//! must not panic, whatever the commands and timing.
#![no_main]

use libfuzzer_sys::fuzz_target;
use limber_emulator::{ModelConfig, Robot};
use limber_p2os::{Command, Decoder};
use std::time::{Duration, Instant};

fuzz_target!(|data: &[u8]| {
    let t0 = Instant::now();
    let mut robot = Robot::new(ModelConfig::default(), t0);
    let mut out = Vec::new();
    for c in [
        Command::Sync0,
        Command::Sync1,
        Command::Sync2,
        Command::Open,
    ] {
        if let Ok(f) = c.encode() {
            robot.handle(f.payload(), t0, &mut out);
        }
    }
    let mut d = Decoder::new();
    d.set_ignore_checksum(true);
    let mut t = t0;
    for part in data.chunks(8) {
        // The first byte of each chunk advances simulated time.
        t += Duration::from_millis(u64::from(part[0]));
        d.decode(&part[1..], |p| robot.handle(p, t, &mut out));
        robot.advance(t, &mut out);
        robot.cycle(t, &mut out);
        out.clear();
    }
});
