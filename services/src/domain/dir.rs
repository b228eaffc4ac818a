//! Where a domain's files live, and who may touch them.
//!
//! iceoryx2 0.10 keeps a domain's files in two places: its root path (static service
//! configurations, node monitors, event sockets) and `/dev/shm` (segments, and one
//! `<prefix>…_node.0_10_0.global_mgmt` counter that it creates world-writable, mode 0666,
//! and never removes). With the default root path `/tmp/iceoryx2` and a prefix derived from
//! the domain name, any local user could create those files first or write into the
//! counter, and so stop every process of the domain from starting
//! (`UnableToGenerateUniqueNodeId`).
//!
//! limber therefore gives every owner a private directory of its own, the *runtime
//! directory* (`$LIMBER_RUNTIME_DIR`, else `/tmp/limber-<uid>`), created mode 0711 (others
//! may look up a name in it, never list, read or create) and refused when it belongs to
//! someone else. Each domain has a random token there
//! (`<domain>.token`, mode 0600, made once); the iceoryx2 prefix is `limber_<token>_`, so no
//! other user can predict the names in `/dev/shm`, and the iceoryx2 root path is
//! `<runtime>/iceoryx2/`, which nobody else can enter. Before a process joins, a
//! `global_mgmt` file of the domain owned by another user is refused; after it joined, the
//! counter's mode is narrowed from 0666 to 0600.
//!
//! **Group mode** (`LIMBER_GROUP=<group>`): several accounts of one Unix group share the
//! domains of a runtime directory of the group's (`$LIMBER_RUNTIME_DIR`, else
//! `/tmp/limber-g-<gid>`), mode 2770 and owned by the group, refused when it has another
//! group or mode, or when this user is not in the group. iceoryx2 0.10 creates every file
//! owner-only (0600 segments, 0400 static configurations, 0750 directories), so each
//! process of the group widens the domain's files *it owns* as soon as iceoryx2 has
//! finished them ([`super::group`]): segments and sockets 0660, static files 0440,
//! directories 2770, all of the group. Everyone outside the group stays locked out.

use std::fs;
use std::io::{self, Write};
use std::os::unix::fs::{DirBuilderExt, MetadataExt, OpenOptionsExt, PermissionsExt};
use std::path::{Path, PathBuf};

use thiserror::Error;

/// The environment variable that names the runtime directory (default `/tmp/limber-<uid>`,
/// in group mode `/tmp/limber-g-<gid>`).
pub const RUNTIME_DIR_ENV: &str = "LIMBER_RUNTIME_DIR";
/// The environment variable that turns group mode on: the name (or number) of the Unix
/// group whose members share the domains (docs/guide/security.md).
pub const GROUP_ENV: &str = "LIMBER_GROUP";
/// Where POSIX shared memory lives on Linux.
/// Where iceoryx2 (and the wake words, [`crate::wake`]) keep a domain's shared memory.
pub(crate) const SHM_DIR: &str = "/dev/shm";
/// The suffix iceoryx2 gives its per-domain node counter.
const GLOBAL_MGMT_SUFFIX: &str = ".global_mgmt";

