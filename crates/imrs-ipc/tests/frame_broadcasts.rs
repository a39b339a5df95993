//! Frames carried by handle (`Shared`) on `SENDALL` and `CALLALL` ports across processes:
//! each broadcast read in place by users in two other processes, and by one in the owner's
//! too, whether built in a loan or on the heap; a user process killed and started again; an
//! absent owner, a wrong type and an unlisted module refused; an owner that exports its port
//! again, rejoined by its users.

mod common;

use std::time::Duration;

use common::{
    Frame, Number, Peer, assert_inspected, finished, peer, until_users, within, word, write_frame,
};
use imrs_ipc::{Imported, IpcError, Remote};
use imrs_ports::{AnyUser, Port, PortSpec, Shared, WireError, usage};
use imrs_testkit::unique_name;

/// The factor each user process answers with, by module.
fn factor_of(module: &str) -> u64 {
    match module {
        "LEFT" => 3,
        "RIGHT" => 5,
        other => panic!("an answer from {other}, not a user"),
    }
}

/// Checks the answers to broadcast `seed`, first and later, one from each of LEFT and
/// RIGHT: each read the frame in place, and built its answer in place, read here in place.
async fn assert_each_inspected<Req>(
    mut broadcast: imrs_ports::Broadcast<'_, Req, Shared<Frame>>,
    seed: u64,
) {
    let first = std::mem::take(&mut broadcast.first);
    let mut from = vec![broadcast.from.to_string()];
    assert_inspected(first, seed, factor_of(&from[0]));
    let (second, answer) = within(10, broadcast.next_reply()).await.unwrap();
    assert_inspected(answer, seed, factor_of(second.as_str()));
    from.push(second.to_string());
    from.sort();
    assert_eq!(from, ["LEFT", "RIGHT"], "each user answers once");
    assert!(within(10, broadcast.next_reply()).await.is_none());
}

/// How many frames each broadcast test sends: more than a port's samples (16), so that a
/// sample kept past its last handle would leave a later broadcast without one.
const BROADCAST_FRAMES: u64 = 40;

/// The user processes LEFT and RIGHT of port `port`, each in `role`, answering
/// [`BROADCAST_FRAMES`] frames.
fn frame_users(role: &str, cell: &str, port: &str) -> Vec<Peer> {
    let frames = BROADCAST_FRAMES.to_string();
    [("LEFT", "3"), ("RIGHT", "5")]
        .iter()
        .map(|(module, factor)| peer(&[role, cell, port, module, &frames, factor]))
        .collect()
}

