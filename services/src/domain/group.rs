//! Group mode: opening the files iceoryx2 makes owner-only to the members of a group.
//!
//! iceoryx2 0.10 gives everything it creates a fixed owner-only mode (0600 segments and
//! sockets, 0400 static configurations, 0750 directories; its `dev_permissions` feature
//! makes them world-accessible instead, which limber never uses). In group mode
//! (`LIMBER_GROUP`, see [`super::dir`]) every process of the group therefore watches
//! (inotify) the domain's files in `/dev/shm` (its prefix) and the iceoryx2 root path, and
//! widens the ones *it owns* as soon as iceoryx2 has finished them:
//!
//! | what                                              | iceoryx2 | group mode |
//! |---------------------------------------------------|----------|------------|
//! | segments, connections, dynamic configurations     | 0600     | 0660       |
//! | event sockets, node monitors (lock files)         | 0600     | 0660       |
//! | static configurations, node details, tags         | 0400     | 0440       |
//! | directories                                       | 0750     | 2770       |
//!
//! and gives them the group. A file still being initialised has another mode (0200 for
//! shared memory, 0600 for a static configuration) and is left alone until iceoryx2 sets
//! its final mode (an inotify `IN_ATTRIB` event). Files start owner-only, so nobody outside
//! the group can open them in between; a member that opens a segment in the instant before
//! it is widened is refused with `EACCES`, which iceoryx2 retries for its
//! `creation_timeout` (1 s) when it opens segments and connections.

use std::collections::{HashMap, HashSet};
use std::fs;
use std::os::unix::fs::{FileTypeExt, MetadataExt, PermissionsExt};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use iceoryx2::node::NodeView;
use rustix::fs::inotify;

use super::dir::{DomainError, GROUP_DIR_MODE, Group, IoError, SHM_DIR, euid};

/// The mode a file of ours should have in group mode, or None to leave it as it is.
/// `in_shm`: the file is in `/dev/shm` (else in the iceoryx2 root path).
fn wanted_mode(md: &fs::Metadata, name: &str, in_shm: bool) -> Option<u32> {
    let mode = md.mode() & 0o7777;
    let ft = md.file_type();
    let want = if ft.is_dir() {
        (!in_shm).then_some(GROUP_DIR_MODE)
    } else if ft.is_socket() {
        Some(0o660)
    } else if ft.is_file() {
        match mode {
            // Final shared memory (in /dev/shm; 0200 while being initialised), and the
            // node monitors' lock files in the root path (iceoryx2 opens both for writing
            // to tell whether a node is alive).
            0o600 if in_shm => Some(0o660),
            0o600
                if name.ends_with(".node_monitor")
                    || name.ends_with(".node_monitor_owner_lock") =>
            {
                Some(0o660)
            }
            // The node counter, made world-writable by iceoryx2.
            0o666 if in_shm => Some(0o660),
            // Final static storage (0600 while being written).
            0o400 => Some(0o440),
            _ => None,
        }
    } else {
        None
    };
    want.filter(|&w| w != mode)
}

/// Widens one entry of ours; a file that went away meanwhile is no error.
fn widen_entry(path: &Path, name: &str, in_shm: bool, gid: u32) -> Result<(), DomainError> {
    let io = |what: &'static str| {
        move |e: std::io::Error| DomainError::Io {
            what,
            path: path.to_path_buf(),
            source: IoError::from(e),
        }
    };
    let md = match fs::symlink_metadata(path) {
        Ok(md) => md,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(io("inspect")(e)),
    };
    if md.uid() != euid() || md.file_type().is_symlink() {
        return Ok(());
    }
    let gone = |r: Result<(), std::io::Error>, what| match r {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        other => other.map_err(io(what)),
    };
    if md.gid() != gid {
        gone(
            rustix::fs::chownat(
                rustix::fs::CWD,
                path,
                None,
                Some(rustix::fs::Gid::from_raw(gid)),
                rustix::fs::AtFlags::SYMLINK_NOFOLLOW,
            )
            .map_err(std::io::Error::from),
            "change the group of",
        )?;
    }
    if let Some(mode) = wanted_mode(&md, name, in_shm) {
        gone(
            fs::set_permissions(path, fs::Permissions::from_mode(mode)),
            "change the mode of",
        )?;
    }
    Ok(())
}

/// What one process watches for one domain.
struct Watch {
    prefix: String,
    gid: u32,
    /// watch descriptor → (directory, is /dev/shm)
    dirs: HashMap<i32, (PathBuf, bool)>,
}

impl Watch {
    fn mine(&self, name: &str, in_shm: bool) -> bool {
        !in_shm || name.starts_with(&self.prefix)
    }

