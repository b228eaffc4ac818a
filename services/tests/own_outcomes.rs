//! A client's own outcomes do not depend on anybody else's traffic: each client reads them on
//! a stream of its own (the `told` channel), which only its own commands fill.
//!
//! Before, every client read every outcome of the device on one `outcome` channel, 256
//! buffered per client: a client that did not look while others' commands were decided (a
//! CLI descheduled for ~10 ms beside a client sending 24 commands a millisecond) found its
//! own outcome overwritten and waited out its timeout (`limber-cli::ownership`'s contention
//! test, which failed the outside CI).

use std::time::Duration;

use limber_interfaces::prelude::*;
use limber_services::prelude::*;
use limber_services::testing::TestArm;
use limber_services::{Channel, WaitError};

const T: Duration = Duration::from_secs(5);
const DEVICE: &str = "own/actarray/0";

fn host(domain: &Domain) -> (Context, DeviceHost<ActArray>) {
    let ctx = Context::new(domain, Role::Driver, "own").unwrap();
    let mut host = DeviceHost::<ActArray>::new(&ctx, &DEVICE.parse().unwrap(), "t").unwrap();
    host.state_mut().actuators_count = 2;
    host.publish().unwrap();
    (ctx, host)
}

#[test]
fn a_clients_outcome_outlives_any_number_of_other_clients_outcomes() {
    let domain = Domain::unique_for_test();
    let (_dctx, mut host) = host(&domain);
    let mut arm = TestArm::new(2);
    let cctx = Context::new(&domain, Role::Client, "own-clients").unwrap();
    let mut mine = ActArrayClient::connect_timeout(&cctx, DEVICE, T).unwrap();
    let mut flood = ActArrayClient::connect_timeout(&cctx, DEVICE, T).unwrap();

    let ticket = mine.move_to(0, 0.3).unwrap();
    host.process(&mut arm).unwrap();
    // While `mine` does not look, the other client's commands are decided: more than twice
    // as many as any buffer of the old shared channel held.
    let others = flood_decided(&mut flood, &mut host, &mut arm);
    assert_eq!(host.stats().commands, 1 + others as u64);
    // Old code: Timeout (its outcome overwritten by the others', and so were the states
    // that showed its command).
    assert_eq!(
        mine.wait_outcome(ticket, Duration::from_secs(2)).unwrap(),
        Status::Ok
    );
    // The flooding client's own buffer holds its latest outcomes; its oldest were
    // overwritten by its own, and are said missed, not waited for.
    let last = flood.move_to(1, 0.2).unwrap();
    host.process(&mut arm).unwrap();
    assert_eq!(flood.wait_outcome(last, T).unwrap(), Status::Ok);
    let first = limber_services::Ticket {
        seq: 1,
        receivers: 1,
    };
    assert!(matches!(
        flood.wait_outcome(first, T),
        Err(WaitError::Missed { .. })
    ));
}

/// `flood` sends more commands than any buffer of the old shared channel held (twice its
/// depth and a round more), each decided by `host` as it goes; returns how many.
fn flood_decided(
    flood: &mut ActArrayClient,
    host: &mut DeviceHost<ActArray>,
    arm: &mut TestArm,
) -> usize {
    let others = 2 * limber_services::qos::OUTCOME_BUFFER + limber_services::qos::CMD_BUFFER;
    let mut sent = 0;
    while sent < others {
        for _ in 0..limber_services::qos::CMD_BUFFER {
            flood.move_to(1, (sent % 10) as f64 * 0.01).unwrap();
            sent += 1;
        }
        while host.process(arm).unwrap().commands > 0 {}
    }
    sent
}

/// A driver of the test arm on a thread of this process until `stop`.
fn driver_thread(
    domain: &Domain,
    stop: &std::sync::Arc<std::sync::atomic::AtomicBool>,
) -> std::thread::JoinHandle<()> {
    let (domain, stop) = (domain.clone(), std::sync::Arc::clone(stop));
    std::thread::spawn(move || {
        let (_ctx, mut host) = host(&domain);
        let mut arm = TestArm::new(2);
        while !stop.load(std::sync::atomic::Ordering::Relaxed) {
            host.process(&mut arm).unwrap();
            std::thread::yield_now();
        }
    })
}

