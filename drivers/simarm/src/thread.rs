//! [`SimArmThread`]: simarm on a thread of the calling process, in a domain, until dropped
//! (for tests and examples that want a simulated arm beside their clients).

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::thread::JoinHandle;
use std::time::Duration;

use limber_kinematics::chain::Chain;
use limber_services::{Context, Domain, Role};

use crate::{SimArm, SimArmOptions};

/// simarm did not start on its thread.
#[derive(Debug, thiserror::Error)]
pub enum SimArmThreadError {
    /// The domain, the context or the driver could not be made (the text says which).
    #[error("simarm did not start: {0}")]
    Start(String),
    /// It did not say it was ready within the time given.
    #[error("simarm did not start within {0:?}")]
    Timeout(Duration),
}

/// simarm running on a thread; stopped and joined when dropped.
#[derive(Debug)]
pub struct SimArmThread {
    stop: Arc<AtomicBool>,
    handle: Option<JoinHandle<()>>,
}

impl SimArmThread {
    /// Starts simarm (`chain`, `options`) in the domain named `domain` and waits up to
    /// `timeout` for its devices.
    pub fn start(
        domain: &str,
        chain: Chain,
        options: SimArmOptions,
        timeout: Duration,
    ) -> Result<Self, SimArmThreadError> {
        let stop = Arc::new(AtomicBool::new(false));
        let (ready_tx, ready_rx) = mpsc::channel();
        let name = domain.to_string();
        let flag = stop.clone();
        let handle = std::thread::spawn(move || {
            let started = Domain::new(&name)
                .map_err(|e| e.to_string())
                .and_then(|d| Context::new(&d, Role::Driver, "simarm").map_err(|e| e.to_string()))
                .and_then(|ctx| {
                    SimArm::new(&ctx, chain, options)
                        .map(|arm| (ctx, arm))
                        .map_err(|e| e.to_string())
                });
            match started {
                Ok((_ctx, mut arm)) => {
                    // The starter may have given up waiting: it then stops us on drop.
                    if ready_tx.send(Ok(())).is_err() {
                        tracing::warn!("simarm on its thread: the starter stopped waiting");
                    }
                    if let Err(e) = arm.run(|| flag.load(Ordering::Relaxed)) {
                        tracing::error!(error = %e, "simarm on its thread stopped");
                    }
                }
                Err(e) => {
                    if let Err(unsent) = ready_tx.send(Err(e)) {
                        tracing::error!(error = ?unsent.0, "simarm on its thread did not start");
                    }
                }
            }
        });
        let t = SimArmThread {
            stop,
            handle: Some(handle),
        };
        match ready_rx.recv_timeout(timeout) {
            Ok(Ok(())) => Ok(t),
            Ok(Err(e)) => {
                // Its thread has ended: joined by the drop.
                drop(t);
                Err(SimArmThreadError::Start(e))
            }
            Err(_) => Err(SimArmThreadError::Timeout(timeout)),
        }
    }
}

impl Drop for SimArmThread {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(h) = self.handle.take()
            && h.join().is_err()
        {
            tracing::error!("simarm's thread panicked");
        }
    }
}
