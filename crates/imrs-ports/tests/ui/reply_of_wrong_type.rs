use imrs_ports::{Port, PortSpec, usage};

async fn screw_in_card() {
    // CARD_IN_PLACE(RC:INTEGER): the reply is an i32 return code, not text.
    let port = Port::<(), i32, usage::Send>::new(PortSpec::new("CARD_IN_PLACE", "LOAD_CARD"));
    let mut screw_in_card = port.user_named("SCREW_IN_CARD").unwrap();
    let ((), reply) = screw_in_card.receive().await.unwrap();
    reply.reply("screwed in");
}

fn main() {
    drop(screw_in_card());
}
