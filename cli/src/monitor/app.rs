//! The monitor's model: the devices of the domain, a connection to each, their latest
//! states, the driver statistics of each robot, and the key commands. No drawing here
//! (see `ui.rs`), and no terminal: tests drive it directly.
//!
//! Nothing in here blocks for long: states are taken with `refresh()` (never waits), the
//! outcome of a key command is polled once per tick, and the only requests (geometry)
//! are made once per device at connection, each with a short timeout.

use std::collections::BTreeMap;
use std::time::{Duration, Instant};

use crossterm::event::KeyCode;
use limber_interfaces::diagnostics::DriverStats;
use limber_services::diagnostics::StatsReader;
use limber_services::prelude::*;
use limber_services::{AnyGeom, CommandError, DeviceInfo, DeviceName, WaitError};

/// How often the device list is read again (devices appearing, drivers dying).
pub const REDISCOVER_EVERY: Duration = Duration::from_secs(1);
/// Timeout of the geometry request made when connecting to a device.
pub const REQUEST_TIMEOUT: Duration = Duration::from_millis(300);
/// How long a key command waits for its outcome before the status line gives up.
pub const OUTCOME_TIMEOUT: Duration = Duration::from_secs(2);
/// A live device that sent nothing new for this long is connected to again (its driver
/// may have restarted between two discoveries, leaving this connection on the old one).
pub const STALE_RECONNECT: Duration = Duration::from_secs(5);
/// How many times the geometry of a device is asked for (once per rediscovery).
const GEOMETRY_TRIES: u32 = 3;

/// A connection to one device of any interface, with its geometry once known.
pub struct Conn {
    /// The client.
    pub client: Box<dyn DeviceClient>,
    /// Its geometry (joint limits, beams...), if the driver answered.
    pub geom: Option<AnyGeom>,
}

impl Conn {
    fn connect(ctx: &Context, name: &DeviceName) -> Result<Conn, String> {
        let mut client =
            connect_device(ctx, &name.to_string(), Duration::ZERO).map_err(|e| e.to_string())?;
        client.set_request_timeout(REQUEST_TIMEOUT);
        let mut conn = Conn { client, geom: None };
        conn.refresh();
        Ok(conn)
    }

    /// The latest state of interface `I` (`None` for a device of another interface).
    pub fn state<I: Interface>(&self) -> Option<&I::Data> {
        self.client.typed_ref::<I>().and_then(|c| c.last_state())
    }

    /// The geometry of interface `I`, once known.
    pub fn geometry<I: Interface>(&self) -> Option<&I::Geom> {
        self.geom.as_ref().and_then(|g| g.get::<I::Geom>())
    }

    /// Asks for the geometry (a request: waits up to [`REQUEST_TIMEOUT`]).
    fn ask_geometry(&mut self) -> bool {
        self.geom = match self.client.geometry_within(REQUEST_TIMEOUT) {
            Ok(g) => Some(g),
            Err(e) => {
                // Asked again at the next discoveries (GEOMETRY_TRIES); the panel shows
                // the state meanwhile.
                tracing::debug!(device = %self.client.device(), error = %e, "no geometry yet");
                None
            }
        };
        self.has_geometry()
    }

    fn has_geometry(&self) -> bool {
        self.geom.is_some()
    }

    /// Takes every state that arrived (never waits).
    fn refresh(&mut self) -> bool {
        self.client.refresh().unwrap_or(false)
    }

    /// The header of the latest state.
    pub fn header(&self) -> Option<&StateHeader> {
        self.client.header()
    }

    /// Age of the latest state.
    pub fn state_age(&self) -> Option<Duration> {
        self.client.state_age()
    }

    /// The outcome of `ticket` if it is known now (never waits).
    fn poll_outcome(&mut self, ticket: Ticket) -> Result<Status, WaitError> {
        self.client.wait_outcome(ticket, Duration::ZERO)
    }

