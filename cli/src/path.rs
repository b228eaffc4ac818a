//! `limber limb DEVICE line|ptp X Y Z [--speed V] [--approach AX AY AZ --orient OX OY OZ]`:
//! the limb's paths (issue 28). A path refused before it started is said with where: the
//! limb state that shows the refusal (published before its outcome) names the first bad
//! point of the path and its fraction.

use clap::Args;
use limber_interfaces::prelude::*;
use limber_services::Client;

use crate::device::{Common, finish, wait_err};
use crate::{CliError, exit};

/// The goal of a `line` or a `ptp`.
#[derive(Debug, Args)]
pub struct PathArgs {
    /// x, y, z of the tool's goal, m (robot frame).
    #[arg(num_args = 3, required = true, allow_negative_numbers = true, value_names = ["X", "Y", "Z"])]
    position: Vec<f64>,
    /// The speed limit: line, the tool's m/s; ptp, the fastest joint's rad/s (0: the
    /// limb's own).
    #[arg(long, default_value_t = 0.0)]
    speed: f64,
    /// The goal's approach vector (with --orient); without both the tool keeps its
    /// orientation (a line turns it evenly on the way).
    #[arg(long, num_args = 3, allow_negative_numbers = true, requires = "orient",
          value_names = ["AX", "AY", "AZ"])]
    approach: Option<Vec<f64>>,
    /// The goal's orientation vector (with --approach).
    #[arg(long, num_args = 3, allow_negative_numbers = true, requires = "approach",
          value_names = ["OX", "OY", "OZ"])]
    orient: Option<Vec<f64>>,
}

fn v3(v: &[f64]) -> [f64; 3] {
    [v[0], v[1], v[2]]
}

/// Sends a LINE (`line`) or a PTP and reports it as every command is reported; a refusal
/// says where the path failed its check.
pub fn run(c: &mut Client<Limb>, p: PathArgs, line: bool, common: &Common) -> Result<(), CliError> {
    let position = v3(&p.position);
    let orientation = p
        .approach
        .as_deref()
        .zip(p.orient.as_deref())
        .map(|(a, o)| (v3(a), v3(o)));
    let sent = if line {
        c.line(position, orientation, p.speed)
    } else {
        c.ptp(position, orientation, p.speed)
    };
    match finish(c, sent, common) {
        Err(e) if e.exit_code() == exit::REFUSED => {
            let s = *c.current(common.timeout()).map_err(wait_err)?;
            match limber_interfaces::describe::limb_path_name(s.refused_kind) {
                Some(_) => {
                    let r = s.refused_at;
                    Err(CliError::new(
                        exit::REFUSED,
                        format!(
                            "{e} at {:.0}% of the path, the tool at ({:.4}, {:.4}, {:.4}) m; nothing moved",
                            s.refused_fraction * 100.0,
                            r.x,
                            r.y,
                            r.z
                        ),
                    ))
                }
                None => Err(e),
            }
        }
        r => r,
    }
}
