//! The loops: event-driven (a WaitSet on the link, the clients and a timer) and spinning,
//! and the timer's work.

use core::ops::ControlFlow;
use std::time::{Duration, Instant};

use limber_services::Drain;
use limber_services::event_loop::{self, FdSource, LoopExit, Wake};

use super::serve::Serve;
use super::{DriverError, Failure, LoopMode, PioneerDriver, RunOptions};

/// Ticks in a row that find clients' work without a wake-up before the driver warns that
/// wake-ups are lost.
const DEAF_TICKS: u32 = 20;

impl PioneerDriver {
    /// Timer work: silence detection, keep-alive, estimates, housekeeping.
    fn tick(&mut self, now: Instant) {
        if self.conn.is_some() {
            if now.duration_since(self.robot.last_rx())
                > Duration::from_millis(self.robot.cfg.link_timeout_ms)
            {
                self.link_failed("silent");
            } else if !self.probe_arm(now) {
                self.link_failed("write failed");
            } else if let Some(c) = self.conn.as_mut()
                && let Err(e) = c.keep_alive()
            {
                tracing::warn!("keep-alive failed: {e}");
                self.link_failed("write failed");
            }
        } else {
            self.try_reconnect();
        }
        self.robot.check_arm_reporting(now);
        // A joint trajectory's next targets.
        self.robot.step_trajectory();
        if let Err(status) =
            super::serve::flush(&mut self.robot, self.conn.as_mut(), &mut self.timing)
        {
            tracing::debug!("trajectory targets not written: {status}");
        }
        // Time-based lift estimate and stall detection move without packets.
        if self.robot.lift.moving.is_some() {
            self.robot.dirty.body = true;
        }
        // The deadman: a lease whose holder died or fell silent ends and stops its device
        // (clients wake the loop only when they send).
        let mut handler = Serve {
            robot: &mut self.robot,
            conn: self.conn.as_mut(),
            stats: &mut self.timing,
        };
        if let Err(e) = self.hosts.check_leases(&mut handler) {
            self.failures.note(Failure::Process, &e);
        }
        // Housekeeping (allocates inside iceoryx2): resources of crashed clients.
        if now.duration_since(self.last_cleanup) > Duration::from_secs(60) {
            self.last_cleanup = now;
            self.hosts.cleanup_dead();
        }
    }

    /// Runs until SIGINT/SIGTERM/SIGHUP; then stops the arm, closes the link and returns
    /// (what the shutdown did is logged; [`PioneerDriver::run_until`] and
    /// [`PioneerDriver::shutdown`] give it).
    pub fn run(&mut self, opts: RunOptions) -> Result<LoopExit, DriverError> {
        let exit = self.run_until(opts, || false);
        let report = self.shutdown();
        tracing::info!("{report}");
        exit
    }

    /// Runs until SIGINT/SIGTERM/SIGHUP or until `stop` (checked at every wake-up, at least every
    /// tick) returns true. The link stays open: run again, or call
    /// [`PioneerDriver::shutdown`] to stop the arm and close it.
    pub fn run_until(
        &mut self,
        opts: RunOptions,
        mut stop: impl FnMut() -> bool,
    ) -> Result<LoopExit, DriverError> {
        self.mode = opts.mode;
        match opts.mode {
            LoopMode::Event => self.run_event(&mut stop),
            LoopMode::Spin => Ok(self.run_spin(&mut stop)),
        }
    }

    /// Wake-ups of the loop so far (each costs iceoryx2's WaitSet one small allocation).
    pub fn wakeups(&self) -> u64 {
        self.wakeups
    }

    /// Ticks of the event-driven loop that found commands or requests waiting (which a
    /// client's wake-up had not brought in first): the safety net under lost wake-ups.
    pub fn tick_found_work(&self) -> u64 {
        self.tick_found_work
    }

    /// Counts a tick that found clients' work, and warns (once per episode) when ticks
    /// keep finding work while no wake-up comes: the clients' wake-ups are lost.
    fn note_tick_work(&mut self, found: bool) {
        let woken = std::mem::take(&mut self.woken_since_tick);
        if found {
            self.tick_found_work += 1;
        }
        if found && !woken {
            self.deaf_ticks = self.deaf_ticks.saturating_add(1);
            if self.deaf_ticks == DEAF_TICKS {
                tracing::warn!(
                    "clients' commands arrive but their wake-ups do not ({DEAF_TICKS} ticks in a \
                     row): serving them at every tick until wake-ups come again"
                );
            }
        } else {
            if self.deaf_ticks >= DEAF_TICKS {
                tracing::info!("clients' wake-ups arrive again");
            }
            self.deaf_ticks = 0;
        }
    }

