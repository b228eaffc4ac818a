//! The gripper's store (the paper's "swallow", Table 4's STORE and RETRIEVE): STORE
//! takes the object between the fingers out of the world into the store, RETRIEVE puts
//! the last one stored back between the fingers. The capacity is
//! [`SimArmOptions::store_capacity`](super::SimArmOptions::store_capacity); 0 means the
//! gripper cannot store (both unsupported, as on the Pioneer).

use limber_interfaces::prelude::*;

use super::{ArmModel, SimObject};

/// Largest store capacity accepted (the store is allocated once, at this size at most).
pub const MAX_STORE_CAPACITY: u32 = 1024;

/// The stored objects, last in first out.
#[derive(Debug)]
pub(super) struct Store {
    capacity: u32,
    items: Vec<SimObject>,
}

impl Store {
    /// An empty store of `capacity` objects (allocated now: nothing allocates later).
    pub(super) fn new(capacity: u32) -> Self {
        let capacity = capacity.min(MAX_STORE_CAPACITY);
        Store {
            capacity,
            items: Vec::with_capacity(capacity as usize),
        }
    }

    /// How many objects it holds at most.
    pub(super) fn capacity(&self) -> u32 {
        self.capacity
    }

    /// How many objects it holds.
    pub(super) fn len(&self) -> u32 {
        self.items.len() as u32
    }
}

impl ArmModel {
    /// STORE: the object between the fingers leaves the world into the store. Refused
    /// UNSUPPORTED without a store, POWERED_OFF, STORE_FULL when the store is full,
    /// NOTHING_TO_STORE when nothing is between the fingers.
    pub(super) fn store_object(&mut self) -> Result<(), Status> {
        if self.store.capacity == 0 {
            return Err(Status::Unsupported);
        }
        self.powered()?;
        if self.store.len() >= self.store.capacity {
            return Err(Status::StoreFull);
        }
        let o = self.take_from_fingers().ok_or(Status::NothingToStore)?;
        self.store.items.push(o);
        Ok(())
    }

    /// RETRIEVE: the last object stored comes back between the fingers, held. Refused
    /// UNSUPPORTED without a store, POWERED_OFF, NOTHING_STORED when the store is empty,
    /// BUSY when there is no room for it between the fingers.
    pub(super) fn retrieve_object(&mut self) -> Result<(), Status> {
        if self.store.capacity == 0 {
            return Err(Status::Unsupported);
        }
        self.powered()?;
        let o = self.store.items.pop().ok_or(Status::NothingStored)?;
        if let Err(o) = self.put_between_fingers(o) {
            self.store.items.push(o);
            return Err(Status::Busy);
        }
        Ok(())
    }

    /// How many objects the gripper has stored.
    pub fn stored(&self) -> u32 {
        self.store.len()
    }
}
