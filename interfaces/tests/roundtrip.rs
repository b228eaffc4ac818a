//! Every message round-trips through bytes and through its typed view; unknown codes and
//! non-finite numbers are rejected with a named error.
#![allow(clippy::field_reassign_with_default)]

use limber_interfaces::prelude::*;
use limber_interfaces::{actarray, gripper, limb};
use proptest::prelude::*;
use zerocopy::{FromBytes, IntoBytes};

/// Through the raw bytes (as another process would see them) and back to the typed view.
fn via_bytes<M: Message + PartialEq + core::fmt::Debug>(m: &M) -> M
where
    M::Raw: IntoBytes + FromBytes + zerocopy::Immutable,
{
    let mut raw = M::Raw::default();
    m.write(&mut raw);
    let bytes = raw.as_bytes().to_vec();
    let back = M::Raw::read_from_bytes(&bytes).expect("size matches");
    M::read(&back).expect("valid message decodes")
}

fn finite() -> impl Strategy<Value = f64> {
    -1.0e6f64..1.0e6
}
fn vec3() -> impl Strategy<Value = Vec3> {
    (finite(), finite(), finite()).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}
fn dir3() -> impl Strategy<Value = Vec3> {
    vec3().prop_filter("non-zero", |v| v.norm() > 1e-3)
}
fn joint() -> impl Strategy<Value = i64> {
    0i64..MAX_ACTUATORS as i64
}
fn values() -> impl Strategy<Value = Vec<f64>> {
    prop::collection::vec(finite(), 0..=MAX_ACTUATORS)
}

fn actarray_command() -> impl Strategy<Value = ActArrayCommand> {
    prop_oneof![
        (joint(), finite()).prop_map(|(j, p)| ActArrayCommand::position(j, p).unwrap()),
        values().prop_map(|v| ActArrayCommand::multi_position(&v).unwrap()),
        (joint(), finite()).prop_map(|(j, s)| ActArrayCommand::speed(j, s).unwrap()),
        values().prop_map(|v| ActArrayCommand::multi_speed(&v).unwrap()),
        (-1i64..MAX_ACTUATORS as i64).prop_map(|j| ActArrayCommand::home(j).unwrap()),
        (-1i64..MAX_ACTUATORS as i64, finite())
            .prop_map(|(j, c)| ActArrayCommand::current(j, c).unwrap()),
        values().prop_map(|v| ActArrayCommand::multi_current(&v).unwrap()),
    ]
}

fn actarray_request() -> impl Strategy<Value = ActArrayRequest> {
    prop_oneof![
        any::<bool>().prop_map(ActArrayRequest::Power),
        any::<bool>().prop_map(ActArrayRequest::Brakes),
        Just(ActArrayRequest::GetGeom),
        (joint(), finite()).prop_map(|(j, s)| ActArrayRequest::speed(j, s).unwrap()),
        (joint(), finite()).prop_map(|(j, a)| ActArrayRequest::accel(j, a).unwrap()),
    ]
}

fn limb_command() -> impl Strategy<Value = LimbCommand> {
    prop_oneof![
        Just(LimbCommand::Home),
        Just(LimbCommand::Stop),
        (vec3(), dir3(), dir3()).prop_map(|(p, a, o)| LimbCommand::set_pose(p, a, o).unwrap()),
        vec3().prop_map(|p| LimbCommand::set_position(p).unwrap()),
        (dir3(), finite()).prop_map(|(d, l)| LimbCommand::vec_move(d, l).unwrap()),
        (vec3(), 0.0f64..10.0).prop_map(|(p, v)| LimbCommand::line(p, None, v).unwrap()),
        (vec3(), dir3(), dir3(), 0.0f64..10.0).prop_map(|(p, a, o, v)| LimbCommand::ptp(
            p,
            Some((a, o)),
            v
        )
        .unwrap()),
    ]
}

fn limb_request() -> impl Strategy<Value = LimbRequest> {
    prop_oneof![
        any::<bool>().prop_map(LimbRequest::Power),
        any::<bool>().prop_map(LimbRequest::Brakes),
        Just(LimbRequest::Geom),
        finite().prop_map(|s| LimbRequest::speed(s).unwrap()),
    ]
}

