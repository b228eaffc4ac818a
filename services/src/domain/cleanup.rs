//! Removing a domain's files once nothing runs in it.
//!
//! A process that ends normally removes its own iceoryx2 files; one that is killed leaves
//! them, and they stay until a process of the same domain cleans up after it. A test's
//! domain ([`Domain::unique_for_test`]) is never joined again, so each one removes its
//! files when its last handle is dropped ([`remove_domain_files`]): the files of the processes
//! the test killed, the node counter iceoryx2 leaves in `/dev/shm`, and the domain's token.
//! A test run thus leaves nothing in the runtime directory or in `/dev/shm`.

use std::collections::HashSet;
use std::fs;
use std::io;
use std::os::unix::fs::MetadataExt;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use iceoryx2::node::{DeadNodeView, NodeListFailure, NodeView};
use iceoryx2::prelude::{CallbackProgression, Node, NodeState, ipc};
use thiserror::Error;

use super::Domain;
use super::dir::{self, DomainError};

/// The files of a domain could not be removed.
#[derive(Debug, Error)]
pub enum RemoveError {
    /// The domain's files could not be found, or are not this user's.
    #[error(transparent)]
    Domain(#[from] DomainError),
    /// iceoryx2 could not list the processes of the domain.
    #[error("cannot list the processes of domain {domain}: {source}")]
    List {
        /// The domain.
        domain: String,
        /// iceoryx2's error.
        #[source]
        source: NodeListFailure,
    },
    /// Processes still run in the domain: its files are theirs.
    #[error(
        "domain {domain} is in use by {alive} live process(es) ({}): stop them first",
        .processes.join(", ")
    )]
    Alive {
        /// The domain.
        domain: String,
        /// How many of its iceoryx2 nodes are alive.
        alive: usize,
        /// Each live process, `NODE (pid N)` (`limber-driver:pioneer (pid 4242)`).
        processes: Vec<String>,
    },
}

/// What [`remove`] removed.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Removed {
    /// Dead processes of the domain whose resources iceoryx2 removed (their segments,
    /// ports and node directories).
    pub dead_processes: usize,
    /// The files and directories removed after that ([`dir::files_of`]: the node counter,
    /// what iceoryx2 could not clean up, the token).
    pub files: usize,
}

impl Removed {
    /// Nothing was there.
    pub fn is_nothing(&self) -> bool {
        self.dead_processes == 0 && self.files == 0
    }
}

/// Removes every file of `domain` when no process runs in it: first the resources of its
/// dead processes, as iceoryx2 removes them, then what is left of the domain
/// ([`dir::files_of`]: the node counter in `/dev/shm`, the files of processes
/// iceoryx2 could not clean up, the token). Only this user's files are removed (in group
/// mode the other members' stay theirs). Returns how many files and directories were
/// removed; a domain without files (no token) is left as it is, and nothing is created.
pub fn remove_domain_files(domain: &Domain) -> Result<usize, RemoveError> {
    remove(domain).map(|r| r.files)
}

/// [`remove_domain_files`], saying also how many dead processes were cleaned up after.
pub fn remove(domain: &Domain) -> Result<Removed, RemoveError> {
    let Some(files) = dir::existing(domain.name())? else {
        return Ok(Removed::default());
    };
    // The token exists: this reads it, it does not make one.
    let config = domain.config()?;
    let mut processes = Vec::new();
    let mut dead = Vec::new();
    Node::<ipc::Service>::list(config, |n| {
        match n {
            NodeState::Alive(v) => processes.push(describe_node(v.details())),
            NodeState::Dead(v) if super::group::node_is_mine(&files.root, v.id().value()) => {
                dead.push(v);
            }
            _ => {}
        }
        CallbackProgression::Continue
    })
    .map_err(|source| RemoveError::List {
        domain: domain.name().to_string(),
        source,
    })?;
    // Before iceoryx2 opens anything of the dead: the segments they left half made.
    let (half_made, _) = sweep_for_dead(
        &files.prefix,
        &files.root,
        &ids_of(&dead),
        processes.is_empty(),
    );
    let dead_processes = remove_stale(dead);
    if !processes.is_empty() {
        return Err(RemoveError::Alive {
            domain: domain.name().to_string(),
            alive: processes.len(),
            processes,
        });
    }
    let me = dir::euid();
    let mut removed = half_made;
    for path in dir::files_of(domain.name(), &files) {
        let Ok(md) = fs::symlink_metadata(&path) else {
            continue;
        };
        if md.uid() != me {
            continue;
        }
        let r = if md.is_dir() {
            fs::remove_dir(&path)
        } else {
            fs::remove_file(&path)
        };
        match r {
            Ok(()) => removed += 1,
            Err(e) if e.kind() == io::ErrorKind::NotFound => {}
            Err(e) => {
                tracing::warn!(path = %path.display(), error = %e, "cannot remove a file of the domain");
            }
        }
    }
    Ok(Removed {
        dead_processes,
        files: removed,
    })
}