/// The domain's directory or files could not be made safe to use.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum DomainError {
    /// The runtime directory, the token or a shm file belongs to another user: limber will
    /// not use files someone else can change.
    #[error(
        "{path} belongs to {owner}, not to you ({me}): limber does not use files another user controls (they could read or deny your domain). Remove it (as root or as {owner}), or set LIMBER_RUNTIME_DIR to a directory of your own"
    )]
    ForeignOwner {
        /// The file or directory.
        path: PathBuf,
        /// Its owner, `name (uid N)`.
        owner: String,
        /// This process's user, `name (uid N)`.
        me: String,
    },
    /// `LIMBER_GROUP` names a group that does not exist.
    #[error(
        "LIMBER_GROUP names the group {0:?}, which does not exist: create it (groupadd {0}) and add its users (usermod -aG {0} USER), or unset LIMBER_GROUP"
    )]
    UnknownGroup(String),
    /// This user is not a member of the group of `LIMBER_GROUP`.
    #[error(
        "you ({me}) are not in group {group} (gid {gid}, LIMBER_GROUP): only its members share its domains. Ask an administrator to run usermod -aG {group} <your user> and log in again, or unset LIMBER_GROUP"
    )]
    NotInGroup {
        /// The group's name.
        group: String,
        /// The group's id.
        gid: u32,
        /// This process's user, `name (uid N)`.
        me: String,
    },
    /// In group mode, a directory or file that is not the group's: another group, a mode
    /// others can use, or a file neither ours nor the group's.
    #[error(
        "{path} (owner {owner}, group {file_group}, mode {mode:o}) is not {group}'s: in group mode limber only uses {what}. Remove it (as root or as its owner), or set LIMBER_RUNTIME_DIR to a directory of the group's"
    )]
    NotTheGroups {
        /// The file or directory.
        path: PathBuf,
        /// Its owner, `name (uid N)`.
        owner: String,
        /// Its group, `name (gid N)`.
        file_group: String,
        /// Its mode.
        mode: u32,
        /// The group of `LIMBER_GROUP`, `name (gid N)`.
        group: String,
        /// What would have been accepted.
        what: &'static str,
    },
    /// The runtime directory is not a directory (a symbolic link, a file).
    #[error("{0} is not a directory (a symbolic link or a file): limber will not follow it")]
    NotADirectory(PathBuf),
    /// `/dev/shm` has less room than a driver needs: its segments would fail later with
    /// SIGBUS when first touched, so a driver refuses to start instead.
    #[error(
        "/dev/shm has {free} bytes free, a driver needs at least {need}: make it larger (e.g. docker run --shm-size=64m, or mount -o remount,size=64m /dev/shm)"
    )]
    ShmTooSmall {
        /// Free bytes.
        free: u64,
        /// Bytes a driver needs at least ([`MIN_SHM_FREE`]).
        need: u64,
    },
    /// The token file does not hold a token.
    #[error(
        "{0} does not hold a domain token (16 hexadecimal digits); remove it to make a new one"
    )]
    BadToken(PathBuf),
    /// A file or directory could not be created, read or given its mode.
    #[error("cannot {what} {path}: {source}")]
    Io {
        /// What was being done ("create", "read", "change the mode of", ...).
        what: &'static str,
        /// The file or directory.
        path: PathBuf,
        /// The error of the system.
        #[source]
        source: IoError,
    },
}

/// An [`io::Error`] that can be cloned and compared (by kind and raw OS code), kept as the
/// source of [`DomainError::Io`].
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[error("{message}")]
pub struct IoError {
    /// The kind.
    pub kind: io::ErrorKind,
    /// The raw OS error code, when there is one (`EACCES`, `ENOSPC`, `EROFS`, ...).
    pub raw_os_error: Option<i32>,
    message: String,
}

impl From<io::Error> for IoError {
    fn from(e: io::Error) -> Self {
        IoError {
            kind: e.kind(),
            raw_os_error: e.raw_os_error(),
            message: e.to_string(),
        }
    }
}

fn io_err<'a>(what: &'static str, path: &'a Path) -> impl FnOnce(io::Error) -> DomainError + 'a {
    move |e| DomainError::Io {
        what,
        path: path.to_path_buf(),
        source: e.into(),
    }
}

/// The effective user id of this process.
pub fn euid() -> u32 {
    rustix::process::geteuid().as_raw()
}

/// `name (uid N)` for a user id (the name from /etc/passwd, when it is there).
pub fn describe_user(uid: u32) -> String {
    let name = fs::read_to_string("/etc/passwd").ok().and_then(|p| {
        p.lines().find_map(|l| {
            let mut f = l.split(':');
            let name = f.next()?;
            let id: u32 = f.nth(1)?.parse().ok()?;
            (id == uid).then(|| name.to_string())
        })
    });
    match name {
        Some(n) => format!("user {n} (uid {uid})"),
        None => format!("uid {uid}"),
    }
}