fn gripper_command() -> impl Strategy<Value = GripperCommand> {
    prop_oneof![
        Just(GripperCommand::Open),
        Just(GripperCommand::Close),
        Just(GripperCommand::Stop),
        Just(GripperCommand::Store),
        Just(GripperCommand::Retrieve),
        (0.0f64..1.0, 0.0f64..100.0, 0.0f64..1.0)
            .prop_map(|(g, e, v)| GripperCommand::goal(g, e, v).unwrap()),
    ]
}

fn actuator_geom() -> impl Strategy<Value = ActuatorGeom> {
    (
        1u32..=2,
        0u32..=1,
        finite(),
        vec3(),
        finite(),
        finite(),
        finite(),
    )
        .prop_map(
            |(kind, has_brakes, length, axis, min, max, speed)| ActuatorGeom {
                kind,
                has_brakes,
                length,
                orientation: Orientation3 {
                    roll: min,
                    pitch: max,
                    yaw: speed,
                },
                axis,
                min: min.min(max),
                centre: (min + max) / 2.0,
                max: min.max(max),
                home: min,
                config_speed: speed,
            },
        )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn actarray_commands_roundtrip(c in actarray_command()) {
        prop_assert_eq!(via_bytes(&c), c);
    }

    #[test]
    fn actarray_requests_roundtrip(r in actarray_request()) {
        prop_assert_eq!(via_bytes(&r), r);
    }

    #[test]
    fn limb_commands_roundtrip(c in limb_command()) {
        prop_assert_eq!(via_bytes(&c), c);
    }

    #[test]
    fn limb_requests_roundtrip(r in limb_request()) {
        prop_assert_eq!(via_bytes(&r), r);
    }

    #[test]
    fn gripper_commands_roundtrip(c in gripper_command()) {
        prop_assert_eq!(via_bytes(&c), c);
        prop_assert_eq!(via_bytes(&GripperRequest::GetGeom), GripperRequest::GetGeom);
    }

    #[test]
    fn actarray_replies_roundtrip(geoms in prop::collection::vec(actuator_geom(), 0..=MAX_ACTUATORS), base in vec3(), nack in 1u32..=10) {
        let mut g = ActArrayGeom::default();
        g.actuators_count = geoms.len() as u32;
        g.actuators[..geoms.len()].copy_from_slice(&geoms);
        g.base_pos = base;
        let mut raw = ActArrayReplyMsg::default();
        ActArrayReply::write(actarray::req::GET_GEOM, Ok(&ActArrayReply::Geom(g)), &mut raw);
        let back = ActArrayReplyMsg::read_from_bytes(raw.as_bytes()).unwrap();
        prop_assert_eq!(ActArrayReply::read(&back).unwrap(), Ok(ActArrayReply::Geom(g)));
        let status = Status::try_from(nack).unwrap();
        ActArrayReply::write(actarray::req::POWER, Err(status), &mut raw);
        prop_assert_eq!(ActArrayReply::read(&raw).unwrap(), Err(status));
        ActArrayReply::write(actarray::req::POWER, Ok(&ActArrayReply::Done), &mut raw);
        prop_assert_eq!(ActArrayReply::read(&raw).unwrap(), Ok(ActArrayReply::Done));
    }

    #[test]
    fn limb_and_gripper_replies_roundtrip(base in vec3(), pos in vec3(), nack in 1u32..=10) {
        let mut raw = LimbReplyMsg::default();
        let g = LimbGeom { base_pos: base };
        LimbReply::write(limb::req::GEOM, Ok(&LimbReply::Geom(g)), &mut raw);
        prop_assert_eq!(LimbReply::read(&raw).unwrap(), Ok(LimbReply::Geom(g)));
        LimbReply::write(limb::req::SPEED, Err(Status::try_from(nack).unwrap()), &mut raw);
        prop_assert_eq!(LimbReply::read(&raw).unwrap(), Err(Status::try_from(nack).unwrap()));
        let mut graw = GripperReplyMsg::default();
        let gg = GripperGeom {
            pose: Pose3 { position: pos, orientation: Orientation3::default() },
            outer_size: Bbox3 { width: 0.3, length: 0.2, height: 0.04 },
            inner_size: Bbox3 { width: 0.2, length: 0.1, height: 0.04 },
            num_beams: 2,
            capacity: 0,
        };
        GripperReply::write(gripper::req::GET_GEOM, Ok(&GripperReply::Geom(gg)), &mut graw);
        prop_assert_eq!(GripperReply::read(&graw).unwrap(), Ok(GripperReply::Geom(gg)));
    }

    #[test]
    fn state_samples_roundtrip_through_bytes(pos in prop::collection::vec(finite(), 0..=MAX_ACTUATORS), st in 1u32..=5, seq in any::<u64>()) {
        let mut d = ActArrayData::default();
        d.header.seq = seq;
        d.actuators_count = pos.len() as u32;
        for (a, p) in d.actuators.iter_mut().zip(&pos) {
            a.position = *p;
            a.state = ActuatorFlags::IDLE.bits();
        }
        let back = ActArrayData::read_from_bytes(d.as_bytes()).unwrap();
        prop_assert_eq!(back, d);
        prop_assert!(back.validate().is_ok());
        let mut l = LimbData::default();
        l.state = st;
        l.position = Vec3::new(pos.first().copied().unwrap_or(0.0), 0.0, 0.0);
        prop_assert!(LimbData::read_from_bytes(l.as_bytes()).unwrap().validate().is_ok());
    }

    /// Arbitrary bytes never panic a decoder; what decodes re-encodes to the same view.
    #[test]
    fn arbitrary_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 3416)) {
        let raw = ActArrayCmdMsg::read_from_prefix(&bytes).unwrap().0;
        if let Ok(c) = ActArrayCommand::read(&raw) { prop_assert_eq!(via_bytes(&c), c); }
        let raw = ActArrayReqMsg::read_from_prefix(&bytes).unwrap().0;
        if let Ok(r) = ActArrayRequest::read(&raw) { prop_assert_eq!(via_bytes(&r), r); }
        let raw = LimbCmdMsg::read_from_prefix(&bytes).unwrap().0;
        if let Ok(c) = LimbCommand::read(&raw) { prop_assert_eq!(via_bytes(&c), c); }
        let raw = LimbReqMsg::read_from_prefix(&bytes).unwrap().0;
        if let Ok(r) = LimbRequest::read(&raw) { prop_assert_eq!(via_bytes(&r), r); }
        let raw = GripperCmdMsg::read_from_prefix(&bytes).unwrap().0;
        let _ = GripperCommand::read(&raw);
        let _ = ActArrayReply::read(&ActArrayReplyMsg::read_from_prefix(&bytes).unwrap().0);
        let _ = LimbReply::read(&LimbReplyMsg::read_from_prefix(&bytes).unwrap().0);
        let _ = GripperReply::read(&GripperReplyMsg::read_from_prefix(&bytes).unwrap().0);
        let _ = ActArrayData::read_from_prefix(&bytes).unwrap().0.validate();
        let _ = LimbData::read_from_prefix(&bytes).unwrap().0.validate();
        let _ = GripperData::read_from_prefix(&bytes).unwrap().0.validate();
    }
}

