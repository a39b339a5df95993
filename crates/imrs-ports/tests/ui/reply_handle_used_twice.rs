use imrs_ports::{Port, PortSpec, usage};

async fn screw_in_card() {
    let port = Port::<(), i32, usage::Send>::new(PortSpec::new("CARD_IN_PLACE", "LOAD_CARD"));
    let mut screw_in_card = port.user_named("SCREW_IN_CARD").unwrap();
    let ((), reply) = screw_in_card.receive().await.unwrap();
    reply.reply(0);
    // A sender is unblocked once: the handle is spent.
    reply.reply(0);
}

fn main() {
    drop(screw_in_card());
}
