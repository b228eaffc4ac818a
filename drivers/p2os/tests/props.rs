//! Properties of the P2OS codec (proptest) and a fixed-seed fuzz run over
//! random and mutated frames.
//!
//! The fuzz run's size comes from `P2OS_FUZZ_FRAMES` (default 20 000):
//! `P2OS_FUZZ_FRAMES=1000000 cargo test --release -p limber-p2os --test props fuzz`.

use limber_p2os::*;
use proptest::prelude::*;
use rand::rngs::SmallRng;
use rand::{Rng as _, SeedableRng};

/// Feeds `stream` in chunks of the given sizes (cycled), collecting payloads
/// and parsing each one as a robot packet and as a command: none may panic.
fn decode_chunked(stream: &[u8], chunks: &[usize]) -> (Vec<Vec<u8>>, DecoderStats) {
    let mut d = Decoder::new();
    let mut out = Vec::new();
    let mut rest = stream;
    let mut k = 0;
    while !rest.is_empty() {
        let n = chunks
            .get(k % chunks.len().max(1))
            .copied()
            .unwrap_or(rest.len())
            .clamp(1, rest.len());
        k += 1;
        d.decode(&rest[..n], |p| {
            let _ = RobotPacket::parse(p);
            let _ = ReceivedCommand::parse(p);
            out.push(p.to_vec());
        });
        rest = &rest[n..];
    }
    (out, d.stats())
}

