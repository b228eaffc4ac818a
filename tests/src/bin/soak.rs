//! `limber-soak`: the soak run (not in CI; `tests/soak/soak.sh` builds and starts it).
//!
//! For `--minutes` minutes: the Pioneer driver (`limber-test-pioneer`) on an emulated robot,
//! `--clients` client threads (each its own iceoryx2 node, reconnecting every epoch) sending
//! random valid and invalid commands, link faults injected in every epoch (garbage and bad
//! checksums, then silence), and the driver restarted at the end of every epoch (SIGTERM and
//! SIGKILL in turn). Each epoch ends with a barrier (every client's request answered, so the
//! driver has handled its commands) and checks the accounting against the driver's
//! statistics: commands sent = handled + lost to a full queue (counted by the driver),
//! carried out = handled − refused. Prints one line per epoch (resident memory and open descriptors of the driver
//! and of this process, the loop period's percentiles and overruns) and a summary; exits 1
//! on any crash or accounting mismatch.

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use clap::Parser;
use limber_emulator::{Emulator, EmulatorConfig, Faults};
use limber_services::diagnostics::StatsReader;
use limber_services::prelude::*;
use limber_services::{Domain, Role};
use limber_tests::{Proc, pioneer_test_config, start_pioneer};

#[derive(Parser)]
struct Args {
    /// How long to run, minutes.
    #[arg(long, default_value_t = 10.0)]
    minutes: f64,
    /// Client threads (4 to 8).
    #[arg(long, default_value_t = 6, value_parser = clap::value_parser!(u32).range(4..=8))]
    clients: u32,
    /// Length of one epoch (between driver restarts), seconds.
    #[arg(long, default_value_t = 20)]
    epoch_s: u64,
    /// The Pioneer driver binary (default: `limber-test-pioneer` beside this one).
    #[arg(long)]
    driver: Option<PathBuf>,
}

/// xorshift64*: enough randomness for a soak, no dependency.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[derive(Default, Clone, Copy)]
struct ClientCounts {
    /// Commands the client published.
    sent: u64,
    /// Commands the client library refused before sending (bad values).
    refused_locally: u64,
    /// Transport errors while sending.
    send_errors: u64,
    /// The barrier request failed.
    barrier_failed: bool,
}

/// One client for one epoch: random commands until `stop`, then a barrier request.
fn client(domain: Domain, seed: u64, stop: Arc<AtomicBool>) -> ClientCounts {
    let mut n = ClientCounts::default();
    let ctx = match Context::new(&domain, Role::Client, &format!("soak{seed}")) {
        Ok(c) => c,
        Err(e) => {
            eprintln!("client {seed}: cannot join: {e}");
            n.barrier_failed = true;
            return n;
        }
    };
    let mut arm = match ActArrayClient::connect_timeout(
        &ctx,
        "pioneer/actarray/0",
        Duration::from_secs(10),
    ) {
        Ok(a) => a,
        Err(e) => {
            eprintln!("client {seed}: cannot connect: {e}");
            n.barrier_failed = true;
            return n;
        }
    };
    let mut rng = Rng(seed | 1);
    let _ = arm.power(true);
    while !stop.load(Ordering::Relaxed) {
        let joint = rng.below(8) as usize; // 6 and 7 do not exist
        let pos = match rng.below(20) {
            0 => f64::NAN,
            1 => 10.0, // beyond every limit
            _ => (rng.unit() - 0.5) * 3.0,
        };
        let r = match rng.below(4) {
            0 => arm.move_at_speed(joint, pos),
            1 => arm.home(Some(joint)),
            _ => arm.move_to(joint, pos),
        };
        match r {
            Ok(_) => n.sent += 1,
            Err(CommandError::Transport(e)) => {
                eprintln!("client {seed}: send failed: {e}");
                n.send_errors += 1;
            }
            Err(_) => n.refused_locally += 1,
        }
        std::thread::sleep(Duration::from_millis(1 + rng.below(4)));
    }
    arm.set_request_timeout(Duration::from_secs(5));
    if let Err(e) = arm.geometry() {
        eprintln!("client {seed}: barrier request failed: {e}");
        n.barrier_failed = true;
    }
    n
}