#[test]
fn unknown_kinds_are_named_errors() {
    let mut raw = ActArrayCmdMsg::default();
    raw.meta.kind = 99;
    assert_eq!(
        ActArrayCommand::read(&raw),
        Err(DecodeError::UnknownKind {
            channel: "actarray command",
            kind: 99
        })
    );
    let mut raw = LimbReqMsg::default();
    raw.meta.kind = 0;
    assert!(matches!(
        LimbRequest::read(&raw),
        Err(DecodeError::UnknownKind { kind: 0, .. })
    ));
    let mut raw = GripperCmdMsg::default();
    raw.meta.kind = 7;
    assert!(matches!(
        GripperCommand::read(&raw),
        Err(DecodeError::UnknownKind { kind: 7, .. })
    ));
    let mut raw = GripperReplyMsg::default();
    raw.meta.status = 42;
    assert_eq!(
        GripperReply::read(&raw),
        Err(DecodeError::UnknownCode {
            field: "status",
            value: 42
        })
    );
}

#[test]
fn unknown_codes_in_state_are_named_errors() {
    let mut d = ActArrayData::default();
    d.actuators_count = 1;
    d.actuators[0].state = 32;
    assert_eq!(
        d.validate(),
        Err(DecodeError::UnknownBits {
            field: "actuator state",
            bits: 32
        })
    );
    d.actuators_count = 33;
    assert!(matches!(
        d.validate(),
        Err(DecodeError::Value(ValueError::TooMany { .. }))
    ));
    let mut l = LimbData::default();
    l.state = 6;
    assert_eq!(
        l.validate(),
        Err(DecodeError::UnknownCode {
            field: "limb state",
            value: 6
        })
    );
    let g = GripperData::default();
    assert_eq!(
        g.validate(),
        Err(DecodeError::UnknownCode {
            field: "gripper state",
            value: 0
        })
    );
    let mut geom = ActuatorGeom::default();
    geom.kind = 3;
    assert!(geom.actuator_kind().is_err());
    assert!(Status::try_from(Status::ALL.last().unwrap().code() + 1).is_err());
    let mut raw = ActArrayReqMsg::default();
    raw.meta.kind = actarray::req::POWER;
    raw.meta.body_len = 4;
    raw.body[0] = 2;
    assert_eq!(
        ActArrayRequest::read(&raw),
        Err(DecodeError::UnknownCode {
            field: "power value",
            value: 2
        })
    );
}