/// The Unix group of group mode (`LIMBER_GROUP`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Group {
    /// Its name.
    pub name: String,
    /// Its id.
    pub gid: u32,
}

/// `name (gid N)` for a group id (the name from /etc/group, when it is there).
pub fn describe_group(gid: u32) -> String {
    match group_entries().into_iter().find(|(_, id)| *id == gid) {
        Some((n, _)) => format!("{n} (gid {gid})"),
        None => format!("gid {gid}"),
    }
}

/// The (name, gid) pairs of /etc/group.
fn group_entries() -> Vec<(String, u32)> {
    let Ok(text) = fs::read_to_string("/etc/group") else {
        return Vec::new();
    };
    text.lines()
        .filter_map(|l| {
            let mut f = l.split(':');
            let name = f.next()?;
            let gid: u32 = f.nth(1)?.parse().ok()?;
            Some((name.to_string(), gid))
        })
        .collect()
}

/// The group of group mode: `LIMBER_GROUP` (a name, or a number), None when unset. Refused
/// when the group does not exist or this user is not a member (root may use any group).
pub fn group_from_env() -> Result<Option<Group>, DomainError> {
    let Some(v) = std::env::var_os(GROUP_ENV).filter(|v| !v.is_empty()) else {
        return Ok(None);
    };
    let v = v.to_string_lossy().into_owned();
    let entries = group_entries();
    let found = entries
        .iter()
        .find(|(n, _)| *n == v)
        .or_else(|| {
            v.parse::<u32>()
                .ok()
                .and_then(|g| entries.iter().find(|(_, id)| *id == g))
        })
        .ok_or_else(|| DomainError::UnknownGroup(v.clone()))?;
    let group = Group {
        name: found.0.clone(),
        gid: found.1,
    };
    let gid = rustix::process::Gid::from_raw(group.gid);
    let member = euid() == 0
        || rustix::process::getegid() == gid
        || rustix::process::getgroups().is_ok_and(|gs| gs.contains(&gid));
    if !member {
        return Err(DomainError::NotInGroup {
            group: group.name,
            gid: group.gid,
            me: describe_user(euid()),
        });
    }
    Ok(Some(group))
}

/// The runtime directory of this process: `$LIMBER_RUNTIME_DIR`, else `/tmp/limber-<uid>`
/// (in group mode, `/tmp/limber-g-<gid>`: see [`runtime_dir_for`]).
pub fn runtime_dir() -> PathBuf {
    runtime_dir_for(group_from_env().ok().flatten().as_ref())
}

/// The runtime directory for a group (None: this user's own).
pub fn runtime_dir_for(group: Option<&Group>) -> PathBuf {
    match std::env::var_os(RUNTIME_DIR_ENV) {
        Some(v) if !v.is_empty() => PathBuf::from(v),
        _ => match group {
            Some(g) => PathBuf::from(format!("/tmp/limber-g-{}", g.gid)),
            None => PathBuf::from(format!("/tmp/limber-{}", euid())),
        },
    }
}

/// The room in `/dev/shm` a driver needs at least: the Pioneer driver's segments take about
/// 4 MiB (they are sparse, so a smaller tmpfs accepts them and the process dies with SIGBUS
/// later); this leaves room for its clients.
pub const MIN_SHM_FREE: u64 = 8 << 20;

/// Refuses to go on when `/dev/shm` has less than [`MIN_SHM_FREE`] bytes free.
pub fn check_shm_space() -> Result<(), DomainError> {
    let path = Path::new(SHM_DIR);
    let st = rustix::fs::statvfs(path).map_err(|e| io_err("inspect", path)(e.into()))?;
    let free = st.f_bavail.saturating_mul(st.f_frsize);
    if free < MIN_SHM_FREE {
        return Err(DomainError::ShmTooSmall {
            free,
            need: MIN_SHM_FREE,
        });
    }
    Ok(())
}

