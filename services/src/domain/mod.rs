//! A domain and its files: the one entry point to where a domain's files live, who may touch
//! them, and when they go.
//!
//! [`Domain`] is what the rest of the crate uses: its iceoryx2 configuration, prefix and root
//! path ([`Domain::config`]), the checks around a process joining it, the cleanup after dead
//! processes, and the removal of all its files ([`Domain::remove_files`], `limber clean`).
//! Underneath, each in its own module:
//!
//! * [`dir`]: the runtime directory, the domain's token, the checks of ownership and modes,
//!   and the list of a domain's files ([`dir::files_of`]).
//! * [`group`]: group mode, opening the files iceoryx2 makes owner-only to a group's members,
//!   and each member's cleanup after its own dead processes.
//! * [`cleanup`]: removing a domain's files once nothing runs in it.
//!
//! This module uses [`crate::naming`] (domain names, [`NameError`]); naming uses nothing of
//! this one: no import cycle.

use core::fmt;
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::{Arc, OnceLock};

use iceoryx2::config::Config;
use iceoryx2::prelude::{FileName, Path as IoxPath, SemanticString};

use crate::naming::{DEFAULT_DOMAIN, DOMAIN_ENV, MAX_DOMAIN_LEN, NameError, valid_ident};

pub mod cleanup;
pub mod dir;
pub mod group;

pub use cleanup::{RemoveError, Removed};
pub use dir::{DomainError, DomainFiles, Group};

/// A domain: the set of devices and clients that can see each other.
#[derive(Debug, Clone)]
pub struct Domain {
    name: String,
    /// The iceoryx2 configuration, made on first use (it needs the domain's files).
    config: Arc<OnceLock<Resolved>>,
    /// A test's domain ([`Domain::unique_for_test`]): removes the domain's files when the
    /// last clone is dropped.
    remove_on_drop: Option<Arc<RemoveOnDrop>>,
}

/// Removes the files of a test's domain when dropped ([`cleanup`]).
#[derive(Debug)]
struct RemoveOnDrop(String);

impl Drop for RemoveOnDrop {
    fn drop(&mut self) {
        cleanup::remove_when_idle(&self.0, cleanup::IDLE_WAIT);
    }
}

/// A domain's iceoryx2 configuration, prefix and group, made once.
#[derive(Debug)]
struct Resolved {
    config: Config,
    prefix: String,
    root: std::path::PathBuf,
    group: Option<Group>,
}

impl Domain {
    /// A domain by name (`[A-Za-z0-9_-]`, 1 to 48 characters).
    pub fn new(name: &str) -> Result<Self, NameError> {
        if !valid_ident(name, MAX_DOMAIN_LEN) {
            return Err(NameError::Domain(name.to_string()));
        }
        Ok(Domain {
            name: name.to_string(),
            config: Arc::new(OnceLock::new()),
            remove_on_drop: None,
        })
    }

    /// The domain named by `LIMBER_DOMAIN`, or `limber`.
    pub fn from_env() -> Result<Self, NameError> {
        match std::env::var(DOMAIN_ENV) {
            Ok(v) if !v.is_empty() => Domain::new(&v),
            _ => Domain::new(DEFAULT_DOMAIN),
        }
    }

