//! One attached end of a port: its place in the core, and what it does on detach.

use std::sync::Arc;
use std::task::{Context, Poll};
use std::time::Duration;

use crate::core::{Core, SlotId, hold};
use crate::error::Gone;
use crate::loom::Ordering;
use crate::meta::Name;
use crate::presence::Presence;
use crate::slot::Slot;

pub(crate) struct Attachment<Req, Rep> {
    pub(crate) core: Arc<Core<Req, Rep>>,
    /// `Owner` for the owner end, `User(i)` for the user attached at slot `i`.
    pub(crate) at: SlotId,
    pub(crate) module: Name,
    pub(crate) timeout: Option<Duration>,
    /// Whether this end's waits park at once ([`End::park_waits`](crate::transport::EndTransport::park_waits)).
    pub(crate) parked: bool,
}

impl<Req, Rep> Attachment<Req, Rep> {
    pub(crate) fn is_owner(&self) -> bool {
        self.at == SlotId::Owner
    }

    pub(crate) fn port(&self) -> &Name {
        &self.core.meta.name
    }

    /// Takes the oldest request waiting for this end to serve it, and where it came from.
    pub(crate) fn try_take(&self) -> Option<(Req, SlotId)> {
        match self.at {
            SlotId::Owner => loop {
                let index = self.core.oldest_posted_user()?;
                if let Some(request) = self.core.users[index].slot.take() {
                    return Some((request, SlotId::User(index)));
                }
                // Its poster withdrew it between the scan and the take: look again.
            },
            SlotId::User(index) => {
                // A broadcast lands in the user's own slot; a plain owner post in the
                // owner's slot, which every user may take from.
                let own = self.core.users[index].slot.take();
                own.map(|request| (request, SlotId::User(index)))
                    .or_else(|| {
                        let shared = self.core.owner_slot.take()?;
                        Some((shared, SlotId::Owner))
                    })
            }
        }
    }

    /// The slots this end serves: every user's, for the owner; a user's own slot (where a
    /// broadcast lands) and the owner's (which any user may take from), for a user.
    fn served_slots(&self) -> impl Iterator<Item = &Slot<Req, Rep>> {
        let (users, owner_slot) = match self.at {
            SlotId::Owner => (&self.core.users[..], None),
            SlotId::User(index) => (
                std::slice::from_ref(&self.core.users[index]),
                Some(&*self.core.owner_slot),
            ),
        };
        users.iter().map(|user| &*user.slot).chain(owner_slot)
    }

    /// How many requests are waiting for this end to serve them.
    pub(crate) fn waiting(&self) -> usize {
        self.served_slots()
            .filter(|slot| slot.posted_ticket().is_some())
            .count()
    }

    /// Whether a request is waiting for this end to serve it.
    pub(crate) fn has_waiting(&self) -> bool {
        self.served_slots()
            .any(|slot| slot.posted_ticket().is_some())
    }

    /// Registers the task to be woken when a request arrives for this end to serve.
    pub(crate) fn register_server(&self, cx: &mut Context<'_>) {
        match self.at {
            SlotId::Owner => self.core.owner_wakers.server.register_by_ref(cx.waker()),
            SlotId::User(index) => self.core.users[index]
                .wakers
                .server
                .register_by_ref(cx.waker()),
        }
    }

    /// Ready once a module is attached at the other end of the port (at once, for a user's
    /// end, whose peer is the owner); otherwise the owner's task is woken when a user
    /// attaches.
    pub(crate) fn poll_peer(&self, cx: &mut Context<'_>) -> Poll<()> {
        let any = |this: &Self| {
            let mut found = false;
            this.each_peer(|_| found = true);
            found
        };
        if any(self) {
            return Poll::Ready(());
        }
        self.core.user_attached.register_by_ref(cx.waker());
        // Looked at again once registered: a user that attached in between is not missed.
        if any(self) {
            Poll::Ready(())
        } else {
            Poll::Pending
        }
    }

    /// The modules at the other end of the port: the owner, for a user's end; the attached
    /// users, for the owner's end.
    pub(crate) fn peers(&self) -> Vec<Name> {
        let mut peers = Vec::new();
        self.each_peer(|peer| peers.push(peer));
        peers
    }

    /// [`Attachment::peers`], one at a time, allocating nothing.
    pub(crate) fn each_peer(&self, mut visit: impl FnMut(Name)) {
        match self.at {
            SlotId::User(_) => visit(self.core.meta.owner.clone()),
            SlotId::Owner => (0..self.core.capacity())
                .filter(|&index| self.core.is_user_attached(index))
                .filter_map(|index| self.core.user_module(index))
                .for_each(visit),
        }
    }

    /// Why no peer can ever come to this end again, if none can.
    pub(crate) fn peer_gone(&self) -> Option<Gone> {
        self.core.peer_gone(self.is_owner())
    }

    /// Makes `presence` the presence of the module holding this end.
    pub(crate) fn bind(&self, presence: &Arc<Presence>)
    where
        Req: Send + 'static,
        Rep: Send + 'static,
    {
        hold(
            &self.core,
            self.at,
            &self.module,
            Some(Arc::clone(presence)),
        );
    }

    /// How long a wait on this end may spin before it parks.
    pub(crate) fn spins(&self) -> u32 {
        if self.parked || self.core.parked.load(Ordering::Relaxed) {
            return 0;
        }
        self.core.meta.process_type.spins()
    }
}

impl<Req, Rep> Attachment<Req, Rep> {
    /// The transport's turn between two looks of a spinning wait, if it has one.
    pub(crate) fn pump(&self) {
        if let Some(pump) = self.core.hooks().and_then(|hooks| hooks.pump.get()) {
            pump.pump();
        }
    }

    /// Tells the transport, if any, that a spinning wait parks now.
    pub(crate) fn parking(&self) {
        if let Some(pump) = self.core.hooks().and_then(|hooks| hooks.pump.get()) {
            pump.parking();
        }
    }
}

impl<Req, Rep> Drop for Attachment<Req, Rep> {
    fn drop(&mut self) {
        match self.at {
            SlotId::Owner => self.core.detach_owner(),
            SlotId::User(index) => self.core.detach_user(index),
        }
    }
}