/// What joining a domain needs: where iceoryx2 keeps its files and the prefix of its names.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DomainFiles {
    /// The iceoryx2 root path (`<runtime>/iceoryx2/`), with a trailing slash.
    pub root: PathBuf,
    /// The iceoryx2 prefix (`limber_<token>_`).
    pub prefix: String,
    /// The group sharing the domain (group mode), or None.
    pub group: Option<Group>,
}

fn foreign(path: &Path, uid: u32) -> DomainError {
    DomainError::ForeignOwner {
        path: path.to_path_buf(),
        owner: describe_user(uid),
        me: describe_user(euid()),
    }
}

/// Makes sure `dir` is a directory of ours that others can neither list nor change
/// (creating it with `mode` if missing, narrowing its mode to `mode` if it is ours and wider).
fn private_dir(dir: &Path, mode: u32) -> Result<(), DomainError> {
    match fs::DirBuilder::new().mode(mode).create(dir) {
        Ok(()) => {}
        Err(e) if e.kind() == io::ErrorKind::AlreadyExists => {}
        Err(e) => return Err(io_err("create", dir)(e)),
    }
    let md = fs::symlink_metadata(dir).map_err(io_err("inspect", dir))?;
    if !md.file_type().is_dir() {
        return Err(DomainError::NotADirectory(dir.to_path_buf()));
    }
    if md.uid() != euid() {
        return Err(foreign(dir, md.uid()));
    }
    if md.mode() & 0o7777 != mode {
        tracing::warn!(dir = %dir.display(), mode = format!("{:o}", md.mode() & 0o7777), "setting the mode of a runtime directory to {mode:o}");
        fs::set_permissions(dir, fs::Permissions::from_mode(mode))
            .map_err(io_err("change the mode of", dir))?;
    }
    Ok(())
}

/// The mode of a group's directories: rwx for owner and group, setgid (new files and
/// directories in it get the group).
pub const GROUP_DIR_MODE: u32 = 0o2770;

fn not_the_groups(
    path: &Path,
    md: &fs::Metadata,
    group: &Group,
    what: &'static str,
) -> DomainError {
    DomainError::NotTheGroups {
        path: path.to_path_buf(),
        owner: describe_user(md.uid()),
        file_group: describe_group(md.gid()),
        mode: md.mode() & 0o7777,
        group: describe_group(group.gid),
        what,
    }
}

/// Makes sure `dir` is a directory of `group`, mode 2770 (creating it if missing; fixing
/// the group and mode when it is ours). One of another group, or that others can use, is
/// refused: it could have been planted.
fn group_dir(dir: &Path, group: &Group) -> Result<(), DomainError> {
    const WHAT: &str = "directories of the group, mode 2770";
    match fs::DirBuilder::new().mode(0o700).create(dir) {
        Ok(()) => {}
        Err(e) if e.kind() == io::ErrorKind::AlreadyExists => {}
        Err(e) => return Err(io_err("create", dir)(e)),
    }
    let md = fs::symlink_metadata(dir).map_err(io_err("inspect", dir))?;
    if !md.file_type().is_dir() {
        return Err(DomainError::NotADirectory(dir.to_path_buf()));
    }
    let right = md.gid() == group.gid && md.mode() & 0o7777 == GROUP_DIR_MODE;
    if right {
        return Ok(());
    }
    if md.uid() != euid() {
        return Err(not_the_groups(dir, &md, group, WHAT));
    }
    if md.gid() != group.gid {
        rustix::fs::chown(dir, None, Some(rustix::fs::Gid::from_raw(group.gid)))
            .map_err(|e| io_err("change the group of", dir)(e.into()))?;
    }
    fs::set_permissions(dir, fs::Permissions::from_mode(GROUP_DIR_MODE))
        .map_err(io_err("change the mode of", dir))?;
    Ok(())
}

