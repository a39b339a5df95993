//! query / response, and the hook that decides when a response handler runs.

mod common;

use std::time::Duration;

use common::{on_both_runtimes, until_sleepers, virtual_clock};
use imrs_ports::{
    Clock, ModuleState, Named, Port, PortSpec, QueryError, Respond, respond_while, usage, user_list,
};

struct LoadCard;
impl Named for LoadCard {
    const NAME: &'static str = "LOAD_CARD";
}

user_list! {
    /// `USERLIST=(LOAD_CARD)` of ASK_CHILD1.
    AskChild1Users = [LoadCard];
}

#[derive(Debug, Default)]
struct LoadCardState {
    num_loaded: u32,
    cycle_time: f64,
}

/// ASK_CHILD1.STATUS: RC1 := 0; NUM1 := NUM_LOADED; CYCLE1 := CYCLE_TIME.
fn status(state: &LoadCardState, (): ()) -> (i32, u32, f64) {
    (0, state.num_loaded, state.cycle_time)
}

#[test]
fn a_parent_queries_its_child_and_the_handler_reads_the_childs_state() {
    on_both_runtimes(|| async {
        // ASK_CHILD1: owned by LOAD_IT, USAGE=QUERY, USERLIST=(LOAD_CARD).
        let port = Port::<(), (i32, u32, f64), usage::Query, AskChild1Users>::new(PortSpec::new(
            "ASK_CHILD1",
            "LOAD_IT",
        ));
        let mut load_it = port.owner().unwrap();
        let mut ask_child1 = port.answer(LoadCard::NAME, status).unwrap();
        let child = tokio::spawn(async move {
            let state = ModuleState::new(LoadCardState::default());
            let background = async {
                for _ in 0..3 {
                    state.update(|s| {
                        s.num_loaded += 1;
                        s.cycle_time = 12.5;
                    });
                    tokio::task::yield_now().await;
                }
                std::future::pending::<()>().await
            };
            let ends: &mut [&mut (dyn Respond<LoadCardState> + Send)] = &mut [&mut ask_child1];
            respond_while(&state, ends, background).await
        });
        let (rc, _, _) = load_it.query(()).await.unwrap();
        assert_eq!(rc, 0);
        // Eventually the background's updates are visible, and never half-made.
        loop {
            let (_, num, cycle) = load_it.query(()).await.unwrap();
            assert!(
                num == 0 || cycle == 12.5,
                "a handler saw a half-made change"
            );
            if num == 3 {
                break;
            }
            tokio::task::yield_now().await;
        }
        child.abort();
    });
}

#[test]
fn the_default_hook_runs_handlers_once_the_background_is_suspended() {
    on_both_runtimes(|| async {
        let port = Port::<(), u32, usage::Response>::new(PortSpec::new("PEEK", "ROBOT"));
        let mut peek = port
            .answer(port.owner_module().clone(), |state: &u32, ()| *state)
            .unwrap();
        let mut asker = port.user_named("ASKER").unwrap();
        // The query is posted before the robot's task first runs (on the current-thread
        // runtime): the hook must still let the background run to its suspension point
        // before answering, and then answer while the background stays suspended for good.
        let asking = tokio::spawn(async move { asker.query(()).await });
        let robot = tokio::spawn(async move {
            let state = ModuleState::new(0u32);
            let background = async {
                state.update(|s| *s = 7);
                std::future::pending::<()>().await
            };
            respond_while(&state, &mut [&mut peek], background).await
        });
        assert_eq!(asking.await.unwrap().unwrap(), 7);
        robot.abort();
    });
}

#[test]
fn a_panicking_handler_fails_the_query_instead_of_hanging_it() {
    on_both_runtimes(|| async {
        let port = Port::<u8, u8, usage::Response>::new(PortSpec::new("FRAGILE", "OWNER"));
        let mut fragile = port
            .answer(port.owner_module().clone(), |_: &(), n: u8| {
                if n == 0 { panic!("no zero") } else { n }
            })
            .unwrap();
        let mut asker = port.user_named("ASKER").unwrap();
        let asking = tokio::spawn(async move { asker.query(0).await });
        let serving = tokio::spawn(async move { fragile.serve(&()).await });
        assert!(serving.await.is_err(), "the handler panicked");
        assert!(matches!(
            asking.await.unwrap(),
            Err(QueryError::NoResponse { .. })
        ));
    });
}