/// A segment found empty and unreadable this long after it was made is not being made any
/// more: iceoryx2 sizes and opens a segment within microseconds of creating it.
const HALF_MADE_AGE: Duration = Duration::from_secs(10);

/// Removes the domain's segments in `/dev/shm` (names starting with `prefix`) that a killed
/// process left half made, and returns how many. iceoryx2 creates a segment write-only and
/// empty, sizes it, then makes it readable; a process killed in between leaves an empty,
/// unreadable file, and iceoryx2's `open` of it (the cleanup after that dead process opens
/// its connections) tries again every millisecond for ever when it runs as root: root may
/// open the unreadable file, finds its size zero, and that case never reaches the timeout
/// (iceoryx2-cal 0.10 `posix_shared_memory::open_impl`; another user is refused the open
/// and gives up). `all`: no process of the domain is alive, so every such file is left
/// over; else only those older than [`HALF_MADE_AGE`] (one being made now is not touched).
/// Returns how many it removed and how many younger ones it left.
fn remove_half_made(prefix: &str, all: bool) -> (usize, usize) {
    let mut young = 0;
    let n = sweep_half_made(prefix, |_, md| {
        let old = md
            .modified()
            .ok()
            .and_then(|t| t.elapsed().ok())
            .is_some_and(|age| age >= HALF_MADE_AGE);
        if !all && !old {
            young += 1;
        }
        all || old
    });
    (n, young)
}

/// Removes the domain's segments (names starting with `prefix`) that are half made
/// (as [`remove_half_made`] sees them, whatever their age) and name a port for which
/// `gone` says its process is gone: nobody will finish them, and iceoryx2, as root, would
/// wait on one for ever when a live port connects to that port. Returns how many.
pub(crate) fn remove_half_made_of(prefix: &str, gone: impl Fn(u128) -> bool) -> usize {
    sweep_half_made(prefix, |name, _| {
        super::group::port_ids(prefix, name)
            .is_some_and(|ids| ids.iter().any(|i| i.parse::<u128>().is_ok_and(&gone)))
    })
}

/// The one test of a half-made segment of the domain (names starting with `prefix`): a
/// file of this user in `/dev/shm`, empty, that nobody may read (see [`remove_half_made`]).
/// Removes each one for which `remove(name, metadata)` says so; returns how many it removed.
fn sweep_half_made(prefix: &str, mut remove: impl FnMut(&str, &fs::Metadata) -> bool) -> usize {
    my_files_in(Path::new(dir::SHM_DIR), prefix)
        .filter(|(_, name, md)| md.len() == 0 && md.mode() & 0o444 == 0 && remove(name, md))
        .map(|(path, _, _)| remove_left_over(&path, "a segment it left half made"))
        .filter(|removed| *removed)
        .count()
}

/// The files of this user in `dir` whose names start with `prefix`: each one's path, name
/// and metadata (a symbolic link is not followed, nor listed).
fn my_files_in(dir: &Path, prefix: &str) -> impl Iterator<Item = (PathBuf, String, fs::Metadata)> {
    let me = dir::euid();
    let prefix = prefix.to_string();
    dir::entries(dir).into_iter().filter_map(move |e| {
        let name = e.file_name().to_string_lossy().to_string();
        if !name.starts_with(&prefix) {
            return None;
        }
        let md = fs::symlink_metadata(e.path()).ok()?;
        (md.is_file() && md.uid() == me).then(|| (e.path(), name, md))
    })
}

/// Removes `path`, `what` a killed process left (said in the log, as is a failure);
/// whether it removed it.
fn remove_left_over(path: &Path, what: &str) -> bool {
    match fs::remove_file(path) {
        Ok(()) => {
            tracing::info!(path = %path.display(), "removed {what}, after a killed process");
            true
        }
        Err(err) if err.kind() == io::ErrorKind::NotFound => false,
        Err(err) => {
            tracing::warn!(path = %path.display(), error = %err, "cannot remove {what}, after a killed process");
            false
        }
    }
}