    fn run_event(&mut self, stop: &mut dyn FnMut() -> bool) -> Result<LoopExit, DriverError> {
        let mut listeners = self.hosts.take_wake_listeners();
        let tick = self.robot.cfg.tick();
        let nominal = tick.as_nanos() as u64;
        loop {
            // Devices offered while running (an arm that answered late) wake the loop too.
            listeners.extend(self.hosts.take_wake_listeners());
            self.devices_added = false;
            // (Re)attach the link's fd: it changes when the link is re-established.
            let fd = self.conn.as_ref().and_then(|c| FdSource::new(c.link()));
            let had_link = fd.is_some();
            let mut stopped = false;
            let exit = event_loop::run(&listeners, tick, fd.as_ref(), |wake| {
                let now = Instant::now();
                self.wakeups += 1;
                match wake {
                    Wake::Fd => {
                        if !self.read_link(now) {
                            self.link_failed("read failed");
                        }
                    }
                    Wake::Clients => {
                        self.woken_since_tick = true;
                        if self.process_clients(Drain::All) {
                            // A client in a tight loop sends its next command within the
                            // linger: picked up without a wake-up.
                            let linger = Duration::from_micros(self.robot.cfg.linger_us.into());
                            event_loop::linger(linger, || self.process_clients(Drain::Linger));
                        }
                    }
                    Wake::Tick(n) => {
                        self.timing.tick(now, nominal, n);
                        // A packet may be sitting in the decoder after a send.
                        if !self.read_link(now) && self.conn.is_some() {
                            self.link_failed("read failed");
                        }
                        self.tick(now);
                        // The safety net under the clients' wake-ups: a wake-up that never
                        // comes (seen in the soak: a device's listener stopped waking the
                        // loop, and its commands and requests waited for ever) delays a
                        // command by one tick at most instead of freezing that device.
                        // The polling variant: commands at every tick, requests at every
                        // 16th, and nothing allocated when nothing waits.
                        let found = self.process_clients(Drain::Spin);
                        self.note_tick_work(found);
                    }
                }
                if std::mem::take(&mut self.arm_info_arrived) {
                    self.on_arm_info();
                }
                self.publish_all(now);
                if stop() {
                    stopped = true;
                    return ControlFlow::Break(());
                }
                // Leave the wait to re-attach when the link went down or came up, or to
                // attach the listeners of new devices.
                if self.conn.is_some() != had_link || self.devices_added {
                    ControlFlow::Break(())
                } else {
                    ControlFlow::Continue(())
                }
            })
            .map_err(DriverError::Loop)?;
            if exit == LoopExit::Signal {
                return Ok(LoopExit::Signal);
            }
            if stopped {
                return Ok(LoopExit::Stopped);
            }
        }
    }

    fn run_spin(&mut self, stop: &mut dyn FnMut() -> bool) -> LoopExit {
        let tick = self.robot.cfg.tick();
        let nominal = tick.as_nanos() as u64;
        let mut next_tick = Instant::now() + tick;
        let mut n: u64 = 0;
        loop {
            let now = Instant::now();
            if self.conn.is_some() && !self.read_link(now) {
                self.link_failed("read failed");
            }
            self.process_clients(Drain::Spin);
            if now >= next_tick {
                let missed = (now.duration_since(next_tick).as_nanos() as u64) / nominal.max(1);
                self.timing.tick(now, nominal, 1 + missed);
                next_tick += tick * (1 + missed as u32);
                self.tick(now);
            }
            if std::mem::take(&mut self.arm_info_arrived) {
                self.on_arm_info();
            }
            self.publish_all(now);
            n += 1;
            if n.is_multiple_of(1024) {
                if self.ctx.termination_requested() {
                    return LoopExit::Signal;
                }
                if stop() {
                    return LoopExit::Stopped;
                }
            }
            core::hint::spin_loop();
        }
    }
}