#[test]
fn a_query_times_out_and_hands_the_query_back() {
    on_both_runtimes(|| async {
        let (clock, shared) = virtual_clock();
        // SHARE_FEEDER: USAGE=QUERY, USERLIST=(CHIP_IT2), TIMEOUT=3 SEC.
        let port = Port::<u8, i32, usage::Query>::new(
            PortSpec::new("SHARE_FEEDER", "CHIP_IT")
                .user_list(["CHIP_IT2"])
                .owner_timeout(Duration::from_secs(3))
                .clock(shared),
        );
        let mut chip_it = port.owner().unwrap();
        // CHIP_IT2 attached, but its handler never gets to run.
        let _chip_it2 = port.answer("CHIP_IT2", |_: &(), _: u8| 1).unwrap();
        let asking = tokio::spawn(async move { chip_it.query(4).await });
        until_sleepers(&clock, 1).await;
        clock.advance(Duration::from_secs(3));
        match asking.await.unwrap() {
            Err(QueryError::Timeout { port, query }) => {
                assert_eq!(port, "SHARE_FEEDER");
                assert_eq!(query, 4);
            }
            other => panic!("expected a timeout, got {other:?}"),
        }
        assert_eq!(clock.now().since_start(), Duration::from_secs(3));
    });
}

#[test]
fn call_all_returns_the_first_answer_and_keeps_the_later_ones() {
    on_both_runtimes(|| async {
        let port = Port::<u8, String, usage::CallAll, imrs_ports::AnyUser, 3>::new(PortSpec::new(
            "STATUS_ALL",
            "LINE",
        ));
        let mut line = port.owner().unwrap();
        let mut cells = Vec::new();
        for name in ["GATE", "LOAD_IT", "CHIP_IT"] {
            let end = port
                .answer(name, move |_: &(), n: u8| format!("{name}:{n}"))
                .unwrap();
            cells.push(end);
        }
        let broadcast = line.call_all(7);
        let mut cells_task = tokio::spawn(async move {
            for cell in &mut cells {
                cell.serve(&()).await.unwrap();
            }
            cells
        });
        let mut broadcast = broadcast.await.unwrap();
        let mut answers = vec![(broadcast.from.to_string(), broadcast.first.clone())];
        while let Some((from, answer)) = broadcast.next_reply().await {
            answers.push((from.to_string(), answer));
        }
        answers.sort();
        assert_eq!(
            answers,
            [
                ("CHIP_IT".to_string(), "CHIP_IT:7".to_string()),
                ("GATE".to_string(), "GATE:7".to_string()),
                ("LOAD_IT".to_string(), "LOAD_IT:7".to_string()),
            ]
        );
        drop(broadcast);
        (&mut cells_task).await.unwrap();
    });
}

#[test]
fn a_transport_takes_a_query_and_answers_it_later_or_fails_the_querier_by_dropping_it() {
    on_both_runtimes(|| async {
        // A RESPONSE port whose answers come from elsewhere: its handler never runs.
        let port = Port::<u32, u32, usage::Response>::new(PortSpec::new("REMOTE", "BRIDGE"));
        let mut bridge = port
            .answer(port.owner_module().clone(), |_: &(), _: u32| {
                unreachable!("the bridge takes every query")
            })
            .unwrap();
        let mut asker = port.user_named("ASKER").unwrap();
        let asking = tokio::spawn(async move {
            let first = asker.query(20).await;
            let second = asker.query(30).await;
            (first, second)
        });
        std::future::poll_fn(|cx| bridge.poll_pending(cx))
            .await
            .unwrap();
        let (query, reply) = bridge.take().unwrap();
        assert_eq!(query, 20);
        assert!(bridge.take().is_none(), "one query waits, and it is taken");
        // Answered later, from elsewhere.
        tokio::task::yield_now().await;
        reply.reply(query + 1);
        std::future::poll_fn(|cx| bridge.poll_pending(cx))
            .await
            .unwrap();
        let (_, unanswered) = bridge.take().unwrap();
        drop(unanswered);
        let (first, second) = asking.await.unwrap();
        assert_eq!(first.unwrap(), 21);
        assert!(
            matches!(second, Err(QueryError::NoResponse { ref port }) if port == "REMOTE"),
            "{second:?}"
        );
    });
}
