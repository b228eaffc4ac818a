//! `limber view` (issue 30): a WebSocket client written here from RFC 6455 and the
//! `foxglove.websocket.v1` specification subscribes to the emulated Pioneer's joint states
//! and its arm's URDF; hostile clients are refused without harm to the server.

mod common;

use std::io::{Read, Write};
use std::net::TcpStream;
use std::time::{Duration, Instant};

use common::{Bg, pioneer_emulated};
use limber_services::Domain;
use serde_json::{Value, json};

/// Starts `limber view` on a free loopback port in `d`, waiting until it shows the arm;
/// the process and its address.
fn start_view(d: &Domain) -> (Bg, String) {
    let mut v = Bg::spawn(d.name(), &["view", "--listen", "127.0.0.1:0"]);
    let ready = v.line(|l| l.ends_with("; ready"));
    let addr = ready
        .split("ws://")
        .nth(1)
        .and_then(|r| r.split(';').next())
        .unwrap()
        .to_string();
    v.line(|l| l == "showing pioneer/actarray/0");
    (v, addr)
}

fn connect(addr: &str) -> TcpStream {
    let s = TcpStream::connect(addr).unwrap();
    // Every read and every write bounded: a server that stops reading fails the test with
    // the call that waited, never hangs it (a write was the one wait without a bound).
    s.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
    s.set_write_timeout(Some(Duration::from_secs(10))).unwrap();
    s
}

/// Sends the opening handshake (offering `protocol`); the server's response head.
fn handshake(s: &mut TcpStream, protocol: Option<&str>) -> String {
    let mut req = String::from(
        "GET / HTTP/1.1\r\nHost: localhost\r\nUpgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n",
    );
    if let Some(p) = protocol {
        req.push_str(&format!("Sec-WebSocket-Protocol: {p}\r\n"));
    }
    req.push_str("\r\n");
    s.write_all(req.as_bytes()).unwrap();
    let mut head = Vec::new();
    let mut b = [0u8; 1];
    while !head.ends_with(b"\r\n\r\n") {
        assert_eq!(s.read(&mut b).unwrap(), 1, "closed during the handshake");
        head.push(b[0]);
    }
    String::from_utf8(head).unwrap()
}

/// Sends one masked client frame.
fn send(s: &mut TcpStream, op: u8, payload: &[u8]) {
    let mask = [0x37u8, 0xfa, 0x21, 0x3d];
    let mut f = vec![0x80 | op];
    match payload.len() {
        n if n < 126 => f.push(0x80 | n as u8),
        n => {
            f.push(0x80 | 126);
            f.extend_from_slice(&(n as u16).to_be_bytes());
        }
    }
    f.extend_from_slice(&mask);
    f.extend(payload.iter().enumerate().map(|(i, b)| b ^ mask[i % 4]));
    s.write_all(&f).unwrap();
}

/// Sends one masked text frame of any length (64-bit length).
fn send_long(s: &mut TcpStream, payload: &[u8]) {
    let mask = [0x11u8, 0x22, 0x33, 0x44];
    let mut f = vec![0x81u8, 0x80 | 127];
    f.extend_from_slice(&(payload.len() as u64).to_be_bytes());
    f.extend_from_slice(&mask);
    f.extend(payload.iter().enumerate().map(|(i, b)| b ^ mask[i % 4]));
    s.write_all(&f).unwrap();
}

/// Reads one server frame: its opcode and payload (a server's frames are not masked).
fn recv(s: &mut TcpStream) -> std::io::Result<(u8, Vec<u8>)> {
    let mut h = [0u8; 2];
    s.read_exact(&mut h)?;
    assert_eq!(h[1] & 0x80, 0, "a server frame must not be masked");
    let len = match h[1] & 0x7f {
        126 => {
            let mut b = [0u8; 2];
            s.read_exact(&mut b)?;
            u16::from_be_bytes(b) as usize
        }
        127 => {
            let mut b = [0u8; 8];
            s.read_exact(&mut b)?;
            u64::from_be_bytes(b) as usize
        }
        n => n as usize,
    };
    let mut p = vec![0u8; len];
    s.read_exact(&mut p)?;
    Ok((h[0] & 0x0f, p))
}

