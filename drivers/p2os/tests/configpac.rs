//! The CONFIGpac parser against a packet written byte by byte from the manual's table
//! ("Table 8. CONFIGpac contents"), and its truncated and extended variants: every
//! truncation inside the base table is an error naming the field, never a panic.

use limber_p2os::{Command, ConfigPacket, ConfigPacketError, Decoder, Frame, RobotPacket, ptype};

fn int(p: &mut Vec<u8>, v: u16) {
    p.extend_from_slice(&v.to_le_bytes());
}

fn string(p: &mut Vec<u8>, s: &str) {
    p.extend_from_slice(s.as_bytes());
    p.push(0);
}

/// A Pioneer 3-DX with the gripper, by hand from the table; the offsets of the fields
/// the tests cut at.
struct Built {
    bytes: Vec<u8>,
    /// Offset of GRIPPER.
    gripper_at: usize,
    /// Length of the base table (up to TRANSKI).
    base_len: usize,
}

fn manual_table(gripper: u16) -> Built {
    let mut p = vec![0x20];
    string(&mut p, "Pioneer"); // ROBOT TYPE
    string(&mut p, "p3dx-sh"); // SUBTYPE
    string(&mut p, "4321"); // SERIALNUM
    p.push(0); // 4MOTS
    int(&mut p, 360); // ROTVELTOP
    int(&mut p, 2200); // TRANSVELTOP
    int(&mut p, 300); // ROTACCTOP
    int(&mut p, 2000); // TRANSACCTOP
    int(&mut p, 400); // PWMMAX
    string(&mut p, "kim"); // NAME
    p.push(100); // SIPCYCLE
    p.push(0); // HOSTBAUD (9600)
    p.push(0); // AUX1BAUD
    let gripper_at = p.len();
    int(&mut p, gripper); // GRIPPER
    int(&mut p, 1); // FRONTSONAR
    p.push(0); // REARSONAR
    int(&mut p, 115); // LOWBATTERY
    int(&mut p, 16570); // REVCOUNT
    int(&mut p, 2000); // WATCHDOG
    p.push(0); // P2MPACS
    int(&mut p, 450); // STALLVAL
    int(&mut p, 100); // STALLCOUNT
    int(&mut p, 300); // JOYVEL
    int(&mut p, 60); // JOYRVEL
    for v in [
        300, 1500, 100, 100, 40, 20, 0, 300, 300, 40, 30, 0, // ROTVELMAX .. TRANSKI
    ] {
        int(&mut p, v);
    }
    let base_len = p.len();
    Built {
        bytes: p,
        gripper_at,
        base_len,
    }
}

#[test]
fn the_manuals_table_parses_field_by_field() {
    let b = manual_table(1);
    let c = ConfigPacket::parse(&b.bytes).unwrap();
    assert_eq!(c.robot_type, "Pioneer");
    assert_eq!(c.subtype, "p3dx-sh");
    assert_eq!(c.serial_number, "4321");
    assert_eq!(c.name, "kim");
    assert_eq!(
        (c.rot_vel_top, c.trans_vel_top, c.pwm_max),
        (360, 2200, 400)
    );
    assert_eq!((c.sip_cycle_ms, c.host_baud, c.aux1_baud), (100, 0, 0));
    assert_eq!((c.gripper, c.front_sonar, c.rear_sonar), (1, 1, 0));
    assert!(c.has_gripper());
    assert_eq!(
        (c.low_battery, c.rev_count, c.watchdog_ms),
        (115, 16570, 2000)
    );
    assert_eq!(
        (c.stall_val, c.stall_count, c.joy_vel, c.joy_rot_vel),
        (450, 100, 300, 60)
    );
    assert_eq!(c.working.trans_vel_max, 1500);
    assert_eq!(c.working.trans_kv, 30);
    assert_eq!(
        (c.bumpers, c.charger, c.aros18, c.extra_len),
        (None, None, None, 0)
    );
    // The encoder writes the same bytes back.
    assert_eq!(c.encode().unwrap().payload(), &b.bytes[..]);
    // And GRIPPER 0 is a robot without one.
    let none = ConfigPacket::parse(&manual_table(0).bytes).unwrap();
    assert!(!none.has_gripper());
}