/// Whether a file found in a domain may be used: ours, or (group mode) the group's and not
/// writable by others.
fn trusted(md: &fs::Metadata, group: Option<&Group>) -> bool {
    md.uid() == euid() || group.is_some_and(|g| md.gid() == g.gid && md.mode() & 0o002 == 0)
}

/// A file found in a domain (`path`, its metadata `md`) that may be used ([`trusted`]), or
/// the error that says whose it is.
pub(crate) fn check_trusted(
    path: &Path,
    md: &fs::Metadata,
    group: Option<&Group>,
) -> Result<(), DomainError> {
    if trusted(md, group) {
        Ok(())
    } else {
        Err(untrusted(path, md, group))
    }
}

/// The error for a file that is not [`trusted`].
fn untrusted(path: &Path, md: &fs::Metadata, group: Option<&Group>) -> DomainError {
    match group {
        Some(g) => not_the_groups(path, md, g, "files of its members"),
        None => foreign(path, md.uid()),
    }
}

fn new_token() -> Result<String, DomainError> {
    let mut bytes = [0u8; 8];
    let path = Path::new("/dev/urandom");
    let mut f = fs::File::open(path).map_err(io_err("read", path))?;
    io::Read::read_exact(&mut f, &mut bytes).map_err(io_err("read", path))?;
    Ok(bytes.iter().map(|b| format!("{b:02x}")).collect())
}

fn valid_token(t: &str) -> bool {
    t.len() == 16 && t.bytes().all(|b| b.is_ascii_hexdigit())
}

/// The token of `domain` in `dir`, made on first use (several processes may race: one wins,
/// all read its token).
fn token(dir: &Path, domain: &str, group: Option<&Group>) -> Result<String, DomainError> {
    let path = dir.join(format!("{domain}.token"));
    if fs::symlink_metadata(&path).is_err() {
        let token = new_token()?;
        // Unique to this attempt (several threads of a process may race too).
        let tmp = dir.join(format!(".{domain}.token.{}.{token}", std::process::id()));
        let mut f = fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .mode(0o600)
            .open(&tmp)
            .map_err(io_err("create", &tmp))?;
        f.write_all(format!("{token}\n").as_bytes())
            .map_err(io_err("write", &tmp))?;
        if let Some(g) = group {
            // The members read it; it has the group of the (setgid) directory already.
            rustix::fs::fchown(&f, None, Some(rustix::fs::Gid::from_raw(g.gid)))
                .map_err(|e| io_err("change the group of", &tmp)(e.into()))?;
            f.set_permissions(fs::Permissions::from_mode(0o640))
                .map_err(io_err("change the mode of", &tmp))?;
        }
        drop(f);
        // link(2) does not replace: the first process to make the token wins.
        let linked = fs::hard_link(&tmp, &path);
        if let Err(e) = fs::remove_file(&tmp) {
            tracing::debug!(path = %tmp.display(), error = %e, "cannot remove the temporary token file");
        }
        match linked {
            Ok(()) => {}
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => {}
            Err(e) => return Err(io_err("create", &path)(e)),
        }
    }
    read_token(path, group)
}

/// The token in the token file `path`, refused when it is not a file of ours (or, in group
/// mode, of the group's) holding a token.
fn read_token(path: PathBuf, group: Option<&Group>) -> Result<String, DomainError> {
    let md = fs::symlink_metadata(&path).map_err(io_err("inspect", &path))?;
    if !md.file_type().is_file() {
        return Err(DomainError::BadToken(path));
    }
    check_trusted(&path, &md, group)?;
    let text = fs::read_to_string(&path).map_err(io_err("read", &path))?;
    let t = text.trim();
    if !valid_token(t) {
        return Err(DomainError::BadToken(path));
    }
    Ok(t.to_string())
}