    /// The name of the client holding the device (a request: waits up to
    /// [`REQUEST_TIMEOUT`]).
    fn holder_name(&mut self) -> String {
        match self.client.holder() {
            Ok(Some(h)) if h.name.is_empty() => format!("client {}", h.client_id),
            Ok(Some(h)) => h.name,
            // Released between the state and the question.
            Ok(None) => "nobody now".to_string(),
            Err(e) => format!("? ({e})"),
        }
    }

    fn driver_status(&self) -> DriverStatus {
        self.client.driver_status()
    }
}

/// One device of the domain.
pub struct Device {
    /// What discovery says about it (name, driver, liveness).
    pub info: DeviceInfo,
    /// The connection, or why there is none.
    pub conn: Result<Conn, String>,
    geometry_tries: u32,
    /// When the last new state arrived (or the connection was made).
    last_new: Instant,
    /// Who holds the device's control lease (asked while its state says it is held).
    pub holder: Option<String>,
    holder_asked: Option<Instant>,
}

impl Device {
    /// True while its driver's process lives (as of the last discovery).
    pub fn alive(&self) -> bool {
        self.info.alive
    }
}

/// A robot's driver process: its statistics channel.
pub struct Robot {
    /// The driver's statistics reader, once the channel exists.
    pub stats: Option<StatsReader>,
    /// Why there is no reader (yet).
    pub stats_error: Option<String>,
    /// The driver name(s) offering the robot's devices.
    pub driver: String,
    /// True while any of its devices' driver lives.
    pub alive: bool,
}

impl Robot {
    /// The latest statistics.
    pub fn latest(&self) -> Option<&DriverStats> {
        self.stats.as_ref().and_then(|s| s.latest())
    }
}

/// What the status line says.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StatusLine {
    /// The text.
    pub text: String,
    /// How it ended.
    pub kind: StatusKind,
}

/// The kind of status line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StatusKind {
    /// A command was sent; its outcome is awaited.
    Pending,
    /// It worked.
    Ok,
    /// It was refused or failed.
    Error,
}

/// A key command.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Action {
    /// Home (limb: home pose; actarray: every joint).
    Home,
    /// Stop (limb: stop; actarray: speed 0 for every joint; gripper: stop).
    Stop,
    /// Open the gripper.
    Open,
    /// Close the gripper.
    Close,
}

impl Action {
    fn name(self) -> &'static str {
        match self {
            Action::Home => "home",
            Action::Stop => "stop",
            Action::Open => "open",
            Action::Close => "close",
        }
    }
}

enum Refusal {
    Command(CommandError),
    Other(String),
}

impl From<CommandError> for Refusal {
    fn from(e: CommandError) -> Self {
        Refusal::Command(e)
    }
}

/// The typed client of a device whose kind was checked.
fn typed<I: Interface>(c: &mut Box<dyn DeviceClient>) -> Result<&mut Client<I>, Refusal> {
    let kind = c.kind();
    c.typed::<I>()
        .ok_or_else(|| Refusal::Other(format!("not {}: {kind}", I::KIND.with_article())))
}

/// Sends the command of `action` to a device.
fn send(conn: &mut Conn, action: Action) -> Result<Ticket, Refusal> {
    let kind = conn.client.kind();
    let joints = conn
        .state::<ActArray>()
        .map(|s| s.actuators().len())
        .filter(|&n| n > 0)
        .or_else(|| conn.geometry::<ActArray>().map(|g| g.actuators().len()))
        .unwrap_or(0);
    let c = &mut conn.client;
    let ticket = match (kind, action) {
        (InterfaceKind::Limb, Action::Home) => typed::<Limb>(c)?.home()?,
        (InterfaceKind::Limb, Action::Stop) => typed::<Limb>(c)?.stop()?,
        (InterfaceKind::ActArray, Action::Home) => typed::<ActArray>(c)?.home(None)?,
        (InterfaceKind::ActArray, Action::Stop) => {
            if joints == 0 {
                return Err(Refusal::Other(
                    "the number of joints is not known yet".to_string(),
                ));
            }
            typed::<ActArray>(c)?.move_at_speed_multi(&vec![0.0; joints])?
        }
        (InterfaceKind::Gripper, Action::Open) => typed::<Gripper>(c)?.open()?,
        (InterfaceKind::Gripper, Action::Close) => typed::<Gripper>(c)?.close()?,
        (InterfaceKind::Gripper, Action::Stop) => typed::<Gripper>(c)?.stop()?,
        _ => {
            return Err(Refusal::Other(format!(
                "not a command of {} (select another device)",
                kind.with_article()
            )));
        }
    };
    Ok(ticket)
}

