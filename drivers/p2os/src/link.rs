//! The link: a serial device (or pty) or a TCP connection, with the decoder.

use super::codec::{Decoder, DecoderStats, EncodeError, Frame};
use super::command::Command;
use super::packet::RobotPacket;
use super::sys::{wait_readable, wait_writable};
use serialport::{ClearBuffer, SerialPort, TTYPort};
use std::io::{self, Read, Write};
use std::net::{SocketAddr, TcpStream, ToSocketAddrs};
use std::os::fd::{AsRawFd, BorrowedFd, RawFd};
use std::path::PathBuf;
use std::time::{Duration, Instant};
use thiserror::Error;

/// Where the robot is.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum LinkTarget {
    /// A serial device or pty path.
    Serial(PathBuf),
    /// A TCP endpoint `host:port` (a serial bridge or a simulator, port
    /// [`DEFAULT_TCP_PORT`] by default).
    Tcp(String),
}

/// The P2OS simulator's default TCP port.
pub const DEFAULT_TCP_PORT: u16 = 8101;

impl LinkTarget {
    /// Parses `tcp://host[:port]` (port 8101 by default) or a device path.
    pub fn parse(s: &str) -> LinkTarget {
        match s.strip_prefix("tcp://") {
            Some(rest)
                if rest
                    .rsplit_once(':')
                    .is_some_and(|(_, p)| p.parse::<u16>().is_ok()) =>
            {
                LinkTarget::Tcp(rest.to_string())
            }
            Some(rest) => LinkTarget::Tcp(format!("{rest}:{DEFAULT_TCP_PORT}")),
            None => LinkTarget::Serial(PathBuf::from(s)),
        }
    }
}

/// Why a link could not be opened.
#[derive(Debug, Error)]
pub enum OpenError {
    /// The serial device could not be opened or configured.
    #[error("cannot open serial device {path}: {source}")]
    Serial {
        /// The device.
        path: PathBuf,
        /// The cause.
        source: serialport::Error,
    },
    /// The TCP address did not resolve.
    #[error("cannot resolve {0}")]
    Resolve(String),
    /// The TCP connection failed (every resolved address).
    #[error("cannot connect to {addr}: {source}")]
    Connect {
        /// The address.
        addr: String,
        /// The last cause.
        source: io::Error,
    },
    /// The descriptor could not be made non-blocking (the link writes and reads without
    /// waiting, and waits with its timeout only when the device is full or empty).
    #[error("cannot make the link non-blocking: {0}")]
    NonBlocking(#[source] io::Error),
}

/// Why a send or receive failed.
#[derive(Debug, Error)]
pub enum LinkError {
    /// Nothing complete arrived within the timeout.
    #[error("no packet within {0:?}")]
    Timeout(Duration),
    /// The other end closed the connection (or the device went away).
    #[error("link closed by the other end")]
    Closed,
    /// An I/O error.
    #[error("link I/O error: {0}")]
    Io(#[from] io::Error),
    /// The command could not be encoded.
    #[error("cannot encode: {0}")]
    Encode(#[from] EncodeError),
    /// A baud rate change was asked of a TCP link.
    #[error("baud rates apply to serial links only")]
    NotSerial,
    /// The serial device refused a setting.
    #[error("serial device: {0}")]
    Serial(#[from] serialport::Error),
}

/// Counters of a link.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LinkStats {
    /// The decoder's counters (packets ok, bad checksums, garbage, bytes in).
    pub decoder: DecoderStats,
    /// Bytes written.
    pub bytes_out: u64,
    /// Packets written.
    pub packets_out: u64,
    /// Packets with a good checksum that did not parse (e.g. a short SIP).
    pub malformed: u64,
}

enum Transport {
    Serial(TTYPort),
    Tcp(TcpStream),
}

/// The serial port's descriptor, for `read(2)` / `write(2)` straight on it: the port's
/// own `Read` / `Write` poll before every call (one more system call per packet).
fn port_fd(p: &TTYPort) -> BorrowedFd<'_> {
    // SAFETY: the TTYPort owns its descriptor and keeps it open until it is dropped; the
    // borrow is tied to `p`, so it cannot outlive the port.
    unsafe { BorrowedFd::borrow_raw(p.as_raw_fd()) }
}

/// One read of the link's non-blocking descriptor: `read(2)` straight on the serial
/// port's, the TCP stream's own read.
impl Read for Transport {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        match self {
            Transport::Serial(p) => Ok(rustix::io::read(port_fd(p), buf)?),
            Transport::Tcp(s) => s.read(buf),
        }
    }
}

/// One write to the link's non-blocking descriptor: `write(2)` straight on the serial
/// port's, the TCP stream's own write (a `send` that raises no SIGPIPE).
impl Write for Transport {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        match self {
            Transport::Serial(p) => Ok(rustix::io::write(port_fd(p), buf)?),
            Transport::Tcp(s) => s.write(buf),
        }
    }

    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

/// A P2OS link. Reading goes through an internal [`Decoder`]; the raw fd is
/// exposed ([`AsRawFd`]) so an event loop can register it with epoll and call
/// [`Link::poll_payload`] / [`Link::poll_packet`] when it becomes readable.
///
/// The descriptor is non-blocking: a send is one `write(2)` while the device has room,
/// and waits for room (up to the write timeout, [`Link::set_write_timeout`]) only when
/// it has none; a receive reads first and waits only when nothing is there.
pub struct Link {
    io: Transport,
    decoder: Decoder,
    bytes_out: u64,
    packets_out: u64,
    malformed: u64,
    last_send: Option<Instant>,
    last_receive: Option<Instant>,
    write_timeout: Duration,
}

impl std::fmt::Debug for Link {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Link")
            .field("serial", &self.is_serial())
            .field("stats", &self.stats())
            .finish()
    }
}

