//! Every documented command runs as a test (issue 13 item 7), like rustdoc's doctests:
//! each shell command in a fenced `sh` block of README.md, examples/**/README.md,
//! python/README.md, TESTING.md, docs/guide/motions.md and docs/guide/paths-and-grippers.md, and the example of each verb's `--help`, runs as written
//! against the emulated Pioneer or simarm, in a domain of its own, with a bounded time.
//!
//! How a command is run:
//!
//! * `limber ARGS`, `cargo run [--release] --bin limber -- ARGS`, `cargo run -p limber-cli
//!   -- ARGS`: the `limber` under test; `cargo run -p limber-examples --bin NAME -- ARGS`:
//!   that example binary (built beside `limber` by a workspace build; `cargo run` as
//!   written otherwise).
//! * A command naming a `pioneer/...` or `simarm/...` device while no such driver runs in
//!   the block gets one first (`limber pioneer --emulated`, `limber simarm`), as the
//!   README's "in another terminal" says.
//! * `CMD &` runs in the background until `kill %N` (SIGTERM; it must exit 0) or the end
//!   of the block; a driver must print its "ready" line first, `limber bridge expose` its
//!   first "exposed" line, `limber bridge mirror` its first "mirrored" line and `limber
//!   player-gateway` its "listening on" line.
//! * `--domain NAME` names a domain of the block's own (NAME prefixed with the block's
//!   unique domain), so that a block may use several domains without meeting others.
//! * `CMD > FILE`: CMD's output must equal FILE (the generated files are up to date).
//! * `limber echo` without `--count` runs until its first sample, then gets Ctrl-C (SIGINT)
//!   and must exit 0.
//! * Anything else must exit 0.
//!
//! A command that cannot run here (a serial device, a release build, the whole CI, a
//! long benchmark, a network install) is marked in the README by an HTML comment right
//! before its block: `<!-- not run by tests: PREFIX | why -->`, PREFIX being the start of
//! the commands it covers (`*`: the whole block). A command neither run nor marked fails
//! the test, and so does a marker that covers no command.

use std::io::{BufRead, BufReader};
use std::os::unix::process::ExitStatusExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use limber_services::Domain;

mod common;
use common::{LIMBER, output, stderr, stdout};

const MARKER: &str = "<!-- not run by tests:";
/// How long a driver may take to say "ready", and a background job to end.
const START_TIMEOUT: Duration = Duration::from_secs(20);

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// A fenced shell block: its file, first line, commands and markers.
#[derive(Debug)]
struct Block {
    file: String,
    line: usize,
    commands: Vec<String>,
    /// (prefix, reason)
    not_run: Vec<(String, String)>,
}

/// The `sh` blocks of a Markdown file, comments stripped, continuation lines joined.
fn blocks(file: &str) -> Vec<Block> {
    let text = std::fs::read_to_string(repo().join(file)).unwrap();
    let mut out = Vec::new();
    let mut markers: Vec<(String, String)> = Vec::new();
    let mut lines = text.lines().enumerate();
    while let Some((i, l)) = lines.next() {
        let t = l.trim();
        if let Some(m) = t.strip_prefix(MARKER) {
            let m = m.trim_end_matches("-->").trim();
            let (prefix, why) = m.split_once('|').unwrap_or((m, ""));
            markers.push((prefix.trim().to_string(), why.trim().to_string()));
            continue;
        }
        if !t.starts_with("```") {
            if !t.is_empty() {
                markers.clear();
            }
            continue;
        }
        let lang = t.trim_start_matches('`');
        let shell = matches!(lang, "sh" | "bash" | "shell" | "console");
        let mut commands = Vec::new();
        let mut pending = String::new();
        for (_, l) in lines.by_ref() {
            if l.trim_start().starts_with("```") {
                break;
            }
            if !shell {
                continue;
            }
            let l = strip_comment(l);
            if let Some(head) = l.strip_suffix('\\') {
                pending.push_str(head);
                pending.push(' ');
                continue;
            }
            pending.push_str(&l);
            let cmd = pending.split_whitespace().collect::<Vec<_>>().join(" ");
            pending.clear();
            if !cmd.is_empty() {
                commands.push(cmd);
            }
        }
        if shell {
            out.push(Block {
                file: file.to_string(),
                line: i + 1,
                commands,
                not_run: std::mem::take(&mut markers),
            });
        }
        markers.clear();
    }
    out
}

