use imrs_ports::{Port, PortSpec, usage};

async fn gate() {
    // GATE owns LET_1_GO with USAGE=SEND: it cannot receive on it.
    let port = Port::<(), i32, usage::Send>::new(PortSpec::new("LET_1_GO", "GATE"));
    let mut gate = port.owner().unwrap();
    let _ = gate.receive().await;
}

fn main() {
    drop(gate());
}