const DEFAULT_WRITE_TIMEOUT: Duration = Duration::from_millis(500);

impl Link {
    fn from_transport(io: Transport) -> Result<Link, OpenError> {
        let nonblocking = match &io {
            Transport::Serial(p) => rustix::io::ioctl_fionbio(port_fd(p), true).map_err(Into::into),
            Transport::Tcp(s) => s.set_nonblocking(true),
        };
        nonblocking.map_err(OpenError::NonBlocking)?;
        Ok(Link {
            io,
            decoder: Decoder::new(),
            bytes_out: 0,
            packets_out: 0,
            malformed: 0,
            last_send: None,
            last_receive: None,
            write_timeout: DEFAULT_WRITE_TIMEOUT,
        })
    }

    /// Opens a serial device (or pty) raw 8N1 at `baud`.
    pub fn open_serial(path: impl Into<PathBuf>, baud: u32) -> Result<Link, OpenError> {
        let path = path.into();
        let err = |source| OpenError::Serial {
            path: path.clone(),
            source,
        };
        let port = serialport::new(path.to_string_lossy(), baud)
            .open_native()
            .map_err(err)?;
        // Stale bytes from before we opened are of no use; flush_input drains them too
        // when the device cannot clear its buffer.
        if let Err(e) = port.clear(ClearBuffer::Input) {
            tracing::debug!("cannot clear the input buffer of {}: {e}", path.display());
        }
        Link::from_transport(Transport::Serial(port))
    }

    /// Wraps an already open serial port (e.g. one end of `TTYPort::pair()`) and makes
    /// it non-blocking.
    pub fn from_serial_port(port: TTYPort) -> Result<Link, OpenError> {
        Link::from_transport(Transport::Serial(port))
    }

    /// Connects over TCP with a connect timeout.
    pub fn connect_tcp(addr: &str, timeout: Duration) -> Result<Link, OpenError> {
        let addrs: Vec<SocketAddr> = addr
            .to_socket_addrs()
            .map_err(|_| OpenError::Resolve(addr.to_string()))?
            .collect();
        let mut last = io::Error::new(io::ErrorKind::NotFound, "no address");
        for a in &addrs {
            match TcpStream::connect_timeout(a, timeout) {
                Ok(s) => return Link::from_tcp_stream(s),
                Err(e) => last = e,
            }
        }
        if addrs.is_empty() {
            return Err(OpenError::Resolve(addr.to_string()));
        }
        Err(OpenError::Connect {
            addr: addr.to_string(),
            source: last,
        })
    }

    /// Wraps a connected TCP stream and makes it non-blocking.
    pub fn from_tcp_stream(s: TcpStream) -> Result<Link, OpenError> {
        if let Err(e) = s.set_nodelay(true) {
            tracing::warn!("TCP_NODELAY not set (commands may be delayed): {e}");
        }
        Link::from_transport(Transport::Tcp(s))
    }

    /// Opens a [`LinkTarget`]: serial at 9600 baud (the first rate of the
    /// sync order), TCP with a 2 s connect timeout.
    pub fn open(target: &LinkTarget) -> Result<Link, OpenError> {
        match target {
            LinkTarget::Serial(p) => Link::open_serial(p.clone(), super::BAUD_RATES[0]),
            LinkTarget::Tcp(a) => Link::connect_tcp(a, Duration::from_secs(2)),
        }
    }

    /// This is a serial link (baud rates apply).
    pub fn is_serial(&self) -> bool {
        matches!(self.io, Transport::Serial(_))
    }