    /// Widens every entry of ours in `dir` (and, in the root path, its subdirectories).
    fn sweep_dir(&self, dir: &Path, in_shm: bool, depth: u32) {
        let Ok(rd) = fs::read_dir(dir) else { return };
        for e in rd.filter_map(Result::ok) {
            let name = e.file_name();
            let name = name.to_string_lossy();
            if !self.mine(&name, in_shm) {
                continue;
            }
            let path = e.path();
            self.widen_logged(&path, &name, in_shm);
            if !in_shm && depth < 3 && e.file_type().is_ok_and(|t| t.is_dir()) {
                self.sweep_dir(&path, false, depth + 1);
            }
        }
    }

    fn widen_logged(&self, path: &Path, name: &str, in_shm: bool) {
        if let Err(e) = widen_entry(path, name, in_shm, self.gid) {
            tracing::warn!(error = %e, "group mode: cannot open a file of the domain to the group");
        }
    }

    fn add(&mut self, fd: &rustix::fd::OwnedFd, dir: &Path, in_shm: bool) {
        let flags = inotify::WatchFlags::CREATE
            | inotify::WatchFlags::ATTRIB
            | inotify::WatchFlags::MOVED_TO
            | inotify::WatchFlags::ONLYDIR
            | inotify::WatchFlags::DONT_FOLLOW;
        match inotify::add_watch(fd, dir, flags) {
            Ok(wd) => {
                self.dirs.insert(wd, (dir.to_path_buf(), in_shm));
            }
            Err(e) => {
                tracing::warn!(dir = %dir.display(), error = %e, "group mode: cannot watch a directory of the domain; its files may stay closed to the group");
            }
        }
    }

    /// Serves the watch's events until the process ends.
    fn run(mut self, fd: rustix::fd::OwnedFd, root: PathBuf) {
        let mut buf = [std::mem::MaybeUninit::<u8>::uninit(); 8192];
        loop {
            let mut reader = inotify::Reader::new(&fd, &mut buf);
            let mut new_dirs = Vec::new();
            let mut overflow = false;
            loop {
                match reader.next() {
                    Ok(ev) => {
                        if ev.events().contains(inotify::ReadFlags::QUEUE_OVERFLOW) {
                            overflow = true;
                        }
                        let (Some((dir, in_shm)), Some(name)) =
                            (self.dirs.get(&ev.wd()), ev.file_name())
                        else {
                            if reader.is_buffer_empty() {
                                break;
                            }
                            continue;
                        };
                        let name = name.to_string_lossy();
                        if self.mine(&name, *in_shm) {
                            let path = dir.join(&*name);
                            self.widen_logged(&path, &name, *in_shm);
                            if !*in_shm && ev.events().contains(inotify::ReadFlags::ISDIR) {
                                new_dirs.push(path);
                            }
                        }
                    }
                    Err(rustix::io::Errno::INTR) => {}
                    Err(e) => {
                        tracing::error!(error = %e, "group mode: the watch of the domain's files failed; new files stay closed to the group");
                        return;
                    }
                }
                if reader.is_buffer_empty() {
                    break;
                }
            }
            for d in new_dirs {
                self.add(&fd, &d, false);
                self.sweep_dir(&d, false, 1);
            }
            if overflow {
                self.sweep_dir(Path::new(SHM_DIR), true, 0);
                self.sweep_dir(&root, false, 0);
            }
        }
    }
}

/// Starts widening the files of the domain with `prefix` (iceoryx2 root `root`) that this
/// process's user owns, for the rest of the process (once per domain and process): a sweep
/// of what exists, then a thread that widens each new file as iceoryx2 finishes it.
pub(crate) fn start(prefix: &str, root: &Path, group: &Group) {
    static STARTED: Mutex<Option<HashSet<String>>> = Mutex::new(None);
    {
        let mut started = STARTED.lock().unwrap_or_else(|p| p.into_inner());
        if !started
            .get_or_insert_with(HashSet::new)
            .insert(prefix.to_string())
        {
            return;
        }
    }
    let mut watch = Watch {
        prefix: prefix.to_string(),
        gid: group.gid,
        dirs: HashMap::new(),
    };
    let fd = match inotify::init(inotify::CreateFlags::CLOEXEC) {
        Ok(fd) => Some(fd),
        Err(e) => {
            tracing::error!(error = %e, "group mode: cannot watch the domain's files (inotify); files made later stay closed to the group");
            None
        }
    };
    if let Some(fd) = &fd {
        watch.add(fd, Path::new(SHM_DIR), true);
        for d in [
            root.to_path_buf(),
            root.join("services"),
            root.join("nodes"),
        ] {
            watch.add(fd, &d, false);
        }
        if let Ok(rd) = fs::read_dir(root.join("nodes")) {
            for e in rd.filter_map(Result::ok) {
                if e.file_type().is_ok_and(|t| t.is_dir()) {
                    watch.add(fd, &e.path(), false);
                }
            }
        }
    }
    watch.sweep_dir(Path::new(SHM_DIR), true, 0);
    watch.sweep_dir(root, false, 0);
    if let Some(fd) = fd {
        let root = root.to_path_buf();
        if let Err(e) = std::thread::Builder::new()
            .name("limber-group".into())
            .spawn(move || watch.run(fd, root))
        {
            tracing::error!(error = %e, "group mode: cannot start the thread that opens new files to the group");
        }
    }
}

