//! Who may reach a bridge, and who a remote client is (docs/guide/security.md: "The bridge"):
//! a listener others reach needs credentials; another Unix user cannot open the owner's
//! socket; TLS with client certificates; a peer authenticated as one principal can forge
//! nothing of another's (commands, lease requests), and nothing of the robot's (states,
//! liveliness tokens); a mirror hosts a bounded number of devices.
//!
//! Every wait is bounded; the negative checks wait on evidence that the forged message
//! would have been handled by then (a later message of the same peer, on the same link,
//! that the bridge did answer).

use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

use limber_bounded_run::output_within;
use limber_interfaces::message::{Envelope, Message};
use limber_interfaces::prelude::*;
use limber_services::prelude::*;
use limber_tests::{Proc, usrpwd_config};
use zenoh::Wait;
use zerocopy::{FromBytes, IntoBytes};

mod bridging;
mod hostile;
use bridging::{
    CLI, arm_in, expose_with, free_port, mirror_with, mirrored_nothing, start_driver, wait_mirrored,
};
use hostile::{HOSTILE, Scratch, hostile_user};

const LIMIT: Duration = Duration::from_secs(30);

/// A scratch directory of this test process, removed when dropped.
struct Dir(std::path::PathBuf);

impl Dir {
    fn new(name: &str) -> Dir {
        let p = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
            .join(format!("access-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&p);
        std::fs::create_dir_all(&p).expect("a scratch directory");
        Dir(p)
    }
}

impl Drop for Dir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Runs the CLI in `domain` to its end; its exit code and stderr.
fn cli(domain: &Domain, args: &[&str]) -> (Option<i32>, String) {
    let mut c = Command::new(CLI);
    c.args(args).env("LIMBER_DOMAIN", domain.name());
    let out = output_within(&mut c, LIMIT);
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// `bridge expose` refuses a TCP or TLS listener without credentials (loopback included),
/// with exit 2 and what to do; `bridge mirror` needs to be told where to connect.
#[test]
fn a_listener_others_reach_needs_credentials() {
    let a = Domain::unique_for_test();
    for endpoint in [
        format!("tcp/127.0.0.1:{}", free_port()),
        format!("tls/127.0.0.1:{}", free_port()),
    ] {
        let (code, err) = cli(&a, &["bridge", "expose", "--listen", &endpoint]);
        assert_eq!(code, Some(2), "{endpoint}: {err}");
        assert!(
            err.contains("without credentials") && err.contains("--zenoh-config"),
            "{err}"
        );
    }
    let (code, err) = cli(&a, &["bridge", "mirror"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("--from DOMAIN"), "{err}");
    let (code, err) = cli(&a, &["bridge", "expose", "--peer", "*"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("invalid peer name"), "{err}");
}

/// Item 1 of the issue: another Unix user's mirror cannot open the owner's private socket,
/// so it mirrors nothing, while the owner's mirror, started after it, mirrors the arm.
#[test]
fn another_unix_user_cannot_reach_the_owners_bridge() {
    let Some(user) = hostile_user() else {
        return;
    };
    assert_eq!(user, HOSTILE);
    let a = Domain::unique_for_test();
    let _driver = start_driver(&a);
    let mut expose = Proc::spawn(CLI, a.name(), &["bridge", "expose"]);
    let ready = expose
        .read_until(|l| l.starts_with("exposing domain"))
        .expect("expose started");
    let endpoint = ready
        .split("listening on ")
        .nth(1)
        .and_then(|r| r.strip_suffix(')'))
        .expect("the endpoint in the line")
        .to_string();
    assert!(
        expose
            .read_until(|l| l == "exposed pioneer/actarray/0")
            .is_some()
    );
    let scratch = Scratch::new("bridge");
    let their_cli = scratch.cli(HOSTILE);
    let rt = scratch.0.join("rt");
    let mut c = Command::new("runuser");
    c.args([
        "-u",
        HOSTILE,
        "--",
        &their_cli,
        "bridge",
        "mirror",
        "--connect",
    ])
    .arg(&endpoint)
    .env("LIMBER_DOMAIN", "stolen")
    .env("LIMBER_RUNTIME_DIR", &rt)
    .current_dir(&scratch.0);
    let mut intruder = Proc::spawn_command(c);
    assert!(
        intruder
            .read_until(|l| l.starts_with("mirroring into"))
            .is_some(),
        "the other user's mirror did not start"
    );
    let b = Domain::unique_for_test();
    let mut mirror = Proc::spawn(CLI, b.name(), &["bridge", "mirror", "--from", a.name()]);
    wait_mirrored(&mut mirror);
    let mut arm = arm_in(&b);
    arm.geometry().expect("the owner's mirror serves the arm");
    mirrored_nothing(intruder);
}

/// Makes a CA, a certificate for the robot (`localhost`), one for the laptop (`laptop`)
/// and one for `laptop` signed by another CA, with `openssl`.
fn certificates(dir: &Path) {
    let run = |args: &str| {
        let out = output_within(
            Command::new("sh")
                .args(["-c", &format!("openssl {args}")])
                .current_dir(dir),
            LIMIT,
        );
        assert!(
            out.status.success(),
            "openssl {args}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    };
    for ca in ["ca", "other-ca"] {
        run(&format!(
            "req -x509 -newkey rsa:2048 -nodes -keyout {ca}.key -out {ca}.pem -days 2 -subj /CN={ca} -addext basicConstraints=critical,CA:TRUE -addext keyUsage=critical,keyCertSign,cRLSign"
        ));
    }
    std::fs::write(
        dir.join("ext.cnf"),
        "basicConstraints=CA:FALSE\nsubjectAltName=DNS:localhost,IP:127.0.0.1\nextendedKeyUsage=serverAuth,clientAuth\n",
    )
    .unwrap();
    for (name, cn, ca) in [
        ("robot", "localhost", "ca"),
        ("laptop", "laptop", "ca"),
        ("forged", "laptop", "other-ca"),
    ] {
        run(&format!(
            "req -newkey rsa:2048 -nodes -keyout {name}.key -out {name}.csr -subj /CN={cn}"
        ));
        run(&format!(
            "x509 -req -in {name}.csr -CA {ca}.pem -CAkey {ca}.key -CAcreateserial -out {name}.pem -days 2 -extfile ext.cnf"
        ));
    }
}

/// A Zenoh TLS configuration in `dir`: listening (the robot) or connecting as `cert`.
fn tls_config(dir: &Path, file: &str, cert: &str, listen: bool) -> String {
    let d = dir.display();
    let side = if listen { "listen" } else { "connect" };
    let text = format!(
        "{{ transport: {{ link: {{ tls: {{ root_ca_certificate: \"{d}/ca.pem\", {side}_certificate: \"{d}/{cert}.pem\", {side}_private_key: \"{d}/{cert}.key\", enable_mtls: true }} }} }} }}\n"
    );
    let path = dir.join(file);
    std::fs::write(&path, text).unwrap();
    path.display().to_string()
}

/// Item 5: TLS compiled in, with client certificates, as bridge/README.md sets it up: the
/// laptop's mirror (a certificate of the robot's CA, `--peer laptop`) moves the arm; a
/// mirror whose certificate another CA signed, started first, mirrors nothing.
#[test]
fn tls_with_client_certificates_lets_in_only_the_named_peer() {
    let dir = Dir::new("tls");
    certificates(&dir.0);
    let robot = tls_config(&dir.0, "robot-tls.json5", "robot", true);
    let laptop = tls_config(&dir.0, "laptop-tls.json5", "laptop", false);
    let forged = tls_config(&dir.0, "forged-tls.json5", "forged", false);
    let a = Domain::unique_for_test();
    let _driver = start_driver(&a);
    let port = free_port();
    let listen = format!("tls/127.0.0.1:{port}");
    let _expose = expose_with(
        &a,
        &[
            "--listen",
            &listen,
            "--zenoh-config",
            &robot,
            "--peer",
            "laptop",
        ],
    );
    let connect = format!("tls/localhost:{port}");
    let b_bad = Domain::unique_for_test();
    let intruder = mirror_with(
        &b_bad,
        &[
            "--connect",
            &connect,
            "--zenoh-config",
            &forged,
            "--as",
            "laptop",
        ],
    );
    let b = Domain::unique_for_test();
    let mut mirror = mirror_with(
        &b,
        &[
            "--connect",
            &connect,
            "--zenoh-config",
            &laptop,
            "--as",
            "laptop",
        ],
    );
    wait_mirrored(&mut mirror);
    let mut arm = arm_in(&b);
    let t = arm.move_to(1, 0.25).expect("send");
    assert_eq!(
        arm.wait_outcome(t, Duration::from_secs(10))
            .expect("outcome"),
        Status::Ok
    );
    mirrored_nothing(intruder);
}

/// A Zenoh session of the test's own, authenticated as `user` (user/password), connected
/// to `endpoint` only: the rogue peer of the issue.
fn rogue(endpoint: &str, config: &str) -> zenoh::Session {
    let mut c = zenoh::Config::from_file(config).expect("the rogue's configuration");
    for (key, value) in [
        ("mode", "\"peer\"".to_string()),
        ("connect/endpoints", format!("[\"{endpoint}\"]")),
        ("listen/endpoints", "[]".to_string()),
        ("scouting/multicast/enabled", "false".to_string()),
    ] {
        c.insert_json5(key, &value).unwrap();
    }
    zenoh::open(c).wait().expect("the rogue's session")
}

/// A POS command of client `client_id`, seq `seq`.
fn pos(client_id: u64, seq: u64, joint: i64, position: f64) -> ActArrayCmdMsg {
    let mut msg = ActArrayCmdMsg::default();
    ActArrayCommand::position(joint, position)
        .unwrap()
        .write(&mut msg);
    let m = msg.meta_mut();
    m.client_id = client_id;
    m.seq = seq;
    msg
}

/// Puts a POS under the rogue's own principal and waits for its outcome: everything the
/// rogue put before on its one link has been handled (or dropped) by then.
fn marker(s: &zenoh::Session, seq: u64) -> Status {
    let me = "mallory/m";
    let sub = s
        .declare_subscriber(format!("limber/pioneer/actarray/0/outcome/{me}"))
        .wait()
        .unwrap();
    let deadline = Instant::now() + LIMIT;
    // The subscription must reach the bridge before the outcome is put: resend until one
    // comes back (each is a new command, refused the same way while the arm is held).
    let mut n = seq;
    loop {
        s.put(
            format!("limber/pioneer/actarray/0/cmd/{me}"),
            pos(77, n, 3, 0.4).as_bytes().to_vec(),
        )
        .wait()
        .unwrap();
        if let Ok(Some(sample)) = sub.recv_timeout(Duration::from_millis(500)) {
            let o = OutcomeMsg::read_from_bytes(&sample.payload().to_bytes()).unwrap();
            return o.status().unwrap();
        }
        n += 1;
        assert!(
            Instant::now() < deadline,
            "the rogue's own command got no outcome"
        );
    }
}

/// Item 2: a peer authenticated as `mallory` forges, under principal `robot` (the mirror's,
/// which holds the arm): a POS (not carried out: joint 2 never moves), a lease RELEASE (no
/// answer; the holder's lease stays), a state with every joint at +1.2345 on `.../state`
/// (never shown in the mirror's domain) and 300 liveliness tokens of fake devices (none
/// hosted). Its own commands are refused "leased", naming the holder.
#[test]
fn a_rogue_peer_forges_no_command_lease_state_or_device() {
    let dir = Dir::new("rogue");
    let users = dir.0.join("users.txt");
    std::fs::write(&users, "robot:a long secret\nmallory:her own password\n").unwrap();
    let robot = usrpwd_config(
        &dir.0,
        "robot.json5",
        "robot",
        "a long secret",
        Some(&users),
    );
    let desk = usrpwd_config(&dir.0, "desk.json5", "robot", "a long secret", None);
    let mallory = usrpwd_config(&dir.0, "mallory.json5", "mallory", "her own password", None);

    let a = Domain::unique_for_test();
    let _driver = start_driver(&a);
    let endpoint = format!("tcp/127.0.0.1:{}", free_port());
    let _expose = expose_with(&a, &["--listen", &endpoint, "--zenoh-config", &robot]);
    let b = Domain::unique_for_test();
    let mut mirror = mirror_with(&b, &["--connect", &endpoint, "--zenoh-config", &desk]);
    wait_mirrored(&mut mirror);
    let mut holder = arm_in(&b);
    holder
        .acquire("desk", Duration::from_secs(5))
        .expect("the desk takes the arm through the bridges");
    let ctx_a = Context::new(&a, Role::Client, "watcher").unwrap();
    let mut watcher = ActArrayClient::connect_timeout(&ctx_a, "pioneer/actarray/0", LIMIT).unwrap();
    let j2_before = watcher.wait_state(LIMIT).unwrap().actuators[2].position;

    let s = rogue(&endpoint, &mallory);
    let rid = "limber/pioneer/actarray/0";
    // A POS as the holder's principal, with the ids it could guess.
    for client_id in 1..=16u64 {
        s.put(
            format!("{rid}/cmd/robot/x"),
            pos(client_id, 1, 2, j2_before + 0.8).as_bytes().to_vec(),
        )
        .wait()
        .unwrap();
    }
    // A RELEASE as the holder's principal: nobody answers it.
    let mut release = LeaseReq {
        op: lease_op::RELEASE,
        client_id: 1,
        ..LeaseReq::default()
    };
    release.seq = 1;
    let replies = s
        .get(format!("{rid}/lease/robot/x"))
        .payload(release.as_bytes().to_vec())
        .timeout(Duration::from_secs(2))
        .wait()
        .unwrap();
    assert!(
        replies.recv().is_err(),
        "a lease request under another principal was answered"
    );
    // A state of its own making.
    let mut fake = ActArrayData {
        actuators_count: 6,
        ..ActArrayData::default()
    };
    for a in fake.actuators.iter_mut().take(6) {
        a.position = 1.2345;
    }
    s.put(format!("{rid}/state"), fake.as_bytes().to_vec())
        .wait()
        .unwrap();
    // 300 fake devices.
    let tokens: Vec<_> = (0..300)
        .map(|i| {
            s.liveliness()
                .declare_token(format!("limber/evil{i}/actarray/0/alive"))
                .wait()
                .unwrap()
        })
        .collect();

    // Its own command, after all of the above on the same link: refused, the arm held.
    assert_eq!(marker(&s, 1), Status::Leased);
    let now = watcher.wait_state(LIMIT).unwrap();
    let j2 = now.actuators[2];
    assert!(
        (j2.position - j2_before).abs() < 0.02 && j2.state & ActuatorFlags::MOVING.bits() == 0,
        "the forged POS moved joint 2: {} (was {j2_before}), state {}",
        j2.position,
        j2.state
    );
    let seq_a = now.header.seq;
    holder.renew().expect("the holder's lease is still its own");
    // The mirror's states up to the driver's latest: none is the rogue's.
    loop {
        let st = holder.wait_state(LIMIT).expect("a mirrored state");
        assert!(
            st.actuators[..6].iter().all(|a| a.position != 1.2345),
            "the rogue's state reached the mirror's domain"
        );
        if st.header.seq >= seq_a {
            break;
        }
    }
    // A device that comes after the tokens is mirrored; none of the tokens' is.
    let _simarm = {
        let mut p = Proc::spawn(CLI, a.name(), &["simarm"]);
        assert!(p.read_until(|l| l.ends_with("ready")).is_some());
        p
    };
    let line = mirror
        .read_until_within(LIMIT, |l| {
            l.starts_with("mirrored simarm/") || l.contains("evil")
        })
        .expect("the mirror hosts simarm's devices");
    assert!(!line.contains("evil"), "{line}");
    drop(tokens);
    holder.release().expect("release");
    s.close().wait().unwrap();
}

/// A mirror hosts `--max-devices` devices at most, and says which it refused.
#[test]
fn a_mirror_hosts_a_bounded_number_of_devices() {
    let a = Domain::unique_for_test();
    let _driver = start_driver(&a);
    let mut expose = Proc::spawn(CLI, a.name(), &["bridge", "expose"]);
    assert!(
        expose
            .read_until(|l| l == "exposed pioneer/actarray/0")
            .is_some()
    );
    let b = Domain::unique_for_test();
    let mut mirror = Proc::spawn(
        CLI,
        b.name(),
        &["bridge", "mirror", "--from", a.name(), "--max-devices", "2"],
    );
    let mut hosted = 0;
    let refused = loop {
        let l = mirror
            .read_until(|l| l.starts_with("mirrored ") || l.starts_with("cannot mirror "))
            .expect("the mirror reports every device");
        if l.starts_with("mirrored ") {
            hosted += 1;
        } else {
            break l;
        }
    };
    assert_eq!(hosted, 2, "{refused}");
    assert!(
        refused.contains("hosts 2 devices at most (--max-devices)"),
        "{refused}"
    );
}