/// The port ids of the nodes `nodes` of the domain with `prefix` (iceoryx2 root `root`): the
/// port tags in each one's node directory (`<root>/nodes/<node>/<prefix><port>.port_tag`),
/// which iceoryx2 writes when it makes a port, before any of the port's segments or
/// connections exists, and removes last when it cleans up after the port. A node directory
/// that cannot be read adds none (logged by [`dir::entries`]).
fn ports_of_nodes(prefix: &str, root: &Path, nodes: &[u128]) -> HashSet<u128> {
    nodes
        .iter()
        .flat_map(|node| dir::entries(&root.join("nodes").join(node.to_string())))
        .filter_map(|e| {
            e.file_name()
                .to_string_lossy()
                .strip_prefix(prefix)
                .and_then(|n| n.strip_suffix(".port_tag"))
                .and_then(|n| n.parse::<u128>().ok())
        })
        .collect()
}

/// Removes the domain's segments (names starting with `prefix`, iceoryx2 root `root`) left
/// half made that name a port of one of the dead nodes `dead`, whatever their age, and
/// returns how many: a process killed while iceoryx2 made one of its connections leaves
/// one (a driver SIGKILLed while it connected a port of its own), and nobody finishes it.
/// A live process of this user connecting to a dead port at that instant keeps the file it
/// has open (only its name goes), and the connection is to a dead peer anyway.
fn remove_half_made_of_nodes(prefix: &str, root: &Path, dead: &[u128]) -> usize {
    if dead.is_empty() {
        return 0;
    }
    let ports = ports_of_nodes(prefix, root, dead);
    if ports.is_empty() {
        return 0;
    }
    remove_half_made_of(prefix, |p| ports.contains(&p))
}

/// iceoryx2's mode of a static storage (a node's details, its port and service tags) while
/// it writes it; it makes it read-only when done, and does not list one still at this mode
/// (iceoryx2-cal 0.10 `static_storage::file`, `INIT_PERMISSIONS`).
const UNFINISHED_MODE: u32 = 0o600;

/// Removes from the directories of the dead nodes `dead` (iceoryx2 root `root`, file names
/// starting with `prefix`) the port and service tags they left unfinished, and returns how
/// many: a process killed while iceoryx2 wrote one leaves it at [`UNFINISHED_MODE`].
/// iceoryx2 does not list such a file; with an unfinished service tag its cleanup after
/// that process failed, and the process stayed listed dead for good. Nobody finishes a
/// tag, and nothing was made after it (iceoryx2 writes a tag before what it tags).
/// Only this user's files go. (A node's details left unfinished, a process killed as its
/// node was made, are not touched: iceoryx2 needs them to clean up after the node with the
/// domain's configuration; `limber clean` removes that node's files once nothing runs.)
fn remove_unfinished_of_nodes(prefix: &str, root: &Path, dead: &[u128]) -> usize {
    let mut n = 0;
    for node in dead {
        let node_dir = root.join("nodes").join(node.to_string());
        n += my_files_in(&node_dir, prefix)
            .filter(|(_, name, md)| {
                let tag = name.ends_with(".port_tag") || name.ends_with(".service_tag");
                tag && md.mode() & 0o7777 == UNFINISHED_MODE
            })
            .map(|(path, _, _)| remove_left_over(&path, "a tag it left unfinished"))
            .filter(|removed| *removed)
            .count();
    }
    n
}

/// The sweep before a cleanup after the dead nodes `dead`: what they left unfinished in
/// their node directories ([`remove_unfinished_of_nodes`]), the half-made segments of their
/// ports at any age ([`remove_half_made_of_nodes`]), then the other half-made ones, old ones
/// or, with `all`, every one ([`remove_half_made`]). Returns how many went and how many
/// young ones of other ports stayed.
fn sweep_for_dead(prefix: &str, root: &Path, dead: &[u128], all: bool) -> (usize, usize) {
    // The port tags first: the half-made segments of their ports are found by them.
    let theirs = remove_half_made_of_nodes(prefix, root, dead);
    let unfinished = remove_unfinished_of_nodes(prefix, root, dead);
    let (others, young) = remove_half_made(prefix, all);
    (theirs + unfinished + others, young)
}

