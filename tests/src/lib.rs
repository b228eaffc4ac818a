//! Helpers shared by the multi-process integration tests: spawning the test driver and
//! test clients in a domain of their own, and stopping them.

use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// A child process that is killed when dropped.
#[derive(Debug)]
pub struct Proc {
    /// The child.
    pub child: Child,
}

impl Proc {
    /// Spawns `exe` with `args` in domain `domain`, stdout piped.
    pub fn spawn(exe: &str, domain: &str, args: &[&str]) -> Proc {
        let child = Command::new(exe)
            .args(args)
            .env("LIMBER_DOMAIN", domain)
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .unwrap_or_else(|e| panic!("cannot start {exe}: {e}"));
        Proc { child }
    }

    /// Sends a signal (SIGKILL, SIGTERM, ...).
    pub fn signal(&self, sig: i32) {
        // SAFETY: kill(2) on our own child's pid has no memory-safety implications.
        unsafe {
            libc::kill(self.child.id() as i32, sig);
        }
    }

    /// Waits up to `timeout` for the exit; returns the exit code (None: killed by a signal
    /// or still running, in which case it is killed).
    pub fn wait_timeout(&mut self, timeout: Duration) -> Option<i32> {
        let deadline = Instant::now() + timeout;
        loop {
            if let Ok(Some(status)) = self.child.try_wait() {
                return status.code();
            }
            if Instant::now() >= deadline {
                let _ = self.child.kill();
                let _ = self.child.wait();
                return None;
            }
            std::thread::sleep(Duration::from_millis(10));
        }
    }

    /// Reads stdout lines until one satisfies `pred` (or EOF); returns it.
    pub fn read_until(&mut self, pred: impl Fn(&str) -> bool) -> Option<String> {
        let out = self.child.stdout.as_mut()?;
        let mut r = BufReader::new(out);
        let mut line = String::new();
        loop {
            line.clear();
            if r.read_line(&mut line).ok()? == 0 {
                return None;
            }
            if pred(line.trim_end()) {
                return Some(line.trim_end().to_string());
            }
        }
    }

    /// All remaining stdout (after the process ended).
    pub fn rest_of_stdout(&mut self) -> String {
        use std::io::Read;
        let mut s = String::new();
        if let Some(out) = self.child.stdout.as_mut() {
            let _ = out.read_to_string(&mut s);
        }
        s
    }
}

impl Drop for Proc {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// A global allocator that counts the allocations made on each thread, for the tests that
/// prove a hot loop allocates nothing. Declare it in a test binary with
/// `#[global_allocator] static GLOBAL: limber_tests::Counting = limber_tests::Counting;`.
#[derive(Debug)]
pub struct Counting;

thread_local! {
    static ALLOCS: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
}

// SAFETY: forwards to the system allocator; only counts calls made on the current thread.
unsafe impl std::alloc::GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: std::alloc::Layout) -> *mut u8 {
        let _ = ALLOCS.try_with(|c| c.set(c.get() + 1));
        // SAFETY: same contract as ours.
        unsafe { std::alloc::System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: std::alloc::Layout) {
        // SAFETY: same contract as ours.
        unsafe { std::alloc::System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: std::alloc::Layout, new_size: usize) -> *mut u8 {
        let _ = ALLOCS.try_with(|c| c.set(c.get() + 1));
        // SAFETY: same contract as ours.
        unsafe { std::alloc::System.realloc(ptr, layout, new_size) }
    }
}

/// Allocations made so far on this thread (when [`Counting`] is the global allocator).
pub fn allocations() -> u64 {
    ALLOCS.with(|c| c.get())
}