/// Prepares the files of `domain` for this process (see the module documentation):
/// the private runtime directory, the domain's token, and a check that no file of the
/// domain in `/dev/shm` belongs to someone else.
///
/// In group mode (`LIMBER_GROUP`) the runtime directory and the iceoryx2 root are the
/// group's (2770); iceoryx2's `services` and `nodes` directories are made here, the group's
/// too, so that every member can create its files there.
pub fn prepare(domain: &str) -> Result<DomainFiles, DomainError> {
    let group = group_from_env()?;
    let dir = runtime_dir_for(group.as_ref());
    let iox = dir.join("iceoryx2");
    match &group {
        None => private_dir(&dir, 0o711)?,
        Some(g) => group_dir(&dir, g)?,
    }
    let token = token(&dir, domain, group.as_ref())?;
    let prefix = format!("limber_{token}_");
    check_shm(&prefix, group.as_ref())?;
    match &group {
        None => private_dir(&iox, 0o700)?,
        Some(g) => {
            group_dir(&iox, g)?;
            group_dir(&iox.join("services"), g)?;
            group_dir(&iox.join("nodes"), g)?;
        }
    }
    let mut root = iox.into_os_string();
    root.push("/");
    Ok(DomainFiles {
        root: PathBuf::from(root),
        prefix,
        group,
    })
}

/// Where the files of `domain` are, when it has any: like [`prepare`], but creates nothing
/// (None: the domain has no token, so no file of it exists).
pub fn existing(domain: &str) -> Result<Option<DomainFiles>, DomainError> {
    let group = group_from_env()?;
    let dir = runtime_dir_for(group.as_ref());
    let path = dir.join(format!("{domain}.token"));
    if fs::symlink_metadata(&path).is_err() {
        return Ok(None);
    }
    let token = read_token(path, group.as_ref())?;
    let mut root = dir.join("iceoryx2").into_os_string();
    root.push("/");
    Ok(Some(DomainFiles {
        root: PathBuf::from(root),
        prefix: format!("limber_{token}_"),
        group,
    }))
}

/// The names of the domains that have files in this process's runtime directory (each has
/// a token there), sorted. None when the directory does not exist; a directory that is not
/// ours (or, in group mode, the group's) is refused, as [`prepare`] refuses it.
pub fn domain_names() -> Result<Vec<String>, DomainError> {
    let group = group_from_env()?;
    let dir = runtime_dir_for(group.as_ref());
    let md = match fs::symlink_metadata(&dir) {
        Ok(md) => md,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(io_err("inspect", &dir)(e)),
    };
    if !md.file_type().is_dir() {
        return Err(DomainError::NotADirectory(dir));
    }
    check_trusted(&dir, &md, group.as_ref())?;
    let mut names: Vec<String> = fs::read_dir(&dir)
        .map_err(io_err("list", &dir))?
        .map(|e| e.map_err(io_err("list", &dir)))
        .collect::<Result<Vec<_>, _>>()?
        .into_iter()
        .filter_map(|e| {
            let name = e.file_name().into_string().ok()?;
            let domain = name.strip_suffix(".token")?;
            crate::naming::valid_ident(domain, crate::naming::MAX_DOMAIN_LEN)
                .then(|| domain.to_string())
        })
        .collect();
    names.sort();
    Ok(names)
}

