//! Blocks move with the gripper: gripped when the fingers close around them, carried with
//! the tool, put down where the fingers open.

use crate::World;

/// Tracks which block the gripper holds, from the tool point and the gripper's state.
#[derive(Debug, Clone, PartialEq)]
pub struct Carrier {
    /// A block is gripped when the gripper closes with the tool point this close to its
    /// centre (horizontally), m.
    pub capture_radius: f64,
    held: Option<Held>,
    was_closed: bool,
}

#[derive(Debug, Clone, Copy, PartialEq)]
struct Held {
    block: usize,
    /// Offset of the block's centre from the tool point (x, y) when gripped.
    offset: [f64; 2],
    /// The tool's height when gripped.
    z0: f64,
}

impl Default for Carrier {
    fn default() -> Self {
        Carrier {
            capture_radius: 0.02,
            held: None,
            was_closed: false,
        }
    }
}

impl Carrier {
    /// The block held, if any (its index in the world).
    pub fn held(&self) -> Option<usize> {
        self.held.map(|h| h.block)
    }

    /// The block between the fingers (held, or within the capture radius of `tool`).
    pub fn between_fingers(&self, world: &World, tool: [f64; 3]) -> Option<usize> {
        self.held().or_else(|| self.nearest(world, tool))
    }

    fn nearest(&self, world: &World, tool: [f64; 3]) -> Option<usize> {
        world
            .blocks
            .iter()
            .enumerate()
            .map(|(i, b)| (i, (b.x - tool[0]).hypot(b.y - tool[1])))
            .filter(|(_, d)| *d <= self.capture_radius)
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(i, _)| i)
    }

    /// Updates the world for the tool point `tool` (m, robot frame) and whether the
    /// gripper is closed: the gripper closing near a block grips it; a gripped block
    /// follows the tool; the gripper opening puts it down where it is.
    pub fn update(&mut self, world: &mut World, tool: [f64; 3], closed: bool) {
        if closed && !self.was_closed && self.held.is_none() {
            self.held = self.nearest(world, tool).map(|i| Held {
                block: i,
                offset: [world.blocks[i].x - tool[0], world.blocks[i].y - tool[1]],
                z0: tool[2],
            });
            if let Some(h) = self.held {
                tracing::info!(block = h.block, "world: the gripper closed on a block");
            }
        }
        if !closed
            && let Some(h) = self.held.take()
            && let Some(b) = world.blocks.get_mut(h.block)
        {
            b.lifted = 0.0;
            tracing::info!(
                block = h.block,
                x = b.x,
                y = b.y,
                "world: a block was put down"
            );
        }
        if let Some(h) = self.held
            && let Some(b) = world.blocks.get_mut(h.block)
        {
            b.x = tool[0] + h.offset[0];
            b.y = tool[1] + h.offset[1];
            b.lifted = (tool[2] - h.z0).max(0.0);
        }
        self.was_closed = closed;
    }
}
