//! `limber demo`: the main job. Starts a robot (the Pioneer emulator and driver, or the
//! simulated arm) and its world (a block at a seeded random place within reach, or where
//! `--block` says, and the laser) in this process and runs the paper's pick-a-block
//! program against it: the laser finds the block, the arm picks it up and puts it down,
//! each step shown with the live joint and gripper state, then where the laser found the
//! block against where it was.

use std::io::IsTerminal;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use clap::{Args, ValueEnum};
use limber_examples::pick_block::{self, Devices, Event, PickParams, Step};
use limber_interfaces::diagnostics::get_text;
use limber_services::diagnostics::StatsReader;
use limber_services::prelude::*;
use limber_services::{Domain, Role};

use crate::out::outln;
use crate::{CliError, exit};

/// Which robot the demo drives.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Robot {
    /// The Pioneer 5-DOF arm: the built-in P2OS emulator on a pty, driven by the real
    /// Pioneer driver.
    Pioneer,
    /// The simulated 6-joint arm (simarm) with its parallel gripper.
    Simarm,
}

/// Arguments of `limber demo`.
#[derive(Debug, Args)]
pub struct DemoArgs {
    /// The robot to run the very same client program on.
    #[arg(long, value_enum, default_value_t = Robot::Pioneer)]
    on: Robot,
    /// The world: the block (`--block X Y`, or `--seed N` for a random place within reach;
    /// default seed 1), `--world FILE`, the laser's noise.
    #[command(flatten)]
    world: crate::world::WorldArgs,
    /// Drop position x y (m, robot frame); default depends on the robot.
    #[arg(long, num_args = 2, allow_negative_numbers = true, value_names = ["X", "Y"])]
    drop: Option<Vec<f64>>,
    /// Run the joints at their fastest (for tests); the default speed is watchable.
    #[arg(long)]
    fast: bool,
}

/// A robot running on threads of this process, stopped when dropped.
struct Running {
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
    limb: String,
    gripper: String,
    arm: String,
    robot: String,
    params: PickParams,
    /// The world's driver: the laser and the blocks (stopped before the robot).
    world: Option<crate::world::RunningWorld>,
}

impl Drop for Running {
    fn drop(&mut self) {
        drop(self.world.take());
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take()
            && t.join().is_err()
        {
            tracing::error!("the demo's driver thread panicked");
        }
    }
}

fn start_pioneer(domain: &Domain) -> Result<Running, CliError> {
    use limber_emulator::{Emulator, EmulatorConfig};
    use limber_pioneer::{PioneerConfig, PioneerDriver, RunOptions, StartOptions};
    let stop = Arc::new(AtomicBool::new(false));
    let (tx, rx) = mpsc::channel::<Result<String, String>>();
    let d = domain.clone();
    let s = Arc::clone(&stop);
    let thread = std::thread::Builder::new()
        .name("pioneer-driver".into())
        .spawn(move || {
            let emu = match Emulator::start_pty(EmulatorConfig::default()) {
                Ok(e) => e,
                Err(e) => {
                    report(&tx, Err(format!("cannot start the emulator: {e}")));
                    return;
                }
            };
            let path = emu
                .pty_path()
                .map(|p| p.display().to_string())
                .unwrap_or_default();
            let ctx = match Context::new(&d, Role::Driver, "pioneer") {
                Ok(c) => c,
                Err(e) => {
                    report(&tx, Err(e.to_string()));
                    return;
                }
            };
            let cfg = PioneerConfig {
                port: path.clone(),
                ..PioneerConfig::default()
            };
            // The emulator's devices say SIMULATED.
            let start = StartOptions { simulated: true };
            let mut driver = match PioneerDriver::start_with(&ctx, cfg, emu.link_target(), start) {
                Ok(d) => d,
                Err(e) => {
                    report(&tx, Err(e.to_string()));
                    return;
                }
            };
            report(&tx, Ok(path));
            if let Err(e) = driver.run_until(RunOptions::default(), || s.load(Ordering::Relaxed)) {
                tracing::error!("the Pioneer driver stopped: {e}");
            }
            let report = driver.shutdown();
            tracing::info!("the Pioneer driver: {report}");
            drop(driver);
            if let Err(e) = emu.stop() {
                tracing::warn!("stopping the emulator: {e}");
            }
        })
        .map_err(|e| CliError::new(exit::FAILURE, e.to_string()))?;
    match rx.recv_timeout(Duration::from_secs(30)) {
        Ok(Ok(path)) => outln!("started the Pioneer emulator on {path} and the Pioneer driver")?,
        Ok(Err(e)) => return Err(CliError::new(exit::FAILURE, e)),
        Err(_) => {
            return Err(CliError::new(
                exit::TIMEOUT,
                "the Pioneer driver did not start within 30 s",
            ));
        }
    }
    Ok(Running {
        stop,
        thread: Some(thread),
        limb: "pioneer/limb/0".into(),
        gripper: "pioneer/gripper/1".into(),
        arm: "pioneer/actarray/0".into(),
        robot: "pioneer".into(),
        params: PickParams::default(),
        world: None,
    })
}

