//! The WebSocket side of `limber view`, from RFC 6455: the opening handshake (with the
//! `foxglove.websocket.v1` subprotocol) and frames. Written here (~200 lines over the
//! SHA-1 and base64 crates already in limber's build) rather than taking tungstenite and
//! its http stack into every cold build. Every length a client sends is bounded and every
//! read has a deadline during the handshake: a hostile client gets an error and its
//! connection closed, never a crash or a hang of the server.

use std::io::{Read, Write};
use std::net::TcpStream;
use std::time::Duration;

use base64::Engine as _;
use thiserror::Error;

/// The subprotocol served.
pub const SUBPROTOCOL: &str = "foxglove.websocket.v1";
/// The largest handshake request accepted.
const MAX_REQUEST: usize = 16 * 1024;
/// The largest message a client may send (its subscriptions are small JSON objects).
pub const MAX_MESSAGE: usize = 1 << 20;
/// How long a client has to complete the handshake.
pub const HANDSHAKE_TIMEOUT: Duration = Duration::from_secs(5);

/// A WebSocket exchange failed.
#[derive(Debug, Error)]
pub enum WsError {
    /// The connection failed or timed out.
    #[error("connection: {0}")]
    Io(#[from] std::io::Error),
    /// The handshake request is not a WebSocket upgrade limber can accept.
    #[error("bad handshake: {0}")]
    Handshake(&'static str),
    /// A frame breaks the protocol (unmasked, reserved bits, a control frame too long...).
    #[error("protocol error: {0}")]
    Protocol(&'static str),
    /// A message longer than [`MAX_MESSAGE`].
    #[error("a message of more than {MAX_MESSAGE} bytes")]
    TooLong,
}

/// The `Sec-WebSocket-Accept` of a `Sec-WebSocket-Key`.
pub fn accept_key(key: &str) -> String {
    let mut h = sha1_smol::Sha1::new();
    h.update(key.trim().as_bytes());
    h.update(b"258EAFA5-E914-47DA-95CA-C5AB0DC85B11");
    base64::engine::general_purpose::STANDARD.encode(h.digest().bytes())
}

/// Answers the opening handshake on `s` (read within [`HANDSHAKE_TIMEOUT`]); a refusal is
/// answered with `400 Bad Request` and its reason before the error is returned.
pub fn handshake(s: &mut TcpStream) -> Result<(), WsError> {
    s.set_read_timeout(Some(HANDSHAKE_TIMEOUT))?;
    let mut req = Vec::new();
    let mut buf = [0u8; 1024];
    while !req.windows(4).any(|w| w == b"\r\n\r\n") {
        if req.len() > MAX_REQUEST {
            return refuse(s, "request too long");
        }
        let n = s.read(&mut buf)?;
        if n == 0 {
            return Err(WsError::Handshake("closed during the handshake"));
        }
        req.extend_from_slice(&buf[..n]);
    }
    let Ok(text) = core::str::from_utf8(&req) else {
        return refuse(s, "not text");
    };
    let mut lines = text.split("\r\n");
    let first = lines.next().unwrap_or("");
    if !first.starts_with("GET ") {
        return refuse(s, "not a GET request");
    }
    let (mut key, mut upgrade, mut protocol) = (None, false, false);
    for l in lines {
        let Some((name, value)) = l.split_once(':') else {
            continue;
        };
        let (name, value) = (name.trim().to_ascii_lowercase(), value.trim());
        match name.as_str() {
            "upgrade" => upgrade = value.eq_ignore_ascii_case("websocket"),
            "sec-websocket-key" => key = Some(value.to_string()),
            "sec-websocket-protocol" => {
                protocol |= value.split(',').any(|p| p.trim() == SUBPROTOCOL);
            }
            _ => {}
        }
    }
    let Some(key) = key.filter(|_| upgrade) else {
        return refuse(s, "not a WebSocket upgrade");
    };
    if !protocol {
        return refuse(s, "the subprotocol foxglove.websocket.v1 is required");
    }
    let reply = format!(
        "HTTP/1.1 101 Switching Protocols\r\nUpgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Accept: {}\r\nSec-WebSocket-Protocol: {SUBPROTOCOL}\r\n\r\n",
        accept_key(&key)
    );
    s.write_all(reply.as_bytes())?;
    s.set_read_timeout(None)?;
    Ok(())
}

fn refuse(s: &mut TcpStream, why: &'static str) -> Result<(), WsError> {
    let body = format!("{why}\n");
    let reply = format!(
        "HTTP/1.1 400 Bad Request\r\nContent-Type: text/plain\r\nContent-Length: {}\r\nConnection: close\r\n\r\n{body}",
        body.len()
    );
    if let Err(e) = s.write_all(reply.as_bytes()) {
        tracing::debug!(error = %e, "cannot answer a refused handshake");
    }
    Err(WsError::Handshake(why))
}

/// Frame opcodes.
pub mod opcode {
    /// A continuation.
    pub const CONTINUATION: u8 = 0x0;
    /// Text.
    pub const TEXT: u8 = 0x1;
    /// Binary.
    pub const BINARY: u8 = 0x2;
    /// Close.
    pub const CLOSE: u8 = 0x8;
    /// Ping.
    pub const PING: u8 = 0x9;
    /// Pong.
    pub const PONG: u8 = 0xA;
}

/// Writes one unfragmented, unmasked frame (a server's).
pub fn write_frame(w: &mut impl Write, op: u8, payload: &[u8]) -> std::io::Result<()> {
    let mut head = Vec::with_capacity(10);
    head.push(0x80 | op);
    match payload.len() {
        n if n < 126 => head.push(n as u8),
        n if n <= 0xFFFF => {
            head.push(126);
            head.extend_from_slice(&(n as u16).to_be_bytes());
        }
        n => {
            head.push(127);
            head.extend_from_slice(&(n as u64).to_be_bytes());
        }
    }
    w.write_all(&head)?;
    w.write_all(payload)
}

/// One frame as read: FIN, opcode, unmasked payload.
struct Frame {
    fin: bool,
    op: u8,
    payload: Vec<u8>,
}

fn read_frame(r: &mut impl Read, budget: usize) -> Result<Frame, WsError> {
    let mut h = [0u8; 2];
    r.read_exact(&mut h)?;
    if h[0] & 0x70 != 0 {
        return Err(WsError::Protocol("reserved bits set"));
    }
    let (fin, op) = (h[0] & 0x80 != 0, h[0] & 0x0F);
    if h[1] & 0x80 == 0 {
        return Err(WsError::Protocol("a client frame must be masked"));
    }
    let len = match h[1] & 0x7F {
        126 => {
            let mut b = [0u8; 2];
            r.read_exact(&mut b)?;
            u64::from(u16::from_be_bytes(b))
        }
        127 => {
            let mut b = [0u8; 8];
            r.read_exact(&mut b)?;
            u64::from_be_bytes(b)
        }
        n => u64::from(n),
    };
    if op >= 0x8 && (len > 125 || !fin) {
        return Err(WsError::Protocol("a control frame must be short and whole"));
    }
    if len > budget as u64 {
        return Err(WsError::TooLong);
    }
    let mut mask = [0u8; 4];
    r.read_exact(&mut mask)?;
    let mut payload = vec![0u8; len as usize];
    r.read_exact(&mut payload)?;
    for (i, b) in payload.iter_mut().enumerate() {
        *b ^= mask[i % 4];
    }
    Ok(Frame { fin, op, payload })
}

/// What a client sent.
#[derive(Debug, PartialEq, Eq)]
pub enum Incoming {
    /// A whole text message.
    Text(String),
    /// A whole binary message.
    Binary(Vec<u8>),
    /// A ping, to answer with a pong of the same payload.
    Ping(Vec<u8>),
    /// The client closes.
    Close,
}

/// Reads a client's messages: control frames as they come, data messages reassembled from
/// their fragments up to [`MAX_MESSAGE`] bytes (a ping between two fragments is answered
/// without losing the first).
#[derive(Debug, Default)]
pub struct MessageReader {
    partial: Option<(u8, Vec<u8>)>,
}

impl MessageReader {
    /// The next message.
    pub fn read(&mut self, r: &mut impl Read) -> Result<Incoming, WsError> {
        loop {
            let budget = MAX_MESSAGE - self.partial.as_ref().map_or(0, |(_, d)| d.len());
            let f = read_frame(r, budget)?;
            match f.op {
                opcode::PING => return Ok(Incoming::Ping(f.payload)),
                opcode::PONG => continue,
                opcode::CLOSE => return Ok(Incoming::Close),
                opcode::TEXT | opcode::BINARY if self.partial.is_none() => {
                    self.partial = Some((f.op, f.payload))
                }
                opcode::CONTINUATION if self.partial.is_some() => {
                    if let Some((_, d)) = self.partial.as_mut() {
                        d.extend_from_slice(&f.payload);
                    }
                }
                _ => return Err(WsError::Protocol("unexpected opcode")),
            }
            if f.fin
                && let Some((op, d)) = self.partial.take()
            {
                return if op == opcode::TEXT {
                    String::from_utf8(d)
                        .map(Incoming::Text)
                        .map_err(|_| WsError::Protocol("text that is not UTF-8"))
                } else {
                    Ok(Incoming::Binary(d))
                };
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_accept_key_of_the_rfc_example() {
        assert_eq!(
            accept_key("dGhlIHNhbXBsZSBub25jZQ=="),
            "s3pPLMBiTxaQ9kYGzzhZRbK+xOo="
        );
    }

    fn masked(op: u8, fin: bool, payload: &[u8]) -> Vec<u8> {
        let mask = [1u8, 2, 3, 4];
        let mut f = vec![if fin { 0x80 } else { 0 } | op, 0x80 | payload.len() as u8];
        f.extend_from_slice(&mask);
        f.extend(payload.iter().enumerate().map(|(i, b)| b ^ mask[i % 4]));
        f
    }

    #[test]
    fn fragments_are_reassembled_and_bad_frames_refused() {
        let mut bytes = masked(opcode::TEXT, false, b"hel");
        bytes.extend(masked(opcode::PING, true, b"p"));
        bytes.extend(masked(opcode::CONTINUATION, true, b"lo"));
        let mut r = bytes.as_slice();
        let mut m = MessageReader::default();
        assert_eq!(m.read(&mut r).unwrap(), Incoming::Ping(b"p".to_vec()));
        assert_eq!(m.read(&mut r).unwrap(), Incoming::Text("hello".into()));
        let read_message = |r: &mut &[u8]| MessageReader::default().read(r);
        // Unmasked.
        let mut r: &[u8] = &[0x81, 0x01, b'x'];
        assert!(matches!(read_message(&mut r), Err(WsError::Protocol(_))));
        // Longer than allowed: refused before anything is allocated for it.
        let mut huge = vec![0x82, 0xFF];
        huge.extend_from_slice(&u64::MAX.to_be_bytes());
        assert!(matches!(
            read_message(&mut huge.as_slice()),
            Err(WsError::TooLong)
        ));
        // Truncated.
        let mut r: &[u8] = &[0x81];
        assert!(matches!(read_message(&mut r), Err(WsError::Io(_))));
    }
}