struct Pending {
    device: DeviceName,
    action: Action,
    ticket: Ticket,
    deadline: Instant,
}

/// The monitor: every device of the domain, live.
pub struct App {
    ctx: Context,
    /// Every device, sorted by name (so grouped by robot).
    pub devices: Vec<Device>,
    /// Every robot with its driver statistics, by name.
    pub robots: BTreeMap<String, Robot>,
    /// The index of the selected device in `devices`.
    pub selected: usize,
    /// The outcome of the last key command.
    pub status: Option<StatusLine>,
    /// Why the last discovery failed, if it did.
    pub discovery_error: Option<String>,
    pending: Option<Pending>,
    last_discovery: Option<Instant>,
    quit: bool,
}

impl App {
    /// A monitor of the domain of `ctx`; discovers and connects at once.
    pub fn new(ctx: Context) -> App {
        let mut app = App {
            ctx,
            devices: Vec::new(),
            robots: BTreeMap::new(),
            selected: 0,
            status: None,
            discovery_error: None,
            pending: None,
            last_discovery: None,
            quit: false,
        };
        app.discover();
        app
    }

    /// The domain's name.
    pub fn domain(&self) -> &str {
        self.ctx.domain().name()
    }

    /// True once q or Esc was pressed.
    pub fn should_quit(&self) -> bool {
        self.quit
    }

    /// Asks the monitor to quit (Ctrl-C).
    pub fn request_quit(&mut self) {
        self.quit = true;
    }

    /// The selected device.
    pub fn selected_device(&self) -> Option<&Device> {
        self.devices.get(self.selected)
    }

    /// One step: rediscovers if due, takes every new state and statistics sample, and
    /// checks the outcome of the pending key command. Never blocks for long.
    pub fn tick(&mut self) {
        if self
            .last_discovery
            .is_none_or(|t| t.elapsed() >= REDISCOVER_EVERY)
        {
            self.discover();
        }
        for d in &mut self.devices {
            if let Ok(c) = &mut d.conn {
                if c.refresh() {
                    d.last_new = Instant::now();
                }
                // The state says whether the device is held; who holds it is a request,
                // asked when it becomes held and once per rediscovery period after.
                let held = c
                    .header()
                    .is_some_and(|h| h.flags & device_flag::LEASED != 0);
                if !held {
                    d.holder = None;
                    d.holder_asked = None;
                } else if d
                    .holder_asked
                    .is_none_or(|t| t.elapsed() >= REDISCOVER_EVERY)
                {
                    d.holder_asked = Some(Instant::now());
                    d.holder = Some(c.holder_name());
                }
            }
        }
        for r in self.robots.values_mut() {
            if let Some(s) = &mut r.stats {
                let _ = s.refresh();
            }
        }
        self.check_pending();
    }

    /// Ticks until every live device has a state and every statistics channel a sample,
    /// or `timeout` passes (for `--once`).
    pub fn settle(&mut self, timeout: Duration) {
        let deadline = Instant::now() + timeout;
        loop {
            self.tick();
            let devices_ready = self.devices.iter().all(|d| {
                !d.alive()
                    || match &d.conn {
                        Ok(c) => c.header().is_some(),
                        Err(_) => true,
                    }
            });
            let stats_ready = self
                .robots
                .values()
                .all(|r| !r.alive || r.stats.is_none() || r.latest().is_some());
            if (devices_ready && stats_ready) || Instant::now() >= deadline {
                return;
            }
            std::thread::sleep(Duration::from_millis(10));
        }
    }