/// Waits for each of `users` to end, having answered every frame.
async fn answered_every_frame(users: Vec<Peer>) {
    for user in users {
        let text = finished(user).await;
        let answered = text.lines().filter(|line| *line == "answered").count();
        assert_eq!(answered as u64, BROADCAST_FRAMES);
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_broadcast_of_frames_is_read_in_place_by_users_in_two_other_processes() {
    let cell = unique_name("shared-send-all");
    let port: Port<Shared<Frame>, Shared<Frame>, usage::SendAll, AnyUser, 2> =
        Port::new(PortSpec::new("FRAMES", "CAMERA").user_list(["LEFT", "RIGHT"]));
    let _exported = imrs_ipc::export(&Remote::new(&cell).unwrap(), &port).unwrap();
    let mut camera = port.owner().unwrap();
    let users = frame_users("frame-listener", &cell, "FRAMES");
    until_users(&camera, 2).await;
    for seed in 1..=BROADCAST_FRAMES {
        // Built in a loan, as a module would: a sample of shared memory, sent once for both
        // users.
        let mut frame = camera.loan().unwrap();
        write_frame(&mut frame, seed);
        let broadcast = within(10, camera.send_all(frame)).await.unwrap();
        assert_each_inspected(broadcast, seed).await;
    }
    answered_every_frame(users).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_callall_of_frames_is_answered_in_place_by_handlers_in_two_other_processes() {
    let cell = unique_name("shared-call-all");
    let port: Port<Shared<Frame>, Shared<Frame>, usage::CallAll, AnyUser, 2> =
        Port::new(PortSpec::new("LOOK", "CAMERA").user_list(["LEFT", "RIGHT"]));
    let _exported = imrs_ipc::export(&Remote::new(&cell).unwrap(), &port).unwrap();
    let mut camera = port.owner().unwrap();
    let users = frame_users("frame-answerer", &cell, "LOOK");
    until_users(&camera, 2).await;
    for seed in 1..=BROADCAST_FRAMES {
        let mut frame = Shared::new(Frame::default());
        write_frame(&mut frame, seed);
        let poll = within(10, camera.call_all(frame)).await.unwrap();
        assert_each_inspected(poll, seed).await;
    }
    answered_every_frame(users).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_broadcast_of_frames_to_a_user_process_killed_ends_with_the_others_answers_and_its_restart_is_served()
 {
    let cell = unique_name("shared-send-all-kill");
    let port: Port<Shared<Frame>, Shared<Frame>, usage::SendAll, AnyUser, 2> =
        Port::new(PortSpec::new("FRAMES", "CAMERA").user_list(["LEFT", "RIGHT"]));
    let _exported = imrs_ipc::export(&Remote::new(&cell).unwrap(), &port).unwrap();
    let mut camera = port.owner().unwrap();
    let mut users = frame_users("frame-listener", &cell, "FRAMES");
    until_users(&camera, 2).await;
    let mut frame = camera.loan().unwrap();
    write_frame(&mut frame, 1);
    let broadcast = within(10, camera.send_all(frame)).await.unwrap();
    assert_each_inspected(broadcast, 1).await;
    // kill -9 RIGHT's process: the next broadcast is answered by LEFT, and ends without
    // RIGHT's answer rather than waiting for it.
    let mut right = users.pop().unwrap();
    right.0.kill().unwrap();
    right.0.wait().unwrap();
    for seed in 2..=3u64 {
        let mut frame = camera.loan().unwrap();
        write_frame(&mut frame, seed);
        let mut broadcast = within(10, camera.send_all(frame)).await.unwrap();
        assert_eq!(broadcast.from, "LEFT");
        assert_inspected(std::mem::take(&mut broadcast.first), seed, 3);
        assert!(within(10, broadcast.next_reply()).await.is_none());
    }
    // A new copy of RIGHT subscribes again, and every broadcast from then on reaches both.
    let again = peer(&["frame-listener", &cell, "FRAMES", "RIGHT", "2", "5"]);
    let mut seed = 4;
    within(10, async {
        loop {
            let mut frame = camera.loan().unwrap();
            write_frame(&mut frame, seed);
            let mut broadcast = camera.send_all(frame).await.unwrap();
            let mut from = vec![broadcast.from.to_string()];
            assert_inspected(
                std::mem::take(&mut broadcast.first),
                seed,
                factor_of(&from[0]),
            );
            if let Some((second, answer)) = broadcast.next_reply().await {
                assert_inspected(answer, seed, factor_of(second.as_str()));
                from.push(second.to_string());
            }
            from.sort();
            if from == ["LEFT", "RIGHT"] {
                break;
            }
            assert_eq!(from, ["LEFT"], "only LEFT answers until RIGHT is back");
            seed += 1;
            tokio::time::sleep(Duration::from_millis(20)).await;
        }
    })
    .await;
    let mut frame = camera.loan().unwrap();
    write_frame(&mut frame, seed + 1);
    let broadcast = within(10, camera.send_all(frame)).await.unwrap();
    assert_each_inspected(broadcast, seed + 1).await;
    let text = finished(again).await;
    assert_eq!(text.lines().filter(|line| *line == "answered").count(), 2);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_broadcast_built_in_a_loan_is_read_in_place_by_a_user_here_and_in_two_other_processes() {
    // Built in a loan: a sample of shared memory, sent once for all three users.
    read_in_place_here_and_in_two_other_processes("shared-send-all-here", |camera| {
        camera.loan().unwrap()
    })
    .await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_broadcast_built_on_the_heap_is_copied_once_and_read_there_by_a_user_here_and_in_two_other_processes()
 {
    // Built on the heap: copied into one sample, sent once for all three users.
    read_in_place_here_and_in_two_other_processes("shared-send-all-heap", |_| {
        Shared::new(Frame::default())
    })
    .await;
}

/// Broadcasts [`BROADCAST_FRAMES`] frames, each made by `build`, to HERE, a user in this
/// process, and to LEFT and RIGHT, each in a process of its own: each reads every frame
/// where it lies in shared memory, read-only, and answers.
async fn read_in_place_here_and_in_two_other_processes(
    test: &str,
    build: impl Fn(&mut imrs_ports::End<Shared<Frame>, Shared<Frame>, usage::SendAll>) -> Shared<Frame>,
) {
    let cell = unique_name(test);
    let port: Port<Shared<Frame>, Shared<Frame>, usage::SendAll, AnyUser, 3> =
        Port::new(PortSpec::new("FRAMES", "CAMERA").user_list(["LEFT", "RIGHT", "HERE"]));
    let _exported = imrs_ipc::export(&Remote::new(&cell).unwrap(), &port).unwrap();
    let mut camera = port.owner().unwrap();
    // HERE, a user in the owner's process, answers as the others do, from the heap.
    let mut here = port.user_named("HERE").unwrap();
    let local = tokio::spawn(async move {
        for _ in 0..BROADCAST_FRAMES {
            let (mut frame, reply) = here.receive().await.unwrap();
            let mut answer = Shared::new(Frame::default());
            answer.words[0] = u64::from(!frame.is_writable());
            for (out, word) in answer.words.iter_mut().zip(frame.words.iter()).skip(4) {
                *out = word.wrapping_mul(7);
            }
            reply.reply(answer);
        }
    });
    let users = frame_users("frame-listener", &cell, "FRAMES");
    until_users(&camera, 3).await;
    for seed in 1..=BROADCAST_FRAMES {
        let mut frame = build(&mut camera);
        write_frame(&mut frame, seed);
        let mut broadcast = within(10, camera.send_all(frame)).await.unwrap();
        let mut answers = vec![(
            broadcast.from.to_string(),
            std::mem::take(&mut broadcast.first),
        )];
        while let Some((from, answer)) = within(10, broadcast.next_reply()).await {
            answers.push((from.to_string(), answer));
        }
        answers.sort_by(|a, b| a.0.cmp(&b.0));
        let from: Vec<&str> = answers.iter().map(|(from, _)| from.as_str()).collect();
        assert_eq!(from, ["HERE", "LEFT", "RIGHT"], "each user answers once");
        for (from, answer) in answers {
            if from != "HERE" {
                assert_inspected(answer, seed, factor_of(&from));
                continue;
            }
            // Read where the owner built it, as sent: a copy would be the user's to write.
            assert_eq!(answer.words[0], 1, "HERE read broadcast {seed} in a copy");
            for at in [4, 5, 4096, 8191] {
                assert_eq!(answer.words[at], word(seed, at).wrapping_mul(7));
            }
        }
    }
    within(10, local).await.unwrap();
    answered_every_frame(users).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_broadcast_port_of_frames_refuses_an_absent_owner_a_wrong_type_and_an_unlisted_module() {
    let cell = unique_name("shared-send-all-refused");
    let remote = Remote::new(&cell).unwrap();
    let nobody = imrs_ipc::import::<Imported<Shared<Frame>, Shared<Frame>, usage::SendAll>, _>(
        &remote, "FRAMES", "CAMERA", "LEFT",
    );
    assert_eq!(
        nobody.err(),
        Some(IpcError::NoOwner {
            port: "FRAMES".into()
        })
    );
    let port: Port<Shared<Frame>, Shared<Frame>, usage::SendAll, AnyUser, 2> =
        Port::new(PortSpec::new("FRAMES", "CAMERA").user_list(["LEFT", "RIGHT"]));
    let _exported = imrs_ipc::export(&remote, &port).unwrap();
    // The broadcasts are of frames, not numbers.
    let error = imrs_ipc::import::<Imported<Shared<Number>, Shared<Frame>, usage::SendAll>, _>(
        &remote, "FRAMES", "CAMERA", "LEFT",
    )
    .err()
    .expect("refused");
    assert!(
        matches!(&error, IpcError::TypeMismatch { port, .. } if port == "FRAMES"),
        "{error:?}"
    );
    let error = imrs_ipc::import::<Imported<Shared<Frame>, Shared<Frame>, usage::SendAll>, _>(
        &remote, "FRAMES", "CAMERA", "STRANGER",
    )
    .err()
    .expect("refused");
    assert_eq!(
        error,
        IpcError::Refused(WireError::NotOnUserList {
            port: "FRAMES".into(),
            module: "STRANGER".into(),
        })
    );
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_owner_that_exports_a_broadcast_port_again_is_rejoined_by_its_user_processes() {
    let cell = unique_name("shared-send-all-again");
    let remote = Remote::new(&cell).unwrap();
    let declare = || -> Port<Shared<Frame>, Shared<Frame>, usage::SendAll, AnyUser, 2> {
        Port::new(PortSpec::new("FRAMES", "CAMERA").user_list(["LEFT", "RIGHT"]))
    };
    let half = BROADCAST_FRAMES / 2;
    let mut seeds = 1..=BROADCAST_FRAMES;
    let mut users = Vec::new();
    for export in 0..2 {
        // The port, declared and exported anew: nothing of the first export is left here.
        let port = declare();
        let exported = imrs_ipc::export(&remote, &port).unwrap();
        if export == 0 {
            users = frame_users("frame-listener", &cell, "FRAMES");
        }
        let mut camera = port.owner().unwrap();
        // The second time, the user processes connected to the first export only.
        until_users(&camera, 2).await;
        for seed in seeds.by_ref().take(half as usize) {
            let mut frame = camera.loan().unwrap();
            write_frame(&mut frame, seed);
            let broadcast = within(10, camera.send_all(frame)).await.unwrap();
            assert_each_inspected(broadcast, seed).await;
        }
        drop(camera);
        drop(exported);
    }
    answered_every_frame(users).await;
}