/// Every file of the domain named `domain` whose files are `files`, as found now: its
/// segments in `/dev/shm`, its event sockets under the iceoryx2 root, its static service
/// configurations under `services/`, the files of its nodes under `nodes/<id>/` and those
/// directories themselves (listed after their files), the nodes' monitors in `nodes/`, and
/// its token last. Only names with
/// the domain's prefix are listed (a node directory, named by the node's id, when the
/// files in it have the prefix), so no other domain's file is ever among them.
pub fn files_of(domain: &str, files: &DomainFiles) -> Vec<PathBuf> {
    let prefix = files.prefix.as_str();
    let with_prefix = |dir: &Path| -> Vec<PathBuf> {
        entries(dir)
            .into_iter()
            .filter(|e| e.file_name().to_string_lossy().starts_with(prefix))
            .map(|e| e.path())
            .collect()
    };
    let mut out = with_prefix(Path::new(SHM_DIR));
    out.extend(with_prefix(&files.root));
    out.extend(with_prefix(&files.root.join("services")));
    let nodes = files.root.join("nodes");
    for node in entries(&nodes) {
        if node.file_type().is_ok_and(|t| t.is_dir()) {
            let ours = with_prefix(&node.path());
            if !ours.is_empty() {
                out.extend(ours);
                out.push(node.path());
            }
        }
    }
    // The nodes' monitors, after their directories.
    out.extend(with_prefix(&nodes));
    let token = files
        .root
        .parent()
        .map(|rt| rt.join(format!("{domain}.token")));
    out.extend(token.filter(|t| fs::symlink_metadata(t).is_ok()));
    out
}

/// The entries of `dir`: none when it does not exist; one that cannot be read is logged
/// and left out (its files stay behind rather than the cleanup failing).
pub(crate) fn entries(dir: &Path) -> Vec<fs::DirEntry> {
    let rd = match fs::read_dir(dir) {
        Ok(rd) => rd,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Vec::new(),
        Err(e) => {
            tracing::warn!(dir = %dir.display(), error = %e, "cannot list a directory of the domain's files");
            return Vec::new();
        }
    };
    rd.filter_map(|e| {
        e.inspect_err(|e| {
            tracing::warn!(dir = %dir.display(), error = %e, "cannot read an entry of a directory of the domain's files");
        })
        .ok()
    })
    .collect()
}

/// The `global_mgmt` files of the domain with `prefix` in `/dev/shm`.
fn global_mgmt_files(prefix: &str) -> Vec<PathBuf> {
    let Ok(rd) = fs::read_dir(SHM_DIR) else {
        return Vec::new();
    };
    rd.filter_map(Result::ok)
        .filter(|e| {
            let n = e.file_name();
            let n = n.to_string_lossy();
            n.starts_with(prefix) && n.ends_with(GLOBAL_MGMT_SUFFIX)
        })
        .map(|e| e.path())
        .collect()
}

/// Refuses a `global_mgmt` file of the domain that belongs to another user (in group mode:
/// that is neither ours nor the group's).
///
/// In group mode, a counter another member's process has just made (0666, of that member's
/// own group) is given the instant that process needs to open it to the group (at most
/// [`COUNTER_WAIT`]).
fn check_shm(prefix: &str, group: Option<&Group>) -> Result<(), DomainError> {
    for path in global_mgmt_files(prefix) {
        let deadline = std::time::Instant::now() + COUNTER_WAIT;
        loop {
            let md = fs::symlink_metadata(&path).map_err(io_err("inspect", &path))?;
            if trusted(&md, group) {
                break;
            }
            let fresh = group.is_some() && md.mode() & 0o777 == 0o666;
            if !fresh || std::time::Instant::now() >= deadline {
                return Err(untrusted(&path, &md, group));
            }
            std::thread::sleep(std::time::Duration::from_millis(5));
        }
    }
    Ok(())
}

/// How long, in group mode, a node counter just made by another member may take to be
/// opened to the group ([`check_shm`]).
const COUNTER_WAIT: std::time::Duration = std::time::Duration::from_secs(1);

