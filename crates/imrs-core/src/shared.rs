//! What a cell's modules share with it and with each other: the clock, the event log, the
//! wiring, the modules running (each with its kill switch), and the handles that watch a
//! module from outside. The cell and the supervisors that run modules both build on it.

use std::collections::BTreeMap;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};

use imrs_ports::{Name, SharedClock, Wiring};

use crate::deadlock::{Diagnosis, ModuleThreads};
use crate::event::{Event, EventKind, EventLog};
use crate::kill::KillSwitch;
use crate::outcome::{ModuleOutcome, Outcome};
use crate::tree::Placement;

pub(crate) struct CellShared {
    pub(crate) clock: SharedClock,
    pub(crate) events: EventLog,
    /// Whether the primitives that succeed are logged, each saying how long it waited and
    /// carrying the text of the values of the ports that show them.
    pub(crate) observe: AtomicBool,
    /// Set by a wait that begins, cleared by the diagnosis that looks at it: while no wait
    /// has begun since the last look, no new cycle can have closed.
    pub(crate) armed: AtomicBool,
    pub(crate) diagnosis: Mutex<Diagnosis>,
    /// Whether the diagnosis has been set going (a watchdog, on a clock other than a
    /// virtual one).
    pub(crate) watched: AtomicBool,
    /// Whether the cell runs on virtual time, where a wait whose peer waits is looked at
    /// as it begins (see [`CellShared::wait_began`]).
    pub(crate) on_virtual_time: bool,
    pub(crate) wiring: Mutex<Wiring>,
    pub(crate) modules: Mutex<Members>,
}

/// The running modules, by name, and the running users of each port.
#[derive(Default)]
pub(crate) struct Members {
    by_name: BTreeMap<Name, Member>,
    /// The running modules that use each port, kept beside `by_name`: a module's start
    /// counts its ports' users here rather than look through every running module.
    users: BTreeMap<Name, Vec<Name>>,
}

impl Members {
    pub(crate) fn contains(&self, module: &Name) -> bool {
        self.by_name.contains_key(module)
    }

    pub(crate) fn get(&self, module: &Name) -> Option<&Member> {
        self.by_name.get(module)
    }

    pub(crate) fn get_mut(&mut self, module: &Name) -> Option<&mut Member> {
        self.by_name.get_mut(module)
    }

    pub(crate) fn insert(&mut self, module: Name, member: Member) {
        for port in &member.placement.uses {
            self.users
                .entry(port.clone())
                .or_default()
                .push(module.clone());
        }
        self.by_name.insert(module, member);
    }

    pub(crate) fn remove(&mut self, module: &Name) {
        let Some(member) = self.by_name.remove(module) else {
            return;
        };
        for port in &member.placement.uses {
            if let Some(users) = self.users.get_mut(port) {
                users.retain(|user| user != module);
                if users.is_empty() {
                    self.users.remove(port);
                }
            }
        }
    }

    /// The running modules that use `port`, in the order they started.
    pub(crate) fn users_of(&self, port: &Name) -> &[Name] {
        self.users.get(port).map_or(&[], Vec::as_slice)
    }

    pub(crate) fn names(&self) -> impl Iterator<Item = &Name> {
        self.by_name.keys()
    }

    pub(crate) fn placements(&self) -> impl Iterator<Item = &Placement> {
        self.by_name.values().map(|member| &member.placement)
    }
}

/// A running module: its switch, and where it sits in the tree.
pub(crate) struct Member {
    pub(crate) switch: Arc<KillSwitch>,
    pub(crate) placement: Placement,
    /// The threads of its running copy, whose waits the deadlock diagnosis reads.
    pub(crate) threads: ModuleThreads,
}

impl CellShared {
    pub(crate) fn new(clock: SharedClock) -> Self {
        Self {
            on_virtual_time: clock.as_virtual().is_some(),
            clock,
            events: EventLog::new(),
            observe: AtomicBool::new(false),
            armed: AtomicBool::new(false),
            diagnosis: Mutex::default(),
            watched: AtomicBool::new(false),
            wiring: Mutex::default(),
            modules: Mutex::default(),
        }
    }

    pub(crate) fn kill(&self, module: &str) -> bool {
        let switch = self.switch(module);
        switch.inspect(|switch| switch.kill()).is_some()
    }

    pub(crate) fn switch(&self, module: &str) -> Option<Arc<KillSwitch>> {
        lock(&self.modules)
            .get(&Name::from(module))
            .map(|member| Arc::clone(&member.switch))
    }

    /// Whether the cell observes its primitives ([`Cell::observe`](crate::Cell::observe)).
    #[inline]
    pub(crate) fn observing(&self) -> bool {
        self.observe.load(Ordering::Relaxed)
    }

