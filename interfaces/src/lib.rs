//! limber-interfaces: the wire contract.
