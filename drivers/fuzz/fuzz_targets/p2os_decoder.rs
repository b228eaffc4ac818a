//! Any byte stream, fed in chunks of any size: the decoder must not panic,
//! must account for every byte, and every payload it delivers must parse
//! (or be refused) without panicking.
#![no_main]

use libfuzzer_sys::fuzz_target;
use limber_p2os::{ConfigPacket, Decoder, ReceivedCommand, RobotPacket};

fuzz_target!(|data: &[u8]| {
    let Some((&chunk, stream)) = data.split_first() else {
        return;
    };
    let chunk = usize::from(chunk).max(1);
    let mut d = Decoder::new();
    let mut delivered = 0u64;
    for part in stream.chunks(chunk) {
        d.decode(part, |p| {
            assert!(!p.is_empty());
            let _ = RobotPacket::parse(p);
            let _ = ConfigPacket::parse(p);
            let _ = ReceivedCommand::parse(p);
            delivered += 1;
        });
    }
    let s = d.stats();
    assert_eq!(s.bytes_in, stream.len() as u64);
    assert_eq!(s.packets_ok, delivered);
});
