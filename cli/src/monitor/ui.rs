//! The monitor's drawing: `draw(frame, app)` renders an [`App`] into any ratatui frame
//! (a terminal, or a `TestBackend` for `--once` and the tests).
//!
//! One panel per driver (its statistics) followed by one panel per device of its robot:
//! joints as bars between their limits, states coloured (idle green, moving yellow,
//! stalled red, braked blue), the limb pose (with a running path and how far it got, or
//! where a path was refused), the gripper and its beams. Dead drivers are
//! greyed and marked DEAD.

use std::fmt::Write as _;

use limber_interfaces::diagnostics::{DriverStats, get_text, hardware, loop_mode};
use limber_services::prelude::*;
use ratatui::Frame;
use ratatui::Terminal;
use ratatui::backend::TestBackend;
use ratatui::buffer::Buffer;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Paragraph};

use super::app::{App, Device, Robot, StatusKind};

const DEAD: Color = Color::DarkGray;
const KEYS: &str = "↑↓ select  h home  s stop  o open  c close  q quit";

/// What one panel shows.
enum PanelKind<'a> {
    Driver(&'a str, &'a Robot),
    Device(usize, &'a Device),
}

struct Panel<'a> {
    kind: PanelKind<'a>,
    height: u16,
}

fn device_lines(d: &Device) -> u16 {
    let Ok(c) = &d.conn else {
        return 1;
    };
    if c.client.kind() == InterfaceKind::ActArray {
        let n = c
            .state::<ActArray>()
            .map(|s| s.actuators().len())
            .filter(|&n| n > 0)
            .or_else(|| c.geometry::<ActArray>().map(|g| g.actuators().len()))
            .unwrap_or(0);
        1 + n.max(1) as u16
    } else if c.client.kind() == InterfaceKind::Limb {
        3
    } else {
        // A gripper, and any interface without a panel of its own: one line.
        1
    }
}

fn panels(app: &App) -> Vec<Panel<'_>> {
    let mut out = Vec::new();
    for (name, robot) in &app.robots {
        let lines = if robot.latest().is_some() { 6 } else { 1 };
        out.push(Panel {
            kind: PanelKind::Driver(name, robot),
            height: lines + 2,
        });
        for (i, d) in app.devices.iter().enumerate() {
            if d.info.name.robot() == name {
                out.push(Panel {
                    kind: PanelKind::Device(i, d),
                    height: device_lines(d) + 2,
                });
            }
        }
    }
    out
}

/// The height that shows every panel of `app` at once (for `--once`).
pub fn full_height(app: &App) -> u16 {
    let body: u16 = panels(app).iter().map(|p| p.height).sum();
    (body + 2).max(4)
}