/// Widens, once, every file of the domain with `prefix` (iceoryx2 root `root`) that this
/// process's user owns (what the thread of `start` does as files appear).
pub fn sweep(prefix: &str, root: &Path, group: &Group) {
    let watch = Watch {
        prefix: prefix.to_string(),
        gid: group.gid,
        dirs: HashMap::new(),
    };
    watch.sweep_dir(Path::new(SHM_DIR), true, 0);
    watch.sweep_dir(root, false, 0);
}

/// The port ids of the domain with `prefix` that have a port tag under `root/nodes/*/`
/// (every port of a live process, and of a dead one not cleaned up yet, has one from its
/// creation on, before any of its segments or connections exists).
fn tagged_ports(prefix: &str, root: &Path) -> Option<HashSet<String>> {
    let mut out = HashSet::new();
    let rd = fs::read_dir(root.join("nodes")).ok()?;
    for node in rd.filter_map(Result::ok) {
        if !node.file_type().is_ok_and(|t| t.is_dir()) {
            continue;
        }
        let Ok(files) = fs::read_dir(node.path()) else {
            // A node directory we cannot read: we cannot tell which ports are alive.
            return None;
        };
        for f in files.filter_map(Result::ok) {
            let name = f.file_name();
            let name = name.to_string_lossy();
            if let Some(id) = name
                .strip_prefix(prefix)
                .and_then(|n| n.strip_suffix(".port_tag"))
            {
                out.insert(id.to_string());
            }
        }
    }
    Some(out)
}

/// The port ids in the name of a segment, connection or event of the domain
/// (`<prefix><hash>_<id>[_<id>].<data|connection|event_mgmt>`), or None for other files.
pub(crate) fn port_ids<'a>(prefix: &str, name: &'a str) -> Option<Vec<&'a str>> {
    let rest = name.strip_prefix(prefix)?;
    let (stem, suffix) = rest.rsplit_once('.')?;
    if !matches!(suffix, "data" | "connection" | "event_mgmt") {
        return None;
    }
    let (_hash, ids) = stem.split_once('_')?;
    let ids: Vec<&str> = ids.split('_').collect();
    ids.iter()
        .all(|i| !i.is_empty() && i.bytes().all(|b| b.is_ascii_digit()))
        .then_some(ids)
}

/// Removes this user's files of the domain in `/dev/shm` that belong to ports that no
/// longer exist. In group mode they are what iceoryx2 leaves when another member's process
/// closes a connection this user's process created, or cleans up a dead process of this
/// user: `/dev/shm` is sticky, so only their owner can remove them. Returns how many were
/// removed. Called when a process of the group joins the domain.
pub fn remove_orphans(prefix: &str, root: &Path) -> usize {
    // /dev/shm first, the tags second: a port is tagged before any of its files exists, so
    // a file seen here whose ports are not tagged afterwards is an orphan.
    let Ok(rd) = fs::read_dir(SHM_DIR) else {
        return 0;
    };
    let candidates: Vec<(PathBuf, String)> = rd
        .filter_map(Result::ok)
        .filter_map(|e| {
            let name = e.file_name().to_string_lossy().into_owned();
            port_ids(prefix, &name)?;
            let md = e.metadata().ok()?;
            (md.uid() == euid()).then(|| (e.path(), name))
        })
        .collect();
    if candidates.is_empty() {
        return 0;
    }
    let Some(tagged) = tagged_ports(prefix, root) else {
        return 0;
    };
    let mut removed = 0;
    for (path, name) in candidates {
        let Some(ids) = port_ids(prefix, &name) else {
            continue;
        };
        if ids.iter().all(|i| tagged.contains(*i)) {
            continue;
        }
        match fs::remove_file(&path) {
            Ok(()) => removed += 1,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(e) => {
                tracing::warn!(path = %path.display(), error = %e, "group mode: cannot remove a file of a port that is gone");
            }
        }
    }
    if removed > 0 {
        tracing::info!(
            removed,
            "group mode: removed this user's files of ports that are gone"
        );
    }
    removed
}

