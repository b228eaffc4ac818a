//! Errors are classified by iceoryx2's variants and keep them as their source; a
//! `DeviceSet` serves its devices through one handler.

use std::error::Error as _;
use std::time::Duration;

use iceoryx2::service::builder::publish_subscribe::{
    PublishSubscribeOpenError, PublishSubscribeOpenOrCreateError,
};
use limber_services::diagnostics::{DiagnosticsError, StatsReader};
use limber_services::prelude::*;
use limber_services::{
    Channel, ConnectError, DeviceSet, DeviceSetHandler, HostError, Incompatibility, Iox2Error,
    WaitError,
};

const T: Duration = Duration::from_secs(2);

fn driver_ctx(domain: &Domain) -> Context {
    Context::new(domain, Role::Driver, "errtest").unwrap()
}

#[test]
fn a_host_of_the_wrong_interface_is_an_error_not_a_panic() {
    let domain = Domain::unique_for_test();
    let ctx = driver_ctx(&domain);
    let err = DeviceHost::<Limb>::new(&ctx, &"r/actarray/0".parse().unwrap(), "t").unwrap_err();
    assert!(
        matches!(err, HostError::WrongInterface { expected, .. } if expected == InterfaceKind::Limb),
        "{err}"
    );
    assert_eq!(err.to_string(), "device r/actarray/0 is not a limb");
}

#[test]
fn a_device_served_twice_is_refused() {
    let domain = Domain::unique_for_test();
    let ctx = driver_ctx(&domain);
    let name: DeviceName = "r/gripper/0".parse().unwrap();
    let _first = DeviceHost::<Gripper>::new(&ctx, &name, "t").unwrap();
    let err = DeviceHost::<Gripper>::new(&ctx, &name, "t").unwrap_err();
    assert!(matches!(err, HostError::AlreadyServed { .. }), "{err}");
}

#[test]
fn a_name_held_by_another_type_is_incompatible_with_its_cause() {
    let domain = Domain::unique_for_test();
    let ctx = driver_ctx(&domain);
    let name: DeviceName = "r/actarray/0".parse().unwrap();
    // Another program holds the data channel's name with another payload type.
    let _other = ctx
        .node()
        .service_builder(&name.service_name(Channel::Data))
        .publish_subscribe::<u64>()
        .create()
        .unwrap();
    let err = DeviceHost::<ActArray>::new(&ctx, &name, "t").unwrap_err();
    let HostError::Incompatible { source, .. } = &err else {
        panic!("expected Incompatible, got {err}");
    };
    assert!(source.is_incompatible_attributes_or_types(), "{source:?}");
    // The iceoryx2 error is reachable as the source, and matched on its variant.
    let cause = err
        .source()
        .and_then(|s| s.downcast_ref::<Iox2Error>())
        .expect("an iceoryx2 source");
    assert!(
        matches!(
            cause,
            Iox2Error::PubSubOpenOrCreate(
                PublishSubscribeOpenOrCreateError::PublishSubscribeOpenError(
                    PublishSubscribeOpenError::IncompatibleTypes
                        | PublishSubscribeOpenError::IncompatibleAttributes
                )
            )
        ),
        "{cause:?}"
    );
}

#[test]
fn clients_tell_absent_wrong_and_incompatible_devices_apart() {
    let domain = Domain::unique_for_test();
    let dctx = driver_ctx(&domain);
    let _arm = DeviceHost::<ActArray>::new(&dctx, &"r/actarray/0".parse().unwrap(), "t").unwrap();
    let ctx = Context::new(&domain, Role::Client, "errclient").unwrap();

    let err = ActArrayClient::connect(&ctx, "r/actarray/3").unwrap_err();
    assert!(matches!(err, ConnectError::NoDriver { .. }), "{err}");

    let err = LimbClient::connect(&ctx, "r/actarray/0").unwrap_err();
    assert!(
        matches!(
            err,
            ConnectError::Incompatible {
                reason: Incompatibility::Interface { .. },
                ..
            }
        ),
        "{err}"
    );
    assert_eq!(
        err.to_string(),
        "r/actarray/0 is incompatible: it is an actarray device, not a limb"
    );

    // A data channel without the layout attribute: another layout version.
    let _old = dctx
        .node()
        .service_builder(
            &"r/limb/0"
                .parse::<DeviceName>()
                .unwrap()
                .service_name(Channel::Data),
        )
        .publish_subscribe::<LimbData>()
        .create()
        .unwrap();
    let err = LimbClient::connect(&ctx, "r/limb/0").unwrap_err();
    let ConnectError::Incompatible {
        reason: Incompatibility::Layout { channel, source },
        ..
    } = &err
    else {
        panic!("expected a layout incompatibility, got {err}");
    };
    assert_eq!(*channel, "data");
    assert_eq!(
        *source,
        Iox2Error::PubSubOpen(PublishSubscribeOpenError::IncompatibleAttributes)
    );
}

