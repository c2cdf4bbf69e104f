//! The reply queue (`snapgen_hdl::reply_queue::ReplyQueue`), clock by clock: the executor's
//! replies waiting for the transmitter.

use snapgen_spec::rules::REPLY_QUEUE;

use crate::io::executor::ReplyDesc;

/// The reply queue (`snapgen_hdl::reply_queue::ReplyQueue`): [`REPLY_QUEUE`] descriptors,
/// first in first out; a write when full is lost (the executor does not write then).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ReplyQueue {
    items: std::collections::VecDeque<ReplyDesc>,
}

impl ReplyQueue {
    /// Empty.
    pub fn new() -> Self {
        Self::default()
    }

    /// The head, if any.
    pub fn head(&self) -> Option<ReplyDesc> {
        self.items.front().copied()
    }

    /// True when full.
    pub fn full(&self) -> bool {
        self.items.len() == REPLY_QUEUE
    }

    /// One clock: pop the head if `pop`, then push `push` if not full.
    pub fn clock(&mut self, reset: bool, push: Option<ReplyDesc>, pop: bool) {
        if reset {
            self.items.clear();
            return;
        }
        let was_full = self.full();
        if pop {
            self.items.pop_front();
        }
        if let Some(r) = push {
            if !was_full {
                self.items.push_back(r);
            }
        }
    }
}