#[test]
fn non_finite_values_are_rejected() {
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        assert_eq!(
            ActArrayCommand::position(0, bad),
            Err(ValueError::NotFinite { field: "position" })
        );
        assert_eq!(
            ActArrayCommand::multi_position(&[0.0, bad]),
            Err(ValueError::NotFinite { field: "positions" })
        );
        assert!(
            LimbCommand::set_pose(
                Vec3::new(bad, 0.0, 0.0),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(0.0, 0.0, 1.0)
            )
            .is_err()
        );
        assert!(LimbCommand::vec_move(Vec3::new(1.0, 0.0, 0.0), bad).is_err());
        assert!(LimbRequest::speed(bad).is_err());
        // A NaN written straight into the raw bytes (as a C program could) is caught on decode.
        let mut raw = ActArrayCmdMsg::default();
        ActArrayCommand::position(1, 0.0).unwrap().write(&mut raw);
        raw.body[8..16].copy_from_slice(&bad.to_ne_bytes());
        assert_eq!(
            ActArrayCommand::read(&raw),
            Err(DecodeError::Value(ValueError::NotFinite {
                field: "position"
            }))
        );
        let mut d = LimbData {
            state: 1,
            ..LimbData::default()
        };
        d.approach.y = bad;
        assert!(matches!(
            d.validate(),
            Err(DecodeError::Value(ValueError::NotFinite {
                field: "approach"
            }))
        ));
    }
    assert_eq!(
        LimbCommand::set_pose(Vec3::default(), Vec3::default(), Vec3::new(0.0, 0.0, 1.0)),
        Err(ValueError::ZeroVector { field: "approach" })
    );
    assert!(matches!(
        ActArrayCommand::position(32, 0.0),
        Err(ValueError::BadJoint { joint: 32, .. })
    ));
    // The valid range as a person reads it: 32 is not valid, 31 is the last.
    assert_eq!(
        ActArrayCommand::position(32, 0.0).unwrap_err().to_string(),
        "joint 32 is not a valid joint index (0 to 31)"
    );
    assert!(matches!(
        ActArrayCommand::position(-1, 0.0),
        Err(ValueError::BadJoint { .. })
    ));
    assert!(ActArrayCommand::home(-1).is_ok());
    assert!(matches!(
        ActArrayCommand::multi_position(&[0.0; 33]),
        Err(ValueError::TooMany { count: 33, .. })
    ));
}

