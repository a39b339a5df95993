//! A client that is not ours — Python's `eclipse-zenoh`, speaking only the documented key
//! expressions and CDR — sends to a port, queries a response handler, is refused off the
//! user list by name, and listens to a `SENDALL` port: it reads a broadcast and answers it.

mod common;

use common::{PROMPTLY, listening, within};
use imrs_ports::{AnyUser, Port, PortSpec, usage};
use imrs_testkit::{free_endpoint, python_with};
use imrs_zenoh::export;

/// The Python package the test drives, at the version of the zenoh crate.
const CLIENT: &str = "eclipse-zenoh==1.10.2";

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_python_client_sends_queries_listens_and_is_refused_off_the_list() {
    let python = python_with("zenoh", CLIENT);
    let endpoint = free_endpoint();
    let host = listening("python_cell", &endpoint).await;
    let double: Port<u64, u64, usage::Receive, AnyUser, 2> =
        Port::new(PortSpec::new("DOUBLE", "DOUBLER").user_list(["PYTHON"]));
    let _double = export(&host, &double).await.unwrap();
    let mut doubler = double.owner().unwrap();
    tokio::spawn(async move {
        while let Ok((n, reply)) = doubler.receive().await {
            reply.reply(2 * n);
        }
    });
    let status: Port<String, String, usage::Response, AnyUser, 2> =
        Port::new(PortSpec::new("STATUS", "CELL"));
    let _status = export(&host, &status).await.unwrap();
    let mut handler = status
        .answer("CELL", |running: &bool, asked: String| {
            format!("{asked}: {}", if *running { "running" } else { "stopped" })
        })
        .unwrap();
    tokio::spawn(async move { while handler.serve(&true).await.is_ok() {} });
    let alarm: Port<String, u32, usage::SendAll, AnyUser, 1> =
        Port::new(PortSpec::new("ALARM", "LINE"));
    let _alarm = export(&host, &alarm).await.unwrap();
    let mut line = alarm.owner().unwrap();
    let broadcasting = tokio::spawn(async move {
        while alarm.users_attached() < 1 {
            tokio::task::yield_now().await;
        }
        line.send_all("feeder 3 empty".to_owned())
            .await
            .map(|broadcast| broadcast.first)
    });

    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/outside_client.py");
    let client = tokio::process::Command::new(python)
        .args([script, &endpoint, "python_cell"])
        .output();
    let output = within(PROMPTLY * 3, "the Python client", client)
        .await
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "the client failed:\n{stdout}\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines[0], "DOUBLE 21 -> 42");
    assert_eq!(lines[1], "STATUS -> status: running");
    assert_eq!(lines[3], "ALARM from LINE: feeder 3 empty");
    let answer = within(PROMPTLY, "the broadcast's answer", broadcasting).await;
    assert_eq!(answer.unwrap().unwrap(), 14);
    assert!(
        lines[2].starts_with("ROGUE refused:")
            && lines[2].contains("ROGUE")
            && lines[2].contains("DOUBLE"),
        "{}",
        lines[2]
    );
}