/// Whether the node directory of node `id` under `root` belongs to this process's user.
pub(crate) fn node_is_mine(root: &Path, id: u128) -> bool {
    fs::symlink_metadata(root.join("nodes").join(id.to_string())).is_ok_and(|md| md.uid() == euid())
}

/// Removes the resources of the dead processes attached to `svc`. In group mode only those
/// of this user's processes: `/dev/shm` is sticky, so a member cleaning up another member's
/// dead process removes its registrations but not its files, and leaves its services marked
/// for destruction with files nobody but their owner (or root) can remove, which no driver
/// can offer again. So each member's processes clean up after their own (iceoryx2's own
/// cleanup of dead nodes is off in every domain: [`super::Domain::config`]). The segments
/// the dead left half made are removed first, whatever their age; the cleanup is put off
/// while a half-made segment of another port is young ([`super::cleanup::half_made_cleared`]).
pub(crate) fn cleanup_dead_nodes<P>(svc: &P, domain: &super::Domain)
where
    P: iceoryx2::service::port_factory::PortFactory<Service = iceoryx2::prelude::ipc::Service>,
{
    use iceoryx2::prelude::{CallbackProgression, NodeState};
    let group = matches!(domain.group(), Ok(Some(_)));
    let root = domain.root().ok();
    let mut dead = Vec::new();
    if let Err(e) = svc.nodes(|n| {
        if let NodeState::Dead(v) = n
            && (!group || root.is_some_and(|r| node_is_mine(r, v.id().value())))
        {
            dead.push(v);
        }
        CallbackProgression::Continue
    }) {
        tracing::warn!(error = %e, "cannot list the nodes of a service");
    }
    // Nobody dead, nothing to do; else not before iceoryx2 can open what they left.
    if dead.is_empty() {
        return;
    }
    if !super::cleanup::half_made_cleared(domain, &super::cleanup::ids_of(&dead)) {
        return;
    }
    if !group {
        svc.try_cleanup_dead_nodes();
        return;
    }
    super::cleanup::remove_stale(dead);
}

/// Removes the resources of the dead processes in `domain`, only this user's in group mode
/// (see [`cleanup_dead_nodes`]): what iceoryx2 would do when a node is created, with its own
/// cleanup off ([`super::Domain::after_join`] says when). Put off, as
/// [`cleanup_dead_nodes`], while a segment of another port is young and half made.
pub(crate) fn cleanup_domain_dead_nodes(domain: &super::Domain) {
    use iceoryx2::prelude::{CallbackProgression, Node, NodeState, ipc};
    // Resolved by the joining process before its node was made: these cannot fail here.
    let (Ok(config), Ok(root), Ok(group)) = (domain.config(), domain.root(), domain.group()) else {
        tracing::warn!(
            domain = domain.name(),
            "cannot clean up after the dead: the domain's files are not known"
        );
        return;
    };
    let only_mine = group.is_some();
    let mut dead = Vec::new();
    if let Err(e) = Node::<ipc::Service>::list(config, |n| {
        if let NodeState::Dead(v) = n
            && (!only_mine || node_is_mine(root, v.id().value()))
        {
            dead.push(v);
        }
        CallbackProgression::Continue
    }) {
        tracing::warn!(error = ?e, "cannot list the nodes of the domain");
    }
    // On every join, the dead or not: the old half-made segments go (as they always did).
    if !super::cleanup::half_made_cleared(domain, &super::cleanup::ids_of(&dead)) || dead.is_empty()
    {
        return;
    }
    super::cleanup::remove_stale(dead);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn port_ids_are_read_from_segment_names() {
        let p = "limber_0123456789abcdef_";
        let h = "b9fc73e5c1f646968758453273c6c65cb372831b";
        assert_eq!(
            port_ids(p, &format!("{p}{h}_12_34.connection")),
            Some(vec!["12", "34"])
        );
        assert_eq!(port_ids(p, &format!("{p}{h}_5.data")), Some(vec!["5"]));
        assert_eq!(port_ids(p, &format!("{p}{h}_5.dynamic")), None);
        assert_eq!(
            port_ids(p, &format!("{p}{h}_node.0_10_0.global_mgmt")),
            None
        );
        assert_eq!(port_ids("limber_other_", &format!("{p}{h}_5.data")), None);
    }
}
