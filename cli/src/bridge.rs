//! `limber bridge`: a domain's devices over Zenoh (`expose`), and remote devices hosted in
//! this domain (`mirror`).

use std::path::PathBuf;

use clap::{Args, Subcommand};
use limber_bridge::expose::ExposeEvent;
use limber_bridge::mirror::MirrorEvent;
use limber_bridge::{
    Allow, CommandKind, DevicePattern, ExposeConfig, ExposeError, MirrorConfig, MirrorError,
    NetConfig, RequestKind, SessionError,
};
use limber_services::signals;

use crate::out::noteln;
use crate::{CliError, domain, exit, parse_seconds};

/// Arguments of `limber bridge`.
#[derive(Debug, Args)]
pub struct BridgeArgs {
    #[command(subcommand)]
    role: Role,
}

#[derive(Debug, Subcommand)]
enum Role {
    /// On the robot's PC: put every device of this domain on Zenoh (state, commands,
    /// requests, a liveliness token per device). Listens on a Unix socket only you can open
    /// (`<runtime dir>/bridge/<domain>.sock`) unless told otherwise; a TCP or TLS listener
    /// needs credentials (--zenoh-config: user/password, or TLS client certificates).
    ///
    /// Runs until SIGINT, SIGTERM, SIGHUP (or SIGQUIT); prints "exposed DEVICE" and "gone
    /// DEVICE" as drivers come and go.
    Expose(ExposeArgs),
    /// On another host (or in another domain of this one): host the devices of a remote
    /// `expose` in this domain under the same names, so that unchanged clients use them.
    /// Connects to --connect ENDPOINT, or to the bridge of domain --from DOMAIN of yours on
    /// this machine; listens on nothing.
    ///
    /// Runs until SIGINT, SIGTERM, SIGHUP (or SIGQUIT); prints "mirrored DEVICE as NAME" and
    /// "gone NAME" as remote devices come and go.
    Mirror(MirrorArgs),
}

/// The network flags of both roles.
#[derive(Debug, Args)]
struct Net {
    /// A Zenoh endpoint to listen on (repeatable), e.g. tls/192.168.1.10:7447; anything but
    /// a Unix socket needs credentials in --zenoh-config (bridge/README.md, Security).
    #[arg(long, value_name = "ENDPOINT")]
    listen: Vec<String>,
    /// A Zenoh endpoint to connect to (repeatable), e.g. tcp/192.168.1.10:7447.
    #[arg(long, value_name = "ENDPOINT")]
    connect: Vec<String>,
    /// A Zenoh configuration file (JSON5) for TLS, user/password and the like; the
    /// endpoints given here apply on top of it (bridge/README.md has examples).
    #[arg(long, value_name = "FILE")]
    zenoh_config: Option<PathBuf>,
}

#[derive(Debug, Args)]
struct ExposeArgs {
    #[command(flatten)]
    net: Net,
    /// How long the driver has to answer a relayed request, in seconds.
    #[arg(long, default_value = "1.5", value_parser = parse_seconds, value_name = "S")]
    request_timeout: f64,
    /// Expose only the devices that match (repeatable; robot/interface/index, each part a
    /// name or *, e.g. pioneer/actarray/*). Default: every device.
    #[arg(long = "device", value_name = "PATTERN")]
    devices: Vec<DevicePattern>,
    /// Let only these commands through (repeatable; interface:kind, e.g. actarray:pos,
    /// gripper:open). Any other command is refused ("unsupported") to its sender. Default:
    /// every command.
    #[arg(long = "allow-command", value_name = "INTERFACE:KIND")]
    allow_commands: Vec<CommandKind>,
    /// Let only these requests that change a device through (repeatable; interface:kind,
    /// e.g. actarray:power, limb:speed). With an --allow-command or --allow-request list,
    /// every request that changes a device and is not listed is refused ("unsupported");
    /// read-only requests (geometry, reach) always pass.
    #[arg(long = "allow-request", value_name = "INTERFACE:KIND")]
    allow_requests: Vec<RequestKind>,
    /// Refuse every command and every request that changes a device (power, brakes,
    /// speed); the state and read-only requests (geometry) still pass.
    #[arg(long)]
    read_only: bool,
    /// A principal that may send commands and requests (repeatable): the common name of a
    /// TLS client certificate, or a user of the user/password dictionary (all of whose
    /// users are principals anyway). Each principal's leases and commands are its own.
    #[arg(long = "peer", value_name = "NAME")]
    peers: Vec<String>,
}

