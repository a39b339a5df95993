//! A module declared with each port named once: made by the cell, `.uses(&port)`,
//! `.respond(&port.handler("STATUS"), handler)` with its name built from the port, `ctx.owner(&port)`
//! and `ctx.user(&port)` attaching for the module; and its state read from outside.

mod common;

use common::{at, paused_runtime, secs};

use imrs_core::CellError;
use imrs_core::prelude::*;
use imrs_core::time::drive;
use imrs_ports::WireError;

#[test]
fn a_cell_declared_through_its_ports_checks_runs_and_can_be_read_after() {
    paused_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        let status: Port<(), u32, usage::Query> =
            cell.port(PortSpec::new("B_STATUS", "WELD_CELL")).unwrap();
        let seams: Port<u32, (), usage::Receive> =
            cell.port(PortSpec::new("SEAMS", "WELD_CELL")).unwrap();

        let welder = ModuleSpec::new("WELDER_B", 0u32)
            .order([
                "WELD".into(),
                status.handler("STATUS").name(),
                "WELDER_B".into(),
            ])
            .uses(&seams)
            .respond(&status.handler("STATUS"), |welded: &u32, ()| *welded)
            .task("WELDER_B", {
                let port = seams.clone(); // the one clone: this task's own handle
                move |ctx| {
                    let seams = ctx.user(&port);
                    async move {
                        let mut seams = seams?;
                        for seam in 1..=3 {
                            ctx.section(&Section::new("WELD"), ctx.delay(secs(5))).await;
                            ctx.state().update(|welded| *welded += 1);
                            ctx.send(&mut seams, seam).await?;
                        }
                        Ok(())
                    }
                }
            });
        let welded = welder.view();
        let reports = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
        let noted = std::sync::Arc::clone(&reports);
        let weld_cell = ModuleSpec::new("WELD_CELL", ()).task("WELD_CELL", move |ctx| {
            let (status, seams) = (ctx.owner(&status), ctx.owner(&seams));
            let noted = std::sync::Arc::clone(&noted);
            async move {
                let (mut status, mut seams) = (status?, seams?);
                for _ in 0..3 {
                    let (_, done) = ctx.receive(&mut seams).await?;
                    done.reply(());
                    let count = ctx.query(&mut status, ()).await?;
                    noted.lock().unwrap().push(count);
                }
                Ok(())
            }
        });
        cell.check(&[welder.declaration(), weld_cell.declaration()])
            .unwrap();
        cell.start(welder).unwrap();
        let mut weld_cell = cell.start(weld_cell).unwrap();
        drive(&clock, at(30)).await;
        assert_eq!(weld_cell.finished().await, ModuleOutcome::Finished);
        assert_eq!(*reports.lock().unwrap(), [1, 2, 3]);
        assert_eq!(welded.inspect(|welded| *welded), 3);
    });
}

#[test]
fn a_response_end_that_cannot_attach_is_reported_and_the_module_is_refused() {
    let (cell, _clock) = Cell::virtual_clock();
    // #USERS=1: one responder only.
    let status: Port<(), u32, usage::Query> =
        cell.port(PortSpec::new("B_STATUS", "WELD_CELL")).unwrap();
    let first = ModuleSpec::new("WELDER_A", ()).respond(&status.handler("STATUS"), |_: &(), ()| 1);
    let second = ModuleSpec::new("WELDER_B", ()).respond(&status.handler("STATUS"), |_: &(), ()| 2);
    let taken = WireError::TooManyUsers {
        port: "B_STATUS".into(),
        module: "WELDER_B".into(),
        capacity: 1,
    };
    let problems = cell
        .check(&[first.declaration(), second.declaration()])
        .unwrap_err();
    assert!(
        problems.0.contains(&CellError::Wire(taken.clone())),
        "{problems}"
    );
    let refused = paused_runtime().block_on(async { cell.start(second).unwrap_err() });
    assert!(refused.0.contains(&CellError::Wire(taken)), "{refused}");
    assert!(
        refused
            .to_string()
            .contains("module WELDER_B cannot use port B_STATUS")
    );
}

#[test]
fn ctx_user_attaches_under_the_module_name_and_the_user_list_names_it() {
    paused_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        let torch: Port<(), (), usage::Send> = cell
            .port(PortSpec::new("TORCH", "WELD_CELL").user_list(["WELDER_A"]))
            .unwrap();
        let refused = std::sync::Arc::new(std::sync::Mutex::new(None));
        let noted = std::sync::Arc::clone(&refused);
        cell.start(
            ModuleSpec::new("WELDER_B", ()).task("WELDER_B", move |ctx| {
                *noted.lock().unwrap() = ctx.user(&torch).err();
                async { Ok(()) }
            }),
        )
        .unwrap();
        drive(&clock, at(1)).await;
        assert_eq!(
            *refused.lock().unwrap(),
            Some(WireError::NotOnUserList {
                port: "TORCH".into(),
                module: "WELDER_B".into()
            })
        );
    });
}
