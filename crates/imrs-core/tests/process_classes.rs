//! One small cell per process class of Shin 1985, section 2.

mod common;

use common::{at, multi_thread_runtime, paused_runtime, secs};

use std::sync::{Arc, Mutex};

use imrs_core::prelude::*;
use imrs_core::time::drive;
use imrs_ports::{AnyUser, RealClock};

/// Independent processes: two stations update a shared conveyor state only through its
/// proprietor, which owns it; a reader queries it.
#[test]
fn independent_a_proprietor_owns_the_shared_conveyor_state() {
    paused_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        // Pallets put on (+1) or taken off (-1) the conveyor.
        let update: Port<i32, (), usage::Receive, AnyUser, 2> =
            cell.port(PortSpec::new("UPDATE", "CONVEYOR")).unwrap();
        let occupancy: Port<(), i32, usage::Response> =
            cell.port(PortSpec::new("OCCUPANCY", "CONVEYOR")).unwrap();
        let proprietor = ModuleSpec::new("CONVEYOR", 0i32)
            .order([occupancy.handler("COUNT").name(), "CONVEYOR".into()])
            .respond(&occupancy.handler("COUNT"), |on: &i32, ()| *on)
            .task("CONVEYOR", {
                let update = update.clone();
                move |ctx| {
                    let update = update.clone();
                    async move {
                        let mut update = update.owner()?;
                        loop {
                            match ctx.receive(&mut update).await {
                                Ok((change, done)) => {
                                    ctx.state().update(|on| *on += change);
                                    done.reply(());
                                }
                                // Every station has finished for good: the count stands,
                                // and the conveyor goes on answering OCCUPANCY.
                                Err(error) if error.is_peer_gone() => {
                                    std::future::pending::<()>().await;
                                }
                                Err(error) => return Err(error.into()),
                            }
                        }
                    }
                }
            });
        let station = |name: &'static str, change: i32, every: u64, times: u32| {
            let update = update.clone();
            ModuleSpec::new(name, ())
                .uses_named("UPDATE", UsageKind::Send)
                .task(name, move |ctx| {
                    let update = update.clone();
                    async move {
                        let mut update = update.user_named(name)?;
                        for _ in 0..times {
                            ctx.delay(secs(every)).await;
                            ctx.send(&mut update, change).await?;
                        }
                        Ok(())
                    }
                })
        };
        cell.start(proprietor).unwrap();
        cell.start(station("GATE", 1, 2, 10)).unwrap();
        cell.start(station("CHIP_IT", -1, 3, 5)).unwrap();
        let mut reader = occupancy.user_named("REPORT").unwrap();
        drive(&clock, at(10)).await;
        assert_eq!(reader.query(()).await.unwrap(), 5 - 3);
        drive(&clock, at(30)).await;
        assert_eq!(reader.query(()).await.unwrap(), 10 - 5);
    });
}

/// Loosely-coupled processes: two robots share one screwdriver through a tool crib, a
/// monitor task written with the primitives; the tool is never in two hands.
#[test]
fn loosely_coupled_two_robots_share_a_tool_through_a_monitor() {
    paused_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        let take: Port<(), (), usage::Receive, AnyUser, 2> =
            cell.port(PortSpec::new("TAKE", "TOOL_CRIB")).unwrap();
        let give_back: Port<(), (), usage::Receive, AnyUser, 2> =
            cell.port(PortSpec::new("GIVE_BACK", "TOOL_CRIB")).unwrap();
        let crib = ModuleSpec::new("TOOL_CRIB", ()).task("TOOL_CRIB", {
            let (take, give_back) = (take.clone(), give_back.clone());
            move |ctx| {
                let (take, give_back) = (take.clone(), give_back.clone());
                async move {
                    let (mut take, mut give_back) = (take.owner()?, give_back.owner()?);
                    loop {
                        // Hand the tool out, then take nothing until it is back.
                        let ((), granted) = ctx.receive(&mut take).await?;
                        granted.reply(());
                        let ((), returned) = ctx.receive(&mut give_back).await?;
                        returned.reply(());
                    }
                }
            }
        });
        let robot = |name: &'static str, work: u64| {
            let (take, give_back) = (take.clone(), give_back.clone());
            ModuleSpec::new(name, ())
                .order(["USE_TOOL", name])
                .task(name, move |ctx| {
                    let (take, give_back) = (take.clone(), give_back.clone());
                    async move {
                        let (mut take, mut give_back) =
                            (take.user_named(name)?, give_back.user_named(name)?);
                        for _ in 0..4 {
                            ctx.send(&mut take, ()).await?;
                            ctx.section(&Section::new("USE_TOOL"), ctx.delay(secs(work)))
                                .await;
                            ctx.send(&mut give_back, ()).await?;
                            ctx.delay(secs(1)).await;
                        }
                        Ok(())
                    }
                })
        };
        cell.start(crib).unwrap();
        let mut robots = [
            cell.start(robot("ROBOT_A", 2)).unwrap(),
            cell.start(robot("ROBOT_B", 3)).unwrap(),
        ];
        drive(&clock, at(60)).await;
        for robot in &mut robots {
            assert_eq!(robot.finished().await, ModuleOutcome::Finished);
        }
        // Who held the tool when, from the sections entered and left.
        let mut holder: Option<Name> = None;
        let mut uses = 0;
        for event in cell.events().snapshot() {
            match event.kind {
                EventKind::SectionEntered { .. } => {
                    assert_eq!(
                        holder, None,
                        "{} took the tool from {holder:?}",
                        event.module
                    );
                    holder = Some(event.module);
                    uses += 1;
                }
                EventKind::SectionLeft { .. } => holder = None,
                _ => {}
            }
        }
        assert_eq!(uses, 8);
    });
}

