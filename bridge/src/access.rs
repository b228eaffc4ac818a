//! Who may reach a bridge, and who each remote client is.
//!
//! **Identity comes from the transport, never from the message.** A remote client's
//! identity, its *principal*, is what Zenoh's authentication established for the session it
//! came through: the user name of Zenoh's user/password authentication, or the common name
//! of the certificate a TLS client presented (`enable_mtls`). On the private Unix socket
//! that `expose` listens on by default, the principal is [`LOCAL_PRINCIPAL`]: only the
//! owner of the runtime directory (and root) can open that socket.
//!
//! The exposing bridge turns the principals it accepts into Zenoh access-control rules
//! ([`expose_acl`]): principal `P` may only put commands on `limber/*/*/*/cmd/P/*`, send
//! requests and lease requests on `.../req/P/*` and `.../lease/P/*`, and it alone receives
//! `.../outcome/P/**`; every principal may read states, liveliness and statistics; nobody
//! may put a state, a liveliness token or anything else. Zenoh enforces these rules on the
//! session's face, so the `P` in a key `expose` receives *is* the authenticated principal,
//! and the driver's leases, held by `expose`'s client ids per (principal, session, remote
//! client), belong to that principal. The last chunk (the mirror's session id) only tells
//! two sessions of one principal apart: they hold the same credentials, so they are the same
//! party, and may act for each other.
//!
//! **A listener others can reach needs credentials** ([`check_listeners`]): TCP (loopback
//! included, where every local user can connect) needs Zenoh's user/password dictionary, TLS
//! needs client certificates or that dictionary. Only a Unix socket listener goes without:
//! the default one is in a directory of the runtime directory that only its owner (in
//! group mode, the group) may enter ([`private_socket`]).

use std::fs;
use std::os::unix::fs::{DirBuilderExt, MetadataExt, PermissionsExt};
use std::path::{Path, PathBuf};

use thiserror::Error;
use zenoh::Config;

use crate::keys::{ROOT, valid_chunk};

/// The principal of the sessions that come through a Unix socket listener.
pub const LOCAL_PRINCIPAL: &str = "local";

