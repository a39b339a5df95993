//! Slips a user can make in writing a cell: each fails loudly, by name, when the cell starts
//! (or in the task that makes it), never in silence at run time.

mod common;

use common::{at, paused_runtime, secs};
use imrs_core::prelude::*;
use imrs_core::time::drive;
use imrs_core::{CellError, ModuleOutcome};
use imrs_ports::{Replied, SendError, WireError};

#[test]
fn a_section_the_order_does_not_rank_fails_its_task_by_name() {
    paused_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        const PLACE: Section = Section::new("PLACE");
        // A cell built from data misspells the section it enters.
        let misspelt = Section::named("PLACEE");
        let spec = ModuleSpec::new("PALLETIZER", ())
            .order([PLACE.name(), "PALLETIZER".into()])
            .task("PALLETIZER", move |ctx| {
                let misspelt = misspelt.clone();
                async move {
                    ctx.section(&PLACE, ctx.delay(secs(1))).await;
                    ctx.section(&misspelt, ctx.delay(secs(1))).await;
                    Ok(())
                }
            });
        let mut module = cell.start(spec).unwrap();
        drive(&clock, at(5)).await;
        let ModuleOutcome::Failed(reason) = module.finished().await else {
            panic!("the module must fail");
        };
        assert!(
            reason.contains(
                "module PALLETIZER entered section PLACEE, which its order does not rank"
            ),
            "{reason}"
        );
    });
}

#[test]
fn a_response_handler_left_out_of_the_order_refuses_the_module_at_start() {
    paused_runtime().block_on(async {
        let (cell, _clock) = Cell::virtual_clock();
        let status: Port<(), u32, usage::Response> =
            cell.port(PortSpec::new("STATUS", "PALLETIZER")).unwrap();
        const PLACE: Section = Section::new("PLACE");
        let spec = ModuleSpec::new("PALLETIZER", 0u32)
            .order([PLACE.name(), "PALLETIZER".into()])
            .respond(&status.handler("ASK"), |placed: &u32, ()| *placed)
            .task("PALLETIZER", |_| async { Ok(()) });
        let refused = cell.start(spec).unwrap_err();
        assert_eq!(
            refused.0,
            [CellError::Unranked {
                module: "PALLETIZER".into(),
                handler: "STATUS.ASK".into(),
            }]
        );
        assert!(refused.to_string().contains("STATUS.ASK"), "{refused}");
    });
}

#[test]
fn a_port_on_another_clock_is_refused_by_name() {
    let (cell, _clock) = Cell::virtual_clock();
    // Made outside the cell: it runs on a wall clock of its own.
    let stray = Port::<(), (), usage::Send>::new(PortSpec::new("STRAY", "GATE"));
    assert_eq!(
        cell.declare(&stray),
        Err(WireError::OtherClock {
            port: "STRAY".into()
        })
    );
    // Made by the cell, but told to use another clock.
    let (_other, other_clock) = Cell::virtual_clock();
    let refused = cell
        .port::<(), (), usage::Send, AnyUser, 1>(
            PortSpec::new("ELSEWHERE", "GATE").clock(std::sync::Arc::new(other_clock)),
        )
        .unwrap_err();
    assert_eq!(
        refused,
        WireError::OtherClock {
            port: "ELSEWHERE".into()
        }
    );
    assert!(
        refused
            .to_string()
            .contains("port ELSEWHERE runs on another clock")
    );
}

#[test]
fn a_port_the_cell_makes_times_out_on_the_cells_virtual_clock() {
    paused_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        let pick: Port<(), (), usage::Send> = cell
            .port(PortSpec::new("PICK", "PALLETIZER").owner_timeout(secs(2)))
            .unwrap();
        let spec = ModuleSpec::new("PALLETIZER", ()).task("PALLETIZER", move |ctx| {
            let pick = ctx.owner(&pick);
            async move {
                let mut pick = pick?;
                // Nobody receives: five sends, five timeouts, 2 s apart on the cell's clock.
                for n in 1..=5u64 {
                    let failed = ctx.send(&mut pick, ()).await.unwrap_err();
                    assert!(failed.is_timeout(), "{failed}");
                    assert_eq!(ctx.now(), at(2 * n));
                }
                Ok(())
            }
        });
        let mut module = cell.start(spec).unwrap();
        drive(&clock, at(20)).await;
        assert_eq!(module.finished().await, ModuleOutcome::Finished);
    });
}