/// Draws the whole monitor.
pub fn draw(frame: &mut Frame, app: &App) {
    let [top, body, bottom] = Layout::vertical([
        Constraint::Length(1),
        Constraint::Min(0),
        Constraint::Length(1),
    ])
    .areas(frame.area());
    let alive = app.devices.iter().filter(|d| d.alive()).count();
    let title = Line::from(vec![
        Span::styled(
            " limber monitor ",
            Style::new().add_modifier(Modifier::BOLD | Modifier::REVERSED),
        ),
        Span::raw(format!(
            " domain {} · {} devices, {} alive",
            app.domain(),
            app.devices.len(),
            alive
        )),
    ]);
    // The keys at the right of the top line, when there is room.
    let keys_w = KEYS.chars().count() as u16 + 1;
    if top.width >= title.width() as u16 + keys_w + 2 {
        let [left, right] =
            Layout::horizontal([Constraint::Min(0), Constraint::Length(keys_w)]).areas(top);
        frame.render_widget(Paragraph::new(title), left);
        frame.render_widget(
            Paragraph::new(Span::styled(KEYS, Style::new().fg(Color::Cyan))),
            right,
        );
    } else {
        frame.render_widget(Paragraph::new(title), top);
    }

    let panels = panels(app);
    if panels.is_empty() {
        let text = match &app.discovery_error {
            Some(e) => format!("cannot list the devices: {e}"),
            None => format!(
                "no devices in domain {} (start a driver, e.g. `limber pioneer --emulated`, or check --domain / LIMBER_DOMAIN)",
                app.domain()
            ),
        };
        frame.render_widget(Paragraph::new(text), body);
    } else {
        // Scroll so that the selected device (and its driver panel if possible) shows.
        let sel = panels
            .iter()
            .position(|p| matches!(p.kind, PanelKind::Device(i, _) if i == app.selected))
            .unwrap_or(0);
        let mut first = 0;
        while first < sel && panels[first..=sel].iter().map(|p| p.height).sum::<u16>() > body.height
        {
            first += 1;
        }
        let mut y = body.y;
        for p in &panels[first..] {
            if y >= body.bottom() {
                break;
            }
            let h = p.height.min(body.bottom() - y);
            let area = Rect::new(body.x, y, body.width, h);
            match p.kind {
                PanelKind::Driver(name, robot) => draw_driver(frame, area, name, robot),
                PanelKind::Device(i, d) => draw_device(frame, area, d, i == app.selected),
            }
            y += h;
        }
    }

    let status = match &app.status {
        None => Line::from(Span::styled(
            " keys: ↑↓/jk select · h home · s stop · o open · c close · q quit",
            Style::new().fg(Color::DarkGray),
        )),
        Some(s) => {
            let style = match s.kind {
                StatusKind::Ok => Style::new().fg(Color::Green),
                StatusKind::Error => Style::new().fg(Color::Red),
                StatusKind::Pending => Style::new().fg(Color::Yellow),
            };
            Line::from(vec![
                Span::raw(" last: "),
                Span::styled(s.text.clone(), style),
            ])
        }
    };
    frame.render_widget(Paragraph::new(status), bottom);
}

fn text(field: &[u8; 32]) -> &str {
    get_text(field).unwrap_or("?")
}

/// 1.5 ms, 12.0 µs, 850 ns.
pub fn fmt_ns(ns: u64) -> String {
    if ns >= 1_000_000 {
        format!("{:.2} ms", ns as f64 / 1e6)
    } else if ns >= 1_000 {
        format!("{:.1} µs", ns as f64 / 1e3)
    } else {
        format!("{ns} ns")
    }
}

/// 1.2 MB, 3.4 kB, 12 B.
pub fn fmt_bytes(b: u64) -> String {
    if b >= 1_000_000 {
        format!("{:.1} MB", b as f64 / 1e6)
    } else if b >= 1_000 {
        format!("{:.1} kB", b as f64 / 1e3)
    } else {
        format!("{b} B")
    }
}

fn liveness(alive: bool) -> Span<'static> {
    if alive {
        Span::styled("ALIVE", Style::new().fg(Color::Green))
    } else {
        Span::styled(
            "DEAD",
            Style::new()
                .fg(Color::Red)
                .add_modifier(Modifier::BOLD | Modifier::CROSSED_OUT),
        )
    }
}

fn draw_driver(frame: &mut Frame, area: Rect, robot_name: &str, r: &Robot) {
    let mut title = vec![
        Span::raw(format!(" driver {robot_name} · {} · ", r.driver)),
        liveness(r.alive),
        Span::raw(" "),
    ];
    let mut lines = Vec::new();
    match r.latest() {
        Some(s) => {
            let link = s.header.flags & device_flag::LINK_UP != 0;
            title.insert(2, Span::raw(" · link "));
            title.insert(
                3,
                if link {
                    Span::styled("UP", Style::new().fg(Color::Green))
                } else {
                    Span::styled("DOWN", Style::new().fg(Color::Red))
                },
            );
            lines.extend(stats_lines(s));
        }
        None => lines.push(Line::from(format!(
            "no driver statistics{}",
            r.stats_error
                .as_ref()
                .map(|e| format!(" ({e})"))
                .unwrap_or_default()
        ))),
    }
    let mut block = Block::bordered().title(Line::from(title));
    if !r.alive {
        block = block
            .border_style(Style::new().fg(DEAD))
            .title_style(Style::new().fg(DEAD));
    }
    frame.render_widget(Paragraph::new(grey_if(lines, !r.alive)).block(block), area);
}

