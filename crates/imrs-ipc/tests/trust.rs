//! The trust boundary between processes of one user: a request header a peer wrote garbage
//! into is refused while the owner keeps serving; a port's shared memory and service files
//! are for the cell's user only; a refused claim of a module name leaves no name behind.

mod common;

use std::time::Duration;

use common::{Frame, Number, owner, peer, until_users, within, word, write_frame};
use imrs_ipc::{FromBytes, Imported, Remote, ZeroCopySend, export, import};
use imrs_ports::{AnyUser, Name, Port, PortSpec, Shared, usage};
use imrs_testkit::unique_name;

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
