//! Frames carried by handle (`Shared`) on `RECEIVE`, `RESPONSE` and `QUERY` ports across
//! processes: built in a loan of shared memory and read in place, and so are their answers;
//! loans beyond what the port allows refused by name; a frame on the heap or in another
//! port's loan copied once; loans held while their owner dies.

mod common;

use std::time::Duration;

use common::{
    Frame, assert_inspected, finished, peer, started_owner, until_users, within, word, write_frame,
};
use imrs_ipc::{Imported, Remote, import};
use imrs_ports::{AnyUser, End, Port, PortSpec, SendError, Shared, usage};
use imrs_testkit::unique_name;

fn sum(frame: &Frame) -> u64 {
    frame
        .words
        .iter()
        .fold(0u64, |sum, &word| sum.wrapping_add(word))
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_frame_built_in_a_loan_is_read_in_place_and_so_is_its_reply() {
    let cell = unique_name("shared");
    let _vision = started_owner("vision", &cell, "IMAGE");
    let remote = Remote::new(&cell).unwrap();
    let imported = import::<Imported<Shared<Frame>, Shared<Frame>, usage::Receive>, _>(
        &remote, "IMAGE", "VISION", "CAMERA",
    )
    .unwrap();
    let mut camera = imported.port().user_named("CAMERA").unwrap();
    let mut replies = Vec::new();
    let mut sums = Vec::new();
    for seed in 1..=20u64 {
        let mut frame = camera.loan().unwrap();
        // Lent by the transport, not the heap; and zeroed, whatever the sample held before.
        assert!(!frame.buffer().is::<Box<Frame>>());
        assert!(frame.words.iter().all(|&word| word == 0));
        for (at, out) in frame.words.iter_mut().enumerate().skip(4) {
            *out = word(seed, at);
        }
        // Frame 10 is answered in a loan the owner made for frame 9: sent as it lies, that
        // answer would go to frame 9's sender, long answered; it must come here.
        frame.words[3] = u64::from(seed == 10);
        sums.push(sum(&frame));
        let reply = within(10, camera.send(frame)).await.unwrap();
        assert_eq!(reply.words[0], 1, "the owner read frame {seed} in a copy");
        assert_eq!(
            reply.words[3], 1,
            "the owner built answer {seed} on the heap"
        );
        replies.push(reply);
    }
    // Every reply still reads as it was written, after the round trips that came after it:
    // a reply lies in its own sample for as long as it is kept.
    for (index, reply) in replies.iter_mut().enumerate() {
        let seed = index as u64 + 1;
        assert!(
            !reply.is_writable(),
            "reply {seed} lies in shared memory, read-only"
        );
        assert_eq!(reply.words[2], sums[index]);
        // The owner kept the previous frame past its reply, and read it again: unchanged.
        let previous = if index == 0 { 0 } else { sums[index - 1] };
        assert_eq!(reply.words[1], previous);
        for at in [4, 5, 4096, 8191] {
            assert_eq!(reply.words[at], word(seed, at).wrapping_mul(3));
        }
    }
    // Changing a reply copies it to the heap first; the copy is the reply's.
    let reply = &mut replies[0];
    reply.words[4] = 7;
    assert!(reply.is_writable());
    assert_eq!(reply.words[5], word(1, 5).wrapping_mul(3));
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn loans_beyond_what_the_port_allows_are_refused_by_name_and_one_given_back_is_lent_again() {
    let cell = unique_name("loans");
    let _vision = started_owner("vision", &cell, "IMAGE");
    let remote = Remote::new(&cell).unwrap();
    let imported = import::<Imported<Shared<Frame>, Shared<Frame>, usage::Receive>, _>(
        &remote, "IMAGE", "VISION", "CAMERA",
    )
    .unwrap();
    let mut camera = imported.port().user_named("CAMERA").unwrap();
    let mut loans = Vec::new();
    let refused = loop {
        match camera.loan() {
            Ok(loan) => loans.push(loan),
            Err(error) => break error,
        }
        assert!(
            loans.len() <= 64,
            "loans without end: the port's memory is unbounded"
        );
    };
    assert!(!loans.is_empty());
    assert_eq!(refused.port.as_str(), "IMAGE");
    assert!(refused.to_string().contains("IMAGE"), "{refused}");
    // One given back is lent again; and a loan held all that while is still sent and served.
    // Every loan the port allows is out again then: each send succeeds only because the
    // frame goes as it lies, taking no loan more — a copy would find no room.
    drop(loans.pop());
    let mut again = camera.loan().unwrap();
    again.words[5] = 11;
    let reply = within(10, camera.send(again)).await.unwrap();
    assert_eq!(reply.words[5], 33);
    drop(reply);
    let mut held = loans.pop().unwrap();
    held.words[6] = 2;
    let reply = within(10, camera.send(held)).await.unwrap();
    assert_eq!(reply.words[6], 6);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_frame_on_the_heap_or_in_another_ports_loan_is_copied_once_and_served() {
    let cell = unique_name("copied");
    let _vision = started_owner("vision", &cell, "IMAGE");
    let remote = Remote::new(&cell).unwrap();
    let imported = import::<Imported<Shared<Frame>, Shared<Frame>, usage::Receive>, _>(
        &remote, "IMAGE", "VISION", "CAMERA",
    )
    .unwrap();
    let other = import::<Imported<Shared<Frame>, Shared<Frame>, usage::Receive>, _>(
        &remote, "IMAGE", "VISION", "CAMERA_2",
    )
    .unwrap();
    let mut camera = imported.port().user_named("CAMERA").unwrap();
    let second = other.port().user_named("CAMERA_2").unwrap();
    // A loan of the other module's: sent on this port, it must be copied, not sent through
    // the client it came from (whose reply would never reach this sender).
    let mut borrowed = second.loan().unwrap();
    borrowed.words[4] = 5;
    let reply = within(10, camera.send(borrowed)).await.unwrap();
    assert_eq!(reply.words[4], 15);
    // A frame on the heap.
    let mut frame = Box::new(Frame { words: [0; 8192] });
    frame.words[8191] = 4;
    let reply = within(10, camera.send(Shared::in_buffer(frame)))
        .await
        .unwrap();
    assert_eq!(reply.words[8191], 12);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_query_built_in_a_loan_is_answered_in_place_by_the_owners_response_handler() {
    let cell = unique_name("shared-query");
    let _inspector = started_owner("inspector", &cell, "INSPECT");
    let remote = Remote::new(&cell).unwrap();
    let imported = imrs_ipc::import::<Imported<Shared<Frame>, Shared<Frame>, usage::Response>, _>(
        &remote,
        "INSPECT",
        "INSPECTOR",
        "ASKER",
    )
    .unwrap();
    let mut asker = imported.port().user_named("ASKER").unwrap();
    for seed in 1..=10u64 {
        let mut frame = asker.loan().unwrap();
        assert!(!frame.buffer().is::<Box<Frame>>());
        write_frame(&mut frame, seed);
        let answer = within(10, asker.query(frame)).await.unwrap();
        assert_inspected(answer, seed, 5);
    }
}

/// The owner of a `QUERY` port of frames queries its user in another process. Its loans
/// are samples of that user's process, where its queries are built and sent as they lie;
/// the user's response handler reads each where it lies and builds its answer in a reply
/// loan, which the owner reads in place.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_owners_query_of_frames_is_answered_in_place_by_its_user_in_another_process() {
    let cell = unique_name("shared-owner-query");
    let port: Port<Shared<Frame>, Shared<Frame>, usage::Query, AnyUser, 1> =
        Port::new(PortSpec::new("ASK_FRAME", "PARENT").user_list(["CHILD"]));
    let _exported = imrs_ipc::export(&Remote::new(&cell).unwrap(), &port).unwrap();
    let mut parent = port.owner().unwrap();
    let child = peer(&["frame-child", &cell, "ASK_FRAME", "CHILD", "11"]);
    until_users(&parent, 1).await;
    // The user is attached a moment before its process's relay is connected: until then a
    // loan is on the heap.
    within(5, async {
        while parent.loan().unwrap().buffer().is::<Box<Frame>>() {
            tokio::time::sleep(Duration::from_millis(20)).await;
        }
    })
    .await;
    let ask = async |parent: &mut End<Shared<Frame>, Shared<Frame>, usage::Query>,
                     mut frame: Shared<Frame>,
                     seed: u64| {
        write_frame(&mut frame, seed);
        let answer = within(10, parent.query(frame)).await.unwrap();
        assert_inspected(answer, seed, 7);
    };
    for seed in 1..=10u64 {
        let frame = parent.loan().unwrap();
        assert!(
            !frame.buffer().is::<Box<Frame>>(),
            "loan {seed} is on the heap"
        );
        ask(&mut parent, frame, seed).await;
    }
    // With every loan out, a query built in the last still crosses: it goes as it lies,
    // where a copy would find no room.
    let mut held = Vec::new();
    let refused = loop {
        match parent.loan() {
            Ok(loan) => held.push(loan),
            Err(error) => break error,
        }
        assert!(held.len() <= 64, "loans without end");
    };
    assert_eq!(refused.port.as_str(), "ASK_FRAME");
    let last = held.pop().unwrap();
    ask(&mut parent, last, 11).await;
    drop(held);
    let text = finished(child).await;
    assert_eq!(text.lines().filter(|line| *line == "answered").count(), 11);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn loans_held_while_their_owner_dies_fail_by_name_and_serve_its_restart() {
    let cell = unique_name("loan-kill");
    let mut first = started_owner("vision", &cell, "IMAGE");
    let remote = Remote::new(&cell).unwrap();
    let imported = import::<Imported<Shared<Frame>, Shared<Frame>, usage::Receive>, _>(
        &remote, "IMAGE", "VISION", "CAMERA",
    )
    .unwrap();
    let mut camera = imported.port().user_named("CAMERA").unwrap();
    // Two frames built while the owner lives; then kill -9 it.
    let (mut doomed, mut kept) = (camera.loan().unwrap(), camera.loan().unwrap());
    doomed.words[4] = 1;
    kept.words[4] = 2;
    first.0.kill().unwrap();
    first.0.wait().unwrap();
    let result = within(5, camera.send(doomed)).await;
    assert!(
        matches!(result, Err(SendError::NoReply { ref port }) if port == "IMAGE"),
        "{result:?}"
    );
    // A new copy of the owner exports the port again. Until its server is seen, a send
    // finds nobody; then new loans are served.
    let _second = started_owner("vision", &cell, "IMAGE");
    within(10, async {
        loop {
            let mut probe = camera.loan().unwrap();
            probe.words[4] = 3;
            match camera.send(probe).await {
                Ok(reply) => break assert_eq!(reply.words[4], 9),
                Err(SendError::NoReply { .. }) => {
                    tokio::time::sleep(Duration::from_millis(50)).await;
                }
                Err(other) => panic!("{other:?}"),
            }
        }
    })
    .await;
    // And the frame built before the death is still the sender's, and is served.
    let reply = within(10, camera.send(kept)).await.unwrap();
    assert_eq!(reply.words[4], 6);
}
