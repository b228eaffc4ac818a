//! `lang`: the same two exchanges from a Rust, a C and a Python client, each a process of
//! its own started the same way (the Rust one this executable's `lang-rust` role), one after
//! the other, against one event-driven driver child (`cmd-driver-event`, the `command`
//! scenario's driver with its default linger):
//!
//! * **state read**: the latest arm state (1376 B) from shared memory into the program:
//!   Rust `ActArrayClient::state()` (in place), C `limber_actarray_state` (a copy into the
//!   caller's struct), Python `ActArrayClient.state()` (a copy into a new ctypes struct, by
//!   the package's compiled `limber._fast` where pip built it, else through ctypes). Each takes whatever
//!   arrived first, as a control loop's read does.
//! * **command round trip**: `move_to` then `wait_outcome`, each client with its defaults
//!   (event-driven, the 30 µs spin budget).
//!
//! The C client is `bench/clients/lang_client.c`, compiled here with `cc` against the
//! source tree's headers and the `liblimber.so` beside this executable (or in
//! `LIMBER_LIB_DIR`); the Python client is `bench/clients/lang_client.py`, run by
//! `LIMBER_PYTHON` (default `python3`) with the package as a user installs it: `pip install
//! --target` of the source tree's `python/` into the run's directory, over that same
//! `liblimber.so` (`LIMBER_LIB`), with `limber._fast` where a C compiler and Python's
//! headers are (the report notes which; without pip, the source tree's `python/`;
//! `LIMBER_PY_CTYPES=1` in the environment has it copy through ctypes, to compare).
//! The scenario is pinned whatever `--pin` says (`RunCtx::pin_scenario`): every client on
//! one core, the driver on another, so that the languages compare on one placement, not on
//! where the scheduler put each process; and each client reads `SETTLE_NS` (20 µs) after its
//! round trip, so that every read takes the same messages.
//! Each language that cannot run (no C compiler, no liblimber.so, no Python that imports
//! limber) is skipped with the reason, printed and noted in the report; Rust always runs.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use hdrhistogram::Histogram;
use limber_interfaces::prelude::*;
use limber_services::prelude::*;
use limber_services::{Role, monotonic_ns};

use super::command::{DEVICE, start_event_driver};
use super::floor::BYTES;
use super::{READY_TIMEOUT, RunCtx, SAMPLE_TIMEOUT, Scenario};
use crate::progress::Progress;
use crate::stats::{Measurement, Metric, Strategy, new_histogram};
use crate::{BenchArgs, BenchError, roles};

/// The C client's source.
const C_CLIENT: &str = include_str!("../../clients/lang_client.c");
/// The Python client's source.
const PY_CLIENT: &str = include_str!("../../clients/lang_client.py");
/// The source tree (the headers of capi/ and interfaces/, the python/ package).
const TREE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/..");

/// The `lang` scenario.
#[derive(Debug, Clone, Copy)]
pub struct Lang;

impl Scenario for Lang {
    fn name(&self) -> &'static str {
        "lang"
    }
    fn description(&self) -> &'static str {
        "reading the state and a command round trip from Rust, C (liblimber) and Python (python/limber), event-driven"
    }
    fn run(&self, ctx: &mut RunCtx) -> Result<(), BenchError> {
        if !ctx.blocking_enabled() {
            ctx.notes.push(
                "lang runs the clients' defaults (event-driven); skipped by --strategy spin".into(),
            );
            return Ok(());
        }
        run(ctx)
    }
}

fn err(what: &str, reason: impl std::fmt::Display) -> BenchError {
    BenchError::Transport {
        context: what.to_string(),
        reason: reason.to_string(),
    }
}

/// A language skipped: the reason, printed and kept for the report.
fn skip(ctx: &mut RunCtx, lang: &str, why: String) {
    let note = format!("{lang} skipped: {why}");
    tracing::warn!("lang: {note}");
    ctx.notes.push(note);
}

fn run(ctx: &mut RunCtx) -> Result<(), BenchError> {
    if let Some(note) = ctx.pin_scenario("lang") {
        ctx.notes.push(note);
    }
    let r = run_pinned(ctx);
    ctx.end_scenario_pin();
    r
}