fn stats_lines(s: &DriverStats) -> Vec<Line<'static>> {
    let mut hw = Vec::new();
    for (bit, name) in [
        (hardware::ARM, "arm"),
        (hardware::GRIPPER, "gripper"),
        (hardware::LIFT, "lift"),
    ] {
        if s.hardware & bit != 0 {
            hw.push(name);
        }
    }
    let mode = match s.loop_mode {
        loop_mode::EVENT => "event",
        loop_mode::SPIN => "spin",
        _ => "?",
    };
    let warn = |n: u64| {
        if n > 0 {
            Style::new().fg(Color::Yellow)
        } else {
            Style::new()
        }
    };
    // Six short lines (at most ~78 columns): readable in an 80-column terminal.
    vec![
        Line::from(format!(
            "robot {} ({} {}) · hw: {} · {mode} loop",
            text(&s.robot_name),
            text(&s.robot_class),
            text(&s.robot_subclass),
            if hw.is_empty() {
                "none".to_string()
            } else {
                hw.join(" ")
            },
        )),
        Line::from(format!(
            "period p50 {} p99 {} max {} · jitter p99 {}",
            fmt_ns(s.period_p50_ns),
            fmt_ns(s.period_p99_ns),
            fmt_ns(s.period_max_ns),
            fmt_ns(s.jitter_p99_ns),
        )),
        Line::from(vec![
            Span::raw(format!("cycles {} · ", s.cycles)),
            Span::styled(format!("overruns {}", s.overruns), warn(s.overruns)),
            Span::raw(format!(
                " · cmd→wire p50 {} p99 {} max {}",
                fmt_ns(s.cmd_to_wire_p50_ns),
                fmt_ns(s.cmd_to_wire_p99_ns),
                fmt_ns(s.cmd_to_wire_max_ns),
            )),
        ]),
        Line::from(format!(
            "link in {} ({} packets) · out {} · SIPs {:.1}/s",
            fmt_bytes(s.bytes_in),
            s.packets_in,
            fmt_bytes(s.bytes_out),
            s.sips_per_s,
        )),
        Line::from(vec![
            Span::styled(
                format!("bad checksums {}", s.bad_checksums),
                warn(s.bad_checksums),
            ),
            Span::raw(" · "),
            Span::styled(
                format!("resync {}", fmt_bytes(s.resync_bytes)),
                warn(s.resync_bytes),
            ),
            Span::raw(" · "),
            Span::styled(format!("reconnects {}", s.reconnects), warn(s.reconnects)),
            Span::raw(" · "),
            Span::styled(
                format!("link faults {}", s.link_faults),
                warn(s.link_faults),
            ),
        ]),
        Line::from(vec![
            Span::raw(format!("commands {} · ", s.commands)),
            Span::styled(format!("refused {}", s.refused), warn(s.refused)),
            Span::raw(format!(" · requests {} · ", s.requests)),
            Span::styled(
                format!("command overflows {}", s.cmd_overflows),
                warn(s.cmd_overflows),
            ),
        ]),
    ]
}

fn header_spans(h: &StateHeader, age: Option<std::time::Duration>) -> Vec<Span<'static>> {
    let mut out = vec![Span::raw(format!(" · #{}", h.seq))];
    if let Some(a) = age {
        // Fixed width, so that the title does not jitter.
        out.push(Span::raw(format!(
            " · age {:5.1} ms",
            a.as_secs_f64() * 1e3
        )));
    }
    if h.flags & device_flag::ABSENT != 0 {
        out.push(Span::styled(" · ABSENT", Style::new().fg(Color::Red)));
    } else if h.flags != 0 && h.flags & device_flag::LINK_UP == 0 {
        out.push(Span::styled(" · LINK DOWN", Style::new().fg(Color::Red)));
    }
    if h.flags & device_flag::SIMULATED != 0 {
        out.push(Span::raw(" · simulated"));
    }
    out
}

