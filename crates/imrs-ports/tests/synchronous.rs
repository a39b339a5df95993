//! Synchronous ports (Lyons & Arbib 1985, §4.2): fan-out, fan-in, late connections, withdrawal and
//! closed ends, as a schema network uses them.

use std::future::Future;
use std::task::{Context, Waker};

use imrs_ports::synchronous::{
    AnyPort, ConnectError, Direction, Input, Output, ReadError, WriteError, connect, connect_any,
};

fn runtime() -> tokio::runtime::Runtime {
    tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .expect("runtime")
}

#[test]
fn a_write_waits_for_a_read_and_every_fanned_out_reader_gets_it() {
    runtime().block_on(async {
        let actual = Output::<u32>::new("actual", "Jposition_1");
        let (a, b) = (Input::new("Pin", "A"), Input::new("Pin", "B"));
        connect(&actual, &a);
        connect(&actual, &b);
        let writer = tokio::spawn({
            let actual = actual.clone();
            async move { actual.write(5).await }
        });
        tokio::task::yield_now().await;
        assert!(!writer.is_finished(), "released before anyone read");
        assert_eq!(a.read().await, Ok(5));
        writer.await.unwrap().unwrap();
        assert_eq!(b.try_read(), Some(5), "the second reader lost the value");
        assert_eq!(b.try_read(), None, "read twice");
    });
}

#[test]
fn fan_in_reads_whichever_writes_first_and_keeps_every_value() {
    runtime().block_on(async {
        let result = Input::<u8>::new("result", "Object?");
        let writers: Vec<_> = (1..=3)
            .map(|i| Output::new("judgement", format!("Objtest_{i}")))
            .collect();
        writers.iter().for_each(|w| connect(w, &result));
        let reading = tokio::spawn({
            let result = result.clone();
            async move { result.read().await }
        });
        tokio::task::yield_now().await;
        assert!(
            !reading.is_finished(),
            "read completed with nothing written"
        );
        let third = tokio::spawn({
            let w = writers[2].clone();
            async move { w.write(1).await }
        });
        assert_eq!(reading.await.unwrap(), Ok(1));
        third.await.unwrap().unwrap();
        let rest = tokio::spawn({
            let (w0, w1) = (writers[0].clone(), writers[1].clone());
            async move { tokio::join!(w0.write(0), w1.write(0)) }
        });
        tokio::task::yield_now().await;
        assert_eq!(result.waiting(), 2);
        assert_eq!((result.read().await, result.read().await), (Ok(0), Ok(0)));
        let (r0, r1) = rest.await.unwrap();
        r0.unwrap();
        r1.unwrap();
    });
}

#[test]
fn an_input_connected_while_a_write_waits_gets_that_write() {
    runtime().block_on(async {
        let f1 = Output::<f32>::new("F1", "SEF_1");
        let writer = tokio::spawn({
            let f1 = f1.clone();
            async move { f1.write(0.5).await }
        });
        tokio::task::yield_now().await;
        let pn = Input::new("Pn", "RObject_1");
        connect(&f1, &pn);
        assert_eq!(pn.read().await, Ok(0.5));
        writer.await.unwrap().unwrap();
    });
}

#[test]
fn a_write_given_up_is_withdrawn_from_every_reader() {
    runtime().block_on(async {
        let contact = Output::<bool>::new("Contact", "Tactile_1");
        let tin = Input::new("Tin", "Closejoint_1");
        connect(&contact, &tin);
        // A sensor replaces its unread sample with a fresh one.
        {
            let mut stale = std::pin::pin!(contact.write(false));
            let polled = stale.as_mut().poll(&mut Context::from_waker(Waker::noop()));
            assert!(polled.is_pending());
            assert_eq!(tin.waiting(), 1);
        }
        assert_eq!(tin.waiting(), 0, "the stale sample is still readable");
        let fresh = tokio::spawn({
            let contact = contact.clone();
            async move { contact.write(true).await }
        });
        assert_eq!(tin.read().await, Ok(true));
        fresh.await.unwrap().unwrap();
    });
}

#[test]
fn closed_ends_fail_named_instead_of_hanging() {
    runtime().block_on(async {
        let out = Output::<u8>::new("judgement", "Objtest_2");
        let input = Input::new("result", "Object?");
        connect(&out, &input);
        drop(out); // the last clone: closed
        assert_eq!(
            input.read().await,
            Err(ReadError::Disconnected {
                owner: "Object?".into(),
                port: "result".into()
            })
        );

        let out = Output::<u8>::new("Pout", "Closejoint_1");
        let input = Input::new("desired", "Jmotor_1");
        connect(&out, &input);
        let writing = tokio::spawn({
            let out = out.clone();
            async move { out.write(3).await }
        });
        tokio::task::yield_now().await;
        input.close();
        let error = writing.await.unwrap().unwrap_err();
        assert!(matches!(error, WriteError::Disconnected { value: 3, .. }));
        assert!(error.to_string().contains("Closejoint_1(Pout)"), "{error}");
        assert!(matches!(input.read().await, Err(ReadError::Closed { .. })));
        let error = {
            out.close();
            out.write(4).await.unwrap_err()
        };
        assert_eq!(error.into_value(), 4);
    });
}