/// A listener or principal was refused.
#[derive(Debug, Error)]
pub enum AccessError {
    /// A listener that others can reach, without credentials.
    #[error(
        "refusing to listen on {endpoint} without credentials: anybody who reaches it (every local user, on loopback too) could command the arm. Use the default listener (a Unix socket only you can open), or give --zenoh-config with Zenoh's user/password authentication (transport/auth/usrpwd with a dictionary_file) or, on tls/, client certificates (transport/link/tls/enable_mtls); docs/guide/security.md"
    )]
    Unauthenticated {
        /// The endpoint.
        endpoint: String,
    },
    /// A principal that cannot be one.
    #[error(
        "invalid peer name {name:?}: a user name or certificate common name of letters, digits, '_', '-' and '.' (not \"{LOCAL_PRINCIPAL}\", the owner's own socket)"
    )]
    BadPrincipal {
        /// The name.
        name: String,
    },
    /// The user/password dictionary could not be read.
    #[error("cannot read the user/password dictionary {path}: {source}")]
    Dictionary {
        /// The file.
        path: String,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// The domain's runtime directory could not be found.
    #[error(transparent)]
    RuntimeDir(#[from] limber_services::DomainError),
    /// The private socket's directory could not be made, or belongs to someone else.
    #[error("cannot use {path} for the bridge's private socket: {why}")]
    SocketDir {
        /// The directory.
        path: PathBuf,
        /// Why.
        why: String,
    },
}

/// A JSON string setting of `config`, if set.
fn setting(config: &Config, key: &str) -> Option<String> {
    let v = config.get_json(key).ok()?;
    let v = v.trim();
    (v != "null").then(|| v.trim_matches('"').to_string())
}

/// Whether `config` authenticates connecting peers with user/password.
fn has_dictionary(config: &Config) -> bool {
    setting(config, "transport/auth/usrpwd/dictionary_file").is_some()
}

/// Whether `config` asks TLS clients for a certificate.
fn has_mtls(config: &Config) -> bool {
    setting(config, "transport/link/tls/enable_mtls").as_deref() == Some("true")
}

/// The protocol of a Zenoh endpoint (`tcp/...` -> `tcp`).
fn protocol(endpoint: &str) -> &str {
    endpoint.split('/').next().unwrap_or("")
}

/// Refuses every listener of `listen` that others can reach without credentials in
/// `config` (see the module's text).
pub fn check_listeners(config: &Config, listen: &[String]) -> Result<(), AccessError> {
    for endpoint in listen {
        let ok = match protocol(endpoint) {
            "unixsock-stream" => true,
            "tls" => has_mtls(config) || has_dictionary(config),
            _ => has_dictionary(config),
        };
        if !ok {
            return Err(AccessError::Unauthenticated {
                endpoint: endpoint.clone(),
            });
        }
    }
    Ok(())
}

/// The principals `expose` accepts: `peers`, and every user of `config`'s user/password
/// dictionary (one `user:password` per line).
pub fn principals(config: &Config, peers: &[String]) -> Result<Vec<String>, AccessError> {
    let mut out = Vec::new();
    for p in peers {
        if !valid_chunk(p) || p == LOCAL_PRINCIPAL {
            return Err(AccessError::BadPrincipal { name: p.clone() });
        }
        out.push(p.clone());
    }
    if let Some(path) = setting(config, "transport/auth/usrpwd/dictionary_file") {
        let text = fs::read_to_string(&path).map_err(|source| AccessError::Dictionary {
            path: path.clone(),
            source,
        })?;
        for user in text
            .lines()
            .filter_map(|l| l.split_once(':'))
            .map(|(u, _)| u)
        {
            if !valid_chunk(user) || user == LOCAL_PRINCIPAL {
                tracing::warn!(
                    user,
                    "a user of the dictionary whose name cannot be a principal: it may not command"
                );
                continue;
            }
            out.push(user.to_string());
        }
    }
    out.sort();
    out.dedup();
    Ok(out)
}

fn quoted(items: &[String]) -> String {
    let q: Vec<String> = items.iter().map(|s| format!("\"{s}\"")).collect();
    format!("[{}]", q.join(","))
}

fn rule(id: &str, flow: &str, messages: &[&str], keys: &[String]) -> String {
    let messages: Vec<String> = messages.iter().map(|m| m.to_string()).collect();
    format!(
        "{{id:\"{id}\",permission:\"allow\",flows:[\"{flow}\"],messages:{},key_exprs:{}}}",
        quoted(&messages),
        quoted(keys)
    )
}

/// The per-principal rules of `p`: its own commands, requests and lease requests in, its
/// own outcomes out.
fn principal_rules(p: &str, n: usize) -> [String; 2] {
    let own = |channel: &str| format!("{ROOT}/*/*/*/{channel}/{p}/*");
    [
        rule(
            &format!("in{n}"),
            "ingress",
            &["put", "query"],
            &[own("cmd"), own("req"), own("lease")],
        ),
        rule(
            &format!("out{n}"),
            "egress",
            &["put"],
            &[format!("{ROOT}/*/*/*/outcome/{p}/*")],
        ),
    ]
}

/// The Zenoh `access_control` setting (JSON5) of an exposing bridge that accepts
/// `principals` over authenticated links and [`LOCAL_PRINCIPAL`] over Unix sockets.
pub fn expose_acl(principals: &[String]) -> String {
    let all = format!("{ROOT}/**");
    let mut rules = vec![
        // Every accepted session may read: subscribe to states, outcomes, statistics and
        // liveliness, ask liveliness.
        rule(
            "read",
            "ingress",
            &[
                "declare_subscriber",
                "declare_liveliness_subscriber",
                "liveliness_query",
            ],
            std::slice::from_ref(&all),
        ),
        // What this bridge offers: states and statistics, its subscribers and queryables,
        // its liveliness tokens, its replies.
        rule(
            "offer",
            "egress",
            &[
                "declare_subscriber",
                "declare_queryable",
                "liveliness_token",
                "reply",
            ],
            std::slice::from_ref(&all),
        ),
        rule(
            "publish",
            "egress",
            &["put"],
            &[
                format!("{ROOT}/*/*/*/state"),
                format!("{ROOT}/*/driver/0/stats"),
            ],
        ),
    ];
    let mut subjects = vec![format!(
        "{{id:\"s_{LOCAL_PRINCIPAL}\",link_protocols:[\"unixsock-stream\"]}}"
    )];
    let mut policies = Vec::new();
    let everyone = ["\"read\"", "\"offer\"", "\"publish\""].join(",");
    let mut add = |n: usize, p: &str, subject_ids: Vec<String>, rules: &mut Vec<String>| {
        rules.extend(principal_rules(p, n));
        let ids: Vec<String> = subject_ids.iter().map(|s| format!("\"{s}\"")).collect();
        policies.push(format!(
            "{{id:\"p{n}\",rules:[{everyone},\"in{n}\",\"out{n}\"],subjects:[{}]}}",
            ids.join(",")
        ));
    };
    add(
        0,
        LOCAL_PRINCIPAL,
        vec![format!("s_{LOCAL_PRINCIPAL}")],
        &mut rules,
    );
    for (i, p) in principals.iter().enumerate() {
        let (u, c) = (format!("u{}", i + 1), format!("c{}", i + 1));
        subjects.push(format!("{{id:\"{u}\",usernames:[\"{p}\"]}}"));
        subjects.push(format!("{{id:\"{c}\",cert_common_names:[\"{p}\"]}}"));
        add(i + 1, p, vec![u, c], &mut rules);
    }
    format!(
        "{{enabled:true,default_permission:\"deny\",rules:[{}],subjects:[{}],policies:[{}]}}",
        rules.join(","),
        subjects.join(","),
        policies.join(",")
    )
}

/// The principal a mirror acts as: `given`, else the user of `config`'s user/password
/// authentication, else [`LOCAL_PRINCIPAL`] (a Unix socket).
pub fn mirror_principal(config: &Config, given: Option<&str>) -> Result<String, AccessError> {
    let name = match given {
        Some(g) => g.to_string(),
        None => setting(config, "transport/auth/usrpwd/user")
            .unwrap_or_else(|| LOCAL_PRINCIPAL.to_string()),
    };
    if !valid_chunk(&name) {
        return Err(AccessError::BadPrincipal { name });
    }
    Ok(name)
}

/// The directory of the bridges' private sockets in `runtime` (`<runtime>/bridge`), made
/// mode 0700 (2770 when the runtime directory is a group's, mode 2770: the group shares
/// its domains) and refused when another user owns it.
pub fn private_socket_dir(runtime: &Path) -> Result<PathBuf, AccessError> {
    let dir = runtime.join("bridge");
    let bad = |why: String| AccessError::SocketDir {
        path: dir.clone(),
        why,
    };
    let rt = fs::metadata(runtime).map_err(|e| bad(format!("its runtime directory: {e}")))?;
    let group = rt.mode() & 0o070 == 0o070;
    let mode = if group { 0o2770 } else { 0o700 };
    match fs::DirBuilder::new().mode(mode).create(&dir) {
        Ok(()) => {
            // The mode of a new directory is narrowed by the umask: set it.
            fs::set_permissions(&dir, fs::Permissions::from_mode(mode))
                .map_err(|e| bad(e.to_string()))?;
        }
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {}
        Err(e) => return Err(bad(e.to_string())),
    }
    let meta = fs::symlink_metadata(&dir).map_err(|e| bad(e.to_string()))?;
    if !meta.is_dir() || meta.uid() != rt.uid() {
        return Err(bad(format!(
            "it is not a directory of the runtime directory's owner (uid {}, not {})",
            meta.uid(),
            rt.uid()
        )));
    }
    if meta.mode() & 0o007 != 0 {
        return Err(bad(format!(
            "others may enter it (mode {:o})",
            meta.mode() & 0o7777
        )));
    }
    Ok(dir)
}

/// The default endpoint of domain `domain`'s exposing bridge: a Unix socket in the private
/// directory of `runtime` ([`private_socket_dir`]).
pub fn private_socket(runtime: &Path, domain: &str) -> Result<String, AccessError> {
    let dir = private_socket_dir(runtime)?;
    Ok(format!(
        "unixsock-stream/{}",
        dir.join(format!("{domain}.sock")).display()
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn config(json: &str) -> Config {
        let mut c = Config::default();
        for (k, v) in json.split(';').filter_map(|kv| kv.split_once('=')) {
            c.insert_json5(k, v).unwrap();
        }
        c
    }

    #[test]
    fn a_listener_others_reach_needs_credentials() {
        let none = Config::default();
        for e in ["tcp/127.0.0.1:7447", "tls/127.0.0.1:7447", "tcp/[::1]:1"] {
            assert!(matches!(
                check_listeners(&none, &[e.to_string()]),
                Err(AccessError::Unauthenticated { .. })
            ));
        }
        assert!(check_listeners(&none, &["unixsock-stream/tmp/x.sock".into()]).is_ok());
        let pw = config("transport/auth/usrpwd/dictionary_file=\"/nonexistent\"");
        assert!(check_listeners(&pw, &["tcp/127.0.0.1:1".into(), "tls/h:1".into()]).is_ok());
        let mtls = config("transport/link/tls/enable_mtls=true");
        assert!(check_listeners(&mtls, &["tls/127.0.0.1:1".into()]).is_ok());
        assert!(check_listeners(&mtls, &["tcp/127.0.0.1:1".into()]).is_err());
    }

    #[test]
    fn principals_are_names_never_wildcards() {
        let none = Config::default();
        for bad in ["", "*", "a/b", "**", "local", "a b", "$*"] {
            assert!(principals(&none, &[bad.to_string()]).is_err(), "{bad:?}");
        }
        assert_eq!(
            principals(&none, &["bob".into(), "alice".into(), "bob".into()]).unwrap(),
            vec!["alice".to_string(), "bob".to_string()]
        );
    }

    #[test]
    fn the_dictionarys_users_are_principals() {
        let dir = std::env::temp_dir().join(format!("limber-access-{}", std::process::id()));
        fs::create_dir_all(&dir).unwrap();
        let dict = dir.join("users.txt");
        fs::write(&dict, "robot:pw\nalice:x:y\n*:evil\n").unwrap();
        let c = config(&format!(
            "transport/auth/usrpwd/dictionary_file=\"{}\"",
            dict.display()
        ));
        assert_eq!(
            principals(&c, &[]).unwrap(),
            vec!["alice".to_string(), "robot".to_string()]
        );
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn the_acl_is_a_setting_zenoh_takes() {
        let mut c = Config::default();
        c.insert_json5(
            "access_control",
            &expose_acl(&["alice".into(), "bob".into()]),
        )
        .unwrap();
        let acl = c.get_json("access_control").unwrap();
        assert!(acl.contains("limber/*/*/*/cmd/alice/*"), "{acl}");
        assert!(acl.contains("limber/*/*/*/outcome/bob/*"), "{acl}");
    }

    #[test]
    fn the_private_socket_dir_is_the_owners_alone() {
        let rt = std::env::temp_dir().join(format!("limber-sock-{}", std::process::id()));
        fs::create_dir_all(&rt).unwrap();
        fs::set_permissions(&rt, fs::Permissions::from_mode(0o711)).unwrap();
        let e = private_socket(&rt, "robot").unwrap();
        assert!(e.starts_with("unixsock-stream/") && e.ends_with("/bridge/robot.sock"));
        let mode = fs::metadata(rt.join("bridge")).unwrap().mode() & 0o7777;
        assert_eq!(mode, 0o700);
        fs::set_permissions(rt.join("bridge"), fs::Permissions::from_mode(0o755)).unwrap();
        assert!(matches!(
            private_socket(&rt, "robot"),
            Err(AccessError::SocketDir { .. })
        ));
        fs::remove_dir_all(&rt).unwrap();
    }
}