/// The line without its shell comment (a `#` at the start or after a blank, outside
/// quotes).
fn strip_comment(l: &str) -> String {
    let mut quote = None;
    let mut prev = ' ';
    for (i, c) in l.char_indices() {
        match (quote, c) {
            (None, '"' | '\'') => quote = Some(c),
            (Some(q), c) if c == q => quote = None,
            (None, '#') if prev.is_whitespace() => return l[..i].trim_end().to_string(),
            _ => {}
        }
        prev = c;
    }
    l.trim_end().to_string()
}

/// How a command maps onto a program of this build.
fn program(words: &[&str]) -> Option<(PathBuf, Vec<String>)> {
    let rest = |from: usize| words[from..].iter().map(|s| s.to_string()).collect();
    if words.first() == Some(&"limber") {
        return Some((PathBuf::from(LIMBER), rest(1)));
    }
    if words.len() > 2 && words[0] == "cargo" && words[1] == "run" {
        let sep = words.iter().position(|w| *w == "--")?;
        let flags = &words[2..sep];
        let bin = flags
            .iter()
            .position(|w| *w == "--bin")
            .and_then(|i| flags.get(i + 1).copied());
        let package = flags
            .iter()
            .position(|w| *w == "-p")
            .and_then(|i| flags.get(i + 1).copied());
        return match (package, bin) {
            (Some("limber-cli") | None, Some("limber") | None) => {
                Some((PathBuf::from(LIMBER), rest(sep + 1)))
            }
            (Some("limber-examples"), Some(name)) => {
                let beside = Path::new(LIMBER).with_file_name(name);
                if beside.exists() {
                    Some((beside, rest(sep + 1)))
                } else {
                    // Not built by this test's build: `cargo run` as written.
                    Some((PathBuf::from("cargo"), rest(1)))
                }
            }
            _ => None,
        };
    }
    None
}

/// The blocks of `files`.
fn documented(files: &[String]) -> Vec<Block> {
    files.iter().flat_map(|f| blocks(f)).collect()
}

/// The READMEs under `examples/`.
fn example_readmes() -> Vec<String> {
    let mut files = vec!["examples/README.md".to_string()];
    for e in std::fs::read_dir(repo().join("examples")).unwrap() {
        let p = e.unwrap().path().join("README.md");
        if p.exists() {
            files.push(p.strip_prefix(repo()).unwrap().display().to_string());
        }
    }
    files.sort();
    files
}

/// The `Example: ...` lines of `limber --help` and of each verb's `--help`.
fn help_examples() -> Vec<String> {
    let top = stdout(&output(Command::new(LIMBER).arg("--help")));
    let verbs: Vec<String> = top
        .lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next().map(str::to_string))
        .filter(|v| v != "help")
        .collect();
    assert!(verbs.len() > 10, "{top}");
    let mut out = Vec::new();
    for v in verbs {
        let help = stdout(&output(Command::new(LIMBER).args([&v, "--help"])));
        for l in help.lines() {
            if let Some(cmd) = l.trim().strip_prefix("Example: ") {
                out.push(cmd.trim().to_string());
            }
        }
    }
    out
}

/// A background job: the process and its output lines.
struct Job {
    child: Child,
    lines: mpsc::Receiver<String>,
    what: String,
}

impl Job {
    fn start(exe: &Path, args: &[String], domain: &str, what: &str) -> Job {
        let mut child = Command::new(exe)
            .args(args)
            .env("LIMBER_DOMAIN", domain)
            .current_dir(repo())
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap_or_else(|e| panic!("{what}: {e}"));
        let (tx, lines) = mpsc::channel();
        for pipe in [
            Box::new(child.stdout.take().unwrap()) as Box<dyn std::io::Read + Send>,
            Box::new(child.stderr.take().unwrap()),
        ] {
            let tx = tx.clone();
            std::thread::spawn(move || {
                for l in BufReader::new(pipe).lines().map_while(Result::ok) {
                    if tx.send(l).is_err() {
                        break;
                    }
                }
            });
        }
        Job {
            child,
            lines,
            what: what.to_string(),
        }
    }