fn frame(payload: &[u8]) -> Vec<u8> {
    Frame::new(payload).unwrap().as_bytes().to_vec()
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 512,
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn any_byte_stream_never_panics(
        bytes in proptest::collection::vec(any::<u8>(), 0..2048),
        chunks in proptest::collection::vec(1usize..300, 1..8),
    ) {
        let (packets, stats) = decode_chunked(&bytes, &chunks);
        prop_assert_eq!(stats.bytes_in, bytes.len() as u64);
        prop_assert_eq!(stats.packets_ok, packets.len() as u64);
        // Every packet costs at least 6 bytes on the wire.
        prop_assert!(packets.len() * 6 <= bytes.len());
        for p in &packets {
            prop_assert!(!p.is_empty() && p.len() <= MAX_PAYLOAD);
        }
    }

    #[test]
    fn header_heavy_streams_never_panic(
        bytes in proptest::collection::vec(prop_oneof![Just(0xFAu8), Just(0xFB), Just(3), any::<u8>()], 0..2048),
        chunks in proptest::collection::vec(1usize..64, 1..8),
    ) {
        let (packets, stats) = decode_chunked(&bytes, &chunks);
        prop_assert_eq!(stats.packets_ok, packets.len() as u64);
    }

    #[test]
    fn encode_then_decode_is_identity(
        payloads in proptest::collection::vec(proptest::collection::vec(any::<u8>(), 1..=MAX_PAYLOAD), 1..6),
        garbage in proptest::collection::vec(proptest::collection::vec(any::<u8>().prop_filter("no header byte", |b| *b != 0xFA), 0..20), 6),
        chunks in proptest::collection::vec(1usize..400, 1..8),
    ) {
        let mut stream = Vec::new();
        for (i, p) in payloads.iter().enumerate() {
            stream.extend_from_slice(&garbage[i]);
            stream.extend(frame(p));
        }
        let (got, stats) = decode_chunked(&stream, &chunks);
        prop_assert_eq!(&got, &payloads);
        prop_assert_eq!(stats.bad_checksums, 0);
        let garbage_len: usize = garbage.iter().take(payloads.len()).map(Vec::len).sum();
        prop_assert_eq!(stats.garbage_bytes, garbage_len as u64);
    }

    #[test]
    fn commands_roundtrip_through_the_robot_side_parser(
        number in any::<u8>(),
        arg in proptest::option::of(-65535i32..=65535),
    ) {
        let cmd = Command::Custom { number, arg };
        let f = cmd.encode().unwrap();
        let rc = ReceivedCommand::parse(f.payload()).unwrap();
        prop_assert_eq!(rc.number, number);
        match arg {
            None => prop_assert_eq!(rc.arg, Argument::None),
            Some(v) => prop_assert_eq!(rc.arg, Argument::Int(v)),
        }
    }

    #[test]
    fn arm_commands_roundtrip(joint in 1u8..=6, lsb in any::<u8>()) {
        let j = ArmJoint::new(joint).unwrap();
        for cmd in [Command::ArmPos { joint: j, tick: lsb }, Command::ArmSpeed { joint: j, ms_per_step: lsb }] {
            let f = cmd.encode().unwrap();
            let rc = ReceivedCommand::parse(f.payload()).unwrap();
            prop_assert_eq!(rc.int(), Some(i32::from(u16::from_le_bytes([lsb, joint]))));
        }
    }

    #[test]
    fn typed_packets_roundtrip(ticks in any::<[u8; 6]>(), status in any::<[u8; 2]>(), cal in any::<[u8; 36]>(), nj in 0usize..=6, timer in any::<u16>()) {
        let a = ArmPacket { status_bytes: status, ticks };
        let f = a.encode().unwrap();
        prop_assert_eq!(RobotPacket::parse(f.payload()).unwrap(), RobotPacket::Arm(a));
        let joints: Vec<JointCalibration> = cal.chunks(6).take(nj).map(|c| JointCalibration {
            speed: c[0], home: c[1], min: c[2], centre: c[3], max: c[4], ticks_per_90: c[5],
        }).collect();
        let info = ArmInfo::new("v1", &joints);
        let f = info.encode().unwrap();
        prop_assert_eq!(RobotPacket::parse(f.payload()).unwrap(), RobotPacket::ArmInfo(info));
        let mut sip = Sip::default();
        sip.timer = timer;
        let f = sip.encode().unwrap();
        prop_assert_eq!(RobotPacket::parse(f.payload()).unwrap(), RobotPacket::Sip(sip));
    }

    #[test]
    fn conversions_stay_in_limits(
        centre in any::<u8>(), a in any::<u8>(), b in any::<u8>(), t in 1u8..=255,
        joint in 1u8..=6, rad in -10.0f64..10.0,
    ) {
        let (min, max) = (a.min(b), a.max(b));
        let c = JointCalibration { speed: 10, home: centre, min, centre, max, ticks_per_90: t };
        let cal = ArmCalibration::from(ArmInfo::new("p", &[c; 6]));
        let j = ArmJoint::new(joint).unwrap();
        let tt = cal.radians_to_ticks(j, rad).unwrap();
        prop_assert!(tt.tick >= min && tt.tick <= max);
        for tick in min..=max {
            let r = cal.ticks_to_radians(j, tick).unwrap();
            prop_assert_eq!(cal.radians_to_ticks(j, r).unwrap().tick, tick);
        }
        let ms = cal.speed_to_ms_per_step(j, rad.abs()).unwrap();
        prop_assert!(ms >= 1);
    }
}