fn run_pinned(ctx: &mut RunCtx) -> Result<(), BenchError> {
    let domain = ctx.domain();
    let (warm, n) = (ctx.count(500, 50), ctx.count(5_000, 300));
    // Three clients, one after the other; Python's exchanges are the slowest.
    let deadline = ctx.deadline_for(3 * (warm + n), Duration::from_micros(500));
    let driver = start_event_driver(ctx, &domain, "lang-driver.hdr", deadline)?;
    let cctx =
        Context::new(&domain, Role::Client, "bench-lang").map_err(|e| err("client context", e))?;
    let mut client = ActArrayClient::connect_timeout(&cctx, DEVICE, READY_TIMEOUT)
        .map_err(|e| err("connect", e))?;
    let r = (|| {
        let out = ctx.tmp_file("lang-Rust.txt");
        let mut rust = crate::child::command()?;
        rust.args(["--role", RUST_ROLE, "--child-domain", domain.name()])
            .arg("--warmup")
            .arg(warm.to_string())
            .arg("--count")
            .arg(n.to_string())
            .arg("--out")
            .arg(&out);
        if let Some(cpu) = ctx.client_cpu() {
            rust.arg("--cpu").arg(cpu.to_string());
        }
        Progress::new(ctx.progress, "lang Rust", warm + n).finish();
        let (state, rtt, _) = samples("Rust", rust, &out, n, deadline)?;
        push(ctx, "rust", "Rust", state, rtt);
        match c_client(ctx) {
            Err(why) => skip(ctx, "C", why),
            Ok(exe) => {
                let (state, rtt, _) =
                    external(ctx, "C", Command::new(exe), &domain, warm, n, deadline)?;
                push(ctx, "c", "C", state, rtt);
            }
        }
        match python(ctx) {
            Err(why) => skip(ctx, "Python", why),
            Ok(cmd) => {
                let (state, rtt, ffi) = external(ctx, "Python", cmd, &domain, warm, n, deadline)?;
                push(ctx, "python", "Python", state, rtt);
                // Python's floor: one ctypes call that does nothing else.
                ctx.push(Measurement {
                    scenario: "lang",
                    id: "lang.python.ffi".into(),
                    label: "Python: one ctypes call into liblimber, no work".into(),
                    strategy: Strategy::Compute,
                    metric: Metric::Read,
                    bytes: None,
                    hist: ffi,
                });
            }
        }
        Ok(())
    })();
    // HOME all joints stops the driver child (if it cannot be sent, its deadline does).
    if let Err(e) = client.home(None) {
        tracing::warn!("cannot tell the driver child to stop: {e}");
    }
    driver.finish(Duration::from_secs(10))?;
    r
}

/// How long every client waits, spinning on the clock, between a command's round trip and
/// the next timed state read (passed to the C and Python clients as their 4th argument).
/// `wait_outcome` returns on the state that shows the command; the driver sends the
/// command's `told` message after it, and the next read takes that message. Read at once,
/// it has come or not as the moment has it (Rust's read 0.18 us without it, 0.35-0.76 us
/// with it, within one run); after the wait it is there for every language, and each read
/// takes the same: the message, and nothing newer.
const SETTLE_NS: u64 = 20_000;

/// The role of the Rust client's process.
pub const RUST_ROLE: &str = "lang-rust";

/// Spins until the monotonic clock reads `until` (ns): [`SETTLE_NS`], Rust's side.
fn settle(until: u64) {
    while monotonic_ns() < until {
        std::hint::spin_loop();
    }
}

