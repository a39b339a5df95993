use imrs_ports::{Port, PortSpec, usage};

async fn load_card() {
    // CARD_IN_PLACE is a SEND port: there is no response handler to query.
    let port = Port::<(), i32, usage::Send>::new(PortSpec::new("CARD_IN_PLACE", "LOAD_CARD"));
    let mut load_card = port.owner().unwrap();
    let _ = load_card.query(()).await;
}

fn main() {
    drop(load_card());
}
