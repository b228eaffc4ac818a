//! `limber emulator`: the command-line front end.

use crate::{CliError, exit};
use limber_emulator::{
    ArmpacLayout, Emulator, EmulatorConfig, EmulatorError, Faults, GripperByteLayout,
    ObjectPlacement, Timing,
};
use limber_services::signals;
use std::io::{Read, Write};
use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

/// Arguments of `limber emulator`.
#[derive(Debug, Clone, clap::Args)]
pub struct EmulatorArgs {
    /// Serve on a new pty (the default); its path is printed first on stdout.
    #[arg(long, conflicts_with = "tcp")]
    pub pty: bool,
    /// Serve on TCP at this port (8101, the simulator port, if no value is
    /// given; 0 = any free port); the address is printed first on stdout.
    #[arg(long, value_name = "PORT", num_args = 0..=1, default_missing_value = "8101")]
    pub tcp: Option<u16>,
    /// Address to bind with --tcp.
    #[arg(long, default_value_t = IpAddr::V4(Ipv4Addr::LOCALHOST))]
    pub bind: IpAddr,
    /// Controller cycle (SIP period) in milliseconds.
    #[arg(long, default_value_t = 100)]
    pub cycle_ms: u64,
    /// Fast mode: answer SYNC, ARM_INFO and ARM_STATUS at once and send an extra ARMpac
    /// after each arm command and motion change (for benchmarks). Default: like the
    /// controller, every packet at the next cycle boundary.
    #[arg(long)]
    pub fast: bool,
    /// ARMpac status byte layout: `manual` (the vendor's manuals: power/connection byte,
    /// then the moving bits) or `aria` (ARIA's reading: one little-endian word, moving
    /// bits first).
    #[arg(long, value_name = "LAYOUT", default_value = "manual", value_parser = parse_layout)]
    pub armpac_layout: ArmpacLayout,
    /// Gripper state byte layout (SIP and GRIPPERpac): `manual` (the Pioneer Gripper
    /// manual: active-high bits, the breakbeams in DIGIN) or `aria` (ARIA's active-low
    /// General-I/O switches, the beams in the byte).
    #[arg(long, value_name = "LAYOUT", default_value = "manual", value_parser = parse_gripper_byte)]
    pub gripper_byte: GripperByteLayout,
    /// Emulate a robot without an arm (arm commands are ignored).
    #[arg(long)]
    pub no_arm: bool,
    /// Emulate a robot without a body gripper and lift: its CONFIGpac says so (GRIPPER 0),
    /// and GRIPPER (33) and GRIPPERVAL (36) commands are logged as unsupported, counted
    /// and ignored, like a gripperless controller (their count is printed on stdout at exit).
    #[arg(long)]
    pub no_gripper: bool,
    /// Never answer CONFIG (18), like a controller that does not implement it.
    #[arg(long)]
    pub no_config: bool,
    /// pty: answer only when the line is set to this baud rate.
    #[arg(long)]
    pub baud: Option<u32>,
    /// Slow wire: take the transmission time of this baud rate.
    #[arg(long)]
    pub slow_wire: Option<u32>,
    /// Put an object between the paddles (both breakbeams).
    #[arg(long)]
    pub object: bool,
    /// Robot name sent in the SYNC2 reply.
    #[arg(long, default_value = "limber-emulator")]
    pub name: String,
    /// Robot class sent in the SYNC2 reply.
    #[arg(long, default_value = "Pioneer")]
    pub class: String,
    /// Robot subclass sent in the SYNC2 reply.
    #[arg(long, default_value = "p3dx")]
    pub subclass: String,
    /// Fault: probability of dropping each outgoing byte.
    #[arg(long, default_value_t = 0.0)]
    pub drop_rate: f64,
    /// Fault: probability of corrupting each outgoing byte.
    #[arg(long, default_value_t = 0.0)]
    pub corrupt_rate: f64,
    /// Fault: probability of a wrong checksum on each outgoing packet.
    #[arg(long, default_value_t = 0.0)]
    pub bad_checksum_rate: f64,
    /// Fault: probability of garbage bytes before each outgoing packet.
    #[arg(long, default_value_t = 0.0)]
    pub garbage_rate: f64,
    /// Fault: drop the first N ARMINFOpac replies (a lost ARM_INFO answer).
    #[arg(long, default_value_t = 0, value_name = "N")]
    pub drop_arm_info: u32,
    /// Seed of the fault generator.
    #[arg(long, default_value_t = 0x5EED)]
    pub seed: u64,
    /// Stop streaming after this many milliseconds without a command (the
    /// simulator does so after about 60 000).
    #[arg(long)]
    pub watchdog_ms: Option<u64>,
    /// Keep running when stdin closes (for `&` in scripts, whose stdin is
    /// /dev/null); stop with SIGINT/SIGTERM/SIGHUP (or SIGQUIT) only.
    #[arg(long)]
    pub ignore_stdin: bool,
}

