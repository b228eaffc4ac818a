//! The decoder and the link's receive path allocate nothing per packet (counted on this
//! thread, which does all the decoding and receiving).

use limber_counting_alloc::{Counting, allocations};
use limber_p2os::*;
use serialport::TTYPort;
use std::io::Write;
use std::time::Duration;

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn decoding_and_receiving_do_not_allocate() {
    let arm = ArmPacket {
        status_bytes: [0x03, 0x05],
        ticks: [1, 2, 3, 4, 5, 6],
    }
    .encode()
    .unwrap();
    let mut sip = Sip::default();
    sip.set_sonars(&[SonarReading::default(); 16]);
    let sip = sip.encode().unwrap();
    let mut stream = Vec::new();
    for i in 0..200 {
        stream.extend_from_slice(arm.as_bytes());
        stream.extend_from_slice(&[0x00, 0xFA, i as u8]);
        stream.extend_from_slice(sip.as_bytes());
    }
    let mut d = Decoder::new();

    let before = allocations();
    let mut n = 0;
    for chunk in stream.chunks(37) {
        d.decode(chunk, |p| {
            if RobotPacket::parse(p).is_ok() {
                n += 1;
            }
        });
    }
    assert_eq!(allocations(), before, "decoder allocated");
    assert_eq!(n, 400);

    // The link's receive path over a pty.
    let (mut master, slave) = TTYPort::pair().unwrap();
    let mut link = Link::from_serial_port(slave).unwrap();
    let frames: Vec<u8> = [arm.as_bytes(), sip.as_bytes()].concat();
    let mut got = 0;
    let before = allocations();
    for _ in 0..50 {
        master.write_all(&frames).unwrap();
        for _ in 0..2 {
            match link.recv(Duration::from_secs(5)) {
                Ok(RobotPacket::Arm(_)) | Ok(RobotPacket::Sip(_)) => got += 1,
                other => panic!("{other:?}"),
            }
        }
        link.send(&Command::Pulse).unwrap();
    }
    assert_eq!(allocations(), before, "link allocated");
    assert_eq!(got, 100);
}
