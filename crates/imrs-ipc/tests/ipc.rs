//! Ports across processes, wired as a user wires them: the owner in a child process (the
//! crate's `ipc_peer`), users here or in more children. Every test has its own cell name,
//! so the tests run in parallel without meeting; across processes the ports run on real
//! time, and the timeouts here only keep a failing test from hanging.

use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Stdio};
use std::time::Duration;

use imrs_ipc::{FromBytes, Imported, IpcError, Remote, ZeroCopySend, export, import};
use imrs_ports::{
    AnyUser, End, Name, Port, PortSpec, ProcessType, ReplyHandle, SendError, Shared, WireError,
    usage,
};
use imrs_testkit::unique_name;

/// The peer's message: the same by name, size and alignment.
#[derive(Debug, Clone, Copy, Default, PartialEq, ZeroCopySend, FromBytes)]
#[repr(C)]
#[type_name("imrs_ipc_tests::Number")]
struct Number {
    value: u64,
}

/// A message the peer does not know.
#[derive(Debug, Clone, Copy, Default, PartialEq, ZeroCopySend, FromBytes)]
#[repr(C)]
#[type_name("imrs_ipc_tests::Wide")]
struct Wide {
    value: u64,
    more: u64,
}

/// The peer's 64 KiB frame, carried by handle (`Shared`).
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend, FromBytes)]
#[repr(C)]
#[type_name("imrs_ipc_tests::Frame")]
struct Frame {
    words: [u64; 8192],
}

impl Default for Frame {
    fn default() -> Self {
        Self { words: [0; 8192] }
    }
}

fn sum(frame: &Frame) -> u64 {
    frame
        .words
        .iter()
        .fold(0u64, |sum, &word| sum.wrapping_add(word))
}

/// Frame `seed`'s words, as a sender writes them.
fn word(seed: u64, at: usize) -> u64 {
    seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ at as u64
}

/// Writes frame `seed`'s words, from word 4 on.
fn write_frame(frame: &mut Frame, seed: u64) {
    for (at, out) in frame.words.iter_mut().enumerate().skip(4) {
        *out = word(seed, at);
    }
}