    /// Sets the serial baud rate ([`LinkError::NotSerial`] over TCP).
    pub fn set_baud_rate(&mut self, baud: u32) -> Result<(), LinkError> {
        match &mut self.io {
            Transport::Serial(p) => Ok(p.set_baud_rate(baud)?),
            Transport::Tcp(_) => Err(LinkError::NotSerial),
        }
    }

    /// The serial baud rate, `None` over TCP.
    pub fn baud_rate(&self) -> Option<u32> {
        match &self.io {
            Transport::Serial(p) => p.baud_rate().ok(),
            Transport::Tcp(_) => None,
        }
    }

    /// How long a send may wait for the device to take its bytes (500 ms by default).
    /// A send that cannot finish in that time fails with [`LinkError::Io`] of kind
    /// [`io::ErrorKind::TimedOut`].
    pub fn set_write_timeout(&mut self, t: Duration) {
        self.write_timeout = t;
    }

    /// How long a send may wait for the device to take its bytes.
    pub fn write_timeout(&self) -> Duration {
        self.write_timeout
    }

    /// Sends a command.
    pub fn send(&mut self, cmd: &Command) -> Result<(), LinkError> {
        let f = cmd.encode()?;
        self.send_frame(&f)
    }

    /// Sends an encoded packet.
    pub fn send_frame(&mut self, frame: &Frame) -> Result<(), LinkError> {
        self.send_bytes(frame.as_bytes())?;
        self.packets_out += 1;
        Ok(())
    }

    /// Sends raw bytes (no framing): `write(2)` at once; only when the device is full
    /// (or took part of the bytes) does it wait for room, at most the write timeout in
    /// all ([`LinkError::Io`] of kind [`io::ErrorKind::TimedOut`] then).
    pub fn send_bytes(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        let r = self.write_all(bytes);
        self.last_send = Some(Instant::now());
        r
    }

    fn write_all(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        let mut rest = bytes;
        // Read from the clock only when the device is full.
        let mut deadline = None;
        while !rest.is_empty() {
            let r = self.io.write(rest);
            match r {
                Ok(0) => return Err(LinkError::Io(io::ErrorKind::WriteZero.into())),
                Ok(n) => {
                    rest = &rest[n..];
                    self.bytes_out += n as u64;
                }
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                Err(e) if e.kind() == io::ErrorKind::WouldBlock => {
                    let deadline =
                        *deadline.get_or_insert_with(|| crate::sys::deadline(self.write_timeout));
                    let left = deadline.saturating_duration_since(Instant::now());
                    if left.is_zero() {
                        return Err(LinkError::Io(io::Error::new(
                            io::ErrorKind::TimedOut,
                            format!(
                                "the link took no more bytes within {:?} ({} of {} sent)",
                                self.write_timeout,
                                bytes.len() - rest.len(),
                                bytes.len()
                            ),
                        )));
                    }
                    // Room, a hang-up, the timeout or a signal: the next write tells.
                    wait_writable(self.as_raw_fd(), left)?;
                }
                Err(e) if is_closed(&e) => return Err(LinkError::Closed),
                Err(e) => return Err(LinkError::Io(e)),
            }
        }
        Ok(())
    }

    /// When a packet was last sent.
    pub fn last_send(&self) -> Option<Instant> {
        self.last_send
    }

    /// When bytes were last received (to tell a fresh link from a stale one).
    pub fn last_receive(&self) -> Option<Instant> {
        self.last_receive
    }

    /// Counters.
    pub fn stats(&self) -> LinkStats {
        LinkStats {
            decoder: self.decoder.stats(),
            bytes_out: self.bytes_out,
            packets_out: self.packets_out,
            malformed: self.malformed,
        }
    }

    /// The decoder (e.g. to set `ignore_checksum`).
    pub fn decoder_mut(&mut self) -> &mut Decoder {
        &mut self.decoder
    }

    /// Discards input: the device's buffer (serial) and everything readable
    /// now, and the decoder's buffer.
    pub fn flush_input(&mut self) -> Result<(), LinkError> {
        if let Transport::Serial(p) = &self.io
            && let Err(e) = p.clear(ClearBuffer::Input)
        {
            // Not fatal: what is readable now is drained below.
            tracing::debug!("cannot clear the serial input buffer: {e}");
        }
        let mut scratch = [0u8; 256];
        // Bounded: a robot that streams faster than we drain cannot hold us.
        for _ in 0..64 {
            let r = self.io.read(&mut scratch);
            match r {
                Ok(0) => return Err(LinkError::Closed),
                Ok(_) => {}
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                Err(e) if e.kind() == io::ErrorKind::WouldBlock => break,
                Err(e) if is_closed(&e) => return Err(LinkError::Closed),
                Err(e) => return Err(LinkError::Io(e)),
            }
        }
        self.decoder.clear();
        Ok(())
    }

