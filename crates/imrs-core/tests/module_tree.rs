//! The module tree: a costarted child belongs to the copy of its parent that started it, and
//! names in a cell are unique.

mod common;

use common::{at, paused_runtime, secs};

use std::sync::{Arc, Mutex};

use imrs_core::prelude::*;
use imrs_core::time::drive;
use imrs_core::{CellError, CellErrors, TaskError};

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
        let port: Port<(), (), usage::Receive> =
            cell.port(PortSpec::new("CHILD_PORT", "CHILD")).unwrap();
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
            CellErrors(vec![CellError::DuplicateModule {
                module: "GATE".into()
            }])
        );
        assert_eq!(second.0[0].to_string(), "two modules are named GATE");
        // The first one is untouched, and `kill` still reaches it.
        assert!(cell.kill("GATE"));
        drop(first);
    });
}

#[test]
fn killing_a_parent_stops_its_children() {
    paused_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        let port: Port<(), (), usage::Receive> =
            cell.port(PortSpec::new("CHILD_PORT", "CHILD")).unwrap();
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

/// A module that idles: the owner of the ports declared for it, and a user of `uses`.
fn idle(name: &str, uses: Option<&Port<(), (), usage::Receive>>) -> ModuleSpec<()> {
    let mut spec = ModuleSpec::new(name, ());
    if let Some(port) = uses {
        spec = spec.uses(port);
    }
    spec.task(name, |ctx| async move {
        loop {
            ctx.delay(secs(1)).await;
        }
    })
}

#[test]
fn the_cell_draws_its_tree_with_vertical_and_horizontal_links() {
    paused_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        let declare = |port: &str, owner: &str| {
            let port: Port<(), (), usage::Receive> = cell.port(PortSpec::new(port, owner)).unwrap();
            port
        };
        // LOADER costarts two cards; each card asks LOADER (vertical), CARD2 asks CARD1, its
        // sibling (horizontal), and GATE, another branch, asks CARD2 (horizontal).
        let load = declare("LOAD", "LOADER");
        let load2 = declare("LOAD2", "LOADER");
        let share = declare("SHARE", "CARD1");
        let pass = declare("PASS", "CARD2");
        let (card1, card2) = (
            idle("CARD1", Some(&load)),
            idle("CARD2", Some(&share)).uses(&load2),
        );
        let children = Arc::new(Mutex::new(Some((card1, card2))));
        let loader = ModuleSpec::new("LOADER", ()).task("LOADER", move |ctx| {
            let children = Arc::clone(&children);
            async move {
                let (card1, card2) = children.lock().unwrap().take().ok_or("started twice")?;
                ctx.costart(card1)?;
                ctx.costart(card2)?;
                loop {
                    ctx.delay(secs(1)).await;
                }
            }
        });
        let processor = Processor::new("CPU1");
        cell.start_on(&processor, loader.priority(2)).unwrap();
        cell.start(idle("GATE", Some(&pass))).unwrap();
        drive(&clock, at(1)).await;

        let tree = cell.tree();
        let kind_of = |port: &str| {
            tree.links
                .iter()
                .filter(|link| link.port.as_str() == port)
                .map(|link| (link.owner.to_string(), link.user.to_string(), link.kind))
                .collect::<Vec<_>>()
        };
        use imrs_core::LinkKind::{Horizontal, Vertical};
        assert_eq!(
            kind_of("LOAD"),
            [("LOADER".into(), "CARD1".into(), Vertical)]
        );
        assert_eq!(
            kind_of("LOAD2"),
            [("LOADER".into(), "CARD2".into(), Vertical)]
        );
        assert_eq!(
            kind_of("SHARE"),
            [("CARD1".into(), "CARD2".into(), Horizontal)]
        );
        assert_eq!(
            kind_of("PASS"),
            [("CARD2".into(), "GATE".into(), Horizontal)]
        );
        let loader = tree.module("LOADER").unwrap();
        assert_eq!(loader.processor.as_ref().map(Name::as_str), Some("CPU1"));
        assert_eq!(loader.priority.number(), Some(2));

        let drawn = tree.to_string();
        let expected = [
            "cell",
            "├─ GATE  [0 vertical, 1 horizontal]",
            "└─ LOADER  [2 vertical, 0 horizontal, priority 2, on CPU1]",
            "   ├─ CARD1  [1 vertical, 1 horizontal]",
            "   └─ CARD2  [1 vertical, 2 horizontal]",
            "links (owner <- user):",
            "  LOAD   LOADER <- CARD1  vertical",
            "  LOAD2  LOADER <- CARD2  vertical",
            "  PASS   CARD2 <- GATE  horizontal",
            "  SHARE  CARD1 <- CARD2  horizontal",
        ];
        assert_eq!(drawn.lines().collect::<Vec<_>>(), expected, "{drawn}");

        // A module that ends leaves the tree, and its links go with it.
        cell.stop("GATE");
        drive(&clock, at(2)).await;
        let tree = cell.tree();
        assert!(tree.module("GATE").is_none());
        assert!(tree.links.iter().all(|link| link.user.as_str() != "GATE"));
    });
}