#[test]
fn a_module_using_a_port_the_cell_never_declared_is_refused_at_start() {
    paused_runtime().block_on(async {
        let (cell, _clock) = Cell::virtual_clock();
        let undeclared = Port::<(), (), usage::Send>::new(
            PortSpec::new("PLACE", "PALLETIZER").clock(cell.clock().clone()),
        );
        let spec = ModuleSpec::new("GRIPPER", ())
            .uses(&undeclared)
            .task("GRIPPER", |_| async { Ok(()) });
        let refused = cell.start(spec).unwrap_err();
        assert_eq!(
            refused.0,
            [CellError::UnknownPort {
                port: "PLACE".into(),
                module: "GRIPPER".into(),
            }]
        );
        assert!(
            refused
                .to_string()
                .contains("module GRIPPER names port PLACE, which is not declared"),
            "{refused}"
        );
    });
}

#[test]
fn a_module_cannot_attach_the_owner_end_of_another_modules_port() {
    paused_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        let place: Port<(), (), usage::Send> =
            cell.port(PortSpec::new("PLACE", "PALLETIZER")).unwrap();
        let spec = ModuleSpec::new("GRIPPER", ()).task("GRIPPER", move |ctx| {
            let place = ctx.owner(&place);
            async move {
                place?;
                Ok(())
            }
        });
        let mut module = cell.start(spec).unwrap();
        drive(&clock, at(1)).await;
        let ModuleOutcome::Failed(reason) = module.finished().await else {
            panic!("the module must fail");
        };
        assert!(
            reason.contains(
                "module GRIPPER attached the owner end of port PLACE, which PALLETIZER owns"
            ),
            "{reason}"
        );
    });
}

#[test]
fn a_reply_to_a_sender_that_timed_out_comes_back_to_the_replier() {
    paused_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        let place: Port<u32, u32, usage::Send> = cell
            .port(PortSpec::new("PLACE", "PALLETIZER").owner_timeout(secs(1)))
            .unwrap();
        let sender = place.owner().unwrap();
        let mut receiver = place.user_named("GRIPPER").unwrap();
        let send = tokio::spawn(async move {
            let mut sender = sender;
            sender.send(7).await
        });
        let (box_no, reply) = receiver.receive().await.unwrap();
        // The gripper takes 3 s; the palletizer gives up after 1 s.
        drive(&clock, at(3)).await;
        let gave_up: SendError<u32> = send.await.unwrap().unwrap_err();
        assert!(gave_up.is_timeout(), "{gave_up}");
        assert_eq!(reply.reply(box_no + 1), Replied::Late(8));

        // A sender still waiting gets its reply, and the replier is told so.
        let sender = place.owner().unwrap();
        let send = tokio::spawn(async move {
            let mut sender = sender;
            sender.send(1).await
        });
        let (box_no, reply) = receiver.receive().await.unwrap();
        assert_eq!(reply.reply(box_no * 10), Replied::Delivered);
        assert_eq!(send.await.unwrap().unwrap(), 10);
    });
}

#[test]
fn a_timeout_bounds_only_the_ends_it_is_declared_for() {
    paused_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        // The owner's end is bounded, the users' are not.
        let owner_bounded: Port<(), (), usage::Response> = cell
            .port(PortSpec::new("OWNER_BOUNDED", "CELL").owner_timeout(secs(2)))
            .unwrap();
        // The users' ends are bounded, the owner's is not.
        let users_bounded: Port<(), (), usage::Response> = cell
            .port(PortSpec::new("USERS_BOUNDED", "CELL").user_timeout(secs(2)))
            .unwrap();
        let mut unbounded_user = owner_bounded.user_named("ASKER").unwrap();
        let mut bounded_user = users_bounded.user_named("ASKER").unwrap();
        assert_eq!(unbounded_user.timeout(), None);
        assert_eq!(bounded_user.timeout(), Some(secs(2)));
        let ports = cell.ports();
        let bounds: Vec<_> = ports
            .iter()
            .map(|port| (port.name.as_str(), port.owner_timeout, port.user_timeout))
            .collect();
        assert_eq!(
            bounds,
            [
                ("OWNER_BOUNDED", Some(secs(2)), None),
                ("USERS_BOUNDED", None, Some(secs(2)))
            ]
        );

        // Nobody answers either port: the bounded query fails at 2 s, the other still waits.
        let unbounded = tokio::spawn(async move { unbounded_user.query(()).await });
        let bounded = tokio::spawn(async move { bounded_user.query(()).await });
        drive(&clock, at(10)).await;
        let failed = bounded.await.unwrap().unwrap_err();
        assert!(failed.is_timeout(), "{failed}");
        assert!(
            !unbounded.is_finished(),
            "the users' end of OWNER_BOUNDED has no timeout"
        );
        unbounded.abort();
    });
}