#[test]
fn a_connection_by_name_checks_types_and_directions_naming_both_ends() {
    let pout: Box<dyn AnyPort> = Box::new(Output::<f32>::new("Pout", "Closejoint_1"));
    let desired: Box<dyn AnyPort> = Box::new(Input::<f64>::new("desired", "Jmotor_1"));
    let error = connect_any(&*pout, &*desired).unwrap_err();
    assert_eq!(
        error.to_string(),
        "cannot connect Closejoint_1(Pout) to Jmotor_1(desired): Closejoint_1(Pout) writes f32, \
         Jmotor_1(desired) reads f64"
    );
    let error = connect_any(&*desired, &*pout).unwrap_err();
    assert_eq!(
        error,
        ConnectError::Direction {
            port: "Jmotor_1(desired)".into(),
            expected: Direction::Output
        }
    );
    let same: Box<dyn AnyPort> = Box::new(Input::<f32>::new("desired", "Jmotor_2"));
    connect_any(&*pout, &*same).unwrap();
}

/// Writers and readers on several threads: every reader gets every value of every writer
/// it is connected to, once, and every writer is released.
#[test]
fn several_threads_lose_nothing_and_read_nothing_twice() {
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(4)
        .build()
        .unwrap();
    runtime.block_on(async {
        const WRITES: u32 = 300;
        let outputs: Vec<Output<(usize, u32)>> = (0..3)
            .map(|w| Output::new("out", format!("W{w}")))
            .collect();
        let inputs: Vec<Input<(usize, u32)>> =
            (0..3).map(|r| Input::new("in", format!("R{r}"))).collect();
        for output in &outputs {
            inputs.iter().for_each(|input| connect(output, input));
        }
        let readers: Vec<_> = inputs
            .into_iter()
            .map(|input| {
                tokio::spawn(async move {
                    let mut seen = vec![Vec::new(); 3];
                    while let Ok((w, n)) = input.read().await {
                        seen[w].push(n);
                    }
                    seen
                })
            })
            .collect();
        let writers: Vec<_> = outputs
            .into_iter()
            .enumerate()
            .map(|(w, output)| {
                tokio::spawn(async move {
                    for n in 0..WRITES {
                        output.write((w, n)).await.unwrap();
                    }
                })
            })
            .collect();
        for writer in writers {
            writer.await.unwrap();
        }
        for reader in readers {
            let seen = reader.await.unwrap();
            for per_writer in seen {
                assert_eq!(per_writer, (0..WRITES).collect::<Vec<_>>());
            }
        }
    });
}

/// A synchronous input is an alternative of `select`, beside a port's end: of the ready
/// ones, the one of highest priority is taken.
#[test]
fn a_select_takes_the_most_urgent_ready_input() {
    use imrs_ports::{Priority, select};
    runtime().block_on(async {
        let stop = Input::<&str>::with_priority("STOP", "HAND", Priority::declared(1));
        let position = Input::<f32>::with_priority("Pin", "HAND", Priority::declared(5));
        let (alarm, sensor) = (
            Output::new("alarm", "SAFETY"),
            Output::new("position", "Jposition_7"),
        );
        connect(&alarm, &stop);
        connect(&sensor, &position);
        let writers =
            tokio::spawn(
                async move { tokio::join!(sensor.write(0.5), alarm.write("emergency stop")) },
            );
        tokio::task::yield_now().await;
        assert_eq!((stop.waiting(), position.waiting()), (1, 1));
        let first = select()
            .or(&position, |p| format!("position {p}"))
            .or(&stop, |s| s.to_string())
            .await
            .unwrap();
        assert_eq!(first, "emergency stop");
        let second = select()
            .or(&position, |p| format!("position {p}"))
            .or(&stop, |s| s.to_string())
            .await
            .unwrap();
        assert_eq!(second, "position 0.5");
        let (a, b) = writers.await.unwrap();
        a.unwrap();
        b.unwrap();
        // Both writers are gone and nothing is left: every alternative is closed.
        let closed = select().or(&position, |_| ()).or(&stop, |_| ()).await;
        assert!(closed.is_err());
    });
}

/// A sensor read by one short-lived reader after another, ten thousand times: each reader
/// gets its value, and the output keeps no list of the readers that are gone.
#[test]
fn readers_that_come_and_go_leave_nothing_behind() {
    runtime().block_on(async {
        let position = Output::<u32>::new("position", "Jposition_7");
        for n in 0..10_000 {
            let reader = Input::new("Pin", "Objtest_1");
            connect(&position, &reader);
            let (written, read) = tokio::join!(position.write(n), reader.read());
            written.unwrap();
            assert_eq!(read, Ok(n));
            assert!(
                position.connections() <= 1,
                "{} kept at {n}",
                position.connections()
            );
        }
        // The last reader is gone too: a write has nobody to wait for, and says so.
        let error = position.write(0).await.unwrap_err();
        assert!(matches!(error, WriteError::Disconnected { .. }));
    });
}
