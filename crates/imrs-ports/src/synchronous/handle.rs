//! What the clones of an end share: the port, closed when the last clone goes.

use std::sync::Arc;

/// A port's state that can be closed.
pub(crate) trait Close {
    fn close(&self);
}

/// Held by every clone of an end; dropping the last one closes the port.
pub(crate) struct Handle<S: Close> {
    pub(crate) shared: Arc<S>,
}

impl<S: Close> Drop for Handle<S> {
    fn drop(&mut self) {
        self.shared.close();
    }
}
