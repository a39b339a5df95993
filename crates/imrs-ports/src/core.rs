//! The in-process transport: the shared state behind one port.
//!
//! One [`Slot`] per user, sized by the port's const-generic capacity when the port is
//! declared, plus one slot for the owner's own posts. Users post into their own slot; the
//! owner posts into its slot (any one user may take it) or, broadcasting, into every user's.

use std::sync::{Arc, Mutex, MutexGuard, OnceLock, PoisonError};
use std::task::Waker;

use crate::clock::SharedClock;
use crate::error::Gone;
use crate::hooks::Hooks;
use crate::loom::{AtomicBool, AtomicU64, AtomicUsize, AtomicWaker, Ordering};
use crate::meta::{Name, PortMeta};
use crate::presence::{Presence, Watcher};
use crate::shown::Shown;
use crate::slot::Slot;
use crate::urgency::wake_at;

/// Who holds, or last held, one side of a port: the module, and its presence when the end
/// was attached inside a module.
#[derive(Default)]
pub(crate) struct Holder {
    module: Option<Name>,
    presence: Option<Arc<Presence>>,
}

impl Holder {
    /// The module, if it held this side and has ended for good.
    fn gone(&self) -> Option<&Name> {
        let presence = self.presence.as_ref()?;
        presence.is_gone().then_some(self.module.as_ref()?)
    }

    /// Whether this side was held by an end that may come back: one of a module that has
    /// not ended for good.
    fn may_come_back(&self) -> bool {
        self.presence
            .as_ref()
            .is_some_and(|presence| !presence.is_gone())
    }
}

/// Which slot of a port: the owner's, or a user's.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum SlotId {
    Owner,
    User(usize),
}

/// Keeps a value on a cache line of its own, so that threads writing their own fields do not
/// steal each other's lines: on a TIGHT port both ends spin, and every stolen line is a
/// cross-core round trip. One 64-byte line, not the pair that adjacent-line prefetchers
/// fetch: with 128 the TIGHT benches were no faster beyond their run-to-run noise, and every
/// port (so every idle module) was half a kilobyte larger.
#[repr(align(64))]
pub(crate) struct Padded<T>(T);

impl<T> std::ops::Deref for Padded<T> {
    type Target = T;

    fn deref(&self) -> &T {
        &self.0
    }
}

/// The two wakers of one side of a port, on a line of their own, apart from the slot: a
/// spinning poster reads the slot's state in a loop, and every write on that line while it
/// does costs the writer a cross-core fetch. The peer that wakes writes here instead.
#[derive(Default)]
pub(crate) struct Wakers {
    /// Wakes this side while it waits to serve (receive or respond), or, for the owner, for
    /// a broadcast's answers.
    pub(crate) server: AtomicWaker,
    /// Wakes the poster of this side's slot while it waits for the slot to be free or for
    /// its answer. For a user slot in a broadcast, that poster is the owner.
    pub(crate) poster: AtomicWaker,
}

pub(crate) struct UserSlot<Req, Rep> {
    pub(crate) slot: Padded<Slot<Req, Rep>>,
    pub(crate) wakers: Padded<Wakers>,
    attached: AtomicBool,
    /// Set by the owner while a broadcast of its awaits this user's answer.
    pub(crate) in_broadcast: AtomicBool,
    /// The attached (or last attached) module: for broadcasts to say who answered, and for
    /// waiters to see whether it is gone. Written on attach and bind.
    holder: Mutex<Holder>,
}

impl<Req, Rep> UserSlot<Req, Rep> {
    pub(crate) fn new() -> Self {
        Self {
            slot: Padded(Slot::new()),
            wakers: Padded(Wakers::default()),
            attached: AtomicBool::new(false),
            in_broadcast: AtomicBool::new(false),
            holder: Mutex::default(),
        }
    }
}