/// Tightly-coupled processes: a parent directs its child through a TIGHT port, across
/// threads, and checks every status it gets back.
#[test]
fn tightly_coupled_a_parent_directs_its_child_through_a_tight_port() {
    let runtime = multi_thread_runtime();
    runtime.block_on(async {
        let cell = Cell::new(Arc::new(RealClock::new()));
        // DIRECT: owned by the child's parent ARM, USAGE=SEND, process type TIGHT.
        let direct = Port::<u32, u32, usage::Send>::new(
            PortSpec::new("DIRECT", "ARM").process_type(ProcessType::Tight),
        );
        let arm = ModuleSpec::new("ARM", ()).task("ARM", {
            let direct = direct.clone();
            move |ctx| {
                let direct = direct.clone();
                async move {
                    let gripper = ModuleSpec::new("GRIPPER", ()).task("GRIPPER", {
                        let direct = direct.clone();
                        move |ctx| {
                            let direct = direct.clone();
                            async move {
                                let mut directives = direct.user_named("GRIPPER")?;
                                loop {
                                    let (opening, status) = ctx.receive(&mut directives).await?;
                                    status.reply(opening * 2);
                                }
                            }
                        }
                    });
                    let gripper = ctx.costart(gripper).unwrap();
                    let mut direct = direct.owner()?;
                    for opening in 0..1000 {
                        assert_eq!(direct.send(opening).await?, opening * 2);
                    }
                    gripper.stop();
                    Ok(())
                }
            }
        });
        let mut arm = cell.start(arm).unwrap();
        assert_eq!(arm.finished().await, ModuleOutcome::Finished);
    });
}

/// Serialized motion: B may only start once A is done, and A's send is what releases it.
#[test]
fn serialized_motion_a_send_releases_the_next_step() {
    paused_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        let card_in_place: Port<(), i32, usage::Send> = cell
            .port(PortSpec::new("CARD_IN_PLACE", "LOAD_CARD"))
            .unwrap();
        let load_card = ModuleSpec::new("LOAD_CARD", ())
            .order(["MOVE_CARD", "LOAD_CARD"])
            .task("LOAD_CARD", {
                let port = card_in_place.clone();
                move |ctx| {
                    let port = port.clone();
                    async move {
                        let mut card_in_place = port.owner()?;
                        ctx.section(&Section::new("MOVE_CARD"), ctx.delay(secs(5)))
                            .await;
                        assert_eq!(ctx.send(&mut card_in_place, ()).await?, 0);
                        Ok(())
                    }
                }
            });
        let screw_in_card = ModuleSpec::new("SCREW_IN_CARD", ())
            .order(["SCREW", "SCREW_IN_CARD"])
            .task("SCREW_IN_CARD", {
                let port = card_in_place.clone();
                move |ctx| {
                    let port = port.clone();
                    async move {
                        let mut card_in_place = port.user_named("SCREW_IN_CARD")?;
                        let ((), anchored) = ctx.receive(&mut card_in_place).await?;
                        ctx.section(&Section::new("SCREW"), ctx.delay(secs(3)))
                            .await;
                        anchored.reply(0);
                        Ok(())
                    }
                }
            });
        cell.start(screw_in_card).unwrap();
        cell.start(load_card).unwrap();
        drive(&clock, at(20)).await;
        let sections: Vec<_> = cell
            .events()
            .snapshot()
            .into_iter()
            .filter_map(|event| match event.kind {
                EventKind::SectionEntered { section } => Some((section.to_string(), event.at)),
                EventKind::SectionLeft { section } => Some((format!("/{section}"), event.at)),
                _ => None,
            })
            .collect();
        assert_eq!(
            sections,
            [
                ("MOVE_CARD".to_string(), at(0)),
                ("/MOVE_CARD".to_string(), at(5)),
                ("SCREW".to_string(), at(5)),
                ("/SCREW".to_string(), at(8)),
            ]
        );
    });
}