fn draw_device(frame: &mut Frame, area: Rect, d: &Device, selected: bool) {
    let name = d.info.name.to_string();
    let iface = d.info.interface();
    let mut title = vec![
        Span::styled(
            format!("{}{name} ", if selected { " ▶ " } else { " " }),
            Style::new().add_modifier(Modifier::BOLD),
        ),
        Span::raw(format!("· {iface} · {} · ", d.info.driver)),
        liveness(d.alive()),
    ];
    if let Ok(c) = &d.conn
        && let Some(h) = c.header()
    {
        title.extend(header_spans(
            h,
            if d.alive() { c.state_age() } else { None },
        ));
        if c.client.kind() == InterfaceKind::ActArray && is_lift(c.geometry::<ActArray>()) {
            title.push(Span::raw(" · lift"));
        }
        if let Some(holder) = &d.holder {
            title.push(Span::styled(
                format!(" · held by {holder}"),
                Style::new().fg(Color::Yellow),
            ));
        }
    }
    title.push(Span::raw(" "));
    let inner_width = area.width.saturating_sub(2);
    let lines = match &d.conn {
        Err(e) => vec![Line::from(format!("not connected: {e}"))],
        Ok(c) => match c.client.kind() {
            InterfaceKind::ActArray => {
                actarray_lines(c.state::<ActArray>(), c.geometry::<ActArray>(), inner_width)
            }
            InterfaceKind::Limb => limb_lines(c.state::<Limb>()),
            InterfaceKind::Gripper => gripper_lines(c.state::<Gripper>(), c.geometry::<Gripper>()),
            // Any other interface (a ranger...): its state's one line, until it gets a
            // panel of its own.
            _ => vec![Line::from(
                c.client
                    .describe()
                    .map_or_else(|| "no data yet".to_string(), |d| d.human()),
            )],
        },
    };
    let mut block = Block::bordered().title(Line::from(title));
    if selected {
        block = block.border_style(Style::new().fg(Color::Cyan).add_modifier(Modifier::BOLD));
    }
    if !d.alive() {
        block = block
            .border_style(Style::new().fg(DEAD))
            .title_style(Style::new().fg(DEAD));
    }
    frame.render_widget(
        Paragraph::new(grey_if(lines, !d.alive())).block(block),
        area,
    );
}

/// A dead driver's last values, greyed: every colour replaced.
fn grey_if(mut lines: Vec<Line<'static>>, dead: bool) -> Vec<Line<'static>> {
    if dead {
        for l in &mut lines {
            for s in &mut l.spans {
                s.style = s.style.fg(DEAD);
            }
        }
    }
    lines
}

fn is_lift(geom: Option<&ActArrayGeom>) -> bool {
    geom.is_some_and(|g| {
        g.actuators().len() == 1 && g.actuators()[0].actuator_kind() == Ok(ActuatorKind::Linear)
    })
}

/// The name and colour of an actuator state.
pub fn actuator_state(bits: u32) -> (&'static str, Color) {
    match ActuatorFlags::from_bits(bits) {
        Some(f) if f.contains(ActuatorFlags::STALLED) => ("stalled", Color::Red),
        Some(f) if f.contains(ActuatorFlags::MOVING) => ("moving", Color::Yellow),
        Some(f) if f.contains(ActuatorFlags::BRAKED) => ("braked", Color::Blue),
        Some(f) if f.contains(ActuatorFlags::IDLE) => ("idle", Color::Green),
        Some(_) => ("-", Color::Gray),
        None => ("?", Color::Magenta),
    }
}

fn actarray_lines(
    s: Option<&ActArrayData>,
    geom: Option<&ActArrayGeom>,
    width: u16,
) -> Vec<Line<'static>> {
    let Some(s) = s else {
        return vec![Line::from("no state yet")];
    };
    let lift = is_lift(geom);
    let mut out = vec![Line::from(vec![
        Span::raw("power "),
        if s.motor_state != 0 {
            Span::styled("on", Style::new().fg(Color::Green))
        } else {
            Span::styled("off", Style::new().fg(Color::Yellow))
        },
        Span::raw(format!(
            " · {} {}{}",
            s.actuators().len(),
            if lift { "actuator" } else { "joints" },
            if geom.is_none() {
                " · limits unknown (no geometry)"
            } else {
                ""
            }
        )),
        Span::styled(trajectory_progress(s), Style::new().fg(Color::Cyan)),
    ])];
    // "j0 " + bar + " +0.1234 rad [-3.1416, +3.1416] v +0.000 stalled" ≈ 48 + bar.
    let bar_w = (width as usize).saturating_sub(52).clamp(8, 40);
    for (i, a) in s.actuators().iter().enumerate() {
        let g = geom.and_then(|g| g.actuators().get(i));
        let unit = match g.map(|g| g.actuator_kind()) {
            Some(Ok(ActuatorKind::Linear)) => "m  ",
            _ => "rad",
        };
        let (state, colour) = actuator_state(a.state);
        let label = if lift {
            "lift".to_string()
        } else {
            format!("j{i:<3}")
        };
        let mut spans = vec![Span::raw(format!("{label} "))];
        match g.filter(|g| g.max > g.min) {
            Some(g) => {
                let f = ((a.position - g.min) / (g.max - g.min)).clamp(0.0, 1.0);
                let filled = (f * bar_w as f64).round() as usize;
                spans.push(Span::styled("█".repeat(filled), Style::new().fg(colour)));
                spans.push(Span::styled(
                    "░".repeat(bar_w - filled),
                    Style::new().fg(Color::DarkGray),
                ));
                let mut t = format!(" {:+.4} {unit} [{:+.3}, {:+.3}]", a.position, g.min, g.max);
                if !g.contains(a.position) {
                    t.push('!');
                }
                spans.push(Span::raw(t));
            }
            None => {
                spans.push(Span::styled(
                    "·".repeat(bar_w),
                    Style::new().fg(Color::DarkGray),
                ));
                spans.push(Span::raw(format!(" {:+.4} {unit} [?]", a.position)));
            }
        }
        let mut t = format!(" v {:+.3}", a.speed);
        if a.current >= 0.0 {
            let _ = write!(t, " I {:.2} A", a.current);
        }
        t.push(' ');
        spans.push(Span::raw(t));
        spans.push(Span::styled(
            state,
            Style::new().fg(colour).add_modifier(Modifier::BOLD),
        ));
        out.push(Line::from(spans));
    }
    if s.actuators().is_empty() {
        out.push(Line::from("no actuators"));
    }
    out
}