    /// Reads the device list again: connects to new devices, forgets vanished ones (but
    /// those it is connected to, whose driver ended cleanly), reconnects to devices whose
    /// driver came back.
    pub fn discover(&mut self) {
        self.last_discovery = Some(Instant::now());
        let list = match list_devices(self.ctx.domain()) {
            Ok(l) => {
                self.discovery_error = None;
                l
            }
            Err(e) => {
                self.discovery_error = Some(e.to_string());
                return;
            }
        };
        let selected = self.selected_device().map(|d| d.info.name.clone());
        let mut old: BTreeMap<String, Device> = self
            .devices
            .drain(..)
            .map(|d| (d.info.name.to_string(), d))
            .collect();
        for info in list {
            let mut dev = match old.remove(&info.name.to_string()) {
                Some(mut d) => {
                    let revived = info.alive && !d.info.alive;
                    let stale = d.last_new.elapsed() >= STALE_RECONNECT;
                    d.info = info;
                    if d.alive() && (revived || stale || d.conn.is_err()) {
                        d.conn = Conn::connect(&self.ctx, &d.info.name);
                        d.last_new = Instant::now();
                        d.geometry_tries = 0;
                    }
                    d
                }
                None => Device {
                    conn: if info.alive {
                        Conn::connect(&self.ctx, &info.name)
                    } else {
                        Err("its driver is dead".to_string())
                    },
                    info,
                    geometry_tries: 0,
                    last_new: Instant::now(),
                    holder: None,
                    holder_asked: None,
                },
            };
            if dev.alive()
                && dev.geometry_tries < GEOMETRY_TRIES
                && let Ok(c) = &mut dev.conn
                && !c.has_geometry()
            {
                dev.geometry_tries += 1;
                c.ask_geometry();
            }
            self.devices.push(dev);
        }
        // A driver that ended cleanly is not listed any more; the devices this monitor is
        // connected to stay, not alive, with their last values (a driver that comes back
        // is listed again and reconnected above).
        for (_, mut d) in old {
            if d.conn.is_ok() {
                d.info.alive = false;
                self.devices.push(d);
            }
        }
        self.devices.sort_by(|a, b| a.info.name.cmp(&b.info.name));
        self.selected = selected
            .and_then(|n| self.devices.iter().position(|d| d.info.name == n))
            .unwrap_or(self.selected)
            .min(self.devices.len().saturating_sub(1));
        // Robots: one statistics channel each.
        let mut robots: BTreeMap<String, (String, bool)> = BTreeMap::new();
        for d in &self.devices {
            let e = robots
                .entry(d.info.name.robot().to_string())
                .or_insert_with(|| (String::new(), false));
            if !e.0.split(", ").any(|x| x == d.info.driver) {
                if !e.0.is_empty() {
                    e.0.push_str(", ");
                }
                e.0.push_str(&d.info.driver);
            }
            e.1 |= d.info.alive;
        }
        self.robots.retain(|k, _| robots.contains_key(k));
        for (name, (driver, alive)) in robots {
            let r = self.robots.entry(name.clone()).or_insert_with(|| Robot {
                stats: None,
                stats_error: None,
                driver: String::new(),
                alive: false,
            });
            let revived = alive && !r.alive;
            r.driver = driver;
            r.alive = alive;
            if alive && (r.stats.is_none() || revived) {
                match StatsReader::open(&self.ctx, &name) {
                    Ok(s) => {
                        r.stats = Some(s);
                        r.stats_error = None;
                    }
                    Err(e) => r.stats_error = Some(e.to_string()),
                }
            }
        }
    }

