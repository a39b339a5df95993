//! Modules as actors, and the order scheduler that runs them, for programming robot work
//! cells after Shin, *Intertask Communications in an Integrated Multi-Robot System* (1985).
//!
//! A **module** controls one indivisible subprocess — a robot, a gate, a feeder. It owns its
//! state, runs its tasks, answers queries with response handlers that read (never write)
//! its state, and reacts to exceptions such as a port's timeout. Its **order** ranks its
//! background code, handlers and named sections; a pending handler runs only when it
//! outranks the section a thread of the module is in, at that thread's next suspension
//! point. Modules talk only through the ports of [`imrs_ports`].
//!
//! Two modules: LOAD_IT queries its child LOAD_CARD for its status.
//!
//! ```
//! use std::time::Duration;
//! use imrs_core::prelude::*;
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! # let runtime = tokio::runtime::Builder::new_current_thread().enable_all().start_paused(true).build()?;
//! # runtime.block_on(async {
//! let (cell, clock) = Cell::virtual_clock();
//! // ASK_CHILD1(RC, NUM_DONE), owned by LOAD_IT: USAGE=QUERY, TIMEOUT=2 SEC.
//! let ask_child1 = Port::<(), (i32, u32), usage::Query>::declare(
//!     PortSpec::new("ASK_CHILD1", "LOAD_IT").timeout(Duration::from_secs(2)).clock(cell.clock().clone()),
//! );
//!
//! #[derive(Default)]
//! struct LoadCard { num_loaded: u32 }
//! let load_card = ModuleSpec::new("LOAD_CARD", LoadCard::default())
//!     .order(["ASK_CHILD1.STATUS", "LOAD_CARD"])
//!     .response("ASK_CHILD1.STATUS", ask_child1.responder_named("LOAD_CARD", |s: &LoadCard, ()| (0, s.num_loaded))?)
//!     .task("LOAD_CARD", |ctx| async move {
//!         loop {
//!             ctx.delay(Duration::from_secs(10)).await; // load a card
//!             ctx.state().update(|s| s.num_loaded += 1);
//!         }
//!     });
//!
//! let load_it = ModuleSpec::new("LOAD_IT", ()).task("LOAD_IT", move |ctx| {
//!     // Each copy of the task attaches anew: a restarted copy re-attaches to the same port.
//!     let ask_child1 = ask_child1.clone();
//!     async move {
//!         let mut ask_child1 = ask_child1.owner()?;
//!         ctx.delay(Duration::from_secs(25)).await;
//!         let (rc, num_loaded) = ctx.query(&mut ask_child1, ()).await?;
//!         assert_eq!((rc, num_loaded), (0, 2));
//!         Ok(())
//!     }
//! });
//! cell.start(load_card);
//! let mut load_it = cell.start(load_it);
//! imrs_core::time::drive(&clock, Instant::from_start(Duration::from_secs(30))).await;
//! assert_eq!(load_it.finished().await, ModuleOutcome::Finished);
//! # Ok::<_, Box<dyn std::error::Error>>(())
//! # })?;
//! # Ok(())
//! # }
//! ```

mod cell;
mod check;
mod deadlock;
mod event;
mod exception;
mod log;
mod module;
mod order;
mod processor;
mod supervision;
pub mod time;
mod waitfor;
mod work;

pub use cell::{Cell, ModuleHandle, ModuleOutcome};
pub use check::{CellError, CellErrors};
pub use event::{Event, EventKind, EventLog};
pub use exception::Exception;
pub use imrs_ports;
pub use log::{Log, Record};
pub use module::ctx::Ctx;
pub use module::spec::{ModuleDecl, ModuleSpec, TaskError, TaskResult};
pub use order::{Order, Rank};
pub use processor::{JobHandle, JobLost, Processor};
pub use supervision::RestartPolicy;
pub use waitfor::{Pool, WaitFor, WaitForError};
pub use work::{Performed, WorkSchedule};

/// Everything a cell author imports.
pub mod prelude {
    pub use crate::{
        Cell, Ctx, Event, EventKind, Exception, ModuleHandle, ModuleOutcome, ModuleSpec, Performed,
        Processor, RestartPolicy, TaskError, TaskResult, WaitFor, WorkSchedule,
    };
    pub use imrs_ports::prelude::*;
    pub use imrs_ports::{Instant, Name, SharedClock, UsageKind};
}
