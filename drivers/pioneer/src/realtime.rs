//! Real-time set-up of the calling thread: CPU pinning, SCHED_FIFO and locked memory.

use std::fmt;

/// Something [`apply_realtime`] was asked for and could not do; the driver runs on without it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RealtimeWarning(String);

impl fmt::Display for RealtimeWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

/// `--cpu N` names a core this process may not run on (none such, or outside its
/// affinity mask, as `taskset` or a cgroup set it).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("--cpu {cpu}: no such core among those this process may use ({usable:?})")]
pub struct CpuError {
    /// The core asked for.
    pub cpu: usize,
    /// The cores this process may use.
    pub usable: Vec<usize>,
}

/// Checks that this process may run on core `cpu`, before anything starts. When the
/// affinity mask cannot be read it passes, and [`apply_realtime`] warns if pinning fails.
pub fn check_cpu(cpu: usize) -> Result<(), CpuError> {
    match core_affinity::get_core_ids() {
        Some(ids) if !ids.iter().any(|c| c.id == cpu) => Err(CpuError {
            cpu,
            usable: ids.into_iter().map(|c| c.id).collect(),
        }),
        _ => Ok(()),
    }
}

/// Pins the calling thread to CPU `cpu` (if given) and, with `rt`, gives it SCHED_FIFO
/// priority 80 and locks the process's memory. Returns a warning for each part that was
/// not permitted (each is also logged).
pub fn apply_realtime(cpu: Option<usize>, rt: bool) -> Vec<RealtimeWarning> {
    let mut warnings = Vec::new();
    let mut warn = |w: String| {
        tracing::warn!("{w}");
        warnings.push(RealtimeWarning(w));
    };
    if let Some(n) = cpu {
        let ok = core_affinity::get_core_ids()
            .and_then(|ids| ids.into_iter().find(|c| c.id == n))
            .map(core_affinity::set_for_current)
            .unwrap_or(false);
        if !ok {
            warn(format!(
                "cannot pin to CPU {n} (no such core, or not permitted)"
            ));
        }
    }
    if rt {
        use thread_priority::{
            RealtimeThreadSchedulePolicy, ThreadPriority, ThreadSchedulePolicy,
            set_thread_priority_and_policy, thread_native_id,
        };
        let prio = ThreadPriority::Crossplatform(80u8.try_into().expect("80 is a valid priority"));
        if let Err(e) = set_thread_priority_and_policy(
            thread_native_id(),
            prio,
            ThreadSchedulePolicy::Realtime(RealtimeThreadSchedulePolicy::Fifo),
        ) {
            warn(format!(
                "SCHED_FIFO not permitted ({e}): running with normal priority (grant CAP_SYS_NICE or run as root)"
            ));
        }
        if let Err(e) = rustix::mm::mlockall(
            rustix::mm::MlockAllFlags::CURRENT | rustix::mm::MlockAllFlags::FUTURE,
        ) {
            warn(format!(
                "mlockall not permitted ({e}): memory may be paged (grant CAP_IPC_LOCK or raise RLIMIT_MEMLOCK)"
            ));
        }
    }
    warnings
}