#[test]
fn absent_driver_statistics_are_no_driver() {
    let domain = Domain::unique_for_test();
    let ctx = Context::new(&domain, Role::Client, "errclient").unwrap();
    let err = StatsReader::open(&ctx, "nobody").unwrap_err();
    assert_eq!(err, DiagnosticsError::NoDriver("nobody".into()));
}

/// An arm at actarray/0 and two grippers, told apart by index.
#[derive(Default)]
struct Robot {
    grips: [u32; 2],
}

impl DeviceSetHandler for Robot {
    fn actarray_request(
        &mut self,
        _: u16,
        req: &ActArrayRequest,
        _: &Origin,
        _: &mut ActArrayData,
    ) -> Result<ActArrayReply, Status> {
        match req {
            ActArrayRequest::Power(_) => Ok(ActArrayReply::Done),
            _ => Err(Status::Unsupported),
        }
    }
    fn gripper_command(
        &mut self,
        index: u16,
        cmd: &GripperCommand,
        _: &Origin,
        state: &mut GripperData,
    ) -> Status {
        match cmd {
            GripperCommand::Close => {
                self.grips[index as usize] += 1;
                state.state = GripperState::Closed as u32;
                Status::Ok
            }
            _ => Status::Unsupported,
        }
    }
}

#[test]
fn a_device_set_serves_each_device_through_one_handler() {
    let domain = Domain::unique_for_test();
    let dctx = driver_ctx(&domain);
    let mut set = DeviceSet::new(
        &dctx,
        "r",
        "t",
        &[
            (InterfaceKind::ActArray, 0),
            (InterfaceKind::Gripper, 0),
            (InterfaceKind::Gripper, 1),
        ],
    )
    .unwrap();
    assert_eq!(set.len(), 3);
    assert!(set.limb(0).is_none() && set.gripper(1).is_some());
    let names: Vec<String> = set.devices().map(|d| d.to_string()).collect();
    assert_eq!(names, ["r/actarray/0", "r/gripper/0", "r/gripper/1"]);
    set.publish_all(monotonic_ns()).unwrap();
    assert_eq!(set.stats().published, 3);
    // The loop must keep the listeners: a dropped one closes the device's wake channel.
    let listeners = set.take_wake_listeners();
    assert_eq!(listeners.len(), 3);
    assert!(set.take_wake_listeners().is_empty());

    // A bad robot name is a name error, not a transport error.
    let err = DeviceSet::new(&dctx, "no/pe", "t", &[(InterfaceKind::Limb, 0)]).unwrap_err();
    assert!(matches!(err, HostError::Name(_)), "{err}");

    let ctx = Context::new(&domain, Role::Client, "setclient").unwrap();
    let mut g1 = GripperClient::connect(&ctx, "r/gripper/1").unwrap();
    let mut arm = ActArrayClient::connect(&ctx, "r/actarray/0").unwrap();
    let ticket = g1.close().unwrap();
    let mut robot = Robot::default();
    let activity = set.process(&mut robot).unwrap();
    assert_eq!(activity.commands, 1);
    assert_eq!(robot.grips, [0, 1]);
    assert_eq!(g1.wait_outcome(ticket, T).unwrap(), Status::Ok);

    // What the handler does not override is refused as unsupported.
    let t = g1.open().unwrap();
    set.process(&mut robot).unwrap();
    assert_eq!(g1.wait_outcome(t, T).unwrap(), Status::Unsupported);
    assert!(matches!(
        g1.wait_outcome(ticket, Duration::ZERO),
        Ok(_) | Err(WaitError::Missed { .. })
    ));
    let stats = set.stats();
    assert_eq!((stats.commands, stats.refused), (2, 1));
    // Every client got the latest state of its own device.
    assert!(arm.current(T).is_ok());
}
