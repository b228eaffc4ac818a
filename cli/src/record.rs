//! `limber record` and `limber replay`: a run into an MCAP file, and back into a domain
//! (the work is in the limber-record crate).

use std::io::Write;
use std::path::PathBuf;
use std::time::Duration;

use clap::{Args, ValueEnum};
use limber_record::mcap::Compression;
use limber_record::{
    Progress, RecordConfig, RecordError, RecordEvent, ReplayConfig, ReplayError, ReplayEvent,
};
use limber_services::signals;

use crate::out::outln;
use crate::{CliError, domain, exit};

/// Chunk compression of `limber record`.
#[derive(Debug, Clone, Copy, ValueEnum)]
enum CompressionArg {
    /// LZ4 frames.
    Lz4,
    /// None.
    None,
}

/// Arguments of `limber record`.
#[derive(Debug, Args)]
pub struct RecordArgs {
    /// The devices to record (robot/interface/index); none: every device of the domain,
    /// including those that start later.
    devices: Vec<String>,
    /// The MCAP file to write.
    #[arg(short, long, value_name = "FILE", required_unless_present = "info")]
    output: Option<PathBuf>,
    /// Stop after this many seconds (default: at Ctrl-C or SIGTERM).
    #[arg(long, value_name = "S", value_parser = crate::parse_seconds)]
    duration: Option<f64>,
    /// How chunks are compressed.
    #[arg(long, value_enum, default_value = "lz4")]
    compression: CompressionArg,
    /// Start a new file every this many megabytes (files FILE_0.mcap, FILE_1.mcap...).
    #[arg(long, value_name = "MB", value_parser = parse_megabytes)]
    split_size: Option<u64>,
    /// Start a new file every this many seconds (files FILE_0.mcap, FILE_1.mcap...).
    #[arg(long, value_name = "S", value_parser = crate::parse_seconds)]
    split_time: Option<f64>,
    /// Summarise a recorded file instead (channels, message counts, time span).
    #[arg(long, value_name = "FILE", conflicts_with_all = ["output", "devices", "duration", "split_size", "split_time"])]
    info: Option<PathBuf>,
}

/// Arguments of `limber replay`.
#[derive(Debug, Args)]
pub struct ReplayArgs {
    /// The MCAP file written by `limber record`.
    file: PathBuf,
    /// Speed: 1 as recorded, 2 twice as fast.
    #[arg(long, default_value_t = 1.0, value_name = "X")]
    rate: f64,
    /// Start again at the end, until Ctrl-C or SIGTERM.
    #[arg(long = "loop")]
    looped: bool,
}

/// `--split-size`: a whole number of megabytes, at least 1; in bytes.
fn parse_megabytes(s: &str) -> Result<u64, String> {
    match s.parse::<u64>() {
        Ok(mb @ 1..=1_000_000) => Ok(mb * 1_000_000),
        _ => Err(format!(
            "{s:?}: a whole number of megabytes from 1 to 1000000"
        )),
    }
}

fn install_signals() -> Result<(), CliError> {
    signals::install().map_err(|e| {
        CliError::new(
            exit::FAILURE,
            format!("cannot install the signal handlers: {e}"),
        )
    })
}

fn progress_line(p: &Progress) -> String {
    let secs = p.elapsed.as_secs_f64().max(1e-9);
    format!(
        "{} messages, {} bytes, {:.1} msg/s, {} channels, {} dropped, {} missed",
        p.messages,
        p.bytes,
        p.messages as f64 / secs,
        p.channels,
        p.dropped,
        p.missed
    )
}

