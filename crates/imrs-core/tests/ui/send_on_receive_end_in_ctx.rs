use imrs_core::prelude::*;

// FREQUENCY is received by GATE: its owner end cannot send, and the compiler says so once.
fn gate(frequency: Port<u32, (), usage::Receive>) -> ModuleSpec<()> {
    ModuleSpec::new("GATE", ()).task("GATE", move |ctx| {
        let frequency = ctx.owner(&frequency);
        async move {
            let mut frequency = frequency?;
            ctx.send(&mut frequency, 1).await?;
            Ok(())
        }
    })
}

fn main() {
    drop(gate);
}
