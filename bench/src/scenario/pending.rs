//! Scenarios that wait for parts being built: registered so that they are listed (as
//! "not yet available") and so that adding them means filling in `run`.
//!
//! * `loop`: the full loop client → driver → P2OS over a pty → emulator → ARMpac →
//!   driver → published state → client, split by stage (driver receive, serial write,
//!   emulator reply, driver publish, client receive) from the stamps each stage records.

use super::{RunCtx, Scenario};
use crate::BenchError;

const WHY: &str = "needs per-stage stamps from the Pioneer driver and the emulator (serial write, controller reply, packet received), which they do not expose yet";

/// The `loop` scenario (placeholder).
#[derive(Debug, Clone, Copy)]
pub struct Loop;

impl Scenario for Loop {
    fn name(&self) -> &'static str {
        "loop"
    }
    fn description(&self) -> &'static str {
        "full loop through the emulator over a pty, split by stage"
    }
    fn availability(&self) -> Result<(), String> {
        Err(WHY.into())
    }
    fn run(&self, _ctx: &mut RunCtx) -> Result<(), BenchError> {
        Err(BenchError::Args(format!("loop: {WHY}")))
    }
}