#[test]
fn a_module_past_a_ports_number_of_users_is_refused_at_start() {
    paused_runtime().block_on(async {
        let (cell, _clock) = Cell::virtual_clock();
        // #USERS=2: two grippers may send to the palletizer, not three.
        let place: Port<(), (), usage::Receive, AnyUser, 2> =
            cell.port(PortSpec::new("PLACE", "PALLETIZER")).unwrap();
        let gripper = |name: &'static str| {
            ModuleSpec::new(name, ())
                .uses(&place)
                .task(name, |ctx| async move {
                    ctx.delay(secs(60)).await;
                    Ok(())
                })
        };
        cell.start(gripper("GRIPPER_A")).unwrap();
        cell.start(gripper("GRIPPER_B")).unwrap();
        let refused = cell.start(gripper("GRIPPER_C")).unwrap_err();
        assert_eq!(
            refused.0,
            [CellError::TooManyUsers {
                port: "PLACE".into(),
                capacity: 2,
                modules: vec!["GRIPPER_A".into(), "GRIPPER_B".into(), "GRIPPER_C".into()],
            }]
        );
    });
}

#[test]
fn a_user_that_ended_makes_room_on_its_port_and_the_refusal_names_the_users_in_order() {
    paused_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        // #USERS=1: one gripper at a time may send to the palletizer.
        let place: Port<(), (), usage::Receive> =
            cell.port(PortSpec::new("PLACE", "PALLETIZER")).unwrap();
        let gripper = |name: &'static str, works: u64| {
            ModuleSpec::new(name, ())
                .uses(&place)
                .task(name, move |ctx| async move {
                    ctx.delay(secs(works)).await;
                    Ok(())
                })
        };
        let mut first = cell.start(gripper("GRIPPER_B", 10)).unwrap();
        let refused = cell.start(gripper("GRIPPER_A", 10)).unwrap_err();
        assert_eq!(
            refused.0,
            [CellError::TooManyUsers {
                port: "PLACE".into(),
                capacity: 1,
                modules: vec!["GRIPPER_B".into(), "GRIPPER_A".into()],
            }]
        );
        drive(&clock, at(11)).await;
        assert_eq!(first.finished().await, ModuleOutcome::Finished);
        // GRIPPER_B has ended: its place on PLACE is free again.
        cell.start(gripper("GRIPPER_A", 10)).unwrap();
        let refused = cell.start(gripper("GRIPPER_C", 10)).unwrap_err();
        assert!(matches!(
            &refused.0[..],
            [CellError::TooManyUsers { modules, .. }]
                if *modules == vec![Name::from("GRIPPER_A"), Name::from("GRIPPER_C")]
        ));
    });
}

#[test]
fn a_second_module_of_a_running_modules_name_is_refused_as_a_duplicate() {
    paused_runtime().block_on(async {
        let (cell, _clock) = Cell::virtual_clock();
        let status: Port<(), u32, usage::Response> =
            cell.port(PortSpec::new("STATUS", "PALLETIZER")).unwrap();
        let palletizer = || {
            let ask = status.handler("ASK");
            ModuleSpec::new("PALLETIZER", 0u32)
                .order([ask.name(), "PALLETIZER".into()])
                .respond(&ask, |placed: &u32, ()| *placed)
                .task("PALLETIZER", |ctx| async move {
                    ctx.delay(secs(60)).await;
                    Ok(())
                })
        };
        cell.start(palletizer()).unwrap();
        // The second copy's answering end cannot attach either; the name is what is wrong.
        let refused = cell.start(palletizer()).unwrap_err();
        assert_eq!(
            refused.0,
            [CellError::DuplicateModule {
                module: "PALLETIZER".into()
            }]
        );
    });
}

#[test]
fn a_port_declared_used_twice_by_one_module_counts_one_user() {
    paused_runtime().block_on(async {
        let (cell, _clock) = Cell::virtual_clock();
        // #USERS=1, and the one user both declares the use and answers on the port.
        let status: Port<(), u32, usage::Query> =
            cell.port(PortSpec::new("STATUS", "PALLETIZER")).unwrap();
        let ask = status.handler("ASK");
        let gripper = ModuleSpec::new("GRIPPER", 3u32)
            .order([ask.name(), "GRIPPER".into()])
            .uses(&status)
            .respond(&ask, |held: &u32, ()| *held)
            .uses(&status)
            .task("GRIPPER", |ctx| async move {
                ctx.delay(secs(60)).await;
                Ok(())
            });
        // Two declarations of one use: still one user of a port of one.
        cell.start(gripper).unwrap();
    });
}
