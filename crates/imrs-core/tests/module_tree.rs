//! The module tree: a costarted child belongs to the copy of its parent that started it, and
//! names in a cell are unique.

mod common;

use common::{at, paused_runtime, secs};

use std::sync::{Arc, Mutex};

use imrs_core::prelude::*;
use imrs_core::time::drive;
use imrs_core::{CellError, TaskError};

/// A child that works for ever on its owned port CHILD_PORT, which a second copy of it could
/// not own while the first still runs.
fn child(port: &Port<(), (), usage::Receive>) -> ModuleSpec<()> {
    let port = port.clone();
    ModuleSpec::new("CHILD", ()).task("CHILD", move |ctx| {
        let port = port.clone();
        async move {
            let _owned = port.owner()?;
            loop {
                ctx.delay(secs(1)).await;
            }
        }
    })
}

#[test]
fn a_restarted_parent_starts_its_child_anew_and_the_old_child_is_gone() {
    paused_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        let port = Port::<(), (), usage::Receive>::declare(
            PortSpec::new("CHILD_PORT", "CHILD").clock(cell.clock().clone()),
        );
        let costarts: Arc<Mutex<Vec<Result<(), String>>>> = Arc::default();
        let seen = Arc::clone(&costarts);
        let parent = cell
            .supervise(RestartPolicy::restart(2, secs(1)), move || {
                let (port, seen) = (port.clone(), Arc::clone(&seen));
                ModuleSpec::new("PARENT", ()).task("PARENT", move |ctx| {
                    let (port, seen) = (port.clone(), Arc::clone(&seen));
                    async move {
                        let child = ctx.costart(child(&port));
                        seen.lock()
                            .unwrap()
                            .push(child.as_ref().map(|_| ()).map_err(|e| e.to_string()));
                        child?;
                        ctx.delay(secs(5)).await;
                        Err::<(), TaskError>("the parent fails".into())
                    }
                })
            })
            .unwrap();
        drive(&clock, at(20)).await;
        // Three copies of the parent, each with a child of its own, each stopped with it.
        assert_eq!(*costarts.lock().unwrap(), [Ok(()), Ok(()), Ok(())]);
        let child_failures = cell
            .events()
            .snapshot()
            .into_iter()
            .filter(|event| event.module == "CHILD")
            .filter(|event| matches!(event.kind, EventKind::TaskFailed { .. }))
            .count();
        assert_eq!(
            child_failures, 0,
            "no child copy met its predecessor's port"
        );
        assert!(matches!(parent.outcome(), Some(ModuleOutcome::Failed(_))));
        assert!(!cell.kill("CHILD"), "the last copy's child went with it");
    });
}

#[test]
fn a_second_module_of_the_same_name_is_refused() {
    paused_runtime().block_on(async {
        let (cell, _clock) = Cell::virtual_clock();
        let idle = || {
            ModuleSpec::new("GATE", ()).task("GATE", |ctx| async move {
                ctx.delay(secs(10)).await;
                Ok(())
            })
        };
        let first = cell.start(idle()).unwrap();
        let second = cell.start(idle()).unwrap_err();
        assert_eq!(
            second,
            CellError::DuplicateModule {
                module: "GATE".into()
            }
        );
        assert_eq!(second.to_string(), "two modules are named GATE");
        // The first one is untouched, and `kill` still reaches it.
        assert!(cell.kill("GATE"));
        drop(first);
    });
}

#[test]
fn killing_a_parent_stops_its_children() {
    paused_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        let port = Port::<(), (), usage::Receive>::declare(
            PortSpec::new("CHILD_PORT", "CHILD").clock(cell.clock().clone()),
        );
        let mut parent = cell
            .start(ModuleSpec::new("PARENT", ()).task("PARENT", move |ctx| {
                let port = port.clone();
                async move {
                    ctx.costart(child(&port))?;
                    ctx.delay(secs(100)).await;
                    Ok(())
                }
            }))
            .unwrap();
        drive(&clock, at(2)).await;
        assert!(cell.kill("PARENT"));
        drive(&clock, at(3)).await;
        assert_eq!(parent.finished().await, ModuleOutcome::Killed);
        assert!(!cell.kill("CHILD"), "the child went with its parent");
        let child_end = cell
            .events()
            .snapshot()
            .into_iter()
            .find(|event| event.module == "CHILD" && event.kind == EventKind::ModuleKilled);
        assert!(child_end.is_some(), "the child's end is in the log");
    });
}