fn start_simarm(domain: &Domain, block: Option<limber_world::Block>) -> Result<Running, CliError> {
    use limber_kinematics::chain::Chain;
    use limber_simarm::{SimArm, SimArmOptions, SimObject};
    let stop = Arc::new(AtomicBool::new(false));
    let (tx, rx) = mpsc::channel::<Result<(), String>>();
    let d = domain.clone();
    let s = Arc::clone(&stop);
    let thread = std::thread::Builder::new()
        .name("simarm".into())
        .spawn(move || {
            let ctx = match Context::new(&d, Role::Driver, "simarm") {
                Ok(c) => c,
                Err(e) => {
                    report(&tx, Err(e.to_string()));
                    return;
                }
            };
            // The world's block, its grasp point at the paper's HandleHeight: the fingers
            // close on it and the gripper's beam sees it.
            let opts = SimArmOptions {
                object: block
                    .map(|b| SimObject::block([b.x, b.y, crate::world::HANDLE_HEIGHT], b.size)),
                ..SimArmOptions::default()
            };
            let mut arm = match SimArm::new(&ctx, Chain::default_6dof(), opts) {
                Ok(a) => a,
                Err(e) => {
                    report(&tx, Err(e.to_string()));
                    return;
                }
            };
            report(&tx, Ok(()));
            if let Err(e) = arm.run(|| s.load(Ordering::Relaxed)) {
                tracing::error!("simarm stopped: {e}");
            }
        })
        .map_err(|e| CliError::new(exit::FAILURE, e.to_string()))?;
    match rx.recv_timeout(Duration::from_secs(30)) {
        Ok(Ok(())) => {
            outln!("started simarm: the built-in 6-joint chain with its parallel gripper")?
        }
        Ok(Err(e)) => return Err(CliError::new(exit::FAILURE, e)),
        Err(_) => {
            return Err(CliError::new(
                exit::TIMEOUT,
                "simarm did not start within 30 s",
            ));
        }
    }
    Ok(Running {
        stop,
        thread: Some(thread),
        limb: "simarm/limb/0".into(),
        gripper: "simarm/gripper/0".into(),
        arm: "simarm/actarray/0".into(),
        robot: "simarm".into(),
        params: PickParams::default(),
        world: None,
    })
}

fn fmt_v(v: Vec3) -> String {
    format!("({:+.3}, {:+.3}, {:+.3})", v.x, v.y, v.z)
}

fn gripper_name(g: &GripperData) -> &'static str {
    match g.gripper_state() {
        Ok(GripperState::Open) => "open",
        Ok(GripperState::Closed) => "closed",
        Ok(GripperState::Moving) => "moving",
        _ => "error",
    }
}

fn step_name(s: &Step) -> String {
    match s {
        Step::Find => "find the block with the laser".into(),
        Step::Home => "home".into(),
        Step::OpenGripper => "open the gripper".into(),
        Step::Approach(x) => format!(
            "approach 5 cm above the block at ({:.2}, {:.2}, {:.2})",
            x[0], x[1], x[2]
        ),
        Step::Descend(x) => format!("descend to the grasp height {:.2} m", x[2]),
        Step::Grip => "grip the block".into(),
        Step::Lift(_) => "lift it".into(),
        Step::Carry(x) => format!("carry it above ({:.2}, {:.2})", x[0], x[1]),
        Step::PutDown(_) => "put it down".into(),
        Step::Release => "release it".into(),
        Step::Retreat(_) => "move up and away".into(),
        Step::HomeAgain => "home again".into(),
    }
}