/// Work-coupled processes: LOAD_A keeps its mate LOAD_B's database current with sequenced
/// updates; when LOAD_A dies, LOAD_B takes over where the database says, and every card is
/// loaded exactly once — even though LOAD_A's last update reaches LOAD_B twice.
#[test]
fn work_coupled_a_mate_takes_over_and_nothing_is_applied_twice_or_lost() {
    paused_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        // UPDATES: LOAD_B receives (seq) updates; a silence of 3 s means LOAD_A is gone.
        let updates: Port<u32, (), usage::Receive> = cell
            .port(PortSpec::new("UPDATES", "LOAD_B").owner_timeout(secs(3)))
            .unwrap();
        // The physical result: the cards loaded, in order.
        let loaded = Arc::new(Mutex::new(Vec::new()));
        const CARDS: u32 = 10;

        let load_a = ModuleSpec::new("LOAD_A", ()).task("LOAD_A", {
            let (updates, loaded) = (updates.clone(), Arc::clone(&loaded));
            move |ctx| {
                let (updates, loaded) = (updates.clone(), Arc::clone(&loaded));
                async move {
                    let mut updates = updates.user_named("LOAD_A")?;
                    for card in 0..CARDS {
                        ctx.delay(secs(1)).await;
                        loaded.lock().unwrap().push(card);
                        // Blocking: LOAD_A goes on only once its mate has the update.
                        ctx.send(&mut updates, card).await?;
                        if card == 5 {
                            // A retransmission, as after a lost acknowledgement.
                            ctx.send(&mut updates, card).await?;
                            panic!("LOAD_A lost its gripper");
                        }
                    }
                    Ok(())
                }
            }
        });
        let load_b = ModuleSpec::new("LOAD_B", None::<u32>).task("LOAD_B", {
            let (updates, loaded) = (updates.clone(), Arc::clone(&loaded));
            move |ctx| {
                let (updates, loaded) = (updates.clone(), Arc::clone(&loaded));
                async move {
                    let mut updates = updates.owner()?;
                    // Apply updates in sequence: a duplicate is acknowledged and ignored.
                    loop {
                        match ctx.receive(&mut updates).await {
                            Ok((seq, ack)) => {
                                ctx.state().update(|done| {
                                    let next = done.map_or(0, |done| done + 1);
                                    assert!(seq <= next, "update {seq} skips {next}");
                                    if seq == next {
                                        *done = Some(seq);
                                    }
                                });
                                ack.reply(());
                            }
                            // Silence, or LOAD_A known dead (it failed for good).
                            Err(error) if error.is_timeout() || error.is_peer_gone() => break,
                            Err(error) => return Err(error.into()),
                        }
                    }
                    // The mate is gone: take over after the last card it reported.
                    let from = ctx.state().read(|done| done.map_or(0, |done| done + 1));
                    for card in from..CARDS {
                        ctx.delay(secs(1)).await;
                        loaded.lock().unwrap().push(card);
                    }
                    Ok(())
                }
            }
        });
        cell.start(load_b).unwrap();
        let mut load_a = cell.start(load_a).unwrap();
        drive(&clock, at(30)).await;
        assert!(matches!(load_a.finished().await, ModuleOutcome::Failed(_)));
        assert_eq!(*loaded.lock().unwrap(), (0..CARDS).collect::<Vec<_>>());
    });
}