    /// A fresh domain for one test: `limber_t<pid>_<n>_<nanos>`, unique on this machine.
    ///
    /// It cleans up after itself: when its last clone is dropped, once no process runs in it
    /// any more (waiting a few seconds at most for processes just killed or told to stop),
    /// every file of the domain is removed, those of processes the test killed included
    /// ([`Domain::remove_files`]). Keep it alive for as long as the test uses
    /// the domain, also when only its name is handed to other processes.
    pub fn unique_for_test() -> Self {
        static N: AtomicU32 = AtomicU32::new(0);
        let n = N.fetch_add(1, Ordering::Relaxed);
        // The pid alone repeats over a long run of test processes, and a test that
        // SIGKILLs a driver leaves its files behind: the clock makes a reused pid a new
        // domain.
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.subsec_nanos());
        let name = format!("limber_t{}_{}_{nanos:x}", std::process::id(), n);
        Domain::for_test(&name).expect("generated test domain names are valid")
    }

    /// A test's domain of a name the test chose (one made from a [`Domain::unique_for_test`]
    /// name, for a test that needs several domains): it cleans up after itself as that one
    /// does.
    pub fn for_test(name: &str) -> Result<Self, NameError> {
        let mut domain = Domain::new(name)?;
        domain.remove_on_drop = Some(Arc::new(RemoveOnDrop(name.to_string())));
        Ok(domain)
    }

    /// The name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The iceoryx2 configuration of this domain: iceoryx2's built-in defaults (a stray
    /// `./config/iceoryx2.toml` does not change a robot's behaviour) with the root path and
    /// prefix of the domain's files, which are prepared (and checked) on the first call; see
    /// [`dir`].
    pub fn config(&self) -> Result<&Config, DomainError> {
        Ok(&self.resolved()?.config)
    }

    /// The iceoryx2 prefix of this domain's files (`limber_<token>_`).
    pub fn prefix(&self) -> Result<&str, DomainError> {
        Ok(&self.resolved()?.prefix)
    }

    /// The iceoryx2 root path of this domain's files (`<runtime>/iceoryx2/`).
    pub fn root(&self) -> Result<&std::path::Path, DomainError> {
        Ok(&self.resolved()?.root)
    }

    /// The runtime directory of this domain's files (the parent of [`Domain::root`]: its
    /// token, its iceoryx2 files, the private sockets of its bridges).
    pub fn runtime_dir(&self) -> Result<&std::path::Path, DomainError> {
        let root = self.root()?;
        Ok(root.parent().unwrap_or(root))
    }

    /// The Unix group that shares this domain (group mode, `LIMBER_GROUP`), or None: the
    /// domain is its user's alone.
    pub fn group(&self) -> Result<Option<&Group>, DomainError> {
        Ok(self.resolved()?.group.as_ref())
    }

    /// In group mode, opens this user's files of the domain to the group now (the watch of
    /// [`group`] does as they appear; this covers the files a port made before a
    /// short-lived process ends). Nothing otherwise.
    pub(crate) fn widen_now(&self) {
        if let Some(r) = self.config.get()
            && let Some(g) = &r.group
        {
            group::sweep(&r.prefix, &r.root, g);
        }
    }

    fn resolved(&self) -> Result<&Resolved, DomainError> {
        if let Some(c) = self.config.get() {
            return Ok(c);
        }
        let files = dir::prepare(&self.name)?;
        let mut config = Config::default();
        let bad = |what: &str| DomainError::Io {
            what: "use",
            path: files.root.clone(),
            source: std::io::Error::new(std::io::ErrorKind::InvalidInput, what.to_string()).into(),
        };
        config.global.prefix = FileName::new(files.prefix.as_bytes())
            .map_err(|_| bad("an invalid iceoryx2 prefix"))?;
        let root = files
            .root
            .to_str()
            .ok_or_else(|| bad("a path that is not UTF-8"))?;
        config.global.set_root_path(
            &IoxPath::new(root.as_bytes()).map_err(|_| bad("an invalid iceoryx2 root path"))?,
        );
        // iceoryx2's own cleanup after dead processes is off: it runs where limber does
        // not look first (a node's creation and drop, a service's opening) and, as root,
        // never returns on a segment a killed process left half made
        // ([`cleanup::half_made_cleared`]); in group mode each member may clean up after
        // its own dead processes only. limber cleans up itself, with both guards:
        // [`Self::after_join`] after the domain's dead processes, [`group::cleanup_dead_nodes`]
        // after those of a service it opens, and the driver's housekeeping.
        config.global.node.cleanup_dead_nodes_on_creation = false;
        config.global.node.cleanup_dead_nodes_on_destruction = false;
        config.global.service.cleanup_dead_nodes_on_open = false;
        Ok(self.config.get_or_init(|| Resolved {
            config,
            prefix: files.prefix,
            root: files.root,
            group: files.group,
        }))
    }

    /// Prepares this process's joining of the domain, before its iceoryx2 node is made: a
    /// driver refuses a `/dev/shm` too small for its segments; in group mode the files the
    /// node will make are opened to the group as they appear ([`group`]).
    pub(crate) fn before_join(&self, driver: bool) -> Result<(), DomainError> {
        let r = self.resolved()?;
        if driver {
            dir::check_shm_space()?;
        }
        if let Some(g) = &r.group {
            group::start(&r.prefix, &r.root, g);
        }
        Ok(())
    }

    /// Secures the domain after this process's node was made: the node counter iceoryx2
    /// makes world-writable is narrowed ([`dir::secure_shm`]); the domain's dead processes
    /// (in group mode, this user's) are cleaned up after ([`group::cleanup_domain_dead_nodes`]:
    /// the segments they left half made are removed first, whatever their age; the cleanup
    /// is put off while a half-made segment of another port is too young to remove,
    /// [`cleanup::half_made_cleared`], and the next process to join, or a driver's
    /// housekeeping, does it then); in group mode the files of this user's ports that are
    /// gone are removed.
    pub(crate) fn after_join(&self) -> Result<(), DomainError> {
        let r = self.resolved()?;
        dir::secure_shm(&r.prefix, r.group.as_ref())?;
        group::cleanup_domain_dead_nodes(self);
        if r.group.is_some() {
            group::remove_orphans(&r.prefix, &r.root);
        }
        Ok(())
    }

    /// Removes the resources of the dead processes attached to `svc` (in group mode, of
    /// this user's processes only: [`group::cleanup_dead_nodes`]).
    pub(crate) fn cleanup_dead_nodes<P>(&self, svc: &P)
    where
        P: iceoryx2::service::port_factory::PortFactory<Service = iceoryx2::prelude::ipc::Service>,
    {
        group::cleanup_dead_nodes(svc, self);
    }

    /// In group mode, the user of a dead node of `svc` that belongs to another user (its
    /// node directory is theirs: only they may clean it up), as `user NAME (uid N)`.
    pub(crate) fn dead_node_of_another_user<P>(&self, svc: &P) -> Option<String>
    where
        P: iceoryx2::service::port_factory::PortFactory<Service = iceoryx2::prelude::ipc::Service>,
    {
        use iceoryx2::node::NodeView;
        use iceoryx2::prelude::{CallbackProgression, NodeState};
        use std::os::unix::fs::MetadataExt;
        self.group().ok().flatten()?;
        let nodes = self.root().ok()?.join("nodes");
        let mut owner = None;
        if let Err(e) = svc.nodes(|n| {
            if let NodeState::Dead(v) = &n
                && let Ok(md) = std::fs::symlink_metadata(nodes.join(v.id().value().to_string()))
                && md.uid() != dir::euid()
            {
                owner = Some(dir::describe_user(md.uid()));
            }
            CallbackProgression::Continue
        }) {
            tracing::warn!(error = %e, "cannot list the nodes of a device");
        }
        owner
    }

    /// Removes every file of the domain when no process runs in it (`limber clean`): see
    /// [`cleanup::remove_domain_files`].
    pub fn remove_files(&self) -> Result<Removed, RemoveError> {
        cleanup::remove(self)
    }
}

impl fmt::Display for Domain {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn domains_validate() {
        assert!(Domain::new("robot_1").is_ok());
        assert!(Domain::new("").is_err());
        assert!(Domain::new("a b").is_err());
        assert!(Domain::new(&"x".repeat(49)).is_err());
        assert_ne!(
            Domain::unique_for_test().name(),
            Domain::unique_for_test().name()
        );
    }
}