#[test]
fn a_path_is_finite_with_a_speed_not_negative_and_a_known_orientation_mode() {
    let p = Vec3::new(0.4, 0.0, 0.3);
    assert_eq!(
        LimbCommand::line(p, None, -0.1),
        Err(ValueError::Negative { field: "speed" })
    );
    assert_eq!(
        LimbCommand::ptp(p, Some((Vec3::default(), Vec3::new(1.0, 0.0, 0.0))), 0.0),
        Err(ValueError::ZeroVector { field: "approach" })
    );
    assert_eq!(
        LimbCommand::line(Vec3::new(f64::NAN, 0.0, 0.0), None, 0.0),
        Err(ValueError::NotFinite { field: "position" })
    );
    // An orientation mode nobody defined: refused by the decoder.
    let mut raw = LimbCmdMsg::default();
    LimbCommand::line(p, None, 0.1).unwrap().write(&mut raw);
    assert_eq!(raw.meta.body_len, 88);
    raw.body[80..84].copy_from_slice(&7u32.to_ne_bytes());
    assert!(matches!(
        LimbCommand::read(&raw),
        Err(DecodeError::UnknownCode {
            field: "path orientation",
            value: 7
        })
    ));
}

#[test]
fn a_gripper_goal_is_finite_and_not_negative() {
    assert_eq!(
        GripperCommand::goal(-0.01, 0.0, 0.0),
        Err(ValueError::Negative { field: "gap" })
    );
    assert_eq!(
        GripperCommand::goal(0.02, -1.0, 0.0),
        Err(ValueError::Negative { field: "effort" })
    );
    assert_eq!(
        GripperCommand::goal(0.02, 0.0, f64::NAN),
        Err(ValueError::NotFinite { field: "speed" })
    );
    // A raw GOAL with a negative gap fails to decode: the driver answers INVALID_ARGUMENT.
    let mut raw = GripperCmdMsg::default();
    GripperCommand::goal(0.02, 5.0, 0.05)
        .unwrap()
        .write(&mut raw);
    assert_eq!(raw.meta.body_len, 24);
    raw.body[..8].copy_from_slice(&(-1.0f64).to_ne_bytes());
    let e = GripperCommand::read(&raw).unwrap_err();
    assert_eq!(e.status(), Status::InvalidArgument);
}

#[test]
fn body_length_must_match_kind() {
    let mut raw = LimbCmdMsg::default();
    LimbCommand::set_position(Vec3::new(0.3, 0.0, 0.2))
        .unwrap()
        .write(&mut raw);
    raw.meta.body_len = 16;
    assert!(matches!(
        LimbCommand::read(&raw),
        Err(DecodeError::BodyLength {
            expected: 24,
            got: 16,
            ..
        })
    ));
    let mut raw = LimbCmdMsg::default();
    LimbCommand::Home.write(&mut raw);
    raw.meta.body_len = 1;
    assert!(LimbCommand::read(&raw).is_err());
}

#[test]
fn manifest_describes_every_struct_without_padding() {
    let m = limber_interfaces::manifest();
    assert!(m.structs.len() >= 40);
    for s in &m.structs {
        let prefix = format!("limber.v{}.", limber_interfaces::LAYOUT_VERSION);
        assert!(s.type_name.starts_with(&prefix), "{}", s.type_name);
        let sum: usize = s.fields.iter().map(|f| f.size).sum();
        assert_eq!(sum, s.size, "{} has padding", s.name);
        let mut end = 0;
        for f in s.fields {
            assert_eq!(f.offset, end, "{}.{} leaves a gap", s.name, f.name);
            end = f.offset + f.size;
            if !f.ty.starts_with(['u', 'i', 'f']) || f.ty.len() > 3 {
                assert!(
                    m.find(f.ty).is_some(),
                    "{}.{} has unknown type {}",
                    s.name,
                    f.name,
                    f.ty
                );
            }
        }
    }
    let json: serde_json::Value = serde_json::from_str(&m.to_json()).unwrap();
    assert_eq!(json["structs"][0]["fields"][0]["name"], "x");
}

