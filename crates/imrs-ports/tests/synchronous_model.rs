//! Synchronous ports against a model of Lyons & Arbib 1985's rule, over random networks and random
//! interleavings of writes, reads, withdrawals and late connections: no value is lost, none
//! is read twice by one reader, and a writer is released exactly when one connected reader
//! has read its value.

use std::collections::VecDeque;
use std::future::Future;
use std::pin::Pin;
use std::task::{Context, Poll, Waker};

use imrs_ports::synchronous::{Input, Output, Write, connect};
use proptest::prelude::*;

const WRITERS: usize = 3;
const READERS: usize = 3;

#[derive(Debug, Clone)]
enum Op {
    Write(usize),
    Read(usize),
    Poll(usize),
    GiveUp(usize),
    Connect(usize, usize),
}

fn op() -> impl Strategy<Value = Op> {
    prop_oneof![
        (0..WRITERS).prop_map(Op::Write),
        (0..READERS).prop_map(Op::Read),
        (0..WRITERS).prop_map(Op::Poll),
        (0..WRITERS).prop_map(Op::GiveUp),
        (0..WRITERS, 0..READERS).prop_map(|(w, r)| Op::Connect(w, r)),
    ]
}

/// What the rule says each end holds.
#[derive(Default)]
struct Model {
    edges: [[bool; READERS]; WRITERS],
    /// A writer's write in progress: its value, and whether any reader has read it.
    writing: [Option<(u32, bool)>; WRITERS],
    queues: [VecDeque<u32>; READERS],
}

fn poll<F: Future + Unpin>(future: &mut F) -> Poll<F::Output> {
    Pin::new(future).poll(&mut Context::from_waker(Waker::noop()))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]
    #[test]
    fn ports_follow_the_rule(
        initial in proptest::array::uniform3(proptest::array::uniform3(any::<bool>())),
        ops in proptest::collection::vec(op(), 1..80),
    ) {
        let outputs: Vec<Output<u32>> = (0..WRITERS).map(|w| Output::new("o", format!("W{w}"))).collect();
        let inputs: Vec<Input<u32>> = (0..READERS).map(|r| Input::new("i", format!("R{r}"))).collect();
        let mut model = Model { edges: initial, ..Model::default() };
        for (w, row) in initial.iter().enumerate() {
            for (r, &edge) in row.iter().enumerate() {
                if edge {
                    connect(&outputs[w], &inputs[r]);
                }
            }
        }
        let mut writes: Vec<Option<Write<'_, u32>>> = (0..WRITERS).map(|_| None).collect();
        let mut next = 0u32;
        let mut value_of = |w: usize| { next += 1; next * 10 + w as u32 };

        for op in ops {
            match op {
                Op::Write(w) if writes[w].is_none() => {
                    let value = value_of(w);
                    let mut write = outputs[w].write(value);
                    prop_assert!(poll(&mut write).is_pending(), "W{} released before a read", w);
                    writes[w] = Some(write);
                    model.writing[w] = Some((value, false));
                    for r in 0..READERS {
                        if model.edges[w][r] {
                            model.queues[r].push_back(value);
                        }
                    }
                }
                Op::Write(_) => {}
                Op::Read(r) => {
                    let got = inputs[r].try_read();
                    let expected = model.queues[r].pop_front();
                    prop_assert_eq!(got, expected, "R{} read the wrong value", r);
                    if let Some(value) = expected {
                        let w = (value % 10) as usize;
                        if let Some((v, read)) = &mut model.writing[w] && *v == value {
                            *read = true;
                        }
                    }
                }
                Op::Poll(w) => {
                    if let Some(write) = &mut writes[w] {
                        let released = poll(write).is_ready();
                        let expected = model.writing[w].is_some_and(|(_, read)| read);
                        prop_assert_eq!(released, expected, "W{} released when it should not be, or not when it should", w);
                        if released {
                            writes[w] = None;
                            model.writing[w] = None;
                        }
                    }
                }
                Op::GiveUp(w) => {
                    writes[w] = None;
                    if let Some((value, false)) = model.writing[w].take() {
                        model.queues.iter_mut().for_each(|q| q.retain(|&v| v != value));
                    }
                }
                Op::Connect(w, r) => {
                    connect(&outputs[w], &inputs[r]);
                    if !model.edges[w][r] {
                        model.edges[w][r] = true;
                        if let Some((value, false)) = model.writing[w] {
                            model.queues[r].push_back(value);
                        }
                    }
                }
            }
        }
        // Whatever is still owed is still readable, once.
        for (input, queue) in inputs.iter().zip(&model.queues) {
            let left: Vec<u32> = std::iter::from_fn(|| input.try_read()).collect();
            prop_assert_eq!(left, Vec::from(queue.clone()));
        }
    }
}