/// Checks the answer to frame `seed` of a handler that inspects frames (the peer's
/// `inspect`) with `factor`: the handler read the frame in place, built its answer in a
/// loan, and that answer is read here in place.
fn assert_inspected(mut answer: Shared<Frame>, seed: u64, factor: u64) {
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
struct Peer(Child);

impl Drop for Peer {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn peer(args: &[&str]) -> Peer {
    Peer(
        Command::new(env!("CARGO_BIN_EXE_ipc_peer"))
            .args(args)
            .stdout(Stdio::piped())
            .spawn()
            .expect("the peer starts"),
    )
}

/// Starts an owner of `port` in `cell` and waits until it has exported it.
fn owner(cell: &str, port: &str) -> Peer {
    started_owner("owner", cell, port)
}

/// Starts an owner of the role `role` (`owner`, `tight-owner`), ready once exported.
fn started_owner(role: &str, cell: &str, port: &str) -> Peer {
    started(&[role, cell, port])
}

/// Starts an owner with `args`, ready once exported.
fn started(args: &[&str]) -> Peer {
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
fn user(cell: &str, module: &str, n: &str) -> Peer {
    peer(&["user", cell, "DOUBLE", module, n])
}

/// Waits for a peer process to end; its answers, one a line. Fails the test if it failed,
/// or if it is still running after 30 s — then it is killed, so nothing hangs.
async fn answers(mut peer: Peer) -> Vec<u64> {
    let deadline = tokio::time::Instant::now() + Duration::from_secs(30);
    let status = loop {
        if let Some(status) = peer.0.try_wait().unwrap() {
            break status;
        }
        assert!(
            tokio::time::Instant::now() < deadline,
            "a peer process hung"
        );
        tokio::time::sleep(Duration::from_millis(20)).await;
    };
    let mut text = String::new();
    std::io::Read::read_to_string(&mut peer.0.stdout.take().unwrap(), &mut text).unwrap();
    assert!(status.success(), "{text}");
    text.lines().map(|line| line.parse().unwrap()).collect()
}

/// Waits for each user process (started by [`user`] to ask the doubles of 1..=`n`) to end,
/// and checks that it got them all, in order.
async fn each_doubled(users: Vec<Peer>, n: u64) {
    for user in users {
        assert_eq!(
            answers(user).await,
            (1..=n).map(|v| 2 * v).collect::<Vec<_>>()
        );
    }
}

/// Waits (10 s at most) until `n` users are attached to `end`'s port.
async fn until_users<Req, Rep, U>(end: &imrs_ports::End<Req, Rep, U>, n: usize)
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
async fn finished(mut peer: Peer) -> String {
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
type Asker = End<Number, Number, usage::Send>;

/// Sends 4000, which the owner sleeps 4 s before answering, and kills the owner with
/// `kill -9` meanwhile: the asker back, and what its send returned (within 3 s).
async fn send_while_the_owner_is_killed(
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
async fn served_again(asker: &mut Asker, value: u64) -> Number {
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

async fn within<T>(seconds: u64, future: impl Future<Output = T>) -> T {
    tokio::time::timeout(Duration::from_secs(seconds), future)
        .await
        .expect("no hang")
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_send_crosses_to_the_owners_process_and_its_reply_comes_back() {
    let cell = unique_name("send");
    let _owner = owner(&cell, "DOUBLE");
    let remote = Remote::new(&cell).unwrap();
    let imported = import::<Imported<Number, Number, usage::Receive>, _>(
        &remote, "DOUBLE", "DOUBLER", "ASKER",
    )
    .unwrap();
    // The module's code is what it would be in one process.
    let mut asker = imported.port().user_named("ASKER").unwrap();
    for value in 1..=200 {
        let reply = within(5, asker.send(Number { value })).await.unwrap();
        assert_eq!(reply.value, 2 * value);
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn two_user_processes_are_served_at_once() {
    let cell = unique_name("users");
    let _owner = owner(&cell, "DOUBLE");
    let users: Vec<Peer> = ["ASKER", "ASKER_2"]
        .iter()
        .map(|module| user(&cell, module, "100"))
        .collect();
    each_doubled(users, 100).await;
}

/// The bridge answers a request where the owner's reply is given, when it can: here in a
/// thread of the test's own, outside the runtime, while requests from four processes keep
/// coming, so that the bridge also takes new requests into the port from that thread. None
/// of that may need the runtime, and every reply must cross.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn replies_given_outside_the_runtime_cross_while_requests_keep_coming() {
    let cell = unique_name("outside");
    let remote = Remote::new(&cell).unwrap();
    let modules = ["ASKER", "ASKER_2", "ASKER_3", "ASKER_4"];
    let port: Port<Number, Number, usage::Receive, AnyUser, 4> =
        Port::new(PortSpec::new("DOUBLE", "DOUBLER").user_list(modules));
    let _exported = export(&remote, &port).unwrap();
    let mut owner = port.owner().unwrap();
    let (handles, replier) = std::sync::mpsc::channel::<(Number, ReplyHandle<Number>)>();
    let replier = std::thread::spawn(move || {
        let mut replied = 0;
        for (number, reply) in replier {
            reply.reply(Number {
                value: 2 * number.value,
            });
            replied += 1;
        }
        replied
    });
    let serving = tokio::spawn(async move {
        for _ in 0..800 {
            let taken = owner.receive().await.unwrap();
            handles.send(taken).unwrap();
        }
    });
    let users: Vec<Peer> = modules
        .iter()
        .map(|module| user(&cell, module, "200"))
        .collect();
    each_doubled(users, 200).await;
    within(5, serving).await.unwrap();
    assert_eq!(
        replier.join().expect("the replying thread did not panic"),
        800
    );
}

/// Runs `future` to its end in this thread, with no runtime: parks until woken.
fn block_on<F: Future>(future: F) -> F::Output {
    struct Unpark(std::thread::Thread);
    impl std::task::Wake for Unpark {
        fn wake(self: std::sync::Arc<Self>) {
            self.0.unpark();
        }
    }
    let waker = std::task::Waker::from(std::sync::Arc::new(Unpark(std::thread::current())));
    let mut context = std::task::Context::from_waker(&waker);
    let mut future = std::pin::pin!(future);
    loop {
        if let std::task::Poll::Ready(output) = future.as_mut().poll(&mut context) {
            return output;
        }
        std::thread::park();
    }
}

/// A module's send carries its request into shared memory in the thread it is polled in,
/// and the reply wakes that thread: here one outside the runtime, which only parks. The
/// bridge must need nothing of the runtime there, and the reply must still come.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_send_polled_outside_the_runtime_crosses_and_its_reply_wakes_it() {
    let cell = unique_name("outside-send");
    let _owner = owner(&cell, "DOUBLE");
    let remote = Remote::new(&cell).unwrap();
    let imported = import::<Imported<Number, Number, usage::Receive>, _>(
        &remote, "DOUBLE", "DOUBLER", "ASKER",
    )
    .unwrap();
    let mut asker = imported.port().user_named("ASKER").unwrap();
    let sender = std::thread::spawn(move || {
        (1..=200)
            .map(|value| block_on(asker.send(Number { value })).unwrap().value)
            .collect::<Vec<_>>()
    });
    let replies = within(10, tokio::task::spawn_blocking(move || sender.join()))
        .await
        .unwrap()
        .expect("the sending thread did not panic");
    assert_eq!(replies, (1..=200).map(|v| 2 * v).collect::<Vec<_>>());
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_module_not_on_the_user_list_is_refused_by_name() {
    let cell = unique_name("unlisted");
    let _owner = owner(&cell, "DOUBLE");
    let remote = Remote::new(&cell).unwrap();
    let error = import::<Imported<Number, Number, usage::Receive>, _>(
        &remote, "DOUBLE", "DOUBLER", "STRANGER",
    )
    .err()
    .expect("refused");
    assert_eq!(
        error,
        IpcError::Refused(WireError::NotOnUserList {
            port: "DOUBLE".into(),
            module: "STRANGER".into(),
        })
    );
    assert!(error.to_string().contains("STRANGER"), "{error}");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_type_the_other_process_does_not_share_is_refused_naming_the_port() {
    let cell = unique_name("types");
    let _owner = owner(&cell, "DOUBLE");
    let remote = Remote::new(&cell).unwrap();
    let error =
        import::<Imported<Wide, Number, usage::Receive>, _>(&remote, "DOUBLE", "DOUBLER", "ASKER")
            .err()
            .expect("refused");
    assert!(
        matches!(&error, IpcError::TypeMismatch { port, .. } if port == "DOUBLE"),
        "{error:?}"
    );
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_owner_killed_mid_rendezvous_fails_the_sender_and_its_restart_is_served() {
    let cell = unique_name("kill");
    let mut first = owner(&cell, "DOUBLE");
    let remote = Remote::new(&cell).unwrap();
    let imported = import::<Imported<Number, Number, usage::Receive>, _>(
        &remote, "DOUBLE", "DOUBLER", "ASKER",
    )
    .unwrap();
    let mut asker = imported.port().user_named("ASKER").unwrap();
    assert_eq!(
        within(5, asker.send(Number { value: 1 }))
            .await
            .unwrap()
            .value,
        2
    );
    let (mut asker, result) = send_while_the_owner_is_killed(asker, &mut first).await;
    assert!(
        matches!(result, Err(SendError::NoReply { ref port }) if port == "DOUBLE"),
        "{result:?}"
    );
    // A new copy of the owner exports the port again; the same importer is served.
    let _second = owner(&cell, "DOUBLE");
    assert_eq!(served_again(&mut asker, 21).await.value, 42);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn two_cells_with_the_same_port_names_never_meet() {
    let (a, b) = (unique_name("cell-a"), unique_name("cell-b"));
    // Were their services one, the second owner would be refused: one owner per port.
    let _owner_a = owner(&a, "DOUBLE");
    let _owner_b = owner(&b, "DOUBLE");
    for cell in [&a, &b] {
        let remote = Remote::new(cell).unwrap();
        let imported = import::<Imported<Number, Number, usage::Receive>, _>(
            &remote, "DOUBLE", "DOUBLER", "ASKER",
        )
        .unwrap();
        let mut asker = imported.port().user_named("ASKER").unwrap();
        assert_eq!(
            within(5, asker.send(Number { value: 8 }))
                .await
                .unwrap()
                .value,
            16
        );
    }
}

#[test]
fn a_cell_name_that_cannot_name_a_service_is_refused_by_name() {
    let error = Remote::new("my cell/../x").unwrap_err();
    assert!(error.to_string().contains("my cell/../x"), "{error}");
}

/// The request header as the bridge lays it out, for a peer that writes garbage into it.
#[derive(Debug, Clone, Copy, ZeroCopySend, FromBytes)]
#[repr(C)]
#[type_name("imrs_ipc::RequestMeta")]
struct ForgedMeta {
    kind: u32,
    module_len: u32,
    module: [u8; 64],
}

impl Default for ForgedMeta {
    fn default() -> Self {
        Self {
            kind: 0,
            module_len: 0,
            module: [0; 64],
        }
    }
}

#[derive(Debug, Clone, Copy, Default, ZeroCopySend, FromBytes)]
#[repr(C)]
#[type_name("imrs_ipc::ReplyMeta")]
struct ReplyMeta {
    status: u32,
    detail: u32,
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_malformed_request_is_refused_and_the_owner_keeps_serving() {
    use iceoryx2::prelude::*;

    let cell = unique_name("garbage");
    let _owner = owner(&cell, "DOUBLE");
    let node = NodeBuilder::new()
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc_threadsafe::Service>()
        .unwrap();
    let name = format!("imrs/{cell}/DOUBLE/messages");
    let service = node
        .service_builder(&ServiceName::new(&name).unwrap())
        .request_response::<Number, Number>()
        .request_user_header::<ForgedMeta>()
        .response_user_header::<ReplyMeta>()
        .open()
        .unwrap();
    let client = service.client_builder().create().unwrap();
    // A module name 999 bytes long in a 64-byte buffer; then a kind that does not exist.
    let forged = [
        ForgedMeta {
            kind: 2,
            module_len: 999,
            module: [b'A'; 64],
        },
        ForgedMeta {
            kind: 77,
            module_len: 5,
            module: [b'A'; 64],
        },
    ];
    for meta in forged {
        let mut loan = client.loan_uninit().unwrap();
        *loan.user_header_mut() = meta;
        let pending = loan.write_payload(Number { value: 1 }).send().unwrap();
        let response = within(5, async {
            loop {
                if let Some(response) = pending.receive().unwrap() {
                    break *response.user_header();
                }
                tokio::time::sleep(Duration::from_millis(10)).await;
            }
        })
        .await;
        assert_ne!(response.status, 0, "a forged request was served");
    }
    // The owner still serves its real users.
    let remote = Remote::new(&cell).unwrap();
    let imported = import::<Imported<Number, Number, usage::Receive>, _>(
        &remote, "DOUBLE", "DOUBLER", "ASKER",
    )
    .unwrap();
    let mut asker = imported.port().user_named("ASKER").unwrap();
    assert_eq!(
        within(5, asker.send(Number { value: 4 }))
            .await
            .unwrap()
            .value,
        8
    );
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_user_timeout_holds_across_processes_and_the_late_reply_harms_nothing() {
    let cell = unique_name("timeout");
    let _owner = owner(&cell, "DOUBLE");
    let remote = Remote::new(&cell).unwrap();
    let imported = import::<Imported<Number, Number, usage::Receive>, _>(
        &remote, "DOUBLE", "DOUBLER", "ASKER",
    )
    .unwrap();
    let mut asker = imported
        .port()
        .user_named("ASKER")
        .unwrap()
        .with_timeout(Duration::from_millis(300));
    // The owner takes 1.5 s over 1500: past the user's timeout.
    let late = within(5, asker.send(Number { value: 1500 })).await;
    assert!(
        matches!(late, Err(SendError::ReplyTimeout { ref port }) if port == "DOUBLE"),
        "{late:?}"
    );
    // Until the owner answers 1500, the user's one outstanding request holds its place in
    // the port, as it would in one process: the next sends time out, untaken. Then the late
    // reply goes nowhere, and each later send gets its own reply.
    for value in [3, 4, 5] {
        let reply = within(5, async {
            loop {
                match asker.send(Number { value }).await {
                    Ok(reply) => break reply,
                    // The owner is still busy with 1500: this one times out too.
                    Err(SendError::ReplyTimeout { .. } | SendError::Timeout { .. }) => {}
                    Err(other) => panic!("{other:?}"),
                }
            }
        })
        .await;
        assert_eq!(reply.value, 2 * value);
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_ports_shared_memory_and_service_files_are_for_the_cells_user_only() {
    use std::os::unix::fs::PermissionsExt;

    let cell = unique_name("permissions");
    let _owner = owner(&cell, "DOUBLE");
    let remote = Remote::new(&cell).unwrap();
    let imported = import::<Imported<Number, Number, usage::Receive>, _>(
        &remote, "DOUBLE", "DOUBLER", "ASKER",
    )
    .unwrap();
    let mut asker = imported.port().user_named("ASKER").unwrap();
    assert_eq!(
        within(5, asker.send(Number { value: 1 }))
            .await
            .unwrap()
            .value,
        2
    );
    // And a port whose broadcasts go out on a publish-subscribe service of its own.
    let frames: Port<Shared<Frame>, Shared<Frame>, usage::SendAll, AnyUser, 1> =
        Port::new(PortSpec::new("FRAMES", "CAMERA").user_list(["LEFT"]));
    let _broadcasts = imrs_ipc::export(&remote, &frames).unwrap();
    let listening = imrs_ipc::import::<Imported<Shared<Frame>, Shared<Frame>, usage::SendAll>, _>(
        &remote, "FRAMES", "CAMERA", "LEFT",
    )
    .unwrap();
    let mut left = listening.port().user_named("LEFT").unwrap();
    let echo = tokio::spawn(async move {
        let (frame, reply) = left.receive().await.unwrap();
        reply.reply(frame);
    });
    let mut camera = frames.owner().unwrap();
    until_users(&camera, 1).await;
    let mut frame = camera.loan().unwrap();
    write_frame(&mut frame, 1);
    let broadcast = within(5, camera.send_all(frame)).await.unwrap();
    assert_eq!(broadcast.first.words[4], word(1, 4));
    within(5, echo).await.unwrap();
    // Every file iceoryx2 keeps for services and their data, but its one host-wide
    // bookkeeping file, is readable and writable by its owner alone.
    let mut files = Vec::new();
    let mut look = vec![std::path::PathBuf::from("/tmp/iceoryx2")];
    while let Some(dir) = look.pop() {
        for entry in std::fs::read_dir(&dir).into_iter().flatten().flatten() {
            let path = entry.path();
            if path.is_dir() {
                look.push(path);
            } else {
                files.push(path);
            }
        }
    }
    files.extend(
        std::fs::read_dir("/dev/shm")
            .unwrap()
            .flatten()
            .map(|entry| entry.path())
            .filter(|path| {
                let name = path.file_name().unwrap().to_string_lossy().into_owned();
                name.starts_with("iox2_") && !name.ends_with("global_mgmt")
            }),
    );
    assert!(
        !files.is_empty(),
        "no iceoryx2 files found: the test looks in the wrong place"
    );
    for path in files {
        // Files of other tests may come and go meanwhile.
        let Ok(metadata) = std::fs::metadata(&path) else {
            continue;
        };
        let mode = metadata.permissions().mode() & 0o777;
        assert_eq!(mode & 0o077, 0, "{} is {mode:o}", path.display());
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_owner_selects_over_an_exported_port_and_a_local_one() {
    use imrs_ports::{AnyUser, Port, PortSpec, select, usage};

    let cell = unique_name("select");
    // This process owns both: DOUBLE, used from another process, and LOCAL, from here.
    let remote_port: Port<Number, Number, usage::Receive, AnyUser, 2> = Port::new(
        PortSpec::new("DOUBLE", "DOUBLER")
            .user_list(["ASKER"])
            .priority(2),
    );
    let local_port: Port<Number, Number, usage::Receive, AnyUser, 1> =
        Port::new(PortSpec::new("LOCAL", "DOUBLER").priority(1));
    let _exported = imrs_ipc::export(&Remote::new(&cell).unwrap(), &remote_port).unwrap();
    let asking = user(&cell, "ASKER", "50");
    let mut local = local_port.user_named("HERE").unwrap();
    let local_sends = tokio::spawn(async move {
        for value in 1..=50 {
            assert_eq!(local.send(Number { value }).await.unwrap().value, 2 * value);
        }
    });
    let (mut from_there, mut from_here) =
        (remote_port.owner().unwrap(), local_port.owner().unwrap());
    let mut served = [0, 0];
    within(30, async {
        while served != [50, 50] {
            let (which, number, reply) = select()
                .or(&mut from_there, |(number, reply)| (0, number, reply))
                .or(&mut from_here, |(number, reply)| (1, number, reply))
                .await
                .unwrap();
            served[which] += 1;
            reply.reply(Number {
                value: 2 * number.value,
            });
        }
    })
    .await;
    within(5, local_sends).await.unwrap();
    assert_eq!(answers(asking).await.len(), 50);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_user_killed_mid_rendezvous_harms_nobody_and_its_restart_is_served() {
    use imrs_ports::{AnyUser, Port, PortSpec, usage};

    let cell = unique_name("user-killed");
    let port: Port<Number, Number, usage::Receive, AnyUser, 1> =
        Port::new(PortSpec::new("DOUBLE", "DOUBLER").user_list(["ASKER"]));
    let _exported = imrs_ipc::export(&Remote::new(&cell).unwrap(), &port).unwrap();
    let mut owner = port.owner().unwrap();
    // The user's first request is here; kill -9 it before the reply.
    let mut first = user(&cell, "ASKER", "5");
    let (number, reply) = within(10, owner.receive()).await.unwrap();
    assert_eq!(number.value, 1);
    first.0.kill().unwrap();
    first.0.wait().unwrap();
    // The reply goes to nobody; the owner's side goes on.
    reply.reply(Number { value: 2 });
    // A new copy of the user, under the same module name, is served in full.
    let second = user(&cell, "ASKER", "3");
    for value in 1..=3 {
        let (number, reply) = within(10, owner.receive()).await.unwrap();
        assert_eq!(number.value, value);
        reply.reply(Number { value: 2 * value });
    }
    assert_eq!(answers(second).await, [2, 4, 6]);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_query_crosses_and_the_owners_response_handler_answers_it() {
    let cell = unique_name("query");
    let mut responder = peer(&["responder", &cell, "TRIPLE"]);
    let stdout = responder.0.stdout.take().expect("piped");
    let mut line = String::new();
    BufReader::new(stdout)
        .read_line(&mut line)
        .expect("the responder speaks");
    assert_eq!(line.trim(), "ready", "the responder failed: {line}");
    let remote = Remote::new(&cell).unwrap();
    let imported = imrs_ipc::import::<Imported<Number, Number, usage::Response>, _>(
        &remote, "TRIPLE", "TRIPLER", "ASKER",
    )
    .unwrap();
    // The module queries, as it would a port of its own process.
    let mut asker = imported.port().user_named("ASKER").unwrap();
    for value in 1..=50 {
        let answer = within(5, asker.query(Number { value })).await.unwrap();
        assert_eq!(answer.value, 3 * value);
    }
    // And the owner's list holds: a module it does not know is refused by name.
    let error = imrs_ipc::import::<Imported<Number, Number, usage::Response>, _>(
        &remote, "TRIPLE", "TRIPLER", "OTHER",
    )
    .err()
    .expect("refused");
    assert_eq!(
        error,
        IpcError::Refused(WireError::NotOnUserList {
            port: "TRIPLE".into(),
            module: "OTHER".into(),
        })
    );
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_broadcast_reaches_users_in_other_processes_and_their_replies_come_back() {
    use imrs_ports::{AnyUser, Port, PortSpec, usage};

    let cell = unique_name("send-all");
    let port: Port<Number, Number, usage::SendAll, AnyUser, 2> =
        Port::new(PortSpec::new("NEWS", "BROADCASTER").user_list(["ASKER", "ASKER_2"]));
    let _exported = imrs_ipc::export(&Remote::new(&cell).unwrap(), &port).unwrap();
    let mut broadcaster = port.owner().unwrap();
    let listeners: Vec<Peer> = ["ASKER", "ASKER_2"]
        .iter()
        .map(|module| peer(&["listener", &cell, "NEWS", module, "20"]))
        .collect();
    // Both listeners' ends are attached when their processes connect.
    until_users(&broadcaster, 2).await;
    for value in 1..=20 {
        let mut broadcast = within(5, broadcaster.send_all(Number { value }))
            .await
            .unwrap();
        assert_eq!(broadcast.first.value, 2 * value);
        let (second, reply) = within(5, broadcast.next_reply()).await.unwrap();
        assert_ne!(second, broadcast.from, "each listener answers once");
        assert_eq!(reply.value, 2 * value);
        assert!(within(5, broadcast.next_reply()).await.is_none());
    }
    for listener in listeners {
        assert_eq!(answers(listener).await, (1..=20).collect::<Vec<_>>());
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_port_full_of_users_refuses_one_more_process_with_its_capacity() {
    use imrs_ports::{AnyUser, Port, PortSpec, usage};

    let cell = unique_name("full");
    // Room for one user, whoever it is.
    let port: Port<Number, Number, usage::Receive, AnyUser, 1> =
        Port::new(PortSpec::new("SINGLE", "OWNER"));
    let remote = Remote::new(&cell).unwrap();
    let _exported = imrs_ipc::export(&remote, &port).unwrap();
    let _first =
        import::<Imported<Number, Number, usage::Receive>, _>(&remote, "SINGLE", "OWNER", "FIRST")
            .unwrap();
    let error =
        import::<Imported<Number, Number, usage::Receive>, _>(&remote, "SINGLE", "OWNER", "SECOND")
            .err()
            .expect("refused");
    assert_eq!(
        error,
        IpcError::Refused(WireError::TooManyUsers {
            port: "SINGLE".into(),
            module: "SECOND".into(),
            capacity: 1,
        })
    );
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_send_dropped_halfway_loses_nothing_and_the_next_gets_its_own_reply() {
    let cell = unique_name("dropped");
    let _owner = owner(&cell, "DOUBLE");
    let remote = Remote::new(&cell).unwrap();
    let imported = import::<Imported<Number, Number, usage::Receive>, _>(
        &remote, "DOUBLE", "DOUBLER", "ASKER",
    )
    .unwrap();
    let mut asker = imported.port().user_named("ASKER").unwrap();
    // The owner takes 1.2 s over 1200; the sender gives up after 200 ms, dropping the send.
    let gave_up = tokio::time::timeout(
        Duration::from_millis(200),
        asker.send(Number { value: 1200 }),
    )
    .await;
    assert!(gave_up.is_err(), "{gave_up:?}");
    // The next send waits for the owner to be done with the dropped one, then gets its own
    // reply, not the late 2400.
    let reply = within(5, asker.send(Number { value: 7 })).await.unwrap();
    assert_eq!(reply.value, 14);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_port_admits_as_many_user_processes_as_its_restrictions_say_not_iceoryx2s_default() {
    use imrs_ports::{AnyUser, Port, PortSpec, usage};

    let cell = unique_name("many");
    // Three times iceoryx2's default of 8 clients to a service.
    const USERS: usize = 24;
    let port: Port<Number, Number, usage::Receive, AnyUser, USERS> =
        Port::new(PortSpec::new("MANY", "OWNER"));
    let remote = Remote::new(&cell).unwrap();
    let _exported = imrs_ipc::export(&remote, &port).unwrap();
    let users: Vec<_> = (0..USERS)
        .map(|n| {
            let module = format!("USER_{n}");
            import::<Imported<Number, Number, usage::Receive>, _>(&remote, "MANY", "OWNER", &module)
                .unwrap_or_else(|error| panic!("{module}: {error}"))
        })
        .collect();
    // One more is refused by the port, naming it, as in one process.
    let error = import::<Imported<Number, Number, usage::Receive>, _>(
        &remote,
        "MANY",
        "OWNER",
        "ONE_TOO_MANY",
    )
    .err()
    .expect("refused");
    assert_eq!(
        error,
        IpcError::Refused(WireError::TooManyUsers {
            port: "MANY".into(),
            module: "ONE_TOO_MANY".into(),
            capacity: USERS,
        })
    );
    // And every admitted user is served.
    let mut owner = port.owner().unwrap();
    let serve = tokio::spawn(async move {
        for _ in 0..USERS {
            let (n, reply) = owner.receive().await.unwrap();
            reply.reply(Number { value: n.value * 2 });
        }
    });
    for (n, imported) in users.iter().enumerate() {
        let mut end = imported.port().user_named(format!("USER_{n}")).unwrap();
        let value = n as u64;
        let doubled = within(10, end.send(Number { value })).await.unwrap();
        assert_eq!(doubled.value, 2 * value);
    }
    within(10, serve).await.unwrap();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn importing_a_port_that_nobody_exports_says_so_at_once() {
    let remote = Remote::new(&unique_name("nobody")).unwrap();
    let started = std::time::Instant::now();
    let error =
        import::<Imported<Number, Number, usage::Receive>, _>(&remote, "NOBODYS", "OWNER", "USER")
            .err()
            .expect("refused");
    assert_eq!(
        error,
        IpcError::NoOwner {
            port: "NOBODYS".into()
        }
    );
    // Not after the connect timeout: the port's services are not there at all.
    assert!(started.elapsed() < Duration::from_secs(2));
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_callall_query_reaches_response_handlers_in_other_processes_and_in_this_one() {
    use imrs_ports::{AnyUser, Port, PortSpec, usage};

    let cell = unique_name("call-all");
    let port: Port<Number, Number, usage::CallAll, AnyUser, 3> =
        Port::new(PortSpec::new("POLL", "CALLER").user_list(["REMOTE_1", "REMOTE_2", "LOCAL"]));
    let _exported = imrs_ipc::export(&Remote::new(&cell).unwrap(), &port).unwrap();
    let mut caller = port.owner().unwrap();
    // A response handler in this process, beside two in others (which answer with 4 n).
    let mut local = port
        .answer("LOCAL", |_: &(), n: Number| Number { value: 3 * n.value })
        .unwrap();
    let answerers: Vec<Peer> = ["REMOTE_1", "REMOTE_2"]
        .iter()
        .map(|module| peer(&["answerer", &cell, "POLL", module, "10"]))
        .collect();
    until_users(&caller, 3).await;
    // The local handler answers only when served, so each query is answered first by a
    // remote one, then by the other, then by the local one.
    for value in 1..=10 {
        let mut poll = within(5, caller.call_all(Number { value })).await.unwrap();
        let mut answers = vec![(poll.from.clone(), poll.first.value)];
        let (from, second) = within(5, poll.next_reply()).await.unwrap();
        answers.push((from, second.value));
        within(5, local.serve(&())).await.unwrap();
        let (from, third) = within(5, poll.next_reply()).await.unwrap();
        answers.push((from, third.value));
        assert!(
            within(5, poll.next_reply()).await.is_none(),
            "three answers"
        );
        answers.sort();
        assert_eq!(
            answers,
            [
                ("LOCAL".into(), 3 * value),
                ("REMOTE_1".into(), 4 * value),
                ("REMOTE_2".into(), 4 * value)
            ]
        );
    }
    for answerer in answerers {
        let text = finished(answerer).await;
        assert_eq!(text.lines().filter(|line| *line == "answered").count(), 10);
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_tight_port_crosses_as_any_other_and_a_dead_owner_still_fails_the_sender() {
    let cell = unique_name("tight");
    let remote = Remote::new(&cell).unwrap();
    let mut owner = started_owner("tight-owner", &cell, "DOUBLE");
    let imported = import::<Imported<Number, Number, usage::Receive>, _>(
        &remote, "DOUBLE", "DOUBLER", "ASKER",
    )
    .unwrap();
    let mut asker = imported.port().user_named("ASKER").unwrap();
    // Three deaths, each of a new copy of the owner: whether the spinning sender's own
    // turn or the bridge's task forwarded the last request is a race, and the death must
    // be seen either way.
    for death in 1..=3 {
        // A restarted owner is served once its server is seen.
        assert_eq!(served_again(&mut asker, 1).await.value, 2);
        for value in 2..=200 {
            let reply = within(5, asker.send(Number { value })).await.unwrap();
            assert_eq!(reply.value, 2 * value);
        }
        let result;
        (asker, result) = send_while_the_owner_is_killed(asker, &mut owner).await;
        assert!(
            matches!(result, Err(SendError::NoReply { ref port }) if port == "DOUBLE"),
            "death {death}: {result:?}"
        );
        owner = started_owner("tight-owner", &cell, "DOUBLE");
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_tight_port_is_served_whether_the_other_side_spins_or_has_parked() {
    let cell = unique_name("tight-turns");
    let _owner = started_owner("tight-owner", &cell, "DOUBLE");
    let remote = Remote::new(&cell).unwrap();
    let imported = import::<Imported<Number, Number, usage::Receive>, _>(
        &remote, "DOUBLE", "DOUBLER", "ASKER",
    )
    .unwrap();
    // The owner declared the port TIGHT: the importing module's waits spin too.
    assert_eq!(imported.port().process_type(), ProcessType::Tight);
    let mut asker = imported.port().user_named("ASKER").unwrap();
    let mut ask = async move |value: u64| {
        let reply = within(5, asker.send(Number { value })).await.unwrap();
        assert_eq!(reply.value, 2 * value);
    };
    // Both spinning: the requests and replies move in the two modules' own turns.
    for value in 1..=500 {
        ask(value).await;
    }
    // The owner has parked between requests: each request's wake-up must reach it.
    for value in 1..=5 {
        tokio::time::sleep(Duration::from_millis(20)).await;
        ask(value).await;
    }
    // The owner answers a second later, long after the sender parked: the reply's wake-up
    // must reach the sender.
    ask(1001).await;
    // And spinning again, as before.
    for value in 1..=100 {
        ask(value).await;
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_tight_port_whose_export_is_dropped_closes_as_a_port_of_one_process_does() {
    use imrs_ports::{AnyUser, Port, PortSpec, ReceiveError, usage};

    // The port keeps the bridge's turns, and the bridge keeps the port: dropping the export
    // must still let the bridge go, with its hold on the port.
    let cell = unique_name("tight-dropped");
    let port: Port<Number, Number, usage::Receive, AnyUser, 1> =
        Port::new(PortSpec::new("DOUBLE", "DOUBLER").process_type(ProcessType::Tight));
    let exported = imrs_ipc::export(&Remote::new(&cell).unwrap(), &port).unwrap();
    let mut owner = port.owner().unwrap();
    drop(exported);
    drop(port);
    let received = within(5, owner.receive()).await;
    assert!(
        matches!(received, Err(ReceiveError::Closed { ref port }) if port == "DOUBLE"),
        "{received:?}"
    );
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_owners_query_reaches_its_user_in_another_process_and_a_gone_user_fails_it() {
    use imrs_ports::{AnyUser, Port, PortSpec, QueryError, usage};

    let cell = unique_name("query");
    // ASK_STATUS(N): USAGE=QUERY, USERLIST=(CHILD): the parent asks its child.
    let port: Port<Number, Number, usage::Query, AnyUser, 1> =
        Port::new(PortSpec::new("ASK_STATUS", "PARENT").user_list(["CHILD"]));
    let _exported = imrs_ipc::export(&Remote::new(&cell).unwrap(), &port).unwrap();
    let mut parent = port.owner().unwrap();
    let child = peer(&["child", &cell, "ASK_STATUS", "CHILD", "10"]);
    until_users(&parent, 1).await;
    for value in 1..=10 {
        let status = within(5, parent.query(Number { value })).await.unwrap();
        assert_eq!(status.value, 5 * value);
    }
    // The child answered ten and ended: the next query fails, typed, and nothing hangs.
    let text = finished(child).await;
    assert_eq!(text.lines().filter(|line| *line == "answered").count(), 10);
    let late = within(10, parent.query(Number { value: 11 })).await;
    assert!(
        matches!(
            late,
            Err(QueryError::NoResponse { .. } | QueryError::PeerGone { .. })
        ),
        "{late:?}"
    );
}

#[test]
fn a_runtime_without_its_io_driver_is_refused_by_name_not_by_a_panic() {
    use imrs_ports::{AnyUser, Port, PortSpec, usage};

    // The bridges wait on tokio's reactor: a runtime built without it cannot carry a port.
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_time()
        .build()
        .unwrap();
    let cell = unique_name("no-io");
    runtime.block_on(async {
        let port: Port<Number, Number, usage::Receive, AnyUser, 1> =
            Port::new(PortSpec::new("QUIET", "OWNER"));
        let error = imrs_ipc::export(&Remote::new(&cell).unwrap(), &port)
            .err()
            .expect("refused");
        assert!(
            matches!(&error, IpcError::Transport { port, .. } if port == "QUIET"),
            "{error:?}"
        );
        assert!(error.to_string().contains("I/O driver"), "{error}");
    });
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

/// The states of the iceoryx2 nodes of process `pid` on this host, "alive" or "dead". (A
/// node whose state iceoryx2 cannot tell has no details, so no process to match.)
fn nodes_of(pid: u32) -> Vec<&'static str> {
    use iceoryx2::node::NodeView;
    use iceoryx2::prelude::*;

    let of = |details: &Option<iceoryx2::node::NodeDetails>| {
        details
            .as_ref()
            .is_some_and(|details| details.process_id().value() as u32 == pid)
    };
    let mut states = Vec::new();
    Node::<ipc_threadsafe::Service>::list(Config::global_config(), |state| {
        match &state {
            NodeState::Alive(node) if of(node.details()) => states.push("alive"),
            NodeState::Dead(node) if of(node.details()) => states.push("dead"),
            _ => {}
        }
        CallbackProgression::Continue
    })
    .unwrap();
    states
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_process_killed_while_nobody_waited_on_it_is_swept_by_the_next_to_start() {
    let mut killed = owner(&unique_name("killed-idle"), "DOUBLE");
    let pid = killed.0.id();
    assert!(nodes_of(pid).contains(&"alive"), "{:?}", nodes_of(pid));
    // Killed with no request waiting on it: no bridge looks for it, and its shared memory
    // stays until another process sweeps.
    killed.0.kill().unwrap();
    killed.0.wait().unwrap();
    // Dead, unless another test's process has already started and swept it.
    assert!(!nodes_of(pid).contains(&"alive"), "{:?}", nodes_of(pid));
    // The next process to wire a port across processes, in any cell, removes it: iceoryx2
    // sweeps the host's dead nodes whenever a node is created, as each crossing port does.
    let _next = owner(&unique_name("next"), "DOUBLE");
    assert_eq!(
        nodes_of(pid),
        Vec::<&str>::new(),
        "the killed process's node is left"
    );
}

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
        eprintln!("DBG {export} peers at once {:?}", camera.peers());
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

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_owner_of_broadcasts_killed_mid_run_and_started_again_reaches_its_user_again() {
    let cell = unique_name("shared-send-all-owner-killed");
    let mut first = started(&["camera", &cell, "FRAMES", "1000000"]);
    let remote = Remote::new(&cell).unwrap();
    let imported = imrs_ipc::import::<Imported<Shared<Frame>, Shared<Frame>, usage::SendAll>, _>(
        &remote, "FRAMES", "CAMERA", "LEFT",
    )
    .unwrap();
    let mut left = imported.port().user_named("LEFT").unwrap();
    // LEFT answers as the camera checks: read in place, three times word 4.
    let (seen, mut heard) = tokio::sync::mpsc::unbounded_channel();
    tokio::spawn(async move {
        while let Ok((mut frame, reply)) = left.receive().await {
            let mut answer: Shared<Frame> = frame.loan_reply();
            answer.words[0] = u64::from(!frame.is_writable());
            answer.words[4] = 3 * frame.words[4];
            reply.reply(answer);
            let _ = seen.send(frame.words[4]);
        }
    });
    for seed in 1..=3 {
        assert_eq!(within(10, heard.recv()).await, Some(seed));
    }
    // kill -9 the camera mid-run.
    first.0.kill().unwrap();
    first.0.wait().unwrap();
    // A new copy of the camera numbers from 1 again, and LEFT hears each of its frames, in
    // order. The frame LEFT was reading when the first died may come first: a later one.
    let mut second = started(&["camera", &cell, "FRAMES", "3"]);
    let mut next = 1;
    while next <= 3 {
        let seed = within(10, heard.recv()).await.unwrap();
        if seed == next {
            next += 1;
        } else {
            assert!(next == 1 && seed > 3, "heard frame {seed}, not {next}");
        }
    }
    // It found every answer as it checks them, read in place.
    assert!(exit_status(&mut second).await.success());
}

/// How `peer` ended, once it has (10 s at most).
async fn exit_status(peer: &mut Peer) -> std::process::ExitStatus {
    within(10, async {
        loop {
            if let Some(status) = peer.0.try_wait().unwrap() {
                return status;
            }
            tokio::time::sleep(Duration::from_millis(20)).await;
        }
    })
    .await
}

/// A response handler's answer: five times the question.
fn five_times(_: &(), number: Number) -> Number {
    Number {
        value: 5 * number.value,
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_owner_of_queries_killed_mid_run_and_started_again_reaches_its_user_again() {
    let cell = unique_name("query-owner-killed");
    let first = started(&["parent", &cell, "ASK_STATUS", "1000000"]);
    let remote = Remote::new(&cell).unwrap();
    let imported = imrs_ipc::import::<Imported<Number, Number, usage::Query>, _>(
        &remote,
        "ASK_STATUS",
        "PARENT",
        "CHILD",
    )
    .unwrap();
    let child = imported.port().answer("CHILD", five_times).unwrap();
    let heard = answering(child);
    answers_an_owner_killed_and_started_again(heard, first, &["parent", &cell, "ASK_STATUS", "3"])
        .await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_owner_of_callalls_killed_mid_run_and_started_again_reaches_its_user_again() {
    let cell = unique_name("call-all-owner-killed");
    let first = started(&["caller", &cell, "POLL", "1000000"]);
    let remote = Remote::new(&cell).unwrap();
    let imported = imrs_ipc::import::<Imported<Number, Number, usage::CallAll>, _>(
        &remote, "POLL", "CALLER", "ANSWERER",
    )
    .unwrap();
    let answerer = imported.port().answer("ANSWERER", five_times).unwrap();
    let heard = answering(answerer);
    answers_an_owner_killed_and_started_again(heard, first, &["caller", &cell, "POLL", "3"]).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_owner_of_broadcasts_of_numbers_killed_mid_run_and_started_again_reaches_its_user_again()
{
    let cell = unique_name("send-all-owner-killed");
    let first = started(&["announcer", &cell, "NEWS", "1000000"]);
    let remote = Remote::new(&cell).unwrap();
    let imported = imrs_ipc::import::<Imported<Number, Number, usage::SendAll>, _>(
        &remote,
        "NEWS",
        "ANNOUNCER",
        "HEARER",
    )
    .unwrap();
    let mut hearer = imported.port().user_named("HEARER").unwrap();
    let (answered, heard) = tokio::sync::mpsc::unbounded_channel();
    tokio::spawn(async move {
        let _imported = imported;
        while let Ok((number, reply)) = hearer.receive().await {
            reply.reply(five_times(&(), number));
            let _ = answered.send(());
        }
    });
    answers_an_owner_killed_and_started_again(heard, first, &["announcer", &cell, "NEWS", "3"])
        .await;
}

/// Serves `handler` without end; says each time it has answered.
fn answering(
    mut handler: imrs_ports::ResponseEnd<Number, Number, ()>,
) -> tokio::sync::mpsc::UnboundedReceiver<()> {
    let (answered, heard) = tokio::sync::mpsc::unbounded_channel();
    tokio::spawn(async move {
        while handler.serve(&()).await.is_ok() {
            let _ = answered.send(());
        }
    });
    heard
}

/// A user here answers the owner in `first` (which asks without end) three times, as
/// `heard` tells; then `first` is killed (`kill -9`), and a new copy of the owner, started
/// with `again` to ask three times, must find all three answers right.
async fn answers_an_owner_killed_and_started_again(
    mut heard: tokio::sync::mpsc::UnboundedReceiver<()>,
    mut first: Peer,
    again: &[&str],
) {
    for _ in 0..3 {
        within(10, heard.recv()).await.unwrap();
    }
    first.0.kill().unwrap();
    first.0.wait().unwrap();
    while heard.try_recv().is_ok() {}
    let mut second = started(again);
    for _ in 0..3 {
        within(10, heard.recv()).await.unwrap();
    }
    // The new owner found every answer five times its question.
    assert!(exit_status(&mut second).await.success());
}

/// The trust boundary: a process of the same user claims module names. Each claim that is
/// refused — off the user list, or past the number of users — leaves no name behind in the
/// owner's process, so that claims without end grow nothing there.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_refused_claim_leaves_no_name_in_the_owners_process() {
    let cell = unique_name("claims");
    let remote = Remote::new(&cell).unwrap();
    let port: Port<Number, Number, usage::Receive, AnyUser, 1> =
        Port::new(PortSpec::new("DOUBLE", "DOUBLER").user_list(["ASKER"]));
    let _exported = export(&remote, &port).unwrap();
    let mut owner = port.owner().unwrap();
    tokio::spawn(async move {
        while let Ok((number, reply)) = owner.receive().await {
            reply.reply(Number {
                value: 2 * number.value,
            });
        }
    });
    // Each claim must be refused for the reason given, which the claimer prints.
    let refused = |args: &[&str], why: &str| {
        let mut claimer = peer(args);
        let status = claimer.0.wait().unwrap();
        let mut said = String::new();
        std::io::Read::read_to_string(&mut claimer.0.stdout.take().unwrap(), &mut said).unwrap();
        assert_eq!(status.code(), Some(2), "{args:?}: {said}");
        assert!(said.contains(why), "{args:?} was refused otherwise: {said}");
    };
    // Off the list.
    let off_list: Vec<String> = (0..20)
        .map(|i| format!("ROGUE_{}_{i}", std::process::id()))
        .collect();
    for module in &off_list {
        refused(
            &["user", &cell, "DOUBLE", module, "1"],
            "not on the user list",
        );
    }
    // Past the number of users of a port with no list: FIRST holds its one place.
    let open =
        Port::<Number, Number, usage::Receive, AnyUser, 1>::new(PortSpec::new("OPEN", "OPENER"));
    let _open = export(&remote, &open).unwrap();
    let _first = open.user_named("FIRST").unwrap();
    let past: Vec<String> = (0..5)
        .map(|i| format!("LATE_{}_{i}", std::process::id()))
        .collect();
    for module in &past {
        refused(&["user", &cell, "OPEN", module, "1"], "active user");
    }
    // Off the list of a SENDALL port, whose remote users are relayed to.
    let alarm: Port<Number, Number, usage::SendAll, AnyUser, 1> =
        Port::new(PortSpec::new("ALARM", "BROADCASTER").user_list(["HEARER"]));
    let _alarm = export(&remote, &alarm).unwrap();
    let listeners: Vec<String> = (0..5)
        .map(|i| format!("EAVESDROPPER_{}_{i}", std::process::id()))
        .collect();
    for module in &listeners {
        refused(
            &["listener", &cell, "ALARM", module, "1"],
            "not on the user list",
        );
    }
    for module in off_list.iter().chain(&past).chain(&listeners) {
        assert_eq!(Name::known(module), None, "{module} was kept");
    }
}
