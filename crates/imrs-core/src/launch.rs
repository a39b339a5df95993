//! Running a module: the supervisor that makes its copies, one after another, as its
//! restart policy allows, and `COSTART`, by which a module's task starts a child. Kept apart
//! from the cell, which calls it, and from a module's context, which it extends with
//! `costart`: a module can start modules, and this is the one place that knows both.

use std::pin::Pin;
use std::sync::Arc;
use std::task::{Context, Poll};

use imrs_ports::transport::Presence;
use imrs_ports::{Name, Wiring};

use crate::check::{CellError, CellErrors, check_module};
use crate::event::EventKind;
use crate::kill::KillSwitch;
use crate::module::ctx::Ctx;
use crate::module::run::{ModuleExit, ModuleRun};
use crate::module::spec::ModuleSpec;
use crate::outcome::{ModuleOutcome, Outcome, Teller};
use crate::shared::{CellShared, Children, Member, Members, ModuleHandle, lock};
use crate::supervision::RestartPolicy;

pub(crate) type Factory<S> = Box<dyn FnMut() -> ModuleSpec<S> + Send>;

/// Spawns the supervisor of one module as a tokio task of its own.
pub(crate) fn spawn_module<S: Send + Sync + 'static>(
    cell: Arc<CellShared>,
    parent: Option<Name>,
    policy: RestartPolicy,
    first: ModuleSpec<S>,
    factory: Option<Factory<S>>,
) -> Result<ModuleHandle, CellErrors> {
    let (handle, supervisor) = supervisor(cell, (parent, None), policy, first, factory)?;
    tokio::spawn(supervisor);
    Ok(handle)
}

/// The supervisor of one module: it runs copies of the module until one finishes, or the
/// policy is spent, or the module is stopped. The caller places it on a task. Each copy's
/// costarted children are stopped, and waited for, when the copy ends: a child belongs to
/// the copy of its parent that started it.
pub(crate) fn supervisor<S: Send + Sync + 'static>(
    cell: Arc<CellShared>,
    (parent, processor): (Option<Name>, Option<Name>),
    policy: RestartPolicy,
    first: ModuleSpec<S>,
    mut factory: Option<Factory<S>>,
) -> Result<(ModuleHandle, impl Future<Output = ()> + Send + 'static), CellErrors> {
    let name = first.name.clone();
    let kill = Arc::new(KillSwitch::default());
    crate::watchdog::watch(&cell);
    {
        // The modules, then the wiring: the order every path that takes both keeps.
        let mut modules = lock(&cell.modules);
        if modules.contains(&name) {
            return Err(CellError::DuplicateModule { module: name }.into());
        }
        let wiring = lock(&cell.wiring);
        let placement = first.placement(parent.clone(), processor, &wiring);
        let mut problems = match check_module(&wiring, &first.declaration()) {
            Ok(()) => Vec::new(),
            Err(found) => found.0,
        };
        // Room on each port it uses, beside the modules running now.
        problems.extend(too_many_users(&wiring, &modules, &name, &placement.uses));
        if !problems.is_empty() {
            return Err(CellErrors(problems));
        }
        modules.insert(
            name.clone(),
            Member {
                switch: Arc::clone(&kill),
                placement,
                threads: Default::default(),
            },
        );
    }
    let presence = Presence::new(name.clone());
    let done = Arc::new(Outcome::default());
    let report = Teller::new(&done);
    let handle = ModuleHandle {
        name: name.clone(),
        kill: Arc::clone(&kill),
        done,
    };
    cell.record(
        &name,
        EventKind::ModuleStarted {
            parent: parent.clone(),
        },
    );
    // Boxed: what an async block captures stays in its task for the task's whole life, and
    // a spec is large beside a running module's needs.
    let first = Box::new(first);
    let supervisor = async move {
        let mut next = Some(first);
        let mut attempt = 0;
        let outcome = loop {
            // In one statement, so that the emptied box is freed before the copy runs.
            let spec = *next.take().expect("a copy is made before every run");
            let children = Children::default();
            let copy = ModuleRun::new(
                spec,
                Arc::clone(&cell),
                parent.clone(),
                Arc::clone(&kill),
                children.clone(),
                &presence,
            );
            let exit = Present {
                presence: &presence,
                copy,
            }
            .await;
            // The kill that ended this copy is spent; one that comes later is for the next.
            // (Rearming before a copy starts would lose a kill made before its first poll.)
            kill.rearm();
            // Boxed, as the restart delay below: awaited once per copy, they would otherwise
            // take room in every idle module's task for its whole life.
            Box::pin(children.stop_all()).await;
            let outcome = match exit {
                ModuleExit::Finished => {
                    cell.record(&name, EventKind::ModuleFinished);
                    break ModuleOutcome::Finished;
                }
                ModuleExit::Killed => {
                    cell.record(&name, EventKind::ModuleKilled);
                    ModuleOutcome::Killed
                }
                ModuleExit::Failed(reason) => {
                    cell.record(
                        &name,
                        EventKind::ModuleFailed {
                            reason: reason.clone(),
                        },
                    );
                    ModuleOutcome::Failed(reason)
                }
            };
            attempt += 1;
            let (Some(delay), Some(factory)) = (policy.delay_before(attempt), factory.as_mut())
            else {
                break outcome;
            };
            if kill.is_stopped() {
                break outcome;
            }
            Box::pin(cell.clock.sleep(delay)).await;
            if kill.is_stopped() {
                break outcome;
            }
            let copy = factory();
            let wired = check_module(&lock(&cell.wiring), &copy.declaration());
            if let Err(problems) = wired {
                // The new copy cannot even be wired (say, its response end is taken).
                let reason = format!("a new copy cannot be wired: {problems}");
                cell.record(
                    &name,
                    EventKind::ModuleFailed {
                        reason: reason.clone(),
                    },
                );
                break ModuleOutcome::Failed(reason);
            }
            next = Some(Box::new(copy));
            cell.record(&name, EventKind::ModuleRestarted { attempt });
        };
        lock(&cell.modules).remove(&name);
        // Gone for good: whoever waits on a port the module held fails now (PeerGone).
        presence.set_gone();
        report.tell(outcome);
    };
    Ok((handle, supervisor))
}