    /// Reads once into the decoder; if nothing was there, waits up to `timeout` for
    /// the fd to become readable and reads once more. Returns whether bytes arrived.
    fn fill(&mut self, timeout: Duration) -> Result<bool, LinkError> {
        if self.read_once()? {
            return Ok(true);
        }
        if timeout.is_zero() || wait_readable(&[self.as_raw_fd()], timeout)? == 0 {
            return Ok(false);
        }
        self.read_once()
    }

    /// One non-blocking read into the decoder. Returns whether bytes arrived.
    fn read_once(&mut self) -> Result<bool, LinkError> {
        let r = self.decoder.read_from(&mut self.io);
        match r {
            Ok(0) => Err(LinkError::Closed),
            Ok(_) => {
                self.last_receive = Some(Instant::now());
                Ok(true)
            }
            Err(e)
                if matches!(
                    e.kind(),
                    io::ErrorKind::WouldBlock
                        | io::ErrorKind::TimedOut
                        | io::ErrorKind::Interrupted
                ) =>
            {
                Ok(false)
            }
            Err(e) if is_closed(&e) => Err(LinkError::Closed),
            Err(e) => Err(LinkError::Io(e)),
        }
    }

    /// Nonblocking: the next payload already buffered or readable now
    /// (one read at most). `Ok(None)` when nothing complete is there.
    pub fn poll_payload(&mut self) -> Result<Option<&[u8]>, LinkError> {
        if self.decoder.has_packet() {
            return Ok(self.decoder.next_packet());
        }
        self.fill(Duration::ZERO)?;
        Ok(self.decoder.next_packet())
    }

    /// Waits up to `timeout` for the next payload (type byte first).
    pub fn recv_payload(&mut self, timeout: Duration) -> Result<&[u8], LinkError> {
        let deadline = crate::sys::deadline(timeout);
        loop {
            if self.decoder.has_packet() {
                break;
            }
            let now = Instant::now();
            if now >= deadline {
                return Err(LinkError::Timeout(timeout));
            }
            self.fill(deadline - now)?;
        }
        self.decoder
            .next_packet()
            .ok_or(LinkError::Timeout(timeout))
    }

    /// Nonblocking: the next parsed packet, if one is complete. Payloads that
    /// do not parse are counted in [`LinkStats::malformed`] and skipped.
    pub fn poll_packet(&mut self) -> Result<Option<RobotPacket<'_>>, LinkError> {
        loop {
            if !self.decoder.has_packet() {
                self.fill(Duration::ZERO)?;
                if !self.decoder.has_packet() {
                    return Ok(None);
                }
            }
            if self.parse_next_ok() {
                break;
            }
        }
        Ok(self.take_parsed())
    }

    /// Waits up to `timeout` for the next parsed packet (malformed ones are
    /// counted and skipped).
    pub fn recv(&mut self, timeout: Duration) -> Result<RobotPacket<'_>, LinkError> {
        let deadline = crate::sys::deadline(timeout);
        loop {
            if self.decoder.has_packet() {
                if self.parse_next_ok() {
                    break;
                }
                continue;
            }
            let now = Instant::now();
            if now >= deadline {
                return Err(LinkError::Timeout(timeout));
            }
            self.fill(deadline - now)?;
        }
        self.take_parsed().ok_or(LinkError::Timeout(timeout))
    }

    /// Peeks at the next buffered packet: if it does not parse, drops it
    /// (counted) and returns false.
    fn parse_next_ok(&mut self) -> bool {
        let ok = match self.decoder.peek_packet() {
            Some(p) => RobotPacket::parse(p).is_ok(),
            None => false,
        };
        if !ok {
            self.malformed += 1;
            // Drop the malformed packet (counted above); what it held is of no use.
            self.decoder.next_packet();
        }
        ok
    }

    fn take_parsed(&mut self) -> Option<RobotPacket<'_>> {
        let p = self.decoder.next_packet()?;
        RobotPacket::parse(p).ok()
    }
}

fn is_closed(e: &io::Error) -> bool {
    matches!(
        e.kind(),
        io::ErrorKind::BrokenPipe
            | io::ErrorKind::ConnectionReset
            | io::ErrorKind::ConnectionAborted
            | io::ErrorKind::UnexpectedEof
            | io::ErrorKind::NotConnected
    ) || e.raw_os_error() == Some(rustix::io::Errno::IO.raw_os_error())
}

impl AsRawFd for Link {
    fn as_raw_fd(&self) -> RawFd {
        match &self.io {
            Transport::Serial(p) => p.as_raw_fd(),
            Transport::Tcp(s) => s.as_raw_fd(),
        }
    }
}