#[test]
fn every_truncation_of_the_base_table_is_an_error_naming_the_field() {
    let b = manual_table(1);
    for cut in 0..b.base_len {
        let r = ConfigPacket::parse(&b.bytes[..cut]);
        match (cut, r) {
            (0, Err(ConfigPacketError::Empty)) => {}
            (_, Err(ConfigPacketError::Truncated { field, offset, len })) => {
                assert_eq!(len, cut);
                assert!(offset <= cut, "cut {cut}: offset {offset}");
                assert!(!field.is_empty());
            }
            (_, other) => panic!("cut at {cut}: {other:?}"),
        }
    }
    // Cut inside GRIPPER: the error says so.
    let e = ConfigPacket::parse(&b.bytes[..b.gripper_at + 1]).unwrap_err();
    assert_eq!(
        e,
        ConfigPacketError::Truncated {
            field: "GRIPPER",
            offset: b.gripper_at,
            len: b.gripper_at + 1
        }
    );
    assert!(e.to_string().contains("GRIPPER"), "{e}");
    // A string without its NUL.
    let e = ConfigPacket::parse(&[0x20, b'P', b'i']).unwrap_err();
    assert!(
        matches!(
            e,
            ConfigPacketError::Truncated {
                field: "ROBOT TYPE",
                ..
            }
        ),
        "{e:?}"
    );
    // Not a CONFIGpac at all.
    assert_eq!(
        ConfigPacket::parse(&[0x32, 0, 0]),
        Err(ConfigPacketError::WrongType(0x32))
    );
}

#[test]
fn later_firmwares_groups_are_read_and_further_bytes_counted() {
    let b = manual_table(1);
    // AROS 1.6: bumpers; 1.7: charger; 1.8: sonar cycle, autobaud, gyro; then a drift
    // factor and version strings of a later ARCOS, not read.
    let mut p = b.bytes.clone();
    p.extend_from_slice(&[5, 5]);
    let c = ConfigPacket::parse(&p).unwrap();
    assert_eq!((c.bumpers, c.charger, c.extra_len), (Some((5, 5)), None, 0));
    p.push(1);
    p.extend_from_slice(&[40, 2, 1]);
    let mut later = p.clone();
    later.extend_from_slice(&[0x10, 0x00, 0, 0]);
    later.extend_from_slice(b"2.7\0");
    let c = ConfigPacket::parse(&later).unwrap();
    assert_eq!(c.bumpers, Some((5, 5)));
    assert_eq!(c.charger, Some(1));
    assert_eq!(c.aros18, Some((40, 2, 1)));
    assert_eq!(c.extra_len, 8);
    assert!(c.has_gripper());
    // A group cut short is an error like any truncation.
    let e = ConfigPacket::parse(&p[..b.base_len + 1]).unwrap_err();
    assert!(
        matches!(
            e,
            ConfigPacketError::Truncated {
                field: "REARBUMPS",
                ..
            }
        ),
        "{e:?}"
    );
    let e = ConfigPacket::parse(&p[..p.len() - 1]).unwrap_err();
    assert!(
        matches!(
            e,
            ConfigPacketError::Truncated {
                field: "HASGYRO",
                ..
            }
        ),
        "{e:?}"
    );
}

#[test]
fn garbage_never_panics() {
    // Every short payload of a small alphabet, with the CONFIGpac type byte.
    let alphabet = [0u8, 1, 0x20, 0xFF, b'a'];
    let mut buf = vec![0x20u8];
    fn rec(buf: &mut Vec<u8>, depth: usize, alphabet: &[u8]) {
        let _ = ConfigPacket::parse(buf);
        if depth == 0 {
            return;
        }
        for &a in alphabet {
            buf.push(a);
            rec(buf, depth - 1, alphabet);
            buf.pop();
        }
    }
    rec(&mut buf, 6, &alphabet);
    // Long runs of NULs and of non-NULs.
    for n in 0..=252 {
        let mut p = vec![0x20];
        p.extend(std::iter::repeat_n(0u8, n));
        let _ = ConfigPacket::parse(&p);
        let mut p = vec![0x20];
        p.extend(std::iter::repeat_n(b'x', n));
        assert!(ConfigPacket::parse(&p).is_err());
    }
}

#[test]
fn config_is_command_18_without_an_argument_and_its_answer_is_framed() {
    assert_eq!(
        Command::Config.encode().unwrap().as_bytes(),
        &[0xFA, 0xFB, 0x03, 18, 0x00, 18]
    );
    let b = manual_table(1);
    let f = Frame::new(&b.bytes).unwrap();
    let mut d = Decoder::new();
    d.feed(f.as_bytes());
    let p = d.next_packet().unwrap();
    match RobotPacket::parse(p).unwrap() {
        RobotPacket::Other {
            packet_type: ptype::CONFIG,
            payload,
        } => assert!(ConfigPacket::parse(payload).unwrap().has_gripper()),
        other => panic!("{other:?}"),
    }
}
