//! A counting allocator checks what the steady state allocates.
//!
//! * Reading state on the client: nothing.
//! * Sending a command, publishing a state, answering: limber itself allocates nothing, but
//!   iceoryx2 0.10 allocates one 48-byte `Rc` per loaned sample (`ChunkMutSharedState::new`
//!   through the single-threaded `ArcSyncPolicy` of `ipc::Service`), on every publish path
//!   including `send_copy`. The test therefore allows exactly one allocation per sample
//!   sent and fails on anything more.

use limber_counting_alloc::allocations_in;
use limber_services::prelude::*;
use limber_services::testing::TestDriver;
use limber_services::{Domain, Role};

#[global_allocator]
static GLOBAL: limber_counting_alloc::Counting = limber_counting_alloc::Counting;

struct Rig {
    driver: TestDriver,
    arm: ActArrayClient,
    limb: LimbClient,
    grip: GripperClient,
}

impl Rig {
    /// One control cycle: 4 commands sent (4 samples), the driver publishes 3 states,
    /// one outcome state per command and one sample on the `outcome` channel per command
    /// (11 samples), and the result of each motion a command of this cycle ends (the
    /// previous cycle's motion on the same joints, preempted: 4 samples); each outcome and
    /// result also goes to the client on its own stream (8 responses, one allocation of
    /// iceoryx2's each as a sample's); the client reads 3 states, its 4 outcomes and the 4
    /// results.
    const SAMPLES_PER_CYCLE: u64 = 27;

    fn cycle(&mut self, i: u64) {
        let p = (i % 100) as f64 * 1e-3;
        self.arm.move_to((i % 6) as usize, p).unwrap();
        self.arm.move_to_multi(&[p, p, p]).unwrap();
        self.limb
            .set_pose([0.3, 0.0, p], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0])
            .unwrap();
        self.grip.close().unwrap();
        self.driver.publish_all().unwrap();
        assert_eq!(self.driver.process().unwrap(), 4);
        self.read();
    }

    fn read(&mut self) {
        assert_eq!(self.arm.state().unwrap().actuators_count, 6);
        let _ = self.limb.state().unwrap().position;
        let _ = self.grip.state().unwrap().beams;
        let _ = self.arm.state_age();
    }
}

#[test]
fn steady_state_allocations_are_only_iceoryx2_loans() {
    let domain = Domain::unique_for_test();
    let dctx = Context::new(&domain, Role::Driver, "alloc-driver").unwrap();
    let driver = TestDriver::new(&dctx, "alloc", 6).unwrap();
    let cctx = Context::new(&domain, Role::Client, "alloc-client").unwrap();
    let mut rig = Rig {
        driver,
        arm: ActArrayClient::connect(&cctx, "alloc/actarray/0").unwrap(),
        limb: LimbClient::connect(&cctx, "alloc/limb/0").unwrap(),
        grip: GripperClient::connect(&cctx, "alloc/gripper/0").unwrap(),
    };
    // Warm up: connections and lazily created resources.
    for i in 0..200 {
        rig.cycle(i);
    }

    // Reading state allocates nothing at all.
    rig.driver.publish_all().unwrap();
    assert_eq!(allocations_in(|| rig.read()), 0, "state reads allocate");
    assert_eq!(allocations_in(|| rig.read()), 0, "state reads allocate");

    // Commands and host cycles: at most iceoryx2's one allocation per sample sent.
    let cycles = 2000;
    let n = allocations_in(|| {
        for i in 0..cycles {
            rig.cycle(i);
        }
    });
    assert!(
        n <= cycles * Rig::SAMPLES_PER_CYCLE,
        "{n} allocations in {cycles} cycles: more than iceoryx2's one per sample sent"
    );
    eprintln!(
        "{n} allocations in {cycles} cycles ({} per cycle, {} samples sent per cycle)",
        n as f64 / cycles as f64,
        Rig::SAMPLES_PER_CYCLE
    );

    // The counter sees allocations (the check can fail).
    assert!(allocations_in(|| drop(vec![1u8; 10])) > 0);
}