fn text(s: &mut TcpStream) -> Value {
    let (op, p) = recv(s).unwrap();
    assert_eq!(op, 1, "a text frame");
    serde_json::from_slice(&p).unwrap()
}

#[test]
fn a_protocol_client_receives_joint_states_and_the_urdf() {
    let d = Domain::unique_for_test();
    let mut pioneer = pioneer_emulated(d.name());
    let (_view, addr) = start_view(&d);

    let mut s = connect(&addr);
    let head = handshake(&mut s, Some("foxglove.websocket.v1"));
    assert!(head.starts_with("HTTP/1.1 101"), "{head}");
    assert!(
        head.contains("Sec-WebSocket-Accept: s3pPLMBiTxaQ9kYGzzhZRbK+xOo=\r\n"),
        "{head}"
    );
    assert!(head.contains("Sec-WebSocket-Protocol: foxglove.websocket.v1\r\n"));

    let info = text(&mut s);
    assert_eq!(info["op"], "serverInfo");
    assert_eq!(info["capabilities"], json!([]), "read-only");
    let adv = text(&mut s);
    assert_eq!(adv["op"], "advertise");
    let channel = |topic: &str| {
        adv["channels"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["topic"] == topic)
            .unwrap_or_else(|| panic!("{topic} not advertised: {adv}"))
            .clone()
    };
    let joints = channel("/pioneer/actarray/0/joint_states");
    assert_eq!(joints["schemaName"], "foxglove.JointStates");
    assert_eq!(joints["encoding"], "json");
    let urdf = channel("/pioneer/actarray/0/robot_description");
    let tf = channel("/pioneer/actarray/0/tf");
    assert_eq!(tf["schemaName"], "foxglove.FrameTransforms");
    let sub = json!({"op": "subscribe", "subscriptions": [
        {"id": 7, "channelId": joints["id"]},
        {"id": 9, "channelId": urdf["id"]},
        {"id": 11, "channelId": tf["id"]},
    ]});
    send(&mut s, 1, sub.to_string().as_bytes());

    let (mut states, mut description, mut transforms) = (Vec::new(), None, None);
    let deadline = Instant::now() + Duration::from_secs(30);
    while states.len() < 3 || description.is_none() || transforms.is_none() {
        assert!(Instant::now() < deadline, "not everything within 30 s");
        let (op, p) = recv(&mut s).unwrap();
        if op != 2 {
            continue; // a later advertise
        }
        assert_eq!(p[0], 1, "Message Data");
        let sub = u32::from_le_bytes(p[1..5].try_into().unwrap());
        let v: Value = serde_json::from_slice(&p[13..]).unwrap();
        match sub {
            7 => states.push(v),
            9 => description = Some(v),
            11 => transforms = Some(v),
            other => panic!("a message for subscription {other}"),
        }
    }
    for st in &states {
        let joints = st["joints"].as_array().unwrap();
        assert!(joints.len() >= 5, "{st}");
        assert_eq!(joints[0]["name"], "j0");
        assert!(joints.iter().all(|j| j["position"].is_f64()), "{st}");
        assert!(st["timestamp"]["sec"].as_u64().unwrap() > 0);
    }
    // The URDF's frames, base_link to tool, each a unit rotation.
    let transforms = transforms.unwrap();
    let frames = transforms["transforms"].as_array().unwrap();
    let children: Vec<&str> = frames
        .iter()
        .map(|t| t["child_frame_id"].as_str().unwrap())
        .collect();
    assert_eq!(
        children,
        [
            "chain_base",
            "link1",
            "link2",
            "link3",
            "link4",
            "link5",
            "tool"
        ]
    );
    for t in frames {
        let r = &t["rotation"];
        let n: f64 = ["x", "y", "z", "w"]
            .iter()
            .map(|k| r[k].as_f64().unwrap().powi(2))
            .sum();
        assert!((n - 1.0).abs() < 1e-9, "{t}");
    }
    let description = description.unwrap();
    let urdf = description["data"].as_str().unwrap();
    assert!(urdf.contains("<robot name=\"pioneer\">"), "{urdf}");
    assert_eq!(urdf.matches("type=\"revolute\"").count(), 5, "{urdf}");

    // Unsupported requests get a status, not a crash.
    send(&mut s, 1, br#"{"op":"setParameters","parameters":[]}"#);
    send(&mut s, 1, b"not json");
    let mut statuses = 0;
    while statuses < 2 {
        assert!(Instant::now() < deadline, "no status within 30 s");
        let (op, p) = recv(&mut s).unwrap();
        if op == 1 && serde_json::from_slice::<Value>(&p).unwrap()["op"] == "status" {
            statuses += 1;
        }
    }

    // The driver ends: its channels are withdrawn.
    assert_eq!(pioneer.term(), Some(0));
    let deadline = Instant::now() + Duration::from_secs(30);
    loop {
        assert!(Instant::now() < deadline, "no unadvertise within 30 s");
        let (op, p) = recv(&mut s).unwrap();
        let v: Value = if op == 1 {
            serde_json::from_slice(&p).unwrap()
        } else {
            continue;
        };
        if v["op"] == "unadvertise" && v["channelIds"].as_array().unwrap().contains(&joints["id"]) {
            break;
        }
    }
}

#[test]
fn hostile_clients_are_refused_and_the_server_serves_on() {
    let d = Domain::unique_for_test();
    let _pioneer = pioneer_emulated(d.name());
    let (_view, addr) = start_view(&d);

    // Without the subprotocol: 400, with the reason.
    let mut s = connect(&addr);
    let head = handshake(&mut s, None);
    assert!(head.starts_with("HTTP/1.1 400"), "{head}");

    // Not HTTP at all: refused, the connection closed.
    let mut s = connect(&addr);
    s.write_all(b"\x00\x01garbage\r\n\r\n").unwrap();
    let mut rest = Vec::new();
    s.read_to_end(&mut rest).unwrap();
    assert!(String::from_utf8_lossy(&rest).starts_with("HTTP/1.1 400"));

    // An unmasked frame, then a frame that claims 2^63 bytes: the connection is closed.
    for bad in [
        vec![0x81u8, 0x02, b'h', b'i'],
        [vec![0x82u8, 0xff], (1u64 << 63).to_be_bytes().to_vec()].concat(),
    ] {
        let mut s = connect(&addr);
        assert!(handshake(&mut s, Some("foxglove.websocket.v1")).starts_with("HTTP/1.1 101"));
        s.write_all(&bad).unwrap();
        let deadline = Instant::now() + Duration::from_secs(30);
        loop {
            assert!(Instant::now() < deadline, "the connection stayed open");
            match recv(&mut s) {
                Ok(_) => continue, // serverInfo, advertise
                Err(_) => break,   // closed
            }
        }
    }

    // Subscriptions beyond the bound are refused with a status, the connection kept.
    let mut s = connect(&addr);
    assert!(handshake(&mut s, Some("foxglove.websocket.v1")).starts_with("HTTP/1.1 101"));
    let adv = [text(&mut s), text(&mut s)];
    let channel = adv[1]["channels"][0]["id"].clone();
    for batch in 0..3 {
        let subs: Vec<Value> = (0..500)
            .map(|i| json!({"id": batch * 500 + i, "channelId": channel}))
            .collect();
        let msg = json!({"op": "subscribe", "subscriptions": subs}).to_string();
        send_long(&mut s, msg.as_bytes());
    }
    let deadline = Instant::now() + Duration::from_secs(30);
    loop {
        assert!(Instant::now() < deadline, "no status within 30 s");
        let (op, p) = recv(&mut s).unwrap();
        if op == 1 {
            let v: Value = serde_json::from_slice(&p).unwrap();
            if v["op"] == "status" {
                assert_eq!(v["message"], "too many subscriptions", "{v}");
                break;
            }
        }
    }

    // The server serves on.
    let mut s = connect(&addr);
    assert!(handshake(&mut s, Some("foxglove.websocket.v1")).starts_with("HTTP/1.1 101"));
    assert_eq!(text(&mut s)["op"], "serverInfo");
}