/// A driver that replaces another knows nothing of the streams its clients opened with the
/// one before: a client asks again when it finds its stream closed, and gets the outcomes
/// of the commands it sent meanwhile.
#[test]
fn a_client_of_a_restarted_driver_gets_its_outcomes_on_a_new_stream() {
    use std::sync::Arc;
    use std::sync::atomic::{AtomicBool, Ordering};
    let domain = Domain::unique_for_test();
    let stop = Arc::new(AtomicBool::new(false));
    let first = driver_thread(&domain, &stop);
    let cctx = Context::new(&domain, Role::Client, "own-restart").unwrap();
    let mut arm = ActArrayClient::connect_timeout(&cctx, DEVICE, T).unwrap();
    let t = arm.move_to(0, 0.2).unwrap();
    assert_eq!(arm.wait_outcome(t, T).unwrap(), Status::Ok);

    stop.store(true, Ordering::Relaxed);
    first.join().unwrap();
    let stop = Arc::new(AtomicBool::new(false));
    let second = driver_thread(&domain, &stop);
    // Another client holds the new driver's device: the client's command is refused as
    // LEASED, an outcome only its stream carries (a state shows the refusal without the
    // holder, and is not taken for the outcome). The new driver takes the command before
    // the client has a stream with it.
    let hctx = Context::new(&domain, Role::Client, "own-holder").unwrap();
    let mut holder = ActArrayClient::connect_timeout(&hctx, DEVICE, T).unwrap();
    holder.set_request_timeout(T);
    holder.acquire("holder", Duration::from_secs(30)).unwrap();
    let t = arm.move_to(0, 0.4).unwrap();
    let told = arm.wait_outcome_detail(t, T);
    stop.store(true, Ordering::Relaxed);
    second.join().unwrap();
    let told = told.unwrap();
    assert_eq!(told.status, Status::Leased);
    assert_eq!(told.other_client, holder.client_id());
}

const FORGE_ENV: &str = "LIMBER_TEST_FORGE_STREAM";

/// Run by `a_stream_asked_for_with_another_processs_client_id_gets_nothing` as a process of
/// its own (a no-op otherwise): asks the driver for the outcome stream of the victim whose
/// client id it was given, reports what it received, and holds its request until told.
#[test]
fn stream_forger_process() {
    let Ok(spec) = std::env::var(FORGE_ENV) else {
        return;
    };
    let (domain, victim) = spec.split_once(' ').unwrap();
    let domain = Domain::new(domain).unwrap();
    let ctx = Context::new(&domain, Role::Client, "mallory").unwrap();
    let device: DeviceName = DEVICE.parse().unwrap();
    let port = ctx
        .node()
        .service_builder(&device.service_name(Channel::Told))
        .request_response::<u64, OutcomeMsg>()
        .open()
        .unwrap()
        .client_builder()
        .create()
        .unwrap();
    let pending = port.send_copy(victim.parse().unwrap()).unwrap();
    println!("ASKED");
    // The parent has the victim's command decided, then closes our stdin.
    let mut line = String::new();
    let _ = std::io::stdin().read_line(&mut line);
    let mut got = 0;
    while let Ok(Some(_)) = pending.receive() {
        got += 1;
    }
    println!("RECEIVED {got}");
}

/// Who a stream is for comes from the transport: a process that asks for the outcome
/// stream of another process's client id receives none of that client's outcomes and does
/// not take the victim's stream from it.
#[test]
fn a_stream_asked_for_with_another_processs_client_id_gets_nothing() {
    use std::io::{BufRead, Write};
    let domain = Domain::unique_for_test();
    let (_dctx, mut host) = host(&domain);
    let mut arm = TestArm::new(2);
    let vctx = Context::new(&domain, Role::Client, "victim").unwrap();
    let mut victim = ActArrayClient::connect_timeout(&vctx, DEVICE, T).unwrap();
    let limber_services::testing::TestProcess {
        mut child, mut out, ..
    } = limber_services::testing::TestProcess::start(
        "stream_forger_process",
        FORGE_ENV,
        &format!("{} {}", domain.name(), victim.client_id()),
        "ASKED",
    );
    let mut line = String::new();
    // The driver meets the forged request (after the victim's own) when it sends the
    // victim's outcome.
    let ticket = victim.move_to(0, 0.4).unwrap();
    host.process(&mut arm).unwrap();
    assert_eq!(victim.wait_outcome(ticket, T).unwrap(), Status::Ok);
    let again = victim.move_to(0, 0.5).unwrap();
    host.process(&mut arm).unwrap();
    assert_eq!(victim.wait_outcome(again, T).unwrap(), Status::Ok);
    child.stdin.take().unwrap().write_all(b"\n").unwrap();
    let mut rest = String::new();
    loop {
        line.clear();
        if out.read_line(&mut line).unwrap() == 0 {
            break;
        }
        rest.push_str(&line);
    }
    assert!(child.wait().unwrap().success());
    assert!(rest.contains("RECEIVED 0"), "the forger's output: {rest}");
}

