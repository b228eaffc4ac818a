//! [`Iox2Error`]: an iceoryx2 failure kept as iceoryx2 reported it, the `#[source]` of
//! the transport variants of this crate's error enums.
//!
//! Every error enum of this crate belongs to one fallible operation (offering a device,
//! publishing, connecting, sending a command, ...). Where a variant stands for a failure of
//! iceoryx2, it holds the iceoryx2 error itself (never its text), so that a caller can
//! walk [`std::error::Error::source`] down to it and match on its variants.

use iceoryx2::node::{NodeCreationFailure, NodeListFailure};
use iceoryx2::port::LoanError;
use iceoryx2::port::ReceiveError;
use iceoryx2::port::SendError;
use iceoryx2::port::client::RequestSendError;
use iceoryx2::port::listener::{ListenerCreateError, ListenerWaitError};
use iceoryx2::port::notifier::{NotifierCreateError, NotifierNotifyError};
use iceoryx2::port::publisher::PublisherCreateError;
use iceoryx2::port::subscriber::SubscriberCreateError;
use iceoryx2::port::update_connections::ConnectionFailure;
use iceoryx2::prelude::SemanticStringError;
use iceoryx2::service::ServiceListError;
use iceoryx2::service::attribute::AttributeDefinitionError;
use iceoryx2::service::builder::event::{EventOpenError, EventOpenOrCreateError};
use iceoryx2::service::builder::publish_subscribe::{
    PublishSubscribeOpenError, PublishSubscribeOpenOrCreateError,
};
use iceoryx2::service::builder::request_response::{
    RequestResponseOpenError, RequestResponseOpenOrCreateError,
};
use iceoryx2::service::port_factory::client::ClientCreateError;
use iceoryx2::service::port_factory::server::ServerCreateError;
use iceoryx2::waitset::{WaitSetAttachmentError, WaitSetCreateError, WaitSetRunError};
use thiserror::Error;

