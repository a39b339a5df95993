//! Modules as actors, and the order scheduler that runs them, for programming robot work
//! cells after Shin, *Intertask Communications in an Integrated Multi-Robot System* (1985).
//!
//! A **module** controls one indivisible subprocess — a robot, a gate, a feeder. It owns its
//! state, runs its tasks, answers queries with response handlers that read (never write)
//! its state, and reacts to exceptions such as a port's timeout. Its **order** ranks its
//! background code, handlers and named sections. Modules talk only through the ports of
//! [`imrs_ports`].
//!
//! # The order rule
//!
//! **A pending handler — response or exception alike — starts at the next suspension point
//! at which its rank outranks both the section of the thread it interrupts (the least urgent
//! live thread of the module) and every named section that any live thread of the module is
//! in.** A named section ranked above a handler is thus a promise that the handler never sees
//! the module inside it, whatever the module's other threads are doing; and CHIP_IT of the
//! seed's Appendix still answers `SHARE_FEEDER1.CRIT_SECTION` while it is in `INSERT`, even
//! with its FREEZE_CARD task in background code.
//!
//! Why this cannot deadlock a module by itself (priority inversion): the rule decides only
//! when a handler *starts*; a thread that runs — a task, or an exception handler already
//! started — is never held back by the order, whatever its rank. So the only waits the order
//! adds are pending handlers waiting for threads to leave sections. A thread leaves its
//! section as soon as its own code does; it is held back only by what it awaits (a port, a
//! delay, a barrier), never by the scheduler. A deadlock inside one module therefore needs a
//! thread that, inside a section some handler H must outrank, waits — directly or through
//! other threads — for H itself: it queries its own module, or waits for what an exception
//! handler it raised would do. For a named section that is a contradiction in the author's
//! order (the section promises H never runs inside it); for the background it is the seed's
//! own rule. Either way the wait goes through a port or barrier, so its `TIMEOUT` bounds it,
//! and a `PORT.TIMEOUT` handler ranked above the section runs. Across modules there is no
//! rank inheritance: the serving module's order decides when its handler runs, and the
//! waiter's port timeout bounds the wait, which is how the seed breaks the CHIP_IT/CHIP_IT2
//! deadlock.
//!
//! # The dead-peer rule
//!
//! **Whoever waits on a port — to send, query, receive or be queried — whose other side was
//! held by a module that has ended for good (finished, failed beyond its restart policy, or
//! killed with no restart coming) gets `PeerGone` at once, and so does every later wait, until
//! a new peer attaches; while a supervised restart is coming, it waits for the new copy,
//! bounded by its timeout.** An end attached by a module's thread, or a response end given to
//! its [`ModuleSpec`], belongs to the module; a costarted child belongs to the copy of its
//! parent that started it and is stopped with it.
//!
//! # The message-handler rule
//!
//! **Of the woken modules (and jobs) on one [`Processor`], the most urgent is polled next: a
//! module's urgency is its own priority ([`ModuleSpec::priority`]), lifted for its next poll
//! to the priority of the port whose message — request or reply — woke it, if that is higher;
//! equals go in the order they were placed, and one that has waited [`Processor::AGING`] polls
//! of others goes first.** Task and port priorities are one scale (1 is the most urgent; none
//! declared ranks below every declared one), so a routine module's emergency stop on a port of
//! priority 1 is served before the routine work of a module of priority 2, and a waiting
//! module is polled within `AGING + n - 1` polls of the others. Between modules on different
//! processors, or started with [`Cell::start`], tokio schedules and priorities do not apply.
//!
//! # Names
//!
//! Module, port, task and section names are interned: each distinct name is kept for the life
//! of the process, so that the paths that run at every message copy and compare a pointer.
//! Name things by role, as the seed does (`CHIP_IT`, `SHARE_FEEDER`), not by part or time.
//! [`Cell::tree`] draws the modules as the seed's tree, each port a vertical or a horizontal
//! link.
//!
//! # What the types do not stop
//!
//! - **Read-only handlers can still write through interior mutability.** A response handler
//!   gets `&S`, so it cannot assign to the state; but an atomic, a `Mutex` or any other cell
//!   inside `S` can be changed through `&S`. Doing so gives up what the order promises: a
//!   change made by a handler lands in the middle of whatever section of the background it
//!   interrupted, the background's `update` closures no longer see the state they left, and
//!   a run on virtual time may stop being reproducible once a handler's write races a task's.
//!   Keep `S` plain data; let a handler that must cause a change send a message or raise an
//!   exception, whose handler changes the state at its rank.
//! - **A caught panic is still printed.** A task (or handler) that panics is caught: the task
//!   fails, its restart policy and its `TASK.FAILED` handler apply, and the module lives on.
//!   Rust's panic hook runs before the catch, though, so the default hook prints the panic
//!   and its location to standard error. To keep a cell's output clean, return an `Err`
//!   instead of panicking, or install a hook of your own with [`std::panic::set_hook`] (for
//!   example one that logs through `tracing`); the failure is in the event log either way.
//! - **Virtual time needs a paused current-thread runtime.** [`time::drive`] advances a
//!   [`VirtualClock`](imrs_ports::VirtualClock) whenever every task is idle, which it reads
//!   from tokio's paused clock: build the runtime with `new_current_thread()` and
//!   `start_paused(true)`, which needs tokio's `test-util` feature.
//!
//! Two modules: LOAD_IT queries LOAD_CARD for its status. Each module, port, section and
//! handler is named once; the cell makes the port on its own clock, and checks each module
//! as it starts.
//!
//! ```
//! use std::time::Duration;
//! use imrs_core::prelude::*;
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! # let runtime = tokio::runtime::Builder::new_current_thread().enable_all().start_paused(true).build()?;
//! # runtime.block_on(async {
//! const LOAD_IT: Module = Module::new("LOAD_IT");
//! const LOAD_CARD: Module = Module::new("LOAD_CARD");
//! const LOAD: Section = Section::new("LOAD");
//! let (cell, clock) = Cell::virtual_clock();
//! // ASK_CHILD1(RC, NUM_DONE), owned by LOAD_IT: USAGE=QUERY, its query bounded by 5 s.
//! let ask_child1: Port<(), (i32, u32), usage::Query> =
//!     cell.port(PortSpec::new("ASK_CHILD1", LOAD_IT).owner_timeout(Duration::from_secs(5)))?;
//! let status = ask_child1.handler("STATUS");
//!
//! #[derive(Default)]
//! struct LoadCard { num_loaded: u32 }
//! let load_card = ModuleSpec::new(LOAD_CARD, LoadCard::default())
//!     .order([LOAD.name(), status.name()]) // STATUS is never answered mid-load
//!     .respond(&status, |s: &LoadCard, ()| (0, s.num_loaded))
//!     .task(LOAD_CARD, |ctx| async move {
//!         loop {
//!             ctx.section(&LOAD, ctx.delay(Duration::from_secs(8))).await; // load a card
//!             ctx.state().update(|s| s.num_loaded += 1);
//!             ctx.delay(Duration::from_secs(2)).await;
//!         }
//!     });
//! let loaded = load_card.view();
//!
//! let load_it = ModuleSpec::new(LOAD_IT, ()).task(LOAD_IT, move |ctx| {
//!     // Each copy of the task attaches anew: a restarted copy re-attaches to the same port.
//!     let ask_child1 = ctx.owner(&ask_child1);
//!     async move {
//!         let mut ask_child1 = ask_child1?;
//!         ctx.delay(Duration::from_secs(25)).await; // LOAD_CARD is in LOAD until 28 s
//!         let (rc, num_loaded) = ctx.query(&mut ask_child1, ()).await?;
//!         assert_eq!((rc, num_loaded), (0, 3));
//!         assert_eq!(ctx.now(), Instant::from_start(Duration::from_secs(28)));
//!         Ok(())
//!     }
//! });
//! cell.start(load_card)?;
//! let mut load_it = cell.start(load_it)?;
//! imrs_core::time::drive(&clock, Instant::from_start(Duration::from_secs(30))).await;
//! assert_eq!(load_it.finished().await, ModuleOutcome::Finished);
//! assert_eq!(loaded.inspect(|s| s.num_loaded), 3);
//! # Ok::<_, Box<dyn std::error::Error>>(())
//! # })?;
//! # Ok(())
//! # }
//! ```

