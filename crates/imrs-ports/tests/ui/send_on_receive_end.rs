use imrs_ports::{Port, PortSpec, usage};

async fn load_card() {
    // LOAD_CARD owns PALLET_IN_PLACE with USAGE=RECEIVE: it cannot send on it.
    let port = Port::<(), (), usage::Receive>::new(PortSpec::new("PALLET_IN_PLACE", "LOAD_CARD"));
    let mut load_card = port.owner().unwrap();
    let _ = load_card.send(()).await;
}

fn main() {
    drop(load_card());
}