/// A module's copy, polled within the module's presence, so that the ends its threads
/// attach are known as the module's.
struct Present<'a, F> {
    presence: &'a Arc<Presence>,
    copy: F,
}

impl<F: Future + Unpin> Future for Present<'_, F> {
    type Output = F::Output;

    #[inline(always)]
    fn poll(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<F::Output> {
        let this = self.get_mut();
        Presence::within(Some(this.presence), || Pin::new(&mut this.copy).poll(cx))
    }
}

/// The ports in `uses` that module `name` would take past their number of users, with the
/// modules running now that use them.
fn too_many_users(
    wiring: &Wiring,
    modules: &Members,
    name: &Name,
    uses: &[Name],
) -> Vec<CellError> {
    uses.iter()
        .filter_map(|port| {
            let mut users: Vec<Name> = modules
                .users_of(port)
                .iter()
                .filter(|module| *module != name)
                .cloned()
                .collect();
            // Looked up only for a port that has users already: a first user always fits.
            if users.is_empty() {
                return None;
            }
            let capacity = wiring.port_info(port.as_str())?.capacity;
            if users.len() < capacity {
                return None;
            }
            users.sort();
            users.push(name.clone());
            Some(CellError::TooManyUsers {
                port: port.clone(),
                capacity,
                modules: users,
            })
        })
        .collect()
}

impl<S: Send + Sync + 'static> Ctx<S> {
    /// `COSTART`: starts `child` as a child module of this one. The child belongs to this
    /// copy of the module: when the copy ends (finished, failed, killed), the child is
    /// stopped. Refused if a module of the child's name runs in the cell.
    pub fn costart<C: Send + Sync + 'static>(
        &self,
        child: ModuleSpec<C>,
    ) -> Result<ModuleHandle, CellErrors> {
        let cell = Arc::clone(&self.module_shared().cell);
        let parent = Some(self.module_shared().name.clone());
        let handle = spawn_module(cell, parent, RestartPolicy::NEVER, child, None)?;
        self.module_shared().children.adopt(&handle);
        Ok(handle)
    }

    /// As [`Ctx::costart`], with a factory that makes a new copy of the child after a
    /// failure, as `policy` allows.
    pub fn costart_supervised<C, F>(
        &self,
        policy: RestartPolicy,
        mut factory: F,
    ) -> Result<ModuleHandle, CellErrors>
    where
        C: Send + Sync + 'static,
        F: FnMut() -> ModuleSpec<C> + Send + 'static,
    {
        let cell = Arc::clone(&self.module_shared().cell);
        let parent = Some(self.module_shared().name.clone());
        let first = factory();
        let handle = spawn_module(cell, parent, policy, first, Some(Box::new(factory)))?;
        self.module_shared().children.adopt(&handle);
        Ok(handle)
    }
}