/// Before a live process cleans up through iceoryx2 after the dead nodes `dead` of
/// `domain`: removes the segments they left half made ([`remove_half_made_of_nodes`], at
/// any age), then the other half-made ones older than [`HALF_MADE_AGE`]
/// ([`remove_half_made`]), and says whether the cleanup may go on: false while a younger
/// one of other ports is there (its maker may be making it still; if it is dead, iceoryx2
/// would wait on it for ever, as root: the cleanup waits for a later call instead, by when
/// it is made or old enough to remove).
pub(crate) fn half_made_cleared(domain: &Domain, dead: &[u128]) -> bool {
    let (Ok(prefix), Ok(root)) = (domain.prefix(), domain.root()) else {
        return true;
    };
    let (_, young) = sweep_for_dead(prefix, root, dead, false);
    if young > 0 {
        tracing::info!(
            domain = domain.name(),
            young,
            age_limit_s = HALF_MADE_AGE.as_secs(),
            "the cleanup after dead processes is put off: a segment of a port not theirs is being made, or was left half made less than age_limit_s ago"
        );
    }
    young == 0
}

/// The ids of the dead nodes `dead` (for [`half_made_cleared`]).
pub(crate) fn ids_of(dead: &[DeadNodeView<ipc::Service>]) -> Vec<u128> {
    dead.iter().map(|v| v.id().value()).collect()
}

/// Has iceoryx2 remove the resources of each of the dead nodes `dead` (their segments,
/// ports, registrations and node directories); returns how many it cleaned up. A failure
/// is logged (another process may be cleaning up after the same node) and the next one
/// tried.
pub(crate) fn remove_stale(dead: Vec<DeadNodeView<ipc::Service>>) -> usize {
    let mut n = 0;
    for v in dead {
        let node = v.id().value();
        match v.blocking_remove_stale_resources(Duration::ZERO) {
            Ok(_) => n += 1,
            Err(e) => {
                tracing::debug!(node, error = ?e, "cannot clean up after a dead process");
            }
        }
    }
    n
}

/// `NODE (pid N)` for a live node (`a process` when its details cannot be read).
fn describe_node(details: &Option<iceoryx2::node::NodeDetails>) -> String {
    match details {
        Some(d) => format!("{} (pid {})", d.name(), d.process_id()),
        None => "a process".to_string(),
    }
}

/// How long a test's domain, when its last handle is dropped, waits for the processes
/// still in it to end (a child just killed, a driver thread just told to stop) before it
/// leaves their files.
pub(crate) const IDLE_WAIT: Duration = Duration::from_secs(5);

/// Removes the files of the domain `name` ([`remove_domain_files`]) as soon as no process
/// runs in it, waiting at most `wait` for that; logs what it cannot remove.
pub(crate) fn remove_when_idle(name: &str, wait: Duration) {
    let Ok(domain) = Domain::new(name) else {
        return;
    };
    let deadline = Instant::now() + wait;
    loop {
        match remove_domain_files(&domain) {
            Ok(_) => return,
            Err(RemoveError::Alive { .. }) if Instant::now() < deadline => {
                std::thread::sleep(Duration::from_millis(10));
            }
            Err(e) => {
                tracing::warn!(domain = name, error = %e, "a test's domain keeps its files");
                return;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Context, Role};

    #[test]
    fn a_domain_in_use_keeps_its_files_and_an_idle_one_loses_them_all() {
        let domain = Domain::new(&format!("limber_cleanup{}", std::process::id())).unwrap();
        assert_eq!(remove_domain_files(&domain).unwrap(), 0, "no token yet");
        assert!(
            dir::existing(domain.name()).unwrap().is_none(),
            "nothing was made"
        );
        let ctx = Context::new(&domain, Role::Client, "cleanup").unwrap();
        let files = dir::existing(domain.name()).unwrap().unwrap();
        let in_use = dir::files_of(domain.name(), &files);
        assert!(
            matches!(
                remove_domain_files(&domain),
                Err(RemoveError::Alive { alive: 1, ref processes, .. })
                    if processes.len() == 1
                        && processes[0].starts_with("limber-client:cleanup (pid ")
            ),
            "a process runs in it"
        );
        assert!(in_use.iter().all(|p| p.exists()), "all kept: {in_use:?}");
        drop(ctx);
        assert!(remove_domain_files(&domain).unwrap() > 0);
        assert_eq!(
            dir::files_of(domain.name(), &files),
            Vec::<std::path::PathBuf>::new()
        );
        assert!(in_use.iter().all(|p| !p.exists()), "all gone: {in_use:?}");
    }
}