#[derive(Debug, Args)]
struct MirrorArgs {
    #[command(flatten)]
    net: Net,
    /// Prepended to each remote robot name, where local names would collide (e.g.
    /// "lab_" hosts pioneer/actarray/0 as lab_pioneer/actarray/0).
    #[arg(long, default_value = "", value_name = "PREFIX")]
    prefix: String,
    /// How long a relayed request may take before its client is told "timeout", in
    /// seconds.
    #[arg(long, default_value = "1.8", value_parser = parse_seconds, value_name = "S")]
    request_timeout: f64,
    /// Connect to the exposing bridge of this domain of yours on this machine (its private
    /// Unix socket), instead of --connect.
    #[arg(long, value_name = "DOMAIN", conflicts_with = "connect")]
    from: Option<String>,
    /// Who this mirror is to the exposing bridge: the common name of its TLS client
    /// certificate (default: its user/password user, else "local", the owner's socket).
    #[arg(long = "as", value_name = "NAME")]
    principal: Option<String>,
    /// The most remote devices hosted at once; more are refused.
    #[arg(long, default_value_t = limber_bridge::mirror::DEFAULT_MAX_DEVICES, value_name = "N")]
    max_devices: usize,
}

fn net_config(net: Net) -> NetConfig {
    NetConfig {
        listen: net.listen,
        connect: net.connect,
        config_file: net.zenoh_config,
    }
}

/// The exit code of a bridge that failed: a listener or principal refused is a usage
/// error (2), anything else a failure (1).
fn bridge_exit(access_refused: bool) -> u8 {
    if access_refused {
        exit::USAGE
    } else {
        exit::FAILURE
    }
}

/// Runs `limber bridge`.
pub fn run(args: BridgeArgs) -> Result<(), CliError> {
    let domain = domain()?;
    if let Err(e) = signals::install() {
        return Err(CliError::new(
            exit::FAILURE,
            format!("cannot install the signal handlers: {e}"),
        ));
    }
    let stop = signals::termination_requested;
    match args.role {
        Role::Expose(a) => {
            let filtered = !a.allow_commands.is_empty() || !a.allow_requests.is_empty();
            let config = ExposeConfig {
                net: net_config(a.net),
                request_timeout: std::time::Duration::from_secs_f64(a.request_timeout),
                allow: Allow {
                    devices: a.devices,
                    commands: filtered.then_some(a.allow_commands),
                    requests: filtered.then_some(a.allow_requests),
                    read_only: a.read_only,
                },
                peers: a.peers,
                ..ExposeConfig::default()
            };
            let name = domain.name().to_string();
            limber_bridge::expose(&domain, &config, &stop, &mut |ev| match ev {
                ExposeEvent::Ready { zid, listen } => noteln!(
                    "exposing domain {name} on Zenoh (id {zid}, listening on {})",
                    listen.join(", ")
                ),
                ExposeEvent::Exposed(d) => noteln!("exposed {d}"),
                ExposeEvent::Gone(d) => noteln!("gone {d}"),
            })
            .map_err(|e| {
                let refused = matches!(
                    e,
                    ExposeError::Session(SessionError::Access(_) | SessionError::ConfigFile { .. })
                );
                CliError::new(bridge_exit(refused), e.to_string())
            })
        }
        Role::Mirror(a) => {
            let mut net = net_config(a.net);
            if let Some(from) = &a.from {
                net.connect = vec![from_domain(from)?];
            }
            if net.connect.is_empty() {
                return Err(CliError::new(
                    exit::USAGE,
                    "bridge mirror needs --from DOMAIN (a bridge of yours on this machine) or --connect ENDPOINT",
                ));
            }
            let config = MirrorConfig {
                net,
                prefix: a.prefix,
                request_timeout: std::time::Duration::from_secs_f64(a.request_timeout),
                principal: a.principal,
                max_devices: a.max_devices,
            };
            let name = domain.name().to_string();
            limber_bridge::mirror(&domain, &config, &stop, &mut |ev| match ev {
                MirrorEvent::Ready { zid, principal } => noteln!(
                    "mirroring into domain {name} (Zenoh id {zid}, as {principal}, connecting to {})",
                    config.net.connect.join(", ")
                ),
                MirrorEvent::Mirrored { remote, local } => {
                    noteln!("mirrored {remote} as {local}")
                }
                MirrorEvent::Gone { local } => noteln!("gone {local}"),
                MirrorEvent::Refused { remote, reason } => {
                    noteln!("cannot mirror {remote}: {reason}")
                }
            })
            .map_err(|e| {
                let refused = matches!(
                    e,
                    MirrorError::Session(SessionError::Access(_) | SessionError::ConfigFile { .. })
                        | MirrorError::Prefix(_)
                );
                CliError::new(bridge_exit(refused), e.to_string())
            })
        }
    }
}

/// The endpoint of the exposing bridge of this user's domain `name` (its private socket).
fn from_domain(name: &str) -> Result<String, CliError> {
    let other = limber_services::Domain::new(name)
        .map_err(|e| CliError::new(exit::USAGE, e.to_string()))?;
    let runtime = limber_services::domain_dir::runtime_dir();
    limber_bridge::access::private_socket(&runtime, other.name())
        .map_err(|e| CliError::new(exit::FAILURE, e.to_string()))
}