#[test]
fn every_status_code_decodes_to_itself_and_names_its_cause() {
    for (i, s) in Status::ALL.iter().enumerate() {
        // In code order (blocks of codes are given out by issue, so there may be gaps).
        if i > 0 {
            assert!(
                Status::ALL[i - 1].code() < s.code(),
                "{s:?} out of code order"
            );
        }
        assert_eq!(Status::try_from(s.code()), Ok(*s));
    }
    assert!(
        Status::try_from(29).is_err(),
        "a code between the blocks is unknown"
    );
    assert_eq!(Status::ObjectPresent.code(), 30);
    assert_eq!(Status::SpeedNotSettable.code(), 33);
    // The codes of the wire never change: new causes get new numbers.
    assert_eq!(Status::InvalidArgument.code(), 10);
    assert_eq!(Status::PoweredOff.code(), 11);
    assert_eq!(Status::UnreachableOrientation.code(), 12);
    assert_eq!(Status::Clamped.code(), 13);
    assert_eq!(Status::Preempted.code(), 14);
    assert_eq!(Status::Leased.code(), 15);
    assert_eq!(Status::Adjusted.code(), 16);
    assert_eq!(Status::Braked.code(), 17);
    assert_eq!(Status::StoreFull.code(), 18);
    assert_eq!(Status::NothingToStore.code(), 19);
    assert_eq!(Status::NothingStored.code(), 20);
    let mut texts: Vec<&str> = Status::ALL.iter().map(|s| s.describe()).collect();
    texts.sort_unstable();
    texts.dedup();
    assert_eq!(texts.len(), Status::ALL.len(), "two causes share a text");
    assert_eq!(Status::PoweredOff.to_string(), "powered off");
    // Clamped was carried out; only Ok is exactly as asked.
    assert!(Status::Clamped.is_carried_out() && !Status::Clamped.is_ok());
    assert!(Status::Ok.is_carried_out());
    assert!(
        Status::ALL[1..].iter().filter(|s| s.is_carried_out()).eq([
            Status::Clamped,
            Status::Adjusted
        ]
        .iter())
    );
}

/// The ranger (issue 27): its one request through the wire and back, a command of any kind
/// refused (a ranger has none), its geometry reply, and a scan's views.
#[test]
fn the_ranger_request_reply_and_scan_views() {
    use limber_interfaces::ranger::{MAX_RANGES, req};
    assert_eq!(via_bytes(&RangerRequest::GetGeom), RangerRequest::GetGeom);
    assert!(RangerRequest::GetGeom.is_read_only());
    let mut raw = RangerCmdMsg::default();
    raw.meta.kind = 1;
    assert_eq!(
        RangerCommand::read(&raw).unwrap_err().status(),
        Status::Unsupported
    );
    let g = RangerGeom {
        min_angle: -1.0,
        max_angle: 1.0,
        angular_res: 0.5,
        max_range: 8.0,
        ranges_count: 5,
        ..RangerGeom::default()
    };
    let mut reply = RangerReplyMsg::default();
    RangerReply::write(req::GET_GEOM, Ok(&RangerReply::Geom(g)), &mut reply);
    assert_eq!(RangerReply::read(&reply).unwrap(), Ok(RangerReply::Geom(g)));
    RangerReply::write(req::GET_GEOM, Err(Status::Unsupported), &mut reply);
    assert_eq!(RangerReply::read(&reply).unwrap(), Err(Status::Unsupported));
    let mut bad = g;
    bad.max_range = f64::NAN;
    RangerReply::write(req::GET_GEOM, Ok(&RangerReply::Geom(bad)), &mut reply);
    assert!(RangerReply::read(&reply).is_err());

    let mut s = RangerData {
        min_angle: -core::f64::consts::FRAC_PI_2,
        angular_res: core::f64::consts::FRAC_PI_2,
        ranges_count: 3,
        ..RangerData::default()
    };
    s.ranges[..3].copy_from_slice(&[1.0, 2.0, 3.0]);
    assert_eq!(s.ranges(), &[1.0, 2.0, 3.0]);
    assert!(s.intensities().is_empty());
    let p = s.point(1).unwrap();
    assert!((p[0] - 2.0).abs() < 1e-12 && p[1].abs() < 1e-12);
    let p = s.point(2).unwrap();
    assert!(p[0].abs() < 1e-12 && (p[1] - 3.0).abs() < 1e-12);
    assert_eq!(s.point(3), None);
    assert!(s.validate().is_ok());
    s.ranges_count = MAX_RANGES as u32 + 1;
    assert!(s.validate().is_err());
    assert_eq!(s.ranges().len(), MAX_RANGES);
    s.ranges_count = 3;
    s.frequency = f64::INFINITY;
    assert!(s.validate().is_err());
}