/// The Rust client (`lang-rust`, a child process as the C and Python clients are, started
/// the same way: run in this process after other scenarios, its round trip read 1.65 us
/// where the same library through C read 2.9 us, and 2.7-2.9 us in a run of `lang` alone):
/// connects to the scenario's driver in `--child-domain` and writes its samples to `--out`
/// as the other clients do, `--warmup` + `--count` exchanges.
pub fn rust_role(args: &BenchArgs) -> Result<(), BenchError> {
    let domain = roles::child_domain(args)?;
    let out = args
        .out
        .as_ref()
        .ok_or_else(|| BenchError::Args("--out is required for this role".into()))?;
    let cctx =
        Context::new(&domain, Role::Client, "bench-lang").map_err(|e| err("client context", e))?;
    let mut client = ActArrayClient::connect_timeout(&cctx, DEVICE, READY_TIMEOUT)
        .map_err(|e| err("connect", e))?;
    client
        .current(READY_TIMEOUT)
        .map_err(|e| err("first state", e))?;
    let (warm, n) = (args.warmup, args.count);
    let mut lines = String::with_capacity(32 * n as usize);
    let mut settled = 0;
    for i in 1..=warm + n {
        settle(settled);
        let t0 = monotonic_ns();
        let p = client.state().map(|d| d.actuators[0].position);
        let t1 = monotonic_ns();
        std::hint::black_box(p);
        let target = if i % 2 == 0 { 0.25 } else { -0.25 };
        let t2 = monotonic_ns();
        let ticket = client.move_to(0, target).map_err(|e| err("move_to", e))?;
        let status = client
            .wait_outcome(ticket, SAMPLE_TIMEOUT)
            .map_err(|e| err("wait_outcome", e))?;
        let t3 = monotonic_ns();
        settled = t3 + SETTLE_NS;
        if status != Status::Ok {
            return Err(err("command", format!("refused: {status}")));
        }
        if i > warm {
            lines.push_str(&format!("state {}\nrtt {}\n", t1 - t0, t3 - t2));
        }
    }
    std::fs::write(out, lines).map_err(|e| BenchError::io(out.display().to_string(), e))
}

/// Runs `cmd` to its end and returns its output; `Err(why)` when it cannot start or runs
/// longer than `limit` (then it is killed).
pub(crate) fn run_bounded(
    mut cmd: Command,
    limit: Duration,
) -> Result<std::process::Output, String> {
    let mut child = cmd
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .map_err(|e| format!("cannot start {:?}: {e}", cmd.get_program()))?;
    let until = Instant::now() + limit;
    loop {
        match child.try_wait() {
            Ok(Some(_)) => break,
            Ok(None) if Instant::now() < until => std::thread::sleep(Duration::from_millis(5)),
            Ok(None) => {
                if let Err(e) = child.kill() {
                    tracing::warn!("cannot kill {:?}: {e}", cmd.get_program());
                }
                if let Err(e) = child.wait() {
                    tracing::warn!("cannot reap {:?}: {e}", cmd.get_program());
                }
                return Err(format!("{:?} ran longer than {limit:?}", cmd.get_program()));
            }
            Err(e) => return Err(format!("waiting for {:?}: {e}", cmd.get_program())),
        }
    }
    child
        .wait_with_output()
        .map_err(|e| format!("reading {:?}: {e}", cmd.get_program()))
}

/// The directory of `liblimber.so`: `LIMBER_LIB_DIR`, else beside this executable (where
/// `cargo build -p limber-c` puts it), else its `deps/`.
fn lib_dir() -> Result<PathBuf, String> {
    let mut dirs = Vec::new();
    if let Some(d) = std::env::var_os("LIMBER_LIB_DIR") {
        dirs.push(PathBuf::from(d));
    }
    if let Some(d) = std::env::current_exe()
        .ok()
        .and_then(|e| e.parent().map(Path::to_path_buf))
    {
        // Beside the executable first, then its deps/.
        let deps = d.join("deps");
        dirs.push(d);
        dirs.push(deps);
    }
    dirs.iter()
        .find(|d| d.join("liblimber.so").is_file())
        .cloned()
        .ok_or_else(|| {
            format!(
                "no liblimber.so in {dirs:?} (build it with `cargo build --release -p limber-c`, or set LIMBER_LIB_DIR)"
            )
        })
}

