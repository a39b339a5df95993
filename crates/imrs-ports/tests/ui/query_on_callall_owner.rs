use imrs_ports::{AnyUser, Port, PortSpec, usage};

async fn supervisor() {
    // STATUS_ALL is a CALLALL port: its owner asks every user with `call_all`.
    let port = Port::<(), i32, usage::CallAll, AnyUser, 3>::new(PortSpec::new("STATUS_ALL", "SUPERVISOR"));
    let mut supervisor = port.owner().unwrap();
    let _ = supervisor.query(()).await;
}

fn main() {
    drop(supervisor());
}
