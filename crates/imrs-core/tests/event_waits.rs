//! The event log says how long each primitive waited, and which primitive failed: what a
//! timeline draws a module's blocked periods from.

mod common;

use common::{at, paused_runtime, secs};

use imrs_core::prelude::*;
use imrs_core::time::drive;
use imrs_core::{Observed, Primitive};

#[test]
fn each_primitive_logs_its_wait_and_a_failure_names_its_primitive() {
    paused_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        cell.observe(true);
        // LOAD_CARD sends a card at 2 s; SCREW_IN_CARD takes 3 s to screw it and reply. The
        // second card waits past the port's 4 s TIMEOUT.
        let card_in_place: Port<u32, i32, usage::Send> = cell
            .port(
                PortSpec::new("CARD_IN_PLACE", "LOAD_CARD")
                    .user_list(["SCREW_IN_CARD"])
                    .owner_timeout(secs(4)),
            )
            .unwrap();
        let (sender, receiver) = (card_in_place.clone(), card_in_place);
        let screwer = ModuleSpec::new("SCREW_IN_CARD", ())
            .uses_named("CARD_IN_PLACE", UsageKind::Receive)
            .task("SCREW_IN_CARD", move |ctx| {
                let port = receiver.clone();
                async move {
                    let mut card_in_place = port.user_named("SCREW_IN_CARD")?;
                    let (card, reply) = ctx.receive(&mut card_in_place).await?;
                    ctx.delay(secs(3)).await;
                    reply.reply(card as i32);
                    // The second card is never answered.
                    let _held = ctx.receive(&mut card_in_place).await?;
                    ctx.delay(secs(60)).await;
                    Ok(())
                }
            });
        let loader = ModuleSpec::new("LOAD_CARD", ())
            .order(["CARD_IN_PLACE.TIMEOUT", "LOAD_CARD"])
            .exception("CARD_IN_PLACE.TIMEOUT", |_ctx: Ctx<()>, _| async {})
            .task("LOAD_CARD", move |ctx| {
                let port = sender.clone();
                async move {
                    let mut card_in_place = port.owner()?;
                    ctx.delay(secs(2)).await;
                    ctx.send(&mut card_in_place, 1).await?;
                    let _ = ctx.send(&mut card_in_place, 2).await;
                    Ok(())
                }
            });
        cell.start(screwer).unwrap();
        cell.start(loader).unwrap();
        drive(&clock, at(30)).await;
        let waits: Vec<_> = cell
            .events()
            .snapshot()
            .into_iter()
            .filter_map(|event| match event.kind {
                EventKind::Sent { observed, .. } => {
                    Some((event.module, "sent", observed?.waited, None))
                }
                EventKind::Received { observed, .. } => {
                    Some((event.module, "received", observed?.waited, None))
                }
                EventKind::PortError {
                    observed,
                    primitive,
                    ..
                } => Some((event.module, "failed", observed?.waited, Some(primitive))),
                _ => None,
            })
            .collect();
        assert_eq!(
            waits,
            [
                // The screwer waited 2 s for the first card, the loader 3 s for its reply.
                ("SCREW_IN_CARD".into(), "received", secs(2), None),
                ("LOAD_CARD".into(), "sent", secs(3), None),
                // The second card is taken at once, and never answered: the send fails at
                // its TIMEOUT, 4 s after it began.
                ("SCREW_IN_CARD".into(), "received", secs(0), None),
                ("LOAD_CARD".into(), "failed", secs(4), Some(Primitive::Send)),
            ]
        );
        assert!(Primitive::Send.awaits_a_peer() && !Primitive::Receive.awaits_a_peer());
    });
}

/// Runs LOAD_CARD sending card 7 to SCREW_IN_CARD, which takes 3 s and replies 70, on a
/// port that shows its values; returns what the log adds to the receive and the send.
fn one_card(observe: bool) -> Vec<Option<Box<Observed>>> {
    paused_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        cell.observe(observe);
        let card_in_place: Port<u32, i32, usage::Send> = cell
            .port(PortSpec::new("CARD_IN_PLACE", "LOAD_CARD"))
            .unwrap()
            .shown();
        let (sender, receiver) = (card_in_place.clone(), card_in_place);
        let screwer = ModuleSpec::new("SCREW_IN_CARD", ()).task("SCREW_IN_CARD", move |ctx| {
            let port = receiver.clone();
            async move {
                let mut card_in_place = port.user_named("SCREW_IN_CARD")?;
                let (card, reply) = ctx.receive(&mut card_in_place).await?;
                ctx.delay(secs(3)).await;
                reply.reply(card as i32 * 10);
                Ok(())
            }
        });
        let loader = ModuleSpec::new("LOAD_CARD", ()).task("LOAD_CARD", move |ctx| {
            let port = sender.clone();
            async move {
                ctx.send(&mut port.owner()?, 7).await?;
                Ok(())
            }
        });
        cell.start(screwer).unwrap();
        cell.start(loader).unwrap();
        drive(&clock, at(5)).await;
        cell.events()
            .snapshot()
            .into_iter()
            .filter_map(|event| match event.kind {
                EventKind::Sent { observed, .. } | EventKind::Received { observed, .. } => {
                    Some(observed)
                }
                _ => None,
            })
            .collect()
    })
}

#[test]
fn a_shown_port_puts_its_values_in_the_log_only_while_the_cell_observes() {
    let shown: Vec<_> = one_card(true)
        .into_iter()
        .map(|observed| observed.map_or((None, None), |o| (o.message, o.reply)))
        .collect();
    assert_eq!(
        shown,
        [
            (Some("7".into()), None),
            (Some("7".into()), Some("70".into()))
        ]
    );
}

#[test]
fn a_cell_that_does_not_observe_logs_no_primitive_that_succeeds() {
    assert_eq!(one_card(false), []);
}