/// A running joint trajectory's progress (point i/N, the largest error, paused), or how
/// the last one ended; empty before the first.
fn trajectory_progress(s: &ActArrayData) -> String {
    let t = &s.trajectory;
    match t.active {
        1 => format!(
            " · trajectory point {}/{}, max error {:.4}{}",
            t.point.min(t.points),
            t.points,
            t.max_error,
            if t.scale == 0.0 { ", paused" } else { "" }
        ),
        2 => match MotionResult::try_from(t.result) {
            Ok(r) => format!(" · last trajectory: {}", r.name()),
            Err(_) => String::new(),
        },
        _ => String::new(),
    }
}

/// The name and colour of a limb state.
pub fn limb_state(v: u32) -> (&'static str, Color) {
    match LimbState::try_from(v) {
        Ok(LimbState::Idle) => ("idle", Color::Green),
        Ok(LimbState::Braked) => ("braked", Color::Blue),
        Ok(LimbState::Moving) => ("moving", Color::Yellow),
        Ok(LimbState::OutOfReach) => ("out of reach", Color::Red),
        Ok(LimbState::Collision) => ("collision", Color::Red),
        Err(_) => ("?", Color::Magenta),
    }
}

fn v3(v: &Vec3) -> String {
    format!("({:+.4}, {:+.4}, {:+.4})", v.x, v.y, v.z)
}

fn limb_lines(s: Option<&LimbData>) -> Vec<Line<'static>> {
    let Some(s) = s else {
        return vec![Line::from("no state yet")];
    };
    let (state, colour) = limb_state(s.state);
    let name = limber_interfaces::describe::limb_path_name;
    // A running LINE or PTP and how far it got; a path refused before it started and where.
    let path = match (name(s.path_kind), name(s.refused_kind)) {
        (Some(kind), _) => Span::styled(
            format!("  {kind} {:.0}%", s.path_progress * 100.0),
            Style::new().fg(Color::Yellow),
        ),
        (None, Some(kind)) => Span::styled(
            format!(
                "  {kind} refused at {:.0}%, {}",
                s.refused_fraction * 100.0,
                v3(&s.refused_at)
            ),
            Style::new().fg(Color::Red),
        ),
        (None, None) => Span::raw(""),
    };
    vec![
        Line::from(vec![
            Span::styled(
                format!("{state:<12}"),
                Style::new().fg(colour).add_modifier(Modifier::BOLD),
            ),
            Span::raw(format!(" position {} m", v3(&s.position))),
            path,
        ]),
        Line::from(format!("{:<12} approach {}", "", v3(&s.approach))),
        Line::from(format!("{:<12} orientation {}", "", v3(&s.orientation))),
    ]
}

