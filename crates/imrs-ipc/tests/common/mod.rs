//! What the tests of ports across processes share: the messages the crate's `ipc_peer`
//! knows, the peer processes started, awaited and killed, and a bounded wait. The owner of a
//! port runs in a child process (`ipc_peer`) or in the test's, its users here or in more
//! children. Every test has its own cell name, so the tests run in parallel without meeting;
//! across processes the ports run on real time, and the timeouts here only keep a failing
//! test from hanging.

// Each test file uses some of these only.
#![allow(dead_code)]

use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Stdio};
use std::time::Duration;

use imrs_ipc::{FromBytes, ZeroCopySend};
use imrs_ports::{End, SendError, Shared, usage};

/// The peer's message: the same by name, size and alignment.
#[derive(Debug, Clone, Copy, Default, PartialEq, ZeroCopySend, FromBytes)]
#[repr(C)]
#[type_name("imrs_ipc_tests::Number")]
pub(crate) struct Number {
    pub(crate) value: u64,
}

/// The peer's 64 KiB frame, carried by handle (`Shared`).
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend, FromBytes)]
#[repr(C)]
#[type_name("imrs_ipc_tests::Frame")]
pub(crate) struct Frame {
    pub(crate) words: [u64; 8192],
}

impl Default for Frame {
    fn default() -> Self {
        Self { words: [0; 8192] }
    }
}

/// Frame `seed`'s words, as a sender writes them.
pub(crate) fn word(seed: u64, at: usize) -> u64 {
    seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ at as u64
}

/// Writes frame `seed`'s words, from word 4 on.
pub(crate) fn write_frame(frame: &mut Frame, seed: u64) {
    for (at, out) in frame.words.iter_mut().enumerate().skip(4) {
        *out = word(seed, at);
    }
}

/// Checks the answer to frame `seed` of a handler that inspects frames (the peer's
/// `inspect`) with `factor`: the handler read the frame in place, built its answer in a
/// loan, and that answer is read here in place.
pub(crate) fn assert_inspected(mut answer: Shared<Frame>, seed: u64, factor: u64) {
    assert_eq!(
        answer.words[0], 1,
        "the handler read query {seed} in a copy"
    );
    assert_eq!(
        answer.words[3], 1,
        "the handler built answer {seed} on the heap"
    );
    assert!(
        !answer.is_writable(),
        "answer {seed} was copied out of its sample"
    );
    for at in [4, 5, 4096, 8191] {
        assert_eq!(answer.words[at], word(seed, at).wrapping_mul(factor));
    }
}

/// A child process, killed when the test ends however it ends.
pub(crate) struct Peer(pub(crate) Child);

impl Drop for Peer {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

pub(crate) fn peer(args: &[&str]) -> Peer {
    Peer(
        Command::new(env!("CARGO_BIN_EXE_ipc_peer"))
            .args(args)
            .stdout(Stdio::piped())
            .spawn()
            .expect("the peer starts"),
    )
}

/// Starts an owner of `port` in `cell` and waits until it has exported it.
pub(crate) fn owner(cell: &str, port: &str) -> Peer {
    started_owner("owner", cell, port)
}

/// Starts an owner of the role `role` (`owner`, `tight-owner`), ready once exported.
pub(crate) fn started_owner(role: &str, cell: &str, port: &str) -> Peer {
    started(&[role, cell, port])
}

/// Starts an owner with `args`, ready once exported.
pub(crate) fn started(args: &[&str]) -> Peer {
    let mut owner = peer(args);
    let stdout = owner.0.stdout.take().expect("piped");
    let mut line = String::new();
    BufReader::new(stdout)
        .read_line(&mut line)
        .expect("the owner speaks");
    assert_eq!(line.trim(), "ready", "the owner failed: {line}");
    owner
}

/// Starts a user process: module `module` asks the doubles of 1..=`n` on `cell`'s DOUBLE.
pub(crate) fn user(cell: &str, module: &str, n: &str) -> Peer {
    peer(&["user", cell, "DOUBLE", module, n])
}

/// Waits for a peer process to end; its answers, one a line. Fails the test if it failed,
/// or if it is still running after 30 s — then it is killed, so nothing hangs.
pub(crate) async fn answers(mut peer: Peer) -> Vec<u64> {
    let deadline = tokio::time::Instant::now() + Duration::from_secs(30);
    let status = loop {
        if let Some(status) = peer.0.try_wait().unwrap() {
            break status;
        }
        if tokio::time::Instant::now() >= deadline {
            let _ = peer.0.kill();
            let _ = peer.0.wait();
            let mut text = String::new();
            let _ = std::io::Read::read_to_string(&mut peer.0.stdout.take().unwrap(), &mut text);
            panic!(
                "a peer process hung after {} answers: {:?}",
                text.lines().count(),
                text.lines().last()
            );
        }
        tokio::time::sleep(Duration::from_millis(20)).await;
    };
    let mut text = String::new();
    std::io::Read::read_to_string(&mut peer.0.stdout.take().unwrap(), &mut text).unwrap();
    assert!(status.success(), "{text}");
    text.lines().map(|line| line.parse().unwrap()).collect()
}

/// Waits (10 s at most) until `n` users are attached to `end`'s port.
pub(crate) async fn until_users<Req, Rep, U>(end: &imrs_ports::End<Req, Rep, U>, n: usize)
where
    Req: Send + 'static,
    Rep: Send + 'static,
    U: imrs_ports::usage::Usage,
{
    within(10, async {
        while end.peers().len() < n {
            tokio::time::sleep(Duration::from_millis(20)).await;
        }
    })
    .await;
}

/// Waits (30 s at most) for a peer process to end successfully; what it printed.
pub(crate) async fn finished(mut peer: Peer) -> String {
    within(30, async {
        loop {
            if let Some(status) = peer.0.try_wait().unwrap() {
                let mut text = String::new();
                std::io::Read::read_to_string(&mut peer.0.stdout.take().unwrap(), &mut text)
                    .unwrap();
                assert!(status.success(), "{text}");
                break text;
            }
            tokio::time::sleep(Duration::from_millis(20)).await;
        }
    })
    .await
}

/// A module's end of an imported port of numbers.
pub(crate) type Asker = End<Number, Number, usage::Send>;

/// Sends 4000, which the owner sleeps 4 s before answering, and kills the owner with
/// `kill -9` meanwhile: the asker back, and what its send returned (within 3 s).
pub(crate) async fn send_while_the_owner_is_killed(
    mut asker: Asker,
    owner: &mut Peer,
) -> (Asker, Result<Number, SendError<Number>>) {
    let sending = tokio::spawn(async move {
        let result = asker.send(Number { value: 4000 }).await;
        (asker, result)
    });
    tokio::time::sleep(Duration::from_millis(300)).await;
    owner.0.kill().unwrap();
    owner.0.wait().unwrap();
    within(3, sending).await.unwrap()
}

/// The reply to `value` from a restarted owner (within 10 s): until its server is seen, a
/// send finds nobody.
pub(crate) async fn served_again(asker: &mut Asker, value: u64) -> Number {
    within(10, async {
        loop {
            match asker.send(Number { value }).await {
                Ok(reply) => break reply,
                Err(SendError::NoReply { .. }) => {
                    tokio::time::sleep(Duration::from_millis(50)).await;
                }
                Err(other) => panic!("{other:?}"),
            }
        }
    })
    .await
}

pub(crate) async fn within<T>(seconds: u64, future: impl Future<Output = T>) -> T {
    tokio::time::timeout(Duration::from_secs(seconds), future)
        .await
        .expect("no hang")
}
