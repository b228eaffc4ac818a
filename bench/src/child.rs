//! Child processes of the scenarios: this benchmark's own executable re-executed with the
//! hidden `--role` argument.
//!
//! Which executable: `$LIMBER_BENCH_EXE` if set; else the current executable, directly if
//! it is `limber-bench*`, otherwise (the `limber` CLI) as `<exe> bench --role ...`.
//!
//! Protocol: the child prints `ready` on stdout once its ports exist, `error: <why>` if
//! it fails, and exits 0 when done. The parent may send lines on the child's stdin (`go`,
//! `quit`). Every wait has a timeout; a child still running when its [`ChildProc`] is
//! dropped, or after its deadline, is killed (by its pid) and reaped.

use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc::{Receiver, RecvTimeoutError, channel};
use std::time::{Duration, Instant};

use crate::BenchError;

/// What a child is asked to do.
#[derive(Debug, Clone, Default)]
pub struct ChildSpec {
    /// The role (see [`crate::roles`]).
    pub role: String,
    /// The domain name.
    pub domain: Option<String>,
    /// Where the child writes its histogram.
    pub out: Option<PathBuf>,
    /// A socket address to connect to.
    pub addr: Option<String>,
    /// A file to map shared (the physical floor's page).
    pub shm: Option<PathBuf>,
    /// How long an event-driven driver child keeps polling after activity.
    pub linger: Option<Duration>,
    /// The device a driver child offers (default `bench/actarray/0`).
    pub device: Option<String>,
    /// The core to pin to.
    pub cpu: Option<usize>,
    /// The core a Pioneer driver child pins its emulator thread to.
    pub emulator_cpu: Option<usize>,
    /// Samples to discard before recording.
    pub warmup: u64,
    /// Samples to produce.
    pub count: u64,
    /// The child's own deadline; the parent kills it a little later.
    pub deadline: Duration,
}

/// A running child.
#[derive(Debug)]
pub struct ChildProc {
    role: String,
    child: Child,
    stdin: Option<ChildStdin>,
    lines: Receiver<String>,
    kill_at: Instant,
}

/// A command that runs this executable's bench (`limber bench` or `limber-bench`), for a
/// child role.
pub(crate) fn command() -> Result<Command, BenchError> {
    if let Some(p) = std::env::var_os("LIMBER_BENCH_EXE") {
        return Ok(Command::new(p));
    }
    let exe = std::env::current_exe().map_err(|e| BenchError::io("current_exe", e))?;
    let direct = exe
        .file_name()
        .map(|n| n.to_string_lossy().starts_with("limber-bench"))
        .unwrap_or(false);
    let mut c = Command::new(&exe);
    if !direct {
        c.arg("bench");
    }
    Ok(c)
}

impl ChildProc {
    /// Starts a child.
    pub fn spawn(spec: &ChildSpec) -> Result<Self, BenchError> {
        let mut c = command()?;
        c.arg("--role").arg(&spec.role);
        if let Some(d) = &spec.domain {
            c.arg("--child-domain").arg(d);
        }
        if let Some(o) = &spec.out {
            c.arg("--out").arg(o);
        }
        if let Some(a) = &spec.addr {
            c.arg("--addr").arg(a);
        }
        if let Some(p) = &spec.shm {
            c.arg("--shm").arg(p);
        }
        if let Some(d) = &spec.device {
            c.arg("--device").arg(d);
        }
        if let Some(l) = spec.linger {
            c.arg("--linger-us").arg(l.as_micros().to_string());
        }
        if let Some(cpu) = spec.cpu {
            c.arg("--cpu").arg(cpu.to_string());
        }
        if let Some(cpu) = spec.emulator_cpu {
            c.arg("--emulator-cpu").arg(cpu.to_string());
        }
        c.arg("--warmup").arg(spec.warmup.to_string());
        c.arg("--count").arg(spec.count.to_string());
        c.arg("--deadline-ms")
            .arg(spec.deadline.as_millis().to_string());
        Self::start(&spec.role, c, spec.deadline)
    }

    /// Starts another program, `cmd` as given, as a child called `role`: its stdout lines
    /// are read as a role's are ([`ChildProc::expect`]), and it is killed `deadline` (and
    /// a little) after its start if still running.
    pub fn spawn_program(role: &str, cmd: Command, deadline: Duration) -> Result<Self, BenchError> {
        Self::start(role, cmd, deadline)
    }