/// A bridge relays its remote clients' commands under client ids of its own process and
/// reads their outcomes on its process's stream: only the commands it relayed fill it.
/// Before, it read them on the shared `outcome` channel (256 deep), where a local client
/// flooding the device pushed them out, and the remote client waited out its timeout.
#[test]
fn a_relayed_commands_outcome_outlives_a_local_clients_flood() {
    let domain = Domain::unique_for_test();
    let (_dctx, mut host) = host(&domain);
    let mut arm = TestArm::new(2);
    let bctx = Context::new(&domain, Role::Client, "own-bridge").unwrap();
    let mut bridge = ActArrayClient::connect_timeout(&bctx, DEVICE, T).unwrap();
    assert!(bridge.relay_open_stream(true));
    let lctx = Context::new(&domain, Role::Client, "own-local").unwrap();
    let mut flood = ActArrayClient::connect_timeout(&lctx, DEVICE, T).unwrap();

    // A remote client's command, as the bridge relays it: a client id of the bridge's
    // process of its own.
    let remote = bctx.new_client_id();
    let mut cmd = ActArrayCmdMsg::default();
    ActArrayCommand::Position {
        joint: 0,
        position: 0.3,
    }
    .write(&mut cmd);
    cmd.meta_mut().client_id = remote;
    cmd.meta_mut().seq = 1;
    assert_eq!(bridge.relay_send(&cmd).unwrap(), 1);
    host.process(&mut arm).unwrap();
    // A local client's flood is decided before the bridge looks.
    flood_decided(&mut flood, &mut host, &mut arm);
    let mut got = Vec::new();
    bridge.relay_own_outcomes(|o| got.push(*o)).unwrap();
    // Exactly the relayed command's: none of the flood's, none of the bridge's own.
    assert_eq!(got.len(), 1, "{got:?}");
    assert_eq!((got[0].client_id, got[0].cmd_seq), (remote, 1));
    assert_eq!(got[0].status, Status::Ok.code());

    // The old way, the `outcome` channel, lost it under the same flood.
    bridge.watch_outcomes().unwrap();
    let remote2 = bctx.new_client_id();
    cmd.meta_mut().client_id = remote2;
    bridge.relay_send(&cmd).unwrap();
    host.process(&mut arm).unwrap();
    flood_decided(&mut flood, &mut host, &mut arm);
    let mut watched = Vec::new();
    bridge.relay_outcomes(|o| watched.push(*o)).unwrap();
    assert!(!watched.iter().any(|o| o.client_id == remote2));
    let mut got = Vec::new();
    bridge.relay_own_outcomes(|o| got.push(*o)).unwrap();
    // Its outcome, and the result of the first relayed command's motion, which it cut short
    // (told to that remote client as it would be to a local one).
    assert!(
        got.iter()
            .any(|o| o.client_id == remote2 && o.is_outcome() && o.status == Status::Ok.code()),
        "{got:?}"
    );
    assert!(
        got.iter()
            .all(|o| o.client_id == remote2 || (o.client_id == remote && o.other_client == remote2)),
        "{got:?}"
    );
}

/// The driver looks whether anybody watches the `outcome` channel when it looks at its
/// connections and with each state it publishes, not before every outcome (iceoryx2's count
/// writes a cache line every process of the service shares): a watcher that subscribes
/// between two commands of a spinning driver gets the outcomes from the driver's next
/// published state on.
#[test]
fn a_watcher_gets_the_outcomes_from_the_drivers_next_state_on() {
    let domain = Domain::unique_for_test();
    let (_dctx, mut host) = host(&domain);
    let mut arm = TestArm::new(2);
    let cctx = Context::new(&domain, Role::Client, "own-watched").unwrap();
    let mut mine = ActArrayClient::connect_timeout(&cctx, DEVICE, T).unwrap();
    let wctx = Context::new(&domain, Role::Client, "own-watcher").unwrap();
    let mut watcher = ActArrayClient::connect_timeout(&wctx, DEVICE, T).unwrap();
    let first = mine.move_to(0, 0.1).unwrap();
    host.process_spin(&mut arm).unwrap();
    assert_eq!(mine.wait_outcome(first, T).unwrap(), Status::Ok);

    watcher.watch_outcomes().unwrap();
    // The driver's tick: it publishes its state, and looks.
    host.publish().unwrap();
    let second = mine.move_to(0, 0.2).unwrap();
    // One spinning poll (which looks at the connections only every few polls).
    assert_eq!(host.process_spin(&mut arm).unwrap().commands, 1);
    assert_eq!(mine.wait_outcome(second, T).unwrap(), Status::Ok);
    let mut watched = Vec::new();
    watcher.relay_outcomes(|o| watched.push(*o)).unwrap();
    assert!(
        watched
            .iter()
            .any(|o| o.client_id == mine.client_id() && o.cmd_seq == second.seq && o.is_outcome()),
        "{watched:?}"
    );
}