/// The name and colour of a gripper state.
pub fn gripper_state(v: u32) -> (&'static str, Color) {
    match GripperState::try_from(v) {
        Ok(GripperState::Open) => ("open", Color::Green),
        Ok(GripperState::Closed) => ("closed", Color::Blue),
        Ok(GripperState::Moving) => ("moving", Color::Yellow),
        Ok(GripperState::Error) => ("error", Color::Red),
        Err(_) => ("?", Color::Magenta),
    }
}

fn gripper_lines(s: Option<&GripperData>, geom: Option<&GripperGeom>) -> Vec<Line<'static>> {
    let Some(s) = s else {
        return vec![Line::from("no state yet")];
    };
    let (state, colour) = gripper_state(s.state);
    let mut spans = vec![
        Span::styled(
            format!("{state:<8}"),
            Style::new().fg(colour).add_modifier(Modifier::BOLD),
        ),
        Span::raw(" beams "),
    ];
    // Without the geometry, show the bits that are set (at least 2).
    let n = geom
        .map(|g| g.num_beams.min(32))
        .unwrap_or_else(|| (32 - s.beams.leading_zeros()).max(2));
    if n == 0 {
        spans.push(Span::raw("none"));
    }
    for i in 0..n {
        if s.beams & (1 << i) != 0 {
            spans.push(Span::styled("●", Style::new().fg(Color::Yellow)));
        } else {
            spans.push(Span::styled("○", Style::new().fg(Color::DarkGray)));
        }
    }
    spans.push(Span::raw(format!(" ({:#b})", s.beams)));
    match geom {
        Some(g) if g.capacity > 0 => {
            spans.push(Span::raw(format!(" · stored {}/{}", s.stored, g.capacity)));
        }
        _ => spans.push(Span::raw(format!(" · stored {}", s.stored))),
    }
    vec![Line::from(spans)]
}

/// The text of a buffer, one line per row, trailing blanks trimmed.
pub fn buffer_text(buf: &Buffer) -> String {
    let mut out = String::new();
    let w = buf.area.width as usize;
    for row in buf.content().chunks(w.max(1)) {
        let mut line = String::new();
        for c in row {
            line.push_str(c.symbol());
        }
        out.push_str(line.trim_end());
        out.push('\n');
    }
    out
}

/// Renders one frame of `app`, `width` columns wide and as tall as everything needs, as
/// plain text (for `--once`, a non-terminal stdout, and the tests).
pub fn render_text(app: &App, width: u16) -> String {
    let height = full_height(app);
    let mut terminal =
        Terminal::new(TestBackend::new(width.max(40), height)).expect("test backend");
    terminal
        .draw(|f| draw(f, app))
        .expect("drawing into memory");
    buffer_text(terminal.backend().buffer())
}

#[cfg(test)]
mod trajectory_tests {
    use super::*;

    #[test]
    fn a_running_trajectory_shows_its_point_and_error_and_an_ended_one_its_result() {
        let mut s = ActArrayData::default();
        assert_eq!(trajectory_progress(&s), "");
        s.trajectory.active = 1;
        s.trajectory.point = 3;
        s.trajectory.points = 8;
        s.trajectory.max_error = 0.0125;
        s.trajectory.scale = 1.0;
        assert_eq!(
            trajectory_progress(&s),
            " · trajectory point 3/8, max error 0.0125"
        );
        s.trajectory.scale = 0.0;
        assert!(trajectory_progress(&s).ends_with(", paused"));
        s.trajectory.active = 2;
        s.trajectory.result = MotionResult::PathToleranceViolated.code();
        assert_eq!(
            trajectory_progress(&s),
            " · last trajectory: PATH_TOLERANCE_VIOLATED"
        );
    }
}