/// Runs `limber record`.
pub fn record(a: RecordArgs) -> Result<(), CliError> {
    if let Some(path) = &a.info {
        let info =
            limber_record::info(path).map_err(|e| CliError::new(exit::FAILURE, e.to_string()))?;
        outln!("file: {}", path.display())?;
        for line in info.to_string().lines() {
            outln!("{line}")?;
        }
        return Ok(());
    }
    let Some(output) = &a.output else {
        return Err(CliError::new(exit::USAGE, "-o FILE is required"));
    };
    install_signals()?;
    let domain = domain()?;
    let config = RecordConfig {
        devices: a.devices.clone(),
        duration: a.duration.map(Duration::from_secs_f64),
        compression: match a.compression {
            CompressionArg::Lz4 => Compression::Lz4,
            CompressionArg::None => Compression::None,
        },
        split_bytes: a.split_size,
        split_time: a.split_time.map(Duration::from_secs_f64),
        ..RecordConfig::default()
    };
    let tty = std::io::IsTerminal::is_terminal(&std::io::stderr());
    let mut report = |ev: RecordEvent| {
        let p = match ev {
            RecordEvent::Recording(d) => {
                crate::out::note(format_args!("recording {d}\n"));
                return;
            }
            RecordEvent::Progress(p) => p,
        };
        // A progress line on stderr: rewritten in place on a terminal, one per second
        // otherwise.
        let mut err = std::io::stderr();
        let shown = if tty {
            write!(err, "\r{:<100}", progress_line(&p))
        } else {
            writeln!(err, "recording: {}", progress_line(&p))
        };
        if let Err(e) = shown {
            tracing::debug!(error = %e, "cannot print the progress");
        }
    };
    outln!("recording into {} (Ctrl-C ends)", output.display())?;
    let p = limber_record::record(
        &domain,
        output,
        &config,
        &signals::termination_requested,
        &mut report,
    )
    .map_err(|e| {
        let code = match e {
            RecordError::Name(_) => exit::USAGE,
            _ => exit::FAILURE,
        };
        CliError::new(code, e.to_string())
    })?;
    if tty {
        eprintln!();
    }
    outln!("recorded {}", progress_line(&p))?;
    Ok(())
}

/// Runs `limber replay`.
pub fn replay(a: ReplayArgs) -> Result<(), CliError> {
    install_signals()?;
    let domain = domain()?;
    let config = ReplayConfig {
        rate: a.rate,
        looped: a.looped,
    };
    let mut failed_print = None;
    let mut report = |ev: ReplayEvent| {
        let shown = match ev {
            ReplayEvent::Hosting(d) => outln!("hosting {d}"),
            ReplayEvent::Driver(r) => outln!("driver statistics of {r}"),
            ReplayEvent::Pass(n) => outln!("pass {n}"),
        };
        if let Err(e) = shown {
            failed_print = Some(e);
        }
    };
    let n = limber_record::replay(
        &domain,
        &a.file,
        &config,
        &signals::termination_requested,
        &mut report,
    )
    .map_err(|e| {
        let code = match e {
            ReplayError::Rate(_) => exit::USAGE,
            _ => exit::FAILURE,
        };
        CliError::new(code, e.to_string())
    })?;
    if let Some(e) = failed_print {
        return Err(e);
    }
    outln!("replayed {n} messages")?;
    Ok(())
}

/// Arguments of `limber view`.
#[derive(Debug, Args)]
pub struct ViewArgs {
    /// Where to listen (Foxglove's default port on loopback; another address exposes the
    /// domain's states, read-only, to whoever reaches it).
    #[arg(long, default_value = "127.0.0.1:8765", value_name = "ADDR:PORT")]
    listen: std::net::SocketAddr,
    /// The chain of simarm's arm when it runs with `--chain FILE` or `--urdf FILE.urdf`
    /// (default: its built-in 6-joint arm), for the URDF served.
    #[arg(long, value_name = "FILE")]
    simarm_chain: Option<PathBuf>,
}

/// Runs `limber view`.
pub fn view(a: ViewArgs) -> Result<(), CliError> {
    install_signals()?;
    let domain = domain()?;
    let simarm_chain = match &a.simarm_chain {
        Some(p) if p.extension().is_some_and(|e| e == "urdf") => Some(
            limber_record::urdf_in::chain_from_urdf_file(p)
                .map_err(|e| CliError::new(exit::USAGE, format!("{}: {e}", p.display())))?,
        ),
        Some(p) => Some(
            limber_kinematics::chain::Chain::from_file(p)
                .map_err(|e| CliError::new(exit::USAGE, e.to_string()))?,
        ),
        None => None,
    };
    let config = limber_record::ViewConfig {
        listen: a.listen,
        simarm_chain,
        ..limber_record::ViewConfig::default()
    };
    let mut report = |ev: limber_record::ViewEvent| match ev {
        limber_record::ViewEvent::Listening(addr) => crate::out::note(format_args!(
            "serving foxglove.websocket.v1 on ws://{addr}; ready\n"
        )),
        limber_record::ViewEvent::Device(d) => crate::out::note(format_args!("showing {d}\n")),
        limber_record::ViewEvent::Client(p) => crate::out::note(format_args!("viewer {p}\n")),
    };
    limber_record::view(
        &domain,
        &config,
        &signals::termination_requested,
        &mut report,
    )
    .map_err(|e| CliError::new(exit::FAILURE, e.to_string()))
}