    /// Module `module` has begun a wait on `port`, served by `peer` (or by the port's
    /// users).
    ///
    /// On a clock other than a virtual one, this marks the next look of the watchdog as
    /// worth making: a load, and a store only for the first wait since the last look.
    ///
    /// On virtual time a cycle may close and be broken within one instant (a query that
    /// times out and is asked again at once, while the twin still waits, then a handler
    /// that breaks it), and a cell's report counts each cycle met. So there the cycle is
    /// looked for as the wait begins, as soon as a peer is seen waiting itself: one lock of
    /// the running modules, and a look only then. A rendezvous answered at once never comes
    /// here.
    #[inline]
    pub(crate) fn wait_began(&self, module: &Name, port: &Name, peer: Option<&Name>) {
        if self.on_virtual_time {
            self.look_if_peer_waits(module, port, peer);
        } else if !self.armed.load(Ordering::Relaxed) {
            self.armed.store(true, Ordering::Relaxed);
        }
    }

    /// [`CellShared::wait_began`] on virtual time: kept out of line, so that the path of a
    /// message on other clocks carries none of it.
    #[inline(never)]
    fn look_if_peer_waits(&self, module: &Name, port: &Name, peer: Option<&Name>) {
        let peer_waits = {
            let modules = lock(&self.modules);
            let waits = |other: &Name| {
                other != module
                    && modules
                        .get(other)
                        .is_some_and(|member| member.threads.any_waiting())
            };
            match peer {
                Some(peer) => waits(peer),
                None => modules.users_of(port).iter().any(waits),
            }
        };
        if peer_waits {
            self.look();
        }
    }

    /// Changes the record of the threads of module `module`'s running copy.
    pub(crate) fn threads_of(&self, module: &Name, change: impl FnOnce(&mut ModuleThreads)) {
        if let Some(member) = lock(&self.modules).get_mut(module) {
            change(&mut member.threads);
        }
    }

    /// Looks for deadlock cycles among the waits in progress, if any wait began since the
    /// last look, and logs each new one from the wait that closed it.
    pub(crate) fn diagnose(&self) {
        if self.armed.swap(false, Ordering::AcqRel) {
            self.look();
        }
    }

    /// Looks for deadlock cycles among the waits in progress now, and logs each new one.
    fn look(&self) {
        let found = {
            let mut diagnosis = lock(&self.diagnosis);
            let modules = lock(&self.modules);
            let users = &modules.users;
            diagnosis.look(
                modules
                    .by_name
                    .iter()
                    .map(|(name, member)| (name, &member.threads)),
                |port| {
                    users
                        .iter()
                        .find(|(name, _)| name.token() == port)
                        .map_or(&[], |(_, users)| users.as_slice())
                },
            )
        };
        if found.is_empty() || !(self.events.is_wanted() || crate::event::traced()) {
            return;
        }
        let at = self.clock.now();
        for found in found {
            self.events.record(Event {
                at,
                module: found.module,
                task: Some(found.task),
                kind: EventKind::Deadlock { cycle: found.cycle },
            });
        }
    }

    pub(crate) fn record(&self, module: &Name, kind: EventKind) {
        self.events.record(Event {
            at: self.clock.now(),
            module: module.clone(),
            task: None,
            kind,
        });
    }
}

pub(crate) fn lock<T>(mutex: &Mutex<T>) -> MutexGuard<'_, T> {
    // Each critical section is one map operation: a panic cannot leave it half-done.
    mutex.lock().unwrap_or_else(PoisonError::into_inner)
}

/// A running module, seen from outside.
#[derive(Debug, Clone)]
pub struct ModuleHandle {
    pub(crate) name: Name,
    pub(crate) kill: Arc<KillSwitch>,
    pub(crate) done: Arc<Outcome>,
}

impl ModuleHandle {
    /// The module's name.
    pub fn name(&self) -> &Name {
        &self.name
    }

    /// Kills the running copy; a supervised module gets a new one.
    pub fn kill(&self) {
        self.kill.kill();
    }

    /// Stops the module for good.
    pub fn stop(&self) {
        self.kill.stop();
    }

    /// How the module ended, if it has.
    pub fn outcome(&self) -> Option<ModuleOutcome> {
        self.done.get()
    }

    /// Waits until the module has ended for good.
    pub async fn finished(&mut self) -> ModuleOutcome {
        // A supervisor dropped without a word (its runtime shut down) tells `Killed`.
        self.done.wait().await
    }
}

/// The modules one copy of a module costarted.
#[derive(Clone, Default)]
pub(crate) struct Children(Arc<Mutex<Vec<ModuleHandle>>>);

impl Children {
    /// Adds `child`, forgetting the children that have ended, so that a parent that
    /// costarts children all its life keeps only the live ones.
    pub(crate) fn adopt(&self, child: &ModuleHandle) {
        let mut children = lock(&self.0);
        children.retain(|known| known.outcome().is_none());
        children.push(child.clone());
    }

    /// Stops every child for good and waits until each has ended (and, in turn, its own
    /// children), so that a new copy of the parent can start children of the same names.
    pub(crate) async fn stop_all(&self) {
        let children = std::mem::take(&mut *lock(&self.0));
        for child in &children {
            child.stop();
        }
        for mut child in children {
            child.finished().await;
        }
    }
}