/// The C client, compiled; `Err(why)` when it cannot be.
fn c_client(ctx: &RunCtx) -> Result<PathBuf, String> {
    let tree = Path::new(TREE);
    let includes = [tree.join("capi/include"), tree.join("interfaces/include")];
    if let Some(missing) = includes.iter().find(|d| !d.is_dir()) {
        return Err(format!(
            "the headers are not at {} (the source tree)",
            missing.display()
        ));
    }
    let lib = lib_dir()?;
    let cc = std::env::var_os("CC").unwrap_or_else(|| "cc".into());
    let src = ctx.tmp_file("lang_client.c");
    let exe = ctx.tmp_file("lang_client");
    std::fs::write(&src, C_CLIENT).map_err(|e| format!("{}: {e}", src.display()))?;
    let mut cmd = Command::new(&cc);
    cmd.args(["-std=c11", "-O2", "-Wall", "-Werror"]);
    for d in &includes {
        cmd.arg("-I").arg(d);
    }
    cmd.arg(&src)
        .arg("-o")
        .arg(&exe)
        .arg("-L")
        .arg(&lib)
        .arg("-llimber")
        .arg(format!("-Wl,-rpath,{}", lib.display()));
    let o = run_bounded(cmd, Duration::from_secs(60)).map_err(|e| format!("no C compiler: {e}"))?;
    if !o.status.success() {
        return Err(format!(
            "{cc:?} could not compile the C client: {}",
            String::from_utf8_lossy(&o.stderr).trim()
        ));
    }
    Ok(exe)
}

/// The Python client's command; `Err(why)` when there is no liblimber.so or no Python that
/// imports limber. The package is the one a user installs: `pip install --target` of the
/// source tree's `python/` into this run's directory, over that liblimber.so (with
/// `limber._fast` where a C compiler and Python's headers are); where pip cannot install it,
/// the source tree's `python/` (ctypes alone). Which one, and why, is noted in the report.
fn python(ctx: &mut RunCtx) -> Result<Command, String> {
    let py = std::env::var_os("LIMBER_PYTHON").unwrap_or_else(|| "python3".into());
    // The C client's liblimber.so; without one, the package looks for its own (and says
    // where it looked when it finds none).
    let lib = lib_dir().map(|d| d.join("liblimber.so"));
    // Without a liblimber.so to package, pip would build one with cargo (minutes): the
    // source tree's package then, which finds its own.
    let installed = match &lib {
        Ok(lib) => pip_install(ctx, &py, lib),
        Err(why) => Err(format!("no liblimber.so to package: {why}")),
    };
    let path = match installed {
        Ok(dir) => dir,
        Err(why) => {
            ctx.notes.push(format!(
                "Python: the package from the source tree (pip could not install it: {why})"
            ));
            Path::new(TREE).join("python")
        }
    };
    let mut probe = Command::new(&py);
    probe
        .args([
            "-c",
            "import limber._lib as l; print('compiled' if l.COMPILED else 'ctypes')",
        ])
        .env("PYTHONPATH", &path);
    if let Ok(lib) = &lib {
        probe.env("LIMBER_LIB", lib);
    }
    let o = run_bounded(probe, Duration::from_secs(60))?;
    if !o.status.success() {
        return Err(format!(
            "{py:?} cannot import limber (from {}, over {}): {} (set LIMBER_PYTHON to a Python >= 3.9, e.g. the venv of .ci/run, and LIMBER_LIB_DIR to the directory of liblimber.so)",
            path.display(),
            lib.as_ref()
                .map_or_else(|why| why.clone(), |l| l.display().to_string()),
            last_line(&o.stderr, "")
        ));
    }
    let how = String::from_utf8_lossy(&o.stdout).trim().to_string();
    ctx.notes.push(if how == "compiled" {
        "Python: states copied by the package's compiled limber._fast".to_string()
    } else {
        "Python: states copied through ctypes (no limber._fast in the package, or LIMBER_PY_CTYPES=1)"
            .to_string()
    });
    let script = ctx.tmp_file("lang_client.py");
    std::fs::write(&script, PY_CLIENT).map_err(|e| format!("{}: {e}", script.display()))?;
    let mut cmd = Command::new(py);
    cmd.arg(script).env("PYTHONPATH", path);
    if let Ok(lib) = lib {
        cmd.env("LIMBER_LIB", lib);
    }
    Ok(cmd)
}

/// `pip install --target` of the source tree's package into this run's directory, over
/// `lib` (so nothing is compiled but `limber._fast`); the directory, or why not.
fn pip_install(ctx: &RunCtx, py: &std::ffi::OsStr, lib: &Path) -> Result<PathBuf, String> {
    let dir = ctx.tmp_file("python-package");
    let mut cmd = Command::new(py);
    cmd.args([
        "-m",
        "pip",
        "install",
        "--quiet",
        "--disable-pip-version-check",
        "--no-deps",
        "--no-build-isolation",
        "--target",
    ])
    .arg(&dir)
    .arg(Path::new(TREE).join("python"))
    .env("LIMBER_LIB", lib);
    let o = run_bounded(cmd, Duration::from_secs(300))?;
    if !o.status.success() {
        return Err(last_line(&o.stderr, "pip failed"));
    }
    Ok(dir)
}

