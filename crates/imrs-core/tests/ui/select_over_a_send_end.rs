use imrs_core::prelude::*;

// A select waits for messages to receive: a SEND end has none to offer.
async fn gate(mut let_1_go: End<(), i32, usage::Send>) {
    let _ = select().or(&mut let_1_go, |_| ()).await;
}

fn main() {
    drop(gate);
}