    fn start(role: &str, mut c: Command, deadline: Duration) -> Result<Self, BenchError> {
        c.stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit());
        let mut child = c.spawn().map_err(|source| BenchError::Spawn {
            role: role.to_string(),
            source,
        })?;
        let stdout = child.stdout.take();
        let stdin = child.stdin.take();
        let (tx, rx) = channel();
        if let Some(out) = stdout {
            std::thread::spawn(move || {
                for line in BufReader::new(out).lines() {
                    match line {
                        Ok(l) => {
                            if tx.send(l).is_err() {
                                break;
                            }
                        }
                        Err(_) => break,
                    }
                }
            });
        }
        Ok(ChildProc {
            role: role.to_string(),
            child,
            stdin,
            lines: rx,
            kill_at: Instant::now() + deadline + Duration::from_secs(5),
        })
    }

    /// The child's process id (to read its CPU time).
    pub fn pid(&self) -> u32 {
        self.child.id()
    }

    /// The role.
    pub fn role(&self) -> &str {
        &self.role
    }

    /// Waits until the child prints `word` (other lines are ignored; `error: ...` fails).
    pub fn expect(&mut self, word: &str, timeout: Duration) -> Result<(), BenchError> {
        let deadline = Instant::now() + timeout;
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.lines.recv_timeout(left) {
                Ok(l) if l.trim() == word => return Ok(()),
                Ok(l) if l.starts_with("error:") => {
                    return Err(BenchError::ChildFailed {
                        role: self.role.clone(),
                        reason: l.trim_start_matches("error:").trim().to_string(),
                    });
                }
                Ok(_) => {}
                Err(RecvTimeoutError::Timeout) => {
                    self.kill();
                    return Err(BenchError::ChildTimeout {
                        role: self.role.clone(),
                        what: format!("no `{word}` within {timeout:?}"),
                    });
                }
                Err(RecvTimeoutError::Disconnected) => {
                    let status = self.child.wait().ok();
                    return Err(BenchError::ChildFailed {
                        role: self.role.clone(),
                        reason: format!("exited before `{word}` ({status:?})"),
                    });
                }
            }
        }
    }

    /// Sends one line on the child's stdin.
    pub fn send_line(&mut self, line: &str) -> Result<(), BenchError> {
        let role = self.role.clone();
        match self.stdin.as_mut() {
            Some(s) => {
                writeln!(s, "{line}").map_err(|e| BenchError::io(format!("stdin of {role}"), e))?;
                s.flush()
                    .map_err(|e| BenchError::io(format!("stdin of {role}"), e))
            }
            None => Err(BenchError::ChildFailed {
                role,
                reason: "stdin closed".into(),
            }),
        }
    }

    /// Whether the child has exited.
    pub fn exited(&mut self) -> bool {
        matches!(self.child.try_wait(), Ok(Some(_)))
    }

    /// Waits up to `timeout` (and never past the child's deadline) for the child to exit
    /// successfully; kills it otherwise.
    pub fn finish(mut self, timeout: Duration) -> Result<(), BenchError> {
        let deadline = (Instant::now() + timeout).min(self.kill_at);
        loop {
            match self.child.try_wait() {
                Ok(Some(st)) if st.success() => return Ok(()),
                Ok(Some(st)) => {
                    let mut reason = format!("exit status {st}");
                    while let Ok(l) = self.lines.try_recv() {
                        if l.starts_with("error:") {
                            reason = l.trim_start_matches("error:").trim().to_string();
                        }
                    }
                    return Err(BenchError::ChildFailed {
                        role: self.role.clone(),
                        reason,
                    });
                }
                Ok(None) if Instant::now() < deadline => {
                    std::thread::sleep(Duration::from_millis(2));
                }
                Ok(None) => {
                    self.kill();
                    return Err(BenchError::ChildTimeout {
                        role: self.role.clone(),
                        what: "did not exit in time".into(),
                    });
                }
                Err(e) => return Err(BenchError::io(format!("waiting for {}", self.role), e)),
            }
        }
    }

    /// Asks the child to end (SIGTERM, by its pid), then [`ChildProc::finish`]es it.
    pub fn terminate(mut self, timeout: Duration) -> Result<(), BenchError> {
        if let Ok(None) = self.child.try_wait() {
            let pid = i32::try_from(self.child.id())
                .ok()
                .and_then(rustix::process::Pid::from_raw);
            match pid {
                Some(pid) => {
                    if let Err(e) =
                        rustix::process::kill_process(pid, rustix::process::Signal::TERM)
                    {
                        tracing::warn!("cannot ask {} to end: {e}", self.role);
                    }
                }
                None => tracing::warn!("{} has no valid pid", self.role),
            }
        }
        self.finish(timeout)
    }

    fn kill(&mut self) {
        if let Ok(None) = self.child.try_wait()
            && let Err(e) = self.child.kill()
        {
            tracing::warn!("cannot kill a benchmark child: {e}");
        }
        if let Err(e) = self.child.wait() {
            tracing::warn!("cannot reap a benchmark child: {e}");
        }
    }
}

impl Drop for ChildProc {
    fn drop(&mut self) {
        self.stdin.take();
        self.kill();
    }
}

/// Reads a histogram a child wrote to `path`.
pub fn read_histogram(path: &Path) -> Result<hdrhistogram::Histogram<u64>, BenchError> {
    let bytes = std::fs::read(path).map_err(|e| BenchError::io(path.display().to_string(), e))?;
    crate::stats::deserialize(&bytes)
}
