//! The order rule with several threads: a named section ranked above a handler protects the
//! module from that handler, whatever its other threads are doing; and CHIP_IT still answers
//! CRIT_SECTION in INSERT while its FREEZE_CARD task runs background code.

mod common;

use common::{CHIP_IT_ORDER, at, paused_runtime, secs};

use imrs_core::prelude::*;
use imrs_core::time::drive;

/// A weld in two halves: `WELD` sets `started`, welds for 10 s, then sets `finished`. A
/// handler that sees them differ has seen the module half-way through a weld.
#[derive(Default)]
struct Welder {
    started: u32,
    finished: u32,
}

/// For each `Responded` event of `module`: when, and in which named section the module's
/// first task was.
fn responses_by_section(cell: &Cell, module: &str, task: &str) -> Vec<(Instant, Option<Name>)> {
    let mut section = None;
    let mut answered = Vec::new();
    for event in cell.events().snapshot() {
        if event.module != module {
            continue;
        }
        let of_task = event.task.as_ref().is_some_and(|name| name == task);
        match &event.kind {
            EventKind::SectionEntered { section: entered } if of_task => {
                section = Some(entered.clone());
            }
            EventKind::SectionLeft { .. } if of_task => section = None,
            EventKind::Responded { .. } => answered.push((event.at, section.clone())),
            _ => {}
        }
    }
    answered
}

/// Starts one module per time in `times`, named `ASK<time>`, that queries `port` then and
/// hands the answer to `check`.
fn start_askers<Rep: Send + 'static>(
    cell: &Cell,
    port: &Port<(), Rep, usage::Response, AnyUser, 8>,
    times: &[u64],
    check: fn(u64, Rep),
) -> Vec<ModuleHandle> {
    let mut askers = Vec::new();
    for &asked in times {
        let port = port.clone();
        let asker = ModuleSpec::new(format!("ASK{asked}"), ()).task("ASK", move |ctx| {
            let port = ctx.user(&port);
            async move {
                let mut port = port?;
                ctx.delay(secs(asked)).await;
                check(asked, ctx.query(&mut port, ()).await?);
                Ok(())
            }
        });
        askers.push(cell.start(asker).unwrap());
    }
    askers
}

fn all_finished(askers: &[ModuleHandle]) {
    for asker in askers {
        assert_eq!(
            asker.outcome(),
            Some(ModuleOutcome::Finished),
            "{}",
            asker.name()
        );
    }
}

#[test]
fn a_query_waits_for_a_named_section_to_be_left_while_another_thread_is_in_background() {
    paused_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        // The test reads the primitives that succeed from the log: logged while observed.
        cell.observe(true);
        let status: Port<(), (u32, u32), usage::Response, AnyUser, 8> =
            cell.port(PortSpec::new("B_STATUS", "WELDER_B")).unwrap();
        let welder = ModuleSpec::new("WELDER_B", Welder::default())
            .order(["WELD", "B_STATUS.STATUS", "WELDER_B"])
            .respond(&status.handler("STATUS"), |welder: &Welder, ()| {
                (welder.started, welder.finished)
            })
            // Background 0-5 s, WELD 5-15 s, background 15-20 s, WELD 20-30 s, ... until 45 s.
            .task("WELDER_B", |ctx| async move {
                for _ in 0..3 {
                    ctx.delay(secs(5)).await;
                    ctx.section(&Section::new("WELD"), async {
                        ctx.state().update(|welder| welder.started += 1);
                        ctx.delay(secs(10)).await;
                        ctx.state().update(|welder| welder.finished += 1);
                    })
                    .await;
                }
                Ok(())
            })
            // A second thread in background code the whole time: the thread a handler would
            // interrupt.
            .task("GAS_MONITOR", |ctx| async move {
                loop {
                    ctx.delay(secs(1)).await;
                }
            });
        cell.start(welder).unwrap();

        let askers = start_askers(
            &cell,
            &status,
            &[3, 8, 22, 33, 40],
            |asked, (started, finished)| {
                assert_eq!(started, finished, "asked at {asked} s: a half-done weld");
            },
        );
        drive(&clock, at(60)).await;
        all_finished(&askers);
        // Asked at 3 s and 33 s (background): at once. At 8 s, 22 s and 40 s (in WELD): when
        // the weld ends, at 15 s, 30 s and 45 s. Never inside WELD.
        let answered = responses_by_section(&cell, "WELDER_B", "WELDER_B");
        let times: Vec<_> = answered.iter().map(|(time, _)| *time).collect();
        assert_eq!(times, [at(3), at(15), at(30), at(33), at(45)]);
        assert!(
            answered.iter().all(|(_, section)| section.is_none()),
            "answered inside a section: {answered:?}"
        );
    });
}

#[test]
fn crit_section_is_answered_in_insert_and_never_in_grasp_or_background_while_freeze_card_runs() {
    paused_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        // The test reads the primitives that succeed from the log: logged while observed.
        cell.observe(true);
        let share_feeder1: Port<(), i32, usage::Response, AnyUser, 8> = cell
            .port(PortSpec::new("SHARE_FEEDER1", "CHIP_IT"))
            .unwrap();
        // The ports whose timeouts CHIP_IT's order ranks; nobody else uses them here.
        let _ready_to_chip: Port<(), (), usage::Receive> = cell
            .port(PortSpec::new("READY_TO_CHIP", "CHIP_IT").owner_timeout(secs(60)))
            .unwrap();
        let _share_feeder: Port<(), i32, usage::Query> = cell
            .port(PortSpec::new("SHARE_FEEDER", "CHIP_IT").owner_timeout(secs(3)))
            .unwrap();
        let chip_it = ModuleSpec::new("CHIP_IT", ())
            .order(CHIP_IT_ORDER)
            .respond(&share_feeder1.handler("CRIT_SECTION"), |_: &(), ()| 0)
            // Background 0-10 s, GRASP 10-20 s, INSERT 20-30 s, twice, then done at 60 s.
            .task("CHIP_IT", |ctx| async move {
                for _ in 0..2 {
                    ctx.delay(secs(10)).await;
                    ctx.section(&Section::new("GRASP"), ctx.delay(secs(10)))
                        .await;
                    ctx.section(&Section::new("INSERT"), ctx.delay(secs(10)))
                        .await;
                }
                Ok(())
            })
            // FREEZE_CARD: background code (rank 3), waiting on the card relay for ever.
            .task("FREEZE_CARD", |ctx| async move {
                loop {
                    ctx.delay(secs(2)).await;
                }
            });
        cell.start(chip_it).unwrap();

        let askers = start_askers(
            &cell,
            &share_feeder1,
            &[5, 15, 25, 35, 45, 52],
            |_, clear| {
                assert_eq!(clear, 0);
            },
        );
        drive(&clock, at(59)).await;
        all_finished(&askers);
        // Asked at 5 (background) and 15 (GRASP): at 20, when INSERT begins. At 25: at once.
        // At 35 and 45: at 50. At 52: at once.
        let answered = responses_by_section(&cell, "CHIP_IT", "CHIP_IT");
        let insert = Some(Name::from("INSERT"));
        assert_eq!(
            answered,
            [
                (at(20), insert.clone()),
                (at(20), insert.clone()),
                (at(25), insert.clone()),
                (at(50), insert.clone()),
                (at(50), insert.clone()),
                (at(52), insert),
            ]
        );
    });
}