    /// A key: ↑/↓ or k/j select a device, h home, s stop, o open, c close, q or Esc quit.
    pub fn handle_key(&mut self, key: KeyCode) {
        match key {
            KeyCode::Char('q') | KeyCode::Esc => self.quit = true,
            KeyCode::Up | KeyCode::Char('k') => self.selected = self.selected.saturating_sub(1),
            KeyCode::Down | KeyCode::Char('j') => {
                self.selected = (self.selected + 1).min(self.devices.len().saturating_sub(1));
            }
            KeyCode::Home => self.selected = 0,
            KeyCode::End => self.selected = self.devices.len().saturating_sub(1),
            KeyCode::Char('h') => self.act(Action::Home),
            KeyCode::Char('s') => self.act(Action::Stop),
            KeyCode::Char('o') => self.act(Action::Open),
            KeyCode::Char('c') => self.act(Action::Close),
            _ => {}
        }
    }

    fn set_status(&mut self, kind: StatusKind, text: String) {
        self.status = Some(StatusLine { text, kind });
    }

    /// Sends the command of `action` to the selected device; its outcome is read by
    /// later ticks.
    pub fn act(&mut self, action: Action) {
        let what = action.name();
        let Some(dev) = self.devices.get_mut(self.selected) else {
            self.set_status(StatusKind::Error, format!("{what}: no device"));
            return;
        };
        let name = dev.info.name.clone();
        if !dev.info.alive {
            self.set_status(
                StatusKind::Error,
                format!("{what} {name}: no driver (it is dead)"),
            );
            return;
        }
        let sent: Result<Ticket, String> = match &mut dev.conn {
            Err(e) => Err(format!("no driver: {e}")),
            Ok(conn) => send(conn, action).map_err(|e| match e {
                Refusal::Command(CommandError::NoDriver) => "no driver".to_string(),
                Refusal::Command(e) => e.to_string(),
                Refusal::Other(e) => e,
            }),
        };
        match sent {
            Ok(ticket) => {
                self.set_status(StatusKind::Pending, format!("{what} {name}: sent…"));
                self.pending = Some(Pending {
                    device: name,
                    action,
                    ticket,
                    deadline: Instant::now() + OUTCOME_TIMEOUT,
                });
            }
            Err(e) => self.set_status(StatusKind::Error, format!("{what} {name}: {e}")),
        }
    }

    /// True while a key command awaits its outcome.
    pub fn is_pending(&self) -> bool {
        self.pending.is_some()
    }

    fn check_pending(&mut self) {
        let Some(p) = &self.pending else { return };
        let (what, name) = (p.action.name(), p.device.clone());
        let Some(conn) = self
            .devices
            .iter_mut()
            .find(|d| d.info.name == p.device)
            .and_then(|d| d.conn.as_mut().ok())
        else {
            self.pending = None;
            self.set_status(StatusKind::Error, format!("{what} {name}: device gone"));
            return;
        };
        let (kind, text) = match conn.poll_outcome(p.ticket) {
            Ok(s) if s.is_carried_out() => (StatusKind::Ok, format!("{what} {name}: {s}")),
            Ok(s) => (StatusKind::Error, format!("{what} {name}: refused: {s}")),
            Err(WaitError::Missed { .. }) => (
                StatusKind::Ok,
                format!("{what} {name}: ok (applied; outcome overwritten by a later command)"),
            ),
            Err(WaitError::Timeout(_)) if Instant::now() < p.deadline => return,
            Err(WaitError::Timeout(_)) => {
                if conn.driver_status() == DriverStatus::Alive {
                    (
                        StatusKind::Error,
                        format!("{what} {name}: no outcome within {OUTCOME_TIMEOUT:?}"),
                    )
                } else {
                    (
                        StatusKind::Error,
                        format!("{what} {name}: no driver (it is gone)"),
                    )
                }
            }
            Err(WaitError::DriverGone) => (
                StatusKind::Error,
                format!("{what} {name}: no driver (it is gone)"),
            ),
            Err(e) => (StatusKind::Error, format!("{what} {name}: {e}")),
        };
        self.pending = None;
        self.set_status(kind, text);
    }
}
