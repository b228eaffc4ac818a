//! `limber player-gateway`: Player's TCP protocol in front of the domain's devices, for
//! Player's own programs (libplayerc, libplayerc++, playerv, playerprint, playerjoy).

use std::net::SocketAddr;

use clap::Args;
use limber_gateway::{Conventions, GatewayConfig, GatewayEvent, MapEntry};
use limber_services::signals;

use crate::out::noteln;
use crate::{CliError, domain, exit};

/// Arguments of `limber player-gateway`.
#[derive(Debug, Args)]
pub struct PlayerGatewayArgs {
    /// Where to listen. Player's protocol has no authentication: anyone who reaches the
    /// port commands the robot, so listen beyond loopback only on a network you trust
    /// (and consider --read-only).
    #[arg(long, default_value = "127.0.0.1:6665", value_name = "ADDR:PORT")]
    listen: SocketAddr,
    /// Refuse every command, every request that changes a device (power, brakes, speed)
    /// and leases; states, the device list and geometry still pass.
    #[arg(long)]
    read_only: bool,
    /// Give a device a fixed Player address (repeatable), e.g.
    /// pioneer/actarray/1=actarray:0 for playerjoy, which moves the lift as actarray:0.
    /// Other devices keep their index, or take the lowest free one. A ranger is Player's
    /// laser (pioneer/ranger/0=laser:0).
    #[arg(long = "map", value_name = "DEVICE=INTERFACE:INDEX")]
    map: Vec<MapEntry>,
    /// Show a lift (an actarray of one linear actuator) in metres instead of Player's
    /// p2os convention (0 down, 1 up).
    #[arg(long)]
    metres: bool,
}

/// Runs `limber player-gateway` until SIGINT, SIGTERM, SIGHUP (or SIGQUIT).
pub fn run(args: PlayerGatewayArgs) -> Result<(), CliError> {
    let domain = domain()?;
    if let Err(e) = signals::install() {
        return Err(CliError::new(
            exit::FAILURE,
            format!("cannot install the signal handlers: {e}"),
        ));
    }
    if !args.listen.ip().is_loopback() {
        tracing::warn!(listen = %args.listen,
            "listening beyond loopback: Player's protocol has no authentication");
    }
    let config = GatewayConfig {
        listen: args.listen,
        read_only: args.read_only,
        map: args.map,
        conventions: Conventions {
            normalise_lift: !args.metres,
        },
        ..GatewayConfig::default()
    };
    let name = domain.name().to_string();
    let mode = if args.read_only { " (read-only)" } else { "" };
    limber_gateway::run(
        &domain,
        &config,
        &signals::termination_requested,
        &mut |ev| match ev {
            GatewayEvent::Listening(a) => {
                noteln!("player gateway for domain {name} listening on {a}{mode}")
            }
            GatewayEvent::Opened { id, peer } => noteln!("session {id} from {peer}"),
            GatewayEvent::Ended { id } => noteln!("session {id} ended"),
            GatewayEvent::Refused(peer) => noteln!("refused {peer}: too many sessions"),
        },
    )
    .map_err(|e| CliError::new(exit::FAILURE, e.to_string()))
}