/// An arm whose commands drive nothing that runs on (the default [`DeviceHandler::motion`]):
/// each command's result is decided when the driver carries it out.
struct Instant;

impl DeviceHandler<ActArray> for Instant {
    fn command(&mut self, cmd: &ActArrayCommand, _: &Origin, state: &mut ActArrayData) -> Status {
        match *cmd {
            ActArrayCommand::Position { joint: 0, position } => {
                state.actuators[0].position = position;
                Status::Ok
            }
            _ => Status::UnknownJoint,
        }
    }
    fn request(
        &mut self,
        _: &ActArrayRequest,
        _: &Origin,
        _: &mut ActArrayData,
    ) -> Result<ActArrayReply, Status> {
        Err(Status::Unsupported)
    }
}

/// A command whose result is decided when it is carried out gets one sample, its outcome
/// and its result at once (`also_outcome`), to its client and to the watchers: one send and
/// one wake-up less on its path. A refused one gets its outcome alone; a command whose
/// motion runs on, its outcome and later its result.
#[test]
fn a_command_decided_at_once_gets_one_sample_its_outcome_and_its_result() {
    let domain = Domain::unique_for_test();
    let (_dctx, mut host) = host(&domain);
    let cctx = Context::new(&domain, Role::Client, "own-instant").unwrap();
    let mut mine = ActArrayClient::connect_timeout(&cctx, DEVICE, T).unwrap();
    let wctx = Context::new(&domain, Role::Client, "own-instant-watcher").unwrap();
    let mut watcher = ActArrayClient::connect_timeout(&wctx, DEVICE, T).unwrap();
    watcher.watch_outcomes().unwrap();
    host.publish().unwrap();

    let ok = mine.move_to(0, 0.2).unwrap();
    let refused = mine.move_to(1, 0.2).unwrap();
    assert_eq!(host.process(&mut Instant).unwrap().commands, 2);
    assert_eq!(mine.wait_outcome(ok, T).unwrap(), Status::Ok);
    let done = mine.wait_done(ok, T).unwrap();
    assert_eq!(done.result(), MotionResult::Reached, "{done}");
    assert_eq!(mine.wait_outcome(refused, T).unwrap(), Status::UnknownJoint);

    let mut watched = Vec::new();
    watcher.relay_outcomes(|o| watched.push(*o)).unwrap();
    let of = |seq: u64| -> Vec<OutcomeMsg> {
        watched
            .iter()
            .filter(|o| o.client_id == mine.client_id() && o.cmd_seq == seq)
            .copied()
            .collect()
    };
    // Old code: two samples for `ok` (its outcome, then its result).
    let samples = of(ok.seq);
    assert_eq!(samples.len(), 1, "{samples:?}");
    let s = samples[0];
    assert!(s.is_outcome(), "{s:?}");
    assert_eq!(s.also_outcome, 1);
    assert_eq!(s.status, Status::Ok.code());
    assert_eq!(s.motion_result().unwrap(), Some(MotionResult::Reached));
    let samples = of(refused.seq);
    assert_eq!(samples.len(), 1, "{samples:?}");
    assert_eq!(samples[0].status, Status::UnknownJoint.code());
    assert_eq!(samples[0].motion_result().unwrap(), None);

    // A motion that runs on: its outcome now (no result in it), its result when it ends.
    let mut arm = TestArm::new(2);
    let moving = mine.move_at_speed(0, 0.5).unwrap();
    host.process(&mut arm).unwrap();
    assert_eq!(mine.wait_outcome(moving, T).unwrap(), Status::Ok);
    let mut watched = Vec::new();
    watcher.relay_outcomes(|o| watched.push(*o)).unwrap();
    let s = watched
        .iter()
        .find(|o| o.client_id == mine.client_id() && o.cmd_seq == moving.seq)
        .copied()
        .unwrap();
    assert!(
        s.is_outcome() && s.also_outcome == 0 && s.result == 0,
        "{s:?}"
    );
}
