//! limber-services: the iceoryx2 layer (built by the services issue).
