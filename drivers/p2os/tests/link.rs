//! The link's send path: the descriptor is non-blocking, so a send is one `write(2)`
//! while the device has room. A device that takes no more bytes ends the send in the
//! write timeout's error (never a hang, never a packet silently dropped), the link
//! works again once the device drains, and a device that takes part of the bytes gets
//! the rest.

use limber_p2os::*;
use serialport::{SerialPort, TTYPort};
use std::io::{self, Read};
use std::net::{TcpListener, TcpStream};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// How long a step of these tests may take before it counts as a hang.
const HANG: Duration = Duration::from_secs(30);

/// Runs `f` on a thread and returns its result, failing the test if it does not
/// finish within [`HANG`].
fn bounded<T: Send + 'static>(what: &str, f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        if tx.send(f()).is_err() {
            eprintln!("the test stopped waiting for this thread");
        }
    });
    rx.recv_timeout(HANG)
        .unwrap_or_else(|e| panic!("{what} did not finish within {HANG:?}: {e}"))
}

/// Reads exactly `n` bytes from `r` (whose reads time out), within [`HANG`].
fn read_exactly(r: &mut impl Read, n: usize) -> Vec<u8> {
    let deadline = Instant::now() + HANG;
    let mut got = vec![0u8; n];
    let mut at = 0;
    while at < n {
        assert!(Instant::now() < deadline, "only {at} of {n} bytes arrived");
        match r.read(&mut got[at..]) {
            Ok(0) => panic!("end of stream after {at} of {n} bytes"),
            Ok(k) => at += k,
            Err(e)
                if matches!(
                    e.kind(),
                    io::ErrorKind::TimedOut
                        | io::ErrorKind::WouldBlock
                        | io::ErrorKind::Interrupted
                ) => {}
            Err(e) => panic!("reading the other end: {e}"),
        }
    }
    got
}

/// Sends 4 KiB chunks until a send fails (the other end reads nothing); returns the
/// error, the chunks sent whole and the link.
fn fill_until_error(mut link: Link) -> (LinkError, u64, Link) {
    let chunk = [0x5Au8; 4096];
    // 40 MB at most: far more than a pty or a loopback socket buffers.
    for sent in 0..10_000u64 {
        if let Err(e) = link.send_bytes(&chunk) {
            return (e, sent, link);
        }
    }
    panic!("40 MB went out and nobody reads the other end: the sends do not block");
}

/// The other end of a link, read only when the test says so.
trait OtherEnd: Read + Send + 'static {}
impl OtherEnd for TTYPort {}
impl OtherEnd for TcpStream {}

fn full_device_times_out_then_recovers(what: &str, link: Link, mut other: impl OtherEnd) {
    let mut link = link;
    link.set_write_timeout(Duration::from_millis(50));
    assert_eq!(link.write_timeout(), Duration::from_millis(50));
    let (e, whole, mut link) = bounded(&format!("{what}: filling the device"), move || {
        fill_until_error(link)
    });
    match &e {
        LinkError::Io(io) if io.kind() == io::ErrorKind::TimedOut => {}
        other => panic!("{what}: expected the write timeout's error, got {other:?}"),
    }
    assert!(whole > 0, "{what}: the device took nothing at all");
    // Every byte that went out is counted, the partly sent chunk's included.
    let out = link.stats().bytes_out;
    assert!(
        (whole * 4096..(whole + 1) * 4096).contains(&out),
        "{what}: {out} bytes counted for {whole} whole chunks"
    );
    // The other end drains exactly what was counted; then the link takes packets again.
    let drained = bounded(&format!("{what}: draining"), move || {
        let n = usize::try_from(out).expect("fits");
        let got = read_exactly(&mut other, n);
        (got, other)
    });
    let (got, mut other) = drained;
    assert!(
        got.iter().all(|&b| b == 0x5A),
        "{what}: other bytes arrived"
    );
    link.send(&Command::Pulse)
        .unwrap_or_else(|e| panic!("{what}: the link did not recover: {e}"));
    let pulse = Command::Pulse.encode().unwrap();
    let n = pulse.as_bytes().len();
    let got = bounded(&format!("{what}: reading the PULSE"), move || {
        read_exactly(&mut other, n)
    });
    assert_eq!(got, pulse.as_bytes(), "{what}");
}

#[test]
fn a_pty_nobody_reads_ends_in_the_write_timeout_and_the_link_recovers() {
    let (mut master, slave) = TTYPort::pair().unwrap();
    master.set_timeout(Duration::from_millis(100)).unwrap();
    let link = Link::from_serial_port(slave).unwrap();
    full_device_times_out_then_recovers("pty", link, master);
}

#[test]
fn a_socket_nobody_reads_ends_in_the_write_timeout_and_the_link_recovers() {
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = listener.local_addr().unwrap().to_string();
    let link = Link::connect_tcp(&addr, HANG).unwrap();
    let (peer, _) = listener.accept().unwrap();
    peer.set_read_timeout(Some(Duration::from_millis(100)))
        .unwrap();
    full_device_times_out_then_recovers("tcp", link, peer);
}

#[test]
fn a_send_larger_than_the_device_takes_at_once_is_completed() {
    // More than a pty buffers: write(2) takes part, the link waits for room and sends
    // the rest, in order.
    let (mut master, slave) = TTYPort::pair().unwrap();
    master.set_timeout(Duration::from_millis(100)).unwrap();
    let mut link = Link::from_serial_port(slave).unwrap();
    link.set_write_timeout(HANG);
    let data: Vec<u8> = (0..300_000u32).map(|i| (i % 251) as u8).collect();
    let n = data.len();
    let reader = std::thread::spawn(move || read_exactly(&mut master, n));
    // The link comes back (open until the reader is done: a closed pty hangs up).
    let (r, link, data) = bounded("the large send", move || {
        let r = link.send_bytes(&data);
        (r, link, data)
    });
    if let Err(e) = r {
        panic!("the large send failed: {e}");
    }
    assert_eq!(link.stats().bytes_out, n as u64);
    let got = reader.join().expect("the reader panicked");
    assert!(got == data, "the bytes arrived out of order or changed");
    drop(link);
}

#[test]
fn a_closed_other_end_is_closed_not_a_timeout() {
    let (master, slave) = TTYPort::pair().unwrap();
    let mut link = Link::from_serial_port(slave).unwrap();
    drop(master);
    let (sent, received) = bounded("sending to a closed pty", move || {
        let sent = link.send(&Command::Pulse);
        let received = link.recv(Duration::from_secs(1)).map(|_| ());
        (sent, received)
    });
    assert!(matches!(sent, Err(LinkError::Closed)), "send: {sent:?}");
    assert!(
        matches!(received, Err(LinkError::Closed)),
        "recv: {received:?}"
    );
}
