//! The trust boundary of a port without a user list: a process of the same user may claim
//! any module name on it, and each name it makes is kept. The owner's process keeps at most
//! `Name::MOST_FROM_PEERS` names made from its peers' text; past them a new name is refused
//! by name, while the names already accepted are served still. Its own test binary, since
//! the bound is the process's.

use std::io::Read;
use std::process::{Command, Stdio};
use std::time::Duration;

use imrs_ipc::{FromBytes, Remote, ZeroCopySend, export};
use imrs_ports::{AnyUser, Name, Port, PortSpec, usage};
use imrs_testkit::unique_name;

/// The peer's message: the same by name, size and alignment.
#[derive(Debug, Clone, Copy, Default, PartialEq, ZeroCopySend, FromBytes)]
#[repr(C)]
#[type_name("imrs_ipc_tests::Number")]
struct Number {
    value: u64,
}

/// Runs `ipc_peer user CELL OPEN MODULE 1` to its end (killed past 30 s): its exit code
/// and what it printed.
async fn user(cell: &str, module: &str) -> (Option<i32>, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_ipc_peer"))
        .args(["user", cell, "OPEN", module, "1"])
        .stdout(Stdio::piped())
        .spawn()
        .expect("the peer starts");
    let deadline = tokio::time::Instant::now() + Duration::from_secs(30);
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if tokio::time::Instant::now() > deadline {
            let _ = child.kill();
            panic!("the user process {module} hung");
        }
        tokio::time::sleep(Duration::from_millis(20)).await;
    };
    let mut said = String::new();
    child
        .stdout
        .take()
        .unwrap()
        .read_to_string(&mut said)
        .unwrap();
    (status.code(), said)
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_new_name_past_the_bound_is_refused_by_name_across_processes() {
    let cell = unique_name("names");
    let remote = Remote::new(&cell).unwrap();
    let open: Port<Number, Number, usage::Receive, AnyUser, 4> =
        Port::new(PortSpec::new("OPEN", "DOUBLER"));
    let _exported = export(&remote, &open).unwrap();
    let mut owner = open.owner().unwrap();
    tokio::spawn(async move {
        while let Ok((number, reply)) = owner.receive().await {
            reply.reply(Number {
                value: 2 * number.value,
            });
        }
    });
    let early = format!("EARLY_{}", std::process::id());
    assert_eq!(user(&cell, &early).await, (Some(0), "2\n".to_owned()));
    // Peers have made the rest of the bound's names, here through another open port.
    let other: Port<Number, Number, usage::Receive, AnyUser, 1> =
        Port::new(PortSpec::new("OTHER", "DOUBLER"));
    let mut made = 1;
    while other.claim(&format!("CHURN_{made}")).is_ok() {
        made += 1;
    }
    assert_eq!(made, Name::MOST_FROM_PEERS);
    let late = format!("LATE_{}", std::process::id());
    let (code, said) = user(&cell, &late).await;
    assert_eq!(code, Some(2), "{said}");
    assert!(
        said.contains(&format!(
            "the owner's process keeps {} module names its peers made already and refused \
             {late}: give port OPEN a user list",
            Name::MOST_FROM_PEERS
        )),
        "{late} was refused otherwise: {said}"
    );
    assert_eq!(Name::known(&late), None, "{late} was kept");
    // The module accepted while there was room is served still.
    assert_eq!(user(&cell, &early).await, (Some(0), "2\n".to_owned()));
}
