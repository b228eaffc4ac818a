//! `limber monitor`: every device of the domain, live, in the terminal, like Player's
//! playerv: joints against their limits, states coloured, the limb pose, grippers and
//! their beams, the lift, and each driver's liveness and link statistics. Keys command
//! the selected device (h home, s stop, o open, c close).
//!
//! The model (`app.rs`) and the drawing (`ui.rs`) know nothing of the terminal; this
//! file owns it: raw mode and the alternate screen, restored on exit and on panic.
//! `--once`, or a stdout that is not a terminal, prints one frame as text instead.

pub mod app;
pub mod ui;

use std::io::IsTerminal as _;
use std::time::{Duration, Instant};

use clap::Args;
use crossterm::event::{self, Event, KeyCode, KeyEventKind, KeyModifiers};

use crate::out::out;
use crate::{CliError, exit};
use app::App;

/// Arguments of `limber monitor`.
#[derive(Debug, Args)]
pub struct MonitorArgs {
    /// Refresh period of the screen, ms.
    #[arg(long, default_value_t = 100, value_name = "MS")]
    interval_ms: u64,
    /// Print one frame as plain text and exit (what happens anyway when stdout is not a
    /// terminal).
    #[arg(long)]
    once: bool,
    /// Width of the `--once` frame, in columns (default: the terminal's, or 120).
    #[arg(long, value_name = "COLS")]
    width: Option<u16>,
}

/// How long `--once` waits for the first state of every device.
const SETTLE: Duration = Duration::from_millis(1500);

/// Runs `limber monitor`.
pub fn run(args: MonitorArgs) -> Result<(), CliError> {
    let ctx = crate::client_context()?;
    let mut app = App::new(ctx);
    let tty = std::io::stdout().is_terminal();
    if args.once || !tty {
        app.settle(SETTLE);
        let width = args
            .width
            .or_else(|| {
                tty.then(|| crossterm::terminal::size().ok().map(|(w, _)| w))
                    .flatten()
            })
            .unwrap_or(120);
        out!("{}", ui::render_text(&app, width))?;
        return Ok(());
    }
    let interval = Duration::from_millis(args.interval_ms.clamp(10, 10_000));
    let mut terminal = ratatui::try_init()
        .map_err(|e| CliError::new(exit::FAILURE, format!("cannot set up the terminal: {e}")))?;
    let result = interact(&mut terminal, &mut app, interval);
    ratatui::restore();
    result.map_err(|e| CliError::new(exit::FAILURE, format!("terminal: {e}")))
}

/// The interactive loop: tick, draw, wait for a key until the next refresh.
fn interact(
    terminal: &mut ratatui::DefaultTerminal,
    app: &mut App,
    interval: Duration,
) -> std::io::Result<()> {
    loop {
        app.tick();
        terminal.draw(|f| ui::draw(f, app))?;
        // While a key command awaits its outcome, look again sooner.
        let wait = if app.is_pending() {
            interval.min(Duration::from_millis(20))
        } else {
            interval
        };
        let next = Instant::now() + wait;
        loop {
            let left = next.saturating_duration_since(Instant::now());
            if left.is_zero() || !event::poll(left)? {
                break;
            }
            match event::read()? {
                Event::Key(k) if k.kind == KeyEventKind::Press => {
                    if k.modifiers.contains(KeyModifiers::CONTROL)
                        && matches!(k.code, KeyCode::Char('c') | KeyCode::Char('d'))
                    {
                        app.request_quit();
                    } else {
                        app.handle_key(k.code);
                    }
                    if app.should_quit() {
                        return Ok(());
                    }
                    break; // redraw at once
                }
                Event::Resize(..) => break,
                _ => {}
            }
        }
    }
}