/// Narrows the mode of the domain's `global_mgmt` files of ours to 0600 (iceoryx2 makes
/// them 0666); in group mode to 0660, of the group. Called after the node was created.
pub fn secure_shm(prefix: &str, group: Option<&Group>) -> Result<(), DomainError> {
    for path in global_mgmt_files(prefix) {
        let md = fs::symlink_metadata(&path).map_err(io_err("inspect", &path))?;
        if md.uid() != euid() {
            if trusted(&md, group) {
                continue;
            }
            return Err(untrusted(&path, &md, group));
        }
        let mode = if group.is_some() { 0o660 } else { 0o600 };
        if let Some(g) = group
            && md.gid() != g.gid
        {
            rustix::fs::chown(&path, None, Some(rustix::fs::Gid::from_raw(g.gid)))
                .map_err(|e| io_err("change the group of", &path)(e.into()))?;
        }
        if md.mode() & 0o777 != mode {
            fs::set_permissions(&path, fs::Permissions::from_mode(mode))
                .map_err(io_err("change the mode of", &path))?;
        }
    }
    Ok(())
}

/// Other users on this machine whose runtime directory (`/tmp/limber-<uid>`) holds a domain
/// named `domain`, as `user NAME (uid N)` (a runtime directory elsewhere is not seen).
pub fn other_owners(domain: &str) -> Vec<String> {
    let mut out = Vec::new();
    let Ok(rd) = fs::read_dir("/tmp") else {
        return out;
    };
    for e in rd.filter_map(Result::ok) {
        let name = e.file_name();
        let Some(uid) = name
            .to_str()
            .and_then(|n| n.strip_prefix("limber-"))
            .and_then(|u| u.parse::<u32>().ok())
        else {
            continue;
        };
        if uid == euid() {
            continue;
        }
        if fs::symlink_metadata(e.path().join(format!("{domain}.token"))).is_ok() {
            out.push(describe_user(uid));
        }
    }
    out
}

/// Empty, or `"; domain D also exists for user NAME (uid N): its devices are theirs
/// alone ..."` when other users have a domain of this name ([`other_owners`]).
pub fn elsewhere_note(domain: &str) -> String {
    let others = other_owners(domain);
    if others.is_empty() {
        return String::new();
    }
    format!(
        "; domain {domain} also exists for {}: a domain's devices are its owner's alone, so run as that user (docs/guide/security.md)",
        others.join(", ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tokens_are_hex_and_checked() {
        let t = new_token().unwrap();
        assert!(valid_token(&t), "{t}");
        assert!(!valid_token("xyz"));
        assert!(!valid_token("0123456789abcdeg"));
    }

    #[test]
    fn threads_racing_to_make_a_token_all_get_the_same_one() {
        let dir = std::env::temp_dir().join(format!("limber-race-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        private_dir(&dir, 0o711).unwrap();
        let tokens: Vec<String> = (0..8)
            .map(|_| {
                let d = dir.clone();
                std::thread::spawn(move || token(&d, "raced", None).unwrap())
            })
            .collect::<Vec<_>>()
            .into_iter()
            .map(|t| t.join().unwrap())
            .collect();
        assert!(tokens.iter().all(|t| t == &tokens[0]), "{tokens:?}");
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn the_token_is_made_once_and_kept() {
        let dir = std::env::temp_dir().join(format!("limber-tok-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        private_dir(&dir, 0o711).unwrap();
        assert_eq!(
            fs::metadata(&dir).unwrap().mode() & 0o777,
            0o711,
            "a new runtime directory is private"
        );
        let a = token(&dir, "d", None).unwrap();
        let b = token(&dir, "d", None).unwrap();
        assert_eq!(a, b);
        assert_ne!(a, token(&dir, "e", None).unwrap());
        let md = fs::metadata(dir.join("d.token")).unwrap();
        assert_eq!(md.mode() & 0o777, 0o600);
        fs::write(dir.join("bad.token"), "nope").unwrap();
        assert!(matches!(
            token(&dir, "bad", None),
            Err(DomainError::BadToken(_))
        ));
        fs::set_permissions(&dir, fs::Permissions::from_mode(0o755)).unwrap();
        private_dir(&dir, 0o711).unwrap();
        assert_eq!(
            fs::metadata(&dir).unwrap().mode() & 0o777,
            0o711,
            "narrowed"
        );
        fs::remove_dir_all(&dir).unwrap();
    }
}