mod cell;
mod check;
mod deadlock;
mod decl;
mod event;
mod exception;
mod kill;
mod launch;
mod log;
mod module;
mod order;
mod outcome;
mod processor;
mod shared;
mod supervision;
mod thread;
pub mod time;
mod tree;
mod wait_record;
mod waitfor;
mod watchdog;
mod work;

pub use cell::{Cell, Declare};
pub use check::{CellError, CellErrors};
pub use decl::ModuleDecl;
pub use event::{Event, EventKind, EventLog, Observed, Primitive};
pub use exception::Exception;
pub use outcome::ModuleOutcome;
pub use shared::ModuleHandle;

pub use log::{Log, Record};
pub use module::ctx::Ctx;

/// The futures and traits behind [`Ctx`]'s port operations: what `ctx.send`, `ctx.receive`
/// and `ctx.query` return, and how a failure names its port. A cell author awaits these and
/// never names them.
pub mod op {
    pub use crate::module::ctx::{
        PortFailure, PortOp, PortOperation, ShowReply, ShowRequest, ShowResult,
    };
}
pub use module::spec::{ModuleSpec, StateView, TaskError, TaskResult};
pub use order::{Order, Rank, Section};
pub use processor::{JobHandle, JobLost, Processor};
pub use supervision::RestartPolicy;
pub use tree::{Link, LinkKind, ModuleTree, TreeModule};
pub use waitfor::{DuplicateMember, Pool, WaitFor, WaitForError};
pub use work::{Performed, WorkSchedule};

/// Everything a cell author imports.
pub mod prelude {
    pub use crate::{
        Cell, Ctx, Event, EventKind, Exception, ModuleHandle, ModuleOutcome, ModuleSpec, Performed,
        Processor, RestartPolicy, Section, TaskError, TaskResult, WaitFor, WorkSchedule,
    };
    pub use imrs_ports::prelude::*;
    pub use imrs_ports::{Instant, Name, SharedClock, UsageKind};
}
