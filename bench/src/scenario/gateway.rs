//! `gateway`: the `request` scenario's GET_GEOM round trip through the Player gateway
//! (`limber player-gateway`'s server, in a thread of this process): a Player client over
//! TCP loopback (PULL mode, so that no DATA comes between a request and its reply) asks
//! the arm's geometry, the gateway's session asks the Pioneer driver (the `request`
//! scenario's child, the emulator in fast mode) and answers. The report sets it beside
//! the direct request and the TCP loopback peer row of the same run; Player 3's own
//! server measured 162 ms p50 for the same request on limber's emulator (the reference,
//! 1.4), noted in the report.

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use limber_gateway::header::{DevAddr, HEADER_SIZE, MsgHeader, message, msg_type};
use limber_gateway::player::{self, DevReq, PLAYER_CODE};
use limber_gateway::{GatewayConfig, GatewayEvent};
use limber_services::monotonic_ns;

use super::request::{START_TIMEOUT, start_pioneer_driver};
use super::{RunCtx, SAMPLE_TIMEOUT, Scenario};
use crate::BenchError;
use crate::progress::Progress;
use crate::stats::{Measurement, Metric, Strategy, new_histogram};

/// Player's own figure, for the report's note.
pub const PLAYER_NOTE: &str = "Player 3's own server, same GET_GEOM on limber's emulator: 162 ms p50 (200 ms back to back; the Player reference, 1.4)";

/// The `gateway` scenario.
#[derive(Debug, Clone, Copy)]
pub struct Gateway;

fn err(what: &str, reason: impl std::fmt::Display) -> BenchError {
    BenchError::Transport {
        context: what.to_string(),
        reason: reason.to_string(),
    }
}

/// A Player client of the gateway, as much as the scenario needs.
struct PlayerLink {
    s: TcpStream,
    port: u16,
}

impl PlayerLink {
    fn connect(addr: SocketAddr) -> Result<Self, BenchError> {
        let mut s = TcpStream::connect(addr).map_err(|e| err("connect to the gateway", e))?;
        s.set_nodelay(true)
            .and_then(|()| s.set_read_timeout(Some(SAMPLE_TIMEOUT)))
            .map_err(|e| err("gateway socket", e))?;
        let mut banner = [0u8; player::BANNER_SIZE];
        s.read_exact(&mut banner)
            .map_err(|e| err("the gateway's banner", e))?;
        Ok(PlayerLink {
            s,
            port: addr.port(),
        })
    }

    fn addr(&self, interf: u16) -> DevAddr {
        DevAddr {
            host: 0,
            robot: self.port.into(),
            interf,
            index: 0,
        }
    }

    /// A request and its reply (an ACK, or an error).
    fn request(&mut self, interf: u16, subtype: u8, body: &[u8]) -> Result<Vec<u8>, BenchError> {
        let h = MsgHeader {
            addr: self.addr(interf),
            mtype: msg_type::REQ,
            subtype,
            ..MsgHeader::default()
        };
        self.s
            .write_all(&message(h, body))
            .map_err(|e| err("send a request", e))?;
        loop {
            let mut hb = [0u8; HEADER_SIZE];
            self.s
                .read_exact(&mut hb)
                .map_err(|e| err("read a reply", e))?;
            let r = MsgHeader::decode(&hb).map_err(|e| err("read a reply", e))?;
            let mut body = vec![0u8; r.size as usize];
            self.s
                .read_exact(&mut body)
                .map_err(|e| err("read a reply", e))?;
            match r.mtype {
                msg_type::RESP_ACK if r.subtype == subtype => return Ok(body),
                msg_type::RESP_NACK => return Err(err("request", "NACKed")),
                _ => {}
            }
        }
    }
}

impl Scenario for Gateway {
    fn name(&self) -> &'static str {
        "gateway"
    }
    fn description(&self) -> &'static str {
        "GET_GEOM round trip through the Player gateway (Player's TCP protocol) to the Pioneer driver on the emulator (fast mode)"
    }
    fn run(&self, ctx: &mut RunCtx) -> Result<(), BenchError> {
        if !ctx.blocking_enabled() {
            ctx.notes.push(
                "gateway runs the event-driven driver only; skipped by --strategy spin".into(),
            );
            return Ok(());
        }
        let domain = ctx.domain();
        let (warm, n) = (ctx.count(200, 50), ctx.count(3_000, 500));
        let mut child = start_pioneer_driver(ctx, &domain, warm + n, Duration::from_micros(800))?;

        let stop = Arc::new(AtomicBool::new(false));
        let (tx, rx) = std::sync::mpsc::channel();
        let server = {
            let (domain, stop) = (domain.clone(), Arc::clone(&stop));
            let config = GatewayConfig {
                listen: SocketAddr::from(([127, 0, 0, 1], 0)),
                ..GatewayConfig::default()
            };
            std::thread::spawn(move || {
                limber_gateway::run(
                    &domain,
                    &config,
                    &|| stop.load(Ordering::Relaxed),
                    &mut |ev| {
                        if let GatewayEvent::Listening(a) = ev
                            && tx.send(a).is_err()
                        {
                            tracing::debug!("the scenario ended first");
                        }
                    },
                )
            })
        };
        let result = measure(ctx, &rx, warm, n);
        stop.store(true, Ordering::Relaxed);
        match server.join() {
            Ok(Ok(())) => {}
            Ok(Err(e)) => tracing::warn!("the gateway: {e}"),
            Err(_) => tracing::error!("the gateway's thread panicked"),
        }
        if let Err(e) = child.send_line("quit") {
            tracing::warn!("cannot tell the driver child to quit: {e}");
        }
        child.finish(Duration::from_secs(10))?;
        let hist = result?;
        ctx.notes.push(PLAYER_NOTE.into());
        ctx.push(Measurement {
            scenario: "gateway",
            id: "gateway.player.rtt".into(),
            label: "GET_GEOM through the Player gateway (TCP), Pioneer driver+emulator (fast mode)"
                .into(),
            strategy: Strategy::Blocking,
            metric: Metric::RoundTrip,
            bytes: None,
            hist,
        });
        Ok(())
    }
}

fn measure(
    ctx: &RunCtx,
    listening: &std::sync::mpsc::Receiver<SocketAddr>,
    warm: u64,
    n: u64,
) -> Result<hdrhistogram::Histogram<u64>, BenchError> {
    let addr = listening
        .recv_timeout(START_TIMEOUT)
        .map_err(|e| err("the gateway does not listen", e))?;
    let mut c = PlayerLink::connect(addr)?;
    // PULL, as libplayerc: no DATA between a request and its reply.
    c.request(PLAYER_CODE, player::req::DATAMODE, &2u32.to_be_bytes())?;
    let dev = DevReq {
        addr: c.addr(53),
        access: player::access::OPEN,
        driver_name: String::new(),
    };
    c.request(PLAYER_CODE, player::req::DEV, &dev.write())?;
    let mut rtt = new_histogram()?;
    let progress = Progress::new(ctx.progress, "gateway GET_GEOM", warm + n);
    for i in 1..=warm + n {
        let t0 = monotonic_ns();
        let g = c.request(53, 3, &[])?;
        let t1 = monotonic_ns();
        if g.len() < 8 || g[..4] == [0; 4] {
            return Err(err("GET_GEOM", "no actuators in the reply"));
        }
        if i > warm {
            rtt.saturating_record(t1.saturating_sub(t0));
        }
        progress.tick(i);
    }
    progress.finish();
    Ok(rtt)
}