/// Resident memory (kB) and open descriptors of a process.
fn rss_fds(pid: u32) -> (u64, usize) {
    let rss = std::fs::read_to_string(format!("/proc/{pid}/status"))
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmRSS:"))
                .and_then(|l| l.split_whitespace().nth(1)?.parse().ok())
        })
        .unwrap_or(0);
    let fds = std::fs::read_dir(format!("/proc/{pid}/fd")).map_or(0, |d| d.count());
    (rss, fds)
}

fn main() -> std::process::ExitCode {
    let a = Args::parse();
    let driver_bin = a.driver.clone().unwrap_or_else(|| {
        std::env::current_exe()
            .expect("own path")
            .with_file_name("limber-test-pioneer")
    });
    let driver_bin = driver_bin.to_str().expect("a UTF-8 path").to_string();
    let domain = Domain::new(&format!("limber_soak{}", std::process::id())).expect("domain");
    let dir = std::env::temp_dir();
    let cfg = pioneer_test_config(&dir, &format!("limber-soak-{}", std::process::id()), "");
    let emu = Emulator::start_pty(EmulatorConfig::default()).expect("emulator");
    let port = emu.pty_path().expect("pty").display().to_string();
    let end = Instant::now() + Duration::from_secs_f64(a.minutes * 60.0);
    let me = std::process::id();
    let ctx = Context::new(&domain, Role::Client, "soak").expect("join");

    let (mut sent, mut handled, mut refused, mut local, mut crashes, mut mismatches) =
        (0u64, 0u64, 0u64, 0u64, 0u64, 0u64);
    let mut lost = 0u64;
    let (mut p99_max, mut max_max, mut overruns, mut cycles) = (0u64, 0u64, 0u64, 0u64);
    let mut p50s = Vec::new();
    let mut samples: Vec<(u64, u64, usize, u64, usize)> = Vec::new();
    println!(
        "epoch  t_s  sent handled refused local  ovf  p50_us  p99_us  max_us overruns  drv_rss_kB drv_fds  own_rss_kB own_fds"
    );
    let mut epoch = 0u64;
    let t0 = Instant::now();
    while Instant::now() < end {
        epoch += 1;
        let mut driver: Proc = start_pioneer(&driver_bin, domain.name(), &port, &cfg);
        let stop = Arc::new(AtomicBool::new(false));
        let threads: Vec<_> = (0..a.clients)
            .map(|i| {
                let (d, s) = (domain.clone(), stop.clone());
                let seed = epoch * 1000 + u64::from(i) + 1;
                std::thread::spawn(move || client(d, seed, s))
            })
            .collect();
        // Link faults in the middle of the epoch.
        let e = Duration::from_secs(a.epoch_s);
        std::thread::sleep(e / 4);
        emu.set_faults(Faults {
            garbage_rate: 0.05,
            bad_checksum_rate: 0.05,
            ..Faults::default()
        });
        std::thread::sleep(e / 4);
        emu.set_faults(Faults {
            silent: true,
            ..Faults::default()
        });
        std::thread::sleep(Duration::from_secs(2));
        emu.set_faults(Faults::default());
        std::thread::sleep((e / 2).saturating_sub(Duration::from_secs(2)));
        stop.store(true, Ordering::Relaxed);
        let counts: Vec<ClientCounts> = threads
            .into_iter()
            .map(|t| t.join().unwrap_or_default())
            .collect();
        let barrier = monotonic_ns();
        let ep_sent: u64 = counts.iter().map(|c| c.sent).sum();
        let ep_local: u64 = counts.iter().map(|c| c.refused_locally).sum();
        if counts.iter().any(|c| c.barrier_failed || c.send_errors > 0) {
            mismatches += 1;
        }
        // The driver's statistics from after the barrier.
        let st = StatsReader::open(&ctx, "pioneer").ok().and_then(|mut r| {
            let deadline = Instant::now() + Duration::from_secs(5);
            while Instant::now() < deadline {
                if let Ok(s) = r.wait(Duration::from_secs(2))
                    && s.header.stamp_ns > barrier
                {
                    return Some(*s);
                }
            }
            None
        });
        let (drss, dfds) = rss_fds(driver.child.id());
        let (orss, ofds) = rss_fds(me);
        if let Ok(Some(status)) = driver.child.try_wait() {
            eprintln!("epoch {epoch}: the driver ended by itself: {status}");
            crashes += 1;
        }
        let Some(st) = st else {
            eprintln!("epoch {epoch}: no statistics from after the barrier");
            mismatches += 1;
            continue;
        };
        if st.commands + st.cmd_overflows != ep_sent {
            eprintln!(
                "epoch {epoch}: MISMATCH sent {ep_sent}, driver handled {} and counted {} lost",
                st.commands, st.cmd_overflows
            );
            mismatches += 1;
        }
        sent += ep_sent;
        handled += st.commands;
        lost += st.cmd_overflows;
        refused += st.refused;
        local += ep_local;
        p99_max = p99_max.max(st.period_p99_ns);
        max_max = max_max.max(st.period_max_ns);
        overruns += st.overruns;
        cycles += st.cycles;
        p50s.push(st.period_p50_ns);
        samples.push((t0.elapsed().as_secs(), drss, dfds, orss, ofds));
        println!(
            "{epoch:>5} {:>4} {ep_sent:>5} {:>7} {:>7} {ep_local:>5} {:>4} {:>7} {:>7} {:>7} {:>8} {drss:>11} {dfds:>7} {orss:>11} {ofds:>7}",
            t0.elapsed().as_secs(),
            st.commands,
            st.refused,
            st.cmd_overflows,
            st.period_p50_ns / 1000,
            st.period_p99_ns / 1000,
            st.period_max_ns / 1000,
            st.overruns
        );
        // Restart: SIGTERM (must end 0) and SIGKILL in turn.
        if epoch % 2 == 1 {
            driver.signal(libc::SIGTERM);
            if driver.wait_timeout(Duration::from_secs(10)) != Some(0) {
                eprintln!("epoch {epoch}: the driver did not end cleanly on SIGTERM");
                crashes += 1;
            }
        } else {
            driver.signal(libc::SIGKILL);
            let _ = driver.wait_timeout(Duration::from_secs(10));
        }
    }
    p50s.sort_unstable();
    let first = samples.first().copied().unwrap_or_default();
    let last = samples.last().copied().unwrap_or_default();
    println!(
        "--- summary: {epoch} epochs, {:.1} min, {} clients",
        t0.elapsed().as_secs_f64() / 60.0,
        a.clients
    );
    println!("crashes {crashes}, accounting mismatches {mismatches}");
    println!(
        "commands sent {sent} = handled {handled} (carried out {}, refused by the driver {refused}) + lost to a full queue and counted {lost}; refused by the client library before sending {local}",
        handled - refused.min(handled)
    );
    println!(
        "loop period: median of epoch medians {} us, worst epoch p99 {} us, worst max {} us, overruns {overruns} of {cycles} cycles",
        p50s.get(p50s.len() / 2).copied().unwrap_or(0) / 1000,
        p99_max / 1000,
        max_max / 1000
    );
    println!(
        "driver (per epoch, restarted): rss {} -> {} kB, fds {} -> {}; soak process: rss {} -> {} kB, fds {} -> {}",
        first.1, last.1, first.2, last.2, first.3, last.3, first.4, last.4
    );
    let _ = std::fs::remove_file(&cfg);
    // The domain's leftovers: iceoryx2's node counter and limber's token (docs/guide/security.md).
    drop(ctx);
    if let Ok(prefix) = domain.prefix() {
        for e in std::fs::read_dir("/dev/shm")
            .into_iter()
            .flatten()
            .flatten()
        {
            let n = e.file_name();
            let n = n.to_string_lossy();
            if n.starts_with(prefix) && n.ends_with(".global_mgmt") {
                let _ = std::fs::remove_file(e.path());
            }
        }
    }
    let _ = std::fs::remove_file(
        limber_services::domain_dir::runtime_dir().join(format!("{}.token", domain.name())),
    );
    if crashes == 0 && mismatches == 0 && sent == handled + lost {
        std::process::ExitCode::SUCCESS
    } else {
        std::process::ExitCode::FAILURE
    }
}