/// The shared state of one port. The user slots are allocated once, when the port is
/// declared, from its const-generic capacity; nothing is allocated per message.
pub(crate) struct Core<Req, Rep> {
    pub(crate) meta: PortMeta,
    pub(crate) clock: SharedClock,
    next_ticket: Padded<AtomicU64>,
    pub(crate) owner_slot: Padded<Slot<Req, Rep>>,
    pub(crate) owner_wakers: Padded<Wakers>,
    owner_attached: AtomicBool,
    owner_holder: Mutex<Holder>,
    /// Wakes whoever waits for a user to attach (`End::peer_attached`): a waker of its own,
    /// so that an attaching never wakes the owner's serving, which a processor orders.
    pub(crate) user_attached: AtomicWaker,
    /// Live `Port` handles: while one exists, a missing end may still attach.
    declarations: AtomicUsize,
    users_attached: AtomicUsize,
    pub(crate) users: Box<[UserSlot<Req, Rep>]>,
    /// How the port's values read in event logs, if the port says.
    pub(crate) shown: OnceLock<Shown<Req, Rep>>,
    /// Whether waits park at once, whatever the process type says
    /// ([`Port::park_waits`](crate::transport::PortTransport::park_waits)).
    pub(crate) parked: AtomicBool,
    /// What transports and filters add to the port, in one allocation made when the
    /// first is set (see [`Hooks`]); most ports have none.
    hooks: OnceLock<Box<Hooks<Req, Rep>>>,
}

impl<Req, Rep> Core<Req, Rep> {
    pub(crate) fn new(meta: PortMeta, clock: SharedClock, capacity: usize) -> Self {
        Self {
            meta,
            clock,
            next_ticket: Padded(AtomicU64::new(0)),
            owner_slot: Padded(Slot::new()),
            owner_wakers: Padded(Wakers::default()),
            owner_attached: AtomicBool::new(false),
            owner_holder: Mutex::default(),
            user_attached: AtomicWaker::new(),
            declarations: AtomicUsize::new(1),
            users_attached: AtomicUsize::new(0),
            users: (0..capacity).map(|_| UserSlot::new()).collect(),
            shown: OnceLock::new(),
            parked: AtomicBool::new(false),
            hooks: OnceLock::new(),
        }
    }

    pub(crate) fn capacity(&self) -> usize {
        self.users.len()
    }

    /// The port's hooks, if any was set: one load for a port without any.
    pub(crate) fn hooks(&self) -> Option<&Hooks<Req, Rep>> {
        self.hooks.get().map(|hooks| &**hooks)
    }

    /// The port's hooks, made empty if none was set yet, so that one can be.
    pub(crate) fn hooks_to_set(&self) -> &Hooks<Req, Rep> {
        self.hooks.get_or_init(Box::default)
    }

    pub(crate) fn slot(&self, id: SlotId) -> &Slot<Req, Rep> {
        match id {
            SlotId::Owner => &self.owner_slot,
            SlotId::User(index) => &self.users[index].slot,
        }
    }

    /// The waker of whoever posted into slot `id`.
    pub(crate) fn poster(&self, id: SlotId) -> &AtomicWaker {
        match id {
            SlotId::Owner => &self.owner_wakers.poster,
            SlotId::User(index) => &self.users[index].wakers.poster,
        }
    }

    /// The ticket for a post from `poster`: it orders the requests of several users, so a
    /// port with one user, or the owner's own slot, needs none (and skips the shared
    /// counter, which every poster would otherwise write).
    pub(crate) fn ticket(&self, poster: SlotId) -> u64 {
        match poster {
            SlotId::User(_) if self.users.len() > 1 => {
                self.next_ticket.fetch_add(1, Ordering::Relaxed)
            }
            _ => 0,
        }
    }

    /// The user slot holding the oldest waiting request, if any.
    pub(crate) fn oldest_posted_user(&self) -> Option<usize> {
        let mut oldest: Option<(u64, usize)> = None;
        for (index, user) in self.users.iter().enumerate() {
            if let Some(ticket) = user.slot.posted_ticket()
                && oldest.is_none_or(|(first, _)| ticket < first)
            {
                oldest = Some((ticket, index));
            }
        }
        oldest.map(|(_, index)| index)
    }

    /// Tells whoever serves the posts of `poster` that something arrived.
    /// The wake is lifted to the port's priority (see [`waking`](crate::transport::waking)).
    pub(crate) fn wake_servers_of(&self, poster: SlotId) {
        wake_at(self.meta.priority, || match poster {
            SlotId::User(_) => self.owner_wakers.server.wake(),
            SlotId::Owner => self.users.iter().for_each(|user| user.wakers.server.wake()),
        });
    }

    pub(crate) fn attach_owner(&self) -> bool {
        self.owner_attached
            .compare_exchange(false, true, Ordering::AcqRel, Ordering::Acquire)
            .is_ok()
    }

    pub(crate) fn detach_owner(&self) {
        self.owner_attached.store(false, Ordering::Release);
        self.wake_all();
    }

    pub(crate) fn attach_user(&self) -> Option<usize> {
        let index = self.users.iter().position(|user| {
            user.attached
                .compare_exchange(false, true, Ordering::AcqRel, Ordering::Acquire)
                .is_ok()
        })?;
        self.users_attached.fetch_add(1, Ordering::AcqRel);
        Some(index)
    }