/// A failure of iceoryx2, one variant per iceoryx2 error type this crate meets. Displays
/// as iceoryx2 displays it; match on the inner iceoryx2 enum to tell causes apart.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
#[non_exhaustive]
pub enum Iox2Error {
    /// Opening a publish-subscribe service.
    #[error(transparent)]
    PubSubOpen(#[from] PublishSubscribeOpenError),
    /// Opening or creating a publish-subscribe service.
    #[error(transparent)]
    PubSubOpenOrCreate(#[from] PublishSubscribeOpenOrCreateError),
    /// Opening an event service.
    #[error(transparent)]
    EventOpen(#[from] EventOpenError),
    /// Opening or creating an event service.
    #[error(transparent)]
    EventOpenOrCreate(#[from] EventOpenOrCreateError),
    /// Opening a request-response service.
    #[error(transparent)]
    ReqRespOpen(#[from] RequestResponseOpenError),
    /// Opening or creating a request-response service.
    #[error(transparent)]
    ReqRespOpenOrCreate(#[from] RequestResponseOpenOrCreateError),
    /// Creating a publisher.
    #[error(transparent)]
    PublisherCreate(#[from] PublisherCreateError),
    /// Creating a subscriber.
    #[error(transparent)]
    SubscriberCreate(#[from] SubscriberCreateError),
    /// Creating a request-response server.
    #[error(transparent)]
    ServerCreate(#[from] ServerCreateError),
    /// Creating a request-response client.
    #[error(transparent)]
    ClientCreate(#[from] ClientCreateError),
    /// Creating an event listener.
    #[error(transparent)]
    ListenerCreate(#[from] ListenerCreateError),
    /// Creating an event notifier.
    #[error(transparent)]
    NotifierCreate(#[from] NotifierCreateError),
    /// Loaning a sample, request or response.
    #[error(transparent)]
    Loan(#[from] LoanError),
    /// Sending a sample or response.
    #[error(transparent)]
    Send(#[from] SendError),
    /// Sending a request.
    #[error(transparent)]
    RequestSend(#[from] RequestSendError),
    /// Receiving a sample, request or response.
    #[error(transparent)]
    Receive(#[from] ReceiveError),
    /// Waiting on an event listener.
    #[error(transparent)]
    ListenerWait(#[from] ListenerWaitError),
    /// Notifying an event.
    #[error(transparent)]
    Notify(#[from] NotifierNotifyError),
    /// Connecting a port to new counterparts.
    #[error(transparent)]
    Connections(#[from] ConnectionFailure),
    /// A service attribute key or value.
    #[error(transparent)]
    AttributeText(#[from] SemanticStringError),
    /// Requiring a service attribute.
    #[error(transparent)]
    AttributeDefinition(#[from] AttributeDefinitionError),
    /// Creating a node.
    #[error(transparent)]
    NodeCreate(#[from] NodeCreationFailure),
    /// Listing the nodes of a service.
    #[error(transparent)]
    NodeList(#[from] NodeListFailure),
    /// Listing the services of a domain.
    #[error(transparent)]
    ServiceList(#[from] ServiceListError),
    /// Creating a WaitSet.
    #[error(transparent)]
    WaitSetCreate(#[from] WaitSetCreateError),
    /// Attaching to a WaitSet.
    #[error(transparent)]
    WaitSetAttach(#[from] WaitSetAttachmentError),
    /// Running a WaitSet.
    #[error(transparent)]
    WaitSetRun(#[from] WaitSetRunError),
}

impl Iox2Error {
    /// True when the service does not exist (nobody created it, or it was cleaned up).
    pub fn is_missing_service(&self) -> bool {
        matches!(
            self,
            Iox2Error::PubSubOpen(PublishSubscribeOpenError::DoesNotExist)
                | Iox2Error::PubSubOpenOrCreate(
                    PublishSubscribeOpenOrCreateError::PublishSubscribeOpenError(
                        PublishSubscribeOpenError::DoesNotExist
                    )
                )
                | Iox2Error::EventOpen(EventOpenError::DoesNotExist)
                | Iox2Error::EventOpenOrCreate(EventOpenOrCreateError::EventOpenError(
                    EventOpenError::DoesNotExist
                ))
                | Iox2Error::ReqRespOpen(RequestResponseOpenError::DoesNotExist)
                | Iox2Error::ReqRespOpenOrCreate(
                    RequestResponseOpenOrCreateError::RequestResponseOpenError(
                        RequestResponseOpenError::DoesNotExist
                    )
                )
        )
    }

    /// True when iceoryx2 could not open a service's files for lack of permission (in group
    /// mode: a member's file not yet opened to the group; else another user's domain).
    pub fn is_permission_denied(&self) -> bool {
        matches!(
            self,
            Iox2Error::PubSubOpen(PublishSubscribeOpenError::InsufficientPermissions)
                | Iox2Error::PubSubOpenOrCreate(
                    PublishSubscribeOpenOrCreateError::PublishSubscribeOpenError(
                        PublishSubscribeOpenError::InsufficientPermissions
                    )
                )
                | Iox2Error::EventOpen(EventOpenError::InsufficientPermissions)
                | Iox2Error::EventOpenOrCreate(EventOpenOrCreateError::EventOpenError(
                    EventOpenError::InsufficientPermissions
                ))
                | Iox2Error::ReqRespOpen(RequestResponseOpenError::InsufficientPermissions)
                | Iox2Error::ReqRespOpenOrCreate(
                    RequestResponseOpenOrCreateError::RequestResponseOpenError(
                        RequestResponseOpenError::InsufficientPermissions
                    )
                )
        )
    }

    /// True when a service or port could not be made because every slot of its kind is
    /// taken (subscribers, publishers, clients, notifiers, listeners, nodes).
    pub fn is_full(&self) -> bool {
        matches!(
            self,
            Iox2Error::SubscriberCreate(SubscriberCreateError::ExceedsMaxSupportedSubscribers)
                | Iox2Error::PublisherCreate(PublisherCreateError::ExceedsMaxSupportedPublishers)
                | Iox2Error::ClientCreate(ClientCreateError::ExceedsMaxSupportedClients)
                | Iox2Error::NotifierCreate(NotifierCreateError::ExceedsMaxSupportedNotifiers)
                | Iox2Error::ListenerCreate(ListenerCreateError::ExceedsMaxSupportedListeners)
                | Iox2Error::PubSubOpen(PublishSubscribeOpenError::ExceedsMaxNumberOfNodes)
                | Iox2Error::EventOpen(EventOpenError::ExceedsMaxNumberOfNodes)
                | Iox2Error::ReqRespOpen(RequestResponseOpenError::ExceedsMaxNumberOfNodes)
        )
    }

    /// True when the service exists with other attributes (another layout version or
    /// driver) or other payload types.
    pub fn is_incompatible_attributes_or_types(&self) -> bool {
        use PublishSubscribeOpenError as P;
        use RequestResponseOpenError as R;
        let pubsub = |e: &P| matches!(e, P::IncompatibleAttributes | P::IncompatibleTypes);
        let event = |e: &EventOpenError| matches!(e, EventOpenError::IncompatibleAttributes);
        let reqresp = |e: &R| {
            matches!(
                e,
                R::IncompatibleAttributes | R::IncompatibleRequestOrResponseType
            )
        };
        match self {
            Iox2Error::PubSubOpen(e) => pubsub(e),
            Iox2Error::PubSubOpenOrCreate(
                PublishSubscribeOpenOrCreateError::PublishSubscribeOpenError(e),
            ) => pubsub(e),
            Iox2Error::EventOpen(e) => event(e),
            Iox2Error::EventOpenOrCreate(EventOpenOrCreateError::EventOpenError(e)) => event(e),
            Iox2Error::ReqRespOpen(e) => reqresp(e),
            Iox2Error::ReqRespOpenOrCreate(
                RequestResponseOpenOrCreateError::RequestResponseOpenError(e),
            ) => reqresp(e),
            _ => false,
        }
    }

    /// True when an existing service of the name does not match what was asked for: its
    /// attributes, types, messaging pattern or quality of service differ.
    pub fn is_incompatible(&self) -> bool {
        use EventOpenError as E;
        use PublishSubscribeOpenError as P;
        use RequestResponseOpenError as R;
        let pubsub = |e: &P| {
            matches!(
                e,
                P::IncompatibleTypes
                    | P::IncompatibleMessagingPattern
                    | P::IncompatibleAttributes
                    | P::IncompatibleOverflowBehavior
            )
        };
        let event = |e: &E| {
            matches!(
                e,
                E::IncompatibleMessagingPattern
                    | E::IncompatibleAttributes
                    | E::IncompatibleDeadline
                    | E::IncompatibleNotifierCreatedEvent
                    | E::IncompatibleNotifierDroppedEvent
                    | E::IncompatibleNotifierDeadEvent
            )
        };
        let reqresp = |e: &R| {
            matches!(
                e,
                R::IncompatibleRequestOrResponseType
                    | R::IncompatibleAttributes
                    | R::IncompatibleMessagingPattern
                    | R::IncompatibleOverflowBehaviorForRequests
                    | R::IncompatibleOverflowBehaviorForResponses
                    | R::IncompatibleBehaviorForFireAndForgetRequests
            )
        };
        match self {
            Iox2Error::PubSubOpen(e) => pubsub(e),
            Iox2Error::PubSubOpenOrCreate(
                PublishSubscribeOpenOrCreateError::PublishSubscribeOpenError(e),
            ) => pubsub(e),
            Iox2Error::EventOpen(e) => event(e),
            Iox2Error::EventOpenOrCreate(EventOpenOrCreateError::EventOpenError(e)) => event(e),
            Iox2Error::ReqRespOpen(e) => reqresp(e),
            Iox2Error::ReqRespOpenOrCreate(
                RequestResponseOpenOrCreateError::RequestResponseOpenError(e),
            ) => reqresp(e),
            _ => false,
        }
    }
}