/// Runs `limber demo`.
pub fn run(a: DemoArgs) -> Result<(), CliError> {
    let domain = crate::domain()?;
    // Before the robot starts: a termination signal stops the arm (the driver thread's
    // loop ends), the other signals that would end a process are ignored.
    limber_services::signals::install().map_err(|e| {
        CliError::new(
            exit::FAILURE,
            format!("cannot install the signal handlers: {e}"),
        )
    })?;
    outln!(
        "limber demo: the paper's pick-a-block program on the {} (domain {}; watch it with `limber monitor` in another terminal)",
        match a.on {
            Robot::Pioneer => "Pioneer arm (emulated)",
            Robot::Simarm => "simulated 6-joint arm",
        },
        domain.name()
    )?;
    let mut world_args = a.world.clone();
    if world_args.world.is_none() && world_args.block.is_empty() && world_args.seed.is_none() {
        world_args.seed = Some(1);
    }
    let world = world_args.world()?;
    let laser_config = world_args.laser()?;
    let placed = world.blocks.first().copied();
    let mut running = match a.on {
        Robot::Pioneer => start_pioneer(&domain)?,
        Robot::Simarm => start_simarm(&domain, placed)?,
    };
    let laser = format!("{}/ranger/0", running.robot);
    running.world = Some(crate::world::RunningWorld::start(
        &domain,
        &running.robot,
        &running.limb,
        &running.gripper,
        world,
        laser_config,
    )?);
    if let Some(b) = placed {
        outln!(
            "placed a block of {:.0} mm at ({:.3}, {:.3}){}; the laser {laser} will find it",
            b.size * 1000.0,
            b.x,
            b.y,
            world_args
                .seed
                .map(|s| format!(" (random, seed {s})"))
                .unwrap_or_default()
        )?;
    }
    let ctx = Context::new(&domain, Role::Client, "demo")
        .map_err(|e| CliError::new(exit::FAILURE, e.to_string()))?;
    let mut params = running.params;
    if let Some(d) = &a.drop {
        params.drop = [d[0], d[1]];
    }
    let mut arm = ActArrayClient::connect_timeout(&ctx, &running.arm, Duration::from_secs(5))
        .map_err(crate::device::connect_err)?;
    if a.fast {
        let n = arm.geometry().map(|g| g.actuators_count).unwrap_or(0) as usize;
        for j in 0..n {
            if let Err(e) = arm.set_speed_config(j, 50.0) {
                tracing::warn!("--fast: joint {j} keeps its speed: {e}");
            }
        }
    }
    let mut dev = Devices::connect_with_laser(
        &ctx,
        &running.limb,
        &running.gripper,
        &laser,
        Duration::from_secs(5),
    )
    .map_err(crate::device::connect_err)?;
    outln!(
        "devices: {} (joints), {} (end effector), {} (gripper), {laser} (laser)\n",
        running.arm,
        running.limb,
        running.gripper
    )?;

    let tty = std::io::stdout().is_terminal();
    let start = Instant::now();
    let mut step_start = Instant::now();
    let mut last_line = Instant::now();
    let mut n = 0;
    // A closed stdout (`limber demo | head -3`) ends the demo quietly after the current
    // step; the arm is stopped when the driver is dropped.
    let mut closed = false;
    let mut say = |args: std::fmt::Arguments<'_>| {
        if closed {
            return;
        }
        let written = crate::out::write(args).and_then(|()| {
            std::io::Write::flush(&mut std::io::stdout()).map_err(crate::out::stdout_error)
        });
        if let Err(e) = written {
            tracing::debug!("demo output stopped: {e}");
            closed = true;
        }
    };
    let result = pick_block::run(&mut dev, &params, &mut |ev| match ev {
        Event::Found(f) => {
            let off = placed.map(|b| (f.centre[0] - b.x).hypot(f.centre[1] - b.y));
            say(format_args!(
                "[ 0/11] the laser's closest point ({:.3}, {:.3}); the block's centre {:.3} m further: found at ({:.3}, {:.3}){}\n",
                f.closest[0],
                f.closest[1],
                params.block_radius,
                f.centre[0],
                f.centre[1],
                off.map(|d| format!(", {:.1} mm from where it was", d * 1000.0))
                    .unwrap_or_default()
            ));
        }
        Event::Start(s) => {
            n += 1;
            step_start = Instant::now();
            say(format_args!("[{n:>2}/11] {} ...\n", step_name(&s)));
        }
        Event::Progress(l, g) => {
            if tty {
                if let Some(s) = arm.state() {
                    let joints: Vec<String> = s
                        .actuators()
                        .iter()
                        .map(|a| format!("{:+.2}", a.position))
                        .collect();
                    say(format_args!(
                        "\r        joints [{}] gripper {:<7} end effector {}   ",
                        joints.join(" "),
                        gripper_name(g),
                        fmt_v(l.position)
                    ));
                }
            } else if last_line.elapsed() > Duration::from_secs(1) {
                last_line = Instant::now();
                say(format_args!(
                    "        moving: end effector {} gripper {}\n",
                    fmt_v(l.position),
                    gripper_name(g)
                ));
            }
        }
        Event::Done(_, l, g) => {
            if tty {
                say(format_args!("\r{:<100}\r", ""));
            }
            let joints: Vec<String> = arm
                .state()
                .map(|s| {
                    s.actuators()
                        .iter()
                        .map(|a| format!("{:+.3}", a.position))
                        .collect()
                })
                .unwrap_or_default();
            say(format_args!(
                "        done in {:.1} s: end effector {} approach {}; gripper {}; joints [{}]\n",
                step_start.elapsed().as_secs_f64(),
                fmt_v(l.position),
                fmt_v(l.approach),
                gripper_name(g),
                joints.join(" ")
            ));
        }
    });
    if closed {
        return Err(CliError::stdout_closed());
    }
    if limber_services::signals::termination_requested() {
        return Err(CliError::new(
            exit::FAILURE,
            "stopped by a signal: the driver stopped the arm",
        ));
    }
    match result {
        Ok(s) => {
            let picked = s.found.map_or(params.block, |f| f.centre);
            outln!(
                "\npicked the block at ({:.3}, {:.3}) and put it down at ({:.2}, {:.2}): {} steps in {:.1} s{}",
                picked[0],
                picked[1],
                params.drop[0],
                params.drop[1],
                s.steps,
                start.elapsed().as_secs_f64(),
                if s.block_seen {
                    "; the gripper's beam saw the block while it was held"
                } else {
                    ""
                }
            )?;
            if a.on == Robot::Pioneer
                && let Ok(mut stats) = StatsReader::open(&ctx, &running.robot)
                && let Ok(st) = stats.wait(Duration::from_millis(1500))
            {
                outln!(
                    "driver: {} {} {}; loop period p50 {:.2} ms p99 {:.2} ms; command to wire p50 {:.1} µs; {:.1} SIPs/s; {} commands, {} refused, {} requests; {} bad checksums",
                    get_text(&st.robot_name).unwrap_or("?"),
                    get_text(&st.robot_class).unwrap_or(""),
                    get_text(&st.robot_subclass).unwrap_or(""),
                    st.period_p50_ns as f64 / 1e6,
                    st.period_p99_ns as f64 / 1e6,
                    st.cmd_to_wire_p50_ns as f64 / 1e3,
                    st.sips_per_s,
                    st.commands,
                    st.refused,
                    st.requests,
                    st.bad_checksums
                )?;
            }
            if let (Some(b), Some(f), Some(now)) = (
                placed,
                s.found,
                running
                    .world
                    .as_ref()
                    .and_then(|w| w.blocks().first().copied()),
            ) {
                outln!(
                    "the block was at ({:.3}, {:.3}); the laser found it at ({:.3}, {:.3}), {:.1} mm off; it is now at ({:.3}, {:.3})",
                    b.x,
                    b.y,
                    f.centre[0],
                    f.centre[1],
                    (f.centre[0] - b.x).hypot(f.centre[1] - b.y) * 1000.0,
                    now.x,
                    now.y
                )?;
            }
            outln!("done.")?;
            Ok(())
        }
        Err(e) => Err(CliError::new(
            exit::FAILURE,
            format!("the program stopped: {e}"),
        )),
    }
}

/// Sends a start-up result to the waiting main thread; if it has given up waiting (its
/// timeout passed), there is nobody left to tell, which is logged.
fn report<T>(tx: &mpsc::Sender<Result<T, String>>, r: Result<T, String>) {
    if tx.send(r).is_err() {
        tracing::debug!("the demo stopped waiting for its driver to start");
    }
}
