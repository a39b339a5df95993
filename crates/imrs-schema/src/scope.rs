//! An assemblage's inside: its components, numbered locally.

use std::any::Any;
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};

use imrs_ports::Name;
use tokio::sync::Notify;

use crate::error::SchemaError;
use crate::net::Net;

/// The components of one assemblage (or of the network's top), by schema and number.
pub(crate) struct Scope {
    /// Prefixes the names of the instances here: empty at the top, `Grip_1/` inside
    /// `Grip_1`.
    pub(crate) path: String,
    pub(crate) parent: Option<Arc<Scope>>,
    pub(crate) net: Arc<Net>,
    members: Mutex<BTreeMap<(&'static str, u32), Option<Member>>>,
    changed: Notify,
}

/// A live instance, as its assemblage holds it.
#[derive(Clone)]
pub(crate) struct Member {
    pub(crate) ports: Arc<dyn Any + Send + Sync>,
    pub(crate) control: Arc<Control>,
}

/// Stops an instance and tells who waits that it ended.
pub(crate) struct Control {
    pub(crate) name: Name,
    pub(crate) inside: Arc<Scope>,
    stop: AtomicBool,
    stopping: Notify,
    ended: AtomicBool,
    ending: Notify,
}

impl Control {
    pub(crate) fn new(name: Name, inside: Arc<Scope>) -> Self {
        Self {
            name,
            inside,
            stop: AtomicBool::new(false),
            stopping: Notify::new(),
            ended: AtomicBool::new(false),
            ending: Notify::new(),
        }
    }

    /// `STOP{N_i}`: the instance ends at its next suspension point, and so does every
    /// instance inside it. All are told at once, before any of them closes its ports, so
    /// that none sees a neighbour's port close and takes it for a failure.
    pub(crate) fn stop(&self) {
        self.stop.store(true, Ordering::SeqCst);
        self.inside.stop_all();
        self.stopping.notify_waiters();
    }

    /// Completes once [`Control::stop`] has been called.
    pub(crate) async fn stopped(&self) {
        wait_for(&self.stopping, || self.stop.load(Ordering::SeqCst)).await;
    }

    pub(crate) fn end(&self) {
        self.ended.store(true, Ordering::SeqCst);
        self.ending.notify_waiters();
    }

    pub(crate) fn has_ended(&self) -> bool {
        self.ended.load(Ordering::SeqCst)
    }

    pub(crate) async fn ended(&self) {
        wait_for(&self.ending, || self.has_ended()).await;
    }
}

/// Waits on `notify` until `done` holds, never missing a notification sent between the
/// check and the wait.
async fn wait_for(notify: &Notify, done: impl Fn() -> bool) {
    loop {
        let notified = notify.notified();
        let mut notified = std::pin::pin!(notified);
        notified.as_mut().enable();
        if done() {
            return;
        }
        notified.await;
    }
}

impl Scope {
    pub(crate) fn top(net: Arc<Net>) -> Arc<Self> {
        Arc::new(Self {
            path: String::new(),
            parent: None,
            net,
            members: Mutex::default(),
            changed: Notify::new(),
        })
    }

    /// The inside of the instance `name`, a component here.
    pub(crate) fn inside(self: &Arc<Self>, name: &Name) -> Arc<Self> {
        Arc::new(Self {
            path: format!("{}/", name),
            parent: Some(Arc::clone(self)),
            net: Arc::clone(&self.net),
            members: Mutex::default(),
            changed: Notify::new(),
        })
    }

    fn members(&self) -> MutexGuard<'_, BTreeMap<(&'static str, u32), Option<Member>>> {
        // Each critical section is one map operation.
        self.members.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// Takes `number` (or the lowest free number) for a new instance of `schema`.
    pub(crate) fn reserve(
        &self,
        schema: &'static str,
        number: Option<u32>,
    ) -> Result<u32, SchemaError> {
        let mut members = self.members();
        let number = match number {
            Some(0) => return Err(SchemaError::ZeroInstance { schema }),
            Some(n) if members.contains_key(&(schema, n)) => {
                return Err(SchemaError::InstanceExists {
                    assemblage: match self.path.strip_suffix('/') {
                        Some(assemblage) => assemblage.into(),
                        None => "/".into(),
                    },
                    schema,
                    number: n,
                });
            }
            Some(n) => n,
            None => (1..)
                .find(|n| !members.contains_key(&(schema, *n)))
                .unwrap_or(u32::MAX),
        };
        members.insert((schema, number), None);
        Ok(number)
    }

    pub(crate) fn fill(&self, schema: &'static str, number: u32, member: Member) {
        self.members().insert((schema, number), Some(member));
    }

    pub(crate) fn remove(&self, schema: &'static str, number: u32) {
        self.members().remove(&(schema, number));
        self.changed.notify_waiters();
    }

    /// The live instances of `schema` here, by number.
    pub(crate) fn of(&self, schema: &'static str) -> Vec<(u32, Member)> {
        self.members()
            .range((schema, 0)..=(schema, u32::MAX))
            .filter_map(|(&(_, n), member)| member.clone().map(|member| (n, member)))
            .collect()
    }

    /// Every live instance here.
    pub(crate) fn all(&self) -> Vec<Member> {
        self.members().values().flatten().cloned().collect()
    }

    pub(crate) fn stop_all(&self) {
        self.all().iter().for_each(|member| member.control.stop());
    }

    /// Completes once no component is left.
    pub(crate) async fn emptied(&self) {
        wait_for(&self.changed, || self.members().is_empty()).await;
    }
}