    /// The holder record of slot `at`'s side.
    fn holder(&self, at: SlotId) -> MutexGuard<'_, Holder> {
        let holder = match at {
            SlotId::Owner => &self.owner_holder,
            SlotId::User(index) => &self.users[index].holder,
        };
        // Each critical section is one read or one write: never left half-done.
        holder.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// The module attached (or last attached) at user slot `index`.
    pub(crate) fn user_module(&self, index: usize) -> Option<Name> {
        self.holder(SlotId::User(index)).module.clone()
    }

    /// Whether user slot `index` was last held by a module that may come back.
    pub(crate) fn user_may_come_back(&self, index: usize) -> bool {
        self.holder(SlotId::User(index)).may_come_back()
    }

    pub(crate) fn detach_user(&self, index: usize) {
        self.users[index].attached.store(false, Ordering::Release);
        self.users_attached.fetch_sub(1, Ordering::AcqRel);
        self.wake_all();
    }

    pub(crate) fn is_user_attached(&self, index: usize) -> bool {
        self.users[index].attached.load(Ordering::Acquire)
    }

    pub(crate) fn users_attached(&self) -> usize {
        self.users_attached.load(Ordering::Acquire)
    }

    pub(crate) fn add_declaration(&self) {
        self.declarations.fetch_add(1, Ordering::AcqRel);
    }

    pub(crate) fn drop_declaration(&self) {
        if self.declarations.fetch_sub(1, Ordering::AcqRel) == 1 {
            self.wake_all();
        }
    }

    /// Whether the other side of `side` is gone for good, and why: nobody attached there,
    /// and either no declaration left from which anybody could attach, or the module that
    /// held it (every module, for the users' side) has ended for good.
    pub(crate) fn peer_gone(&self, owner_side: bool) -> Option<Gone> {
        // The usual case, a peer attached, costs one load and takes no lock.
        if self.other_side_attached(owner_side) {
            return None;
        }
        if self.declarations.load(Ordering::Acquire) == 0 {
            return Some(Gone::Closed);
        }
        let gone = if owner_side {
            let mut gone = None;
            for index in 0..self.capacity() {
                let holder = self.holder(SlotId::User(index));
                match (&holder.module, holder.gone()) {
                    (None, _) => {} // never held
                    (Some(_), Some(module)) => gone = Some(module.clone()),
                    (Some(_), None) => return None,
                }
            }
            gone
        } else {
            self.holder(SlotId::Owner).gone().cloned()
        };
        // A new peer may have attached while the holders were read.
        if self.other_side_attached(owner_side) {
            return None;
        }
        gone.map(Gone::Peer)
    }

    fn other_side_attached(&self, owner_side: bool) -> bool {
        if owner_side {
            self.users_attached() > 0
        } else {
            self.owner_attached.load(Ordering::Acquire)
        }
    }

    /// Wakes every waiter, so that each re-checks whether its peer is gone.
    pub(crate) fn wake_all(&self) {
        self.owner_wakers.server.wake();
        self.owner_wakers.poster.wake();
        for user in self.users.iter() {
            user.wakers.server.wake();
            user.wakers.poster.wake();
        }
    }
}

/// Registers `waker` with every user slot's poster waker: a broadcast waits on all of them.
pub(crate) fn register_broadcast<Req, Rep>(core: &Core<Req, Rep>, waker: &Waker) {
    for user in core.users.iter() {
        if user.in_broadcast.load(Ordering::Relaxed) {
            user.wakers.poster.register_by_ref(waker);
        }
    }
}

/// Records `module`, with the presence entered now (if any), as the holder of `at`, and has
/// the presence wake the port's waiters when the module is gone.
pub(crate) fn hold<Req: Send + 'static, Rep: Send + 'static>(
    core: &Arc<Core<Req, Rep>>,
    at: SlotId,
    module: &Name,
    presence: Option<Arc<Presence>>,
) {
    if let Some(presence) = &presence {
        let watcher: Arc<dyn Watcher> = Arc::clone(core) as Arc<dyn Watcher>;
        presence.watch(Arc::downgrade(&watcher));
    }
    let mut holder = core.holder(at);
    holder.module = Some(module.clone());
    holder.presence = presence;
}

impl<Req: Send, Rep: Send> Watcher for Core<Req, Rep> {
    fn wake_all(&self) {
        Core::wake_all(self);
    }
}