fn parse_gripper_byte(s: &str) -> Result<GripperByteLayout, String> {
    GripperByteLayout::from_name(s).ok_or_else(|| format!("{s:?}: expected manual or aria"))
}

fn parse_layout(s: &str) -> Result<ArmpacLayout, String> {
    ArmpacLayout::from_name(s).ok_or_else(|| format!("{s:?}: expected manual or aria"))
}

fn check_rate(name: &str, v: f64) -> Result<f64, EmulatorError> {
    if (0.0..=1.0).contains(&v) {
        Ok(v)
    } else {
        Err(EmulatorError::Args(format!(
            "--{name} must be in 0..=1, got {v}"
        )))
    }
}

impl EmulatorArgs {
    /// The emulator configuration these arguments describe.
    pub fn config(&self) -> Result<EmulatorConfig, EmulatorError> {
        if self.cycle_ms == 0 {
            return Err(EmulatorError::Args("--cycle-ms must be at least 1".into()));
        }
        let mut cfg = EmulatorConfig {
            cycle: Duration::from_millis(self.cycle_ms),
            baud: self.baud,
            seed: self.seed,
            faults: Faults {
                drop_rate: check_rate("drop-rate", self.drop_rate)?,
                corrupt_rate: check_rate("corrupt-rate", self.corrupt_rate)?,
                bad_checksum_rate: check_rate("bad-checksum-rate", self.bad_checksum_rate)?,
                garbage_rate: check_rate("garbage-rate", self.garbage_rate)?,
                silent: false,
                slow_wire_baud: self.slow_wire,
                drop_arm_info_replies: self.drop_arm_info,
                no_config: self.no_config,
                deaf: false,
            },
            watchdog: self.watchdog_ms.map(Duration::from_millis),
            timing: if self.fast {
                Timing::Fast
            } else {
                Timing::Controller
            },
            ..EmulatorConfig::default()
        };
        cfg.model.armpac_layout = self.armpac_layout;
        cfg.model.gripper_byte = self.gripper_byte;
        if self.no_arm {
            cfg.model.arm = None;
        }
        cfg.model.gripper = !self.no_gripper;
        cfg.model.identity.name = self.name.clone();
        cfg.model.identity.class = self.class.clone();
        cfg.model.identity.subclass = self.subclass.clone();
        Ok(cfg)
    }
}

/// Runs `limber emulator` until a termination signal (SIGINT, SIGTERM, SIGHUP, SIGQUIT,
/// SIGXCPU, SIGPWR: [`limber_services::signals`]) or until stdin closes (unless
/// `--ignore-stdin`); the other signals that would end a process are ignored. The first
/// line on stdout is the pty path or the TCP address.
pub fn run(args: EmulatorArgs) -> Result<(), CliError> {
    serve(args).map_err(|e| {
        let code = match e {
            EmulatorError::Args(_) => exit::USAGE,
            _ => exit::FAILURE,
        };
        CliError::new(code, e.to_string())
    })
}

fn serve(args: EmulatorArgs) -> Result<(), EmulatorError> {
    let cfg = args.config()?;
    // Before the first line: whoever read it may signal at once. The termination signals
    // end it; the other signals that would end a process are ignored
    // (limber_services::signals).
    signals::install().map_err(std::io::Error::from)?;
    let emu = match args.tcp {
        Some(port) => Emulator::start_tcp(cfg, SocketAddr::new(args.bind, port))?,
        None => Emulator::start_pty(cfg)?,
    };
    if args.object {
        emu.set_object(Some(ObjectPlacement::Inner));
    }
    {
        let mut out = std::io::stdout().lock();
        match (emu.pty_path(), emu.tcp_addr()) {
            (Some(p), _) => writeln!(out, "{}", p.display())?,
            (None, Some(a)) => writeln!(out, "{a}")?,
            (None, None) => {}
        }
        out.flush()?;
    }
    let stop = Arc::new(AtomicBool::new(false));
    if !args.ignore_stdin {
        let s = Arc::clone(&stop);
        std::thread::Builder::new()
            .name("emulator-stdin".into())
            .spawn(move || {
                let mut buf = [0u8; 256];
                let mut stdin = std::io::stdin().lock();
                while matches!(stdin.read(&mut buf), Ok(n) if n > 0) {}
                s.store(true, Ordering::SeqCst);
            })?;
    }
    while !stop.load(Ordering::SeqCst) && !signals::termination_requested() {
        if !emu.is_running() {
            break;
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let st = emu.state().robot;
    if st.unsupported_gripper_commands + st.unsupported_gripperval_commands > 0 {
        let mut out = std::io::stdout().lock();
        writeln!(
            out,
            "unsupported commands received (the robot has no gripper): GRIPPER (33) x{}, \
             GRIPPERVAL (36) x{}",
            st.unsupported_gripper_commands, st.unsupported_gripperval_commands
        )?;
        out.flush()?;
    }
    emu.stop()
}