/// The last line of a program's output (what Python and pip say last: the error), or
/// `none` when it printed nothing.
fn last_line(out: &[u8], none: &str) -> String {
    String::from_utf8_lossy(out)
        .lines()
        .last()
        .unwrap_or(none)
        .trim()
        .to_string()
}

/// An external client's samples: state reads, round trips, single calls into liblimber
/// (Python's; empty from C).
type Samples = (Histogram<u64>, Histogram<u64>, Histogram<u64>);

/// Runs an external client (`cmd WARMUP COUNT OUT SETTLE_NS`) in the scenario's domain and reads its
/// samples: state reads, round trips, and (Python) single calls into liblimber.
fn external(
    ctx: &RunCtx,
    lang: &str,
    mut cmd: Command,
    domain: &limber_services::Domain,
    warm: u64,
    n: u64,
    limit: Duration,
) -> Result<Samples, BenchError> {
    let out = ctx.tmp_file(&format!("lang-{lang}.txt"));
    // The exchanges run in the client's process: announced, not ticked.
    Progress::new(ctx.progress, &format!("lang {lang}"), warm + n).finish();
    cmd.arg(warm.to_string())
        .arg(n.to_string())
        .arg(&out)
        .arg(SETTLE_NS.to_string())
        .env("LIMBER_DOMAIN", domain.name());
    samples(lang, cmd, &out, n, limit)
}

/// Runs a client (`cmd`, its arguments given) to its end and reads the `n` samples it wrote
/// to `out`: state reads, round trips, and (Python) single calls into liblimber.
fn samples(
    lang: &str,
    cmd: Command,
    out: &Path,
    n: u64,
    limit: Duration,
) -> Result<Samples, BenchError> {
    let o = run_bounded(cmd, limit).map_err(|why| BenchError::ChildFailed {
        role: format!("{lang} client"),
        reason: why,
    })?;
    if !o.status.success() {
        return Err(BenchError::ChildFailed {
            role: format!("{lang} client"),
            reason: format!(
                "{}: {}",
                o.status,
                String::from_utf8_lossy(&o.stderr).trim()
            ),
        });
    }
    let text =
        std::fs::read_to_string(out).map_err(|e| BenchError::io(out.display().to_string(), e))?;
    let (mut state, mut rtt, mut ffi) = (new_histogram()?, new_histogram()?, new_histogram()?);
    for line in text.lines() {
        let bad = || BenchError::ChildFailed {
            role: format!("{lang} client"),
            reason: format!("a bad sample line {line:?}"),
        };
        let (kind, ns) = line.split_once(' ').ok_or_else(bad)?;
        let ns: u64 = ns.parse().map_err(|_| bad())?;
        match kind {
            "state" => state.saturating_record(ns),
            "rtt" => rtt.saturating_record(ns),
            "ffi" => ffi.saturating_record(ns),
            _ => return Err(bad()),
        }
    }

    if state.len() != n || rtt.len() != n {
        return Err(BenchError::ChildFailed {
            role: format!("{lang} client"),
            reason: format!("{} and {} samples, not {n}", state.len(), rtt.len()),
        });
    }
    Ok((state, rtt, ffi))
}

fn push(ctx: &mut RunCtx, key: &str, lang: &str, state: Histogram<u64>, rtt: Histogram<u64>) {
    ctx.push(Measurement {
        scenario: "lang",
        id: format!("lang.{key}.state"),
        label: format!("{lang}: read the latest state"),
        strategy: Strategy::Compute,
        metric: Metric::Read,
        bytes: Some((0, BYTES.1)),
        hist: state,
    });
    ctx.push(Measurement {
        scenario: "lang",
        id: format!("lang.{key}.rtt"),
        label: format!("{lang}: command→outcome"),
        strategy: Strategy::Blocking,
        metric: Metric::RoundTrip,
        bytes: Some(BYTES),
        hist: rtt,
    });
}
