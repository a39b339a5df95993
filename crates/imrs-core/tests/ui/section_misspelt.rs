use imrs_core::prelude::*;

// PLACE is made once; a task that misspells it names nothing.
const PLACE: Section = Section::new("PLACE");

fn main() {
    let _ = ModuleSpec::new("PALLETIZER", ())
        .order([PLACE.name(), "PALLETIZER".into()])
        .task("PALLETIZER", |ctx| async move {
            ctx.section(&PLACEE, ctx.delay(std::time::Duration::from_secs(1))).await;
            Ok(())
        });
}