/// A random frame: a typed robot packet, a typed command, or random bytes.
fn random_frame(r: &mut SmallRng) -> Vec<u8> {
    match r.random_range(0..6) {
        0 => {
            let mut sip = Sip::default();
            sip.x = r.random::<u16>();
            sip.timer = r.random::<u16>();
            let n = r.random_range(0..17) as usize;
            let readings: Vec<SonarReading> = (0..n)
                .map(|i| SonarReading {
                    index: i as u8,
                    range: r.random::<u16>(),
                })
                .collect();
            sip.set_sonars(&readings);
            sip.encode().unwrap().as_bytes().to_vec()
        }
        1 => ArmPacket {
            status_bytes: r.random::<u16>().to_le_bytes(),
            ticks: r.random(),
        }
        .encode()
        .unwrap()
        .as_bytes()
        .to_vec(),
        2 => {
            let n = r.random_range(0..7) as usize;
            let joints: Vec<JointCalibration> = (0..n)
                .map(|_| JointCalibration {
                    speed: r.random::<u8>(),
                    home: r.random::<u8>(),
                    min: r.random::<u8>(),
                    centre: r.random::<u8>(),
                    max: r.random::<u8>(),
                    ticks_per_90: r.random::<u8>(),
                })
                .collect();
            ArmInfo::new("fuzz", &joints)
                .encode()
                .unwrap()
                .as_bytes()
                .to_vec()
        }
        3 => Command::Custom {
            number: r.random::<u8>(),
            arg: if r.random_range(0..2) == 0 {
                None
            } else {
                Some(r.random_range(-65535..=65535))
            },
        }
        .encode()
        .unwrap()
        .as_bytes()
        .to_vec(),
        _ => {
            let n = 1 + r.random_range(0..MAX_PAYLOAD as u64) as usize;
            let mut p: Vec<u8> = (0..n).map(|_| r.random::<u8>()).collect();
            // Often a known packet type, to reach the typed parsers.
            if r.random_range(0..2) == 0 {
                p[0] = [0x00, 0x02, 0x32, 0xA0, 0xA1, 0xE0][r.random_range(0..6) as usize];
            }
            frame(&p)
        }
    }
}

/// Mutates a frame in place: bit flips, byte changes, inserts, deletes,
/// truncation, a wrong length byte, or extra header bytes.
fn mutate(r: &mut SmallRng, f: &mut Vec<u8>) {
    for _ in 0..1 + r.random_range(0..3) {
        if f.is_empty() {
            f.push(r.random::<u8>());
        }
        let i = r.random_range(0..f.len() as u64) as usize;
        match r.random_range(0..7) {
            0 => f[i] ^= 1 << r.random_range(0..8),
            1 => f[i] = r.random::<u8>(),
            2 => f.insert(i, r.random::<u8>()),
            3 => {
                f.remove(i);
            }
            4 => f.truncate(i),
            5 => {
                if f.len() > 2 {
                    f[2] = r.random::<u8>();
                }
            }
            _ => f.splice(i..i, [0xFA, 0xFB]).for_each(drop),
        }
    }
}

#[test]
fn fuzz_random_and_mutated_frames() {
    let count: u64 = std::env::var("P2OS_FUZZ_FRAMES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(20_000);
    // A fixed seed: every run fuzzes the same frames.
    let mut r = SmallRng::seed_from_u64(0x00C0_FFEE_0000_2026);
    let mut d = Decoder::new();
    let mut fed = 0u64;
    let mut intact = 0u64;
    let mut delivered = 0u64;
    let mut stream = Vec::with_capacity(1 << 16);
    let mut frames = 0u64;
    while frames < count {
        stream.clear();
        // A batch of frames with mutations and garbage between them.
        for _ in 0..64.min(count - frames) {
            frames += 1;
            let mut f = random_frame(&mut r);
            match r.random_range(0..10) {
                0..=3 => intact += 1,
                4..=8 => mutate(&mut r, &mut f),
                _ => {
                    let n = r.random_range(0..40) as usize;
                    f = (0..n).map(|_| r.random::<u8>()).collect();
                }
            }
            stream.extend_from_slice(&f);
        }
        let mut rest = &stream[..];
        while !rest.is_empty() {
            let n = (1 + r.random_range(0..512) as usize).min(rest.len());
            d.decode(&rest[..n], |p| {
                delivered += 1;
                let _ = RobotPacket::parse(p);
                let _ = limber_p2os::ConfigPacket::parse(p);
                let _ = ReceivedCommand::parse(p);
            });
            fed += n as u64;
            rest = &rest[n..];
        }
    }
    let s = d.stats();
    assert_eq!(s.bytes_in, fed);
    assert_eq!(s.packets_ok, delivered);
    // A corrupted frame can swallow the next one only if its bogus checksum
    // happens to match; the rescan after a bad checksum finds the rest.
    assert!(
        delivered * 100 >= intact * 99,
        "intact frames {intact}, delivered {delivered}, stats {s:?}"
    );
    println!("fuzz: {frames} frames, {fed} bytes, {intact} intact, stats {s:?}");
}