    /// Waits (bounded) for a line satisfying `pred`; the lines seen on failure.
    fn wait_line(&mut self, pred: impl Fn(&str) -> bool, within: Duration) -> Result<(), String> {
        let deadline = Instant::now() + within;
        let mut seen = String::new();
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.lines.recv_timeout(left) {
                Ok(l) if pred(&l) => return Ok(()),
                Ok(l) => {
                    seen.push_str(&l);
                    seen.push('\n');
                }
                Err(_) => return Err(seen),
            }
        }
    }

    /// Sends `sig` and waits (bounded) for the exit status.
    fn end(&mut self, sig: i32) -> Option<ExitStatus> {
        // SAFETY: kill(2) on the pid of a child this test started and has not reaped.
        unsafe { libc::kill(self.child.id() as i32, sig) };
        let deadline = Instant::now() + START_TIMEOUT;
        while Instant::now() < deadline {
            if let Ok(Some(st)) = self.child.try_wait() {
                return Some(st);
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        let _ = self.child.kill();
        let _ = self.child.wait();
        None
    }
}

impl Drop for Job {
    fn drop(&mut self) {
        if let Ok(None) = self.child.try_wait() {
            self.end(libc::SIGTERM);
        }
    }
}

/// The verb of `limber ARGS` and the word after it, past a leading `--domain NAME`.
fn verb(args: &[String]) -> (Option<&str>, Option<&str>) {
    let skip = match args.first().map(String::as_str) {
        Some("--domain") => 2,
        Some(a) if a.starts_with("--domain=") => 1,
        _ => 0,
    };
    (
        args.get(skip).map(String::as_str),
        args.get(skip + 1).map(String::as_str),
    )
}

/// A shell session: a domain of its own and the background jobs.
struct Session {
    /// First: the jobs end before the domains, which then remove their files.
    jobs: Vec<Job>,
    domain: Domain,
    /// The domains of `--domain NAME`.
    named: Vec<Domain>,
    pioneer: bool,
    simarm: bool,
}

impl Session {
    fn new() -> Session {
        Session {
            jobs: Vec::new(),
            domain: Domain::unique_for_test(),
            named: Vec::new(),
            pioneer: false,
            simarm: false,
        }
    }

    fn background(&mut self, exe: &Path, args: &[String], what: &str) -> Result<(), String> {
        let mut job = Job::start(exe, args, self.domain.name(), what);
        let (verb, role) = verb(args);
        if verb == Some("pioneer") || verb == Some("simarm") {
            job.wait_line(|l| l.ends_with("ready"), START_TIMEOUT)
                .map_err(|seen| format!("{what}: no \"ready\" line:\n{seen}"))?;
            self.pioneer |= verb == Some("pioneer");
            self.simarm |= verb == Some("simarm");
        }
        if verb == Some("bridge") {
            let first = match role {
                Some("expose") => "exposed ",
                _ => "mirrored ",
            };
            job.wait_line(|l| l.starts_with(first), START_TIMEOUT)
                .map_err(|seen| format!("{what}: no \"{first}\" line:\n{seen}"))?;
        }
        if verb == Some("player-gateway") {
            job.wait_line(|l| l.contains(" listening on "), START_TIMEOUT)
                .map_err(|seen| format!("{what}: no \"listening on\" line:\n{seen}"))?;
        }
        self.jobs.push(job);
        Ok(())
    }

    /// `--domain NAME` becomes a domain of this session's own.
    fn own_domains(&mut self, args: Vec<String>) -> Vec<String> {
        let mut out = Vec::with_capacity(args.len());
        let mut it = args.into_iter();
        while let Some(a) = it.next() {
            let mut own = |n: &str| {
                let name = format!("{}_{n}", self.domain.name());
                if !self.named.iter().any(|d| d.name() == name) {
                    // A bad name stays as it is: the command reports it.
                    self.named.extend(Domain::for_test(&name).ok());
                }
                name
            };
            // `bridge mirror --from NAME` names a domain too.
            if a == "--domain" || a == "--from" {
                out.push(a);
                if let Some(n) = it.next() {
                    out.push(own(&n));
                }
            } else if let Some(n) = a.strip_prefix("--domain=") {
                let n = own(n);
                out.push(format!("--domain={n}"));
            } else {
                out.push(a);
            }
        }
        out
    }

    /// Starts the driver a command's device needs, if none runs yet.
    fn driver_for(&mut self, cmd: &str) -> Result<(), String> {
        let limber = PathBuf::from(LIMBER);
        if cmd.contains("pioneer/") && !self.pioneer {
            let args = ["pioneer", "--emulated"].map(String::from);
            self.background(&limber, &args, "limber pioneer --emulated")?;
        }
        if cmd.contains("simarm/") && !self.simarm {
            self.background(&limber, &["simarm".to_string()], "limber simarm")?;
        }
        Ok(())
    }

    /// Runs one command as the module docs say.
    fn run(&mut self, cmd: &str) -> Result<(), String> {
        if let Some(n) = cmd.strip_prefix("kill %") {
            let n: usize = n.trim().parse().map_err(|_| format!("{cmd}: bad job"))?;
            let job = self
                .jobs
                .get_mut(n.wrapping_sub(1))
                .ok_or(format!("{cmd}: no such job"))?;
            return match job.end(libc::SIGTERM) {
                Some(st) if st.success() => Ok(()),
                other => Err(format!("{cmd}: {} ended with {other:?}", job.what)),
            };
        }
        let (cmd, to_file) = match cmd.split_once(" > ") {
            Some((c, f)) => (c.trim(), Some(f.trim())),
            None => (cmd, None),
        };
        let (cmd, background) = match cmd.strip_suffix(" &").or(cmd.strip_suffix('&')) {
            Some(c) => (c.trim(), true),
            None => (cmd, false),
        };
        let words: Vec<&str> = cmd.split_whitespace().collect();
        let (exe, args) = program(&words).ok_or(format!("{cmd}: not a command this test runs"))?;
        let args = self.own_domains(args);
        if !(matches!(verb(&args).0, Some("pioneer" | "simarm")) && background) {
            self.driver_for(cmd)?;
        }
        if background {
            return self.background(&exe, &args, cmd);
        }
        if verb(&args).0 == Some("echo") && !args.iter().any(|a| a == "--count") {
            // Runs until Ctrl-C: one sample, then SIGINT; it exits 0 or dies of SIGINT, as
            // a shell's Ctrl-C expects.
            let mut job = Job::start(&exe, &args, self.domain.name(), cmd);
            job.wait_line(|l| l.starts_with('#') || l.starts_with('{'), START_TIMEOUT)
                .map_err(|seen| format!("{cmd}: no sample:\n{seen}"))?;
            return match job.end(libc::SIGINT) {
                Some(st) if st.success() || st.signal() == Some(libc::SIGINT) => Ok(()),
                other => Err(format!("{cmd}: Ctrl-C ended it with {other:?}")),
            };
        }
        let mut c = Command::new(&exe);
        c.args(&args)
            .env("LIMBER_DOMAIN", self.domain.name())
            .current_dir(repo());
        let o = output(&mut c);
        if !o.status.success() {
            return Err(format!(
                "{cmd}: {}\nstdout:\n{}\nstderr:\n{}",
                o.status,
                stdout(&o),
                stderr(&o)
            ));
        }
        if let Some(f) = to_file {
            let want = std::fs::read_to_string(repo().join(f)).map_err(|e| format!("{f}: {e}"))?;
            if stdout(&o) != want {
                return Err(format!(
                    "{cmd}: its output differs from {f} (regenerate it)"
                ));
            }
        }
        Ok(())
    }
}

/// Runs `commands` in one session; the failures, each with its place.
fn run_block(place: &str, commands: &[String]) -> Vec<String> {
    let mut s = Session::new();
    let mut failures = Vec::new();
    for c in commands {
        if let Err(e) = s.run(c) {
            failures.push(format!("{place}: {e}"));
        }
    }
    failures
}

fn covered(not_run: &[(String, String)], cmd: &str) -> bool {
    not_run
        .iter()
        .any(|(p, _)| p == "*" || cmd.starts_with(p.as_str()))
}

/// Runs every block of `files`: the failures and the number of commands run.
fn failures(files: &[String]) -> (Vec<String>, usize) {
    let blocks = documented(files);
    let mut failures = Vec::new();
    let mut ran = 0;
    for b in &blocks {
        let place = format!("{}:{}", b.file, b.line);
        for (p, why) in &b.not_run {
            if why.is_empty() {
                failures.push(format!("{place}: the marker for {p:?} gives no reason"));
            }
            if p != "*" && !b.commands.iter().any(|c| c.starts_with(p.as_str())) {
                failures.push(format!("{place}: the marker {p:?} covers no command"));
            }
        }
        let run: Vec<String> = b
            .commands
            .iter()
            .filter(|c| !covered(&b.not_run, c))
            .cloned()
            .collect();
        ran += run.len();
        failures.extend(run_block(&place, &run));
    }
    (failures, ran)
}

/// Runs every block of `files`, failing on any failure; the number of commands run.
fn check(files: &[String]) -> usize {
    let (failures, ran) = failures(files);
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
    ran
}

#[test]
fn every_command_of_the_readme_runs_or_is_marked() {
    let ran = check(&["README.md".to_string()]);
    assert!(ran >= 10, "only {ran} commands ran");
}

#[test]
fn every_command_of_the_example_readmes_runs_or_is_marked() {
    let files = example_readmes();
    assert!(files.len() >= 3, "{files:?}");
    let ran = check(&files);
    assert!(ran >= 4, "only {ran} commands ran");
}

#[test]
fn every_command_of_the_python_readme_runs_or_is_marked() {
    check(&["python/README.md".to_string()]);
}

#[test]
fn every_command_of_the_motions_guide_runs_or_is_marked() {
    let ran = check(&["docs/guide/motions.md".to_string()]);
    assert!(ran >= 5, "only {ran} commands ran");
}

#[test]
fn every_command_of_the_paths_and_grippers_guide_runs_or_is_marked() {
    let ran = check(&["docs/guide/paths-and-grippers.md".to_string()]);
    assert!(ran >= 5, "only {ran} commands ran");
}

#[test]
fn every_command_of_testing_md_runs_or_is_marked() {
    let ran = check(&["TESTING.md".to_string()]);
    assert!(ran >= 1, "only {ran} commands ran");
}

#[test]
fn every_help_example_runs() {
    let examples = help_examples();
    assert!(examples.len() >= 3, "{examples:?}");
    let mut failures = Vec::new();
    for e in &examples {
        failures.extend(run_block("--help", std::slice::from_ref(e)));
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

#[test]
fn commands_are_read_as_a_shell_would() {
    assert_eq!(strip_comment("limber list   # every device"), "limber list");
    assert_eq!(strip_comment("# a comment"), "");
    assert_eq!(strip_comment("echo 'a # b'"), "echo 'a # b'");
    assert_eq!(strip_comment("kill %1"), "kill %1");
    let (exe, args) =
        program(&["cargo", "run", "--release", "--bin", "limber", "--", "demo"]).unwrap();
    assert_eq!(
        (exe.to_str().unwrap(), args),
        (LIMBER, vec!["demo".to_string()])
    );
    let (exe, _) = program(&["cargo", "run", "-p", "limber-cli", "--", "layout"]).unwrap();
    assert_eq!(exe.to_str().unwrap(), LIMBER);
    assert!(program(&["bash", ".ci/run"]).is_none());
    assert!(program(&["cargo", "build", "--release"]).is_none());
}

#[test]
fn a_command_neither_run_nor_marked_fails_and_so_does_a_stale_marker() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    let write = |name: &str, text: &str| {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p.display().to_string()
    };
    let unmarked = write("unmarked.md", "```sh\nbash .ci/run\n```\n");
    let (f, _) = failures(&[unmarked]);
    assert!(
        f.len() == 1 && f[0].contains("not a command this test runs"),
        "{f:?}"
    );
    let failing = write("failing.md", "```sh\nlimber layout --bogus\n```\n");
    let (f, _) = failures(&[failing]);
    assert!(f.len() == 1 && f[0].contains("--bogus"), "{f:?}");
    let stale = write(
        "stale.md",
        "<!-- not run by tests: cargo build | slow -->\n```sh\nlimber layout\n```\n",
    );
    let (f, ran) = failures(&[stale]);
    assert!(f.len() == 1 && f[0].contains("covers no command"), "{f:?}");
    assert_eq!(ran, 1);
    let marked = write(
        "marked.md",
        "<!-- not run by tests: bash .ci/run | every test -->\n```sh\nbash .ci/run\n```\n",
    );
    assert_eq!(failures(&[marked]), (vec![], 0));
}
